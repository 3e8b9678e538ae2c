"""CuriosityModel (online L_tran + L_con features) and AgentFeatures on real envs."""

import gymnasium as gym
import numpy as np
import pytest
import torch

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent import AgentConfig, SimounAgent
from simoun_agent.curiosity_model import (
    AgentFeatures,
    CuriosityConfig,
    CuriosityModel,
    encode_actions,
)
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity import FeatureSource
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)

TINY = dict(num_filters=8, feature_dim=16, aux_hidden_dim=64, seed=0)


def point_reach():
    return SimounObservation(gym.make("simoun/PointReach-v0"), size=None)


def test_losses_fall_over_a_short_run_on_a_real_env():
    env = point_reach()
    config = CuriosityConfig(
        **TINY, batch_size=32, capacity=400, learning_starts=100, update_every=1
    )
    model = CuriosityModel.for_env(env, config, device="cpu")
    env = ConsistencyCuriosityReward(env, model)
    env.reset(seed=0)
    env.action_space.seed(0)
    history = []
    for _ in range(260):
        *_, terminated, truncated, _ = env.step(env.action_space.sample())
        if model.updates > len(history):
            history.append(model.last_metrics)
        if terminated or truncated:
            env.reset()
    # 161 steps started (calls 100..260), the last one's weights published at the next call
    assert model.updates == len(history) == 160 and model.pending
    first, last = history[:15], history[-15:]
    for name in ("transition_loss", "contrastive_loss", "motion_contrastive_loss"):
        before = np.mean([m[name] for m in first])
        after = np.mean([m[name] for m in last])
        assert after < 0.8 * before, (name, before, after)
    # the motion path has not collapsed to a constant that G predicts trivially
    assert np.mean([m["motion_std"] for m in last]) > 0.2


def test_one_watch_call_triggers_at_most_one_update_of_one_batch():
    config = CuriosityConfig(**TINY, batch_size=8, capacity=64, learning_starts=16, update_every=3)
    model = CuriosityModel((3, 24, 24), gym.spaces.Box(-2, 2, (1,)), config, device="cpu")
    rng = np.random.default_rng(0)
    updates = []
    for _ in range(12):
        triplets = rng.integers(0, 256, (40, 3, 3, 24, 24), dtype=np.uint8)
        before = model.updates
        model.watch(triplets, rng.uniform(-2, 2, (40, 1)), triplets, *np.zeros((2, 40), bool))
        updates.append(model.updates - before)
    # the step started at call 3 is published at call 6, and so on
    assert updates == [0, 0, 0] + [0, 0, 1] * 3 and model.pending
    assert model.size == 64


def test_features_are_float32_deterministic_and_checked():
    triplets = np.random.default_rng(1).integers(0, 256, (5, 3, 1, 24, 24), dtype=np.uint8)
    space = gym.spaces.Discrete(3)
    a = CuriosityModel((1, 24, 24), space, CuriosityConfig(**TINY), device="cpu")
    b = CuriosityModel((1, 24, 24), space, CuriosityConfig(**TINY), device="cpu")
    assert isinstance(a, FeatureSource)
    f_m, f_a = a(triplets)
    assert f_m.shape == (5, 16) and f_a.shape == (5, 3, 16) and f_m.dtype == np.float32
    np.testing.assert_array_equal(f_m, b(triplets)[0])
    with pytest.raises(ValueError, match=r"uint8 \(B, 3, 1, 24, 24\)"):
        a(triplets.astype(np.float32))
    with pytest.raises(ValueError, match="for_env"):
        a(triplets[:, :, :, :10])


def test_state_dict_restores_the_features_and_counters():
    env = point_reach()
    config = CuriosityConfig(**TINY, batch_size=8, capacity=32, learning_starts=8, update_every=1)
    model = CuriosityModel.for_env(env, config, device="cpu")
    env = ConsistencyCuriosityReward(env, model)
    obs, _ = env.reset(seed=0)
    for _ in range(12):
        obs, *_ = env.step(env.action_space.sample())
    fresh = CuriosityModel.for_env(env, CuriosityConfig(**{**TINY, "seed": 5}), device="cpu")
    fresh.load_state_dict(model.state_dict())
    np.testing.assert_array_equal(fresh(obs["frames"][None])[1], model(obs["frames"][None])[1])
    assert (fresh.updates, fresh.watch_calls) == (model.updates, model.watch_calls) == (4, 12)


def test_actions_are_encoded_for_the_transition_model():
    one_hot = encode_actions(gym.spaces.Discrete(3, start=1), np.array([1, 3]))
    np.testing.assert_array_equal(one_hot, [[1, 0, 0], [0, 0, 1]])
    multi = encode_actions(gym.spaces.MultiDiscrete([3, 2], start=[1, -1]), np.array([[3, -1]]))
    np.testing.assert_array_equal(multi, [[0, 0, 1, 1, 0]])
    scaled = encode_actions(gym.spaces.Box(0.0, 4.0, (2,)), np.array([[0.0, 2.0], [4.0, 1.0]]))
    np.testing.assert_allclose(scaled, [[-1, 0], [1, -0.5]])
    with pytest.raises(TypeError, match="action spaces"):
        CuriosityModel((3, 24, 24), gym.spaces.Text(4), device="cpu")


def test_vector_wrapper_feeds_one_model_with_every_sub_env():
    envs = gym.make_vec(
        "simoun/PointReach-v0",
        num_envs=4,
        vectorization_mode="sync",
        wrappers=[lambda e: SimounObservation(e, size=None)],
    )
    config = CuriosityConfig(
        **TINY, batch_size=16, capacity=128, learning_starts=16, update_every=2
    )
    model = CuriosityModel.for_env(envs, config, device="cpu")
    envs = ConsistencyCuriosityVectorReward(envs, model)
    envs.reset(seed=0)
    for _ in range(10):
        _, _, _, _, info = envs.step(envs.action_space.sample())
    assert model.size == 40 and model.updates == 3 and model.pending
    assert np.all(info["reward_intrinsic"] > 0)
    envs.close()


def test_agent_features_expose_a_simoun_agents_encoder():
    torch.manual_seed(0)  # the agent's weights, so the step's reward does not hang on test order
    env = point_reach()
    agent = SimounAgent(
        (3, 32, 32),
        action_dim=2,
        config=AgentConfig(num_filters=8, feature_dim=16, hidden_dim=32, batch_size=8),
        device="cpu",
    )
    features = AgentFeatures(agent)
    env = ConsistencyCuriosityReward(env, features)
    obs, _ = env.reset(seed=0)
    obs, _, _, _, info = env.step(np.array([0.5, -0.5], dtype=np.float32))
    f_m, f_a = features(obs["frames"][None])
    expected_m, expected_a = agent.encoder_features(obs["frames"][None])
    np.testing.assert_array_equal(f_m, expected_m.numpy())
    np.testing.assert_array_equal(f_a, expected_a.numpy())
    assert f_a.shape == (1, 3, 16) and info["reward_intrinsic"] > 0
    with pytest.raises(TypeError, match="encoder_features"):
        AgentFeatures(torch.nn.Linear(2, 2))


def test_a_random_conv_kernel_wider_than_the_encoded_frames_is_refused_when_built():
    space = gym.spaces.Box(-2, 2, (1,))
    wide = CuriosityConfig(**{**TINY, "random_conv_kernel": 33})
    with pytest.raises(ValueError) as error:
        CuriosityModel((3, 32, 32), space, wide, device="cpu")
    assert "CuriosityConfig.random_conv_kernel=33 (or lower it, e.g. to 3) need H, W >= 33" in (
        str(error.value)
    )
    CuriosityModel((3, 32, 32), space, CuriosityConfig(**{**TINY, "random_conv_kernel": 31}), "cpu")
    off = CuriosityConfig(**{**TINY, "random_conv_kernel": 33, "contrastive_weight": 0.0})
    CuriosityModel((3, 32, 32), space, off, device="cpu")
