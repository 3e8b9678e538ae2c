"""The tuning phase's selection rule, fixed before any tuning run: for each arm entry (consistency,
rnd, ...), the setting with the highest area under its success curve, averaged over the tuning
seeds.

The area of one run is the trapezoid of the evaluation success rate over env steps, divided by
the run's budget, so it lies in [0, 1] and rewards learning early as well as learning at all.
A setting is eligible only when every tuning seed of every task has finished for it; ties go to
the smaller ``scale``, then to the name. Entries with a single setting (plain PPO) are listed
for reference.
"""

from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from simoun_agent import table
from simoun_agent.config import SetupError
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import present
from simoun_agent.run.rundir import check_output_dir, check_output_files, copy_fix
from simoun_lab.minigrid_study.arms import parse_arm
from simoun_lab.minigrid_study.report import check_run_folder, damaged, read_eval, read_finished
from simoun_lab.minigrid_study.run import EVAL_CSV, SUMMARY
from simoun_lab.minigrid_study.spec import Run, StudySpec

__all__ = ["SELECTION", "run_auc", "select", "write_selection"]

SELECTION = "selection"
"""``selection.json`` and ``selection.md`` in the tuning archive"""


def run_auc(rows: list[dict[str, float]], steps: int) -> float:
    """Trapezoid of ``success_rate`` over ``env_step``, divided by ``steps``."""
    x = np.array([row["env_step"] for row in rows], dtype=np.float64)
    y = np.array([row["success_rate"] for row in rows], dtype=np.float64)
    if len(x) < 2 or not np.all(np.isfinite(y)):
        raise ValueError(f"an eval.csv needs 2+ finite evaluations for an area, got {y.tolist()}")
    return float(np.trapezoid(y, x) / steps)


def finished_auc(spec: StudySpec, archive: Path, run: Run) -> float:
    """The area of a finished run, its files checked as the report checks them (SetupError
    naming a damaged one)."""
    read_finished(spec, archive, run)
    path = archive / run.name / EVAL_CSV
    rows = read_eval(path)
    if len(rows) < 2:
        raise damaged(
            path, f"it holds {len(rows)} evaluation; the area under a success curve needs 2 or more"
        )
    return run_auc(rows, run.task.steps)


def select(spec: StudySpec, archive: Path) -> dict[str, Any]:
    """Per arm: its area on each finished run and their mean; per entry: the selected setting
    (None while a setting of that entry is still missing runs)."""
    arms: dict[str, dict[str, Any]] = {}
    for run in spec.runs():  # a run's directory replaced by a file is named, not left out
        check_run_folder(archive, run)
    for arm in spec.arms:
        runs = [r for r in spec.runs() if r.arm == arm]
        areas = {
            r.name: finished_auc(spec, archive, r)
            for r in runs
            if present(archive / r.name / SUMMARY)  # a damaged summary is named, not skipped
        }
        arms[arm] = {
            "areas": areas,
            "mean_area": float(np.mean(list(areas.values()))) if areas else None,
            "complete": len(areas) == len(runs),
        }
    by_entry: dict[str, list[str]] = defaultdict(list)
    for arm in spec.arms:
        by_entry[parse_arm(arm)[0]].append(arm)
    selected: dict[str, str | None] = {}
    for entry, names in by_entry.items():
        if not all(arms[name]["complete"] for name in names):
            selected[entry] = None
            continue

        def rank(name: str) -> tuple[float, float, str]:
            scale = parse_arm(name)[1].get("scale", 0.0)
            return (-arms[name]["mean_area"], scale, name)

        selected[entry] = min(names, key=rank)
    return {"arms": arms, "selected": selected}


def write_selection(spec: StudySpec, archive: Path) -> Path:
    """Write ``selection.json`` and ``selection.md`` into ``archive``; return the Markdown's
    path."""
    copy = copy_fix(archive, "python -m simoun_lab.minigrid_study select --archive")
    check_output_dir(archive, None, fix=copy)  # before the runs are read, as the report does
    check_output_files([archive / f"{SELECTION}.json", archive / f"{SELECTION}.md"])
    result = select(spec, archive)
    if not any(record["areas"] for record in result["arms"].values()):
        raise SetupError(
            f"--archive {archive} holds no finished run of its spec: nothing to select from yet "
            f"(its {SELECTION}.md and {SELECTION}.json are left as they are); train the runs "
            f"with: python -m simoun_lab.minigrid_study run --archive {archive}"
        )
    lines = [
        "# Tuning: the selected setting of each arm",
        "",
        "Rule (fixed before the runs): the highest mean area under the success curve (trapezoid",
        "over env steps / budget) over the tuning seeds; ties to the smaller scale. An entry is",
        "selected only when all its settings have finished on every tuning seed.",
        "",
    ]
    rows = []
    for arm, record in result["arms"].items():
        mean = "-" if record["mean_area"] is None else f"{record['mean_area']:.3f}"
        areas = ", ".join(f"{a:.3f}" for a in record["areas"].values()) or "-"
        done = f"{len(record['areas'])} of {len([r for r in spec.runs() if r.arm == arm])}"
        rows.append([arm, mean, areas, done])
    lines += [table.markdown_table(["arm", "mean area", "areas per run", "finished"], rows)]
    lines += ["", "Selected:", ""]
    for entry, name in result["selected"].items():
        lines.append(f"- {entry}: {name or 'not yet (settings still running)'}")
    text = json.dumps(result, indent=2)
    atomic_write(archive / f"{SELECTION}.json", lambda tmp: tmp.write_text(text))
    path = archive / f"{SELECTION}.md"
    atomic_write(path, lambda tmp: tmp.write_text("\n".join(lines) + "\n"))
    return path
