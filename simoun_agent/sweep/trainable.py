"""Ray Tune's trainable: each trial is one ordinary ``simoun-train`` run in its own run directory,
reporting every evaluation to Tune through a :class:`~simoun_agent.run.train.TrainCallback`.

A trial continues from its run directory's checkpoint when there is one (a resumed sweep), and
writes ``error.txt`` (the traceback) into its run directory when it fails, so the failure stays
visible beside the run, to ``simoun-report`` too, without Ray.
"""

from __future__ import annotations

import shutil
import signal
import traceback
from dataclasses import asdict
from pathlib import Path
from typing import Any

from simoun_agent.run import train
from simoun_agent.run.checkpoint import CHECKPOINT_NAME, atomic_write
from simoun_agent.run.presets import resolve
from simoun_agent.run.signals import Stopped
from simoun_agent.sweep.grid import Trial
from simoun_agent.sweep.report import ERROR_FILE

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


def open_run(trial: Trial) -> train.Run:
    """The trial's run: continued from its checkpoint, else started afresh.

    A run directory with ``config.json`` but no checkpoint was stopped before its first
    checkpoint: it holds nothing to continue from, so its files are removed and it starts over.
    """
    run_dir = Path(trial.run_dir)
    if (run_dir / CHECKPOINT_NAME).is_file():
        return train.resume_run(run_dir, {})
    if (run_dir / train.CONFIG_NAME).is_file():
        shutil.rmtree(run_dir)
    return train.create_run(resolve(trial.preset, trial.overrides))


def run_trial(
    config: dict[str, Any], trials: dict[str, dict[str, Any]], stop_file: str | None = None
) -> None:
    """Tune's function trainable: train the trial named ``config["trial"]`` to the end, or until
    ``stop_file`` appears (then it ends unfinished, with a checkpoint to resume from)."""
    trial = Trial(**trials[config["trial"]])
    run_dir = Path(trial.run_dir)
    callbacks: list[train.TrainCallback] = [TuneReporter()]
    if stop_file is not None:
        callbacks.append(StopFile(Path(stop_file)))
    try:
        run = open_run(trial)
        try:
            train.train(run, callbacks=callbacks)
        except Stopped:
            return
        finally:
            run.env.close()
            run.eval_env.close()
    except Exception:
        text = traceback.format_exc()
        run_dir.mkdir(parents=True, exist_ok=True)
        atomic_write(run_dir / ERROR_FILE, lambda tmp: tmp.write_text(text))
        raise
    (run_dir / ERROR_FILE).unlink(missing_ok=True)


def trial_table(trials: list[Trial]) -> dict[str, dict[str, Any]]:
    """``{trial name: its fields}``, the lookup :func:`run_trial` is given (Tune's config then
    holds only the short name, which its progress table shows)."""
    return {trial.name: asdict(trial) for trial in trials}
