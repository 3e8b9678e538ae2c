"""simoun-sweep on a local Ray instance: a grid of tiny PointReach runs, a failing trial, Ctrl-C
and --resume, and the bad inputs it refuses."""

import contextlib
import csv
import dataclasses
import fcntl
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import ray  # the lab extra: a missing install fails instead of skipping
from broken_envs import NAN_REACH_ID
from flag_lists import override
from test_train_failures import under_file_size_limit

from benchmarks.sweep import tiny_flags
from simoun_agent.config import SetupError, resolve, to_dict
from simoun_agent.run import train
from simoun_agent.run.checkpoint import load_checkpoint
from simoun_agent.run.logger import read_csv
from simoun_lab.cli import report as report_cli
from simoun_lab.cli import sweep as cli
from simoun_lab.cli.sweep import base_differences
from simoun_lab.sweep.grid import (
    SWEEP_FILE,
    SweepSpec,
    check_devices,
    check_trial_dirs,
    config_differences,
    parse_seeds,
    split_values,
    trial_problem,
)
from simoun_lab.sweep.launch import gpus_per_trial
from simoun_lab.sweep.trainable import finished, open_run

TINY = override(
    tiny_flags(total_env_steps=60),
    *("--image-size", "24", "--eval-every", "20", "--checkpoint-every", "20"),
)
"""The benchmark's tiny PointReach run, shorter (40 updates after 20 random steps) and on smaller
frames: the sweep's machinery is under test, not learning. PointReach's episodes last 20 steps,
and an evaluation waits for an episode's end, so every step count here is a multiple of 20."""


def tiny_without(flag: str) -> list[str]:
    """TINY less one flag and its value (for a key the grid gives instead)."""
    at = TINY.index(flag)
    return TINY[:at] + TINY[at + 2 :]


def run_dirs(sweep_dir: Path) -> list[Path]:
    return sorted(p.parent for p in sweep_dir.glob("*/*/s*/config.json"))


def tune_results(sweep_dir: Path, experiment: int = -1) -> dict[str, list[dict]]:
    """What each trial reported to Tune (its result.json lines), by trial name."""
    experiments = sorted(p for p in (sweep_dir / "tune").iterdir() if p.is_dir())
    results = {}
    for trial_dir in experiments[experiment].iterdir():
        if (trial_dir / "result.json").is_file():
            lines = (trial_dir / "result.json").read_text().splitlines()
            rows = [json.loads(line) for line in lines]
            results[json.loads((trial_dir / "params.json").read_text())["trial"]] = rows
    return results


def report_rows(sweep_dir: Path) -> list[dict]:
    with (sweep_dir / "report.csv").open(newline="") as f:
        return list(csv.DictReader(f))


@pytest.fixture(scope="module")
def sweep_dir(ray_address, tmp_path_factory):
    """2 recipes x 2 seeds, run once for the tests that read it."""
    sweep_dir = tmp_path_factory.mktemp("sweeps") / "recipes"
    argv = [*TINY, "--grid", "agent.recipe=drq,sac", "--seeds", "0-1", "--verbose", "0"]
    assert cli.main([*argv, "--sweep-dir", str(sweep_dir)]) == 0
    return sweep_dir


def test_grid_of_two_recipes_and_two_seeds_makes_four_runs_and_a_report(sweep_dir):
    dirs = run_dirs(sweep_dir)
    assert [d.relative_to(sweep_dir).as_posix() for d in dirs] == [
        "agent.recipe=drq/simoun-PointReach-v0/s0",
        "agent.recipe=drq/simoun-PointReach-v0/s1",
        "agent.recipe=sac/simoun-PointReach-v0/s0",
        "agent.recipe=sac/simoun-PointReach-v0/s1",
    ]
    for run_dir in dirs:
        config = json.loads((run_dir / "config.json").read_text())
        assert config["agent"]["recipe"] == run_dir.parts[-3].split("=")[1]
        assert config["seed"] == int(run_dir.name[1:])
        assert config["torch_threads"] == 1  # one torch thread per CPU of the trial
        assert (run_dir / "summary.json").is_file()
    rows = report_rows(sweep_dir)
    assert [(row["variant"], row["n"]) for row in rows] == [
        ("agent.recipe=drq", "2"),
        ("agent.recipe=sac", "2"),
    ]
    table = (sweep_dir / "report.md").read_text()
    assert "| agent.recipe=drq | simoun-PointReach-v0 | 2 |" in table
    for png in ("curves_env_steps.png", "curves_wall_time.png"):
        assert (sweep_dir / png).stat().st_size > 1000


def test_trials_report_each_evaluation_to_tune(sweep_dir):
    reported = tune_results(sweep_dir)
    assert len(reported) == 4
    for name, rows in reported.items():
        run_dir = sweep_dir / name
        logged = read_csv(run_dir / "eval.csv")
        assert [row["env_step"] for row in rows] == [0, 20, 40, 60]
        assert [row["return_mean"] for row in rows] == [row["return_mean"] for row in logged]


def test_a_failing_trial_is_reported_and_the_others_finish(ray_address, tmp_path, capsys):
    # NanReach (tests/broken_envs.py) with nan_reward is made, reset and rendered as PointReach
    # is, so it passes every check before Ray, but its rewards are NaN: that trial stops inside
    # Ray at its first step, the other one finishes.
    sweep_dir = tmp_path / "failing"
    argv = override(TINY, "--env", f"broken_envs:{NAN_REACH_ID}")
    argv += ["--grid", 'env_kwargs={"nan_reward": true},{}']
    argv += ["--seeds", "0", "--sweep-dir", str(sweep_dir)]
    assert cli.main([*argv, "--verbose", "0"]) == 1
    bad, good = sorted(sweep_dir.glob("env_kwargs=*"), key=lambda p: len(p.name), reverse=True)
    assert (good / "simoun-test-NanReach-v0/s0/summary.json").is_file()
    assert not (bad / "simoun-test-NanReach-v0/s0/summary.json").exists()
    error = (bad / "simoun-test-NanReach-v0/s0/error.txt").read_text()
    assert "the evaluation env returned the reward nan at step 1" in error
    assert "TypeError" not in error  # the trial's own error, not Ray's failure to copy it
    err = capsys.readouterr().err
    assert 'FAILED env_kwargs={"nan_reward":true}/simoun-test-NanReach-v0/s0' in err
    assert "--resume" in err
    assert [row["n"] for row in report_rows(sweep_dir)] == ["0", "1"]
    assert "## Failed runs" in (sweep_dir / "report.md").read_text()


def test_an_env_kwarg_the_env_refuses_is_named_before_ray_starts(tmp_path, capsys):
    sweep_dir = tmp_path / "refused"
    argv = [*TINY, "--grid", 'env_kwargs={"step_size": NaN},{}', "--sweep-dir", str(sweep_dir)]
    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    said = "simoun/PointReach-v0 cannot use step_size=NaN (making it failed: step_size must be a"
    assert said in err
    assert "Traceback" not in err


def test_cameras_and_env_kwargs_a_trial_fails_on_are_named_before_ray_starts(tmp_path, capsys):
    dmc = override(TINY, "--env", "dm_control/cartpole-swingup-v0")
    grids = {
        "cameras=2,3": "--cameras 3: dm_control/cartpole-swingup-v0 has only 2 cameras",
        'env_kwargs={"render_kwargs": {"camera_id": 7}},{}': "render_kwargs.camera_id=7 is not a "
        "camera of dm_control/cartpole-swingup-v0",
    }
    for grid, said in grids.items():
        sweep_dir = tmp_path / "refused"
        with pytest.raises(SystemExit) as exit_info:
            cli.main([*dmc, "--grid", grid, "--sweep-dir", str(sweep_dir)])
        assert exit_info.value.code == 2
        err = capsys.readouterr().err
        assert said in err and "Traceback" not in err, err


def test_interrupted_sweep_resumes_only_the_unfinished_trials(ray_address, tmp_path):
    sweep_dir = tmp_path / "interrupted"
    # The two short trials are scheduled first (2 CPUs, 1 per trial) and finish; Ctrl-C comes
    # once both have and a long one has written a checkpoint, well before it can finish. (Under
    # load the first long trial can checkpoint while the second short one still runs: CI saw it,
    # so the test waits for both conditions; the second long trial starts only after both.)
    argv = [*tiny_without("--total-env-steps"), "--grid", "total_env_steps=40,160"]
    argv += ["--seeds", "0-1", "--sweep-dir"]
    argv += [str(sweep_dir), "--address", ray_address, "--verbose", "0"]
    command = [sys.executable, "-m", "simoun_lab.cli.sweep", *argv]
    log = tmp_path / "sweep.log"  # a file, not a pipe nobody reads until the end
    with log.open("w") as out:
        proc = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, text=True)
    long_runs = [sweep_dir / f"total_env_steps=160/simoun-PointReach-v0/s{s}" for s in (0, 1)]
    short_runs = [sweep_dir / f"total_env_steps=40/simoun-PointReach-v0/s{s}" for s in (0, 1)]

    def ready() -> bool:
        shorts_done = all((d / "summary.json").exists() for d in short_runs)
        return shorts_done and any(
            (d / "checkpoint.pt").exists() and not (d / "summary.json").exists() for d in long_runs
        )

    deadline = time.monotonic() + 300  # generous: a loaded CI machine must not fail the test
    while not ready():
        assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
        time.sleep(0.1)
    proc.send_signal(signal.SIGINT)
    proc.wait(timeout=300)  # generous: a loaded CI machine must not fail the test
    output = log.read_text()
    assert proc.returncode == 130, output
    assert "simoun-sweep --resume --sweep-dir" in output

    summaries = {d: (d / "summary.json").read_bytes() for d in short_runs}
    unfinished = [d for d in long_runs if not (d / "summary.json").exists()]
    assert unfinished
    checkpointed = [d for d in unfinished if (d / "checkpoint.pt").exists()]
    assert checkpointed

    resumed = [*argv, "--resume"]
    result = subprocess.run(
        [sys.executable, "-m", "simoun_lab.cli.sweep", *resumed],
        capture_output=True,
        text=True,
        timeout=600,  # generous: a loaded CI machine must not fail the test
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert f"{len(unfinished)} trials to run, {4 - len(unfinished)} already finished" in (
        result.stdout
    )
    reported = tune_results(sweep_dir)  # the resumed part's Tune experiment
    assert sorted(reported) == sorted(d.relative_to(sweep_dir).as_posix() for d in unfinished)
    for run_dir in checkpointed:  # went on from its checkpoint: no evaluation at step 0 again
        assert reported[run_dir.relative_to(sweep_dir).as_posix()][0]["env_step"] > 0
    assert {d: (d / "summary.json").read_bytes() for d in short_runs} == summaries
    assert all((d / "summary.json").is_file() for d in long_runs)
    assert [row["n"] for row in report_rows(sweep_dir)] == ["2", "2"]


def test_sigterm_stops_every_trial_with_a_checkpoint_and_resume_finishes(ray_address, tmp_path):
    sweep_dir = tmp_path / "terminated"
    # one long trial, no periodic checkpoint: the only checkpoint is the one SIGTERM asks for
    argv = [*tiny_without("--total-env-steps"), "--total-env-steps", "100000"]
    at = argv.index("--checkpoint-every")
    argv[at + 1] = "1000000000"
    argv += ["--seeds", "0", "--sweep-dir", str(sweep_dir), "--address", ray_address]
    argv += ["--verbose", "0"]
    command = [sys.executable, "-m", "simoun_lab.cli.sweep", *argv]
    log = tmp_path / "sweep.log"
    with log.open("w") as out:
        proc = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, text=True)
    run_dir = sweep_dir / "base/simoun-PointReach-v0/s0"
    deadline = time.monotonic() + 120
    while not (run_dir / "train.csv").exists():
        assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
        time.sleep(0.1)
    sent = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=300)  # generous: a loaded CI machine must not fail the test
    output = log.read_text()
    assert proc.returncode == 143, output
    # the stop must not wait for the 100k-step trial (minutes); 90 s leaves room for a loaded box
    assert time.monotonic() - sent < 90, output
    assert "simoun-sweep --resume --sweep-dir" in output
    assert not (run_dir / "summary.json").exists() and not (sweep_dir / "STOP").exists()
    stopped_at = load_checkpoint(run_dir)["state"]["env_step"]
    assert stopped_at > 0

    # the trial's run directory is an ordinary run: simoun-train continues it from the checkpoint
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "simoun_agent.cli.train",
            "--resume",
            str(run_dir),
            "--total-env-steps",
            str(stopped_at + 20),
        ],
        capture_output=True,
        text=True,
        timeout=600,  # generous: a loaded CI machine must not fail the test
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert json.loads((run_dir / "summary.json").read_text())["env_step"] >= stopped_at + 20


def error_of(argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)
    assert exit_info.value.code == 2
    return capsys.readouterr().err


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--grid", "agent.lrr=1e-3"], "unknown config key 'agent.lrr' (did you mean agent.lr?)"),
        (["--grid", "image_size=32,48"], "image_size is given both as a base flag and in --grid"),
        (["--grid", "agent.recipe=drqq,sac"], "--agent.recipe 'drqq' (did you mean 'drq'?)"),
        (["--grid", "agent.lr="], "has an empty value"),
        (["--grid", "agent.lr"], "--grid takes KEY=V1,V2"),
        (["--grid", "agent.lr=1e-3,,3e-4"], "has an empty value"),
        (["--grid", "seed=1,2"], "use --seeds"),
        (["--grid", "seeds=1,2"], "unknown config key 'seeds' (the sweep sets seed itself: give it "
         "as --seeds)"),
        (["--seeds", "5-2"], "the range '5-2' runs backwards; write it low-high, e.g. --seeds 2-5"),
        (["--seeds", "a"], "cannot read 'a'"),
        (["--seed", "3", "--seeds", "0-1"], "give the seeds once"),
        (["--torch-threads", "2"], "use --cpus-per-trial"),
        (["--cpus-per-trial", "0"], "--cpus-per-trial must be at least 1, got 0"),
        (["--envs", "simoun/PointReach-v0,"], "--envs 'simoun/PointReach-v0,' has an empty id"),
        (["--envs", "simoun/PointReach-v0", "--env", "simoun/PointReach-v0"], "give the envs once"),
        (
            ["--envs", "simoun/PointReach-v0,dm_control/cartpole-swingup-v1"],
            "--envs dm_control/cartpole-swingup-v1: unknown environment id "
            "'dm_control/cartpole-swingup-v1'; did you mean dm_control/cartpole-swingup-v0",
        ),
        (["--envs", "CartPole-v1"], "--envs CartPole-v1: CartPole-v1 has action space Discrete(2)"),
        (["--envs", "simoun/PointReach-v0;Pendulum-v1"], "--envs 'simoun/PointReach-v0;Pendulum-v1'"
         ": values separated by ';'; --envs takes comma-separated values, e.g. --envs "
         "simoun/PointReach-v0,Pendulum-v1"),
        (["--envs", "simoun/PointReach-v0 | Pendulum-v1"], "e.g. --envs "
         "simoun/PointReach-v0,Pendulum-v1"),
        (["--envs", "simoun/PointReach-v0 Pendulum-v1"], "values separated by ' '"),
        (["--seeds", "0;1"], "--seeds takes comma-separated values, e.g. --seeds 0,1"),
        (["--grid", "agent.lr=1e-3|3e-4"], "e.g. --grid agent.lr=1e-3,3e-4"),
        (["--envs", "NoSuchEnv-v0"], "or MODULE:ID (e.g. minigrid:"),
        (["--env", "MiniGrid-Empty-5x5-v0", "--env-module", "minigrid"], "Discrete(7)"),
        (["--grid", "agent.lr=[1e-3,3e-4]"], "--grid 'agent.lr=[1e-3,3e-4]': --grid takes each "
         "value, comma-separated, not a list in brackets; write --grid agent.lr=1e-3,3e-4"),
        (["--grid", "agent.n_step=(1, 3)"], "write --grid agent.n_step=1,3"),
        (["--grid", "agent.n_step=1-3"], "--grid 'agent.n_step=1-3': --grid takes each value, "
         "comma-separated, not a range; write --grid agent.n_step=1,2,3"),
        (["--grid", "agent.lr=fast"], "--grid 'agent.lr=fast': cannot read agent.lr='fast': "
         "expected float; --grid takes comma-separated values, e.g. --grid agent.lr=V1,V2"),
        (["--seeds", "[0,1]"], "--seeds takes the seeds comma-separated, not a list in brackets; "
         "write --seeds 0,1"),
        (["--envs", "[simoun/PointReach-v0, Pendulum-v1]"], "write --envs "
         "simoun/PointReach-v0,Pendulum-v1"),
        (["--grid", "eval_distraction=color_easy,color_hard"], "--grid eval_distraction "
         "color_easy needs a dm_control task (it recolours or re-renders a MuJoCo scene), but "
         "this run trains on simoun/PointReach-v0; leave color_easy out of --grid "
         "eval_distraction"),
        (["--eval-distraction", "video_hard"], "trial base/simoun-PointReach-v0/s1: "
         "--eval-distraction video_hard needs a dm_control task"),
        (["--grid", "action_repeat=1,100"], "trial action_repeat=100/simoun-PointReach-v0/s1: "
         "--action-repeat 100 (TrainConfig.action_repeat) is longer than the whole run"),
        (["--grid", "action_repeat=1,15"], "trial action_repeat=15/simoun-PointReach-v0/s1: "
         "--action-repeat 15 (TrainConfig.action_repeat): an episode of simoun/PointReach-v0 "
         "ends after 20 env steps"),
        (["--gpus-per-trial", "0.5"], "--gpus-per-trial 0.5 and --device cpu contradict each "
         "other: each trial would reserve 0.5 GPUs it never uses"),
        # a preset only labels a run under --grid: its values come with --preset, one a sweep
        (["--grid", "preset=cpu,highway-cpu"], "--grid preset=cpu,highway-cpu: --grid cannot "
         "vary the preset: the config key preset only labels a run"),
        (["--grid", "preset=cpu"], "run one sweep per preset, each with its own --preset and "
         "--sweep-dir"),
        # a text key reads a bracketed list as one value
        (["--grid", "agent.recipe=['simoun','drq']"], "--grid \"agent.recipe=['simoun','drq']\": "
         "--grid takes each value, comma-separated, not a list in brackets; write --grid "
         "agent.recipe=simoun,drq"),
        (["--grid", "agent.encoder=(stacked, single)"], "write --grid "
         "agent.encoder=stacked,single"),
        # a per-trial check of a --grid value sends the fix to --grid, not to the base flag
        (["--grid", "env_module=nosuchmodule,none"], "trial env_module=nosuchmodule/"
         "simoun-PointReach-v0/s1: --env-module 'nosuchmodule' is not installed, so the ids it "
         "registers are unknown; pip install nosuchmodule (or the package that provides "
         "nosuchmodule); --env-module nosuchmodule is this trial's value from --grid "
         "env_module=nosuchmodule,none: make the fix in --grid"),
        (["--grid", 'env_kwargs={"a":1},{}'], "simoun/PointReach-v0 takes no keyword 'a'; it "
         'accepts: max_steps, size, step_size; --env-kwargs {"a":1} is this trial\'s value from '
         "--grid"),
        (["--grid", "action_repeat=1,100"], "or --total-env-steps many times 100; "
         "--action-repeat 100 is this trial's value from --grid action_repeat=1,100: make the "
         "fix in --grid (leave 100 out of its values"),
    ],
)  # fmt: skip
def test_bad_grid_input_fails_before_anything_runs(flags, message, tmp_path, capsys):
    sweep_dir = tmp_path / "bad"
    base = tiny_without("--env") if {"--envs", "--env"} & set(flags) else TINY
    err = error_of([*base, *flags, "--sweep-dir", str(sweep_dir)], capsys)
    assert message in err
    assert not sweep_dir.exists()


def test_a_cuda_trial_given_no_gpu_is_refused_naming_both_flags(tmp_path):
    for grid, said in (({}, "--device cuda"), ({"device": ["cuda", "cpu"]}, "--grid device=cuda")):
        base = {} if grid else {"device": "cuda"}
        spec = SweepSpec(None, base, grid, [0], ["simoun/PointReach-v0"])
        with pytest.raises(SetupError) as refused:
            check_devices(spec.trials(tmp_path), 0.0, grid)
        assert f"--gpus-per-trial 0 and {said}" in str(refused.value)
        assert "set --gpus-per-trial to 1" in str(refused.value)
        check_devices(spec.trials(tmp_path), None, grid)  # auto follows the device
    cpu = SweepSpec(None, {"device": "cpu"}, {}, [0], ["simoun/PointReach-v0"])
    check_devices(cpu.trials(tmp_path), 0.0, {})


def test_a_replay_or_a_batch_the_run_cannot_hold_is_refused_before_ray_starts(tmp_path, capsys):
    tiny = tiny_without("--replay-capacity")
    # full, a replay of 50 keeps 49 whole windows of PointReach's 20-step episodes
    small = ["agent.batch_size=50" if a == "agent.batch_size=8" else a for a in tiny]
    argv = [*small, "--grid", "replay_capacity=50,1000", "--sweep-dir", str(tmp_path / "r")]
    err = error_of(argv, capsys)
    assert "trial replay_capacity=50/simoun-PointReach-v0/s1: --replay-capacity 50 keeps" in err
    assert "fewer than a batch of 50 (--agent.batch-size 50)" in err
    assert "Set --replay-capacity 54 or more" in err
    # 512x512 frames at a batch of 512: hundreds of GB for one update
    bigger = override(TINY, "--image-size", "512")
    bigger = ["agent.batch_size=512" if a == "agent.batch_size=8" else a for a in bigger]
    err = error_of([*bigger, "--sweep-dir", str(tmp_path / "r")], capsys)
    assert re.search(
        r"trial base/simoun-PointReach-v0/s\d: --image-size 512 with --agent.batch-size 512", err
    )
    assert "so the run would be killed" in err
    assert not (tmp_path / "r").exists()


def test_resume_with_another_grid_is_refused_and_changes_nothing(sweep_dir, capsys):
    saved = (sweep_dir / SWEEP_FILE).read_bytes()
    experiments = sorted((sweep_dir / "tune").iterdir())
    argv = [*TINY, "--grid", "agent.recipe=drq,curl", "--seeds", "0-1", "--resume"]
    err = error_of([*argv, "--sweep-dir", str(sweep_dir)], capsys)
    assert "was started with another grid" in err
    assert '--grid: saved {"agent.recipe": ["drq", "sac"]}' in err
    # starting a new sweep over it is refused too
    err = error_of([*TINY, "--seeds", "0", "--sweep-dir", str(sweep_dir)], capsys)
    assert "already holds a sweep; continue it with --resume" in err
    assert (sweep_dir / SWEEP_FILE).read_bytes() == saved
    assert sorted((sweep_dir / "tune").iterdir()) == experiments


def test_resume_of_a_finished_sweep_runs_nothing(sweep_dir, capsys):
    summaries = {d: (d / "summary.json").read_bytes() for d in run_dirs(sweep_dir)}
    assert cli.main(["--resume", "--sweep-dir", str(sweep_dir)]) == 0
    assert "0 trials to run, 4 already finished" in capsys.readouterr().out
    assert {d: (d / "summary.json").read_bytes() for d in run_dirs(sweep_dir)} == summaries


def test_a_finished_sweep_extended_with_total_env_steps_trains_each_run_on(
    ray_address, tmp_path, capsys
):
    sweep_dir = tmp_path / "extended"
    argv = [*TINY, "--seeds", "0", "--sweep-dir", str(sweep_dir), "--address", ray_address]
    assert cli.main([*argv, "--verbose", "0"]) == 0
    run_dir = sweep_dir / "base/simoun-PointReach-v0/s0"
    assert json.loads((run_dir / "summary.json").read_text())["env_step"] == 60
    capsys.readouterr()

    err = error_of(["--resume", "--sweep-dir", str(sweep_dir), "--total-env-steps", "40"], capsys)
    assert "--total-env-steps 40 is below the sweep's 60" in err
    extend = ["--resume", "--sweep-dir", str(sweep_dir), "--total-env-steps", "120"]
    assert cli.main([*extend, "--address", ray_address, "--verbose", "0"]) == 0
    assert "1 trials to run, 0 already finished" in capsys.readouterr().out
    # went on from the final checkpoint: the evaluations continue the grid, none repeated
    evaluated = [row["env_step"] for row in read_csv(run_dir / "eval.csv")]
    assert evaluated == [0, 20, 40, 60, 80, 100, 120]
    assert json.loads((run_dir / "summary.json").read_text())["env_step"] == 120
    assert json.loads((sweep_dir / SWEEP_FILE).read_text())["base"]["total_env_steps"] == 120
    assert cli.main(["--resume", "--sweep-dir", str(sweep_dir)]) == 0
    assert "0 trials to run, 1 already finished" in capsys.readouterr().out


def test_unreachable_address_fails_within_seconds(tmp_path):
    with socket.socket() as sock:  # a port nothing listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    argv = [*TINY, "--seeds", "0", "--sweep-dir", str(tmp_path / "s")]
    start = time.monotonic()
    result = subprocess.run(
        [sys.executable, "-m", "simoun_lab.cli.sweep", *argv, "--address", f"127.0.0.1:{port}"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    # Ray's own GCS wait is minutes; the probe answers in CONNECT_TIMEOUT_S (5 s) plus the
    # interpreter and imports, which a loaded CI machine can stretch to tens of seconds
    assert time.monotonic() - start < 60
    assert result.returncode == 2
    assert f"--address 127.0.0.1:{port}: no Ray cluster answers" in result.stderr
    assert "ray start --head" in result.stderr
    assert not (tmp_path / "s").exists()


def test_without_ray_the_sweep_says_how_to_install_it(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "ray", None)  # what `import ray` meets when not installed
    err = error_of([*TINY, "--seeds", "0", "--sweep-dir", str(tmp_path / "s")], capsys)
    assert "pip install 'simoun[lab]'" in err


def test_seeds_and_grid_values_parse():
    assert parse_seeds("0-2,5") == [0, 1, 2, 5]
    assert parse_seeds("3") == [3]
    assert split_values('1e-3, {"a": [1, 2]},"x,y"') == ["1e-3", '{"a": [1, 2]}', '"x,y"']


BASE = {
    "env": "simoun/PointReach-v0",
    "image_size": 24,
    "total_env_steps": 40,
    "warmup_agent_steps": 20,
    "replay_capacity": 1000,
    "eval_every": 20,
    "eval_episodes": 1,
    "checkpoint_every": 20,
    "video": False,
    "device": "cpu",
    "agent.batch_size": 8,
    "agent.num_filters": 8,
    "agent.feature_dim": 16,
    "agent.hidden_dim": 32,
    "agent.aux_hidden_dim": 32,
}
"""TINY as a sweep's base config, shorter still (20 updates)."""

TRIAL = "base/simoun-PointReach-v0/s{}"


@pytest.fixture(scope="module")
def trained_sweep(tmp_path_factory):
    """A finished sweep of seeds 1 and 2, its trials trained here without Ray as the sweep
    trains them: what simoun-sweep leaves."""
    sweep_dir = tmp_path_factory.mktemp("sweeps") / "trained"
    sweep_dir.mkdir()
    spec = SweepSpec.create(None, BASE, [], "1-2", None)
    spec.save(sweep_dir)
    for trial in spec.trials(sweep_dir):
        run = train.create_run(resolve(trial.preset, trial.overrides))
        train.train(run)
        run.env.close()
        run.eval_env.close()
        train.release(run)
    return sweep_dir


def copy_sweep(sweep_dir: Path, tmp_path: Path) -> Path:
    return Path(shutil.copytree(sweep_dir, tmp_path / "sw"))


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        (["--seeds", "0-3"], "(--seeds: saved [1, 2], given [0, 1, 2, 3])"),
        (["--grid", "agent.lr=1e-3,3e-4"], '--grid: saved {}, given {"agent.lr": [0.001, 0.0003]}'),
        (["--cpus-per-trial", "2"], "(--cpus-per-trial: saved 1, given 2)"),
        (["--eval-every", "40", "--seeds", "1-2"], "(--eval-every: saved 20, given 40)"),
        (
            ["--cpus-per-trial", "2", "--agent.lr", "0.01", "--preset", "cpu"],
            '(--preset: saved null, given "cpu"; --agent.lr: saved 0.001, given 0.01; '
            "--cpus-per-trial: saved 1, given 2)",
        ),
    ],
)  # fmt: skip
def test_a_resume_refusal_names_only_the_flags_given_that_differ(
    trained_sweep, tmp_path, capsys, flags, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir), *flags], capsys)
    assert f"the sweep in {sweep_dir} was started with another grid" in err
    assert said in err
    assert "--envs" not in err and "base config" not in err


def test_a_resume_with_flags_equal_to_the_saved_ones_goes_on(trained_sweep, tmp_path, capsys):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    argv = ["--resume", "--sweep-dir", str(sweep_dir), "--seeds", "1-2", "--eval-every", "20"]
    assert cli.main([*argv, "--env", "simoun/PointReach-v0", "--cpus-per-trial", "1"]) == 0
    assert "0 trials to run, 2 already finished" in capsys.readouterr().out


SWEEP_JSON_DAMAGES = [
    (lambda d: d.update(seeds="1"), 'seeds is "1", not a list of seeds'),
    (lambda d: d.update(seeds=[1, 1]), "seeds is [1, 1], not a list of seeds"),
    (lambda d: d.update(seeds=[True]), "seeds is [true], not a list of seeds"),
    (lambda d: d.update(envs=[]), "envs is [], not a list of Gymnasium ids"),
    (lambda d: d.update(envs="simoun/PointReach-v0"), 'envs is "simoun/PointReach-v0", not a list'),
    (lambda d: d.update(grid={"agent.lr": 0.001}), "grid: agent.lr is 0.001, not a non-empty list"),
    (lambda d: d.update(grid={"agent.lr": []}), "grid: agent.lr is [], not a non-empty list"),
    (lambda d: d.update(grid={"agent.lr": ["x"]}), 'grid: agent.lr is "x", which must be a number'),
    (lambda d: d.update(grid={"seed": [1, 2]}), "grid varies seed, which the sweep sets"),
    (lambda d: d.update(grid={"preset": ["cpu", "highway-cpu"]}), "grid varies preset, which "
     "only labels a run: a sweep has one preset"),
    (lambda d: d.update(grid=[]), "grid is [], not a JSON object"),
    (lambda d: d.update(preset="cpux"), "preset is \"cpux\", which is no preset (did you mean"),
    (lambda d: d["base"].update(nope=1), "base: 'nope' is no config key"),
    (lambda d: d["base"].update(eval_every=0), "base: eval_every is 0, which must be an int >= 1"),
    (lambda d: d["base"].update(torch_threads=0), "base sets torch_threads, which the sweep sets"),
    (lambda d: d.update(base=None), "base is null, not a JSON object of config keys"),
    (lambda d: d.update(cpus_per_trial=0), "cpus_per_trial is 0, not an integer >= 1"),
    (lambda d: d.update(cpus_per_trial="2"), 'cpus_per_trial is "2", not an integer >= 1'),
    (lambda d: d.pop("envs"), "it has no envs, which every sweep records"),
    (lambda d: d.update(nope=1), "it holds the key 'nope', which no sweep writes"),
    (lambda d: d.update(preset="cartpole-swingup"), "preset 'cartpole-swingup' is meant for "
     "dm_control/cartpole-swingup-v0, but envs lists 'simoun/PointReach-v0'"),
]  # fmt: skip


@pytest.mark.parametrize("command", ["report", "resume"])
@pytest.mark.parametrize(("edit", "said"), SWEEP_JSON_DAMAGES)
def test_a_sweep_json_edited_out_of_what_a_sweep_accepts_is_named(
    trained_sweep, tmp_path, capsys, command, edit, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    path = sweep_dir / SWEEP_FILE
    saved = json.loads(path.read_text())
    edit(saved)
    path.write_text(json.dumps(saved))
    main = report_cli.main if command == "report" else cli.main
    argv = [str(sweep_dir)] if command == "report" else ["--resume", "--sweep-dir", str(sweep_dir)]
    err = error_of_main(main, argv, capsys)
    assert f"{path} is damaged ({said}" in err
    assert "restore it from a copy" in err and "start a new sweep in a new --sweep-dir" in err
    assert "--seed " not in err and "--torch-threads" not in err and "Traceback" not in err


def error_of_main(main, argv: list[str], capsys) -> str:
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    return capsys.readouterr().err


def another_env(run_dir: Path) -> None:
    config = json.loads((run_dir / "config.json").read_text())
    (run_dir / "config.json").write_text(json.dumps({**config, "env": "Pendulum-v1"}))


def another_seed(run_dir: Path) -> None:
    config = json.loads((run_dir / "config.json").read_text())
    (run_dir / "config.json").write_text(json.dumps({**config, "seed": 2}))


def config_removed(run_dir: Path) -> None:
    (run_dir / "config.json").unlink()


def summary_over_config(run_dir: Path) -> None:
    shutil.copyfile(run_dir / "summary.json", run_dir / "config.json")


TRIAL_DAMAGES = [
    (another_env, "config.json records env Pendulum-v1, but the sweep's trial "
     f"{TRIAL.format(1)} has simoun/PointReach-v0: it is another run's config"),
    (another_seed, f"config.json records seed 2, but the sweep's trial {TRIAL.format(1)} has 1"),
    (config_removed, "config.json is missing, though the run's other files are there"),
    (summary_over_config, "config.json is damaged: it holds summary.json's keys (env_step, "
     "final_eval), not config.json's (it has no env, seed, agent): summary.json was copied over "
     "it"),
]  # fmt: skip


@pytest.mark.parametrize(("damage", "said"), TRIAL_DAMAGES)
def test_a_trial_run_that_is_not_the_trials_own_is_left_out_of_the_report(
    trained_sweep, tmp_path, damage, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    damage(sweep_dir / TRIAL.format(1))
    assert report_cli.main([str(sweep_dir), "--out", str(tmp_path / "out")]) == 0
    (row,) = list(csv.DictReader((tmp_path / "out" / "report.csv").open()))
    assert (row["env"], row["n"]) == ("simoun-PointReach-v0", "1")
    table = (tmp_path / "out" / "report.md").read_text()
    assert "## Damaged runs (not counted)" in table and f"- {TRIAL.format(1)}: {said}" in table


def test_a_config_copied_over_a_trials_summary_is_named_on_resume(trained_sweep, tmp_path, capsys):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    shutil.copyfile(run_dir / "config.json", run_dir / "summary.json")
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"{run_dir / 'summary.json'} is damaged: it holds config.json's keys" in err
    assert "already finished" not in capsys.readouterr().out


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("", "it is empty"),
        ("garbage\n", "it is not JSON"),
        ('{"env_step": 40, "final_e', "it is not JSON"),
        ("[40]", "it holds an array, not a JSON object"),
        ('{"env_step": "40", "final_eval": {"return_mean": 1.0}}', 'its env_step is "40"'),
        ('{"env_step": 40, "final_eval": null}', "it has no finite final_eval.return_mean"),
    ],
)
def test_an_unreadable_trial_summary_is_refused_on_resume_not_counted_finished(
    trained_sweep, tmp_path, capsys, text, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    (run_dir / "summary.json").write_text(text)
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(1)}: {run_dir / 'summary.json'} is damaged: {said}" in err
    assert f"remove it (rm {run_dir / 'summary.json'}) so that the resume writes" in err
    assert f"move the run directory aside (mv {run_dir} {run_dir}.aside)" in err
    assert "Traceback" not in err and "already finished" not in capsys.readouterr().out


def test_a_trial_whose_damaged_summary_was_removed_gets_its_end_written_again(
    trained_sweep, tmp_path
):
    """The first fix of the refusal above: the trial (as a resumed sweep trains it) writes its
    summary.json again from its checkpoint, its eval.csv as it was."""
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    spec = SweepSpec.load(sweep_dir)
    trial = spec.trials(sweep_dir)[0]
    run_dir = Path(trial.run_dir)
    kept = json.loads((run_dir / "summary.json").read_text())
    evaluations = (run_dir / "eval.csv").read_text()
    (run_dir / "summary.json").unlink()
    assert not finished(trial)
    run = open_run(trial)
    train.train(run)
    train.release(run)
    assert json.loads((run_dir / "summary.json").read_text())["final_eval"] == kept["final_eval"]
    assert (run_dir / "eval.csv").read_text() == evaluations and finished(trial)


@pytest.mark.parametrize(("damage", "said"), TRIAL_DAMAGES)
def test_a_trial_run_that_is_not_the_trials_own_is_refused_on_resume(
    trained_sweep, tmp_path, capsys, damage, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    damage(run_dir)
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(1)}: {run_dir / said}" in err
    assert f"move the run directory aside (mv {run_dir} {run_dir}.aside)" in err
    assert "already finished" not in capsys.readouterr().out


@pytest.mark.parametrize(
    ("key", "value", "said"),
    [
        ("agent.lr", 0.01, "agent.lr 0.001 where the sweep gives 0.01"),
        ("image_size", 48, "image_size 24 where the sweep gives 48"),
        ("agent.recipe", "drq", "agent.recipe none where the sweep gives drq"),
    ],
)
def test_a_sweep_json_base_changed_after_its_trials_ran_is_refused_on_resume(
    trained_sweep, tmp_path, capsys, key, value, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    path = sweep_dir / "sweep.json"
    saved = json.loads(path.read_text())
    saved["base"][key] = value
    path.write_text(json.dumps(saved))
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(1)} was trained with {said}" in err
    assert f"{path} was changed after the trial started" in err
    assert "Restore sweep.json as it was" in err and "a new --sweep-dir" in err
    assert "already finished" not in capsys.readouterr().out


def test_a_trial_config_differing_from_a_default_names_the_version_as_a_cause(
    trained_sweep, tmp_path, capsys
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    path = sweep_dir / TRIAL.format(2) / "config.json"
    config = json.loads(path.read_text())
    default = config["agent"]["critic_tau"]
    config["agent"]["critic_tau"] = default / 2  # a default that changed since the trial ran
    path.write_text(json.dumps(config))
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(2)} was trained with agent.critic_tau {default / 2}" in err
    assert "or this version of simoun gives a default another value" in err
    assert "resume with the version of simoun that started the sweep" in err


def test_a_sweep_extended_or_given_other_cpus_on_resume_keeps_its_trials(trained_sweep, tmp_path):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    spec = SweepSpec.load(sweep_dir)
    check_trial_dirs(spec.extended(2 * spec.total_env_steps()), sweep_dir)
    check_trial_dirs(dataclasses.replace(spec, cpus_per_trial=2), sweep_dir)


def test_a_sweep_loads_from_its_directory_or_its_sweep_json(trained_sweep):
    spec = SweepSpec.load(trained_sweep)
    assert SweepSpec.load(trained_sweep / "sweep.json") == spec
    assert SweepSpec.load(str(trained_sweep)) == spec


def test_an_emptied_trial_is_listed_by_the_report_and_trained_anew_on_resume(
    trained_sweep, tmp_path
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    shutil.rmtree(run_dir)
    run_dir.mkdir()
    assert report_cli.main([str(sweep_dir), "--out", str(tmp_path / "out")]) == 0
    table = (tmp_path / "out" / "report.md").read_text()
    assert f"- {TRIAL.format(1)}: its directory is empty (the trial has not started" in table
    spec = SweepSpec.load(sweep_dir)
    check_trial_dirs(spec, sweep_dir)  # nothing to refuse: the trial starts over


def linked_to_nothing(run_dir: Path) -> None:
    shutil.rmtree(run_dir)
    run_dir.symlink_to("nowhere")


def linked_to_its_folder(run_dir: Path) -> None:
    shutil.rmtree(run_dir)
    run_dir.symlink_to("..")


TRIAL_LINKS = [
    (linked_to_nothing, "it is a symbolic link to nowhere, which does not exist"),
    (linked_to_its_folder, "it is a symbolic link to .., a folder it is in (a loop)"),
]


@pytest.mark.parametrize(("damage", "said"), TRIAL_LINKS)
def test_a_trial_linked_to_nothing_or_to_its_own_folder_is_named_by_resume_and_report(
    trained_sweep, tmp_path, capsys, damage, said
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    damage(run_dir)
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(1)}: {run_dir} (its run directory) is damaged: {said}" in err
    assert f"or remove what stands there (rm {run_dir}) so that the trial trains anew" in err
    assert report_cli.main([str(sweep_dir), "--out", str(tmp_path / "out")]) == 0
    table = (tmp_path / "out" / "report.md").read_text()
    assert f"- {TRIAL.format(1)}: its directory is damaged: {said}" in table


def test_a_trial_moved_out_of_the_sweep_and_linked_back_is_read_as_the_run(trained_sweep, tmp_path):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    shutil.move(run_dir, tmp_path / "outside")
    run_dir.symlink_to(tmp_path / "outside")
    spec = SweepSpec.load(sweep_dir)
    check_trial_dirs(spec, sweep_dir)  # nothing to refuse: the trial is there, finished
    assert all(finished(trial) for trial in spec.trials(sweep_dir))
    assert report_cli.main([str(sweep_dir), "--out", str(tmp_path / "out")]) == 0
    (row,) = list(csv.DictReader((tmp_path / "out" / "report.csv").open()))
    assert row["n"] == "2"


def test_auto_gpus_refuse_a_cuda_trial_on_a_cluster_without_gpus(ray_address):
    assert ray.cluster_resources().get("GPU", 0) == 0  # the tests' local instance
    with pytest.raises(SetupError, match="the Ray cluster has no GPU"):
        gpus_per_trial(ray, "auto", "cuda")
    assert gpus_per_trial(ray, "auto", "mps") == gpus_per_trial(ray, "auto", None) == 0.0


def test_a_finished_trial_whose_logs_cannot_be_read_is_named_before_the_sweep_goes_on(
    trained_sweep, tmp_path, capsys
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(1)
    (run_dir / "eval.csv").write_text(
        "version https://git-lfs.github.com/spec/v1\noid sha256:4d7a\nsize 2086\n"
    )
    err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(1)} is finished, but its run {run_dir} cannot be read" in err
    assert "eval.csv is damaged: it is a Git LFS pointer" in err and "git lfs pull" in err
    assert f"mv {run_dir} {run_dir}.aside" in err
    assert not (sweep_dir / "report").exists()


def test_a_closing_report_that_cannot_be_written_is_named_and_fails_the_sweep(
    trained_sweep, tmp_path, capsys
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    table = sweep_dir / "report.md"
    table.unlink(missing_ok=True)
    table.mkdir()  # where the report writes a file: only moving it aside frees the place
    assert cli.main(["--resume", "--sweep-dir", str(sweep_dir)]) == 1
    err = capsys.readouterr().err
    assert f"report not written: cannot write {table} (it is a directory" in err
    assert f"mv {table} {table}.aside) and run the command again" in err
    assert "--out" not in err  # simoun-sweep has none
    assert f"then write it with: simoun-report {sweep_dir}" in err


def test_a_closing_report_figure_that_does_not_fit_is_named_and_fails_the_sweep(
    trained_sweep, tmp_path
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    argv = ["--resume", "--sweep-dir", str(sweep_dir)]
    done = under_file_size_limit("simoun_lab.cli.sweep", argv)
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    said = re.search(r"report not written: cannot write (\S+): the file is larger", done.stderr)
    assert said and "ulimit -f unlimited" in done.stderr, done.stderr
    assert f"(or write the report with: simoun-report {sweep_dir})" in done.stderr
    assert not list(Path(said[1]).parent.glob(".*.tmp*"))


def test_a_device_spelled_otherwise_on_resume_is_the_same_device(tmp_path):
    env = "simoun/PointReach-v0"
    flags = {"env": env, "image_size": 24, "device": "cpu"}
    saved = SweepSpec(None, flags, {}, [1], [env])
    assert base_differences({"device": "cpu:0"}, saved) == []
    assert base_differences({"device": "cpu:0", "image_size": 32}, saved) == [
        "--image-size: saved 24, given 32"
    ]
    # a trial trained with device cpu is the sweep's own under device cpu:0
    (trial,) = SweepSpec(None, {**flags, "device": "cpu:0"}, {}, [1], [env]).trials(tmp_path)
    run_dir = Path(trial.run_dir)
    run_dir.mkdir(parents=True)
    trained = resolve(None, {**trial.overrides, "device": "cpu"})
    (run_dir / "config.json").write_text(json.dumps(to_dict(trained)))
    assert trial_problem(trial, {}) is None
    assert config_differences(trial) == {}


@contextlib.contextmanager
def trainer_holding(run_dir: Path) -> Iterator[int]:
    """``run_dir``'s lock held as a running trainer holds it (its PID in the file); the PID."""
    with (run_dir / ".lock").open("a+") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        handle.write(f"{os.getpid()}\n")  # after the PID of the trainer that ran before
        handle.flush()
        yield os.getpid()


def test_a_resume_while_a_trial_still_trains_is_refused_before_ray(trained_sweep, tmp_path, capsys):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    run_dir = sweep_dir / TRIAL.format(2)
    (run_dir / "summary.json").unlink()
    with trainer_holding(run_dir) as pid:
        err = error_of(["--resume", "--sweep-dir", str(sweep_dir)], capsys)
    assert f"trial {TRIAL.format(2)} of the sweep in {sweep_dir} is in use by another " in err
    assert f"trainer (PID {pid}): the sweep is still running in another process" in err
    assert f"kill -TERM {pid}" in err and "Traceback" not in err
    assert "trials to run" not in capsys.readouterr().out
    assert not (run_dir / "summary.json").exists()


def test_a_sweep_dir_inside_another_sweep_or_a_study_archive_is_refused(
    trained_sweep, tmp_path, capsys
):
    sweep_dir = copy_sweep(trained_sweep, tmp_path)
    archive = Path(shutil.copytree("docs/studies/dmc100k", tmp_path / "arch"))
    for inside, said in (
        (sweep_dir / "base", f"lies inside {sweep_dir}, a simoun-sweep directory"),
        (archive / "tuning" / "new", f"lies inside {archive}, the archive of a SAC study"),
    ):
        err = error_of([*TINY, "--sweep-dir", str(inside)], capsys)
        assert f"--sweep-dir {inside} {said}" in err and "Traceback" not in err
    assert not (sweep_dir / "base" / "sweep.json").exists()
    assert not (archive / "tuning" / "new").exists()
    cli.check_sweep_place(sweep_dir / "base" / "..")  # the sweep itself, written another way
