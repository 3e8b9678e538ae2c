"""Files and folders of another user, and commands run as an ordinary user, for the tests of
what a command says of a file it may not read or a folder it may not write.

Root reads and writes through permission bits, so as root a command runs in a child process
that has dropped root's capabilities (file modes then bite as they do for any user), and
"another user's" files are ``nobody``'s. As any other user the files stay the user's own,
with their permission bits taken away (``chmod 000``, ``chmod a-w``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = os.geteuid() == 0
NOBODY = 65534  # the unprivileged user every Linux system has

DROP_CAPABILITIES = """
import ctypes
libc = ctypes.CDLL(None, use_errno=True)
for capability in range(64):
    libc.prctl(24, capability, 0, 0, 0)  # PR_CAPBSET_DROP: nothing started gets them back
class Header(ctypes.Structure):
    _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]
class Sets(ctypes.Structure):
    _fields_ = [(name, ctypes.c_uint32) for name in ("effective", "permitted", "inherited")]
assert libc.capset(ctypes.byref(Header(0x20080522, 0)), (Sets * 2)()) == 0
"""


def unreadable(path: Path) -> None:
    """``path`` (a file, or a folder and all in it) made another user's that the user may not
    read: mode 600 for a file, 700 for a folder (a colleague's private run)."""
    if not ROOT:
        path.chmod(0)
        return
    for each in [path, *(path.rglob("*") if path.is_dir() else ())]:
        os.lchown(each, NOBODY, NOBODY)
    path.chmod(0o700 if path.is_dir() else 0o600)


def unwritable(path: Path) -> None:
    """The folder ``path`` (and all in it) made another user's, readable but not writable."""
    for each in [path, *path.rglob("*")]:
        if ROOT:
            os.lchown(each, NOBODY, NOBODY)
        else:
            each.chmod(each.stat().st_mode & ~0o222)


def restored(path: Path) -> None:
    """``path`` and all in it the user's own and writable again (pytest removes it then)."""
    os.chmod(path, 0o755 if path.is_dir() else 0o644)  # first: its files can then be listed
    for each in [path, *(path.rglob("*") if path.is_dir() else ())]:
        if ROOT:
            os.lchown(each, os.geteuid(), os.getegid())
        os.chmod(each, 0o755 if each.is_dir() else 0o644)


def run_as_user(module: str, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``module``'s ``main`` run with ``args`` as an ordinary user, in a child process."""
    main = f"import sys\nfrom {module} import main\nsys.exit(main(sys.argv[1:]))\n"
    return run_code_as_user(main, *args, cwd=cwd)


def run_code_as_user(code: str, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """The Python ``code`` run as an ordinary user in a child process (``args``: its argv)."""
    return subprocess.run(
        [sys.executable, "-c", (DROP_CAPABILITIES if ROOT else "") + code, *args],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        cwd=cwd,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[1])},
    )
