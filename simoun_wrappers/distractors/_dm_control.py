"""What the distractors share: finding the dm_control physics, checking the level, seeding."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from simoun_wrappers._checks import check_reset_seed, is_int

LEVELS = ("easy", "hard")


def is_closed_dm_control(env: gym.Env) -> bool:
    """Whether ``env`` is a dm_control task whose ``close()`` freed its physics (shimmy's
    close() frees the physics but keeps it: its model is gone)."""
    physics = getattr(getattr(env.unwrapped, "_env", None), "physics", None)
    return physics is not None and not hasattr(physics, "model")


def check_open(env: gym.Env, owner: str) -> None:
    """A ValueError (as Python's closed files give) naming ``close()`` when ``env`` is a
    dm_control task whose ``close()`` freed its physics. ``owner`` calls it before each reset,
    step and render: shimmy's own error then is an AttributeError deep in dm_control."""
    if is_closed_dm_control(env):
        spec = env.unwrapped.spec
        env_id = spec.id if spec is not None else "dm_control/cartpole-swingup-v0"
        raise ValueError(
            f"{owner} cannot reset, step or render {env.unwrapped}: the env was closed "
            f"(close() freed its dm_control physics). Make the env anew, "
            f"gym.make({env_id!r}, render_mode='rgb_array'), and wrap it again."
        )


def dm_control_physics(env: gym.Env, owner: str, refusal: str | None = None) -> Any:
    """The ``dm_control.mujoco.Physics`` of a dm_control task made through shimmy.

    Raises a TypeError for any other env, with ``refusal`` as its message (by default one that
    names what works instead for a distractor), and the ValueError of :func:`check_open` for a
    task that was closed.
    """
    check_open(env, owner)
    physics = getattr(getattr(env.unwrapped, "_env", None), "physics", None)
    if physics is None:
        raise TypeError(
            refusal
            or f"{owner} needs a dm_control task made through shimmy (it changes the MuJoCo "
            f"model or reads its segmentation), got {env.unwrapped}; make one with "
            f"gym.make('dm_control/cartpole-swingup-v0', render_mode='rgb_array'). For other "
            f"envs, RandomConvolution(env) randomises the appearance of any pixel env."
        )
    return physics


def check_level(level: str, owner: str) -> None:
    if level not in LEVELS:
        raise ValueError(f"{owner} level must be one of {LEVELS}, got {level!r}.")


def check_seed(seed: int | None, owner: str) -> None:
    if seed is not None and not (is_int(seed) and seed >= 0):
        raise ValueError(f"{owner} seed must be a non-negative int or None, got {seed!r}.")


def episode_rng(
    seed: int | None, reset_seed: int | None, current: np.random.Generator, owner: str
) -> np.random.Generator:
    """The generator of an episode's distraction.

    ``reset(seed=s)`` makes it a function of ``(seed, s)`` alone, so evaluation episode ``s``
    sees the same distraction whatever ran before; an unseeded reset keeps drawing from the
    wrapper's own stream (seeded by ``seed`` at construction). The env's RNG is never used, so
    the dynamics cannot change.
    """
    check_reset_seed(reset_seed, owner)
    if reset_seed is None:
        return current
    return np.random.default_rng([reset_seed] if seed is None else [reset_seed, seed])
