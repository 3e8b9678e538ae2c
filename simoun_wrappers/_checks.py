"""Argument checks shared by the wrappers."""

import functools
import inspect
import os
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.error import ClosedEnvironmentError, ResetNeeded


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


def check_reset_seed(seed: Any, owner: str) -> int | None:
    """``seed`` of ``owner.reset(seed=...)`` as a Python int, or None; a ValueError for anything
    else, raised before ``owner`` or the env it wraps seeds a random generator with it (numpy's
    and Gymnasium's errors name no argument, and Gymnasium takes ``True`` for 1). A numpy int is
    taken as the int it holds: Gymnasium's own seeding refuses it."""
    if seed is None:
        return None
    if not (is_int(seed) and seed >= 0):
        raise ValueError(
            f"{owner}.reset(seed=...) takes None or an int >= 0, got {seed!r}; e.g. "
            f"env.reset(seed=0), or env.reset() to continue the random stream."
        )
    return int(seed)


def keyword_reset(reset: Callable) -> Callable:
    """``reset`` refusing positional arguments with a TypeError that names the wrapper the user
    made and ``seed``: Python's own names the class that defines ``reset`` (a base class the
    user never made). Its signature stays Gymnasium's, keyword-only ``seed`` and ``options``
    (``inspect.signature`` reads it through ``__wrapped__``)."""

    @functools.wraps(reset)
    def checked(self: Any, *args: Any, **kwargs: Any) -> Any:
        if args:
            raise TypeError(
                f"{type(self).__name__}.reset() takes 1 positional argument but "
                f"{len(args) + 1} were given: seed and options are keyword-only, as in every "
                f"Gymnasium env; e.g. env.reset(seed={args[0]!r:.20})"
            )
        return reset(self, **kwargs)

    return checked


def refuse_step_before_reset(has_reset: bool, owner: str) -> None:
    """A ResetNeeded when ``owner`` steps before its first ``reset()``. For wrappers whose
    constructor resets the env to read its first image: that reset satisfies Gymnasium's
    OrderEnforcing under them, so without this a step would run on an episode the user never
    started or seeded."""
    if not has_reset:
        raise ResetNeeded(
            f"Cannot call {owner}.step() before reset(); call env.reset(seed=...) first to start "
            f"a seeded episode."
        )


class ClosedEnvError(ClosedEnvironmentError, ValueError):
    """A reset or step after ``close()``: Gymnasium's ClosedEnvironmentError, and a ValueError
    as Python's closed files give (and as a closed dm_control task is refused)."""


def refuse_after_close(closed: bool, owner: str, call: str) -> None:
    """A :class:`ClosedEnvError` when ``owner`` was closed and is asked to ``call`` (reset or
    step): under it a closed env fails inside its renderer (pygame, MuJoCo) with an error that
    names nothing, or steps on as if it were open."""
    if closed:
        raise ClosedEnvError(
            f"Cannot call {owner}.{call}() after close(): close() released the env and its "
            f"renderer. Make the env anew and wrap it again, and call close() only when done."
        )


def check_vector_reset_seed(seed: Any, owner: str, num_envs: int) -> int | list[int | None] | None:
    """``seed`` of a vector env's ``owner.reset(seed=...)``: None, an int (sub-env ``i`` gets
    ``seed + i``) or one int or None per sub-env, as Python values; a ValueError naming the
    sub-envs for anything else."""
    if not isinstance(seed, (list, tuple)):
        return check_reset_seed(seed, owner)
    if len(seed) != num_envs:
        raise ValueError(
            f"{owner}.reset(seed=[...]) takes one seed per sub-env, {num_envs} here, got "
            f"{len(seed)}: {list(seed)!r}; e.g. envs.reset(seed=0) (sub-env i gets seed 0 + i)."
        )
    return [check_reset_seed(one, owner) for one in seed]


def plain(value: Any) -> Any:
    """``value`` with numpy scalars and arrays made Python values (recursively through lists,
    tuples and dicts): what a wrapper records of its constructor arguments for ``env.spec``,
    whose ``to_json()`` takes only plain values."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if type(value) in (list, tuple):  # not a named tuple, whose fields are its arguments
        return type(value)(plain(item) for item in value)
    if type(value) is dict:
        return {key: plain(item) for key, item in value.items()}
    return value


def _box_problem(action: Any, space: spaces.Box) -> str | None:
    """Why ``action`` is not an action of ``space``, or None when it is. As ``Box.contains``,
    with two exceptions the envs themselves make: a float array is taken for a Box of another
    float type (``np.array([0.5])`` for Pendulum's float32 Box), and a value out of the bounds
    is left to the env, which clips it (Pendulum, MuJoCo; ``gymnasium.wrappers.ClipAction`` for
    the others). NaN is refused: no env can clip it, and it would silently spoil the state."""
    try:
        array = np.asarray(action)
    except (TypeError, ValueError):
        return f"{type(action).__name__}, not an array"
    if array.dtype.kind not in "biuf":
        return f"{type(action).__name__} of dtype {array.dtype}, not real numbers"
    if not np.can_cast(array.dtype, space.dtype, casting="same_kind"):
        return f"of dtype {array.dtype}, which does not cast to {space.dtype}"
    if array.shape != space.shape:
        return f"of shape {array.shape}, not {space.shape}"
    if np.isnan(array).any():
        return "it holds NaN"
    return None


def _valid_actions(space: spaces.Space, vector: int | None) -> str:
    """What the actions of ``space`` are, with an example; ``vector`` is the number of sub-envs
    of a vector env's batched space, else None."""
    each = f", one per sub-env ({vector} sub-envs)" if vector else ""
    if isinstance(space, spaces.Discrete):
        last = int(space.start) + int(space.n) - 1
        return f"an int in {int(space.start)}..{last}, e.g. {int(space.start)}"
    if isinstance(space, spaces.MultiDiscrete):
        low, high = space.start, space.start + space.nvec - 1
        if np.all(low == low.flat[0]) and np.all(high == high.flat[0]):
            low, high = low.flat[0], high.flat[0]
        return (
            f"an int array of shape {space.shape} with values in {low.tolist()}..{high.tolist()}"
            f"{each}, e.g. np.array({space.start.tolist()})"
        )
    if isinstance(space, spaces.Box):
        low, high = np.min(space.low), np.max(space.high)
        example = np.zeros(space.shape).clip(space.low, space.high).tolist()
        return (
            f"an array of shape {space.shape} ({space.dtype}) with values in [{low}, {high}]"
            f"{each}, e.g. np.array({example}, np.{space.dtype})"
        )
    return f"a value of {space}{each}, e.g. env.action_space.sample()"


def _problem(action: Any, space: spaces.Space) -> str | None:
    """Why ``action`` is not in ``space`` (None when it is): ``space.contains`` for every
    space, with Box's float types taken as :func:`_box_problem` says, also inside Tuple and
    Dict spaces."""
    if isinstance(space, spaces.Box):
        return _box_problem(action, space)
    if isinstance(space, spaces.Tuple):
        if not isinstance(action, Sequence) or len(action) != len(space.spaces):
            return f"not a tuple of {len(space.spaces)} actions"
        return next(filter(None, map(_problem, action, space.spaces)), None)
    if isinstance(space, spaces.Dict):
        if not isinstance(action, Mapping) or set(action) != set(space.spaces):
            return f"not a dict with the keys {list(space.spaces)}"
        return next(filter(None, (_problem(action[k], s) for k, s in space.spaces.items())), None)
    if space.contains(action):
        return None
    if isinstance(space, (spaces.Discrete, spaces.MultiDiscrete)):
        array = np.asarray(action)
        if not np.issubdtype(array.dtype, np.integer):
            return f"{type(action).__name__} of dtype {array.dtype}, not ints"
        if array.shape != space.shape:
            return f"of shape {array.shape}, not {space.shape}"
        return "out of its range"
    return "not one of its values"


def check_action(action: Any, space: spaces.Space, owner: str, vector: int | None = None) -> None:
    """A ValueError unless ``action`` is in ``space``, the action space ``owner`` exposes (the
    batched one for a vector env of ``vector`` sub-envs), raised before the env gets it: an
    env's own error names neither the space nor what is valid, and some envs take a wrong
    action silently.

    Gymnasium's ``space.contains`` decides, so a 0-d value is no action of a ``Box`` of shape
    ``(1,)`` (pass ``np.array([a])``) and a float no action of a ``Discrete``; a ``Box`` takes
    a float array of another float type and leaves its bounds to the env (see
    :func:`_box_problem`).
    """
    problem = _problem(action, space)
    if problem is not None:
        raise ValueError(
            f"{owner}.step got the action {action!r:.80}, which is not in its action space "
            f"{space}: {problem}. Pass {_valid_actions(space, vector)}."
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


def check_callable(value: Any, name: str, call: str, args: tuple, fix: str) -> None:
    """A TypeError for a ``value`` of the argument ``name`` that is not callable, or whose
    signature cannot take ``args`` (how it will be called, written as ``call``): without this
    it fails at its first call, far from where it was given, with Python's message naming
    neither the argument nor the call. A signature that cannot be read (some builtins) is
    taken as it is; ``fix`` says what to pass instead."""
    if not callable(value):
        raise TypeError(
            f"{name} must be a callable, called as {call}, got {type(value).__name__} "
            f"{value!r:.60}; {fix}"
        )
    problem = _bind_problem(value, args)
    if problem is not None:
        raise TypeError(
            f"{name} is called as {call}, which its signature {problem[0]} does not take "
            f"({problem[1]}); {fix}"
        )


def _bind_problem(func: Callable, args: tuple) -> tuple[str, str] | None:
    """(the signature, why) when ``func(*args)`` does not match ``func``'s signature; None
    when it does, or when the signature cannot be read."""
    try:
        signature = inspect.signature(func)
    except (TypeError, ValueError):
        return None
    try:
        signature.bind(*args)
    except TypeError as err:
        return str(signature), str(err)
    return None


def unexpanded_home(path: Any) -> str | None:
    """The fix for a ``path`` that starts with a ``~`` nobody expanded and names nothing as
    written (Python, unlike a shell, reads ``'~/runs'`` as a folder called ``~``): the
    sentence to add to the error; None for any other path."""
    if not isinstance(path, (str, os.PathLike)):
        return None
    text = os.fspath(path)
    if not isinstance(text, str) or not (text == "~" or text.startswith(("~/", "~" + os.sep))):
        return None
    if os.path.exists(text):
        return None
    return (
        f"Python does not expand ~ in a path (only a shell does), so {text!r} names a folder "
        f"called ~ here; pass os.path.expanduser({text!r}), which is {os.path.expanduser(text)!r}"
    )


def check_path(value: Any, name: str, example: str, what: str = "a path") -> None:
    """The one check of a path argument of the Python API: a TypeError for a ``value`` of the
    argument ``name`` that is no path (a str or os.PathLike), and a ValueError for one that
    starts with an unexpanded ``~`` (:func:`unexpanded_home`); ``example`` is a call that
    works, ``what`` what the path names. (The command lines refuse such a path as they read
    their flags, with the flag's name.)"""
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(
            f"{name} must be {what}, as a str or os.PathLike, got {type(value).__name__} "
            f"{value!r:.60}; e.g. {example}"
        )
    home = unexpanded_home(value)
    if home is not None:  # the call as written: load_run(path='~/runs'), not path=...)='~/runs'
        given = repr(os.fspath(value))
        call = name.replace("...", given) if "..." in name else f"{name}={given}"
        raise ValueError(f"{call}: {home}")
