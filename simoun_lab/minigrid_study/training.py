"""A study run set up to train: its envs, PPO learner and callbacks, and its ``config.json``."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from stable_baselines3 import PPO

from simoun_agent.run.atomic import atomic_write
from simoun_lab.minigrid_study.arms import build_arm
from simoun_lab.minigrid_study.envs import SB3VecEnv, pixel_vector_env
from simoun_lab.minigrid_study.spec import Run, StudySpec
from simoun_lab.minigrid_study.study_log import StudyLog
from simoun_lab.minigrid_study.timing import RolloutClock, TimedVecEnv

__all__ = ["CONFIG", "Training", "set_up", "write_json"]

CONFIG = "config.json"
"""a run's configuration: its name, the code's commit, its seeds and the study spec"""


def write_json(path: Path, value: Any) -> None:
    """Write ``value`` to ``path`` as indented JSON, atomically (the study's one JSON writer)."""
    atomic_write(path, lambda tmp: tmp.write_text(json.dumps(value, indent=2) + "\n"))


@dataclass
class Training:
    """A run set up to train: its envs, PPO learner and callbacks."""

    envs: Any
    """the training vector env, with the arm's intrinsic-reward wrapper (if any)"""
    timed: TimedVecEnv
    """the SB3 view of ``envs`` PPO steps, timing its steps"""
    eval_envs: SB3VecEnv
    """one sub-env per evaluation episode"""
    ppo: PPO
    clock: RolloutClock
    log: StudyLog
    env_seed: int
    """seeds the training envs on a fresh start"""

    def close(self) -> None:
        self.timed.close()
        self.eval_envs.close()


def set_up(spec: StudySpec, run: Run, run_dir: Path, commit: str | None = None) -> Training:
    """Build ``run``'s envs and learner and write its ``config.json``. One
    ``SeedSequence(seed)`` spawns the training envs', PPO's and the intrinsic model's seeds, so
    two seeds share no stream; the evaluation episodes use the spec's fixed env seeds.
    ``commit`` (the code's git commit) is recorded in ``config.json``."""
    run_dir.mkdir(parents=True, exist_ok=True)
    torch.set_num_threads(1)
    env_seed, ppo_seed, model_seed = (
        int(s.generate_state(1)[0] % 2**31) for s in np.random.SeedSequence(run.seed).spawn(3)
    )
    device = torch.device(spec.device)
    seeds = {"env": env_seed, "ppo": ppo_seed, "model": model_seed}
    config = {"run": run.name, "commit": commit, "seeds": seeds, "spec": spec.to_json()}
    write_json(run_dir / CONFIG, config)
    envs = build_arm(
        run.arm, pixel_vector_env(run.task.env_id, spec.ppo.n_envs), model_seed, device
    )
    timed = TimedVecEnv(SB3VecEnv(envs))
    eval_envs = SB3VecEnv(pixel_vector_env(run.task.env_id, spec.eval_episodes))
    ppo = PPO("CnnPolicy", timed, seed=ppo_seed, device=device, **spec.ppo.kwargs())
    clock = RolloutClock(timed)
    log = StudyLog(spec, run, eval_envs, clock)
    return Training(envs, timed, eval_envs, ppo, clock, log, env_seed)
