"""Small environments bundled for tests and examples; importing this module registers them."""

import gymnasium as gym

from simoun_agent.envs.point_reach import PointReach

POINT_REACH_ID = "simoun/PointReach-v0"

if POINT_REACH_ID not in gym.registry:
    gym.register(POINT_REACH_ID, entry_point="simoun_agent.envs.point_reach:PointReach")

__all__ = ["POINT_REACH_ID", "PointReach"]
