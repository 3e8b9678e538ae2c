"""Argument checks shared by the wrappers."""

from typing import Any

import numpy as np


def is_int(value: Any) -> bool:
    """Whether ``value`` is an integer: a Python or numpy int, not a bool (``True`` is an int
    to Python, but ``size=True`` or ``repeat=True`` is a mistake, not 1)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def check_positive_int(value: Any, name: str, fix: str) -> None:
    """A clear error for a ``value`` of the argument ``name`` that is not a positive int;
    ``fix`` says what to pass instead."""
    if not is_int(value) or value < 1:
        raise ValueError(f"{name} must be a positive int, got {value!r}; {fix}")
