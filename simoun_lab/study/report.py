"""The study's report: the protocol it ran, then the held-out evaluation's statistics and costs.

Written into ``<study>/report/`` (and the archive's ``report/``):

- ``tuning/`` and ``evaluation/``: ``simoun-report`` of each phase's runs
  (:func:`simoun_lab.sweep.report.write_report`: per recipe and task the IQM of the normalized
  final return with its 95 % stratified bootstrap CI, the aggregate over tasks, the probability
  of improvement of each pair, per-task curves and the performance profile);
- ``report.md``: the protocol (code commit, recipes and what each was given, grid, seeds of each
  phase, budgets, selection rule, each recipe's selected setting with its tuning score), the
  evaluation phase's per-task and aggregate IQM with CIs and the probability that the first
  recipe improves on each other one (read from ``evaluation/``), the IQM curves over all tasks
  against env steps and wall time (``iqm_curves.png``), and the wall and CPU time of the runs;
- ``scores.csv``: one row per finished run of both phases (final return, score, wall and CPU
  time, machine load at its start);
- with ``[diagnostics]`` in the spec: each ablation's IQM, its difference to its method and
  P(method > ablation), with CIs (the ablations stay out of the compared recipes' tables);
- with ``[generalization]``: per recipe, the return under each distraction mode over the train
  mode's return, IQM over runs with CIs, and P(first recipe > Y) of that ratio;
- with the driving measures in the evaluation runs' ``eval.csv`` (highway-env): the paper's
  Table 2, per recipe the IQM over runs of each final measure with CIs beside the reference
  drivers of the study directory's ``references.json``, and P(first recipe > Y) on return and
  on crash rate (:mod:`simoun_lab.study.driving`);
- with ``update_cost.json`` in the study directory (``benchmarks/recipe_update.py --json``, each
  recipe's update time over the baseline's, measured side by side): the IQM curves against wall
  time on the baseline's clock stretched by each recipe's ratio (``iqm_wall_time_update_cost.png``).

Scores follow Agarwal et al. 2021 (:mod:`simoun_lab.stats`): the last evaluation's mean
return divided by the task's maximum (1000 for dm_control; raw returns for tasks without a
known maximum).
"""

from __future__ import annotations

import csv
import difflib
import json
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simoun_agent import table
from simoun_agent.config import RECIPES, SetupError, resolve, to_dict
from simoun_agent.config.envs import env_label
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import is_real, show
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import Damaged, broken_link, present, read_json_object
from simoun_agent.run.layout import SUMMARY_NAME
from simoun_agent.run.rundir import check_output_dir, check_output_files, output_files
from simoun_lab import stats
from simoun_lab.study.checks import check_run_folder
from simoun_lab.study.choice import SELECTION_FILE, Choice, check_config, read_finished
from simoun_lab.study.driving import (
    MEASURES,
    REFERENCE_COMMAND,
    REFERENCES_JSON,
    final_measures,
    read_references,
)
from simoun_lab.study.generalization import read_modes
from simoun_lab.study.plan import (
    EVALUATION,
    TUNING,
    StudyRun,
    evaluation_runs,
    setting_label,
    tuning_runs,
)
from simoun_lab.study.selection import SELECTION_RULES, TIE_RULE
from simoun_lab.study.spec import StudySpec, fixed_by
from simoun_lab.sweep import report as sweep_report
from simoun_lab.sweep.trainable import read_trial_parts

REPORT_DIR = "report"
REPORT_MD = "report.md"
SCORES_CSV = "scores.csv"
CURVES_PNG = "iqm_curves.png"

CURVE_POINTS = 50
"""Points of the common wall-time grid the IQM curve is drawn on."""

UPDATE_COST_JSON = "update_cost.json"
"""Per-recipe update-cost ratios measured side by side, in the study directory:
``benchmarks/recipe_update.py --json`` writes ``baseline`` (the recipe the ratios divide by),
``ratio`` (recipe -> its update time over the baseline's), ``ms_per_update``, ``task``,
``action_repeat``, ``command``, ``commit`` and ``machine``."""

COST_CURVES_PNG = "iqm_wall_time_update_cost.png"

REPORT_FILES = (
    REPORT_MD,
    SCORES_CSV,
    CURVES_PNG,
    COST_CURVES_PNG,
    *(f"{phase}/{name}" for phase in (TUNING, EVALUATION) for name in sweep_report.REPORT_FILES),
)
"""The files the report writes in its directory (names and paths under it)."""


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
    modes: dict | None = None
    """mode -> mean return of the final agent (``generalization.csv``, ``train`` included);
    None when it was not played"""
    driving: dict | None = None
    """the final evaluation's driving measures (eval.csv's last row, raw return included:
    :data:`~simoun_lab.study.driving.MEASURES`); None when eval.csv has no driving columns"""


def read_result(study_dir: Path, run: StudyRun) -> RunResult | None:
    """The run's result, None when it has not finished."""
    run_dir = Path(study_dir, run.name)
    if not present(run_dir / SUMMARY_NAME):
        return None
    summary, curve, rows = read_finished(run_dir)
    curve["return_mean"] = stats.normalize(run.task, curve["return_mean"])
    final = float(summary["final_eval"]["return_mean"])
    parts = read_trial_parts(run_dir)
    cpu = sum(part.get("cpu_s", math.nan) for part in parts) if parts else math.nan
    load = parts[0]["loadavg"][0] / parts[0]["cpu_count"] if parts else math.nan
    score = float(stats.normalize(run.task, [final])[0])
    modes = read_modes(run_dir, int(summary["env_step"]))
    wall = float(summary["wall_time_s"])
    return RunResult(run, final, score, curve, wall, cpu, load, modes, final_measures(rows))


def _interval(point: float, low: float, high: float, digits: str = ".3f") -> str:
    return f"{point:{digits}} [{low:{digits}}, {high:{digits}}]"


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
    for method, ablations in spec.diagnostics.items():
        lines.append(
            f"- Diagnostics of `{method}` (not compared recipes, not tuned): "
            + ", ".join(f"`{a}`" for a in ablations)
            + f", each at `{method}`'s selected setting "
            f"(`{setting_label(choices[method].setting)}`) on the evaluation tasks and seeds."
        )
    if spec.generalization:
        lines.append(
            "- Generalization: each evaluation run's final agent played "
            f"{spec.generalization_episodes} episodes of the train mode and of each of "
            f"{', '.join(spec.generalization)} (`simoun_agent/generalization/`), on the run's "
            "evaluation seeds; nothing trained again."
        )
    lines += [
        "",
        "### What each recipe was given",
        "",
        "Each recipe got the same base config, grid, seeds and budgets; its own values are its "
        "recipe's (`simoun_agent/config/recipes.py`) and the grid setting its tuning selected.",
        "",
        table.markdown_table(
            ["recipe", "what it is", "selected setting", "tuning score"],
            [
                [
                    recipe,
                    RECIPES[recipe].description,
                    f"`{setting_label(choices[recipe].setting)}`",
                    f"{choices[recipe].score:.4g}",
                ]
                for recipe in spec.recipes
            ],
            align="lllr",
        ),
    ]
    keys, values = recipe_differences(spec, choices)
    if keys:
        lines += [
            "",
            "The resolved configs of the evaluation runs differ only in these keys:",
            "",
            table.markdown_table(
                ["recipe", *keys],
                [[recipe] + [show(values[recipe][key]) for key in keys] for recipe in spec.recipes],
            ),
        ]
    lines += [
        "",
        "### Tuning scores",
        "",
        "Each setting's score by the selection rule: the mean over tasks of the mean over seeds "
        "(each seed's score in brackets); **bold** is the selected one.",
        "",
    ]
    rows = []
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
            rows.append([recipe, label, score, *per_task])
    headers = ["recipe", "setting", "score", *(env_label(t) for t in tuning.tasks)]
    return [*lines, table.markdown_table(headers, rows, align="llr")]


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
        "interval (Agarwal et al. 2021; `simoun_lab/stats.py`). With a few seeds per task the "
        "intervals are wide: overlapping intervals are no evidence of a difference.",
        "",
    ]
    # the diagnostic recipes run under evaluation/ too: their own section compares them
    per_task = [r for r in per_task if recipe_of(r) in order]
    aggregate = [r for r in aggregate if recipe_of(r) in order]
    improvement = [r for r in improvement if recipe_of(r, "y") in order]
    per_task.sort(key=lambda r: (tasks.index(r["env"]), order.get(recipe_of(r), 0)))
    rows = []
    for row in per_task:
        spread = "" if math.isnan(row["final_return_std"]) else f" ± {row['final_return_std']:.0f}"
        rows.append(
            [
                row["env"],
                recipe_of(row),
                f"{row['n']:.0f}",
                f"{row['final_return_mean']:.1f}{spread}",
                _interval(row["iqm"], row["iqm_low"], row["iqm_high"]),
            ]
        )
    headers = ["task", "recipe", "n", "return (mean ± std)", "IQM score [95 % CI]"]
    lines.append(table.markdown_table(headers, rows, align="llrrr"))
    aggregate.sort(key=lambda r: order.get(recipe_of(r), 0))
    lines += [
        "",
        "Over all evaluation tasks (IQM of every run's score, tasks pooled):",
        "",
        table.markdown_table(
            ["recipe", "runs", "IQM score [95 % CI]"],
            [
                [recipe_of(r), f"{r['runs']:.0f}", _interval(r["iqm"], r["iqm_low"], r["iqm_high"])]
                for r in aggregate
            ],
            align="lrr",
        ),
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
            table.markdown_table(
                ["Y", "tasks", "P(X > Y) [95 % CI]"],
                [
                    [recipe_of(r, "y"), r["tasks"], _interval(r["p"], r["low"], r["high"])]
                    for r in mine
                ],
                align="llr",
            ),
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


def scores_by_task(
    results: list[RunResult], recipe: str, value: Callable[[RunResult], float] | None = None
) -> dict[str, np.ndarray]:
    """Task -> ``value`` (default: the normalized final score) of each of ``recipe``'s runs
    among ``results``."""
    scores: dict[str, list[float]] = {}
    for result in results:
        if result.run.recipe == recipe:
            score = result.score if value is None else value(result)
            scores.setdefault(result.run.task, []).append(score)
    return {task: np.array(values) for task, values in scores.items()}


def _bootstrap(scores: stats.Scores) -> tuple[float, float, float]:
    return stats.stratified_bootstrap_ci(
        scores,
        stats.aggregate_iqm,
        sweep_report.BOOTSTRAP_REPS,
        sweep_report.CONFIDENCE,
        sweep_report.BOOTSTRAP_SEED,
    )


def _pair(method: stats.Scores, other: stats.Scores) -> tuple[dict, dict]:
    """Both score sets on the tasks both have runs of."""
    tasks = [task for task in method if task in other]
    return {t: method[t] for t in tasks}, {t: other[t] for t in tasks}


def measure_scores(driven: list[RunResult], recipe: str, key: str) -> dict[str, np.ndarray]:
    """Task -> the final driving measure ``key`` of each of ``recipe``'s runs among ``driven``
    (runs with driving measures)."""
    return scores_by_task(driven, recipe, lambda result: result.driving[key])


def reference_lines(spec: StudySpec, references: dict[str, Any] | None) -> list[str]:
    """Where the reference drivers' rows came from, or how to add them."""
    if references is None:
        return [
            f"No `{REFERENCES_JSON}` in the study directory, so no reference drivers' rows "
            '(docs/driving.md, "Reference drivers", has their committed numbers). To add them '
            f"at the study's preset: `{REFERENCE_COMMAND}` (DIR: this study's directory), then "
            "write the report again (`simoun-study report`)."
        ]
    lines = [
        'The rows marked (reference): the reference drivers of docs/driving.md ("Reference '
        'drivers"), played through the same environment stack, evaluation and metric code as '
        f"the learned ones, read from `{REFERENCES_JSON}` in the study directory, written by "
        f"`{references['command']}`: preset `{references['preset']}`, "
        f"{references['episodes']} episode(s) from seed {references['seed']}. Each cell is "
        "the mean over those episodes (no interval)."
    ]
    if references["preset"] != spec.preset:
        lines[0] += (
            f" They were played on preset `{references['preset']}`, not the study's "
            f"`{spec.preset}`: their numbers do not compare with the recipes'."
        )
    return lines


def driving_section(spec: StudySpec, results: list[RunResult], study_dir: Path) -> list[str]:
    """The paper's Table 2 from the evaluation runs whose eval.csv has the driving measures:
    per recipe the IQM over runs of each final measure with its interval, the reference
    drivers' rows, and P(first recipe > Y) on return and on crash rate (fewer crashes). Empty
    when no run has the measures."""
    driven = [r for r in results if r.driving is not None and r.run.recipe in spec.recipes]
    if not driven:
        return []
    recipes = [recipe for recipe in spec.recipes if any(r.run.recipe == recipe for r in driven)]
    rows = []
    for recipe in recipes:
        cells = [
            _interval(*_bootstrap(measure_scores(driven, recipe, key)), digits)
            for key, _, digits in MEASURES
        ]
        rows.append([recipe, sum(r.run.recipe == recipe for r in driven), *cells])
    references = read_references(study_dir)
    for driver, metrics in (references or {}).get("drivers", {}).items():
        cells = [format(metrics[key], digits) for key, _, digits in MEASURES]
        rows.append([f"{driver} (reference)", "–", *cells])
    headers = ["recipe or driver", "runs", *(header for _, header, _ in MEASURES)]
    lines = [
        "",
        "## Driving measures (the paper's Table 2)",
        "",
        "Each evaluation run's final evaluation (the last row of its `eval.csv`, means over its "
        "episodes), as `simoun_agent/run/driving_metrics.py` measures them: the return "
        "(highway-env's reward summed over an episode, not normalized), the crash rate (the "
        "share of episodes that crashed), the distance travelled, the mean speed, the mean "
        "abs(steering) over full lock and the brake fraction (the mean braking over full "
        "braking). A recipe's cell: the IQM over its runs (tasks pooled) with its 95 % "
        "stratified bootstrap interval.",
        "",
        *reference_lines(spec, references),
        "",
        table.markdown_table(headers, rows, align="lr" + "r" * len(MEASURES)),
    ]
    first = spec.recipes[0]
    args = (sweep_report.BOOTSTRAP_REPS, sweep_report.CONFIDENCE, sweep_report.BOOTSTRAP_SEED)
    mine = {key: measure_scores(driven, first, key) for key in ("return_mean", "crash_rate")}
    pairs = []
    for other in recipes[1:] if first in recipes else []:
        x, y = _pair(mine["return_mean"], measure_scores(driven, other, "return_mean"))
        crash_x, crash_y = _pair(mine["crash_rate"], measure_scores(driven, other, "crash_rate"))
        if not x:
            pairs.append([other, "–", "–"])
            continue
        # fewer crashes is better: P(-crash rate of X > -crash rate of Y)
        fewer = stats.probability_of_improvement_ci(
            {t: -v for t, v in crash_x.items()}, {t: -v for t, v in crash_y.items()}, *args
        )
        improvement = stats.probability_of_improvement_ci(x, y, *args)
        pairs.append([other, _interval(*improvement), _interval(*fewer)])
    if pairs:
        lines += [
            "",
            f"P({first} > Y): the chance that a run of {first} does better than a run of Y on "
            "the same task (ties count one half), averaged over the tasks both ran, with its "
            "95 % stratified bootstrap interval; 0.5 is no difference. On return higher is "
            "better; on crash rate lower is better, so that column is P(fewer crashes).",
            "",
            table.markdown_table(
                [
                    "Y",
                    f"P({first} > Y) on return [95 % CI]",
                    f"P({first} > Y) on crash rate, lower is better: P(fewer crashes) [95 % CI]",
                ],
                pairs,
                align="lrr",
            ),
        ]
    return lines


def diagnostics_section(spec: StudySpec, results: list[RunResult]) -> list[str]:
    """Each method's ablations against it: IQM, the IQM difference and P(method > ablation),
    each with its 95 % stratified bootstrap interval (method and ablation resampled apart)."""
    lines: list[str] = []
    args = (sweep_report.BOOTSTRAP_REPS, sweep_report.CONFIDENCE, sweep_report.BOOTSTRAP_SEED)
    for method, ablations in spec.diagnostics.items():
        mine = scores_by_task(results, method)
        rows = []
        for ablation in ablations:
            x, y = _pair(mine, scores_by_task(results, ablation))
            if not x:
                rows.append([ablation, RECIPES[ablation].description, 0, "–", "–", "–"])
                continue
            difference = stats.difference_ci(x, y, stats.aggregate_iqm, *args)
            improvement = stats.probability_of_improvement_ci(x, y, *args)
            runs = sum(len(v) for v in y.values())
            rows.append(
                [
                    ablation,
                    RECIPES[ablation].description,
                    runs,
                    _interval(*_bootstrap(y)),
                    _interval(*difference),
                    _interval(*improvement),
                ]
            )
        lines += [
            "",
            f"## Diagnostics of {method}: what each part adds",
            "",
            f"Ablations of `{method}`, not compared recipes: each ran at `{method}`'s selected "
            "setting on the same evaluation tasks and seeds, untuned. IQM score: as above, tasks "
            f"pooled; difference: IQM({method}) - IQM(ablation), positive when the part helps; "
            f"P({method} > ablation): as above, 0.5 is no difference. Intervals: 95 % stratified "
            "bootstrap, the runs of both resampled apart within each task.",
            "",
            f"`{method}` itself: {sum(len(v) for v in mine.values())} runs, IQM score "
            + (_interval(*_bootstrap(mine)) if mine else "– (no finished run)")
            + ".",
            "",
            table.markdown_table(
                [
                    "ablation",
                    "what it is",
                    "runs",
                    "IQM score [95 % CI]",
                    f"IQM({method}) - IQM(ablation) [95 % CI]",
                    f"P({method} > ablation) [95 % CI]",
                ],
                rows,
                align="llrrrr",
            ),
        ]
    return lines


def mode_ratios(results: list[RunResult], recipe: str, mode: str) -> tuple[dict, int]:
    """Task -> each played run's return under ``mode`` over its train-mode return, for
    ``recipe``; and how many played runs were left out for a train return of 0 or less (no
    ratio)."""
    ratios: dict[str, list[float]] = {}
    left_out = 0
    for result in results:
        if result.run.recipe != recipe or result.modes is None:
            continue
        train = result.modes["train"]
        if train <= 0:
            left_out += 1
            continue
        ratios.setdefault(result.run.task, []).append(result.modes[mode] / train)
    return {task: np.array(values) for task, values in ratios.items()}, left_out


def generalization_section(spec: StudySpec, results: list[RunResult]) -> list[str]:
    """Per recipe, the return under each distraction mode over the train-mode return of the
    same final agent on the same seeds: IQM over runs with its interval; then P(first recipe
    > Y) of that ratio per mode."""
    recipes = spec.recipes + list(spec.ablations())
    modes = spec.generalization
    args = (sweep_report.BOOTSTRAP_REPS, sweep_report.CONFIDENCE, sweep_report.BOOTSTRAP_SEED)
    lines = [
        "",
        "## Generalization under distraction",
        "",
        f"Each evaluation run's final agent played {spec.generalization_episodes} episodes of "
        "the train mode and of each distraction mode on the same reset seeds "
        "(`generalization.csv` in each run's directory). A cell: the IQM over runs (tasks "
        "pooled) of the mode's mean return over the train mode's, 1 is no loss, with its 95 % "
        "stratified bootstrap interval; train score: the IQM of the train mode's normalized "
        "return. A run whose train return is 0 or less has no ratio and is left out.",
        "",
    ]
    scored = []
    played = [r for r in results if r.modes is not None]
    for recipe in recipes:
        mine = [r for r in played if r.run.recipe == recipe]
        if not mine:
            continue
        train: dict[str, list[float]] = {}
        for r in mine:
            train.setdefault(r.run.task, []).append(r.modes["train"])
        train_scores = {t: stats.normalize(t, v) for t, v in train.items()}
        cells = []
        for mode in modes:
            ratios, _ = mode_ratios(played, recipe, mode)
            cells.append(_interval(*_bootstrap(ratios)) if ratios else "–")
        _, left_out = mode_ratios(played, recipe, modes[0])
        count = f"{len(mine)}" + (f" ({left_out} left out)" if left_out else "")
        scored.append([recipe, count, _interval(*_bootstrap(train_scores)), *cells])
    headers = ["recipe", "runs", "train score [95 % CI]", *modes]
    lines.append(table.markdown_table(headers, scored, align="lrr" + "r" * len(modes)))
    first = spec.recipes[0]
    rows = []
    for other in recipes[1:]:
        cells = []
        for mode in modes:
            x, y = _pair(mode_ratios(played, first, mode)[0], mode_ratios(played, other, mode)[0])
            cells.append(_interval(*stats.probability_of_improvement_ci(x, y, *args)) if x else "–")
        rows.append([other, *cells])
    if rows:
        lines += [
            "",
            f"P({first} > Y) of that ratio, per mode: the chance that a run of {first} keeps "
            "more of its train-mode return than a run of Y on the same task, with its 95 % "
            "interval.",
            "",
            table.markdown_table(["Y", *modes], rows, align="l" + "r" * len(modes)),
        ]
    unplayed = [r.run.name for r in results if r.modes is None]
    if unplayed:
        lines += ["", "Finished evaluation runs not played (not counted):", ""]
        lines += [f"- {name}" for name in unplayed]
    return lines


UPDATE_COST_KEYS = (
    "baseline",
    "ratio",
    "ms_per_update",
    "task",
    "action_repeat",
    "command",
    "commit",
    "machine",
)
"""The keys of :data:`UPDATE_COST_JSON` the report reads."""


def read_update_costs(spec: StudySpec, study_dir: Path) -> dict[str, Any] | None:
    """The study's ``update_cost.json`` (:data:`UPDATE_COST_JSON`), None when there is none;
    SetupError naming the file, what is wrong and how to write it again when it is damaged,
    lacks a key the report reads, or holds a value the report cannot use
    (:func:`update_cost_problem`)."""
    path = study_dir / UPDATE_COST_JSON
    if not present(path):
        return None
    try:
        costs = read_json_object(path)
    except Damaged as err:
        problem = str(err)
    else:
        problem = update_cost_problem(spec, costs)
        if problem is None:
            return costs
    raise SetupError(
        f"{path} is damaged: {problem}. Write it again with `python benchmarks/recipe_update.py "
        f"--selection {study_dir / SELECTION_FILE} --json {path}`, or move it aside (mv {path} "
        f"{path}.damaged) to report the runs' own wall times"
    )


def update_cost_problem(spec: StudySpec, costs: dict[str, Any]) -> str | None:
    """What is wrong with the contents ``costs`` of ``update_cost.json``, else None: a key the
    report reads missing, a baseline that is not one of the study's recipes (no run gives its
    clock), a ratio or time per update that is not a positive number (``"2.1x"``, 0, NaN), or
    a recipe with a ratio and no time per update."""
    missing = [key for key in UPDATE_COST_KEYS if key not in costs]
    if missing:
        return f"it has no {', '.join(missing)}"
    recipes = spec.recipes + list(spec.ablations())
    if costs["baseline"] not in recipes:
        return (
            f"its baseline is {json.dumps(costs['baseline'])}, which is not a recipe of this study "
            f"({', '.join(recipes)}): no run of it gives the clock the ratios stretch"
        )
    for key in ("ratio", "ms_per_update"):
        if not isinstance(costs[key], dict):
            return f"its {key} is not an object"
        if problem := unknown_recipe(key, costs[key], recipes):
            return problem
        for recipe, value in costs[key].items():
            if not (is_real(value) and value > 0):
                return (
                    f"its {key}.{recipe} is {json.dumps(value)}, which must be a positive "
                    "number (such as 2.1, without a unit)"
                )
    untimed = [recipe for recipe in costs["ratio"] if recipe not in costs["ms_per_update"]]
    if untimed:
        return f"ratio has {', '.join(untimed)}, which ms_per_update does not"
    return None


def unknown_recipe(key: str, values: dict[str, Any], recipes: list[str]) -> str | None:
    """What is wrong when ``values`` (the file's ``key``: ratio or ms_per_update) holds a name
    that is no recipe (a run's folder, a misspelling), with the study's recipe it comes closest
    to: left alone, its recipe would be reported as having no ratio. A recipe of simoun outside
    this study (``recipe_update.py --ablations`` times more) is taken; the report leaves it out."""
    for name in values:
        if name in recipes or name in RECIPES:
            continue
        close = [recipe for recipe in recipes if name.split("/")[0] == recipe]
        close = close or difflib.get_close_matches(name, recipes, n=1, cutoff=0.6)
        guess = f" (did you mean {close[0]}? rename the key to it)" if close else ""
        return (
            f"its {key} has {json.dumps(name)}, which is not a recipe{guess}: the file is keyed "
            f"by recipe name (this study's: {', '.join(recipes)}), not by a run's folder"
        )
    return None


def baseline_clock(results: list[RunResult], baseline: str) -> dict[str, tuple]:
    """Task -> (env steps, wall seconds): at each evaluation step, the median over the
    baseline's runs on that task of the wall time it had taken (their common steps only)."""
    clocks = {}
    for task in dict.fromkeys(r.run.task for r in results):
        runs = [r for r in results if r.run.recipe == baseline and r.run.task == task]
        if not runs:
            continue
        steps = runs[0].curve["env_step"]
        for run in runs[1:]:
            steps = np.intersect1d(steps, run.curve["env_step"])
        walls = [np.interp(steps, r.curve["env_step"], r.curve["wall_time_s"]) for r in runs]
        clocks[task] = (steps, np.median(walls, axis=0))
    return clocks


def cost_curves(
    results: list[RunResult], costs: dict[str, Any]
) -> tuple[list[RunResult], dict[str, list[str]]]:
    """The runs with ``cost_time_s`` on their curves: the baseline's clock on their task at
    their evaluation steps, times their recipe's update-cost ratio; and the recipes left out,
    by reason (no ratio in the file; no finished run of the baseline on their task)."""
    clocks = baseline_clock(results, costs["baseline"])
    placed: list[RunResult] = []
    left_out: dict[str, list[str]] = {}
    for result in results:
        ratio = costs["ratio"].get(result.run.recipe)
        reason = (
            "no ratio in the file"
            if ratio is None
            else f"no finished run of {costs['baseline']} on their task"
            if result.run.task not in clocks
            else None
        )
        if reason:
            recipes = left_out.setdefault(reason, [])
            recipes += [result.run.recipe] if result.run.recipe not in recipes else []
            continue
        steps, wall = clocks[result.run.task]
        curve = dict(result.curve)
        curve["cost_time_s"] = ratio * np.interp(curve["env_step"], steps, wall)
        placed.append(RunResult(**{**result.__dict__, "curve": curve}))
    return placed, left_out


def update_cost_section(
    spec: StudySpec, results: list[RunResult], costs: dict[str, Any] | None, out: Path
) -> list[str]:
    """IQM curves against wall time at the measured update costs ``costs``
    (:func:`read_update_costs`), with where the ratios came from; without ``update_cost.json``
    (None), how to measure them."""
    lines = ["", "## Wall time at update costs measured side by side", ""]
    if costs is None:
        return [
            *lines,
            f"No `{UPDATE_COST_JSON}` in the study directory: the wall-time curves above use the "
            "runs' own wall times, measured while machines ran under different loads. To compare "
            "at equal wall time, time every recipe's update in one process at the study's "
            f"commit: `python benchmarks/recipe_update.py --selection DIR/{SELECTION_FILE} "
            f"--json DIR/{UPDATE_COST_JSON}` (DIR: this study's directory), then write the "
            "report again (`simoun-study report`).",
        ]
    baseline = costs["baseline"]
    placed, left_out = cost_curves(results, costs)
    recipes = [r for r in spec.recipes + list(spec.ablations()) if r in costs["ratio"]]
    lines += [
        f"Update-cost ratios from `{UPDATE_COST_JSON}`: `{costs['command']}` at commit "
        f"`{costs['commit']}` on {costs['machine']}, {env_label(costs['task'])} at action "
        f"repeat {costs['action_repeat']}; every recipe's update timed in one process, "
        f"interleaved, as the median of its repeats, over {baseline}'s.",
        "",
        table.markdown_table(
            ["recipe", "ms per update", f"x {baseline}"],
            [[r, f"{costs['ms_per_update'][r]:.1f}", f"{costs['ratio'][r]:.2f}"] for r in recipes],
            align="lrr",
        ),
        "",
        f"Each run is placed on {baseline}'s clock (at each evaluation step, the median wall "
        f"time of {baseline}'s evaluation runs on the task) stretched by its recipe's ratio, so "
        "every recipe's time comes from one machine's measurement. The whole step, env and "
        "evaluations included, is charged at the update's ratio: where updates take a share u "
        f"of {baseline}'s step, the true ratio is u x ratio + 1 - u, and the gaps between "
        "curves are drawn wider than they are, either way.",
    ]
    if placed:  # the figure is linked only where it is drawn
        lines += ["", f"![IQM curves at measured update costs]({COST_CURVES_PNG})"]
    for reason, names in left_out.items():
        lines += ["", f"Not drawn ({reason}): {', '.join(names)}."]
    if placed:
        plot_curves(
            [r for r in recipes if any(p.run.recipe == r for p in placed)],
            placed,
            out / COST_CURVES_PNG,
            [("cost_time_s", f"seconds on {baseline}'s clock x update-cost ratio", CURVE_POINTS)],
        )
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
    ]
    rows = []
    groups: dict[tuple[str, str], list[RunResult]] = {}
    for result in results:
        groups.setdefault((result.run.phase, result.run.recipe), []).append(result)
    for (phase, recipe), group in groups.items():
        steps = np.mean([r.run.env_steps for r in group])
        wall = np.mean([r.wall_s for r in group])
        loads = [r.load for r in group if not math.isnan(r.load)]
        load = f"{max(loads):.2f}" if loads else "–"
        rows.append(
            [
                phase,
                recipe,
                len(group),
                f"{steps:.0f}",
                f"{wall:.0f}",
                mean_cpu(group),
                f"{steps / wall:.1f}",
                load,
            ]
        )
    headers = ["phase", "recipe", "runs", "env steps", "wall time per run (s)"]
    headers += ["CPU time per run (s)", "env steps per wall second", "load at start (max)"]
    lines.append(table.markdown_table(headers, rows, align="llrrrrrr"))
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


AXES = [
    ("env_step", "environment steps", None),
    ("wall_time_s", "wall-clock seconds", CURVE_POINTS),
]
"""The IQM curves' x axes: the curve key, its label, the points of its grid (None: the
evaluation steps)."""


def plot_curves(
    recipes: list[str], results: list[RunResult], path: Path, axes_of: list[tuple] = AXES
) -> None:
    """IQM over all tasks' runs with its band per recipe, one panel per x axis of ``axes_of``
    (each recipe's curve up to its shortest run)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(axes_of), figsize=(5.5 * len(axes_of), 4), dpi=110)
    axes = np.atleast_1d(axes)
    for ax, (x_key, label, points) in zip(axes, axes_of, strict=True):
        for recipe in recipes:
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
    if rows:
        table.write_csv(path, list(rows[0]), rows)


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
    out = report_dir(study_dir / REPORT_DIR, REPORT_FILES)
    costs = read_update_costs(spec, study_dir)  # before the work, which a bad file would lose
    runs = phase_runs(spec, EVALUATION, choices)
    for run in tuning_runs(spec) + runs:  # a damaged run is named, not counted as unfinished
        check_run_folder(study_dir, run.name)
    for run in runs:  # before simoun-report of the phase, which would leave a damaged one out
        if present(Path(study_dir, run.name, SUMMARY_NAME)):
            check_config(spec, study_dir, run)
    phases = [
        phase
        for phase in (TUNING, EVALUATION)
        if any(run.finished(study_dir) for run in phase_runs(spec, phase, choices))
    ]
    for phase in phases:  # both before either is written: a report is not left half new
        check_output_dir(out / phase, None, sweep_report.REPORT_FILES)
    for phase in phases:  # the study command has no --out: its report's folders are its own
        sweep_report.write_report(study_dir / phase, out / phase, flag=None)
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
        plot_curves(spec.recipes, results, out / CURVES_PNG)
        lines += driving_section(spec, results, study_dir)
        if spec.diagnostics:
            lines += diagnostics_section(spec, results)
        if spec.generalization:
            lines += generalization_section(spec, results)
        lines += update_cost_section(spec, results, costs, out)
    if missing:
        lines += ["", "## Evaluation runs not finished (not counted)", ""]
        lines += [f"- {name}" for name in missing]
    lines += time_section(tuned + results)
    text = "\n".join(lines) + "\n"
    atomic_write(out / REPORT_MD, lambda tmp: tmp.write_text(text))
    _write_csv(out / SCORES_CSV, score_rows(tuned + results))
    return sorted(p for p in out.rglob("*") if p.is_file())


def report_dir(out: Path, files: Iterable[str] = ()) -> Path:
    """The report's directory ``out``, made; SetupError naming it when something else stands
    there (a file, a link to nothing), which a report cannot be written into, or naming one of
    the ``files`` (names or glob patterns) the report writes in it when something else than a
    file stands there (:func:`~simoun_agent.run.rundir.check_output_files`)."""
    problem = broken_link(out)
    if problem is None and present(out) and not out.is_dir():
        problem = "it is a file, not a directory"
    if problem:
        raise SetupError(
            f"{out} is where the report is written, but {problem}; move it aside (mv {out} "
            f"{out}.old) and run the command again"
        )
    check_output_files(output_files(out, files))
    out.mkdir(parents=True, exist_ok=True)
    return out


def phase_runs(spec: StudySpec, phase: str, choices: dict[str, Choice]) -> list[StudyRun]:
    if phase == TUNING:
        return tuning_runs(spec)
    return evaluation_runs(spec, {recipe: choice.setting for recipe, choice in choices.items()})
