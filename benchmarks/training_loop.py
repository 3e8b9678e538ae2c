"""Training-loop throughput of the cpu preset: the environment stepped in the training process
against the environment stepped in a background process (``--env-process``), in one run.

    python benchmarks/training_loop.py [--agent-steps 400] [--repeats 2]

First prints where one training step's time goes (environment = physics + render, update, act,
each timed alone on dm_control cartpole-swingup at the preset's 48x48), then runs the same short
training run (warm-up, then ``--agent-steps`` decisions with one update each; evaluation of one
episode at the start and end) with each runner, interleaved, and prints env steps per second and
the ratio background / in-process. Time it on a quiet machine: the background process needs the
second core.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from simoun_agent.config import resolve
from simoun_agent.run import train


def config(run_dir: Path, env_process: bool, agent_steps: int, warmup: int):
    return resolve(
        "cpu",
        {
            "total_env_steps": 8 * (warmup + agent_steps),
            "warmup_agent_steps": warmup,
            "eval_every": 10**9,
            "checkpoint_every": 10**9,
            "eval_episodes": 1,
            "video": False,
            "progress": False,
            "device": "cpu",
            "env_process": env_process,
            "run_dir": str(run_dir),
        },
    )


def profile(run: train.Run, steps: int) -> dict[str, float]:
    """Milliseconds per environment step, update and act, each timed alone."""
    rng = np.random.default_rng(0)
    obs = run.env.reset(seed=0)
    run.replay.start_episode(obs["frames"][-1])
    start = time.perf_counter()
    for _ in range(steps):
        action = rng.uniform(-1, 1, run.env.action_space.shape).astype(np.float32)
        run.env.step_async(action)
        obs, reward, terminated, truncated = run.env.step_wait()
        run.replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            obs = run.env.reset(seed=1)
            run.replay.start_episode(obs["frames"][-1])
    env_ms = 1000 * (time.perf_counter() - start) / steps
    start = time.perf_counter()
    for _ in range(steps // 4):
        run.agent.update(run.replay, 0)
    update_ms = 4000 * (time.perf_counter() - start) / steps
    start = time.perf_counter()
    for _ in range(steps):
        run.agent.act(obs["frames"])
    act_ms = 1000 * (time.perf_counter() - start) / steps
    return {"env": env_ms, "update": update_ms, "act": act_ms}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--agent-steps", type=int, default=400)
    parser.add_argument("--warmup", type=int, default=100)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        probe = train.create_run(config(Path(tmp) / "profile", False, 0, args.warmup))
        parts = profile(probe, 200)
        probe.env.close()
        probe.eval_env.close()
        total = sum(parts.values())
        print("one training step of the cpu preset (cartpole-swingup 48x48, 1 torch thread):")
        for name, ms in parts.items():
            print(f"  {name:7} {ms:7.1f} ms  {100 * ms / total:5.1f} %")
        speeds: dict[bool, list[float]] = {False: [], True: []}
        for repeat in range(args.repeats):
            for background in (False, True):
                run_dir = Path(tmp) / f"r{repeat}-{background}"
                run = train.create_run(config(run_dir, background, args.agent_steps, args.warmup))
                start = time.perf_counter()
                try:
                    train.train(run)
                finally:
                    run.env.close()
                    run.eval_env.close()
                speeds[background].append(run.counters.env_step / (time.perf_counter() - start))
    inline, background = (statistics.median(speeds[b]) for b in (False, True))
    print(
        f"env steps per second over {args.agent_steps} agent steps after a {args.warmup}-step "
        f"warm-up (median of {args.repeats}): in-process {inline:.1f}, background process "
        f"{background:.1f}, ratio {background / inline:.2f}x"
    )


if __name__ == "__main__":
    main()
