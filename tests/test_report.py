"""simoun-report on a directory of ordinary simoun-train runs (no Ray): variants found from the
configs, mean ± std over seeds of the final return and the normalized AUC, the curves."""

import csv
import itertools
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

import matplotlib.colors
import matplotlib.image
import numpy as np
import pytest
from other_users import restored, run_as_user, unreadable
from test_train_failures import named_unwritten_file, under_file_size_limit
from test_train_resume import TINY as RESUME_TINY

from simoun_agent.config import resolve, to_dict
from simoun_agent.run import train
from simoun_agent.run.logger import read_csv
from simoun_lab import stats
from simoun_lab.cli import report as report_cli
from simoun_lab.sweep import report
from simoun_lab.sweep.grid import SweepSpec

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
    assert report_cli.main([str(runs_dir), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "| agent.lr=0.001 | simoun-PointReach-v0 | 2 |" in out
    assert (tmp_path / "out" / report.REPORT_CSV).is_file()
    with pytest.raises(SystemExit) as exit_info:
        report_cli.main([str(tmp_path / "out")])
    assert exit_info.value.code == 2
    assert "no runs under" in capsys.readouterr().err


def test_a_figure_that_does_not_fit_is_named_with_the_fix_and_left_unwritten(runs_dir, tmp_path):
    done = under_file_size_limit("simoun_lab.cli.report", [str(runs_dir), "--out", str(tmp_path)])
    path = named_unwritten_file(done, "simoun-report", "pass --out DIR on another disk")
    assert path.parent == tmp_path and path.suffix == ".png" and not path.exists()


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


def test_at_step_0_compares_the_evaluations_before_training(runs_dir, tmp_path, capsys):
    out = tmp_path / "at-0"
    assert report_cli.main([str(runs_dir), "--at-step", "0", "--out", str(out)]) == 0
    rows = {row["variant"]: row for row in rows_of(out)}
    at_0 = [
        next(r for r in read_csv(runs_dir / name / "eval.csv") if r["env_step"] == 0)
        for name in ("a-s0", "a-s1")
    ]
    a = rows["agent.lr=0.001"]
    assert int(a["n"]) == 2
    assert float(a["final_return_mean"]) == pytest.approx(np.mean([r["return_mean"] for r in at_0]))
    assert "an equal budget of 0 env steps" in (out / report.REPORT_MD).read_text()


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        (["--at-step", "-1"], "--at-step -1: give a number of env steps >= 0, e.g. --at-step"),
        (["--at-wall-time", "0"], "--at-wall-time 0: give a positive finite number of seconds"),
        (["--at-wall-time", "nan"], "--at-wall-time nan: give a positive finite number"),
    ],
)
def test_a_budget_below_its_range_is_refused_naming_the_flag(flags, said, runs_dir, capsys):
    with pytest.raises(SystemExit) as exit_info:
        report_cli.main([str(runs_dir), *flags])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and said in err and "Traceback" not in err


def test_a_dict_valued_key_stays_one_value_so_it_can_name_a_variant():
    flat = report.flatten({"env_kwargs": {"config": {"lanes": 4}}, "agent": {"lr": 1e-3}})
    assert flat == {"env_kwargs": {"config": {"lanes": 4}}, "agent.lr": 1e-3}


def finals_of(root, names):
    return [
        json.loads((root / name / "summary.json").read_text())["final_eval"]["return_mean"]
        for name in names
    ]


def copy_runs(source, names, dest):
    """Real run directories, copied so that a test can add to or take from them."""
    for name in names:
        shutil.copytree(source / name, dest / name)
    return dest


@pytest.fixture(scope="module")
def grid_run(tmp_path_factory):
    """A finished run like a-s0/a-s1 (lr 1e-3) but of seed 2, evaluated every 40 env steps
    (0, 40, 80, 120) instead of every 60."""
    root = tmp_path_factory.mktemp("grid")
    config = resolve(
        None, {**TINY, "agent.lr": 1e-3, "seed": 2, "eval_every": 40, "run_dir": str(root / "c")}
    )
    run = train.create_run(config)
    train.train(run)
    run.env.close()
    run.eval_env.close()
    return root / "c"


def test_report_gives_the_iqm_and_mean_with_bootstrap_intervals(runs_dir):
    row = rows_of(runs_dir)[0]
    finals = finals_of(runs_dir, ("a-s0", "a-s1"))
    task = {"simoun-PointReach-v0": np.array(finals)}
    assert float(row["iqm"]) == pytest.approx(np.mean(finals))  # 2 runs: int(0.5) = 0 cut
    iqm_ci = stats.stratified_bootstrap_ci(task, stats.aggregate_iqm, 2000, 0.95, 0)
    mean_ci = stats.stratified_bootstrap_ci(task, stats.aggregate_mean, 2000, 0.95, 0)
    assert [float(row[k]) for k in ("iqm", "iqm_low", "iqm_high")] == pytest.approx(iqm_ci)
    assert [float(row[k]) for k in ("norm_mean", "norm_mean_low", "norm_mean_high")] == (
        pytest.approx(mean_ci)
    )
    # two runs: a resample is (x, x), (x, y) or (y, y), so the 95 % bounds are the two finals
    assert float(row["iqm_low"]) == pytest.approx(min(finals))
    assert float(row["iqm_high"]) == pytest.approx(max(finals))
    assert row["score_max"] == ""  # PointReach has no known maximum: raw returns
    assert (
        "simoun-PointReach-v0: raw return (no known maximum)"
        in (runs_dir / report.REPORT_MD).read_text()
    )


def test_dm_control_returns_are_normalized_by_their_maximum_of_1000(tmp_path):
    """The committed main job: the dmc100k study's 5 evaluation seeds of the cpu preset on
    cartpole-swingup, real run directories."""
    main_job = (
        Path(__file__).parent.parent / "docs/studies/dmc100k/evaluation/simoun/cartpole-swingup"
    )
    report.write_report(main_job, tmp_path)
    (row,) = rows_of(tmp_path)
    finals = finals_of(main_job, ("s1", "s2", "s3", "s4", "s5"))
    assert float(row["score_max"]) == 1000
    middle = sorted(finals)[1:4]  # 5 runs: the lowest and the highest cut
    assert float(row["iqm"]) == pytest.approx(np.mean(middle) / 1000)
    assert float(row["iqm_low"]) < float(row["iqm"]) < float(row["iqm_high"])
    assert float(row["final_return_mean"]) == pytest.approx(np.mean(finals))  # kept, raw


def test_probability_of_improvement_and_aggregate_tables(runs_dir):
    finals_a = finals_of(runs_dir, ("a-s0", "a-s1"))
    (final_b,) = finals_of(runs_dir, ("b-s0",))
    by_hand = np.mean([(a > final_b) + (a == final_b) / 2 for a in finals_a])
    with (runs_dir / report.IMPROVEMENT_CSV).open(newline="") as f:
        pairs = {(r["x"], r["y"]): r for r in csv.DictReader(f)}
    a, b = "agent.lr=0.001", "agent.lr=0.0003"
    assert set(pairs) == {(a, b), (b, a)}
    assert float(pairs[a, b]["p"]) == pytest.approx(by_hand)
    assert float(pairs[b, a]["p"]) == pytest.approx(1 - by_hand)
    assert pairs[a, b]["tasks"] == "simoun-PointReach-v0"
    assert 0 <= float(pairs[a, b]["low"]) <= float(pairs[a, b]["p"]) <= float(pairs[a, b]["high"])
    with (runs_dir / report.AGGREGATE_CSV).open(newline="") as f:
        aggregate = {r["variant"]: r for r in csv.DictReader(f)}
    assert aggregate[a]["runs"] == "2"
    assert float(aggregate[a]["iqm"]) == pytest.approx(np.mean(finals_a))
    table = (runs_dir / report.REPORT_MD).read_text()
    assert f"| (1) {a} | – | {float(pairs[a, b]['p']):.3g} [" in table


def test_iqm_curve_and_performance_profile_figures(runs_dir):
    comparison = report.compare_runs(runs_dir)
    bands = report.iqm_bands(comparison.groups)["simoun-PointReach-v0"]
    steps, point, low, high = bands["agent.lr=0.001 (n=2)"]
    curves = [read_csv(runs_dir / name / "eval.csv") for name in ("a-s0", "a-s1")]
    assert list(steps) == [0, 60, 120]
    expected = [np.mean([curve[i]["return_mean"] for curve in curves]) for i in range(3)]
    assert point == pytest.approx(expected)
    assert np.all(low <= point) and np.all(point <= high)
    profiles = report.profile_bands(report.variant_scores(comparison.groups))
    taus, fraction, _, _ = profiles["agent.lr=0.001"]
    finals = finals_of(runs_dir, ("a-s0", "a-s1"))
    assert fraction == pytest.approx([np.mean([f > tau for f in finals]) for tau in taus])
    for name in (report.IQM_STEPS_PNG, report.PROFILE_PNG):
        image = matplotlib.image.imread(runs_dir / name)
        assert image.ndim == 3 and image.shape[0] > 100


def test_at_step_counts_only_runs_with_an_evaluation_at_that_step(runs_dir, grid_run, tmp_path):
    root = copy_runs(runs_dir, ("a-s0", "a-s1"), tmp_path / "runs")
    shutil.copytree(grid_run, root / "c")
    report.write_report(root, tmp_path / "at-40", budget=("env_step", 40))
    rows = {row["variant"]: row for row in rows_of(tmp_path / "at-40")}
    assert rows["eval_every=40"]["n"] == "1" and rows["eval_every=60"]["n"] == "0"
    table = (tmp_path / "at-40" / report.REPORT_MD).read_text()
    assert "- a-s0: no evaluation at 40 env steps (last before it 0, next 60)" in table
    report.write_report(root, tmp_path / "at-60", budget=("env_step", 60))
    rows = {row["variant"]: row for row in rows_of(tmp_path / "at-60")}
    assert rows["eval_every=60"]["n"] == "2" and rows["eval_every=40"]["n"] == "0"
    table = (tmp_path / "at-60" / report.REPORT_MD).read_text()
    assert "- c: no evaluation at 60 env steps (last before it 40, next 80)" in table


def test_a_budget_that_leaves_every_run_out_is_refused_naming_the_steps_the_runs_have(
    runs_dir, grid_run, tmp_path, capsys
):
    root = copy_runs(runs_dir, ("a-s0", "a-s1"), tmp_path / "runs")
    shutil.copytree(grid_run, root / "c")
    with pytest.raises(SystemExit) as exit_info:
        report_cli.main([str(root), "--at-step", "25", "--out", str(tmp_path / "at-25")])
    assert exit_info.value.code == 2
    message = capsys.readouterr().err
    assert "--at-step 25 leaves every run out" in message
    assert "the runs evaluate at 40, 60, 80, 120" in message
    assert "e.g. --at-step 120" in message
    assert not (tmp_path / "at-25").exists()
    # from Python the budget is named as the argument it is, and so is the fix
    with pytest.raises(report.SetupError) as err:
        report.write_report(root, tmp_path / "at-200", budget=("env_step", 200))
    assert str(err.value).startswith("budget=('env_step', 200) leaves every run out")
    assert "e.g. budget=('env_step', 120), or pass budget=None" in str(err.value)
    assert "--at-step" not in str(err.value)


@pytest.mark.parametrize(
    ("budget", "error", "message"),
    [
        (("env_steps", 40), ValueError, "got 'env_steps'; did you mean 'env_step'?"),
        (("env_step", "40"), TypeError, r"budget's value must be a number \(env steps\), got str"),
        (40, TypeError, r"budget must be None or a pair \(column, value\), got int 40"),
        (("env_step",), TypeError, r"budget must be None or a pair \(column, value\), got tuple"),
        ("env_step", TypeError, r"budget must be None or a pair \(column, value\), got str"),
        (
            ("env_step", -5),
            ValueError,
            r"budget=\('env_step', -5\): give a number of env steps >= 0",
        ),
        (("wall_time_s", float("nan")), ValueError, "give a positive finite number of seconds"),
        (("wall_time_s", 0), ValueError, "give a positive finite number of seconds"),
    ],
)
def test_a_budget_from_python_is_checked_in_python_terms(
    runs_dir, tmp_path, budget, error, message
):
    with pytest.raises(error, match=message) as err:
        report.write_report(runs_dir, tmp_path / "out", budget=budget)
    assert "--at-" not in str(err.value) and "budget" in str(err.value)
    assert not (tmp_path / "out").exists()


def test_the_report_root_must_be_one_directory(runs_dir, tmp_path):
    with pytest.raises(TypeError, match=r"write_report\(root=\.\.\.\) must be one directory"):
        report.write_report([str(runs_dir)], tmp_path / "out")
    with pytest.raises(TypeError, match=r"write_report\(out=\.\.\.\) must be a path"):
        report.write_report(runs_dir, ["out"])
    with pytest.raises(TypeError, match=r"root must be one directory"):
        report.compare_runs([runs_dir])


def test_a_row_holds_runs_of_one_evaluation_grid(runs_dir, grid_run, tmp_path):
    """In a sweep's directory the grid keys alone name the variants, so a run of the same lr on
    another evaluation grid would join the row: it is listed and left out."""
    root = copy_runs(runs_dir, ("a-s0", "a-s1"), tmp_path / "sweep")
    shutil.copytree(grid_run, root / "c")
    base = {key: value for key, value in TINY.items() if key not in ("agent.lr", "torch_threads")}
    SweepSpec.create(None, base, ["agent.lr=0.001,0.0003"], "0-2", None).save(root)
    report.write_report(root, tmp_path / "out")
    (row,) = rows_of(tmp_path / "out")
    assert (row["variant"], row["n"]) == ("agent.lr=0.001", "2")
    table = (tmp_path / "out" / report.REPORT_MD).read_text()
    assert (
        "## Runs on another evaluation grid (not counted)\n\n- c (eval_every=40; its row: 60)"
        in table
    )


def test_at_wall_time_uses_the_last_evaluation_within_it_of_runs_that_trained_past_it(
    runs_dir, tmp_path
):
    root = copy_runs(runs_dir, ("a-s0",), tmp_path / "runs")
    evaluations = read_csv(root / "a-s0" / "eval.csv")
    between = (evaluations[1]["wall_time_s"] + evaluations[2]["wall_time_s"]) / 2
    report.write_report(root, tmp_path / "between", budget=("wall_time_s", between))
    (row,) = rows_of(tmp_path / "between")
    assert row["n"] == "1"
    assert float(row["final_return_mean"]) == pytest.approx(evaluations[1]["return_mean"])
    assert int(row["env_steps"]) == 60
    beyond = evaluations[-1]["wall_time_s"] + 100
    with pytest.raises(
        report.SetupError, match=r"budget=\('wall_time_s', .*\) leaves every"
    ) as err:
        report.write_report(root, tmp_path / "beyond", budget=("wall_time_s", beyond))
    example = float(str(err.value).split("e.g. budget=('wall_time_s', ")[1].split(")")[0])
    report.write_report(root, tmp_path / "example", budget=("wall_time_s", example))
    assert rows_of(tmp_path / "example")[0]["n"] == "1"


def test_a_seed_counts_once_the_finished_run_then_the_most_recent_kept(runs_dir, tmp_path):
    """A plain run and a sweep trial of the same config and seed count once."""
    root = copy_runs(runs_dir, ("a-s0", "a-s1"), tmp_path / "runs")
    trial = root / "sweep" / "agent.lr=0.001" / "simoun-PointReach-v0" / "s0"
    shutil.copytree(root / "a-s0", trial)
    (trial / "summary.json").unlink()  # the trial never finished; it is the newer one
    os.utime(trial / "eval.csv", (time.time() + 60, time.time() + 60))
    report.write_report(root, tmp_path / "unfinished-copy")
    (row,) = rows_of(tmp_path / "unfinished-copy")
    assert (row["n"], row["unfinished"]) == ("2", "0")  # a-s0 and a-s1, the copy dropped
    table = (tmp_path / "unfinished-copy" / report.REPORT_MD).read_text()
    dropped = "sweep/agent.lr=0.001/simoun-PointReach-v0/s0"
    assert "## Duplicate seeds (dropped)" in table
    assert f"- {dropped} (seed 0; kept a-s0)" in table
    shutil.copy(root / "a-s0" / "summary.json", trial / "summary.json")  # both finished now
    report.write_report(root, tmp_path / "finished-copy")
    assert rows_of(tmp_path / "finished-copy")[0]["n"] == "2"
    table = (tmp_path / "finished-copy" / report.REPORT_MD).read_text()
    assert f"- a-s0 (seed 0; kept {dropped})" in table  # the more recent one is kept


def test_a_single_run_directory_gets_its_report_beside_it(runs_dir, tmp_path, capsys):
    run_dir = copy_runs(runs_dir, ("a-s0",), tmp_path)
    before = sorted(p.name for p in (run_dir / "a-s0").iterdir())
    assert report_cli.main([str(run_dir / "a-s0")]) == 0
    assert sorted(p.name for p in (run_dir / "a-s0").iterdir()) == before
    assert (tmp_path / "report-a-s0" / report.REPORT_CSV).is_file()
    assert f"written: {tmp_path / 'report-a-s0' / report.REPORT_MD}" in capsys.readouterr().out


def test_a_read_only_directory_is_refused_naming_it_and_the_out_flag(runs_dir, tmp_path):
    """Root writes through permission bits, so as root the directory is made a read-only bind
    mount in a user and mount namespace of its own (as a read-only share would be); as any
    other user its write bits are taken away."""
    root = copy_runs(runs_dir, ("a-s0",), tmp_path / "runs")
    command = [sys.executable, "-m", "simoun_lab.cli.report", str(root)]
    if os.geteuid() == 0:
        mount = f"mount --bind {root} {root} && mount -o remount,bind,ro {root} {root}"
        command = ["unshare", "-rm", "sh", "-c", f"{mount} && exec {shlex.join(command)}"]
    else:
        root.chmod(0o555)
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=300, check=False)
    finally:
        root.chmod(0o755)
    assert result.returncode == 2, result.stderr
    assert f"cannot write to the output directory {root}" in result.stderr
    assert "pass a writable --out" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (root / report.REPORT_MD).exists()


@pytest.mark.parametrize(
    "text",
    ["{not json", "[]", '{"preset": null, "base": {}, "grid": [], "seeds": [0], "envs": ["a"]}'],
)
def test_a_damaged_sweep_json_is_named_with_its_fix(runs_dir, text, tmp_path, capsys):
    root = copy_runs(runs_dir, ["a-s0", "b-s0"], tmp_path / "sweep")
    (root / "sweep.json").write_text(text)
    with pytest.raises(SystemExit) as exit_info:
        report_cli.main([str(root)])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"{root / 'sweep.json'} is damaged" in err
    assert "restore it from a copy" in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("name", "change", "said"),
    [
        ("eval.csv", lambda rows: [rows[0], *reversed(rows[1:])], "eval.csv line 3: env_step"),
        ("eval.csv", lambda rows: [*rows, rows[-1]], "does not come after the line before"),
        ("eval.csv", lambda rows: [rows[0], ["-20", *rows[1][1:]], *rows[2:]], "is negative"),
        ("summary.json", {"env_step": "forty"}, "summary.json: env_step is 'forty', not a number"),
        (
            "summary.json",
            {"env_step": 100000},
            "summary.json says the run ended at env step 100000, but the last evaluation in "
            "eval.csv is at",
        ),
    ],
)
def test_a_run_with_steps_out_of_order_or_a_summary_of_the_wrong_type_is_named(
    runs_dir, name, change, said, tmp_path, capsys
):
    run = tmp_path / "a-s0"
    shutil.copytree(runs_dir / "a-s0", run)
    path = run / name
    if name == "summary.json":
        path.write_text(json.dumps({**json.loads(path.read_text()), **change}))
    else:
        rows = [line.split(",") for line in path.read_text().splitlines()]
        path.write_text("\n".join(",".join(row) for row in change(rows)) + "\n")
    with pytest.raises(SystemExit):
        report_cli.main([str(tmp_path)])
    err = capsys.readouterr().err
    assert "every run is damaged" in err and said in err, err


def test_an_equal_wall_time_budget_must_be_finite(runs_dir, capsys):
    with pytest.raises(SystemExit):
        report_cli.main([str(runs_dir), "--at-wall-time", "inf"])
    assert "--at-wall-time inf: give a positive finite number" in capsys.readouterr().err


@pytest.mark.parametrize("key", ["env", "seed", "agent"])
def test_a_config_without_a_key_every_run_records_is_named_and_left_out(key, tmp_path):
    from test_input_checks import write_run

    for seed in range(2):
        write_run(tmp_path, f"s{seed}", "dm_control/cartpole-swingup-v0", seed, 500.0 + seed)
    point = write_run(tmp_path, "point", "simoun/PointReach-v0", 5, 3.0)
    config = json.loads((point / "config.json").read_text())
    del config[key]
    (point / "config.json").write_text(json.dumps(config))
    report.write_report(tmp_path)
    text = (tmp_path / "report.md").read_text()
    assert "## Damaged runs (not counted)" in text
    assert f"- point: config.json has no {key}, which every run records" in text
    with (tmp_path / "report.csv").open() as f:
        (row,) = csv.DictReader(f)
    assert row["n"] == "2" and float(row["final_return_mean"]) == pytest.approx(500.5)


def test_an_archive_of_the_minigrid_study_is_sent_to_its_own_report(capsys):
    root = Path(__file__).resolve().parents[1] / "docs/studies/minigrid"
    with pytest.raises(SystemExit):
        report_cli.main([str(root), "--out", "never-written"])
    err = capsys.readouterr().err
    assert "holds runs of the MiniGrid study, which simoun-report does not read" in err
    assert f"python -m simoun_lab.minigrid_study report --archive {root}" in err
    assert not Path("never-written").exists()


def test_a_task_folder_of_a_minigrid_archive_is_sent_to_the_archives_report(capsys):
    root = Path(__file__).resolve().parents[1] / "docs/studies/minigrid"
    with pytest.raises(SystemExit):
        report_cli.main([str(root / "MiniGrid-DoorKey-6x6-v0"), "--out", "never-written"])
    err = capsys.readouterr().err
    assert "holds runs of the MiniGrid study, which simoun-report does not read" in err
    assert f"python -m simoun_lab.minigrid_study report --archive {root}`" in err
    assert not Path("never-written").exists()


def test_a_run_the_user_may_not_read_is_named_not_left_out_in_silence(runs_dir, tmp_path):
    """A colleague's private run folder (mode 700) among the user's runs is listed as a run
    that cannot be read, with its owner and the fix; the others are reported."""
    root = copy_runs(runs_dir, ("a-s0", "a-s1"), tmp_path / "runs")
    unreadable(root / "a-s1")
    try:
        result = run_as_user("simoun_lab.cli.report", str(root), "--out", str(tmp_path / "r"))
    finally:
        restored(root / "a-s1")
    assert result.returncode == 0, result.stderr[-3000:]
    assert "## Runs that cannot be read (not counted)" in result.stdout
    assert f"- a-s1: {root / 'a-s1'} cannot be read: permission denied (owner " in result.stdout
    assert "chmod" in result.stdout


def test_a_run_whose_log_the_user_may_not_read_is_not_called_damaged(runs_dir, tmp_path):
    root = copy_runs(runs_dir, ("a-s0",), tmp_path / "runs")
    unreadable(root / "a-s0" / "eval.csv")
    try:
        result = run_as_user("simoun_lab.cli.report", str(root), "--out", str(tmp_path / "r"))
    finally:
        restored(root / "a-s0" / "eval.csv")
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"{root / 'a-s0' / 'eval.csv'} cannot be read: permission denied" in result.stderr
    for word in ("Traceback", "damaged", "restore", "remove"):
        assert word not in result.stderr
