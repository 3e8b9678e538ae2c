"""A run's configuration resolved in four layers, each checked the same way.

The dataclass defaults (the paper's DrQ-style setup), then a named preset
(:mod:`simoun_agent.config.presets`), then a named agent recipe (``--agent.recipe drq``,
:mod:`simoun_agent.config.recipes`, with its values for the run's DMC task), then the user's
overrides (``--agent.batch-size 64`` or ``--set agent.batch_size=64``). A layer's value replaces
the one below it, but for ``env_kwargs``, whose keys are merged into the layer's below (key by
key, nested dicts too): ``--preset highway-cpu --env-kwargs '{"config": {"lanes_count": 2}}'``
keeps the preset's continuous actions and episode settings. Every layer's keys
pass :func:`~simoun_agent.config.keys.check_keys`, so a misspelled key is refused with its
close match wherever it comes from. The resolved config is saved as ``config.json`` in the run
directory and checked again when the run is resumed.

Example:
    >>> config = resolve("cpu", {"agent.recipe": "drq", "seed": 3})
    >>> config.agent.encoder, config.agent.batch_size, config.seed
    ('stacked', 64, 3)
    >>> from_dict(to_dict(config)) == config
    True
"""

from __future__ import annotations

import dataclasses
import json
import typing
from typing import Any

from simoun_agent.config.envs import dmc_task, split_env_id
from simoun_agent.config.errors import SetupError
from simoun_agent.config.keys import check_keys, config_fields, config_sections
from simoun_agent.config.presets import PRESETS, fit_highway_config
from simoun_agent.config.recipes import RECIPES
from simoun_agent.config.rules import did_you_mean_name, rules_of
from simoun_agent.config.train import TrainConfig


def resolve(preset: str | None, overrides: dict[str, Any]) -> TrainConfig:
    """Build a TrainConfig from the defaults, a preset and ``{"agent.lr": 3e-4, ...}`` overrides.

    Every layer (the preset, the recipe, the overrides) is checked for unknown keys the same
    way. Raises SetupError for an unknown preset or key, or a preset meant for another
    environment.
    """
    if not isinstance(overrides, dict):
        raise SetupError(
            f"overrides must be a dict of config keys, got {type(overrides).__name__} "
            f"{overrides!r:.60}; e.g. resolve('cpu', {{'agent.lr': 3e-4, 'seed': 1}})"
        )
    check_keys(overrides)
    values: dict[str, Any] = {}
    if preset is not None:
        values.update(preset_values(preset))
        chosen = PRESETS[preset]
        env_id = split_env_id(overrides.get("env", values.get("env", TrainConfig.env)))[1]
        if not chosen.accepts(env_id):
            meant = "highway-env ids" if chosen.envs == "highway" else chosen.envs
            fitting = [name for name, other in PRESETS.items() if other.envs != "any"]
            fitting = [name for name in fitting if PRESETS[name].accepts(env_id)] + ["cpu"]
            raise SetupError(
                f"preset {preset!r} is meant for {meant}, not {env_id!r}; drop --env to train "
                f"on {meant}, or use a preset for {env_id!r}: {' or '.join(fitting)} (or no "
                "preset for the paper defaults)"
            )
        if chosen.envs == "highway":
            values["env_kwargs"] = {
                **values["env_kwargs"],
                "config": fit_highway_config(values["env_kwargs"]["config"], env_id),
            }
    recipe = overrides.get("agent.recipe", values.get("agent.recipe"))
    if recipe is not None:
        env_id = split_env_id(overrides.get("env", values.get("env", TrainConfig.env)))[1]
        values.update(recipe_values(recipe, dmc_task(env_id)))
    if isinstance(values.get("env_kwargs"), dict) and isinstance(overrides.get("env_kwargs"), dict):
        overrides = {
            **overrides,
            "env_kwargs": merged(values["env_kwargs"], overrides["env_kwargs"]),
        }
    values.update(overrides)
    return from_flat(values)


def merged(base: dict, extra: dict) -> dict:
    """``base`` with ``extra``'s keys set over it, dicts merged key by key at every depth.

    Example:
        >>> merged({"config": {"lanes_count": 4, "duration": 40}}, {"config": {"lanes_count": 2}})
        {'config': {'lanes_count': 2, 'duration': 40}}
    """
    out = dict(base)
    for key, value in extra.items():
        below = out.get(key)
        out[key] = (
            merged(below, value) if isinstance(below, dict) and isinstance(value, dict) else value
        )
    return out


def preset_values(name: str) -> dict[str, Any]:
    """The flat overrides of the preset ``name`` with ``"preset": name``; SetupError for an
    unknown preset or a preset entry with an unknown key."""
    if not isinstance(name, str) or name not in PRESETS:
        raise SetupError(
            f"unknown preset {name!r}{did_you_mean_name(name, list(PRESETS))}; choose one of "
            f"{', '.join(PRESETS)}"
        )
    values = flatten(PRESETS[name].overrides)
    check_keys(values, f"preset {name!r}", "fix its entry in simoun_agent.config.presets.PRESETS")
    return {**values, "preset": name}


def recipe_values(name: str, task: str | None = None) -> dict[str, Any]:
    """The flat overrides (``{"agent.encoder": "stacked", ...}``) of the recipe ``name`` on the
    DMC ``task`` (its ``per_task`` values there; None: any other env); SetupError for an unknown
    recipe or a recipe entry with an unknown key."""
    if not isinstance(name, str) or name not in RECIPES:
        raise SetupError(
            f"unknown recipe --agent.recipe {name!r}{did_you_mean_name(name, list(RECIPES))}; "
            f"choose one of {', '.join(RECIPES)}"
        )
    values = {"agent." + key: value for key, value in RECIPES[name].values_for(task).items()}
    check_keys(values, f"recipe {name!r}", "fix its entry in simoun_agent.config.recipes.RECIPES")
    return values


def flatten(nested: dict, prefix: str = "") -> dict[str, Any]:
    """``{"agent": {"lr": 1e-3}, "seed": 1}`` -> ``{"agent.lr": 1e-3, "seed": 1}``: the dicts
    of config sections are walked, any other dict (``env_kwargs``) is a value."""
    sections = config_sections()
    flat = {}
    for key, value in nested.items():
        if isinstance(value, dict) and prefix + key + "." in sections:
            flat.update(flatten(value, prefix + key + "."))
        else:
            flat[prefix + key] = value
    return flat


def from_flat(values: dict[str, Any]) -> TrainConfig:
    """TrainConfig from flat keys (``"agent.lr"``) over the dataclass defaults; SetupError for a
    key no field has (nothing is dropped silently)."""
    check_keys(values)
    try:
        return _build(TrainConfig, "", values)
    except ValueError as err:
        raise SetupError(str(err)) from None


def _build(cls: type, prefix: str, values: dict[str, Any]) -> Any:
    """``cls`` with every field given: its value in ``values``, else its default. Given in
    full, an ``AgentConfig`` takes nothing from its recipe by itself: the layers above put
    the recipe's values in ``values`` (for the run's task), and a saved config that lacks a
    key means the default, not what the recipe holds today."""
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for f in dataclasses.fields(cls):
        if dataclasses.is_dataclass(hints[f.name]):
            kwargs[f.name] = _build(hints[f.name], prefix + f.name + ".", values)
        elif prefix + f.name in values:
            kwargs[f.name] = values[prefix + f.name]
        elif f.default is not dataclasses.MISSING:
            kwargs[f.name] = f.default
        else:
            kwargs[f.name] = f.default_factory()  # type: ignore[misc]
    return cls(**kwargs)


def to_dict(config: TrainConfig) -> dict[str, Any]:
    """JSON-ready nested dict of a config (tuples become lists)."""
    return json.loads(json.dumps(dataclasses.asdict(config)))


SAVED_BEFORE = {"agent.next_state_encoder": "online"}
"""What a saved config that lacks a key ran with, where that differs from today's default: the
key was added with this value as its default, which the default has since left."""


def from_dict(data: dict[str, Any], where: str | None = None) -> TrainConfig:
    """Inverse of :func:`to_dict`; raises SetupError for keys this version does not know, or
    for ``data`` that is not a dict of config keys. ``where`` names the file ``data`` was read
    from, whose errors say how to restore it; None (a value built in Python) has them name the
    key and the type it takes. A key the config predates takes its :data:`SAVED_BEFORE` value
    if it has one (what the run did), else this version's default."""
    blame = _FileBlame(where) if where is not None else _ValueBlame()
    if not isinstance(data, dict):
        raise SetupError(blame.not_a_dict(data))
    for prefix, cls in config_sections().items():
        section = _section_value(data, prefix)
        if prefix and section is not None and not isinstance(section, dict):
            raise SetupError(blame.not_a_section(prefix.rstrip("."), cls, section))
    flat = {**SAVED_BEFORE, **flatten(data)}
    check_keys(flat, blame.source, blame.unknown_fix)
    known = config_fields()
    sections = config_sections()
    for key, value in flat.items():
        kind, default, _ = known[key]
        if isinstance(value, list) and (typing.get_origin(kind) or kind) is tuple:
            flat[key] = value = tuple(value)
        name = key.rpartition(".")[2]
        rule = rules_of(sections[key.removesuffix(name)])[name]
        if not rule.ok(value):
            need = rule.need + (rule.suggest(value) if rule.suggest else "")
            raise SetupError(blame.bad_value(key, value, need, default))
    try:
        return from_flat(flat)
    except SetupError as err:  # a cross-field check, spelled as flags: say where it came from
        raise SetupError(f"{blame.source} does not hold a valid config: {err}") from None


def _section_value(data: dict[str, Any], prefix: str) -> Any:
    """What ``data`` holds at the section ``prefix`` (``"agent."``); None where it is absent."""
    value: Any = data
    for part in prefix.split(".")[:-1]:
        if not isinstance(value, dict):
            return None
        value = value.get(part)
    return value


def _python_key(key: str) -> str:
    """``"agent.lr"`` -> ``"data['agent']['lr']"``, the key as Python indexes the dict."""
    return "data" + "".join(f"[{part!r}]" for part in key.split("."))


class _FileBlame:
    """from_dict's refusals of a config read from a file: it is damaged or edited."""

    def __init__(self, where: str) -> None:
        self.source = where
        self.unknown_fix = (
            "it was written by another version of simoun; use that version, or train it again"
        )

    def not_a_dict(self, data: Any) -> str:
        return (
            f"{self.source} holds {type(data).__name__} where a JSON object of config keys "
            "belongs: it is damaged; restore it from a copy, or train the run again"
        )

    def not_a_section(self, key: str, cls: type, value: Any) -> str:
        return (
            f"{self.source}: {key} holds {type(value).__name__} where a JSON object of "
            f"{cls.__name__} fields belongs: it is damaged; restore it from a copy, or train "
            "the run again"
        )

    def bad_value(self, key: str, value: Any, need: str, default: Any) -> str:
        return (
            f"{self.source}: {key} is {json.dumps(value, default=repr)}, which must be {need}; "
            f"the file is damaged or was edited: set {key} there to what the run was trained "
            f"with (the default is {json.dumps(default)}), restore the file from a copy, or "
            "train the run again"
        )


class _ValueBlame:
    """from_dict's refusals of a value built in Python: the key and the type it takes."""

    source = "from_dict(data)"
    unknown_fix = "to_dict(TrainConfig()) lists every key, or resolve(None, {...}) takes flat ones"

    def not_a_dict(self, data: Any) -> str:
        hint = (
            "; it is a config already: use it as it is (dataclasses.replace(config, ...) to "
            "change it), or pass to_dict(config)"
            if dataclasses.is_dataclass(data)
            else "; e.g. from_dict(to_dict(config))"
        )
        return (
            f"from_dict(data) takes a dict of config keys (what to_dict(config) returns), got "
            f"{type(data).__name__}{hint}"
        )

    def not_a_section(self, key: str, cls: type, value: Any) -> str:
        return (
            f"from_dict(data): {_python_key(key)} must be a dict of {cls.__name__} fields, got "
            f"{type(value).__name__} {value!r:.60}; e.g. {_python_key(key)} = "
            f"to_dict(config)[{key.rpartition('.')[2]!r}], or leave it out for the defaults"
        )

    def bad_value(self, key: str, value: Any, need: str, default: Any) -> str:
        return (
            f"from_dict(data): {_python_key(key)} is {value!r:.60} ({type(value).__name__}), "
            f"which must be {need}; e.g. {_python_key(key)} = {default!r} (the default)"
        )
