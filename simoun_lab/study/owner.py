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
    full = Path(os.path.abspath(path))  # sw/base/.. is sw itself, not a folder inside it
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


SWEEP_FILE = "sweep.json"
"""A simoun-sweep directory's record (:data:`simoun_lab.sweep.grid.SWEEP_FILE`)."""


def sweep_folder(where: Path) -> str | None:
    """``"a simoun-sweep directory (DIR/sweep.json)"`` when ``where`` keeps a sweep's record."""
    if not (where / SWEEP_FILE).is_file():
        return None
    return f"a simoun-sweep directory ({shown(where / SWEEP_FILE)})"


def enclosing_sweep(path: Path) -> tuple[Path, str] | None:
    """The sweep directory ``path`` lies inside (relative, as ``path`` is given), with what it
    is (:func:`sweep_folder`); None when it lies in none. Every folder of a sweep directory is
    the sweep's: its trials' and its report's."""
    full = Path(os.path.abspath(path))  # sw/base/.. is sw itself, not a folder inside it
    for parent in full.parents:
        given = Path(os.path.relpath(parent)) if not path.is_absolute() else parent
        found = sweep_folder(given)
        if found is not None:
            return given, found
    return None


def check_not_in_sweep(path: Path, flag: str, inside_only: bool = False) -> None:
    """Refuse ``flag``'s directory ``path``, where a study or sweep is about to write, when it
    is a simoun-sweep directory (unless ``inside_only``: ``--sweep-dir`` itself names one to
    resume) or lies inside one: its runs and records would mix into that sweep's, whose report
    reads every run under it."""
    found = None if inside_only else sweep_folder(path)
    if found is not None:
        raise SetupError(
            f"{flag} {shown(path)} is {found}: writing there would mix runs and records into "
            f"that sweep's; pass a new directory (resume the sweep with simoun-sweep --resume "
            f"--sweep-dir {shown(path)})"
        )
    inside = enclosing_sweep(path)
    if inside is not None:
        sweep, found = inside
        raise SetupError(
            f"{flag} {shown(path)} lies inside {shown(sweep)}, {found}: its runs and records "
            f"would mix into that sweep's, whose report reads every run under it; pass a "
            f"directory of its own, outside {shown(sweep)}"
        )


def check_not_other_archive(path: Path, flag: str) -> None:
    """Refuse ``flag``'s working directory ``path`` (Ray's records and the runs in progress)
    when it is a study's archive (:func:`sac_study`, :func:`minigrid_study`): the archive given
    with it is another folder, so this one is another study's, whose runs and records the work
    would mix with."""
    found = sac_study(path) or minigrid_study(path)
    if found is None:
        return
    record = PPO_SPEC_FILE if minigrid_study(path) else STUDY_FILE
    raise SetupError(
        f"{flag} {shown(path)} is the archive of another study, {found}: Ray's records and the "
        f"runs in progress would go among that study's runs; pass a new directory to {flag} "
        f"(that study is resumed with its own archive, which holds its {record})"
    )
