"""The config flags of ``simoun-train`` and ``simoun-sweep``: ``--preset NAME``, one flag per
config key (tyro, from the fields of ``TrainConfig`` and ``AgentConfig``) and ``--set
KEY=VALUE``, read back as the overrides the user gave.

The preset is read from the command line before parsing, so the flags' defaults in ``--help``
are the preset's (``simoun-train --preset cpu --help``). The overrides are the keys whose flag
the command line names, not the values that differ from the defaults: a value equal to the
preset's must still win over a recipe (``--preset cpu --agent.recipe sac
--agent.augmentation shift``), and a resumed run must refuse a fixed key even when it is given
its saved value.
"""

from __future__ import annotations

import functools
import json
import typing
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any

import tyro

from simoun_agent.cli.command_flags import Flag, command_flags
from simoun_agent.cli.flags import empty_value, negated
from simoun_agent.config import PRESETS, RECIPES, SetupError, TrainConfig, resolve
from simoun_agent.config.keys import (
    FALSE_WORDS,
    NONE_WORDS,
    TRUE_WORDS,
    check_keys,
    config_fields,
    parse_value,
)
from simoun_agent.config.rules import did_you_mean_name

PRESETS_HELP = "start from a named preset: " + ", ".join(PRESETS)
RECIPES_HELP = "agent recipes (--agent.recipe NAME):\n" + "\n".join(
    f"  {name:18} {recipe.description}" for name, recipe in RECIPES.items()
)
PRESETS_LIST = "presets (--preset NAME):\n" + "\n".join(
    f"  {name:18} {preset.description}" for name, preset in PRESETS.items()
)


@dataclass
class ConfigFlags:
    """The run config as the command line gives it."""

    preset: Annotated[str | None, tyro.conf.arg(metavar="NAME", help=PRESETS_HELP)] = None
    set: Annotated[
        tuple[str, ...], tyro.conf.UseAppendAction, tyro.conf.arg(metavar="KEY=VALUE")
    ] = ()
    """override a config key, e.g. --set agent.lr=3e-4 (like the flags below)"""
    config: Annotated[TrainConfig, tyro.conf.arg(name="")] = field(default_factory=TrainConfig)
    """the config keys (defaults: the preset's; each is also KEY for --set)"""


def config_default(argv: Sequence[str]) -> TrainConfig:
    """The defaults the flags start from: the preset that ``argv`` names, else the dataclass
    defaults; SetupError for an unknown preset."""
    return resolve(preset_in(argv), {})


def preset_in(argv: Sequence[str]) -> str | None:
    """The value of ``--preset NAME`` / ``--preset=NAME`` in ``argv``, else None; SetupError
    when it is given twice with different names."""
    names = []
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        if arg == "--preset" and i + 1 < len(argv):
            names.append(argv[i + 1])
        if arg.startswith("--preset="):
            names.append(arg.partition("=")[2])
    for name in names:
        if not name.strip():
            raise SetupError(empty_value("--preset", name))
    if len(set(names)) > 1:
        raise SetupError(f"--preset is given twice ({' and '.join(names)}); give it once")
    if not names or names[0].lower() in NONE_WORDS:  # --preset none: the paper defaults
        return None
    return names[0]


@functools.cache
def config_flags() -> dict[str, str]:
    """Every spelling of a config key's flag -> the key: ``--agent.batch-size``, and for a
    switch its negation (``--agent.no-curiosity``) and the former ``--no-agent.curiosity``."""
    flags = {}
    for key, (kind, _, _) in config_fields().items():
        flag = key_flag(key)
        flags[flag] = key
        if kind is bool:
            flags[negated(flag)] = flags["--no-" + flag[2:]] = key
    flags.pop("--preset")  # the command's own --preset, not the informational config key
    return flags


def key_flag(key: str) -> str:
    """``agent.batch_size`` -> ``--agent.batch-size``, the flag tyro makes for a config key."""
    return "--" + key.replace("_", "-")


def config_switches() -> list[str]:
    """The flags of the boolean config keys (``--video``, ``--agent.curiosity``, ...)."""
    return [key_flag(key) for key, (kind, _, _) in config_fields().items() if kind is bool]


def overrides_from(flags: ConfigFlags, argv: Sequence[str], command: Any = None) -> dict[str, Any]:
    """``{"agent.lr": 3e-4, ...}``: the config keys whose flag ``argv`` names, with the values
    tyro read into ``flags`` (a list key's values also split at commas, as ``--set`` does), then
    the ``--set`` pairs, typed. ``command`` is the command's dataclass: a ``--set`` of one of its
    own flags (``--set resume=RUN``) is answered with that flag."""
    known = config_flags()
    fields = config_fields()
    check_given_once(argv, flags.set)
    given = {}
    for arg in argv:
        if arg == "--":
            break
        key = known.get(arg.partition("=")[0])
        if key is not None:
            value = functools.reduce(getattr, key.split("."), flags.config)
            if isinstance(value, tuple):  # a repeated flag may list several: --eval-distraction a,b
                value = parse_value(key, ",".join(value), fields[key][0])
            given[key] = value
    for pair in flags.set:
        key, sep, value = pair.partition("=")
        key = key.replace("-", "_")  # the flag's spelling: --set agent.batch-size=64
        if not sep or not key:
            raise SetupError(f"--set takes KEY=VALUE, got {pair!r}; e.g. --set agent.lr=3e-4")
        if key == "preset" and value == flags.preset:
            continue  # the label --preset gives anyway
        check_set_key(key, value, pair, own_flags(command, argv))
        given[key] = parse_value(key, value, fields[key][0])
    return given


def own_flags(command: Any, argv: Sequence[str]) -> dict[str, tuple[str, Flag]]:
    """The flags of ``command`` (a command's dataclass; None: none) that set no config key, by
    the name ``--set`` would give them: ``{"resume": ("--resume", Flag(...)), ...}``."""
    if command is None:
        return {}
    return {
        name[2:].replace("-", "_"): (name, flag)
        for name, flag in command_flags(command, argv).items()
        if not flag.config and flag.switch is not False and name not in ("--set", "--preset")
    }


COMMAND_ONLY_FLAGS = {
    "help": "lists every flag and config key",
    "version": "prints the installed version",
}
"""flags every command takes that are no field of its dataclass, by the key ``--set`` would
give them, with what each does"""


def check_set_key(
    key: str, value: str, pair: str, own: dict[str, tuple[str, Flag]] | None = None
) -> None:
    """SetupError for the key of ``--set KEY=VALUE`` that is no config key, with the fix for
    the common ways of getting it wrong: spaces around ``=``, ``preset`` (a label that
    ``--preset`` sets with the preset's values; an unknown name with the presets), a flag of
    the command (``own``, :func:`own_flags`: ``--set resume=RUN`` for ``--resume RUN``), a key
    inside ``env_kwargs``; else the close matches of
    :func:`~simoun_agent.config.keys.check_keys`."""
    if key != key.strip() or value != value.lstrip():
        raise SetupError(
            f"--set {pair!r}: KEY=VALUE takes no spaces around '='; write "
            f"--set {key.strip()}={value.strip()}"
        )
    if key == "preset":
        raise SetupError(set_preset_problem(value))
    if key in COMMAND_ONLY_FLAGS:
        raise SetupError(
            f"--set {pair}: {key} is not a config key but the flag --{key}, which "
            f"{COMMAND_ONLY_FLAGS[key]}; give --{key} alone"
        )
    if own and key in own:
        name, flag = own[key]
        fix = f"give {name} {value} instead"
        if flag.switch is not None:  # a switch: given alone, or left out
            fix = f"leave {name} out" if value.lower() in FALSE_WORDS else f"give {name} instead"
        raise SetupError(f"--set {pair}: {key} is not a config key but the flag {name}; {fix}")
    section, dot, inner = key.partition(".")
    if dot and section == "env_kwargs":
        try:
            typed = json.loads(value)
        except json.JSONDecodeError:
            typed = value
        raise SetupError(
            f"--set {pair}: env_kwargs takes a whole JSON object, not a key inside it; give "
            f"--env-kwargs '{json.dumps({inner: typed})}'"
        )
    check_keys([key])  # an unknown key fails here, with its close matches


def set_preset_problem(value: str) -> str:
    """Why ``--set preset=VALUE`` is refused: a preset's values are applied by ``--preset``, and
    an unknown name is no preset at all (named with the presets there are)."""
    if value not in PRESETS:
        return (
            f"--set preset={value}: {value!r} is no preset{did_you_mean_name(value, PRESETS)}; "
            f"the presets are {', '.join(PRESETS)}, and one is applied by --preset NAME (e.g. "
            "--preset cpu), not by --set"
        )
    return (
        f"--set preset={value} would only label the run: a preset's values are applied by "
        f"--preset; give --preset {value} instead"
    )


def check_given_once(argv: Sequence[str], pairs: Sequence[str]) -> None:
    """Raise SetupError for a config key given twice with different values, by its flag or by
    ``--set`` (``--seed 1 --seed 2``, ``--seed 1 --set seed=2``): one of them would win without
    a word. A list key's flag is meant to be repeated (``--eval-distraction a
    --eval-distraction b``) and is exempt; the same value twice is harmless."""
    known = config_flags()
    fields = config_fields()
    given: dict[str, list[tuple[str, Any]]] = {}
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        name, eq, text = arg.partition("=")
        key = known.get(name)
        if key is None:
            continue
        kind = fields[key][0]
        if typing.get_origin(kind) is tuple or kind is tuple:
            continue
        if kind is bool:
            following = argv[i + 1].lower() if i + 1 < len(argv) else ""
            if name != key_flag(key):  # a negation
                value = False
            elif eq:
                value = text.lower() in TRUE_WORDS
            elif following in TRUE_WORDS + FALSE_WORDS:
                value = following in TRUE_WORDS
                arg = f"{arg} {argv[i + 1]}"
            else:
                value = True
        else:
            if not eq and i + 1 >= len(argv):
                continue  # tyro says the value is missing
            value = parse_value(key, text if eq else argv[i + 1], kind)
        given.setdefault(key, []).append(
            (arg if eq or kind is bool else f"{arg} {argv[i + 1]}", value)
        )
    for pair in pairs:
        key, sep, text = pair.partition("=")
        key = key.replace("-", "_")
        if sep and key in fields:
            given.setdefault(key, []).append(
                (f"--set {pair}", parse_value(key, text, fields[key][0]))
            )
    for key, uses in given.items():
        if len({json.dumps(value, default=str) for _, value in uses}) > 1:
            raise SetupError(
                f"{key} is given twice with different values ({' and '.join(u for u, _ in uses)}); "
                "give it once"
            )
