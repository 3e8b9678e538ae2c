"""Which study a directory belongs to, told before a study writes into it: a SAC study's
directory or archive keeps its record (``study.json``), a MiniGrid PPO study's archive its spec
(``spec.json``) beside one folder per task. A study given another study's directory, or a
folder inside another study's archive (``--archive docs/studies/dmc100k/tuning``), would write
its record and runs over that study's.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.kept import Damaged, read_json_object
from simoun_lab.study.given_path import shown
from simoun_lab.study.record_file import RECORD_KEYS

STUDY_FILE = "study.json"
"""A SAC study's record (:data:`simoun_lab.study.runner.STUDY_FILE`)."""

PPO_SPEC_FILE = "spec.json"
"""A MiniGrid PPO study's spec in its archive
(:data:`simoun_lab.minigrid_study.runner.SPEC_FILE`)."""

OWN_FOLDERS = ("tuning", "evaluation", "tune", "report")
"""Folders a study writes in its directory or archive beside its tasks' (a MiniGrid study's):
the SAC study's phases, Ray Tune's records, the report."""


def read_object(path: Path) -> dict[str, Any] | None:
    """The JSON object in ``path``, read as every kept file is
    (:func:`~simoun_agent.run.kept.read_json_object`); None when it is not there or not one."""
    try:
        return read_json_object(path) if path.is_file() else None
    except Damaged:
        return None


def sac_study(where: Path) -> str | None:
    """``"a SAC study, 'dmc100k' (DIR/study.json)"`` when ``where`` keeps a study record."""
    record = read_object(where / STUDY_FILE)
    if record is None or not all(key in record for key in RECORD_KEYS):
        return None
    name = record["spec"].get("name") if isinstance(record["spec"], dict) else None
    return f"a SAC study, {name!r} ({shown(where / STUDY_FILE)})"


def minigrid_study(where: Path) -> str | None:
    """``"a MiniGrid PPO study (DIR/spec.json)"`` when ``where`` keeps a MiniGrid study's spec."""
    spec = read_object(where / PPO_SPEC_FILE)
    if spec is None or not isinstance(spec.get("tasks"), list) or "arms" not in spec:
        return None
    return f"a MiniGrid PPO study ({shown(where / PPO_SPEC_FILE)})"


def own_folders(where: Path) -> set[str]:
    """The folders directly under the archive ``where`` that its study writes: each phase or
    task folder of its spec, and :data:`OWN_FOLDERS`."""
    folders = set(OWN_FOLDERS)
    spec = read_object(where / PPO_SPEC_FILE) or {}
    for task in spec.get("tasks", []) if isinstance(spec.get("tasks"), list) else []:
        if isinstance(task, dict) and isinstance(task.get("env_id"), str):
            folders.add(task["env_id"])
    return folders


def enclosing_study(path: Path) -> tuple[Path, str] | None:
    """The study archive ``path`` lies inside (relative, as ``path`` is given), and the study
    (:func:`sac_study`, :func:`minigrid_study`): a parent that keeps a study's record or spec,
    with ``path`` under one of the folders that study writes (:func:`own_folders`); None when it
    lies in none."""
    full = path.absolute()
    for parent in full.parents:
        if full.relative_to(parent).parts[0] not in own_folders(parent):
            continue  # a folder of the study's own, not one beside its archive
        given = Path(os.path.relpath(parent)) if not path.is_absolute() else parent
        study = sac_study(given) or minigrid_study(given)
        if study is not None:
            return given, study
    return None


def check_not_inside_archive(path: Path, flag: str) -> None:
    """Refuse ``flag``'s directory ``path``, given as a study's archive to read, when it is a
    folder inside one (:func:`enclosing_study`): its archive is the one to pass."""
    found = enclosing_study(path)
    if found is None:
        return
    archive, study = found
    raise SetupError(
        f"{flag} {shown(path)} is a folder inside {shown(archive)}, the archive of {study}, not "
        f"an archive itself; pass the archive ({flag} {shown(archive)})"
    )


def check_not_inside_study(path: Path, flag: str) -> None:
    """Refuse ``flag``'s directory ``path`` when it lies inside another study's archive
    (:func:`enclosing_study`), before anything is written into it."""
    found = enclosing_study(path)
    if found is None:
        return
    archive, study = found
    raise SetupError(
        f"{flag} {shown(path)} lies inside {shown(archive)}, the archive of {study}: a study "
        f"written there would mix its record and runs into that archive's; pass a directory of "
        f"its own, outside {shown(archive)} (e.g. a new one beside it)"
    )
