"""SAC actor and twin-Q critic heads on the encoder's state vector (Sec. 3.3)."""

from __future__ import annotations

import math

import torch
from torch import nn

from simoun_agent.losses import actor_loss, soft_value
from simoun_agent.models.networks import ActorNet, mlp, state_trunk


class Actor(ActorNet):
    """Tanh-squashed Gaussian policy pi(a | f_t) with log-std bounded by a tanh rescale (SAC-AE).

    The ``"gaussian"`` entry of :data:`simoun_agent.models.actors.ACTORS`: it explores by
    sampling, and its TD target and loss carry SAC's entropy term with the learned temperature
    alpha. ``step`` (the exploration schedule of other actors) is unused. ``trunk_dim``: its own
    trunk on the state (:func:`~simoun_agent.models.networks.state_trunk`), or None.
    """

    def __init__(
        self,
        repr_dim: int,
        action_dim: int,
        hidden_dim: int,
        log_std_min: float,
        log_std_max: float,
        trunk_dim: int | None = None,
    ) -> None:
        super().__init__(repr_dim, hidden_dim, 2 * action_dim, trunk_dim)
        self.log_std_min = log_std_min
        self.log_std_max = log_std_max

    def forward(
        self, state: torch.Tensor, deterministic: bool = False
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Return a squashed action and its log-probability ``(B, 1)`` (of the sampled action)."""
        mu, log_std = self.outputs(state).chunk(2, dim=-1)
        log_std = torch.tanh(log_std)
        log_std = self.log_std_min + 0.5 * (self.log_std_max - self.log_std_min) * (log_std + 1)
        noise = torch.zeros_like(mu) if deterministic else torch.randn_like(mu)
        pre_tanh = mu + noise * log_std.exp()
        action = torch.tanh(pre_tanh)
        log_prob = (-0.5 * noise.pow(2) - log_std).sum(-1, keepdim=True)
        log_prob = log_prob - 0.5 * math.log(2 * math.pi) * mu.shape[-1]
        log_prob = log_prob - torch.log1p(-action.pow(2) + 1e-6).sum(-1, keepdim=True)
        return action, log_prob

    def act(self, state: torch.Tensor, deterministic: bool, step: int) -> torch.Tensor:
        """The action to take: a sample of pi, or its mode when ``deterministic``."""
        return self(state, deterministic)[0]

    def next_value(
        self,
        critic_target: Critic,
        policy_state: torch.Tensor,
        value_state: torch.Tensor,
        alpha: torch.Tensor,
        step: int,
    ) -> torch.Tensor:
        """Eq. 10 for the TD target: a_{t+1} ~ pi(. | policy_state), Q-bar read on
        ``value_state`` (the same state, or the target encoder's)."""
        action, log_prob = self(policy_state)
        return soft_value(*critic_target(value_state, action), log_prob, alpha)

    def loss(
        self, critic: Critic, state: torch.Tensor, alpha: torch.Tensor, step: int
    ) -> tuple[torch.Tensor, torch.Tensor, dict[str, torch.Tensor]]:
        """Eq. 11, with log pi of the sampled actions for the temperature loss."""
        action, log_prob = self(state)
        return actor_loss(alpha, log_prob, *critic(state, action)), log_prob, {}


class Critic(nn.Module):
    """Twin Q heads Q1, Q2 on ``[f_t, a_t]`` (clipped double-Q). ``trunk_dim``: the critic's own
    trunk on the state, shared by both heads and part of the critic's EMA target (DrQ-v2's
    Critic; :func:`~simoun_agent.models.networks.state_trunk`), or None."""

    def __init__(
        self, repr_dim: int, action_dim: int, hidden_dim: int, trunk_dim: int | None = None
    ) -> None:
        super().__init__()
        self.trunk, in_dim = state_trunk(repr_dim, trunk_dim)
        self.q1 = mlp(in_dim + action_dim, hidden_dim, 1)
        self.q2 = mlp(in_dim + action_dim, hidden_dim, 1)

    def forward(
        self, state: torch.Tensor, action: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor]:
        x = torch.cat([self.trunk(state), action], dim=-1)
        return self.q1(x), self.q2(x)
