"""random_conv (batched, per-sample kernels) and the RandomConvolution env wrapper."""

import gymnasium as gym
import numpy as np
import pytest
import torch
import torch.nn.functional as F
from gymnasium.utils.env_checker import check_env

from simoun_wrappers import RandomConvolution, SimounObservation
from simoun_wrappers.augment import random_conv


def _gen(seed: int = 0) -> torch.Generator:
    return torch.Generator().manual_seed(seed)


def test_shape_dtype_and_device_kept():
    for shape in [(4, 3, 16, 16), (4, 3, 3, 16, 12), (2, 1, 1, 8, 8)]:
        for dtype in (torch.float32, torch.float64):
            x = torch.rand(shape, dtype=dtype)
            y = random_conv(x, generator=_gen())
            assert y.shape == x.shape and y.dtype == dtype and y.device == x.device


def test_frames_of_a_sample_share_one_kernel_and_samples_differ():
    torch.manual_seed(0)
    frame = torch.rand(3, 16, 16)
    # Every sample holds the same frame three times, so only kernels can tell them apart.
    batch = frame.expand(6, 3, 3, 16, 16).contiguous()
    out = random_conv(batch, generator=_gen(1))
    for i in range(6):
        torch.testing.assert_close(out[i, 0], out[i, 1])
        torch.testing.assert_close(out[i, 0], out[i, 2])
    for i in range(6):
        for j in range(i + 1, 6):
            assert (out[i, 0] - out[j, 0]).abs().mean() > 1e-3


@pytest.mark.parametrize("batch, frames", [(5, 2), (1, 1)])  # grouped and single-group paths
def test_matches_a_per_sample_loop_with_the_documented_init(batch, frames):
    x = torch.rand(batch, frames, 3, 10, 10)
    out = random_conv(x, generator=_gen(7))
    weights = torch.randn(3 * batch, 3, 3, 3, generator=_gen(7)) * (2.0 / (27 + 27)) ** 0.5
    for i in range(batch):
        expected = F.conv2d(x[i], weights[3 * i : 3 * i + 3], padding=1)
        torch.testing.assert_close(out[i], expected)


def test_generator_and_global_rng_reproduce_kernels():
    x = torch.rand(4, 3, 8, 8)
    torch.testing.assert_close(random_conv(x, generator=_gen(3)), random_conv(x, generator=_gen(3)))
    torch.manual_seed(11)
    a = random_conv(x)
    torch.manual_seed(11)
    torch.testing.assert_close(a, random_conv(x))
    clamped = random_conv(x * 255, kernel_size=5, generator=_gen(0), clamp=(0.0, 255.0))
    assert clamped.min() >= 0 and clamped.max() <= 255


def test_random_conv_errors():
    with pytest.raises(TypeError, match=r"floating-point.*float\(\) / 255"):
        random_conv(torch.zeros(2, 3, 8, 8, dtype=torch.uint8))
    with pytest.raises(ValueError, match=r"batch\[None\]"):
        random_conv(torch.zeros(3, 8, 8))
    with pytest.raises(ValueError, match=r"positive odd int"):
        random_conv(torch.zeros(2, 3, 8, 8), kernel_size=4)


@pytest.mark.parametrize(
    ("shape", "named"),
    [
        ((2, 0, 8, 8), r"C \(channels\) axis is empty"),
        ((2, 3, 0, 8), r"H \(rows\) axis is empty"),
        ((2, 0, 3, 8, 8), r"T \(frames\) axis is empty"),
        ((2, 3, 0, 0), r"H \(rows\), W \(columns\) axes are empty"),
    ],
)
def test_a_batch_with_an_empty_axis_is_named_and_an_empty_batch_is_returned(shape, named):
    with pytest.raises(ValueError, match=rf"random_conv got a batch of shape .*{named}"):
        random_conv(torch.zeros(shape))
    assert random_conv(torch.zeros(0, 3, 8, 8)).shape == (0, 3, 8, 8)


def _randconv_cartpole() -> RandomConvolution:
    return RandomConvolution(gym.make("CartPole-v1", render_mode="rgb_array"))


def test_wrapper_kernel_is_fixed_in_an_episode_and_resampled_at_reset():
    env = _randconv_cartpole()
    raw = env.unwrapped
    first, _ = env.reset(seed=5)
    assert first.shape == raw.render().shape and first.dtype == np.uint8
    corner = first[:20, :20].copy()  # background: the same raw pixels at every step
    for _ in range(3):
        obs, *_ = env.step(0)
        np.testing.assert_array_equal(obs[:20, :20], corner)
    colours = {tuple(corner[5, 5])}
    for _ in range(4):
        colours.add(tuple(env.reset()[0][5, 5]))
    assert len(colours) > 1
    again, _ = env.reset(seed=5)
    np.testing.assert_array_equal(again, first)


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")
def test_wrapper_composes_with_simoun_observation():
    env = SimounObservation(_randconv_cartpole(), size=16)
    obs, _ = env.reset(seed=0)
    assert obs["frames"].shape == (3, 3, 16, 16)
    check_env(env)


def test_wrapper_errors():
    with pytest.raises(ValueError, match=r"RandomConvolution needs pixels"):
        RandomConvolution(gym.make("CartPole-v1"))
    with pytest.raises(ValueError, match=r"positive odd int"):
        RandomConvolution(gym.make("CartPole-v1", render_mode="rgb_array"), kernel_size=2)


def test_random_convolution_from_renders_refuses_step_before_reset():
    # AddRenderObservation resets the env while the chain is built; the user's reset starts it
    env = RandomConvolution(gym.make("CartPole-v1", render_mode="rgb_array"))
    with pytest.raises(gym.error.ResetNeeded, match=r"call env\.reset\(seed=\.\.\.\)"):
        env.step(0)
    env.reset(seed=0)
    env.step(0)
