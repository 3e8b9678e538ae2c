"""Atomic file writing: a file is either its old complete self or its new complete self.

Each file is written to a temporary name in the same directory and renamed over the old one
(``os.replace`` is atomic on POSIX and Windows), so a crash or a full disk at any moment leaves
the previous version in place. A process killed while writing (``kill -9``) leaves its temporary
behind, named so that :func:`dead_temporaries` can find it once its writer is gone. A write
that does not fit (:data:`SPACE_ERRNOS`) raises OSError naming the file's final name, which
:func:`space_problem` puts in words.
"""

from __future__ import annotations

import errno
import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path

from simoun_agent.config.errors import SetupError

_TEMPORARY = re.compile(r"^\..+\.(?P<pid>\d+)\.tmp(\.[^.]+)?$")
"""The name :func:`atomic_write` gives its temporary: ``.<stem>.<pid>.tmp<suffix>``."""

SPACE_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)
"""Write errors that mean the data did not fit: a full disk, a full quota, a file size limit."""

NO_SPACE_EXIT = 75
"""Exit status after a write that did not fit: sysexits' EX_TEMPFAIL (free space, then retry)."""

_REASONS = {
    errno.ENOSPC: "the disk is full",
    errno.EDQUOT: "the disk quota is used up",
    errno.EFBIG: "the file is larger than the file size limit allows",
}
_FIXES = {
    errno.ENOSPC: "free space on that disk (df -h {where} shows it)",
    errno.EDQUOT: "free space under your quota (quota -s shows it), or ask for a larger one",
    errno.EFBIG: "raise the limit (ulimit -f unlimited; a login node's limit: ask its "
    "administrator)",
}


def atomic_write(path: Path, write: Callable[[Path], None]) -> None:
    """Call ``write(tmp)`` on a temporary file beside ``path``, then rename it to ``path``;
    SetupError naming ``path`` when a directory stands there, which no rename replaces (the
    commands check their outputs before their work: this names one they did not)."""
    if path.is_dir() and not path.is_symlink():
        raise SetupError(
            f"cannot write {path}: it is a directory, not a file; move it aside (mv {path} "
            f"{path}.aside) and run the command again"
        )
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        write(tmp)
        os.replace(tmp, path)
    except OSError as err:
        if err.errno not in SPACE_ERRNOS:
            raise
        # a library's write (PIL, numpy) names no file: name the one being written
        raise OSError(err.errno, err.strerror, os.fspath(path)) from err
    finally:
        tmp.unlink(missing_ok=True)


def space_problem(err: OSError, elsewhere: str | None = None) -> str | None:
    """What a write error of :data:`SPACE_ERRNOS` means and its fix, in words (None for another
    error): the file being written, the OS's reason, that nothing of it was written under its
    name (:func:`atomic_write`), and the fix; ``elsewhere``: how the command writes to another
    place (``"pass --out DIR on another disk"``), None for a command that cannot."""
    if err.errno not in SPACE_ERRNOS:
        return None
    reason = f"{_REASONS[err.errno]} ({err.strerror})"
    if err.filename is None:
        what, where = "a write failed", "."
    else:
        path = Path(os.fsdecode(err.filename))
        what = f"cannot write {path}"
        where = os.fspath(path.parent)
        reason += f"; {path.name} was not written (an earlier version of it is kept)"
    fix = _FIXES[err.errno].format(where=where)
    if elsewhere:
        fix += f", or {elsewhere}"
    return f"{what}: {reason}. To go on, {fix}, and run the command again"


def dead_temporaries(directory: Path) -> Iterator[Path]:
    """The temporaries of :func:`atomic_write` in ``directory`` whose process is dead (a live
    one may still be writing)."""
    for path in directory.glob(".*.tmp*"):
        match = _TEMPORARY.match(path.name)
        if match and not _alive(int(match["pid"])):
            yield path


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True
