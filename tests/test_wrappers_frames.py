"""FrameTriplet, ResidualMotion and ActionRepeat on real environments."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.wrappers import AddRenderObservation, FrameStackObservation, ResizeObservation

from simoun_wrappers import ActionRepeat, FrameTriplet, ResidualMotion
from simoun_wrappers.motion import residual_motion


def _pixel_cartpole() -> gym.Env:
    env = gym.make("CartPole-v1", render_mode="rgb_array")
    return ResizeObservation(AddRenderObservation(env), (24, 32))


@pytest.mark.parametrize("num_frames", [2, 3, 4])
def test_frame_triplet_equals_frame_stack_over_episodes(num_frames):
    ours = FrameTriplet(_pixel_cartpole(), num_frames)
    ref = FrameStackObservation(_pixel_cartpole(), num_frames, padding_type="reset")
    assert ours.observation_space == ref.observation_space
    actions = np.random.default_rng(0).integers(0, 2, size=200)
    episodes, step = 0, 0
    for seed in range(3):
        a, _ = ours.reset(seed=seed)
        b, _ = ref.reset(seed=seed)
        np.testing.assert_array_equal(a, b)
        done = False
        while not done:
            a, ra, ta, ua, _ = ours.step(actions[step % len(actions)])
            b, rb, tb, ub, _ = ref.step(actions[step % len(actions)])
            np.testing.assert_array_equal(a, b)
            assert (ra, ta, ua) == (rb, tb, ub)
            done, step = ta or ua, step + 1
        episodes += 1
    assert episodes == 3 and step > 3 * num_frames


def test_frame_triplet_returns_fresh_arrays():
    env = FrameTriplet(gym.make("CartPole-v1"))
    first, _ = env.reset(seed=0)
    kept = first.copy()
    second, *_ = env.step(0)
    third, *_ = env.step(1)
    assert not np.shares_memory(second, third)
    np.testing.assert_array_equal(first, kept)
    np.testing.assert_array_equal(third[:2], second[1:])


def test_frame_triplet_rejects_non_box():
    with pytest.raises(TypeError, match=r"Box observations.*SimounObservation"):
        FrameTriplet(gym.make("Blackjack-v1"))


def test_residual_motion_is_exact_with_negative_differences():
    frames = np.array([250, 3, 255, 0], dtype=np.uint8).reshape(4, 1, 1, 1)
    frames = np.broadcast_to(frames, (4, 2, 2, 3)).copy()
    frames[:, 1] = frames[:, 1][::-1]  # second channel runs the other way
    motion = residual_motion(frames)
    assert motion.dtype == np.int16 and motion.shape == (6, 2, 3)
    np.testing.assert_array_equal(motion[::2, 0, 0], [-247, 252, -255])
    np.testing.assert_array_equal(motion[1::2, 0, 0], [255, -252, 247])
    batch = np.stack([frames, frames[::-1]])
    np.testing.assert_array_equal(residual_motion(batch)[0], motion)


def test_residual_motion_wrapper_on_random_frames():
    env = ResidualMotion(FrameTriplet(_channel_first_cartpole()))
    obs, _ = env.reset(seed=0)
    assert not obs["motion"].any()  # reset padding: no motion yet
    for _ in range(3):
        obs, *_ = env.step(1)
    expected = obs["frames"][1:].astype(np.int32) - obs["frames"][:-1].astype(np.int32)
    np.testing.assert_array_equal(obs["motion"], expected.reshape(6, 24, 32))
    assert obs["motion"].min() < 0 < obs["motion"].max()
    assert env.observation_space.contains(obs)


def _channel_first_cartpole() -> gym.Env:
    space = gym.spaces.Box(0, 255, (3, 24, 32), np.uint8)
    return gym.wrappers.TransformObservation(
        _pixel_cartpole(), lambda o: o.transpose(2, 0, 1), space
    )


def test_residual_motion_errors_name_the_fix():
    with pytest.raises(TypeError, match=r"uint8 Box of shape"):
        ResidualMotion(FrameTriplet(gym.make("CartPole-v1")))
    with pytest.raises(ValueError, match=r"at least 2 stacked frames.*FrameTriplet"):
        ResidualMotion(FrameTriplet(_channel_first_cartpole(), num_frames=1))
    with pytest.raises(TypeError, match=r"uint8 frames"):
        residual_motion(np.zeros((3, 1, 2, 2), dtype=np.float32))
    with pytest.raises(ValueError, match=r"k >= 2"):
        residual_motion(np.zeros((1, 1, 2, 2), dtype=np.uint8))


def test_action_repeat_sums_rewards_and_stops_at_episode_end():
    # The time limit ends the episode at inner step 6, in the middle of the second agent step.
    env = ActionRepeat(gym.make("CartPole-v1", max_episode_steps=6), repeat=4)
    ref = gym.make("CartPole-v1", max_episode_steps=6)
    env.reset(seed=0)
    ref.reset(seed=0)
    obs, reward, terminated, truncated, _ = env.step(1)
    assert (reward, terminated, truncated) == (4.0, False, False)
    obs, reward, terminated, truncated, _ = env.step(0)
    assert (reward, terminated, truncated) == (2.0, False, True)  # 2 inner steps, not 4
    for action in [1] * 4 + [0] * 2:
        expected, *_ = ref.step(action)
    np.testing.assert_array_equal(obs, expected)  # the last inner step's observation
    with pytest.raises(ValueError, match=r"positive int.*ActionRepeat\(env, 8\)"):
        ActionRepeat(gym.make("CartPole-v1"), repeat=0)
