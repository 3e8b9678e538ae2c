"""Stable-Baselines3 PPO from pixels, with Simoun's consistency curiosity added to the reward.

The env is rendered to small frames, stacked into Simoun's triplet and folded to a
``(3C, H, W)`` uint8 image (what SB3's ``CnnPolicy`` takes); ``ConsistencyCuriosityReward``
adds Eq. 13's intrinsic reward, with features from a ``CuriosityModel`` that trains its own
dual-path encoder on the transitions it sees. No Simoun agent is involved.

    python examples/sb3_ppo_curiosity.py                     # PointReach (pixels only), 1 env
    python examples/sb3_ppo_curiosity.py --n-envs 4          # 4 sub-envs sharing one model
    python examples/sb3_ppo_curiosity.py --env Pendulum-v1   # any env with rgb_array renders

Watch ``curiosity/motion_std`` and ``curiosity/appearance_std``: near 0 means the features do
not tell frames apart. On renders of a small object on a plain page (CartPole-v1, Pendulum-v1
at 48x48) f_a barely varies from the start and L_con stays at chance in a short run, so the
intrinsic reward mostly follows f_m.

The intrinsic reward and the model's losses are logged with SB3's logger (stdout and, with
``--tensorboard DIR``, TensorBoard) under ``curiosity/``.
"""

from __future__ import annotations

import argparse

import gymnasium as gym
import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.env_util import make_vec_env

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward


class CuriosityLog(BaseCallback):
    """Record the mean intrinsic / extrinsic reward and the model's last losses at each rollout."""

    def __init__(self, model: CuriosityModel) -> None:
        super().__init__()
        self.curiosity = model
        self.intrinsic: list[float] = []
        self.extrinsic: list[float] = []

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            self.intrinsic.append(info["reward_intrinsic"])
            self.extrinsic.append(info["reward_extrinsic"])
        return True

    def _on_rollout_end(self) -> None:
        self.logger.record("curiosity/reward_intrinsic", float(np.mean(self.intrinsic)))
        self.logger.record("curiosity/reward_extrinsic", float(np.mean(self.extrinsic)))
        for name, value in self.curiosity.last_metrics.items():
            self.logger.record(f"curiosity/{name}", value)
        self.intrinsic.clear()
        self.extrinsic.clear()


def make_env(env_id: str, size: int) -> gym.Env:
    """The pixel env: rendered, resized, stacked into a triplet and folded for SB3."""
    env = gym.make(env_id, render_mode="rgb_array")
    return SimounObservation(env, size=size, fold_frames=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--env", default="simoun/PointReach-v0", help="env with rgb_array renders")
    parser.add_argument("--steps", type=int, default=4096, help="total env steps")
    parser.add_argument("--size", type=int, default=48, help="frame side (SB3's CNN needs >= 36)")
    parser.add_argument("--n-envs", type=int, default=1, help="sub-envs (DummyVecEnv)")
    parser.add_argument("--scale", type=float, default=0.2, help="C of Eq. 13")
    parser.add_argument("--device", default="cpu", help="torch device of PPO and the model")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, default=1, help="torch CPU threads")
    parser.add_argument("--tensorboard", default=None, help="TensorBoard log directory")
    args = parser.parse_args()
    torch.manual_seed(args.seed)
    torch.set_num_threads(args.threads)

    probe = make_env(args.env, args.size)
    # One model for every sub-env: DummyVecEnv steps them in this process, in turn.
    curiosity = CuriosityModel.for_env(
        probe,
        CuriosityConfig(batch_size=32, update_every=8, learning_starts=256, seed=args.seed),
        device=args.device,
    )
    probe.close()
    envs = make_vec_env(
        lambda: make_env(args.env, args.size),
        n_envs=args.n_envs,
        seed=args.seed,
        wrapper_class=ConsistencyCuriosityReward,
        wrapper_kwargs={"features": curiosity, "scale": args.scale},
    )
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
    agent.learn(total_timesteps=args.steps, callback=CuriosityLog(curiosity))
    print(f"curiosity model: {curiosity.updates} updates, last {curiosity.last_metrics}")
    envs.close()


if __name__ == "__main__":
    main()
