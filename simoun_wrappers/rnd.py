"""Random network distillation (Burda et al. 2019) as Gymnasium reward wrappers.

The standard comparator for Simoun's consistency curiosity, on the same wrappers
(``simoun_wrappers.intrinsic_reward``): only the signal differs. A novelty source (e.g.
``simoun_agent.rnd_model.RNDModel``: a fixed random target network and a predictor trained to
match it, on observations normalized by a running mean/std and clipped to [-5, 5]) gives the
prediction error of the newest frame of each triplet (:class:`RNDSignal`); by default the
wrappers divide it by the running standard deviation of the errors. Nothing here imports torch.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import gymnasium as gym
import numpy as np
from gymnasium.vector import VectorEnv

from simoun_wrappers.intrinsic_normalization import Normalization
from simoun_wrappers.intrinsic_reward import (
    IntrinsicReward,
    IntrinsicSignal,
    IntrinsicVectorReward,
    SharedSource,
    SourceProtocol,
)

__all__ = ["NoveltySource", "RNDReward", "RNDSignal", "RNDVectorReward"]


@runtime_checkable
class NoveltySource(Protocol):
    """Anything that maps a batch of frame triplets to one novelty score (an error) each.

    ``__call__(triplets)`` takes ``uint8 (B, 3, C, H, W)`` and returns ``(B,)`` non-negative
    floats, larger for less familiar observations (``simoun_agent.rnd_model.RNDModel``: the
    predictor's squared error on the newest frame). The triplets are a numpy array, never a
    torch tensor: a torch module goes behind a function that converts them, e.g. ``lambda t:
    net(torch.as_tensor(t).float().flatten(1)).squeeze(-1).detach().numpy()``. Like a
    ``FeatureSource`` it may define ``watch(triplets, actions, next_triplets, terminated,
    truncated)`` to learn online and ``close()``.
    """

    def __call__(self, triplets: np.ndarray) -> np.ndarray: ...


class RNDSignal(IntrinsicSignal):
    """The novelty source's error on the newest frame of each triplet."""

    source_protocol = SourceProtocol(
        "novelty",
        NoveltySource,
        "callable: uint8 (B, 3, C, H, W) -> (B,) errors",
        "simoun_agent.rnd_model.RNDModel.for_env(env)",
    )

    def __init__(self, novelty: NoveltySource | SharedSource) -> None:
        super().__init__(novelty)

    def raw(self, triplets: np.ndarray) -> np.ndarray:
        errors = self.call_source(triplets)
        errors = None if isinstance(errors, tuple) else np.asarray(errors, dtype=np.float64)
        if errors is None or errors.shape != (len(triplets),):
            shape = "a tuple" if errors is None else f"shape {errors.shape}"
            raise ValueError(
                f"The novelty source {type(self.source).__name__} returned {shape} for "
                f"{len(triplets)} triplets; it must return one error per triplet, shape "
                f"({len(triplets)},). (A FeatureSource such as CuriosityModel goes with "
                "ConsistencyCuriosityReward, not RNDReward.)"
            )
        if np.any(errors < 0):  # a non-finite error is named with its step by the wrapper
            raise ValueError(
                f"The novelty source {type(self.source).__name__} returned {errors}: errors must "
                "be >= 0 (a distance or a squared error)."
            )
        return errors


class RNDArguments:
    """The RND wrappers' constructor: the novelty source, the scale, the normalization and the
    warm-up."""

    signal_type = RNDSignal

    def __init__(
        self,
        env: gym.Env | VectorEnv,
        novelty: NoveltySource,
        scale: float = 0.05,
        warmup: int = 1024,
        normalization: str | Normalization = "reward_std",
        decay: float = 0.0,
        progress: float | None = None,
    ) -> None:
        """Wrap ``env``, whose observations are Simoun triplets.

        Args:
            env: an env yielding ``SimounObservation`` observations (Dict with ``"frames"``, or
                the folded ``(3C, H, W)`` Box): a single env for :class:`RNDReward`, a vector
                env for :class:`RNDVectorReward`.
            novelty: the :class:`NoveltySource`, e.g. ``RNDModel.for_env(env)``.
            scale: the weight of the normalized error in the reward.
            warmup: transitions that get reward 0 while the statistics settle: in the first half
                only the source learns from them (an ``RNDModel``'s per-pixel observation
                statistics, from a few frames at first, make early errors huge: measured on
                MiniGrid-DoorKey-6x6 with 8 random sub-envs, counting those errors left the std
                at 4.4 and the rewards of steps 400-600 at 0.003), in the second half they also
                set the normalization's statistics. 1024 is one PPO rollout of 8 sub-envs x 128
                steps.
            normalization: a name of ``simoun_wrappers.intrinsic_normalization.NORMALIZATIONS``
                or a ``Normalization``; ``"reward_std"`` divides by the running std of the errors,
                ``"return_std"`` by that of the discounted intrinsic return as Burda et al. do.
                An instance keeps one wrapper's running statistics: one already held by
                another wrapper is refused (build a new one, or pass the name).
            decay: lambda of a weight ``exp(-lambda * t)``, per environment step.
            progress: None, or NovelD's alpha: pay ``max(e(s') - alpha * e(s), 0)``.
        """
        super().__init__(
            env,
            scale,
            normalization,
            {"decay": decay, "warmup": warmup, "progress": progress},
            {"novelty": novelty},
            {},
        )


class RNDReward(RNDArguments, IntrinsicReward):
    """Add random network distillation's novelty bonus to the env's reward.

    ``r = r_e + scale * e / std(e)``: ``e`` is the novelty source's error on the newest frame of
    the triplet reached (an ``RNDModel``'s predictor against its fixed random target), ``std(e)``
    the running standard deviation of the errors (``normalization="reward_std"``; see
    :class:`RNDArguments` for the others). ``info`` gets
    ``"reward_extrinsic"`` and ``"reward_intrinsic"``; a source with ``watch`` is handed every
    transition. The normalization's statistics are in ``state_dict()`` / ``load_state_dict()``. For
    ``gym.make_vec`` prefer :class:`RNDVectorReward`.

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.rnd import RNDReward
        >>> def novelty(triplets):  # how far the newest frame is from mid-grey
        ...     return np.abs(triplets[:, -1].astype(np.float32) - 128).mean(axis=(1, 2, 3))
        >>> env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=16)
        >>> env = RNDReward(env, novelty, scale=0.1, warmup=0)
        >>> _ = env.reset(seed=0)
        >>> _, reward, _, _, info = env.step(0)
        >>> bool(np.isclose(reward, info["reward_extrinsic"] + info["reward_intrinsic"]))
        True
    """


class RNDVectorReward(RNDArguments, IntrinsicVectorReward):
    """Random network distillation's bonus for every sub-env of a vector env, in one call.

    Same reward as :class:`RNDReward`; one source and one set of error statistics serve all
    sub-envs, and the autoreset steps are skipped in both autoreset modes (see
    :class:`~simoun_wrappers.intrinsic_reward.IntrinsicVectorReward`). ``info`` gets
    ``"reward_extrinsic"`` and ``"reward_intrinsic"`` arrays of shape ``(num_envs,)``.

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.rnd import RNDVectorReward
        >>> def novelty(triplets):
        ...     return np.abs(triplets[:, -1].astype(np.float32) - 128).mean(axis=(1, 2, 3))
        >>> envs = gym.make_vec("CartPole-v1", num_envs=2, vectorization_mode="sync",
        ...                     render_mode="rgb_array",
        ...                     wrappers=[lambda e: SimounObservation(e, size=16)])
        >>> envs = RNDVectorReward(envs, novelty, warmup=0)
        >>> _ = envs.reset(seed=0)
        >>> _, rewards, _, _, info = envs.step(np.array([0, 1]))
        >>> rewards.shape, info["reward_intrinsic"].shape
        ((2,), (2,))
    """
