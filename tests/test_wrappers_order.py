"""Wrapper order: a wrapper that belongs under the frame stack refuses to go over it,
naming the order to use, and the right order does what the wrong one silently would not."""

import gymnasium as gym
import numpy as np
import pytest
import shimmy
from gymnasium.wrappers import FrameStackObservation

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_wrappers import (
    ActionRepeat,
    FrameTriplet,
    MultiCamera,
    RandomConvolution,
    SimounObservation,
)

gym.register_envs(shimmy)


def point_reach() -> gym.Env:
    return gym.make("simoun/PointReach-v0", max_steps=50)


def dm_cartpole() -> gym.Env:
    return gym.make(
        "dm_control/cartpole-swingup-v0",
        render_mode="rgb_array",
        render_kwargs={"width": 32, "height": 32, "camera_id": 0},
    )


@pytest.mark.parametrize(
    "stacked",
    [
        lambda: SimounObservation(point_reach(), size=32),
        lambda: SimounObservation(point_reach(), size=32, fold_frames=True),
        lambda: FrameTriplet(point_reach()),
        lambda: FrameStackObservation(point_reach(), 3),
    ],
    ids=["simoun", "folded", "triplet", "gymnasium-stack"],
)
def test_action_repeat_over_a_frame_stack_names_the_right_order(stacked):
    with pytest.raises(
        TypeError, match=r"ActionRepeat goes under.*SimounObservation\(ActionRepeat\(env, 4\)"
    ):
        ActionRepeat(stacked(), 4)


def test_action_repeat_under_the_stack_fills_the_triplet_with_decisions():
    env = SimounObservation(ActionRepeat(point_reach(), 4), size=32, motion=False)
    reference = point_reach()
    obs, _ = env.reset(seed=5)
    image, _ = reference.reset(seed=5)
    seen = [image]
    for action in ([1.0, 0.0], [0.0, -1.0]):
        obs, *_ = env.step(np.array(action, np.float32))
        for _ in range(4):
            image, *_ = reference.step(np.array(action, np.float32))
        seen.append(image)
    expected = np.stack(seen).transpose(0, 3, 1, 2)
    np.testing.assert_array_equal(obs["frames"], expected)
    assert not (expected[1] == expected[2]).all()  # the dot moved between decisions


def test_multicamera_over_simoun_observation_names_the_right_order():
    with pytest.raises(
        TypeError, match=r"MultiCamera goes under.*SimounObservation\(MultiCamera\(env, cameras\)"
    ):
        MultiCamera(SimounObservation(dm_cartpole(), size=32), [0, 1], size=32)
    right = SimounObservation(MultiCamera(dm_cartpole(), [0, 1], size=32), size=None)
    obs, _ = right.reset(seed=0)
    assert obs["frames"].shape == (3, 3, 32, 64)
    assert obs["motion"].shape == (6, 32, 64)


def test_multicamera_over_random_convolution_names_the_right_order():
    with pytest.raises(TypeError, match=r"RandomConvolution\(MultiCamera\(env, cameras\)\)"):
        MultiCamera(RandomConvolution(dm_cartpole()), [0, 1], size=32)
    plain = MultiCamera(dm_cartpole(), [0, 1], size=32)
    convolved = RandomConvolution(MultiCamera(dm_cartpole(), [0, 1], size=32))
    a, _ = plain.reset(seed=0)
    b, _ = convolved.reset(seed=0)
    assert a.shape == b.shape == (32, 64, 3)
    assert np.abs(a.astype(int) - b).mean() > 5  # the convolution reached both views


@pytest.mark.parametrize(
    "stacked",
    [
        lambda: SimounObservation(point_reach(), size=32),
        lambda: FrameStackObservation(point_reach(), 3),
    ],
    ids=["simoun", "gymnasium-stack"],
)
def test_simoun_observation_over_a_frame_stack_is_refused(stacked):
    with pytest.raises(TypeError, match=r"stacks frames itself.*Apply SimounObservation once"):
        SimounObservation(stacked(), size=32)
