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

from simoun_wrappers.curiosity import FeatureSource, consistency_distance
from simoun_wrappers.intrinsic_normalization import Normalization, PaperMaxima
from simoun_wrappers.intrinsic_reward import (
    IntrinsicReward,
    IntrinsicSignal,
    IntrinsicVectorReward,
    SharedSource,
    SourceProtocol,
)

__all__ = ["ConsistencyCuriosityReward", "ConsistencyCuriosityVectorReward", "ConsistencySignal"]


PAPER_DECAY = 2e-5
"""Eq. 13's lambda per environment step (CCLF's value for its similar term)"""


class ConsistencySignal(IntrinsicSignal):
    """Eq. 13's distance ``d``: how far the motion features disagree with the appearance
    features' frame-to-frame changes (:func:`~simoun_wrappers.curiosity.consistency_distance`),
    from a :class:`~simoun_wrappers.curiosity.FeatureSource`."""

    source_protocol = SourceProtocol(
        "features",
        FeatureSource,
        "callable: uint8 (B, 3, C, H, W) -> f_m (B, D), f_a (B, 3, D)",
        "simoun_agent.curiosity_model.CuriosityModel",
    )

    def __init__(self, features: FeatureSource | SharedSource) -> None:
        super().__init__(features)

    @property
    def features(self) -> FeatureSource:
        """The feature source (this signal's ``source``)."""
        return self.source

    def raw(self, triplets: np.ndarray) -> np.ndarray:
        f_m, f_a = self._features(triplets)
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
        return consistency_distance(f_m, f_a).astype(np.float64)

    def _features(self, triplets: np.ndarray) -> tuple[Any, Any]:
        """The source's ``(f_m, f_a)``, or a clear error naming the source and what it must
        return (Python's own is "too many values to unpack")."""
        returned = self.call_source(triplets)
        if isinstance(returned, (tuple, list)) and len(returned) == 2:
            return returned[0], returned[1]
        if isinstance(returned, (tuple, list)):
            got = f"a {type(returned).__name__} of {len(returned)}"
        else:
            shape = getattr(returned, "shape", None)
            got = f"a {type(returned).__name__}" + (f" of shape {tuple(shape)}" if shape else "")
        hint = (
            " A NoveltySource such as RNDModel (one error per triplet) goes with RNDReward, not "
            "ConsistencyCuriosityReward."
            if not isinstance(returned, (tuple, list))
            else ""
        )
        raise ValueError(
            f"The feature source {source_name(self.source)} returned {got} for "
            f"{len(triplets)} triplets; a FeatureSource (features=) must return the tuple "
            f"(f_m, f_a): motion features ({len(triplets)}, D) and appearance features "
            f"({len(triplets)}, 3, D).{hint}"
        )


def source_name(source: object) -> str:
    """How an error names a source: a function by its name, an object by its class."""
    qualname = getattr(source, "__qualname__", None)
    return f"function {qualname}" if isinstance(qualname, str) else type(source).__name__


def is_paper(normalization: str | Normalization) -> bool:
    """Whether ``normalization`` is Eq. 13's, by name or as an instance."""
    if isinstance(normalization, Normalization):
        return isinstance(normalization, PaperMaxima)
    return isinstance(normalization, str) and normalization == PaperMaxima.name


class ConsistencyArguments:
    """The consistency wrappers' constructor: ``features``, Eq. 13's constants, and the
    normalization."""

    signal_type = ConsistencySignal

    def __init__(
        self,
        env: gym.Env | VectorEnv,
        features: FeatureSource,
        scale: float = 0.2,
        decay: float | None = None,
        r_e_max_init: float | None = None,
        r_i_max_init: float | None = None,
        normalization: str | Normalization = "paper",
        warmup: int = 0,
        progress: float | None = None,
    ) -> None:
        """Wrap ``env``, whose observations are Simoun triplets.

        Args:
            env: an env yielding ``SimounObservation`` observations (Dict with ``"frames"``, or
                the folded ``(3C, H, W)`` Box): a single env for
                :class:`ConsistencyCuriosityReward`, a vector env for
                :class:`ConsistencyCuriosityVectorReward`.
            features: the :class:`FeatureSource` giving ``f_m`` and ``f_a``.
            scale: the weight of the normalized reward (C of Eq. 13).
            decay: lambda of Eq. 13's ``exp(-lambda * t)``, per environment step; None: the
                paper's 2e-5 with Eq. 13's normalization, given by name (``"paper"``) or as an
                instance (``PaperMaxima(...)``), else 0 (the literature's normalizations have no
                schedule).
            r_e_max_init: initial running maximum of ``|r_e|`` (> 0) of ``normalization=
                "paper"``; None: 1.0. Refused with any other normalization, an instance
                included (``PaperMaxima(r_e_max_init=...)`` takes it there).
            r_i_max_init: initial running maximum of ``d`` (> 0), as ``r_e_max_init``. Both
                defaults match ``simoun_agent.AgentConfig``; a tiny ``r_i_max_init`` lets the
                first distances set the scale instead.
            normalization: a name of ``simoun_wrappers.intrinsic_normalization.NORMALIZATIONS``
                or a ``Normalization``; an instance means what its name means (a
                ``PaperMaxima()`` is ``"paper"``). ``"paper"`` (Eq. 13 as written) is always
                positive: a bonus for staying alive to an on-policy learner (see
                docs/intrinsic-rewards.md). An instance keeps one wrapper's running
                statistics: one already held by another wrapper is refused (build a new one,
                or pass the name).
            warmup: transitions that get reward 0 while the statistics settle.
            progress: None, or NovelD's alpha: pay ``max(d(s') - alpha * d(s), 0)``.
        """
        if decay is None:
            decay = PAPER_DECAY if is_paper(normalization) else 0.0
        super().__init__(
            env,
            scale,
            normalization,
            {"decay": decay, "warmup": warmup, "progress": progress},
            {"features": features},
            {"r_e_max_init": r_e_max_init, "r_i_max_init": r_i_max_init},
        )


class ConsistencyCuriosityReward(ConsistencyArguments, IntrinsicReward):
    """Add Simoun's consistency-guided intrinsic reward (Eq. 13) to the env's reward.

    At every step the wrapper encodes the new observation's triplet ``[o_{t-1}, o_t, o_{t+1}]``
    with ``features``, measures how far the motion features disagree with the appearance
    features' frame-to-frame changes (``d``), and returns ``r_e + r_i`` with
    ``r_i = scale * exp(-decay * t) * normalize(d)``. With ``normalization="paper"`` this is
    Eq. 13: ``normalize(d) = d * r_e_max / r_i_max``, ``r_e_max`` the running maximum of
    ``|r_e|`` and ``r_i_max`` that of ``d``, both raised before ``r_i`` is computed, so
    ``r_i <= scale * r_e_max``. ``t`` counts the steps taken through this wrapper. ``info`` gets
    ``"reward_extrinsic"`` and ``"reward_intrinsic"``.

    Feature sources that learn online (with a ``watch`` method) are handed every transition.
    The normalization's statistics and the step are in ``state_dict()`` / ``load_state_dict()``
    and are
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
    call; ``"return_std"`` keeps one discounted return per sub-env. The autoreset steps are
    skipped in both autoreset modes (see
    :class:`~simoun_wrappers.intrinsic_reward.IntrinsicVectorReward`). The global step ``t``
    counts the sub-env transitions scored (one per sub-env per vector step, autoreset steps left
    out). ``info`` gets ``"reward_extrinsic"`` and ``"reward_intrinsic"`` arrays of shape
    ``(num_envs,)``.

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.curiosity_reward import ConsistencyCuriosityVectorReward
        >>> def features(triplets):  # each frame's mean brightness, and its last change
        ...     f_a = triplets.mean(axis=(2, 3, 4), dtype=np.float32)[..., None]
        ...     return f_a[:, 2] - f_a[:, 1], f_a
        >>> envs = gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="sync",
        ...                     render_mode="rgb_array",
        ...                     wrappers=[lambda e: SimounObservation(e, size=16)])
        >>> envs = ConsistencyCuriosityVectorReward(envs, features)
        >>> _ = envs.reset(seed=0)
        >>> _, rewards, _, _, info = envs.step(np.array([0, 1]))
        >>> rewards.shape, info["reward_intrinsic"].shape
        ((2,), (2,))
    """
