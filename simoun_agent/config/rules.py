"""What a config field accepts (:class:`Rule`), the field that carries it and the check every
config runs.

Each field of ``AgentConfig`` and ``TrainConfig`` is a :func:`setting`: its type, default,
rule and (in the docstring under it) help text in one place. Both call :func:`check_fields`
from ``__post_init__``, then their cross-field checks, so a bad value fails when the config is
built (command line, preset, recipe, Python or a saved ``config.json``), not deep inside torch
later. Errors are ``ValueError``; the command-line tools print them without a traceback.

Example:
    >>> from simoun_agent.config import AgentConfig
    >>> AgentConfig(batch_size=0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: --agent.batch-size 0 (AgentConfig.batch_size) must be an int >= 1 (below 2**63)...
"""

from __future__ import annotations

import dataclasses
import difflib
import json
import math
import numbers
import os
import shlex
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Rule:
    """What one field accepts: ``ok(value)``, described as ``need`` (``"an int >= 1"``)."""

    need: str
    """the accepted values in words, completing "must be ..." """
    ok: Callable[[Any], bool]
    """True for an accepted value"""
    fix: str = ""
    """advice after the error; empty: suggest the field's default"""
    suggest: Callable[[Any], str] | None = None
    """the close match of a refused value, as `` (did you mean 'dual'?)``, or empty"""


def is_int(value: Any) -> bool:
    """An integer that is not a bool."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def is_real(value: Any) -> bool:
    """A finite real number that is not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)


def integer(low: int, optional: bool = False, fix: str = "", odd: bool = False) -> Rule:
    """An int ``>= low`` (odd when ``odd``) that int64 holds, or None when ``optional``: the
    counters are numpy and torch int64s, so a larger one would wrap around."""
    need = f"an {'odd ' if odd else ''}int >= {low} (below 2**63)" + (
        " or none" if optional else ""
    )
    return Rule(
        need,
        lambda v: (
            (optional and v is None) or (is_int(v) and low <= v < 2**63 and (not odd or v % 2))
        ),
        fix,
    )


def real(low: float, high: float | None = None, open_low: bool = False, fix: str = "") -> Rule:
    """A finite number in ``[low, high]`` (``(low, ...`` when ``open_low``)."""
    bounds = f"> {low:g}" if open_low else f">= {low:g}"
    need = f"a number {bounds}" + (f" and <= {high:g}" if high is not None else "")
    return Rule(
        need,
        lambda v: (
            is_real(v) and (v > low if open_low else v >= low) and (high is None or v <= high)
        ),
        fix,
    )


def finite() -> Rule:
    return Rule("a finite number", is_real)


def boolean() -> Rule:
    return Rule("true or false", lambda v: isinstance(v, bool))


def one_of(options: Sequence[str]) -> Rule:
    return Rule(
        "a known name",
        lambda v: v in options,
        f"choose one of {', '.join(options)}",
        lambda v: did_you_mean_name(v, options),
    )


def optional_name(options: Sequence[str]) -> Rule:
    """None or one of ``options``, the names of a registry (the recipes, the presets). Only a
    string is looked up: a list or dict is refused as any wrong name is, where the lookup in a
    dict registry would fail as unhashable."""
    names = list(options)
    return Rule(
        f"none or one of {', '.join(names)}",
        lambda v: v is None or (isinstance(v, str) and v in names),
        suggest=lambda v: did_you_mean_name(v, names),
    )


def fold_name(name: str) -> str:
    """``name`` in lower case with ``-`` for ``_``: two spellings of one name fold alike."""
    return name.lower().replace("_", "-")


def closest_name(typed: Any, options: Sequence[str], cutoff: float = 0.6) -> str | None:
    """The name of ``options`` that ``typed`` most likely meant: first one spelled in other
    letter case or with ``_`` for ``-`` (``'DrQ'``, ``'Highway_CPU'``), else the closest
    spelling (difflib, ``cutoff``); None when none is close."""
    if not isinstance(typed, str) or not typed:
        return None
    folded = {fold_name(name): name for name in options}
    if fold_name(typed) in folded:
        return folded[fold_name(typed)]
    match = difflib.get_close_matches(typed, list(options), n=1, cutoff=cutoff)
    return match[0] if match else None


def did_you_mean_name(typed: Any, options: Sequence[str]) -> str:
    """`` (did you mean 'dual'?)`` for a mistyped name of ``options`` (:func:`closest_name`),
    or empty."""
    close = closest_name(typed, options)
    return f" (did you mean {close!r}?)" if close else ""


def text(optional: bool = False, fix: str = "") -> Rule:
    need = "a non-empty string" + (" or none" if optional else "")
    return Rule(need, lambda v: (optional and v is None) or (isinstance(v, str) and v != ""), fix)


def path(optional: bool = False, fix: str = "") -> Rule:
    """A file system path: a non-empty str or an ``os.PathLike`` (a ``pathlib.Path``, the usual
    form in Python), or None when ``optional``. The config keeps it as a str (JSON)."""
    need = "a path (a non-empty str or os.PathLike such as pathlib.Path)" + (
        " or none" if optional else ""
    )

    def ok(value: Any) -> bool:
        if optional and value is None:
            return True
        text = os.fspath(value) if isinstance(value, os.PathLike) else value
        return isinstance(text, str) and text != ""

    return Rule(need, ok, fix)


def module_name(optional: bool = False, fix: str = "") -> Rule:
    """A module that ``importlib.import_module`` can be given: dotted Python identifiers, no
    leading dot (a relative name needs a package) and no ``:ID`` (that form belongs to
    ``--env``)."""
    need = "an importable absolute module name (dotted identifiers, e.g. minigrid or ale_py)"
    return Rule(
        need + (" or none" if optional else ""),
        lambda v: (
            (optional and v is None)
            or (isinstance(v, str) and all(part.isidentifier() for part in v.split(".")))
        ),
        fix,
    )


def json_object(fix: str = "") -> Rule:
    return Rule("a JSON object (a dict)", lambda v: isinstance(v, dict), fix)


RULE = "rule"
"""The key of a field's :class:`Rule` in its ``dataclasses.field`` metadata."""


def setting(default: Any, rule: Rule) -> Any:
    """A config field: ``default`` and the ``rule`` its values must keep.

    Example:
        >>> @dataclass
        ... class Example:
        ...     size: int = setting(8, integer(1))
        >>> rules_of(Example)["size"].need
        'an int >= 1 (below 2**63)'
    """
    return dataclasses.field(default=default, metadata=with_rule(rule))


def with_rule(rule: Rule) -> dict[str, Rule]:
    """The metadata that gives a ``dataclasses.field`` its rule, for a field whose default a
    factory builds afresh for each config (a dict, a nested config), which :func:`setting`
    does not take: ``field(default_factory=dict, metadata=with_rule(json_object()))``."""
    return {RULE: rule}


def rules_of(config: Any) -> dict[str, Rule]:
    """The rule of every field of a config dataclass (or of one of its instances), by field
    name; TypeError for a field made without one (a programming error), so nothing reaches the
    agent unchecked."""
    fields = dataclasses.fields(config)
    unruled = [f.name for f in fields if RULE not in f.metadata]
    if unruled:
        name = config.__name__ if isinstance(config, type) else type(config).__name__
        raise TypeError(f"{name} fields without a rule: {', '.join(unruled)}")
    return {f.name: f.metadata[RULE] for f in fields}


def flag_name(prefix: str, name: str) -> str:
    """``("agent.", "batch_size")`` -> ``"--agent.batch-size"``, the command-line flag."""
    return "--" + prefix + name.replace("_", "-")


def show(value: Any) -> str:
    """A value as written on the command line: true/false, none, compact JSON for dicts and
    lists, numbers and strings as they are. Error messages, sweep variant names (and so their
    directories) and study settings all write values this way.

    Example:
        >>> show(None), show(True), show({"lanes": 4}), show(("video_hard",)), show(3e-4)
        ('none', 'true', '{"lanes":4}', '["video_hard"]', '0.0003')
    """
    if isinstance(value, bool) or value is None:
        return json.dumps(value).replace("null", "none")
    if isinstance(value, (dict, list, tuple)):
        return json.dumps(value, separators=(",", ":"))
    return str(value)


def check_fields(config: Any, prefix: str) -> None:
    """Raise ValueError for the first field of ``config`` that breaks its rule (a nested config
    checks its own fields); ``prefix`` starts the fields' flags (``"agent."``)."""
    cls = type(config).__name__
    rules = rules_of(config)
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        value = plain_json(value) if isinstance(value, dict) else plain_scalar(value)
        setattr(config, f.name, value)
        if dataclasses.is_dataclass(value):
            continue
        rule = rules[f.name]
        if not rule.ok(value):
            flag = flag_name(prefix, f.name)
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            fix = rule.fix or f"e.g. {flag} {show(default)} (the default)"
            close = rule.suggest(value) if rule.suggest else ""
            given, kind = wrong_kind(value, str(f.type))
            raise ValueError(
                f"{flag} {given} ({cls}.{f.name}) must be {rule.need}{close}{kind}; {fix}"
            )


def plain_scalar(value: Any) -> Any:
    """A numpy scalar or 0-d array as the Python number it holds (what a config means by it,
    and what ``config.json`` can hold); anything else as it is."""
    if type(value).__module__ == "numpy" and getattr(value, "ndim", None) == 0:
        return value.item()
    return value


def plain_json(value: Any) -> Any:
    """``value`` in the types JSON holds, as the same value read from the command line's JSON
    would be: numpy scalars as Python numbers and tuples as lists, inside dicts and lists too
    (``{"max_steps": np.int64(10)}``, ``{"config": {"reward_speed_range": (20, 30)}}`` from
    Python). ``config.json`` can then hold it, and the env gets what the command line gives.

    Example:
        >>> import numpy as np
        >>> plain_json({"max_steps": np.int64(10), "config": {"range": (20, 30)}})
        {'max_steps': 10, 'config': {'range': [20, 30]}}
    """
    if isinstance(value, dict):
        return {key: plain_json(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain_json(item) for item in value]
    return plain_scalar(value)


def wrong_kind(value: Any, annotation: str) -> tuple[str, str]:
    """``value`` as an error message shows it and, for a value of a kind its field never takes
    (a string where a number belongs, an array), ``", not a str"``: ``--seed '3'`` must not
    read as if the number 3 was given."""
    if isinstance(value, str) and "str" not in annotation:
        return repr(value), ", not a str"
    if isinstance(value, (list, tuple, dict, set)) and not any(
        kind in annotation for kind in ("list", "tuple", "dict", "Sequence", "Mapping")
    ):
        return show(value), f", not a {type(value).__name__}"
    if getattr(value, "ndim", 0):
        return show(value), f", not a {type(value).__module__}.{type(value).__name__}"
    if isinstance(value, str):  # quoted when a space or an empty value would not show
        return shlex.quote(value), ""
    return show(value), ""


def fail(config: Any, prefix: str, name: str, problem: str) -> ValueError:
    """A ValueError for a cross-field problem of ``config``'s field ``name``, named as a flag and
    as the field: ``--flag value (Config.name): problem``."""
    value = getattr(config, name)
    shown = shlex.quote(value) if isinstance(value, str) else show(value)
    return ValueError(
        f"{flag_name(prefix, name)} {shown} ({type(config).__name__}.{name}): {problem}"
    )


def knob(config: Any, prefix: str, name: str, value: Any) -> str:
    """A setting to change, for the command line and for Python alike.

    Example:
        >>> from simoun_agent.config import AgentConfig
        >>> knob(AgentConfig(), "agent.", "num_frames", 3)
        '--agent.num-frames 3 (AgentConfig.num_frames=3)'
    """
    return f"{flag_name(prefix, name)} {show(value)} ({type(config).__name__}.{name}={value!r})"
