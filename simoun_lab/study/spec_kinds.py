"""The kind of value each fixed key of a study spec holds, checked before any value is read.

A value of the wrong kind (``selection = ["auc"]``, ``preset = 3``, ``recipes = [["simoun"]]``)
would otherwise reach code that expects a name, and fail there without saying which key is at
fault. :func:`kind_problem` names the first key whose value is of the wrong kind, what it must
be and an example; config keys (``[base]``, ``[grid]``, per-task tables) are typed by their
config field instead, as ``--set`` reads them.
"""

from __future__ import annotations

import datetime
import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

from simoun_agent.config import PRESETS
from simoun_lab.study.selection import SELECTION_RULES

ANY = "*"
"""In a path of :data:`SPEC_KINDS`, any key of the table above it."""


@dataclass(frozen=True)
class Kind:
    """What a spec key holds: ``ok(value)``, described as ``need``, with an ``example`` line."""

    need: str
    ok: Callable[[Any], bool]
    example: str


def is_text(value: Any) -> bool:
    return isinstance(value, str)


def is_table(value: Any) -> bool:
    return isinstance(value, dict)


def is_texts(value: Any) -> bool:
    return isinstance(value, list) and all(isinstance(item, str) for item in value)


def is_whole(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def is_seeds(value: Any) -> bool:
    """``"1-3"`` or ``[1, 2, 3]``."""
    return isinstance(value, str) or (isinstance(value, list) and all(map(is_whole, value)))


def is_gpus(value: Any) -> bool:
    number = isinstance(value, int | float) and not isinstance(value, bool)
    return number or isinstance(value, str)


RULE_NAMES = " or ".join(SELECTION_RULES)
TABLE = "a table"
RECIPE_NAMES = "an array of recipe names (strings)"
SEEDS = 'seeds as an array of whole numbers or a range string ("1-5")'
PER_TASK = "or a table with one per task"

SPEC_KINDS: dict[tuple[str, ...], Kind] = {
    ("description",): Kind("a string", is_text, 'description = "what the study asks"'),
    ("recipes",): Kind(RECIPE_NAMES, is_texts, 'recipes = ["simoun", "drq"]'),
    ("selection",): Kind(f"one rule name ({RULE_NAMES})", is_text, 'selection = "auc"'),
    ("grid_overrides",): Kind(
        "an array of grid keys (strings)", is_texts, 'grid_overrides = ["agent.n_step"]'
    ),
    ("base",): Kind(TABLE, is_table, '[base] with preset = "cpu" and config keys'),
    ("base", "preset"): Kind(f"one preset name ({', '.join(PRESETS)})", is_text, 'preset = "cpu"'),
    ("grid",): Kind(TABLE, is_table, "[grid] with agent.n_step = [1, 3]"),
    **{
        key: kind
        for phase in ("tuning", "evaluation")
        for key, kind in {
            (phase,): Kind(TABLE, is_table, f"[{phase}] with tasks, seeds and env_steps"),
            (phase, "tasks"): Kind(
                "an array of Gymnasium ids (strings)",
                is_texts,
                'tasks = ["dm_control/cartpole-swingup-v0"]',
            ),
            (phase, "seeds"): Kind(
                f"{SEEDS}, {PER_TASK}",
                lambda value: is_seeds(value) or is_table(value),
                'seeds = "1-5" or seeds = [1, 2, 3]',
            ),
            (phase, "seeds", ANY): Kind(SEEDS, is_seeds, '"dm_control/cheetah-run-v0" = "1-3"'),
            (phase, "env_steps"): Kind(
                f"a whole number of env steps, {PER_TASK}",
                lambda value: is_whole(value) or is_table(value),
                "env_steps = 100_000",
            ),
            (phase, "env_steps", ANY): Kind(
                "a whole number of env steps", is_whole, '"dm_control/cheetah-run-v0" = 100_000'
            ),
        }.items()
    },
    ("tasks",): Kind(TABLE, is_table, '[tasks."dm_control/cheetah-run-v0"]'),
    ("tasks", ANY): Kind(
        "a table of config keys", is_table, '[tasks."dm_control/cheetah-run-v0"] action_repeat = 4'
    ),
    ("resources",): Kind(TABLE, is_table, "[resources] with cpus_per_trial = 1"),
    ("resources", "cpus_per_trial"): Kind("a whole number", is_whole, "cpus_per_trial = 1"),
    ("resources", "max_concurrent_trials"): Kind(
        "a whole number", is_whole, "max_concurrent_trials = 2"
    ),
    ("resources", "gpus_per_trial"): Kind(
        'a number or "auto"', is_gpus, 'gpus_per_trial = 1 or gpus_per_trial = "auto"'
    ),
    ("diagnostics",): Kind(TABLE, is_table, '[diagnostics] with simoun = ["simoun_no_aux"]'),
    ("diagnostics", ANY): Kind(RECIPE_NAMES, is_texts, 'simoun = ["simoun_no_curiosity"]'),
    ("generalization",): Kind(TABLE, is_table, '[generalization] with modes = ["color_hard"]'),
    ("generalization", "modes"): Kind(
        "an array of distraction modes (strings)", is_texts, 'modes = ["color_hard", "video_hard"]'
    ),
    ("generalization", "episodes"): Kind("a whole number", is_whole, "episodes = 10"),
}
"""Each fixed key of a spec, a table before its keys: a key is looked at only when the table
above it is one."""


def kind_name(value: Any) -> str:
    """The TOML kind of ``value``, with the value: ``an array (["auc"])``."""
    shown = json.dumps(value, default=str)
    if isinstance(value, bool):
        return f"a boolean ({shown})"
    for types, name in (
        (str, "a string"),
        (list, "an array"),
        (dict, "a table"),
        (int, "an integer"),
        (float, "a float"),
        ((datetime.date, datetime.time), "a date or time"),
    ):
        if isinstance(value, types):
            return f"{name} ({shown})"
    return shown


def values_at(data: Any, path: tuple[str, ...]) -> Iterator[tuple[tuple[str, ...], Any]]:
    """``(the key's full path, its value)`` for each key of ``data`` that ``path`` matches."""
    if not path:
        yield (), data
        return
    if not isinstance(data, dict):
        return
    head, rest = path[0], path[1:]
    keys = list(data) if head == ANY else [head] if head in data else []
    for key in keys:
        for where, value in values_at(data[key], rest):
            yield (key, *where), value


def kind_problem(data: dict[str, Any]) -> tuple[tuple[str, ...], str] | None:
    """``(where, what is wrong)`` for the first key of the parsed spec ``data`` whose value is
    not of its kind (:data:`SPEC_KINDS`), else None."""
    for path, kind in SPEC_KINDS.items():  # a table before its keys, which it may not hold
        for where, value in values_at(data, path):
            if not kind.ok(value):
                return where, f"give {kind.need}, not {given(value, kind)}; e.g. {kind.example}"
    return None


def given(value: Any, kind: Kind) -> str:
    """What ``value`` is, for a key of ``kind``: the item at fault of an array where an array
    belongs, else the value's own kind."""
    if isinstance(value, list) and kind.ok([]):
        for item in value:
            if not kind.ok([item]):
                return f"an array holding {kind_name(item)}"
    return kind_name(value)
