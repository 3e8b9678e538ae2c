"""The study engine: both trainers offer its trial interface, the archive's writer copies a
finished run's files and drops its carried checkpoint, and a local Ray instance runs trials at
the driver's priority. The engine on Ray Tune is exercised by tests/test_study.py,
tests/test_sweep.py and tests/test_minigrid_study.py."""

import os
from pathlib import Path

import pytest

from simoun_agent.config import SetupError
from simoun_lab.engine.launcher import archive_files, changed_keys, read_run_files
from simoun_lab.engine.ray_start import connect, load_ray
from simoun_lab.engine.trial import Trial
from simoun_lab.minigrid_study.spec import StudySpec
from simoun_lab.minigrid_study.trial import MiniGridTrial
from simoun_lab.sweep.grid import SweepSpec
from simoun_lab.sweep.trainable import SacTrial


def test_both_trainers_are_engine_trials(tmp_path):
    spec = StudySpec()
    minigrid = MiniGridTrial(spec, spec.runs()[0], str(tmp_path))
    assert isinstance(minigrid, Trial)
    assert minigrid.run_dir == str(tmp_path / "runs" / "MiniGrid-DoorKey-6x6-v0/ppo/s0")
    assert minigrid.checkpoint == "checkpoint.pt" and minigrid.run_files[-1] == "summary.json"
    assert not minigrid.finished()
    (sweep_trial,) = SweepSpec.create(None, {}, [], "0", None).trials(str(tmp_path))
    sac = SacTrial(sweep_trial, "tuning/a/s0")
    assert isinstance(sac, Trial) and sac.checkpoint is None  # its replay stays out of archives
    assert sac.run_dir == sweep_trial.run_dir and not sac.finished()


def test_the_archive_gets_the_run_files_and_loses_the_carried_checkpoint(tmp_path):
    run_dir, archive = tmp_path / "run", tmp_path / "archive"
    run_dir.mkdir()
    for name in ("summary.json", "eval.csv", "config.json"):
        (run_dir / name).write_text(name)
    files = read_run_files(run_dir, ("config.json", "summary.json", "eval.csv", "absent.csv"))
    assert list(files) == ["config.json", "summary.json", "eval.csv"]  # the absent one skipped
    (archive / "a/s0").mkdir(parents=True)
    (archive / "a/s0/checkpoint.pt").write_bytes(b"saved")
    archive_files(archive, "a/s0", files, "checkpoint.pt")
    written = {p.name for p in archive.joinpath("a/s0").iterdir()}
    assert written == {"config.json", "eval.csv", "summary.json"}
    assert Path(archive, "a/s0/eval.csv").read_text() == "eval.csv"


def test_changed_keys_names_each_key_whose_value_differs_or_is_missing():
    saved, wanted = {"a": 1, "b": [2], "c": 3}, {"a": 1, "b": [3], "d": 4}
    assert changed_keys(saved, wanted) == ["b", "c", "d"]
    assert changed_keys(saved, dict(saved)) == []


def test_a_local_ray_instance_runs_trials_at_the_drivers_priority():
    ray = load_ray()
    assert connect(ray, None, 1)
    try:
        worker_niceness = ray.get(ray.remote(lambda: os.nice(0)).remote())
    finally:
        ray.shutdown()
    assert worker_niceness == os.nice(0)  # Ray's own default puts its workers 15 lower


def test_a_local_ray_instance_of_no_cpu_is_refused_before_ray_starts():
    ray = load_ray()
    with pytest.raises(
        SetupError, match=r"--num-cpus 0: a local Ray instance needs at least 1 CPU"
    ):
        connect(ray, None, 0)
    assert not ray.is_initialized()


@pytest.mark.parametrize(
    ("address", "environment", "said"),
    [
        ("auto", None, r"--num-cpus 2 with --address auto: .*drop --num-cpus.*drop --address"),
        ("10.0.0.1:6379", None, r"with --address 10\.0\.0\.1:6379"),
        (None, "nohost:1", r"with RAY_ADDRESS=nohost:1: .*unset RAY_ADDRESS to run on a local"),
    ],
)
def test_cpus_of_a_local_instance_with_a_cluster_address_are_refused(
    address, environment, said, monkeypatch
):
    if environment is None:
        monkeypatch.delenv("RAY_ADDRESS", raising=False)
    else:
        monkeypatch.setenv("RAY_ADDRESS", environment)
    ray = load_ray()
    with pytest.raises(SetupError, match=said):
        connect(ray, address, 2)
    assert not ray.is_initialized()


@pytest.mark.parametrize("address", [None, "auto"])
def test_a_ray_address_in_the_environment_that_does_not_answer_fails_within_seconds(
    address, monkeypatch
):
    monkeypatch.setenv("RAY_ADDRESS", "nohost:1")
    ray = load_ray()
    with pytest.raises(
        SetupError, match=r"RAY_ADDRESS=nohost:1: no Ray cluster answers .*unset RAY_ADDRESS"
    ):
        connect(ray, address, None)
    assert not ray.is_initialized()
