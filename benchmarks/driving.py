"""Training throughput of the highway-cpu preset against its environment alone, in one run.

    python benchmarks/driving.py [--decisions 300] [--warmup 200] [--repeats 2] [--set KEY=VALUE]

Builds the preset's run as simoun-train does (highway-fast-v0 under MultiCamera and
SimounObservation, the agent, the replay; one torch thread), then, alternating in each repeat:

- env alone: ``--decisions`` random decisions through the same environment stack;
- agent training: after ``--warmup`` random decisions into the replay, ``--decisions`` decisions
  of the training loop's work (act, step, store, then ``updates_per_step`` updates).

It prints env steps per second of both, by wall clock and by process CPU time, and the ratio
agent / env alone. On a machine shared with other work the wall clock counts the waits for a
core, so the CPU-time rate is the closer one to a quiet machine; as a second check it times the
cpu preset's update (48x48 RGB, batch 64, 16 filters) as a yardstick, which took 107 ms on the
quiet 2-core machine (README, benchmarks/training_loop.py), and scales the agent's rate by it.
``--set`` overrides a preset value (``--set agent.batch_size=64 --set image_size=84``), and
``--set cameras=3`` times the paper's three-view layout.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import torch

from simoun_agent import FrameReplay, SimounAgent
from simoun_agent.config import resolve
from simoun_agent.config.keys import config_fields, parse_value
from simoun_agent.run import train

PRESET = "highway-cpu"
YARDSTICK_QUIET_MS = 107.0
"""The cpu preset's update on the quiet 2-core machine (README: benchmarks/training_loop.py)."""


class Clock:
    """Wall and process CPU seconds since it was made."""

    def __init__(self) -> None:
        self.wall, self.cpu = time.perf_counter(), time.process_time()

    def rates(self, steps: int) -> tuple[float, float]:
        """Steps per wall second and per process CPU second."""
        return steps / (time.perf_counter() - self.wall), steps / (time.process_time() - self.cpu)


def env_alone(run: train.Run, decisions: int, seed: int) -> tuple[float, float]:
    """Random decisions through the run's environment stack."""
    rng = np.random.default_rng(seed)
    shape = run.env.action_space.shape
    run.env.reset(seed=seed)
    clock = Clock()
    for _ in range(decisions):
        run.env.step_async(rng.uniform(-1, 1, shape).astype(np.float32))
        _, _, terminated, truncated = run.env.step_wait()
        if terminated or truncated:
            run.env.reset(seed=seed)
    return clock.rates(decisions)


def training(run: train.Run, decisions: int, warmup: int, seed: int) -> tuple[float, float]:
    """The training loop's work per decision (simoun_agent.run.train), after a random warm-up."""
    rng = np.random.default_rng(seed)
    shape = run.env.action_space.shape
    obs = None
    clock = None
    for decision in range(warmup + decisions):
        if decision == warmup:
            clock = Clock()
        if obs is None:
            obs = run.env.reset(seed=seed + decision)
            run.replay.start_episode(obs["frames"][-1])
        if decision < warmup:
            action = rng.uniform(-1, 1, shape).astype(np.float32)
        else:
            action = run.agent.act(obs["frames"], step=decision)
        run.env.step_async(action)
        if decision >= warmup:
            for _ in range(run.config.updates_per_step):
                run.agent.update(run.replay, decision)
        obs, reward, terminated, truncated = run.env.step_wait()
        run.replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            obs = None
    return clock.rates(decisions)


def yardstick_ms(updates: int) -> float:
    """Process CPU milliseconds of one update of the cpu preset's agent (48x48 RGB frames)."""
    config = resolve("cpu", {"device": "cpu"}).agent
    frame = (3, 48, 48)
    rng = np.random.default_rng(0)
    replay = FrameReplay(400, frame, 1, seed=0)
    for t in range(400):
        if t % 100 == 0:
            replay.start_episode(rng.integers(0, 256, frame, dtype=np.uint8))
        image = rng.integers(0, 256, frame, dtype=np.uint8)
        replay.add(rng.uniform(-1, 1, 1), rng.random(), image, False, (t + 1) % 100 == 0)
    agent = SimounAgent(frame, 1, config, device="cpu")
    for _ in range(2):
        agent.update(replay, 0)
    start = time.process_time()
    for _ in range(updates):
        agent.update(replay, 0)
    return 1000 * (time.process_time() - start) / updates


def overrides(pairs: list[str], run_dir: Path, steps: int) -> dict:
    fields = config_fields()
    values = {}
    for pair in pairs:
        key, _, text = pair.partition("=")
        values[key] = parse_value(key, text, fields[key][0])
    return {
        **values,
        "total_env_steps": steps,
        "eval_every": 10**9,
        "checkpoint_every": 10**9,
        "video": False,
        "progress": False,
        "device": "cpu",
        "run_dir": str(run_dir),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--decisions", type=int, default=300)
    parser.add_argument("--warmup", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        steps = args.warmup + args.decisions
        config = resolve(PRESET, overrides(args.set, Path(tmp) / "run", steps))
        torch.set_num_threads(config.torch_threads or 1)
        agent = config.agent
        print(
            f"{PRESET}: {config.env}, {config.cameras} camera(s) x {config.image_size}x"
            f"{config.image_size} {'gray' if config.grayscale else 'RGB'}, batch "
            f"{agent.batch_size}, {agent.num_filters} filters, hidden {agent.hidden_dim}, "
            f"features {agent.feature_dim}, {config.updates_per_step} update(s) per decision, "
            f"{torch.get_num_threads()} torch thread(s); load average "
            f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"
        )
        rates: dict[str, list[tuple[float, float]]] = {"env": [], "agent": []}
        for repeat in range(args.repeats):
            run = train.create_run(
                resolve(PRESET, overrides(args.set, Path(tmp) / f"r{repeat}", steps))
            )
            try:
                rates["env"].append(env_alone(run, args.decisions, seed=repeat))
                rates["agent"].append(training(run, args.decisions, args.warmup, seed=repeat))
            finally:
                run.env.close()
                run.eval_env.close()
                run.lock.close()
        yardstick = yardstick_ms(10)
    repeat = config.resolved_action_repeat()
    env_wall, env_cpu = (repeat * statistics.median(r[i] for r in rates["env"]) for i in (0, 1))
    agent_wall, agent_cpu = (
        repeat * statistics.median(r[i] for r in rates["agent"]) for i in (0, 1)
    )
    quiet = agent_cpu * yardstick / YARDSTICK_QUIET_MS
    print(f"env steps per second (median of {args.repeats}; {args.decisions} decisions each):")
    print(f"  env alone         wall {env_wall:7.1f}   per CPU second {env_cpu:7.1f}")
    print(f"  agent training    wall {agent_wall:7.1f}   per CPU second {agent_cpu:7.1f}")
    wall_ratio, cpu_ratio = agent_wall / env_wall, agent_cpu / env_cpu
    print(f"  ratio agent / env alone: wall {wall_ratio:.3f}, CPU {cpu_ratio:.3f}")
    print(
        f"yardstick: the cpu preset's update took {yardstick:.0f} ms of CPU here against "
        f"{YARDSTICK_QUIET_MS:.0f} ms on the quiet machine; scaled by it, agent training "
        f"~{quiet:.1f} env steps/s there"
    )


if __name__ == "__main__":
    main()
