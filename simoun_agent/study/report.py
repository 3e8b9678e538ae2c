"""The study's report: the protocol it ran, then the held-out evaluation's statistics and costs.

Written into ``<study>/report/`` (and the archive's ``report/``):

- ``tuning/`` and ``evaluation/``: ``simoun-report`` of each phase's runs
  (:func:`simoun_agent.sweep.report.write_report`: per recipe and task the IQM of the normalized
  final return with its 95 % stratified bootstrap CI, the aggregate over tasks, the probability
  of improvement of each pair, per-task curves and the performance profile);
- ``report.md``: the protocol (code commit, recipes and what each was given, grid, seeds of each
  phase, budgets, selection rule, each recipe's selected setting with its tuning score), the
  evaluation phase's per-task and aggregate IQM with CIs and the probability that the first
  recipe improves on each other one (read from ``evaluation/``), the IQM curves over all tasks
  against env steps and wall time (``iqm_curves.png``), and the wall and CPU time of the runs;
- ``scores.csv``: one row per finished run of both phases (final return, score, wall and CPU
  time, machine load at its start).

Scores follow Agarwal et al. 2021 (:mod:`simoun_agent.stats`): the last evaluation's mean
return divided by the task's maximum (1000 for dm_control; raw returns for tasks without a
known maximum).
"""

from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simoun_agent import stats
from simoun_agent.config import RECIPES, resolve, to_dict
from simoun_agent.config.envs import env_label
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import show
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.layout import SUMMARY_NAME
from simoun_agent.run.logger import EVAL_CSV, read_csv
from simoun_agent.study.choice import Choice
from simoun_agent.study.plan import (
    EVALUATION,
    TUNING,
    StudyRun,
    evaluation_runs,
    setting_label,
    tuning_runs,
)
from simoun_agent.study.selection import SELECTION_RULES, TIE_RULE
from simoun_agent.study.spec import StudySpec, fixed_by
from simoun_agent.sweep import report as sweep_report
from simoun_agent.sweep.trainable import read_trial_parts

REPORT_DIR = "report"
REPORT_MD = "report.md"
SCORES_CSV = "scores.csv"
CURVES_PNG = "iqm_curves.png"

CURVE_POINTS = 50
"""Points of the common wall-time grid the IQM curve is drawn on."""


@dataclass
class RunResult:
    """One finished run, as the report uses it."""

    run: StudyRun
    final_return: float
    score: float
    """normalized final return"""
    curve: dict
    """eval.csv's env_step, return_mean (normalized) and wall_time_s columns"""
    wall_s: float
    """training-loop seconds (summary.json)"""
    cpu_s: float
    """CPU seconds over the trial's parts (trial.json; NaN without it)"""
    load: float
    """1-minute load average per CPU at the trial's first start (NaN without it)"""


def read_result(study_dir: Path, run: StudyRun) -> RunResult | None:
    """The run's result, None when it has not finished."""
    run_dir = Path(study_dir, run.name)
    if not (run_dir / SUMMARY_NAME).is_file():
        return None
    summary = json.loads((run_dir / SUMMARY_NAME).read_text())
    rows = read_csv(run_dir / EVAL_CSV)
    curve = {
        "env_step": np.array([row["env_step"] for row in rows]),
        "return_mean": stats.normalize(run.task, [row["return_mean"] for row in rows]),
        "wall_time_s": np.array([row.get("wall_time_s", math.nan) for row in rows]),
    }
    final = float(summary["final_eval"]["return_mean"])
    parts = read_trial_parts(run_dir)
    cpu = sum(part.get("cpu_s", math.nan) for part in parts) if parts else math.nan
    load = parts[0]["loadavg"][0] / parts[0]["cpu_count"] if parts else math.nan
    score = float(stats.normalize(run.task, [final])[0])
    return RunResult(run, final, score, curve, float(summary["wall_time_s"]), cpu, load)


def _interval(point: float, low: float, high: float) -> str:
    return f"{point:.3f} [{low:.3f}, {high:.3f}]"


def _seeds(seeds: list[int]) -> str:
    return ", ".join(map(str, seeds))


def recipe_differences(spec: StudySpec, choices: dict[str, Choice]) -> tuple[list[str], dict]:
    """The resolved config keys in which the recipes' evaluation runs differ (on the first
    evaluation task, with their selected settings), and each recipe's values of them."""
    task = spec.evaluation.tasks[0]
    flat = {}
    for recipe in spec.recipes:
        overrides = spec.overrides(recipe, task, choices[recipe].setting, 0, 1)
        flat[recipe] = flatten(to_dict(resolve(spec.preset, overrides)))
    keys = [
        key
        for key in flat[spec.recipes[0]]
        if len({show(values.get(key)) for values in flat.values()}) > 1
    ]
    return keys, {recipe: {key: flat[recipe].get(key) for key in keys} for recipe in flat}


def protocol(spec: StudySpec, record: dict[str, Any], choices: dict[str, Choice]) -> list[str]:
    """The report's first part: what ran, as the spec and the study record say."""
    codes = [
        f"`{p['commit'] or p['version']}`" + (" (uncommitted changes)" if p["dirty"] else "")
        for p in record["parts"]
    ]
    codes = list(dict.fromkeys(codes))
    tuning, evaluation = spec.tuning, spec.evaluation
    lines = [f"# Study `{spec.name}`", ""]
    if spec.description:
        lines += [spec.description, ""]
    lines += [
        "## Protocol",
        "",
        f"- Spec: `{record['spec_file']}` (copied into `study.json`). Code: commit "
        f"{', '.join(codes)}"
        + (" (resumed from other commits with --allow-other-commit)" if len(codes) > 1 else "")
        + ".",
        f"- Recipes: {', '.join(f'`{r}`' for r in spec.recipes)}; the first, `{spec.recipes[0]}`, "
        "is compared with each of the others.",
        f"- Every run of both phases: preset `{spec.preset or 'none'}`"
        + (
            " with " + ", ".join(f"`{k} = {show(v)}`" for k, v in spec.base.items())
            if spec.base
            else ""
        )
        + (
            "; per task: "
            + "; ".join(
                f"{env_label(task)}: " + ", ".join(f"`{k} = {show(v)}`" for k, v in extra.items())
                for task, extra in spec.task_config.items()
            )
            if spec.task_config
            else ""
        )
        + f"; {spec.cpus_per_trial} CPU (torch thread) per run.",
        "- Shared tuning grid, the same for every recipe: "
        + "; ".join(f"`{k}` in {{{', '.join(show(v) for v in vs)}}}" for k, vs in spec.grid.items())
        + f" ({len(spec.settings())} settings).",
    ]
    overridden = [
        f"{recipe}'s `{key} = {show(value)}`"
        for key in spec.grid_overrides
        for recipe, value in fixed_by(key, spec.recipes).items()
    ]
    if overridden:
        lines.append(
            "- The grid overrides what a recipe fixes (`grid_overrides`): "
            + ", ".join(overridden)
            + "; each such value is one of the grid's, so the recipe as published is one of "
            "its settings."
        )
    lines += [
        "- Tuning phase: "
        + "; ".join(
            f"{env_label(t)}, seeds {_seeds(tuning.seeds[t])}, {tuning.env_steps[t]} env steps"
            for t in tuning.tasks
        )
        + f" ({len(tuning_runs(spec))} runs: every recipe x setting x seed).",
        f"- Selection: {SELECTION_RULES[spec.selection].description} (rule `{spec.selection}`); "
        f"{TIE_RULE}.",
        "- Evaluation phase, on held-out seeds (none is a tuning seed), each recipe with its "
        "selected setting: "
        + "; ".join(
            f"{env_label(t)}, seeds {_seeds(evaluation.seeds[t])}, "
            f"{evaluation.env_steps[t]} env steps"
            for t in evaluation.tasks
        )
        + f" ({len(evaluation_runs(spec))} runs).",
    ]
    untuned = [t for t in evaluation.tasks if t not in tuning.tasks]
    if untuned:
        lines.append(
            f"- Tuned on {', '.join(env_label(t) for t in tuning.tasks)} only: each recipe's "
            "selected setting is used on every evaluation task, "
            f"{', '.join(env_label(t) for t in untuned)} included, untuned there."
        )
    lines += [
        "",
        "### What each recipe was given",
        "",
        "Each recipe got the same base config, grid, seeds and budgets; its own values are its "
        "recipe's (`simoun_agent/config/recipes.py`) and the grid setting its tuning selected.",
        "",
        "| recipe | what it is | selected setting | tuning score |",
        "|---|---|---|---:|",
    ]
    for recipe in spec.recipes:
        choice = choices[recipe]
        lines.append(
            f"| {recipe} | {RECIPES[recipe].description} | `{setting_label(choice.setting)}` | "
            f"{choice.score:.4g} |"
        )
    keys, values = recipe_differences(spec, choices)
    if keys:
        lines += [
            "",
            "The resolved configs of the evaluation runs differ only in these keys:",
            "",
            "| recipe | " + " | ".join(keys) + " |",
            "|---|" + "---|" * len(keys),
        ]
        for recipe in spec.recipes:
            cells = [show(values[recipe][key]) for key in keys]
            lines.append(f"| {recipe} | " + " | ".join(cells) + " |")
    lines += [
        "",
        "### Tuning scores",
        "",
        "Each setting's score by the selection rule: the mean over tasks of the mean over seeds "
        "(each seed's score in brackets); **bold** is the selected one.",
        "",
        "| recipe | setting | score | " + " | ".join(env_label(t) for t in tuning.tasks) + " |",
        "|---|---|---:|" + "---|" * len(tuning.tasks),
    ]
    for recipe in spec.recipes:
        for candidate in choices[recipe].candidates:
            chosen = candidate.setting == choices[recipe].setting
            label = f"`{setting_label(candidate.setting)}`"
            score = f"{candidate.score:.4g}"
            if chosen:
                label, score = f"**{label}**", f"**{score}**"
            per_task = [
                "[" + ", ".join(f"{s:.3g}" for s in candidate.runs[t]) + "]" for t in tuning.tasks
            ]
            lines.append(f"| {recipe} | {label} | {score} | " + " | ".join(per_task) + " |")
    return lines


def read_rows(path: Path) -> list[dict[str, Any]]:
    """A CSV of the phase report, numbers as floats."""
    if not path.is_file():
        return []
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    return [{k: _number(v) for k, v in row.items()} for row in rows]


def _number(text: str) -> Any:
    try:
        return float(text)
    except ValueError:
        return text


def recipe_variants(root: Path) -> dict[str, str]:
    """The phase report's variant name of each recipe's runs under ``root``."""
    records = sweep_report.find_runs(root)
    keys = sweep_report.variant_keys(records, root)
    return {
        sweep_report.variant_name(record.config, keys): record.config["agent.recipe"]
        for record in records
    }


def results_section(spec: StudySpec, phase_report: Path, recipes: dict[str, str]) -> list[str]:
    """The evaluation phase's statistics, as ``simoun-report`` computed them into
    ``phase_report`` (per task, aggregate over tasks, probability of improvement)."""
    per_task = read_rows(phase_report / sweep_report.REPORT_CSV)
    aggregate = read_rows(phase_report / sweep_report.AGGREGATE_CSV)
    improvement = read_rows(phase_report / sweep_report.IMPROVEMENT_CSV)
    order = {recipe: i for i, recipe in enumerate(spec.recipes)}
    tasks = [env_label(t) for t in spec.evaluation.tasks]

    def recipe_of(row: dict[str, Any], key: str = "variant") -> str:
        return recipes.get(row[key], row[key])

    maxima = [
        f"{env_label(t)}: {stats.max_return(t):g}"
        for t in spec.evaluation.tasks
        if stats.max_return(t)
    ]
    raw = [env_label(t) for t in spec.evaluation.tasks if not stats.max_return(t)]
    lines = [
        "",
        "## Results on the held-out seeds",
        "",
        "Score: the last evaluation's mean return divided by the task's maximum return ("
        + "; ".join(
            maxima + ([f"raw returns on {', '.join(raw)}: no known maximum"] if raw else [])
        )
        + "). IQM: the 25 % trimmed mean over runs; [low, high]: the 95 % stratified bootstrap "
        "interval (Agarwal et al. 2021; `simoun_agent/stats.py`). With a few seeds per task the "
        "intervals are wide: overlapping intervals are no evidence of a difference.",
        "",
        "| task | recipe | n | return (mean ± std) | IQM score [95 % CI] |",
        "|---|---|---:|---:|---:|",
    ]
    per_task.sort(key=lambda r: (tasks.index(r["env"]), order.get(recipe_of(r), 0)))
    for row in per_task:
        spread = "" if math.isnan(row["final_return_std"]) else f" ± {row['final_return_std']:.0f}"
        lines.append(
            f"| {row['env']} | {recipe_of(row)} | {row['n']:.0f} | "
            f"{row['final_return_mean']:.1f}{spread} | "
            f"{_interval(row['iqm'], row['iqm_low'], row['iqm_high'])} |"
        )
    aggregate.sort(key=lambda r: order.get(recipe_of(r), 0))
    lines += [
        "",
        "Over all evaluation tasks (IQM of every run's score, tasks pooled):",
        "",
        "| recipe | runs | IQM score [95 % CI] |",
        "|---|---:|---:|",
    ]
    lines += [
        f"| {recipe_of(r)} | {r['runs']:.0f} | {_interval(r['iqm'], r['iqm_low'], r['iqm_high'])} |"
        for r in aggregate
    ]
    first = spec.recipes[0]
    mine = [r for r in improvement if recipe_of(r, "x") == first]
    mine.sort(key=lambda r: order.get(recipe_of(r, "y"), 0))
    if mine:
        lines += [
            "",
            f"Probability of improvement P({first} > Y): the chance that a run of {first} "
            "scores above a run of Y on the same task (ties count one half), averaged over the "
            "tasks both ran, with its 95 % stratified bootstrap interval; 0.5 is no difference.",
            "",
            "| Y | tasks | P(X > Y) [95 % CI] |",
            "|---|---|---:|",
        ]
        lines += [
            f"| {recipe_of(r, 'y')} | {r['tasks']} | {_interval(r['p'], r['low'], r['high'])} |"
            for r in mine
        ]
    lines += [
        "",
        "Sample efficiency: the IQM of the normalized evaluation return over every evaluation "
        "run (all tasks pooled), with its 95 % band, against env steps and against wall-clock "
        "seconds:",
        "",
        f"![IQM curves]({CURVES_PNG})",
        "",
        "Per task, and the score distribution (performance profile): "
        f"[evaluation/{sweep_report.REPORT_MD}](evaluation/{sweep_report.REPORT_MD}); the "
        f"tuning runs: [tuning/{sweep_report.REPORT_MD}](tuning/{sweep_report.REPORT_MD}).",
    ]
    return lines


def time_section(results: list[RunResult]) -> list[str]:
    lines = [
        "",
        "## Time",
        "",
        "Wall time: seconds in the training loop (`summary.json`, evaluations included). CPU "
        "time: user + system seconds of the trial's process (`trial.json`, summed over its "
        "parts); a part whose process was ended (a machine handed back) recorded none, so a run "
        "with such a part is left out of the mean, which then says over how many runs it is. Load: "
        "the 1-minute load average per CPU when the trial started (above 1, runs waited for a "
        "CPU and their wall times are inflated).",
        "",
        "| phase | recipe | runs | env steps | wall time per run (s) | CPU time per run (s) | "
        "env steps per wall second | load at start (max) |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    groups: dict[tuple[str, str], list[RunResult]] = {}
    for result in results:
        groups.setdefault((result.run.phase, result.run.recipe), []).append(result)
    for (phase, recipe), group in groups.items():
        steps = np.mean([r.run.env_steps for r in group])
        wall = np.mean([r.wall_s for r in group])
        loads = [r.load for r in group if not math.isnan(r.load)]
        load = f"{max(loads):.2f}" if loads else "–"
        lines.append(
            f"| {phase} | {recipe} | {len(group)} | {steps:.0f} | {wall:.0f} | "
            f"{mean_cpu(group)} | {steps / wall:.1f} | {load} |"
        )
    total_cpu = np.nansum([r.cpu_s for r in results])
    unrecorded = sum(math.isnan(r.cpu_s) for r in results)
    lines += [
        "",
        f"Total over {len(results)} runs: {sum(r.wall_s for r in results) / 3600:.2f} h of "
        f"wall time, {total_cpu / 3600:.2f} h of CPU time"
        + (f" (without {unrecorded} runs' unrecorded parts)" if unrecorded else "")
        + f". Every run's times are in `{SCORES_CSV}`.",
    ]
    return lines


def mean_cpu(group: list[RunResult]) -> str:
    """The mean CPU time of the runs whose every part recorded one, with their count when some
    did not; '–' when none did."""
    known = [r.cpu_s for r in group if not math.isnan(r.cpu_s)]
    if not known:
        return "–"
    count = "" if len(known) == len(group) else f" ({len(known)} of {len(group)} runs)"
    return f"{np.mean(known):.0f}{count}"


def curve_scores(
    runs: list[RunResult], x_key: str, points: int | None
) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The runs' normalized returns on one grid of ``x_key`` up to the shortest run's end (the
    evaluation steps, or ``points`` evenly spaced values): the grid and task -> (runs, points)."""
    end = min(run.curve[x_key][-1] for run in runs)
    if points is None:
        grid = np.unique(np.concatenate([run.curve[x_key] for run in runs]))
        grid = grid[grid <= end]
    else:
        grid = np.linspace(0.0, end, points)
    curves: dict[str, list[np.ndarray]] = {}
    for run in runs:
        curve = np.interp(grid, run.curve[x_key], run.curve["return_mean"])
        curves.setdefault(run.run.task, []).append(curve)
    return grid, {task: np.stack(values) for task, values in curves.items()}


def plot_curves(spec: StudySpec, results: list[RunResult], path: Path) -> None:
    """IQM over all tasks' runs with its band per recipe, against env steps and wall time (each
    recipe's curve up to its shortest run)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4), dpi=110)
    for ax, x_key, label, points in (
        (axes[0], "env_step", "environment steps", None),
        (axes[1], "wall_time_s", "wall-clock seconds", CURVE_POINTS),
    ):
        for recipe in spec.recipes:
            runs = [r for r in results if r.run.recipe == recipe and len(r.curve[x_key])]
            if not runs:
                continue
            grid, scores = curve_scores(runs, x_key, points)
            point, low, high = stats.stratified_bootstrap_band(
                scores,
                stats.iqm_over_steps,
                sweep_report.BOOTSTRAP_REPS,
                sweep_report.CONFIDENCE,
                sweep_report.BOOTSTRAP_SEED,
            )
            ax.plot(grid, point, label=recipe)
            ax.fill_between(grid, low, high, alpha=0.2)
        ax.set_xlabel(label)
        ax.set_ylabel("IQM of the normalized return (95 % CI)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)


def _write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    if not rows:
        return
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    atomic_write(path, lambda tmp: tmp.write_text(buffer.getvalue()))


def score_rows(results: list[RunResult]) -> list[dict[str, Any]]:
    return [
        {
            "phase": r.run.phase,
            "recipe": r.run.recipe,
            "setting": setting_label(r.run.setting),
            "task": env_label(r.run.task),
            "seed": r.run.seed,
            "env_steps": r.run.env_steps,
            "final_return": r.final_return,
            "score": r.score,
            "wall_time_s": r.wall_s,
            "cpu_time_s": r.cpu_s,
            "load_per_cpu": r.load,
            "run": r.run.name,
        }
        for r in results
    ]


def write_study_report(
    spec: StudySpec,
    study_dir: Path,
    record: dict[str, Any],
    choices: dict[str, Choice],
    rewritten_by: str | None = None,
) -> list[Path]:
    """Write the report of the study in ``study_dir`` into its ``report/``; returns its files.
    Counts the finished evaluation runs (the missing ones are listed). ``rewritten_by``: the
    commit of the code writing the report again after the study (``simoun-study report``),
    named under the protocol."""
    out = study_dir / REPORT_DIR
    out.mkdir(parents=True, exist_ok=True)
    for phase in (TUNING, EVALUATION):
        if any(run.finished(study_dir) for run in phase_runs(spec, phase, choices)):
            sweep_report.write_report(study_dir / phase, out / phase)
    runs = phase_runs(spec, EVALUATION, choices)
    results = [result for run in runs if (result := read_result(study_dir, run)) is not None]
    tuned = [r for run in tuning_runs(spec) if (r := read_result(study_dir, run)) is not None]
    missing = [run.name for run in runs if not run.finished(study_dir)]
    lines = protocol(spec, record, choices)
    if rewritten_by is not None:
        lines.append(
            f"- This report was written again from the finished runs by the code at commit "
            f"{rewritten_by} (`simoun-study report`); the runs are the study's."
        )
    if results:
        recipes = recipe_variants(study_dir / EVALUATION)
        lines += results_section(spec, out / EVALUATION, recipes)
        plot_curves(spec, results, out / CURVES_PNG)
    if missing:
        lines += ["", "## Evaluation runs not finished (not counted)", ""]
        lines += [f"- {name}" for name in missing]
    lines += time_section(tuned + results)
    text = "\n".join(lines) + "\n"
    atomic_write(out / REPORT_MD, lambda tmp: tmp.write_text(text))
    _write_csv(out / SCORES_CSV, score_rows(tuned + results))
    return sorted(p for p in out.rglob("*") if p.is_file())


def phase_runs(spec: StudySpec, phase: str, choices: dict[str, Choice]) -> list[StudyRun]:
    if phase == TUNING:
        return tuning_runs(spec)
    return evaluation_runs(spec, {recipe: choice.setting for recipe, choice in choices.items()})
