"""Reading a run's kept files, with the damage a disk, a copy or an editor leaves named.

``simoun-train --resume``, ``simoun-eval``, ``simoun-analyze`` and ``simoun-report`` read the
files a run keeps (``config.json``, ``eval.csv``, ``train.csv``, ``summary.json``,
``checkpoint.pt``); each names a damaged one by its path, what is wrong and the fix, rather than
failing inside a parser or taking the damage for data. :class:`Damaged` carries what is wrong;
each caller adds the fix that fits its command.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

STEP_LIMIT = 2**63
"""Steps at or past it are damage: counters, TensorBoard and numpy hold steps as int64."""

_UTF16_MARKS = (b"\xff\xfe", b"\xfe\xff")


class Damaged(ValueError):
    """A kept file that cannot be what the run wrote; ``str()`` says what is wrong with it."""


def broken_link(path: Path) -> str | None:
    """What is wrong with ``path`` when it is a symbolic link to nothing, else None (an existing
    file's ``exists()`` is True, a missing one's is False: a link to nothing looks missing)."""
    if path.is_symlink() and not path.exists():
        return f"it is a symbolic link to {os.readlink(path)}, which does not exist"
    return None


_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
)


def not_a_file(path: Path) -> str | None:
    """What is wrong with ``path`` when it is there but is not a regular file, else None: a
    read of a named pipe waits for a writer forever, and a device can give bytes without end."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return None  # missing or unreadable: the read that follows names it
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "something else")
    return f"it is {kind}, not a regular file"


def read_text(path: Path) -> str:
    """The UTF-8 text of ``path`` (a leading byte order mark dropped, as a spreadsheet writes
    it); :class:`Damaged` for a link to nothing, something that is not a regular file (checked
    before it is opened), text in another encoding or NUL bytes, which no run writes. OSError
    for a file that cannot be read."""
    problem = broken_link(path) or not_a_file(path)
    if problem:
        raise Damaged(problem)
    data = path.read_bytes()
    if data.startswith(_UTF16_MARKS):
        raise Damaged("it is saved as UTF-16 text, not UTF-8")
    if b"\0" in data:
        line = data[: data.index(b"\0")].count(b"\n") + 1
        raise Damaged(f"line {line} holds a NUL byte (zero bytes from a disk or copy failure)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        raise Damaged(f"line {line} is not UTF-8 text (byte {data[err.start]:#04x})") from None


def binary_problem(path: Path) -> str:
    """What is visibly wrong with a binary file that its reader refused: empty, or all zero
    bytes (a disk that lost the data, a copy cut off); else that it cannot be read."""
    try:
        size = path.stat().st_size
        if size == 0:
            return "it is empty"
        with path.open("rb") as f:
            while chunk := f.read(1 << 20):
                if chunk.count(0) != len(chunk):
                    return f"it cannot be read ({size} bytes, cut short or overwritten)"
    except OSError as err:
        return f"it cannot be read ({err.strerror})"
    return f"all its {size} bytes are zero (a disk or copy failure)"
