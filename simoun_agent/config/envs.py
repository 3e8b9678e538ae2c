"""What the configuration knows of environment ids: Gymnasium's MODULE:ID form, the paper's
DeepMind Control tasks and their action repeats, and highway-env's ids."""

from __future__ import annotations

import functools
import importlib

import gymnasium as gym
from gymnasium.envs.registration import EnvSpec

PAPER_ACTION_REPEAT = {
    "cartpole-swingup": 8,
    "reacher-easy": 4,
    "cheetah-run": 4,
    "ball_in_cup-catch": 4,
    "walker-walk": 2,
    "finger-spin": 2,
}
"""Action repeat of the paper's six DeepMind Control tasks (DrQ's values)."""


def split_env_id(env: str) -> tuple[str | None, str]:
    """``"minigrid:MiniGrid-DoorKey-6x6-v0"`` -> ``("minigrid", "MiniGrid-DoorKey-6x6-v0")``,
    Gymnasium's MODULE:ID form (``gym.make`` imports MODULE to register ID); ``(None, env)``
    for a plain id."""
    module, sep, env_id = env.rpartition(":")
    return (module, env_id) if sep else (None, env)


def dmc_task(env_id: str) -> str | None:
    """``"dm_control/cartpole-swingup-v0"`` -> ``"cartpole-swingup"``; None for other ids."""
    if not env_id.startswith("dm_control/"):
        return None
    return env_id.removeprefix("dm_control/").rsplit("-v", 1)[0]


def env_label(env_id: str) -> str:
    """The task's name in run and trial directories and in reports:
    ``dm_control/cartpole-swingup-v0`` -> ``cartpole-swingup``; others with ``/`` as ``-``, less
    a ``MODULE:`` that names the package registering the id."""
    env_id = env_id.rpartition(":")[2]
    return dmc_task(env_id) or env_id.replace("/", "-")


@functools.cache
def register_family(package: str) -> bool:
    """Import ``package`` (``highway_env``, ``minigrid``, ``shimmy``), whose import registers a
    family of ids, so that the registry holds them before an id is judged by its family (an
    id is not highway-env's merely because highway_env was not imported yet); whether it is
    installed."""
    try:
        importlib.import_module(package)
    except ImportError:
        return False
    return True


def registered_spec(env_id: str, package: str) -> EnvSpec | None:
    """``env_id``'s registration once the family ``package`` registers is in the registry
    (:func:`register_family`); None for an id that neither it nor an imported module
    registers."""
    if env_id not in gym.registry:
        register_family(package)
    return gym.registry.get(env_id)


def is_highway(env_id: str) -> bool:
    """True for ids registered by highway-env (``highway-v0``, ``intersection-v0``, ...),
    whether or not highway_env was imported before."""
    spec = registered_spec(env_id, "highway_env")
    if spec is None:  # highway-env is not installed: its best-known ids still count
        return env_id.split("-v")[0] in {"highway", "highway-fast", "merge", "roundabout"}
    entry = spec.entry_point if isinstance(spec.entry_point, str) else ""
    return entry.startswith("highway_env")
