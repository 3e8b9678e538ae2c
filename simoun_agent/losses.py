"""Every loss of Simoun, one function per equation of the paper (Sec. 3).

Each takes tensors only: the caller runs the networks (G, R, the critic, the policy) and
passes their outputs, so a function here holds its equation's arithmetic and nothing else.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F


def transition_loss(predicted_next_motion: torch.Tensor, next_motion: torch.Tensor) -> torch.Tensor:
    """Eq. 2: || G(f^m_t, a_t) - f^m_{t+1} ||_2^2, batch mean, given G's prediction
    ``(B, D)``; the target f^m_{t+1} is detached."""
    return (predicted_next_motion - next_motion.detach()).pow(2).sum(-1).mean()


def contrastive_loss(
    anchor: torch.Tensor, key: torch.Tensor, weight: torch.Tensor | None = None
) -> torch.Tensor:
    """Eq. 3: InfoNCE over the batch. Row i scores anchor i against every key; key i (the
    augmented view of the same frame, from the momentum encoder, detached) is the positive and
    the other K-1 keys of the batch are the negatives. ``weight`` is the ``(D, D)`` matrix W of
    CURL's bilinear score anchor W key^T (the identity = Eq. 3's inner product); ``None`` uses
    the plain inner product."""
    key = key.detach()
    logits = anchor @ weight @ key.T if weight is not None else anchor @ key.T
    logits = logits - logits.amax(dim=1, keepdim=True).detach()
    labels = torch.arange(anchor.shape[0], device=anchor.device)
    return F.cross_entropy(logits, labels)


def reward_loss(predicted_reward: torch.Tensor, reward: torch.Tensor) -> torch.Tensor:
    """Eq. 7: (R(f_t, a_t) - r^e_{t+1})^2, batch mean, given R's prediction ``(B,)``, against
    the extrinsic reward only."""
    return F.mse_loss(predicted_reward, reward)


def soft_value(
    next_q1: torch.Tensor, next_q2: torch.Tensor, next_log_prob: torch.Tensor, alpha: torch.Tensor
) -> torch.Tensor:
    """Eq. 10: V(o_{t+1}) = min(Qbar_1, Qbar_2)(o_{t+1}, a_{t+1}) - alpha log pi(a_{t+1}|.)."""
    return torch.min(next_q1, next_q2) - alpha * next_log_prob


def deterministic_value(next_q1: torch.Tensor, next_q2: torch.Tensor) -> torch.Tensor:
    """DrQ-v2's V(o_{t+1}) = min(Qbar_1, Qbar_2)(o_{t+1}, a~_{t+1}) at the target-smoothed action
    a~ (clipped noise, Fujimoto et al. 2018): no entropy term."""
    return torch.min(next_q1, next_q2)


def intrinsic_return(intrinsic: torch.Tensor, mask: torch.Tensor, gamma: float) -> torch.Tensor:
    """Eq. 13's part of an n-step target: sum_j gamma^j r^i(s_{t+j}) over the steps j < m of the
    return. ``intrinsic`` and ``mask`` ``(n, B)`` (row j: r^i of s_{t+j}, and 1 where step j
    lies in the episode); returns ``(B,)``. With n = 1 it is r^i(s_t), the one-step target's."""
    weights = gamma ** torch.arange(len(intrinsic), dtype=intrinsic.dtype, device=intrinsic.device)
    return (weights[:, None] * mask * intrinsic).sum(0)


def td_target(
    reward: torch.Tensor, discount: torch.Tensor, gamma: float, value: torch.Tensor
) -> torch.Tensor:
    """The target of Eq. 9: r_t + gamma * V(o_{t+1}); ``discount`` is 0 where the episode
    terminated (no bootstrap) and 1 otherwise (truncation bootstraps). Shapes ``(B,)``,
    V ``(B, 1)``."""
    return (reward + gamma * discount * value.squeeze(-1)).unsqueeze(-1)


def critic_loss(q1: torch.Tensor, q2: torch.Tensor, target: torch.Tensor) -> torch.Tensor:
    """Eq. 9: the soft Bellman error of both Q heads, (Q - target)^2, batch mean each."""
    target = target.detach()
    return F.mse_loss(q1, target) + F.mse_loss(q2, target)


def actor_loss(
    alpha: torch.Tensor, log_prob: torch.Tensor, q1: torch.Tensor, q2: torch.Tensor
) -> torch.Tensor:
    """Eq. 11: E[alpha log pi(a_t | o_t) - min(Q1, Q2)(o_t, a_t)], alpha held fixed."""
    return (alpha.detach() * log_prob - torch.min(q1, q2)).mean()


def deterministic_actor_loss(q1: torch.Tensor, q2: torch.Tensor) -> torch.Tensor:
    """DrQ-v2's policy loss: -E[min(Q1, Q2)(o_t, a~_t)] at the noisy action a~_t (DDPG with
    clipped double Q), the critic held fixed; no entropy term."""
    return -torch.min(q1, q2).mean()


def temperature_loss(
    log_alpha: torch.Tensor, log_prob: torch.Tensor, target_entropy: float
) -> torch.Tensor:
    """SAC's automatic temperature: E[alpha (-log pi - H_target)], the policy held fixed."""
    return (log_alpha.exp() * (-log_prob - target_entropy).detach()).mean()


def total_loss(
    critic: torch.Tensor,
    transition: torch.Tensor | None,
    contrastive: torch.Tensor | None,
    reward: torch.Tensor | None,
    transition_weight: float = 1.0,
    contrastive_weight: float = 1.0,
    reward_weight: float = 1.0,
) -> torch.Tensor:
    """Eq. 14 without its L_pi term: L_Q + w_tran L_tran + w_con L_con + w_re L_re, the loss that
    trains the encoder. L_pi trains only the actor (it sees detached features), so it is stepped
    on its own (:func:`actor_loss`). ``None`` terms are absent for the chosen encoder."""
    loss = critic
    for term, weight in (
        (transition, transition_weight),
        (contrastive, contrastive_weight),
        (reward, reward_weight),
    ):
        if term is not None and weight != 0:
            loss = loss + weight * term
    return loss
