"""Consistency curiosity (Eq. 13) as Gymnasium reward wrappers, for a single env and a vector env.

Any learner (PPO, SAC, DQN from any library) gets Simoun's intrinsic reward by wrapping its
environment; the features come from any :class:`~simoun_wrappers.curiosity.FeatureSource`
(``simoun_agent.curiosity_model.CuriosityModel`` learns them online; ``AgentFeatures`` reuses a
trained Simoun agent's encoder).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, VectorEnv, VectorWrapper

from simoun_wrappers.curiosity import (
    FeatureSource,
    RunningMax,
    consistency_distance,
    consistency_reward,
)

__all__ = ["ConsistencyCuriosityReward", "ConsistencyCuriosityVectorReward"]


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
            f"Consistency curiosity needs Simoun frame triplets as uint8, got {space}. Wrap the "
            "env in SimounObservation(env) (or SimounObservation(env, fold_frames=True) for SB3)."
        )
    if len(shape) == 4 and shape[0] == 3:
        return shape
    if len(shape) == 3 and shape[0] % 3 == 0:
        return (3, shape[0] // 3, *shape[1:])
    raise ValueError(
        f"Consistency curiosity needs a triplet of frames t-2, t-1, t: a (3, C, H, W) or folded "
        f"(3C, H, W) uint8 observation; got shape {shape}. Use SimounObservation(env, "
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
    """A feature source as recorded in ``env.spec``: kept by reference, never deep-copied.

    Every wrapper stacked above ours deep-copies the spec (SB3's ``Monitor`` reads ``env.spec``),
    which would copy a ``CuriosityModel``'s weights and frame buffer (measured: about 1 s and
    85 MB with an unpooled 84x84 buffer) and wait for its update thread.
    ``gym.make(env.spec)`` hands this holder back to the constructor, which unwraps it,
    so a rebuilt env shares the original source, as it does when nothing is stacked above.
    """

    def __init__(self, source: FeatureSource) -> None:
        self.source = source

    def __deepcopy__(self, memo: dict[int, Any]) -> SharedSource:
        return self

    def __repr__(self) -> str:
        return f"SharedSource({self.source!r})"


class IntrinsicReward:
    """The bookkeeping shared by both wrappers: features -> Eq. 13, the running maxima, the step.

    ``__call__(triplets, extrinsic)`` checks its inputs, computes ``d`` with the feature source,
    raises the running maxima with the batch (so ``r_i <= scale * r_e_max``), computes Eq. 13 at the
    current global step, then advances the step by the batch size (one env step per sub-env).
    """

    def __init__(
        self,
        features: FeatureSource | SharedSource,
        scale: float,
        decay: float,
        r_e_max_init: float,
        r_i_max_init: float,
    ) -> None:
        if isinstance(features, SharedSource):
            features = features.source
        if not isinstance(features, FeatureSource):
            raise TypeError(
                f"features must be a FeatureSource (callable: uint8 (B, 3, C, H, W) -> f_m (B, D), "
                f"f_a (B, 3, D)), got {type(features).__name__}. Use e.g. "
                "simoun_agent.curiosity_model.CuriosityModel."
            )
        if not (scale >= 0 and decay >= 0):  # also refuses NaN
            raise ValueError(
                f"scale and decay must be numbers >= 0, got scale={scale}, decay={decay}; use "
                "the paper's scale=0.2, decay=2e-5, or decay=0 for a reward that never fades."
            )
        self.features = features
        self.scale = float(scale)
        self.decay = float(decay)
        self.maxima = RunningMax(r_e_max=r_e_max_init, r_i_max=r_i_max_init)
        self.step = 0

    def __call__(self, triplets: np.ndarray, extrinsic: np.ndarray) -> np.ndarray:
        if not np.all(np.isfinite(extrinsic)):
            raise ValueError(
                f"The env returned a NaN or inf reward {extrinsic}; the curiosity wrapper cannot "
                "scale against it. Fix the env's reward (or clip it in a wrapper below this one)."
            )
        f_m, f_a = self.features(triplets)
        f_m = np.asarray(f_m, dtype=np.float32)
        f_a = np.asarray(f_a, dtype=np.float32)
        if not (np.all(np.isfinite(f_m)) and np.all(np.isfinite(f_a))):
            raise ValueError(
                f"The feature source {type(self.features).__name__} returned NaN or inf features; "
                "its encoder has diverged (lower its learning rate) or got a bad input."
            )
        if f_m.shape[0] != len(triplets):
            raise ValueError(
                f"The feature source returned {f_m.shape[0]} feature rows for {len(triplets)} "
                "triplets; it must return one row per triplet."
            )
        distance = consistency_distance(f_m, f_a)
        self.maxima.update(extrinsic, distance)
        reward = consistency_reward(
            distance, self.step, self.maxima.r_e_max, self.maxima.r_i_max, self.scale, self.decay
        )
        self.step += len(triplets)
        return reward.astype(np.float64)

    def watch(
        self,
        triplets: np.ndarray,
        actions: np.ndarray,
        next_triplets: np.ndarray,
        terminated: np.ndarray,
        truncated: np.ndarray,
    ) -> None:
        """Hand the transitions to the feature source when it learns online."""
        watch = getattr(self.features, "watch", None)
        if watch is not None and len(triplets):
            watch(triplets, actions, next_triplets, terminated, truncated)

    def close(self) -> None:
        """Close the feature source when it has a ``close`` (a model's update thread)."""
        close = getattr(self.features, "close", None)
        if close is not None:
            close()

    def state_dict(self) -> dict[str, Any]:
        return {"step": self.step, **self.maxima.state_dict()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.maxima.load_state_dict(state)
        self.step = int(state["step"])


class CuriosityState:
    """The wrappers' ``state_dict`` / ``load_state_dict``: step and maxima of ``curiosity``."""

    curiosity: IntrinsicReward

    def state_dict(self) -> dict[str, Any]:
        """The global step and both running maxima (the feature source keeps its own state)."""
        return self.curiosity.state_dict()

    def load_state_dict(self, state: dict[str, Any]) -> None:
        """Restore what :meth:`state_dict` returned."""
        self.curiosity.load_state_dict(state)

    def close(self) -> None:
        """Close the env, then the feature source (stops a ``CuriosityModel``'s update thread;
        a model shared with other envs starts a new one when they step again)."""
        try:
            super().close()
        finally:
            self.curiosity.close()


class ConsistencyCuriosityReward(
    CuriosityState, gym.RewardWrapper, gym.utils.RecordConstructorArgs
):
    """Add Simoun's consistency-guided intrinsic reward (Eq. 13) to the env's reward.

    At every step the wrapper encodes the new observation's triplet ``[o_{t-1}, o_t, o_{t+1}]``
    with ``features``, measures how far the motion features disagree with the appearance
    features' frame-to-frame changes, and returns ``r_e + r_i`` with
    ``r_i = scale * exp(-decay * t) * d * r_e_max / r_i_max``. ``r_e_max`` is the running maximum
    of ``|r_e|`` and ``r_i_max`` the running maximum of ``d``, both raised before ``r_i`` is
    computed, so ``r_i <= scale * r_e_max``. ``t`` counts the steps taken through this wrapper.
    ``info`` gets ``"reward_extrinsic"`` and ``"reward_intrinsic"``.

    Feature sources that learn online (with a ``watch`` method) are handed every transition.
    The running maxima and the step are in ``state_dict()`` / ``load_state_dict()`` and are
    pickled with the wrapper; in an ``AsyncVectorEnv`` read them with
    ``envs.call("state_dict")``. For ``gym.make_vec`` prefer
    :class:`ConsistencyCuriosityVectorReward`: one feature source, one batched call for all
    sub-envs.

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward
        >>> projection = np.random.default_rng(0).normal(size=(3 * 16 * 16, 8)) / 400
        >>> def features(triplets):  # a fixed random projection of each frame
        ...     f_a = triplets.reshape(*triplets.shape[:2], -1) @ projection
        ...     return (f_a[:, 2] - f_a[:, 1]).astype(np.float32), f_a.astype(np.float32)
        >>> env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=16)
        >>> env = ConsistencyCuriosityReward(env, features)
        >>> _ = env.reset(seed=0)
        >>> _, reward, _, _, info = env.step(0)
        >>> bool(np.isclose(reward, info["reward_extrinsic"] + info["reward_intrinsic"]))
        True
    """

    def __init__(
        self,
        env: gym.Env,
        features: FeatureSource,
        scale: float = 0.2,
        decay: float = 2e-5,
        r_e_max_init: float = 1.0,
        r_i_max_init: float = 1.0,
    ) -> None:
        """Wrap ``env``, whose observations are Simoun triplets.

        Args:
            env: an env yielding ``SimounObservation`` observations (Dict with ``"frames"``, or
                the folded ``(3C, H, W)`` Box).
            features: the :class:`FeatureSource` giving ``f_m`` and ``f_a``.
            scale: the temperature weight C of Eq. 13.
            decay: lambda of Eq. 13, per environment step.
            r_e_max_init: initial running maximum of ``|r_e|`` (> 0).
            r_i_max_init: initial running maximum of ``d`` (> 0). Both defaults match
                ``simoun_agent.AgentConfig``; a tiny ``r_i_max_init`` lets the first distances set
                the scale instead.
        """
        gym.utils.RecordConstructorArgs.__init__(
            self,
            features=SharedSource(features),
            scale=scale,
            decay=decay,
            r_e_max_init=r_e_max_init,
            r_i_max_init=r_i_max_init,
        )
        gym.RewardWrapper.__init__(self, env)
        self._read = triplet_reader(env.observation_space)
        self.curiosity = IntrinsicReward(features, scale, decay, r_e_max_init, r_i_max_init)
        self._last_triplet: np.ndarray | None = None

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        self._last_triplet = self._read(obs)
        return obs, info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        if self._last_triplet is None:
            raise gym.error.ResetNeeded("Call reset() before step() on ConsistencyCuriosityReward.")
        obs, extrinsic, terminated, truncated, info = self.env.step(action)
        triplet = self._read(obs)
        intrinsic = float(self.curiosity(triplet, np.array([extrinsic], dtype=np.float64))[0])
        self.curiosity.watch(
            self._last_triplet,
            np.asarray(action)[None],
            triplet,
            np.array([terminated]),
            np.array([truncated]),
        )
        self._last_triplet = triplet
        info = {**info, "reward_extrinsic": float(extrinsic), "reward_intrinsic": intrinsic}
        return obs, self.reward(extrinsic) + intrinsic, terminated, truncated, info

    def reward(self, reward: SupportsFloat) -> float:
        """The extrinsic part, passed through (Eq. 12 adds r_i to it in :meth:`step`)."""
        return float(reward)


class ConsistencyCuriosityVectorReward(
    CuriosityState, VectorWrapper, gym.utils.RecordConstructorArgs
):
    """Eq. 13's intrinsic reward for every sub-env of a vector env, in one batched feature call.

    Same reward as :class:`ConsistencyCuriosityReward`, but one feature source and one running
    maximum serve all sub-envs, and the features of all active sub-envs are computed in a single
    call. With ``AutoresetMode.NEXT_STEP`` (Gymnasium's default) the step after a sub-env's
    episode ended only resets it: that dummy step gets no intrinsic reward, does not move the
    statistics and is not handed to the feature source (as Gymnasium's vector ``NormalizeReward``
    skips it). With ``AutoresetMode.SAME_STEP`` the ending step is scored on the episode's last
    triplet, ``info["final_obs"]``, since the returned observation already starts the next one.
    The global step ``t`` counts the sub-env transitions scored (one per sub-env per vector
    step, autoreset steps left out).
    ``info`` gets ``"reward_extrinsic"`` and ``"reward_intrinsic"`` arrays of shape ``(num_envs,)``.

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.curiosity_reward import ConsistencyCuriosityVectorReward
        >>> projection = np.random.default_rng(0).normal(size=(3 * 16 * 16, 8)) / 400
        >>> def features(triplets):
        ...     f_a = triplets.reshape(*triplets.shape[:2], -1) @ projection
        ...     return (f_a[:, 2] - f_a[:, 1]).astype(np.float32), f_a.astype(np.float32)
        >>> envs = gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="sync",
        ...                     render_mode="rgb_array",
        ...                     wrappers=[lambda e: SimounObservation(e, size=16)])
        >>> envs = ConsistencyCuriosityVectorReward(envs, features)
        >>> _ = envs.reset(seed=0)
        >>> _, rewards, _, _, info = envs.step(np.array([0, 1]))
        >>> rewards.shape, info["reward_intrinsic"].shape
        ((2,), (2,))
    """

    def __init__(
        self,
        env: VectorEnv,
        features: FeatureSource,
        scale: float = 0.2,
        decay: float = 2e-5,
        r_e_max_init: float = 1.0,
        r_i_max_init: float = 1.0,
    ) -> None:
        """Wrap the vector env ``env``; arguments as in :class:`ConsistencyCuriosityReward`."""
        gym.utils.RecordConstructorArgs.__init__(
            self,
            features=SharedSource(features),
            scale=scale,
            decay=decay,
            r_e_max_init=r_e_max_init,
            r_i_max_init=r_i_max_init,
        )
        VectorWrapper.__init__(self, env)
        self._read = triplet_reader(env.single_observation_space)
        self.curiosity = IntrinsicReward(features, scale, decay, r_e_max_init, r_i_max_init)
        self._autoreset_mode = env.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
        self._prev_dones = np.zeros(self.num_envs, dtype=bool)
        self._last_triplets: np.ndarray | None = None

    def reset(
        self, *, seed: int | list[int] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(seed=seed, options=options)
        triplets = self._read(obs)
        mask = None if options is None else options.get("reset_mask")
        if mask is None or self._last_triplets is None:
            self._last_triplets = triplets
            self._prev_dones[:] = False
        else:
            self._last_triplets[mask] = triplets[mask]
            self._prev_dones[mask] = False
        return obs, info

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict]:
        if self._last_triplets is None:
            raise gym.error.ResetNeeded("Call reset() before step() on the curiosity wrapper.")
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
        intrinsic = np.zeros(self.num_envs, dtype=np.float64)
        if active.any():
            intrinsic[active] = self.curiosity(scored[active], extrinsic[active])
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
