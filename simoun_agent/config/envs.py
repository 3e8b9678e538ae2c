"""What the configuration knows of environment ids: Gymnasium's MODULE:ID form, the paper's
DeepMind Control tasks and their action repeats, and highway-env's ids."""

from __future__ import annotations

import gymnasium as gym

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


def is_highway(env_id: str) -> bool:
    """True for ids registered by highway-env (``highway-v0``, ``merge-v0``, ...)."""
    spec = gym.registry.get(env_id)
    if spec is None:
        return env_id.split("-v")[0] in {"highway", "highway-fast", "merge", "roundabout"}
    entry = spec.entry_point if isinstance(spec.entry_point, str) else ""
    return entry.startswith("highway_env")
