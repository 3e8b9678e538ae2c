"""The line of a key in a TOML text, for error messages: ``tomllib`` gives values, no positions.

A key is addressed by its full path, tables included: ``("grid", "agent", "n_step")`` is found
whether the text says ``[grid]`` then ``agent.n_step = [1, 3]``, or ``[grid.agent]`` then
``n_step = ...``. A key inside an inline table (``seeds = {"a" = [1]}``, always one line in TOML
1.0) or an array is found on its parent's line; a table on its header line. Lines inside
multi-line strings are skipped.

Example:
    >>> text = '[grid]\\nagent.n_step = [1, 3]\\n\\n[tasks."dm_control/x-v0"]\\nframe_skip = 8'
    >>> key_line(text, ("grid", "agent", "n_step")), key_line(text, ("tasks", "dm_control/x-v0"))
    (2, 4)
    >>> key_line(text, ("tasks", "dm_control/x-v0", "frame_skip")), key_line(text, ("nope",))
    (5, None)
"""

from __future__ import annotations

import json
import re

_KEY = r"""(?:[A-Za-z0-9_-]+|"(?:[^"\\]|\\.)*"|'[^']*')"""
_DOTTED = rf"{_KEY}(?:\s*\.\s*{_KEY})*"
_HEADER = re.compile(rf"^\s*\[\[?\s*({_DOTTED})\s*\]\]?")
_ASSIGNMENT = re.compile(rf"^\s*({_DOTTED})\s*=")


def key_parts(dotted: str) -> tuple[str, ...]:
    """``'a."b.c".d'`` -> ``("a", "b.c", "d")``: TOML's dotted key, quotes removed."""
    parts = re.findall(_KEY, dotted)
    return tuple(json.loads(p) if p.startswith('"') else p.strip("'") for p in parts)


def key_line(text: str, path: tuple[str, ...]) -> int | None:
    """The 1-based line that defines ``path`` (or holds it, for a key in an inline table or an
    array), None when the text has no such key."""
    table: tuple[str, ...] = ()
    in_string = False
    for number, line in enumerate(text.splitlines(), start=1):
        was_in_string = in_string
        in_string ^= (line.count('"""') + line.count("'''")) % 2 == 1
        if was_in_string:
            continue
        header = _HEADER.match(line)
        if header:
            table = key_parts(header[1])
            if table[: len(path)] == path:
                return number
            continue
        assignment = _ASSIGNMENT.match(line)
        if not assignment:
            continue
        full = table + key_parts(assignment[1])
        if full[: len(path)] == path or path[: len(full)] == full:
            return number
    return None
