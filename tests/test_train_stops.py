"""A stop in every phase of a run: Ctrl-C or SIGTERM during the warm-up, an evaluation
(the initial one, a later one, the final one) or the final video is acknowledged at once, writes
a checkpoint and exits with 130 / 143; an evaluation is abandoned, never logged halfway, and
runs again on resume, which ends where a run that never stopped ends. Callbacks' ``on_start`` and
``on_end`` run however a run ends.

The signal tests run the real command in a subprocess and poll its output or run directory for
the phase they want to interrupt (no fixed sleeps); the phase is named in the stop message.
"""

import fcntl
import os
import pty
import re
import signal
import struct
import subprocess
import sys
import termios
import threading
import time
from pathlib import Path

import pytest
import torch
from flag_lists import override
from test_train_resume import tiny_config, weights, without_wall_time
from test_train_sigterm import CARTPOLE, TINY

from simoun_agent.cli import train as train_cli
from simoun_agent.generalization.callback import DistractionEvaluation
from simoun_agent.run import train
from simoun_agent.run.checkpoint import load_checkpoint
from simoun_agent.run.logger import read_csv
from simoun_agent.run.signals import Stopped

POINT_REACH = [*TINY, "--env", "simoun/PointReach-v0"]
"""simoun-train flags of a tiny run on the 20-step PointReach task."""
LIMIT_S = 240
"""Generous: the machine may be loaded."""


class Child:
    """simoun-train in a subprocess of its own process group (signalled whole, as a terminal's
    Ctrl-C or a scheduler does), its stdout and stderr read together as they come. With
    ``terminal`` they go to a pseudo-terminal, so the trainer shows its progress bar."""

    def __init__(self, args: list[str], terminal: bool = False) -> None:
        env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        if terminal:
            self.fd, tty = pty.openpty()
            fcntl.ioctl(tty, termios.TIOCSWINSZ, struct.pack("HHHH", 50, 250, 0, 0))
            streams = {"stdout": tty, "stderr": tty}
        else:
            self.fd, writer = os.pipe()
            streams = {"stdout": writer, "stderr": writer}
        self.process = subprocess.Popen(
            [sys.executable, *args],
            stdin=subprocess.DEVNULL,
            env=env,
            start_new_session=True,
            **streams,
        )
        os.close(streams["stdout"])
        self.chunks: list[str] = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        while True:
            try:
                data = os.read(self.fd, 65536)
            except OSError:  # EIO: the child closed the pseudo-terminal
                break
            if not data:
                break
            self.chunks.append(data.decode(errors="replace"))
        os.close(self.fd)

    @property
    def output(self) -> str:
        return "".join(self.chunks)

    def wait_for(self, condition, what: str) -> None:
        """Poll ``condition(output)`` until it holds; fail if the child ends first or it takes
        longer than :data:`LIMIT_S`."""
        deadline = time.monotonic() + LIMIT_S
        while not condition(self.output):
            if self.process.poll() is not None:
                self.reader.join(10)
                assert condition(self.output), f"exited {self.process.returncode} before {what}"
                return
            assert time.monotonic() < deadline, f"no {what} within {LIMIT_S} s:\n{self.output}"
            time.sleep(0.05)

    def signal(self, signum: int) -> None:
        os.killpg(self.process.pid, signum)

    def returncode(self) -> int:
        self.process.wait(LIMIT_S)
        self.reader.join(10)
        return self.process.returncode

    def kill(self) -> None:
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGKILL)
            self.process.wait()


@pytest.fixture
def child():
    children = []

    def start(args: list[str], terminal: bool = False) -> Child:
        children.append(Child(args, terminal))
        return children[-1]

    yield start
    for started in children:
        started.kill()


def trainer(run_dir: Path, *flags: str) -> list[str]:
    return [
        "-m",
        "simoun_agent.cli.train",
        *override(POINT_REACH, *flags, "--run-dir", str(run_dir)),
    ]


def counters(run_dir: Path) -> dict:
    return load_checkpoint(run_dir)["state"]["counters"]


def logged_steps(run_dir: Path) -> list[float]:
    path = run_dir / "eval.csv"
    return [row["env_step"] for row in read_csv(path)] if path.exists() else []


def acknowledged_then_stopped(output: str, name: str, phase: str) -> bool:
    """The acknowledgement came first, then the stop message naming the phase and --resume."""
    said = output.find(f"{name} received: stopping at the next step")
    stopped = output.find(f"stopped by {name} during {phase}")
    return 0 <= said < stopped and "continue with: simoun-train --resume" in output[stopped:]


def test_ctrl_c_in_the_warm_up(child, tmp_path):
    run_dir = tmp_path / "run"
    flags = ["--warmup-agent-steps", "100000", "--total-env-steps", "200000"]
    process = child(trainer(run_dir, *flags, "--eval-every", "1000000"))
    process.wait_for(lambda _: (run_dir / "train.csv").exists(), "a finished episode")
    process.signal(signal.SIGINT)
    assert process.returncode() == 130, process.output
    assert acknowledged_then_stopped(process.output, "SIGINT", "the warm-up"), process.output
    assert 0 < counters(run_dir)["agent_step"] < 100000


def test_ctrl_c_in_the_initial_evaluation(child, tmp_path):
    run_dir = tmp_path / "run"
    flags = ["--eval-episodes", "50", "--total-env-steps", "1000", "--progress", "true"]
    process = child(trainer(run_dir, *flags))
    # without a terminal the trainer says when its first evaluation starts
    process.wait_for(lambda out: "evaluating at env step 0 (50 episodes)" in out, "the evaluation")
    process.signal(signal.SIGINT)
    assert process.returncode() == 130, process.output
    output = process.output
    assert acknowledged_then_stopped(output, "SIGINT", "the initial evaluation (abandoned"), output
    assert counters(run_dir)["env_step"] == 0 and counters(run_dir)["eval_pending"]
    assert logged_steps(run_dir) == []  # nothing of the abandoned evaluation


def test_sigterm_in_a_later_evaluation_shown_on_the_progress_bar(child, tmp_path):
    run_dir = tmp_path / "run"
    flags = ["--eval-episodes", "50", "--eval-every", "40", "--total-env-steps", "1000"]
    process = child(trainer(run_dir, *flags, "--progress", "true"), terminal=True)

    def evaluating_after_training(output: str) -> bool:
        # the bar: "... | 40/1000 [00:12<..., evaluating: 3/50 episodes]"
        shown = re.findall(r"\| (\d+)/1000 \[[^\]]*evaluating: \d+/50 episodes", output)
        return any(int(step) >= 40 for step in shown)

    process.wait_for(evaluating_after_training, "the second evaluation on the bar")
    process.signal(signal.SIGTERM)
    assert process.returncode() == 143, process.output
    output = process.output
    assert re.search(r"\| 0/1000 \[[^\]]*evaluating: \d+/50 episodes", output)  # the first one
    assert acknowledged_then_stopped(output, "SIGTERM", "an evaluation (abandoned"), output
    assert counters(run_dir)["env_step"] == 40 and counters(run_dir)["eval_pending"]
    assert logged_steps(run_dir) == [0]


SIGTERM_AFTER_THE_FINAL_EVALUATION = """
import os, signal, sys
from simoun_agent.cli import train as train_cli
from simoun_agent.run import train

class SigtermAtTheEnd(train.TrainCallback):
    # logged after the final evaluation (of the run's end: none falls due on the way), so the
    # signal comes before the video starts
    def on_logged(self, run, metrics):
        if run.counters.env_step >= run.config.total_env_steps:
            os.kill(os.getpid(), signal.SIGTERM)

plain = train.train
train.train = lambda run, callbacks=(): plain(run, [*callbacks, SigtermAtTheEnd()])
sys.exit(train_cli.main(sys.argv[1:]))
"""


def test_sigterm_before_the_final_video_and_resume_records_it(child, tmp_path):
    run_dir = tmp_path / "run"
    flags = override(
        POINT_REACH, "--eval-every", "1000", "--total-env-steps", "40", "--video", "true"
    )
    process = child(["-c", SIGTERM_AFTER_THE_FINAL_EVALUATION, *flags, "--run-dir", str(run_dir)])
    assert process.returncode() == 143, process.output
    assert acknowledged_then_stopped(process.output, "SIGTERM", "the final video"), process.output
    assert counters(run_dir)["env_step"] == 40 and not counters(run_dir)["eval_pending"]
    assert not (run_dir / "summary.json").exists() and not (run_dir / "video.mp4").exists()

    assert train_cli.main(["--resume", str(run_dir)]) == 0  # at its last step, with the end to do
    assert (run_dir / "summary.json").exists() and (run_dir / "video.mp4").stat().st_size > 0
    assert logged_steps(run_dir) == [0, 40]  # the final evaluation is not played twice


class StopInEvaluation(train.TrainCallback):
    """Ask for a stop, as SIGTERM would, while the evaluation at env step ``step`` plays."""

    def __init__(self, step: int) -> None:
        self.step = step

    def stop_requested(self, run: train.Run) -> int | None:
        at = run.counters.env_step == self.step and run.counters.eval_pending
        return signal.SIGTERM if at else None


class Lifecycle(train.TrainCallback):
    """Records the hooks it sees."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, object]] = []

    def on_start(self, run: train.Run) -> None:
        self.calls.append(("start", run.counters.env_step))

    def on_logged(self, run: train.Run, metrics: dict[str, float]) -> None:
        self.calls.append(("logged", run.counters.env_step))

    def on_end(self, run: train.Run, metrics: dict[str, float] | None) -> None:
        self.calls.append(("end", None if metrics is None else metrics["return_mean"]))


@pytest.fixture(scope="module")
def straight_run(tmp_path_factory):
    """A run that nothing stops, and the hooks its Lifecycle callback saw."""
    run_dir = tmp_path_factory.mktemp("straight") / "run"
    run, lifecycle = train.create_run(tiny_config(run_dir)), Lifecycle()
    final = train.train(run, [lifecycle])
    return run, lifecycle.calls, final


@pytest.mark.parametrize("step", [0, 60, 120], ids=["initial", "later", "final"])
def test_a_run_stopped_in_an_evaluation_resumes_to_the_straight_runs_end(
    step, straight_run, tmp_path
):
    straight, _, _ = straight_run
    run_dir = tmp_path / "run"
    with pytest.raises(Stopped) as stop:
        train.train(train.create_run(tiny_config(run_dir)), [StopInEvaluation(step)])
    assert stop.value.exit_code == 143
    assert counters(run_dir)["env_step"] == step and counters(run_dir)["eval_pending"]
    assert step not in logged_steps(run_dir)

    resumed = train.resume_run(run_dir, {})
    train.train(resumed)
    assert resumed.counters == straight.counters
    expected, got = weights(straight.agent), weights(resumed.agent)
    assert [key for key in expected if not torch.equal(expected[key], got[key])] == []
    straight_eval = read_csv(Path(straight.run_dir) / "eval.csv")
    assert [without_wall_time(r) for r in read_csv(run_dir / "eval.csv")] == [
        without_wall_time(r) for r in straight_eval
    ]


def test_on_start_and_on_end_bracket_a_run_that_ends_and_one_that_stops(straight_run, tmp_path):
    _, calls, final = straight_run
    logged = [("logged", 0), ("logged", 60), ("logged", 120)]
    assert calls == [("start", 0), *logged, ("end", final["return_mean"])]
    stopped = Lifecycle()
    with pytest.raises(Stopped):
        train.train(train.create_run(tiny_config(tmp_path / "run")), [stopped, StopInEvaluation(0)])
    assert stopped.calls == [("start", 0), ("end", None)]


class StopAfterFirstEvaluation(train.TrainCallback):
    def stop_requested(self, run: train.Run) -> int | None:
        return signal.SIGINT if not run.counters.eval_pending else None


class WatchedDistractions(DistractionEvaluation):
    """Keeps the distracted envs it opened, to look at them after the run."""

    def on_start(self, run: train.Run) -> None:
        super().on_start(run)
        self.opened = list(self._envs.values())


def test_distraction_envs_are_closed_when_a_run_stops(tmp_path):
    flags = {"env": CARTPOLE[1], "env_kwargs": {"task_kwargs": {"time_limit": 1}}}
    config = tiny_config(tmp_path / "run", **flags)
    distractions = WatchedDistractions(["color_easy"])
    run = train.create_run(config)
    try:
        with pytest.raises(Stopped):
            train.train(run, [distractions, StopAfterFirstEvaluation()])
    finally:
        run.env.close()
        run.eval_env.close()
    assert len(distractions.opened) == 1
    # shimmy's close frees the MuJoCo data of the dm_control physics
    assert not hasattr(distractions.opened[0].unwrapped._env.physics, "_data")


class SigtermAfterFirstEvaluation(train.TrainCallback):
    """Sends this process a real SIGTERM once the first evaluation is logged."""

    def on_logged(self, run: train.Run, metrics: dict[str, float]) -> None:
        os.kill(os.getpid(), signal.SIGTERM)


def test_distraction_envs_are_closed_when_a_signal_stops_the_run(tmp_path):
    flags = {"env": CARTPOLE[1], "env_kwargs": {"task_kwargs": {"time_limit": 1}}}
    config = tiny_config(tmp_path / "run", eval_distraction=("color_easy",), **flags)
    distractions = WatchedDistractions(["color_easy"])
    run = train.create_run(config)
    try:
        with pytest.raises(Stopped) as stopped:
            train.train(run, [distractions, SigtermAfterFirstEvaluation()])
    finally:
        run.env.close()
        run.eval_env.close()
    assert stopped.value.signum == signal.SIGTERM
    assert load_checkpoint(run.run_dir)["state"]["env_step"] == 0  # after the initial evaluation
    assert len(distractions.opened) == 1
    assert not hasattr(distractions.opened[0].unwrapped._env.physics, "_data")


def test_a_distraction_setting_without_its_callback_is_refused(tmp_path):
    flags = {"env": CARTPOLE[1], "env_kwargs": {"task_kwargs": {"time_limit": 1}}}
    run = train.create_run(tiny_config(tmp_path / "run", eval_distraction=("color_easy",), **flags))
    try:
        with pytest.raises(ValueError, match="distraction_callbacks"):
            train.train(run)
    finally:
        run.env.close()
        run.eval_env.close()
        train.release(run)
