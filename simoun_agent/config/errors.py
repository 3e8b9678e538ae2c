"""The error a user can fix, shared by the configuration and every command-line tool."""

from __future__ import annotations


class SetupError(ValueError):
    """A bad input the user can fix (unknown env or key, foreign checkpoint, ...).

    The command-line tools print its message, which names the problem and the fix, without a
    traceback.
    """
