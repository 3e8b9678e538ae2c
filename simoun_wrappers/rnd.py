"""Random network distillation (Burda et al. 2019) as Gymnasium reward wrappers.

The standard comparator for Simoun's consistency curiosity, on the same wrappers
(``simoun_wrappers.intrinsic_reward``): only the signal differs. A novelty source (e.g.
``simoun_agent.rnd_model.RNDModel``: a fixed random target network and a predictor trained to
match it, on observations normalized by a running mean/std and clipped to [-5, 5]) gives the
prediction error of the newest frame of each triplet; :class:`RNDSignal` divides it by a running
standard deviation of the errors. Nothing here imports torch.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import gymnasium as gym
import numpy as np
from gymnasium.vector import VectorEnv
from gymnasium.wrappers.utils import RunningMeanStd

from simoun_wrappers.intrinsic_reward import (
    IntrinsicReward,
    IntrinsicSignal,
    IntrinsicVectorReward,
    SharedSource,
)

__all__ = ["NoveltySource", "RNDReward", "RNDSignal", "RNDVectorReward"]


@runtime_checkable
class NoveltySource(Protocol):
    """Anything that maps a batch of frame triplets to one novelty score (an error) each.

    ``__call__(triplets)`` takes ``uint8 (B, 3, C, H, W)`` and returns ``(B,)`` non-negative
    floats, larger for less familiar observations (``simoun_agent.rnd_model.RNDModel``: the
    predictor's squared error on the newest frame). Like a ``FeatureSource`` it may define
    ``watch(triplets, actions, next_triplets, terminated, truncated)`` to learn online and
    ``close()``.
    """

    def __call__(self, triplets: np.ndarray) -> np.ndarray: ...


class RNDSignal(IntrinsicSignal):
    """The novelty source's error divided by the running standard deviation of the errors.

    The running mean/std (Gymnasium's ``RunningMeanStd``) is raised with the batch first, then
    ``error / sqrt(var + 1e-8)`` is returned. The first ``warmup`` scored transitions get reward
    0, as Burda et al. step a random agent to set their normalization before training: in the
    first half only the source learns from them (an ``RNDModel``'s per-pixel observation
    statistics, from a few frames at first, make early errors huge: measured on
    MiniGrid-DoorKey-6x6 with 8 random sub-envs, counting those errors left the std at 4.4 and
    the rewards of steps 400-600 at 0.003), in the second half they also set the error
    statistics, so the first reward is not divided by the std of a handful of errors. (Burda et
    al. divide by the std of the discounted intrinsic *return*; this divides by the std of the
    reward itself, which needs no per-env return and no discount.)
    """

    def __init__(self, novelty: NoveltySource | SharedSource, warmup: int) -> None:
        super().__init__(novelty)
        if not isinstance(self.source, NoveltySource):
            raise TypeError(
                f"novelty must be a NoveltySource (callable: uint8 (B, 3, C, H, W) -> (B,) "
                f"errors), got {type(self.source).__name__}. Use e.g. "
                "simoun_agent.rnd_model.RNDModel.for_env(env)."
            )
        if not (isinstance(warmup, (int, np.integer)) and warmup >= 0):
            raise ValueError(
                f"warmup must be an int >= 0 (transitions that get no reward while the "
                f"statistics settle), got {warmup!r}; e.g. warmup=1024."
            )
        self.warmup = int(warmup)
        # epsilon=0: no prior pseudo-sample (Gymnasium's default is one of weight 1e-4 with
        # variance 1, which outweighs the variance of errors that differ by less than 1e-2)
        self.errors = RunningMeanStd(epsilon=0.0, shape=())
        self.scored = 0
        """transitions scored so far"""

    def __call__(self, triplets: np.ndarray, extrinsic: np.ndarray) -> np.ndarray:
        errors = self.source(triplets)
        errors = None if isinstance(errors, tuple) else np.asarray(errors, dtype=np.float64)
        if errors is None or errors.shape != (len(triplets),):
            shape = "a tuple" if errors is None else f"shape {errors.shape}"
            raise ValueError(
                f"The novelty source {type(self.source).__name__} returned {shape} for "
                f"{len(triplets)} triplets; it must return one error per triplet, shape "
                f"({len(triplets)},). (A FeatureSource such as CuriosityModel goes with "
                "ConsistencyCuriosityReward, not RNDReward.)"
            )
        if not (np.all(np.isfinite(errors)) and np.all(errors >= 0)):
            raise ValueError(
                f"The novelty source {type(self.source).__name__} returned {errors}: errors must "
                "be finite and >= 0; its predictor has diverged (lower its learning rate)."
            )
        position = self.scored + np.arange(len(errors))
        self.scored += len(errors)
        # The first half of the warm-up only reaches the source (its observation statistics
        # settle); the second half also sets the error statistics; rewards start after it.
        counted = position >= self.warmup // 2
        if counted.any():
            self.errors.update(errors[counted])
        normalized = errors / np.sqrt(self.errors.var + 1e-8)
        return np.where(position >= self.warmup, normalized, 0.0)

    def state_dict(self) -> dict[str, Any]:
        """The transitions scored and the running mean, variance and count of the errors."""
        return {
            "scored": self.scored,
            "error_mean": float(self.errors.mean),
            "error_var": float(self.errors.var),
            "error_count": float(self.errors.count),
        }

    def load_state_dict(self, state: dict[str, Any]) -> None:
        self.errors.mean = np.float64(state["error_mean"])
        self.errors.var = np.float64(state["error_var"])
        self.errors.count = float(state["error_count"])
        self.scored = int(state["scored"])


class RNDArguments:
    """The RND wrappers' constructor: the novelty source, the scale and the warm-up."""

    signal_type = RNDSignal

    def __init__(
        self,
        env: gym.Env | VectorEnv,
        novelty: NoveltySource,
        scale: float = 0.05,
        warmup: int = 1024,
    ) -> None:
        """Wrap ``env``, whose observations are Simoun triplets.

        Args:
            env: an env yielding ``SimounObservation`` observations (Dict with ``"frames"``, or
                the folded ``(3C, H, W)`` Box): a single env for :class:`RNDReward`, a vector
                env for :class:`RNDVectorReward`.
            novelty: the :class:`NoveltySource`, e.g. ``RNDModel.for_env(env)``.
            scale: the weight of the normalized error in the reward.
            warmup: transitions that get reward 0 while the statistics settle (see
                :class:`RNDSignal`); 1024 is one PPO rollout of 8 sub-envs x 128 steps.
        """
        super().__init__(env, scale, novelty=novelty, warmup=warmup)


class RNDReward(RNDArguments, IntrinsicReward):
    """Add random network distillation's novelty bonus to the env's reward.

    ``r = r_e + scale * e / std(e)``: ``e`` is the novelty source's error on the newest frame of
    the triplet reached (an ``RNDModel``'s predictor against its fixed random target), ``std(e)``
    the running standard deviation of the errors (see :class:`RNDSignal`). ``info`` gets
    ``"reward_extrinsic"`` and ``"reward_intrinsic"``; a source with ``watch`` is handed every
    transition. The error statistics are in ``state_dict()`` / ``load_state_dict()``. For
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
