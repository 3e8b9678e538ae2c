"""The numeric keys of a highway-env task's ``config`` that some values turn into another task, or
none: a simulation that never advances, a road without lanes, an episode over before it starts.
highway-env takes such values without a word (``"simulation_frequency": 0`` runs no simulation
step, so every episode returns the same), so they are refused before the env is made, naming
``config.KEY`` and a value that works.

Example:
    >>> check_highway_config("highway-fast-v0", {"lanes_count": 2}, {"lanes_count": 3})
    >>> check_highway_config("highway-fast-v0", {"lanes_count": 0}, {"lanes_count": 3})
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    simoun_agent.config.errors.SetupError: --env-kwargs: config.lanes_count=0 (...) must be a...
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from simoun_agent.config import SetupError


@dataclass(frozen=True)
class Limit:
    """The values one key of highway-env's ``config`` takes: at least ``low`` (above it when
    ``open_low``), at most ``high``, a whole number when ``whole``."""

    meaning: str
    """what the key sets, in words"""
    low: float
    open_low: bool = False
    whole: bool = False
    high: float | None = None

    def ok(self, value: float) -> bool:
        above = value > self.low if self.open_low else value >= self.low
        below = self.high is None or value <= self.high
        return above and below and (not self.whole or float(value).is_integer())

    def need(self) -> str:
        kind = "a whole number" if self.whole else "a number"
        bound = f"> {self.low:g}" if self.open_low else f">= {self.low:g}"
        return f"{kind} {bound}" + (f" and <= {self.high:g}" if self.high is not None else "")


HIGHWAY_LIMITS = {
    "simulation_frequency": Limit("simulation steps per second", 0, open_low=True),
    "policy_frequency": Limit("agent decisions per second", 0, open_low=True),
    "duration": Limit("episode length in seconds", 0, open_low=True),
    "lanes_count": Limit("number of lanes", 1, whole=True),
    "vehicles_count": Limit("number of other vehicles", 0, whole=True),
    "controlled_vehicles": Limit("number of vehicles the agent drives", 1, whole=True),
    "initial_vehicle_count": Limit("number of vehicles at the start", 0, whole=True),
    "other_vehicles": Limit("number of other vehicles", 0, whole=True),
    "vehicles_density": Limit("traffic density", 0, open_low=True),
    "spawn_probability": Limit("chance of a new vehicle at each step", 0, high=1),
    "speed_limit": Limit("speed limit in m/s", 0, open_low=True),
    "scaling": Limit("pixels per metre of the env's own viewer", 0, open_low=True),
}
"""What each numeric key of a highway-env ``config`` (in any task that has it) must be for the
task to be one: frequencies, durations, densities and the speed limit above 0, counts of lanes
and of driven vehicles at least 1, counts of other vehicles at least 0, a probability in [0, 1].
The screen size is left out: simoun's cameras set it for every view."""


def check_highway_config(env_id: str, given: Any, defaults: Any) -> None:
    """SetupError for a key of ``given`` (the ``config`` of ``--env-kwargs``) that
    :data:`HIGHWAY_LIMITS` refuses, or for a policy frequency above the simulation frequency;
    ``defaults`` is the task's ``default_config()``, whose keys are the task's. Values that
    are not numbers are left to the kind check (a string for a number)."""
    if not isinstance(given, dict) or not isinstance(defaults, dict):
        return
    for key, value in given.items():
        limit = HIGHWAY_LIMITS.get(key)
        if limit is None or key not in defaults or not _is_number(value):
            continue
        if not limit.ok(value):
            raise SetupError(
                f"--env-kwargs: config.{key}={json.dumps(value)} ({env_id}'s {limit.meaning}) "
                f"must be {limit.need()}; e.g. {_example(key, defaults[key])} (its "
                f"default), or drop config.{key}"
            )
    _check_frequencies(env_id, given, defaults)


def _check_frequencies(env_id: str, given: dict, defaults: dict) -> None:
    """SetupError when the policy frequency given (or the default one) is above the simulation
    frequency: highway-env runs ``simulation_frequency // policy_frequency`` simulation steps
    per decision, so none would run and every episode would be the same."""
    keys = ("simulation_frequency", "policy_frequency")
    if not any(key in given for key in keys):
        return
    simulation, policy = (given.get(key, defaults.get(key)) for key in keys)
    if not (_is_number(simulation) and _is_number(policy)) or simulation // policy >= 1:
        return
    raise SetupError(
        f"--env-kwargs: config.policy_frequency={json.dumps(policy)} is above "
        f"config.simulation_frequency={json.dumps(simulation)} for {env_id}: highway-env runs "
        "simulation_frequency // policy_frequency simulation steps per decision, so no vehicle "
        "would ever move and every episode would be the same; set config.simulation_frequency "
        f"to {json.dumps(policy)} or more, or config.policy_frequency to "
        f"{json.dumps(simulation)} or less"
    )


def _is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _example(key: str, value: object) -> str:
    return f"'{json.dumps({'config': {key: value}})}'"
