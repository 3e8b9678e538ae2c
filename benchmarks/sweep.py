"""Ray Tune's overhead: the same 4 tiny trials (2 recipes x 2 seeds of the tests' PointReach
config) run by ``simoun-sweep`` and by plain sequential ``simoun-train`` calls.

Baseline: the 4 ``simoun-train`` processes one after the other, each with one torch thread, as a
user without the sweep would run them. The sweep runs them on a fresh local Ray instance with
``--cpus-per-trial 1`` (two side by side on 2 cores) and writes its report, Ray's start-up and
shutdown included: both sides are timed from the command's start to its exit. Each round runs
both, in alternating order, so a change of load on a shared machine hits them alike; the ratio
printed is sweep time / sequential time (the target is <= 1.15: the parallelism pays for Ray).

    python benchmarks/sweep.py                       # 120 env steps per trial, 1 round
    python benchmarks/sweep.py --total-env-steps 600 --rounds 3
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

RECIPES = ("drq", "sac")
SEEDS = (0, 1)


def tiny_flags(total_env_steps: int) -> list[str]:
    """The tiny run of tests/test_train_resume.py as config flags (tests/test_sweep.py runs it
    shorter, on smaller frames)."""
    return [
        "--env", "simoun/PointReach-v0",
        "--image-size", "32",
        "--total-env-steps", str(total_env_steps),
        "--warmup-agent-steps", "20",
        "--replay-capacity", "1000",
        "--eval-every", "60",
        "--eval-episodes", "1",
        "--checkpoint-every", "60",
        "--video", "false",
        "--progress", "false",
        "--device", "cpu",
        "--set", "agent.batch_size=8",
        "--set", "agent.num_filters=8",
        "--set", "agent.feature_dim=16",
        "--set", "agent.hidden_dim=32",
        "--set", "agent.aux_hidden_dim=32",
    ]  # fmt: skip


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def sequential(out: Path, flags: list[str]) -> float:
    """The 4 trials as 4 ``simoun-train`` processes in a row."""
    total = 0.0
    for recipe in RECIPES:
        for seed in SEEDS:
            run_dir = out / f"{recipe}-s{seed}"
            command = [sys.executable, "-m", "simoun_agent.cli.train", *flags]
            command += ["--torch-threads", "1", "--agent.recipe", recipe, "--seed", str(seed)]
            total += timed([*command, "--run-dir", str(run_dir)])
    return total


def sweep(out: Path, flags: list[str], num_cpus: int) -> float:
    """The 4 trials as one ``simoun-sweep``, a fresh local Ray instance of ``num_cpus``."""
    grid = ["--grid", "agent.recipe=" + ",".join(RECIPES), "--seeds", f"{SEEDS[0]}-{SEEDS[-1]}"]
    command = [sys.executable, "-m", "simoun_lab.cli.sweep", *flags, *grid]
    command += ["--cpus-per-trial", "1", "--num-cpus", str(num_cpus), "--verbose", "0"]
    return timed([*command, "--sweep-dir", str(out / "sweep")])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--total-env-steps", type=int, default=120, help="per trial")
    parser.add_argument("--rounds", type=int, default=1)
    parser.add_argument("--num-cpus", type=int, default=2, help="of the sweep's Ray instance")
    args = parser.parse_args()
    flags = tiny_flags(args.total_env_steps)
    print(
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, load average "
        f"{os.getloadavg()[0]:.1f}; 4 trials of {args.total_env_steps} env steps"
    )
    ratios = []
    for round_ in range(args.rounds):
        root = Path(tempfile.mkdtemp(prefix="simoun-bench-sweep-"))
        try:
            if round_ % 2 == 0:
                plain = sequential(root / "plain", flags)
                tuned = sweep(root, flags, args.num_cpus)
            else:
                tuned = sweep(root, flags, args.num_cpus)
                plain = sequential(root / "plain", flags)
        finally:
            shutil.rmtree(root, ignore_errors=True)
        ratios.append(tuned / plain)
        print(
            f"round {round_}: sequential simoun-train {plain:.1f} s, simoun-sweep {tuned:.1f} s, "
            f"ratio {tuned / plain:.2f}x"
        )
    print(
        "simoun-sweep / sequential simoun-train wall time: median "
        f"{statistics.median(ratios):.2f}x over {len(ratios)} rounds (target <= 1.15x); load "
        f"average now {os.getloadavg()[0]:.1f}"
    )


if __name__ == "__main__":
    main()
