"""Stable-Baselines3 PPO from pixels, with Simoun's consistency curiosity added to the reward.

The env is rendered to small frames, stacked into Simoun's triplet and folded to a
``(3C, H, W)`` uint8 image (what SB3's ``CnnPolicy`` takes); ``ConsistencyCuriosityReward``
adds Eq. 13's intrinsic reward, with features from a ``CuriosityModel`` that trains its own
dual-path encoder on the transitions it sees (in a background thread). No Simoun agent is
involved. Each run writes a CSV of episode returns (see ``curiosity_study.py``), so the two arms
of a comparison can be run per seed and plotted later:

    python examples/sb3_ppo_curiosity.py                   # ball_in_cup-catch (sparse), 48 px
    python examples/sb3_ppo_curiosity.py --no-curiosity    # the baseline arm, same seed
    python examples/sb3_ppo_curiosity.py --env dm_control/cartpole-balance_sparse-v0 --seed 1
    python examples/sb3_ppo_curiosity.py --env simoun/PointReach-v0 --action-repeat 1 --n-envs 4

Watch ``curiosity/motion_std`` and ``curiosity/appearance_std`` in the log: near 0 means the
features do not tell frames apart and the intrinsic reward is close to a constant bonus.
"""

from __future__ import annotations

import argparse

from curiosity_study import add_arguments, learn_and_log, make_envs
from stable_baselines3 import PPO


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    add_arguments(parser, steps=2048)
    parser.add_argument("--n-envs", type=int, default=1, help="sub-envs sharing one model")
    parser.add_argument("--tensorboard", default=None, help="TensorBoard log directory")
    args = parser.parse_args()

    envs, curiosity = make_envs(args, args.n_envs)
    agent = PPO(
        "CnnPolicy",
        envs,
        n_steps=max(256 // args.n_envs, 32),
        batch_size=64,
        n_epochs=4,
        seed=args.seed,
        device=args.device,
        verbose=1,
        tensorboard_log=args.tensorboard,
    )
    learn_and_log(agent, "ppo", args, curiosity)


if __name__ == "__main__":
    main()
