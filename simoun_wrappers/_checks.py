"""Argument checks shared by the wrappers."""

from typing import Any

import numpy as np


def is_int(value: Any) -> bool:
    """Whether ``value`` is an integer: a Python or numpy int, not a bool (``True`` is an int
    to Python, but ``size=True`` or ``repeat=True`` is a mistake, not 1)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def is_real(value: Any) -> bool:
    """Whether ``value`` is a real number: a Python or numpy int or float, not a bool
    (``scale=True`` is a mistake, not 1) and not a string (``scale="0.1"`` is not converted)."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )


def check_reset_seed(seed: Any, owner: str) -> None:
    """A clear error for a ``reset(seed=...)`` that is neither None nor an int >= 0, raised before
    ``owner`` seeds its own random generator with it (numpy's error names no argument)."""
    if seed is not None and not (is_int(seed) and seed >= 0):
        raise ValueError(
            f"{owner}.reset(seed=...) takes None or an int >= 0, got {seed!r}; e.g. "
            f"env.reset(seed=0), or env.reset() to continue the random stream."
        )


def check_positive_int(value: Any, name: str, fix: str) -> None:
    """A clear error for a ``value`` of the argument ``name`` that is not a positive int;
    ``fix`` says what to pass instead."""
    if not is_int(value) or value < 1:
        raise ValueError(f"{name} must be a positive int, got {value!r}; {fix}")


def check_nonnegative_int(value: Any, name: str, fix: str) -> None:
    """A ValueError for a ``value`` of the argument ``name`` that is not an int >= 0 (a count or
    a step: a float, a string or a bool would fail later, far from the call, or count wrong);
    ``fix`` says what to pass instead."""
    if not is_int(value) or value < 0:
        raise ValueError(f"{name} must be an int >= 0, got {value!r}; {fix}")


def check_bool(value: Any, name: str) -> None:
    """A TypeError for a ``value`` of the argument ``name`` that is not a Python or numpy bool:
    a truthy stand-in such as ``"no"`` or ``"false"`` would otherwise switch the option on."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r} ({type(value).__name__}).")


def check_finite_positive(value: Any, name: str, fix: str) -> None:
    """A ValueError for a ``value`` of the argument ``name`` that is not a finite real > 0;
    ``fix`` says what to pass instead."""
    if not (is_real(value) and np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}; {fix}")
