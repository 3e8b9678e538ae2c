"""simoun-train / simoun-eval conventions and misuse: boolean switches, --version,
plain status lines without a terminal, resume and rerun mistakes, one trainer per run directory,
no silent overwrite of an evaluation; simoun-eval stops promptly on SIGTERM."""

import ctypes.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import pytest
import torch
from flag_lists import TINY_AGENT, override
from test_train_failures import named_unwritten_file, under_file_size_limit

from simoun_agent.cli import eval as eval_cli
from simoun_agent.cli import train as train_cli
from simoun_agent.run.logger import read_csv

TINY = [
    "--env", "simoun/PointReach-v0",
    "--image-size", "32",
    "--warmup-agent-steps", "10",
    "--eval-every", "20",
    "--eval-episodes", "1",
    "--checkpoint-every", "20",
    *TINY_AGENT,
]  # fmt: skip


def run_flags(run_dir: Path, steps: int = 40, *extra: str) -> list[str]:
    return override(TINY, "--run-dir", str(run_dir), "--total-env-steps", str(steps), *extra)


def exit_message(capsys, main, argv) -> str:
    """The error simoun-train / simoun-eval prints when it refuses ``argv`` (exit status 2)."""
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    assert exit_info.value.code == 2
    return capsys.readouterr().err


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    """A finished 40-step run (evaluations at 0, 20 and 40)."""
    run_dir = tmp_path_factory.mktemp("runs") / "finished"
    assert train_cli.main(run_flags(run_dir, 40, "--no-progress", "--no-video")) == 0
    return run_dir


@pytest.mark.parametrize("main", [train_cli.main, eval_cli.main])
def test_version(main, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert "0." in capsys.readouterr().out


@pytest.mark.parametrize(
    ("switches", "progress", "video"),
    [
        (["--no-progress", "--no-video"], False, False),
        (["--progress", "false", "--video", "false"], False, False),
        (["--progress=no", "--no-video"], False, False),
    ],
)
def test_boolean_switches_and_the_old_spelling(switches, progress, video, tmp_path):
    assert train_cli.main(run_flags(tmp_path / "run", 20, *switches)) == 0
    config = json.loads((tmp_path / "run" / "config.json").read_text())
    assert (config["progress"], config["video"]) == (progress, video)


def test_simoun_eval_takes_the_same_switches(finished, tmp_path):
    out = tmp_path / "ev"
    argv = [str(finished), "--episodes", "1", "--out", str(out), "--no-video", "--no-progress"]
    assert eval_cli.main(argv) == 0
    assert not (out / "video.mp4").exists()
    assert eval_cli.main([*argv[:-2], "--video", "true", "--overwrite"]) == 0
    assert (out / "video.mp4").stat().st_size > 0


def test_without_a_terminal_one_status_line_per_evaluation_and_no_bar(tmp_path):
    run_dir = tmp_path / "run"
    done = subprocess.run(
        [sys.executable, "-m", "simoun_agent.cli.train", *run_flags(run_dir, 40, "--no-video")],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "\r" not in done.stderr and "it/s" not in done.stderr  # no tqdm redraws
    status = [line for line in done.stderr.splitlines() if line.startswith("env step ")]
    assert len(status) == len(read_csv(run_dir / "eval.csv")) == 3, done.stderr
    assert status[-1].startswith("env step 40/40")


def test_resume_to_fewer_steps_than_done_is_refused_and_changes_nothing(finished, capsys):
    before = {name: (finished / name).read_bytes() for name in ("eval.csv", "summary.json")}
    err = exit_message(
        capsys, train_cli.main, ["--resume", str(finished), "--total-env-steps", "20"]
    )
    assert "--total-env-steps 20" in err and "40" in err
    assert {name: (finished / name).read_bytes() for name in before} == before


CRASH_AFTER_FIRST_EVALUATION = """
import os, signal, sys
from simoun_agent.cli import train as train_cli
from simoun_agent.cli import eval as eval_cli
from simoun_agent.run import train

class Crash(train.TrainCallback):
    def on_logged(self, run, metrics):
        os.kill(os.getpid(), signal.SIGKILL)  # as an out-of-memory kill would

plain = train.train
train.train = lambda run, callbacks=(): plain(run, [*callbacks, Crash()])
sys.exit(train_cli.main(sys.argv[1:]))
"""


def test_rerun_after_a_crash_before_the_first_checkpoint_offers_overwrite(tmp_path, capsys):
    run_dir = tmp_path / "run"
    flags = run_flags(run_dir, 20, "--no-progress", "--no-video")
    crashed = subprocess.run(
        [sys.executable, "-c", CRASH_AFTER_FIRST_EVALUATION, *flags],
        capture_output=True,
        timeout=300,
    )
    assert crashed.returncode == -signal.SIGKILL
    assert (run_dir / "config.json").exists() and not (run_dir / "checkpoint.pt").exists()

    assert "--overwrite" in exit_message(capsys, train_cli.main, flags)
    assert "--overwrite" in exit_message(capsys, train_cli.main, ["--resume", str(run_dir)])
    assert train_cli.main([*flags, "--overwrite"]) == 0
    assert (run_dir / "summary.json").exists()
    assert [row["env_step"] for row in read_csv(run_dir / "eval.csv")] == [0, 20]


def test_overwrite_never_deletes_a_run_with_a_checkpoint(finished, capsys):
    err = exit_message(capsys, train_cli.main, [*run_flags(finished, 40), "--overwrite"])
    assert "--resume" in err
    assert (finished / "checkpoint.pt").exists() and (finished / "summary.json").exists()


def test_a_second_trainer_on_the_same_run_dir_is_refused_with_the_first_pid(tmp_path, capsys):
    run_dir = tmp_path / "run"
    long_run = run_flags(run_dir, 1000000, "--no-progress", "--no-video", "--eval-every", "1000000")
    first = subprocess.Popen(
        [sys.executable, "-m", "simoun_agent.cli.train", *long_run],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 120
        while not (run_dir / "config.json").exists():
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.2)
        for argv in (run_flags(run_dir, 40), ["--resume", str(run_dir)]):
            assert f"PID {first.pid}" in exit_message(capsys, train_cli.main, argv)
    finally:
        first.kill()
        first.wait()


def test_simoun_eval_does_not_overwrite_an_earlier_evaluation(finished, capsys):
    argv = [str(finished), "--episodes", "1", "--no-video"]
    assert eval_cli.main(argv) == 0
    written = (finished / "eval-40" / "metrics.json").read_bytes()
    err = exit_message(capsys, eval_cli.main, argv)
    assert "eval-40" in err and "--overwrite" in err and "--out" in err
    assert (finished / "eval-40" / "metrics.json").read_bytes() == written
    assert eval_cli.main([*argv, "--overwrite"]) == 0


def test_simoun_eval_names_metrics_that_do_not_fit_and_leaves_no_part_of_them(finished, tmp_path):
    argv = [str(finished), "--episodes", "1", "--no-video", "--out", str(tmp_path / "e")]
    done = under_file_size_limit("simoun_agent.cli.eval", argv, limit=100)
    path = named_unwritten_file(done, "simoun-eval", "pass --out DIR on another disk")
    assert path == tmp_path / "e" / "metrics.json" and not path.exists()


def test_simoun_eval_stops_promptly_on_sigterm_even_when_sdl_took_it(tmp_path):
    run_dir = tmp_path / "highway"
    highway = '{"config": {"action": {"type": "ContinuousAction"}, "duration": 4}}'
    flags = override(TINY, "--env", "highway-fast-v0", "--env-kwargs", highway)
    assert train_cli.main([*flags, "--run-dir", str(run_dir), "--total-env-steps", "12"]) == 0
    process = subprocess.Popen(
        [sys.executable, "-m", "simoun_agent.cli.eval", str(run_dir), "--episodes", "10000"],
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "SDL_NO_SIGNAL_HANDLERS": "0", "PYTHONUNBUFFERED": "1"},
    )
    watchdog = threading.Timer(120, process.kill)  # a silent child must not hang the suite
    watchdog.start()
    try:
        lines = [process.stderr.readline()]
        while not lines[-1].startswith("episode "):  # until the first episode's status line
            assert lines[-1], "".join(lines)
            lines.append(process.stderr.readline())
        assert "SIGTERM handler" in "".join(lines)  # SDL's handler was found and replaced
        process.send_signal(signal.SIGTERM)
        # 10,000 episodes take hours: exiting 143 at all means the signal stopped it, and at
        # once means no further episode (one may have ended while the signal was on its way)
        assert process.wait(timeout=120) == 143
        after = process.stderr.read()
        assert "stopped by SIGTERM" in after
        assert after.count("episode ") <= 1, after
    finally:
        watchdog.cancel()
        process.kill()
        process.wait()
    assert not (run_dir / "eval-12").exists()  # nothing half-written is left behind


def test_simoun_eval_refuses_a_negative_seed(finished, capsys):
    err = exit_message(capsys, eval_cli.main, [str(finished), "--seed", "-1", "--no-video"])
    assert "--seed -1" in err


ENV_MODULE = """
import gymnasium as gym

gym.register("simoun-test/WideReach-v0", entry_point="simoun_agent.envs.point_reach:PointReach",
             kwargs={"size": 40}, max_episode_steps=20)
"""


def test_env_module_is_saved_so_resume_and_simoun_eval_rebuild_the_env(tmp_path, monkeypatch):
    (tmp_path / "simoun_test_envs.py").write_text(ENV_MODULE)
    monkeypatch.syspath_prepend(str(tmp_path))
    run_dir = tmp_path / "run"
    flags = override(TINY, "--env", "simoun_test_envs:simoun-test/WideReach-v0", "--no-progress")
    assert train_cli.main([*flags, "--run-dir", str(run_dir), "--total-env-steps", "20"]) == 0
    config = json.loads((run_dir / "config.json").read_text())
    assert (config["env"], config["env_module"]) == ("simoun-test/WideReach-v0", "simoun_test_envs")
    assert train_cli.main(["--resume", str(run_dir), "--total-env-steps", "40", "--no-video"]) == 0
    # a fresh interpreter knows the id only by importing the module that config.json names
    done = subprocess.run(
        [sys.executable, "-m", "simoun_agent.cli.eval", str(run_dir), "--episodes", "1"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(tmp_path)},
    )
    assert done.returncode == 0, done.stderr
    assert json.loads((run_dir / "eval-40" / "metrics.json").read_text())["env_step"] == 40


def test_a_missing_env_module_and_bad_env_kwargs_end_in_one_line_not_a_traceback(tmp_path, capsys):
    run_dir = tmp_path / "run"
    flags = override(run_flags(run_dir, 20), "--env", "simoun_no_such_package:Thing-v0")
    err = exit_message(capsys, train_cli.main, flags)
    assert "'simoun_no_such_package' is not installed" in err and "pip install" in err
    flags = [*run_flags(run_dir, 20), "--env-kwargs", '{"foo": 1}']
    err = exit_message(capsys, train_cli.main, flags)
    assert err == (
        "simoun-train: error: --env-kwargs: simoun/PointReach-v0 takes no keyword 'foo'; it "
        "accepts: max_steps, size, step_size\n"
    )
    assert not run_dir.exists()  # refused before anything was built or written


def test_env_kwargs_and_cameras_the_env_fails_on_are_refused_before_a_run(tmp_path, capsys):
    run_dir = tmp_path / "run"
    pendulum = override(run_flags(run_dir, 20), "--env", "Pendulum-v1")
    cases = {
        '{"g": "x"}': "--env-kwargs: g='x' does not fit Pendulum-v1: its 'g' is a number",
        '{"g": null}': "Pendulum-v1 was made with g=None but failed at its first reset and step",
        '{"max_episode_steps": 0}': "--env-kwargs: max_episode_steps=0 (gymnasium.make's",
        '{"autoreset": true}': "'autoreset' is a setting of Pendulum-v1's registration",
    }
    for kwargs, said in cases.items():
        err = exit_message(capsys, train_cli.main, [*pendulum, "--env-kwargs", kwargs])
        assert said in err and "Traceback" not in err, err
    cameras = override(run_flags(run_dir, 20), "--env", "dm_control/cartpole-swingup-v0")
    err = exit_message(capsys, train_cli.main, [*cameras, "--cameras", "3"])
    assert "--cameras 3: dm_control/cartpole-swingup-v0 has only 2 cameras" in err
    assert not run_dir.exists()  # refused before anything was written
    limited = [*pendulum, "--env-kwargs", '{"max_episode_steps": 10}', "--no-progress"]
    assert train_cli.main([*limited, "--no-video"]) == 0
    assert json.loads((run_dir / "config.json").read_text())["env_kwargs"] == {
        "max_episode_steps": 10
    }


def test_torch_threads_beyond_the_cores_are_warned_of_once(finished, tmp_path, capsys):
    cores = len(os.sched_getaffinity(0))
    threads = torch.get_num_threads()
    warning = f"--torch-threads {cores + 1} is more than the {cores} CPU core"
    try:
        flags = run_flags(tmp_path / "run", 20, "--torch-threads", str(cores + 1), "--no-video")
        assert train_cli.main([*flags, "--no-progress"]) == 0
        assert capsys.readouterr().err.count(warning) == 1
        argv = [str(finished), "--episodes", "1", "--no-video", "--out", str(tmp_path / "ev")]
        assert eval_cli.main([*argv, "--torch-threads", str(cores + 1)]) == 0
        assert capsys.readouterr().err.count(warning) == 1
        assert eval_cli.main([*argv, "--overwrite", "--torch-threads", str(cores)]) == 0
        assert "CPU core" not in capsys.readouterr().err
    finally:
        torch.set_num_threads(threads)


def test_set_with_a_misspelled_key_suggests_by_meaning_and_takes_the_flag_spelling(
    tmp_path, capsys
):
    err = exit_message(
        capsys, train_cli.main, [*run_flags(tmp_path / "run"), "--set", "agent.learning_rate=3e-4"]
    )
    assert "unknown config key agent.learning_rate (did you mean agent.lr?)" in err
    base = run_flags(tmp_path / "run", 20, "--no-progress", "--no-video")
    at = base.index("--agent.batch-size")
    argv = [*base[:at], *base[at + 2 :], "--set", "agent.batch-size=10"]
    assert train_cli.main(argv) == 0
    assert json.loads((tmp_path / "run" / "config.json").read_text())["agent"]["batch_size"] == 10


def test_frames_too_large_for_the_memory_are_refused_before_anything_is_built(tmp_path, capsys):
    run_dir = tmp_path / "run"
    # 512x512 frames at batch 512: hundreds of GB for one update, on any machine
    flags = run_flags(run_dir, 20)
    for flag in ("--image-size", "--agent.batch-size"):
        flags[flags.index(flag) + 1] = "512"
    err = exit_message(capsys, train_cli.main, [*flags, "--replay-capacity", "1000"])
    assert "--image-size 512 with --agent.batch-size 512" in err
    assert "GB" in err and "Set --agent.batch-size " in err
    assert not run_dir.exists()


def test_resume_changes_torch_threads_even_to_the_saved_value(finished, tmp_path):
    run_dir = tmp_path / "run"
    shutil.copytree(finished, run_dir)
    saved = json.loads((run_dir / "config.json").read_text())["torch_threads"]
    for threads, steps in ((saved, 60), (saved + 1, 80)):
        argv = ["--resume", str(run_dir), "--torch-threads", str(threads), "--no-video"]
        assert train_cli.main([*argv, "--total-env-steps", str(steps), "--no-progress"]) == 0
        assert json.loads((run_dir / "config.json").read_text())["torch_threads"] == threads


def test_simoun_eval_uses_the_runs_torch_threads_unless_told(finished, tmp_path, capsys):
    threads = torch.get_num_threads()
    saved = json.loads((finished / "config.json").read_text())["torch_threads"]
    try:
        torch.set_num_threads(saved + 1)
        argv = [str(finished), "--episodes", "1", "--no-video", "--out", str(tmp_path / "ev")]
        assert eval_cli.main(argv) == 0
        assert torch.get_num_threads() == saved
        assert eval_cli.main([*argv, "--overwrite", "--torch-threads", str(saved + 1)]) == 0
        assert torch.get_num_threads() == saved + 1
        report = [*argv, "--torch-threads", "2", "--distraction", "train"]
        err = exit_message(capsys, eval_cli.main, report)
        assert "--torch-threads" in err and "each run's own" in err
    finally:
        torch.set_num_threads(threads)


def test_help_says_evaluations_wait_for_the_episode_end(capsys):
    with pytest.raises(SystemExit):
        train_cli.main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "environment steps between evaluations (run at the next episode end)" in text


def test_a_refused_distraction_leaves_no_report_directory(finished, capsys):
    err = exit_message(capsys, eval_cli.main, [str(finished), "--distraction", "color_hard"])
    assert "needs a dm_control task" in err
    assert not (finished / "generalization").exists()


@pytest.mark.skipif(shutil.which("unshare") is None, reason="needs util-linux's unshare")
def test_resume_of_a_read_only_run_directory_is_one_clear_error(finished):
    # a read-only bind mount in a user namespace: read-only even for root, nothing changed
    # outside the child
    script = (
        f'mount --bind -o ro "{finished}" "{finished}" && exec "{sys.executable}" -m '
        f'simoun_agent.cli.train --resume "{finished}" --total-env-steps 400'
    )
    probe = subprocess.run(
        ["unshare", "-rm", "sh", "-c", f'mount --bind -o ro "{finished}" "{finished}"'],
        capture_output=True,
        timeout=120,
    )
    if probe.returncode != 0:
        pytest.skip(f"no read-only bind mount here: {probe.stderr.decode().strip()}")
    done = subprocess.run(
        ["unshare", "-rm", "sh", "-c", script], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert f"cannot write to the run directory {finished} (Read-only file system)" in done.stderr
    assert "Make it writable" in done.stderr
    assert f"cp -r {finished} ~/{finished.name} && simoun-train --resume ~/{finished.name}" in (
        done.stderr
    )


def test_an_unknown_mujoco_gl_is_refused_in_one_line(tmp_path):
    run_dir = tmp_path / "run"
    # action repeat 1: the 40 steps hold more decisions than the warm-up, so nothing is warned of
    argv = run_flags(run_dir, 40, "--env", "dm_control/cartpole-swingup-v0", "--action-repeat", "1")
    done = subprocess.run(
        [sys.executable, "-m", "simoun_agent.cli.train", *argv],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MUJOCO_GL": "bogus"},
        cwd=tmp_path,
    )
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert "MUJOCO_GL='bogus'" in done.stderr and "egl or osmesa or glfw" in done.stderr
    assert not run_dir.exists()


def refusal_in_one_line(command: str, argv: list[str], **variables: str) -> str:
    """What simoun-COMMAND prints when it refuses ``argv`` run on a machine without a display,
    with the environment ``variables``; it must exit 2 without a traceback or a destructor's
    'Exception ignored'."""
    unset = ("DISPLAY", "WAYLAND_DISPLAY", "MUJOCO_GL", "PYOPENGL_PLATFORM", "SDL_VIDEODRIVER")
    env = {key: value for key, value in os.environ.items() if key not in unset}
    with tempfile.TemporaryDirectory() as here:  # MuJoCo's error leaves MUJOCO_LOG.TXT in the cwd
        done = subprocess.run(
            [sys.executable, "-m", f"simoun_agent.cli.{command}", *argv],
            capture_output=True,
            text=True,
            timeout=300,
            env={**env, **variables},
            cwd=here,
        )
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and "Exception ignored" not in done.stderr
    assert "GLFWError" not in done.stderr, done.stderr
    return done.stderr


@pytest.mark.parametrize(
    ("env", "variables", "said"),
    [
        ("HalfCheetah-v5", {"MUJOCO_GL": "glfw"}, "MUJOCO_GL=glfw cannot render HalfCheetah-v5 "
         "on this machine: GLFW opens a window, and this machine has no display (DISPLAY is "
         "unset) (FatalError: an OpenGL platform library has not been loaded"),
        ("dm_control/cartpole-swingup-v0", {"MUJOCO_GL": "glfw"}, "MUJOCO_GL=glfw cannot "
         "render dm_control/cartpole-swingup-v0 on this machine: GLFW opens a window"),
        ("dm_control/cartpole-swingup-v0", {"MUJOCO_GL": "osmesa"}, "MUJOCO_GL=osmesa cannot "
         "render dm_control/cartpole-swingup-v0 on this machine: OSMesa needs the library "
         "libOSMesa, which is not installed"),
        ("HalfCheetah-v5", {"MUJOCO_GL": "osmesa"}, "MUJOCO_GL=osmesa cannot render "
         "HalfCheetah-v5 on this machine: OSMesa needs the library libOSMesa"),
    ],
)  # fmt: skip
def test_a_mujoco_gl_that_cannot_run_here_is_named_with_the_fix(tmp_path, env, variables, said):
    if variables["MUJOCO_GL"] == "osmesa" and ctypes.util.find_library("OSMesa") is not None:
        pytest.skip("libOSMesa is installed here: OSMesa renders")
    run_dir = tmp_path / "run"
    stderr = refusal_in_one_line("train", run_flags(run_dir, 40, "--env", env), **variables)
    assert said in stderr
    assert stderr.strip().endswith(
        "set MUJOCO_GL=egl, or unset it (simoun sets egl when there is no display)"
    )
    assert not run_dir.exists()


def test_a_pyopengl_platform_at_odds_with_mujoco_gl_is_named(tmp_path):
    argv = run_flags(tmp_path / "run", 40, "--env", "dm_control/cartpole-swingup-v0")
    stderr = refusal_in_one_line("train", argv, MUJOCO_GL="egl", PYOPENGL_PLATFORM="glx")
    assert "PYOPENGL_PLATFORM=glx does not match MUJOCO_GL=egl, so dm_control/" in stderr
    assert "unset PYOPENGL_PLATFORM (dm_control and mujoco set it from MUJOCO_GL)" in stderr
    assert "not installed" not in stderr


def test_an_sdl_video_driver_that_cannot_run_here_is_named_not_the_env_kwargs(tmp_path):
    argv = run_flags(tmp_path / "run", 40, "--env", "highway-fast-v0", "--preset", "highway-cpu")
    stderr = refusal_in_one_line("train", argv, SDL_VIDEODRIVER="x11")
    assert "SDL_VIDEODRIVER=x11 cannot draw highway-fast-v0's frames on this machine" in stderr
    assert "set SDL_VIDEODRIVER=offscreen, or unset it" in stderr
    assert "--env-kwargs" not in stderr


def test_simoun_eval_names_a_mujoco_gl_that_cannot_run_here(tmp_path):
    run_dir = tmp_path / "dmc"
    argv = run_flags(run_dir, 16, "--env", "dm_control/cartpole-swingup-v0", "--action-repeat", "4")
    assert train_cli.main(override(argv, "--warmup-agent-steps", "2")) == 0
    stderr = refusal_in_one_line(
        "eval", [str(run_dir), "--no-video", "--episodes", "1"], MUJOCO_GL="glfw"
    )
    assert "MUJOCO_GL=glfw cannot render dm_control/cartpole-swingup-v0 on this machine" in stderr
