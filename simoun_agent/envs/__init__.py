"""Small environments bundled for tests and examples; importing this module registers them."""

import gymnasium as gym

from simoun_agent.envs.point_reach import PointReach
from simoun_wrappers._homes import missing_name

POINT_REACH_ID = "simoun/PointReach-v0"

if POINT_REACH_ID not in gym.registry:
    gym.register(POINT_REACH_ID, entry_point="simoun_agent.envs.point_reach:PointReach")

__all__ = ["POINT_REACH_ID", "PointReach"]


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
