"""The paper's Table 2 driving measures (CARLA), adapted to highway-env.

| paper (CARLA)      | here (highway-env)                                                      |
|--------------------|-------------------------------------------------------------------------|
| episode reward     | sum of highway-env's rewards over the episode                           |
| distance (m)       | path length of the ego vehicle (highway-env positions are in metres)    |
| crash intensity    | ego speed (m/s) at the first step flagged crashed; crash rate alongside |
| average steer      | mean of abs(steering angle) / maximum steering angle                    |
| average brake      | mean of max(-acceleration, 0) / maximum deceleration (0 when not braking) |
| (not in Table 2)   | mean speed: mean ego speed (m/s) over the decisions                     |

The ego vehicle's state is read from ``env.unwrapped.vehicle`` (position, speed, the applied
``action`` in physical units) and the crash flag from ``info["crashed"]`` after each decision.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np


def is_driving_env(env: gym.Env) -> bool:
    """True for highway-env envs (an ego ``vehicle`` driven through an ``action_type``)."""
    base = env.unwrapped
    return hasattr(base, "vehicle") and hasattr(base, "action_type")


@dataclass
class DrivingEpisode:
    """Accumulates one episode's driving measures, one agent decision at a time."""

    reward: float = 0.0
    distance_m: float = 0.0
    crashed: bool = False
    crash_speed: float = math.nan
    steer: list[float] = field(default_factory=list)
    speed: list[float] = field(default_factory=list)
    brake: list[float] = field(default_factory=list)
    _position: np.ndarray | None = None

    def start(self, env: gym.Env) -> None:
        """Call after ``env.reset()``."""
        self._position = np.array(env.unwrapped.vehicle.position, dtype=float)

    def step(self, env: gym.Env, reward: float, info: dict) -> None:
        """Call after each ``env.step()``."""
        base = env.unwrapped
        vehicle = base.vehicle
        position = np.array(vehicle.position, dtype=float)
        self.distance_m += float(np.linalg.norm(position - self._position))
        self._position = position
        self.reward += float(reward)
        max_steer = max(abs(v) for v in base.action_type.steering_range)
        max_brake = abs(min(base.action_type.acceleration_range))
        applied = vehicle.action
        self.steer.append(abs(float(applied.get("steering", 0.0))) / max_steer)
        self.speed.append(float(vehicle.speed))
        self.brake.append(max(-float(applied.get("acceleration", 0.0)), 0.0) / max_brake)
        if info.get("crashed", vehicle.crashed) and not self.crashed:
            self.crashed = True
            self.crash_speed = float(vehicle.speed)


def summarize(episodes: list[DrivingEpisode]) -> dict[str, float]:
    """Means over episodes; ``crash_speed`` averages the crashed episodes only (NaN if none)."""
    crash_speeds = [e.crash_speed for e in episodes if e.crashed]
    return {
        "episode_reward": float(np.mean([e.reward for e in episodes])),
        "distance_m": float(np.mean([e.distance_m for e in episodes])),
        "crash_rate": float(np.mean([e.crashed for e in episodes])),
        "crash_speed": float(np.mean(crash_speeds)) if crash_speeds else math.nan,
        "mean_abs_steer": float(np.mean([np.mean(e.steer) for e in episodes])),
        "mean_speed": float(np.mean([np.mean(e.speed) if e.speed else math.nan for e in episodes])),
        "brake_fraction": float(np.mean([np.mean(e.brake) for e in episodes])),
    }


MEASURES = (
    ("return_mean", "return", ".1f"),
    ("return_std", "± std", ".1f"),
    ("crash_rate", "crash rate", ".2f"),
    ("distance_m", "distance (m)", ".0f"),
    ("mean_speed", "mean speed (m/s)", ".1f"),
    ("mean_abs_steer", "mean abs(steer)", ".3f"),
    ("brake_fraction", "brake fraction", ".3f"),
    ("length_mean", "length", ".0f"),
)
"""Each driving measure's key, table header and format, for every table that shows one."""


def columns(*keys: str) -> tuple[tuple[str, str, str], ...]:
    """(key, header, format) of each of ``keys``, in that order."""
    known = {measure[0]: measure for measure in MEASURES}
    return tuple(known[key] for key in keys)
