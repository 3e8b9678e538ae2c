"""Speed of one Simoun training step against a CURL-equivalent step, in one process.

Both steps sample their batch from their own replay and run every loss and optimiser of their
method; step counts are even so the averages cover the steps where the actor and the targets do
and do not update. Baseline and Simoun alternate in each repeat and the medians are reported, so
a machine shared with other work slows both alike. Also prints the act latency for one
observation and the replay bytes per transition at 84x84 RGB.

    python benchmarks/update.py                      # batch 32 and 128, all threads
    python benchmarks/update.py --threads 1 --batch-sizes 128 --repeats 7

``--n-step-curiosity`` instead times the cpu preset's Simoun update (48x48, 3-step returns,
random shift, batch 64, one thread) with Eq. 13's intrinsic reward of every step of the return
against the same agent adding only that of the state at t (the form without ``return_mask``),
alternating in each repeat.
"""

from __future__ import annotations

import argparse
import itertools
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parent))

from curl_baseline import CurlBaseline

from simoun_agent import AgentConfig, FrameReplay, SimounAgent

FRAME = (3, 84, 84)
ACTION_DIM = 6


def filled_replay(
    transitions: int, episode_length: int = 100, seed: int = 0, frame: tuple = FRAME
) -> FrameReplay:
    """A replay of random frames, in episodes of ``episode_length`` steps."""
    rng = np.random.default_rng(seed)
    replay = FrameReplay(transitions, frame, ACTION_DIM, seed=seed)
    for t in range(transitions):
        if t % episode_length == 0:
            replay.start_episode(rng.integers(0, 256, frame, dtype=np.uint8))
        end = (t + 1) % episode_length == 0
        image = rng.integers(0, 256, frame, dtype=np.uint8)
        replay.add(rng.uniform(-1, 1, ACTION_DIM), rng.random(), image, False, end)
    return replay


def first_step_curiosity(agent: SimounAgent, replay: FrameReplay):
    """Like ``stepper``, but through the n-step call without ``return_mask``: only r^i(s_t)
    enters each n-step target (the same encoder passes but the triplet at
    t+2)."""
    counter = itertools.count()
    cfg = agent.config

    def step() -> None:
        batch = replay.sample(cfg.batch_size, cfg.n_step, cfg.discount)
        put = {name: torch.from_numpy(value) for name, value in batch.items()}
        bootstrap = (put["bootstrap_obs"], put["return"])
        agent.update_window(
            put["window"], put["action"], put["reward"], put["discount"], next(counter), bootstrap
        )

    return step


def n_step_curiosity(args: argparse.Namespace) -> None:
    """Per-step against first-step curiosity at the cpu preset's settings."""
    from simoun_agent.config import resolve

    torch.set_num_threads(1)
    config = resolve("cpu", {}).agent
    size = resolve("cpu", {}).image_size
    replay = filled_replay(1000, frame=(3, size, size))
    agents = []
    for _ in range(2):
        torch.manual_seed(0)
        agents.append(SimounAgent((3, size, size), ACTION_DIM, config, device="cpu"))
    per_step, first = stepper(agents[0], replay), first_step_curiosity(agents[1], replay)
    per_step()
    first()
    print(
        f"torch {torch.__version__}, 1 thread, cpu preset: {size}x{size} RGB, batch "
        f"{config.batch_size}, n_step {config.n_step}, augmentation {config.augmentation}, "
        f"encoder {config.encoder}; {args.steps} steps x {args.repeats} interleaved repeats"
    )
    times: dict[str, list[tuple[float, float]]] = {"first": [], "per_step": []}
    for _ in range(args.repeats):
        times["first"].append(time_steps(first, args.steps))
        times["per_step"].append(time_steps(per_step, args.steps))
    for kind, label in ((0, "wall"), (1, "cpu")):
        old = statistics.median(t[kind] for t in times["first"])
        new = statistics.median(t[kind] for t in times["per_step"])
        print(
            f"ms per update ({label}), median: r_i of s_t only {old:.1f}, r_i of every step "
            f"{new:.1f}, ratio {new / old:.3f}"
        )


def stepper(agent: SimounAgent, replay: FrameReplay):
    """A no-argument call doing one ``agent.update`` at the next environment step."""
    counter = itertools.count()
    return lambda: agent.update(replay, next(counter))


def time_steps(fn, steps: int) -> tuple[float, float]:
    """Wall-clock and process CPU milliseconds per call of ``fn`` over ``steps`` calls."""
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        fn()
    return 1e3 * (time.perf_counter() - wall) / steps, 1e3 * (time.process_time() - cpu) / steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch-sizes", type=int, nargs="+", default=[32, 128])
    parser.add_argument("--steps", type=int, default=4, help="steps per timing (even)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--threads", type=int, default=torch.get_num_threads())
    parser.add_argument("--encoder", default="dual_interactive")
    parser.add_argument("--no-channels-last", action="store_true", help="Simoun in NCHW")
    parser.add_argument(
        "--full-gradient", action="store_true", help="Simoun with detach_past_frames=False"
    )
    parser.add_argument(
        "--curl-channels-last", action="store_true", help="give the baseline channels-last too"
    )
    parser.add_argument(
        "--n-step-curiosity",
        action="store_true",
        help="per-step against first-step curiosity in 3-step targets (cpu preset)",
    )
    args = parser.parse_args()
    if args.n_step_curiosity:
        n_step_curiosity(args)
        return
    torch.set_num_threads(args.threads)
    torch.manual_seed(0)
    replay = filled_replay(1000)

    print(
        f"torch {torch.__version__}, {args.threads} threads, 84x84 RGB, {ACTION_DIM} actions, "
        f"encoder {args.encoder}, gradient through frames t-2, t-1: {args.full_gradient}, "
        f"channels-last: Simoun {not args.no_channels_last}, CURL "
        f"{args.curl_channels_last}; {args.steps} steps x {args.repeats} interleaved repeats"
    )
    print("ms per training step: median (min) of the repeats; wall clock and process CPU time")
    header = ("batch", "CURL wall", "Simoun wall", "ratio", "CURL cpu", "Simoun cpu", "ratio")
    print("{:>5} {:>17} {:>17} {:>11} {:>17} {:>17} {:>11}".format(*header))
    for batch in args.batch_sizes:
        config = AgentConfig(
            encoder=args.encoder,
            batch_size=batch,
            curiosity=args.encoder.startswith("dual"),
            channels_last=not args.no_channels_last,
            detach_past_frames=not args.full_gradient,
        )
        agent = SimounAgent(FRAME, ACTION_DIM, config, device="cpu")
        curl = CurlBaseline(ACTION_DIM, batch, channels_last=args.curl_channels_last)
        ours = stepper(agent, replay)
        curl.update()
        ours()
        curl_ms, ours_ms = [], []
        for _ in range(args.repeats):
            curl_ms.append(time_steps(curl.update, args.steps))
            ours_ms.append(time_steps(ours, args.steps))
        row = [f"{batch:>5}"]
        for kind in (0, 1):
            c = [m[kind] for m in curl_ms]
            o = [m[kind] for m in ours_ms]
            cm, om = statistics.median(c), statistics.median(o)
            row += [f"{cm:>8.0f} ({min(c):>6.0f})", f"{om:>8.0f} ({min(o):>6.0f})"]
            row.append(f"{om / cm:>4.2f} ({min(o) / min(c):.2f})")
        print(" ".join(row), flush=True)

    obs = replay.sample(1)["obs"][0]
    agent.act(obs)
    act_ms = statistics.median(time_steps(lambda: agent.act(obs), 20)[0] for _ in range(5))
    curl_obs = curl.obs[0, :, :84, :84]
    curl.act(curl_obs)
    curl_act_ms = statistics.median(time_steps(lambda: curl.act(curl_obs), 20)[0] for _ in range(5))
    print(f"act latency, one observation: Simoun {act_ms:.2f} ms, CURL {curl_act_ms:.2f} ms")
    big = FrameReplay(100_000, FRAME, ACTION_DIM)
    curl_bytes = 2 * 9 * 100 * 100 + 4 * ACTION_DIM + 4 + 4
    print(
        f"replay bytes per transition (capacity 100,000): Simoun {big.bytes_per_transition:,.0f}, "
        f"CURL {curl_bytes:,}"
    )


if __name__ == "__main__":
    main()
