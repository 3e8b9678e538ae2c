"""Consistency curiosity on ``gym.make_vec`` with 4 sub-envs, two ways.

- default: ``ConsistencyCuriosityVectorReward`` on the vector env: one ``CuriosityModel`` for all
  sub-envs, one batched feature call per vector step, the autoreset steps skipped;
- ``--per-env``: the single-env ``ConsistencyCuriosityReward`` inside ``make_vec``'s
  ``wrappers=[...]``: each sub-env (each process with ``--async``) has its own model and maxima.

Random actions stand in for a learner; every 100 vector steps it prints the mean extrinsic and
intrinsic reward and the model's losses.

    python examples/curiosity_make_vec.py
    python examples/curiosity_make_vec.py --per-env --async
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np
import torch

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)

CONFIG = CuriosityConfig(batch_size=32, update_every=4, learning_starts=128, seed=0)


def pixels(env: gym.Env, size: int) -> gym.Env:
    return SimounObservation(env, size=size)


def with_own_model(env: gym.Env, size: int) -> gym.Env:
    env = pixels(env, size)
    return ConsistencyCuriosityReward(env, CuriosityModel.for_env(env, CONFIG, device="cpu"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--env", default="simoun/PointReach-v0", help="env with rgb_array renders")
    parser.add_argument("--num-envs", type=int, default=4)
    parser.add_argument("--steps", type=int, default=600, help="vector steps")
    parser.add_argument("--size", type=int, default=32, help="frame side")
    parser.add_argument("--per-env", action="store_true", help="one wrapper and model per sub-env")
    parser.add_argument("--async", dest="asynchronous", action="store_true", help="subprocesses")
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)

    per_env = with_own_model if args.per_env else pixels
    envs = gym.make_vec(
        args.env,
        num_envs=args.num_envs,
        vectorization_mode="async" if args.asynchronous else "sync",
        render_mode="rgb_array",
        wrappers=[lambda env: per_env(env, args.size)],
    )
    model = None
    if not args.per_env:
        model = CuriosityModel.for_env(envs, CONFIG, device="cpu")
        envs = ConsistencyCuriosityVectorReward(envs, model)

    envs.reset(seed=0)
    envs.action_space.seed(0)
    extrinsic, intrinsic = [], []
    for step in range(1, args.steps + 1):
        _, _, _, _, info = envs.step(envs.action_space.sample())
        # Vector infos mark with "_key" which sub-envs reported a key (the per-env wrappers do
        # not run on autoreset steps).
        stepped = info.get("_reward_intrinsic", np.zeros(args.num_envs, dtype=bool))
        extrinsic.extend(info["reward_extrinsic"][stepped] if stepped.any() else [])
        intrinsic.extend(info["reward_intrinsic"][stepped] if stepped.any() else [])
        if step % 100 == 0:
            line = f"step {step:5d}  r_e {np.mean(extrinsic):+.3f}  r_i {np.mean(intrinsic):.3f}"
            if model is not None and model.last_metrics:
                metrics = model.last_metrics
                line += "  " + "  ".join(f"{k} {v:.3g}" for k, v in metrics.items())
            print(line, flush=True)
            extrinsic.clear()
            intrinsic.clear()
    state = envs.call("state_dict") if args.per_env else envs.state_dict()
    print("curiosity state:", state)
    envs.close()


if __name__ == "__main__":
    main()
