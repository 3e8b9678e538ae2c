"""Stable-Baselines3 SAC from pixels, with Simoun's consistency curiosity added to the reward.

As ``sb3_ppo_curiosity.py``, for an off-policy learner. The replay buffer stores r_e + r_i as
the wrapper computed it at collection time, with the curiosity model of that moment and the
global-step decay of Eq. 13 at that step; Simoun's own agent instead recomputes r_i on every
sampled batch with its current encoder. With the default buffer (10,000 transitions, a few
thousand steps of a CPU run) the stored rewards are at most that many steps old. Each run writes
a CSV of episode returns (see ``curiosity_study.py``):

    python examples/sb3_sac_curiosity.py                   # ball_in_cup-catch (sparse), 48 px
    python examples/sb3_sac_curiosity.py --no-curiosity    # the baseline arm, same seed
"""

from __future__ import annotations

import argparse

from curiosity_study import add_arguments, learn_and_log, make_envs
from stable_baselines3 import SAC


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_arguments(parser, steps=1500)
    parser.add_argument("--buffer-size", type=int, default=10_000, help="replay transitions")
    args = parser.parse_args()

    envs, curiosity = make_envs(args, n_envs=1)
    agent = SAC(
        "CnnPolicy",
        envs,
        buffer_size=args.buffer_size,
        # one frame triplet per transition instead of two (t and t+1): half the memory
        optimize_memory_usage=True,
        replay_buffer_kwargs={"handle_timeout_termination": False},
        learning_starts=500,
        batch_size=64,
        train_freq=2,
        seed=args.seed,
        device=args.device,
        verbose=1,
    )
    learn_and_log(agent, "sac", args, curiosity, log_interval=1)


if __name__ == "__main__":
    main()
