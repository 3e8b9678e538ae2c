"""Command-line conventions shared by the commands of :mod:`simoun_agent.cli`.

Booleans are switches, ``--video`` / ``--no-video`` (``argparse.BooleanOptionalAction``), and the
older spelling with a value, ``--video false`` or ``--video=false``, still works: :func:`bool_argv`
rewrites it to the switch before parsing. Both tools answer ``--version``.
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Sequence
from importlib.metadata import PackageNotFoundError, version

TRUE_WORDS = ("1", "true", "yes", "on")
FALSE_WORDS = ("0", "false", "no", "off")


def bool_argv(argv: Sequence[str], flags: Iterable[str]) -> list[str]:
    """``argv`` with ``--flag WORD`` / ``--flag=WORD`` (WORD true/false, yes/no, on/off, 1/0)
    rewritten to ``--flag`` / ``--no-flag`` for each boolean ``flags`` entry (``"--video"``).

    Example:
        >>> bool_argv(["--video", "false", "--progress=yes", "run"], ["--video", "--progress"])
        ['--no-video', '--progress', 'run']
    """
    flags = set(flags)
    words = TRUE_WORDS + FALSE_WORDS
    out: list[str] = []
    i = 0
    while i < len(argv):
        name, eq, word = argv[i].partition("=")
        if name in flags and not eq and i + 1 < len(argv) and argv[i + 1].lower() in words:
            word, step = argv[i + 1], 2
        elif name in flags and eq and word.lower() in words:
            step = 1
        else:
            out.append(argv[i])
            i += 1
            continue
        out.append(name if word.lower() in TRUE_WORDS else "--no-" + name[2:])
        i += step
    return out


def add_version(parser: argparse.ArgumentParser) -> None:
    """``--version``: the installed simoun version."""
    try:
        installed = version("simoun")
    except PackageNotFoundError:  # run from a source tree that was never installed
        installed = "unknown (not installed)"
    parser.add_argument("--version", action="version", version=f"%(prog)s {installed}")
