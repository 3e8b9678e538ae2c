"""simoun-train / simoun-eval conventions and misuse (issue 10): boolean switches, --version,
plain status lines without a terminal, resume and rerun mistakes, one trainer per run directory,
no silent overwrite of an evaluation; simoun-eval stops promptly on SIGTERM (issue 14)."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from simoun_agent.run import evaluate, train
from simoun_agent.run.logger import read_csv

TINY = [
    "--env", "simoun/PointReach-v0",
    "--image-size", "32",
    "--warmup-agent-steps", "10",
    "--eval-every", "20",
    "--eval-episodes", "1",
    "--checkpoint-every", "20",
    "--device", "cpu",
    "--torch-threads", "1",
    "--agent.batch-size", "8",
    "--agent.num-filters", "4",
    "--agent.feature-dim", "8",
    "--agent.hidden-dim", "16",
    "--agent.aux-hidden-dim", "16",
]  # fmt: skip


def run_flags(run_dir: Path, steps: int = 40, *extra: str) -> list[str]:
    return [*TINY, "--run-dir", str(run_dir), "--total-env-steps", str(steps), *extra]


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
    assert train.main(run_flags(run_dir, 40, "--no-progress", "--no-video")) == 0
    return run_dir


@pytest.mark.parametrize("main", [train.main, evaluate.main])
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
    assert train.main(run_flags(tmp_path / "run", 20, *switches)) == 0
    config = json.loads((tmp_path / "run" / "config.json").read_text())
    assert (config["progress"], config["video"]) == (progress, video)


def test_simoun_eval_takes_the_same_switches(finished, tmp_path):
    out = tmp_path / "ev"
    argv = [str(finished), "--episodes", "1", "--out", str(out), "--no-video", "--no-progress"]
    assert evaluate.main(argv) == 0
    assert not (out / "video.mp4").exists()
    assert evaluate.main([*argv[:-2], "--video", "true", "--overwrite"]) == 0
    assert (out / "video.mp4").stat().st_size > 0


def test_without_a_terminal_one_status_line_per_evaluation_and_no_bar(tmp_path):
    run_dir = tmp_path / "run"
    done = subprocess.run(
        [sys.executable, "-m", "simoun_agent.run.train", *run_flags(run_dir, 40, "--no-video")],
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
    err = exit_message(capsys, train.main, ["--resume", str(finished), "--total-env-steps", "20"])
    assert "--total-env-steps 20" in err and "40" in err
    assert {name: (finished / name).read_bytes() for name in before} == before


CRASH_AFTER_FIRST_EVALUATION = """
import os, signal, sys
from simoun_agent.run import train

class Crash(train.TrainCallback):
    def on_logged(self, run, metrics):
        os.kill(os.getpid(), signal.SIGKILL)  # as an out-of-memory kill would

plain = train.train
train.train = lambda run, callbacks=(): plain(run, [*callbacks, Crash()])
sys.exit(train.main(sys.argv[1:]))
"""


def test_rerun_after_a_crash_before_the_first_checkpoint_offers_overwrite(tmp_path, capsys):
    run_dir = tmp_path / "run"
    flags = run_flags(run_dir, 20, "--no-progress", "--no-video")
    crashed = subprocess.run(
        [sys.executable, "-c", CRASH_AFTER_FIRST_EVALUATION, *flags], capture_output=True
    )
    assert crashed.returncode == -signal.SIGKILL
    assert (run_dir / "config.json").exists() and not (run_dir / "checkpoint.pt").exists()

    assert "--overwrite" in exit_message(capsys, train.main, flags)
    assert "--overwrite" in exit_message(capsys, train.main, ["--resume", str(run_dir)])
    assert train.main([*flags, "--overwrite"]) == 0
    assert (run_dir / "summary.json").exists()
    assert [row["env_step"] for row in read_csv(run_dir / "eval.csv")] == [0, 20]


def test_overwrite_never_deletes_a_run_with_a_checkpoint(finished, capsys):
    err = exit_message(capsys, train.main, [*run_flags(finished, 40), "--overwrite"])
    assert "--resume" in err
    assert (finished / "checkpoint.pt").exists() and (finished / "summary.json").exists()


def test_a_second_trainer_on_the_same_run_dir_is_refused_with_the_first_pid(tmp_path, capsys):
    run_dir = tmp_path / "run"
    long_run = run_flags(run_dir, 1000000, "--no-progress", "--no-video", "--eval-every", "1000000")
    first = subprocess.Popen(
        [sys.executable, "-m", "simoun_agent.run.train", *long_run],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 120
        while not (run_dir / "config.json").exists():
            assert first.poll() is None and time.monotonic() < deadline
            time.sleep(0.2)
        for argv in (run_flags(run_dir, 40), ["--resume", str(run_dir)]):
            assert f"PID {first.pid}" in exit_message(capsys, train.main, argv)
    finally:
        first.kill()
        first.wait()


def test_simoun_eval_does_not_overwrite_an_earlier_evaluation(finished, capsys):
    argv = [str(finished), "--episodes", "1", "--no-video"]
    assert evaluate.main(argv) == 0
    written = (finished / "eval-40" / "metrics.json").read_bytes()
    err = exit_message(capsys, evaluate.main, argv)
    assert "eval-40" in err and "--overwrite" in err and "--out" in err
    assert (finished / "eval-40" / "metrics.json").read_bytes() == written
    assert evaluate.main([*argv, "--overwrite"]) == 0


def test_simoun_eval_stops_promptly_on_sigterm_even_when_sdl_took_it(tmp_path):
    run_dir = tmp_path / "highway"
    highway = '{"config": {"action": {"type": "ContinuousAction"}, "duration": 4}}'
    flags = [*TINY, "--env", "highway-fast-v0", "--env-kwargs", highway]
    assert train.main([*flags, "--run-dir", str(run_dir), "--total-env-steps", "12"]) == 0
    process = subprocess.Popen(
        [sys.executable, "-m", "simoun_agent.run.evaluate", str(run_dir), "--episodes", "10000"],
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
    err = exit_message(capsys, evaluate.main, [str(finished), "--seed", "-1", "--no-video"])
    assert "--seed -1" in err
