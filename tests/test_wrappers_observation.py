"""SimounObservation on dm_control, highway-env, a rendered state env and MultiCamera."""

import gymnasium as gym
import highway_env
import numpy as np
import pytest
import shimmy
from gymnasium.utils.env_checker import check_env

from simoun_wrappers import MultiCamera, SimounObservation
from simoun_wrappers.motion import residual_motion

gym.register_envs(shimmy)
gym.register_envs(highway_env)

# check_env warns whenever it is given a wrapped env, which is the point here.
pytestmark = pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")

HIGHWAY_CONFIG = {
    "screen_width": 64,
    "screen_height": 48,
    "simulation_frequency": 5,
    "policy_frequency": 1,
    "vehicles_count": 5,
    "duration": 10,
}


def dm_cartpole(size: int = 48, **kwargs) -> gym.Env:
    render_kwargs = {"width": size, "height": size, "camera_id": 0}
    return gym.make(
        "dm_control/cartpole-swingup-v0", render_mode="rgb_array", render_kwargs=render_kwargs
    )


def _assert_triplets(env: gym.Env, steps: int = 3) -> dict:
    obs, _ = env.reset(seed=1)
    frames = obs["frames"]
    assert (frames[0] == frames[1]).all() and (frames[1] == frames[2]).all()
    for _ in range(steps):
        obs, *_ = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs)
    np.testing.assert_array_equal(obs["motion"], residual_motion(obs["frames"]))
    return obs


def test_check_env_dm_control_pixels_from_render():
    env = SimounObservation(dm_cartpole(), size=32)
    assert env.observation_space["frames"].shape == (3, 3, 32, 32)
    assert env.observation_space["motion"].shape == (6, 32, 32)
    check_env(env)
    obs = _assert_triplets(env)
    assert obs["frames"].std() > 5  # a real rendering, not a blank frame


def test_check_env_highway_rgb_from_render():
    env = SimounObservation(
        gym.make("highway-fast-v0", render_mode="rgb_array", config=HIGHWAY_CONFIG), size=32
    )
    check_env(env)
    obs = _assert_triplets(env)
    assert obs["frames"].std() > 5
    assert np.abs(obs["motion"]).max() > 0  # traffic moves


def test_check_env_state_env_rendered_grayscale_rectangular():
    env = SimounObservation(
        gym.make("CartPole-v1", render_mode="rgb_array"), size=(24, 36), grayscale=True
    )
    assert env.observation_space["frames"].shape == (3, 1, 24, 36)
    assert env.observation_space["motion"].shape == (2, 24, 36)
    check_env(env)
    _assert_triplets(env)


def test_check_env_multicamera_stack():
    cams = MultiCamera(dm_cartpole(), ["fixed", "lookatcart"], size=(32, 32))
    env = SimounObservation(cams, size=None)
    assert env.observation_space["frames"].shape == (3, 3, 32, 64)
    check_env(env)
    _assert_triplets(env)


def test_fold_frames_gives_an_sb3_image_box():
    from stable_baselines3.common.preprocessing import is_image_space

    env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), 32, fold_frames=True)
    assert env.observation_space == gym.spaces.Box(0, 255, (9, 32, 32), np.uint8)
    assert is_image_space(env.observation_space, check_channels=False)
    obs, _ = env.reset(seed=0)
    for _ in range(2):
        obs, *_ = env.step(1)
    stack = obs.reshape(3, 3, 32, 32)
    assert not (stack[1] == stack[2]).all()
    check_env(env)


def test_motion_off_keeps_only_frames():
    env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), 16, motion=False)
    assert list(env.observation_space) == ["frames"]
    obs, _ = env.reset(seed=0)
    assert set(obs) == {"frames"}


def test_image_observations_are_used_directly():
    env = SimounObservation(
        gym.wrappers.AddRenderObservation(gym.make("CartPole-v1", render_mode="rgb_array")),
        size=16,
    )
    assert env.metadata["render_modes"] == ["human", "rgb_array"]  # not narrowed: no render
    obs, _ = env.reset(seed=0)
    assert obs["frames"].shape == (3, 3, 16, 16)


def test_spec_rebuilds_the_same_chain():
    env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), 16, grayscale=True)
    assert [w.name for w in env.spec.additional_wrappers] == ["SimounObservation"]
    rebuilt = gym.make(env.spec)
    a, _ = env.reset(seed=3)
    b, _ = rebuilt.reset(seed=3)
    np.testing.assert_array_equal(a["frames"], b["frames"])
    assert rebuilt.observation_space == env.observation_space


def test_error_without_pixels_names_render_mode():
    with pytest.raises(ValueError, match=r"neither image observations.*render_mode='rgb_array'"):
        SimounObservation(gym.make("CartPole-v1"))


def test_error_non_uint8_image_names_conversion():
    space = gym.spaces.Box(0.0, 1.0, (16, 16, 3), np.float32)
    env = gym.wrappers.TransformObservation(
        gym.wrappers.ResizeObservation(
            gym.wrappers.AddRenderObservation(gym.make("CartPole-v1", render_mode="rgb_array")),
            (16, 16),
        ),
        lambda o: o.astype(np.float32) / 255,
        space,
    )
    with pytest.raises(TypeError, match=r"uint8 images.*float32.*astype\(np.uint8\)"):
        SimounObservation(env, source="observation")
    plain = gym.make("CartPole-v1")
    float_images = gym.wrappers.TransformObservation(
        plain, lambda o: np.zeros((16, 16, 3), np.float32), space
    )
    with pytest.raises(TypeError, match=r"uint8 images"):
        SimounObservation(float_images)


def test_error_motion_with_one_frame_names_the_fix():
    with pytest.raises(ValueError, match=r"at least 2 frames.*num_frames=3.*motion=False"):
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), num_frames=1)
    env = SimounObservation(
        gym.make("CartPole-v1", render_mode="rgb_array"), 16, num_frames=1, motion=False
    )
    assert env.observation_space["frames"].shape == (1, 3, 16, 16)


def test_a_size_given_as_a_numpy_array_is_taken_and_recorded_as_python_ints():
    env = SimounObservation(
        gym.make("CartPole-v1", render_mode="rgb_array"), size=np.array([16, 24])
    )
    assert env.observation_space["frames"].shape == (3, 3, 16, 24)
    assert env.spec.additional_wrappers[-1].kwargs["size"] == (16, 24)
    env.spec.to_json()
    square = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=np.array(16))
    assert square.observation_space["frames"].shape == (3, 3, 16, 16)
    with pytest.raises(ValueError, match=r"size must be a positive int or an \(H, W\) pair"):
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=np.ones((2, 2)))


def test_error_bad_size_and_source():
    with pytest.raises(ValueError, match=r"size must be.*size=84"):
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=(0, 4))
    with pytest.raises(ValueError, match=r"source must be one of"):
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), source="camera")
    with pytest.raises(ValueError, match=r"num_frames must be a positive int.*use 3"):
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), num_frames=0)
    with pytest.raises(TypeError, match=r"needs image observations.*source='render'"):
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), source="observation")


@pytest.mark.parametrize("grayscale", [False, True])
def test_frames_equal_gymnasiums_own_chain_channel_first(grayscale):
    def render_env() -> gym.Env:
        return gym.make("CartPole-v1", render_mode="rgb_array", max_episode_steps=8)

    ours = SimounObservation(render_env(), size=(20, 30), grayscale=grayscale)
    ref = gym.wrappers.ResizeObservation(gym.wrappers.AddRenderObservation(render_env()), (20, 30))
    if grayscale:
        ref = gym.wrappers.GrayscaleObservation(ref, keep_dim=True)
    ref = gym.wrappers.FrameStackObservation(ref, 3, padding_type="reset")
    obs, _ = ours.reset(seed=0)
    expected, _ = ref.reset(seed=0)
    for t in range(12):  # past the time limit: one reset inside the loop
        np.testing.assert_array_equal(obs["frames"], expected.transpose(0, 3, 1, 2))
        np.testing.assert_array_equal(obs["motion"], residual_motion(obs["frames"]))
        obs, _, terminated, truncated, _ = ours.step(t % 2)
        expected, *_ = ref.step(t % 2)
        if terminated or truncated:
            obs, _ = ours.reset(seed=1)
            expected, _ = ref.reset(seed=1)


def test_a_wrapper_that_changed_the_render_mode_is_named_with_the_order_that_works():
    collected = gym.wrappers.RenderCollection(gym.make("Pendulum-v1", render_mode="rgb_array"))
    with pytest.raises(
        ValueError,
        match=r"RenderCollection turned the render mode 'rgb_array' into 'rgb_array_list'.*"
        r"RenderCollection\(SimounObservation\(env, ...\)\)",
    ):
        SimounObservation(collected, size=16)
    right = gym.wrappers.RenderCollection(
        SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=16)
    )
    right.reset(seed=0)
    right.step(right.action_space.sample())
    assert len(right.render()) == 2


def test_render_mode_rgb_array_list_names_the_render_mode_that_works():
    with pytest.raises(ValueError) as error:
        SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array_list"), size=16)
    said = str(error.value)
    assert "gym.make adds it for render_mode='rgb_array_list'" in said
    assert "gym.make(env_id, render_mode='rgb_array')" in said


@pytest.mark.parametrize("call", ["step", "reset"])
def test_a_reset_or_step_after_close_is_refused(call):
    from simoun_wrappers import RandomConvolution

    for make in (lambda e: SimounObservation(e, size=16), RandomConvolution):
        env = make(gym.make("Pendulum-v1", render_mode="rgb_array"))
        env.reset(seed=0)
        env.close()
        name = type(env).__name__
        with pytest.raises(ValueError, match=rf"Cannot call {name}\.{call}\(\) after close\(\)"):
            env.step(env.action_space.sample()) if call == "step" else env.reset(seed=0)
