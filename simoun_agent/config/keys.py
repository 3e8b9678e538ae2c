"""The keys of the configuration: every field by its flat key (``agent.lr``), its type, default
and docstring; typing a command-line value for it; refusing keys no field has, with the close
match (:mod:`simoun_agent.config.key_match`), wherever they come from."""

from __future__ import annotations

import ast
import dataclasses
import functools
import inspect
import itertools
import json
import re
import textwrap
import types
import typing
from typing import Any

from simoun_agent.config.errors import SetupError
from simoun_agent.config.key_match import did_you_mean
from simoun_agent.config.train import TrainConfig

TRUE_WORDS = ("1", "true", "yes", "on")
FALSE_WORDS = ("0", "false", "no", "off")
NONE_WORDS = ("none", "null")
"""How a command line writes true, false and None (any case)."""


def field_docs(cls: type) -> dict[str, str]:
    """The docstring under each field of a dataclass and of the dataclasses it extends
    (cleanrl style), each on one line, read from their source."""
    docs: dict[str, str] = {}
    for owner in reversed(cls.__mro__):
        if dataclasses.is_dataclass(owner):
            docs.update(_own_field_docs(owner))
    return docs


@functools.cache  # parsing the source costs ~1 ms a class, and resolve() reads every class
def _own_field_docs(cls: type) -> dict[str, str]:
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    except (OSError, TypeError):
        return {}
    body = tree.body[0].body
    docs = {}
    for node, following in itertools.pairwise(body):
        if (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and isinstance(following, ast.Expr)
            and isinstance(following.value, ast.Constant)
            and isinstance(following.value.value, str)
        ):
            docs[node.target.id] = " ".join(following.value.value.split())
    return docs


def config_sections(cls: type | None = None) -> dict[str, type]:
    """Nested config sections by key prefix: ``{"": TrainConfig, "agent.": AgentConfig, ...}``.

    A field whose type is a dataclass is a section; a new section is one such field.
    """
    cls = cls or TrainConfig
    sections = {"": cls}
    for name, kind in typing.get_type_hints(cls).items():
        if dataclasses.is_dataclass(kind):
            sections.update(
                {name + "." + sub: inner for sub, inner in config_sections(kind).items()}
            )
    return sections


def config_fields() -> dict[str, tuple[type, Any, str]]:
    """Every overridable key (``"seed"``, ``"agent.lr"``, ...) -> (type, default, doc)."""
    keys = {}
    for prefix, cls in config_sections().items():
        hints = typing.get_type_hints(cls)
        docs = field_docs(cls)
        for f in dataclasses.fields(cls):
            if dataclasses.is_dataclass(hints[f.name]):
                continue
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            keys[prefix + f.name] = (hints[f.name], default, docs.get(f.name, ""))
    return keys


def parse_value(key: str, text: str, kind: Any) -> Any:
    """Convert a command-line string to the field's type, or raise SetupError naming the key."""
    options = typing.get_args(kind) if _is_union(kind) else (kind,)
    if type(None) in options and text.lower() in NONE_WORDS:
        return None
    errors = []
    for option in options:
        if option is type(None):
            continue
        try:
            return _parse_one(text, option)
        except ValueError as error:
            errors.append(str(error))
    if quoted := _kept_quotes(key, text, kind):
        raise SetupError(quoted)
    raise SetupError(f"cannot read {key}={text!r}: {'; '.join(errors)}")


def _kept_quotes(key: str, text: str, kind: Any) -> str:
    """The refusal of a value a script or a doubled quoting left inside its quotes
    (``env_kwargs='{"size": 32}'`` as one word), when the value inside them reads; else empty."""
    stripped = text.strip()
    if len(stripped) < 2 or stripped[0] not in "'\"" or stripped[-1] != stripped[0]:
        return ""
    inner = stripped[1:-1]
    try:
        parse_value(key, inner, kind)
    except SetupError:
        return ""
    return (
        f"cannot read {key}={stripped}: the value still has its outer quotes "
        f"({stripped[0]}...{stripped[0]}), so it is one string; drop them, so that the command "
        f"gets {key}={inner} (in a shell, quote the whole word: --set '{key}={inner}')"
    )


def _is_union(kind: Any) -> bool:
    return typing.get_origin(kind) in (typing.Union, types.UnionType)


def _parse_one(text: str, kind: Any) -> Any:
    origin = typing.get_origin(kind) or kind
    if origin is bool:
        lowered = text.lower()
        if lowered in TRUE_WORDS:
            return True
        if lowered in FALSE_WORDS:
            return False
        raise ValueError("expected true or false")
    if origin in (int, float, str):
        try:
            return origin(text)
        except ValueError:
            raise ValueError(f"expected {origin.__name__}") from None
    words = origin in (list, tuple) and set(typing.get_args(kind)) in ({str}, {str, Ellipsis})
    if words and not text.lstrip().startswith("["):
        # A list of words may be given plainly: --set eval_distraction=video_hard,color_hard
        value = [item.strip() for item in text.split(",") if item.strip()]
        return tuple(value) if origin is tuple else value
    if origin in (dict, list, tuple):
        try:
            value = json_value(text)
        except json.JSONDecodeError as err:
            fixed = json_repaired(text)
            fix = f"; in JSON: {fixed}" if fixed else ""
            raise ValueError(
                f"expected JSON for a {origin.__name__}: {json_mistake(text, err)}{fix}"
            ) from None
        return tuple(value) if origin is tuple else value
    raise ValueError(f"unsupported type {kind}")


def json_value(text: str) -> Any:
    """``json.loads(text)``, but a JSON object that gives a key twice (``{"a": 1, "a": 2}``,
    which json reads as its last value without a word) raises ValueError naming the key."""

    def unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        value: dict[str, Any] = {}
        for key, item in pairs:
            if key in value:
                raise ValueError(f"the key {key!r} is given twice; give each key once")
            value[key] = item
        return value

    return json.loads(text, object_pairs_hook=unique)


TYPOGRAPHIC_QUOTES = {
    **dict.fromkeys("\u201c\u201d\u201e\u201f\u2033\u00ab\u00bb", '"'),
    **dict.fromkeys("\u2018\u2019\u201a\u201b\u2032", "'"),
}
"""Quotes a word processor, a chat or a web page writes for a typed ``"`` or ``'`` (curly
quotes, primes, guillemets), each with the straight quote it stands for."""

PYTHON_LITERAL = re.compile(r"(True|False|None)\b")


def json_mistake(text: str, err: json.JSONDecodeError) -> str:
    """What json found wrong in ``text`` typed as a value (``err``: its error on it), and where,
    with the cause named when it is one of the usual slips: typographic quotes, Python's
    True/False/None, strings in single quotes, a comma after the last item."""
    found = f"{err.msg} at line {err.lineno} column {err.colno}"
    typographic = sorted({char for char in text if char in TYPOGRAPHIC_QUOTES})
    if typographic:
        return (
            f"{found}: it has typographic quotes ({' '.join(typographic)}), as a word processor "
            'or web page writes them; JSON takes straight double quotes (")'
        )
    before, rest = text[: err.pos].rstrip(), text[err.pos :]
    if before.endswith(",") and rest.lstrip()[:1] in ("}", "]"):
        return f"{found}: a comma after the last item, which JSON does not allow; remove it"
    if literal := PYTHON_LITERAL.match(rest):
        return (
            f"{found}: {literal.group(1)} is Python's spelling; JSON writes true, false and null "
            "in lower case"
        )
    if rest.startswith("'"):
        return (
            f"{found}: JSON strings take double quotes, not single ones; in a shell, put the whole "
            "object in single quotes and its strings in double quotes"
        )
    return found


def json_repaired(text: str) -> str | None:
    """``text`` as the JSON its author meant, when it is JSON but for the slips
    :func:`json_mistake` names (typographic quotes, a Python dict or list literal); else
    None."""
    straight = text.translate(str.maketrans(TYPOGRAPHIC_QUOTES))
    for read in (json.loads, ast.literal_eval):
        try:
            value = read(straight)
            return json.dumps(value, ensure_ascii=False) if isinstance(value, dict | list) else None
        except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
            continue
    return None


HELP_FIX = "`simoun-train --help` lists every key"


def close_match(key: str) -> str:
    """``" (did you mean agent.lr?)"`` for an unknown ``key``, or an empty string when no config
    key is close (:func:`simoun_agent.config.key_match.did_you_mean` over every field); a section
    (``agent``) is answered with one of its fields."""
    fields = [known for known in config_fields() if known.startswith(key + ".")]
    if fields:
        return f" ({key} is a section: set one of its fields, e.g. {fields[0]})"
    return did_you_mean(key, {known: doc for known, (_, _, doc) in config_fields().items()})


def check_keys(keys: Any, source: str = "", fix: str = HELP_FIX) -> None:
    """Raise SetupError naming every key of ``keys`` that no config field has, each with its
    close matches (:func:`close_match`); ``source`` says where the keys came from (none: the
    user) and ``fix`` how to correct them. The user's overrides, presets, recipes and saved
    configs all pass here."""
    known = config_fields()
    unknown = [key for key in keys if key not in known]
    if unknown:
        named = ", ".join(key + close_match(key) for key in unknown)
        where = f"{source}: " if source else ""
        raise SetupError(f"{where}unknown config key {named}; {fix}")
