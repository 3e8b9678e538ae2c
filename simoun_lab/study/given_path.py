"""A path as the user gave it, shown so that what the message names is what was typed: quoted
when it holds blanks or other characters a bare path would hide (``'dmc100k.toml '``), and,
for one that is not there, the note that it is there without its surrounding blanks.

Example:
    >>> shown("docs/studies/dmc100k.toml"), shown("dmc100k.toml ")
    ('docs/studies/dmc100k.toml', "'dmc100k.toml '")
"""

from __future__ import annotations

import shlex
from pathlib import Path


def shown(path: Path | str) -> str:
    """``path`` bare when it is plain, else quoted as a shell would take it back."""
    text = str(path)
    if not text.isprintable():
        return repr(text)
    return shlex.quote(text) if text else "''"


def blanks_note(path: Path | str) -> str:
    """``"; 'x.toml ' has blanks around it, and x.toml is there: ..."`` for a path that does
    not exist while the same path without its surrounding blanks does; else empty."""
    text = str(path)
    stripped = text.strip()
    if stripped == text or not stripped or Path(text).exists() or not Path(stripped).exists():
        return ""
    return (
        f"; {shown(text)} has a blank (a space or tab) at its start or end, and "
        f"{shown(stripped)} is there: give the path without the blank"
    )
