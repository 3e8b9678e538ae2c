"""Is env stepping the bottleneck of SB3 PPO on MiniGrid pixels? And what will the study cost?

For each arm of the MiniGrid study (``simoun_lab.minigrid_study``), PPO with the study's
settings (rl-zoo's MiniGrid entry: 8 sub-envs x 128 steps, 10 epochs of minibatch 64,
``CnnPolicy`` on the folded 56x56 triplet) trains for a few rollouts on one torch thread. Per
rollout it times ``env.step`` of the wrapped vector env (pixels, triplets and the arm's
intrinsic reward, its model's forward pass and training thread included) against PPO's update
of that rollout, and prints

1. the ratio env-step time / update time per arm (the named baseline: PPO's own update, in the
   same rollout): far below 1 means stepping is not the bottleneck and a faster renderer would
   not pay;
2. env steps per second of each arm (the training loop: stepping, the policy's forward passes,
   the update; evaluations left out), and
3. the study's estimated run-hours: every run of the spec's tasks x arms x seeds at these
   rates (one torch thread a run; two runs at a time on two free cores halve the wall time).

Medians over the rollouts after the first (torch's warm-up). Run:

    python benchmarks/minigrid_ppo.py [--env MiniGrid-DoorKey-6x6-v0] [--rollouts 4]
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch
from stable_baselines3 import PPO

from simoun_lab.minigrid_study.arms import ARMS
from simoun_lab.minigrid_study.envs import SB3VecEnv, pixel_vector_env
from simoun_lab.minigrid_study.spec import StudySpec
from simoun_lab.minigrid_study.timing import RolloutClock, TimedVecEnv


def measure(env_id: str, arm: str, rollouts: int, spec: StudySpec) -> dict[str, float]:
    """Median seconds per rollout of env stepping, of the update and of the whole loop."""
    envs = ARMS[arm](pixel_vector_env(env_id, spec.ppo.n_envs), 0, torch.device("cpu"))
    timed = TimedVecEnv(SB3VecEnv(envs))
    ppo = PPO("CnnPolicy", timed, seed=0, device="cpu", **spec.ppo.kwargs())
    clock = RolloutClock(timed)
    per_rollout = spec.ppo.n_envs * spec.ppo.n_steps
    ppo.learn(rollouts * per_rollout, callback=clock)
    timed.close()
    rows = clock.rows[1:]
    return {
        "env_s": statistics.median(r["env_s"] for r in rows),
        "update_s": statistics.median(r["update_s"] for r in rows),
        "loop_s": statistics.median(r["collect_s"] + r["update_s"] for r in rows),
        "steps": per_rollout,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--env", default="MiniGrid-DoorKey-6x6-v0")
    parser.add_argument("--rollouts", type=int, default=4, help="rollouts per arm (>= 2)")
    args = parser.parse_args()
    torch.set_num_threads(1)
    spec = StudySpec()
    rates = {}
    print(f"{args.env}, {args.rollouts} rollouts of {spec.ppo.n_envs}x{spec.ppo.n_steps} steps")
    print("arm          env s  update s  env/update  steps/s")
    for arm in spec.arms:
        start = time.perf_counter()
        m = measure(args.env, arm, args.rollouts, spec)
        rates[arm] = m["steps"] / m["loop_s"]
        print(
            f"{arm:<12} {m['env_s']:5.2f}  {m['update_s']:8.2f}  {m['env_s'] / m['update_s']:10.2f}"
            f"  {rates[arm]:7.1f}   ({time.perf_counter() - start:.0f} s)"
        )
    hours = {arm: 0.0 for arm in spec.arms}
    for run in spec.runs():
        hours[run.arm] += run.task.steps / rates[run.arm] / 3600
    total = sum(hours.values())
    print("study run-hours at these rates: " + ", ".join(f"{a} {h:.1f}" for a, h in hours.items()))
    print(f"total {total:.1f} run-hours ({total / 2:.1f} h wall at two runs at a time)")


if __name__ == "__main__":
    main()
