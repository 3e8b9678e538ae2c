"""Stopping a run cleanly on Ctrl-C (SIGINT) or SIGTERM (schedulers, Ray, ``kill``).

The first signal is a request that the training loop answers at its next clean point: it
finishes the current step (an evaluation is abandoned between two of its steps), writes the
checkpoint atomically and exits with 128 + the signal number, the shell's convention: **130**
after SIGINT, **143** after SIGTERM. It is acknowledged at once with a line on stderr. A second
signal stops at once (SIGINT raises ``KeyboardInterrupt``, SIGTERM kills the process the default
way).

Python can only catch signals whose C-level handler is its own. pygame's SDL installs its own
SIGINT/SIGTERM handlers when it initialises (highway-env renders through it), unless
``SDL_NO_SIGNAL_HANDLERS=1`` (a default that ``simoun_wrappers`` sets); :func:`deferred_stop`
reads the C-level handlers before taking them over and warns when another library held them.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
"""The signals that ask a run to stop at its next clean point."""


def exit_code(signum: int) -> int:
    """The exit status after a stop requested by ``signum``: 128 + the signal number."""
    return 128 + int(signum)


class StopRequest:
    """Set by the first stop signal, or by one of ``sources``; the loop and the evaluations poll
    :meth:`is_set` between steps."""

    def __init__(self) -> None:
        self.signum: int | None = None
        """the signal that asked to stop, None while running"""
        self.sources: list[Callable[[], int | None]] = []
        """asked by :meth:`is_set` while no signal came: a signal number stops as that signal
        would (supervisors that cannot signal the loop's thread, such as a Ray Tune trial)"""

    def is_set(self) -> bool:
        for source in self.sources:
            if self.signum is not None:
                break
            asked = source()
            if asked is not None and self.signum is None:  # a signal may have come meanwhile
                self.signum = asked
        return self.signum is not None


class Stopped(KeyboardInterrupt):
    """A stop signal was answered: raised by the training loop once its checkpoint is written,
    and by :func:`stop_at_once` at once. ``exit_code`` is 130 (SIGINT) or 143 (SIGTERM)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signal.Signals(signum).name)
        self.signum = signum
        self.exit_code = exit_code(signum)


def c_handler(signum: int) -> int | None:
    """Address of the C-level handler of ``signum`` (0: SIG_DFL, 1: SIG_IGN), read with
    ``sigaction``; None where libc cannot be asked (not POSIX)."""
    if sys.platform == "win32":
        return None
    libc = ctypes.CDLL(None, use_errno=True)
    # struct sigaction starts with the handler pointer on Linux and macOS; 512 bytes cover the
    # rest of it (the mask, flags and restorer) on every platform we run on.
    action = ctypes.create_string_buffer(512)
    if libc.sigaction(int(signum), None, action) != 0:
        return None
    return ctypes.c_void_p.from_buffer(action).value or 0


def foreign_handlers(before: dict[int, int | None], python_handler: int | None) -> list[str]:
    """Names of the signals whose C-level handler in ``before`` was neither the default, ignore,
    nor Python's own (``python_handler``, the address Python installs for every signal)."""
    return [
        signal.Signals(signum).name
        for signum, address in before.items()
        if address not in (None, 0, 1, python_handler)
    ]


def acknowledge(signum: int) -> None:
    """Say on stderr, at once, that the signal was heard and what comes next. ``os.write``: the
    handler may interrupt a write to ``sys.stderr`` (a progress bar), which a second buffered
    write would fail with "reentrant call"."""
    name = signal.Signals(signum).name
    again = "Ctrl-C again" if signum == signal.SIGINT else f"a second {name}"
    text = (
        f"{name} received: stopping at the next step with a checkpoint, then exit "
        f"{exit_code(signum)}; {again} stops at once, without one\n"
    )
    os.write(2, (("\n" if os.isatty(2) else "") + text).encode())


@contextmanager
def deferred_stop(request: StopRequest | None = None) -> Iterator[StopRequest]:
    """Turn the first SIGINT or SIGTERM into a :class:`StopRequest` (``request``, or a new one)
    that the loop answers between steps, acknowledged at once on stderr; a second one stops at
    once. Enter it after the environments are built: a library that installed its own C-level
    handlers while they were made (SDL) is replaced and named in a warning. Outside the main
    thread signals cannot be caught: only the request's sources can set it.
    """
    request = StopRequest() if request is None else request

    def handler(signum: int, frame: Any) -> None:
        if request.signum is None:
            request.signum = signum
            acknowledge(signum)
            return
        if signum == signal.SIGTERM:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
        raise KeyboardInterrupt

    with _handling(handler):
        yield request


@contextmanager
def stop_at_once() -> Iterator[None]:
    """Raise :class:`Stopped` as soon as SIGINT or SIGTERM arrives (``simoun-eval``: nothing to
    save halfway). Like :func:`deferred_stop`, it takes the signals back from a library that
    installed its own handlers, so enter it after the environment is built."""

    def handler(signum: int, frame: Any) -> None:
        raise Stopped(signum)

    with _handling(handler):
        yield


@contextmanager
def _handling(handler: Callable[[int, Any], None]) -> Iterator[None]:
    """Install ``handler`` for the stop signals (main thread only), warning when a library held
    them at the C level; restore the previous handlers on exit."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {signum: c_handler(signum) for signum in STOP_SIGNALS}
    previous = {signum: signal.signal(signum, handler) for signum in STOP_SIGNALS}
    taken = foreign_handlers(before, c_handler(signal.SIGINT))
    if taken:
        warnings.warn(
            f"another library had installed its own {' and '.join(taken)} handler (pygame's SDL "
            "does unless SDL_NO_SIGNAL_HANDLERS=1); Python's handler is back in place so the run "
            "stops cleanly. Leave SDL_NO_SIGNAL_HANDLERS=1 (simoun_wrappers' default) set to "
            "keep SDL off them.",
            stacklevel=5,  # the caller of deferred_stop or stop_at_once
        )
    try:
        yield
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old)
