"""The Simoun SAC agent: one update step = augment, encode, TD target, critic + auxiliary
losses, actor, EMA targets."""

from __future__ import annotations

import copy
import functools
import math
from collections.abc import Mapping
from dataclasses import asdict
from typing import NamedTuple

import numpy as np
import torch

from simoun_agent.config import AgentConfig
from simoun_agent.config.agent import check_agent_config
from simoun_agent.config.device import device_key
from simoun_agent.config.shapes import check_agent_inputs
from simoun_agent.device import default_device
from simoun_agent.losses import (
    contrastive_loss,
    critic_loss,
    intrinsic_return,
    reward_loss,
    td_target,
    temperature_loss,
    total_loss,
    transition_loss,
)
from simoun_agent.models.actors import ACTORS, make_actor, trunk_dim
from simoun_agent.models.encoder import ENCODERS, Encoding, make_encoder, weight_init
from simoun_agent.models.networks import BilinearSimilarity, RewardModel, TransitionModel
from simoun_agent.models.sac import Critic
from simoun_agent.replay import FrameReplay
from simoun_agent.state_checks import (
    count_problems,
    module_problems,
    optimizer_problems,
    tensor_problems,
)
from simoun_wrappers._checks import check_bool, check_nonnegative_int
from simoun_wrappers.augment import random_conv, random_shift, shift_pad
from simoun_wrappers.curiosity import RunningMax, consistency_distance, consistency_reward


class Views(NamedTuple):
    """The augmented inputs of one update (:meth:`SimounAgent.augment`)."""

    windows: list[torch.Tensor]
    """per RL view, uint8 ``(B, L, C, H, W)``: the update's window (frames t-2 .. t+1, or .. t+n
    with per-step curiosity), every frame of a sample under the view's one offset"""
    next_obs: list[torch.Tensor]
    """per target view, uint8 ``(B, 3, C, H, W)``: the triplet the TD target bootstraps from,
    under the same offset as the view's window"""
    shared: int
    """how many target views bootstrap from the triplet at t+1 of a critic view, whose online
    state the encoder pass of the critic views already gives (the shared-frame trick)"""
    key: torch.Tensor | None
    """the contrastive positive (Eq. 3) as float frames; None without L_con"""


def unchanged(frames: torch.Tensor) -> torch.Tensor:
    """The RL view of augmentation "none": the frames as they are."""
    return frames


def same_device(asked: object, device: torch.device) -> bool:
    """Whether ``asked`` (what ``to()`` was given) names ``device``; a device without an index
    is the current GPU (``"cuda"``) or the one of its kind (``"cpu"`` is ``"cpu:0"``)."""
    try:
        wanted = torch.device(asked)
    except (RuntimeError, TypeError):
        return False
    return device_key(str(wanted)) == device_key(str(device))


def check_tensor(value: object, name: str, kind: str, shape: str) -> None:
    """A TypeError naming ``update_window``'s argument ``name`` unless ``value`` is a torch
    tensor of ``kind`` (``"uint8"`` or ``"float"``); ``shape`` is the one it must have."""
    if not isinstance(value, torch.Tensor):
        raise TypeError(
            f"update_window({name}=...) must be a torch tensor, {kind} {shape}, got "
            f"{type(value).__name__}; convert it with torch.as_tensor(value, device=agent.device)"
            ", or use agent.update(replay, step), which samples and converts the batch"
        )
    ok = value.dtype == torch.uint8 if kind == "uint8" else value.dtype.is_floating_point
    if not ok:
        raise TypeError(
            f"update_window({name}=...) must be {kind} {shape}, got {value.dtype}; "
            + (
                "pass the frames as stored, 0..255 (they are divided by 255 inside)"
                if kind == "uint8"
                else f"convert it with {name}.float()"
            )
        )


def check_shape(value: torch.Tensor, name: str, shape: tuple, what: str) -> None:
    """A ValueError naming ``update_window``'s argument ``name`` unless ``value`` has ``shape``
    (``what`` says what it holds)."""
    if tuple(value.shape) != tuple(shape):
        raise ValueError(
            f"update_window({name}=...) must have shape {tuple(shape)} ({what}), got "
            f"{tuple(value.shape)}; pass FrameReplay.sample's batch, or reshape it"
        )


def check_config_in_use(config: AgentConfig) -> None:
    """Check ``config`` again where it is used: a dataclass takes any value assigned after it
    was built (``config.lr = -1``), which would otherwise fail inside torch naming no field."""
    try:
        check_agent_config(config)
    except ValueError as err:
        raise ValueError(f"SimounAgent cannot use this config: {err}") from None


class SimounAgent:
    """SAC on the dual-path (or ablation) encoder with Simoun's auxiliary losses and curiosity.

    One :meth:`update` runs each unique frame of the batch through each path once: the online
    encoder sees frames t-2 .. t+1 and the residual pairs of t and t+1 (gradient only where a
    loss needs it, see ``AgentConfig.detach_past_frames``), which gives the state at t and, with
    the target Q heads, the TD target at t+1 (DrQ-v2 style); the momentum (EMA) encoder sees only
    the random-conv view of o_t, for the contrastive keys. The actor update and the curiosity
    reward reuse the online features of t, detached.

    Example:
        >>> import numpy as np
        >>> agent = SimounAgent((3, 48, 48), action_dim=2, config=AgentConfig(batch_size=8))
        >>> agent.act(np.zeros((3, 3, 48, 48), np.uint8)).shape
        (2,)
    """

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        action_dim: int,
        config: AgentConfig | None = None,
        device: str | torch.device | None = None,
    ) -> None:
        if config is not None and not isinstance(config, AgentConfig):
            raise TypeError(
                f"config must be an AgentConfig, got {type(config).__name__} ({config!r:.60}); "
                "e.g. AgentConfig(batch_size=128), AgentConfig(**values) for a dict, or "
                "simoun_agent.config.resolve(preset, overrides).agent for a preset"
            )
        self.config = config = config or AgentConfig()
        check_config_in_use(config)
        check_agent_inputs(frame_shape, action_dim, config)
        self.frame_shape = tuple(int(s) for s in frame_shape)
        self.action_dim = int(action_dim)
        self.device = default_device(device)
        self.obs_shape = (config.num_frames, *self.frame_shape)

        self.encoder = make_encoder(config, self.frame_shape).to(self.device)
        repr_dim = self.encoder.repr_dim
        self.critic = Critic(repr_dim, action_dim, config.hidden_dim, trunk_dim(config)).to(
            self.device
        )
        self.actor = make_actor(config, repr_dim, action_dim).to(self.device)
        self.motion_path = ENCODERS[config.encoder].motion_path
        # L_tran predicts f^m of a dual encoder, or the whole state of a single-path one (whose
        # size is feature_dim too), so every Fig. 6 encoder trains with the same losses
        self.transition = (
            TransitionModel(config.feature_dim, action_dim, config.aux_hidden_dim).to(self.device)
            if config.transition_weight
            else None
        )
        self.reward_model = (
            RewardModel(repr_dim, action_dim, config.aux_hidden_dim).to(self.device)
            if config.reward_weight
            else None
        )
        self.similarity = (
            BilinearSimilarity(config.feature_dim, config.similarity_init).to(self.device)
            if config.contrastive_weight
            else None
        )
        self.shift_pad = (
            config.shift_pad if config.shift_pad is not None else shift_pad(self.frame_shape[1])
        )
        # the update's parts, resolved here so that the update path does not read config names
        shifts = config.augmentation == "shift"
        self.augment_view = (
            functools.partial(random_shift, pad=self.shift_pad) if shifts else unchanged
        )
        """one RL view of a batch: DrQ's random shift (one offset per sample), or the frames
        unchanged (augmentation "none")"""
        self.view_count = max(config.critic_augmentations, config.target_augmentations)
        """RL views drawn per update: one per critic view (DrQ's M) and per target view (its K)"""
        self.independent_next_shift = shifts and config.independent_next_shift
        """whether each target view shifts its bootstrap triplet by an offset of its own"""
        keys = {"shift": self.shifted_key, "random_conv": self.random_conv_key}
        self.contrastive_key = (
            keys[config.contrastive_view] if self.similarity is not None else None
        )
        """how the contrastive positive (Eq. 3) is made, :meth:`shifted_key` or
        :meth:`random_conv_key`; None without L_con"""
        for net in (self.critic, self.actor, self.transition, self.reward_model):
            if net is not None:
                net.apply(weight_init)
        self.encoder_target = copy.deepcopy(self.encoder).requires_grad_(False)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self.value_encoder = self.encoder_target if config.next_state_encoder == "target" else None
        """the encoder of the next state the target Q heads read: the EMA encoder, or None for
        the online state the actor reads"""
        self.log_alpha = (
            torch.tensor(math.log(config.init_temperature), device=self.device, requires_grad=True)
            if ACTORS[config.actor].temperature
            else None
        )
        """log of SAC's temperature; None for an actor without one"""
        self.target_entropy = -float(action_dim)

        # L_con in its own step trains W there alone (CURL's cpc_optimizer)
        similarity = None if config.contrastive_step else self.similarity
        heads = (self.critic, self.reward_model, similarity, self.transition)
        representation = [self.encoder, *(net for net in heads if net is not None)]
        # fused Adam: one kernel per tensor, measured ~7x faster than foreach on our CPU
        self.critic_optimizer = torch.optim.Adam(
            [p for m in representation for p in m.parameters()], lr=config.lr, fused=True
        )
        self.contrastive_optimizers = (
            tuple(
                torch.optim.Adam(params, lr=config.lr, fused=True)
                for params in (
                    list(self.encoder.parameters()),
                    [*self.encoder.parameters(), *self.similarity.parameters()],
                )
            )
            if config.contrastive_step and self.similarity is not None
            else ()
        )
        """with ``contrastive_step``: CURL's encoder_optimizer (the encoder) and cpc_optimizer
        (the encoder and W), both stepped by L_con's one gradient"""
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(), lr=config.lr, fused=True)
        self.alpha_optimizer = (
            torch.optim.Adam(
                [self.log_alpha], lr=config.alpha_lr, betas=(config.alpha_beta, 0.999), fused=True
            )
            if self.log_alpha is not None
            else None
        )
        self.running_max = RunningMax(config.r_e_max_init, config.r_i_max_init).to(self.device)
        self.num_updates = 0
        """gradient steps taken; drives the actor / target update schedules"""
        self.env_step = 0
        """global env step of the latest update; :meth:`act`'s default for the exploration
        schedule of an actor that has one"""
        self.reads_encoder_target = self.value_encoder is not None or self.similarity is not None
        """whether anything reads the EMA encoder (the TD target, the contrastive keys); when
        nothing does, :meth:`update_targets` leaves it"""

    @property
    def alpha(self) -> torch.Tensor | None:
        """SAC's temperature; None for an actor without one."""
        return None if self.log_alpha is None else self.log_alpha.exp()

    # -- acting --------------------------------------------------------------------------------

    def _check_obs(
        self, frames: np.ndarray | torch.Tensor, batched: bool, name: str
    ) -> torch.Tensor:
        """``frames`` (the argument ``name``) as a tensor on the device, or an error naming the
        argument and the uint8 array of the shape it must be."""
        if isinstance(frames, dict):
            raise ValueError(
                f"expected the uint8 frames array, got SimounObservation's whole dict (keys "
                f"{sorted(frames)}); pass its 'frames' entry: agent.act(obs['frames'])"
            )
        want = ("(B, " if batched else "(") + ", ".join(map(str, self.obs_shape)) + ")"
        if not isinstance(frames, (np.ndarray, torch.Tensor)):
            # a list would be converted slowly and with a guessed dtype, never uint8
            raise TypeError(
                f"{name} must be a uint8 numpy array (or torch tensor) of shape {want} (frames "
                f"t-2, t-1, t, channel-first), got a {type(frames).__name__}; pass the 'frames' "
                "entry of SimounObservation unchanged, or np.asarray(frames, np.uint8)"
            )
        expected = ((-1,) if batched else ()) + self.obs_shape
        shape = tuple(frames.shape)
        ok_shape = len(shape) == len(expected) and shape[-4:] == self.obs_shape
        if not ok_shape or str(frames.dtype).split(".")[-1] != "uint8":
            raise ValueError(
                f"{name}: expected uint8 frames of shape {want} (frames t-2, t-1, t, "
                f"channel-first), got {frames.dtype} {shape}; pass the 'frames' entry of "
                "SimounObservation unchanged"
            )
        return torch.as_tensor(frames, device=self.device)

    def _check_step(self, step: int | None, owner: str) -> int:
        """``step``, the global env step given to ``owner``, or that of the latest update for
        None; a ValueError for anything but None or an int >= 0 (numpy ints included), which
        would otherwise reach the exploration and curiosity schedules."""
        if step is None:
            return self.env_step
        check_nonnegative_int(
            step, f"{owner}(step=...)", "pass the global env step, e.g. step=0, or None"
        )
        if step >= 2**63:  # the schedules and the checkpoints hold it as an int64
            raise ValueError(
                f"{owner}(step=...) must be below 2**63, got {step}; pass the global env step, "
                "e.g. step=0, or None"
            )
        return int(step)

    def act(
        self,
        frames: np.ndarray | torch.Tensor,
        deterministic: bool = False,
        step: int | None = None,
    ) -> np.ndarray:
        """Action in [-1, 1]^action_dim for one observation ``uint8 (3, C, H, W)``, a numpy array
        or a torch tensor: the policy's mode when ``deterministic`` (evaluation), else its
        exploration. ``step``: the global env step (an int >= 0), which sets the noise of a
        scheduled actor (DrQ-v2's); None: that of the latest :meth:`update`."""
        check_bool(deterministic, "act(deterministic=...)")
        step = self._check_step(step, "act")
        obs = self._check_obs(frames, batched=False, name="act(frames)").unsqueeze(0)
        with torch.inference_mode():
            action = self.actor.act(self.encoder(obs).state, deterministic, step)
        return action[0].cpu().numpy()

    def encoder_features(
        self, triplets: np.ndarray | torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Curiosity features of the online encoder for ``uint8 (B, 3, C, H, W)``: f^m_t ``(B, D)``
        (as in the state) and f^a of frames t-2, t-1, t ``(B, 3, D)`` (before interaction), as
        detached tensors on the agent's device — exactly what Eq. 13 uses in :meth:`update`."""
        if not self.motion_path:
            raise ValueError(
                f"encoder_features needs a dual-path encoder; this agent uses "
                f"{self.config.encoder!r} (set AgentConfig.encoder to 'dual' or 'dual_interactive')"
            )
        obs = self._check_obs(triplets, batched=True, name="encoder_features(triplets)")
        with torch.no_grad():
            enc = self.encoder(obs, frame_features=True)
        return enc.motion.detach(), enc.appearance

    # -- learning ------------------------------------------------------------------------------

    def update(self, replay: FrameReplay, step: int) -> dict[str, torch.Tensor]:
        """One gradient step on ``config.batch_size`` transitions sampled from ``replay``.

        ``step`` is the global environment step, an int >= 0 (curiosity decay, exploration
        schedule). Returns detached 0-d tensors (no host sync here); call ``float()`` on the ones
        you log.
        """
        cfg = self.config
        step = self._check_step(step, "update")
        stored = (getattr(replay, "frame_shape", None), getattr(replay, "action_dim", None))
        if stored != (self.frame_shape, self.action_dim):
            raise ValueError(
                f"replay holds frames {stored[0]} and actions of {stored[1]}, but this agent "
                f"was built for frames {self.frame_shape} and actions of {self.action_dim}; "
                f"create the replay with FrameReplay(capacity, {self.frame_shape}, "
                f"{self.action_dim})"
            )
        frames = getattr(replay, "num_frames", None)
        if frames != cfg.num_frames:
            raise ValueError(
                f"replay has num_frames={frames!r}, but this agent stacks "
                f"AgentConfig.num_frames={cfg.num_frames} frames per observation; create the "
                f"replay with FrameReplay(capacity, {self.frame_shape}, {self.action_dim}, "
                f"num_frames={cfg.num_frames})"
            )
        batch = replay.sample(cfg.batch_size, cfg.n_step, cfg.discount)

        def put(name: str) -> torch.Tensor:
            return torch.from_numpy(batch[name]).to(self.device, non_blocking=True)

        action, reward, discount = put("action"), put("reward"), put("discount")
        if cfg.n_step == 1:
            return self.update_window(put("window"), action, reward, discount, step)
        return self.update_window(
            put("n_step_window"),
            action,
            reward,
            discount,
            step,
            bootstrap=(put("bootstrap_obs"), put("return")),
            return_mask=put("return_mask"),
        )

    def update_window(
        self,
        window: torch.Tensor,
        action: torch.Tensor,
        reward: torch.Tensor,
        discount: torch.Tensor,
        step: int,
        bootstrap: tuple[torch.Tensor, torch.Tensor] | None = None,
        return_mask: torch.Tensor | None = None,
    ) -> dict[str, torch.Tensor]:
        """One gradient step on a batch already on the device (what :meth:`update` samples).

        ``window`` is uint8 ``(B, 4, C, H, W)``, frames t-2 .. t+1 (the triplet at t and, shifted
        by one frame, the one at t+1); ``action`` float ``(B, A)``; ``reward`` (r_{t+1}) and
        ``discount`` ``(B,)``; ``step`` the global environment step. ``bootstrap``: for n-step
        targets, the uint8 triplet to bootstrap from ``(B, 3, C, H, W)`` and the n-step return
        ``(B,)`` that replaces ``reward`` in the TD target (``FrameReplay.sample``'s
        ``bootstrap_obs`` and ``return``; ``discount`` then carries gamma^(m-1)); L_re and L_tran
        keep the one-step reward and frame t+1. ``return_mask`` (with ``bootstrap``): float
        ``(B, n)``, 1 for each step j < m of the n-step return (the replay's ``return_mask``);
        ``window`` then holds frames t-2 .. t+n (its ``n_step_window``) and Eq. 13's intrinsic
        reward of every state s_{t+j}, j < m, enters the target, discounted by gamma^j. Without
        it only r^i(s_t) does.

        The steps, each a method returning its metrics: :meth:`augment` (the RL views: with
        ``augmentation="shift"`` each view shifts a sample's frames by one random offset; the
        contrastive key: a random convolution of the view's frames (Eq. 3), or, with
        ``contrastive_view="shift"`` (CURL), an independent shift of the unshifted ones),
        :meth:`encode`, :meth:`td_target` (averaged over ``target_augmentations`` views),
        :meth:`update_critic` (L_Q averaged over ``critic_augmentations`` views and the
        auxiliary losses), :meth:`update_actor` every ``actor_update_every`` and
        :meth:`update_targets` every ``target_update_every`` gradient steps, then, with
        ``contrastive_step`` (CURL), :meth:`update_contrastive`.
        """
        cfg = self.config
        self.env_step = step = self._check_step(step, "update_window")
        self.check_batch(window, action, reward, discount, bootstrap, return_mask)
        steps = 1 if return_mask is None else return_mask.shape[1]
        self.check_window(window, steps)
        bootstrap_obs, n_return = bootstrap if bootstrap is not None else (None, reward)
        views = self.augment(window, bootstrap_obs)
        per_step = cfg.curiosity and steps > 1
        enc, following = self.encode(views, next_features=per_step)
        q_target, metrics = self.td_target(
            views, enc, following, reward, n_return, discount, return_mask, step
        )
        metrics.update(self.update_critic(views, enc, following, action, reward, q_target))
        if self.num_updates % cfg.actor_update_every == 0:
            metrics.update(self.update_actor(enc.state[: len(action)].detach(), step))
        if self.num_updates % cfg.target_update_every == 0:
            self.update_targets()
        if self.contrastive_optimizers:
            metrics.update(self.update_contrastive(views))
        self.num_updates += 1
        return metrics

    def check_batch(
        self,
        window: object,
        action: object,
        reward: object,
        discount: object,
        bootstrap: object,
        return_mask: object,
    ) -> None:
        """TypeError or ValueError naming the argument of :meth:`update_window` that is not the
        tensor it takes (type, dtype, shape against this agent's and the window's batch size):
        without this a wrong one fails deep in a layer, or broadcasts silently (a ``(B, 1)``
        reward against ``(B,)`` values)."""
        frames = ", ".join(map(str, self.frame_shape))
        check_tensor(window, "window", "uint8", f"(B, {self.config.num_frames + 1}, {frames})")
        if window.dim() != 5 or tuple(window.shape[2:]) != self.frame_shape:
            raise ValueError(
                f"update_window(window=...) must be uint8 (B, frames, {frames}) for this agent's "
                f"frames {self.frame_shape}, got {tuple(window.shape)}; pass FrameReplay.sample's "
                "'window' (channel-first, as SimounObservation gives them)"
            )
        size = window.shape[0]
        check_tensor(action, "action", "float", f"({size}, {self.action_dim})")
        what = f"the window holds {size} samples"
        check_shape(
            action, "action", (size, self.action_dim), f"{what}, actions of {self.action_dim}"
        )
        for name, value in (("reward", reward), ("discount", discount)):
            check_tensor(value, name, "float", f"({size},)")
            check_shape(value, name, (size,), f"one value per sample: {what}")
        if bootstrap is not None:
            if not (isinstance(bootstrap, tuple) and len(bootstrap) == 2):
                raise TypeError(
                    "update_window(bootstrap=...) must be a pair (bootstrap_obs, n_step_return) "
                    f"or None, got {type(bootstrap).__name__}; pass (batch['bootstrap_obs'], "
                    "batch['return']) of FrameReplay.sample"
                )
            obs, n_return = bootstrap
            want = (size, self.config.num_frames, *self.frame_shape)
            check_tensor(obs, "bootstrap[0]", "uint8", str(want))
            check_shape(obs, "bootstrap[0]", want, f"the triplets to bootstrap from: {what}")
            check_tensor(n_return, "bootstrap[1]", "float", f"({size},)")
            check_shape(n_return, "bootstrap[1]", (size,), f"one n-step return per sample: {what}")
        if return_mask is not None:
            check_tensor(return_mask, "return_mask", "float", f"({size}, n)")
            if return_mask.dim() != 2 or return_mask.shape[0] != size:
                raise ValueError(
                    f"update_window(return_mask=...) must be float ({size}, n), one row per "
                    f"sample of the window, got {tuple(return_mask.shape)}; pass "
                    "FrameReplay.sample's 'return_mask'"
                )

    def check_window(self, window: torch.Tensor, steps: int) -> None:
        """ValueError unless ``window`` holds the frames of a triplet and ``steps`` more."""
        k = self.config.num_frames
        if window.shape[1] != k + steps:
            raise ValueError(
                f"window holds {window.shape[1]} frames; with {steps} return step(s) it must hold "
                f"{k + steps} (frames t-{k - 1} .. t+{steps}): pass "
                "FrameReplay.sample's 'window', or its 'n_step_window' with 'return_mask'"
            )

    def augment(self, window: torch.Tensor, bootstrap_obs: torch.Tensor | None) -> Views:
        """The augmented inputs of one update, in this order of random draws: the
        max(critic_augmentations, target_augmentations) RL views, each the window and the
        bootstrap triplet under one random shift per sample (or unchanged with augmentation
        "none"); with ``independent_next_shift``, the window alone, then the target views'
        bootstrap triplets each under a shift of its own; then the contrastive key's view."""
        cfg = self.config
        k, length = cfg.num_frames, window.shape[1]
        independent = self.independent_next_shift
        frames = window
        if bootstrap_obs is not None and not independent:
            frames = torch.cat([window, bootstrap_obs], dim=1)
        views = [self.augment_view(frames) for _ in range(self.view_count)]
        if independent:
            following = window[:, 1 : k + 1] if bootstrap_obs is None else bootstrap_obs
            next_obs = [self.augment_view(following) for _ in range(self.view_count)]
        else:
            next_obs = [
                v[:, length:] if bootstrap_obs is not None else v[:, 1 : k + 1] for v in views
            ]
        windows = [v[:, :length] for v in views]
        key = (
            self.contrastive_key(window[:, :k], windows[0][:, :k])
            if self.contrastive_key is not None
            else None
        )
        shared = (
            0
            if bootstrap_obs is not None or independent
            else min(cfg.target_augmentations, cfg.critic_augmentations)
        )
        return Views(windows, next_obs[: cfg.target_augmentations], shared, key)

    def shifted_key(self, triplet: torch.Tensor, first_view: torch.Tensor) -> torch.Tensor:
        """CURL's contrastive positive: the unshifted triplet at t under a shift of its own."""
        return self.encoder.key_frames(random_shift(triplet, self.shift_pad))

    def random_conv_key(self, triplet: torch.Tensor, first_view: torch.Tensor) -> torch.Tensor:
        """Eq. 3's contrastive positive: a random convolution of the first RL view's triplet
        at t."""
        return random_conv(self.encoder.key_frames(first_view), self.config.random_conv_kernel)

    def encode(self, views: Views, next_features: bool = False) -> tuple[Encoding, Encoding | None]:
        """The online encoder on the critic views stacked into one batch of M*B: the state at t
        with gradient and, when the target, L_tran or per-step curiosity reads it, at t+1
        without (each unique frame through each path once; per-frame f^a at t+1 when
        ``next_features``)."""
        check_bool(next_features, "encode(next_features=...)")
        cfg = self.config
        k, views_m = cfg.num_frames, cfg.critic_augmentations
        windows = [w[:, : k + 1] for w in views.windows[:views_m]]
        stacked = windows[0] if views_m == 1 else torch.cat(windows)
        if views.shared or next_features or self.transition is not None:
            return self.encoder.encode_transition(
                stacked, frame_features=cfg.curiosity, next_frame_features=next_features
            )
        return self.encoder(stacked[:, :k], frame_features=cfg.curiosity), None

    def td_target(
        self,
        views: Views,
        enc: Encoding,
        following: Encoding | None,
        reward: torch.Tensor,
        n_return: torch.Tensor,
        discount: torch.Tensor,
        return_mask: torch.Tensor | None,
        step: int,
    ) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
        """The target of Eq. 9, ``(B, 1)``, without gradient: the (n-step) return plus Eq. 13's
        intrinsic return, plus gamma * discount * V of the next state (the actor's
        :meth:`next_value`), V averaged over the target views (DrQ's K)."""
        cfg = self.config
        step = self._check_step(step, "td_target")
        with torch.no_grad():
            policy_state, value_state = self.next_states(views, following)
            value = self.actor.next_value(
                self.critic_target, policy_state, value_state, self.alpha, step
            )
            value = value.unflatten(0, (cfg.target_augmentations, -1)).mean(0)
            metrics = {}
            if cfg.curiosity:
                r_i = self.intrinsic_reward(views, enc, following, reward, return_mask, step)
                n_return = n_return + r_i
                metrics["intrinsic_reward"] = r_i.mean()
            return td_target(n_return, discount, cfg.discount, value), metrics

    def next_states(
        self, views: Views, following: Encoding | None
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """The next state of each target view, stacked ``(K*B, D)``: as the actor sees it (the
        online encoder; the critic views' t+1 states are reused where they are the same frames)
        and as the target Q heads read it (``next_state_encoder``)."""
        rows = views.shared * len(views.windows[0])
        parts = [following.state[:rows]] if views.shared else []
        if len(views.next_obs) > views.shared:
            parts.append(self.encoder(torch.cat(views.next_obs[views.shared :])).state)
        policy_state = parts[0] if len(parts) == 1 else torch.cat(parts)
        if self.value_encoder is None:
            return policy_state, policy_state
        return policy_state, self.value_encoder(torch.cat(views.next_obs)).state

    def intrinsic_reward(
        self,
        views: Views,
        enc: Encoding,
        following: Encoding | None,
        extrinsic: torch.Tensor,
        return_mask: torch.Tensor | None,
        step: int,
    ) -> torch.Tensor:
        """Eq. 13 for each step of the return, ``(B,)``: sum_j gamma^j r^i(s_{t+j}) over the steps
        j < m in ``return_mask`` (j = 0 alone without it), each r^i on the online features of the
        first view's triplet ending at t+j (s_t and s_{t+1} from the encoding, later ones
        encoded here), without gradient. The running maxima are raised with the batch first
        (the distances of steps past the episode's end count as 0)."""
        cfg = self.config
        step = self._check_step(step, "intrinsic_reward")
        batch = len(extrinsic)
        steps = 1 if return_mask is None else return_mask.shape[1]
        motion, appearance = [enc.motion[:batch]], [enc.appearance[:batch]]
        if steps > 1:
            motion.append(following.motion[:batch])
            appearance.append(following.appearance[:batch])
        if steps > 2:
            k = cfg.num_frames
            ahead = [views.windows[0][:, j : j + k] for j in range(2, steps)]
            later = self.encoder(torch.cat(ahead), frame_features=True)
            motion.append(later.motion)
            appearance.append(later.appearance)
        distance = consistency_distance(torch.cat(motion).detach(), torch.cat(appearance))
        mask = extrinsic.new_ones(1, batch) if return_mask is None else return_mask.T
        distance = distance.unflatten(0, (steps, batch)) * mask
        self.running_max.update(extrinsic, distance)
        r_i = consistency_reward(
            distance,
            step,
            self.running_max.r_e_max,
            self.running_max.r_i_max,
            cfg.curiosity_scale,
            cfg.curiosity_decay,
        )
        return intrinsic_return(r_i, mask, cfg.discount)

    def update_critic(
        self,
        views: Views,
        enc: Encoding,
        following: Encoding | None,
        action: torch.Tensor,
        reward: torch.Tensor,
        q_target: torch.Tensor,
    ) -> dict[str, torch.Tensor]:
        """Eq. 14 without L_pi, one optimiser step of the encoder and its heads: L_Q (Eq. 9) over
        the M critic views (the mean, as DrQ's paper writes it; its code sums the views, the
        same step under Adam), L_tran, L_con and L_re on the first view."""
        cfg = self.config
        batch, views_m = len(action), cfg.critic_augmentations
        actions = action if views_m == 1 else action.repeat(views_m, 1)
        targets = q_target if views_m == 1 else q_target.repeat(views_m, 1)
        q1, q2 = self.critic(enc.state, actions)
        l_q = critic_loss(q1, q2, targets)
        l_tran = (
            transition_loss(
                self.transition(self.dynamics(enc)[:batch], action),
                self.dynamics(following)[:batch],
            )
            if self.transition is not None
            else None
        )
        l_con = None
        if views.key is not None and not self.contrastive_optimizers:
            with torch.no_grad():
                key = self.encoder_target.encode_key(views.key)
            l_con = contrastive_loss(enc.anchor[:batch], key, self.similarity.weight)
        l_re = (
            reward_loss(self.reward_model(enc.state[:batch], action), reward)
            if self.reward_model is not None
            else None
        )
        loss = total_loss(
            l_q,
            l_tran,
            l_con,
            l_re,
            cfg.transition_weight,
            cfg.contrastive_weight,
            cfg.reward_weight,
        )
        self.critic_optimizer.zero_grad(set_to_none=True)
        loss.backward()
        self.critic_optimizer.step()

        metrics = {"critic_loss": l_q.detach(), "q": q1.detach().mean()}
        for name, term in (
            ("transition_loss", l_tran),
            ("contrastive_loss", l_con),
            ("reward_loss", l_re),
        ):
            if term is not None:
                metrics[name] = term.detach()
        return metrics

    def update_contrastive(self, views: Views) -> dict[str, torch.Tensor]:
        """L_con (Eq. 3) in a step of its own, after the critic, actor and EMA updates (CURL's
        update_cpc in curl_sac.py): the anchor encoded again by the updated online encoder from
        the first view's triplet at t, the key by the updated EMA encoder; one gradient, then
        CURL's two Adam steps (the encoder alone, then the encoder and W)."""
        anchor = self.encoder(views.windows[0][:, : self.config.num_frames]).anchor
        with torch.no_grad():
            key = self.encoder_target.encode_key(views.key)
        loss = contrastive_loss(anchor, key, self.similarity.weight)
        for optimizer in self.contrastive_optimizers:
            optimizer.zero_grad(set_to_none=True)
        loss.backward()
        for optimizer in self.contrastive_optimizers:
            optimizer.step()
        return {"contrastive_loss": loss.detach()}

    def dynamics(self, enc: Encoding) -> torch.Tensor:
        """What L_tran predicts the next value of: f^m with a motion path, else the state."""
        return enc.motion if self.motion_path else enc.state

    def update_actor(self, state: torch.Tensor, step: int | None = None) -> dict[str, torch.Tensor]:
        """The actor's loss (Eq. 11 for SAC's) on detached features, then the temperature when
        the actor has one; the critic is held fixed. ``step``: the global env step (None: that
        of the latest update)."""
        step = self._check_step(step, "update_actor")
        self.critic.requires_grad_(False)
        l_pi, log_prob, extra = self.actor.loss(self.critic, state, self.alpha, step)
        self.critic.requires_grad_(True)
        self.actor_optimizer.zero_grad(set_to_none=True)
        l_pi.backward()
        self.actor_optimizer.step()
        metrics = {"actor_loss": l_pi.detach()}
        if self.log_alpha is not None:
            l_alpha = temperature_loss(self.log_alpha, log_prob, self.target_entropy)
            self.alpha_optimizer.zero_grad(set_to_none=True)
            l_alpha.backward()
            self.alpha_optimizer.step()
            metrics.update(alpha=self.alpha.detach(), entropy=-log_prob.detach().mean())
        return {**metrics, **extra}

    def update_targets(self) -> None:
        """EMA: target <- target + tau (online - target), the encoder (when anything reads its
        target) and the critic (Q heads and, with ``separate_trunks``, its trunk) at their own
        tau."""
        pairs = [(self.critic, self.critic_target, self.config.critic_tau)]
        if self.reads_encoder_target:
            pairs.append((self.encoder, self.encoder_target, self.config.encoder_tau))
        with torch.no_grad():
            for online, target, tau in pairs:
                torch._foreach_lerp_(list(target.parameters()), list(online.parameters()), tau)

    # -- checkpoints ---------------------------------------------------------------------------

    def modules(self) -> dict[str, torch.nn.Module]:
        """Every network, by state-dict key."""
        nets = {
            "encoder": self.encoder,
            "encoder_target": self.encoder_target,
            "critic": self.critic,
            "critic_target": self.critic_target,
            "actor": self.actor,
            "reward_model": self.reward_model,
            "similarity": self.similarity,
            "transition": self.transition,
        }
        return {name: net for name, net in nets.items() if net is not None}

    def state_dict(self) -> dict:
        """Networks, targets, optimisers, temperature (when the actor has one), running maxima,
        update counter, env step, config."""
        state = {name: net.state_dict() for name, net in self.modules().items()}
        state.update(
            critic_optimizer=self.critic_optimizer.state_dict(),
            actor_optimizer=self.actor_optimizer.state_dict(),
            running_max=self.running_max.state_dict(),
            num_updates=self.num_updates,
            env_step=self.env_step,
            config=asdict(self.config),
        )
        if self.log_alpha is not None:
            state.update(
                log_alpha=self.log_alpha.detach().clone(),
                alpha_optimizer=self.alpha_optimizer.state_dict(),
            )
        if self.contrastive_optimizers:
            state["contrastive_optimizers"] = [o.state_dict() for o in self.contrastive_optimizers]
        return state

    def check_state(self, state: dict) -> None:
        """A ValueError (TypeError for no dict) that names what of ``state`` does not fit this
        agent: a part missing, a part this agent has no network for, a network or optimizer
        state of another shape, a counter or running maximum that is no number, with the config
        fields that differ; nothing is loaded."""
        if not isinstance(state, Mapping):
            raise TypeError(
                f"state must be the dict SimounAgent.state_dict() returns, got "
                f"{type(state).__name__}; e.g. agent.load_state_dict(other.state_dict())"
            )
        nets = self.modules()
        required = [*nets, "critic_optimizer", "actor_optimizer", "running_max", "num_updates"]
        if self.log_alpha is not None:
            required += ["log_alpha", "alpha_optimizer"]
        if self.contrastive_optimizers:
            required.append("contrastive_optimizers")
        problems = []
        missing = [key for key in required if key not in state]
        if missing:
            problems.append(f"it lacks {', '.join(missing)}")
        extra = [
            key
            for key in ("reward_model", "similarity", "transition", "contrastive_optimizers")
            if key in state and key not in required
        ]
        if extra:
            problems.append(f"it holds {', '.join(extra)}, which this agent has none of")
        for name, net in nets.items():
            if name in state:
                problems += module_problems(name, net, state[name])
        problems += self._other_state_problems(state)
        if not problems:
            return
        config = state.get("config")
        differ = (
            [
                f"{key} {config[key]!r} there, {value!r} here"
                for key, value in asdict(self.config).items()
                if key in config and config[key] != value
            ]
            if isinstance(config, Mapping)
            else []
        )
        more = len(problems) - 4
        shown = "; ".join(problems[:4]) + (f"; {more} more" if more > 0 else "")
        raise ValueError(
            f"this state does not fit this agent: {shown}"
            + (f" (the state's config differs: {', '.join(differ)})" if differ else "")
            + ". The state must come from SimounAgent.state_dict() of an agent of the same "
            f"config, frame_shape {self.frame_shape} and action_dim {self.action_dim}; build "
            "this agent with the config the state was saved with. Nothing was loaded"
        )

    def _other_state_problems(self, state: Mapping) -> list[str]:
        """What of ``state`` besides the networks does not fit: the optimizers, the
        temperature, the running maxima and the counters (each only where present: a missing
        one is named by :meth:`check_state`)."""
        optimizers = {
            "critic_optimizer": self.critic_optimizer,
            "actor_optimizer": self.actor_optimizer,
        }
        if self.log_alpha is not None:
            optimizers["alpha_optimizer"] = self.alpha_optimizer
        problems = []
        for name, optimizer in optimizers.items():
            if name in state:
                problems += optimizer_problems(name, optimizer, state[name])
        if self.contrastive_optimizers and "contrastive_optimizers" in state:
            saved = state["contrastive_optimizers"]
            if not isinstance(saved, (list, tuple)) or len(saved) != len(
                self.contrastive_optimizers
            ):
                problems.append(
                    f"its contrastive_optimizers is {saved!r:.60}, not a list of "
                    f"{len(self.contrastive_optimizers)} optimizer states"
                )
            else:
                for i, (optimizer, one) in enumerate(
                    zip(self.contrastive_optimizers, saved, strict=True)
                ):
                    problems += optimizer_problems(f"contrastive_optimizers[{i}]", optimizer, one)
        if self.log_alpha is not None and "log_alpha" in state:
            problems += tensor_problems("log_alpha", self.log_alpha, state["log_alpha"])
        if "running_max" in state:
            saved = RunningMax.state_problems(state["running_max"])
            problems += [f"its running_max: {problem}" for problem in saved]
        for name in ("num_updates", "env_step"):
            if name in state:
                problems += count_problems(name, state[name])
        return problems

    def to(self, device: str | torch.device) -> SimounAgent:
        """The agent itself when it is on ``device`` already (as a torch module's ``to``);
        otherwise refused with a TypeError that says how to move an agent: its device is chosen
        when it is built (its optimizers, generators and running maxima live there too), so
        ``SimounAgent(..., device=device)`` and :meth:`load_state_dict` move it whole."""
        if same_device(device, self.device):
            return self
        raise TypeError(
            f"SimounAgent.to({device!r}): an agent's device is chosen when it is built, not "
            f"moved like a torch module (this one is on {self.device}). Build it there, "
            f"SimounAgent(frame_shape, action_dim, config, device={str(device)!r}), and load "
            "the trained weights into it: moved.load_state_dict(agent.state_dict())."
        )

    def cpu(self) -> SimounAgent:
        """The agent itself on the CPU; elsewhere refused as :meth:`to` is."""
        return self.to("cpu")

    def cuda(self) -> SimounAgent:
        """The agent itself on the GPU; elsewhere refused as :meth:`to` is."""
        return self.to("cuda")

    def load_state_dict(self, state: dict) -> None:
        """Restore what :meth:`state_dict` saved (into an agent built with the same config,
        frame shape and action_dim); a state that does not fit is refused by
        :meth:`check_state` before anything is loaded."""
        self.check_state(state)
        for name, net in self.modules().items():
            net.load_state_dict(state[name])
        if self.log_alpha is not None:
            with torch.no_grad():
                self.log_alpha.copy_(state["log_alpha"])
            self.alpha_optimizer.load_state_dict(state["alpha_optimizer"])
        self.critic_optimizer.load_state_dict(state["critic_optimizer"])
        self.actor_optimizer.load_state_dict(state["actor_optimizer"])
        for optimizer, saved in zip(
            self.contrastive_optimizers, state.get("contrastive_optimizers", ()), strict=True
        ):
            optimizer.load_state_dict(saved)
        self.running_max.load_state_dict(state["running_max"])
        self.num_updates = int(state["num_updates"])
        # saved since the deterministic actor; older checkpoints hold only Gaussian actors,
        # which do not read it
        self.env_step = int(state.get("env_step", 0))
