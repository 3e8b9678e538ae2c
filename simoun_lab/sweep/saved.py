"""What a saved ``sweep.json`` may hold: each field checked against what
:meth:`~simoun_lab.sweep.grid.SweepSpec.create` accepts from the flags, so an edited or damaged
file is named with the key at fault before a trial is configured from it (where the problem
would otherwise be told as a flag the user never gave).

Example:
    >>> saved_problem({"preset": None, "base": {}, "grid": {}, "seeds": "1", "envs": ["a"]})
    'seeds is "1", not a list of seeds (integers in [0, 2**32), each once)'
"""

from __future__ import annotations

import json
import typing
from collections.abc import Callable
from typing import Any

from simoun_agent.config import PRESETS
from simoun_agent.config.envs import split_env_id
from simoun_agent.config.keys import close_match, config_fields, config_sections
from simoun_agent.config.rules import did_you_mean_name, is_int, rules_of, show

REQUIRED = ("preset", "base", "grid", "seeds", "envs")
"""The keys every sweep.json holds (``cpus_per_trial`` came later: 1 when absent)."""

OPTIONAL = ("cpus_per_trial",)

SET_BY_THE_SWEEP = ("seed", "env", "run_dir", "torch_threads")
"""Keys each trial gets from the sweep itself, which its grid may not vary."""

SEED_LIMIT = 2**32
"""Seeds numpy takes."""


def saved_problem(data: dict[str, Any]) -> str | None:
    """What is wrong with the fields of a sweep.json, naming the key; None when each holds what
    a sweep writes."""
    missing = [key for key in REQUIRED if key not in data]
    if missing:
        return f"it has no {' or '.join(missing)}, which every sweep records"
    unknown = [key for key in data if key not in REQUIRED + OPTIONAL]
    if unknown:
        return f"it holds the key {unknown[0]!r}, which no sweep writes"
    checks: tuple[tuple[str, Callable[[Any], str | None]], ...] = (
        ("preset", preset_problem),
        ("base", base_problem),
        ("grid", grid_problem),
        ("seeds", seeds_problem),
        ("envs", envs_problem),
        ("cpus_per_trial", cpus_problem),
    )
    for key, check in checks:
        if key in data and (problem := check(data[key])):
            return problem
    return preset_env_problem(data["preset"], data["envs"])


def preset_problem(preset: Any) -> str | None:
    if preset is None or preset in PRESETS:
        return None
    close = did_you_mean_name(preset, list(PRESETS)) if isinstance(preset, str) else ""
    return f"preset is {json.dumps(preset)}, which is no preset{close}"


def preset_env_problem(preset: str | None, envs: list[str]) -> str | None:
    """A preset meant for one task with an env of another (checked here, as the trials would
    refuse it naming ``--env``)."""
    if preset is None:
        return None
    chosen = PRESETS[preset]
    for env in envs:
        if not chosen.accepts(split_env_id(env)[1]):
            meant = "highway-env ids" if chosen.envs == "highway" else chosen.envs
            return f"preset {preset!r} is meant for {meant}, but envs lists {env!r}"
    return None


def base_problem(base: Any) -> str | None:
    if not isinstance(base, dict):
        return f"base is {json.dumps(base)}, not a JSON object of config keys"
    for key, value in base.items():
        if key in ("run_dir", "torch_threads"):
            return f"base sets {key}, which the sweep sets for each trial"
        if problem := key_problem(key) or value_problem(key, value):
            return f"base: {problem}"
    return None


def grid_problem(grid: Any) -> str | None:
    if not isinstance(grid, dict):
        return f"grid is {json.dumps(grid)}, not a JSON object of config keys and their values"
    for key, values in grid.items():
        if key in SET_BY_THE_SWEEP:
            return f"grid varies {key}, which the sweep sets for each trial"
        if key == "preset":
            return "grid varies preset, which only labels a run: a sweep has one preset"
        if problem := key_problem(key):
            return f"grid: {problem}"
        if not (isinstance(values, list) and values):
            return f"grid: {key} is {json.dumps(values)}, not a non-empty list of values"
        if len({show(value) for value in values}) < len(values):
            return f"grid: {key} lists a value twice"
        for value in values:
            if problem := value_problem(key, value):
                return f"grid: {problem}"
    return None


def seeds_problem(seeds: Any) -> str | None:
    good = (
        isinstance(seeds, list)
        and seeds
        and all(is_int(seed) and 0 <= seed < SEED_LIMIT for seed in seeds)
        and len(set(seeds)) == len(seeds)
    )
    if good:
        return None
    return (
        f"seeds is {json.dumps(seeds)[:80]}, not a list of seeds (integers in [0, 2**32), each "
        "once)"
    )


def envs_problem(envs: Any) -> str | None:
    good = (
        isinstance(envs, list)
        and envs
        and all(isinstance(env, str) and env for env in envs)
        and len(set(envs)) == len(envs)
    )
    if good:
        return None
    return f"envs is {json.dumps(envs)[:80]}, not a list of Gymnasium ids (at least one, each once)"


def cpus_problem(cpus: Any) -> str | None:
    if is_int(cpus) and cpus >= 1:
        return None
    return f"cpus_per_trial is {json.dumps(cpus)}, not an integer >= 1"


def key_problem(key: str) -> str | None:
    if key in config_fields():
        return None
    return f"{key!r} is no config key{close_match(key)}"


def value_problem(key: str, value: Any) -> str | None:
    """What is wrong with ``value`` for the config key ``key`` (its rule, as a run's saved
    config.json is checked), or None."""
    kind = config_fields()[key][0]
    if isinstance(value, list) and (typing.get_origin(kind) or kind) is tuple:
        value = tuple(value)
    name = key.rpartition(".")[2]
    rule = rules_of(config_sections()[key.removesuffix(name)])[name]
    if rule.ok(value):
        return None
    return f"{key} is {json.dumps(value)}, which must be {rule.need}"
