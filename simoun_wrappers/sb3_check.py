"""Which Stable-Baselines3 policy fits a ``SimounObservation``, and why the others do not.

SB3 treats only a 3-D uint8 ``Box`` as an image (its ``is_image_space``). ``SimounObservation``'s
default observation is a Dict of a 4-D ``(k, C, H, W)`` frame stack and int16 motion channels:
``MultiInputPolicy`` accepts it but flattens both into an MLP on raw pixels, and ``CnnPolicy``
refuses it with SB3's advice to use ``MultiInputPolicy``. The supported path is
``SimounObservation(env, fold_frames=True)`` (the triplet as one ``(k*C, H, W)`` uint8 image) with
``"CnnPolicy"``, whose NatureCNN needs frames of at least 36x36. SB3 itself is not imported.
"""

from __future__ import annotations

import difflib

import gymnasium as gym
import numpy as np
from gymnasium import spaces

NATURE_CNN_MIN_SIZE = 36
"""Smallest side NatureCNN takes: 8x8 stride 4, 4x4 stride 2, 3x3 stride 1 leave 1x1 at 36."""

_FIX = (
    "Use SimounObservation(env, fold_frames=True) with 'CnnPolicy': the frames become one "
    "(k*C, H, W) uint8 image that SB3's NatureCNN convolves (motion is then left out; "
    "residual_motion(obs.reshape(k, C, H, W)) recovers it)."
)


SB3_POLICIES = ("CnnPolicy", "MlpPolicy", "MultiInputPolicy")
"""The policy names every SB3 algorithm for images registers (a name outside them is a
``KeyError`` inside SB3)."""


def _policy_kind(policy: str | type) -> str:
    name = policy if isinstance(policy, str) else getattr(policy, "__name__", str(policy))
    for kind in ("MultiInput", "Cnn", "Mlp"):
        if kind in name:
            return kind
    return ""


def check_sb3_policy(env: gym.Env | gym.Space, policy: str | type) -> str | type:
    """Return ``policy`` if SB3 would see ``env``'s frames as images, else raise ValueError.

    Args:
        env: an env (or vector env, or its observation space) built with ``SimounObservation``.
        policy: the policy given to the SB3 algorithm, a name (``"CnnPolicy"``: one of
            :data:`SB3_POLICIES`, a misspelling is refused with its close match) or a class;
            custom policy classes (neither Cnn, Mlp nor MultiInput in the name) pass unchecked.

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.sb3_check import check_sb3_policy
        >>> env = gym.make("CartPole-v1", render_mode="rgb_array")
        >>> check_sb3_policy(SimounObservation(env, size=64, fold_frames=True), "CnnPolicy")
        'CnnPolicy'
        >>> check_sb3_policy(SimounObservation(env, size=64), "MultiInputPolicy")
        Traceback (most recent call last):
        ...
        ValueError: MultiInputPolicy would flatten the (3, 3, 64, 64) frame stack ...
    """
    if isinstance(policy, str) and policy not in SB3_POLICIES:
        match = difflib.get_close_matches(policy, SB3_POLICIES, n=1, cutoff=0.5)
        hint = f" (did you mean {match[0]!r}?)" if match else ""
        raise ValueError(
            f"policy {policy!r} is not a Stable-Baselines3 policy name{hint}; SB3 knows "
            f"{', '.join(map(repr, SB3_POLICIES))} (or pass a policy class)"
        )
    if not isinstance(policy, (str, type)):
        raise TypeError(f"policy must be a policy name (str) or class, got {type(policy).__name__}")
    if isinstance(env, spaces.Space):
        space = env
    elif isinstance(getattr(env, "single_observation_space", None), spaces.Space):
        space = env.single_observation_space  # a vector env: SB3 reads one sub-env's space
    elif isinstance(getattr(env, "observation_space", None), spaces.Space):
        space = env.observation_space
    else:
        raise TypeError(
            "env must be a gymnasium Env, a VectorEnv or an observation space, got "
            f"{type(env).__name__}"
        )
    kind = _policy_kind(policy)
    if not kind:
        return policy
    name = policy if isinstance(policy, str) else policy.__name__
    frames = space.spaces.get("frames") if isinstance(space, spaces.Dict) else None
    if isinstance(frames, spaces.Box) and len(frames.shape) == 4:
        if kind == "MultiInput":
            raise ValueError(
                f"{name} would flatten the {frames.shape} frame stack (and the int16 motion "
                f"channels) of this Dict observation into an MLP on raw pixels: SB3 takes only "
                f"3-D uint8 Boxes as images. {_FIX}"
            )
        raise ValueError(
            f"{name} needs one (C, H, W) uint8 image, but this observation is a Dict with a "
            f"{frames.shape} frame stack (SB3 would then ask for MultiInputPolicy, which "
            f"flattens the pixels into an MLP). {_FIX}"
        )
    folded = isinstance(space, spaces.Box) and len(space.shape) == 3 and space.dtype == np.uint8
    if not folded:
        return policy
    if kind != "Cnn":
        raise ValueError(
            f"{name} does not convolve the {space.shape} uint8 image (MlpPolicy flattens it "
            f"into an MLP on raw pixels, MultiInputPolicy needs a Dict); use 'CnnPolicy'."
        )
    if min(space.shape[1:]) < NATURE_CNN_MIN_SIZE:
        raise ValueError(
            f"CnnPolicy's NatureCNN needs frames of at least {NATURE_CNN_MIN_SIZE}x"
            f"{NATURE_CNN_MIN_SIZE}, got {space.shape[1]}x{space.shape[2]}; use "
            f"SimounObservation(env, size={NATURE_CNN_MIN_SIZE}) or larger, or a smaller "
            f"features_extractor_class in policy_kwargs."
        )
    return policy
