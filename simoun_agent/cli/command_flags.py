"""The flags a command's dataclass makes on tyro's command line, read from its fields the way
tyro names them: a field ``sweep_dir`` is ``--sweep-dir``, a section ``agent`` prefixes its
fields (``--agent.lr``) unless it is named ``""``, a switch also has its negation
(``--agent.no-curiosity``) and a positional field makes no flag. For a union of subcommands the
flags are those of the subcommand that the command line names, so a subcommand's options are
checked as a plain command's are (:func:`simoun_agent.cli.flags.parse` refuses an unknown flag
with the ones it most likely meant, and an option given twice).

A flag or positional argument that names a file or directory is typed ``Path``, or marked
:data:`PATH` when the command reads it as a string: its value is checked against the file
system's length limits before anything runs.
"""

from __future__ import annotations

import dataclasses
import typing
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import tyro
from tyro.constructors import PrimitiveConstructorSpec

from simoun_agent.config import AgentConfig, TrainConfig
from simoun_agent.config.keys import field_docs

CONFIG_SECTIONS = (TrainConfig, AgentConfig)
"""The run config's sections: filled without their checks (those run once, in ``resolve``),
and their keys given twice compared by value
(``simoun_agent.cli.config_flags.check_given_once``)."""

ARG = type(tyro.conf.arg())
SUBCOMMAND = type(tyro.conf.subcommand())


class PathMarker:
    """The type of :data:`PATH`."""


PATH = PathMarker()
"""``Annotated[str, PATH]``: a string field that names a file or directory."""

CONFIG_PATHS = frozenset({"run_dir"})
"""The run config's keys that name a directory (the config keeps them as strings)."""


@dataclass(frozen=True)
class Flag:
    """One flag of a command."""

    key: str
    """the field it sets, dotted from the command: ``agent.lr``, ``sweep_dir``"""
    doc: str
    """the field's docstring (its help)"""
    switch: bool | None
    """True for a switch, False for its negation, None for an option that takes a value"""
    repeatable: bool
    """a list given by repeating the flag"""
    config: bool
    """a key of the run config (compared by value where it is read)"""
    variadic: bool = False
    """takes any number of words after it (``--probes a b``, ``--video`` alone or ``--video
    mp4``)"""
    path: bool = False
    """names a file or directory"""
    json: bool = False
    """takes a JSON object (``--env-kwargs '{"a": 1}'``)"""
    number: type | None = None
    """int or float for an option that takes a number (``--episodes 10``)"""
    setting: bool = False
    """takes a ``KEY=VALUE`` word (``--set agent.lr=1e-3``, ``--grid agent.lr=1e-3,3e-4``)"""


@dataclass(frozen=True)
class PositionalArg:
    """One positional argument of a command."""

    metavar: str
    """its name in help: ``DIR``, ``RUN``"""
    variadic: bool
    """any number of words (``simoun-eval RUN [RUN ...]``)"""
    path: bool
    """names a file or directory"""
    name: str = ""
    """its field (``checkpoint``)"""


def unwrap(hint: Any) -> tuple[Any, list[Any]]:
    """``Annotated[T, m1, m2]`` (nested too) -> ``(T, [m1, m2])``."""
    markers: list[Any] = []
    while typing.get_origin(hint) is Annotated:
        hint, *more = typing.get_args(hint)
        markers.extend(more)
    return hint, markers


def subcommands(command: Any) -> dict[str, type]:
    """Subcommand name -> dataclass for a union of ``Annotated[cls, tyro.conf.subcommand(..)]``;
    empty for a plain dataclass."""
    if typing.get_origin(command) is not typing.Union:
        return {}
    named = {}
    for option in typing.get_args(command):
        cls, markers = unwrap(option)
        for marker in markers:
            if isinstance(marker, SUBCOMMAND) and marker.name:
                named[marker.name] = cls
    return named


def chosen(command: Any, argv: Sequence[str]) -> type | None:
    """The dataclass ``argv`` runs: ``command`` itself, or the subcommand it names first (None
    when it names none: tyro then asks for one)."""
    named = subcommands(command)
    if not named:
        return command if dataclasses.is_dataclass(command) else None
    for arg in argv:
        if arg == "--":
            break
        if arg in named:
            return named[arg]
    return None


def command_flags(command: Any, argv: Sequence[str]) -> dict[str, Flag]:
    """Every spelling of every flag of the dataclass ``argv`` runs (:func:`chosen`) -> its
    :class:`Flag`; empty when ``argv`` names no subcommand of a union."""
    cls = chosen(command, argv)
    flags: dict[str, Flag] = {}
    if cls is not None:
        _add_fields(cls, "", False, flags)
    return flags


def takes_positional(command: Any, argv: Sequence[str]) -> bool:
    """Whether the dataclass ``argv`` runs has a positional argument (True when it names no
    subcommand: nothing is known yet)."""
    found = positionals(command, argv)
    return found is None or bool(found)


def positionals(command: Any, argv: Sequence[str]) -> list[PositionalArg] | None:
    """The positional arguments of the dataclass ``argv`` runs, in order (None when it names no
    subcommand of a union)."""
    cls = chosen(command, argv)
    if cls is None:
        return None
    hints = typing.get_type_hints(cls, include_extras=True)
    found = []
    for field in dataclasses.fields(cls):
        kind, markers = unwrap(hints[field.name])
        if tyro.conf.Positional not in markers:
            continue
        metavar = next(
            (m.metavar for m in markers if isinstance(m, ARG) and m.metavar), field.name.upper()
        )
        path = _names_path(kind, markers)
        found.append(PositionalArg(metavar, _sequence(kind), path, field.name))
    return found


def _sequence(kind: Any) -> bool:
    return typing.get_origin(kind) in (tuple, list) or kind in (tuple, list)


def _names_path(kind: Any, markers: list[Any]) -> bool:
    """Whether a field of type ``kind`` (optional or a sequence of it) names a path."""
    if PATH in markers:
        return True
    inner = {arg for arg in typing.get_args(kind) if arg not in (type(None), Ellipsis)}
    return kind is Path or inner == {Path}


def _number(kind: Any) -> type | None:
    """int or float for a field of that type (optional too), else None."""
    options = {arg for arg in typing.get_args(kind) if arg is not type(None)} or {kind}
    return options.pop() if len(options) == 1 and options <= {int, float} else None


def _add_fields(cls: type, prefix: str, config: bool, flags: dict[str, Flag]) -> None:
    hints = typing.get_type_hints(cls, include_extras=True)
    docs = field_docs(cls)
    config = config or cls in CONFIG_SECTIONS
    for field in dataclasses.fields(cls):
        # the config's informational preset key: the commands' own --preset resolves it
        if not field.init or (cls is TrainConfig and field.name == "preset"):
            continue
        kind, markers = unwrap(hints[field.name])
        if any(marker is tyro.conf.Positional for marker in markers):
            continue
        given = [m for m in markers if isinstance(m, ARG)]
        name = next((m.name for m in given if m.name is not None), field.name)
        doc = next((m.help for m in given if m.help), docs.get(field.name, ""))
        if dataclasses.is_dataclass(kind):
            _add_fields(kind, f"{prefix}{name}." if name else prefix, config, flags)
            continue
        key = prefix + name
        flag = "--" + key.replace("_", "-")
        repeatable = _sequence(kind)
        switch = True if kind is bool else None
        appended = config or tyro.conf.UseAppendAction in markers
        variadic = (repeatable and not appended) or any(
            isinstance(m, PrimitiveConstructorSpec) and m.nargs in ("*", "+", "?") for m in markers
        )
        path = _names_path(kind, markers) or (config and key in CONFIG_PATHS)
        json = (typing.get_origin(kind) or kind) is dict
        number = _number(kind)
        setting = any("=" in (m.metavar or "") for m in given)
        flags[flag] = Flag(
            key, doc, switch, repeatable, config, variadic, path, json, number, setting
        )
        if kind is bool and tyro.conf.FlagCreatePairsOff not in markers:
            section, dot, last = flag[2:].rpartition(".")
            negation = Flag(key, doc, False, False, config)
            flags[f"--{section}{dot}no-{last}"] = flags[f"--no-{flag[2:]}"] = negation
