"""Every wrapper records its constructor arguments: gym.make(env.spec) rebuilds the same chain."""

import gymnasium as gym
import numpy as np
import pytest
import shimmy

from simoun_wrappers import (
    ActionRepeat,
    FrameTriplet,
    MultiCamera,
    RandomConvolution,
    ResidualMotion,
    SimounObservation,
)

gym.register_envs(shimmy)


def _channel_first(env: gym.Env) -> gym.Env:
    env = gym.wrappers.ResizeObservation(gym.wrappers.AddRenderObservation(env), (16, 16))
    space = gym.spaces.Box(0, 255, (3, 16, 16), np.uint8)
    return gym.wrappers.TransformObservation(env, lambda o: o.transpose(2, 0, 1), space)


def _cartpole() -> gym.Env:
    return gym.make("CartPole-v1", render_mode="rgb_array")


CHAINS = {
    "FrameTriplet": lambda: FrameTriplet(gym.make("CartPole-v1"), num_frames=4),
    "ResidualMotion": lambda: ResidualMotion(FrameTriplet(_channel_first(_cartpole()), 2)),
    "ActionRepeat": lambda: ActionRepeat(gym.make("CartPole-v1"), repeat=3),
    "RandomConvolution": lambda: SimounObservation(RandomConvolution(_cartpole(), 5), size=16),
    "MultiCamera": lambda: MultiCamera(
        gym.make("dm_control/cartpole-swingup-v0"), ["lookatcart", 0], size=(12, 20)
    ),
    "SimounObservation": lambda: SimounObservation(
        _cartpole(), size=(12, 20), grayscale=True, num_frames=4, fold_frames=True
    ),
}


@pytest.mark.parametrize("name", list(CHAINS))
def test_spec_rebuilds_an_equal_env(name):
    env = CHAINS[name]()
    rebuilt = gym.make(env.spec)
    assert rebuilt.spec.additional_wrappers[-1].name == env.spec.additional_wrappers[-1].name
    assert rebuilt.observation_space == env.observation_space
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(3)]
    for a, b in [(env.reset(seed=2)[0], rebuilt.reset(seed=2)[0])] + [
        (env.step(action)[0], rebuilt.step(action)[0]) for action in actions
    ]:
        if isinstance(a, dict):
            assert a.keys() == b.keys()
            for key in a:
                np.testing.assert_array_equal(a[key], b[key])
        else:
            np.testing.assert_array_equal(a, b)
