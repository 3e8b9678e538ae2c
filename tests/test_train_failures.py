"""What a run does when something fails under it: a full disk at a checkpoint, a NaN
reward from the env, the temporary a ``kill -9`` leaves halfway through a checkpoint.

The full disk is real, not a mock: a subprocess under ``RLIMIT_FSIZE`` (its writes past the limit
fail with EFBIG, as ``ulimit -f`` makes them) and a checkpoint written into ``/dev/full`` (every
write fails with ENOSPC), since a small filesystem cannot be mounted without root.
"""

import errno
import os
import signal
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from flag_lists import override
from test_train_resume import tiny_config
from test_train_sigterm import TINY

from simoun_agent.cli import train as train_cli
from simoun_agent.envs import PointReach
from simoun_agent.run import train
from simoun_agent.run.atomic import space_problem
from simoun_agent.run.checkpoint import NoSpace, atomic_write, load_checkpoint
from simoun_agent.run.logger import read_csv

LIMIT_S = 240
"""Generous: the machine may be loaded."""

UNDER_FILE_SIZE_LIMIT = """
import resource, signal, sys
from simoun_agent.cli import train as train_cli
from simoun_agent.run import train

signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
sys.exit(train_cli.main(sys.argv[2:]))
"""
UNDER_LIMIT_MAIN = """
import importlib, resource, signal, sys

signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
limit = int(sys.argv[1])
main = importlib.import_module(sys.argv[2]).main
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
sys.exit(main(sys.argv[3:]))
"""


def under_file_size_limit(module: str, argv: list[str], limit: int = 10_000):
    """``module``'s ``main(argv)`` in a subprocess whose files can grow to ``limit`` bytes
    only: a write past it fails part-way with EFBIG, as one on a full disk does with ENOSPC."""
    return subprocess.run(
        [sys.executable, "-c", UNDER_LIMIT_MAIN, str(limit), module, *argv],
        capture_output=True,
        text=True,
        timeout=LIMIT_S,
    )


def named_unwritten_file(done, prog: str, elsewhere: str) -> Path:
    """The file ``prog``'s error names after a write that did not fit, checked: status
    NO_SPACE_EXIT, no traceback, the reason and the fixes said, and no temporary beside it."""
    err = done.stderr
    assert done.returncode == train.NO_SPACE_EXIT, done.stdout + err
    assert "Traceback" not in err and f"{prog}: error: cannot write " in err, err
    line = err[err.index(f"{prog}: error: cannot write ") :]  # after the progress lines
    path = Path(line.removeprefix(f"{prog}: error: cannot write ").split(": ", 1)[0])
    said = (
        f"the file is larger than the file size limit allows (File too large); {path.name} was "
        "not written (an earlier version of it is kept). To go on, raise the limit (ulimit -f "
        "unlimited"
    )
    assert said in err and elsewhere in err, err
    assert not list(path.parent.glob(".*.tmp*")), err
    return path


FILE_SIZE_LIMIT = 300_000
"""Above every file of the run but the replay past about 90 frames (3 KB a frame at 32x32): the
checkpoints at env steps 20-80 fit, those from 100 on do not."""


def test_a_full_disk_keeps_the_last_checkpoint_and_stops_after_three_failures(tmp_path):
    run_dir = tmp_path / "run"
    flags = override(TINY, "--env", "simoun/PointReach-v0", "--checkpoint-every", "20")
    flags += ["--total-env-steps", "1000", "--eval-every", "1000", "--run-dir", str(run_dir)]
    done = subprocess.run(
        [sys.executable, "-c", UNDER_FILE_SIZE_LIMIT, str(FILE_SIZE_LIMIT), *flags],
        capture_output=True,
        text=True,
        timeout=LIMIT_S,
    )
    assert done.returncode == train.NO_SPACE_EXIT, done.stdout + done.stderr
    assert "Traceback" not in done.stderr, done.stderr
    failures = [line for line in done.stderr.splitlines() if f"no space left on {run_dir}" in line]
    assert len(failures) == train.CHECKPOINT_TRIES, done.stderr
    assert all(" MB needed, a write failed: File too large" in line for line in failures)
    assert "training goes on and tries again at the next checkpoint" in failures[0]
    saved = load_checkpoint(run_dir)["state"]["env_step"]  # the last one that fitted, intact
    assert 20 <= saved <= 80 and saved % 20 == 0
    assert f"the latest checkpoint (env step {saved}) is intact" in failures[-1]
    assert f"simoun-train --resume {run_dir}" in failures[-1]
    stopped_at = saved + 20 * train.CHECKPOINT_TRIES  # three failures in a row: no more
    assert f"Stopped at env step {stopped_at}" in failures[-1]
    assert sorted(p.name for p in run_dir.glob("*.npz")) == [f"replay-{saved}.npz"]
    assert not list(run_dir.glob(".*.tmp*"))

    # with space again, the run continues from that checkpoint
    assert (
        train_cli.main(["--resume", str(run_dir), "--total-env-steps", str(stopped_at + 20)]) == 0
    )
    assert load_checkpoint(run_dir)["state"]["env_step"] == stopped_at + 20


class CheckpointIntoDevFull(train.TrainCallback):
    """At the evaluation of env step ``step``, points the temporary of the next checkpoint.pt at
    /dev/full, where the write fails with ENOSPC; atomic_write removes the link afterwards, so
    the next checkpoint goes to disk again. At the next evaluation, records what is on disk."""

    def __init__(self, step: int) -> None:
        self.step = step
        self.on_disk: tuple[int, list[str]] | None = None

    def on_logged(self, run: train.Run, metrics: dict[str, float]) -> None:
        if run.counters.env_step == self.step:
            (run.run_dir / f".checkpoint.{os.getpid()}.tmp.pt").symlink_to("/dev/full")
        elif run.counters.env_step == self.step + 20:
            saved = load_checkpoint(run.run_dir)["state"]["env_step"]
            self.on_disk = (saved, sorted(p.name for p in run.run_dir.glob("replay-*.npz")))


def test_a_checkpoint_that_hits_enospc_is_reported_and_the_next_one_is_written(tmp_path, capsys):
    config = tiny_config(tmp_path / "run", total_env_steps=80, eval_every=20, checkpoint_every=20)
    probe = CheckpointIntoDevFull(step=40)
    train.train(train.create_run(config), [probe])
    err = capsys.readouterr().err
    assert f"no space left on {config.run_dir}: " in err
    assert "MB needed, a write failed: No space left on device" in err
    assert "The checkpoint at env step 40 failed and the previous one is intact" in err
    # before the next checkpoint: the one of step 20, and no replay of the failed one
    assert probe.on_disk == (20, ["replay-20.npz"])
    assert load_checkpoint(config.run_dir)["state"]["env_step"] == 80
    assert (Path(config.run_dir) / "summary.json").exists()


def test_save_checkpoint_raises_no_space_and_leaves_the_previous_checkpoint(tmp_path):
    run = train.create_run(tiny_config(tmp_path / "run", total_env_steps=20))
    train.train(run)
    before = {p.name: p.read_bytes() for p in run.run_dir.iterdir() if p.is_file()}
    run.counters.env_step = 40  # a later checkpoint, whose replay file is a new one
    (run.run_dir / f".replay-40.{os.getpid()}.tmp.npz").symlink_to("/dev/full")
    with pytest.raises(NoSpace) as failure:
        train.checkpoint(run)
    assert failure.value.errno == errno.ENOSPC and failure.value.needed > 100_000
    assert str(failure.value).startswith(f"no space left on {run.run_dir}: ")
    after = {p.name: p.read_bytes() for p in run.run_dir.iterdir() if p.is_file()}
    assert after == before


class NanRewardAt(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Returns a NaN reward at the ``step``-th step of this env (counted across episodes)."""

    def __init__(self, env: gym.Env, step: int) -> None:
        gym.utils.RecordConstructorArgs.__init__(self, step=step)
        gym.Wrapper.__init__(self, env)
        self.step_at, self.steps = step, 0

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.steps += 1
        return obs, np.nan if self.steps == self.step_at else reward, terminated, truncated, info


NAN_ENV = "SimounTest/NanReward-v0"
if NAN_ENV not in gym.registry:
    gym.register(
        NAN_ENV,
        entry_point=lambda render_mode=None, nan_at=50: NanRewardAt(
            PointReach(render_mode=render_mode), nan_at
        ),
    )


def test_a_nan_reward_stops_with_a_checkpoint_and_a_clear_error(tmp_path, capsys):
    run_dir = tmp_path / "run"
    flags = [*TINY, "--env", NAN_ENV, "--env-kwargs", '{"nan_at": 50}', "--run-dir", str(run_dir)]
    # The evaluation env, another instance, takes 20 steps before training reaches its 50th.
    assert train_cli.main([*flags, "--total-env-steps", "1000", "--eval-every", "1000"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert f"{NAN_ENV} returned the reward nan at env step 50 (step 10 of training episode 2" in err
    assert "checkpoint at env step 49: fix the environment" in err and "--resume" in err
    assert load_checkpoint(run_dir)["state"]["env_step"] == 49
    assert [row["episode"] for row in read_csv(run_dir / "train.csv")] == [0, 1]

    # resumable, no --overwrite needed: the resumed env's own 50th step fails again, later on
    assert train_cli.main(["--resume", str(run_dir)]) == 1
    assert "returned the reward nan at env step 99" in capsys.readouterr().err
    assert load_checkpoint(run_dir)["state"]["env_step"] == 98


KILLED_WHILE_CHECKPOINTING = """
import os, signal, sys
from pathlib import Path
from simoun_agent.run.checkpoint import atomic_write

def write(tmp):
    tmp.write_bytes(b"")  # what torch.save had written when the kill came
    os.kill(os.getpid(), signal.SIGKILL)

atomic_write(Path(sys.argv[1]) / "checkpoint.pt", write)
"""


def test_temporaries_of_dead_writers_are_removed_at_resume_and_a_live_ones_kept(tmp_path):
    run_dir = tmp_path / "run"
    train.train(train.create_run(tiny_config(run_dir, total_env_steps=20)))
    killed = subprocess.Popen([sys.executable, "-c", KILLED_WHILE_CHECKPOINTING, str(run_dir)])
    assert killed.wait(LIMIT_S) == -signal.SIGKILL
    dead = run_dir / f".checkpoint.{killed.pid}.tmp.pt"
    assert dead.stat().st_size == 0  # the leftover a kill -9 leaves
    orphan = run_dir / "replay-40.npz"  # a kill between the replay's rename and checkpoint.pt's
    orphan.write_bytes(b"")
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        writing = run_dir / f".learning_curve.{live.pid}.tmp.png"
        writing.write_bytes(b"")
        run = train.resume_run(run_dir, {"total_env_steps": 40})
        assert not dead.exists() and not orphan.exists()
        assert writing.exists()  # its writer may still finish
        assert (run_dir / "replay-20.npz").exists()  # the checkpoint's own
    finally:
        live.kill()
        live.wait()
    train.train(run)
    assert load_checkpoint(run_dir)["state"]["env_step"] == 40


def test_atomic_write_leaves_nothing_when_the_write_fails(tmp_path):
    target = tmp_path / "file.txt"
    target.write_text("old")
    (tmp_path / f".file.{os.getpid()}.tmp.txt").symlink_to("/dev/full")
    with pytest.raises(OSError) as failure:
        atomic_write(target, lambda tmp: tmp.write_text("new" * 10_000))
    assert failure.value.errno == errno.ENOSPC
    assert target.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["file.txt"]


def test_atomic_write_names_the_file_a_write_that_does_not_fit_was_for(tmp_path):
    target = tmp_path / "curves.png"
    (tmp_path / f".curves.{os.getpid()}.tmp.png").symlink_to("/dev/full")
    with pytest.raises(OSError) as failure:
        atomic_write(target, lambda tmp: tmp.write_bytes(b"x" * 10_000))
    assert failure.value.filename == str(target)
    said = space_problem(failure.value, "pass --out DIR on another disk")
    assert said == (
        f"cannot write {target}: the disk is full (No space left on device); curves.png was not "
        f"written (an earlier version of it is kept). To go on, free space on that disk (df -h "
        f"{tmp_path} shows it), or pass --out DIR on another disk, and run the command again"
    )


@pytest.mark.parametrize(
    ("number", "said"),
    [
        (errno.EDQUOT, "the disk quota is used up (Disk quota exceeded)"),
        (errno.EFBIG, "the file is larger than the file size limit allows (File too large)"),
    ],
)
def test_a_full_quota_and_a_file_size_limit_are_told_with_their_own_fix(number, said):
    error = OSError(number, os.strerror(number), "out/report.md")
    fix = "free space under your quota" if number == errno.EDQUOT else "ulimit -f unlimited"
    text = space_problem(error)
    assert text.startswith(f"cannot write out/report.md: {said}") and fix in text
    assert space_problem(OSError(errno.EACCES, "Permission denied", "out/report.md")) is None


def test_simoun_train_names_a_config_that_does_not_fit(tmp_path):
    run_dir = tmp_path / "run"
    flags = override(TINY, "--env", "simoun/PointReach-v0", "--run-dir", str(run_dir))
    done = under_file_size_limit("simoun_agent.cli.train", flags, limit=100)
    path = named_unwritten_file(done, "simoun-train", "pass --run-dir DIR on another disk")
    assert path.parent == run_dir and not path.exists()


def test_atomic_write_names_a_directory_in_place_of_its_file_and_leaves_it(tmp_path):
    target = tmp_path / "report.md"
    (target / "kept").mkdir(parents=True)
    with pytest.raises(ValueError, match=f"cannot write {target}: it is a directory, not a file"):
        atomic_write(target, lambda tmp: tmp.write_text("new"))
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["kept", "report.md"]


def test_a_nan_reward_in_an_evaluation_stops_with_a_checkpoint_naming_step_and_value(
    tmp_path, capsys
):
    run_dir = tmp_path / "run"
    flags = [*TINY, "--env", NAN_ENV, "--env-kwargs", '{"nan_at": 5}', "--run-dir", str(run_dir)]
    # the initial evaluation plays before any training step: its env's 5th step is NaN
    assert train_cli.main([*flags, "--total-env-steps", "100"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "returned the reward nan at step 5 of evaluation episode 0" in err
    assert "Stopped at env step 0 with a checkpoint" in err and "--resume" in err
    counters = load_checkpoint(run_dir)["state"]["counters"]
    assert counters["env_step"] == 0 and counters["eval_pending"]
    assert not (run_dir / "eval.csv").is_file() or read_csv(run_dir / "eval.csv") == []
