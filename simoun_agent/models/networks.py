"""Auxiliary heads of Simoun: transition model G (Eq. 2), reward model R (Eq. 7), contrastive W."""

from __future__ import annotations

import torch
from torch import nn


def mlp(in_dim: int, hidden_dim: int, out_dim: int, hidden_layers: int = 2) -> nn.Sequential:
    """Linear-ReLU stack with ``hidden_layers`` hidden layers of ``hidden_dim`` units."""
    layers: list[nn.Module] = []
    for i in range(hidden_layers):
        layers += [nn.Linear(in_dim if i == 0 else hidden_dim, hidden_dim), nn.ReLU()]
    layers.append(nn.Linear(hidden_dim, out_dim))
    return nn.Sequential(*layers)


def state_trunk(repr_dim: int, trunk_dim: int | None) -> tuple[nn.Module, int]:
    """The trunk an actor or a critic puts on the encoder's state, and its output size: DrQ-v2's
    Linear -> LayerNorm -> Tanh of ``trunk_dim`` units (the trunk of Actor and Critic in
    drqv2.py), or, for ``None``, none (the identity on the ``repr_dim`` state)."""
    if trunk_dim is None:
        return nn.Identity(), repr_dim
    layers = nn.Sequential(nn.Linear(repr_dim, trunk_dim), nn.LayerNorm(trunk_dim), nn.Tanh())
    return layers, trunk_dim


class ActorNet(nn.Module):
    """Base of the actors: the actor's own :func:`state_trunk` on the encoder's state, then an
    :func:`mlp` of two hidden layers to ``out_dim`` raw outputs (:meth:`outputs`)."""

    def __init__(self, repr_dim: int, hidden_dim: int, out_dim: int, trunk_dim: int | None) -> None:
        super().__init__()
        self.state_trunk, in_dim = state_trunk(repr_dim, trunk_dim)
        self.trunk = mlp(in_dim, hidden_dim, out_dim)

    def outputs(self, state: torch.Tensor) -> torch.Tensor:
        """The network's raw outputs on ``state`` ``(B, repr_dim)``."""
        return self.trunk(self.state_trunk(state))


class TransitionModel(nn.Module):
    """G(f^m_t, a_t): two FC layers predicting the next motion feature f^m_{t+1} (Eq. 2)."""

    def __init__(self, feature_dim: int, action_dim: int, hidden_dim: int) -> None:
        super().__init__()
        self.net = mlp(feature_dim + action_dim, hidden_dim, feature_dim, hidden_layers=1)

    def forward(self, motion: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat([motion, action], dim=-1))


class RewardModel(nn.Module):
    """R(f_t, a_t): two FC layers predicting the extrinsic reward r_{t+1} (Eq. 7)."""

    def __init__(self, repr_dim: int, action_dim: int, hidden_dim: int) -> None:
        super().__init__()
        self.net = mlp(repr_dim + action_dim, hidden_dim, 1, hidden_layers=1)

    def forward(self, state: torch.Tensor, action: torch.Tensor) -> torch.Tensor:
        return self.net(torch.cat([state, action], dim=-1)).squeeze(-1)


class BilinearSimilarity(nn.Module):
    """The learned W of CURL's score q W k^T between anchors and keys (the score itself is
    :func:`simoun_agent.losses.contrastive_loss`, given ``weight``). W starts as the identity
    (``init="identity"``: Eq. 3's plain inner product) or uniform on [0, 1) (``"uniform"``: CURL's
    ``torch.rand`` in curl_sac.py's CURL module)."""

    def __init__(self, feature_dim: int, init: str = "identity") -> None:
        super().__init__()
        identity = init == "identity"
        start = torch.eye(feature_dim) if identity else torch.rand(feature_dim, feature_dim)
        self.weight = nn.Parameter(start)
