"""The actors the agent can train, by ``AgentConfig.actor`` name: SAC's Gaussian policy and
DrQ-v2's deterministic policy with scheduled exploration noise.

Each actor is a module on the encoder's state vector with three methods the agent calls, so the
agent holds no branch on the actor's kind:

``act(state, deterministic, step)``
    the action to take (``deterministic``: evaluation; ``step``: the global env step)
``next_value(critic_target, policy_state, value_state, alpha, step)``
    V(o_{t+1}) of the TD target: the next action from ``policy_state`` (the online encoder's),
    the target Q heads read on ``value_state``
``loss(critic, state, alpha, step)``
    ``(policy loss, log pi or None, metrics)``; the log-probabilities train the temperature

and its :class:`ActorEntry` says whether it has a temperature (SAC's learned alpha).

Example:
    >>> import torch
    >>> from simoun_agent.config import AgentConfig
    >>> actor = make_actor(AgentConfig(actor="deterministic"), repr_dim=8, action_dim=2)
    >>> actor.std(0), actor.std(10**9)  # DrQ-v2's linear schedule, 1.0 down to 0.1
    (1.0, 0.1)
    >>> actor.act(torch.zeros(3, 8), deterministic=True, step=0).shape
    torch.Size([3, 2])
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch import nn

from simoun_agent.config import AgentConfig
from simoun_agent.losses import deterministic_actor_loss, deterministic_value
from simoun_agent.models.networks import ActorNet
from simoun_agent.models.sac import Actor, Critic


def exploration_std(step: int, start: float, end: float, duration: int) -> float:
    """DrQ-v2's ``linear(start, end, duration)`` schedule: ``start`` at step 0, ``end`` from step
    ``duration`` on, linear in between."""
    progress = min(max(step, 0) / duration, 1.0)
    return (1.0 - progress) * start + progress * end


class DeterministicActor(ActorNet):
    """DrQ-v2's policy (Yarats et al. 2022): a = tanh(mu(f_t)), no entropy and no temperature.

    It explores with Gaussian noise whose std follows :func:`exploration_std` of the global env
    step; the TD target and the policy loss read the critic at ``mu + clip(noise, +-noise_clip)``
    (target policy smoothing, Fujimoto et al. 2018), the action kept in [-1, 1] by a clamp whose
    gradient is the identity (DrQ-v2's TruncatedNormal). ``trunk_dim``: its own trunk on the
    state (DrQ-v2's Actor.trunk; :func:`~simoun_agent.models.networks.state_trunk`), or None.
    """

    def __init__(
        self,
        repr_dim: int,
        action_dim: int,
        hidden_dim: int,
        std_start: float,
        std_end: float,
        std_steps: int,
        noise_clip: float,
        trunk_dim: int | None = None,
    ) -> None:
        super().__init__(repr_dim, hidden_dim, action_dim, trunk_dim)
        self.schedule = (std_start, std_end, std_steps)
        self.noise_clip = noise_clip

    def forward(self, state: torch.Tensor) -> torch.Tensor:
        """The deterministic action mu(f_t) in [-1, 1]."""
        return torch.tanh(self.outputs(state))

    def std(self, step: int) -> float:
        """The exploration noise std at global env step ``step``."""
        return exploration_std(step, *self.schedule)

    def act(self, state: torch.Tensor, deterministic: bool, step: int) -> torch.Tensor:
        """mu, or mu plus unclipped noise of the scheduled std, clamped to [-1, 1]."""
        mu = self(state)
        if deterministic:
            return mu
        return (mu + self.std(step) * torch.randn_like(mu)).clamp(-1.0, 1.0)

    def smoothed(self, state: torch.Tensor, step: int) -> torch.Tensor:
        """mu + clip(std(step) * noise, -noise_clip, noise_clip), clamped to [-1, 1] with the
        identity as the clamp's gradient."""
        mu = self(state)
        noise = (self.std(step) * torch.randn_like(mu)).clamp(-self.noise_clip, self.noise_clip)
        action = mu + noise
        return action + (action.clamp(-1.0, 1.0) - action).detach()

    def next_value(
        self,
        critic_target: Critic,
        policy_state: torch.Tensor,
        value_state: torch.Tensor,
        alpha: torch.Tensor | None,
        step: int,
    ) -> torch.Tensor:
        return deterministic_value(*critic_target(value_state, self.smoothed(policy_state, step)))

    def loss(
        self, critic: Critic, state: torch.Tensor, alpha: torch.Tensor | None, step: int
    ) -> tuple[torch.Tensor, None, dict[str, torch.Tensor]]:
        loss = deterministic_actor_loss(*critic(state, self.smoothed(state, step)))
        return loss, None, {"exploration_std": torch.tensor(self.std(step))}


def trunk_dim(config: AgentConfig) -> int | None:
    """The size of the actor's and the critic's own trunks, None without them
    (``AgentConfig.separate_trunks``)."""
    return config.feature_dim if config.separate_trunks else None


@dataclass(frozen=True)
class ActorEntry:
    """How to build one registered actor, and what the agent trains beside it."""

    build: Callable[[AgentConfig, int, int], nn.Module]
    """(config, state size, action size) -> the actor"""
    temperature: bool
    """True: SAC's entropy term with a learned temperature alpha (log alpha, its optimiser and
    loss); False: no entropy term at all"""
    description: str
    """one line for help texts"""


ACTORS: dict[str, ActorEntry] = {
    "gaussian": ActorEntry(
        lambda c, repr_dim, action_dim: Actor(
            repr_dim, action_dim, c.hidden_dim, c.log_std_min, c.log_std_max, trunk_dim(c)
        ),
        temperature=True,
        description="SAC's tanh-squashed Gaussian policy with a learned temperature",
    ),
    "deterministic": ActorEntry(
        lambda c, repr_dim, action_dim: DeterministicActor(
            repr_dim,
            action_dim,
            c.hidden_dim,
            c.exploration_std_start,
            c.exploration_std_end,
            c.exploration_steps,
            c.noise_clip,
            trunk_dim(c),
        ),
        temperature=False,
        description="DrQ-v2's deterministic policy with scheduled, clipped exploration noise",
    ),
}
"""The actors by ``AgentConfig.actor`` name; a new actor is one entry."""


def make_actor(config: AgentConfig, repr_dim: int, action_dim: int) -> nn.Module:
    """Build the actor named by ``config.actor`` from :data:`ACTORS`."""
    return ACTORS[config.actor].build(config, repr_dim, action_dim)
