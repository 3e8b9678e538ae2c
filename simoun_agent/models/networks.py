"""Auxiliary heads of Simoun: transition model G (Eq. 2), reward model R (Eq. 7), contrastive W."""

from __future__ import annotations

import torch
from torch import nn

from simoun_agent.models.sac import mlp


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
    """Score q W k^T between anchors and keys; W starts as the identity, i.e. Eq. 3's plain inner
    product, and is learned as in CURL."""

    def __init__(self, feature_dim: int) -> None:
        super().__init__()
        self.weight = nn.Parameter(torch.eye(feature_dim))

    def forward(self, anchor: torch.Tensor, key: torch.Tensor) -> torch.Tensor:
        return anchor @ self.weight @ key.T
