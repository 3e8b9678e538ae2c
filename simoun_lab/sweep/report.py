"""The report behind ``simoun-report DIR`` (:mod:`simoun_lab.cli.report`): compare the runs
of a sweep, or of any directory of ``simoun-train`` runs, per variant and env, over seeds (the
paper's Table 1 and Fig. 6), with the statistics of Agarwal et al. 2021 (rliable;
:mod:`simoun_lab.stats`). Needs no Ray.

    simoun-report sweeps/baselines
    simoun-report runs/ --out runs/report

Runs are found by their ``config.json``. A *variant* is the config values that tell runs of
the same env apart, seeds aside: a sweep's ``--grid`` keys, or, for plain runs, every key that
differs between two runs of one env (``seed``, ``run_dir`` and output-only keys excepted).
Only finished runs (``summary.json`` present) are counted; unfinished and failed ones are
listed. ``--at-step N`` / ``--at-wall-time SECONDS`` compare at an equal budget instead
(:func:`at_budget`). A row counts each seed once (:func:`drop_duplicate_seeds`) and runs of
one evaluation grid (:func:`one_evaluation_grid`). Writes:

- ``report.md`` and ``report.csv``: per variant x env, the number of seeds n and mean ± std
  over seeds (sample std, ddof=1) of the final evaluation return, of the area under the
  learning curve, of the wall time and of the env steps per second; and on the final returns
  normalized by the task's maximum (:func:`simoun_lab.stats.normalize`), the IQM and the mean
  with their 95 % stratified-bootstrap confidence intervals (columns ``iqm``, ``iqm_low``,
  ``iqm_high``, ``norm_mean``, ``norm_mean_low``, ``norm_mean_high``, ``score_max``);
- ``aggregate.csv``: per variant, the IQM and mean over all runs of all its tasks, with CIs;
- ``probability_of_improvement.csv``: for each ordered pair of variants, P(X > Y) with its CI;
- ``curves_env_steps.png`` and ``curves_wall_time.png``: the evaluation return's mean ± std
  band per variant against env steps and against wall-clock seconds, one panel per env;
- ``iqm_env_steps.png``: the IQM over seeds of the normalized return at each evaluation, with
  its 95 % CI band, one panel per env (sample efficiency);
- ``performance_profile.png``: per variant, the fraction of runs (all tasks pooled) whose
  normalized score exceeds each threshold, with its 95 % CI band.
"""

from __future__ import annotations

import csv
import difflib
import functools
import itertools
import json
import math
import os
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from simoun_agent import table
from simoun_agent.config import SetupError, from_dict, to_dict
from simoun_agent.config.envs import env_label
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import is_real, show
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import (
    DENIED,
    STEP_LIMIT,
    Damaged,
    Unreadable,
    folder_problem,
    kind_problem,
    packed_problem,
    permission_problem,
    present,
    read_json_object,
    read_text,
)
from simoun_agent.run.layout import CONFIG_NAME, EVAL_CSV, SUMMARY_NAME
from simoun_agent.run.logger import log_values
from simoun_agent.run.rundir import STUDY_RECORD, make_output_dir
from simoun_lab import stats
from simoun_lab.sweep.grid import (
    BASE_VARIANT,
    DAMAGED_DIR,
    SWEEP_FILE,
    SweepSpec,
    trial_problem,
)
from simoun_lab.sweep.report_plots import Band, plot_panels
from simoun_wrappers._checks import check_path
from simoun_wrappers._checks import is_real as is_number

REPORT_MD = "report.md"
REPORT_CSV = "report.csv"
AGGREGATE_CSV = "aggregate.csv"
IMPROVEMENT_CSV = "probability_of_improvement.csv"
CURVES_STEPS_PNG = "curves_env_steps.png"
CURVES_TIME_PNG = "curves_wall_time.png"
IQM_STEPS_PNG = "iqm_env_steps.png"
PROFILE_PNG = "performance_profile.png"
REPORT_FILES = (
    REPORT_MD,
    REPORT_CSV,
    AGGREGATE_CSV,
    IMPROVEMENT_CSV,
    CURVES_STEPS_PNG,
    CURVES_TIME_PNG,
    IQM_STEPS_PNG,
    PROFILE_PNG,
)
"""The files :func:`write_report` writes."""
ERROR_FILE = "error.txt"
"""Written by a failed sweep trial into its run directory (:mod:`simoun_lab.sweep.trainable`)."""


def error_line(path: Path) -> str:
    """The last line of a failed trial's :data:`ERROR_FILE` (its traceback's error), or what is
    wrong with the file: a damaged one must not hide that the trial failed."""
    try:
        lines = read_text(path).strip().splitlines()
    except Damaged as err:
        return f"failed ({path.name} is damaged: {err})"
    except OSError as err:
        return f"failed ({path.name} cannot be read: {err.strerror})"
    return lines[-1] if lines else "failed"


NOT_VARIANT = {
    "seed",
    "run_dir",
    "progress",
    "video",
    "checkpoint_every",
    "device",
    "torch_threads",
}
"""Keys that differ between runs without making them another method: the seed and where or how
the run was executed."""

GRID_KEY = "eval_every"
"""The config key that sets a run's evaluation grid (an evaluation every that many env steps)."""

CURVE_POINTS = 100
"""Points of the common wall-time grid the runs of a variant are interpolated onto."""

PROFILE_POINTS = 101
"""Thresholds tau at which the performance profiles are drawn."""

BOOTSTRAP_REPS = 2000
"""Stratified bootstrap resamples per confidence interval (rliable's profiles use 2,000)."""

BOOTSTRAP_SEED = 0
"""Seed of every resampling, so a report is reproducible to the digit."""

CONFIDENCE = 0.95
"""Coverage of every confidence interval."""


@dataclass
class RunRecord:
    """One run directory as the report sees it."""

    run_dir: Path
    config: dict[str, Any]
    """flat config (``{"agent.lr": 0.001, ...}``)"""
    curve: dict[str, np.ndarray]
    """eval.csv columns env_step, return_mean, wall_time_s"""
    summary: dict[str, Any] | None
    """summary.json, present only when the run finished (or reached the compared budget)"""
    error: str | None
    """last line of error.txt when a sweep trial failed"""
    modified: float = 0.0
    """when the run last wrote (eval.csv's or config.json's mtime): the most recent of two runs
    of one seed is kept"""

    @property
    def env(self) -> str:
        return self.config["env"]

    @property
    def seed(self) -> Any:
        return self.config["seed"]

    def label(self, root: Path) -> str:
        """The run directory relative to the report's root (its name when it is the root)."""
        relative = self.run_dir.relative_to(root).as_posix()
        return self.run_dir.name if relative == "." else relative


def with_defaults(saved: dict[str, Any]) -> dict[str, Any]:
    """A saved config with this version's defaults for the keys it predates, so a run saved
    before a key existed groups with runs that have its default; as saved when it no longer
    loads (a key since removed, a value now refused).

    A run saved with recipe "drq" before DrQ's K/M augmented views existed (no
    ``critic_augmentations`` key) ran SAC + shift, which is the "rad" recipe now: it is
    relabelled so it does not group with faithful DrQ runs."""
    agent = saved.get("agent", {})
    if agent.get("recipe") == "drq" and "critic_augmentations" not in agent:
        saved = {**saved, "agent": {**agent, "recipe": "rad"}}
    try:
        return to_dict(from_dict(saved))
    except (SetupError, TypeError, ValueError):
        return saved


CURVE_COLUMNS = ("env_step", "return_mean", "wall_time_s")
"""The eval.csv columns the report reads."""


class DamagedRun(Exception):
    """A run's file cannot be read as the run wrote it (empty, cut short, not a number)."""


def find_runs(
    root: Path, damaged: list[str] | None = None, unreadable: list[str] | None = None
) -> list[RunRecord]:
    """Every run directory under ``root`` (Tune's own records under ``tune/`` skipped). A run
    whose config.json, eval.csv or summary.json cannot be read is left out and, when
    ``damaged`` is given, named there with the file and what is wrong with it. A run folder or
    file the user may not read (a colleague's private run) is left out and named in
    ``unreadable`` (in ``damaged`` where it is not given) with its owner, mode and the fix;
    :class:`~simoun_agent.run.kept.Unreadable` where neither list is given."""
    denied = unreadable if unreadable is not None else damaged
    records = []
    for config_path in config_paths(root, [] if damaged is None else damaged, denied):
        label = config_path.parent.relative_to(root).as_posix()
        try:
            records.append(read_run(config_path))
        except DamagedRun as err:
            if damaged is not None:
                damaged.append(f"{label}: {err}")
        except Unreadable as err:
            if denied is None:
                raise
            denied.append(f"{label}: {err}")
    return records


def config_paths(root: Path, damaged: list[str], unreadable: list[str] | None = None) -> list[Path]:
    """Every run's ``config.json`` under ``root`` (a link to nothing included: its run is named
    as damaged), Tune's records under ``tune/`` and hidden folders skipped. A link to a folder
    is followed (a run moved elsewhere and linked back is a run), each folder once; a link to a
    folder it is in (a loop), and a folder whose config.json lies packed beside its name
    (``config.json.gz``), are named in ``damaged``, not walked round or passed over. A folder
    the user may not open (a colleague's private run) is named in ``unreadable``, not passed
    over in silence (:class:`~simoun_agent.run.kept.Unreadable` where it is None)."""
    found: list[Path] = []
    seen = {os.path.realpath(root)}

    def refused(err: OSError) -> None:
        if err.errno not in DENIED:
            return  # a folder removed while it was walked
        problem = permission_problem(Path(err.filename))
        if unreadable is None:
            raise Unreadable(problem)
        unreadable.append(f"{Path(err.filename).relative_to(root).as_posix()}: {problem}")

    for top, folders, files in os.walk(root, onerror=refused, followlinks=True):
        here = Path(top)
        kept = []
        for name in sorted(folders):
            path = here / name
            if name.startswith(".") or (here == root and name == "tune"):
                continue
            problem = folder_problem(path) if path.is_symlink() else None
            if problem:
                damaged.append(f"{path.relative_to(root).as_posix()}: {DAMAGED_DIR}{problem}")
            elif (real := os.path.realpath(path)) not in seen:
                seen.add(real)
                kept.append(name)
        folders[:] = kept
        found += [here / CONFIG_NAME] if CONFIG_NAME in files else []
        if CONFIG_NAME not in files and (packed := packed_problem(here / CONFIG_NAME)):
            damaged.append(f"{here.relative_to(root).as_posix()}: {packed}")
    return sorted(found)


def read_json(path: Path) -> dict[str, Any]:
    """A JSON object from ``path``, or :class:`DamagedRun` saying what is wrong with it (a run's
    config.json or summary.json holding the other's keys included: :func:`kind_problem`)."""
    try:
        data = read_json_object(path)
    except Damaged as err:
        raise DamagedRun(f"{path.name} is damaged: {err}") from None
    if not MINIGRID_RUN_KEYS <= data.keys() and (problem := kind_problem(path.name, list(data))):
        raise DamagedRun(f"{path.name} is damaged: {problem}")
    return data


def read_curve(path: Path) -> dict[str, np.ndarray]:
    """eval.csv's :data:`CURVE_COLUMNS`, or :class:`DamagedRun`: a file with a column
    missing, a value that is not a number, or a NaN or infinite return would otherwise blank
    or bend the statistics of its whole row."""
    if packed := packed_problem(path):
        raise DamagedRun(packed.replace(f"{path} is", f"{path.name} is", 1))
    if not path.is_file() and not path.is_symlink():
        return {key: np.zeros(0) for key in CURVE_COLUMNS}
    try:
        rows = log_values(path, columns=())  # the missing columns are named below, all at once
    except Damaged as err:
        raise DamagedRun(f"{path.name} is damaged: {err}") from None
    except Unreadable:
        raise
    except (OSError, ValueError, TypeError, csv.Error) as err:
        raise DamagedRun(f"{path.name} cannot be read ({err})") from None
    if path.stat().st_size and not rows and "env_step" not in read_text(path):
        raise DamagedRun(f"{path.name} has no header line")
    if rows and (problem := kind_problem(path.name, list(rows[0]))):
        raise DamagedRun(f"{path.name} is damaged: {problem}")
    if rows and (missing := [key for key in CURVE_COLUMNS if key not in rows[0]]):
        raise DamagedRun(f"{path.name} has no column {', '.join(missing)}")
    curve = {key: np.array([row[key] for row in rows], dtype=float) for key in CURVE_COLUMNS}
    bad = ~np.isfinite(np.stack(list(curve.values()))).all(axis=0) if rows else []
    if np.any(bad):
        line = int(np.argmax(bad)) + 2  # 1-based, after the header
        raise DamagedRun(f"{path.name} line {line} has an empty, NaN or infinite value")
    steps = curve["env_step"]
    if np.any(steps != np.floor(steps)):  # whole numbers only, as simoun-train --resume reads them
        line = int(np.argmax(steps != np.floor(steps))) + 2
        raise DamagedRun(
            f"{path.name} line {line}: env_step {steps[line - 2]:g} is not a step count (a whole "
            "number of steps)"
        )
    if np.any(steps >= STEP_LIMIT):
        line = int(np.argmax(steps >= STEP_LIMIT)) + 2
        raise DamagedRun(
            f"{path.name} line {line}: env_step {steps[line - 2]:g} is past 2**63, more steps "
            "than a run can count"
        )
    if len(steps) and (steps[0] < 0 or np.any(np.diff(steps) <= 0)):
        line = 2 if steps[0] < 0 else int(np.argmax(np.diff(steps) <= 0)) + 3
        raise DamagedRun(
            f"{path.name} line {line}: env_step {steps[line - 2]:g} is negative or does not come "
            "after the line before (rows out of order or repeated)"
        )
    return curve


RECORDED_KEYS = ("env", "seed", "agent")
"""Keys every saved config.json holds, with no default that could stand in for them: the task,
the seed and the agent's settings (keys added later are filled in by :func:`with_defaults`)."""


MINIGRID_RUN_KEYS = frozenset({"run", "spec", "seeds"})
"""Keys of a run of the MiniGrid study (SB3 PPO), which this report does not read."""
MINIGRID_RUN = (
    "a run of the MiniGrid study, which simoun-report does not read; report it with `python -m "
    "simoun_lab.minigrid_study report --archive DIR`"
)


def check_summary(summary: dict[str, Any], curve: dict[str, np.ndarray]) -> None:
    """:class:`DamagedRun` when a finished run's ``summary`` lacks a finite final return, a
    step or a wall time, or ends at another step than the last evaluation of its ``curve``
    (:func:`read_curve`)."""
    final = summary.get("final_eval", {})
    value = final.get("return_mean") if isinstance(final, dict) else None
    if not (isinstance(value, (int, float)) and math.isfinite(value)):
        raise DamagedRun(f"{SUMMARY_NAME} has no finite final_eval.return_mean ({value})")
    for key in ("env_step", "wall_time_s"):
        if not (is_real(summary.get(key)) and summary[key] >= 0):
            raise DamagedRun(f"{SUMMARY_NAME}: {key} is {summary.get(key)!r}, not a number >= 0")
    if not len(curve["env_step"]):
        raise DamagedRun(f"{EVAL_CSV} holds no evaluation, but the run finished")
    # the run's final evaluation is the last row of eval.csv: a summary that claims another
    # step would put the run at a budget it never trained to
    if summary["env_step"] != curve["env_step"][-1]:
        raise DamagedRun(
            f"{SUMMARY_NAME} says the run ended at env step {summary['env_step']:g}, but the "
            f"last evaluation in {EVAL_CSV} is at {curve['env_step'][-1]:g}"
        )
    # a summary.json copied from another run of the same length (another seed) ends at the
    # same step: its final return is then not the one the run's last evaluation logged
    last = float(curve["return_mean"][-1])
    if not math.isclose(value, last, rel_tol=1e-6, abs_tol=1e-9):
        raise DamagedRun(
            f"{SUMMARY_NAME}'s final return {value:g} is not the {last:g} of the last evaluation "
            f"in {EVAL_CSV} (env step {summary['env_step']:g}): the two files are of different "
            "runs (one copied from another run, or edited)"
        )


def read_run(config_path: Path) -> RunRecord:
    """The run of ``config_path``'s directory, or :class:`DamagedRun`."""
    run_dir = config_path.parent
    saved = read_json(config_path)
    if MINIGRID_RUN_KEYS <= saved.keys():
        raise DamagedRun(MINIGRID_RUN)
    # checked before the defaults fill them in: a run without them would be reported as the
    # default task, seed or agent
    missing = [key for key in RECORDED_KEYS if key not in saved]
    if missing:
        raise DamagedRun(
            f"{CONFIG_NAME} has no {' or '.join(missing)}, which every run records; its task and "
            "settings cannot be told"
        )
    config = flatten(with_defaults(saved))
    curve = read_curve(run_dir / EVAL_CSV)
    summary_path = run_dir / SUMMARY_NAME
    summary = read_json(summary_path) if present(summary_path) else None
    if summary is not None:
        check_summary(summary, curve)
    error_path = run_dir / ERROR_FILE
    error = error_line(error_path) if present(error_path) and summary is None else None
    written = run_dir / EVAL_CSV if (run_dir / EVAL_CSV).is_file() else config_path
    return RunRecord(run_dir, config, curve, summary, error, written.stat().st_mtime)


TASK_KEYS = {"env", "env_kwargs", "action_repeat"}
"""Keys that go with the task: runs of one variant on two envs differ in them. Within an env
they still tell variants apart."""


def sweep_grid(root: Path) -> dict[str, list[Any]] | None:
    """The grid of the sweep in ``root`` (its ``sweep.json``), None for runs of no sweep;
    SetupError naming the file when it is damaged."""
    return SweepSpec.load(root).grid if present(root / SWEEP_FILE) else None


def sweep_trials_only(
    root: Path, records: list[RunRecord], damaged: list[str], unreadable: Sequence[str] = ()
) -> list[RunRecord]:
    """``records`` less the trials of the sweep in ``root`` whose run directory is not the
    trial's own (:func:`~simoun_lab.sweep.grid.trial_problem`: config.json missing, or another
    env, seed or grid value), each named in ``damaged``: such a run would be counted as finished
    or reported under another env. Runs of no sweep, and runs outside its trials' directories,
    are kept as they are. Runs in ``unreadable`` (named already) are passed over."""
    if not present(root / SWEEP_FILE):
        return records
    spec = SweepSpec.load(root)
    named = {line.partition(": ")[0] for line in [*damaged, *unreadable]}
    refused: set[Path] = set()
    for trial in spec.trials(root):
        run_dir = Path(trial.run_dir)
        label = run_dir.relative_to(root).as_posix()
        if label in named:
            continue  # its config.json is damaged: find_runs named it
        problem = trial_problem(trial, spec.grid)
        if run_dir.is_dir() and not any(run_dir.iterdir()):
            problem = (
                "its directory is empty (the trial has not started, or its files were removed; "
                "simoun-sweep --resume trains it)"
            )
        if problem:
            damaged.append(f"{label}: {problem}")
            refused.add(run_dir)
    return [record for record in records if record.run_dir not in refused]


def variant_keys(records: list[RunRecord], root: Path) -> list[str]:
    """The keys that name a variant: a sweep's grid keys; else the keys that differ between
    runs (within an env, or across envs for any key but :data:`TASK_KEYS`: runs configured
    differently on two tasks are two variants, never pooled as one across tasks), recipe and
    preset first, each kept only if it tells apart runs the kept ones do not
    (``agent.recipe`` differing implies its encoder, losses... which then add nothing)."""
    if (grid := sweep_grid(root)) is not None:
        return list(grid)
    candidates = list(dict.fromkeys(key for record in records for key in record.config))
    candidates.sort(key=lambda key: not key.endswith(("recipe", "preset")))
    keys: list[str] = []
    for key in candidates:
        if key in NOT_VARIANT:
            continue
        within_env = _splits(records, [*keys, key]) > _splits(records, keys)
        across = key not in TASK_KEYS and (
            _splits(records, [*keys, key], by_env=False) > _splits(records, keys, by_env=False)
        )
        if within_env or across:
            keys.append(key)
    return keys


def _splits(records: list[RunRecord], keys: list[str], by_env: bool = True) -> int:
    """How many groups ``keys`` (with the env, when ``by_env``) make of the runs."""
    return len(
        {
            json.dumps(
                [record.env if by_env else "", *(record.config.get(key) for key in keys)],
                sort_keys=True,
            )
            for record in records
        }
    )


def variant_name(config: dict[str, Any], keys: list[str]) -> str:
    return ",".join(f"{key}={show(config.get(key))}" for key in keys) or BASE_VARIANT


def area_under_curve(steps: np.ndarray, returns: np.ndarray) -> float:
    """Normalized area under the learning curve: the trapezoid integral of the evaluation return
    over env steps divided by the env-step span, i.e. the run's average return (in return units,
    comparable across run lengths). NaN with fewer than two evaluations."""
    if len(steps) < 2 or steps[-1] <= steps[0]:
        return math.nan
    return float(np.trapezoid(returns, steps) / (steps[-1] - steps[0]))


def mean_std(values: list[float]) -> tuple[float, float]:
    """Mean and sample standard deviation (ddof=1; NaN for a single value)."""
    array = np.asarray(values, dtype=float)
    if array.size == 0:
        return math.nan, math.nan
    std = float(array.std(ddof=1)) if array.size > 1 else math.nan
    return float(array.mean()), std


def _ci_cells(prefix: str, estimate: tuple[float, float, float]) -> dict[str, float]:
    point, low, high = estimate
    return {prefix: point, f"{prefix}_low": low, f"{prefix}_high": high}


NO_ESTIMATE = (math.nan, math.nan, math.nan)


@dataclass
class Group:
    """The runs of one variant on one env."""

    variant: str
    env: str
    """the env's label (``cartpole-swingup``)"""
    runs: list[RunRecord]

    @property
    def env_id(self) -> str:
        return self.runs[0].env

    @property
    def done(self) -> list[RunRecord]:
        """The runs that count: finished, or cut at the compared budget."""
        return [run for run in self.runs if run.summary is not None]

    def scores(self) -> np.ndarray:
        """The counted runs' final evaluation returns, normalized (:func:`stats.normalize`)."""
        finals = [run.summary["final_eval"]["return_mean"] for run in self.done]
        return stats.normalize(self.env_id, np.array(finals, dtype=float))

    def row(self) -> dict[str, Any]:
        done = self.done
        finals = [run.summary["final_eval"]["return_mean"] for run in done]
        aucs = [area_under_curve(run.curve["env_step"], run.curve["return_mean"]) for run in done]
        walls = [run.summary["wall_time_s"] for run in done]
        speeds = [run.summary["env_step"] / run.summary["wall_time_s"] for run in done]
        row: dict[str, Any] = {"variant": self.variant, "env": self.env, "n": len(done)}
        for name, values in (
            ("final_return", finals),
            ("auc", aucs),
            ("wall_time_s", walls),
            ("env_steps_per_s", speeds),
        ):
            row[f"{name}_mean"], row[f"{name}_std"] = mean_std(values)
        row["env_steps"] = int(np.mean([run.summary["env_step"] for run in done])) if done else 0
        row["unfinished"] = len(self.runs) - len(done)
        scores = {self.env: self.scores()} if done else {}
        row.update(_ci_cells("iqm", _bootstrap(scores, stats.aggregate_iqm)))
        row.update(_ci_cells("norm_mean", _bootstrap(scores, stats.aggregate_mean)))
        row["score_max"] = stats.max_return(self.env_id) or ""
        return row


def _bootstrap(
    scores: stats.Scores, statistic: Callable[[stats.Scores], float]
) -> tuple[float, float, float]:
    """The report's seeded 95 % stratified-bootstrap estimate; NaN without runs."""
    if not scores:
        return NO_ESTIMATE
    return stats.stratified_bootstrap_ci(
        scores, statistic, BOOTSTRAP_REPS, CONFIDENCE, BOOTSTRAP_SEED
    )


def group_runs(records: list[RunRecord], keys: list[str], root: Path) -> list[Group]:
    """Runs by variant and env; a sweep's variants in its grid's order, others as found."""
    groups: dict[tuple[str, str], Group] = {}
    for record in records:
        variant = variant_name(record.config, keys)
        label = env_label(record.env)
        groups.setdefault((variant, label), Group(variant, label, [])).runs.append(record)
    order = list(dict.fromkeys(group.variant for group in groups.values()))
    if (grid := sweep_grid(root)) is not None:
        combos = itertools.product(*grid.values())
        order = [variant_name(dict(zip(grid, c, strict=True)), list(grid)) for c in combos]
    return sorted(groups.values(), key=lambda group: order.index(group.variant))


BUDGETS = {"env_step": "env steps", "wall_time_s": "seconds of wall time"}
"""What ``--at-step`` and ``--at-wall-time`` cut the runs at (an eval.csv column)."""

BUDGET_RULE = (
    "--at-step N counts a run only if it has an evaluation at N env steps, or within half its "
    "eval_every of N (a run stopped mid-episode and resumed evaluates a few steps off its "
    "grid; such runs are listed with the step used), so every row compares evaluations at N, "
    "never at 20k beside 30k; --at-wall-time S counts a run "
    "only if it trained past S (an evaluation at or after S seconds) and uses its last "
    "evaluation at or before S. Runs that fall short are listed. Each row holds runs of one "
    "evaluation grid (eval_every): runs on another grid than most of their row are listed and "
    "left out."
)
"""The equal-budget rule, as ``--help`` and the report say it."""


def at_budget(record: RunRecord, column: str, budget: float) -> RunRecord | None:
    """``record`` as if it had ended at ``budget`` of ``column`` (``env_step`` or
    ``wall_time_s``), or None when it does not count there (:func:`shortfall` says why).

    For env steps the run needs an evaluation at exactly ``budget``, so runs evaluated every
    20k and every 30k steps are never mixed at 30k. For wall time, evaluations land at no
    common second: the run must have trained past ``budget`` (an evaluation at or after it),
    and its last evaluation at or before ``budget`` counts.
    """
    if shortfall(record, column, budget) is not None:
        return None
    end = nearest_evaluation(record, budget) if column == "env_step" else budget
    keep = record.curve[column] <= end
    curve = {key: values[keep] for key, values in record.curve.items()}
    summary = {
        "env_step": float(curve["env_step"][-1]),
        "wall_time_s": float(curve["wall_time_s"][-1]),
        "final_eval": {"return_mean": float(curve["return_mean"][-1])},
    }
    return RunRecord(record.run_dir, record.config, curve, summary, None, record.modified)


def nearest_evaluation(record: RunRecord, step: float) -> float | None:
    """The env step of ``record``'s evaluation at ``step``, else, for a step on its grid (a
    multiple of its ``eval_every``), of its nearest one within half an ``eval_every`` (a run
    stopped mid-episode and resumed evaluates off its grid by less than an episode), else
    None."""
    x = record.curve["env_step"]
    if not len(x):
        return None
    near = x[np.argmin(np.abs(x - step))]
    every = record.config.get("eval_every")
    on_grid = isinstance(every, (int, float)) and every > 0 and step % every == 0
    if near == step or (on_grid and abs(near - step) <= every / 2):
        return float(near)
    return None


def shortfall(record: RunRecord, column: str, budget: float) -> str | None:
    """Why ``record`` does not count at ``budget`` of ``column`` (None when it does)."""
    x = record.curve[column]
    if not len(x):
        return "no evaluation yet"
    if column == "env_step":
        if nearest_evaluation(record, budget) is not None:
            return None
        if x.max() < budget:
            return f"reached only {x.max():g} env steps"
        before, after = x[x < budget], x[x > budget]
        last = f"{before.max():g}" if len(before) else "none"
        return (
            f"no evaluation at {budget:g} env steps (last before it {last}, next {after.min():g})"
        )
    if x.max() < budget:
        return f"trained only {x.max():.0f} s (its last evaluation)"
    if not np.any(x <= budget):
        return f"no evaluation within {budget:g} s"
    return None


BUDGET_FLAGS = {"env_step": "--at-step", "wall_time_s": "--at-wall-time"}
"""The command-line flag of each budget column, as ``simoun-report`` passes them
(``budget_flags``) so that its errors name its flags."""

BUDGET_EXAMPLE = "budget=('env_step', 100000) or budget=('wall_time_s', 3600.0)"
"""The Python form of a budget, for errors."""


def budget_form(column: str, value: float, flags: dict[str, str] | None) -> str:
    """``value`` of ``column`` as the user gave it: ``--at-step 40`` on the command line
    (``flags``), ``budget=('env_step', 40)`` in Python."""
    if flags is not None:
        return f"{flags[column]} {value:g}"
    return f"budget=({column!r}, {value:g})"


def without_budget(column: str, flags: dict[str, str] | None) -> str:
    """How to compare the runs at their ends instead: leave the flag out, or budget=None."""
    return f"leave {flags[column]} out" if flags is not None else "pass budget=None"


def check_budget(budget: object) -> tuple[str, float] | None:
    """``budget`` of :func:`compare_runs` and :func:`write_report` in Python's terms: None or a
    pair (column, value), the column ``env_step`` (a number of env steps >= 0) or
    ``wall_time_s`` (a positive finite number of seconds); a TypeError or ValueError naming
    ``budget`` otherwise (the command line checks its flags itself)."""
    if budget is None:
        return None
    if isinstance(budget, str | bytes) or not isinstance(budget, tuple | list) or len(budget) != 2:
        raise TypeError(
            f"budget must be None or a pair (column, value), got {type(budget).__name__} "
            f"{budget!r:.60}; e.g. {BUDGET_EXAMPLE}, or budget=None to compare the runs at "
            "their ends"
        )
    column, value = budget
    if not isinstance(column, str) or column not in BUDGETS:
        close = difflib.get_close_matches(str(column), list(BUDGETS), n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise ValueError(
            f"budget's column must be one of {', '.join(map(repr, BUDGETS))} (an eval.csv "
            f"column), got {column!r}; {hint}e.g. {BUDGET_EXAMPLE}"
        )
    if not is_number(value):
        raise TypeError(
            f"budget's value must be a number ({BUDGETS[column]}), got "
            f"{type(value).__name__} {value!r:.40}; e.g. budget=({column!r}, "
            f"{100000 if column == 'env_step' else 3600.0})"
        )
    if column == "env_step" and not (math.isfinite(value) and value >= 0):
        raise ValueError(
            f"budget=({column!r}, {value:g}): give a number of env steps >= 0, e.g. "
            f"budget=('env_step', 100000) (or 0, the evaluation before any training)"
        )
    if column == "wall_time_s" and not (math.isfinite(value) and value > 0):
        raise ValueError(
            f"budget=({column!r}, {value:g}): give a positive finite number of seconds, e.g. "
            "budget=('wall_time_s', 3600.0)"
        )
    return column, float(value) if column == "wall_time_s" else value


def check_budget_keeps_a_run(
    records: list[RunRecord],
    column: str,
    budget: float,
    flags: dict[str, str] | None = None,
) -> None:
    """Raise SetupError when runs with evaluations exist but none counts at ``budget`` of
    ``column``: a report of empty rows compares nothing. The message names the budget as the
    user gave it (:func:`budget_form`: a flag of ``flags``, or Python's form), the budgets the
    runs do reach and one that keeps them all."""
    curves = [record.curve[column] for record in records if len(record.curve[column])]
    if not curves:
        return
    given = budget_form(column, budget, flags)
    leave = without_budget(column, flags)
    if column == "env_step":
        # the evaluation at step 0 is before any training: no budget to compare at
        reached = [{float(x) for x in curve if x > 0} for curve in curves]
        steps = sorted(set.union(*reached))
        if not steps:
            return
        shared = set.intersection(*reached)
        example = max(shared) if shared else steps[-1]
        raise SetupError(
            f"{given} leaves every run out: no run has an evaluation at {budget:g} env steps "
            f"(the runs evaluate at {listed(steps)}); pass one of those, e.g. "
            f"{budget_form(column, example, flags)}, or {leave} to compare the runs at their ends"
        )
    longest = max(float(curve.max()) for curve in curves)
    example = round_down(min(float(curve.max()) for curve in curves))
    raise SetupError(
        f"{given} leaves every run out: no run trained that long with an evaluation within it "
        f"(the longest trained {longest:.3g} s, by its last evaluation); pass a budget every run "
        f"reached, e.g. {budget_form(column, example, flags)}, or {leave} to compare the runs at "
        "their ends"
    )


def round_down(value: float) -> float:
    """``value`` rounded down to three significant digits (a budget it still reaches)."""
    if value <= 0:
        return value
    scale = 10.0 ** (2 - math.floor(math.log10(value)))
    return math.floor(value * scale) / scale


def listed(values: list[float], most: int = 8) -> str:
    """``values`` as ``a, b, c`` (the first and last three with ``...`` between when long)."""
    shown = [f"{value:g}" for value in values]
    if len(shown) > most:
        shown = [*shown[:3], "...", *shown[-3:]]
    return ", ".join(shown)


def drop_duplicate_seeds(runs: list[RunRecord]) -> tuple[list[RunRecord], list[tuple]]:
    """One run per seed: of two runs with one seed (a plain run and a sweep trial of the same
    config), the one that counts (finished or at the budget) is kept, then one that did not
    fail, then the most recent. Returns the kept runs and (dropped, kept) pairs."""
    kept: dict[Any, RunRecord] = {}
    dropped = []
    for run in sorted(runs, key=_preference, reverse=True):
        seed = json.dumps(run.seed)
        if seed in kept:
            dropped.append((run, kept[seed]))
        else:
            kept[seed] = run
    return [run for run in runs if run in kept.values()], dropped


def _preference(run: RunRecord) -> tuple[bool, bool, float]:
    return run.summary is not None, run.error is None, run.modified


def one_evaluation_grid(runs: list[RunRecord]) -> tuple[list[RunRecord], list[RunRecord]]:
    """The runs on the evaluation grid (``eval_every``) of most counted runs of the row (of
    most runs when none counts; the first found on a tie), and those on another grid."""
    counted = [run for run in runs if run.summary is not None] or runs
    grid = Counter(json.dumps(run.config.get(GRID_KEY)) for run in counted).most_common(1)[0][0]
    on_grid = [run for run in runs if json.dumps(run.config.get(GRID_KEY)) == grid]
    return on_grid, [run for run in runs if run not in on_grid]


@dataclass
class Comparison:
    """What the report compares: the rows' runs and the runs it lists without counting."""

    root: Path
    budget: tuple[str, float] | None
    groups: list[Group]
    unfinished: list[str] = field(default_factory=list)
    """runs not finished (or short of the budget), with the reason at a budget"""
    failures: list[str] = field(default_factory=list)
    duplicates: list[str] = field(default_factory=list)
    """runs dropped for repeating a seed of their row, with the run kept instead"""
    off_grid: list[str] = field(default_factory=list)
    """runs left out for another evaluation grid than their row's"""
    damaged: list[str] = field(default_factory=list)
    """runs left out for a file that cannot be read, with the file and the problem"""
    unreadable: list[str] = field(default_factory=list)
    """runs left out for a folder or file the user may not read, with its owner and mode"""
    nearby: list[str] = field(default_factory=list)
    """runs counted at an ``--at-step`` budget with their evaluation nearest to it"""


def compare_runs(
    root: Path,
    budget: tuple[str, float] | None = None,
    budget_flags: dict[str, str] | None = None,
) -> Comparison:
    """Find the runs under ``root``, cut them at ``budget`` (:func:`at_budget`), group them,
    keep one evaluation grid per row (:func:`one_evaluation_grid`) and one run per seed
    (:func:`drop_duplicate_seeds`). Raises SetupError when ``root`` holds no run, or when
    ``budget`` leaves out every run that has evaluations (:func:`check_budget_keeps_a_run`),
    naming the budget by the flags of ``budget_flags`` (a command's :data:`BUDGET_FLAGS`) or,
    without them, in Python's form."""
    check_path(root, "root", "compare_runs('sweeps/baselines')", ROOT_WHAT)
    budget = check_budget(budget)
    root = Path(root)
    if not root.exists():
        raise SetupError(
            f"{root} does not exist; pass a sweep directory (simoun-sweep --sweep-dir) or the "
            "parent of run directories"
        )
    if not root.is_dir():
        raise SetupError(
            f"{root} is a file, not a directory; pass a sweep directory (simoun-sweep "
            "--sweep-dir) or the parent of run directories"
        )
    refuse_study(root)
    damaged: list[str] = []
    unreadable: list[str] = []
    found = find_runs(root, damaged, unreadable)
    records = sweep_trials_only(root, found, damaged, unreadable)
    if not records and unreadable and not damaged:
        raise SetupError(
            f"no runs under {root} that can be read (permission denied: {'; '.join(unreadable)})"
        )
    if not records:
        if damaged and all(line.endswith(MINIGRID_RUN) for line in damaged):
            raise SetupError(
                f"{root} holds runs of the MiniGrid study, which simoun-report does not read; "
                "report them with `python -m simoun_lab.minigrid_study report --archive "
                f"{minigrid_archive(root)}`"
            )
        if damaged:
            private = (
                f"; the others: permission denied: {'; '.join(unreadable)}" if unreadable else ""
            )
            raise SetupError(
                f"no runs under {root} that can be read (every run is damaged: "
                f"{'; '.join(damaged)}); restore those files from a copy, or remove the damaged "
                f"runs{private}"
            )
        raise SetupError(
            f"no runs under {root} (no config.json); pass a sweep directory or a directory of "
            "simoun-train runs"
        )
    reasons: dict[Path, str] = {}
    comparison_nearby: list[str] = []
    if budget is not None:
        column, value = budget
        cut_records = []
        for record in records:
            cut = at_budget(record, column, value)
            if cut is not None and cut.summary["env_step"] != value and column == "env_step":
                comparison_nearby.append(
                    f"{record.label(root)}: its evaluation at {cut.summary['env_step']:g} env "
                    f"steps (eval_every {show(record.config.get('eval_every'))})"
                )
            if cut is None and record.error is None:
                reasons[record.run_dir] = shortfall(record, column, value) or ""
                record.summary = None
            cut_records.append(cut or record)
        if not any(record.summary is not None for record in cut_records):
            check_budget_keeps_a_run(records, column, value, budget_flags)
        records = cut_records
    comparison = Comparison(root, budget, group_runs(records, variant_keys(records, root), root))
    comparison.damaged = damaged
    comparison.unreadable = unreadable
    comparison.nearby = comparison_nearby
    for group in comparison.groups:
        # the grid first, so that a copy of a seed on another grid cannot displace its peer
        group.runs, others = one_evaluation_grid(group.runs)
        grid = show(group.runs[0].config.get(GRID_KEY))
        comparison.off_grid += [
            f"{run.label(root)} ({GRID_KEY}={show(run.config.get(GRID_KEY))}; its row: {grid})"
            for run in others
        ]
        group.runs, dropped = drop_duplicate_seeds(group.runs)
        comparison.duplicates += [
            f"{run.label(root)} (seed {show(run.seed)}; kept {kept.label(root)})"
            for run, kept in dropped
        ]
        for run in group.runs:
            if run.error is not None:
                comparison.failures.append(f"{run.label(root)}: {run.error}")
            elif run.summary is None:
                reason = reasons.get(run.run_dir)
                comparison.unfinished.append(
                    f"{run.label(root)}: {reason}" if reason else run.label(root)
                )
    return comparison


def variant_scores(groups: list[Group]) -> dict[str, dict[str, np.ndarray]]:
    """variant -> env -> the normalized final scores of its counted runs (envs without a
    counted run left out): the input of every statistic across tasks."""
    scores: dict[str, dict[str, np.ndarray]] = {}
    for group in groups:
        if group.done:
            scores.setdefault(group.variant, {})[group.env] = group.scores()
    return scores


def normalized_only(
    scores: dict[str, dict[str, np.ndarray]], groups: list[Group]
) -> dict[str, dict[str, np.ndarray]]:
    """``scores`` of the tasks with a known maximum return only, when there are several tasks:
    a raw return pooled with other tasks' scores (or another task's raw returns) weighs by its
    task's scale, not by how well the variant did. One task pools nothing: all its scores."""
    if len({group.env for group in groups}) == 1:
        return scores
    known = {group.env for group in groups if stats.max_return(group.env_id)}
    kept = {v: {t: x for t, x in tasks.items() if t in known} for v, tasks in scores.items()}
    return {variant: tasks for variant, tasks in kept.items() if tasks}


def aggregate_rows(scores: dict[str, dict[str, np.ndarray]]) -> list[dict[str, Any]]:
    """Per variant, the IQM and the mean over all runs of all its tasks, with 95 % CIs."""
    rows = []
    for variant, tasks in scores.items():
        row: dict[str, Any] = {
            "variant": variant,
            "tasks": " ".join(tasks),
            "runs": sum(len(runs) for runs in tasks.values()),
        }
        row.update(_ci_cells("iqm", _bootstrap(tasks, stats.aggregate_iqm)))
        row.update(_ci_cells("mean", _bootstrap(tasks, stats.aggregate_mean)))
        rows.append(row)
    return rows


def improvement_rows(scores: dict[str, dict[str, np.ndarray]]) -> list[dict[str, Any]]:
    """For each ordered pair of variants with a task in common, P(X > Y) over the tasks both
    have, with its 95 % CI (:func:`stats.probability_of_improvement_ci`)."""
    rows = []
    for x, y in itertools.permutations(scores, 2):
        tasks = [task for task in scores[x] if task in scores[y]]
        if not tasks:
            continue
        p, low, high = stats.probability_of_improvement_ci(
            {task: scores[x][task] for task in tasks},
            {task: scores[y][task] for task in tasks},
            BOOTSTRAP_REPS,
            CONFIDENCE,
            BOOTSTRAP_SEED,
        )
        rows.append({"x": x, "y": y, "tasks": " ".join(tasks), "p": p, "low": low, "high": high})
    return rows


def band(
    runs: list[RunRecord], x_key: str, points: int | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The runs' evaluation returns on a common x grid (the shared range of ``x_key``; the
    union of their x values, or ``points`` evenly spaced ones): x, mean and sample std over
    runs (zero for one run)."""
    curves = [(run.curve[x_key], run.curve["return_mean"]) for run in runs if len(run.curve[x_key])]
    if not curves:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    low = max(x[0] for x, _ in curves)
    high = min(x[-1] for x, _ in curves)
    if points is None:
        grid = np.unique(np.concatenate([x for x, _ in curves]))
        grid = grid[(grid >= low) & (grid <= high)]
    else:
        grid = np.linspace(low, high, points)
    values = np.stack([np.interp(grid, x, y) for x, y in curves])
    std = values.std(axis=0, ddof=1) if len(values) > 1 else np.zeros_like(grid)
    return grid, values.mean(axis=0), std


def std_bands(groups: list[Group], x_key: str, points: int | None) -> dict[str, dict[str, Band]]:
    """env -> variant -> mean ± std of the counted runs' evaluation returns (:func:`band`)."""
    panels: dict[str, dict[str, Band]] = {group.env: {} for group in groups}
    for group in (group for group in groups if group.done):
        x, mean, std = band(group.done, x_key, points)
        panels[group.env][f"{group.variant} (n={len(group.done)})"] = (
            x,
            mean,
            mean - std,
            mean + std,
        )
    return panels


def iqm_bands(groups: list[Group]) -> dict[str, dict[str, Band]]:
    """env -> variant -> the IQM over seeds of the normalized evaluation return at each env
    step that all the counted runs evaluated, with its 95 % stratified-bootstrap band."""
    panels: dict[str, dict[str, Band]] = {group.env: {} for group in groups}
    for group in (group for group in groups if group.done):
        by_step = [
            dict(zip(run.curve["env_step"], run.curve["return_mean"], strict=True))
            for run in group.done
        ]
        steps = np.array(sorted(functools.reduce(set.intersection, map(set, by_step))))
        if not len(steps):
            continue
        curves = np.array([[returns[step] for step in steps] for returns in by_step])
        point, low, high = stats.stratified_bootstrap_band(
            {group.env: stats.normalize(group.env_id, curves)},
            stats.iqm_over_steps,
            BOOTSTRAP_REPS,
            CONFIDENCE,
            BOOTSTRAP_SEED,
        )
        panels[group.env][f"{group.variant} (n={len(group.done)})"] = (steps, point, low, high)
    return panels


def profile_bands(scores: dict[str, dict[str, np.ndarray]]) -> dict[str, Band]:
    """variant -> its performance profile (all tasks pooled) with the 95 % band, on thresholds
    from 0 (or the lowest score) to a little above the highest score."""
    values = [runs for tasks in scores.values() for runs in tasks.values()]
    if not values:
        return {}
    pooled = np.concatenate(values)
    low, high = min(0.0, pooled.min()), pooled.max()
    taus = np.linspace(low, high + 0.05 * (high - low or 1.0), PROFILE_POINTS)
    bands = {}
    for variant, tasks in scores.items():
        point, low, high = stats.stratified_bootstrap_band(
            tasks,
            lambda s: stats.performance_profile(s, taus),
            BOOTSTRAP_REPS,
            CONFIDENCE,
            BOOTSTRAP_SEED,
        )
        bands[variant] = (taus, point, low, high)
    return bands


def _pm(mean: float, std: float) -> str:
    if math.isnan(mean):
        return "–"
    return f"{mean:.4g}" if math.isnan(std) else f"{mean:.4g} ± {std:.2g}"


def _ci(point: float, low: float, high: float) -> str:
    if math.isnan(point):
        return "–"
    return f"{point:.3g} [{low:.3g}, {high:.3g}]"


def _interval(row: dict, key: str) -> str:
    """``row[key]`` with its 95 % interval (``key_low``, ``key_high``)."""
    return _ci(row[key], row[f"{key}_low"], row[f"{key}_high"])


def _interval_table(rows: list[dict], columns: list[str], mean: str) -> str:
    """A table of ``columns`` (row keys, also the headers), then each row's IQM and its ``mean``
    key with their 95 % intervals."""
    return table.markdown_table(
        [*columns, "IQM [95 % CI]", "mean [95 % CI]"],
        [[*(row[c] for c in columns), _interval(row, "iqm"), _interval(row, mean)] for row in rows],
        align="llrrr",
    )


def raw_tasks(groups: list[Group]) -> list[str]:
    """The envs whose returns stay raw (no known maximum)."""
    envs = dict.fromkeys((group.env, group.env_id) for group in groups)
    return [env for env, env_id in envs if not stats.max_return(env_id)]


def normalization_note(groups: list[Group]) -> str:
    """Which envs' returns are divided by what (:data:`stats.NORMALIZERS`)."""
    parts = []
    for env, env_id in dict.fromkeys((group.env, group.env_id) for group in groups):
        maximum = stats.max_return(env_id)
        parts.append(
            f"{env}: return / {maximum:g}" if maximum else f"{env}: raw return (no known maximum)"
        )
    return "; ".join(parts)


def markdown(
    comparison: Comparison,
    rows: list[dict[str, Any]],
    aggregates: list[dict[str, Any]],
    improvements: list[dict[str, Any]],
) -> str:
    budget = comparison.budget
    counted = "finished runs only"
    rule = []
    if budget is not None:
        counted = f"every run cut at an equal budget of {budget[1]:g} {BUDGETS[budget[0]]}"
        rule = [f"Budget rule: {BUDGET_RULE}", ""]
    lines = [
        "# Sweep report",
        "",
        *rule,
        f"Mean ± std over seeds (sample std, ddof=1; none for n = 1), {counted}. Final "
        "return: the last evaluation's mean return. AUC: normalized area under the learning "
        "curve (trapezoid of the evaluation return over env steps, divided by the env-step "
        "span: the run's average evaluation return). Wall time: seconds in the training loop, "
        "evaluations included. Each seed counts once per row.",
        "",
        table.markdown_table(
            [
                "variant",
                "env",
                "n",
                "final return",
                "AUC",
                "wall time (s)",
                "env steps/s",
                "env steps",
            ],
            [
                [
                    row["variant"],
                    row["env"],
                    row["n"],
                    _pm(row["final_return_mean"], row["final_return_std"]),
                    _pm(row["auc_mean"], row["auc_std"]),
                    _pm(row["wall_time_s_mean"], row["wall_time_s_std"]),
                    _pm(row["env_steps_per_s_mean"], row["env_steps_per_s_std"]),
                    row["env_steps"],
                ]
                for row in rows
            ],
            align="llrrrrrr",
        ),
    ]
    lines += [
        "",
        "## Normalized scores, IQM and 95 % confidence intervals",
        "",
        "Score: the final return divided by the task's maximum "
        f"({normalization_note(comparison.groups)}). "
        "IQM: interquartile mean over seeds, the mean of the middle 50 % of runs (25 % cut at "
        "each end, so 3 seeds keep all 3). Intervals: 95 % percentile intervals over "
        f"{BOOTSTRAP_REPS} stratified bootstrap resamples of the seeds (seed {BOOTSTRAP_SEED}; "
        "Agarwal et al. 2021). A wide interval says the seeds disagree: more seeds narrow it.",
        "",
        _interval_table(rows, ["variant", "env", "n"], "norm_mean"),
    ]
    lines += [
        "",
        "### Across tasks",
        "",
        "IQM over all runs of all the variant's tasks; mean: the mean over tasks of each task's "
        "mean. The seeds are resampled within each task."
        + (
            f" Normalized scores only: {', '.join(raw)} (no known maximum) enter no statistic "
            "across tasks."
            if len({g.env for g in comparison.groups}) > 1 and (raw := raw_tasks(comparison.groups))
            else ""
        ),
        "",
        _interval_table(aggregates, ["variant", "tasks", "runs"], "mean"),
    ]
    if improvements:
        lines += _improvement_table(improvements)
    lines += [
        "",
        f"![IQM over env steps]({IQM_STEPS_PNG})",
        f"![performance profiles]({PROFILE_PNG})",
        f"![learning curves]({CURVES_STEPS_PNG})",
        f"![wall time]({CURVES_TIME_PNG})",
    ]
    if comparison.unfinished:
        title = "Unfinished runs" if budget is None else "Runs short of the budget"
        lines += _run_list(f"{title} (not counted)", comparison.unfinished)
    if comparison.nearby:
        lines += _run_list(
            f"Runs counted at the evaluation nearest to {budget[1]:g} env steps",
            comparison.nearby,
            "No evaluation at exactly the budget (a stop mid-episode and a resume move the "
            "later evaluations off the grid by less than an episode); the nearest one within "
            "half its eval_every counts.",
        )
    lines += _run_list(
        "Duplicate seeds (dropped)",
        comparison.duplicates,
        "A seed counts once per row: of two runs with one seed, the one that counts "
        "(finished, or at the budget) is kept, then one that did not fail, then the most "
        "recent.",
    )
    lines += _run_list("Runs on another evaluation grid (not counted)", comparison.off_grid)
    lines += _run_list("Failed runs", comparison.failures)
    lines += _run_list(
        "Damaged runs (not counted)",
        comparison.damaged,
        "A file of these runs cannot be read as simoun-train writes it; fix or remove it.",
    )
    lines += _run_list(
        "Runs that cannot be read (not counted)",
        comparison.unreadable,
        "These runs, or files of them, are another user's and private (permission denied); "
        "they are whole, as far as this report knows: make them readable and report again.",
    )
    return "\n".join(lines) + "\n"


def _run_list(title: str, runs: list[str], note: str = "") -> list[str]:
    """A report section listing ``runs`` under ``title`` after ``note``; none without runs."""
    if not runs:
        return []
    return ["", f"## {title}", "", *([note, ""] if note else []), *(f"- {run}" for run in runs)]


def _improvement_table(improvements: list[dict[str, Any]]) -> list[str]:
    """P(row > column) for every pair of variants, as a matrix whose columns are numbered (the
    variants' names are too long for headers)."""
    variants = list(dict.fromkeys(row["x"] for row in improvements))
    cell = {(row["x"], row["y"]): _ci(row["p"], row["low"], row["high"]) for row in improvements}
    numbers = [f"({i})" for i in range(1, len(variants) + 1)]
    lines = [
        "",
        "### Probability of improvement",
        "",
        "P(row > column): the probability that a run of the row's variant scores above a run of "
        "the column's on the same task (ties count one half), averaged over the tasks both ran, "
        "with its 95 % CI (the two variants' seeds resampled independently). Above 0.5 the row "
        "tends to win; an interval that excludes 0.5 is a difference these seeds support.",
        "",
    ]
    rows = [
        [f"{number} {x}"]
        + ["–" if x == y else cell.get((x, y), "no common task") for y in variants]
        for number, x in zip(numbers, variants, strict=True)
    ]
    align = "l" + "r" * len(variants)
    return [*lines, table.markdown_table(["P(row > column)", *numbers], rows, align)]


AGGREGATE_COLUMNS = ["variant", "tasks", "runs", "iqm", "iqm_low", "iqm_high", "mean", "mean_low"]
AGGREGATE_COLUMNS += ["mean_high"]
IMPROVEMENT_COLUMNS = ["x", "y", "tasks", "p", "low", "high"]


def minigrid_archive(root: Path) -> Path:
    """The archive of the MiniGrid study whose runs lie under ``root``: ``root`` when it keeps
    the study's spec, else the archive it lies inside (``root`` a task folder of it), which the
    MiniGrid study's report takes; ``root`` when it lies in none."""
    from simoun_lab.study.owner import enclosing_study, minigrid_study

    found = enclosing_study(root)
    if minigrid_study(root) is None and found is not None and minigrid_study(found[0]):
        return found[0]
    return root


def refuse_study(root: Path) -> None:
    """SetupError for a simoun-study directory or archive given whole: its tuning variants and
    its evaluation runs, of other budgets, would be compared side by side as one sweep, and the
    report written among the study's records; ``simoun-study report`` is its report, and a
    phase of it (``evaluation/``) is a comparison simoun-report makes."""
    if (root / STUDY_RECORD).is_file():
        raise SetupError(
            f"{root} is a simoun-study directory or archive (it holds {STUDY_RECORD}), which "
            f"simoun-report does not report whole; report it with `simoun-study report SPEC "
            f"--study-dir {root}` (SPEC: the study's spec, e.g. docs/studies/dmc100k.toml), or "
            f"compare the runs of one phase with `simoun-report {root / 'evaluation'} --out DIR`"
        )


ROOT_WHAT = (
    "one directory: a sweep directory or the parent of the runs to compare (for runs in "
    "several places, copy or link them under one directory)"
)
"""What the report's ``root`` is, for errors."""


def default_out(root: Path) -> Path:
    """Where the report goes without ``--out``: into ``root``, except for a single run
    directory (its own ``config.json``), whose report goes beside it
    (``<parent>/report-<name>``) so the run directory stays as simoun-train wrote it."""
    root = Path(root)
    if (root / CONFIG_NAME).is_file():
        return root.parent / f"report-{root.name}"
    return root


def write_report(
    root: Path,
    out: Path | None = None,
    budget: tuple[str, float] | None = None,
    flag: str | None = "--out",
    budget_flags: dict[str, str] | None = None,
) -> list[Path]:
    """Write the tables and figures of the runs under ``root`` into ``out`` (default:
    :func:`default_out`); returns the files written. Raises SetupError when ``root`` holds no
    run or ``out`` cannot be written, its fix naming ``flag``, the option that gave ``out``
    (None: a command that has none, such as the report a sweep or a study writes at its end,
    whose fix is to move what stands there aside).

    ``budget`` = (``"env_step"`` or ``"wall_time_s"``, value) compares the runs at an equal
    budget instead of at their ends (:func:`at_budget`); the runs short of it are listed.
    ``budget_flags`` names it in errors by a command's flags (:data:`BUDGET_FLAGS`), else as
    ``budget=(column, value)``.
    """
    check_path(root, "write_report(root=...)", "write_report('sweeps/baselines')", ROOT_WHAT)
    if out is not None:
        check_path(out, "write_report(out=...)", "write_report('runs', out='runs/report')")
    root = Path(root)
    out = Path(out) if out is not None else default_out(root)
    comparison = compare_runs(root, budget, budget_flags)
    make_output_dir(out, flag, REPORT_FILES)
    groups = comparison.groups
    rows = [group.row() for group in groups]
    scores = variant_scores(groups)
    normalized = normalized_only(scores, groups)
    aggregates = aggregate_rows(normalized)
    improvements = improvement_rows(scores)
    text = markdown(comparison, rows, aggregates, improvements)
    atomic_write(out / REPORT_MD, lambda tmp: tmp.write_text(text))
    table.write_csv(out / REPORT_CSV, list(rows[0]), rows)
    table.write_csv(out / AGGREGATE_CSV, AGGREGATE_COLUMNS, aggregates)
    table.write_csv(out / IMPROVEMENT_CSV, IMPROVEMENT_COLUMNS, improvements)
    score = "normalized score (final return / task maximum)"
    plot_panels(
        std_bands(groups, "env_step", None),
        "environment steps",
        "evaluation return (mean ± std)",
        out / CURVES_STEPS_PNG,
    )
    plot_panels(
        std_bands(groups, "wall_time_s", CURVE_POINTS),
        "wall-clock seconds",
        "evaluation return (mean ± std)",
        out / CURVES_TIME_PNG,
    )
    plot_panels(
        iqm_bands(groups),
        "environment steps",
        "IQM of the normalized return (95 % CI)",
        out / IQM_STEPS_PNG,
    )
    plot_panels(
        {"all tasks": profile_bands(normalized)},
        f"tau, {score}",
        "fraction of runs with score > tau (95 % CI)",
        out / PROFILE_PNG,
        steps=True,
    )
    return [out / name for name in REPORT_FILES]
