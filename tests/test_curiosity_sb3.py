"""Stable-Baselines3 through ConsistencyCuriosityReward: a short PPO run, and the two examples."""

import csv
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common import callbacks

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


class RewardsSeen(callbacks.BaseCallback):
    """The reward PPO stores at each step, next to the wrapper's two parts of it."""

    def __init__(self):
        super().__init__()
        self.steps = []

    def _on_step(self) -> bool:
        info = self.locals["infos"][0]
        reward = float(self.locals["rewards"][0])
        self.steps.append((reward, info["reward_extrinsic"], info["reward_intrinsic"]))
        return True


def test_ppo_trains_on_extrinsic_plus_intrinsic_reward_through_the_wrapper(small_ppo):
    # SB3's NatureCNN needs frames of at least 36x36; the folded triplet is its (9, H, W) image.
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=36, fold_frames=True)
    config = CuriosityConfig(
        num_filters=8, feature_dim=16, aux_hidden_dim=32, batch_size=16,
        capacity=128, learning_starts=32, update_every=8, seed=0,
    )  # fmt: skip
    model = CuriosityModel.for_env(env, config, device="cpu")
    env = ConsistencyCuriosityReward(env, model)
    ppo = small_ppo(env)
    seen = RewardsSeen()
    ppo.learn(total_timesteps=192, callback=seen)
    assert ppo.num_timesteps == 192
    assert env.state_dict()["scored"] == 192
    assert model.updates == (192 - 32) // 8  # one more started, published at its next due step
    rewards, extrinsic, intrinsic = (np.array(v) for v in zip(*seen.steps, strict=True))
    assert len(rewards) == 192
    # PPO was trained on r_e + r_i (Eq. 12), r_i from Eq. 13 at every step
    np.testing.assert_allclose(rewards, extrinsic + intrinsic, rtol=1e-6)
    assert np.all(intrinsic > 0) and np.all(
        intrinsic <= 0.2 * env.state_dict()["normalization"]["r_e_max"] + 1e-6
    )


@pytest.mark.parametrize(
    ("script", "curiosity"), [("sb3_ppo_curiosity.py", True), ("sb3_sac_curiosity.py", False)]
)
def test_examples_write_a_csv_of_episode_returns(tmp_path, script, curiosity):
    out = tmp_path / "returns.csv"
    command = [sys.executable, str(EXAMPLES / script), "--env", "simoun/PointReach-v0"]
    command += ["--size", "36", "--action-repeat", "1", "--steps", "64", "--csv", str(out)]
    command += [] if curiosity else ["--no-curiosity"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    with out.open() as file:
        rows = list(csv.DictReader(file))
    assert len(rows) >= 3  # PointReach episodes last 20 steps
    assert {row["curiosity"] for row in rows} == {str(curiosity)}
    assert all(int(row["length"]) == 20 for row in rows)
    # the CSV scores the task's own reward; curiosity only adds the intrinsic column
    assert all(float(row["return_extrinsic"]) < 0 for row in rows)
    intrinsic = [float(row["return_intrinsic"]) for row in rows]
    assert all(r > 0 for r in intrinsic) if curiosity else all(r == 0 for r in intrinsic)
