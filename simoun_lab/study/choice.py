"""The tuning phase's outcome: every setting's score and the one chosen for each recipe, by the
spec's selection rule (:mod:`simoun_lab.study.selection`), saved as ``selection.json``."""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from simoun_agent.config import SetupError, resolve, to_dict
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import show
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import packed_problem, present
from simoun_agent.run.layout import CONFIG_NAME, SUMMARY_NAME
from simoun_agent.run.logger import EVAL_CSV, read_csv
from simoun_lab.study.plan import StudyRun, tuning_runs
from simoun_lab.study.selection import SELECTION_RULES, TIE_RULE, best_setting
from simoun_lab.study.spec import StudySpec
from simoun_lab.sweep import report as sweep_report

SELECTION_FILE = "selection.json"


@dataclass
class Candidate:
    """One grid setting of one recipe, scored on its tuning runs."""

    setting: dict
    score: float
    """mean over tuning tasks of the mean over each task's seeds"""
    runs: dict
    """task -> each seed's score, in seed order"""


@dataclass
class Choice:
    """A recipe's selected setting and every setting it was chosen from."""

    recipe: str
    setting: dict
    score: float
    candidates: list


def read_finished(run_dir: Path) -> tuple[dict[str, Any], dict[str, np.ndarray], list[dict]]:
    """A finished run's ``summary.json``, its ``eval.csv`` curve (raw returns) and rows, checked
    as ``simoun-report`` checks them (:func:`~simoun_lab.sweep.report.check_summary`);
    SetupError naming the run, the file, what is wrong and the fix when one is damaged."""
    try:
        summary = sweep_report.read_json(run_dir / SUMMARY_NAME)
        curve = sweep_report.read_curve(run_dir / EVAL_CSV)
        sweep_report.check_summary(summary, curve)
        rows = read_csv(run_dir / EVAL_CSV)
    except sweep_report.DamagedRun as err:
        problem = str(err)
    except ValueError as err:  # a column the curve does not hold
        problem = f"{EVAL_CSV} holds a value that is not a number ({err})"
    else:
        return summary, curve, rows
    raise damaged_run(run_dir, problem)


def damaged_run(run_dir: Path, problem: str) -> SetupError:
    """The error for a finished run whose files say ``problem``: the two fixes."""
    return SetupError(
        f"the finished run {run_dir}: {problem}. Restore the run's files from a copy (the study "
        f"directory and its archive each keep one), or move the run aside in both (mv {run_dir} "
        f"{run_dir}.damaged) and resume the study: the run is then trained again"
    )


def check_config(spec: StudySpec, study_dir: Path, run: StudyRun) -> None:
    """SetupError when the finished ``run``'s ``config.json`` is missing or damaged (then
    ``simoun-report`` of its phase would leave the run out) or records another run than the
    spec gives it (another recipe, task, seed, setting or budget: its result would be counted
    as this run's)."""
    run_dir = Path(study_dir, run.name)
    path = run_dir / CONFIG_NAME
    if packed := packed_problem(path):
        raise damaged_run(run_dir, packed)
    if not present(path):
        raise damaged_run(run_dir, f"{CONFIG_NAME} is missing, but the run finished")
    try:
        saved = sweep_report.read_run(path).config
    except sweep_report.DamagedRun as err:
        raise damaged_run(run_dir, str(err)) from None
    overrides = spec.overrides(run.recipe, run.task, run.setting or {}, run.seed, run.env_steps)
    overrides.pop("progress")
    wanted = flatten(to_dict(resolve(spec.preset, overrides)))
    keys = ["preset", *overrides] if spec.preset else list(overrides)
    differ = [key for key in keys if show(saved.get(key)) != show(wanted.get(key))]
    if differ:
        values = "; ".join(
            f"{key} is {show(saved.get(key))} where the spec gives {show(wanted.get(key))}"
            for key in differ
        )
        raise damaged_run(run_dir, f"{CONFIG_NAME} records another run than this one: {values}")


def run_score(spec: StudySpec, study_dir: Path, run: StudyRun) -> float:
    """The selection rule's score of one finished tuning run, from its ``eval.csv``."""
    run_dir = Path(study_dir, run.name)
    phase_dir = Path(study_dir, run.phase)
    if not present(phase_dir):  # every run of the phase is gone, not one unfinished
        raise SetupError(
            f"{phase_dir}, the folder of the study's {run.phase} runs, is missing (deleted, or "
            "left out of a copy), so no setting can be selected; restore it from a copy (the "
            f"study directory and its archive each keep one), or resume the study, which trains "
            f"every {run.phase} run again"
        )
    if not present(run_dir / SUMMARY_NAME):  # a damaged summary is named, not taken for none
        raise SetupError(
            f"the tuning run {run.name} has not finished, so no setting can be selected yet; "
            "resume the study to finish it"
        )
    check_config(spec, study_dir, run)
    _, curve, _ = read_finished(run_dir)
    return SELECTION_RULES[spec.selection].score(run.task, curve["env_step"], curve["return_mean"])


def choose(spec: StudySpec, study_dir: Path) -> dict[str, Choice]:
    """Each recipe's setting, chosen from its finished tuning runs."""
    runs = tuning_runs(spec)
    choices = {}
    for recipe in spec.recipes:
        candidates = []
        for setting in spec.settings():
            mine = [r for r in runs if r.recipe == recipe and r.setting == setting]
            by_task = {
                task: [run_score(spec, study_dir, r) for r in mine if r.task == task]
                for task in spec.tuning.tasks
            }
            score = float(np.mean([np.mean(scores) for scores in by_task.values()]))
            candidates.append(Candidate(setting, score, by_task))
        chosen = best_setting([(c.setting, c.score) for c in candidates])
        score = next(c.score for c in candidates if c.setting == chosen)
        choices[recipe] = Choice(recipe, chosen, score, candidates)
    return choices


def save_choices(choices: dict[str, Choice], spec: StudySpec, path: Path) -> None:
    data = {
        "rule": spec.selection,
        "description": SELECTION_RULES[spec.selection].description,
        "ties": TIE_RULE,
        "recipes": {recipe: asdict(choice) for recipe, choice in choices.items()},
    }
    text = json.dumps(data, indent=2) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text))
