"""Atomic file writing: a file is either its old complete self or its new complete self.

Each file is written to a temporary name in the same directory and renamed over the old one
(``os.replace`` is atomic on POSIX and Windows), so a crash or a full disk at any moment leaves
the previous version in place. A process killed while writing (``kill -9``) leaves its temporary
behind, named so that :func:`dead_temporaries` can find it once its writer is gone.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterator
from pathlib import Path

from simoun_agent.config.errors import SetupError

_TEMPORARY = re.compile(r"^\..+\.(?P<pid>\d+)\.tmp(\.[^.]+)?$")
"""The name :func:`atomic_write` gives its temporary: ``.<stem>.<pid>.tmp<suffix>``."""


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
    finally:
        tmp.unlink(missing_ok=True)


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
