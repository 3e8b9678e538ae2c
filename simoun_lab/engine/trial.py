"""What one run must offer the study engine (:mod:`simoun_lab.engine.launcher`).

A run lives in its run directory and is finished once its ``summary.json`` exists: the run
writes it last, so its presence marks a whole run. The engine trains each unfinished trial on
Ray Tune, hands each checkpoint the trial writes to Tune (then to the archive), and copies the
trial's ``run_files`` into the archive once it has finished.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Protocol, runtime_checkable

from simoun_agent.config import SetupError
from simoun_agent.run.kept import reading
from simoun_agent.run.layout import LOCK_NAME, SUMMARY_NAME
from simoun_agent.run.rundir import lock_holder

__all__ = ["SUMMARY", "Trial", "check_no_live_runs", "summary_written"]

SUMMARY = SUMMARY_NAME
"""a finished run's summary, written last: its presence marks a finished run"""


def summary_written(run_dir: Path | str) -> bool:
    """Whether the run directory ``run_dir`` holds a finished run; :class:`~simoun_agent.run.
    kept.Unreadable` for a run folder the user may not enter (a colleague's private run)."""
    path = Path(run_dir) / SUMMARY
    with reading(path):
        return path.is_file()


def check_no_live_runs(folder: Path, what: str, kind: str = "run") -> None:
    """SetupError naming the first run directory under ``folder`` (``what``'s: ``the sweep``,
    ``the study``; each one a ``kind``, trial or run) whose lock a running trainer holds
    (:func:`~simoun_agent.run.rundir.lock_holder`, which writes nothing): ``what`` is still
    running in another process, and a second one would train the same runs over each other.
    Called before Ray starts."""
    if not folder.is_dir():
        return
    for lock in sorted(folder.rglob(LOCK_NAME)):
        try:
            holder = lock_holder(lock.parent)
        except OSError:
            continue  # a lock that cannot be read is named by the trainer that meets it
        if holder is not None:
            raise SetupError(
                f"{kind} {lock.parent.relative_to(folder)} of {what} in {folder} is in use by "
                f"another trainer (PID {holder}): {what} is still running in another process, "
                "and two trainers in one run directory would overwrite each other's "
                f"checkpoints. Wait for it to end, or stop it (Ctrl-C where it runs, or kill "
                f"-TERM {holder}), then run this command again"
            )


@runtime_checkable
class Trial(Protocol):
    """One run of a study or sweep, as the engine runs it (pickled to Ray's workers)."""

    @property
    def name(self) -> str:
        """unique among the trials launched together; the run's path under the archive"""
        ...

    @property
    def run_dir(self) -> str:
        """where the run writes its files (absolute: Tune runs each trial in a folder of its
        own)"""
        ...

    @property
    def run_files(self) -> tuple[str, ...]:
        """the files of a finished run that the archive keeps, ``summary.json`` last"""
        ...

    @property
    def checkpoint(self) -> str | None:
        """the file name of the run's checkpoint, carried into the archive while the run is in
        progress and resumed from there when the run directory is gone (None: not carried,
        e.g. one holding a replay buffer)"""
        ...

    def finished(self) -> bool:
        """Whether the run in ``run_dir`` has finished."""
        ...

    def train(self, on_checkpoint: Callable[[Path], None] | None) -> None:
        """Train the run in ``run_dir`` to its end (going on from a checkpoint there), calling
        ``on_checkpoint`` with each checkpoint it writes; a run asked to stop may return
        unfinished."""
        ...
