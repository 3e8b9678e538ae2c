"""Per-step cost of consistency curiosity with a CuriosityModel, against the env's own step.

Baseline: the same pixel env (``SimounObservation``) stepped with random actions in the same
process, without the curiosity wrapper. Measured for one env (``ConsistencyCuriosityReward``)
and for ``gym.make_vec`` with ``--num-envs`` sub-envs (``ConsistencyCuriosityVectorReward``, per
vector step), in these settings:

- features: the model encodes every new triplet but never trains (inference cost);
- training, thread: the default schedule, one Adam step of ``--batch-size`` every
  ``--update-every`` env (or vector) steps, run in the model's background thread;
- training, inline: the same steps on the env's thread (``CuriosityConfig(background=False)``).

The settings run side by side, interleaved: each round times a block of ``--block`` steps of
every setting in turn, so a change of load on a shared machine hits them all alike. A block of
a training setting ends by waiting for its update in flight (counted: nothing overlaps the next
block). The overhead is the median over rounds of ``block time / baseline block time - 1``. The
models' buffers are filled (untimed) before timing, so every timed step follows the
steady-state schedule.

    python benchmarks/curiosity.py                          # dm_control cartpole-swingup, 84x84
    python benchmarks/curiosity.py --num-filters 32 --encoder-size 0   # the agent-sized encoder
    python benchmarks/curiosity.py --env CartPole-v1 --size 64
"""

from __future__ import annotations

import argparse
import dataclasses
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


class Setting:
    """One env (bare or wrapped) with its own action stream, stepped a block at a time."""

    def __init__(self, env, model: CuriosityModel | None, vector: bool, seed: int) -> None:
        self.env, self.model, self.vector = env, model, vector
        self.env.reset(seed=seed)
        self.env.action_space.seed(seed)
        self.blocks: list[float] = []
        self.update_ms: list[float] = []
        self.wait_ms: list[float] = []

    def step(self) -> float:
        """One step; returns the seconds spent resetting after it (not counted)."""
        before = self.model.updates if self.model else 0
        _, _, terminated, truncated, _ = self.env.step(self.env.action_space.sample())
        if self.model is not None and self.model.updates > before:
            self.update_ms.append(self.model.last_metrics["update_ms"])
            self.wait_ms.append(self.model.last_metrics["wait_ms"])
        if not self.vector and (terminated or truncated):
            start = time.perf_counter()
            self.env.reset()
            return time.perf_counter() - start
        return 0.0

    def fill(self) -> None:
        """Step (untimed) until the model's buffer holds what its first update needs."""
        while self.model is not None and self.model.size < self.model.config.learning_starts:
            self.step()
        self.update_ms.clear()
        self.wait_ms.clear()

    def time_block(self, steps: int) -> None:
        start = time.perf_counter()
        untimed = sum(self.step() for _ in range(steps))
        if self.model is not None:
            self.model.wait()
        self.blocks.append((time.perf_counter() - start - untimed) / steps)


def measure(
    build: Callable[[], gym.Env | gym.vector.VectorEnv],
    wrap: Callable,
    config: CuriosityConfig,
    block: int,
    rounds: int,
    vector: bool,
) -> dict[str, Setting]:
    """Every setting's per-step seconds per round, measured interleaved."""
    configs = {
        "features": dataclasses.replace(config, update_every=10**9),
        "training, thread": dataclasses.replace(config, background=True),
        "training, inline": dataclasses.replace(config, background=False),
    }
    settings = {"env alone": Setting(build(), None, vector, seed=0)}
    for name, cfg in configs.items():
        env = build()
        model = CuriosityModel.for_env(env, cfg, device="cpu")
        settings[name] = Setting(wrap(env, model), model, vector, seed=0)
    for setting in settings.values():
        setting.fill()
        setting.time_block(max(2, block // 4))  # warm caches, renderer, the update thread
        setting.blocks.clear()
    for _ in range(rounds):
        for setting in settings.values():
            setting.time_block(block)
    for setting in settings.values():
        setting.env.close()
    return settings


def report(label: str, settings: dict[str, Setting]) -> None:
    base = np.array(settings["env alone"].blocks)
    print(f"{label + ': env alone':<40}{1000 * np.median(base):>8.1f}")
    for name, setting in settings.items():
        if name == "env alone":
            continue
        overhead = np.median(np.array(setting.blocks) / base - 1.0)
        line = f"  + {name:<36}{1000 * np.median(setting.blocks):>8.1f}{overhead:>+10.0%}"
        if setting.update_ms:
            line += (
                f"   update {np.median(setting.update_ms):.0f} ms, "
                f"wait {np.median(setting.wait_ms):.1f} ms ({len(setting.update_ms)} updates)"
            )
        print(line)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--env", default="dm_control/cartpole-swingup-v0")
    parser.add_argument("--size", type=int, default=84, help="frame side")
    parser.add_argument("--block", type=int, default=32, help="steps per timed block")
    parser.add_argument("--rounds", type=int, default=6, help="timed blocks per setting")
    parser.add_argument("--num-envs", type=int, default=4)
    parser.add_argument("--batch-size", type=int, default=CuriosityConfig.batch_size)
    parser.add_argument("--update-every", type=int, default=CuriosityConfig.update_every)
    parser.add_argument("--num-filters", type=int, default=CuriosityConfig.num_filters)
    parser.add_argument(
        "--encoder-size",
        type=int,
        default=CuriosityConfig.encoder_size,
        help="CuriosityConfig.encoder_size; 0 for None (full-size frames)",
    )
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    config = CuriosityConfig(
        batch_size=args.batch_size,
        update_every=args.update_every,
        num_filters=args.num_filters,
        encoder_size=args.encoder_size or None,
        learning_starts=args.batch_size,
        capacity=max(args.batch_size, 1000),
        seed=0,
    )
    print(
        f"{args.env} {args.size}x{args.size}; CuriosityModel {config.num_filters} filters, "
        f"encoder_size {config.encoder_size}, batch {config.batch_size}, update every "
        f"{config.update_every}; {args.rounds} rounds of {args.block} steps; torch "
        f"{torch.__version__}, {args.threads} thread(s), {os.cpu_count()} CPUs "
        f"({platform.processor() or 'cpu'}), load {os.getloadavg()[0]:.1f}"
    )
    single = measure(
        lambda: make_pixel_env(args.env, args.size),
        ConsistencyCuriosityReward,
        config,
        args.block,
        args.rounds,
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
        args.block,
        args.rounds,
        vector=True,
    )
    print(f"{'setting (median over rounds)':<40}{'ms/step':>8}{'overhead':>10}")
    report("1 env", single)
    report(f"vector of {args.num_envs}, per step", vector)


if __name__ == "__main__":
    main()
