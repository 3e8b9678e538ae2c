"""One reward-wrapper mechanism for intrinsic rewards, for a single env and a vector env.

``reward = r_e + scale * exp(-decay * t) * normalize(x)``, ``x`` from an
:class:`IntrinsicSignal`: Simoun's consistency distance (``simoun_wrappers.curiosity_reward``),
random network distillation's error (``simoun_wrappers.rnd``) and a constant bonus
(:class:`ConstantSignal`) are one signal class each over the same two wrappers
(:class:`IntrinsicReward`, :class:`IntrinsicVectorReward`), and every signal with a spread takes
every normalization of ``simoun_wrappers.intrinsic_normalization`` (the constant bonus takes
none: a constant has no spread to divide by). The wrappers handle the rest:
reading the Simoun frame triplets, skipping the autoreset steps of a vector env, handing each
transition to a source that learns online, ``info``, state and ``close``.
"""

from __future__ import annotations

import inspect
import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from typing import Any, ClassVar, NamedTuple, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv, VectorWrapper

from simoun_wrappers._checks import (
    check_action,
    check_callable,
    check_reset_seed,
    check_vector_reset_seed,
    is_int,
    is_real,
    keyword_reset,
    plain,
    refuse_after_close,
)
from simoun_wrappers._spec import CheckedSpecWrapper, CheckedVectorSpecWrapper, SharedSource
from simoun_wrappers.frames import check_single_env
from simoun_wrappers.intrinsic_normalization import (
    Normalization,
    Raw,
    claim_normalization,
    make_normalization,
    normalization_name,
)

__all__ = [
    "ConstantBonusReward",
    "ConstantBonusVectorReward",
    "ConstantSignal",
    "IntrinsicMechanism",
    "IntrinsicReward",
    "IntrinsicSignal",
    "IntrinsicVectorReward",
    "SharedSource",
    "triplet_reader",
    "triplet_shape",
]


def triplet_shape(space: spaces.Space) -> tuple[int, int, int, int]:
    """``(3, C, H, W)``: the frame triplet held by one observation of ``space``.

    Accepted layouts: a ``Dict`` with a ``"frames"`` Box ``(3, C, H, W)`` (``SimounObservation``),
    a Box ``(3, C, H, W)`` (``FrameTriplet`` on channel-first frames), or the folded Box
    ``(3C, H, W)`` (``SimounObservation(fold_frames=True)``, for SB3).
    """
    frames = (
        space["frames"] if isinstance(space, spaces.Dict) and "frames" in space.spaces else space
    )
    shape = getattr(frames, "shape", None)
    if not isinstance(frames, spaces.Box) or frames.dtype != np.uint8 or shape is None:
        raise TypeError(
            f"The intrinsic-reward wrappers need Simoun frame triplets as uint8, got {space}. Wrap "
            "the env in SimounObservation(env) (or SimounObservation(env, fold_frames=True) for "
            "SB3)."
        )
    if len(shape) == 4 and shape[0] == 3:
        return shape
    if len(shape) == 3 and shape[0] % 3 == 0:
        return (3, shape[0] // 3, *shape[1:])
    raise ValueError(
        f"The intrinsic-reward wrappers need a triplet of frames t-2, t-1, t: a (3, C, H, W) or "
        f"folded (3C, H, W) uint8 observation; got shape {shape}. Use SimounObservation(env, "
        "num_frames=3)."
    )


class TripletReader:
    """Takes a batch of observations of ``space`` to ``uint8 (B, 3, C, H, W)``; a class, not a
    closure, so that the wrappers holding one pickle."""

    def __init__(self, space: spaces.Space) -> None:
        self.shape = triplet_shape(space)
        self.use_key = isinstance(space, spaces.Dict)

    def __call__(self, batch: Any) -> np.ndarray:
        # A copy: the wrappers keep the previous triplet, and the caller owns the observation.
        array = np.array(batch["frames"] if self.use_key else batch, dtype=np.uint8)
        return array.reshape(-1, *self.shape)


def triplet_reader(space: spaces.Space) -> Callable[[Any], np.ndarray]:
    """A function taking a batch of observations of ``space`` to ``uint8 (B, 3, C, H, W)``."""
    return TripletReader(space)


def _observation_space(env: gym.Env | VectorEnv) -> spaces.Space:
    return env.single_observation_space if isinstance(env, VectorEnv) else env.observation_space


def env_triplet_reader(env: gym.Env | VectorEnv, owner: str) -> TripletReader:
    """The :class:`TripletReader` of ``env``'s (for a vector env, each sub-env's) observations.
    When they are no triplets but wrappers over an env of triplets changed them (Gymnasium's
    ``NormalizeObservation``, ``FlattenObservation``), the TypeError names those wrappers and
    the order that works: ``owner`` reads the triplets, the wrappers go outside it."""
    try:
        return TripletReader(_observation_space(env))
    except (TypeError, ValueError):
        over: list[str] = []
        inner = env
        while isinstance(inner, (gym.Wrapper, VectorWrapper)):
            over.append(type(inner).__name__)
            inner = inner.env
            try:
                triplet_shape(_observation_space(inner))
            except (TypeError, ValueError):
                continue
            outside = ", ".join(over)
            raise TypeError(
                f"{owner} reads Simoun frame triplets, but {outside} over "
                f"{type(inner).__name__} changed them to {_observation_space(env)}. Put "
                f"{outside} outside {owner}: e.g. {over[0]}({owner}({type(inner).__name__}(env, "
                f"...), ...)) gives the reward the triplets and the learner the changed "
                "observations."
            ) from None
        raise


LARGEST = np.finfo(np.float64).max


def finite_sum(extrinsic: np.ndarray, intrinsic: np.ndarray) -> np.ndarray:
    """``extrinsic + intrinsic``, at most the largest float in size: finite rewards whose sum
    overflows give that float, not an inf that a learner would take for a broken env."""
    with np.errstate(over="ignore"):
        total = np.add(extrinsic, intrinsic, dtype=np.float64)
    return np.clip(total, -LARGEST, LARGEST)


class SourceProtocol(NamedTuple):
    """The protocol a signal's source must follow, and how a refusal explains it."""

    argument: str
    """the wrappers' argument that takes the source"""
    protocol: type
    """a ``runtime_checkable`` Protocol"""
    expects: str
    """what the protocol's call takes and returns"""
    example: str
    """a source that follows it"""


class IntrinsicSignal(ABC):
    """A raw intrinsic value for each frame triplet reached: novelty, disagreement, a bonus.

    :meth:`raw` returns one finite float per triplet; the wrappers normalize it (one
    :class:`~simoun_wrappers.intrinsic_normalization.Normalization` for every signal) and weight
    it. ``source`` is the model behind the signal (None for a signal that needs none); when it
    has ``watch(triplets, actions, next_triplets, terminated, truncated)`` it is handed every
    scored transition (to learn online), and its ``close()`` is called by the wrappers'
    ``close()``. A new signal is one subclass implementing :meth:`raw`; one that needs a source
    names the protocol the source must follow in :attr:`source_protocol`.
    """

    source_protocol: ClassVar[SourceProtocol | None] = None
    """what the source must be, checked when the signal is built; None: anything"""

    def __init__(self, source: Any = None) -> None:
        self.source = SharedSource.unwrap(source)
        wanted = self.source_protocol
        if wanted is not None and isinstance(self.source, type):
            raise TypeError(class_for_instance(self.source, wanted))
        if wanted is not None and not isinstance(self.source, wanted.protocol):
            raise TypeError(
                f"{wanted.argument} must be a {wanted.protocol.__name__} ({wanted.expects}), got "
                f"{type(self.source).__name__}. Use e.g. {wanted.example}."
            )
        if wanted is not None:
            check_callable(
                self.source,
                wanted.argument,
                f"{wanted.argument}(triplets)",
                (None,),
                f"it must take one argument ({wanted.expects}), e.g. {wanted.example}.",
            )

    @abstractmethod
    def raw(self, triplets: np.ndarray) -> np.ndarray:
        """``(B,)`` float64 raw values of the triplets ``uint8 (B, 3, C, H, W)``."""

    def call_source(self, triplets: np.ndarray) -> Any:
        """The source's answer for ``triplets``; an error raised inside the source (say a torch
        module given the numpy triplets) is raised again naming the source and what it was
        given, since the error alone names neither. The project's own models (CuriosityModel,
        RNDModel) name themselves and their fix: their errors pass unchanged."""
        try:
            return self.source(triplets)
        except Exception as err:
            if is_own(self.source):
                raise
            raise source_failure(err, self.source, self.source_protocol, triplets) from err

    def watch(self, *transitions: np.ndarray) -> None:
        """Hand a batch of ``transitions`` (``triplets, actions, next_triplets, terminated,
        truncated``, the source's ``watch`` arguments) to the source when it learns online."""
        watch = getattr(self.source, "watch", None)
        if watch is not None and len(transitions[0]):
            watch(*transitions)

    def close(self) -> None:
        """Close the source when it has a ``close`` (a model's update thread)."""
        close = getattr(self.source, "close", None)
        if close is not None:
            close()


def is_own(source: Any) -> bool:
    """Whether ``source`` is an instance of a class of simoun's packages."""
    return type(source).__module__.partition(".")[0] in ("simoun_agent", "simoun_wrappers")


def class_for_instance(source: type, wanted: SourceProtocol) -> str:
    """Why a source given as a class is refused (a class is callable with one argument, so the
    protocol alone would take it and fail at the first step): build it, with ``for_env`` when
    the class has one."""
    name = source.__name__
    build = (
        f"{wanted.argument}={name}.for_env(env), which sizes the model for the env's frames"
        if callable(getattr(source, "for_env", None))
        else f"an instance, {wanted.argument}={name}(...)"
    )
    return (
        f"{wanted.argument} must be a {wanted.protocol.__name__} instance ({wanted.expects}), got "
        f"the class {name} itself; pass {build}."
    )


def source_failure(
    err: Exception, source: Any, wanted: SourceProtocol | None, triplets: np.ndarray
) -> Exception:
    """``err``, raised inside ``source`` on ``triplets``, as an error of the same kind that
    names the source, what it was given (numpy uint8 triplets, not torch tensors) and how a
    torch module is called on them."""
    argument = wanted.argument if wanted is not None else "source"
    qualname = getattr(source, "__qualname__", None)
    named = f"function {qualname}" if isinstance(qualname, str) else type(source).__name__
    torch_call = (
        f"e.g. {argument}=lambda t: net(torch.as_tensor(t).float().flatten(1)).squeeze(-1)"
        ".detach().numpy()"
        if argument == "novelty"
        else "torch.as_tensor(triplets).float(), and give back numpy arrays"
    )
    message = (
        f"The {argument}= source {named} raised {type(err).__name__}: {err} -- when given the "
        f"triplets, a numpy uint8 array of shape {triplets.shape} (B, 3, C, H, W), as every "
        f"source is. A torch module needs them as a float tensor, {torch_call}"
        + (f"; or use {wanted.example}." if wanted is not None else ".")
    )
    try:
        return type(err)(message)
    except Exception:  # an error class whose constructor takes other arguments
        return RuntimeError(message)


class ConstantSignal(IntrinsicSignal):
    """1 for every transition: with ``normalization="none"`` and ``scale=b``, a constant bonus of
    ``b`` a step, the control that tells a survival bonus from a novelty reward."""

    def raw(self, triplets: np.ndarray) -> np.ndarray:
        return np.ones(len(triplets), dtype=np.float64)


def check_scale(scale: float) -> float:
    """``scale`` as a float, or a clear error when it is negative, NaN or infinite."""
    if not (is_real(scale) and math.isfinite(scale) and scale >= 0):
        raise ValueError(
            f"scale must be a finite number >= 0 (the weight of the intrinsic reward), got "
            f"{scale!r}; use e.g. scale=0.01, or scale=0 to log the intrinsic reward without "
            "adding it."
        )
    return float(scale)


def check_weighting(decay: float, warmup: int, progress: float | None) -> None:
    """A clear error for a ``decay``, ``warmup`` or ``progress`` out of range."""
    if not (is_real(decay) and decay >= 0 and math.isfinite(decay)):
        raise ValueError(
            f"decay must be a finite number >= 0 (lambda of exp(-lambda * t), per env step), got "
            f"{decay!r}; use the paper's decay=2e-5, or decay=0 for a weight that never fades."
        )
    if not (is_int(warmup) and warmup >= 0):
        raise ValueError(
            f"warmup must be an int >= 0 (transitions that get no reward while the statistics "
            f"settle), got {warmup!r}; e.g. warmup=1024."
        )
    if progress is not None and not (is_real(progress) and 0 < progress <= 1):
        raise ValueError(
            f"progress must be None or a number in (0, 1] (NovelD's alpha), got {progress!r}; "
            "NovelD uses progress=0.5."
        )


def check_extrinsic(extrinsic: np.ndarray) -> None:
    if not np.all(np.isfinite(extrinsic)):
        raise ValueError(
            f"The env returned a NaN or inf reward {extrinsic}; the intrinsic-reward wrapper "
            "cannot scale against it. Fix the env's reward (or clip it in a wrapper below this "
            "one)."
        )


def is_sb3_vec_env(env: Any) -> bool:
    """Whether ``env`` is a Stable-Baselines3 VecEnv (DummyVecEnv, SubprocVecEnv, a
    VecEnvWrapper), told by its module: SB3 is not imported for the check."""
    return any(
        klass.__module__.startswith("stable_baselines3.") and klass.__name__ == "VecEnv"
        for klass in type(env).__mro__
    )


def not_a_vector_env(env: Any, owner: str) -> str:
    """Why the vector reward ``owner`` refuses ``env``, with the fix that works for it: an SB3
    VecEnv is a vector env to its user but not a Gymnasium one, and takes the single-env reward
    inside each of its envs."""
    single = owner.replace("VectorReward", "Reward")
    if is_sb3_vec_env(env):
        kind = type(env).__name__
        return (
            f"{owner} wraps a Gymnasium vector env (gymnasium.vector.VectorEnv), got "
            f"Stable-Baselines3's {kind}, which is not one (SB3's VecEnvs have their own step "
            f"API). Put the single-env {single} inside {kind}'s env function instead: "
            f"{kind}([lambda: {single}(SimounObservation(gym.make(env_id, "
            f"render_mode='rgb_array'), fold_frames=True), ...)])."
        )
    return (
        f"{owner} wraps a Gymnasium vector env (gymnasium.vector.VectorEnv), got "
        f"{type(env).__name__} {env!r:.60}; use {single}(env, ...) on a single env, or "
        f"gym.make_vec(env_id, num_envs, wrappers=[lambda e: SimounObservation(e, ...)]) for a "
        f"vector env."
    )


class IntrinsicMechanism(ABC):
    """What the two wrappers share: the signal, its normalization and weight, and scoring.

    The reward of a transition ``s -> s'`` scored ``t`` transitions after the wrapper started:

    ``r_i = scale * exp(-decay * t) * normalize(x)``, ``x = signal(s')``, or with ``progress``
    alpha ``x = max(signal(s') - alpha * signal(s), 0)`` (NovelD, Zhang et al. 2021: pay for
    progress into less familiar states, not for being in them; their episodic first-visit gate
    is not applied). During the first ``warmup`` transitions ``r_i = 0``; the second half of the
    warm-up already raises the normalization's statistics (Burda et al. step a random agent to
    set theirs before training).
    """

    signal_type: ClassVar[type[IntrinsicSignal]]
    """the signal a wrapper class builds, from its constructor's signal arguments"""
    vector: ClassVar[bool]
    """whether the wrapper takes a vector env"""
    signal: IntrinsicSignal

    def __init__(
        self,
        env: gym.Env | VectorEnv,
        scale: float,
        normalization: str | Normalization,
        weighting: dict[str, Any],
        arguments: dict[str, Any],
        paper: dict[str, float],
    ) -> None:
        """Wrap ``env``; ``weighting``: ``decay``, ``warmup``, ``progress``; ``arguments``: the
        signal's, its source first; ``paper``: the ``"paper"`` normalization's initial maxima.

        Checks the env's kind and every value, builds the signal from ``arguments`` and the
        normalization, and records every constructor argument for ``env.spec`` (the source held
        by reference: see :class:`SharedSource`)."""
        name = type(self).__name__
        if not self.vector and not isinstance(env, VectorEnv):
            check_single_env(env, name)
        if isinstance(env, VectorEnv) != self.vector:
            if self.vector:
                raise TypeError(not_a_vector_env(env, name))
            raise TypeError(
                f"{name} wraps a single env, got the vector env {env}; use "
                f"{name.replace('Reward', 'VectorReward')}(envs, ...) on the vector env, or put "
                f"{name} in each sub-env (gym.make_vec(..., wrappers=[...]))"
            )
        self.scale = check_scale(scale)
        check_weighting(**weighting)
        self.decay = float(weighting["decay"])
        self.warmup = int(weighting["warmup"])
        self.progress = weighting["progress"]
        recorded = dict(arguments)
        if arguments:
            name, source = next(iter(arguments.items()))
            recorded[name] = SharedSource(SharedSource.unwrap(source))
        recorded.update(scale=scale, normalization=normalization, **weighting, **paper)
        # only what the class's constructor takes, so that gym.make(env.spec) re-makes it (the
        # constant bonus fixes its normalization, warm-up and progress)
        taken = inspect.signature(type(self).__init__).parameters
        gym.utils.RecordConstructorArgs.__init__(
            self, **{key: plain(value) for key, value in recorded.items() if key in taken}
        )
        self.signal = self.signal_type(**arguments)
        self.normalization = make_normalization(normalization, **paper)
        claim_normalization(self.normalization, self)
        self.scored = 0
        """transitions scored so far: the step t of the weight and the warm-up's clock"""
        self._closed = False
        self._attach(env)

    @abstractmethod
    def _attach(self, env: Any) -> None:
        """Initialise the wrapper base class on ``env`` and the wrapper's own state."""

    def _score(
        self, previous: np.ndarray, reached: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray
    ) -> np.ndarray:
        """``(B,)`` weighted intrinsic rewards of the transitions ``previous -> reached``."""
        if self.progress is None:
            raw = self._raw(reached)
        else:
            both = self._raw(np.concatenate([previous, reached]))
            raw = np.maximum(both[len(reached) :] - self.progress * both[: len(reached)], 0.0)
        position = self.scored + np.arange(len(raw))
        normalized = self._normalize(raw, extrinsic, envs, position >= self.warmup // 2)
        weight = self.scale * math.exp(-self.decay * self.scored)
        self.scored += len(raw)
        return np.where(position >= self.warmup, weight * normalized, 0.0)

    def _normalize(
        self, raw: np.ndarray, extrinsic: np.ndarray, envs: np.ndarray, counted: np.ndarray
    ) -> np.ndarray:
        """The normalization's rewards for ``raw``, checked as the raw values are: one finite
        float per row (a user's own ``Normalization`` may return anything)."""
        returned = self.normalization(raw, extrinsic, envs, counted)
        try:
            values = np.asarray(returned, dtype=np.float64)
        except (TypeError, ValueError):
            values = None
        if values is None or values.shape != raw.shape:
            got = (
                f"shape {values.shape}"
                if values is not None and values.ndim
                else f"{returned!r:.40} ({type(returned).__name__})"
            )
            raise ValueError(
                f"normalization {self.normalization!r} returned {got} for a batch of "
                f"{len(raw)} raw values; its __call__ must return one reward per row, a float "
                f"array of shape ({len(raw)},)."
            )
        if not np.all(np.isfinite(values)):
            row = int(np.flatnonzero(~np.isfinite(values))[0])
            raise ValueError(
                f"normalization {self.normalization!r} gave the non-finite reward {values[row]} "
                f"for the raw value {raw[row]} at transition {self.scored + row} of this "
                "wrapper; a Normalization must turn finite values into finite rewards (check its "
                "statistics, e.g. a division by a spread of 0)."
            )
        return values

    def _raw(self, triplets: np.ndarray) -> np.ndarray:
        raw = np.asarray(self.signal.raw(triplets), dtype=np.float64)
        if raw.shape != (len(triplets),):
            raise ValueError(
                f"{type(self.signal).__name__} returned shape {raw.shape} for {len(triplets)} "
                f"triplets; it must return one value per triplet, shape ({len(triplets)},)."
            )
        if not np.all(np.isfinite(raw)):
            bad = raw[~np.isfinite(raw)][0]
            raise ValueError(
                f"{type(self.signal).__name__} gave the non-finite intrinsic value {bad} at "
                f"transition {self.scored} of this wrapper; its model has diverged (lower its "
                "learning rate) or got a bad input."
            )
        return raw

    def check_state(self, state: Any) -> None:
        """A TypeError for a ``state`` that is no dict, a ValueError naming what else keeps it
        from this wrapper: ``scored`` or ``normalization`` missing or bad, or statistics of
        another normalization than this wrapper's (named both)."""
        name = type(self).__name__
        normalization = normalization_name(self.normalization)
        fix = (
            f"the state must come from state_dict() of a {name} with "
            f"normalization={normalization!r}, e.g. env.load_state_dict(other.state_dict())"
        )
        if not isinstance(state, Mapping):
            raise TypeError(
                f"{name}.load_state_dict got a {type(state).__name__}, not a dict; {fix}."
            )
        problems = [f"it lacks {key!r}" for key in ("scored", "normalization") if key not in state]
        scored = state.get("scored", 0)
        if not (is_real(scored) and math.isfinite(scored) and scored >= 0 and scored % 1 == 0):
            problems.append(f"its scored is {scored!r}, not an int >= 0")
        if "normalization" in state:
            statistics = state["normalization"]
            unfit = self.normalization.state_problems(statistics)
            num_envs = self.num_envs if self.vector else 1
            problems += unfit or self.normalization.sub_env_problems(statistics, num_envs)
        if problems:
            raise ValueError(
                f"{name}.load_state_dict cannot load this state: {'; '.join(problems)}; {fix}. "
                "Nothing was loaded."
            )

    def state_dict(self) -> dict[str, Any]:
        """The transitions scored and the normalization's statistics (the source keeps its own
        state)."""
        return {"scored": self.scored, "normalization": self.normalization.state_dict()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned; a state that does not fit this wrapper (see
        :meth:`check_state`) is refused and nothing is loaded."""
        self.check_state(state)
        self.normalization.load_state_dict(state["normalization"])
        self.scored = int(state["scored"])

    def close(self) -> None:
        """Close the env, then the source (stops a model's update thread; a model shared with
        other envs starts a new one when they step again)."""
        self._closed = True
        try:
            super().close()
        finally:
            self.signal.close()


class IntrinsicReward(
    IntrinsicMechanism, CheckedSpecWrapper, gym.Wrapper, gym.utils.RecordConstructorArgs
):
    """``r_e + r_i`` for a single env, ``r_i`` from the class's signal on the triplet reached
    (see :class:`IntrinsicMechanism` for the normalization and the weight).

    ``info`` gets ``"reward_extrinsic"`` and ``"reward_intrinsic"`` (``r_i``); the reward returned
    is their sum. Subclasses (``ConsistencyCuriosityReward``, ``RNDReward``,
    ``ConstantBonusReward``) name their ``signal_type`` and give their constructor's signature.
    A source (function or model) or a ``Normalization`` instance cannot be written as JSON:
    ``env.spec.to_json()`` raises a TypeError naming it (see ``simoun_wrappers._spec``), while
    ``gym.make(env.spec)`` re-makes the env in the same process.
    """

    vector = False

    def _attach(self, env: gym.Env) -> None:
        gym.Wrapper.__init__(self, env)
        self._read = env_triplet_reader(env, type(self).__name__)
        self._last_triplet: np.ndarray | None = None

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        refuse_after_close(self._closed, type(self).__name__, "reset")
        seed = check_reset_seed(seed, type(self).__name__)
        obs, info = self.env.reset(seed=seed, options=options)
        self._last_triplet = self._read(obs)
        return obs, info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        refuse_after_close(self._closed, type(self).__name__, "step")
        if self._last_triplet is None:
            raise gym.error.ResetNeeded(f"Call reset() before step() on {type(self).__name__}.")
        check_action(action, self.action_space, type(self).__name__)
        obs, extrinsic, terminated, truncated, info = self.env.step(action)
        extrinsic = float(extrinsic)
        batch = np.array([extrinsic], dtype=np.float64)
        check_extrinsic(batch)
        triplet = self._read(obs)
        intrinsic = float(self._score(self._last_triplet, triplet, batch, ONE_ENV)[0])
        self.signal.watch(
            self._last_triplet,
            np.asarray(action)[None],
            triplet,
            np.array([terminated]),
            np.array([truncated]),
        )
        self._last_triplet = triplet
        info = {**info, "reward_extrinsic": extrinsic, "reward_intrinsic": intrinsic}
        return obs, float(finite_sum(extrinsic, intrinsic)), terminated, truncated, info


ONE_ENV = np.zeros(1, dtype=np.int64)
"""the sub-env index of a single env's transitions"""


def check_dict_info(env: VectorEnv, owner: str) -> None:
    """A TypeError when Gymnasium's ``DictInfoToList`` is under the vector reward ``owner``:
    the reward reads and extends the vector env's info dict (``final_obs``,
    ``reward_intrinsic``), which that wrapper turns into a list. It goes outside, as
    Gymnasium's own vector wrappers that read the info require (``RecordEpisodeStatistics``)."""
    layer: Any = env
    while layer is not None:
        if isinstance(layer, gym.wrappers.vector.DictInfoToList):
            raise TypeError(dict_info_problem(owner))
        layer = getattr(layer, "env", None)


def check_info_is_dict(info: Any, owner: str) -> None:
    """A TypeError when the vector env under ``owner`` gives an info that is not a dict."""
    if not isinstance(info, dict):
        raise TypeError(dict_info_problem(owner, type(info).__name__))


def dict_info_problem(owner: str, got: str | None = None) -> str:
    """Why ``owner`` refuses a list of infos (``got``: the type it got, when it got one)."""
    given = f", got a {got}" if got else ""
    return (
        f"{owner} reads and extends the vector env's info dict{given}: Gymnasium's "
        f"DictInfoToList under it turns the dict into a list of dicts. Put DictInfoToList "
        f"outside, DictInfoToList({owner}(envs, ...)), as Gymnasium's RecordEpisodeStatistics "
        "requires it too."
    )


class IntrinsicVectorReward(
    IntrinsicMechanism, CheckedVectorSpecWrapper, VectorWrapper, gym.utils.RecordConstructorArgs
):
    """``r_e + r_i`` for every sub-env of a vector env, in one batched signal call.

    One signal (one source, one normalization) serves all sub-envs, and the triplets of all
    active sub-envs are scored in a single call. With ``AutoresetMode.NEXT_STEP`` (Gymnasium's
    default) the step after a sub-env's episode ended only resets it: that dummy step gets no
    intrinsic reward, does not move the statistics and is not handed to the source (as
    Gymnasium's vector ``NormalizeReward`` skips it). With ``AutoresetMode.SAME_STEP`` the ending
    step is scored on the episode's last triplet, ``info["final_obs"]``, since the returned
    observation already starts the next one. ``info`` gets ``"reward_extrinsic"`` and
    ``"reward_intrinsic"`` arrays of shape ``(num_envs,)``.
    """

    vector = True

    def _attach(self, env: VectorEnv) -> None:
        check_dict_info(env, type(self).__name__)
        VectorWrapper.__init__(self, env)
        self._read = env_triplet_reader(env, type(self).__name__)
        self._autoreset_mode = env.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
        self._prev_dones = np.zeros(self.num_envs, dtype=bool)
        self._last_triplets: np.ndarray | None = None

    @keyword_reset
    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        # read before the reset: Gymnasium's vector envs pop "reset_mask" from the options
        refuse_after_close(self._closed, type(self).__name__, "reset")
        mask = None if options is None else options.get("reset_mask")
        seed = check_vector_reset_seed(seed, type(self).__name__, self.num_envs)
        obs, info = self.env.reset(seed=seed, options=options)
        check_info_is_dict(info, type(self).__name__)
        # a masked reset returns the other sub-envs' observations unchanged
        self._last_triplets = self._read(obs)
        # a sub-env left out of the mask that has just ended still autoresets on its next step
        self._prev_dones[slice(None) if mask is None else np.asarray(mask)] = False
        return obs, info

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        refuse_after_close(self._closed, type(self).__name__, "step")
        if self._last_triplets is None:
            raise gym.error.ResetNeeded(f"Call reset() before step() on {type(self).__name__}.")
        check_action(actions, self.action_space, type(self).__name__, vector=self.num_envs)
        obs, extrinsic, terminated, truncated, info = self.env.step(actions)
        check_info_is_dict(info, type(self).__name__)
        triplets = self._read(obs)
        # The triplet that ends a SAME_STEP episode is in final_obs; obs already holds the reset.
        ended = np.logical_or(terminated, truncated)
        scored = triplets
        if self._autoreset_mode == AutoresetMode.SAME_STEP and ended.any():
            scored = triplets.copy()
            for i in np.flatnonzero(ended):
                scored[i] = self._read(info["final_obs"][i])[0]
        if self._autoreset_mode == AutoresetMode.NEXT_STEP:
            active = ~self._prev_dones
        else:
            active = np.ones(self.num_envs, dtype=bool)
        extrinsic = np.asarray(extrinsic, dtype=np.float64)
        check_extrinsic(extrinsic[active])
        intrinsic = np.zeros(self.num_envs, dtype=np.float64)
        if active.any():
            intrinsic[active] = self._score(
                self._last_triplets[active],
                scored[active],
                extrinsic[active],
                np.flatnonzero(active),
            )
            self.signal.watch(
                self._last_triplets[active],
                np.asarray(actions)[active],
                scored[active],
                np.asarray(terminated)[active],
                np.asarray(truncated)[active],
            )
        self._last_triplets = triplets
        self._prev_dones = ended
        everywhere = np.ones(self.num_envs, dtype=bool)
        info = {
            **info,
            "reward_extrinsic": extrinsic,
            "_reward_extrinsic": everywhere,
            "reward_intrinsic": intrinsic,
            "_reward_intrinsic": everywhere,
        }
        return obs, finite_sum(extrinsic, intrinsic), terminated, truncated, info


class ConstantBonusArguments:
    """The constant-bonus wrappers' constructor: the bonus per step."""

    signal_type = ConstantSignal

    def __init__(
        self,
        env: gym.Env | VectorEnv,
        scale: float,
        decay: float = 0.0,
        normalization: str | Normalization = "none",
    ) -> None:
        """Wrap ``env``, whose observations are Simoun triplets (read but not used).

        Args:
            env: a single env for :class:`ConstantBonusReward`, a vector env for
                :class:`ConstantBonusVectorReward`.
            scale: the bonus paid at every step.
            decay: lambda of a weight ``exp(-lambda * t)``, per environment step.
            normalization: ``"none"`` only (or ``Raw()``): the bonus is ``scale`` itself. A
                constant has no spread to divide by (``"reward_std"`` and ``"standardize"``
                would pay 0 at every step) and no novelty to scale; any other is refused.
        """
        check_constant_normalization(normalization, type(self).__name__)
        super().__init__(
            env, scale, "none", {"decay": decay, "warmup": 0, "progress": None}, {}, {}
        )


def check_constant_normalization(normalization: Any, owner: str) -> None:
    """A ValueError for a constant bonus given a normalization other than ``"none"``: the
    running statistics of a constant would turn it into 0 or into a bonus that depends on the
    env's rewards, which is no longer the control it is meant to be."""
    if isinstance(normalization, Raw) or (
        isinstance(normalization, str) and normalization == Raw.name
    ):
        return
    raise ValueError(
        f"{owner} takes no normalization, got normalization={normalization!r}: its raw value is "
        "the constant 1, whose running std is 0 ('reward_std' and 'standardize' would pay 0 at "
        "every step), and 'paper' or 'return_std' would scale it by the env's rewards or by "
        "time, so it would no longer be the control it is; the bonus is scale itself. Drop "
        f"normalization (a bonus of b a step is {owner}(env, scale=b)); to pay a normalized "
        "novelty use RNDReward or ConsistencyCuriosityReward with that normalization."
    )


class ConstantBonusReward(ConstantBonusArguments, IntrinsicReward):
    """Add a constant ``scale`` to every step's reward: the control arm of an intrinsic-reward
    study. A reward that helps only as much as this bonus helps by paying for survival, not for
    novelty (Burda et al. 2018, "Death is not the end").

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.intrinsic_reward import ConstantBonusReward
        >>> env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=16)
        >>> env = ConstantBonusReward(env, scale=0.1)
        >>> _ = env.reset(seed=0)
        >>> _, reward, _, _, info = env.step(0)
        >>> reward, info["reward_intrinsic"]
        (1.1, 0.1)
    """


class ConstantBonusVectorReward(ConstantBonusArguments, IntrinsicVectorReward):
    """A constant ``scale`` added to every scored step of every sub-env (the autoreset steps
    get nothing, as in :class:`IntrinsicVectorReward`).

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.intrinsic_reward import ConstantBonusVectorReward
        >>> envs = gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="sync",
        ...                     render_mode="rgb_array",
        ...                     wrappers=[lambda e: SimounObservation(e, size=16)])
        >>> envs = ConstantBonusVectorReward(envs, scale=0.1)
        >>> _ = envs.reset(seed=0)
        >>> _, rewards, _, _, info = envs.step(np.array([0, 1]))
        >>> rewards.tolist()
        [1.1, 1.1]
    """
