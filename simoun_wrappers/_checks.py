"""Argument checks shared by the wrappers."""

from typing import Any

import numpy as np


def is_int(value: Any) -> bool:
    """Whether ``value`` is an integer: a Python or numpy int, not a bool (``True`` is an int
    to Python, but ``size=True`` or ``repeat=True`` is a mistake, not 1)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))
