"""Feature sources for the consistency-curiosity wrappers (``simoun_wrappers.curiosity_reward``).

- :class:`CuriosityModel`: a dual-path encoder trained online, with L_tran (Eq. 2) and L_con
  (Eq. 3) only, on the transitions the wrapper shows it. No agent needed: a PPO, SAC or DQN user
  of any library gets Simoun's curiosity from it.
- :class:`AgentFeatures`: a (trained) :class:`~simoun_agent.SimounAgent`'s own encoder, so its
  features can shape another learner's reward.

Both follow :class:`simoun_wrappers.curiosity.FeatureSource`.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch
from gymnasium import spaces

from simoun_agent.config import AgentConfig
from simoun_agent.config.rules import Rule, is_int, real, setting
from simoun_agent.config.shapes import min_image_size
from simoun_agent.losses import contrastive_loss, transition_loss
from simoun_agent.models.encoder import PixelEncoder, make_encoder
from simoun_agent.models.networks import BilinearSimilarity, TransitionModel
from simoun_agent.online_model import (
    ENCODER_SIZE,
    SEED,
    SWITCH,
    OnlineModel,
    check_online_config,
    count,
)
from simoun_wrappers.augment import random_conv

__all__ = ["AgentFeatures", "CuriosityConfig", "CuriosityModel", "encode_actions"]

BATCH = Rule(
    "an int >= 2 (the contrastive loss takes its negatives from the batch)",
    lambda v: is_int(v) and v >= 2,
)
ODD_KERNEL = Rule(
    "an odd int >= 1 (the random convolution keeps the frame's size)",
    lambda v: is_int(v) and v >= 1 and v % 2 == 1,
    "e.g. CuriosityConfig(random_conv_kernel=3) (the default, as Lee et al. 2020)",
)


@dataclass
class CuriosityConfig:
    """Hyperparameters of :class:`CuriosityModel` (encoder sizes as in ``AgentConfig``).

    The defaults size the encoder for a reward signal at a small share of an env step (16
    filters on frames pooled to about 42x42, updates in a background thread);
    ``CuriosityConfig(num_filters=32, encoder_size=None)`` is the agent's own encoder size.
    """

    feature_dim: int = setting(50, count(1))
    """size of f_m and of each f_a"""
    num_filters: int = setting(16, count(1))
    """filters of every conv layer of both paths (the agent uses 32: about 2.6x the update time
    at 42x42, measured with ``benchmarks/curiosity.py``)"""
    encoder_size: int | None = setting(42, ENCODER_SIZE)
    """frames are average-pooled by the integer factor ``min(H, W) // encoder_size`` before the
    encoder and the buffer (84x84 -> 42x42, 4x fewer pixels); no pooling when that factor is
    below 2. None encodes frames at their full size, as the agent does"""
    interactive: bool = setting(True, SWITCH)
    """use the structural interactive module (Eq. 4-6) between the paths"""
    aux_hidden_dim: int = setting(256, count(1))
    """hidden units of the transition model G (Eq. 2)"""
    capacity: int = setting(1000, count(1))
    """transitions kept in the internal buffer (4 uint8 frames each: 21 MB at 42x42 RGB)"""
    batch_size: int = setting(32, BATCH)
    """transitions per gradient step"""
    update_every: int = setting(8, count(1))
    """one gradient step every this many ``watch`` calls (env steps, or vector steps)"""
    learning_starts: int = setting(256, count(0))
    """transitions stored before the first gradient step"""
    background: bool = setting(True, SWITCH)
    """take the gradient steps in a background thread while the env steps on (torch releases
    the GIL in its kernels). The rewards are the same either way by design, but only False
    (each step inside the ``watch`` call that is due, on the caller's thread: slower, no thread)
    is bit-reproducible beside other torch work in the process"""
    lr: float = setting(1e-3, real(0.0, open_low=True))
    """Adam learning rate"""
    encoder_tau: float = setting(0.05, real(0.0, 1.0, open_low=True))
    """EMA rate of the momentum encoder that encodes the L_con keys"""
    transition_weight: float = setting(0.1, real(0.0))
    """weight of L_tran (Eq. 2). Its squared error sums over the feature dimensions and is
    minimised exactly by a constant f_m; at weight 1 it outweighed the term below and the motion
    path collapsed (measured on dm_control cartpole-swingup, 48x48, random actions)"""
    contrastive_weight: float = setting(1.0, real(0.0))
    """weight of L_con (Eq. 3)"""
    motion_contrastive_weight: float = setting(3.0, real(0.0))
    """weight of L_tran's InfoNCE form (G's prediction must pick its own f_m_{t+1} out of the
    batch). Not in the paper, whose motion path also gets the critic's gradient: with L_tran
    alone the motion path collapsed to a constant on PointReach, Pendulum and dm_control
    cartpole (measured). 0 (with transition_weight=1) gives exactly L_tran + L_con"""
    random_conv_kernel: int = setting(3, ODD_KERNEL)
    """kernel of the random convolution making the contrastive positives"""
    channels_last: bool = setting(True, SWITCH)
    """channels-last convolutions (the agent's default)"""
    seed: int | None = setting(None, SEED)
    """seeds the weights, the buffer sampling and the augmentation (None: nondeterministic)"""

    def __post_init__(self) -> None:
        check_online_config(self)


def action_dim(space: spaces.Space) -> int:
    """Width of :func:`encode_actions`' output for ``space``."""
    if isinstance(space, spaces.Discrete):
        return int(space.n)
    if isinstance(space, spaces.MultiDiscrete):
        return int(np.sum(space.nvec))
    if isinstance(space, (spaces.Box, spaces.MultiBinary)):
        return int(np.prod(space.shape))
    raise TypeError(
        f"CuriosityModel handles Discrete, MultiDiscrete, MultiBinary and Box action spaces, got "
        f"{space}; flatten it first (gymnasium.wrappers.FlattenObservation-style) or pass a Box."
    )


def encode_actions(space: spaces.Space, actions: np.ndarray) -> np.ndarray:
    """A batch of actions as float32 ``(B, action_dim(space))`` for the transition model G.

    Discrete actions become one-hot vectors (MultiDiscrete: concatenated one-hots); bounded Box
    actions are rescaled to [-1, 1]; MultiBinary and unbounded Box actions are used as they are.
    """
    actions = np.asarray(actions)
    if isinstance(space, spaces.Discrete):
        return np.eye(space.n, dtype=np.float32)[actions.reshape(-1) - space.start]
    if isinstance(space, spaces.MultiDiscrete):
        flat = actions.reshape(len(actions), -1) - space.start.reshape(-1)
        parts = [np.eye(n, dtype=np.float32)[flat[:, i]] for i, n in enumerate(space.nvec.ravel())]
        return np.concatenate(parts, axis=1)
    flat = actions.reshape(len(actions), -1).astype(np.float32)
    if isinstance(space, spaces.Box) and space.is_bounded():
        low, high = space.low.reshape(-1), space.high.reshape(-1)
        flat = 2.0 * (flat - low) / (high - low) - 1.0
    return flat


class CuriosityModel(OnlineModel):
    """A dual-path encoder trained online with L_tran + L_con, as a curiosity ``FeatureSource``.

    Calling it encodes a batch of triplets (one batched, gradient-free forward pass) and returns
    ``f_m (B, D)`` and ``f_a (B, 3, D)`` as numpy float32. The wrappers hand it every transition
    through :meth:`watch`; it keeps the last ``capacity`` of them (frames t-2 .. t+1, uint8, any
    number of sub-envs interleaved) and, once ``learning_starts`` are stored, takes one Adam step
    on a batch of ``batch_size`` every ``update_every`` calls to ``watch``:

    - L_tran (Eq. 2): G(f_m_t, a_t) predicts f_m_{t+1} (no gradient into the target), plus the
      same prediction in InfoNCE form against the batch (``motion_contrastive_weight``);
    - L_con (Eq. 3): f_a_t must pick, among the batch, the momentum encoder's features of a
      random-convolution view of the same frame.

    The encoder is the agent's ``DualPathEncoder`` and its ``encode_transition`` (each of the
    four frames through each path once); the losses are ``simoun_agent.losses``'. Frames are
    average-pooled to about ``encoder_size`` first (84x84 -> 42x42 by default), and must then
    be at least 19x19 (15x15 without the interactive module); the action space is Discrete,
    MultiDiscrete, MultiBinary or Box.

    **Schedule and reproducibility.** The batch of the step due at watch call ``k`` is sampled
    at that call; the step runs in a background thread (``background=True``) or at once
    (``background=False``), and its weights are published at the next due call, ``k +
    update_every``, where ``watch`` waits for it if it has not finished. Features always come
    from published weights, never from a model half-way through a step, and ``updates`` counts
    the published steps (``feature_version`` is the count the last feature call used). So with a
    ``seed`` the schedule, the batches and the rewards are the same with and without the
    thread, whatever its timing; only ``update_ms`` and ``wait_ms`` (time ``watch`` spent
    waiting for the thread) vary. Bit for bit from run to run only with ``background=False``
    (on the same hardware and torch thread count; on CUDA only with
    ``torch.use_deterministic_algorithms``): beside a learner's own torch work in the same
    process (SB3 PPO), two threaded runs of one seed were measured to part in a float's last
    bit within the first 1,024 env steps, and the gap grows. The step only waits when an
    update takes longer than ``update_every`` env steps. A failed update (e.g. a non-finite
    loss) is raised by the first call to the model after it failed (at the latest by the next
    due ``watch``, which waits for it), and the model refuses to go on until
    :meth:`load_state_dict`. Call :meth:`close` (the wrappers' ``close()`` does) to stop the
    thread; a later ``watch`` starts a new one.

    Measured with ``benchmarks/curiosity.py`` (dm_control cartpole-swingup at 84x84, one torch
    thread, a shared 2-core CPU under load; tables in docs/intrinsic-rewards.md): the defaults
    added 11-21 % to the env's step time for the features and 5-29 % with training in the thread, in
    three runs. On a GPU pass ``device="cuda"``. ``last_metrics`` holds the last published step's
    losses, its duration (``update_ms``), the wait for it (``wait_ms``) and the batch standard
    deviation of f_m and f_a (``motion_std``, ``appearance_std``: near 0 means the features
    collapsed to a constant).

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import SimounObservation
        >>> from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward
        >>> from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
        >>> env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=32)
        >>> config = CuriosityConfig(batch_size=8, learning_starts=8, update_every=4, seed=0)
        >>> model = CuriosityModel.for_env(env, config, device="cpu")
        >>> env = ConsistencyCuriosityReward(env, model)
        >>> _ = env.reset(seed=0)
        >>> for _ in range(12):
        ...     *_, terminated, truncated, info = env.step(env.action_space.sample())
        ...     if terminated or truncated:
        ...         _ = env.reset()
        >>> model.updates, sorted(model.last_metrics)[:2]  # steps due at calls 8, 12; one published
        (1, ['appearance_std', 'contrastive_loss'])
        >>> env.close()  # stops the update thread
    """

    config_type = CuriosityConfig

    def _smallest_frame(self) -> tuple[int, str, int]:
        config = self.config
        needs = "the conv paths" + (" and the interactive module" if config.interactive else "")
        smallest = min_image_size(AgentConfig(encoder=self._encoder_name()))
        kernel = config.random_conv_kernel
        if config.contrastive_weight and kernel > smallest:
            # L_con's positives are a random convolution of the encoded frames: a kernel wider
            # than them sees only padding, and would fail at the first update, in the background
            needs += (
                f" and the random convolution of CuriosityConfig.random_conv_kernel={kernel} "
                "(or lower it, e.g. to 3)"
            )
            smallest = kernel
        return smallest, needs, max(32, smallest)

    def _encoder_name(self) -> str:
        return "dual_interactive" if self.config.interactive else "dual"

    def _slot_bytes(self) -> int:
        """Four uint8 frames and the encoded action (float32)."""
        return 4 * math.prod(self.encoded_shape) + 4 * action_dim(self.action_space)

    def _build(self) -> PixelEncoder:
        """The encoder, its momentum copy, G, the bilinear similarity, one Adam for all, and the
        buffer of windows and encoded actions."""
        config = self.config
        encoder_config = AgentConfig(
            encoder=self._encoder_name(),
            feature_dim=config.feature_dim,
            num_filters=config.num_filters,
            channels_last=config.channels_last,
        )
        self.encoder = make_encoder(encoder_config, self.encoded_shape).to(self.device)
        self.transition = TransitionModel(
            config.feature_dim, action_dim(self.action_space), config.aux_hidden_dim
        ).to(self.device)
        self.momentum = copy.deepcopy(self.encoder).requires_grad_(False)
        self.similarity = BilinearSimilarity(config.feature_dim).to(self.device)
        self.optimizer = torch.optim.Adam(
            [
                *self.encoder.parameters(),
                *self.transition.parameters(),
                *self.similarity.parameters(),
            ],
            lr=config.lr,
        )
        self._windows = np.zeros((config.capacity, 4, *self.encoded_shape), dtype=np.uint8)
        self._actions = np.zeros((config.capacity, action_dim(self.action_space)), dtype=np.float32)
        self.feature_version = 0
        return self.encoder

    @torch.no_grad()
    def __call__(self, triplets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``f_m (B, D)`` and ``f_a (B, 3, D)`` (frames t-2, t-1, t) of uint8 triplets."""
        self._raise_failure()
        frames = self._pooled(self._check(triplets, "triplets"))
        encoding = self.published(torch.as_tensor(frames, device=self.device), frame_features=True)
        self.feature_version = self.updates
        return (
            encoding.motion.float().cpu().numpy(),
            encoding.appearance.float().cpu().numpy(),
        )

    def _store(self, triplets: np.ndarray, actions: np.ndarray, next_triplets: np.ndarray) -> None:
        """Keep frames t-2 .. t+1 of each transition (pooled) and its encoded action."""
        slots = self._next_slots(len(triplets))
        self._windows[slots, :3] = self._pooled(triplets)
        self._windows[slots, 3] = self._pooled(next_triplets[:, -1])
        self._actions[slots] = encode_actions(self.action_space, actions)

    def _sample(self) -> tuple[torch.Tensor, torch.Tensor]:
        """A batch copied out of the buffer, on the caller's thread (the buffer keeps filling)."""
        idx = self._batch_indices()
        window = torch.as_tensor(self._windows[idx], device=self.device)
        return window, torch.as_tensor(self._actions[idx], device=self.device)

    def _loss(
        self, window: torch.Tensor, action: torch.Tensor
    ) -> tuple[torch.Tensor, dict[str, float]]:
        """L_tran + L_con + L_tran's InfoNCE form, weighted, on a batch of windows."""
        cfg = self.config
        enc, following = self.encoder.encode_transition(window)
        with torch.no_grad():
            view = random_conv(
                self.encoder.to_float(window[:, 2]), cfg.random_conv_kernel, self.generator
            )
            key = self.momentum.encode_key(view)
        l_tran = transition_loss(self.transition(enc.motion, action), following.motion)
        l_con = contrastive_loss(enc.anchor, key, self.similarity.weight)
        # Eq. 2 in InfoNCE form: G's prediction must pick its own f_m_{t+1} out of the batch.
        # Without it the motion path can collapse to a constant that G predicts exactly.
        l_motion = contrastive_loss(self.transition(enc.motion, action), following.motion)
        loss = (
            cfg.transition_weight * l_tran
            + cfg.contrastive_weight * l_con
            + cfg.motion_contrastive_weight * l_motion
        )
        metrics = {
            "transition_loss": float(l_tran.detach()),
            "contrastive_loss": float(l_con.detach()),
            "motion_contrastive_loss": float(l_motion.detach()),
            "motion_std": float(enc.motion.detach().std(0).mean()),
            "appearance_std": float(enc.anchor.detach().std(0).mean()),
        }
        return loss, metrics

    def _after_step(self) -> None:
        """The momentum encoder's EMA towards the online encoder."""
        with torch.no_grad():
            for ema, online_param in zip(
                self.momentum.parameters(), self.encoder.parameters(), strict=True
            ):
                ema.lerp_(online_param, self.config.encoder_tau)

    def _trained(self) -> PixelEncoder:
        return self.encoder

    def _stateful(self) -> dict[str, Any]:
        return {
            "encoder": self.encoder,
            "momentum": self.momentum,
            "transition": self.transition,
            "similarity": self.similarity,
            "optimizer": self.optimizer,
        }


class AgentFeatures:
    """A Simoun agent's encoder as a curiosity ``FeatureSource`` (frozen: it never trains here).

    Example:
        >>> import numpy as np
        >>> from simoun_agent import AgentConfig, SimounAgent
        >>> from simoun_agent.curiosity_model import AgentFeatures
        >>> agent = SimounAgent((3, 32, 32), action_dim=1, config=AgentConfig(), device="cpu")
        >>> f_m, f_a = AgentFeatures(agent)(np.zeros((2, 3, 3, 32, 32), np.uint8))
        >>> f_m.shape, f_a.shape
        ((2, 50), (2, 3, 50))
    """

    def __init__(self, agent: Any) -> None:
        """Wrap ``agent``, which must have a dual-path encoder (``encoder_features``)."""
        if not callable(getattr(agent, "encoder_features", None)):
            raise TypeError(
                f"AgentFeatures needs an object with encoder_features(triplets) -> (f_m, f_a), "
                f"e.g. simoun_agent.SimounAgent; got {type(agent).__name__}."
            )
        self.agent = agent

    def __call__(self, triplets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        f_m, f_a = self.agent.encoder_features(triplets)
        return _to_numpy(f_m), _to_numpy(f_a)


def _to_numpy(x: Any) -> np.ndarray:
    if isinstance(x, torch.Tensor):
        return x.detach().float().cpu().numpy()
    return np.asarray(x, dtype=np.float32)
