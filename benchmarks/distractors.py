"""Cost of the distractors against the plain env, measured in one run on the same env and seed.

Baseline: ``SimounObservation(ActionRepeat(env, 8), size=84)`` on dm_control cartpole-swingup
rendering 84x84 from camera 0, the stack ``simoun-train`` builds. Contenders: the same stack
with ``ColorShift`` or ``MovingBackground`` (procedural, ``hard``) under it. Printed: the
median seconds per agent step and per reset of each, and the ratio to the baseline.
``MovingBackground`` renders each frame twice (colour and segmentation), so expect about 2x on
render-bound machines; ``ColorShift`` costs only at reset (MuJoCo rebuilds two textures).

Blocks of the contenders are interleaved, so a noisy shared machine slows all alike. Run:

    python benchmarks/distractors.py [--repeats 5] [--steps 20]
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import gymnasium as gym
import numpy as np

from simoun_wrappers import ActionRepeat, ColorShift, MovingBackground, SimounObservation

SIZE = 84


def make(distractor: Callable[[gym.Env], gym.Env] | None) -> gym.Env:
    import shimmy  # here, not at the top: simoun_wrappers must set MUJOCO_GL=egl first

    gym.register_envs(shimmy)
    render = {"height": SIZE, "width": SIZE, "camera_id": 0}
    env = gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array", render_kwargs=render)
    if distractor is not None:
        env = distractor(env)
    return SimounObservation(ActionRepeat(env, 8), size=SIZE)


def block(env: gym.Env, steps: int, seed: int) -> tuple[float, float]:
    """Seconds of one reset and mean seconds per step over ``steps`` steps."""
    start = time.perf_counter()
    env.reset(seed=seed)
    reset = time.perf_counter() - start
    action = np.zeros(env.action_space.shape, np.float32)
    start = time.perf_counter()
    for _ in range(steps):
        env.step(action)
    return reset, (time.perf_counter() - start) / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="interleaved blocks per contender")
    parser.add_argument("--steps", type=int, default=20, help="agent steps per block")
    args = parser.parse_args()
    contenders = {
        "plain (baseline)": make(None),
        "ColorShift(hard)": make(lambda env: ColorShift(env, "hard", seed=0)),
        "MovingBackground(hard)": make(lambda env: MovingBackground(env, "hard", seed=0)),
    }
    times: dict[str, list[tuple[float, float]]] = {name: [] for name in contenders}
    for env in contenders.values():
        block(env, 2, seed=0)  # warm-up: GL contexts and first textures
    for repeat in range(args.repeats):
        for name, env in contenders.items():
            times[name].append(block(env, args.steps, seed=repeat))
    base_reset = statistics.median(t[0] for t in times["plain (baseline)"])
    base_step = statistics.median(t[1] for t in times["plain (baseline)"])
    print(f"{'stack':24} {'ms/step':>8} {'x plain':>8} {'ms/reset':>9} {'x plain':>8}")
    for name, values in times.items():
        reset = statistics.median(t[0] for t in values)
        step = statistics.median(t[1] for t in values)
        print(
            f"{name:24} {step * 1e3:8.2f} {step / base_step:8.2f} "
            f"{reset * 1e3:9.1f} {reset / base_reset:8.2f}"
        )


if __name__ == "__main__":
    main()
