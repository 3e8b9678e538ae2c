"""The supported Stable-Baselines3 path: ``fold_frames=True`` with ``CnnPolicy``; what
SB3 does with the Dict form, and ``check_sb3_policy`` saying why and what to use."""

import gymnasium as gym
import minigrid
import numpy as np
import pytest
import stable_baselines3 as sb3
import torch
from stable_baselines3.common.policies import ActorCriticCnnPolicy, ActorCriticPolicy

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_wrappers import SimounObservation, check_sb3_policy

gym.register_envs(minigrid)

FIX = r"SimounObservation\(env, fold_frames=True\) with 'CnnPolicy'"


def point_reach(**options) -> gym.Env:
    return SimounObservation(gym.make("simoun/PointReach-v0"), size=36, **options)


def test_folded_triplet_with_cnn_policy_convolves_all_frames_and_learns(small_ppo):
    env = point_reach(fold_frames=True)
    assert check_sb3_policy(env, "CnnPolicy") == "CnnPolicy"
    ppo = small_ppo(env, n_steps=32, batch_size=16)
    extractor = ppo.policy.features_extractor
    assert type(extractor).__name__ == "NatureCNN"
    assert extractor.cnn[0].in_channels == 9  # the three RGB frames of the triplet
    before = [p.detach().clone() for p in extractor.parameters()]
    ppo.learn(total_timesteps=32)
    assert ppo.num_timesteps == 32
    assert any(not torch.equal(a, b) for a, b in zip(before, extractor.parameters(), strict=True))
    obs, _ = env.reset(seed=0)
    action, _ = ppo.predict(obs, deterministic=True)
    assert env.action_space.contains(action.astype(np.float32))


def test_multi_input_policy_on_the_dict_flattens_pixels_and_the_check_says_so():
    env = point_reach()
    ppo = sb3.PPO("MultiInputPolicy", env, n_steps=32, batch_size=16, device="cpu")
    frames_extractor = ppo.policy.features_extractor.extractors["frames"]
    assert isinstance(frames_extractor, torch.nn.Flatten)  # an MLP on raw pixels, silently
    with pytest.raises(ValueError, match=r"flatten the \(3, 3, 36, 36\) frame stack.*" + FIX):
        check_sb3_policy(env, "MultiInputPolicy")
    with pytest.raises(ValueError, match=FIX):  # SB3's own alias class
        check_sb3_policy(env, sb3.PPO.policy_aliases["MultiInputPolicy"])


def test_cnn_policy_on_the_dict_gets_sb3s_misleading_error_and_ours_points_to_folding():
    env = point_reach()
    with pytest.raises(ValueError, match="You must use `MultiInputPolicy`"):
        sb3.PPO("CnnPolicy", env, device="cpu")
    with pytest.raises(ValueError, match=r"CnnPolicy needs one \(C, H, W\) uint8 image.*" + FIX):
        check_sb3_policy(env.observation_space, "CnnPolicy")


def test_mlp_policy_on_the_folded_image_and_frames_too_small_for_nature_cnn():
    with pytest.raises(ValueError, match=r"MlpPolicy does not convolve.*use 'CnnPolicy'"):
        check_sb3_policy(point_reach(fold_frames=True), "MlpPolicy")
    small = SimounObservation(gym.make("simoun/PointReach-v0"), size=32, fold_frames=True)
    with pytest.raises(ValueError, match=r"at least 36x36, got 32x32.*size=36"):
        check_sb3_policy(small, "CnnPolicy")
    with pytest.raises(RuntimeError):  # what SB3 alone does with them
        sb3.PPO("CnnPolicy", small, device="cpu")


def test_a_space_sb3_takes_in_no_policy_is_refused_for_every_policy():
    blackjack = gym.make("Blackjack-v1")  # a Tuple of Discretes
    with pytest.raises(NotImplementedError, match="Tuple"):  # what SB3 alone does with it
        sb3.PPO("MlpPolicy", blackjack, device="cpu")
    for policy in ("MlpPolicy", "CnnPolicy", "MultiInputPolicy", ActorCriticPolicy):
        with pytest.raises(ValueError, match=r"takes this observation space: it is a Tuple "
                           r"space.*gymnasium\.wrappers\.FlattenObservation"):  # fmt: skip
            check_sb3_policy(blackjack, policy)
    flat = gym.wrappers.FlattenObservation(blackjack)
    assert check_sb3_policy(flat, "MlpPolicy") == "MlpPolicy"
    sb3.PPO("MlpPolicy", flat, n_steps=16, batch_size=16, device="cpu")
    minigrid_env = gym.make("MiniGrid-Empty-5x5-v0")  # a Dict holding a MissionSpace
    with pytest.raises(TypeError):
        sb3.PPO("MultiInputPolicy", minigrid_env, device="cpu")
    with pytest.raises(ValueError, match=r"its Dict holds a MissionSpace under 'mission'"):
        check_sb3_policy(minigrid_env, "MultiInputPolicy")
    nested = gym.spaces.Dict(inner=gym.spaces.Dict(a=gym.spaces.Discrete(2)))
    with pytest.raises(ValueError, match=r"holds a Dict under 'inner'.*no nested spaces"):
        check_sb3_policy(nested, "MultiInputPolicy")


def minigrid_image_and_direction() -> gym.Env:
    """MiniGrid's Dict observation without its mission text: a 7x7 image and a direction."""
    env = gym.make("MiniGrid-Empty-5x5-v0")
    return gym.wrappers.FilterObservation(env, ["image", "direction"])


@pytest.mark.parametrize(
    ("make", "policy", "said", "fitting"),
    [
        (lambda: gym.make("CartPole-v1"), "MultiInputPolicy", "use 'MlpPolicy'", "MlpPolicy"),
        (lambda: gym.make("CartPole-v1"), "CnnPolicy", "use 'MlpPolicy'", "MlpPolicy"),
        (lambda: point_reach(fold_frames=True), "MultiInputPolicy", "use 'CnnPolicy'", None),
        (minigrid_image_and_direction, "MlpPolicy", "Pass 'MultiInputPolicy'", None),
        (minigrid_image_and_direction, "MultiInputPolicy", "'image' of this Dict with NatureCNN, "
         "which needs at least 36x36, got 7x7", None),
    ],
)  # fmt: skip
def test_a_policy_that_does_not_fit_the_space_is_named_with_the_one_that_does(
    make, policy, said, fitting
):
    env = make()
    with pytest.raises((ValueError, AttributeError, AssertionError, RuntimeError)):
        sb3.PPO(policy, env, n_steps=16, batch_size=16, device="cpu")  # SB3 refuses it too
    with pytest.raises(ValueError) as raised:
        check_sb3_policy(env, policy)
    assert policy in str(raised.value) and said in str(raised.value)
    if fitting:
        assert check_sb3_policy(env, fitting) == fitting
        sb3.PPO(fitting, env, n_steps=16, batch_size=16, device="cpu")


@pytest.mark.parametrize("given", [sb3.PPO, sb3.SAC, dict])
def test_a_class_that_is_no_policy_is_named_with_the_policy_names(given):
    space = gym.spaces.Box(0, 255, (84, 84, 3), np.uint8)
    algorithm = given is not dict
    said = "an SB3 algorithm, not a policy" if algorithm else r"no policy class \(no torch module\)"
    with pytest.raises(TypeError, match=rf"policy {given.__name__} is {said}; pass the policy's "
                       r"name \('CnnPolicy', 'MlpPolicy', 'MultiInputPolicy'\)"):  # fmt: skip
        check_sb3_policy(space, given)
    assert check_sb3_policy(space, ActorCriticCnnPolicy) is ActorCriticCnnPolicy
