"""Input pairs for the information-bias analysis, made from a run's own environment.

Every pair starts from an observation ``x`` = frames [o_{t-2}, o_{t-1}, o_t] that the trained
agent saw while playing its evaluation episodes deterministically (only steps t >= 2, so the three
frames are real, not the reset padding). No data is downloaded.

- *dynamic pair* ``(x, recolour(x))``: shares the motion, differs in appearance. ``recolour`` is
  one random 3x3 ``C -> C`` convolution (Lee et al. 2020, :func:`simoun_wrappers.augment.
  random_conv`, Xavier-normal weights, no bias) applied to all frames of the observation with the
  same kernel, clipped to [0, 1] and rounded back to uint8; each pair draws its own kernel. The
  same kernel on every frame keeps where and how things move (before clipping, the residuals
  are the convolution of the original residuals) while colours, contrast and textures change,
  as Kowal et al.'s stylised copies of a video do.
  With ``--recolour model`` (dm_control tasks) ``recolour(x)`` is instead the same observation
  re-rendered by a twin of the environment that replays the episode's seed and actions under
  new colours of the skybox, the materials and the geoms (:mod:`simoun_lab.analysis.recolour`).
- *static pair* ``(x, shuffle(x))``: shares the appearance, differs in motion. ``shuffle`` puts the
  same frames in another order, a permutation drawn uniformly among those that are not the
  identity (one per pair): the same pixels, so the same objects and colours, but the residual
  frames, and so the motion the encoder sees, change.
"""

from __future__ import annotations

import itertools

import numpy as np
import torch

from simoun_lab.analysis.runs import OBSERVATIONS_EXAMPLE, observation_batch
from simoun_wrappers._checks import is_int
from simoun_wrappers.augment import random_conv

RECOLOUR_KERNEL = 3
"""Kernel width of the recolouring convolution (Lee et al. 2020's value)."""


def recolour(observations: np.ndarray, generator: torch.Generator) -> np.ndarray:
    """``(N, k, C, H, W)`` uint8 -> the same observations through one random convolution per
    observation, shared by its k frames, as uint8."""
    frames = torch.as_tensor(observations).float().div_(255.0)
    out = random_conv(frames, RECOLOUR_KERNEL, generator=generator, clamp=(0.0, 1.0))
    return out.mul_(255.0).round_().to(torch.uint8).numpy()


def shuffle_frames(observations: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """``(N, k, C, H, W)`` -> each observation's frames in a random order other than the given."""
    k = observations.shape[1]
    if k < 2:
        raise ValueError(f"static pairs shuffle frames, so they need k >= 2 frames, got k={k}")
    orders = np.array([p for p in itertools.permutations(range(k)) if list(p) != list(range(k))])
    chosen = orders[rng.integers(len(orders), size=len(observations))]
    return np.take_along_axis(observations, chosen[:, :, None, None, None], axis=1)


def make_pairs(
    observations: np.ndarray, seed: int, recoloured: np.ndarray | None = None
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``{"dynamic": (x, recolour(x)), "static": (x, shuffle(x))}`` for observations
    ``(N, k, C, H, W)`` uint8, reproducible from ``seed``. ``recoloured`` gives the second
    member of the dynamic pairs instead (e.g. re-rendered by :mod:`simoun_lab.analysis.recolour`).
    """
    observations = _pair_inputs(observations, seed, recoloured)
    generator = torch.Generator().manual_seed(seed)
    rng = np.random.default_rng(seed)
    if recoloured is None:
        recoloured = recolour(observations, generator)
    return {
        "dynamic": (observations, recoloured),
        "static": (observations, shuffle_frames(observations, rng)),
    }


def _pair_inputs(observations: object, seed: object, recoloured: object) -> np.ndarray:
    """:func:`make_pairs`' arguments checked, ``observations`` as a numpy array: uint8
    ``(N, k, C, H, W)`` with k >= 2 (the static pairs shuffle the frames), a seed of numpy's
    range, and ``recoloured`` one uint8 copy of every observation."""
    batch = observation_batch(observations, "make_pairs")
    if batch.shape[1] < 2:
        raise ValueError(
            f"make_pairs(observations=...) need k >= 2 frames per observation (the static pairs "
            f"shuffle them), got shape {tuple(batch.shape)}; pass the env's stacked frames, e.g. "
            f"{OBSERVATIONS_EXAMPLE}"
        )
    if not (is_int(seed) and 0 <= seed < 2**63):
        raise (ValueError if is_int(seed) else TypeError)(
            f"make_pairs(seed=...) must be an int in [0, 2**63) (it seeds the recolouring and the "
            f"shuffles), got {type(seed).__name__} {seed!r:.60}; e.g. seed=0"
        )
    if recoloured is not None:
        second = observation_batch(recoloured, "make_pairs", "recoloured")
        if second.shape != batch.shape:
            raise ValueError(
                f"make_pairs(recoloured=...) must hold one recoloured copy of every observation, "
                f"the shape of observations {tuple(batch.shape)}, got {tuple(second.shape)}; "
                "give the recoloured copies of the same observations, in their order, or "
                "recoloured=None to recolour them with a random convolution"
            )
    return observations if isinstance(observations, np.ndarray) else batch.numpy()


def usable_steps(length: int, block: int | None = None) -> np.ndarray:
    """Steps t >= 2 of an episode of ``length`` decisions (observations 0..length), and with a
    ``block``, only the last step of each block (t = block - 1 mod block)."""
    steps = np.arange(2, length + 1)
    return steps if block is None else steps[steps % block == block - 1]


def sample_rows(total: int, count: int, seed: int) -> np.ndarray:
    """``count`` of ``range(total)`` drawn without replacement, sorted, reproducible."""
    if total < count:
        raise ValueError(f"only {total} observations to draw {count} from")
    return np.sort(np.random.default_rng(seed).choice(total, size=count, replace=False))
