"""Which code a study ran: the git commit of simoun's checkout, and whether it had uncommitted
changes. A study resumed from other code would mix two versions of the methods under study in
one comparison, so ``simoun-study run --resume`` refuses another commit unless told otherwise.

Example:
    >>> record = code_version()
    >>> sorted(record)
    ['commit', 'dirty', 'version']
"""

from __future__ import annotations

import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

import simoun_agent

CHECKOUT = Path(simoun_agent.__file__).resolve().parent.parent
"""The directory simoun is imported from (a git checkout, unless installed from a wheel)."""


def _git(checkout: Path, *args: str) -> str | None:
    # --no-optional-locks: reading the checkout must not write its index (``git status``
    # refreshes it), which a full disk or the user's own git at the same moment would break
    try:
        done = subprocess.run(
            ["git", "--no-optional-locks", *args],
            cwd=checkout,
            capture_output=True,
            text=True,
            timeout=30,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return done.stdout.strip()


def code_version(checkout: Path = CHECKOUT) -> dict[str, Any]:
    """``{"commit": git rev-parse HEAD of the ``checkout`` (None outside git), "dirty": whether
    ``git status --porcelain`` lists changes (None outside git), "version": the installed
    package's version}``. Only reads the checkout: its index is left as it is."""
    commit = _git(checkout, "rev-parse", "HEAD")
    status = _git(checkout, "status", "--porcelain") if commit else None
    try:
        installed = version("simoun")
    except PackageNotFoundError:
        installed = None
    return {
        "commit": commit,
        "dirty": None if status is None else bool(status),
        "version": installed,
    }


def same_code(recorded: dict[str, Any], current: dict[str, Any]) -> bool:
    """Whether ``current`` is the code ``recorded`` names: the same commit (the same version
    when neither is a git checkout)."""
    if recorded.get("commit") or current.get("commit"):
        return recorded.get("commit") == current.get("commit")
    return recorded.get("version") == current.get("version")
