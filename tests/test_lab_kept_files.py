"""The lab's commands on kept files damaged as a disk, a copy or an editor leaves them (empty, cut
short, not JSON, UTF-16, NUL bytes, a directory, a named pipe or a link to nothing in place of
the file, JSON of another kind): each names the file, what is wrong and the fix, exits with
status 2 without a traceback, and never waits on a pipe. The files are copies of the committed
study archives."""

from __future__ import annotations

import contextlib
import errno
import io
import json
import os
import pwd
import re
import shutil
import signal
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from other_users import restored, run_as_user, run_code_as_user, unreadable, unwritable

from simoun_agent.config import SetupError
from simoun_agent.run.kept import (
    Damaged,
    Unreadable,
    csv_number,
    read_csv_rows,
    read_json_object,
    reading,
)
from simoun_lab.cli import report as report_cli
from simoun_lab.cli import study as study_cli
from simoun_lab.engine.launcher import read_run_files
from simoun_lab.minigrid_study import __main__ as minigrid_cli
from simoun_lab.minigrid_study.runner import record_spec, run_study
from simoun_lab.minigrid_study.spec import load_spec as load_minigrid_spec
from simoun_lab.study.checks import finished_config
from simoun_lab.study.choice import choose
from simoun_lab.study.driving import REFERENCES_JSON, read_references
from simoun_lab.study.generalization import read_modes
from simoun_lab.study.options import StudyOptions
from simoun_lab.study.plan import evaluation_runs
from simoun_lab.study.report import UPDATE_COST_JSON, read_result, read_update_costs
from simoun_lab.study.runner import open_study
from simoun_lab.study.spec import load_spec
from simoun_lab.sweep import launch
from simoun_lab.sweep.grid import SweepSpec, Trial
from simoun_lab.sweep.trainable import finished, read_trial_parts

DOCS = Path(__file__).resolve().parents[1] / "docs" / "studies"
MINIGRID = DOCS / "minigrid"
MINIGRID_RUNS = [f"MiniGrid-DoorKey-6x6-v0/{arm}/s0" for arm in ("ppo", "consistency", "rnd")]
"""one seed of every arm: the runs a report compares"""
DMC = DOCS / "dmc100k"
DMC_SPEC = DOCS / "dmc100k.toml"
TUNING_RUN = "tuning/drq/agent.n_step=3/cartpole-swingup/s101"
EVALUATION_RUN = "evaluation/drq/cheetah-run/s1"


@pytest.fixture(autouse=True)
def no_hang() -> Iterator[None]:
    """Fail a test that waits on a named pipe instead of hanging the suite; 300 s, as a whole
    study report of the DMC archive takes about a minute on a loaded 2-core machine."""

    def stop(signum, frame):
        raise TimeoutError("a read waited on a named pipe")

    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(300)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def emptied(path: Path) -> None:
    path.write_bytes(b"")


def cut_short(path: Path) -> None:
    path.write_bytes(path.read_bytes()[:20])


def utf16(path: Path) -> None:
    path.write_text(path.read_text(), encoding="utf-16")


def nul_byte(path: Path) -> None:
    data = path.read_bytes()
    path.write_bytes(data[:4] + b"\0" + data[4:])


def a_directory(path: Path) -> None:
    path.unlink()
    path.mkdir()


def named_pipe(path: Path) -> None:
    path.unlink()
    os.mkfifo(path)


def link_to_nothing(path: Path) -> None:
    path.unlink()
    path.symlink_to(path.with_name("moved-away"))


def an_array(path: Path) -> None:
    path.write_text("[1, 2]")


DAMAGES: dict[Callable[[Path], None], str] = {
    emptied: "it is empty",
    cut_short: "it is not JSON (",
    utf16: "it is saved as UTF-16 text, not UTF-8",
    nul_byte: "line 1 holds a NUL byte",
    a_directory: "it is a directory, not a regular file",
    named_pipe: "it is a named pipe (FIFO), not a regular file",
    link_to_nothing: "it is a symbolic link to ",
    an_array: "it holds an array, not a JSON object",
}
"""each damage of a JSON file, and what is said of it"""


def run_main(main: Callable[[list[str]], int], *args: str) -> tuple[int, str]:
    """A command's exit status (returned, or exited with) and what it printed."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        try:
            status = main(list(args))
        except SystemExit as exit_info:
            status = exit_info.code
    return status, out.getvalue()


def refused(main: Callable[[list[str]], int], *args: str) -> str:
    """What a command says when it refuses: status 2, no traceback."""
    status, printed = run_main(main, *args)
    assert status == 2, printed[-3000:]
    assert "Traceback" not in printed
    return printed


@pytest.mark.parametrize("damage", list(DAMAGES), ids=lambda d: d.__name__)
def test_a_damaged_json_file_is_named_by_the_shared_reader(damage, tmp_path):
    path = tmp_path / "summary.json"
    path.write_text(json.dumps({"env_step": 100, "final_eval": {"return_mean": 1.0}}))
    damage(path)
    with pytest.raises(Damaged, match="^" + re.escape(DAMAGES[damage])):
        read_json_object(path)


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("", "it is empty"),
        ("step,return_mean\n0,1\n", "its first line has no env_step column"),
        ("env_step,return_mean\n0,1\n20\n", "line 3 has 1 fields where the header has 2"),
        ("env_step\n" + "1" * 200_000 + "\n", "it is not a CSV file (field larger than"),
        ("# seed 1\nenv_step,return_mean\n0,1\n", "line 1 is a comment ('# seed 1'): CSV has"),
        ("env_step,return_mean\n0,1\n# outlier\n", "line 3 is a comment ('# outlier'): CSV has"),
    ],
)
def test_a_damaged_csv_file_is_named_by_the_shared_reader(text, problem, tmp_path):
    path = tmp_path / "eval.csv"
    path.write_text(text)
    with pytest.raises(Damaged, match=re.escape(problem)):
        read_csv_rows(path, ("env_step",))


def test_the_shared_csv_reader_reads_rows_as_written_and_names_a_value_that_is_no_number(
    tmp_path,
):
    path = tmp_path / "eval.csv"
    path.write_text("\ufeffenv_step,return_mean\r\n0,\r\n\r\n20,1.5\r\n", newline="")
    rows = read_csv_rows(path, ("env_step",))
    assert rows == [{"env_step": "0", "return_mean": ""}, {"env_step": "20", "return_mean": "1.5"}]
    assert csv_number("1.5", "return_mean", 3) == 1.5
    with pytest.raises(Damaged, match="line 3: return_mean is 'x', not a number"):
        csv_number("x", "return_mean", 3)
    path.write_text("env_step, return_mean\n0, 1.5\n")  # a space after each comma
    assert read_csv_rows(path, ("return_mean",)) == [{"env_step": "0", "return_mean": "1.5"}]


@pytest.fixture
def minigrid_archive(tmp_path: Path) -> Path:
    """One seed of each arm of the committed MiniGrid study, with its spec."""
    archive = tmp_path / "archive"
    for name in MINIGRID_RUNS:
        shutil.copytree(MINIGRID / name, archive / name)
    shutil.copy(MINIGRID / "spec.json", archive / "spec.json")
    return archive


def test_the_minigrid_report_reads_the_copied_runs(minigrid_archive):
    status, printed = run_main(minigrid_cli.main, "report", "--archive", str(minigrid_archive))
    assert status == 0, printed[-3000:]
    assert (minigrid_archive / "report" / "report.md").is_file()


@pytest.mark.parametrize(
    ("file", "damage", "problem"),
    [
        *(("summary.json", d, problem) for d, problem in DAMAGES.items() if d is not nul_byte),
        ("summary.json", nul_byte, "line 2 holds a NUL byte"),  # written indented
        ("summary.json", lambda p: p.write_text('{"env_steps": 1}'), "env_s is null, not a number"),
        ("eval.csv", emptied, "it is empty"),
        ("eval.csv", named_pipe, "it is a named pipe (FIFO), not a regular file"),
        (
            "eval.csv",
            lambda p: p.write_text("env_step,wall_s\n0,1\n"),
            "its first line has no success_rate, return_mean column",
        ),
        ("eval.csv", lambda p: p.write_text(p.read_text()[:40]), "it holds no row after its"),
        ("train.csv", utf16, "it is saved as UTF-16 text, not UTF-8"),
        ("train.csv", link_to_nothing, "it is a symbolic link to "),
    ],
)
def test_a_damaged_minigrid_run_file_is_named_by_the_report(
    file, damage, problem, minigrid_archive
):
    path = minigrid_archive / MINIGRID_RUNS[1] / file
    damage(path)
    printed = refused(minigrid_cli.main, "report", "--archive", str(minigrid_archive))
    assert f"{path} is damaged: {problem}" in printed
    assert f"mv {path.parent} {path.parent}.damaged" in printed and "Restore it" in printed


def test_a_value_that_is_not_a_number_is_named_by_the_minigrid_selection(minigrid_archive):
    path = minigrid_archive / MINIGRID_RUNS[0] / "eval.csv"
    lines = path.read_text().splitlines()
    lines[2] = "x" + lines[2][lines[2].index(",") :]
    path.write_text("\n".join(lines) + "\n")
    printed = refused(minigrid_cli.main, "select", "--archive", str(minigrid_archive))
    assert f"{path} is damaged: line 3: env_step is 'x', not a number" in printed


@pytest.mark.parametrize("damage", [emptied, named_pipe, an_array], ids=lambda d: d.__name__)
def test_a_damaged_archive_spec_is_named_with_the_fix(damage, minigrid_archive):
    path = minigrid_archive / "spec.json"
    damage(path)
    printed = refused(minigrid_cli.main, "report", "--archive", str(minigrid_archive))
    assert (
        f"{path} is damaged: {DAMAGES[damage]}" in printed and "Restore it from a copy" in printed
    )
    # a run given its spec on the command line checks it against the archive's before training
    with pytest.raises(SetupError, match=re.escape(f"{path} is damaged: ")):
        record_spec(load_minigrid_spec(MINIGRID / "spec.json"), minigrid_archive)


def test_a_spec_in_place_of_which_a_named_pipe_stands_is_named(tmp_path):
    spec = tmp_path / "spec.toml"
    os.mkfifo(spec)
    printed = refused(study_cli.main, "plan", str(spec))
    assert f"cannot read the study spec {spec} (it is a named pipe (FIFO)" in printed


@pytest.fixture
def dmc_archive(tmp_path: Path) -> Path:
    """A copy of the committed dmc100k study archive."""
    return Path(shutil.copytree(DMC, tmp_path / "dmc100k"))


@pytest.mark.parametrize(
    "damage", [emptied, a_directory, named_pipe, an_array], ids=lambda d: d.__name__
)
def test_a_damaged_study_record_is_named_by_the_report(damage, dmc_archive):
    path = dmc_archive / "study.json"
    damage(path)
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{path} is damaged: {DAMAGES[damage]}" in printed
    assert "Restore it from a copy (the study directory and its archive each keep one" in printed


def test_a_study_record_without_its_parts_is_named(dmc_archive):
    path = dmc_archive / "study.json"
    record = json.loads(path.read_text())
    del record["parts"]
    path.write_text(json.dumps(record))
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{path} is damaged: it has no parts, which every study record holds" in printed


@pytest.mark.parametrize(
    ("file", "damage", "problem"),
    [
        ("summary.json", utf16, "summary.json is damaged: it is saved as UTF-16 text"),
        ("summary.json", named_pipe, "summary.json is damaged: it is a named pipe (FIFO)"),
        ("eval.csv", nul_byte, "eval.csv is damaged: line 1 holds a NUL byte"),
        ("eval.csv", emptied, "eval.csv holds no evaluation, but the run finished"),
    ],
)
def test_a_damaged_tuning_run_is_named_by_the_study_report(file, damage, problem, dmc_archive):
    run_dir = dmc_archive / TUNING_RUN
    damage(run_dir / file)
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"the finished run {run_dir}: {problem}" in printed
    assert f"mv {run_dir} {run_dir}.damaged" in printed


@pytest.fixture
def evaluation_run(tmp_path: Path):
    """A copy of one evaluation run of the committed dmc100k study: (study dir, its run)."""
    shutil.copytree(DMC / EVALUATION_RUN, tmp_path / EVALUATION_RUN)
    spec = load_spec(DMC_SPEC)
    chosen = {recipe: choice.setting for recipe, choice in choose(spec, DMC).items()}
    (run,) = [r for r in evaluation_runs(spec, chosen) if r.name == EVALUATION_RUN]
    return tmp_path, run


def test_the_evaluation_run_copy_reads_as_its_result(evaluation_run):
    study_dir, run = evaluation_run
    result = read_result(study_dir, run)
    assert (
        result.final_return
        == json.loads((DMC / EVALUATION_RUN / "summary.json").read_text())["final_eval"][
            "return_mean"
        ]
    )
    assert result.cpu_s > 0 and result.modes is None


@pytest.mark.parametrize(
    ("file", "damage", "problem"),
    [
        ("summary.json", link_to_nothing, "summary.json is damaged: it is a symbolic link to "),
        ("summary.json", lambda p: p.write_text("{}"), "has no finite final_eval.return_mean"),
        ("trial.json", emptied, "trial.json is damaged: it is empty"),
        ("trial.json", named_pipe, "trial.json is damaged: it is a named pipe (FIFO)"),
        ("trial.json", lambda p: p.write_text('{"parts": 3}'), "trial.json is damaged: its parts"),
        (
            "trial.json",
            lambda p: p.write_text('{"parts": [{"cpu_count": 2, "loadavg": "high"}]}'),
            'trial.json is damaged: part 1\'s loadavg is "high", where an array of the 1, 5 and',
        ),
        (
            "trial.json",
            lambda p: p.write_text('{"parts": [{"cpu_count": 0, "loadavg": [1, 1, 1]}]}'),
            "trial.json is damaged: part 1's cpu_count is 0, where a whole number of CPUs",
        ),
    ],
)
def test_a_damaged_evaluation_run_is_named_when_its_result_is_read(
    file, damage, problem, evaluation_run
):
    study_dir, run = evaluation_run
    damage(study_dir / run.name / file)
    with pytest.raises(SetupError, match=re.escape(problem)):
        read_result(study_dir, run)


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        (b"", "it is empty"),
        (b"mode,env_step\ntrain,100000\n", "its first line has no return_mean column"),
        (b"mode,env_step,return_mean\ntrain,100000,high\n", "line 2: return_mean is 'high'"),
        ("mode,env_step,return_mean\n".encode("utf-16"), "it is saved as UTF-16 text"),
    ],
)
def test_a_damaged_generalization_csv_is_named_with_the_fix(text, problem, evaluation_run):
    study_dir, run = evaluation_run
    path = study_dir / run.name / "generalization.csv"
    path.write_bytes(text)
    with pytest.raises(SetupError, match=re.escape(f"is damaged: {problem}")) as refusal:
        read_modes(study_dir / run.name, 100000)
    assert str(path) in str(refusal.value) and "the run's final agent is then played" in str(
        refusal.value
    )


def test_a_generalization_csv_reads_as_written(evaluation_run):
    study_dir, run = evaluation_run
    path = study_dir / run.name / "generalization.csv"
    path.write_text("mode,env_step,return_mean\ntrain,100000,250.5\nvideo_easy,100000,12\n")
    assert read_modes(study_dir / run.name, 100000) == {"train": 250.5, "video_easy": 12.0}
    assert read_modes(study_dir / run.name, 50000) is None  # not the final agent's


@pytest.mark.parametrize(
    ("damage", "problem"),
    [
        (lambda p: p.write_bytes(b"{\0}"), "line 1 holds a NUL byte"),
        (lambda p: p.write_text('{"baseline": "sac"}'), "it has no ratio, ms_per_update"),
        (lambda p: os.mkfifo(p), "it is a named pipe (FIFO)"),
    ],
)
def test_a_damaged_update_cost_file_is_named_with_the_command_that_writes_it(
    damage, problem, tmp_path
):
    path = tmp_path / UPDATE_COST_JSON
    damage(path)
    with pytest.raises(SetupError, match=re.escape(problem)) as refusal:
        read_update_costs(load_spec(DMC_SPEC), tmp_path)
    assert f"{path} is damaged" in str(refusal.value)
    assert "python benchmarks/recipe_update.py --selection" in str(refusal.value)


UPDATE_COSTS = {
    "baseline": "drq",
    "ratio": {"drq": 1.0, "simoun": 2.1},
    "ms_per_update": {"drq": 2.0, "simoun": 4.2},
    "task": "dm_control/cartpole-swingup-v0",
    "action_repeat": 8,
    "command": "python benchmarks/recipe_update.py --json update_cost.json",
    "commit": "0" * 40,
    "machine": "a test machine",
}
"""an update_cost.json of the dmc100k study as benchmarks/recipe_update.py writes it"""


@pytest.mark.parametrize(
    ("changes", "problem"),
    [
        ({"baseline": "sac"}, 'its baseline is "sac", which is not a recipe of this study'),
        ({"ratio": {"drq": 1.0, "simoun": "2.1x"}}, 'its ratio.simoun is "2.1x", which must'),
        ({"ratio": {"drq": 1.0, "simoun": 0}}, "its ratio.simoun is 0, which must be a positive"),
        ({"ratio": {"drq": True}}, "its ratio.drq is true, which must be a positive number"),
        ({"ms_per_update": {"drq": -2.0, "simoun": 4.2}}, "its ms_per_update.drq is -2.0"),
        ({"ms_per_update": {"drq": 2.0}}, "ratio has simoun, which ms_per_update does not"),
        (
            {
                "ratio": {"drq": 1.0, "simoun/agent.n_step=3": 2.1},
                "ms_per_update": {"drq": 2.0, "simoun/agent.n_step=3": 4.2},
            },
            'its ratio has "simoun/agent.n_step=3", which is not a recipe (did you mean simoun? '
            "rename the key to it): the file is keyed by recipe name (this study's: simoun, drq",
        ),
        (
            {"ms_per_update": {"drq": 2.0, "simoun": 4.2, "curll": 3.0}},
            'its ms_per_update has "curll", which is not a recipe (did you mean curl?',
        ),
    ],
)
def test_an_update_cost_value_the_report_cannot_use_is_named_before_the_report(
    changes, problem, dmc_archive
):
    path = dmc_archive / UPDATE_COST_JSON
    path.write_text(json.dumps({**UPDATE_COSTS, **changes}))
    before = sorted(p.relative_to(dmc_archive) for p in dmc_archive.rglob("*"))
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{path} is damaged: {problem}" in printed
    assert f"mv {path} {path}.damaged" in printed
    assert sorted(p.relative_to(dmc_archive) for p in dmc_archive.rglob("*")) == before


def test_a_non_finite_update_cost_ratio_is_named(dmc_archive):
    path = dmc_archive / UPDATE_COST_JSON
    path.write_text(json.dumps({**UPDATE_COSTS, "ratio": {"drq": 1.0, "simoun": float("nan")}}))
    with pytest.raises(SetupError, match=re.escape("its ratio.simoun is NaN, which must be")):
        read_update_costs(load_spec(DMC_SPEC), dmc_archive)


def test_the_update_cost_figure_is_linked_only_when_drawn(dmc_archive):
    (dmc_archive / UPDATE_COST_JSON).write_text(json.dumps(UPDATE_COSTS))
    status, printed = run_main(
        study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive)
    )
    assert status == 0, printed[-3000:]
    report = (dmc_archive / "report" / "report.md").read_text()
    figure = dmc_archive / "report" / "iqm_wall_time_update_cost.png"
    assert "(iqm_wall_time_update_cost.png)" in report and figure.stat().st_size > 1000
    assert "Not drawn (no ratio in the file): drqv2, rad, curl." in report
    figure.unlink()
    (dmc_archive / UPDATE_COST_JSON).write_text(
        json.dumps({**UPDATE_COSTS, "ratio": {}, "ms_per_update": {}})
    )
    status, printed = run_main(
        study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive)
    )
    assert status == 0, printed[-3000:]
    report = (dmc_archive / "report" / "report.md").read_text()
    assert "iqm_wall_time_update_cost.png" not in report and not figure.exists()
    assert "Not drawn (no ratio in the file): simoun, drq, drqv2, rad, curl." in report


@pytest.mark.parametrize(
    "name", ["report.md", "scores.csv", "iqm_curves.png", "evaluation/report.md"]
)
def test_a_study_report_file_that_is_a_folder_is_named_before_the_report(name, dmc_archive):
    path = dmc_archive / "report" / name
    shutil.rmtree(path, ignore_errors=True)
    path.unlink(missing_ok=True)
    path.mkdir(parents=True)
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"cannot write {path} (it is a directory, not a regular file)" in printed
    assert f"mv {path} {path}.aside" in printed


def test_a_study_report_file_that_is_a_folder_is_named_before_the_study_runs(tmp_path):
    path = tmp_path / "study" / "report" / "report.md"
    path.mkdir(parents=True)
    printed = refused(study_cli.main, "run", str(DMC_SPEC), "--study-dir", str(tmp_path / "study"))
    assert f"cannot write {path} (it is a directory, not a regular file)" in printed
    assert sorted(p.name for p in (tmp_path / "study").rglob("*")) == ["report", "report.md"]


def test_a_deleted_tuning_folder_is_named_as_missing_not_as_unfinished_runs(dmc_archive):
    shutil.rmtree(dmc_archive / "tuning")
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{dmc_archive / 'tuning'}, the folder of the study's tuning runs, is missing" in printed
    assert "restore it from a copy" in printed and "has not finished" not in printed


@pytest.mark.parametrize(
    ("command", "name"),
    [("report", "report/report.md"), ("report", "report/MiniGrid-DoorKey-6x6-v0_success.png"),
     ("select", "selection.md"), ("select", "selection.json")],
)  # fmt: skip
def test_a_minigrid_output_file_that_is_a_folder_is_named_before_the_work(
    command, name, minigrid_archive
):
    path = minigrid_archive / name
    path.mkdir(parents=True)
    printed = refused(minigrid_cli.main, command, "--archive", str(minigrid_archive))
    assert f"cannot write {path} (it is a directory, not a regular file)" in printed
    assert f"mv {path} {path}.aside" in printed
    assert not (minigrid_archive / "report" / "report.md").is_file()


@pytest.mark.parametrize("damage", [utf16, named_pipe, link_to_nothing], ids=lambda d: d.__name__)
def test_a_damaged_references_file_is_named_with_its_command(damage, tmp_path):
    path = tmp_path / REFERENCES_JSON
    path.write_text("{}")
    damage(path)
    with pytest.raises(SetupError, match=re.escape(f"is damaged: {DAMAGES[damage]}")) as refusal:
        read_references(tmp_path)
    assert str(path) in str(refusal.value) and "write it again with" in str(refusal.value)


@pytest.mark.parametrize("damage", [utf16, a_directory, cut_short], ids=lambda d: d.__name__)
def test_a_damaged_config_of_a_finished_run_is_named_when_a_fixed_spec_is_checked(damage, tmp_path):
    shutil.copytree(DMC / TUNING_RUN, tmp_path / TUNING_RUN)
    path = tmp_path / TUNING_RUN / "config.json"
    damage(path)
    with pytest.raises(SetupError, match=re.escape(f"is damaged: {DAMAGES[damage]}")) as refusal:
        finished_config(TUNING_RUN, [tmp_path])
    assert str(path) in str(refusal.value) and "resume: the run is then trained again" in str(
        refusal.value
    )


def trial_of(run_dir: Path) -> Trial:
    return Trial("base", "dm_control/cheetah-run-v0", 1, str(run_dir), None, {})


@pytest.mark.parametrize("damage", [utf16, emptied, an_array], ids=lambda d: d.__name__)
def test_a_damaged_summary_leaves_a_sweep_trial_finished_for_the_report_to_name(damage, tmp_path):
    run_dir = Path(shutil.copytree(DMC / EVALUATION_RUN, tmp_path / "run"))
    damage(run_dir / "summary.json")
    assert finished(trial_of(run_dir))
    named_pipe(run_dir / "summary.json")
    assert not finished(trial_of(run_dir))  # not read: resuming the trial names it


def test_a_damaged_trial_record_is_named(tmp_path):
    run_dir = Path(shutil.copytree(DMC / EVALUATION_RUN, tmp_path / "run"))
    assert read_trial_parts(run_dir)[0]["cpu_count"] == 2
    utf16(run_dir / "trial.json")
    with pytest.raises(
        SetupError, match=r"trial\.json is damaged: it is saved as UTF-16"
    ) as refusal:
        read_trial_parts(run_dir)
    assert f"mv {run_dir / 'trial.json'} {run_dir / 'trial.json'}.damaged" in str(refusal.value)


@pytest.mark.parametrize(
    ("damage", "said"),
    [
        (emptied, "failed"),
        (
            utf16,
            "failed (error.txt is damaged: it is saved as UTF-16 text, not UTF-8; convert it "
            "(iconv -f UTF-16 -t UTF-8 {error} > {error}.utf8 && mv {error}.utf8 {error}))",
        ),
        (a_directory, "failed (error.txt is damaged: it is a directory, not a regular file)"),
    ],
)
def test_a_damaged_error_file_still_says_the_trial_failed(damage, said, tmp_path, capsys):
    run_dir = Path(shutil.copytree(DMC / EVALUATION_RUN, tmp_path / "sweep" / "run"))
    (run_dir / "summary.json").unlink()
    error = run_dir / "error.txt"
    error.write_text("Traceback ...\nRuntimeError: out of memory\n")
    damage(error)
    status = launch.summarize({"failed": [trial_of(run_dir)]}, tmp_path / "sweep", [])
    assert status == 1
    said = said.format(error=error)
    assert f"FAILED base/cheetah-run/s1: {said} (traceback: {error})" in capsys.readouterr().err
    shutil.copytree(DMC / "evaluation/drq/cheetah-run/s2", tmp_path / "sweep" / "finished")
    assert report_cli.main([str(tmp_path / "sweep"), "--out", str(tmp_path / "report")]) == 0
    assert f"- run: {said}" in (tmp_path / "report" / "report.md").read_text()


@pytest.mark.parametrize("damage", [a_directory, link_to_nothing], ids=lambda d: d.__name__)
def test_a_damaged_sweep_record_is_named_not_taken_for_a_missing_one(damage, tmp_path):
    path = tmp_path / "sweep.json"
    path.write_text("{}")
    damage(path)
    with pytest.raises(SetupError, match=re.escape(f"{path} is damaged ({DAMAGES[damage]}")):
        SweepSpec.load(tmp_path)


@pytest.mark.parametrize("damage", [utf16, a_directory], ids=lambda d: d.__name__)
def test_a_damaged_run_file_is_not_archived(damage, tmp_path):
    run_dir = Path(shutil.copytree(DMC / EVALUATION_RUN, tmp_path / "run"))
    names = ("config.json", "eval.csv", "summary.json")
    assert list(read_run_files(run_dir, names)) == list(names)
    damage(run_dir / "eval.csv")
    with pytest.raises(SetupError, match=re.escape(f"{run_dir / 'eval.csv'} is damaged: ")):
        read_run_files(run_dir, names)


def zero_filled(path: Path) -> None:
    path.write_bytes(bytes(path.stat().st_size))


def overwritten_inside(path: Path) -> None:
    data = bytearray(path.read_bytes())
    data[len(data) // 2] ^= 0xFF
    path.write_bytes(bytes(data))


@pytest.mark.parametrize(
    ("damage", "problem"),
    [
        (emptied, "it is empty"),
        (zero_filled, "bytes are zero"),
        (cut_short, "it cannot be read"),
        (overwritten_inside, "does not match its checksum"),
        (a_directory, "it is a directory, not a regular file"),
    ],
    ids=lambda d: getattr(d, "__name__", ""),
)
def test_a_damaged_checkpoint_of_an_unfinished_minigrid_run_is_refused_before_ray_starts(
    damage, problem, tmp_path
):
    import torch

    spec = load_minigrid_spec(MINIGRID / "spec.json")
    archive = tmp_path / "archive"
    record_spec(spec, archive)
    path = archive / spec.runs()[0].name / "checkpoint.pt"
    path.parent.mkdir(parents=True)
    torch.save({"policy": {"w": torch.arange(4096.0)}, "env_step": 1024}, path)
    damage(path)
    with pytest.raises(SetupError) as error:
        run_study(spec, archive, tmp_path / "work")
    said = str(error.value)
    assert f"{path} is damaged: " in said and problem in said, said
    assert f"mv {path} {path}.damaged" in said
    assert not (tmp_path / "work").exists()  # nothing started


def test_a_minigrid_run_directory_replaced_by_a_file_is_named_by_report_and_select(
    minigrid_archive,
):
    path = minigrid_archive / MINIGRID_RUNS[0]
    shutil.rmtree(path)
    path.write_text("not a directory\n")
    for command in ("report", "select"):
        printed = refused(minigrid_cli.main, command, "--archive", str(minigrid_archive))
        said = f"{path} (the directory of run {MINIGRID_RUNS[0]}) is damaged: it is a file"
        assert said in printed
        assert f"mv {path} {path}.damaged" in printed


def edit_json(path: Path, **changes: object) -> None:
    path.write_text(json.dumps({**json.loads(path.read_text()), **changes}))


@pytest.mark.parametrize(
    ("changes", "problem"),
    [
        ({"run": MINIGRID_RUNS[1]}, f'its run is "{MINIGRID_RUNS[1]}", not {MINIGRID_RUNS[0]!r}'),
        ({"env_steps": 10**30}, "env_steps is 1000000000000000000000000000000, but a run of "),
        (
            {"env_steps": 399_999},
            "env_steps is 399999, but a run of 400000 env steps takes from 400000 to 401023",
        ),
    ],
)
def test_a_minigrid_summary_of_another_run_or_budget_is_named(changes, problem, minigrid_archive):
    path = minigrid_archive / MINIGRID_RUNS[0] / "summary.json"
    edit_json(path, **changes)
    printed = refused(minigrid_cli.main, "report", "--archive", str(minigrid_archive))
    assert f"{path} is damaged: {problem}" in printed


def test_a_minigrid_spec_of_another_study_is_named_not_taken_for_nothing_to_report(
    minigrid_archive,
):
    path = minigrid_archive / "spec.json"
    shutil.copy(DOCS / "minigrid-v2/tuning/spec.json", path)
    printed = refused(minigrid_cli.main, "report", "--archive", str(minigrid_archive))
    assert f"{minigrid_archive} holds no finished run of the spec in {path}, but 3 " in printed
    assert "is another study's" in printed and "nothing to report" not in printed


def test_a_resumed_minigrid_study_checks_its_finished_runs_before_ray(minigrid_archive, tmp_path):
    config = minigrid_archive / MINIGRID_RUNS[0] / "config.json"
    shutil.copy(minigrid_archive / MINIGRID_RUNS[1] / "config.json", config)
    spec = load_minigrid_spec(minigrid_archive / "spec.json")
    with pytest.raises(SetupError, match=re.escape(f"{config} is damaged: its run is ")):
        run_study(spec, minigrid_archive, tmp_path / "work", address="no-such-cluster:1")


def test_a_study_run_directory_replaced_by_a_file_is_named_by_the_report(dmc_archive):
    path = dmc_archive / EVALUATION_RUN
    shutil.rmtree(path)
    path.write_text("not a directory\n")
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{path} (the directory of run {EVALUATION_RUN}) is damaged: it is a file" in printed


def test_a_study_record_with_recipes_a_string_is_named_as_damaged(dmc_archive):
    path = dmc_archive / "study.json"
    record = json.loads(path.read_text())
    record["spec"]["recipes"] = "simoun"
    path.write_text(json.dumps(record))
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f'{path} is damaged: its spec\'s recipes is "simoun", where an array belongs' in printed


def test_a_resumed_study_with_the_record_of_another_study_names_it(dmc_archive, tmp_path):
    path = dmc_archive / "study.json"
    shutil.copy(DOCS / "dmc100k-drqv2-easy" / "study.json", path)
    options = StudyOptions(
        study_dir=tmp_path / "s", archive=dmc_archive, resume=True, allow_other_commit=True
    )
    with pytest.raises(SetupError, match=re.escape(f"{path} is the record of another study")):
        open_study(load_spec(DMC_SPEC), str(DMC_SPEC), options)


def linked_to_its_folder(path: Path) -> None:
    shutil.rmtree(path)
    path.symlink_to("..")


LOOP = "is damaged: it is a symbolic link to .., a folder it is in (a loop), not the run's"


def test_a_minigrid_run_linked_to_its_own_folder_is_named_by_report_and_select(minigrid_archive):
    path = minigrid_archive / MINIGRID_RUNS[0]
    linked_to_its_folder(path)
    for command in ("report", "select"):
        printed = refused(minigrid_cli.main, command, "--archive", str(minigrid_archive))
        assert f"{path} (the directory of run {MINIGRID_RUNS[0]}) {LOOP}" in printed
        assert f"mv {path} {path}.damaged" in printed


def test_a_study_run_linked_to_its_own_folder_is_named_by_the_report(dmc_archive):
    path = dmc_archive / EVALUATION_RUN
    linked_to_its_folder(path)
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{path} (the directory of run {EVALUATION_RUN}) {LOOP}" in printed


def test_a_study_archive_given_to_simoun_report_is_refused_naming_its_report(dmc_archive):
    before = sorted(p.relative_to(dmc_archive) for p in dmc_archive.rglob("*"))
    printed = refused(report_cli.main, str(dmc_archive))
    assert f"{dmc_archive} is a simoun-study directory or archive (it holds study.json)" in printed
    assert f"simoun-study report SPEC --study-dir {dmc_archive}" in printed
    assert sorted(p.relative_to(dmc_archive) for p in dmc_archive.rglob("*")) == before
    # a phase of it is a comparison simoun-report makes
    status, printed = run_main(report_cli.main, str(dmc_archive / "evaluation"), "--out",
                               str(dmc_archive.parent / "out"))  # fmt: skip
    assert status == 0, printed[-3000:]


def test_a_study_archive_given_as_a_sweep_is_named_with_the_study_command(dmc_archive):
    with pytest.raises(SetupError, match=re.escape("it is a simoun-study directory or archive")):
        SweepSpec.load(dmc_archive)


def test_a_damaged_log_of_a_finished_minigrid_run_is_named_before_run_starts(
    minigrid_archive, tmp_path, monkeypatch
):
    monkeypatch.setenv("RAY_ADDRESS", "no-ray-in-this-test")  # a run that got past the checks
    path = minigrid_archive / MINIGRID_RUNS[1] / "eval.csv"
    path.write_bytes(path.read_bytes() + bytes(512))
    printed = refused(minigrid_cli.main, "run", "--archive", str(minigrid_archive), "--work-dir",
                      str(tmp_path / "work"))  # fmt: skip
    assert f"{path} is damaged: line " in printed and "holds a NUL byte" in printed
    assert not (tmp_path / "work").exists() or not any((tmp_path / "work").iterdir())


@pytest.mark.parametrize(
    ("source", "target", "problem"),
    [
        ("train.csv", "eval.csv", "eval.csv is damaged: it holds train.csv's columns"),
        ("summary.json", "config.json", "config.json is damaged: it holds summary.json's keys"),
        ("config.json", "summary.json", "summary.json is damaged: it holds config.json's keys"),
    ],
)
def test_a_file_of_a_finished_study_run_copied_over_another_is_named(
    source, target, problem, dmc_archive
):
    run_dir = dmc_archive / TUNING_RUN
    shutil.copyfile(run_dir / source, run_dir / target)
    printed = refused(study_cli.main, "report", str(DMC_SPEC), "--study-dir", str(dmc_archive))
    assert f"{problem}" in printed and str(run_dir) in printed


def test_every_kept_json_file_is_read_alike_in_utf16(tmp_path):
    """One reader for every kept JSON file: a UTF-16 study record, MiniGrid spec, sweep.json or
    update_cost.json is refused alike, with the command that converts it."""
    from simoun_lab.study.owner import read_object

    record = Path(shutil.copy(DMC / "study.json", tmp_path / "study.json"))
    utf16(record)
    with pytest.raises(Damaged, match="saved as UTF-16 text, not UTF-8; convert it") as info:
        read_json_object(record)
    assert f"iconv -f UTF-16 -t UTF-8 {record} > {record}.utf8 && mv {record}.utf8 {record}" in (
        str(info.value)
    )
    assert read_object(record) is None  # the owner check reads it as every reader does
    spec = Path(shutil.copy("docs/studies/minigrid/spec.json", tmp_path / "spec.json"))
    utf16(spec)
    with pytest.raises(SetupError, match="saved as UTF-16 text, not UTF-8; convert it"):
        load_minigrid_spec(spec)


def test_a_read_refused_for_permission_is_told_apart_from_damage(tmp_path):
    """The OSError of a file the user may not read (EACCES, EPERM) names the file, its owner and
    mode and the fix for permissions; any other OSError is left to its reader."""
    path = tmp_path / "summary.json"
    path.write_text("{}")
    path.chmod(0o640)
    for code in (errno.EACCES, errno.EPERM):
        with pytest.raises(Unreadable) as refusal, reading(path):
            raise OSError(code, os.strerror(code), str(path))
        said = str(refusal.value)
        owner = pwd.getpwuid(os.geteuid()).pw_name
        assert said.startswith(
            f"{path} cannot be read: permission denied (owner {owner}, mode 640)"
        )
        assert f"chmod u+r {path}" in said
        assert not re.search("damaged|corrupt|restore|delete|anew", said, re.IGNORECASE)
    with pytest.raises(OSError, match="Input/output error"), reading(path):
        raise OSError(errno.EIO, os.strerror(errno.EIO), str(path))


def test_every_shared_reader_names_a_file_or_folder_the_user_may_not_read(tmp_path):
    """The readers every command uses raise Unreadable, as an ordinary user, for another
    user's file and for a file in a colleague's private folder, where they would name damage
    or let a PermissionError escape."""
    (tmp_path / "checkpoint.pt").write_bytes(b"PK\3\4" + bytes(100))
    (tmp_path / "summary.json").write_text("{}")
    private = tmp_path / "private"
    private.mkdir()
    (private / "summary.json").write_text("{}")
    readers = {
        "read_text": "summary.json",
        "read_json_object": "summary.json",
        "summary_problem": "summary.json",
        "checkpoint_problem": "checkpoint.pt",
        "binary_problem": "checkpoint.pt",
        "present": "private/summary.json",
        "summary_written": "private",
    }
    for name in ("checkpoint.pt", "summary.json", "private"):
        unreadable(tmp_path / name)
    code = """
import sys
from pathlib import Path
from simoun_agent.run import kept
from simoun_lab.engine.trial import summary_written
for name, path in zip(sys.argv[1::2], sys.argv[2::2]):
    try:
        getattr(kept, name, summary_written)(Path(path))
    except kept.Unreadable as err:
        print(name, "->", err)
"""
    argv = [part for name, file in readers.items() for part in (name, str(tmp_path / file))]
    try:
        result = run_code_as_user(code, *argv)
    finally:
        for name in ("checkpoint.pt", "summary.json", "private"):
            restored(tmp_path / name)
    assert result.returncode == 0, result.stderr[-3000:]
    said = dict(line.split(" -> ") for line in result.stdout.splitlines())
    assert sorted(said) == sorted(readers)
    for name, file in readers.items():
        assert said[name].startswith(str(tmp_path / file)), said[name]
        assert "cannot be read" in said[name]
        assert "permission denied (owner " in said[name] and "chmod" in said[name]
    assert all(f"(its folder {private})" in said[name] for name in ("present", "summary_written"))


def test_a_private_run_folder_is_named_by_the_minigrid_report(minigrid_archive):
    run = minigrid_archive / MINIGRID_RUNS[0]
    unreadable(run)
    try:
        result = run_as_user(
            "simoun_lab.minigrid_study.__main__", "report", "--archive", str(minigrid_archive)
        )
    finally:
        restored(run)
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"{run / 'summary.json'} cannot be read (its folder {run}): permission denied" in (
        result.stderr
    )
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize("command", ["report", "select"])
def test_a_minigrid_archive_that_cannot_be_written_is_refused_before_it_is_read(
    command, minigrid_archive
):
    """The report and the selection check the folder they write into first, as the other
    commands do, with the fix for another user's archive: a copy of it."""
    unwritable(minigrid_archive)
    try:
        result = run_as_user(
            "simoun_lab.minigrid_study.__main__", command, "--archive", str(minigrid_archive)
        )
    finally:
        restored(minigrid_archive)
    assert result.returncode == 2, result.stderr[-3000:]
    assert "cannot write to the output directory" in result.stderr
    assert f"cp -r {minigrid_archive} ~/archive && python -m simoun_lab.minigrid_study " in (
        result.stderr
    )
    assert "Traceback" not in result.stderr


def test_a_private_evaluation_run_is_named_by_the_study_report(dmc_archive):
    run = dmc_archive / EVALUATION_RUN
    unreadable(run)
    try:
        result = run_as_user(
            "simoun_lab.cli.study", "report", str(DMC_SPEC), "--study-dir", str(dmc_archive)
        )
    finally:
        restored(run)
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"cannot be read (its folder {run}): permission denied" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_minigrid_run_or_archive_is_named_by_the_commands_of_simoun_train_runs(
    minigrid_archive,
):
    from simoun_agent.cli import eval as eval_cli
    from simoun_agent.cli import train as train_cli
    from simoun_lab.cli import analyze as analyze_cli

    run = minigrid_archive / MINIGRID_RUNS[0]
    before = sorted(p.relative_to(minigrid_archive) for p in minigrid_archive.rglob("*"))
    report = f"`python -m simoun_lab.minigrid_study report --archive {minigrid_archive}`"
    only = "simoun-train, simoun-eval and simoun-analyze work on simoun-train runs only"
    for main, args in (
        (analyze_cli.main, ["bias", str(run), "--pairs", "8", "--out", str(run.parent / "b")]),
        (analyze_cli.main, ["masks", str(run)]),
        (eval_cli.main, [str(run)]),
        (train_cli.main, ["--resume", str(run)]),
    ):
        printed = refused(main, *args)
        assert (
            f"{run} is a run of a MiniGrid PPO study (its config.json names the study's" in printed
        )
        assert f"{report} reports" in printed and only in printed, printed
        assert "no checkpoint" not in printed and "unknown config key" not in printed
    for where, said in (
        (minigrid_archive, "the archive of a MiniGrid PPO study"),
        (run.parent, f"a folder of {minigrid_archive}, the archive of a MiniGrid PPO study"),
    ):
        printed = refused(analyze_cli.main, "masks", str(where))
        assert (
            f"{where} is {said} ({minigrid_archive / 'spec.json'})" in printed and only in printed
        )
    assert sorted(p.relative_to(minigrid_archive) for p in minigrid_archive.rglob("*")) == before
