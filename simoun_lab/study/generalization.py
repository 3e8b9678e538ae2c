"""Generalization from the study's own runs (the paper's Fig. 8): once an evaluation run has
finished, its final agent (``checkpoint.pt``) plays the train mode and each of the spec's
distraction modes (:mod:`simoun_agent.generalization`), the same episodes on the run's
evaluation seeds, and the returns go into the run's ``generalization.csv``, which the archive
keeps. Nothing is trained again; a run restored from the archive without its checkpoint cannot
be played and is reported as missing.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from simoun_agent import table
from simoun_agent.config import SetupError
from simoun_agent.generalization.evaluation import evaluate_runs
from simoun_agent.run.kept import Damaged, csv_number, present, read_csv_rows
from simoun_agent.run.layout import CHECKPOINT_NAME
from simoun_lab.study.archive import GENERALIZATION_CSV, copy_file

COLUMNS = ("mode", "return_mean", "return_std", "episodes", "first_seed", "env_step")
"""The columns of ``generalization.csv``: one row per mode, ``train`` first."""
MODE_COLUMNS = ("mode", "env_step", "return_mean")
"""The columns of ``generalization.csv`` the report reads."""


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
    if not present(path):
        return None
    try:
        played = [
            (row["mode"], *(csv_number(row[key], key, line) for key in ("env_step", "return_mean")))
            for line, row in enumerate(read_csv_rows(path, MODE_COLUMNS), start=2)
        ]
    except Damaged as err:
        problem = str(err)
    except OSError as err:
        problem = f"it cannot be read ({err.strerror})"
    else:
        if any(step != env_step for _, step, _ in played):
            return None
        return {mode: value for mode, _, value in played}
    raise SetupError(
        f"{path} is damaged: {problem}. Restore it from a copy (the study directory and its "
        f"archive each keep one), or move it aside in both (mv {path} {path}.damaged) and "
        "resume the study: the run's final agent is then played again"
    )


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
