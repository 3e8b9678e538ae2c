"""simoun-report on a directory of ordinary simoun-train runs (no Ray): variants found from the
configs, mean ± std over seeds of the final return and the normalized AUC, the curves."""

import csv
import itertools
import json
import math

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from test_train_resume import TINY as RESUME_TINY

from simoun_agent.run import train
from simoun_agent.run.logger import read_csv
from simoun_agent.run.presets import resolve, to_dict
from simoun_agent.sweep import report

TINY = {key: value for key, value in RESUME_TINY.items() if key != "seed"}
"""The tiny run of tests/test_train_resume.py, each run choosing its own seed."""


@pytest.fixture(scope="module")
def runs_dir(tmp_path_factory):
    """Three finished runs (lr 1e-3 with seeds 0 and 1, lr 3e-4 with seed 0) and one that was
    set up but never trained (lr 3e-4, seed 1), as simoun-train leaves them."""
    root = tmp_path_factory.mktemp("runs")
    for name, lr, seed, trained in (
        ("a-s0", 1e-3, 0, True),
        ("a-s1", 1e-3, 1, True),
        ("b-s0", 3e-4, 0, True),
        ("b-s1", 3e-4, 1, False),
    ):
        config = resolve(None, {**TINY, "agent.lr": lr, "seed": seed, "run_dir": str(root / name)})
        run = train.create_run(config)
        if trained:
            train.train(run)
        run.env.close()
        run.eval_env.close()
    report.write_report(root)
    return root


def rows_of(root):
    with (root / report.REPORT_CSV).open(newline="") as f:
        return list(csv.DictReader(f))


def trapezoid_by_hand(rows):
    area = 0.0
    for before, after in itertools.pairwise(rows):
        width = after["env_step"] - before["env_step"]
        area += width * (before["return_mean"] + after["return_mean"]) / 2
    return area / (rows[-1]["env_step"] - rows[0]["env_step"])


def sample_std(values):
    mean = sum(values) / len(values)
    return math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))


def test_plain_runs_group_by_the_key_that_differs(runs_dir):
    rows = rows_of(runs_dir)
    assert [(r["variant"], r["env"], r["n"], r["unfinished"]) for r in rows] == [
        ("agent.lr=0.001", "simoun-PointReach-v0", "2", "0"),
        ("agent.lr=0.0003", "simoun-PointReach-v0", "1", "1"),
    ]
    table = (runs_dir / report.REPORT_MD).read_text()
    assert "## Unfinished runs (not counted)\n\n- b-s1" in table
    assert "normalized area under the learning curve" in table


def test_final_return_and_auc_are_mean_and_sample_std_over_seeds(runs_dir):
    row = rows_of(runs_dir)[0]
    summaries = [json.loads((runs_dir / n / "summary.json").read_text()) for n in ("a-s0", "a-s1")]
    finals = [s["final_eval"]["return_mean"] for s in summaries]
    aucs = [trapezoid_by_hand(read_csv(runs_dir / n / "eval.csv")) for n in ("a-s0", "a-s1")]
    speeds = [s["env_step"] / s["wall_time_s"] for s in summaries]
    assert float(row["final_return_mean"]) == pytest.approx(sum(finals) / 2)
    assert float(row["final_return_std"]) == pytest.approx(sample_std(finals))
    assert float(row["auc_mean"]) == pytest.approx(sum(aucs) / 2)
    assert float(row["auc_std"]) == pytest.approx(sample_std(aucs))
    assert float(row["env_steps_per_s_mean"]) == pytest.approx(sum(speeds) / 2)
    assert int(row["env_steps"]) == 120
    single = rows_of(runs_dir)[1]
    assert single["final_return_std"] == "nan"  # one seed: no spread to report


def line_pixels(image: np.ndarray, colour: str) -> int:
    """Pixels of ``image`` drawn in matplotlib colour ``colour`` (a line's core, not its band)."""
    rgb = np.array(matplotlib.colors.to_rgb(colour))
    return int(np.all(np.abs(image[..., :3] - rgb) < 0.03, axis=-1).sum())


def test_curves_are_drawn_against_env_steps_and_wall_time(runs_dir, tmp_path):
    """The curves plot each variant's mean return over seeds at each evaluation, one line per
    variant across the panel (far more pixels than a legend sample), and other data (the runs
    cut at 60 env steps) draw another picture."""
    groups = report.compare_runs(runs_dir).groups
    bands = report.std_bands(groups, "env_step", None)["simoun-PointReach-v0"]
    x, mean, low, high = bands["agent.lr=0.001 (n=2)"]
    curves = [read_csv(runs_dir / name / "eval.csv") for name in ("a-s0", "a-s1")]
    np.testing.assert_array_equal(x, [row["env_step"] for row in curves[0]])
    by_hand = [(a["return_mean"] + b["return_mean"]) / 2 for a, b in zip(*curves, strict=True)]
    np.testing.assert_allclose(mean, by_hand)
    assert np.all(high - low >= 0) and np.any(high > low)
    images = {}
    for name in (report.CURVES_STEPS_PNG, report.CURVES_TIME_PNG):
        images[name] = image = matplotlib.image.imread(runs_dir / name)
        for colour in ("C0", "C1"):  # the two variants
            assert line_pixels(image, colour) > 300, (name, colour)
    cut = tmp_path / "cut"
    report.write_report(runs_dir, cut, budget=("env_step", 60))
    other = matplotlib.image.imread(cut / report.CURVES_STEPS_PNG)
    steps = images[report.CURVES_STEPS_PNG]
    assert other.shape != steps.shape or np.abs(other - steps).max() > 0.5


def test_auc_is_the_normalized_trapezoid():
    steps, returns = np.array([0.0, 10.0, 20.0]), np.array([0.0, 10.0, 10.0])
    assert report.area_under_curve(steps, returns) == pytest.approx((50 + 100) / 20)
    assert math.isnan(report.area_under_curve(steps[:1], returns[:1]))


def test_cli_prints_the_table_and_refuses_a_directory_without_runs(runs_dir, tmp_path, capsys):
    assert report.main([str(runs_dir), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "| agent.lr=0.001 | simoun-PointReach-v0 | 2 |" in out
    assert (tmp_path / "out" / report.REPORT_CSV).is_file()
    with pytest.raises(SystemExit) as exit_info:
        report.main([str(tmp_path / "out")])
    assert exit_info.value.code == 2
    assert "no runs under" in capsys.readouterr().err


def test_a_recipe_names_the_variant_without_the_values_it_implies(tmp_path):
    """drq and sac differ in augmentation and temperature settings too: the recipe alone names
    them; a key that splits the runs further (the lr) is kept."""
    records = []
    for recipe, lr, seed in (
        ("drq", 1e-3, 0),
        ("drq", 1e-3, 1),
        ("sac", 1e-3, 0),
        ("sac", 3e-4, 0),
    ):
        config = to_dict(
            resolve(None, {**TINY, "agent.recipe": recipe, "agent.lr": lr, "seed": seed})
        )
        records.append(report.RunRecord(tmp_path, report.flatten(config), {}, None, None))
    assert report.variant_keys(records, tmp_path) == ["agent.recipe", "agent.lr"]


def test_equal_budget_cuts_every_run_at_it_and_counts_unfinished_runs_that_reached_it(
    runs_dir, tmp_path
):
    out = tmp_path / "at-60"
    (runs_dir / "a-s1" / "summary.json").rename(tmp_path / "summary.json")  # a-s1 "unfinished"
    try:
        report.write_report(runs_dir, out, budget=("env_step", 60))
    finally:
        (tmp_path / "summary.json").rename(runs_dir / "a-s1" / "summary.json")
    rows = {row["variant"]: row for row in rows_of(out)}
    at_60 = {
        name: next(r for r in read_csv(runs_dir / name / "eval.csv") if r["env_step"] == 60)
        for name in ("a-s0", "a-s1", "b-s0")
    }
    a = rows["agent.lr=0.001"]
    assert int(a["n"]) == 2  # the unfinished run reached 60 steps: it counts
    expected = [at_60[name]["return_mean"] for name in ("a-s0", "a-s1")]
    assert float(a["final_return_mean"]) == pytest.approx(np.mean(expected))
    assert float(a["wall_time_s_mean"]) == pytest.approx(
        np.mean([at_60[name]["wall_time_s"] for name in ("a-s0", "a-s1")])
    )
    assert int(rows["agent.lr=0.0003"]["n"]) == 1  # b-s1 never trained: short of the budget
    assert "b-s1" in (out / report.REPORT_MD).read_text().split("short of the budget")[1]
    with pytest.raises(SystemExit):
        report.main([str(runs_dir), "--at-step", "0"])


def test_a_dict_valued_key_stays_one_value_so_it_can_name_a_variant():
    flat = report.flatten({"env_kwargs": {"config": {"lanes": 4}}, "agent": {"lr": 1e-3}})
    assert flat == {"env_kwargs": {"config": {"lanes": 4}}, "agent.lr": 1e-3}
