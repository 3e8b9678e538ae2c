"""The packages that register Gymnasium ids on import, known by the ids' namespace or name, so
that an id of a package that is not installed (or not imported) is named with its package
rather than called unknown.

Example:
    >>> provider("ALE/Pong-v5").pip
    'ale-py'
    >>> provider("CartPole-v1") is None
    True
"""

from __future__ import annotations

import contextlib
import importlib
import importlib.util
from dataclasses import dataclass

import gymnasium as gym

from simoun_agent.config import SetupError


@dataclass(frozen=True)
class Provider:
    """A package whose import registers a family of ids."""

    module: str
    """the module to import (the MODULE of ``--env MODULE:ID``)"""
    pip: str
    """its name for ``pip install``"""
    what: str
    """the family of environments, in words"""


PROVIDERS_BY_NAMESPACE = {
    "ALE": Provider("ale_py", "ale-py", "the Atari games of the Arcade Learning Environment"),
    "Meta-World": Provider("metaworld", "metaworld", "Meta-World's robot arm tasks"),
}
"""``NAMESPACE/`` of an id -> the package that registers it (``dm_control/`` ids are simoun's own
suite, see ``make_env._SUITES``)"""

PROVIDERS_BY_PREFIX = {
    ("MiniGrid-", "BabyAI-"): Provider("minigrid", "minigrid", "MiniGrid's grid worlds"),
    ("MiniWorld-",): Provider("miniworld", "miniworld", "MiniWorld's 3D rooms"),
    (
        "Fetch",
        "HandManipulate",
        "HandReach",
        "Adroit",
        "AntMaze_",
        "PointMaze_",
        "FrankaKitchen",
    ): Provider("gymnasium_robotics", "gymnasium-robotics", "Gymnasium-Robotics' tasks"),
    ("Panda",): Provider("panda_gym", "panda-gym", "panda-gym's robot arm tasks"),
    ("Safety",): Provider("safety_gymnasium", "safety-gymnasium", "Safety-Gymnasium's tasks"),
    ("mo-",): Provider("mo_gymnasium", "mo-gymnasium", "MO-Gymnasium's multi-objective tasks"),
}
"""the start of an id without a namespace -> the package that registers it"""


def provider(env_id: str) -> Provider | None:
    """The package that registers ``env_id``, known by its namespace or the start of its name;
    None for an id of no package listed here."""
    namespace, slash, _ = env_id.partition("/")
    if slash and namespace in PROVIDERS_BY_NAMESPACE:
        return PROVIDERS_BY_NAMESPACE[namespace]
    for prefixes, known in PROVIDERS_BY_PREFIX.items():
        if env_id.startswith(prefixes):
            return known
    return None


def unregistered_package(env_id: str) -> SetupError | None:
    """The SetupError for ``env_id`` (not registered) when a known package registers it: what
    to install when the package is missing, and the ``--env MODULE:ID`` that imports it when
    it is installed and registers the id; None for an id of no known package, or one that its
    installed package does not register (its close ids are then registered to be offered)."""
    known = provider(env_id)
    if known is None:
        return None
    if importlib.util.find_spec(known.module) is None:
        return SetupError(
            f"--env {env_id}: ids like this one belong to {known.what}, which the package "
            f"{known.pip} registers when it is imported, and {known.pip} is not installed; "
            f"pip install {known.pip}, then pass --env {known.module}:{env_id}"
        )
    with contextlib.suppress(Exception):  # a package that fails on import: the id stays unknown
        importlib.import_module(known.module)
    if env_id not in gym.registry:
        return None
    return SetupError(
        f"--env {env_id}: {known.module} registers this id when it is imported; pass --env "
        f"{known.module}:{env_id} so that it is imported first"
    )
