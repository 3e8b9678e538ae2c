"""SAC actor and twin-Q critic heads on the encoder's state vector (Sec. 3.3)."""

from __future__ import annotations

import math

import torch
from torch import nn


def mlp(in_dim: int, hidden_dim: int, out_dim: int, hidden_layers: int = 2) -> nn.Sequential:
    """Linear-ReLU stack with ``hidden_layers`` hidden layers of ``hidden_dim`` units."""
    layers: list[nn.Module] = []
    for i in range(hidden_layers):
        layers += [nn.Linear(in_dim if i == 0 else hidden_dim, hidden_dim), nn.ReLU()]
    layers.append(nn.Linear(hidden_dim, out_dim))
    return nn.Sequential(*layers)


class Actor(nn.Module):
    """Tanh-squashed Gaussian policy pi(a | f_t) with log-std bounded by a tanh rescale (SAC-AE)."""

    def __init__(
        self,
        repr_dim: int,
        action_dim: int,
        hidden_dim: int,
        log_std_min: float,
        log_std_max: float,
    ) -> None:
        super().__init__()
        self.trunk = mlp(repr_dim, hidden_dim, 2 * action_dim)
        self.log_std_min = log_std_min
        self.log_std_max = log_std_max

    def forward(
        self, state: torch.Tensor, deterministic: bool = False
    ) -> tuple[torch.Tensor, torch.Tensor]:
        """Return a squashed action and its log-probability ``(B, 1)`` (of the sampled action)."""
        mu, log_std = self.trunk(state).chunk(2, dim=-1)
        log_std = torch.tanh(log_std)
        log_std = self.log_std_min + 0.5 * (self.log_std_max - self.log_std_min) * (log_std + 1)
        noise = torch.zeros_like(mu) if deterministic else torch.randn_like(mu)
        pre_tanh = mu + noise * log_std.exp()
        action = torch.tanh(pre_tanh)
        log_prob = (-0.5 * noise.pow(2) - log_std).sum(-1, keepdim=True)
        log_prob = log_prob - 0.5 * math.log(2 * math.pi) * mu.shape[-1]
        log_prob = log_prob - torch.log1p(-action.pow(2) + 1e-6).sum(-1, keepdim=True)
        return action, log_prob


class Critic(nn.Module):
    """Twin Q heads Q1, Q2 on ``[f_t, a_t]`` (clipped double-Q)."""

    def __init__(self, repr_dim: int, action_dim: int, hidden_dim: int) -> None:
        super().__init__()
        self.q1 = mlp(repr_dim + action_dim, hidden_dim, 1)
        self.q2 = mlp(repr_dim + action_dim, hidden_dim, 1)

    def forward(
        self, state: torch.Tensor, action: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor]:
        x = torch.cat([state, action], dim=-1)
        return self.q1(x), self.q2(x)
