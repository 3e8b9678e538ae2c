"""The study's report from its archive: per task and arm the IQM of the final success rate and
extrinsic return with 95 % stratified bootstrap CIs (Agarwal et al. 2021, ``simoun_lab.stats``),
the probability that an intrinsic arm beats plain PPO, curves against env steps and wall time,
each arm's step-time cost, and what the intrinsic rewards look like during training.

Scores are the last evaluation of each run (32 episodes on fixed held-out env seeds by default).
DoorKey's return lies in [0, 1] (1 - 0.9 x steps / max_steps on success), so success rate and
return need no normalization. Only seeds on which every arm has finished are used, so a study
stopped part way compares the arms on the same seeds; the runs left out are counted.
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure  # no pyplot: no backend or global figure state
from matplotlib.ticker import EngFormatter

from simoun_agent import table
from simoun_agent.config import SetupError
from simoun_agent.config.device import device_keys
from simoun_agent.config.rules import is_real
from simoun_agent.run.checkpoint import atomic_write
from simoun_agent.run.kept import (
    Damaged,
    csv_number,
    folder_problem,
    present,
    read_csv_rows,
    read_json_object,
)
from simoun_agent.run.rundir import check_output_dir, copy_fix
from simoun_lab import stats
from simoun_lab.minigrid_study.run import EVAL_CSV, SUMMARY, TRAIN_CSV
from simoun_lab.minigrid_study.spec import Run, StudySpec, spec_from_dict
from simoun_lab.minigrid_study.training import CONFIG
from simoun_lab.study.report import report_dir

__all__ = ["REPORT", "write_report"]

REPORT = "report.md"
REPS = 2000
"""bootstrap resamples of every interval"""
MIN_SEEDS = 3
"""fewest seeds a task needs for an interval, and to enter a pooled score or a comparison: a
bootstrap over one or two runs gives an interval that looks precise and is not"""


EVAL_COLUMNS = ("env_step", "wall_s", "success_rate", "return_mean")
"""the eval.csv columns the report and the selection read"""
SUMMARY_KEYS = ("env_steps", "env_s", "update_s", "steps_per_s")
"""the summary.json numbers the report reads"""


def damaged(path: Path, problem: str) -> SetupError:
    """The error for a finished run's damaged file: what is wrong, and the two fixes."""
    run_dir = path.parent
    return SetupError(
        f"{path} is damaged: {problem}. Restore it from a copy (git checkout -- {path}, for a "
        f"committed archive), or move its run aside (mv {run_dir} {run_dir}.damaged) and run the "
        "study again, which trains that run anew"
    )


def read_rows(path: Path, columns: tuple[str, ...] = ("env_step",)) -> list[dict[str, float]]:
    """The rows of a finished run's ``eval.csv`` or ``train.csv``, values as floats; SetupError
    naming the file when it is damaged, lacks one of ``columns`` or holds no row."""
    try:
        rows = read_csv_rows(path, columns)
        if not rows:
            raise Damaged("it holds no row after its header, but its run finished")
        return [
            {key: csv_number(text, key, line) for key, text in row.items()}
            for line, row in enumerate(rows, start=2)
        ]
    except Damaged as err:
        raise damaged(path, str(err)) from None
    except OSError as err:
        raise damaged(path, unreadable(err)) from None


def unreadable(err: OSError) -> str:
    """What is wrong with a finished run's file that could not be opened."""
    if isinstance(err, FileNotFoundError):
        return "it is missing, but its run finished (summary.json is there)"
    return f"it cannot be read ({err.strerror})"


def read_eval(path: Path) -> list[dict[str, float]]:
    """A finished run's ``eval.csv`` (:func:`read_rows`); SetupError naming the file and line
    when a value the report and the selection read is not finite, a step is negative or does
    not come after the one before (rows out of order or repeated), or a success rate lies
    outside [0, 1]."""
    rows = read_rows(path, EVAL_COLUMNS)
    for line, row in enumerate(rows, start=2):
        problem = eval_row_problem(row, rows[line - 3] if line > 2 else None)
        if problem:
            raise damaged(path, f"line {line}: {problem}")
    return rows


def eval_row_problem(row: dict[str, float], before: dict[str, float] | None) -> str | None:
    """What is wrong with one row of ``eval.csv`` (``before``: the row above it), else None."""
    for key in EVAL_COLUMNS:
        if not math.isfinite(row[key]):
            return f"{key} is {row[key]}, not a finite number"
    step = row["env_step"]
    if step < 0 or (before is not None and step <= before["env_step"]):
        return (
            f"env_step {step:g} is negative or does not come after the line before (rows out "
            "of order or repeated)"
        )
    if not 0 <= row["success_rate"] <= 1:
        return f"success_rate is {row['success_rate']:g}, not a rate in [0, 1]"
    return None


def read_summary(path: Path, spec: StudySpec, run: Run) -> dict[str, Any]:
    """A finished run's ``summary.json``; SetupError naming the file when it is damaged, records
    another run, lacks one of :data:`SUMMARY_KEYS` as a number > 0, its env_steps is not the
    run's budget (rounded up to whole rollouts), or its final success rate is no rate in
    [0, 1] or its final return no finite number."""
    try:
        summary = read_json_object(path)
    except Damaged as err:
        raise damaged(path, str(err)) from None
    for key in SUMMARY_KEYS:
        value = summary.get(key)
        if not (is_real(value) and value > 0):
            raise damaged(path, f"{key} is {json.dumps(value)}, not a number > 0")
    if summary.get("run") != run.name:  # a copy of another run's would count its results twice
        raise damaged(path, f"its run is {json.dumps(summary.get('run'))}, not {run.name!r}")
    rollout = spec.ppo.n_envs * spec.ppo.n_steps  # PPO stops after the rollout that passes it
    steps, budget = summary["env_steps"], run.task.steps
    if not budget <= steps < budget + rollout:
        raise damaged(
            path,
            f"env_steps is {json.dumps(steps)}, but a run of {budget} env steps takes from "
            f"{budget} to {budget + rollout - 1} (whole rollouts of {rollout} steps)",
        )
    rate, final = summary.get("final_success_rate"), summary.get("final_return_mean")
    if not (is_real(rate) and 0 <= rate <= 1):
        raise damaged(path, f"final_success_rate is {json.dumps(rate)}, not a rate in [0, 1]")
    if not is_real(final):
        raise damaged(path, f"final_return_mean is {json.dumps(final)}, not a finite number")
    return summary


def check_config(path: Path, spec: StudySpec, run: Run) -> None:
    """SetupError naming a finished run's ``config.json`` when it is damaged, or records
    another run or a run of another spec: its results would be counted as this run's."""
    if not present(path):
        raise damaged(path, unreadable(FileNotFoundError()))
    try:
        config = read_json_object(path)
    except Damaged as err:
        raise damaged(path, str(err)) from None
    if config.get("run") != run.name:
        raise damaged(path, f"its run is {json.dumps(config.get('run'))}, not {run.name!r}")
    saved = config.get("spec")
    if not isinstance(saved, dict):
        raise damaged(path, f"its spec is {json.dumps(saved)}, not the object of a study spec")
    try:
        trained = spec_from_dict(saved, str(path)).to_json()
    except SetupError as err:
        raise damaged(path, f"its spec cannot be read ({err})") from None
    trained, wanted = device_keys(trained), device_keys(spec.to_json())
    changed = sorted(key for key in {**trained, **wanted} if trained.get(key) != wanted.get(key))
    if changed:
        raise damaged(
            path,
            f"its run was trained with another spec than the archive's ({', '.join(changed)} "
            f"differ: {describe_change(trained, wanted, changed[0])})",
        )


def describe_change(trained: dict[str, Any], wanted: dict[str, Any], key: str) -> str:
    """``key`` of two specs' JSON forms, the nested keys that differ named where there are."""
    old, new = trained.get(key), wanted.get(key)
    if isinstance(old, dict) and isinstance(new, dict):
        inner = [k for k in {**old, **new} if old.get(k) != new.get(k)]
        return ", ".join(
            f"{key}.{k} {json.dumps(old.get(k))} where the spec has {json.dumps(new.get(k))}"
            for k in inner
        )
    return f"{key} {json.dumps(old)} where the spec has {json.dumps(new)}"


def read_finished(spec: StudySpec, archive: Path, run: Run) -> dict[str, Any]:
    """A finished run's checked ``summary.json``, its ``config.json`` checked against ``spec``
    and its logs read as the report and the selection read them (SetupError naming a damaged
    file): ``run``, ``report`` and ``select`` each check every finished run's files this way
    before their work, so that a damaged log is named before hours of training, not after."""
    summary = read_summary(archive / run.name / SUMMARY, spec, run)
    check_config(archive / run.name / CONFIG, spec, run)
    read_eval(archive / run.name / EVAL_CSV)
    read_rows(archive / run.name / TRAIN_CSV, TRAIN_COLUMNS)
    return summary


def check_run_folder(archive: Path, run: Run) -> None:
    """SetupError naming a run's place in the archive when something else than a directory
    stands there (a file, a link to nothing or to a folder it is in): the run would be left out
    as unfinished."""
    path = archive / run.name
    problem = folder_problem(path)
    if problem:
        raise SetupError(
            f"{path} (the directory of run {run.name}) is damaged: {problem}. Restore the run "
            f"from a copy (git checkout -- {path}, for a committed archive), or move it aside "
            f"(mv {path} {path}.damaged) and run the study again, which trains that run anew"
        )


def finished(spec: StudySpec, archive: Path) -> list[Run]:
    """The spec's runs finished in the archive, each checked (:func:`read_finished`); SetupError
    naming a run's damaged directory or file: a damaged run is named, not left out."""
    for run in spec.runs():
        check_run_folder(archive, run)
    done = [r for r in spec.runs() if present(archive / r.name / SUMMARY)]
    for run in done:
        read_finished(spec, archive, run)
    return done


class Records:
    """The archive's runs of the seeds every arm has finished (``finished``: all finished
    runs): ``eval``, ``train`` rows and ``summary`` by run. A run is finished once anything is
    at its ``summary.json``: a damaged one is named, not taken for a run still to train."""

    def __init__(self, spec: StudySpec, archive: Path) -> None:
        self.spec, self.archive = spec, archive
        self.finished = finished(spec, archive)
        done = {(r.task.env_id, r.seed, r.arm) for r in self.finished}
        self.used = [
            r
            for r in self.finished
            if all((r.task.env_id, r.seed, arm) in done for arm in spec.arms)
        ]
        self.summary = {r.name: read_finished(spec, archive, r) for r in self.used}
        self.eval = {r.name: read_eval(archive / r.name / EVAL_CSV) for r in self.used}
        self.train = {
            r.name: read_rows(archive / r.name / TRAIN_CSV, TRAIN_COLUMNS) for r in self.used
        }

    def runs(self, env_id: str, arm: str) -> list[Run]:
        return [r for r in self.used if r.task.env_id == env_id and r.arm == arm]

    def final(self, env_id: str, arm: str, key: str) -> np.ndarray:
        """The last evaluation's ``key`` of each finished run of ``arm`` on ``env_id``."""
        return np.array([self.eval[r.name][-1][key] for r in self.runs(env_id, arm)])

    def curves(self, env_id: str, arm: str, key: str) -> np.ndarray:
        """``(runs, evaluations)`` of ``key``; every run shares the spec's evaluation grid."""
        rows = [self.eval[r.name] for r in self.runs(env_id, arm)]
        length = min(len(r) for r in rows)
        return np.array([[row[key] for row in r[:length]] for r in rows])


def ci_text(point: float, low: float, high: float) -> str:
    return f"{point:.2f} [{low:.2f}, {high:.2f}]"


def score_table(records: Records, key: str) -> str:
    """A Markdown table: IQM of the final ``key`` with its 95 % CI, per task and arm, and over
    the tasks with ``MIN_SEEDS`` seeds; a task with fewer shows its runs' values alone."""
    spec = records.spec
    tasks = [t.env_id for t in spec.tasks]
    rows = []
    for arm in spec.arms:
        cells, pooled = [], {}
        for env_id in tasks:
            scores = records.final(env_id, arm, key)
            if len(scores) == 0:
                cells.append("—")
            elif len(scores) < MIN_SEEDS:
                values = ", ".join(f"{s:.2f}" for s in scores)
                cells.append(f"{values} (n={len(scores)}, no CI)")
            else:
                pooled[env_id] = scores
                ci = stats.stratified_bootstrap_ci({env_id: scores}, stats.aggregate_iqm, REPS)
                cells.append(f"{ci_text(*ci)} (n={len(scores)})")
        whole = stats.stratified_bootstrap_ci(pooled, stats.aggregate_iqm, REPS) if pooled else None
        cells.append(ci_text(*whole) if whole else "—")
        rows.append([arm, *cells])
    return table.markdown_table(["arm", *tasks, f"tasks with {MIN_SEEDS}+ seeds"], rows)


def improvement_lines(records: Records) -> list[str]:
    """P(arm > ppo) on the final success rate, per intrinsic arm, over the tasks both ran on
    ``MIN_SEEDS`` seeds."""
    lines = []
    for arm in [a for a in records.spec.arms if a != "ppo"]:
        x, y = {}, {}
        for task in records.spec.tasks:
            mine = records.final(task.env_id, arm, "success_rate")
            base = records.final(task.env_id, "ppo", "success_rate")
            if min(len(mine), len(base)) >= MIN_SEEDS:
                x[task.env_id], y[task.env_id] = mine, base
        if x:
            ci = stats.probability_of_improvement_ci(x, y, REPS)
            lines.append(f"- P({arm} > ppo) on success rate: {ci_text(*ci)} ({', '.join(x)})")
        else:
            lines.append(f"- P({arm} > ppo) on success rate: no task has {MIN_SEEDS} seeds yet")
    return lines


def cost_table(records: Records) -> str:
    """Seconds per 1000 env steps in env stepping (intrinsic reward included) and in PPO's
    updates, env steps per second of training, and the arm's wall time over plain PPO's."""
    rows = []
    for task in records.spec.tasks:
        base = None
        for arm in records.spec.arms:
            summaries = [records.summary[r.name] for r in records.runs(task.env_id, arm)]
            if not summaries:
                continue
            steps = np.array([s["env_steps"] for s in summaries], dtype=float)
            env = np.mean(np.array([s["env_s"] for s in summaries]) / steps) * 1000
            update = np.mean(np.array([s["update_s"] for s in summaries]) / steps) * 1000
            rate = np.mean([s["steps_per_s"] for s in summaries])
            base = rate if arm == "ppo" else base
            ratio = f"{base / rate:.2f}x" if base else "—"
            rows.append([task.env_id, arm, f"{env:.2f}", f"{update:.2f}", f"{rate:.1f}", ratio])
    headers = ["task", "arm", "env s / 1k steps", "update s / 1k steps", "steps / s"]
    return table.markdown_table([*headers, "wall vs ppo"], rows)


INTRINSIC_KEYS = (
    "intrinsic_mean",
    "intrinsic_std",
    "novelty_corr",
    "intrinsic_still_mean",
    "intrinsic_moving_mean",
    "still_fraction",
    "states_visited",
)
TRAIN_COLUMNS = ("env_step", *INTRINSIC_KEYS)
"""the train.csv columns the report reads"""


PARTS = {
    "0-10 %": (0.0, 0.1),
    "10-30 %": (0.1, 0.3),
    "45-55 %": (0.45, 0.55),
    "90-100 %": (0.9, 1.0),
}
"""brackets of training, as fractions of a run's rollouts (10-30 %: where a policy has turned
towards what the intrinsic reward pays for while that reward is still large)"""


def bracket_means(
    records: Records, runs: list[Run], part: tuple[float, float], values: Any
) -> np.ndarray:
    """``values(row)`` (a list of numbers) averaged over the rollouts of the bracket ``part`` of
    each run, then over runs; NaN-free means where some rollout has no value (no still triplet,
    a constant reward)."""
    lo, hi = part
    per_run = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for run in runs:
            rows = records.train[run.name]
            n = len(rows)
            chosen = rows[int(lo * n) : max(int(hi * n), int(lo * n) + 1)]
            per_run.append(np.nanmean([values(r) for r in chosen], axis=0))
        return np.nanmean(per_run, axis=0)


def intrinsic_table(records: Records) -> str:
    """The intrinsic reward per rollout, averaged over each tenth-of-training bracket's rollouts
    and over seeds, in the brackets of :data:`PARTS`. Plain PPO's rows (no
    intrinsic reward) give the share of still triplets its policy makes, for comparison."""
    rows = []
    for task in records.spec.tasks:
        for arm in records.spec.arms:
            runs = records.runs(task.env_id, arm)
            for part, bracket in PARTS.items() if runs else ():
                means = bracket_means(
                    records, runs, bracket, lambda r: [r[k] for k in INTRINSIC_KEYS]
                )
                cells = [
                    f"{v:.0f}" if key == "states_visited" else f"{v:.3f}"
                    for key, v in zip(INTRINSIC_KEYS, means, strict=True)
                ]
                rows.append([task.env_id, arm, part, *cells])
    return table.markdown_table(["task", "arm", "part", *INTRINSIC_KEYS], rows)


def survival_row(row: dict[str, float], gamma: float) -> list[float]:
    """What makes a positive per-step reward a survival bonus, from one rollout's row: the share
    of the reward's second moment its mean carries (``mean^2 / (mean^2 + std^2)``: 1 for a
    constant), the discounted value of that mean to a policy that never ends its episode
    (``mean / (1 - gamma)``, against DoorKey's success reward of at most 1), and whether the
    reward correlated negatively with novelty (1.0) or not (0.0)."""
    mean, std, corr = row["intrinsic_mean"], row["intrinsic_std"], row["novelty_corr"]
    moment = mean**2 + std**2
    return [
        mean**2 / moment if moment > 0 else np.nan,
        mean / (1 - gamma),
        float(corr < 0) if np.isfinite(corr) else np.nan,
    ]


def survival_table(records: Records) -> str:
    """:func:`survival_row` averaged over each bracket of training and over seeds."""
    gamma = records.spec.ppo.gamma
    rows = []
    for task in records.spec.tasks:
        for arm in [a for a in records.spec.arms if a != "ppo"]:
            runs = records.runs(task.env_id, arm)
            for part, bracket in PARTS.items() if runs else ():
                share, value, negative = bracket_means(
                    records, runs, bracket, lambda r: survival_row(r, gamma)
                )
                cells = [f"{share:.3f}", f"{value:.3f}", f"{negative:.2f}"]
                rows.append([task.env_id, arm, part, *cells])
    headers = ["task", "arm", "part", "constant share", "bonus value mean/(1-gamma)"]
    return table.markdown_table([*headers, "rollouts corr < 0"], rows)


def plot_curves(records: Records, out: Path) -> list[str]:
    """Success rate (IQM over seeds, 95 % band) against env steps and training wall time, one
    figure per task; returns the image file names."""
    names = []
    for task in records.spec.tasks:
        fig = Figure(figsize=(11, 4))
        axes = fig.subplots(1, 2, sharey=True)
        drawn = False
        for arm in records.spec.arms:
            if not records.runs(task.env_id, arm):
                continue
            success = records.curves(task.env_id, arm, "success_rate")
            point, low, high = stats.stratified_bootstrap_band(
                {task.env_id: success}, stats.iqm_over_steps, REPS
            )
            steps = records.curves(task.env_id, arm, "env_step").mean(axis=0)
            wall = records.curves(task.env_id, arm, "wall_s").mean(axis=0) / 3600
            for ax, x in zip(axes, (steps, wall), strict=True):
                ax.plot(x, point, label=f"{arm} (n={len(success)})")
                ax.fill_between(x, low, high, alpha=0.2)
            drawn = True
        if not drawn:
            continue
        axes[0].set_xlabel("env steps")
        axes[0].xaxis.set_major_formatter(EngFormatter())  # 400 k, not overlapping 400000s
        axes[1].set_xlabel("training wall time (h, mean over seeds)")
        axes[0].set_ylabel("success rate (IQM, 95 % CI)")
        axes[0].legend()
        fig.suptitle(task.env_id)
        name = f"{task.env_id}_success.png"
        atomic_write(out / name, lambda tmp, fig=fig: fig.savefig(tmp, format="png", dpi=90))
        names.append(name)
    return names


TRAINING_PANELS = (
    ("intrinsic_mean", "intrinsic reward, rollout mean (log)"),
    ("novelty_corr", "corr(intrinsic, 1/sqrt(N(s)))"),
    ("still_fraction", "share of still triplets"),
)


def plot_training(records: Records, out: Path) -> list[str]:
    """Per task, against env steps, each arm's per-rollout intrinsic-reward mean, its novelty
    correlation and its policy's share of still triplets (means over seeds, each curve a rolling
    mean over up to 10 rollouts; one colour per arm in every panel); returns the image names."""
    names = []
    for task in records.spec.tasks:
        fig = Figure(figsize=(15, 4))
        axes = fig.subplots(1, len(TRAINING_PANELS))
        drawn = False
        for index, arm in enumerate(records.spec.arms):
            runs = records.runs(task.env_id, arm)
            if not runs:
                continue
            length = min(len(records.train[r.name]) for r in runs)
            steps = np.array([row["env_step"] for row in records.train[runs[0].name][:length]])
            window = min(10, length)  # short runs (a smoke test) still get a curve
            for ax, (key, label) in zip(axes, TRAINING_PANELS, strict=True):
                if key != "still_fraction" and arm == "ppo":
                    continue  # plain PPO has no intrinsic reward
                values = np.array(
                    [[row[key] for row in records.train[r.name][:length]] for r in runs]
                )
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", RuntimeWarning)
                    mean = np.nanmean(values, axis=0)
                smooth = np.convolve(np.nan_to_num(mean), np.ones(window) / window, mode="valid")
                label_arm = f"{arm} (n={len(runs)})"
                ax.plot(steps[window - 1 :], smooth, color=f"C{index}", label=label_arm)
                ax.set_title(label)
                ax.set_xlabel("env steps")
                ax.xaxis.set_major_formatter(EngFormatter())
                if key == "intrinsic_mean":
                    ax.set_yscale("log")
            drawn = True
        if not drawn:
            continue
        axes[-1].legend()
        fig.suptitle(f"{task.env_id}: the intrinsic rewards during training")
        name = f"{task.env_id}_intrinsic.png"
        atomic_write(out / name, lambda tmp, fig=fig: fig.savefig(tmp, format="png", dpi=90))
        names.append(name)
    return names


def write_report(spec: StudySpec, archive: Path) -> Path:
    """Write ``report.md`` and the curves into ``archive/report``; returns the report's path."""
    files = (REPORT, "*_success.png", "*_intrinsic.png")
    # checked before the runs are read: a report folder that cannot be written would fail
    # only at its first figure (a file in its place is named by report_dir, with its fix)
    if (archive / "report").is_dir() or not present(archive / "report"):
        copy = copy_fix(archive, "python -m simoun_lab.minigrid_study report --archive")
        check_output_dir(archive / "report", None, files, fix=copy)  # made once the runs read well
    records = Records(spec, archive)
    out = report_dir(archive / "report", files)
    total = len(spec.runs())
    lines = [
        "# MiniGrid PPO study: does an intrinsic reward help PPO from pixels?",
        "",
        f"{len(records.finished)} of {total} runs finished; {len(records.used)} used (the seeds "
        f"on which every arm has finished). Scores: the last evaluation of each "
        f"run ({spec.eval_episodes} episodes on env seeds {spec.eval_seed}+), IQM over seeds "
        f"with a 95 % stratified bootstrap CI, n = runs (a task with fewer than {MIN_SEEDS} seeds "
        "shows its runs' values, without an interval, and enters no pooled score or "
        "comparison). For scale (another setting: symbolic "
        "observations, 256 envs), RLeXplore reports PPO's success on DoorKey-8x8 at 1M steps as "
        "0.22 alone, 0.83 with ICM, 0.95 with RE3.",
        "",
        "## Final success rate",
        "",
        score_table(records, "success_rate"),
        "",
        *improvement_lines(records),
        "",
        "## Final extrinsic return",
        "",
        score_table(records, "return_mean"),
        "",
        "## Step-time cost",
        "",
        cost_table(records),
        "",
        "## The intrinsic rewards during training",
        "",
        "Per rollout: mean and std of the intrinsic reward, its correlation with the novelty "
        "1/sqrt(N(s)) of the symbolic state reached (position, direction, carrying, door open), "
        "its mean on still triplets (three equal frames) and on the others, the share of "
        "still triplets, and the number of distinct symbolic states reached since the run began "
        "(the exploration each arm's policy achieved; plain PPO's rows for comparison).",
        "",
        intrinsic_table(records),
        "",
        "## Is it a survival bonus?",
        "",
        "A positive reward that is nearly the same at every step pays the agent for staying in "
        "its episode: in DoorKey, reaching the goal (a reward of at most 1) ends that income. "
        "Per rollout: the share of the reward's second moment its mean carries "
        "(mean^2 / (mean^2 + std^2), 1 for a constant), the discounted value of the mean reward "
        f"to a policy that never ends its episode (mean / (1 - gamma), gamma {spec.ppo.gamma}), "
        "and the share of rollouts whose reward correlated negatively with novelty. "
        "`python -m simoun_lab.minigrid_study probe` measures the correlation without PPO "
        "(`probe/`).",
        "",
        survival_table(records),
        "",
        *[f"![{name}]({name})" for name in plot_training(records, out)],
        "",
        "## Curves",
        "",
        *[f"![{name}]({name})" for name in plot_curves(records, out)],
        "",
    ]
    path = out / REPORT
    atomic_write(path, lambda tmp: tmp.write_text("\n".join(lines)))
    return path
