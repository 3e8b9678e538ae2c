"""Random network distillation (Burda et al. 2019, "Exploration by Random Network Distillation")
as a novelty source for ``simoun_wrappers.rnd.RNDReward``: the standard comparator for Simoun's
consistency curiosity.

A fixed, randomly initialised target network f maps an observation to a feature vector; a
predictor f^ is trained online to match it on the observations the agent reaches. Its error
``|| f^(x) - f(x) ||^2`` stays high on observations unlike those seen, so it measures novelty.
Both networks see the newest frame of each triplet, normalized per pixel by a running mean/std
of the watched frames and clipped to [-5, 5], as in the paper.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from gymnasium.wrappers.utils import RunningMeanStd
from torch import nn

from simoun_agent.config.rules import is_real, real, setting
from simoun_agent.online_model import (
    ENCODER_SIZE,
    SEED,
    SWITCH,
    OnlineModel,
    check_online_config,
    count,
)

__all__ = ["RNDConfig", "RNDModel", "rnd_network"]

STATISTICS = ("observation_mean", "observation_var", "observation_count")
"""The keys of the running frame statistics in a state."""

SMALLEST_SIDE = 36
"""the three convolutions (8/4, 4/2, 3/1) need frames of at least 36x36"""


@dataclass
class RNDConfig:
    """Hyperparameters of :class:`RNDModel` (network and learning rate as in Burda et al.)."""

    feature_dim: int = setting(512, count(1))
    """output size of the target and the predictor (the paper: 512)"""
    encoder_size: int | None = setting(42, ENCODER_SIZE)
    """frames are average-pooled by the integer factor ``min(H, W) // encoder_size`` first
    (84x84 -> 42x42; MiniGrid's 56x56 views are kept as they are); None never pools"""
    capacity: int = setting(1000, count(1))
    """frames kept in the buffer the predictor is trained on"""
    batch_size: int = setting(64, count(1))
    """frames per gradient step"""
    update_every: int = setting(8, count(1))
    """one gradient step every this many ``watch`` calls (env steps, or vector steps: with 8
    sub-envs each watched frame is trained on about once)"""
    learning_starts: int = setting(256, count(0))
    """frames stored before the first gradient step"""
    background: bool = setting(True, SWITCH)
    """take the gradient steps in a background thread (same schedule and rewards as
    ``CuriosityConfig.background``; False for bit-reproducible runs, as there)"""
    lr: float = setting(1e-4, real(0.0, open_low=True))
    """Adam learning rate of the predictor (the paper: 1e-4)"""
    seed: int | None = setting(None, SEED)
    """seeds both networks and the buffer sampling (None: nondeterministic)"""

    def __post_init__(self) -> None:
        check_online_config(self)


def rnd_network(
    channels: int, side: tuple[int, int], feature_dim: int, predictor: bool
) -> nn.Module:
    """The paper's network: conv 32x8x8/4, 64x4x4/2, 64x3x3/1 (leaky ReLU), a linear layer to
    ``feature_dim``; the predictor adds two ReLU layers of ``feature_dim`` before its output.
    Orthogonal initialisation (gain sqrt 2), biases 0."""
    convs = nn.Sequential(
        nn.Conv2d(channels, 32, 8, stride=4),
        nn.LeakyReLU(),
        nn.Conv2d(32, 64, 4, stride=2),
        nn.LeakyReLU(),
        nn.Conv2d(64, 64, 3, stride=1),
        nn.LeakyReLU(),
        nn.Flatten(),
    )
    with torch.no_grad():
        flat = convs(torch.zeros(1, channels, *side)).shape[1]
    head: list[nn.Module] = [nn.Linear(flat, feature_dim)]
    if predictor:
        head += [nn.ReLU(), nn.Linear(feature_dim, feature_dim)]
        head += [nn.ReLU(), nn.Linear(feature_dim, feature_dim)]
    network = nn.Sequential(convs, *head)
    for module in network.modules():
        if isinstance(module, (nn.Conv2d, nn.Linear)):
            nn.init.orthogonal_(module.weight, math.sqrt(2))
            nn.init.zeros_(module.bias)
    return network


class RNDModel(OnlineModel):
    """Random network distillation trained online, as a ``NoveltySource`` for ``RNDReward``.

    Calling it returns, for each uint8 triplet, the published predictor's mean squared error
    against the fixed target on the newest frame (float32 ``(B,)``). The wrapper hands it every
    transition through :meth:`watch`; it keeps the last ``capacity`` reached frames (pooled,
    uint8), updates the per-pixel running mean/std with them and, once ``learning_starts`` are
    stored, takes one Adam step of the predictor on ``batch_size`` of them every
    ``update_every`` calls, in a background thread, on the schedule of
    :class:`~simoun_agent.online_model.OnlineModel` (weights published whole, the same rewards
    with and without the thread). A batch is normalized with the statistics of the moment it
    is sampled. ``last_metrics`` holds the last published step's ``loss``, ``update_ms`` and
    ``wait_ms``. Actions are not used (RND scores states). Frames must be at least 36x36 after
    the pooling of ``RNDConfig.encoder_size``.

    Example:
        >>> import gymnasium as gym
        >>> from simoun_agent.rnd_model import RNDConfig, RNDModel
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.rnd import RNDReward
        >>> config = RNDConfig(batch_size=8, learning_starts=8, update_every=4, seed=0)
        >>> env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=36)
        >>> env = RNDReward(env, RNDModel.for_env(env, config, device="cpu"), warmup=4)
        >>> _ = env.reset(seed=0)
        >>> rewards = [env.step(t % 2)[4]["reward_intrinsic"] for t in range(12)]
        >>> rewards[:4], all(r > 0 for r in rewards[4:])  # the first 4 only set the statistics
        ([0.0, 0.0, 0.0, 0.0], True)
        >>> env.close()  # stops the update thread
    """

    config_type = RNDConfig
    _more_state = STATISTICS

    def _smallest_frame(self) -> tuple[int, str, int]:
        return SMALLEST_SIDE, "RND's convolutions", 42

    def _slot_bytes(self) -> int:
        return math.prod(self.encoded_shape)

    def _build(self) -> nn.Module:
        """The fixed target, the predictor and its Adam, the buffer and the running statistics
        (``action_space`` is not used: RND scores states; ``RNDModel.for_env(env)`` passes it
        as for ``CuriosityModel``)."""
        config = self.config
        c, h, w = self.encoded_shape
        self.target = rnd_network(c, (h, w), config.feature_dim, predictor=False)
        self.predictor = rnd_network(c, (h, w), config.feature_dim, predictor=True)
        self.target.to(self.device).requires_grad_(False)
        self.predictor.to(self.device)
        self.optimizer = torch.optim.Adam(self.predictor.parameters(), lr=config.lr)
        # epsilon=0: exact statistics, so a pixel that never changed normalizes to 0
        self.observations = RunningMeanStd(epsilon=0.0, shape=self.encoded_shape)
        """per-pixel running mean/std of the watched frames (after pooling)"""
        self._frames = np.zeros((config.capacity, *self.encoded_shape), dtype=np.uint8)
        return self.predictor

    def _normalized(self, frames: np.ndarray) -> torch.Tensor:
        """uint8 pooled frames as float32, normalized by the running statistics, in [-5, 5]."""
        std = np.sqrt(self.observations.var + 1e-8)
        x = ((frames - self.observations.mean) / std).clip(-5.0, 5.0).astype(np.float32)
        return torch.as_tensor(x, device=self.device)

    @torch.no_grad()
    def __call__(self, triplets: np.ndarray) -> np.ndarray:
        """The published predictor's mean squared error on the newest frame of each triplet."""
        self._raise_failure()
        x = self._normalized(self._pooled(self._check(triplets, "triplets")[:, -1]))
        error = (self.published(x) - self.target(x)).pow(2).mean(-1)
        return error.float().cpu().numpy()

    def _store(self, triplets: np.ndarray, actions: np.ndarray, next_triplets: np.ndarray) -> None:
        """Keep the frame each transition reached and add it to the running statistics."""
        frames = self._pooled(next_triplets[:, -1])
        self.observations.update(frames.astype(np.float64))
        self._frames[self._next_slots(len(frames))] = frames

    def _sample(self) -> tuple[torch.Tensor]:
        return (self._normalized(self._frames[self._batch_indices()]),)

    def _loss(self, x: torch.Tensor) -> tuple[torch.Tensor, dict[str, float]]:
        with torch.no_grad():
            target = self.target(x)
        loss = (self.predictor(x) - target).pow(2).mean()
        return loss, {"loss": float(loss.detach())}

    def _trained(self) -> nn.Module:
        return self.predictor

    def _stateful(self) -> dict[str, Any]:
        return {"predictor": self.predictor, "target": self.target, "optimizer": self.optimizer}

    def _modules_state(self) -> dict[str, Any]:
        return {
            **super()._modules_state(),
            "observation_mean": self.observations.mean.copy(),
            "observation_var": self.observations.var.copy(),
            "observation_count": self.observations.count,
        }

    def _state_problems(self, state: Mapping) -> list[str]:
        """Those of every online model, and the running statistics of the frames: arrays of the
        pooled frame's shape, a variance >= 0 and a count >= 0."""
        problems = super()._state_problems(state)
        for key in ("observation_mean", "observation_var"):
            if key in state:
                problems += self._statistics_problems(key, state[key])
        count = state.get("observation_count", 0)
        if not (is_real(count) and math.isfinite(count) and count >= 0):
            problems.append(f"its observation_count is {count!r:.60}, not a number >= 0")
        return problems

    def _statistics_problems(self, key: str, saved: Any) -> list[str]:
        """A running mean or variance: finite numbers of the pooled frame's shape (the
        variance >= 0)."""
        try:
            values = np.asarray(saved, dtype=np.float64)
        except (TypeError, ValueError):
            return [f"its {key} is a {type(saved).__name__}, not an array of numbers"]
        if values.shape != self.encoded_shape:
            return [f"{key} is {values.shape} there, {self.encoded_shape} here"]
        if not np.all(np.isfinite(values)) or (key == "observation_var" and np.any(values < 0)):
            return [
                f"its {key} holds values that are not finite"
                + (" or below 0" if key == "observation_var" else "")
            ]
        return []

    def _load_modules_state(self, state: dict[str, Any]) -> None:
        super()._load_modules_state(state)
        self.observations.mean = np.array(state["observation_mean"], dtype=np.float64)
        self.observations.var = np.array(state["observation_var"], dtype=np.float64)
        self.observations.count = float(state["observation_count"])
