"""How a raw intrinsic signal becomes the reward an algorithm sees: one choice for every signal.

A raw signal (Simoun's consistency distance ``d``, RND's prediction error, a constant) has a
scale no learner should depend on, and its sign decides what it teaches: always positive, it
pays an on-policy learner for staying alive (Burda et al. 2018, "Large-Scale Study of
Curiosity-Driven Learning", section "Death is not the end"). The normalisations here:

==============  =========================================================  ========================
name            reward for raw value ``x``                                 source
==============  =========================================================  ========================
``paper``       ``x * r_e_max / r_i_max`` (running maxima of ``|r_e|``     Simoun, Eq. 13
                and ``x``, raised with the batch first): in ``[0, r_e_max]``
``reward_std``  ``x / std(x)``, running std of the raw values              RLeXplore's ``rms``
``return_std``  ``x / std(R)``, running std of the discounted intrinsic    Burda et al. 2019 (RND),
                return ``R <- gamma * R + x`` per sub-env, never reset     ``RewardForwardFilter``
``standardize`` ``(x - mean(x)) / std(x)``: zero mean                      DEIR (Wan et al. 2023)
``none``        ``x``                                                      (the raw signal)
==============  =========================================================  ========================

Each is a class with ``__call__(raw, extrinsic, envs, counted)``: the statistics are raised with
the ``counted`` rows first, then every row is normalized. A statistic that has not spread yet
(a running std of 0, as after a first batch of equal values) gives 0 rather than a division by
zero: documented on each class. Nothing here imports torch.
"""

from __future__ import annotations

import math
import weakref
from abc import ABC, abstractmethod
from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
from gymnasium.wrappers.utils import RunningMeanStd

from simoun_wrappers._checks import is_real
from simoun_wrappers.curiosity import RunningMax

__all__ = [
    "NORMALIZATIONS",
    "Normalization",
    "PaperMaxima",
    "Raw",
    "ReturnStd",
    "RewardStd",
    "Standardize",
    "claim_normalization",
    "make_normalization",
]

TINY_STD = 1e-8
"""a running std at or below this has not spread yet: the normalized reward is 0"""


def running_moments() -> RunningMeanStd:
    """Gymnasium's ``RunningMeanStd`` with no prior pseudo-sample (its default adds one of weight
    1e-4 and variance 1, which outweighs the variance of values that differ by less than 1e-2)."""
    return RunningMeanStd(epsilon=0.0, shape=())


def divide_by_std(values: np.ndarray, moments: RunningMeanStd) -> np.ndarray:
    """``values / std``, or 0 everywhere while the std is at most :data:`TINY_STD`."""
    std = math.sqrt(max(float(moments.var), 0.0))
    if std <= TINY_STD:
        return np.zeros_like(values, dtype=np.float64)
    return values / std


def moments_state(moments: RunningMeanStd) -> dict[str, float]:
    return {"mean": float(moments.mean), "var": float(moments.var), "count": float(moments.count)}


def load_moments(moments: RunningMeanStd, state: dict[str, float]) -> None:
    moments.mean = np.float64(state["mean"])
    moments.var = np.float64(state["var"])
    moments.count = float(state["count"])


class Normalization(ABC):
    """Turns a batch of raw intrinsic values into normalized rewards, keeping running statistics.

    ``__call__(raw, extrinsic, envs, counted)``: ``raw`` ``(B,)`` finite floats, ``extrinsic``
    ``(B,)`` the env's rewards of the same transitions, ``envs`` ``(B,)`` the sub-env index of
    each row (0 for a single env), ``counted`` ``(B,)`` bool: the rows that update the
    statistics (the others, inside a warm-up, are normalized with the statistics as they are).
    """

    name: ClassVar[str]
    """the name a wrapper's ``normalization`` argument takes"""

    @abstractmethod
    def __call__(
        self, raw: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray, counted: np.ndarray
    ) -> np.ndarray:
        """``(B,)`` float64 normalized rewards."""

    @abstractmethod
    def state_dict(self) -> dict[str, Any]:
        """The running statistics."""

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned; a state that does not fit (see
        :meth:`state_problems`) is refused with a ValueError and nothing is loaded."""
        problems = self.state_problems(state)
        if problems:
            raise ValueError(
                f"{type(self).__name__}.load_state_dict cannot load this state: "
                f"{'; '.join(problems)}; pass what state_dict() of a "
                f"{normalization_name(self)!r} normalization returned. Nothing was loaded."
            )
        self.restore(state)

    @abstractmethod
    def restore(self, state: dict[str, Any]) -> None:
        """Load a state :meth:`load_state_dict` has checked."""

    bounds: ClassVar[dict[str, str]] = {}
    """statistics with a sign: key -> ``">= 0"`` or ``"> 0"``"""

    per_env: ClassVar[tuple[str, ...]] = ()
    """statistics that are lists of one value per sub-env (empty before the first step)"""

    def state_problems(self, state: Any) -> list[str]:
        """What keeps ``state`` from being loaded here, empty when it fits: not a dict, the
        statistics of another normalization (named), keys missing or unknown, or a value of the
        wrong type, not finite or of the wrong sign. The keys and types expected are those of
        this normalization's own :meth:`state_dict`."""
        own = self.state_dict()
        if not isinstance(state, Mapping):
            return [f"its normalization statistics are a {type(state).__name__}, not a dict"]
        if set(state) != set(own):
            # an empty dict is the state of 'none', but far more often a state never filled in
            saved = saved_with(state) if state else []
            if saved and normalization_name(self) not in saved:
                return [
                    f"it was saved with normalization {' or '.join(map(repr, saved))}, but this "
                    f"wrapper's is {normalization_name(self)!r}"
                ]
            problems = []
            missing = [key for key in own if key not in state]
            if missing:
                problems.append(f"its normalization statistics lack {', '.join(missing)}")
            unknown = [str(key) for key in state if key not in own]
            if unknown:
                problems.append(
                    f"its normalization statistics hold {', '.join(unknown)}, which "
                    f"{normalization_name(self)!r} has none of"
                )
            return problems
        problems = []
        for key, mine in own.items():
            value = state[key]
            if is_real(mine):
                if not (is_real(value) and math.isfinite(value)):
                    problems.append(f"its {key} is {value!r}, not a finite number")
                elif self.bounds.get(key) == "> 0" and not value > 0:
                    problems.append(f"its {key} is {value!r}, not > 0")
                elif self.bounds.get(key) == ">= 0" and not value >= 0:
                    problems.append(f"its {key} is {value!r}, not >= 0")
            elif isinstance(mine, list):
                if not (
                    isinstance(value, (list, tuple, np.ndarray))
                    and all(is_real(v) and math.isfinite(v) for v in value)
                ):
                    problems.append(f"its {key} is {value!r}, not a list of finite numbers")
            elif not isinstance(value, type(mine)):
                problems.append(
                    f"its {key} is a {type(value).__name__}, not a {type(mine).__name__}"
                )
        return problems

    def sub_env_problems(self, state: dict[str, Any], num_envs: int) -> list[str]:
        """What keeps ``state``, which :meth:`state_problems` passed, from a wrapper of
        ``num_envs`` sub-envs (1 for a single env): a :attr:`per_env` list of another length,
        whose sub-envs would take each other's statistics or start from nothing."""
        return [
            f"its {key} holds {len(state[key])} values, one per sub-env, but this wrapper has "
            f"{num_envs} sub-env{'s' if num_envs != 1 else ''} (num_envs={num_envs}); a state "
            "loads only into a wrapper with as many sub-envs as the one that saved it"
            for key in self.per_env
            if len(state[key]) not in (0, num_envs)
        ]

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


BATCH = ("raw", "extrinsic", "envs", "counted")
"""the arguments of a normalization's call, in order"""


def checked_batch(
    owner: Normalization, raw: Any, extrinsic: Any, envs: Any, counted: Any
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The four arguments of ``owner``'s call as arrays, after checking them: each of shape
    ``(B,)``, ``raw`` finite numbers and ``extrinsic`` numbers, ``envs`` integer sub-env
    indices >= 0 (floats would index nothing) and ``counted`` bool (a mask of 0/1 ints would
    index rows 0 and 1 in its place, and raise the statistics with the wrong rows). TypeError
    or ValueError naming the argument."""
    arrays = [np.asarray(value) for value in (raw, extrinsic, envs, counted)]
    call = f"{type(owner).__name__}()(raw, extrinsic, envs, counted)"
    size = arrays[0].shape[0] if arrays[0].ndim == 1 else None
    for name, array in zip(BATCH, arrays, strict=True):
        if array.ndim != 1 or (size is not None and len(array) != size):
            want = f"({size},) like raw" if size is not None else "(B,), one value per row"
            raise ValueError(f"{call}: {name} must have shape {want}, got shape {array.shape}")
    for name, array in zip(BATCH[:2], arrays[:2], strict=True):
        if not np.issubdtype(array.dtype, np.number) or np.issubdtype(array.dtype, np.bool_):
            raise TypeError(
                f"{call}: {name} must be numbers, got {array.dtype} {array.tolist()!r:.80}"
            )
    if not np.isfinite(arrays[0]).all():
        raise ValueError(f"{call}: raw must be finite, got {arrays[0].tolist()!r:.80}")
    envs_array, counted_array = arrays[2], arrays[3]
    if not np.issubdtype(envs_array.dtype, np.integer) or (envs_array < 0).any():
        raise TypeError(
            f"{call}: envs must be the sub-env index of each row, ints >= 0, got "
            f"{envs_array.dtype} {envs_array.tolist()!r:.80}; e.g. np.array([0, 1]), or "
            "np.zeros(len(raw), int) for a single env"
        )
    if counted_array.dtype != np.bool_:
        raise TypeError(
            f"{call}: counted must be a bool mask of the rows that raise the statistics, got "
            f"{counted_array.dtype} {counted_array.tolist()!r:.80} (an int array would index rows "
            "by number); e.g. np.ones(len(raw), bool), or np.asarray(counted, bool)"
        )
    return arrays[0], arrays[1], envs_array, counted_array


def normalization_name(normalization: Normalization) -> str:
    """The name ``normalization`` is registered under, or its class name for one of the user's."""
    return getattr(normalization, "name", type(normalization).__name__)


def saved_with(state: Mapping) -> list[str]:
    """The registered normalizations whose statistics have exactly the keys of ``state``."""
    return [name for name, cls in NORMALIZATIONS.items() if set(cls().state_dict()) == set(state)]


class PaperMaxima(Normalization):
    """Eq. 13's normalisation: ``x * r_e_max / r_i_max``.

    ``r_e_max`` is the running maximum of ``|r_e|`` and ``r_i_max`` that of the raw value, both
    raised with the counted rows before the batch is normalized (:class:`RunningMax`), so the
    reward lies in ``[0, r_e_max]`` for a non-negative signal. With the wrapper's weight
    ``scale * exp(-decay * t)`` this is Eq. 13 exactly (``consistency_reward``). It is always
    positive: to an on-policy learner, a bonus for staying alive.

    Example:
        >>> import numpy as np
        >>> norm = PaperMaxima(r_e_max_init=1.0, r_i_max_init=1.0)
        >>> norm(np.array([2.0, 1.0]), np.array([0.0, 0.5]), np.zeros(2, int), np.ones(2, bool))
        array([1. , 0.5])
    """

    name = "paper"
    bounds: ClassVar[dict[str, str]] = {"r_e_max": "> 0", "r_i_max": "> 0"}

    def __init__(self, r_e_max_init: float = 1.0, r_i_max_init: float = 1.0) -> None:
        self.initial = {"r_e_max_init": r_e_max_init, "r_i_max_init": r_i_max_init}
        for name, value in (("r_e_max_init", r_e_max_init), ("r_i_max_init", r_i_max_init)):
            if not (is_real(value) and math.isfinite(value) and value > 0):
                raise ValueError(
                    f"{name} must be a finite number > 0 (the initial running maximum that "
                    f"scales the intrinsic reward), got {value!r}; e.g. {name}=1.0 (the default)."
                )
        self.maxima = RunningMax(r_e_max=r_e_max_init, r_i_max=r_i_max_init)

    def __call__(
        self, raw: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray, counted: np.ndarray
    ) -> np.ndarray:
        raw, extrinsic, envs, counted = checked_batch(self, raw, extrinsic, envs, counted)
        self.maxima.update(extrinsic[counted], raw[counted])
        return raw * (self.maxima.r_e_max / self.maxima.r_i_max)

    def state_dict(self) -> dict[str, Any]:
        return self.maxima.state_dict()

    def restore(self, state: dict[str, Any]) -> None:
        self.maxima.load_state_dict(state)

    def __repr__(self) -> str:
        return f"PaperMaxima({', '.join(f'{k}={v!r}' for k, v in self.initial.items())})"


class RewardStd(Normalization):
    """``x / std(x)``: the raw value over the running standard deviation of the raw values
    (RLeXplore's default ``rms`` normalisation, rllte ``BaseReward``). No mean is subtracted, so
    a non-negative signal stays non-negative. While the std is 0 the reward is 0.

    Example:
        >>> import numpy as np
        >>> norm = RewardStd()
        >>> norm(np.array([1.0, 3.0]), np.zeros(2), np.zeros(2, int), np.ones(2, bool))
        array([1., 3.])
    """

    name = "reward_std"
    bounds: ClassVar[dict[str, str]] = {"var": ">= 0", "count": ">= 0"}
    centred: ClassVar[bool] = False
    """subtract the running mean before dividing (:class:`Standardize`)"""

    def __init__(self) -> None:
        self.moments = running_moments()

    def __call__(
        self, raw: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray, counted: np.ndarray
    ) -> np.ndarray:
        raw, extrinsic, envs, counted = checked_batch(self, raw, extrinsic, envs, counted)
        if counted.any():
            self.moments.update(raw[counted])
        centre = float(self.moments.mean) if self.centred else 0.0
        return divide_by_std(raw - centre, self.moments)

    def state_dict(self) -> dict[str, Any]:
        return moments_state(self.moments)

    def restore(self, state: dict[str, Any]) -> None:
        load_moments(self.moments, state)


class ReturnStd(Normalization):
    """``x / std(R)``: the raw value over the running standard deviation of the discounted
    intrinsic return ``R <- gamma * R + x``, one ``R`` per sub-env, never reset at episode ends
    (Burda et al. 2019, "Exploration by Random Network Distillation": the intrinsic return is
    non-episodic; their ``RewardForwardFilter`` with gamma 0.99). No mean is subtracted. Each
    row's ``R`` is advanced in batch order (a sub-env appears once per vector step); the
    counted rows' ``R`` raise the statistics. While the std is 0 the reward is 0.

    Example:
        >>> import numpy as np
        >>> norm = ReturnStd(gamma=0.5)
        >>> _ = norm(np.array([2.0, 4.0]), np.zeros(2), np.array([0, 1]), np.ones(2, bool))
        >>> norm.returns   # R after one step: the raw values
        array([2., 4.])
        >>> norm(np.array([2.0, 0.0]), np.zeros(2), np.array([0, 1]), np.ones(2, bool)).round(3)
        array([2.412, 0.   ])
        >>> norm.returns   # 0.5 * R + x; the std of R over [2, 4, 3, 2] is 0.829
        array([3., 2.])
    """

    name = "return_std"
    bounds: ClassVar[dict[str, str]] = {"var": ">= 0", "count": ">= 0"}
    per_env = ("returns",)

    def __init__(self, gamma: float = 0.99) -> None:
        # the wrappers' number rule: numpy scalars are numbers, a bool is a mistake, NaN is out
        if not (is_real(gamma) and 0 <= gamma < 1):
            raise ValueError(
                f"gamma must be a number in [0, 1) (the intrinsic return's discount), got "
                f"{gamma!r}; RND uses gamma=0.99."
            )
        self.gamma = float(gamma)
        self.returns = np.zeros(0, dtype=np.float64)
        """the discounted intrinsic return of each sub-env so far"""
        self.moments = running_moments()

    def __call__(
        self, raw: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray, counted: np.ndarray
    ) -> np.ndarray:
        raw, extrinsic, envs, counted = checked_batch(self, raw, extrinsic, envs, counted)
        if len(envs) and envs.max() >= len(self.returns):
            grown = np.zeros(int(envs.max()) + 1, dtype=np.float64)
            grown[: len(self.returns)] = self.returns
            self.returns = grown
        batch_returns = np.empty(len(raw), dtype=np.float64)
        for row, (env, value) in enumerate(zip(envs, raw, strict=True)):
            self.returns[env] = self.gamma * self.returns[env] + value
            batch_returns[row] = self.returns[env]
        if counted.any():
            self.moments.update(batch_returns[counted])
        return divide_by_std(raw, self.moments)

    def state_dict(self) -> dict[str, Any]:
        return {**moments_state(self.moments), "returns": self.returns.tolist()}

    def restore(self, state: dict[str, Any]) -> None:
        load_moments(self.moments, state)
        self.returns = np.asarray(state["returns"], dtype=np.float64)

    def __repr__(self) -> str:
        return f"ReturnStd(gamma={self.gamma})"


class Standardize(RewardStd):
    """``(x - mean(x)) / std(x)``: zero-mean standardisation with the running mean and std of the
    raw values (DEIR, Wan et al. 2023, ``int_rew_norm=1``; it uses an exponential moving average
    where this uses the running mean over all values). About half the steps are paid and half
    charged, so a policy gains nothing by prolonging its episode unless what it sees is more
    novel than usual. While the std is 0 the reward is 0.

    Example:
        >>> import numpy as np
        >>> norm = Standardize()
        >>> norm(np.array([1.0, 3.0]), np.zeros(2), np.zeros(2, int), np.ones(2, bool))
        array([-1.,  1.])
    """

    name = "standardize"
    centred = True


class Raw(Normalization):
    """``x``: the raw signal unchanged (a constant bonus, or a signal already on a known scale).

    Example:
        >>> import numpy as np
        >>> Raw()(np.array([0.5]), np.zeros(1), np.zeros(1, int), np.ones(1, bool))
        array([0.5])
    """

    name = "none"

    def __call__(
        self, raw: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray, counted: np.ndarray
    ) -> np.ndarray:
        raw = checked_batch(self, raw, extrinsic, envs, counted)[0]
        return raw.astype(np.float64)

    def state_dict(self) -> dict[str, Any]:
        return {}

    def restore(self, state: dict[str, Any]) -> None:
        return None


NORMALIZATIONS: dict[str, type[Normalization]] = {
    cls.name: cls for cls in (PaperMaxima, RewardStd, ReturnStd, Standardize, Raw)
}
"""normalization name -> class"""


def make_normalization(normalization: str | Normalization, **paper: float | None) -> Normalization:
    """``normalization`` itself when it is a :class:`Normalization`, else the registered class of
    that name, built with its defaults. ``paper``: ``r_e_max_init`` / ``r_i_max_init`` of
    ``"paper"``, None where not given. Given with another name they are refused (it has no
    running maxima), and so they are with an instance, which keeps the values it was built with:
    ``PaperMaxima(r_e_max_init=5.0)`` is how an instance takes them."""
    given = {key: value for key, value in paper.items() if value is not None}
    if isinstance(normalization, Normalization):
        if given:
            raise unused_maxima(given, normalization)
        return normalization
    if not isinstance(normalization, str) or normalization not in NORMALIZATIONS:
        from difflib import get_close_matches

        close = get_close_matches(str(normalization), NORMALIZATIONS, n=1)
        hint = f"did you mean {close[0]!r}? " if close else ""
        raise ValueError(
            f"normalization={normalization!r} is not one of {list(NORMALIZATIONS)}; {hint}"
            "or pass a Normalization instance (e.g. ReturnStd(gamma=0.999))."
        )
    if normalization == PaperMaxima.name:
        return PaperMaxima(**given)
    if given:
        raise unused_maxima(given, normalization)
    return NORMALIZATIONS[normalization]()


_HOLDERS: dict[int, tuple[weakref.ref, weakref.ref]] = {}
"""``id`` of each instance given to a wrapper -> (the instance, that wrapper), both held weakly:
a dropped wrapper frees its instance for another, and a user's class need not be hashable"""


def claim_normalization(normalization: Normalization, holder: object) -> None:
    """Make ``holder`` (a wrapper) the one whose running statistics ``normalization`` keeps; a
    ValueError when another wrapper still holds it. Two wrappers on one instance would mix
    their statistics (a training and an evaluation env raising one running std) without a
    word, and a copy would leave the user's instance unused, so it is refused instead. One
    without statistics (``Raw()``) has nothing to mix and may serve any number of wrappers."""
    if not normalization.state_dict():
        return
    for key in [key for key, (kept, owner) in _HOLDERS.items() if None in (kept(), owner())]:
        del _HOLDERS[key]
    kept, owner = _HOLDERS.get(id(normalization), (None, None))
    other = owner() if kept is not None and kept() is normalization else None
    if other is not None and other is not holder:
        name = normalization_name(normalization)
        by_name = f", or the name normalization={name!r}, which builds one per wrapper" * (
            name in NORMALIZATIONS
        )
        # the built-in classes' reprs are their constructor calls
        made_again = (
            repr(normalization) if name in NORMALIZATIONS else f"{type(normalization).__name__}()"
        )
        raise ValueError(
            f"normalization={normalization!r} already keeps the running statistics of another "
            f"{type(other).__name__}; one instance in two wrappers would mix their statistics. "
            f"Give each wrapper its own: a new instance (normalization={made_again}){by_name}."
        )
    _HOLDERS[id(normalization)] = (weakref.ref(normalization), weakref.ref(holder))


def unused_maxima(given: dict[str, float], normalization: str | Normalization) -> ValueError:
    """The error for initial maxima (``given``) that ``normalization`` would not use: an
    argument must never be dropped without a word."""
    named = ", ".join(f"{key}={value!r}" for key, value in given.items())
    keys = " and ".join(given)
    if isinstance(normalization, PaperMaxima):
        return ValueError(
            f"{named} cannot change normalization={normalization!r}: an instance keeps the "
            f"initial maxima it was built with. Build it with them, normalization="
            f"PaperMaxima({named}), or pass normalization='paper', {named}."
        )
    return ValueError(
        f"{named} is used by normalization='paper' only, and normalization={normalization!r} "
        f"has no running maxima; drop {keys}, or use normalization='paper' (Eq. 13)."
    )
