"""Command-line conventions shared by the commands of :mod:`simoun_agent.cli` and
:mod:`simoun_lab.cli`, parsed with tyro.

Every command is a dataclass whose field docstrings are its help text; :func:`parse` hands it
to ``tyro.cli`` with :data:`REGISTRY`, which adds four conventions tyro does not have:

* help is each field's docstring on one line (tyro keeps the docstring's line breaks); a
  tuple key of the config is given by repeating its flag (``--eval-distraction video_hard
  --eval-distraction color_hard``); and a section of the run config (``TrainConfig``,
  ``AgentConfig``) is filled with the values read but not checked (:func:`_unchecked`): a
  value that is only valid once the preset and recipe layers are under it must not be
  refused, so the commands hand the values the user gave to
  :func:`simoun_agent.config.resolve`, which builds and checks the config once;
* dicts are JSON (``--env-kwargs '{"a": 1}'``), and an optional value takes ``none``;
* booleans are switches, ``--video`` / ``--no-video`` (``--agent.no-curiosity`` in a section),
  and the older spelling with a value, ``--video false`` or ``--video=false``, still works:
  :func:`bool_argv` rewrites it to the switch before parsing;
* every command answers ``--version``; help printed to a pipe is not wrapped at 80 columns;
  output into a pipe that closed early (``simoun-report DIR | head``) ends the command
  quietly (:func:`quiet_pipe`).

Before tyro reads the command line, :func:`parse` refuses in one line, naming the flag or
argument: an unknown flag (the command's own in other letter case, another library's name for
a flag told this command's own, :mod:`simoun_agent.cli.other_names`, another simoun command's
flag named as that command's; a flag offered by spelling takes the kind of value given), a
second value of an option that takes one, a word after a switch, a switch given a value it
does not take, a word no argument takes, an empty or blank value, a path the file system cannot
hold, a dict's value that is not a JSON object (what json found and where, or a key given
twice), an option given twice with different values, and a number past int64.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import itertools
import json
import os
import re
import shlex
import sys
import typing
import unicodedata
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Annotated, Any, NoReturn, TypeVar

import tyro
from tyro.constructors import (
    MISSING_NONPROP,
    ConstructorRegistry,
    PrimitiveConstructorSpec,
    PrimitiveTypeInfo,
    StructConstructorSpec,
    StructFieldSpec,
    StructTypeInfo,
    UnsupportedTypeAnnotationError,
)

from simoun_agent.cli.command_flags import (
    CONFIG_SECTIONS,
    Flag,
    PositionalArg,
    command_flags,
    positionals,
    subcommands,
    takes_positional,
)
from simoun_agent.cli.other_names import Meant, name_key
from simoun_agent.config import TrainConfig
from simoun_agent.config.key_match import NAME_WEIGHT, close_keys, meaning_score
from simoun_agent.config.keys import (
    FALSE_WORDS,
    NONE_WORDS,
    TRUE_WORDS,
    config_fields,
    field_docs,
    json_mistake,
    json_repaired,
    json_value,
)
from simoun_agent.run.atomic import NO_SPACE_EXIT, space_problem

T = TypeVar("T")

REGISTRY = ConstructorRegistry()
"""The conventions above, for every ``tyro.cli`` call of the commands."""

COMMAND_PACKAGES = ("simoun_agent.", "simoun_lab.")
"""Where the dataclasses these conventions apply to are defined (the lab's commands share
them; the lab is named here as a string, never imported)."""

PIPED_HELP_COLUMNS = "160"
"""Width of help written to a pipe (grep, less, a log): a field's doc stays on one line."""


@REGISTRY.struct_rule
def _dataclass(info: StructTypeInfo) -> StructConstructorSpec | None:
    cls = info.type
    # ours only: tyro wraps a union of commands in a generic dataclass of its own
    if not (isinstance(cls, type) and dataclasses.is_dataclass(cls)):
        return None
    if not cls.__module__.startswith(COMMAND_PACKAGES):
        return None
    hints = typing.get_type_hints(cls, include_extras=True)
    if cls in CONFIG_SECTIONS:  # a list of the config is given by repeating its flag
        hints = {
            name: Annotated[hint, tyro.conf.UseAppendAction]
            if typing.get_origin(hint) is tuple
            else hint
            for name, hint in hints.items()
        }
    docs = field_docs(cls)
    given = info.default if isinstance(info.default, cls) else None
    fields = tuple(
        StructFieldSpec(f.name, hints[f.name], _default(f, given), docs.get(f.name))
        for f in dataclasses.fields(cls)
        # a preset is chosen with the commands' own --preset, which resolves it
        if f.init and not (cls is TrainConfig and f.name == "preset")
    )
    build = _unchecked(cls) if cls in CONFIG_SECTIONS else cls
    return StructConstructorSpec(instantiate=build, fields=fields)


def _unchecked(cls: type[T]) -> Any:
    """``cls(**values)`` without ``__post_init__``: the values as typed, checked later by
    :func:`simoun_agent.config.resolve` once the preset and recipe layers are applied."""

    def build(**values: Any) -> T:
        section = object.__new__(cls)
        section.__dict__.update(values)
        return section

    return build


def _default(field: dataclasses.Field, given: Any) -> Any:
    if given is not None:
        return getattr(given, field.name)
    if field.default is not dataclasses.MISSING:
        return field.default
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return MISSING_NONPROP


def json_object(text: str, flag: str = "") -> dict:
    """The JSON object ``text`` (a dict option's value, of ``flag`` when given); ValueError when
    it is not one, saying what json found and where, and the object meant when the text is one
    but for a usual slip (:func:`~simoun_agent.config.keys.json_mistake`), or when it gives a
    key twice (:func:`~simoun_agent.config.keys.json_value`)."""
    try:
        value = json_value(text)
    except json.JSONDecodeError as err:
        fixed = json_repaired(text)
        fix = f"give {flag} {shlex.quote(fixed)}" if flag else f"e.g. {shlex.quote(fixed)}"
        raise ValueError(
            f"{text!r} is not JSON ({json_mistake(text, err)})"
            + (f"; {fix}" if fixed else "; a JSON object is written e.g. '{\"a\": 1}'")
        ) from None
    if not isinstance(value, dict):
        raise ValueError(
            f"expected a JSON object, e.g. '{{\"a\": 1}}', got {text!r} (a JSON "
            f"{type(value).__name__})"
        )
    return value


@REGISTRY.primitive_rule
def _json_dict(info: PrimitiveTypeInfo) -> PrimitiveConstructorSpec | None:
    if (info.type_origin or info.type) is not dict:
        return None

    def read(args: list[str]) -> dict:
        return json_object(args[0])

    return PrimitiveConstructorSpec(
        nargs=1,
        metavar="JSON",
        instance_from_str=read,
        is_instance=lambda value: isinstance(value, dict),
        str_from_instance=lambda value: [json.dumps(value)],
    )


@REGISTRY.primitive_rule
def _optional(info: PrimitiveTypeInfo) -> PrimitiveConstructorSpec | None:
    options = typing.get_args(info.type)
    if type(None) not in options or len(options) != 2 or typing.get_origin(info.type) is None:
        return None
    inner_type = next(option for option in options if option is not type(None))
    inner = ConstructorRegistry.get_primitive_spec(PrimitiveTypeInfo.make(inner_type, info.markers))
    if isinstance(inner, UnsupportedTypeAnnotationError) or inner.nargs != 1:
        return None

    def read(args: list[str]) -> Any:
        return None if args[0].lower() in NONE_WORDS else inner.instance_from_str(args)

    return PrimitiveConstructorSpec(
        nargs=1,
        metavar=f"{inner.metavar}|none",
        instance_from_str=read,
        is_instance=lambda value: value is None or inner.is_instance(value),
        str_from_instance=lambda value: (
            ["none"] if value is None else inner.str_from_instance(value)
        ),
    )


def bool_argv(argv: Sequence[str], flags: Iterable[str]) -> list[str]:
    """``argv`` with ``--flag WORD`` / ``--flag=WORD`` (WORD true/false, yes/no, on/off, 1/0)
    rewritten to ``--flag`` / its negation (:func:`negated`) for each boolean ``flags`` entry
    (``"--video"``), and argparse's former negation ``--no-agent.curiosity`` to tyro's.

    Example:
        >>> bool_argv(["--video", "false", "--progress=yes", "run"], ["--video", "--progress"])
        ['--no-video', '--progress', 'run']
        >>> bool_argv(["--agent.curiosity", "off", "--no-agent.channels-last"],
        ...           ["--agent.curiosity", "--agent.channels-last"])
        ['--agent.no-curiosity', '--agent.no-channels-last']
    """
    flags = set(flags)
    former = {"--no-" + flag[2:]: negated(flag) for flag in flags}
    words = TRUE_WORDS + FALSE_WORDS
    out: list[str] = []
    i = 0
    while i < len(argv):
        name, eq, word = argv[i].partition("=")
        if name in flags and not eq and i + 1 < len(argv) and argv[i + 1].lower() in words:
            word, step = argv[i + 1], 2
        elif name in flags and eq and word.lower() in words:
            step = 1
        elif name in flags and eq:
            raise ValueError(
                f"{name} is a switch: it takes true or false ({name}=true, {name}=false), or "
                f"give {name} / {negated(name)} alone; got {argv[i]!r}"
            )
        else:
            out.append(former.get(argv[i], argv[i]))
            i += 1
            continue
        out.append(name if word.lower() in TRUE_WORDS else negated(name))
        i += step
    return out


def refuse_unknown_subcommand(argv: Sequence[str], command: Any, prog: str) -> None:
    """Raise ValueError when ``argv`` does not start with one of ``command``'s subcommands: a
    word that is none of them (``Run`` for ``run``, ``plot`` for ``report``), named with the
    close ones, or flags before the subcommand. tyro would answer with a box listing every word
    as a misplaced option."""
    named = subcommands(command)
    words = [arg for arg in argv if arg not in ("--help", "-h")]
    if not named or not words or words[0] in named:
        return
    first = words[0]
    example = f"`{prog} {next(iter(named))} --help`"
    if first.startswith("-"):
        later = next((arg for arg in words if arg in named), None)
        where = f"put {later} before {first}" if later else f"name one of {', '.join(named)}"
        raise ValueError(
            f"{first} comes before the subcommand; {prog} takes its subcommand first ({where}), "
            f"e.g. {example}"
        )
    lowered = {name.lower(): name for name in named}
    close = lowered.get(first.lower())
    options = [close] if close else close_keys(first, dict.fromkeys(named, ""))
    hint = f" (did you mean {' or '.join(options)}?)" if options else ""
    raise ValueError(
        f"unknown subcommand {first!r}{hint}; {prog} takes one of {', '.join(named)} first, "
        f"e.g. {example}"
    )


def run_setting(name: str) -> str | None:
    """The run config key whose flag ``name`` is (``--action-repeat``: action_repeat; a
    switch's negation too, ``--agent.no-curiosity``), else None."""
    for key, (kind, _, _) in config_fields().items():
        flag = "--" + key.replace("_", "-")
        if name == flag or (kind is bool and name in (negated(flag), "--no-" + flag[2:])):
            return key
    return None


def refuse_unknown(
    argv: Sequence[str],
    flags: dict[str, Flag],
    command: Any,
    prog: str,
    reads_runs: bool = False,
    other_names: Mapping[str, Meant] | None = None,
    siblings: Mapping[str, Any] | None = None,
) -> None:
    """Raise ValueError for a ``--flag`` of ``argv`` that is not one of ``flags`` (the command's,
    :func:`~simoun_agent.cli.command_flags.command_flags`), naming what it most likely meant:
    the command's own flag in other letter case or with ``_`` for ``-`` (``--Seed``: ``--seed``),
    the command's counterpart of another library's flag (``other_names``, e.g.
    :data:`~simoun_agent.cli.other_names.RUN_CONFIG_NAMES`: ``--buffer-size``:
    ``--replay-capacity``), the positional argument it names (``simoun-eval --run-dir``), a
    flag of another simoun command (``siblings``: its name -> its command dataclass) as that
    command's, a switch's negation for a ``--no-`` name, else the flags found by meaning as
    well as spelling (``--frame-size``: ``--image-size``; ``--num-episodes``: ``--episodes``)
    that take the kind of value it was given; for a command that ``reads_runs``, a flag of the
    run config is told to be the run's own. Nothing is checked before a subcommand is named:
    tyro asks for one."""
    if not flags:
        return
    named = subcommands(command)
    sub = next((f" {arg}" for arg in argv if arg in named), "")
    for arg in argv:
        if arg == "--":
            break
        name = arg.partition("=")[0]
        if not name.startswith("--") or name in flags or name in ("--help", "--version"):
            continue
        if spelled := ascii_flag(arg):
            raise lookalike_error(arg, spelled)
        meant = (other_names or {}).get(name_key(name))
        raise unknown_flag_error(
            arg, argv, flags, command, (prog, sub), reads_runs, meant, siblings
        )


def unknown_flag_error(
    arg: str,
    argv: Sequence[str],
    flags: dict[str, Flag],
    command: Any,
    called: tuple[str, str],
    reads_runs: bool,
    meant: Meant | None,
    siblings: Mapping[str, Any] | None = None,
) -> ValueError:
    """The refusal of the unknown flag ``arg`` of ``argv``, for the command ``called`` (its
    name, and its subcommand with a space before it, or empty); ``meant`` is what the command
    calls it (:mod:`simoun_agent.cli.other_names`)."""
    name = arg.partition("=")[0]
    prog = "".join(called)
    help_line = f"`{prog} --help` lists every flag"
    if (own := same_flag(name, flags)) is not None:
        return ValueError(
            f"unknown flag {name}: flags are written in lower case with dashes; give {own} "
            f"({short_doc(flags[own].doc)})"
        )
    slot = positional_named(name, command, argv, meant)
    if slot is not None:
        return ValueError(
            f"unknown flag {name}: {slot.metavar} is a positional argument of {prog}, given "
            f"without a flag: {called[0]} {shlex.join(without_flag(argv, arg))}"
        )
    other = sibling_flag(name, siblings, prog)
    value = typed_value(arg, argv)
    if meant is not None and (text := counterpart(meant, flags, prog, value)):
        return ValueError(f"unknown flag {name}: {other}{text}; {help_line}")
    if reads_runs and (key := run_setting_meant(name, flags, meant)):
        setting = "--" + key.replace("_", "-")
        shown = "" if config_fields()[key][0] is bool else " ..."
        return ValueError(
            f"{name} is not a flag of {prog}: {key} is a setting of the run, saved in its "
            f"config.json, and {prog} uses the run's own; it is chosen when the run is trained "
            f"(simoun-train {setting}{shown}). {help_line}"
        )
    matches = negated_matches(name, flags)
    if matches is None:
        matches = close_flags(name, flags, value_kind(value), by_name=bool(other))
    if other:
        said = " or ".join(f"{flag} ({short_doc(flags[flag].doc)})" for flag in matches)
        here = f"{prog} has {said}" if matches else f"{prog} has no such flag"
        return ValueError(f"unknown flag {name}: {other}{here}; {help_line}")
    hint = f" (did you mean {' or '.join(matches)}?)" if matches else ""
    return ValueError(f"unknown flag {name}{hint}; {help_line}")


def close_flags(name: str, flags: dict[str, Flag], kind: str, by_name: bool) -> list[str]:
    """The flags of ``flags`` that the unknown ``name``, given a value of ``kind``
    (:func:`value_kind`), most likely meant, by meaning and spelling; only those that take such
    a value, and with ``by_name`` only those that share a word of their name (``name`` is
    another command's flag: a flag found through its help alone is another thing)."""
    docs = {flag.key: flag.doc for flag in flags.values()}
    typed = name[2:]
    keys = [
        key
        for key in close_keys(typed, docs)
        if not by_name or meaning_score(typed, key, docs[key]) >= NAME_WEIGHT
    ]
    found = ["--" + key.replace("_", "-") for key in keys]
    return [flag for flag in found if flag not in flags or takes(flags[flag], kind)]


def same_flag(name: str, flags: dict[str, Flag]) -> str | None:
    """The flag of ``flags`` that ``name`` spells in other letter case, or with ``_`` for ``-``
    (``--Seed``, ``--run_dir``, ``--Agent.LR``), else None."""
    typed = name_key(name)
    return next((flag for flag in flags if name_key(flag) == typed), None)


def sibling_flag(name: str, siblings: Mapping[str, Any] | None, prog: str) -> str:
    """``"--videos is simoun-eval's flag (its help), not simoun-train's; "`` when ``name`` (in
    any letter case) is a flag of another simoun command of ``siblings`` (its name -> its
    command dataclass), else empty."""
    typed = name_key(name)
    for other, command in (siblings or {}).items():
        for flag, given in command_flags(command, []).items():
            if name_key(flag) == typed:
                doc = " ".join(given.doc.split()).rstrip(".")
                return f"{flag} is {other}'s flag ({doc}), not {prog}'s; "
    return ""


def typed_value(arg: str, argv: Sequence[str]) -> str | None:
    """The value the unknown option ``arg`` of ``argv`` was given: its ``=VALUE``, else the
    word after it unless that is a flag; None when it has none (it was typed as a switch)."""
    _, eq, value = arg.partition("=")
    if eq:
        return value
    at = list(argv).index(arg) + 1
    following = argv[at] if at < len(argv) else None
    if following is None or (following.startswith("-") and not NUMBER_WORD.fullmatch(following)):
        return None
    return following


def value_kind(value: str | None) -> str:
    """What kind of value ``value`` is: switch (none), bool (true/false words), number, json or
    word."""
    if value is None:
        return "switch"
    if NUMBER_WORD.fullmatch(value):
        return "number"
    if value.lower() in TRUE_WORDS + FALSE_WORDS:
        return "bool"
    return "json" if value.lstrip().startswith("{") else "word"


def takes(flag: Flag, kind: str) -> bool:
    """Whether ``flag`` takes a value of ``kind`` (:func:`value_kind`): a flag that takes
    another (a number for a path, a value for a switch) is no flag that was meant."""
    own = flag_kind(flag)
    if kind == "number":
        return own == "number" or (own == "word" and not flag.path)
    if kind == "bool":
        return own in ("switch", "word")
    return own == kind


def flag_kind(flag: Flag) -> str:
    """What kind of value ``flag`` takes, in :func:`value_kind`'s words (bool is a switch's)."""
    if flag.switch is not None:
        return "switch"
    if flag.json:
        return "json"
    return "number" if flag.number else "word"


def counterpart(meant: Meant, flags: dict[str, Flag], prog: str, value: str | None = None) -> str:
    """What ``meant`` is in a command with ``flags``: its flags there, each with its help, and
    its note (``{value}`` there the value typed, else N); the note alone, as not supported
    here, when it names no flag; empty when its flags are none of the command's."""
    present = [flag for flag in meant.flags if flag in flags]
    written = meant.note.replace("{value}", value if value is not None else "N")
    note = f"; {written}" if written else ""
    if present:
        said = " or ".join(f"{flag} ({short_doc(flags[flag].doc)})" for flag in present)
        return f"{prog} calls it {said}{note}"
    if written and not meant.flags:
        return f"not supported here: {written}"
    return ""


def short_doc(doc: str) -> str:
    """A flag's help up to its first clause: what it is, without the details."""
    first = re.split(r"; |(?<!e\.g)\. |: | \(|, e\.g\.", " ".join(doc.split()), maxsplit=1)[0]
    return first.rstrip(".")


def positional_named(
    name: str, command: Any, argv: Sequence[str], meant: Meant | None
) -> PositionalArg | None:
    """The positional argument the unknown flag ``name`` stands for: the one ``meant`` says, or
    the one whose name or metavar it spells (``--checkpoint``, ``--run``, ``--spec``)."""
    slots = positionals(command, argv) or []
    typed = key_words(name[2:])
    for slot in slots:
        if (meant is not None and meant.positional) or typed in (
            key_words(slot.metavar),
            key_words(slot.name),
        ):
            return slot
    return None


def key_words(text: str) -> list[str]:
    """The lower-case words of a flag or key: ``--run-dir``, ``run_dir``, ``RUN_DIR``: run, dir."""
    return re.findall(r"[a-z0-9]+", text.lower())


def without_flag(argv: Sequence[str], arg: str) -> list[str]:
    """``argv`` with the option word ``arg`` left out (``--run-dir=DIR`` becomes ``DIR``): its
    value then fills the positional argument."""
    out = []
    for word in argv:
        if word == arg:
            _, eq, value = word.partition("=")
            out.extend([value] if eq else [])
            continue
        out.append(word)
    return out


def run_setting_meant(name: str, flags: dict[str, Flag], meant: Meant | None) -> str | None:
    """The run config key that the unknown ``name`` sets, by its own spelling or through its
    counterpart ``meant``; None when a flag of the command shares a word with ``name``
    (``--eval-episodes``: ``--episodes``), which is then the one meant."""
    docs = {flag.key: flag.doc for flag in flags.values()}
    alike = any(
        meaning_score(name[2:], key, docs[key]) >= NAME_WEIGHT for key in close_keys(name[2:], docs)
    )
    if alike:
        return None
    candidates = [name, *(meant.flags if meant is not None else ())]
    return next((key for flag in candidates if (key := run_setting(flag))), None)


NEGATING_WORDS = ("no", "disable", "without")
"""First words of a flag that turn its switch off (``--no-curiosity``, ``--disable-video``)."""


def negated_matches(name: str, flags: dict[str, Flag]) -> list[str] | None:
    """For an unknown ``--no-X`` flag (or ``--disable-X``), the negations of the switches that X
    most likely means (``--no-curiosity``: ``--agent.no-curiosity``), and never a flag that
    would turn X on or set another value; None for a name that negates nothing."""
    section, dot, last = name[2:].rpartition(".")
    first, _, rest = last.replace("_", "-").partition("-")
    if first.lower() not in NEGATING_WORDS or not rest:
        return None
    switches = {flag.key: flag.doc for flag in flags.values() if flag.switch is True}
    typed = f"{section}{dot}{rest}"
    # a switch named by a word of X: one found through its help alone may be another thing
    # to turn off (--no-eval is not --no-video)
    keys = [
        key
        for key in close_keys(typed, switches)
        if meaning_score(typed, key, switches[key]) >= NAME_WEIGHT
    ]
    negations = (negated("--" + key.replace("_", "-")) for key in keys)
    return [flag for flag in negations if flag in flags]


SHORT_OPTION = re.compile(r"-[A-Za-z][A-Za-z0-9]*(=.*)?")
"""A one-dash option (``-V``, ``-v``, ``-n=3``); a negative number is a value, not one."""


def refuse_short_options(argv: Sequence[str], flags: dict[str, Flag], prog: str) -> None:
    """Raise ValueError for a one-dash option other than ``-h``: the commands' flags are long
    ones, and tyro would answer with its usage box, which names neither ``--version`` nor the
    long flag meant. A word after an option that takes a value is that value."""
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        if arg == "-h" or not SHORT_OPTION.fullmatch(arg):
            continue
        before = flags.get(argv[i - 1]) if i else None
        if before is not None and before.switch is None:
            continue
        letters = arg[1:].partition("=")[0]
        close = [name for name in flags if name[2:].startswith(letters.lower())][:3]
        hint = f" (did you mean {' or '.join(close)}?)" if len(letters) > 1 and close else ""
        raise ValueError(
            f"unknown option {arg}{hint}: {prog} has long flags only, besides -h; --version "
            f"prints its version, and `{prog} --help` lists every flag"
        )


def refuse_stray_words(
    argv: Sequence[str], flags: dict[str, Flag], positional: bool, switches: Iterable[str] = ()
) -> None:
    """Raise ValueError for a word after a switch in a command that takes no positional
    argument (``--progress maybe``, ``--overwrite true``): tyro would name only the word, not
    the switch it was meant for. :func:`bool_argv` already took the true/false words of
    ``switches``."""
    if positional:
        return
    for arg, following in itertools.pairwise(argv):
        if arg == "--":
            break
        flag = flags.get(arg)
        meant_as_flag = following.startswith("-") or ascii_flag(following)
        if flag is None or flag.switch is None or meant_as_flag:
            continue
        if forms := setting_forms(following, flags):
            raise ValueError(
                f"{arg} is a switch and takes no value, and a KEY=VALUE setting is not given "
                f"bare: write {forms}; got {following!r}"
            )
        raise ValueError(f"{switch_use(arg, flag, switches)}; got {following!r}")


SETTING_WORD = re.compile(r"[+~]{0,2}([A-Za-z_][A-Za-z0-9_.-]*)=(.*)", re.DOTALL)
"""A ``KEY=VALUE`` word, as Hydra takes overrides (``agent.lr=1e-3``, ``+agent.lr=1e-3``)."""


def setting_forms(word: str, flags: dict[str, Flag]) -> str:
    """For a ``KEY=VALUE`` word typed bare (Hydra's way), the forms in which the command takes
    that setting: ``--set agent.lr=1e-3 or --agent.lr 1e-3`` (each one it has); empty for any
    other word."""
    match = SETTING_WORD.fullmatch(word)
    if match is None:
        return ""
    key, value = match.groups()
    name = "--" + key.replace("_", "-")
    flag = flags.get(name)
    if key in ("help", "version"):
        return name
    if flag is not None and not flag.config:  # the command's own flag: --set refuses it
        if flag.switch is None:
            return f"{name} {value}"
        return f"nothing: leave {name} out" if value.lower() in FALSE_WORDS else name
    forms = [f"--set {key}={value}"] if "--set" in flags else []
    if flag is not None:
        forms.append(f"{name} {value}")
    return " or ".join(forms)


DASHED_SETTING = re.compile(r"-{1,2}([A-Za-z_][A-Za-z0-9_.-]*)=(.*)", re.DOTALL)
"""A ``KEY=VALUE`` word written with a flag's dashes (``--agent.lr=1e-3,3e-4``)."""


def refuse_setting_read_as_flag(argv: Sequence[str], flags: dict[str, Flag]) -> None:
    """Raise ValueError for an option that takes a ``KEY=VALUE`` word (``--grid``, ``--set``)
    followed by one written with dashes (``--grid --agent.lr=1e-3,3e-4``): the shell hands it
    on as a flag of its own, so the option is left without its value, and tyro says only that
    the value is missing."""
    for arg, following in itertools.pairwise(argv):
        if arg == "--":
            break
        flag = flags.get(arg)
        match = DASHED_SETTING.fullmatch(following)
        if flag is None or not flag.setting or match is None:
            continue
        key, value = match.groups()
        meant = f"{key.replace('-', '_')}={value}"
        raise ValueError(
            f"{arg} takes a KEY=VALUE word, and {following!r} after it starts with dashes, so it "
            f"was read as a flag of its own and {arg} was left without a value; write the key "
            f"without dashes: {arg} {shlex.quote(meant)}"
        )


def switch_use(name: str, flag: Flag, switches: Iterable[str]) -> str:
    """How the switch ``name`` is given: with true or false when its flag is one of
    ``switches`` (:func:`bool_argv` reads those), else alone."""
    positive = "--" + flag.key.replace("_", "-")
    if name == positive and positive in switches:
        return (
            f"{name} is a switch: it takes true or false ({name} true, {name} false), or give "
            f"{name} / {negated(name)} alone"
        )
    if positive in switches:
        return f"{name} takes no value; give {name} alone, or {positive}=true / {positive}=false"
    return f"{name} is a switch and takes no value; give {name} alone, or leave it out"


def refuse_repeated(argv: Sequence[str], flags: dict[str, Flag]) -> None:
    """Raise ValueError for an option of ``flags`` given twice with different values
    (``--episodes 1 --episodes 2``, ``--video --no-video``, a subcommand's ``--study-dir a
    --study-dir b``, a list's ``--probes rnd --probes consistency``): tyro would keep the last
    without a word. Switches come as ``--video`` / ``--no-video`` here (:func:`bool_argv` ran
    first); a list given by repeating its flag (``--grid``, ``--set``) is meant to be repeated,
    and the run config's keys are compared by value where they are read
    (:func:`simoun_agent.cli.config_flags.check_given_once`)."""
    refuse_repeated_lists(argv, flags)
    given: dict[str, dict[str, str]] = {}
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        name, eq, text = arg.partition("=")
        flag = flags.get(name)
        if flag is None or flag.repeatable or flag.config:
            continue
        if flag.switch is not None:
            value, said = str(flag.switch), arg
        elif eq or i + 1 < len(argv):
            value = text if eq else argv[i + 1]
            said = arg if eq else f"{arg} {value}"
        else:
            continue  # tyro says the value is missing
        given.setdefault(flag.key, {}).setdefault(value, said)
    for key, values in given.items():
        if len(values) > 1:
            raise ValueError(
                f"--{key.replace('_', '-')} is given twice with different values "
                f"({' and '.join(values.values())}); give it once"
            )


def list_values(argv: Sequence[str], flags: dict[str, Flag]) -> dict[str, list[list[str]]]:
    """For each list option that takes its values after one flag (``--probes rnd consistency``),
    the words given after each of its flags, in order."""
    given: dict[str, list[list[str]]] = {}
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        name, eq, text = arg.partition("=")
        flag = flags.get(name)
        if flag is None or not (flag.repeatable and flag.variadic) or flag.config:
            continue
        words = (
            [text]
            if eq
            else list(itertools.takewhile(lambda w: not w.startswith("--"), argv[i + 1 :]))
        )
        given.setdefault(name, []).append(words)
    return given


def refuse_repeated_lists(argv: Sequence[str], flags: dict[str, Flag]) -> None:
    """Raise ValueError for a list option that takes its values after one flag given twice with
    different values (``--probes rnd --probes consistency``): tyro keeps the last list and drops
    the first without a word, so every value goes after one flag."""
    for name, lists in list_values(argv, flags).items():
        if len({tuple(words) for words in lists}) < 2:
            continue
        said = " and ".join(shlex.join([name, *words]) for words in lists)
        every = list(dict.fromkeys(word for words in lists for word in words))
        raise ValueError(
            f"{name} is given twice with different values ({said}), and only the last would "
            f"count; give every value after one {name}: {shlex.join([name, *every])}"
        )


LOOKALIKE_DASHES = "\u2010\u2011\u2012\u2013\u2014\u2015\u2212\ufe58\ufe63"
"""Dashes a word processor, autocorrect or a web page puts where ``-`` was typed (hyphens, en
and em dashes, the minus sign); NFKC turns the fullwidth ones into ASCII itself."""


def ascii_flag(word: str) -> str | None:
    """The ASCII spelling (``--seed``) of a word typed as a flag with look-alike characters
    (``–-seed``, ``—seed``, fullwidth ``－－ｓｅｅｄ``), else None: such a word is no flag to
    the shell or to tyro, so it would be taken for a value."""
    if word.isascii():
        return None
    spelled = unicodedata.normalize("NFKC", word).translate(
        dict.fromkeys(map(ord, LOOKALIKE_DASHES), "-")
    )
    name, eq, value = spelled.partition("=")
    if not re.fullmatch(r"-{1,2}[A-Za-z][A-Za-z0-9_.-]*", name):
        return None
    return "--" + name.lstrip("-") + eq + value


def lookalike_error(word: str, spelled: str) -> ValueError:
    return ValueError(
        f"{word!r} looks like a flag typed with a non-ASCII dash or letters (as autocorrect or "
        f"a web page writes them); type it in ASCII: {spelled}"
    )


@dataclass(frozen=True)
class Given:
    """One value of a command line as tyro will read it."""

    flag: str | None
    """the option's spelling (``--out``), None for a positional argument"""
    value: str | None
    """the value as written, None for a switch given alone"""
    positional: PositionalArg | None = None
    """the positional argument the value fills (None: an option's, or a stray word)"""

    @property
    def unplaced(self) -> bool:
        """a word that no option and no positional argument takes"""
        return self.flag is None and self.positional is None


def given_values(argv: Sequence[str], flags: dict[str, Flag], command: Any) -> Iterator[Given]:
    """The values of ``argv`` in order, each with its option or positional argument: an option
    takes the word after it (a variadic one every word up to the next flag), ``--flag=VALUE``
    its own; a word no option takes fills the next positional argument, and a variadic
    positional argument takes one run of words (tyro reads no more after a flag between them).
    Nothing before a named subcommand; ``--`` ends the walk; a word no argument takes comes
    with ``positional`` None."""
    slots = positionals(command, argv)
    if slots is None:
        return
    named = subcommands(command)
    subcommand_seen = not named
    filled = 0  # positional arguments done
    run = "none"  # of the variadic one: none, open (taking words), closed (a flag came after)
    i = 0
    while i < len(argv):
        arg = argv[i]
        if arg == "--":
            return
        if spelled := ascii_flag(arg):  # whatever it would fill, it was meant as a flag
            raise lookalike_error(arg, spelled)
        name, eq, text = arg.partition("=")
        flag = flags.get(name) if arg.startswith("--") else None
        i += 1
        if arg.startswith("-") and arg.strip("-") and run == "open":
            run = "closed"
        if flag is not None:
            if eq or flag.switch is not None:
                yield Given(name, text if eq else None)
                continue
            while i < len(argv) and not (argv[i].startswith("--") and argv[i] != "--"):
                if spelled := ascii_flag(argv[i]):
                    raise lookalike_error(argv[i], spelled)
                yield Given(name, argv[i])
                i += 1
                if not flag.variadic:
                    break
            continue
        if arg.startswith("-") and arg.strip("-"):
            continue  # --help, -h; an unknown flag was refused already
        if not subcommand_seen and arg in named:
            subcommand_seen = True
            continue
        slot = slots[filled] if filled < len(slots) else None
        if slot is not None and slot.variadic:
            if run == "closed":
                slot = None
            run = "open" if run == "none" else run
        elif slot is not None:
            filled += 1
        yield Given(None, arg, slot)


def refuse_stray_arguments(
    argv: Sequence[str],
    flags: dict[str, Flag],
    command: Any,
    prog: str,
    other_names: Mapping[str, Meant] | None = None,
) -> None:
    """Raise ValueError for a word that no option and no positional argument takes
    (``simoun-train foo``, ``simoun-report DIR extra``, ``simoun-eval A --episodes 1 B``): tyro
    would print a box of help. A word right after an option's value is named as a second value
    of that option (``--seed 1 2``), with what to do instead (``other_names``' note for the
    flag, one JSON object for a dict); a number or ``KEY=VALUE`` word where a path goes, as
    the flag's value it was meant to be."""
    slots = positionals(command, argv) or []
    sub = next((f" {arg}" for arg in argv if arg in subcommands(command)), "")
    takes = "no positional argument (every value goes with its --flag)"
    if slots:
        takes = "only " + " ".join(
            f"{slot.metavar} [{slot.metavar} ...], all together before or after the flags"
            if slot.variadic
            else slot.metavar
            for slot in slots
        )
    after_dashes = argv[argv.index("--") + 1 :] if "--" in argv and not slots else []
    values = list(given_values(argv, flags, command))
    for before, value in zip([None, *values], values, strict=False):
        if not value.unplaced:
            continue
        forms = setting_forms(value.value, flags)
        if second_value(before, value.value, flags, bool(slots), other_names) and (
            not forms or flags[before.flag].repeatable
        ):
            raise second_value_error(before, value.value, flags, other_names)
        if forms:
            hint = f"a KEY=VALUE setting is not given bare: write {forms}"
        else:
            hint = number_hint(value.value, flags) or f"`{prog}{sub} --help` lists its flags"
        raise ValueError(f"unexpected argument {value.value!r}: {prog}{sub} takes {takes}; {hint}")
    for word in after_dashes:
        forms = setting_forms(word, flags)
        hint = (
            f"; a KEY=VALUE setting is not given bare: write {forms}"
            if forms
            else f"; `{prog}{sub} --help` lists its flags"
        )
        raise ValueError(f"unexpected argument {word!r}: {prog}{sub} takes {takes}{hint}")
    for value in values:
        if value.positional is not None and value.positional.path:
            refuse_setting_as_path(value.value, value.positional, flags, f"{prog}{sub}")
            refuse_number_as_path(value.value, value.positional, flags, f"{prog}{sub}")


def refuse_setting_as_path(
    word: str, slot: PositionalArg, flags: dict[str, Flag], prog: str
) -> None:
    """Raise ValueError for a ``KEY=VALUE`` word (``episodes=1``) given where a path goes and
    naming nothing on disk: it was meant as a setting, and the command would read it as one
    more path (a second run, say)."""
    if SETTING_WORD.fullmatch(word) is None or Path(word).exists():
        return
    forms = setting_forms(word, flags)
    fix = f"write {forms}" if forms else f"`{prog} --help` lists its flags"
    raise ValueError(
        f"{word!r} is not a {slot.metavar} (no such file or directory) but a KEY=VALUE setting, "
        f"which {prog} does not take bare: it takes options as flags; {fix}"
    )


def second_value(
    before: Given | None,
    word: str,
    flags: dict[str, Flag],
    positional: bool,
    other_names: Mapping[str, Meant] | None,
) -> bool:
    """Whether the stray ``word``, typed after ``before``, was meant as a second value of
    ``before``'s option: a number after a number's, a JSON object after a JSON option's;
    another word when the command takes no positional argument it could have been, or the
    command says how that option takes several (``other_names``)."""
    if before is None or before.flag is None or before.value is None:
        return False
    flag = flags[before.flag]
    if flag.number is not None:
        return NUMBER_WORD.fullmatch(word) is not None
    if flag.json:
        return word.lstrip().startswith("{")
    meant = (other_names or {}).get(name_key(before.flag))
    return not positional or (meant is not None and bool(meant.note) and not meant.flags)


def second_value_error(
    given: Given, word: str, flags: dict[str, Flag], other_names: Mapping[str, Meant] | None
) -> ValueError:
    """The refusal of ``word``, typed after the value of ``given``'s option, which takes one."""
    name, first = given.flag or "", given.value or ""
    flag = flags[name]
    said = f"{name} takes one value, so {word!r} after {first!r} is left over"
    meant = (other_names or {}).get(name_key(name))
    if meant is not None and meant.note and not meant.flags:
        return ValueError(f"{said}: {meant.note}")
    if flag.json and (merged := merged_json(first, word)):
        return ValueError(
            f"{said}: put every key in one JSON object, e.g. {name} {shlex.quote(merged)}"
        )
    if flag.repeatable:
        return ValueError(f"{said}: give {name} once per value, e.g. {name} {first} {name} {word}")
    return ValueError(f"{said}: give one value, e.g. {name} {first}")


def merged_json(first: str, second: str) -> str | None:
    """The JSON object holding the keys of the objects ``first`` and ``second`` (the second's
    value where both give a key), None when either is not a JSON object."""
    try:
        return json.dumps(json_object(first) | json_object(second))
    except ValueError:
        return None


NUMBER_WORD = re.compile(r"[+-]?([0-9][0-9_]*)(\.[0-9]*)?([eE][+-]?[0-9]+)?")
"""A bare number (``1``, ``0.5``, ``1e-3``)."""


def refuse_number_as_path(
    word: str, slot: PositionalArg, flags: dict[str, Flag], prog: str
) -> None:
    """Raise ValueError for a number given where a path goes and naming nothing on disk
    (``simoun-eval RUN 1``): it was meant as a flag's value (``--episodes 1``), and the command
    would read it as one more path (a second run, say)."""
    if NUMBER_WORD.fullmatch(word) is None or Path(word).exists():
        return
    fix = number_hint(word, flags) or f"`{prog} --help` lists its flags"
    raise ValueError(
        f"{word!r} is not a {slot.metavar} (no such file or directory) but a number, which "
        f"{prog} does not take bare: {fix}"
    )


def number_hint(word: str, flags: dict[str, Flag]) -> str:
    """For a bare number ``word``, the command's own flags it may be the value of (``--episodes
    1 (episodes to play)``, three at most); empty for another word, or a command with none."""
    match = NUMBER_WORD.fullmatch(word)
    if match is None:
        return ""
    fits = (float,) if match.group(2) or match.group(3) else (int, float)
    numeric = [
        name
        for name, flag in flags.items()
        if flag.number in fits and not flag.config and name == "--" + flag.key.replace("_", "-")
    ]
    examples = [f"{name} {word} ({short_doc(flags[name].doc)})" for name in numeric[:3]]
    if not examples:
        return ""
    return f"a number goes with the flag it is for, e.g. {' or '.join(examples)}"


def refuse_switch_values(
    argv: Sequence[str], flags: dict[str, Flag], switches: Iterable[str]
) -> None:
    """Raise ValueError for a switch given ``=VALUE`` (``--overwrite=false``,
    ``--no-progress=false``) that :func:`bool_argv` did not read: tyro would say only
    ``Unrecognized options: false``."""
    for arg in argv:
        if arg == "--":
            break
        name, eq, _ = arg.partition("=")
        flag = flags.get(name)
        if flag is not None and flag.switch is not None and eq:
            raise ValueError(f"{switch_use(name, flag, switches)}; got {arg!r}")


def refuse_empty_values(argv: Sequence[str], flags: dict[str, Flag], command: Any) -> None:
    """Raise ValueError for an empty or blank value (``--out=``, ``--out ''``, ``--env '  '``,
    ``simoun-report ''``): an empty path is the current directory, and no other value of the
    commands is blank."""
    for value in given_values(argv, flags, command):
        if value.value is None or value.value.strip():
            continue
        if value.flag is None:
            where = value.positional.metavar if value.positional else "an argument"
            raise ValueError(f"{where} is given an empty value ({value.value!r}); give {where}")
        raise ValueError(empty_value(value.flag, value.value, flags[value.flag]))


def empty_value(flag: str, value: str, given: Flag | None = None) -> str:
    """The refusal of an empty or blank ``value`` of ``flag``."""
    fix = f"give {flag} a value, or leave it out for its default"
    if given is not None and given.config and given.repeatable:
        fix += f" (--set {given.key}= empties the list)"
    return f"{flag} is given an empty value ({value!r}); {fix}"


def refuse_bad_json(argv: Sequence[str], flags: dict[str, Flag], command: Any) -> None:
    """Raise ValueError naming the flag for a dict option's value that is not a JSON object, or
    that gives a key twice (``--env-kwargs '{"a": 1, "a": 2}'``): tyro would keep the last
    value without a word, or print a box of help."""
    for value in given_values(argv, flags, command):
        if value.flag is not None and value.value is not None and flags[value.flag].json:
            try:
                json_object(value.value, value.flag)
            except ValueError as err:
                raise ValueError(f"{value.flag}: {err}") from None


NAME_MAX = 255
"""Bytes in one file or directory name at most (Linux's file systems)."""

PATH_MAX = 4096
"""Bytes in a whole path at most, its final NUL included (Linux)."""


def path_values(
    argv: Sequence[str], flags: dict[str, Flag], command: Any
) -> Iterator[tuple[str, str]]:
    """(where it was given: the flag or the positional's name, the text) of each path value of
    ``argv``."""
    for value in given_values(argv, flags, command):
        if value.value is None:
            continue
        if value.flag is not None:
            where, path = value.flag, flags[value.flag].path
        else:
            where = value.positional.metavar if value.positional else ""
            path = value.positional is not None and value.positional.path
        if path:
            yield where, value.value


def refuse_long_paths(argv: Sequence[str], flags: dict[str, Flag], command: Any) -> None:
    """Raise ValueError for a path value the file system cannot hold: a name longer than
    :data:`NAME_MAX` bytes, or a path of :data:`PATH_MAX` bytes or more. The operating system
    would refuse it from inside whichever step touches it first, with a traceback."""
    for where, text in path_values(argv, flags, command):
        size = len(os.fsencode(text))
        longest = max((len(os.fsencode(name)) for name in text.split("/")), default=0)
        short = text if len(text) <= 60 else text[:40] + "..."
        if size >= PATH_MAX:
            raise ValueError(
                f"{where} {short}: the path is {size} bytes long, past the file system's limit "
                f"of {PATH_MAX - 1}; give a shorter path"
            )
        if longest > NAME_MAX:
            raise ValueError(
                f"{where} {short}: a name in the path is {longest} bytes long, past the file "
                f"system's limit of {NAME_MAX}; give a shorter name"
            )


def refuse_unexpanded_home(argv: Sequence[str], flags: dict[str, Flag], command: Any) -> None:
    """Raise ValueError for a path value that starts with a ``~`` the shell did not expand
    (``--resume=~/runs/a``, a quoted ``'~/runs'``, a script's argument list) and that names
    nothing as written: it would be read, or made, as a directory called ``~`` here."""
    for where, text in path_values(argv, flags, command):
        if (text == "~" or text.startswith("~/")) and not os.path.exists(text):
            raise ValueError(
                f"{where} {text}: the shell did not expand ~ (it does not after = or inside "
                f"quotes), so this names a directory called ~ here, which does not exist; give "
                f"{os.path.expanduser(text)}"
            )


INT64_END = 2**63
"""Where int64 ends: a count, seed or step at or past it wraps around in numpy and torch."""


def refuse_huge_numbers(argv: Sequence[str], flags: dict[str, Flag], prog: str) -> None:
    """Raise ValueError for an option of ``flags`` given a whole number that int64 does not
    hold (``--episodes 99999999999999999999``): every count, seed and step becomes a numpy or
    torch int64, where it would wrap around or fail from inside the library."""
    for i, arg in enumerate(argv):
        if arg == "--":
            break
        name, eq, text = arg.partition("=")
        flag = flags.get(name)
        if flag is None or flag.switch is not None or not (eq or i + 1 < len(argv)):
            continue
        value = text if eq else argv[i + 1]
        if re.fullmatch(r"[+-]?[0-9_]+", value.strip()) and abs(int(value)) >= INT64_END:
            raise ValueError(
                f"{name} {value}: larger than any count, seed or step can be (they are int64s, "
                f"below 2**63); give a smaller number (`{prog} --help` shows each default)"
            )


def negated(flag: str) -> str:
    """tyro's negation of a switch: ``--video`` -> ``--no-video``, ``--agent.curiosity`` ->
    ``--agent.no-curiosity``."""
    section, dot, name = flag[2:].rpartition(".")
    return f"--{section}{dot}no-{name}"


def installed_version() -> str:
    """The installed simoun version."""
    try:
        return version("simoun")
    except PackageNotFoundError:  # run from a source tree that was never installed
        return "unknown (not installed)"


VERSION_HELP = "--version: print the installed version and exit."
"""The line every command's help ends its description with: tyro does not list ``--version``,
which :func:`parse` answers itself."""


def parse(
    cls: Any,
    argv: Sequence[str] | None,
    prog: str,
    description: str,
    default: T | None = None,
    switches: Iterable[str] = (),
    reads_runs: bool = False,
    other_names: Mapping[str, Meant] | None = None,
    siblings: Mapping[str, Any] | None = None,
) -> T:
    """``cls`` from ``argv`` (None: ``sys.argv[1:]``) with tyro and :data:`REGISTRY`;
    ``switches`` are the boolean flags that also take the older ``--flag false``; a command that
    ``reads_runs`` tells a run config flag it does not take to be the run's own; ``other_names``
    are other libraries' flags with what they are called in the command
    (:mod:`simoun_agent.cli.other_names`); ``siblings`` the other simoun commands (name ->
    command dataclass) whose flags an unknown flag is named as. Exits 0
    after ``--version`` or ``--help``, 2 with one line for input the checks above refuse, or
    tyro's message for other input it cannot read."""
    argv = list(sys.argv[1:] if argv is None else argv)
    switches = list(switches)
    description = f"{description}\n\n{VERSION_HELP}"
    if "--version" in argv:
        print(f"{prog} {installed_version()}")
        sys.exit(0)
    try:
        flags = command_flags(cls, argv)
        refuse_setting_read_as_flag(argv, flags)
        argv = bool_argv(argv, switches)
        refuse_short_options(argv, flags, prog)
        refuse_unknown_subcommand(argv, cls, prog)
        refuse_unknown(argv, flags, cls, prog, reads_runs, other_names, siblings)
        refuse_stray_words(argv, flags, takes_positional(cls, argv), switches)
        refuse_switch_values(argv, flags, switches)
        refuse_stray_arguments(argv, flags, cls, prog, other_names)
        refuse_empty_values(argv, flags, cls)
        refuse_long_paths(argv, flags, cls)
        refuse_unexpanded_home(argv, flags, cls)
        refuse_bad_json(argv, flags, cls)
        refuse_repeated(argv, flags)
        refuse_huge_numbers(argv, flags, prog)
    except ValueError as err:
        fail(prog, err)
    with _help_unwrapped_in_pipes():
        return tyro.cli(
            cls,
            prog=prog,
            description=description,
            args=argv,
            default=MISSING_NONPROP if default is None else default,
            registry=REGISTRY,
        )


@contextlib.contextmanager
def _help_unwrapped_in_pipes() -> Iterator[None]:
    # tyro lays help out at the terminal's width, 80 columns without one (shutil reads COLUMNS)
    if sys.stdout.isatty() or "COLUMNS" in os.environ:
        yield
        return
    os.environ["COLUMNS"] = PIPED_HELP_COLUMNS
    try:
        yield
    finally:
        del os.environ["COLUMNS"]


def fail(prog: str, message: object) -> NoReturn:
    """``PROG: error: MESSAGE`` on stderr, then exit status 2 (bad input)."""
    print(f"{prog}: error: {message}", file=sys.stderr)
    sys.exit(2)


CLOSED_PIPE_EXIT = 141
"""Exit status after the reader of stdout went away: a shell's status for a command ended by
SIGPIPE (128 + 13), as ``cat`` or ``grep`` would end."""


def quiet_pipe(main: Callable[..., int]) -> Callable[..., int]:
    """``main`` that ends quietly with :data:`CLOSED_PIPE_EXIT` when its output pipe closes
    early (``| head``) instead of printing a traceback. SIGPIPE itself stays ignored, as Python
    sets it: a Ray driver writes to sockets whose peer may go, which must raise, not kill."""

    @functools.wraps(main)
    def wrapped(argv: Sequence[str] | None = None) -> int:
        try:
            return main(argv)
        except BrokenPipeError:
            # the interpreter flushes stdout again at exit: point it at /dev/null so that
            # flush has nowhere to fail
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return CLOSED_PIPE_EXIT

    return wrapped


def names_full_disk(
    prog: str, elsewhere: str | None = None
) -> Callable[[Callable[..., int]], Callable[..., int]]:
    """``main`` that ends a write that did not fit (a full disk or quota, a file size limit) with
    one clear error, ``PROG: error: cannot write FILE: REASON. To go on, FIX``
    (:func:`~simoun_agent.run.atomic.space_problem`), and :data:`NO_SPACE_EXIT`, instead of the
    traceback of the library that wrote it (PIL, numpy). ``elsewhere``: how the command writes
    to another place (``"pass --out DIR on another disk"``), None where it cannot."""

    def decorate(main: Callable[..., int]) -> Callable[..., int]:
        @functools.wraps(main)
        def wrapped(argv: Sequence[str] | None = None) -> int:
            try:
                return main(argv)
            except OSError as err:
                problem = space_problem(err, elsewhere)
                if problem is None:
                    raise
                print(f"{prog}: error: {problem}", file=sys.stderr)
                return NO_SPACE_EXIT

        return wrapped

    return decorate
