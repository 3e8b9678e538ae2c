"""The SB3 PPO MiniGrid trainer behind the engine's trial interface
(:class:`~simoun_lab.engine.trial.Trial`): one study run in its run directory under the work
directory, its checkpoint carried into the archive while it is in progress."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from simoun_agent.run.rundir import lock_run_dir
from simoun_lab.engine.trial import summary_written
from simoun_lab.minigrid_study.checkpoint import CHECKPOINT
from simoun_lab.minigrid_study.run import RUN_FILES, train_run
from simoun_lab.minigrid_study.spec import Run, StudySpec

__all__ = ["RUNS_DIR", "MiniGridTrial"]

RUNS_DIR = "runs"
"""the run directories under the work directory, kept across invocations for resuming"""


@dataclass(frozen=True)
class MiniGridTrial:
    """The study run ``run`` of ``spec``, trained in ``<work_dir>/runs/<task>/<arm>/s<seed>``;
    ``commit`` (the code's git commit) goes into its ``config.json``."""

    spec: StudySpec
    run: Run
    work_dir: str
    """absolute: Tune runs each trial in a folder of its own"""
    commit: str | None = None
    run_files: tuple[str, ...] = RUN_FILES
    checkpoint: str | None = CHECKPOINT

    @property
    def name(self) -> str:
        return self.run.name

    @property
    def run_dir(self) -> str:
        return str(Path(self.work_dir, RUNS_DIR, self.run.name))

    def finished(self) -> bool:
        return summary_written(self.run_dir)

    def train(self, on_checkpoint: Callable[[Path], None] | None = None) -> None:
        """Train the run, holding its run directory's lock
        (:func:`~simoun_agent.run.rundir.lock_run_dir`) as simoun-train does: a second study
        started on the same work directory is refused before it trains the run again."""
        run_dir = Path(self.run_dir)
        run_dir.mkdir(parents=True, exist_ok=True)
        with lock_run_dir(run_dir):
            train_run(self.spec, self.run, run_dir, self.commit, on_checkpoint)
