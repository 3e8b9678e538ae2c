"""The study report's driving section (the paper's Table 2) on real tiny highway-fast-v0 runs: its
cells against values computed by hand from the runs' eval.csv, the reference drivers' rows from
the file the reference command writes (a file it did not write is refused naming the command),
and no section for runs without the driving columns."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest
from flag_lists import SMALL_AGENT

from simoun_agent.config import SetupError
from simoun_agent.run import driving_reference, train
from simoun_lab.study.driving import MEASURES, REFERENCES_JSON, read_references
from simoun_lab.study.plan import evaluation_runs
from simoun_lab.study.report import driving_section, read_result
from simoun_lab.study.spec import load_spec
from simoun_lab.sweep.trainable import open_run

pytest.importorskip("highway_env")

TINY = """\
warmup_agent_steps = 8
replay_capacity = 1000
eval_every = 12
eval_episodes = 2
checkpoint_every = 1000
"""
"""[base] keys of both studies: 12 env steps of random actions, then 2 evaluation episodes"""

HIGHWAY_BASE = """\
preset = "highway-cpu"
# 2-second episodes (10 decisions): the preset's highway-fast-v0 settings otherwise
env_kwargs = {config = {action = {type = "ContinuousAction"}, policy_frequency = 5, \
simulation_frequency = 5, duration = 2, offroad_terminal = true}}
"""


def spec_text(recipes: list[str], base: str, task: str, seeds: str) -> str:
    """A study of ``recipes`` with one grid setting, 12 env steps a run in both phases."""
    phase = f'tasks = ["{task}"]\nenv_steps = 12\n'
    return (
        f"recipes = {recipes}\n\n[base]\n{base}{TINY}{SMALL_AGENT}\n[grid]\nagent.n_step = [3]\n\n"
        f"[tuning]\n{phase}seeds = [101]\n\n[evaluation]\n{phase}seeds = {seeds}\n"
    ).replace("'", '"')


def train_runs(spec_text: str, root: Path, skip: int = 0):
    """The spec's evaluation runs trained into ``root`` but the last ``skip`` (left unfinished),
    each with its recipe's one grid setting: (spec, runs)."""
    spec_path = root / "spec.toml"
    spec_path.write_text(spec_text)
    spec = load_spec(spec_path)
    runs = evaluation_runs(spec, {recipe: spec.settings()[0] for recipe in spec.recipes})
    for study_run in runs[: len(runs) - skip]:
        run = open_run(study_run.trial(spec, root))
        try:
            train.train(run)
        finally:
            run.env.close()
            run.eval_env.close()
    return spec, runs


def final_row(run_dir: Path) -> dict[str, float]:
    with (run_dir / "eval.csv").open(newline="") as f:
        return {key: float(value) for key, value in list(csv.DictReader(f))[-1].items()}


def cells(lines: list[str], header: str, first: str) -> list[str]:
    """The cells of the row whose first cell is ``first`` in the table whose first column is
    headed ``header``."""
    tables = [block.splitlines() for block in "\n".join(lines).split("\n\n")]
    (rows,) = [block for block in tables if block[0].startswith(f"| {header} |")]
    (row,) = [line.strip("| ").split(" | ") for line in rows if line.startswith(f"| {first} |")]
    return row[1:]


def interval(values: list[float], digits: str) -> str:
    """By hand: the IQM of one or two runs is their mean, and the percentile interval of its
    bootstrap runs from the smaller value to the larger (both resamples of one run alone)."""
    mean = sum(values) / len(values)
    return f"{mean:{digits}} [{min(values):{digits}}, {max(values):{digits}}]"


def better(x: list[float], y: list[float]) -> float:
    """By hand: P(a run of x beats a run of y), ties one half."""
    return float(np.mean([(a > b) + (a == b) / 2 for a in x for b in y]))


def test_the_driving_table_holds_each_recipes_final_measures_and_the_reference_drivers(tmp_path):
    # simoun with 2 runs, drq with 1 (its second run unfinished)
    text = spec_text(["simoun", "drq"], HIGHWAY_BASE, "highway-fast-v0", '"1-2"')
    spec, runs = train_runs(text, tmp_path, skip=1)
    results = [r for run in runs if (r := read_result(tmp_path, run)) is not None]
    finals = {recipe: [] for recipe in spec.recipes}
    for run in runs[:-1]:
        finals[run.recipe].append(final_row(tmp_path / run.name))
    assert [len(v) for v in finals.values()] == [2, 1]

    lines = driving_section(spec, results, tmp_path)
    assert "## Driving measures (the paper's Table 2)" in lines
    assert any(f"No `{REFERENCES_JSON}` in the study directory" in line for line in lines)
    for recipe, rows in finals.items():
        expected = [interval([row[key] for row in rows], digits) for key, _, digits in MEASURES]
        assert cells(lines, "recipe or driver", recipe) == [str(len(rows)), *expected]
    simoun, drq = finals["simoun"], finals["drq"]
    p_return = better([r["return_mean"] for r in simoun], [r["return_mean"] for r in drq])
    p_fewer = better([-r["crash_rate"] for r in simoun], [-r["crash_rate"] for r in drq])
    on_return, on_crashes = cells(lines, "Y", "drq")
    assert on_return.startswith(f"{p_return:.3f} [") and on_crashes.startswith(f"{p_fewer:.3f} [")
    assert any("on crash rate, lower is better: P(fewer crashes)" in line for line in lines)

    # the reference drivers, as the reference command writes them into the study directory
    references = tmp_path / REFERENCES_JSON
    argv = ["--episodes", "1", "--seed", "1000", "--json", str(references)]
    assert driving_reference.main(argv) == 0
    drivers = json.loads(references.read_text())["drivers"]
    lines = driving_section(spec, results, tmp_path)
    for driver, metrics in drivers.items():
        expected = [format(metrics[key], digits) for key, _, digits in MEASURES]
        assert cells(lines, "recipe or driver", f"{driver} (reference)") == ["–", *expected]
    said = " ".join(lines)
    assert f"python -m simoun_agent.run.driving_reference {' '.join(argv)}" in said
    assert "preset `highway-cpu`, 1 episode(s) from seed 1000" in said


def test_runs_without_the_driving_columns_get_no_driving_section(tmp_path):
    text = spec_text(["sac"], "image_size = 32\n", "simoun/PointReach-v0", "[1]")
    spec, runs = train_runs(text, tmp_path)
    (result,) = [read_result(tmp_path, run) for run in runs]
    assert (
        result.driving is None
        and result.final_return == final_row(tmp_path / runs[0].name)["return_mean"]
    )
    assert driving_section(spec, [result], tmp_path) == []


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("{not json", "is damaged: it is not JSON"),
        ("[1, 2]", "is damaged: it holds an array, not a JSON object"),
        ('{"command": "c", "preset": "highway-cpu"}', "lacks episodes, seed, drivers"),
        (
            '{"command": "c", "preset": "p", "episodes": 1, "seed": 0, '
            '"drivers": {"zero": {"return_mean": 1.0}}}',
            "driver 'zero' lacks crash_rate, distance_m",
        ),
    ],
)
def test_a_references_file_the_command_did_not_write_is_named_with_the_command(
    text, said, tmp_path
):
    (tmp_path / REFERENCES_JSON).write_text(text)
    with pytest.raises(SetupError) as refused:
        read_references(tmp_path)
    assert said in str(refused.value)
    assert "write it again with `python -m simoun_agent.run.driving_reference" in str(refused.value)
    assert f"--json {tmp_path}/{REFERENCES_JSON}`" in str(refused.value)
