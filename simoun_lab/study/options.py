"""The options of running a study (``simoun-study run``), apart from the runner: the command
line reads them without importing torch or Ray, so ``--help`` and a bad flag are answered at
once."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

__all__ = ["StudyOptions"]


@dataclass
class StudyOptions:
    """Where and how :func:`simoun_lab.study.runner.run_study` runs a study (the options of
    ``simoun-study run``)."""

    study_dir: Path
    """where the runs and the report go; on a cluster, a directory every machine sees"""
    archive: Path | None = None
    """copy each finished run's CSVs, config.json and summary.json (no checkpoints, replays,
    videos or tb/) here as it completes, with the study record, the selection and the report,
    e.g. docs/studies/NAME; a resumed study counts archived runs as done"""
    resume: bool = False
    """continue the study: finished runs (in --study-dir, else in --archive) are kept, the
    others go on from their checkpoints or start"""
    allow_other_commit: bool = False
    """resume even though the code is at another commit than the study started from"""
    address: str | None = None
    """run on a Ray cluster: auto (the one `ray start` made here), HOST:PORT or
    ray://HOST:PORT; none: a local Ray instance"""
    num_cpus: int | None = None
    """CPUs of the local Ray instance (none: all)"""
    verbose: Literal[0, 1, 2] = 1
    """Tune's output"""
