"""simoun-study on a local Ray instance: a tiny end-to-end study on PointReach (2 recipes x a
2-value grid x 2 tuning + 2 evaluation seeds), its plan, resume from the archive, the commit
check, and the bad specs it refuses before Ray starts, each naming its line."""

import csv
import json
import math
import os
import re
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import ray  # noqa: F401  (the lab extra: a missing install fails instead of skipping)
from flag_lists import SMALL_AGENT
from test_train_failures import named_unwritten_file, under_file_size_limit

from simoun_agent.config import RECIPES, SetupError, resolve, to_dict
from simoun_lab.cli import study as cli
from simoun_lab.study.checks import changes
from simoun_lab.study.plan import evaluation_runs, tuning_runs
from simoun_lab.study.provenance import code_version
from simoun_lab.study.report import RunResult, cost_curves, mean_cpu, read_result
from simoun_lab.study.runner import StudyOptions, check_same_spec, open_study, spec_from
from simoun_lab.study.spec import load_spec
from simoun_lab.study.toml_lines import key_line

SPEC = (
    """\
description = "a tiny study for tests"
recipes = ["simoun", "sac"]

[base]
image_size = 32
warmup_agent_steps = 20
replay_capacity = 1000
eval_every = 40
eval_episodes = 1
checkpoint_every = 40
"""
    + SMALL_AGENT
    + """
[grid]
agent.n_step = [1, 3]

[tuning]
tasks = ["simoun/PointReach-v0"]
seeds = [101, 102]
env_steps = 80

[evaluation]
tasks = ["simoun/PointReach-v0"]
seeds = "1-2"
env_steps = 80

[resources]
max_concurrent_trials = 2
"""
)
"""tests/test_sweep.py's tiny run, shortened to 80 env steps, as a study (a few seconds per run)."""


def write_spec(path: Path, text: str = SPEC) -> Path:
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def study(ray_address, tmp_path_factory):
    """The tiny study, run once with an archive: (spec, study dir, archive)."""
    root = tmp_path_factory.mktemp("study")
    spec = write_spec(root / "tiny.toml")
    argv = ["run", str(spec), "--study-dir", str(root / "s"), "--archive", str(root / "a")]
    assert cli.main([*argv, "--verbose", "0"]) == 0
    return spec, root / "s", root / "a"


def run_dirs(root: Path) -> list[str]:
    return sorted(p.parent.relative_to(root).as_posix() for p in root.glob("*/**/summary.json"))


def test_study_tunes_selects_evaluates_and_reports(study):
    spec_path, study_dir, _ = study
    spec = load_spec(spec_path)
    names = [run.name for run in tuning_runs(spec)]
    selection = json.loads((study_dir / "selection.json").read_text())
    chosen = {r: c["setting"] for r, c in selection["recipes"].items()}
    names += [run.name for run in evaluation_runs(spec, chosen)]
    assert run_dirs(study_dir) == sorted(names)
    assert len(names) == 12 and "tuning/simoun/agent.n_step=3/simoun-PointReach-v0/s102" in names
    assert "evaluation/sac/simoun-PointReach-v0/s2" in names
    for recipe, choice in selection["recipes"].items():
        scores = {json.dumps(c["setting"]): c["score"] for c in choice["candidates"]}
        assert choice["score"] == max(scores.values())  # the best setting won
        assert len(scores) == 2 and all(
            len(c["runs"]["simoun/PointReach-v0"]) == 2 for c in choice["candidates"]
        )
        config = json.loads(
            (study_dir / f"evaluation/{recipe}/simoun-PointReach-v0/s1/config.json").read_text()
        )
        assert config["agent"]["recipe"] == recipe
        assert config["agent"]["n_step"] == choice["setting"]["agent.n_step"]
        assert config["seed"] == 1 and config["total_env_steps"] == 80
    report = (study_dir / "report/report.md").read_text()
    for recipe, choice in selection["recipes"].items():
        setting = f"agent.n_step={choice['setting']['agent.n_step']}"
        row = f"| {recipe} | {RECIPES[recipe].description} | `{setting}` | {choice['score']:.4g} |"
        assert row in report
    assert "| simoun-PointReach-v0 | simoun | 2 |" in report
    assert "IQM score [95 % CI]" in report and "P(X > Y) [95 % CI]" in report
    assert "| sac | simoun-PointReach-v0 | " in report  # P(simoun > sac)
    assert "seeds 101, 102, 80 env steps" in report and "seeds 1, 2, 80 env steps" in report
    for png in ("iqm_curves.png", "evaluation/curves_wall_time.png", "tuning/iqm_env_steps.png"):
        assert (study_dir / "report" / png).stat().st_size > 1000
    trial = json.loads((study_dir / names[0] / "trial.json").read_text())["parts"]
    assert len(trial) == 1 and trial[0]["cpu_s"] > 0 and len(trial[0]["loadavg"]) == 3
    assert trial[0]["env_step_start"] == 0 and trial[0]["env_step_end"] == 80


def test_report_writes_the_report_again_from_the_archive_alone(study, tmp_path):
    spec_path, study_dir, archive = study
    copy = tmp_path / "archive"
    shutil.copytree(archive, copy)
    shutil.rmtree(copy / "report")
    assert cli.main(["report", str(spec_path), "--study-dir", str(copy)]) == 0
    again = (copy / "report/report.md").read_text()
    assert "written again from the finished runs by the code at commit" in again
    first = (study_dir / "report/report.md").read_text()
    results = first[first.index("## Results") : first.index("## Time")]
    assert results in again  # the same runs give the same statistics
    assert (copy / "report/iqm_curves.png").stat().st_size > 1000
    other = write_spec(tmp_path / "other.toml", SPEC.replace("[101, 102]", "[103, 104]"))
    with pytest.raises(SystemExit):
        cli.main(["report", str(other), "--study-dir", str(copy)])


def test_cpu_time_of_a_group_leaves_out_runs_with_an_unrecorded_part():
    def result(cpu_s: float) -> RunResult:
        return RunResult(None, 0.0, 0.0, {}, 10.0, cpu_s, 0.5)

    assert mean_cpu([result(100.0), result(300.0)]) == "200"
    assert mean_cpu([result(100.0), result(math.nan)]) == "100 (1 of 2 runs)"
    assert mean_cpu([result(math.nan)]) == "–"


def test_archive_holds_the_finished_runs_without_checkpoints(study):
    _, study_dir, archive = study
    assert run_dirs(archive) == run_dirs(study_dir)
    files = {p.name for p in archive.rglob("*") if p.is_file()}
    assert not any(name.endswith((".pt", ".npz", ".mp4")) for name in files)
    assert not list(archive.rglob("tb"))
    kept = archive / run_dirs(archive)[0]
    assert sorted(p.name for p in kept.iterdir()) == [
        "config.json", "eval.csv", "summary.json", "train.csv", "trial.json"
    ]  # fmt: skip
    record = json.loads((archive / "study.json").read_text())
    assert record["spec"]["recipes"] == ["simoun", "sac"]
    assert re.fullmatch("[0-9a-f]{40}", record["parts"][0]["commit"])  # tests run in a checkout
    assert isinstance(record["parts"][0]["dirty"], bool)
    assert (archive / "selection.json").is_file() and (archive / "report/report.md").is_file()


def restamp(record_path: Path) -> None:
    """Record the code's current commit as the study's: other work may be committed while this
    test runs, and the commit check has a test of its own."""
    record = json.loads(record_path.read_text())
    record["parts"][0].update(code_version())
    record_path.write_text(json.dumps(record))


def test_a_renamed_copy_of_the_spec_is_told_that_a_study_is_named_for_its_spec_file(
    study, tmp_path, capsys
):
    spec_path, _, archive = study
    renamed = tmp_path / f"my-{spec_path.name}"
    shutil.copy(spec_path, renamed)
    with pytest.raises(SystemExit) as stop:
        cli.main(["report", str(renamed), "--study-dir", str(archive)])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and "a study is named for its spec file" in err
    assert f"pass the spec under the name {spec_path.name}" in err


def test_resume_from_the_archive_reruns_only_the_missing_run(study, tmp_path, capsys):
    spec_path, study_dir, archive = study
    # the study directory is gone (another machine); the archive lost one evaluation run
    shutil.copytree(archive, tmp_path / "a")
    missing = "evaluation/sac/simoun-PointReach-v0/s2"
    shutil.rmtree(tmp_path / "a" / missing)
    restamp(tmp_path / "a" / "study.json")
    kept = {name: (archive / name / "summary.json").read_bytes() for name in run_dirs(archive)}
    argv = ["run", str(spec_path), "--study-dir", str(tmp_path / "s")]
    assert cli.main([*argv, "--archive", str(tmp_path / "a"), "--resume", "--verbose", "0"]) == 0
    out = capsys.readouterr().out
    assert "tuning: 0 runs to run, 8 already finished (8 restored from" in out
    assert "evaluation: 1 runs to run, 3 already finished (3 restored from" in out
    assert run_dirs(tmp_path / "s") == sorted(kept)
    for name, summary in kept.items():
        if name != missing:
            assert (tmp_path / "s" / name / "summary.json").read_bytes() == summary
            assert not (tmp_path / "s" / name / "checkpoint.pt").exists()  # restored, not rerun
    assert (tmp_path / "s" / missing / "checkpoint.pt").is_file()  # trained again
    assert (tmp_path / "a" / missing / "summary.json").is_file()  # and archived
    # the same tuning runs, so the same selection
    assert json.loads((tmp_path / "s/selection.json").read_text()) == json.loads(
        (study_dir / "selection.json").read_text()
    )
    assert len(json.loads((tmp_path / "a/study.json").read_text())["parts"]) == 2


def test_resume_from_another_commit_is_refused_unless_allowed(study, tmp_path, capsys):
    spec_path, study_dir, _ = study
    shutil.copytree(study_dir, tmp_path / "s", ignore=shutil.ignore_patterns("tune"))
    record = json.loads((tmp_path / "s/study.json").read_text())
    record["parts"][0].update(commit="0" * 40, dirty=False)
    (tmp_path / "s/study.json").write_text(json.dumps(record))
    argv = ["run", str(spec_path), "--study-dir", str(tmp_path / "s"), "--resume"]
    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"this study ran from commit {'0' * 40}" in err
    assert "the code under study must not change" in err and "--allow-other-commit" in err
    assert cli.main([*argv, "--allow-other-commit", "--verbose", "0"]) == 0  # all finished
    parts = json.loads((tmp_path / "s/study.json").read_text())["parts"]
    assert len(parts) == 2 and parts[1]["allowed_other_commit"] is True


def test_allow_other_commit_without_resume_is_refused_before_anything_is_made(tmp_path, capsys):
    spec_path = write_spec(tmp_path / "tiny.toml")
    argv = ["run", str(spec_path), "--study-dir", str(tmp_path / "s"), "--allow-other-commit"]
    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "--allow-other-commit works only with --resume" in err
    assert "add --resume to continue the study in --study-dir, or drop --allow-other-commit" in err
    assert not (tmp_path / "s").exists()


def test_resume_with_another_spec_and_a_new_study_over_an_old_one_are_refused(study, capsys):
    spec_path, study_dir, _ = study
    (spec_path.parent / "changed").mkdir(exist_ok=True)
    other = write_spec(
        spec_path.parent / "changed" / spec_path.name,
        SPEC.replace("eval_episodes = 1", "eval_episodes = 2"),
    )
    with pytest.raises(SystemExit):
        cli.main(["run", str(other), "--study-dir", str(study_dir), "--resume"])
    err = capsys.readouterr().err
    assert "would be trained otherwise under the changed spec (eval_episodes: 1 when it ran" in err
    with pytest.raises(SystemExit):
        cli.main(["run", str(spec_path), "--study-dir", str(study_dir)])
    assert "already holds a study; continue it with --resume" in capsys.readouterr().err


def test_a_spec_fixed_after_a_failure_resumes_keeping_the_finished_runs(study, tmp_path):
    _, study_dir, _ = study
    shutil.copytree(study_dir, tmp_path / "s", ignore=shutil.ignore_patterns("tune"))
    restamp(tmp_path / "s" / "study.json")
    options = StudyOptions(study_dir=tmp_path / "s", resume=True)
    # a held-out seed added: every finished run stays as it ran
    (tmp_path / "fixed").mkdir()
    fixed = write_spec(
        tmp_path / "fixed" / "tiny.toml", SPEC.replace('seeds = "1-2"', 'seeds = "1-3"')
    )
    record = open_study(spec_from(str(fixed)), str(fixed), options)
    assert record["spec"] == spec_from(str(fixed)).to_json()
    assert record["spec_text"] == fixed.read_text()
    assert record["parts"][-1]["spec_changed"]["keys"] == ["evaluation"]
    # a grid value added once the evaluation ran would select again
    regrid = write_spec(tmp_path / "regrid.toml", SPEC.replace("[1, 3]", "[1, 3, 5]"))
    with pytest.raises(SetupError, match=r"the evaluation of (sac|simoun) has started"):
        open_study(spec_from(str(regrid)), str(regrid), options)


@pytest.mark.parametrize(
    ("task", "said"),
    [("CartPole-v1", "Discrete(2)"), ("minigrid:MiniGrid-Empty-5x5-v0", "Discrete(7)")],
)
def test_plan_refuses_a_discrete_action_task_naming_the_spec_line(task, said, tmp_path, capsys):
    evaluated = 'tasks = ["simoun/PointReach-v0"]\nseeds = "1-2"'
    text = SPEC.replace(evaluated, evaluated.replace("simoun/PointReach-v0", task))
    path = write_spec(tmp_path / "discrete.toml", text)
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["plan", str(path), "--probe-updates", "0"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    line = key_line(text, ("evaluation", "tasks"))
    assert f"{path}:{line}: [evaluation] tasks: " in err and said in err, err
    assert "Replace it in [evaluation] tasks" in err and "Traceback" not in err


def test_plan_lists_every_run_and_a_measured_estimate(tmp_path, capsys):
    spec = write_spec(tmp_path / "tiny.toml")
    assert cli.main(["plan", str(spec), "--probe-updates", "2"]) == 0
    out = capsys.readouterr().out
    rows = [
        line.split() for line in out.splitlines() if line.startswith(("tuning ", "evaluation "))
    ]
    assert len(rows) == 12
    assert rows[0][:6] == [
        "tuning",
        "simoun-PointReach-v0",
        "simoun",
        "agent.n_step=1",
        "101",
        "80",
    ]
    assert rows[-1][:6] == ["evaluation", "simoun-PointReach-v0", "sac", "(selected)", "2", "80"]
    assert all(row[-1] == "s" and float(row[-2]) >= 0 for row in rows)  # "N s" estimates
    assert "runs: 8 tuning + 4 evaluation = 12" in out
    assert "estimated CPU time: tuning" in out and "with 2 runs at a time" in out
    assert (
        "for each of 4 configurations (recipe x task x setting x budget), 20 actions and 2 " in out
    )


def test_plan_without_a_probe_lists_the_runs_only(tmp_path, capsys):
    spec = write_spec(tmp_path / "tiny.toml")
    assert cli.main(["plan", str(spec), "--probe-updates", "0"]) == 0
    out = capsys.readouterr().out
    assert "runs: 8 tuning + 4 evaluation = 12" in out and "estimated" not in out
    assert "note:" not in out


def test_plan_notes_runs_that_evaluate_less_often_than_their_budget(tmp_path, capsys):
    text = SPEC.replace("eval_every = 40", "eval_every = 100").replace(
        "env_steps = 80\n\n[resources]", "env_steps = 120\n\n[resources]"
    )
    spec = write_spec(tmp_path / "tiny.toml", text)
    assert cli.main(["plan", str(spec), "--probe-updates", "0"]) == 0
    out = capsys.readouterr().out
    assert (
        "note: the tuning runs on simoun-PointReach-v0 evaluate every 100 env steps (eval_every "
        "in [base]), more than their 80: each is evaluated only at step 0 and at the end; the "
        "auc selection rule reads those two points; for a learning curve, give an eval_every "
        "below 80"
    ) in out
    assert "the evaluation runs" not in out  # 120 env steps: evaluated at 100 too


MAX = "max_concurrent_trials = 2\n"
"""The spec's last line, after which a bad spec adds an optional table."""

BAD_SPECS = [
    ('recipes = ["simoun", "sac"]', 'recipe = ["simoun", "sac"]',
     "unknown key 'recipe' (did you mean 'recipes'"),
    ('recipes = ["simoun", "sac"]', 'recipes = ["simon", "sac"]',
     "unknown recipe 'simon' (did you mean 'simoun'?)"),
    ('recipes = ["simoun", "sac"]', 'recipes = ["sac", "sac"]', "'sac' is listed twice"),
    ('description = "a tiny study for tests"', 'selection = "best"',
     "unknown selection rule 'best'; choose one of auc, final"),
    ('description = "a tiny study for tests"', 'selection = ["auc"]',
     'selection: give one rule name (auc or final), not an array (["auc"]); e.g. selection = '
     '"auc"'),
    ('recipes = ["simoun", "sac"]', 'recipes = [["simoun"], "sac"]',
     'recipes: give an array of recipe names (strings), not an array holding an array '
     '(["simoun"]); e.g. recipes = ["simoun", "drq"]'),
    ("eval_episodes = 1", 'eval_episodes = 1\npreset = ["cpu"]',
     'highway-cpu), not an array (["cpu"]); e.g. preset = "cpu"'),
    ("seeds = [101, 102]", 'seeds = [101, "102"]',
     '[tuning] seeds: give seeds as an array of whole numbers or a range string ("1-5"), or a '
     'table with one per task, not an array holding a string ("102")'),
    ('seeds = "1-2"', 'seeds = { "simoun/PointReach-v0" = 2 }',
     '[evaluation] seeds.simoun/PointReach-v0: give seeds as an array of whole numbers or a '
     'range string ("1-5"), not an integer (2)'),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 2.0",
     "[resources] max_concurrent_trials: give a whole number, not a float (2.0); e.g. "
     "max_concurrent_trials = 2"),
    ("max_concurrent_trials = 2", MAX + '[diagnostics]\nsimoun = [{ recipe = "simoun_no_aux" }]',
     '[diagnostics] simoun: give an array of recipe names (strings), not an array holding a '
     'table ({"recipe": "simoun_no_aux"})'),
    ("max_concurrent_trials = 2", MAX + '[generalization]\nmodes = ["color_easy"]\nepisodes = "5"',
     '[generalization] episodes: give a whole number, not a string ("5"); e.g. episodes = 10'),
    ("agent.n_step = [1, 3]", "agent.n_stepp = [1, 3]",
     "unknown config key 'agent.n_stepp' (did you mean agent.n_step?)"),
    ("agent.n_step = [1, 3]", "agent.n_step = 3",
     "give a non-empty list of values, e.g. agent.n_step = [3, ...]"),
    ("agent.n_step = [1, 3]", "agent.n_step = []",
     "give a non-empty list of values, e.g. agent.n_step = [1, ...]"),
    ("agent.n_step = [1, 3]", 'agent.n_step = "three"',
     "give a non-empty list of values, e.g. agent.n_step = [1, ...]"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 1]", "a value is listed twice"),
    ("agent.n_step = [1, 3]", 'agent.n_step = [1, 3]\npreset = ["cpu", "highway-cpu"]',
     "[grid] preset: the grid cannot vary the preset: the config key preset only labels a run"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 0]", "agent.n_step = 0"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3.5]", "cannot read agent.n_step='3.5'"),
    ("agent.n_step = [1, 3]", '# no grid values', "the grid is empty"),
    ("agent.n_step = [1, 3]", 'agent.augmentation = ["none", "shift"]',
     "recipe 'sac' fixes agent.augmentation = none, and the grid would override it, so 'sac' "
     'would no longer be itself; drop agent.augmentation from [grid], or, to tune it for every '
     'recipe alike, list it in grid_overrides = ["agent.augmentation"]'),
    ('recipes = ["simoun", "sac"]', 'recipes = ["simoun", "sac"]\ngrid_overrides = ["agent.lr"]',
     "'agent.lr' is no key of [grid]"),
    ('recipes = ["simoun", "sac"]',
     'recipes = ["simoun", "sac"]\ngrid_overrides = ["agent.n_stp"]',
     "grid_overrides: unknown config key 'agent.n_stp' (did you mean agent.n_step?)"),
    ("agent.n_step = [1, 3]", 'agent.recipe = ["drq"]', "the study sets agent.recipe itself"),
    ("eval_episodes = 1", "eval_episodes = 1\nagent.encoder = \"single\"",
     "recipe 'simoun' fixes agent.encoder = dual_interactive, and [base] would override it"),
    ("eval_episodes = 1", 'eval_episodes = "many"', "cannot read eval_episodes='many'"),
    ("eval_episodes = 1", "eval_episodes = 1\nseed = 3", "the study sets seed itself"),
    ("eval_episodes = 1", "eval_episodes = 1\nagent.n_step = 3",
     "agent.n_step is in [base] too (line 10)", "agent.n_step = [1, 3]"),
    ("eval_episodes = 1", "eval_episodes = 1\npreset = \"cpuu\"",
     "unknown preset 'cpuu' (did you mean 'cpu'?)"),
    ('tasks = ["simoun/PointReach-v0"]\nseeds = [101, 102]',
     'tasks = ["simoun/PointReech-v0"]\nseeds = [101, 102]',
     # the closest id first; other test envs registered in the same worker may follow it
     "unknown environment id 'simoun/PointReech-v0'; did you mean simoun/PointReach-v0",
     'tasks = ["simoun/PointReech-v0"]'),
    ("seeds = [101, 102]", "seeds = [101, 101]", "seed 101 is listed twice"),
    ("seeds = [101, 102]", 'seeds = "102-101"', "runs backwards"),
    ('seeds = "1-2"', 'seeds = "1-2,101"',
     "seed 101 of simoun/PointReach-v0 is a tuning seed too; evaluation seeds must be held out"),
    ('seeds = "1-2"', 'seeds = { "CartPole-v1" = [1] }',
     "'CartPole-v1' is not one of this phase's tasks"),
    ("env_steps = 80\n\n[evaluation]", "env_steps = 0\n\n[evaluation]",
     "give a positive integer of env steps, not 0", "env_steps = 0"),
    ("env_steps = 80\n\n[evaluation]", "env_steps = 80\nbudget = 5\n\n[evaluation]",
     "unknown key 'budget'", "budget = 5"),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 2\ncpus_per_trial = 0",
     "give a positive integer, not 0"),
    ("[resources]", '[tasks."CartPole-v1"]\naction_repeat = 2\n\n[resources]',
     "'CartPole-v1' is no task of [tuning] or [evaluation]", '[tasks."CartPole-v1"]'),
    ("[resources]", '[tasks."simoun/PointReach-v0"]\naction_repeatt = 2\n\n[resources]',
     "unknown config key 'action_repeatt' (did you mean action_repeat?)", "action_repeatt = 2"),
    ("[resources]", '[tasks."simoun/PointReach-v0"]\nagent.n_step = 3\n\n[resources]',
     "[tasks.\"simoun/PointReach-v0\"] agent.n_step: agent.n_step is set in [grid] too (line 20), "
     "and the grid's values override [tasks.\"simoun/PointReach-v0\"]'s in every run of the task; "
     "set it in one place only: in [grid] to tune it on every task, or in each task's table (and "
     "drop it from [grid])", "agent.n_step = 3"),
    ("[resources]", '[tasks."simoun/PointReach-v0"]\neval_episodes = 2\n\n[resources]',
     "eval_episodes is set in [base] too (line 9), and [base]'s value is then used for no run of "
     "this task; set it in one place only", "eval_episodes = 2"),
    ("[resources]", '[tasks."simoun/PointReach-v0"]\nenv_steps = 40\n\n[resources]',
     "unknown config key 'env_steps' (the study sets total_env_steps itself: give it as "
     "env_steps in [tuning] and [evaluation])", "env_steps = 40"),
    ("max_concurrent_trials = 2", MAX + '[diagnostics]\nsimoun = ["simoun_no_auxx"]',
     "unknown recipe 'simoun_no_auxx' (did you mean 'simoun_no_aux'?)"),
    ("max_concurrent_trials = 2", MAX + '[diagnostics]\ndrq = ["simoun_no_aux"]',
     "'drq' is not one of the study's recipes (simoun, sac)"),
    ("max_concurrent_trials = 2", MAX + '[diagnostics]\nsimoun = ["sac"]',
     "'sac' is one of the study's recipes, tuned and compared on its own"),
    ("max_concurrent_trials = 2", MAX + '[diagnostics]\nsac = ["simoun_no_aux"]',
     "'simoun_no_aux' is an ablation of 'simoun', not of 'sac'; list it under simoun = "),
    ("max_concurrent_trials = 2", MAX + '[diagnostics]\nsimoun = ["drq"]',
     "'drq' is no ablation (a method of its own)"),
    ("max_concurrent_trials = 2", MAX + '[generalization]\nmodes = ["color_easy", "color_easy"]',
     "'color_easy' is listed twice; list each mode once"),
    ("max_concurrent_trials = 2", MAX + '[generalization]\nmodes = ["colour_easy"]',
     "unknown distraction 'colour_easy' in modes; did you mean 'color_easy'?"),
    ("max_concurrent_trials = 2", MAX + '[generalization]\nmodes = ["train"]',
     "the train mode is always played"),
    ("max_concurrent_trials = 2", MAX + '[generalization]\nmodes = ["color_easy"]',
     "the evaluation task simoun/PointReach-v0 is no dm_control task"),
]  # fmt: skip
"""(text of the good spec, its replacement, what the error says[, the text of the line it
names]): by default the error names the line where the replacement ends."""


@pytest.mark.parametrize("case", BAD_SPECS, ids=[case[2][:40] for case in BAD_SPECS])
def test_a_bad_spec_fails_naming_its_line_and_the_fix(case, tmp_path):
    old, new, message, at = (*case, None)[:4]
    assert old in SPEC
    text = SPEC.replace(old, new, 1)
    path = write_spec(tmp_path / "bad.toml", text)
    with pytest.raises(SetupError) as error:
        spec_from(str(path))
    line = text[: text.index(at or new) + len(at or new)].count("\n") + 1
    if new.startswith("#"):  # nothing left in [grid]: its header's line
        line = text.splitlines().index("[grid]") + 1
    assert f"{path}:{line}: " in str(error.value)
    assert message in str(error.value)


def test_grid_overrides_lets_the_grid_tune_a_key_a_recipe_fixes(tmp_path):
    text = SPEC.replace(
        'recipes = ["simoun", "sac"]',
        'recipes = ["simoun", "sac"]\ngrid_overrides = ["agent.augmentation"]',
    )
    text = text.replace("agent.n_step = [1, 3]", 'agent.augmentation = ["none", "shift"]')
    spec = spec_from(str(write_spec(tmp_path / "tuned.toml", text)))
    assert spec.grid == {"agent.augmentation": ["none", "shift"]}
    runs = tuning_runs(spec)
    assert "tuning/sac/agent.augmentation=shift/simoun-PointReach-v0/s101" in [r.name for r in runs]
    without = SPEC.replace("agent.n_step = [1, 3]", 'agent.augmentation = ["shift"]')
    overriding = without.replace(
        'recipes = ["simoun", "sac"]',
        'recipes = ["simoun", "sac"]\ngrid_overrides = ["agent.augmentation"]',
    )
    path = write_spec(tmp_path / "unoffered.toml", overriding)
    with pytest.raises(SetupError, match="which the grid does not offer; add none to its values"):
        spec_from(str(path))


def test_bad_toml_and_missing_parts_fail_before_ray_starts(tmp_path, capsys):
    path = write_spec(tmp_path / "broken.toml", SPEC.replace("[grid]", "[grid"))
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["run", str(path), "--study-dir", str(tmp_path / "s")])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("simoun-study: error: ") and "Traceback" not in err
    assert f"{path}: not valid TOML" in err and "(at line 19, column 6)" in err
    assert not (tmp_path / "s").exists()
    path = write_spec(tmp_path / "half.toml", SPEC[: SPEC.index("[evaluation]")])
    with pytest.raises(SetupError, match="no 'evaluation'; a study needs recipes, grid"):
        spec_from(str(path))


def test_key_lines_follow_tables_dotted_keys_and_inline_tables():
    text = (
        'a = """\nb = 1\n"""\n[grid.agent]\nn_step = [1, 3]\n[evaluation]\n'
        'seeds = { "dm_control/x-v0" = [1] }\n'
    )
    assert key_line(text, ("b",)) is None  # inside a multi-line string
    assert key_line(text, ("grid", "agent", "n_step")) == 5
    assert key_line(text, ("evaluation", "seeds", "dm_control/x-v0")) == 7
    assert key_line(text, ("grid",)) == 4


def test_help_runs_for_the_command_and_each_subcommand(capsys):
    for argv in (["--help"], ["plan", "--help"], ["run", "--help"], ["report", "--help"]):
        with pytest.raises(SystemExit) as exit_info:
            cli.main(argv)
        assert exit_info.value.code == 0
    out = capsys.readouterr().out
    assert "simoun-study plan docs/studies/dmc100k.toml" in out
    assert "simoun-study report docs/studies/dmc100k.toml --study-dir docs/studies/dmc100k" in out
    assert "--probe-updates N" in out and "--allow-other-commit" in out and "--archive DIR" in out


def test_the_dmc100k_spec_plans_its_runs():
    spec = spec_from("docs/studies/dmc100k.toml")
    assert spec.recipes == ["simoun", "drq", "drqv2", "rad", "curl"]
    assert spec.preset == "cpu" and spec.grid == {"agent.n_step": [1, 3]}
    assert spec.base == {"eval_every": 10_000, "eval_episodes": 10, "video": False}
    tuning, evaluation = tuning_runs(spec), evaluation_runs(spec)
    assert len(tuning) == 5 * 2 * 2 and {r.seed for r in tuning} == {101, 102}
    assert {r.task for r in tuning} == {"dm_control/cartpole-swingup-v0"}
    assert {r.env_steps for r in tuning} == {50_000} and {r.env_steps for r in evaluation} == {
        100_000
    }
    cheetah = [r for r in evaluation if r.task == "dm_control/cheetah-run-v0"]
    assert len(evaluation) == 5 * (5 + 3) and {r.seed for r in cheetah} == {1, 2, 3}
    assert spec.task_config == {
        "dm_control/cartpole-swingup-v0": {"action_repeat": 8},
        "dm_control/cheetah-run-v0": {"action_repeat": 4},
    }
    assert spec.cpus_per_trial == 1 and spec.max_concurrent_trials == 2


def test_the_drqv2_easy_supplement_runs_the_dmc100k_protocol_on_its_cartpole_runs():
    study = spec_from("docs/studies/dmc100k.toml")
    supplement = spec_from("docs/studies/dmc100k-drqv2-easy.toml")
    assert supplement.recipes == ["drqv2_easy"]
    for key in ("selection", "preset", "base", "grid", "grid_overrides", "tuning"):
        assert getattr(supplement, key) == getattr(study, key), key
    cartpole = "dm_control/cartpole-swingup-v0"
    assert supplement.task_config == {cartpole: study.task_config[cartpole]}
    runs = {(r.task, r.seed, r.env_steps) for r in evaluation_runs(supplement)}
    assert runs == {(r.task, r.seed, r.env_steps) for r in evaluation_runs(study)} & {
        (cartpole, seed, 100_000) for seed in range(1, 6)
    }
    assert len(runs) == 5


def test_without_ray_a_study_plans_and_says_how_to_install_ray_to_run(
    monkeypatch, tmp_path, capsys
):
    monkeypatch.setitem(sys.modules, "ray", None)  # what `import ray` meets when not installed
    spec = write_spec(tmp_path / "tiny.toml")
    assert cli.main(["plan", str(spec), "--probe-updates", "0"]) == 0
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["run", str(spec), "--study-dir", str(tmp_path / "s")])
    assert exit_info.value.code == 2
    assert "pip install 'simoun[lab]'" in capsys.readouterr().err
    assert not (tmp_path / "s").exists()


DMC_SPEC = (
    """\
description = "a tiny study with diagnostics and generalization"
recipes = ["simoun", "sac"]

[base]
env_kwargs = { task_kwargs = { time_limit = 1 } }
image_size = 32
warmup_agent_steps = 10
replay_capacity = 1000
eval_every = 1000
eval_episodes = 1
checkpoint_every = 1000
"""
    + SMALL_AGENT
    + """
[grid]
agent.n_step = [1]

[tuning]
tasks = ["dm_control/cartpole-swingup-v0"]
seeds = [101]
env_steps = 60

[evaluation]
tasks = ["dm_control/cartpole-swingup-v0"]
seeds = [1]
env_steps = 60

[diagnostics]
simoun = ["simoun_no_aux"]

[generalization]
modes = ["color_easy", "video_hard"]
episodes = 1

[resources]
max_concurrent_trials = 2
"""
)
"""A 1 s cartpole-swingup episode (13 decisions at its action repeat of 8, a reward above 0 at
every step): one tuning and one evaluation seed, simoun's aux-loss ablation as a diagnostic and
two distraction modes."""


@pytest.fixture(scope="module")
def dmc_study(ray_address, tmp_path_factory):
    """The tiny DMC study, run once with an archive: (spec, study dir, archive)."""
    root = tmp_path_factory.mktemp("dmc_study")
    spec = write_spec(root / "dmc.toml", DMC_SPEC)
    argv = ["run", str(spec), "--study-dir", str(root / "s"), "--archive", str(root / "a")]
    assert cli.main([*argv, "--verbose", "0"]) == 0
    return spec, root / "s", root / "a"


def test_a_diagnostic_runs_at_its_methods_selected_setting_and_is_reported_apart(dmc_study):
    _, study_dir, archive = dmc_study
    ablation = study_dir / "evaluation/simoun_no_aux/cartpole-swingup/s1"
    config = json.loads((ablation / "config.json").read_text())
    assert config["agent"]["recipe"] == "simoun_no_aux" and config["agent"]["n_step"] == 1
    assert (archive / "evaluation/simoun_no_aux/cartpole-swingup/s1/summary.json").is_file()
    report = (study_dir / "report/report.md").read_text()
    assert "## Diagnostics of simoun: what each part adds" in report
    assert "P(simoun > ablation) [95 % CI]" in report
    results = report[report.index("## Results") : report.index("## Diagnostics")]
    assert "simoun_no_aux" not in results  # not among the compared recipes' tables
    # one run each on one task: the interval of a difference collapses onto it
    scores = {
        name: json.loads((study_dir / f"evaluation/{name}/cartpole-swingup/s1/summary.json")
                         .read_text())["final_eval"]["return_mean"] / 1000
        for name in ("simoun", "simoun_no_aux")
    }  # fmt: skip
    difference = scores["simoun"] - scores["simoun_no_aux"]
    p = 1.0 if difference > 0 else 0.0 if difference < 0 else 0.5
    row = next(line for line in report.splitlines() if line.startswith("| simoun_no_aux |"))
    cells = [cell.strip() for cell in row.split("|")[1:-1]]
    no_aux = f"{scores['simoun_no_aux']:.3f}"
    assert cells[2:] == [
        "1",
        f"{no_aux} [{no_aux}, {no_aux}]",
        f"{difference:.3f} [{difference:.3f}, {difference:.3f}]",
        f"{p:.3f} [{p:.3f}, {p:.3f}]",
    ]


def test_generalization_plays_each_final_agent_on_the_train_mode_and_each_distraction(dmc_study):
    _, study_dir, archive = dmc_study
    report = (study_dir / "report/report.md").read_text()
    ratios = {}
    for recipe in ("simoun", "sac", "simoun_no_aux"):
        name = f"evaluation/{recipe}/cartpole-swingup/s1"
        with (study_dir / name / "generalization.csv").open(newline="") as f:
            rows = list(csv.DictReader(f))
        assert [row["mode"] for row in rows] == ["train", "color_easy", "video_hard"]
        summary = json.loads((study_dir / name / "summary.json").read_text())
        assert {row["episodes"] for row in rows} == {"1"}
        assert {row["env_step"] for row in rows} == {str(summary["env_step"])}  # the final agent
        # the train mode is the run's own final evaluation: same agent, seeds and episodes
        assert float(rows[0]["return_mean"]) == pytest.approx(summary["final_eval"]["return_mean"])
        assert (archive / name / "generalization.csv").read_bytes() == (
            study_dir / name / "generalization.csv"
        ).read_bytes()
        train = float(rows[0]["return_mean"])
        assert train > 0
        ratios[recipe] = [float(row["return_mean"]) / train for row in rows[1:]]
    section = report[report.index("## Generalization under distraction") :]
    for recipe, values in ratios.items():
        row = next(line for line in section.splitlines() if line.startswith(f"| {recipe} | 1 |"))
        # one run: each interval is the run's own ratio
        assert row.endswith(" | ".join(f"{v:.3f} [{v:.3f}, {v:.3f}]" for v in values) + " |")
    p = 1.0 if ratios["simoun"][1] > ratios["sac"][1] else 0.0  # P(simoun > sac), video_hard
    if ratios["simoun"][1] == ratios["sac"][1]:
        p = 0.5
    against = section[section.index("P(simoun > Y) of that ratio") :]
    row = next(line for line in against.splitlines() if line.startswith("| sac |"))
    assert row.endswith(f"| {p:.3f} [{p:.3f}, {p:.3f}] |")
    assert "No `update_cost.json` in the study directory" in report


def test_update_cost_ratios_place_each_run_on_the_baselines_clock(dmc_study, tmp_path):
    spec_path, _, archive = dmc_study
    copy = tmp_path / "archive"
    shutil.copytree(archive, copy)
    costs = {
        "baseline": "sac",
        "ratio": {"sac": 1.0, "simoun": 1.5},
        "ms_per_update": {"sac": 2.0, "simoun": 3.0},
        "task": "dm_control/cartpole-swingup-v0",
        "action_repeat": 4,
        "command": "python benchmarks/recipe_update.py --json update_cost.json",
        "commit": "0" * 40,
        "machine": "a test machine",
    }
    (copy / "update_cost.json").write_text(json.dumps(costs))
    assert cli.main(["report", str(spec_path), "--study-dir", str(copy)]) == 0
    report = (copy / "report/report.md").read_text()
    assert "`python benchmarks/recipe_update.py --json update_cost.json` at commit" in report
    assert "| simoun | 3.0 | 1.50 |" in report and "| sac | 2.0 | 1.00 |" in report
    assert "Not drawn (no ratio in the file): simoun_no_aux." in report
    assert (copy / "report/iqm_wall_time_update_cost.png").stat().st_size > 1000
    spec = load_spec(spec_path)
    chosen = {"simoun": {"agent.n_step": 1}, "sac": {"agent.n_step": 1}}
    results = [read_result(copy, run) for run in evaluation_runs(spec, chosen)]
    placed, left_out = cost_curves(results, costs)
    assert left_out == {"no ratio in the file": ["simoun_no_aux"]}
    by_recipe = {r.run.recipe: r.curve for r in placed}
    np.testing.assert_allclose(by_recipe["sac"]["cost_time_s"], by_recipe["sac"]["wall_time_s"])
    np.testing.assert_allclose(  # one sac run: its clock is its own wall time
        by_recipe["simoun"]["cost_time_s"], 1.5 * by_recipe["sac"]["wall_time_s"]
    )


def test_the_dmc100k_v2_spec_reruns_the_protocol_on_five_seeds_per_task_with_diagnostics():
    first = spec_from("docs/studies/dmc100k.toml")
    spec = spec_from("docs/studies/dmc100k-v2.toml")
    for key in ("recipes", "selection", "preset", "base", "grid", "grid_overrides", "tuning"):
        assert getattr(spec, key) == getattr(first, key), key
    assert spec.task_config == first.task_config
    assert spec.evaluation.seeds == {task: [1, 2, 3, 4, 5] for task in spec.evaluation.tasks}
    assert spec.evaluation.tasks == ["dm_control/cartpole-swingup-v0", "dm_control/cheetah-run-v0"]
    assert spec.diagnostics == {
        "simoun": ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]
    }
    assert spec.generalization == ["color_easy", "color_hard", "video_easy", "video_hard"]
    assert spec.generalization_episodes == 10
    runs = evaluation_runs(spec, {recipe: {"agent.n_step": 3} for recipe in spec.recipes})
    assert len(tuning_runs(spec)) == 20 and len(runs) == (5 + 3) * 2 * 5
    ablations = [run for run in runs if run.of is not None]
    assert {run.of for run in ablations} == {"simoun"} and len(ablations) == 30
    assert all(run.setting == {"agent.n_step": 3} for run in ablations)


def test_a_study_record_saved_before_diagnostics_existed_reads_as_its_spec():
    record = json.loads(Path("docs/studies/dmc100k/study.json").read_text())
    assert "diagnostics" not in record["spec"]
    spec = spec_from("docs/studies/dmc100k.toml")
    check_same_spec(record, spec, "not the same", "fix it")  # raises when they differ
    with pytest.raises(SetupError, match="diagnostics differ"):
        check_same_spec(record, replace(spec, diagnostics={"simoun": ["simoun_no_aux"]}), "", "")


def test_a_task_given_as_module_id_reaches_every_run_with_its_module(tmp_path):
    from broken_envs import NAN_REACH_ID

    from simoun_agent.config import resolve

    task = f"broken_envs:{NAN_REACH_ID}"
    spec = load_spec(write_spec(tmp_path / "spec.toml", SPEC.replace("simoun/PointReach-v0", task)))
    runs = tuning_runs(spec) + evaluation_runs(spec, {r: {"agent.n_step": 1} for r in spec.recipes})
    for run in runs:
        # the trial's process resolves these overrides: the module must be among them
        trial = run.trial(spec, tmp_path)
        config = resolve(trial.preset, trial.overrides)
        assert (config.env, config.env_module) == (NAN_REACH_ID, "broken_envs")
        assert "/simoun-test-NanReach-v0/" in trial.run_dir


DMC = Path("docs/studies/dmc100k")
DMC_TUNING_RUN = "tuning/simoun/agent.n_step=1/cartpole-swingup/s101"
DMC_EVALUATION_RUN = "evaluation/simoun/cartpole-swingup/s1"


@pytest.fixture
def dmc_archive(tmp_path: Path) -> Path:
    """A copy of the committed dmc100k study archive."""
    return Path(shutil.copytree(DMC, tmp_path / "dmc100k"))


def report_refused(archive: Path, capsys, spec: str = "docs/studies/dmc100k.toml") -> str:
    """What ``simoun-study report`` says refusing ``archive``: status 2, no traceback."""
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["report", spec, "--study-dir", str(archive)])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and "Traceback" not in err
    return err


def edit_json(path: Path, edit) -> None:
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))


@pytest.mark.parametrize(
    ("run", "damage", "said"),
    [
        (DMC_EVALUATION_RUN, lambda p: p.unlink(), "config.json is missing, but the run finished"),
        (DMC_EVALUATION_RUN, lambda p: p.write_text("{"), "config.json is damaged: it is not JSON"),
        (
            DMC_TUNING_RUN,
            lambda p: edit_json(p, lambda d: d["agent"].update(recipe="drq")),
            "config.json records another run than this one: agent.recipe is drq where the "
            "spec gives simoun",
        ),
        (
            DMC_EVALUATION_RUN,
            lambda p: edit_json(p, lambda d: d.update(seed=7)),
            "config.json records another run than this one: seed is 7 where the spec gives 1",
        ),
    ],
)
def test_a_finished_run_whose_config_is_damaged_or_another_runs_is_named_by_the_report(
    run, damage, said, dmc_archive, capsys
):
    damage(dmc_archive / run / "config.json")
    err = report_refused(dmc_archive, capsys)
    assert f"the finished run {dmc_archive / run}: {said}" in err
    assert f"mv {dmc_archive / run} {dmc_archive / run}.damaged" in err


@pytest.mark.parametrize(
    ("run", "text", "said"),
    [
        (DMC_TUNING_RUN, "", "it is empty"),
        (DMC_TUNING_RUN, '{"env_step": 100000, "final_', "it is not JSON"),
        (DMC_EVALUATION_RUN, "garbage", "it is not JSON"),
        (DMC_EVALUATION_RUN, "[]", "it holds an array, not a JSON object"),
    ],
)
def test_a_finished_runs_unreadable_summary_is_named_on_resume_before_it_counts(
    run, text, said, dmc_archive, tmp_path, capsys
):
    path = dmc_archive / run / "summary.json"
    path.write_text(text)
    argv = ["run", "docs/studies/dmc100k.toml", "--study-dir", str(tmp_path / "s")]
    with pytest.raises(SystemExit) as exit_info:
        cli.main([*argv, "--archive", str(dmc_archive), "--resume", "--allow-other-commit"])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and "Traceback" not in err
    assert f"{path} (the mark that run {run} finished) is damaged: {said}" in err
    assert f"mv {dmc_archive / run} {dmc_archive / run}.damaged" in err
    assert not (tmp_path / "s" / run).exists()  # nothing restored from the archive


def test_a_report_figure_that_does_not_fit_is_named_with_the_fix_and_left_unwritten(dmc_archive):
    argv = ["report", "docs/studies/dmc100k.toml", "--study-dir", str(dmc_archive)]
    done = under_file_size_limit("simoun_lab.cli.study", argv)
    fix = "copy the study directory to another disk and pass the copy as --study-dir"
    path = named_unwritten_file(done, "simoun-study", fix)
    committed = DMC / path.relative_to(dmc_archive)  # the report the archive held is kept
    assert path.suffix == ".png" and path.read_bytes() == committed.read_bytes()


@pytest.mark.parametrize(
    ("renamed", "kind", "meant"),
    [
        ("evaluation/Simoun", "recipe", "simoun"),
        ("tuning/simoun/agent.n_step=1/Cartpole-Swingup", "task", "cartpole-swingup"),
        ("Evaluation", "phase", "evaluation"),
    ],
)
def test_a_folder_of_runs_in_other_capitals_is_named_not_counted_as_unfinished(
    renamed, kind, meant, dmc_archive, capsys
):
    stray = dmc_archive / renamed
    (stray.parent / meant).rename(stray)
    report = (dmc_archive / "report" / "report.md").read_bytes()
    err = report_refused(dmc_archive, capsys)
    assert f"{stray} is not a {kind} of the spec: did you mean {meant}?" in err
    assert f"rename it (mv {stray} {stray.parent / meant})" in err
    assert (dmc_archive / "report" / "report.md").read_bytes() == report


def test_a_second_copy_of_a_recipes_runs_in_other_capitals_is_named_not_counted_twice(
    dmc_archive, capsys
):
    stray = dmc_archive / "evaluation" / "Simoun"
    shutil.copytree(dmc_archive / "evaluation" / "simoun", stray)
    err = report_refused(dmc_archive, capsys)
    assert f"{stray} is a second copy, which the phase report would count twice" in err
    assert f"(mv {stray} {dmc_archive.parent / 'dmc100k-evaluation-Simoun'})" in err


def test_the_code_version_reads_the_checkout_without_writing_its_index(tmp_path):
    def git(*args: str) -> None:
        subprocess.run(["git", "-C", str(tmp_path), *args], check=True, capture_output=True)

    git("init", "-q")
    (tmp_path / "a.txt").write_text("a\n")
    git("add", "a.txt")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-q", "-m", "a")
    os.utime(tmp_path / "a.txt", (1, 1))  # stat data changed: a plain git status rewrites the index
    index = tmp_path / ".git" / "index"
    before = (index.read_bytes(), index.stat().st_mtime_ns)
    assert code_version(tmp_path)["dirty"] is False
    assert (index.read_bytes(), index.stat().st_mtime_ns) == before


def test_a_report_directory_that_is_a_file_is_named(dmc_archive, capsys):
    shutil.rmtree(dmc_archive / "report")
    (dmc_archive / "report").write_text("notes\n")
    err = report_refused(dmc_archive, capsys)
    assert f"{dmc_archive / 'report'} is where the report is written, but it is a file" in err
    assert f"mv {dmc_archive / 'report'} {dmc_archive / 'report'}.old" in err


@pytest.mark.parametrize(
    ("edit", "said"),
    [
        (lambda d: d["parts"][0].pop("commit"), "its part 1 has no commit, which every part"),
        (lambda d: d["spec"].pop("tuning"), "its spec has no tuning"),
        (lambda d: d["spec"].update(budget=3), "its spec has an unknown key 'budget'"),
        (lambda d: d["spec"].update(evaluation=[]), "its spec's evaluation is not a phase"),
    ],
)
def test_a_study_record_with_a_part_or_spec_key_missing_is_named(edit, said, dmc_archive, capsys):
    edit_json(dmc_archive / "study.json", edit)
    err = report_refused(dmc_archive, capsys)
    assert f"{dmc_archive / 'study.json'} is damaged: {said}" in err


def test_a_study_record_saved_before_specs_named_a_selection_rule_reads_as_auc():
    record = json.loads((DMC / "study.json").read_text())
    del record["spec"]["selection"]
    spec = spec_from("docs/studies/dmc100k.toml")
    assert spec.selection == "auc"
    check_same_spec(record, spec, "not the same", "fix it")  # raises when they differ


def test_a_minigrid_archive_given_a_sac_spec_is_told_its_kind(tmp_path, capsys):
    archive = Path(shutil.copytree("docs/studies/minigrid-v2/tuning", tmp_path / "mgt"))
    err = report_refused(archive, capsys)
    assert f"{archive} holds runs of a MiniGrid PPO study ({archive / 'spec.json'})" in err


DOCS = Path(__file__).resolve().parents[1] / "docs" / "studies"
"""The committed studies: their specs and archives."""


@pytest.mark.parametrize("name", ["study.json", "record.toml"])
def test_plan_names_a_study_record_given_as_its_spec(name, tmp_path, capsys):
    record = shutil.copy(DOCS / "dmc100k" / "study.json", tmp_path / name)
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["plan", str(record)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"{record} is a study's record (the study.json that simoun-study run keeps" in err
    assert "not a study spec; pass the spec file the study was run from, " in err
    assert "docs/studies/dmc100k.toml" in err and "unknown key" not in err


@pytest.mark.parametrize(
    ("base", "key", "said"),
    [
        (
            "env_kwargs = { nope = 1 }",
            "env_kwargs",
            "simoun/PointReach-v0 cannot be trained with it: env_kwargs: simoun/PointReach-v0 "
            "takes no keyword 'nope'; it accepts: max_steps, size, step_size",
        ),
        (
            'env_module = "nosuchmodule"',
            "env_module",
            "env_module 'nosuchmodule' is not installed, so the ids it registers are unknown; pip "
            "install nosuchmodule (or the package that provides nosuchmodule), or drop env_module",
        ),
        (
            "action_repeat = 15",
            "action_repeat",
            "action_repeat 15 (TrainConfig.action_repeat): an episode of simoun/PointReach-v0 "
            "ends after 20 env steps",
        ),
        (
            'eval_distraction = ["color_easy"]',
            "eval_distraction",
            "eval_distraction color_easy needs a dm_control task (it recolours or re-renders a "
            "MuJoCo scene), but this run trains on simoun/PointReach-v0; leave color_easy out of "
            "eval_distraction",
        ),
    ],
)
def test_plan_blames_a_bad_env_setting_on_its_own_line(base, key, said, tmp_path, capsys):
    text = SPEC.replace("[grid]", f"{base}\n\n[grid]")
    path = write_spec(tmp_path / "edited.toml", text)
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["plan", str(path), "--probe-updates", "0"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"{path}:{key_line(text, ('base', key))}: [base] {key}: " in err, err
    assert said in err and "[tuning] tasks" not in err and " --" not in err, err


def test_a_study_is_refused_an_archive_of_another_study_and_leaves_it_unchanged(tmp_path, capsys):
    archive = Path(shutil.copytree(DOCS / "dmc100k", tmp_path / "arch"))
    kept = (archive / "study.json").read_bytes()
    spec_path = DOCS / "highway50k.toml"
    said = (
        f"--archive {archive} holds another study, 'dmc100k' (run from "
        "docs/studies/dmc100k.toml), not the study 'highway50k'"
    )
    for flags in ({"resume": True}, {"resume": True, "allow_other_commit": True}, {}):
        options = StudyOptions(study_dir=tmp_path / "s", archive=archive, **flags)
        with pytest.raises(SetupError, match=re.escape(said)):
            open_study(spec_from(str(spec_path)), str(spec_path), options)
    argv = ["run", str(spec_path), "--study-dir", str(tmp_path / "s"), "--archive", str(archive)]
    with pytest.raises(SystemExit) as exit_info:
        cli.main([*argv, "--resume", "--allow-other-commit"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert said in err and "to continue 'dmc100k', pass its spec" in err and "commit" not in err
    assert (archive / "study.json").read_bytes() == kept
    assert not (tmp_path / "s" / "study.json").exists()


def test_a_study_is_refused_the_archive_of_a_minigrid_study(tmp_path):
    archive = tmp_path / "mg"
    archive.mkdir()
    shutil.copy(DOCS / "minigrid" / "spec.json", archive / "spec.json")
    spec_path = write_spec(tmp_path / "tiny.toml")
    options = StudyOptions(study_dir=tmp_path / "s", archive=archive)
    with pytest.raises(SetupError, match="holds runs of a MiniGrid PPO study"):
        open_study(spec_from(str(spec_path)), str(spec_path), options)
    assert not (archive / "study.json").exists()


def test_a_study_is_refused_a_folder_inside_another_studys_archive(tmp_path, capsys):
    archive = Path(shutil.copytree(DOCS / "dmc100k", tmp_path / "arch"))
    mg = Path(shutil.copytree(DOCS / "minigrid-v2" / "tuning", tmp_path / "mg"))
    kept = {p: p.read_bytes() for root in (archive, mg) for p in root.rglob("*") if p.is_file()}
    spec_path = str(DOCS / "dmc100k.toml")
    for inside, owner in ((archive / "tuning", archive), (mg / "MiniGrid-DoorKey-6x6-v0", mg)):
        for flag in ("--archive", "--study-dir"):
            study_dir = str(tmp_path / "s") if flag == "--archive" else str(inside)
            argv = ["run", spec_path, "--study-dir", study_dir]
            argv += ["--archive", str(inside)] if flag == "--archive" else []
            with pytest.raises(SystemExit) as exit_info:
                cli.main(argv)
            assert exit_info.value.code == 2
            err = capsys.readouterr().err
            assert f"{flag} {inside} lies inside {owner}, the archive of a " in err, err
        options = StudyOptions(study_dir=tmp_path / "s", archive=inside)
        with pytest.raises(SetupError, match="lies inside"):
            open_study(spec_from(spec_path), spec_path, options)
    after = {p: p.read_bytes() for root in (archive, mg) for p in root.rglob("*") if p.is_file()}
    assert after == kept and not (tmp_path / "s").exists()


def test_plan_names_a_spec_path_with_a_trailing_blank(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    write_spec(tmp_path / "tiny.toml")
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["plan", "tiny.toml ", "--probe-updates", "0"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "cannot read the study spec 'tiny.toml ' (No such file or directory); " in err
    assert "and tiny.toml is there: give the path without the blank" in err


def test_plan_refuses_gpus_per_trial_for_runs_on_the_cpu(tmp_path, capsys):
    resources = "max_concurrent_trials = 2"
    text = SPEC.replace(resources, f"{resources}\ngpus_per_trial = 1")
    path = write_spec(tmp_path / "gpus.toml", text)
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["plan", str(path), "--probe-updates", "0"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    line = key_line(text, ("resources", "gpus_per_trial"))
    assert f"{path}:{line}: [resources] gpus_per_trial: gpus_per_trial = 1 and [base] " in err
    assert 'device = "cpu" contradict each other' in err and "set it to 0" in err


def test_a_phase_report_folder_that_is_a_file_is_named_with_a_fix_the_command_has(
    dmc_archive, capsys
):
    tuning = dmc_archive / "report" / "tuning"
    shutil.rmtree(tuning)
    tuning.write_text("notes\n")
    err = report_refused(dmc_archive, capsys)
    assert f"the output directory {tuning} is a file, not a directory" in err
    assert f"move it aside (mv {tuning} {tuning}.aside) and run the command again" in err
    assert "--out" not in err  # simoun-study report has no --out


def test_a_study_directory_given_as_a_packed_file_is_told_to_unpack_it(tmp_path, capsys):
    packed = tmp_path / "arch.tar.gz"
    packed.write_bytes(b"\x1f\x8b\x08\x00")
    err = report_refused(packed, capsys)
    assert f"{packed} is a file, not a directory" in err and "no such directory" not in err
    assert f"tar -xf {packed} -C {tmp_path}" in err


def test_a_finished_runs_device_spelled_otherwise_is_no_change():
    trained = to_dict(resolve(None, {"device": "cpu"}))
    assert changes(trained, to_dict(resolve(None, {"device": "cpu:0"}))) == []
    seeded = to_dict(resolve(None, {"device": "cpu", "seed": 7}))
    assert changes(trained, seeded) == ["seed: 1 when it ran, 7 now"]


def test_a_study_whose_run_still_trains_is_refused_before_its_record_changes(tmp_path, capsys):
    from simoun_agent.run.rundir import lock_run_dir

    spec_path = write_spec(tmp_path / "tiny.toml")
    study_dir = tmp_path / "s"
    run = "tuning/simoun-PointReach-v0/simoun/n_step=1/s101"
    (study_dir / run).mkdir(parents=True)
    with lock_run_dir(study_dir / run):  # as the trial of a study started earlier holds it
        with pytest.raises(SystemExit) as exit_info:
            cli.main(["run", str(spec_path), "--study-dir", str(study_dir)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"run {run} of the study in {study_dir} is in use by another trainer (PID " in err
    assert "the study is still running in another process" in err and "Traceback" not in err
    assert not (study_dir / "study.json").exists()


def test_a_study_is_refused_a_sweep_directory_or_a_folder_inside_one(tmp_path, capsys):
    sweep = tmp_path / "sw"
    sweep.mkdir()
    (sweep / "sweep.json").write_text("{}")
    spec_path = str(write_spec(tmp_path / "tiny.toml"))
    for flag, where, said in (
        ("--study-dir", sweep, f"--study-dir {sweep} is a simoun-sweep directory"),
        ("--study-dir", sweep / "s", f"--study-dir {sweep / 's'} lies inside {sweep}, a "),
        ("--archive", sweep / "a", f"--archive {sweep / 'a'} lies inside {sweep}, a "),
    ):
        argv = ["run", spec_path, "--study-dir", str(where if flag == "--study-dir" else tmp_path)]
        argv += ["--archive", str(where)] if flag == "--archive" else []
        with pytest.raises(SystemExit) as exit_info:
            cli.main(argv)
        assert exit_info.value.code == 2
        err = capsys.readouterr().err
        assert said in err and "Traceback" not in err, err
    assert sorted(p.name for p in sweep.iterdir()) == ["sweep.json"]


def test_an_env_setting_of_base_at_fault_is_named_at_its_base_line(tmp_path, capsys):
    text = (DOCS / "highway50k.toml").read_text()
    assert "\nvideo = false\n" in text and "env_kwargs" not in text.partition("[grid]")[0]
    text = text.replace(
        "\nvideo = false\n", "\nvideo = false\nenv_kwargs = { config = { durration = 40 } }\n"
    )
    path = write_spec(tmp_path / "edit.toml", text)
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["plan", str(path), "--probe-updates", "0"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    line = key_line(text, ("base", "env_kwargs"))
    assert f"{path}:{line}: [base] env_kwargs: highway-fast-v0 cannot be trained with it" in err
    assert "config.durration is not a setting of highway-fast-v0's config" in err
    assert "did you mean config.duration?" in err
    assert "[tuning] tasks" not in err and "Traceback" not in err
