"""Generalization from the study's own runs (the paper's Fig. 8): once an evaluation run has
finished, its final agent (``checkpoint.pt``) plays the train mode and each of the spec's
distraction modes (:mod:`simoun_agent.generalization`), the same episodes on the run's
evaluation seeds, and the returns go into the run's ``generalization.csv``, which the archive
keeps. Nothing is trained again; a run restored from the archive without its checkpoint cannot
be played and is reported as missing.
"""

from __future__ import annotations

import csv
from dataclasses import asdict
from pathlib import Path

from simoun_agent import table
from simoun_agent.generalization.evaluation import evaluate_runs
from simoun_agent.run.layout import CHECKPOINT_NAME
from simoun_lab.study.archive import GENERALIZATION_CSV, copy_file

COLUMNS = ("mode", "return_mean", "return_std", "episodes", "first_seed", "env_step")
"""The columns of ``generalization.csv``: one row per mode, ``train`` first."""


def play_modes(run_dir: str, modes: list[str], episodes: int) -> str:
    """Play the final agent of the finished run at ``run_dir`` on the train mode and ``modes``,
    ``episodes`` each, and write its ``generalization.csv``; returns the file's path."""
    results = evaluate_runs([Path(run_dir)], ["train", *modes], episodes)
    path = Path(run_dir, GENERALIZATION_CSV)
    table.write_csv(path, COLUMNS, map(asdict, results))
    return str(path)


def read_modes(run_dir: Path, env_step: int) -> dict[str, float] | None:
    """Mode -> mean return of the run's ``generalization.csv``; None when it has none, or when
    its agent was not the final one (a checkpoint at another env step than ``env_step``)."""
    path = run_dir / GENERALIZATION_CSV
    if not path.is_file():
        return None
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    if any(int(float(row["env_step"])) != env_step for row in rows):
        return None
    return {row["mode"]: float(row["return_mean"]) for row in rows}


def to_play(study_dir: Path, archive: Path | None, names: list[str]) -> list[str]:
    """The finished runs among ``names`` (paths under the study directory) still to play: those
    whose ``generalization.csv`` is neither in the run directory nor in the archive (an archived
    one is copied back, so the report finds it)."""
    todo = []
    for name in names:
        here = study_dir / name / GENERALIZATION_CSV
        kept = None if archive is None else archive / name / GENERALIZATION_CSV
        if here.is_file():
            continue
        if kept is not None and kept.is_file():
            copy_file(kept, here)
            continue
        todo.append(name)
    return todo


def playable(run_dir: Path) -> bool:
    """Whether the run's final agent is there to play (the checkpoint of the run's end; a run
    restored from the archive keeps none)."""
    return (run_dir / CHECKPOINT_NAME).is_file()
