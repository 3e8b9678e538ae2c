"""The SAC trainer behind the engine's trial interface: each trial is one ordinary ``simoun-train``
run in its own run directory, reporting every evaluation to Tune through a
:class:`~simoun_agent.run.callback.TrainCallback`.

A trial continues from its run directory's checkpoint when there is one (a resumed sweep), and
writes ``error.txt`` (the traceback) into its run directory when it fails, so the failure stays
visible beside the run, to ``simoun-report`` too, without Ray. ``trial.json`` records where,
under what machine load and with how much CPU time each part of the trial ran.
"""

from __future__ import annotations

import json
import math
import os
import resource
import shutil
import signal
import socket
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError, resolve
from simoun_agent.config.rules import is_real
from simoun_agent.generalization import check_eval_distractions, distraction_callbacks
from simoun_agent.run import train
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import Damaged, present, read_json_object
from simoun_agent.run.layout import CHECKPOINT_NAME, CONFIG_NAME, SUMMARY_NAME
from simoun_agent.run.signals import Stopped
from simoun_lab.sweep.grid import Trial
from simoun_lab.sweep.report import ERROR_FILE

TRIAL_FILE = "trial.json"
"""Written by each trial into its run directory: one entry per part it ran (a resumed trial has
several), with the start time, host, CPU count, load average at the start, env steps, wall and
CPU seconds (:func:`start_part`, :func:`end_part`)."""

STOP_FILE = "STOP"
"""Written into the sweep directory by ``simoun-sweep`` on SIGTERM: every trial then stops at
its next step with a checkpoint (a Ray trial runs in a worker thread, where no signal reaches
it), and ``simoun-sweep --resume`` goes on from there."""


class StopFile(train.TrainCallback):
    """Ask the trial's training loop to stop, as on SIGTERM, once ``path`` exists."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def stop_requested(self, run: train.Run) -> int | None:
        return signal.SIGTERM if self.path.exists() else None


class TuneReporter(train.TrainCallback):
    """Report each logged evaluation (``env_step``, ``return_mean``, ``wall_time_s``, ...) to Tune,
    so its progress table and TensorBoard show live curves."""

    def on_logged(self, run: train.Run, metrics: dict[str, float]) -> None:
        from ray import tune

        tune.report({"env_step": run.counters.env_step, **metrics})


def trial_budget(trial: Trial) -> int:
    """The env steps the trial trains to (its overrides', else its preset's)."""
    return resolve(trial.preset, trial.overrides).total_env_steps


def open_run(trial: Trial) -> train.Run:
    """The trial's run: continued from its checkpoint (to the trial's budget, which an extended
    sweep raised), else started afresh.

    A run directory with ``config.json`` but no checkpoint was stopped before its first
    checkpoint: it holds nothing to continue from, so its files are removed and it starts over.
    """
    run_dir = Path(trial.run_dir)
    if (run_dir / CHECKPOINT_NAME).is_file():
        budget = {"total_env_steps": trial_budget(trial)}
        return train.resume_run(run_dir, budget, check=check_eval_distractions)
    if (run_dir / CONFIG_NAME).is_file():
        shutil.rmtree(run_dir)
    config = resolve(trial.preset, trial.overrides)
    return train.create_run(config, check=check_eval_distractions)


def finished(trial: Trial) -> bool:
    """True once the trial's run has ended at the sweep's budget (a sweep extended with a larger
    ``--total-env-steps`` makes its finished runs unfinished again)."""
    path = Path(trial.run_dir) / SUMMARY_NAME
    if not path.is_file():
        return False
    try:
        done = read_json_object(path).get("env_step")
    except (Damaged, OSError):
        done = None
    if not is_real(done):
        return True  # damaged: check_trial_dirs refuses it before a sweep starts or resumes
    return done >= trial_budget(trial)


@dataclass(frozen=True)
class SacTrial:
    """A sweep trial (one ``simoun-train`` run) as the engine's
    :class:`~simoun_lab.engine.trial.Trial`: trained to the end, or until ``stop_file`` appears
    (then it ends unfinished, with a checkpoint to resume from). Its checkpoint holds the replay
    buffer, too large to carry into an archive."""

    run: Trial
    """the sweep's trial"""
    name: str
    """the run's name in the Tune experiment and its path under the archive"""
    stop_file: str | None = None
    run_files: tuple[str, ...] = ()
    """the files an archive keeps of the finished run"""
    checkpoint: str | None = None

    @property
    def run_dir(self) -> str:
        return self.run.run_dir

    def finished(self) -> bool:
        return finished(self.run)

    def train(self, on_checkpoint: Callable[[Path], None] | None = None) -> None:
        """Train the run, writing ``error.txt`` (the traceback) into its run directory when it
        fails (``on_checkpoint`` is not called: the checkpoint is not carried)."""
        run_dir = Path(self.run_dir)
        callbacks: list[train.TrainCallback] = [TuneReporter()]
        if self.stop_file is not None:
            callbacks.append(StopFile(Path(self.stop_file)))
        try:
            run = open_run(self.run)
            part = start_part(run)
            try:
                train.train(run, callbacks=[*distraction_callbacks(run.config), *callbacks])
            except Stopped:
                return
            finally:
                run.env.close()
                run.eval_env.close()
                end_part(run, part)
        except Exception:
            text = traceback.format_exc()
            run_dir.mkdir(parents=True, exist_ok=True)
            atomic_write(run_dir / ERROR_FILE, lambda tmp: tmp.write_text(text))
            raise
        (run_dir / ERROR_FILE).unlink(missing_ok=True)


def cpu_seconds() -> float:
    """CPU time of this process (all its threads: the trial, and Ray's own in its worker) and of
    its finished children (a background env process once closed), user + system."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def start_part(run: train.Run) -> dict[str, Any]:
    """Append this part of the trial (a resumed trial has several) to its ``trial.json``: when
    and where it started and how loaded the machine was then (``os.getloadavg``: processes
    running or waiting for a CPU, averaged over 1, 5 and 15 minutes)."""
    part = {
        "started_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "host": socket.gethostname(),
        "cpu_count": os.cpu_count(),
        "loadavg": list(os.getloadavg()),
        "env_step_start": run.counters.env_step,
        "_cpu_start": cpu_seconds(),
        "_wall_start": time.perf_counter(),
    }
    _write_part(run.run_dir, part)
    return part


def end_part(run: train.Run, part: dict[str, Any]) -> None:
    """Complete this part's entry in ``trial.json`` with its env steps, wall and CPU time."""
    part["env_step_end"] = run.counters.env_step
    part["wall_s"] = time.perf_counter() - part["_wall_start"]
    part["cpu_s"] = cpu_seconds() - part["_cpu_start"]
    _write_part(run.run_dir, part, replace_last=True)


def _write_part(run_dir: Path, part: dict[str, Any], replace_last: bool = False) -> None:
    """Append ``part`` to ``trial.json`` (or replace its last entry), leaving out the private
    ``_`` entries."""
    parts = read_trial_parts(run_dir)[: -1 if replace_last else None]
    parts.append({key: value for key, value in part.items() if not key.startswith("_")})
    text = json.dumps({"parts": parts}, indent=2) + "\n"
    atomic_write(run_dir / TRIAL_FILE, lambda tmp: tmp.write_text(text))


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


PART_FIELDS: dict[str, tuple[Callable[[Any], bool], str]] = {
    "cpu_count": (lambda v: _number(v) and v == int(v) and v >= 1, "a whole number of CPUs"),
    "loadavg": (
        lambda v: isinstance(v, list) and len(v) == 3 and all(_number(x) and x >= 0 for x in v),
        "an array of the 1, 5 and 15-minute load averages (3 numbers, 0 or more)",
    ),
    "env_step_start": (lambda v: _number(v) and v == int(v) and v >= 0, "an env step count"),
    "env_step_end": (lambda v: _number(v) and v == int(v) and v >= 0, "an env step count"),
    "wall_s": (lambda v: _number(v) and v >= 0, "seconds (a number, 0 or more)"),
    "cpu_s": (lambda v: _number(v) and v >= 0, "seconds (a number, 0 or more)"),
}
"""The fields of a ``trial.json`` part that reports compute with, and what each must be."""


def part_problem(part: dict[str, Any], number: int) -> str | None:
    """What is wrong with the ``number``-th part of a ``trial.json`` (a field of
    :data:`PART_FIELDS` of the wrong type or range), else None; a field not yet written (a part
    still running has no ``cpu_s``) is left out."""
    for key, (ok, need) in PART_FIELDS.items():
        if key in part and not ok(part[key]):
            return f"part {number}'s {key} is {json.dumps(part[key])}, where {need} belongs"
    return None


def read_trial_parts(run_dir: Path) -> list[dict[str, Any]]:
    """The parts recorded in a run directory's ``trial.json`` (none without one); SetupError
    naming the file, what is wrong and the fix when it is damaged."""
    path = Path(run_dir) / TRIAL_FILE
    if not present(path):
        return []
    try:
        parts = read_json_object(path).get("parts")
    except Damaged as err:
        problem = str(err)
    else:
        if isinstance(parts, list) and all(isinstance(part, dict) for part in parts):
            problem = next(filter(None, map(part_problem, parts, range(1, len(parts) + 1))), None)
            if problem is None:
                return parts
        else:
            problem = "its parts are not an array of JSON objects (one per part the run ran)"
    raise SetupError(
        f"{path} is damaged: {problem}. Restore it from a copy (a study's archive keeps one), or "
        f"move it aside (mv {path} {path}.damaged): the run's CPU time and machine load are then "
        "left out"
    )
