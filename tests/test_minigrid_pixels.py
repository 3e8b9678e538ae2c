"""MiniGrid from pixels as a user writes it (RGBImgPartialObsWrapper + ImgObsWrapper ->
SimounObservation -> an intrinsic-reward wrapper), Discrete actions: check_env and short SB3
PPO runs whose rewards are checked against the wrappers' two parts."""

import gymnasium as gym
import minigrid  # noqa: F401  (registers the MiniGrid-* ids)
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from minigrid.wrappers import ImgObsWrapper, RGBImgPartialObsWrapper
from stable_baselines3.common import callbacks

from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_agent.rnd_model import RNDConfig, RNDModel
from simoun_wrappers import ConsistencyCuriosityReward, RNDReward, SimounObservation

SMALL_CURIOSITY = CuriosityConfig(
    num_filters=8, feature_dim=16, aux_hidden_dim=32, batch_size=16,
    capacity=128, learning_starts=32, update_every=8, seed=0,
)  # fmt: skip
SMALL_RND = RNDConfig(
    feature_dim=32, batch_size=16, capacity=128, learning_starts=32, update_every=8, seed=0
)


def pixels(fold_frames: bool = False) -> gym.Env:
    env = ImgObsWrapper(RGBImgPartialObsWrapper(gym.make("MiniGrid-DoorKey-5x5-v0")))
    return SimounObservation(env, size=None, fold_frames=fold_frames)


def consistency(env: gym.Env, **kwargs) -> gym.Env:
    model = CuriosityModel.for_env(env, SMALL_CURIOSITY, "cpu")
    return ConsistencyCuriosityReward(env, model, **kwargs)


def rnd(env: gym.Env, warmup: int = 64) -> gym.Env:
    return RNDReward(env, RNDModel.for_env(env, SMALL_RND, "cpu"), warmup=warmup)


def test_the_pixel_chain_gives_triplets_of_the_56x56_view():
    env = pixels()
    assert env.observation_space["frames"].shape == (3, 3, 56, 56)
    assert isinstance(env.action_space, gym.spaces.Discrete) and env.action_space.n == 7
    assert pixels(fold_frames=True).observation_space.shape == (9, 56, 56)


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")
@pytest.mark.parametrize(
    "wrap",
    [
        lambda env: consistency(env, decay=0.0, r_i_max_init=1e6),
        lambda env: rnd(env, warmup=10_000),
    ],
)
def test_both_wrappers_pass_check_env_on_minigrid_pixels(wrap):
    # minigrid's RGBImgPartialObsWrapper records no constructor arguments, so env.spec cannot
    # rebuild the chain (check_env's close check does that). check_env wants the same reward
    # from the same seed and action: running statistics that move with each step are not, so
    # here Eq. 13's maximum stays above every distance and RND's warm-up keeps its reward at 0
    env = wrap(pixels())
    check_env(env, skip_render_check=True, skip_close_check=True)
    env.close()


class RewardsSeen(callbacks.BaseCallback):
    """The reward PPO stores at each step, next to the wrapper's two parts of it."""

    def __init__(self):
        super().__init__()
        self.steps = []
        self.still = []
        """whether the triplet reached is one frame three times (a turn into nothing, a no-op)"""

    def _on_step(self) -> bool:
        info = self.locals["infos"][0]
        reward = float(self.locals["rewards"][0])
        self.steps.append((reward, info["reward_extrinsic"], info["reward_intrinsic"]))
        obs = info.get("terminal_observation", self.locals["new_obs"][0])
        frames = obs.reshape(3, 3, 56, 56)
        self.still.append(bool(np.all(frames == frames[:1])))
        return True


@pytest.mark.parametrize("arm", ["consistency", "rnd"])
def test_ppo_trains_on_extrinsic_plus_intrinsic(arm, small_ppo):
    env = consistency(pixels(fold_frames=True)) if arm == "consistency" else rnd(pixels(True))
    ppo = small_ppo(env)
    seen = RewardsSeen()
    ppo.learn(total_timesteps=256, callback=seen)
    model = env.signal.source
    assert ppo.num_timesteps == 256 and model.updates == (256 - 32) // 8
    rewards, extrinsic, intrinsic = (np.array(v) for v in zip(*seen.steps, strict=True))
    np.testing.assert_allclose(rewards, extrinsic + intrinsic, rtol=1e-6)
    # DoorKey pays only on reaching the goal: 0 on every other step
    assert np.all((extrinsic == 0) | (extrinsic > 0))
    if arm == "consistency":
        r_e_max = env.state_dict()["normalization"]["r_e_max"]
        assert np.all(intrinsic <= 0.2 * r_e_max + 1e-9)
        # A still triplet (a no-op or a move into a wall: 106 of these 256 PPO steps)
        # has no motion and no appearance change. With the initial weights (zero biases) its
        # f_m is 0 and so is Eq. 13's distance; once trained (the first step is published at
        # watch call 40), the biases make |f_m| of no motion a constant the reward pays for.
        still, initial = np.array(seen.still), np.arange(256) < 40
        assert 0 < still[initial].sum() < initial.sum()
        # 0 up to float rounding (one CI run gave 9.6e-8 for one still step; moves pay > 1e-3)
        assert np.all(intrinsic[initial & still] < 1e-6)
        assert np.all(intrinsic[initial & ~still] > 1e-6)
        assert np.all(intrinsic[~initial] > 0)
        assert env.state_dict()["scored"] == 256
    else:
        assert np.all(intrinsic[:64] == 0) and np.all(intrinsic[64:] > 0)
        assert env.state_dict()["scored"] == 256
        assert env.state_dict()["normalization"]["count"] == 256 - 64 // 2  # from mid warm-up on
    env.close()
