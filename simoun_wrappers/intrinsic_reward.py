"""One reward-wrapper mechanism for intrinsic rewards, for a single env and a vector env.

``reward = r_e + scale * r_i`` with ``r_i`` from an :class:`IntrinsicSignal`: Simoun's
consistency curiosity (Eq. 13, ``simoun_wrappers.curiosity_reward``) and random network
distillation (``simoun_wrappers.rnd``) are one signal class each over the same two wrappers
(:class:`IntrinsicReward`, :class:`IntrinsicVectorReward`), which handle the rest: reading the
Simoun frame triplets, skipping the autoreset steps of a vector env, handing each transition to
a source that learns online, ``info``, state and ``close``.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv, VectorWrapper

__all__ = [
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


def triplet_reader(space: spaces.Space) -> Callable[[Any], np.ndarray]:
    """A function taking a batch of observations of ``space`` to ``uint8 (B, 3, C, H, W)``."""
    shape = triplet_shape(space)
    use_key = isinstance(space, spaces.Dict)

    def read(batch: Any) -> np.ndarray:
        # A copy: the wrappers keep the previous triplet, and the caller owns the observation.
        array = np.array(batch["frames"] if use_key else batch, dtype=np.uint8)
        return array.reshape(-1, *shape)

    return read


class SharedSource:
    """A source as recorded in ``env.spec``: kept by reference, never deep-copied.

    Every wrapper stacked above ours deep-copies the spec (SB3's ``Monitor`` reads ``env.spec``),
    which would copy a ``CuriosityModel``'s weights and frame buffer (measured: about 1 s and
    85 MB with an unpooled 84x84 buffer) and wait for its update thread.
    ``gym.make(env.spec)`` hands this holder back to the constructor, which unwraps it,
    so a rebuilt env shares the original source, as it does when nothing is stacked above.
    """

    def __init__(self, source: Any) -> None:
        self.source = source

    def __deepcopy__(self, memo: dict[int, Any]) -> SharedSource:
        return self

    def __repr__(self) -> str:
        return f"SharedSource({self.source!r})"

    @staticmethod
    def unwrap(source: Any) -> Any:
        """``source`` itself, or the source a :class:`SharedSource` holds."""
        return source.source if isinstance(source, SharedSource) else source


class IntrinsicSignal(ABC):
    """An intrinsic reward computed from the frame triplets the env reaches.

    ``__call__(triplets, extrinsic)`` returns the *normalized* intrinsic reward of each
    transition (the wrapper multiplies it by its ``scale``), updating the signal's running
    statistics with the batch first. ``source`` is the model behind it; when it has
    ``watch(triplets, actions, next_triplets, terminated, truncated)`` it is handed every scored
    transition (to learn online), and its ``close()`` is called by the wrappers' ``close()``.
    Subclasses implement ``__call__``, ``state_dict`` and ``load_state_dict``.
    """

    def __init__(self, source: Any) -> None:
        self.source = SharedSource.unwrap(source)

    @abstractmethod
    def __call__(self, triplets: np.ndarray, extrinsic: np.ndarray) -> np.ndarray:
        """``(B,)`` float64 normalized intrinsic rewards of the triplets reached."""

    @abstractmethod
    def state_dict(self) -> dict[str, Any]:
        """The signal's running statistics (the source keeps its own state)."""

    @abstractmethod
    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned."""

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


def check_scale(scale: float) -> float:
    """``scale`` as a float, or a clear error when it is negative, NaN or infinite."""
    if not (isinstance(scale, (int, float, np.number)) and math.isfinite(scale) and scale >= 0):
        raise ValueError(
            f"scale must be a finite number >= 0 (the weight of the intrinsic reward), got "
            f"{scale!r}; use e.g. scale=0.2, or scale=0 to log the intrinsic reward without "
            "adding it."
        )
    return float(scale)


def check_extrinsic(extrinsic: np.ndarray) -> None:
    if not np.all(np.isfinite(extrinsic)):
        raise ValueError(
            f"The env returned a NaN or inf reward {extrinsic}; the intrinsic-reward wrapper "
            "cannot scale against it. Fix the env's reward (or clip it in a wrapper below this "
            "one)."
        )


class IntrinsicState:
    """What the two wrappers share: building their signal from the constructor's arguments, and
    ``state_dict`` / ``load_state_dict`` / ``close`` from it."""

    signal_type: ClassVar[type[IntrinsicSignal]]
    """the signal a wrapper class builds, from its constructor's arguments but ``env`` and
    ``scale``"""
    curiosity: IntrinsicSignal

    def _build_signal(self, scale: float, arguments: dict[str, Any]) -> IntrinsicSignal:
        """Record the constructor's arguments for ``env.spec`` (the source, the first of
        ``arguments``, held by reference: see :class:`SharedSource`) and build the signal."""
        name, source = next(iter(arguments.items()))
        recorded = {**arguments, name: SharedSource(SharedSource.unwrap(source)), "scale": scale}
        gym.utils.RecordConstructorArgs.__init__(self, **recorded)
        return self.signal_type(**arguments)

    def state_dict(self) -> dict[str, Any]:
        """The signal's running statistics (the source keeps its own state)."""
        return self.curiosity.state_dict()

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned."""
        self.curiosity.load_state_dict(state)

    def close(self) -> None:
        """Close the env, then the source (stops a model's update thread; a model shared with
        other envs starts a new one when they step again)."""
        try:
            super().close()
        finally:
            self.curiosity.close()


class IntrinsicReward(IntrinsicState, gym.Wrapper, gym.utils.RecordConstructorArgs):
    """``r_e + scale * r_i`` for a single env, ``r_i`` from the class's signal on the triplet
    reached.

    ``info`` gets ``"reward_extrinsic"`` and ``"reward_intrinsic"`` (``scale * r_i``); the
    reward returned is their sum. Subclasses (``ConsistencyCuriosityReward``, ``RNDReward``)
    name their ``signal_type`` and give their constructor's signature.
    """

    def __init__(self, env: gym.Env, scale: float, **arguments: Any) -> None:
        """Wrap ``env``; ``arguments``: the signal's, its source first (recorded in
        ``env.spec``)."""
        if isinstance(env, VectorEnv):
            vector = type(self).__name__.replace("Reward", "VectorReward")
            raise TypeError(
                f"{type(self).__name__} wraps a single env, got the vector env {env}; use "
                f"{vector}(envs, ...) on the vector env, or put {type(self).__name__} in each "
                "sub-env (gym.make_vec(..., wrappers=[...]))"
            )
        self.scale = check_scale(scale)
        signal = self._build_signal(scale, arguments)
        gym.Wrapper.__init__(self, env)
        self._read = triplet_reader(env.observation_space)
        self.curiosity = signal
        self._last_triplet: np.ndarray | None = None

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        self._last_triplet = self._read(obs)
        return obs, info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        if self._last_triplet is None:
            raise gym.error.ResetNeeded(f"Call reset() before step() on {type(self).__name__}.")
        obs, extrinsic, terminated, truncated, info = self.env.step(action)
        extrinsic = float(extrinsic)
        batch = np.array([extrinsic], dtype=np.float64)
        check_extrinsic(batch)
        triplet = self._read(obs)
        intrinsic = self.scale * float(self.curiosity(triplet, batch)[0])
        self.curiosity.watch(
            self._last_triplet,
            np.asarray(action)[None],
            triplet,
            np.array([terminated]),
            np.array([truncated]),
        )
        self._last_triplet = triplet
        info = {**info, "reward_extrinsic": extrinsic, "reward_intrinsic": intrinsic}
        return obs, extrinsic + intrinsic, terminated, truncated, info


class IntrinsicVectorReward(IntrinsicState, VectorWrapper, gym.utils.RecordConstructorArgs):
    """``r_e + scale * r_i`` for every sub-env of a vector env, in one batched signal call.

    One signal (one source, one set of running statistics) serves all sub-envs, and the triplets
    of all active sub-envs are scored in a single call. With ``AutoresetMode.NEXT_STEP``
    (Gymnasium's default) the step after a sub-env's episode ended only resets it: that dummy
    step gets no intrinsic reward, does not move the statistics and is not handed to the source
    (as Gymnasium's vector ``NormalizeReward`` skips it). With ``AutoresetMode.SAME_STEP`` the
    ending step is scored on the episode's last triplet, ``info["final_obs"]``, since the
    returned observation already starts the next one. ``info`` gets ``"reward_extrinsic"`` and
    ``"reward_intrinsic"`` arrays of shape ``(num_envs,)``.
    """

    def __init__(self, env: VectorEnv, scale: float, **arguments: Any) -> None:
        """Wrap the vector env ``env``; ``arguments`` as in :class:`IntrinsicReward`."""
        self.scale = check_scale(scale)
        signal = self._build_signal(scale, arguments)
        VectorWrapper.__init__(self, env)
        self._read = triplet_reader(env.single_observation_space)
        self.curiosity = signal
        self._autoreset_mode = env.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
        self._prev_dones = np.zeros(self.num_envs, dtype=bool)
        self._last_triplets: np.ndarray | None = None

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        # read before the reset: Gymnasium's vector envs pop "reset_mask" from the options
        mask = None if options is None else options.get("reset_mask")
        obs, info = self.env.reset(seed=seed, options=options)
        # a masked reset returns the other sub-envs' observations unchanged
        self._last_triplets = self._read(obs)
        # a sub-env left out of the mask that has just ended still autoresets on its next step
        self._prev_dones[slice(None) if mask is None else np.asarray(mask)] = False
        return obs, info

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        if self._last_triplets is None:
            raise gym.error.ResetNeeded(f"Call reset() before step() on {type(self).__name__}.")
        obs, extrinsic, terminated, truncated, info = self.env.step(actions)
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
            intrinsic[active] = self.scale * self.curiosity(scored[active], extrinsic[active])
            self.curiosity.watch(
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
        return obs, extrinsic + intrinsic, terminated, truncated, info
