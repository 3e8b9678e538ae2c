"""The archive of a study: what must survive it, small enough to commit while the study runs.

``--archive DIR`` (e.g. ``docs/studies/dmc100k``) gets ``study.json`` (the spec and the commit
it ran from), each finished run's logs and records as the run completes, the selection and the
report; no checkpoints, replay files, videos, learning-curve images or TensorBoard logs. A run
is archived only once finished (``summary.json``, copied last, marks a complete copy), so a
resumed study treats an archived run as done and copies it back when its run directory is gone.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from simoun_agent.config import SetupError
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.layout import CONFIG_NAME, EVAL_CSV, SUMMARY_NAME, TRAIN_CSV
from simoun_lab.engine.launcher import archive_files, read_run_files
from simoun_lab.sweep.trainable import TRIAL_FILE

GENERALIZATION_CSV = "generalization.csv"
"""A finished evaluation run's returns under the distraction modes
(:mod:`simoun_lab.study.generalization`), written after the run."""

RUN_FILES = (CONFIG_NAME, EVAL_CSV, TRAIN_CSV, TRIAL_FILE, GENERALIZATION_CSV, SUMMARY_NAME)
"""What the archive keeps of a finished run, ``summary.json`` last (its mark of a whole copy)."""


def check_archive_apart(archive: Path, other: Path, other_flag: str, example: str) -> None:
    """Refuse an ``--archive`` that is the working directory ``other`` (given as ``other_flag``),
    lies inside it or holds it: the archive is the finished runs' copy, and runs found under
    one would be read twice, or the records it keeps removed with the working directory.
    ``example`` is a directory apart to suggest."""
    kept, work = archive.resolve(), other.resolve()
    if kept == work:
        problem = f"--archive {archive} is the {other_flag} itself"
    elif work in kept.parents:
        problem = f"--archive {archive} is inside {other_flag} {other}"
    elif kept in work.parents:
        problem = f"{other_flag} {other} is inside --archive {archive}"
    else:
        return
    raise SetupError(
        f"{problem}; the archive keeps a copy of the finished runs apart from the {other_flag} "
        f"records: pass directories apart from each other (e.g. --archive {example})"
    )


def copy_file(source: Path, target: Path) -> None:
    """Copy ``source`` to ``target`` atomically (a reader never sees half a file)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(target, lambda tmp: shutil.copyfile(source, tmp))


def archive_run(study_dir: Path, archive: Path, name: str) -> bool:
    """Copy the finished run ``name`` (its path under the study directory) into the archive;
    False, copying nothing, when it has not finished or is archived already."""
    run_dir, kept = study_dir / name, archive / name
    if not (run_dir / SUMMARY_NAME).is_file() or (kept / SUMMARY_NAME).is_file():
        return False
    archive_files(archive, name, read_run_files(run_dir, RUN_FILES))
    return True


def restore_run(study_dir: Path, archive: Path, name: str) -> bool:
    """Copy an archived finished run back into the study directory when its run directory has
    no finished run (it was deleted, or the study moved to another machine); returns whether it
    did. Files the archive lacks (a checkpoint of an earlier part) are left as they are."""
    run_dir, kept = study_dir / name, archive / name
    if (run_dir / SUMMARY_NAME).is_file() or not (kept / SUMMARY_NAME).is_file():
        return False
    for file in RUN_FILES:
        if (kept / file).is_file():
            copy_file(kept / file, run_dir / file)
    return True


def archive_tree(source: Path, target: Path) -> None:
    """Copy every file under ``source`` (a report) to ``target``, each atomically."""
    for file in sorted(source.rglob("*")):
        if file.is_file():
            copy_file(file, target / file.relative_to(source))
