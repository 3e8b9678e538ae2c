"""Random convolution (Lee et al. 2020, "network randomization") for batches and for envs, and
DrQ's random shift for batches.

Weight initialisation: every kernel is drawn from a Xavier/Glorot normal distribution,
``N(0, 2 / (fan_in + fan_out))`` with ``fan_in = fan_out = C * k * k``, as in the authors'
netrand code. Its gain is 1, so an output pixel has about the same mean square as the input
pixels; the convolution is linear and unclamped, so outputs may leave the input's range
(negative values included) unless ``clamp`` is given. Borders are zero-padded ("same"
padding, as in netrand), so the image keeps its size.
"""

from __future__ import annotations

import numbers
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium.wrappers import TransformObservation

from simoun_wrappers._checks import check_reset_seed, is_int, keyword_reset, plain
from simoun_wrappers.frames import check_single_env, refuse_over_frame_stack
from simoun_wrappers.observation import ChainWrapper, image_layout, pixel_env

if TYPE_CHECKING:
    import torch


def _ordered_bounds(clamp: object) -> bool:
    """Whether ``clamp`` is a pair of real numbers ``(low, high)`` with ``low <= high``."""
    if not isinstance(clamp, (tuple, list)) or len(clamp) != 2:
        return False
    low, high = clamp
    real = all(isinstance(b, numbers.Real) and not isinstance(b, bool) for b in clamp)
    return real and low <= high


def random_conv(
    batch: torch.Tensor,
    kernel_size: int = 3,
    generator: torch.Generator | None = None,
    clamp: tuple[float, float] | None = None,
) -> torch.Tensor:
    """Pass every sample of a batch through its own random ``C -> C`` convolution.

    Args:
        batch: float tensor ``(B, C, H, W)`` or ``(B, T, C, H, W)``; the ``T`` frames of one sample
            share that sample's kernel, so motion between them is kept.
        kernel_size: odd kernel width; the output keeps ``H`` and ``W``.
        generator: source of the kernel weights; ``None`` uses torch's global RNG, so a saved RNG
            state replays the same kernels. It may live on another device than ``batch``.
        clamp: optional ``(low, high)`` bounds for the output, e.g. ``(0.0, 1.0)`` for images in
            [0, 1]; ``None`` returns the raw linear output.

    Returns:
        A tensor of ``batch``'s shape, dtype and device. All samples go through one grouped
        convolution: there is no Python loop over the batch.

    Example:
        >>> import torch
        >>> from simoun_wrappers.augment import random_conv
        >>> frames = torch.rand(8, 3, 3, 64, 64)  # 8 triplets of RGB frames in [0, 1]
        >>> random_conv(frames, generator=torch.Generator().manual_seed(0)).shape
        torch.Size([8, 3, 3, 64, 64])
    """
    import torch
    import torch.nn.functional as F

    if not isinstance(batch, torch.Tensor) or not batch.is_floating_point():
        given = batch.dtype if isinstance(batch, torch.Tensor) else described(batch)
        raise TypeError(
            f"random_conv expects a floating-point torch.Tensor, got {given}; convert frames "
            f"first, e.g. torch.as_tensor(frames).float() / 255."
        )
    if batch.ndim not in (4, 5):
        raise ValueError(
            f"random_conv expects a (B, C, H, W) or (B, T, C, H, W) batch, got shape "
            f"{tuple(batch.shape)}; add a leading batch axis with batch[None] for one sample."
        )
    check_no_empty_axis(batch.shape)
    if not is_int(kernel_size) or kernel_size < 1 or kernel_size % 2 == 0:
        raise ValueError(
            f"kernel_size must be a positive odd int so the output keeps its size, got "
            f"{kernel_size!r}; use 3 (Lee et al. 2020) or another odd value."
        )
    check_kernel_fits(kernel_size, batch.shape[-2], batch.shape[-1])
    if generator is not None and not isinstance(generator, torch.Generator):
        raise TypeError(
            f"generator must be a torch.Generator or None, got {described(generator)}; e.g. "
            "generator=torch.Generator().manual_seed(0), or None for torch's global RNG."
        )
    if clamp is not None and not _ordered_bounds(clamp):
        raise ValueError(
            f"clamp must be (low, high) with low <= high, got {clamp!r}; e.g. clamp=(0.0, 1.0) "
            "for images in [0, 1], or None for the raw output."
        )
    shape = batch.shape
    if shape[0] == 0:
        return batch.clone()  # an empty batch: a grouped convolution needs at least one group
    frames = batch if batch.ndim == 5 else batch.unsqueeze(1)
    b, t, c, h, w = frames.shape

    fan = c * kernel_size * kernel_size
    std = (2.0 / (fan + fan)) ** 0.5
    weight_device = batch.device if generator is None else generator.device
    weight = torch.randn(
        (b * c, c, kernel_size, kernel_size),
        generator=generator,
        device=weight_device,
        dtype=batch.dtype,
    )
    weight = (weight * std).to(batch.device)

    # One group per frame: sample b's kernel is repeated for its t frames, so the batch is read
    # in place as (1, b*t*c, h, w) and the output needs no transpose either.
    weight = weight.reshape(b, 1, c, c, kernel_size, kernel_size).expand(b, t, -1, -1, -1, -1)
    weight = weight.reshape(b * t * c, c, kernel_size, kernel_size)
    stacked = frames.reshape(1, b * t * c, h, w)
    if stacked.device.type == "cpu" and torch.backends.mkldnn.enabled and b * t > 1:
        # oneDNN's grouped convolution with 3 channels per group runs about 2x slower than
        # PyTorch's native kernel on CPU (benchmarks/wrappers.py), so it sits out this call.
        # With one group (RandomConvolution's single frame) oneDNN is 2-7x the faster one.
        torch.backends.mkldnn.enabled = False
        try:
            out = F.conv2d(stacked, weight, padding=kernel_size // 2, groups=b * t)
        finally:
            torch.backends.mkldnn.enabled = True
    else:
        out = F.conv2d(stacked, weight, padding=kernel_size // 2, groups=b * t)
    if clamp is not None:
        out = out.clamp(clamp[0], clamp[1])
    return out.reshape(shape)


def described(value: Any) -> str:
    """``value``'s type as a user names it, with a numpy array's dtype: ``numpy.ndarray of
    float32``, ``list``."""
    if isinstance(value, np.ndarray):
        return f"numpy.ndarray of {value.dtype}"
    return type(value).__name__


def check_no_empty_axis(shape: tuple[int, ...]) -> None:
    """Refuse a batch with no channels, frames, rows or columns (a batch of no samples is
    fine): a convolution of nothing is a slicing mistake upstream, not an image."""
    axes = ("B", "C", "H", "W") if len(shape) == 4 else ("B", "T", "C", "H", "W")
    meaning = {"T": "frames", "C": "channels", "H": "rows", "W": "columns"}
    empty = [axis for axis, size in zip(axes[1:], shape[1:], strict=True) if size == 0]
    if empty:
        named = ", ".join(f"{axis} ({meaning[axis]})" for axis in empty)
        raise ValueError(
            f"random_conv got a batch of shape {tuple(shape)} whose {named} "
            f"{'axis is' if len(empty) == 1 else 'axes are'} empty; "
            f"pass images with at least one channel and pixel, e.g. shape "
            f"({', '.join(axes)}) = {(2, 3, 84, 84) if len(shape) == 4 else (2, 3, 3, 84, 84)}"
        )


def check_kernel_fits(kernel_size: int, height: int, width: int) -> None:
    """Refuse a kernel wider than the image: it would only see padding, and its cost grows
    with its area (a 301-wide kernel over a 256x256 render takes hours)."""
    if kernel_size > min(height, width):
        raise ValueError(
            f"kernel_size {kernel_size} is larger than the {height}x{width} image; use 3 "
            f"(Lee et al. 2020), or an odd value up to {min(height, width)}."
        )


def shift_pad(image_size: int) -> int:
    """DrQ's random-shift padding scaled with the image: 4 px at 84 px, at least 1 px."""
    return max(1, round(4 * image_size / 84))


def random_shift(
    batch: torch.Tensor, pad: int, generator: torch.Generator | None = None
) -> torch.Tensor:
    """DrQ's random shift: replicate-pad every image by ``pad`` pixels, crop back at a random
    integer offset, one offset per sample for all of its frames.

    Replicate padding followed by a crop equals indexing with clamped coordinates, which is
    what this does: exact on any dtype (uint8 frames stay uint8), no float copy, no Python loop
    over the batch. Sharing the offset across a sample's frames keeps the residuals between
    them (the motion path's input) the residuals of the shifted frames.

    Args:
        batch: ``(B, T, C, H, W)`` frames (or ``(B, C, H, W)``), any dtype.
        pad: maximum shift in pixels in each direction (DrQ: 4 at 84 px, see :func:`shift_pad`).
        generator: source of the offsets; ``None`` uses torch's global RNG.

    Example:
        >>> import torch
        >>> from simoun_wrappers.augment import random_shift
        >>> frames = torch.randint(0, 256, (8, 4, 3, 48, 48), dtype=torch.uint8)
        >>> shifted = random_shift(frames, pad=2, generator=torch.Generator().manual_seed(0))
        >>> shifted.shape, shifted.dtype
        (torch.Size([8, 4, 3, 48, 48]), torch.uint8)
    """
    import torch

    if not isinstance(batch, torch.Tensor) or batch.ndim not in (4, 5):
        raise TypeError(
            f"random_shift expects a torch.Tensor (B, T, C, H, W) or (B, C, H, W), got "
            f"{type(batch).__name__} {tuple(getattr(batch, 'shape', ()))}"
        )
    if pad < 0:
        raise ValueError(f"random_shift needs pad >= 0, got {pad}")
    n, (h, w) = batch.shape[0], batch.shape[-2:]
    offsets = torch.randint(0, 2 * pad + 1, (2, n, 1), generator=generator)
    offsets = offsets.to(batch.device) - pad
    rows = (torch.arange(h, device=batch.device) + offsets[0]).clamp_(0, h - 1)
    cols = (torch.arange(w, device=batch.device) + offsets[1]).clamp_(0, w - 1)
    index = torch.arange(n, device=batch.device)[:, None, None]
    # (B, H, W, ...) after advanced indexing of the last two axes: move them back
    moved = batch.movedim((-2, -1), (1, 2))[index, rows[:, :, None], cols[:, None, :]]
    return moved.movedim((1, 2), (-2, -1))


class RandomConvolution(ChainWrapper):
    """Pass every frame through a random convolution whose kernel is resampled every episode.

    Network randomization (Lee et al. 2020) as an env wrapper, for generalization training and
    evaluation: the same ``C -> C`` kernel (Xavier-normal, see ``random_conv``) colours every
    frame of an episode, and ``reset()`` draws a new one. Outputs are rounded and clipped to
    [0, 255] uint8, so the wrapper composes with ``SimounObservation`` on top. Pixels come from
    image observations (``(H, W, C)`` or ``(H, W)`` uint8) or from ``render()`` with
    ``render_mode="rgb_array"``. Kernels come from the wrapper's own RNG: ``reset(seed=s)`` makes
    them reproducible and the env's own RNG is left untouched. It goes *under* the frame stack
    (``SimounObservation(RandomConvolution(env))``); over a stacked env it raises, since it would
    replace the triplet and its motion channels with a convolved ``render()``. Reading pixels
    from ``render()`` resets the env while the wrapper is built (Gymnasium's
    ``AddRenderObservation``), so ``step()`` before the first ``reset()`` raises Gymnasium's
    ``ResetNeeded``: episodes start with the user's ``reset(seed=...)``.

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import RandomConvolution, SimounObservation
        >>> env = gym.make("CartPole-v1", render_mode="rgb_array")
        >>> env = SimounObservation(RandomConvolution(env), size=64)
        >>> obs, _ = env.reset(seed=0)
        >>> obs["frames"].shape
        (3, 3, 64, 64)
    """

    def __init__(self, env: gym.Env, kernel_size: int = 3, source: str = "auto") -> None:
        """Wrap ``env``.

        Args:
            env: an env with image observations or ``render_mode="rgb_array"``.
            kernel_size: odd kernel width; the image keeps its size.
            source: ``"auto"``, ``"observation"`` or ``"render"``, as in ``SimounObservation``.
        """
        check_single_env(env, "RandomConvolution")
        gym.utils.RecordConstructorArgs.__init__(
            self, kernel_size=plain(kernel_size), source=source
        )
        import torch

        if not is_int(kernel_size) or kernel_size < 1 or kernel_size % 2 == 0:
            raise ValueError(
                f"kernel_size must be a positive odd int, got {kernel_size!r}; use 3 as in "
                f"Lee et al. 2020."
            )
        refuse_over_frame_stack(
            env,
            "RandomConvolution",
            "convolving its render() would drop the triplet and its motion channels",
            "SimounObservation(RandomConvolution(env), ...) convolves every frame of the triplet "
            "with the episode's kernel, and motion is computed from the convolved frames",
        )
        chain, from_render = pixel_env(env, source, owner="RandomConvolution")
        self._layout = image_layout(chain.observation_space)
        check_kernel_fits(kernel_size, *self._layout[:2])
        chain = TransformObservation(chain, self._convolve, chain.observation_space)
        ChainWrapper.__init__(self, chain, env)
        if from_render:
            self.metadata = {**env.metadata, "render_modes": ["rgb_array"]}
        self.kernel_size = kernel_size
        self._rng = np.random.default_rng()
        self._generator = torch.Generator()
        self._kernel_seed = 0

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        seed = check_reset_seed(seed, "RandomConvolution")
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        self._kernel_seed = int(self._rng.integers(2**62))
        return super().reset(seed=seed, options=options)

    def _convolve(self, image: np.ndarray) -> np.ndarray:
        import torch

        height, width, channels = self._layout
        chw = torch.from_numpy(np.ascontiguousarray(image).reshape(height, width, channels))
        batch = chw.permute(2, 0, 1)[None].float()
        # Re-seeding before each call makes random_conv draw the episode's kernel again.
        self._generator.manual_seed(self._kernel_seed)
        out = random_conv(batch, self.kernel_size, self._generator, clamp=(0.0, 255.0))
        return out[0].round().to(torch.uint8).permute(1, 2, 0).reshape(image.shape).numpy()
