"""An env broken on purpose, for tests whose trial must fail inside a worker after every check
before training has passed: importing this module registers it."""

import gymnasium as gym

from simoun_agent.envs import PointReach

NAN_REACH_ID = "simoun-test/NanReach-v0"


class NanReach(PointReach):
    """PointReach whose rewards are NaN when ``nan_reward`` is set: it is made, reset and
    rendered as PointReach is, so only a step shows the fault."""

    def __init__(self, render_mode: str | None = None, nan_reward: bool = False):
        super().__init__(render_mode=render_mode)
        self.nan_reward = nan_reward

    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        return obs, float("nan") if self.nan_reward else reward, terminated, truncated, info


if NAN_REACH_ID not in gym.registry:
    gym.register(NAN_REACH_ID, entry_point=NanReach)
