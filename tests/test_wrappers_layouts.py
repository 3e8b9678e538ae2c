"""What SimounObservation takes as pixels: RGBA (alpha dropped), a Dict's "pixels"
entry over render(); refused with the conversion to make: MiniGrid's object-id grid, channel-first
planes and stacked grayscale frames."""

import gymnasium as gym
import highway_env
import minigrid
import numpy as np
import pytest
from dm_control import suite
from dm_control.suite.wrappers import pixels
from gymnasium.spaces import Box
from gymnasium.wrappers import TransformObservation
from minigrid.wrappers import ImgObsWrapper, RGBImgObsWrapper, RGBImgPartialObsWrapper
from shimmy import DmControlCompatibilityV0

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_wrappers import RandomConvolution, SimounObservation

gym.register_envs(highway_env)
gym.register_envs(minigrid)


def minigrid_env() -> gym.Env:
    return gym.make("MiniGrid-Empty-5x5-v0", render_mode="rgb_array")


def point_reach(render_mode: str | None = None) -> gym.Env:
    return gym.make("simoun/PointReach-v0", render_mode=render_mode)


def test_minigrid_object_grid_is_refused_naming_the_pixel_wrapper():
    grid = ImgObsWrapper(minigrid_env())
    assert grid.observation_space == Box(0, 255, (7, 7, 3), np.uint8)  # looks like an image
    fix = r"ImgObsWrapper\(RGBImgPartialObsWrapper\(env\)\).*RGBImgObsWrapper.*source='render'"
    for wrapper in (SimounObservation, RandomConvolution):
        with pytest.raises(TypeError, match=r"object ids.*not an image.*" + fix):
            wrapper(grid)


def test_minigrid_pixel_wrappers_and_renders_are_taken():
    partial = ImgObsWrapper(RGBImgPartialObsWrapper(minigrid_env()))
    env = SimounObservation(partial, size=None, motion=False)
    obs, _ = env.reset(seed=0)
    image, _ = ImgObsWrapper(RGBImgPartialObsWrapper(minigrid_env())).reset(seed=0)
    assert obs["frames"].shape == (3, 3, 56, 56)
    np.testing.assert_array_equal(obs["frames"][-1], image.transpose(2, 0, 1))

    full = SimounObservation(ImgObsWrapper(RGBImgObsWrapper(minigrid_env())), size=None)
    assert full.observation_space["frames"].shape == (3, 3, 40, 40)
    rendered = SimounObservation(ImgObsWrapper(minigrid_env()), size=32, source="render")
    obs, _ = rendered.reset(seed=0)
    assert obs["frames"].shape == (3, 3, 32, 32) and obs["frames"].std() > 5


def dm_control_with_pixel_observations() -> gym.Env:
    """cartpole whose observation holds camera 1's pixels while render() shows camera 0."""
    size = {"height": 32, "width": 32}
    task = suite.load("cartpole", "swingup", task_kwargs={"random": 0})
    task = pixels.Wrapper(task, pixels_only=False, render_kwargs={"camera_id": 1, **size})
    return DmControlCompatibilityV0(
        task, render_mode="rgb_array", render_kwargs={"camera_id": 0, **size}
    )


def test_dict_pixels_entry_wins_over_render_and_source_render_picks_the_renders():
    inner = dm_control_with_pixel_observations()
    assert "pixels" in inner.observation_space.spaces and inner.render_mode == "rgb_array"
    env = SimounObservation(inner, size=None)
    obs, _ = env.reset(seed=0)
    obs, *_ = env.step(env.action_space.sample())
    camera_1 = inner._env.physics.render(camera_id=1, height=32, width=32)
    camera_0 = inner.render()
    assert not (camera_0 == camera_1).all()
    np.testing.assert_array_equal(obs["frames"][-1], camera_1.transpose(2, 0, 1))

    renders = SimounObservation(dm_control_with_pixel_observations(), size=None, source="render")
    obs, _ = renders.reset(seed=0)
    np.testing.assert_array_equal(obs["frames"][-1], renders.render().transpose(2, 0, 1))


def test_rgba_observations_lose_their_alpha():
    rgba = Box(0, 255, (32, 32, 4), np.uint8)

    def add_alpha(image: np.ndarray) -> np.ndarray:
        return np.concatenate([image, np.full((32, 32, 1), 255, np.uint8)], axis=-1)

    env = SimounObservation(TransformObservation(point_reach(), add_alpha, rgba), size=None)
    assert env.observation_space["frames"].shape == (3, 3, 32, 32)
    obs, _ = env.reset(seed=2)
    image, _ = point_reach().reset(seed=2)
    np.testing.assert_array_equal(obs["frames"][-1], image.transpose(2, 0, 1))


def test_channel_first_image_is_refused_with_the_transpose_that_fixes_it():
    chw = Box(0, 255, (3, 32, 32), np.uint8)
    channel_first = TransformObservation(point_reach(), lambda o: o.transpose(2, 0, 1), chw)
    with pytest.raises(
        TypeError, match=r"channel-first planes \(3, 32, 32\).*transpose\(1, 2, 0\)"
    ):
        SimounObservation(channel_first)
    hwc = Box(0, 255, (32, 32, 3), np.uint8)
    fixed = TransformObservation(channel_first, lambda o: o.transpose(1, 2, 0), hwc)
    obs, _ = SimounObservation(fixed, size=None).reset(seed=2)
    image, _ = point_reach().reset(seed=2)
    np.testing.assert_array_equal(obs["frames"][-1], image.transpose(2, 0, 1))


def test_channel_first_image_with_renders_is_refused_not_swapped_for_render():
    chw = Box(0, 255, (3, 32, 32), np.uint8)
    env = TransformObservation(point_reach("rgb_array"), lambda o: o.transpose(2, 0, 1), chw)
    with pytest.raises(TypeError, match=r"channel-first.*source='render'"):
        SimounObservation(env)


def test_highway_stacked_grayscale_is_refused_and_source_render_works():
    config = {
        "observation": {
            "type": "GrayscaleObservation",
            "observation_shape": (64, 32),
            "stack_size": 4,
            "weights": [0.2989, 0.5870, 0.1140],
        },
        "vehicles_count": 5,
    }
    env = gym.make("highway-fast-v0", render_mode="rgb_array", config=config)
    assert env.observation_space.shape == (4, 64, 32)
    with pytest.raises(TypeError, match=r"4 stacked grayscale frames.*source='render'"):
        SimounObservation(env, size=32)
    obs, _ = SimounObservation(env, size=32, source="render").reset(seed=0)
    assert obs["frames"].shape == (3, 3, 32, 32) and obs["frames"].std() > 5
