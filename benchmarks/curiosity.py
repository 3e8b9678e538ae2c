"""Per-step cost of consistency curiosity with a CuriosityModel, against the env's own step.

Baseline: the same pixel env (``SimounObservation``) stepped with the same random actions in
the same process, without the curiosity wrapper. Measured for one env
(``ConsistencyCuriosityReward``) and for ``gym.make_vec`` with ``--num-envs`` sub-envs
(``ConsistencyCuriosityVectorReward``, per vector step), each with

- features only: the model encodes every new triplet but never trains (inference cost),
- features + training: the default schedule, one Adam step of ``--batch-size`` every
  ``--update-every`` env (or vector) steps, averaged over the steps.

The overhead is ``(wrapped - baseline) / baseline`` of the mean step time. The model's buffer is
filled (untimed) before timing so every timed step follows the steady-state schedule.

    python benchmarks/curiosity.py                          # dm_control cartpole-swingup, 84x84
    python benchmarks/curiosity.py --env CartPole-v1 --size 64
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from collections.abc import Callable

import gymnasium as gym
import numpy as np
import torch

import simoun_wrappers  # noqa: F401  (headless rendering defaults before dm_control loads)
from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)


def make_kwargs(env_id: str, size: int) -> dict:
    """``gym.make`` / ``gym.make_vec`` arguments that make ``env_id`` render ``size`` frames."""
    if env_id.startswith("dm_control/"):
        import shimmy

        gym.register_envs(shimmy)
        render = {"width": size, "height": size, "camera_id": 0}
        return {"render_mode": "rgb_array", "render_kwargs": render}
    return {"render_mode": "rgb_array"}


def make_pixel_env(env_id: str, size: int) -> gym.Env:
    return SimounObservation(gym.make(env_id, **make_kwargs(env_id, size)), size=size)


def time_steps(env, steps: int, vector: bool) -> float:
    """Mean seconds per step over ``steps`` random-action steps (resets excluded for one env)."""
    env.action_space.seed(0)
    total = 0.0
    for _ in range(steps):
        action = env.action_space.sample()
        start = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(action)
        total += time.perf_counter() - start
        if not vector and (terminated or truncated):
            env.reset()
    return total / steps


def fill(env, model: CuriosityModel, vector: bool) -> None:
    """Step (untimed) until the model's buffer holds what its first update needs."""
    env.action_space.seed(1)
    while model.size < model.config.learning_starts:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if not vector and (terminated or truncated):
            env.reset()


def measure(
    build: Callable[[], gym.Env | gym.vector.VectorEnv],
    wrap: Callable,
    config: CuriosityConfig,
    steps: int,
    vector: bool,
) -> dict[str, float]:
    """Baseline, features-only and features+training seconds per step, and the update time."""
    base = build()
    base.reset(seed=0)
    time_steps(base, 10, vector)  # warm caches / renderer
    results = {"baseline": time_steps(base, steps, vector)}
    base.close()
    for name, cfg in (
        ("features", CuriosityConfig(**{**vars(config), "update_every": 10**9})),
        ("training", config),
    ):
        env = build()
        model = CuriosityModel.for_env(env, cfg, device="cpu")
        env = wrap(env, model)
        env.reset(seed=0)
        fill(env, model, vector)
        updates = model.updates
        update_ms = []
        env.action_space.seed(0)
        total = 0.0
        for _ in range(steps):
            action = env.action_space.sample()
            before = model.updates
            start = time.perf_counter()
            _, _, terminated, truncated, _ = env.step(action)
            total += time.perf_counter() - start
            if model.updates > before:
                update_ms.append(model.last_metrics["update_ms"])
            if not vector and (terminated or truncated):
                env.reset()
        results[name] = total / steps
        if name == "training":
            results["updates"] = model.updates - updates
            results["update_ms"] = float(np.mean(update_ms)) if update_ms else float("nan")
        env.close()
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--env", default="dm_control/cartpole-swingup-v0")
    parser.add_argument("--size", type=int, default=84, help="frame side")
    parser.add_argument("--steps", type=int, default=200, help="timed steps per measurement")
    parser.add_argument("--num-envs", type=int, default=4)
    parser.add_argument("--batch-size", type=int, default=CuriosityConfig.batch_size)
    parser.add_argument("--update-every", type=int, default=CuriosityConfig.update_every)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    config = CuriosityConfig(
        batch_size=args.batch_size,
        update_every=args.update_every,
        learning_starts=args.batch_size,
        capacity=max(args.batch_size, 1000),
        seed=0,
    )
    print(
        f"{args.env} {args.size}x{args.size}, CuriosityModel defaults but batch "
        f"{config.batch_size}, update every {config.update_every}; torch {torch.__version__}, "
        f"{args.threads} thread(s), {os.cpu_count()} CPUs ({platform.processor() or 'cpu'})"
    )

    single = measure(
        lambda: make_pixel_env(args.env, args.size),
        ConsistencyCuriosityReward,
        config,
        args.steps,
        vector=False,
    )
    vector = measure(
        lambda: gym.make_vec(
            args.env,
            num_envs=args.num_envs,
            vectorization_mode="sync",
            wrappers=[lambda env: SimounObservation(env, size=args.size)],
            **make_kwargs(args.env, args.size),
        ),
        ConsistencyCuriosityVectorReward,
        config,
        max(args.steps // args.num_envs, 2 * args.update_every),
        vector=True,
    )
    print(f"{'setting':<40}{'ms/step':>10}{'overhead':>11}")
    for label, r in (("1 env", single), (f"vector of {args.num_envs} (per vector step)", vector)):
        print(f"{label + ': env alone':<40}{1000 * r['baseline']:>10.1f}{'':>11}")
        for name in ("features", "training"):
            extra = (r[name] - r["baseline"]) / r["baseline"]
            what = "+ features" if name == "features" else "+ features + training"
            print(f"{'  ' + what:<40}{1000 * r[name]:>10.1f}{extra:>+10.0%} ")
        print(f"{'  one update (batch ' + str(config.batch_size) + ')':<40}{r['update_ms']:>10.1f}")


if __name__ == "__main__":
    main()
