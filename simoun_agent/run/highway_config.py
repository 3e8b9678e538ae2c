"""The keys and values of a highway-env task's ``config`` that turn it into another task, or
none: a key the task does not have (highway-env ignores it, so a misspelt ``lane_count`` leaves
the default), a value of another kind than the default's (``"offroad_terminal": "no"`` is taken
by its truth value), a second driven vehicle (the agent drives one; the other gets no driver),
manual control (the agent's actions would never reach the vehicle), an action with no axis, a
range whose ends are swapped (the high-speed reward then pays for driving slowly, a steering
range mirrors the wheel), a view setting simoun's cameras replace, a simulation that never
advances, a road without lanes, an episode over before it starts. highway-env takes
such values without a word, so they are refused before the env is made, naming ``config.KEY``
and a value that works.

Example:
    >>> check_highway_config("highway-fast-v0", {"lanes_count": 2}, {"lanes_count": 3})
    >>> check_highway_config("highway-fast-v0", {"lanes_count": 0}, {"lanes_count": 3})
    ... # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    simoun_agent.config.errors.SetupError: --env-kwargs: config.lanes_count=0 (...) must be a...
"""

from __future__ import annotations

import difflib
import inspect
import json
import math
import numbers
from dataclasses import dataclass
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.config.rules import plain_json


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
    "initial_vehicle_count": Limit("number of vehicles at the start", 0, whole=True),
    "other_vehicles": Limit("number of other vehicles", 0, whole=True),
    "vehicles_density": Limit("traffic density", 0, open_low=True),
    "spawn_probability": Limit("chance of a new vehicle at each step", 0, high=1),
    "speed_limit": Limit("speed limit in m/s", 0, open_low=True),
}
"""What each numeric key of a highway-env ``config`` (in any task that has it) must be for the
task to be one: frequencies, durations, densities and the speed limit above 0, a count of lanes
at least 1, counts of other vehicles at least 0, a probability in [0, 1]. The view's keys are
refused whole (:data:`CAMERA_KEYS`). ``controlled_vehicles`` must be 1 (see
:func:`_check_driven`)."""

LIMIT_PATTERNS = (
    (("lanes",), Limit("number of lanes", 1, whole=True)),
    (("_count", "_vehicles"), Limit("number of vehicles", 0, whole=True)),
    (("spacing",), Limit("spacing between vehicles at the start", 0, open_low=True)),
    (("length",), Limit("road length in metres", 0, open_low=True)),
    (("radius",), Limit("radius in metres", 0, open_low=True)),
    (("duration",), Limit("duration in seconds", 0, open_low=True)),
    (("frequency",), Limit("rate per second", 0, open_low=True)),
    (("density",), Limit("traffic density", 0, open_low=True)),
    (("probability",), Limit("probability", 0, high=1)),
    (("noise",), Limit("noise scale", 0)),
    (("speed_limit",), Limit("speed limit in m/s", 0, open_low=True)),
)
"""Limits of the numeric keys :data:`HIGHWAY_LIMITS` does not list, by what their names say
(``ego_spacing``, ``before_merge_length``, ``roundabout_radius``, ``state_noise``, ...), so
that every task's spacings, lengths, counts, durations, frequencies, densities and noises are
held to their meaning: a negative spacing puts the ego vehicle before the road's start, off its
lane. Rewards, costs and weights are left free (a negative one is a penalty), and so are keys
whose name says none of these."""

FREE_WORDS = ("reward", "cost", "weight")
"""words of a key whose value may take any sign"""


def limit_of(key: str) -> Limit | None:
    """The :class:`Limit` of the highway-env ``config`` key ``key``: its own in
    :data:`HIGHWAY_LIMITS`, else the first of :data:`LIMIT_PATTERNS` whose words its name
    holds; None for a reward, cost or weight, or a key that names no quantity."""
    if key in HIGHWAY_LIMITS:
        return HIGHWAY_LIMITS[key]
    if any(word in key for word in FREE_WORDS):
        return None
    for words, limit in LIMIT_PATTERNS:
        if any(word in key for word in words):
            return limit
    return None


ORDERED_RANGES = {
    "reward_speed_range": "speeds mapped onto the high-speed reward, [slowest, fastest] in m/s",
    "speed_range": "speeds the vehicle may reach, [lowest, highest] in m/s",
    "acceleration_range": "accelerations the action's [-1, 1] maps onto, [lowest, highest] "
    "in m/s^2",
    "steering_range": "steering angles the action's [-1, 1] maps onto, [lowest, highest] in "
    "radians",
}
"""``[low, high]`` keys (of ``config`` or of ``config.action``) whose order makes the task, with
what they set: highway-env maps a speed through ``reward_speed_range`` with a linear map, so
swapped ends pay the high-speed reward for driving slowly; it takes ``speed_range`` as
(MIN_SPEED, MAX_SPEED); and it maps the agent's [-1, 1] action onto ``acceleration_range`` and
``steering_range`` linearly, so swapped ends mirror that axis (+1 brakes, or steers the other
way) without a word. Every other ``*_range`` key must run low to high too."""

CAMERA_KEYS = {
    "scaling": "--cameras and --image-size",
    "centering_position": "--cameras",
    "screen_width": "--image-size",
    "screen_height": "--image-size",
}
"""keys of highway-env's ``config`` that set the rendered view, which simoun's cameras set for
every view (their layout from ``--cameras``, their size and zoom from ``--image-size``): a
value given here would be replaced without a word; each with the flags that set it"""


def check_highway_config(env_id: str, given: Any, defaults: Any) -> None:
    """SetupError for a key of ``given`` (the ``config`` of ``--env-kwargs``) that the task's
    ``defaults`` (its ``default_config()``) lack, a value of another kind than the default's,
    a value :func:`limit_of` refuses, a view key simoun's cameras set, a ``controlled_vehicles``
    other than 1, manual control, a range in the wrong order, an unknown action type or key, an
    action with no axis, or a policy frequency above the simulation frequency. Numpy scalars and
    tuples are read as the numbers and lists they hold."""
    if not isinstance(given, dict) or not isinstance(defaults, dict):
        return
    given = plain_json(given)
    for key, value in given.items():
        _check_known(env_id, key, defaults)
        _check_not_camera(key, value)
        _check_kind(env_id, f"config.{key}", value, defaults[key])
        limit = limit_of(key)
        if limit is not None and _is_number(value) and not limit.ok(value):
            raise SetupError(
                f"--env-kwargs: config.{key}={json.dumps(value)} ({env_id}'s {limit.meaning}) "
                f"must be {limit.need()}; e.g. {_example(key, defaults[key])} (its "
                f"default), or drop config.{key}"
            )
        _check_range(f"config.{key}", value)
    _check_driven(env_id, given)
    _check_manual(env_id, given)
    _check_action(env_id, given.get("action"), defaults.get("action"))
    _check_frequencies(env_id, given, defaults)


def _check_known(env_id: str, key: str, defaults: dict) -> None:
    """SetupError for a key that is not one of the task's: highway-env would ignore it."""
    if key in defaults:
        return
    close = difflib.get_close_matches(key, list(defaults), n=1)
    hint = f"did you mean config.{close[0]}?" if close else f"its keys are {', '.join(defaults)}."
    raise SetupError(
        f"--env-kwargs: config.{key} is not a setting of {env_id}'s config, and highway-env "
        f"would ignore it; {hint} Fix the key or drop it"
    )


def _kind(value: object) -> str | None:
    """The JSON kind of a default value, in words; None where any value may go (a None
    default: highway-env reads None there as "choose for me")."""
    if value is None:
        return None
    if isinstance(value, bool):
        return "true or false"
    if _is_number(value):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)} values"
    if isinstance(value, dict):
        return "a JSON object"
    return None


def _fits(value: object, default: object) -> bool:
    if isinstance(default, bool):
        return isinstance(value, bool)
    if _is_number(default):
        return _is_number(value)
    if isinstance(default, str):
        return isinstance(value, str)
    if isinstance(default, (list, tuple)):
        return (
            isinstance(value, (list, tuple))
            and len(value) == len(default)
            and all(_fits(item, expected) for item, expected in zip(value, default, strict=True))
        )
    if isinstance(default, dict):
        return isinstance(value, dict)
    return True


def _check_kind(env_id: str, name: str, value: object, default: object) -> None:
    """SetupError for a value of another kind than the default's: a switch given ``"yes"`` (any
    non-empty string switches it on, ``"no"`` too), a count given ``true`` (read as 1), a list
    where a number goes; ``null`` is refused where the default is not, as highway-env takes it
    as the value itself rather than as its default."""
    kind = _kind(default)
    if kind is None or _fits(value, default):
        return
    key = name.split(".")[-1]
    limit = limit_of(key) if name.count(".") == 1 else None
    need = limit.need() if limit is not None else kind
    if isinstance(default, (list, tuple)) and all(_is_number(item) for item in default):
        need = f"a list of {len(default)} numbers"
    raise SetupError(
        f"--env-kwargs: {name}={json.dumps(value)} does not fit {env_id}: {name} must be "
        f"{need} (its default is {json.dumps(_plain(default))}); e.g. "
        f"'{json.dumps(nested(name, _plain(default)))}', or drop {name}"
    )


def _check_range(name: str, value: object) -> None:
    """SetupError for a ``[low, high]`` range (any ``*_range`` key) whose ends are swapped or
    equal (:data:`ORDERED_RANGES`)."""
    key = name.split(".")[-1]
    if not key.endswith("_range") or not _is_pair(value):
        return
    low, high = value
    if low < high:
        return
    meaning = ORDERED_RANGES.get(key, "range [low, high]")
    if low == high:
        raise SetupError(
            f"--env-kwargs: {name}={json.dumps(value)} ({meaning}) has equal ends, so it holds "
            f"one value; give a low end below the high end, e.g. "
            f"'{json.dumps(nested(name, [-abs(low) or -1, abs(low) or 1]))}', or drop {name}"
        )
    mirrored = (
        ", and swapped ends would mirror that axis of the agent's action"
        if key in ("acceleration_range", "steering_range")
        else ""
    )
    raise SetupError(
        f"--env-kwargs: {name}={json.dumps(value)} ({meaning}) must have its low end first and "
        f"below its high end{mirrored}; e.g. '{json.dumps(nested(name, sorted(value)))}', or "
        f"drop {name}"
    )


def _check_not_camera(key: str, value: object) -> None:
    """SetupError for a view key (:data:`CAMERA_KEYS`): simoun's cameras set it for every view."""
    if key not in CAMERA_KEYS:
        return
    flags = CAMERA_KEYS[key]
    raise SetupError(
        f"--env-kwargs: config.{key}={json.dumps(value)} sets highway-env's rendered view, which "
        f"simoun's cameras set for every view the agent sees (from {flags}), so the value "
        f"would be replaced; drop config.{key} and pick the views with {flags}"
    )


def _check_manual(env_id: str, given: dict) -> None:
    """SetupError for ``manual_control`` switched on: highway-env then drives the vehicle from
    the keyboard and never applies the agent's actions."""
    if given.get("manual_control") is not True:
        return
    raise SetupError(
        f"--env-kwargs: config.manual_control=true makes {env_id} drive the vehicle from the "
        "keyboard of a window, and highway-env would never apply the agent's actions, so the "
        "agent could learn nothing; drop config.manual_control (or set it false)"
    )


def _check_driven(env_id: str, given: dict) -> None:
    """SetupError for a ``controlled_vehicles`` other than 1: the agent drives one vehicle, and
    highway-env gives the others no driver (they go straight at their first speed)."""
    if "controlled_vehicles" not in given or given["controlled_vehicles"] == 1:
        return
    raise SetupError(
        f"--env-kwargs: config.controlled_vehicles={json.dumps(given['controlled_vehicles'])} "
        f"must be 1 for {env_id}: the agent drives one vehicle, and highway-env would give "
        "any other no driver at all (it goes straight at its first speed); give "
        '\'{"config": {"controlled_vehicles": 1}}\', or drop config.controlled_vehicles'
    )


ACTION_TYPES = ("ContinuousAction", "DiscreteAction", "DiscreteMetaAction", "MultiAgentAction")
"""the action types highway-env's ``action_factory`` makes (``config.action.type``)"""


def _check_action(env_id: str, action: object, default: object) -> None:
    """SetupError for ``config.action`` with an unknown type, a key its action class does not
    take (it takes ``**kwargs`` and ignores them), a value of another kind than the class's
    default, or a range in the wrong order. Keys of the task's own default action are taken,
    as highway-env writes some there that the class ignores."""
    if not isinstance(action, dict) or "type" not in action:
        return
    kind = action["type"]
    if kind not in ACTION_TYPES:
        close = difflib.get_close_matches(str(kind), ACTION_TYPES, n=1)
        hint = f"did you mean {close[0]!r}? The" if close else "the"
        raise SetupError(
            f"--env-kwargs: config.action.type={json.dumps(kind)} is not an action type of "
            f"highway-env; {hint} types are {', '.join(ACTION_TYPES)}, and the agent drives "
            'with \'{"config": {"action": {"type": "ContinuousAction"}}}\''
        )
    parameters = _action_parameters(kind)
    known = {"type", *parameters, *(default if isinstance(default, dict) else {})}
    for key, value in action.items():
        if key not in known:
            close = difflib.get_close_matches(key, sorted(known), n=1)
            hint = (
                f"did you mean config.action.{close[0]}?"
                if close
                else f"its keys are {', '.join(sorted(known))}."
            )
            raise SetupError(
                f"--env-kwargs: config.action.{key} is not a setting of highway-env's {kind}, "
                f"which would ignore it; {hint} Fix the key or drop it"
            )
        _check_kind(env_id, f"config.action.{key}", value, parameters.get(key))
        if key.endswith("_range") and value is not None and not _is_pair(value):
            example = json.dumps(nested(f"config.action.{key}", [-1, 1]))
            raise SetupError(
                f"--env-kwargs: config.action.{key}={json.dumps(value)} must be a list of 2 "
                f"numbers [low, high]; e.g. '{example}', or drop config.action.{key}"
            )
        _check_range(f"config.action.{key}", value)
    _check_axes(kind, action, parameters)


def _check_axes(kind: str, action: dict, parameters: dict[str, Any]) -> None:
    """SetupError for an action with ``lateral`` and ``longitudinal`` both false: highway-env
    then gives it no axis at all (an empty action), and the agent has nothing to drive with."""
    if not {"lateral", "longitudinal"} <= set(parameters):
        return
    axes = [axis for axis in ("longitudinal", "lateral") if action.get(axis, parameters[axis])]
    if axes:
        return
    raise SetupError(
        f"--env-kwargs: config.action has longitudinal=false and lateral=false, so highway-env's "
        f"{kind} has no axis (neither throttle nor steering) and the agent could not drive; set "
        "one of them true, or drop both (the agent then controls throttle and steering)"
    )


def _action_parameters(kind: str) -> dict[str, Any]:
    """The named parameters of highway-env's action class ``kind`` and their defaults."""
    from highway_env.envs.common import action

    parameters = inspect.signature(getattr(action, kind)).parameters.values()
    return {
        p.name: None if p.default is p.empty else p.default
        for p in parameters
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name not in ("self", "env")
    }


def _is_pair(value: object) -> bool:
    return isinstance(value, (list, tuple)) and len(value) == 2 and all(map(_is_number, value))


def _plain(value: object) -> object:
    """A default as JSON writes it (highway-env keeps some as numpy floats or tuples)."""
    if isinstance(value, (list, tuple)):
        return [_plain(item) for item in value]
    return float(value) if isinstance(value, float) else value


def nested(name: str, value: object) -> dict:
    """``"config.lanes_count", 4`` -> ``{"config": {"lanes_count": 4}}``."""
    head, _, rest = name.partition(".")
    return {head: nested(rest, value) if rest else value}


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
    """A finite number, a numpy one too (not a bool)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)


def _example(key: str, value: object) -> str:
    return f"'{json.dumps({'config': {key: value}})}'"
