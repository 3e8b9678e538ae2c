"""Consistency curiosity (Eq. 13) as Gymnasium reward wrappers, for a single env and a vector env.

Any learner (PPO, SAC, DQN from any library) gets Simoun's intrinsic reward by wrapping its
environment; the features come from any :class:`~simoun_wrappers.curiosity.FeatureSource`
(``simoun_agent.curiosity_model.CuriosityModel`` learns them online; ``AgentFeatures`` reuses a
trained Simoun agent's encoder). The wrappers are ``simoun_wrappers.intrinsic_reward``'s, with
:class:`ConsistencySignal` as their signal.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import VectorEnv

from simoun_wrappers.curiosity import (
    FeatureSource,
    RunningMax,
    consistency_distance,
    consistency_reward,
)
from simoun_wrappers.intrinsic_reward import (
    IntrinsicReward,
    IntrinsicSignal,
    IntrinsicVectorReward,
    SharedSource,
)

__all__ = ["ConsistencyCuriosityReward", "ConsistencyCuriosityVectorReward", "ConsistencySignal"]


class ConsistencySignal(IntrinsicSignal):
    """Eq. 13 without its weight C: ``exp(-decay * t) * d * r_e_max / r_i_max``.

    ``__call__(triplets, extrinsic)`` computes ``d`` with the feature source, raises the running
    maxima with the batch (so the result is <= ``r_e_max``), computes Eq. 13 at the current
    global step, then advances the step by the batch size (one env step per sub-env).
    """

    def __init__(
        self,
        features: FeatureSource | SharedSource,
        decay: float,
        r_e_max_init: float,
        r_i_max_init: float,
    ) -> None:
        super().__init__(features)
        if not isinstance(self.source, FeatureSource):
            raise TypeError(
                f"features must be a FeatureSource (callable: uint8 (B, 3, C, H, W) -> f_m (B, D), "
                f"f_a (B, 3, D)), got {type(self.source).__name__}. Use e.g. "
                "simoun_agent.curiosity_model.CuriosityModel."
            )
        if not decay >= 0:  # also refuses NaN
            raise ValueError(
                f"decay must be a number >= 0, got decay={decay}; use the paper's decay=2e-5, or "
                "decay=0 for a reward that never fades."
            )
        self.decay = float(decay)
        self.maxima = RunningMax(r_e_max=r_e_max_init, r_i_max=r_i_max_init)
        self.step = 0

    @property
    def features(self) -> FeatureSource:
        """The feature source (this signal's ``source``)."""
        return self.source

    def __call__(self, triplets: np.ndarray, extrinsic: np.ndarray) -> np.ndarray:
        f_m, f_a = self.source(triplets)
        f_m = np.asarray(f_m, dtype=np.float32)
        f_a = np.asarray(f_a, dtype=np.float32)
        if not (np.all(np.isfinite(f_m)) and np.all(np.isfinite(f_a))):
            raise ValueError(
                f"The feature source {type(self.source).__name__} returned NaN or inf features; "
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
            distance, self.step, self.maxima.r_e_max, self.maxima.r_i_max, 1.0, self.decay
        )
        self.step += len(triplets)
        return reward.astype(np.float64)

    def state_dict(self) -> dict[str, Any]:
        """The global step and both running maxima."""
        return {"step": self.step, **self.maxima.state_dict()}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.maxima.load_state_dict(state)
        self.step = int(state["step"])


class ConsistencyArguments:
    """The consistency wrappers' constructor: ``features`` and Eq. 13's constants."""

    signal_type = ConsistencySignal

    def __init__(
        self,
        env: gym.Env | VectorEnv,
        features: FeatureSource,
        scale: float = 0.2,
        decay: float = 2e-5,
        r_e_max_init: float = 1.0,
        r_i_max_init: float = 1.0,
    ) -> None:
        """Wrap ``env``, whose observations are Simoun triplets.

        Args:
            env: an env yielding ``SimounObservation`` observations (Dict with ``"frames"``, or
                the folded ``(3C, H, W)`` Box): a single env for
                :class:`ConsistencyCuriosityReward`, a vector env for
                :class:`ConsistencyCuriosityVectorReward`.
            features: the :class:`FeatureSource` giving ``f_m`` and ``f_a``.
            scale: the temperature weight C of Eq. 13.
            decay: lambda of Eq. 13, per environment step.
            r_e_max_init: initial running maximum of ``|r_e|`` (> 0).
            r_i_max_init: initial running maximum of ``d`` (> 0). Both defaults match
                ``simoun_agent.AgentConfig``; a tiny ``r_i_max_init`` lets the first distances set
                the scale instead.
        """
        super().__init__(
            env,
            scale,
            features=features,
            decay=decay,
            r_e_max_init=r_e_max_init,
            r_i_max_init=r_i_max_init,
        )


class ConsistencyCuriosityReward(ConsistencyArguments, IntrinsicReward):
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


class ConsistencyCuriosityVectorReward(ConsistencyArguments, IntrinsicVectorReward):
    """Eq. 13's intrinsic reward for every sub-env of a vector env, in one batched feature call.

    Same reward as :class:`ConsistencyCuriosityReward`, but one feature source and one running
    maximum serve all sub-envs, and the features of all active sub-envs are computed in a single
    call. The autoreset steps are skipped in both autoreset modes (see
    :class:`~simoun_wrappers.intrinsic_reward.IntrinsicVectorReward`). The global step ``t``
    counts the sub-env transitions scored (one per sub-env per vector step, autoreset steps left
    out). ``info`` gets ``"reward_extrinsic"`` and ``"reward_intrinsic"`` arrays of shape
    ``(num_envs,)``.

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
