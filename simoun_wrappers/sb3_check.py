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


_SB3_LEAVES = (spaces.Box, spaces.Discrete, spaces.MultiDiscrete, spaces.MultiBinary)
"""The observation spaces SB3's policies and buffers take (its ``get_obs_shape``), alone or as
the values of a Dict."""


def _fix_for(space: spaces.Space) -> str:
    """What makes ``space`` one an SB3 policy takes: flattening, where gymnasium can."""
    try:
        flat = spaces.utils.flatten_space(space)
    except (NotImplementedError, TypeError, ValueError):
        flat = None
    if isinstance(flat, spaces.Box):
        return (
            "wrap the env in gymnasium.wrappers.FlattenObservation (a 1-D Box, for "
            "'MlpPolicy'), or give it a Dict of those spaces (for 'MultiInputPolicy')"
        )
    return (
        "convert the observation in a wrapper of your own to a Box (for 'MlpPolicy') or a Dict "
        "of those spaces (for 'MultiInputPolicy')"
    )


def _kind_name(space: spaces.Space) -> str:
    return type(space).__name__


def _unsupported(space: spaces.Space) -> str | None:
    """Why no SB3 policy takes ``space`` (a kind SB3 refuses, or a Dict nesting one), else None."""
    leaves = ", ".join(kind.__name__ for kind in _SB3_LEAVES)
    if isinstance(space, spaces.Dict):
        for key, sub in space.spaces.items():
            if isinstance(sub, (spaces.Dict, spaces.Tuple)):
                return (
                    f"its Dict holds a {_kind_name(sub)} under {key!r}, and SB3 takes no nested "
                    f"spaces (only {leaves} in a Dict)"
                )
            if not isinstance(sub, _SB3_LEAVES):
                return (
                    f"its Dict holds a {_kind_name(sub)} under {key!r}, which SB3 takes in no "
                    f"policy (only {leaves})"
                )
        return None
    if not isinstance(space, _SB3_LEAVES):
        return (
            f"it is a {_kind_name(space)} space, which SB3 takes in no policy (it takes {leaves}, "
            "and a Dict of those)"
        )
    return None


def _is_image(space: spaces.Space) -> bool:
    """SB3's ``is_image_space``: a 3-D uint8 Box of bounds 0 .. 255, the only input NatureCNN
    (CnnPolicy, and MultiInputPolicy's image keys) convolves."""
    return (
        isinstance(space, spaces.Box)
        and len(space.shape) == 3
        and space.dtype == np.uint8
        and bool(np.all(space.low == 0) and np.all(space.high == 255))
    )


def _image_sides(space: spaces.Box) -> tuple[int, int]:
    """Height and width of an image space as SB3 reads it: the channels are its smallest
    dimension (``is_image_space_channels_first``), first or last."""
    shape = list(space.shape)
    del shape[int(np.argmin(shape))]
    return shape[0], shape[1]


def _policy_kind(policy: str | type) -> str:
    name = policy if isinstance(policy, str) else getattr(policy, "__name__", str(policy))
    for kind in ("MultiInput", "Cnn", "Mlp"):
        if kind in name:
            return kind
    return ""


def check_policy_class(policy: type) -> None:
    """Refuse a class that is no policy: SB3's policies are torch modules, so an algorithm class
    (``stable_baselines3.PPO``) or any other class given where the policy belongs is named, with
    the policy names to pass instead."""
    ancestors = {f"{kind.__module__}.{kind.__qualname__}" for kind in policy.__mro__}
    if "torch.nn.modules.module.Module" in ancestors:
        return
    names = ", ".join(map(repr, SB3_POLICIES))
    algorithm = any(kind.__name__ == "BaseAlgorithm" for kind in policy.__mro__)
    what = "an SB3 algorithm, not a policy" if algorithm else "no policy class (no torch module)"
    example = f" for {policy.__name__}('CnnPolicy', env)" if algorithm else ""
    raise TypeError(
        f"policy {policy.__name__} is {what}; pass the policy's name ({names}) or a policy "
        f"class, e.g. check_sb3_policy(env, 'CnnPolicy'){example}"
    )


def check_sb3_policy(env: gym.Env | gym.Space, policy: str | type) -> str | type:
    """Return ``policy`` if SB3 would see ``env``'s frames as images, else raise ValueError.

    Every space is checked against what SB3's policies take: Box, Discrete, MultiDiscrete and
    MultiBinary (``MlpPolicy``; ``CnnPolicy`` for a 3-D uint8 image), or a Dict of those
    (``MultiInputPolicy`` only); a Tuple, a nested Dict or another kind is refused for every
    policy, custom classes included, and a policy that does not fit is named with the one that
    does.

    Args:
        env: an env (or vector env, or its observation space), usually built with
            ``SimounObservation``.
        policy: the policy given to the SB3 algorithm, a name (``"CnnPolicy"``: one of
            :data:`SB3_POLICIES`, a misspelling is refused with its close match) or a class;
            custom policy classes (neither Cnn, Mlp nor MultiInput in the name) are checked only
            for a space that no SB3 policy takes.

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
    if isinstance(policy, type):
        check_policy_class(policy)
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
    name = policy if isinstance(policy, str) else policy.__name__
    problem = _unsupported(space)
    if problem:
        raise ValueError(
            f"no Stable-Baselines3 policy ({name} included) takes this observation space: "
            f"{problem}; {_fix_for(space)}. Space: {space}"
        )
    kind = _policy_kind(policy)
    if not kind:
        return policy
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
    if isinstance(space, spaces.Dict):
        if kind != "MultiInput":
            raise ValueError(
                f"{name} does not take a Dict observation ({space}); SB3 takes a Dict only with "
                f"'MultiInputPolicy'. Pass 'MultiInputPolicy', or flatten the Dict with "
                "gymnasium.wrappers.FlattenObservation for 'MlpPolicy'"
            )
        for key, sub in space.spaces.items():
            if _is_image(sub) and min(_image_sides(sub)) < NATURE_CNN_MIN_SIZE:
                height, width = _image_sides(sub)
                raise ValueError(
                    f"{name} convolves the image {key!r} of this Dict with NatureCNN, which "
                    f"needs at least {NATURE_CNN_MIN_SIZE}x{NATURE_CNN_MIN_SIZE}, got "
                    f"{height}x{width}; resize that image to {NATURE_CNN_MIN_SIZE}x"
                    f"{NATURE_CNN_MIN_SIZE} or larger, or pass a smaller features_extractor_class "
                    "in policy_kwargs."
                )
        return policy
    if kind == "MultiInput":
        fits = "'CnnPolicy'" if _is_image(space) else "'MlpPolicy'"
        raise ValueError(
            f"{name} needs a Dict observation, but this one is a {_kind_name(space)} ({space}); "
            f"use {fits}"
        )
    if not _is_image(space):
        if kind == "Cnn":
            raise ValueError(
                f"{name} convolves only a 3-D uint8 Box of bounds 0 .. 255 (an image to SB3), "
                f"but this observation is {space}; use 'MlpPolicy'"
            )
        return policy
    if kind != "Cnn":
        raise ValueError(
            f"{name} does not convolve the {space.shape} uint8 image (MlpPolicy flattens it "
            f"into an MLP on raw pixels, MultiInputPolicy needs a Dict); use 'CnnPolicy'."
        )
    height, width = _image_sides(space)
    if min(height, width) < NATURE_CNN_MIN_SIZE:
        raise ValueError(
            f"CnnPolicy's NatureCNN needs frames of at least {NATURE_CNN_MIN_SIZE}x"
            f"{NATURE_CNN_MIN_SIZE}, got {height}x{width}; use "
            f"SimounObservation(env, size={NATURE_CNN_MIN_SIZE}) or larger, or a smaller "
            f"features_extractor_class in policy_kwargs."
        )
    return policy
