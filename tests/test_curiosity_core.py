"""Eq. 13 core (simoun_wrappers.curiosity): hand computations and the running maxima."""

import math
import pickle

import gymnasium as gym
import numpy as np
import pytest
import torch

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity import RunningMax, consistency_distance, consistency_reward
from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward

F_M = np.array([[1.0, -2.0, 0.5], [0.0, 0.0, 0.0]], dtype=np.float32)
F_A = np.array(
    [
        [[0.0, 0.0, 0.0], [1.0, -1.0, 2.0], [0.0, 1.0, 2.0]],
        [[3.0, 3.0, 3.0], [3.0, 3.0, 3.0], [3.0, 3.0, 3.0]],
    ],
    dtype=np.float32,
)


def _hand_distance():
    # sample 0: |f_m| = [1, 2, .5]; |a1-a0| + |a2-a1| = [1, 1, 2] + [1, 2, 0] = [2, 3, 2]
    # diff = [-1, -1, -1.5] -> sqrt(1 + 1 + 2.25); sample 1: all zero -> 0
    return np.array([math.sqrt(4.25), 0.0])


def test_distance_matches_hand_computation_numpy():
    d = consistency_distance(F_M, F_A)
    assert d.shape == (2,) and d.dtype == np.float32
    np.testing.assert_allclose(d, _hand_distance(), rtol=1e-6)


def test_distance_and_reward_match_on_torch_without_leaving_the_tensor_world():
    d = consistency_distance(torch.from_numpy(F_M), torch.from_numpy(F_A))
    assert isinstance(d, torch.Tensor)
    np.testing.assert_allclose(d.numpy(), _hand_distance(), rtol=1e-6)
    r = consistency_reward(d, torch.tensor(1000.0), torch.tensor(3.0), torch.tensor(2.0))
    assert isinstance(r, torch.Tensor) and r.shape == (2,)
    expected = 0.2 * math.exp(-2e-5 * 1000) * _hand_distance() * 3.0 / 2.0
    np.testing.assert_allclose(r.numpy(), expected, rtol=1e-6)


def test_reward_is_eq13_and_decays_with_step():
    d = _hand_distance()
    r0 = consistency_reward(d, 0, r_e_max=4.0, r_i_max=2.0, scale=0.5, decay=1e-3)
    np.testing.assert_allclose(r0, 0.5 * d * 4.0 / 2.0)
    r1 = consistency_reward(d, 1000, r_e_max=4.0, r_i_max=2.0, scale=0.5, decay=1e-3)
    np.testing.assert_allclose(r1, r0 * math.exp(-1.0))
    assert r1[0] < r0[0]


def test_bad_feature_shapes_are_named():
    with pytest.raises(ValueError, match=r"f_a must have shape \(B, 3, D\)"):
        consistency_distance(F_M, F_A[:, :2])
    with pytest.raises(ValueError, match="f_m must have shape"):
        consistency_distance(F_M[:, :2], F_A)


def test_running_max_tracks_magnitude_of_extrinsic_and_raw_distance():
    stats = RunningMax(r_e_max=0.5, r_i_max=0.1)
    stats.update(np.array([-3.0, 1.0]), np.array([0.05]))
    assert stats.r_e_max == 3.0 and stats.r_i_max == 0.1
    stats.update(np.array([2.0]), np.array([0.7, 0.2]))
    assert stats.r_e_max == 3.0 and stats.r_i_max == pytest.approx(0.7)
    stats.update(np.array([]), np.array([]))
    assert stats.r_e_max == 3.0


def test_update_before_reward_bounds_intrinsic_by_scale_times_r_e_max():
    rng = np.random.default_rng(0)
    stats = RunningMax(r_e_max=1e-3, r_i_max=1e-3)
    for step in range(50):
        r_e = rng.normal(size=8)
        d = rng.exponential(size=8) * (step + 1)
        stats.update(r_e, d)
        r_i = consistency_reward(d, step, stats.r_e_max, stats.r_i_max, scale=0.2, decay=0.0)
        assert np.all(r_i <= 0.2 * stats.r_e_max + 1e-12)


def test_running_max_rejects_bad_values_with_a_fix():
    with pytest.raises(ValueError, match="finite number > 0"):
        RunningMax(r_e_max=0.0)
    stats = RunningMax()
    with pytest.raises(ValueError, match="NaN or inf extrinsic reward"):
        stats.update(np.array([np.nan]), np.array([1.0]))
    with pytest.raises(ValueError, match="NaN or inf consistency distance"):
        stats.update(np.array([1.0]), np.array([np.inf]))
    assert stats.state_dict() == {"r_e_max": 1.0, "r_i_max": 1.0}


def test_running_max_on_tensors_stays_a_0d_tensor():
    stats = RunningMax(r_e_max=2.0, r_i_max=1.0).to("cpu")
    stats.update(torch.tensor([-5.0, 1.0]), torch.tensor([0.5]))
    assert isinstance(stats.r_e_max, torch.Tensor) and stats.r_e_max.shape == ()
    assert float(stats.r_e_max) == 5.0 and float(stats.r_i_max) == 1.0
    plain = RunningMax()
    plain.update(torch.tensor([3.0]), torch.tensor([4.0]))
    assert isinstance(plain.r_i_max, torch.Tensor) and float(plain.r_i_max) == 4.0


@pytest.mark.parametrize("value", ["x", None, 0.0, float("inf"), True])
def test_a_maximum_that_is_no_finite_number_above_zero_is_named(value):
    with pytest.raises(ValueError, match=r"RunningMax\.r_i_max must be a finite number > 0"):
        RunningMax(r_i_max=value)


def test_state_dict_round_trip_and_pickle():
    stats = RunningMax(r_e_max=1.0, r_i_max=1.0)
    stats.update(np.array([7.0]), np.array([3.0]))
    clone = pickle.loads(pickle.dumps(stats))
    assert clone == stats
    on_device = RunningMax().to("cpu")
    on_device.load_state_dict(stats.state_dict())
    assert isinstance(on_device.r_e_max, torch.Tensor)
    assert on_device.state_dict() == {"r_e_max": 7.0, "r_i_max": 3.0}
    for state, said in [
        ({"r_e_max": 1.0}, "it lacks r_i_max"),
        ({"r_e_max": 1.0, "r_i_max": None}, "its r_i_max is None, not a finite number > 0"),
        ({"r_e_max": float("nan"), "r_i_max": 1.0}, "its r_e_max is nan"),
        ({"r_e_max": 1.0, "r_i_max": -2}, "its r_i_max is -2"),
        (None, "it is a NoneType, not a dict"),
    ]:
        with pytest.raises(ValueError, match=rf"cannot load this state: {said}.*Nothing was"):
            on_device.load_state_dict(state)
        assert on_device.state_dict() == {"r_e_max": 7.0, "r_i_max": 3.0}
    on_device.load_state_dict({"r_e_max": torch.tensor(2.0), "r_i_max": np.float32(4.0)})
    assert on_device.state_dict() == {"r_e_max": 2.0, "r_i_max": 4.0}


def test_the_wrapper_scores_a_plain_function_source_by_eq13_and_refuses_a_non_source():
    """FeatureSource is the wrappers' contract: any callable giving (f_m, f_a) drives Eq. 13, an
    object that is not one is refused with the protocol spelled out."""
    projection = np.random.default_rng(0).normal(size=(16 * 16 * 3, 4)) / 500

    def project(triplets):
        f_a = triplets.reshape(*triplets.shape[:2], -1).astype(np.float64) @ projection
        return (f_a[:, 2] - f_a[:, 1] + 0.3).astype(np.float32), f_a.astype(np.float32)

    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=16, motion=False)
    env = ConsistencyCuriosityReward(env, project, scale=0.5, decay=1e-3, r_i_max_init=1e-3)
    env.reset(seed=0)
    next_obs, reward, *_, info = env.step(np.array([0.5, -0.5], np.float32))
    f_m, f_a = (x.astype(np.float64) for x in project(next_obs["frames"][None]))
    flow = np.abs(f_a[:, 1] - f_a[:, 0]) + np.abs(f_a[:, 2] - f_a[:, 1])
    d = np.sqrt(((np.abs(f_m) - flow) ** 2).sum())
    r_e = info["reward_extrinsic"]
    expected = 0.5 * math.exp(-1e-3 * 0) * d * max(1.0, abs(r_e)) / max(1e-3, d)
    assert info["reward_intrinsic"] == pytest.approx(expected, rel=1e-5)
    assert reward == pytest.approx(r_e + expected, rel=1e-6)
    with pytest.raises(TypeError, match=r"must be a FeatureSource \(callable"):
        ConsistencyCuriosityReward(env, object())
