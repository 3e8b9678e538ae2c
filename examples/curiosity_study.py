"""Shared parts of the Stable-Baselines3 curiosity examples (``sb3_ppo_curiosity.py``,
``sb3_sac_curiosity.py``): the pixel env, the optional curiosity wrapper, and a CSV of episode
returns, so runs with and without curiosity can be compared later.

Each run writes one CSV (rewritten atomically after every rollout) with a row per finished
episode: ``algo, env, seed, curiosity, timestep, episode, return_extrinsic, return_intrinsic,
length, wall_time_s``. ``return_extrinsic`` is the env's own return (SB3's ``Monitor`` sits below
the curiosity wrapper), so both arms of a comparison are scored on the task's reward alone.
"""

from __future__ import annotations

import argparse
import csv
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import VecEnv

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_agent.run.atomic import atomic_write
from simoun_wrappers import ActionRepeat, SimounObservation
from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward

COLUMNS = [
    "algo",
    "env",
    "seed",
    "curiosity",
    "timestep",
    "episode",
    "return_extrinsic",
    "return_intrinsic",
    "length",
    "wall_time_s",
]


def add_arguments(parser: argparse.ArgumentParser, steps: int) -> None:
    """The flags both examples share."""
    parser.add_argument(
        "--env",
        default="dm_control/ball_in_cup-catch-v0",
        help="any env with rgb_array renders; dm_control ids render at --size through shimmy",
    )
    parser.add_argument("--steps", type=int, default=steps, help="total agent steps")
    parser.add_argument("--size", type=int, default=48, help="frame side (SB3's CNN needs >= 36)")
    parser.add_argument(
        "--action-repeat", type=int, default=4, help="env steps per agent step (ActionRepeat)"
    )
    parser.add_argument("--no-curiosity", action="store_true", help="the baseline arm")
    parser.add_argument("--scale", type=float, default=0.2, help="C of Eq. 13")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--device", default="cpu", help="torch device of the agent and the model")
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    parser.add_argument("--csv", type=Path, default=None, help="episode returns (default: named)")


def make_env(env_id: str, size: int, action_repeat: int) -> gym.Env:
    """The pixel env: rendered at ``size``, actions repeated, stacked and folded for SB3."""
    if env_id.startswith("dm_control/"):
        import shimmy  # after simoun_wrappers, which picks headless rendering for dm_control

        gym.register_envs(shimmy)
        render = {"width": size, "height": size, "camera_id": 0}
        env = gym.make(env_id, render_mode="rgb_array", render_kwargs=render)
    else:
        env = gym.make(env_id, render_mode="rgb_array")
    if action_repeat > 1:
        env = ActionRepeat(env, action_repeat)
    return SimounObservation(env, size=size, fold_frames=True)


def make_envs(args: argparse.Namespace, n_envs: int) -> tuple[VecEnv, CuriosityModel | None]:
    """``n_envs`` sub-envs (DummyVecEnv, each in SB3's ``Monitor``), with one shared
    ``CuriosityModel`` unless ``--no-curiosity``."""
    torch.manual_seed(args.seed)
    torch.set_num_threads(args.threads)

    def build() -> gym.Env:
        return make_env(args.env, args.size, args.action_repeat)

    model = None
    wrapper_class, wrapper_kwargs = None, None
    if not args.no_curiosity:
        probe = build()
        model = CuriosityModel.for_env(probe, CuriosityConfig(seed=args.seed), device=args.device)
        probe.close()
        wrapper_class = ConsistencyCuriosityReward
        wrapper_kwargs = {"features": model, "scale": args.scale}
    envs = make_vec_env(
        build,
        n_envs=n_envs,
        seed=args.seed,
        wrapper_class=wrapper_class,
        wrapper_kwargs=wrapper_kwargs,
    )
    return envs, model


def csv_path(args: argparse.Namespace, algo: str) -> Path:
    if args.csv is not None:
        return args.csv
    task = args.env.split("/")[-1].removesuffix("-v0")
    arm = "baseline" if args.no_curiosity else "curiosity"
    return Path(f"{algo}_{task}_{arm}_seed{args.seed}.csv")


class EpisodeLog(BaseCallback):
    """Collect a row per finished episode, write the CSV after every rollout and at the end, and
    log the curiosity model's last losses under ``curiosity/``."""

    def __init__(
        self, path: Path, algo: str, args: argparse.Namespace, curiosity: CuriosityModel | None
    ) -> None:
        super().__init__()
        self.path, self.curiosity = path, curiosity
        self.fixed = {
            "algo": algo,
            "env": args.env,
            "seed": args.seed,
            "curiosity": not args.no_curiosity,
        }
        self.rows: list[dict[str, Any]] = []
        self.intrinsic: np.ndarray | None = None
        self.start = time.perf_counter()

    def _on_step(self) -> bool:
        infos = self.locals["infos"]
        if self.intrinsic is None:
            self.intrinsic = np.zeros(len(infos))
        for i, info in enumerate(infos):
            self.intrinsic[i] += info.get("reward_intrinsic", 0.0)
            if "episode" in info:
                self.rows.append(
                    {
                        **self.fixed,
                        "timestep": self.num_timesteps,
                        "episode": len(self.rows),
                        "return_extrinsic": float(info["episode"]["r"]),
                        "return_intrinsic": float(self.intrinsic[i]),
                        "length": int(info["episode"]["l"]),
                        "wall_time_s": round(time.perf_counter() - self.start, 3),
                    }
                )
                self.intrinsic[i] = 0.0
        return True

    def _on_rollout_end(self) -> None:
        if self.curiosity is not None:
            for name, value in self.curiosity.last_metrics.items():
                self.logger.record(f"curiosity/{name}", value)
        self.write()

    def _on_training_end(self) -> None:
        self.write()

    def write(self) -> None:
        def dump(tmp: Path) -> None:
            with tmp.open("w", newline="") as file:
                writer = csv.DictWriter(file, fieldnames=COLUMNS)
                writer.writeheader()
                writer.writerows(self.rows)

        self.path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(self.path, dump)


def learn_and_log(
    agent: BaseAlgorithm,
    algo: str,
    args: argparse.Namespace,
    curiosity: CuriosityModel | None,
    **learn_kwargs: Any,
) -> None:
    """Train ``agent`` for ``args.steps`` with an :class:`EpisodeLog`, close its envs (which stops
    the curiosity model's update thread) and say where the CSV went."""
    log = EpisodeLog(csv_path(args, algo), algo, args, curiosity)
    agent.learn(total_timesteps=args.steps, callback=log, **learn_kwargs)
    agent.get_env().close()
    print(f"{len(log.rows)} episodes -> {log.path}")
    if curiosity is not None:
        print(f"curiosity model: {curiosity.updates} updates, last {curiosity.last_metrics}")
