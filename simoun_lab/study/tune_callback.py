"""Ray Tune's side of the archive: each finished run is copied as its trial completes, so the
archive can be committed while the study runs. Imported only once Ray is there."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ray import tune

from simoun_lab.study.archive import archive_run


class ArchiveOnComplete(tune.Callback):
    """Copy a completed trial's run into the archive (a trial stopped on SIGTERM completes
    too, unfinished: :func:`~simoun_lab.study.archive.archive_run` then copies nothing)."""

    def __init__(self, study_dir: Path, archive: Path, names: dict[str, str]) -> None:
        self.study_dir, self.archive = study_dir, archive
        self.names = names
        """Tune's trial name -> the run's path under the study directory"""

    def on_trial_complete(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
        name = self.names.get(trial.config["trial"])
        if name is not None:
            archive_run(self.study_dir, self.archive, name)
