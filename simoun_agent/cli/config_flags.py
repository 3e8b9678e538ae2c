"""The config flags of ``simoun-train`` and ``simoun-sweep``: ``--preset``, ``--set KEY=VALUE``
and one flag per config key, read back as typed overrides."""

from __future__ import annotations

import argparse
import json
import typing
from typing import Any

from simoun_agent.config import PRESETS, SetupError
from simoun_agent.config.keys import check_keys, config_fields, parse_value


def add_config_arguments(parser: argparse.ArgumentParser) -> None:
    """``--preset``, ``--set KEY=VALUE`` and one flag per config key (read by
    :func:`overrides_from`); shared by ``simoun-train`` and ``simoun-sweep``."""
    parser.add_argument("--preset", choices=list(PRESETS), help="start from a named preset")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config key, e.g. --set agent.lr=3e-4 (repeatable; like the flags below)",
    )
    group = parser.add_argument_group(
        "config keys (defaults before any preset; each is also KEY for --set)"
    )
    for key, (kind, default, doc) in config_fields().items():
        if key == "preset":
            continue
        shown = json.dumps(default) if isinstance(default, dict) else repr(default)
        flag = "--" + key.replace("_", "-")
        switch = kind is bool
        hint = f"; --no-{flag[2:]} for false" if switch else ""
        group.add_argument(
            flag,
            dest=key,
            # A tuple key's flag is repeatable: --eval-distraction video_hard --eval-distraction ...
            action="append" if (typing.get_origin(kind) or kind) is tuple else "store",
            default=argparse.SUPPRESS,
            metavar=_metavar(kind),
            # a switch: --progress alone means true, and --progress false still works
            **({"nargs": "?", "const": "true"} if switch else {}),
            help=f"{doc} (default: {shown}{hint})".replace("%", "%%"),
        )
        if switch:
            group.add_argument(
                f"--no-{flag[2:]}",
                dest=key,
                action="store_const",
                const="false",
                default=argparse.SUPPRESS,
                help=argparse.SUPPRESS,
            )


def _metavar(kind: Any) -> str:
    names = {int: "INT", float: "FLOAT", str: "STR", bool: "BOOL", dict: "JSON"}
    skipped = (type(None), Ellipsis)  # Ellipsis: tuple[str, ...] shows as STR
    options = [option for option in typing.get_args(kind) or (kind,) if option not in skipped]
    return "|".join(names.get(typing.get_origin(o) or o, "VALUE") for o in options)


def overrides_from(args: argparse.Namespace) -> dict[str, Any]:
    """``{"agent.lr": 3e-4, ...}`` from the config flags and ``--set`` pairs, typed."""
    fields = config_fields()
    given = {k: v for k, v in vars(args).items() if k in fields and k != "preset"}
    for pair in args.set:
        key, sep, value = pair.partition("=")
        key = key.replace("-", "_")  # the flag's spelling: --set agent.batch-size=64
        if not sep:
            raise SetupError(f"--set takes KEY=VALUE, got {pair!r}; e.g. --set agent.lr=3e-4")
        check_keys([key])  # an unknown key fails here, with its close matches
        given[key] = value
    given = {key: ",".join(v) if isinstance(v, list) else v for key, v in given.items()}
    return {key: parse_value(key, value, fields[key][0]) for key, value in given.items()}
