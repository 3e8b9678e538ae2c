"""Wrapper costs against named baselines, measured in one run on the same env and seed.

1. FrameTriplet vs gymnasium's FrameStackObservation(3, padding_type="reset"): per-step time
   of the stacking itself on 84x84 RGB frames recorded from dm_control cartpole-swingup, and
   per-step time on the live env (target: ratio <= 1.0).
2. SimounObservation vs a raw dm_control cartpole-swingup step with its 84x84 render: the time
   spent outside the env's step() and render(), as a fraction of them (target: < 5%).
3. random_conv (one grouped convolution) vs a per-sample Python loop drawing the same kernels,
   at batch 128 of 84x84 RGB triplets (target: >= 10x). On a CPU each sample's convolution
   costs far more than the loop's Python overhead, so expect a small gain there; the grouped
   form pays off where per-call launch costs dominate, i.e. on a GPU (``--device cuda``).

Every figure is a median over repeated blocks, with blocks of the two contenders interleaved,
so a noisy shared machine slows both alike. Run:

    python benchmarks/wrappers.py [--repeats 7] [--threads 1] [--device cpu]
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import gymnasium as gym
import numpy as np
import torch
import torch.nn.functional as F
from gymnasium.wrappers import AddRenderObservation, FrameStackObservation

from simoun_wrappers import FrameTriplet, SimounObservation
from simoun_wrappers.augment import random_conv

SEED = 0
SIZE = 84


def make_cartpole() -> gym.Env:
    """dm_control cartpole-swingup rendering 84x84 RGB from camera 0."""
    import shimmy  # here, not at the top: simoun_wrappers must set MUJOCO_GL=egl first

    gym.register_envs(shimmy)
    render_kwargs = {"width": SIZE, "height": SIZE, "camera_id": 0}
    return gym.make(
        "dm_control/cartpole-swingup-v0", render_mode="rgb_array", render_kwargs=render_kwargs
    )


class RecordedFrames(gym.Env):
    """Replays frames recorded from a real env, so that only the wrapper's work is timed."""

    def __init__(self, frames: np.ndarray) -> None:
        self.frames = frames
        self.observation_space = gym.spaces.Box(0, 255, frames.shape[1:], np.uint8)
        self.action_space = gym.spaces.Discrete(1)
        self.t = 0

    def reset(self, *, seed=None, options=None):
        self.t = 0
        return self.frames[0], {}

    def step(self, action):
        self.t += 1
        return self.frames[self.t % len(self.frames)], 0.0, False, False, {}


class StepTimer(gym.Wrapper):
    """Accumulates the seconds spent in the wrapped env's step() and render()."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.seconds = 0.0

    def step(self, action):
        start = time.perf_counter()
        out = self.env.step(action)
        self.seconds += time.perf_counter() - start
        return out

    def render(self):
        start = time.perf_counter()
        out = self.env.render()
        self.seconds += time.perf_counter() - start
        return out


def per_step(env: gym.Env, actions: np.ndarray) -> float:
    """Median-ready sample: mean seconds per step over one episode prefix from the same seed."""
    env.reset(seed=SEED)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    return (time.perf_counter() - start) / len(actions)


def interleaved(contenders: dict[str, Callable[[], float]], repeats: int) -> dict[str, float]:
    samples = {name: [] for name in contenders}
    for _ in range(repeats):
        for name, run in contenders.items():
            samples[name].append(run())
    return {name: statistics.median(values) for name, values in samples.items()}


def bench_frame_triplet(repeats: int, steps: int) -> None:
    env = make_cartpole()
    actions = np.random.default_rng(SEED).uniform(-1, 1, size=(steps, 1)).astype(np.float32)
    pixels = AddRenderObservation(env)
    first, _ = pixels.reset(seed=SEED)
    recorded = np.stack([first] + [pixels.step(a)[0] for a in actions[: steps // 4]])
    replay_actions = np.zeros(steps * 20, dtype=np.int64)
    t = interleaved(
        {
            "ours": lambda: per_step(FrameTriplet(RecordedFrames(recorded), 3), replay_actions),
            "gym": lambda: per_step(
                FrameStackObservation(RecordedFrames(recorded), 3, padding_type="reset"),
                replay_actions,
            ),
        },
        repeats,
    )
    print(
        f"FrameTriplet stacking, 84x84x3 frames:  {t['ours'] * 1e6:7.1f} us/step   "
        f"FrameStackObservation(3): {t['gym'] * 1e6:7.1f} us/step   "
        f"ratio {t['ours'] / t['gym']:.2f}x (target <= 1.0x)"
    )
    live = interleaved(
        {
            "ours": lambda: per_step(FrameTriplet(pixels, 3), actions),
            "gym": lambda: per_step(
                FrameStackObservation(pixels, 3, padding_type="reset"), actions
            ),
        },
        repeats,
    )
    print(
        f"FrameTriplet on the live env (step+render): {live['ours'] * 1e3:6.2f} ms/step   "
        f"FrameStackObservation(3): {live['gym'] * 1e3:6.2f} ms/step   "
        f"ratio {live['ours'] / live['gym']:.3f}x (the render dominates both)"
    )


def bench_simoun_observation(repeats: int, steps: int) -> None:
    actions = np.random.default_rng(SEED).uniform(-1, 1, size=(steps, 1)).astype(np.float32)
    raw = make_cartpole()
    timer = StepTimer(make_cartpole())
    wrapped = SimounObservation(timer, size=SIZE)

    def raw_step_and_render() -> float:
        raw.reset(seed=SEED)
        start = time.perf_counter()
        for action in actions:
            raw.step(action)
            raw.render()
        return (time.perf_counter() - start) / len(actions)

    def overhead_fraction() -> float:
        wrapped.reset(seed=SEED)
        timer.seconds = 0.0
        start = time.perf_counter()
        for action in actions:
            wrapped.step(action)
        total = time.perf_counter() - start
        return (total - timer.seconds) / timer.seconds

    def wrapped_step() -> float:
        return per_step(wrapped, actions)

    t = interleaved(
        {"raw": raw_step_and_render, "wrapped": wrapped_step, "overhead": overhead_fraction},
        repeats,
    )
    print(
        f"SimounObservation(size=84) on dm_control cartpole: {t['wrapped'] * 1e3:6.2f} ms/step   "
        f"raw step + 84x84 render: {t['raw'] * 1e3:6.2f} ms/step"
    )
    print(
        f"  time outside the env's step()+render(): {t['overhead'] * 100:.2f}% of them "
        f"(target < 5%); end-to-end ratio {t['wrapped'] / t['raw']:.3f}x (two env "
        f"instances: their step-time noise on a shared machine exceeds the overhead)"
    )


def loop_random_conv(batch: torch.Tensor, generator: torch.Generator) -> torch.Tensor:
    """Baseline: one kernel and one convolution per sample, as netrand / DMC-GB do."""
    b, c = batch.shape[0], batch.shape[2]
    std = (2.0 / (2 * c * 9)) ** 0.5
    outs = []
    for i in range(b):
        weight = torch.randn((c, c, 3, 3), generator=generator, device=generator.device) * std
        outs.append(F.conv2d(batch[i], weight.to(batch.device), padding=1))
    return torch.stack(outs)


def bench_random_conv(repeats: int, batch_size: int, device: str) -> None:
    generator = torch.Generator(device=device).manual_seed(SEED)
    batch = torch.rand((batch_size, 3, 3, SIZE, SIZE), generator=generator, device=device)

    def timed(fn: Callable[[], torch.Tensor], calls: int = 5) -> float:
        fn()
        if device.startswith("cuda"):
            torch.cuda.synchronize()
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        if device.startswith("cuda"):
            torch.cuda.synchronize()
        return (time.perf_counter() - start) / calls

    t = interleaved(
        {
            "grouped": lambda: timed(lambda: random_conv(batch, generator=generator)),
            "loop": lambda: timed(lambda: loop_random_conv(batch, generator)),
        },
        repeats,
    )
    print(
        f"random_conv, batch {batch_size} of 3x3x84x84 on {device}: "
        f"{batch_size / t['grouped']:9.0f} samples/s   per-sample loop: "
        f"{batch_size / t['loop']:9.0f} samples/s   speed-up {t['loop'] / t['grouped']:.1f}x "
        f"(target >= 10x)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=7, help="interleaved blocks per figure")
    parser.add_argument("--steps", type=int, default=100, help="env steps per block")
    parser.add_argument("--batch", type=int, default=128, help="random_conv batch size")
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    parser.add_argument("--device", default="cpu", help="device for random_conv")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    print(
        f"torch {torch.__version__}, {args.threads} thread(s); medians of {args.repeats} "
        f"interleaved blocks; seed {SEED}"
    )
    bench_frame_triplet(args.repeats, args.steps)
    bench_simoun_observation(args.repeats, args.steps)
    bench_random_conv(args.repeats, args.batch, args.device)


if __name__ == "__main__":
    main()
