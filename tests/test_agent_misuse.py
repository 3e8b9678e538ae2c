"""SimounAgent and FrameReplay misuse: each a clear error
or the right result, on real environments."""

import gymnasium as gym
import highway_env
import minigrid
import numpy as np
import pytest

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent import AgentConfig, FrameReplay, SimounAgent
from simoun_wrappers import SimounObservation

gym.register_envs(highway_env)
gym.register_envs(minigrid)

SIZE = 32


def point_reach_replay(steps: int, seed: int = 0) -> FrameReplay:
    """A replay of PointReach frames taken with random actions."""
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=None, motion=False)
    replay = FrameReplay(capacity=50, frame_shape=(3, SIZE, SIZE), action_dim=2, seed=seed)
    obs, _ = env.reset(seed=seed)
    replay.start_episode(obs["frames"][-1])
    env.action_space.seed(seed)
    for _ in range(steps):
        action = env.action_space.sample()
        obs, reward, terminated, truncated, _ = env.step(action)
        replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            obs, _ = env.reset()
            replay.start_episode(obs["frames"][-1])
    return replay


def test_load_on_an_instance_fills_that_instance(tmp_path):
    saved = point_reach_replay(steps=30, seed=1)
    path = tmp_path / "replay.npz"
    saved.save(path)
    target = FrameReplay(capacity=50, frame_shape=(3, SIZE, SIZE), action_dim=2)
    assert len(target) == 0
    assert target.load(path) is target
    assert len(target) == len(saved) == 30
    fresh = FrameReplay.load(path)
    for _ in range(2):
        a, b, c = saved.sample(8), target.sample(8), fresh.sample(8)
        for key in a:
            np.testing.assert_array_equal(a[key], b[key])
            np.testing.assert_array_equal(a[key], c[key])


def test_load_into_a_buffer_of_another_shape_names_both(tmp_path):
    path = tmp_path / "replay.npz"
    point_reach_replay(steps=5).save(path)
    other = FrameReplay(capacity=50, frame_shape=(3, 48, 48), action_dim=2)
    with pytest.raises(
        ValueError,
        match=r"frame_shape \(3, 32, 32\) in the file, \(3, 48, 48\) here.*"
        r"FrameReplay\.load\(path\).*frame_shape=\(3, 32, 32\)",
    ):
        other.load(path)
    assert len(other) == 0
    smaller = FrameReplay(capacity=10, frame_shape=(3, SIZE, SIZE), action_dim=1)
    with pytest.raises(ValueError, match=r"capacity 50 in the file, 10 here; action_dim 2"):
        smaller.load(path)


def test_act_on_the_whole_observation_dict_says_pass_frames():
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=None)
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=AgentConfig(batch_size=8))
    obs, _ = env.reset(seed=0)
    with pytest.raises(ValueError, match=r"whole dict \(keys \['frames', 'motion'\]\).*"
                       r"agent\.act\(obs\['frames'\]\)"):  # fmt: skip
        agent.act(obs)
    assert agent.act(obs["frames"]).shape == (2,)


@pytest.mark.parametrize(
    "make", [lambda: gym.make("highway-fast-v0"), lambda: gym.make("MiniGrid-Empty-5x5-v0")]
)
def test_discrete_action_space_is_refused_with_what_to_do(make):
    space = make().action_space
    assert isinstance(space, gym.spaces.Discrete)
    with pytest.raises(ValueError, match=r"continuous actions \(a 1-D Box\).*ContinuousAction.*"
                       r"fold_frames=True"):  # fmt: skip
        SimounAgent((3, 48, 48), action_dim=space)
