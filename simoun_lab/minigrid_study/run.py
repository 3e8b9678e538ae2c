"""One run of the study: SB3 PPO on MiniGrid pixels with one arm's reward, evaluated on fixed
held-out env seeds, its records written to a run directory (``summary.json`` last).

Files: ``eval.csv`` (per evaluation: ``env_step``, ``wall_s``, ``success_rate``,
``return_mean`` of the env's own reward), ``train.csv`` (per PPO rollout: time in env stepping
and in the update, training episodes, and the intrinsic reward's mean, std and correlation with
state novelty), ``config.json`` and ``summary.json``.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from stable_baselines3.common.callbacks import CallbackList

from simoun_agent.run.atomic import atomic_write
from simoun_lab.engine.trial import SUMMARY
from simoun_lab.minigrid_study.checkpoint import CHECKPOINT, RunCheckpoint, restore
from simoun_lab.minigrid_study.spec import Run, StudySpec
from simoun_lab.minigrid_study.training import CONFIG, set_up, write_json

__all__ = ["EVAL_CSV", "RUN_FILES", "SUMMARY", "TRAIN_CSV", "train_run"]

EVAL_CSV, TRAIN_CSV = "eval.csv", "train.csv"
RUN_FILES = (CONFIG, EVAL_CSV, TRAIN_CSV, SUMMARY)
"""a run's files, ``summary.json`` last: its presence marks a finished run"""


def write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    fields = list(dict.fromkeys(key for row in rows for key in row))

    def write(tmp: Path) -> None:
        with tmp.open("w", newline="") as file:
            writer = csv.DictWriter(file, fieldnames=fields, restval="")
            writer.writeheader()
            writer.writerows(rows)

    atomic_write(path, write)


def train_run(
    spec: StudySpec,
    run: Run,
    run_dir: Path,
    commit: str | None = None,
    on_checkpoint: Callable[[Path], None] | None = None,
) -> dict[str, Any]:
    """Train and evaluate ``run`` (set up by :func:`set_up`), writing its files into
    ``run_dir``; returns the summary. A ``checkpoint.pt`` left in ``run_dir`` by an ended
    process is gone on from (:mod:`~simoun_lab.minigrid_study.checkpoint`); each new one is
    passed to ``on_checkpoint``; the finished run removes it."""
    training = set_up(spec, run, run_dir, commit)
    ppo, clock, log = training.ppo, training.clock, training.log
    checkpoint_path = run_dir / CHECKPOINT
    part = {"started_utc": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    if checkpoint_path.is_file():
        part["env_step_start"] = restore(checkpoint_path, training)
    else:
        training.timed.seed(training.env_seed)
        part["env_step_start"] = 0
    log.parts.append(part)
    checkpoint = RunCheckpoint(checkpoint_path, training, on_checkpoint)
    try:
        ppo.learn(
            run.task.steps - ppo.num_timesteps,
            callback=CallbackList([clock, log, checkpoint]),
            reset_num_timesteps=False,
        )
        if log.eval_rows[-1]["env_step"] < ppo.num_timesteps:
            log.evaluate_now()  # after the last update
    finally:
        training.close()
    training_wall = log.training_wall_s()
    rows = [
        {**rollout, **times} for rollout, times in zip(log.rollout_rows, clock.rows, strict=True)
    ]
    write_csv(run_dir / EVAL_CSV, log.eval_rows)
    write_csv(run_dir / TRAIN_CSV, rows)
    final = log.eval_rows[-1]
    summary = {
        "run": run.name,
        "env_steps": ppo.num_timesteps,
        "wall_s": training_wall + log.eval_s,
        "training_wall_s": training_wall,
        "steps_per_s": ppo.num_timesteps / training_wall,
        "env_s": sum(r["env_s"] for r in clock.rows),
        "update_s": sum(r.get("update_s", 0.0) for r in clock.rows),
        "final_success_rate": final["success_rate"],
        "final_return_mean": final["return_mean"],
        "parts": log.parts,
    }
    write_json(run_dir / SUMMARY, summary)
    checkpoint_path.unlink(missing_ok=True)
    return summary
