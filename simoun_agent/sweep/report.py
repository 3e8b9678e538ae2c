"""``simoun-report DIR``: compare the runs of a sweep, or of any directory of ``simoun-train``
runs, per variant and env, over seeds (the paper's Table 1 and Fig. 6). Needs no Ray.

    simoun-report sweeps/baselines
    simoun-report runs/ --out runs/report

Runs are found by their ``config.json``. A *variant* is the config values that tell runs of
the same env apart, seeds aside: a sweep's ``--grid`` keys, or, for plain runs, every key that
differs between two runs of one env (``seed``, ``run_dir`` and output-only keys excepted).
Only finished runs (``summary.json`` present) are counted; unfinished and failed ones are
listed. ``--at-step N`` / ``--at-wall-time SECONDS`` compare at an equal budget instead: every
run that reached it, finished or not, counts with its last evaluation within it. Writes:

- ``report.md`` and ``report.csv``: per variant x env, the number of seeds n and mean ± std
  over seeds (sample std, ddof=1) of the final evaluation return, of the area under the
  learning curve, of the wall time and of the env steps per second;
- ``curves_env_steps.png`` and ``curves_wall_time.png``: the evaluation return's mean ± std
  band per variant against env steps and against wall-clock seconds, one panel per env.
"""

from __future__ import annotations

import argparse
import csv
import io
import itertools
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simoun_agent.run.checkpoint import atomic_write
from simoun_agent.run.logger import EVAL_CSV, read_csv
from simoun_agent.run.presets import SetupError, config_sections, from_dict, to_dict
from simoun_agent.run.train import CONFIG_NAME, SUMMARY_NAME
from simoun_agent.sweep.grid import BASE_VARIANT, SWEEP_FILE, env_label, show

REPORT_MD = "report.md"
REPORT_CSV = "report.csv"
CURVES_STEPS_PNG = "curves_env_steps.png"
CURVES_TIME_PNG = "curves_wall_time.png"
ERROR_FILE = "error.txt"
"""Written by a failed sweep trial into its run directory (:mod:`simoun_agent.sweep.trainable`)."""

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

CURVE_POINTS = 100
"""Points of the common wall-time grid the runs of a variant are interpolated onto."""


@dataclass
class RunRecord:
    """One run directory as the report sees it."""

    run_dir: Path
    config: dict[str, Any]
    """flat config (``{"agent.lr": 0.001, ...}``)"""
    curve: dict[str, np.ndarray]
    """eval.csv columns env_step, return_mean, wall_time_s"""
    summary: dict[str, Any] | None
    """summary.json, present only when the run finished"""
    error: str | None
    """last line of error.txt when a sweep trial failed"""

    @property
    def env(self) -> str:
        return self.config["env"]


def flatten(nested: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"agent": {"lr": 1}}`` -> ``{"agent.lr": 1}``: config sections are walked, any other
    dict (``env_kwargs``) stays one value, as on the command line."""
    sections = config_sections()
    flat: dict[str, Any] = {}
    for key, value in nested.items():
        if isinstance(value, dict) and f"{prefix}{key}." in sections:
            flat.update(flatten(value, f"{prefix}{key}."))
        else:
            flat[prefix + key] = value
    return flat


def with_defaults(saved: dict[str, Any]) -> dict[str, Any]:
    """A saved config with this version's defaults for the keys it predates, so a run saved
    before a key existed groups with runs that have its default; as saved when it no longer
    loads (a key since removed, a value now refused)."""
    try:
        return to_dict(from_dict(saved))
    except (SetupError, TypeError, ValueError):
        return saved


def find_runs(root: Path) -> list[RunRecord]:
    """Every run directory under ``root`` (Tune's own records under ``tune/`` skipped)."""
    records = []
    for config_path in sorted(root.rglob(CONFIG_NAME)):
        relative = config_path.relative_to(root).parts
        if relative[0] == "tune" or any(part.startswith(".") for part in relative):
            continue
        run_dir = config_path.parent
        try:
            config = flatten(with_defaults(json.loads(config_path.read_text())))
        except json.JSONDecodeError:
            continue
        if "env" not in config or "seed" not in config:
            continue
        rows = read_csv(run_dir / EVAL_CSV) if (run_dir / EVAL_CSV).is_file() else []
        curve = {
            key: np.array([row.get(key, math.nan) for row in rows], dtype=float)
            for key in ("env_step", "return_mean", "wall_time_s")
        }
        summary_path = run_dir / SUMMARY_NAME
        summary = json.loads(summary_path.read_text()) if summary_path.is_file() else None
        error_path = run_dir / ERROR_FILE
        error = None
        if error_path.is_file() and summary is None:
            lines = error_path.read_text().strip().splitlines()
            error = lines[-1] if lines else "failed"
        records.append(RunRecord(run_dir, config, curve, summary, error))
    return records


def variant_keys(records: list[RunRecord], root: Path) -> list[str]:
    """The keys that name a variant: a sweep's grid keys; else the keys that differ within an
    env, recipe and preset first, each kept only if it tells apart runs the kept ones do not
    (``agent.recipe`` differing implies its encoder, losses... which then add nothing)."""
    sweep_file = root / SWEEP_FILE
    if sweep_file.is_file():
        return list(json.loads(sweep_file.read_text())["grid"])
    candidates = list(dict.fromkeys(key for record in records for key in record.config))
    candidates.sort(key=lambda key: not key.endswith(("recipe", "preset")))
    keys: list[str] = []
    for key in candidates:
        if key not in NOT_VARIANT and _splits(records, [*keys, key]) > _splits(records, keys):
            keys.append(key)
    return keys


def _splits(records: list[RunRecord], keys: list[str]) -> int:
    """How many groups ``keys`` (with the env) make of the runs."""
    return len(
        {
            json.dumps([record.env, *(record.config.get(key) for key in keys)], sort_keys=True)
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


@dataclass
class Group:
    """The runs of one variant on one env."""

    variant: str
    env: str
    runs: list[RunRecord]

    @property
    def done(self) -> list[RunRecord]:
        return [run for run in self.runs if run.summary is not None]

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
        return row


def group_runs(records: list[RunRecord], keys: list[str], root: Path) -> list[Group]:
    """Runs by variant and env; a sweep's variants in its grid's order, others as found."""
    groups: dict[tuple[str, str], Group] = {}
    for record in records:
        variant = variant_name(record.config, keys)
        label = env_label(record.env)
        groups.setdefault((variant, label), Group(variant, label, [])).runs.append(record)
    order = list(dict.fromkeys(group.variant for group in groups.values()))
    if (root / SWEEP_FILE).is_file():
        grid = json.loads((root / SWEEP_FILE).read_text())["grid"]
        combos = itertools.product(*grid.values())
        order = [variant_name(dict(zip(grid, c, strict=True)), list(grid)) for c in combos]
    return sorted(groups.values(), key=lambda group: order.index(group.variant))


def _pm(mean: float, std: float) -> str:
    if math.isnan(mean):
        return "–"
    return f"{mean:.4g}" if math.isnan(std) else f"{mean:.4g} ± {std:.2g}"


def markdown(
    rows: list[dict[str, Any]],
    failures: list[str],
    unfinished: list[str],
    budget: tuple[str, float] | None = None,
) -> str:
    counted = "finished runs only"
    if budget is not None:
        counted = (
            f"every run cut at an equal budget of {budget[1]:g} {BUDGETS[budget[0]]} (its last "
            "evaluation within it; runs that had not reached it are not counted)"
        )
    lines = [
        "# Sweep report",
        "",
        f"Mean ± std over seeds (sample std, ddof=1; none for n = 1), {counted}. Final "
        "return: the last evaluation's mean return. AUC: normalized area under the learning "
        "curve (trapezoid of the evaluation return over env steps, divided by the env-step "
        "span: the run's average evaluation return). Wall time: seconds in the training loop, "
        "evaluations included.",
        "",
        "| variant | env | n | final return | AUC | wall time (s) | env steps/s | env steps |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for row in rows:
        cells = [
            row["variant"],
            row["env"],
            str(row["n"]),
            _pm(row["final_return_mean"], row["final_return_std"]),
            _pm(row["auc_mean"], row["auc_std"]),
            _pm(row["wall_time_s_mean"], row["wall_time_s_std"]),
            _pm(row["env_steps_per_s_mean"], row["env_steps_per_s_std"]),
            str(row["env_steps"]),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    if unfinished:
        title = "Unfinished runs" if budget is None else "Runs short of the budget"
        lines += ["", f"## {title} (not counted)", ""] + [f"- {u}" for u in unfinished]
    if failures:
        lines += ["", "## Failed runs", ""] + [f"- {f}" for f in failures]
    lines += ["", f"![learning curves]({CURVES_STEPS_PNG})", f"![wall time]({CURVES_TIME_PNG})"]
    return "\n".join(lines) + "\n"


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


def plot_curves(groups: list[Group], x_key: str, xlabel: str, path: Path, points: int | None):
    """One panel per env, one mean ± std band per variant (finished runs)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    envs = list(dict.fromkeys(group.env for group in groups))
    fig, axes = plt.subplots(1, len(envs), figsize=(5.5 * len(envs), 4), dpi=110, squeeze=False)
    for ax, env in zip(axes[0], envs, strict=True):
        for group in (g for g in groups if g.env == env and g.done):
            x, mean, std = band(group.done, x_key, points)
            ax.plot(x, mean, label=f"{group.variant} (n={len(group.done)})")
            ax.fill_between(x, mean - std, mean + std, alpha=0.2)
        ax.set_title(env)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("evaluation return")
        ax.grid(alpha=0.3)
        if not ax.lines:
            ax.text(0.5, 0.5, "no finished run", ha="center", transform=ax.transAxes)
    fig.tight_layout()
    # one legend under the panels: ten recipes' labels inside a panel would hide its curves
    labelled = {line.get_label(): line for ax in axes[0] for line in ax.lines}
    if labelled:
        fig.legend(
            labelled.values(),
            labelled.keys(),
            loc="upper center",
            bbox_to_anchor=(0.5, 0.0),
            ncol=min(3, len(labelled)),
            fontsize="small",
        )
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png", bbox_inches="tight"))
    plt.close(fig)


BUDGETS = {"env_step": "env steps", "wall_time_s": "seconds of wall time"}
"""What ``--at-step`` and ``--at-wall-time`` cut the runs at (an eval.csv column)."""


def at_budget(record: RunRecord, column: str, budget: float) -> RunRecord | None:
    """``record`` as if it had ended at its last evaluation within ``budget`` of ``column``
    (``env_step`` or ``wall_time_s``); None if the run has not reached the budget yet (so every
    run counted had the same budget)."""
    x = record.curve[column]
    if not len(x) or x[-1] < budget:
        return None
    keep = x <= budget
    curve = {key: values[keep] for key, values in record.curve.items()}
    summary = {
        "env_step": float(curve["env_step"][-1]),
        "wall_time_s": float(curve["wall_time_s"][-1]),
        "final_eval": {"return_mean": float(curve["return_mean"][-1])},
    }
    return RunRecord(record.run_dir, record.config, curve, summary, None)


def write_report(
    root: Path, out: Path | None = None, budget: tuple[str, float] | None = None
) -> list[Path]:
    """Write the tables and curves of the runs under ``root`` into ``out`` (default: ``root``);
    returns the files written. Raises SetupError when ``root`` holds no run.

    ``budget`` = (``"env_step"`` or ``"wall_time_s"``, value) compares the runs at an equal
    budget instead of at their ends: each run that reached it, finished or not, counts with its
    last evaluation within it; the others are listed as not having reached it.
    """
    root, out = Path(root), Path(out or root)
    records = find_runs(root)
    if not records:
        raise SetupError(
            f"no runs under {root} (no {CONFIG_NAME} found); pass a sweep directory or a "
            "directory of simoun-train runs"
        )
    if budget is not None:
        column, value = budget
        cut = {id(record): at_budget(record, column, value) for record in records}
        short = [r for r in records if cut[id(r)] is None and r.error is None]
        records = [cut[id(r)] or r for r in records]
        for record in short:
            record.summary = None
    groups = group_runs(records, variant_keys(records, root), root)
    rows = [group.row() for group in groups]
    unfinished = [
        str(run.run_dir.relative_to(root))
        for run in records
        if run.summary is None and run.error is None
    ]
    failures = [
        f"{run.run_dir.relative_to(root)}: {run.error}" for run in records if run.error is not None
    ]
    out.mkdir(parents=True, exist_ok=True)
    text = markdown(rows, failures, unfinished, budget)
    atomic_write(out / REPORT_MD, lambda tmp: tmp.write_text(text))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    atomic_write(out / REPORT_CSV, lambda tmp: tmp.write_text(buffer.getvalue()))
    plot_curves(groups, "env_step", "environment steps", out / CURVES_STEPS_PNG, None)
    plot_curves(groups, "wall_time_s", "wall-clock seconds", out / CURVES_TIME_PNG, CURVE_POINTS)
    return [out / name for name in (REPORT_MD, REPORT_CSV, CURVES_STEPS_PNG, CURVES_TIME_PNG)]


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-report``."""
    parser = argparse.ArgumentParser(
        prog="simoun-report",
        description="Tables (Markdown, CSV) and learning curves (PNG) of a sweep or of a "
        "directory of simoun-train runs, per variant and env, over seeds.",
    )
    parser.add_argument("root", metavar="DIR", help="a sweep directory or a directory of runs")
    parser.add_argument("--out", metavar="DIR", help="where to write the report (default: DIR)")
    equal = parser.add_mutually_exclusive_group()
    equal.add_argument(
        "--at-step",
        type=int,
        metavar="N",
        help="compare at an equal budget of N env steps: every run that reached N, finished or "
        "not, counts with its last evaluation at or before N",
    )
    equal.add_argument(
        "--at-wall-time",
        type=float,
        metavar="SECONDS",
        help="compare at an equal wall-time budget: every run that trained that long counts "
        "with its last evaluation within it",
    )
    args = parser.parse_args(argv)
    budget = None
    if args.at_step is not None:
        budget = ("env_step", args.at_step)
    elif args.at_wall_time is not None:
        budget = ("wall_time_s", args.at_wall_time)
    if budget is not None and budget[1] <= 0:
        parser.exit(2, "simoun-report: error: --at-step / --at-wall-time must be positive\n")
    try:
        written = write_report(Path(args.root), Path(args.out) if args.out else None, budget)
    except SetupError as err:
        parser.exit(2, f"simoun-report: error: {err}\n")
    print((Path(written[0])).read_text(), end="")
    print(f"written: {', '.join(map(str, written))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
