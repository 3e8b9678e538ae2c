"""Run logs: CSV files, TensorBoard scalars and the learning-curve PNG.

``eval.csv`` holds one row per evaluation and ``train.csv`` one row per training episode; both
are plain CSV for pandas or a spreadsheet. The same numbers go to TensorBoard under ``tb/``.
``learning_curve.png`` is redrawn from ``eval.csv`` after every evaluation, so it always shows
the whole run, resumed parts included.
"""

from __future__ import annotations

import csv
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import (
    Damaged,
    csv_lines,
    csv_number,
    header_problem,
    kind_problem,
    read_csv_rows,
    step_count,
)
from simoun_agent.run.layout import CURVE_PNG, EVAL_CSV, TENSORBOARD_DIR, TRAIN_CSV


class CsvLog:
    """Append rows of a fixed set of columns to a CSV file, flushed at each row.

    On resume (``resume_step`` given) rows logged after that step are dropped: they belong to
    the part of the run that the checkpoint does not hold and that will be redone.
    """

    def __init__(self, path: Path, resume_step: int | None = None) -> None:
        self.path = path
        self.columns: list[str] | None = None
        self.last_row: dict[str, str] | None = None
        """the last row kept on resume (None for a new log)"""
        self.last_step: int | None = None
        """env step of the last row in the file (None while it has none)"""
        if resume_step is not None and path.exists():
            self.columns, rows = read_log(path)
            rows = [row for row in rows if int(row["env_step"]) <= resume_step]
            self._rewrite(rows)
            self.last_row = rows[-1] if rows else None
            self.last_step = None if self.last_row is None else int(self.last_row["env_step"])
        elif path.exists():
            path.unlink()

    def _rewrite(self, rows: list[dict[str, str]]) -> None:
        def write(tmp: Path) -> None:
            with tmp.open("w", newline="") as f:
                writer = csv.DictWriter(f, self.columns)
                writer.writeheader()
                writer.writerows(rows)

        atomic_write(self.path, write)

    def write(self, row: dict[str, Any]) -> None:
        """Append ``row``; a key not seen before adds a column (the file is rewritten once)."""
        if self.columns is None:
            self.columns = list(row)
            self._rewrite([])
        elif any(key not in self.columns for key in row):
            rows = read_csv_rows(self.path)
            self.columns += [key for key in row if key not in self.columns]
            self._rewrite(rows)
        with self.path.open("a", newline="") as f:
            csv.DictWriter(f, self.columns).writerow(row)
        self.last_step = int(row["env_step"])


def read_log(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    """The columns and rows of a log written by :class:`CsvLog`, checked before a resumed run
    rewrites it; SetupError naming the file, the damage and the fix when it is empty, has no
    ``env_step`` header, has another file's header (:func:`~simoun_agent.run.kept.kind_problem`:
    train.csv copied over eval.csv), or has a row that does not fit the header. Nothing is
    changed then: the user's file stays as it is."""
    try:
        lines = csv_lines(path)
    except Damaged as err:
        raise damaged_log(path, str(err)) from None
    if not lines or "env_step" not in lines[0]:
        problem = "it is empty" if not lines else header_problem(lines[0])
        raise damaged_log(path, problem or "its first line has no env_step column")
    columns, at = lines[0], lines[0].index("env_step")
    rows = []
    for number, values in enumerate(lines[1:], start=2):
        if len(values) != len(columns):
            fields = f"{len(values)} fields where the header has {len(columns)}"
            raise damaged_log(path, f"line {number} has {fields}")
        try:
            step = step_count(values[at])
        except Damaged as err:
            raise damaged_log(path, f"line {number}'s {err}") from None
        if rows and step <= int(rows[-1]["env_step"]):
            raise damaged_log(path, f"line {number}'s env_step {values[at]} does not come after "
                              f"line {number - 1}'s {rows[-1]['env_step']} (rows out of order or "
                              "repeated)")  # fmt: skip
        # written back as the run writes it: a resumed log holds one spelling of its steps
        rows.append({**dict(zip(columns, values, strict=True)), "env_step": str(step)})
    problem = kind_problem(path.name, columns)
    if problem:
        raise damaged_log(path, problem)
    return columns, rows


def damaged_log(path: Path, problem: str) -> SetupError:
    """The error for a damaged log: what is wrong, that nothing was changed, and two fixes that
    let the run resume (a resumed run without the file starts it again)."""
    return SetupError(
        f"{path} is damaged: {problem}. Nothing in the run was changed. Restore the file from a "
        f"copy, or move it aside (mv {path} {path}.damaged) and resume again: the run goes on "
        f"from its checkpoint with a new {path.name} from there"
    )


def read_csv(
    path: str | os.PathLike[str], columns: Sequence[str] = ("env_step",)
) -> list[dict[str, float]]:
    """Rows of a CSV written by :class:`CsvLog` (a str or a path), numbers as floats (NaN where
    empty); :class:`~simoun_agent.run.kept.Damaged` (a ValueError) naming the file for text no
    run writes (:func:`log_values`); TypeError when ``path`` is neither a str nor a path, or
    ``columns`` (names the header must hold) not a list or tuple of str. An empty file has no
    rows."""
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(
            f"read_csv's path must be a str or a pathlib.Path of a CSV log, not "
            f"{type(path).__name__}; pass read_csv('RUN_DIR/eval.csv')"
        )
    check_columns(columns)
    try:
        return log_values(Path(path), tuple(columns))
    except Damaged as err:
        raise Damaged(f"{path} cannot be read as a CSV log: {err}") from None


def check_columns(columns: Any) -> None:
    """TypeError naming read_csv's ``columns`` when it is not a list or tuple of column names:
    a single str would be read as one name per character, and the file blamed for them."""
    if isinstance(columns, (list, tuple)) and all(isinstance(name, str) for name in columns):
        return
    shown = f"{type(columns).__name__} {columns!r:.60}"
    example = f"({columns!r},)" if isinstance(columns, str) else "('return_mean',)"
    raise TypeError(
        f"read_csv's columns must be a list or tuple of column names, not {shown}; pass "
        f"columns={example}"
    )


def log_values(path: Path, columns: Sequence[str] = ("env_step",)) -> list[dict[str, float]]:
    """:func:`read_csv` for a caller that names the file itself: :class:`Damaged` saying what
    is wrong for a first line of numbers (the header deleted), a header without one of
    ``columns``, a value that is not a number (its line and column named), a JSON file, and
    what :func:`~simoun_agent.run.kept.read_csv_rows` refuses."""
    rows = read_csv_rows(path, columns, empty_ok=True)
    return [
        {column: csv_number(text, column, line) for column, text in row.items()}
        for line, row in enumerate(rows, start=2)
    ]


def plot_learning_curve(eval_csv: Path, png: Path, title: str) -> None:
    """Draw mean evaluation return (with its min-max band) against environment steps."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = read_csv(eval_csv)
    steps = [row["env_step"] for row in rows]
    mean = [row["return_mean"] for row in rows]
    fig, ax = plt.subplots(figsize=(6, 4), dpi=110)
    ax.fill_between(
        steps,
        [row["return_min"] for row in rows],
        [row["return_max"] for row in rows],
        alpha=0.25,
        label="min-max over episodes",
    )
    ax.plot(steps, mean, marker="o", label="mean evaluation return")
    # Test curves beside the training env's (simoun-train --eval-distraction), as in DMC-GB.
    for key in rows[0] if rows else ():
        if key.endswith("/return_mean"):
            mode = key.removesuffix("/return_mean")
            ax.plot(steps, [row[key] for row in rows], marker=".", label=f"{mode} (mean)")
    ax.set_xlabel("environment steps")
    ax.set_ylabel("episode return")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(loc="best")
    fig.tight_layout()
    atomic_write(png, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)


class RunLogger:
    """Everything a training run logs, in one place.

    Args:
        run_dir: the run directory.
        title: the learning curve's title (e.g. the env id and preset).
        resume_step: the checkpoint's env step when resuming, else None.
    """

    def __init__(self, run_dir: Path, title: str, resume_step: int | None = None) -> None:
        from torch.utils.tensorboard import SummaryWriter

        self.run_dir = run_dir
        self.title = title
        self.eval_log = CsvLog(run_dir / EVAL_CSV, resume_step)
        self.train_log = CsvLog(run_dir / TRAIN_CSV, resume_step)
        self.tensorboard = SummaryWriter(run_dir / TENSORBOARD_DIR, purge_step=resume_step)
        last = self.eval_log.last_row
        self.last_eval_step: int | None = None if last is None else int(last["env_step"])
        """env step of the latest evaluation in eval.csv (a resumed run's included)"""
        self.last_eval: dict[str, float] | None = None
        """its metrics (as logged, without env_step)"""
        if last is not None:
            self.last_eval = {k: float(v or "nan") for k, v in last.items() if k != "env_step"}

    def train_episode(self, env_step: int, row: dict[str, Any]) -> None:
        """One finished training episode: return, length, speed and the last update's losses."""
        self.train_log.write({"env_step": env_step, **row})
        for key, value in row.items():
            if isinstance(value, (int, float)) and math.isfinite(value):
                self.tensorboard.add_scalar(f"train/{key}", value, env_step)

    def evaluation(self, env_step: int, metrics: dict[str, float]) -> None:
        """One evaluation: append to eval.csv, TensorBoard, and redraw the learning curve."""
        self.eval_log.write({"env_step": env_step, **metrics})
        self.last_eval_step, self.last_eval = env_step, dict(metrics)
        for key, value in metrics.items():
            if math.isfinite(value):
                self.tensorboard.add_scalar(f"eval/{key}", value, env_step)
        self.tensorboard.flush()
        plot_learning_curve(self.run_dir / EVAL_CSV, self.run_dir / CURVE_PNG, self.title)

    def last_steps(self) -> dict[str, int | None]:
        """The env step of each log's last row, by file name (None for a log with no row yet):
        saved with a checkpoint, so that a resumed run can tell a log restored from an older
        copy, which lacks rows the checkpoint had logged."""
        return {EVAL_CSV: self.eval_log.last_step, TRAIN_CSV: self.train_log.last_step}

    def close(self) -> None:
        self.tensorboard.close()
