"""A CURL-equivalent training step, the speed baseline of ``benchmarks/update.py``.

Written to CURL's published recipe (Laskin et al. 2020, github.com/MishaLaskin/curl): 9-channel
stack of 3 RGB frames stored at 100x100 and randomly cropped to 84x84 (anchor and positive are
independent crops), one conv encoder (4 x 3x3 conv, 32 filters, strides 2,1,1,1; FC 50 +
LayerNorm) owned by the critic, the actor holding its own FC/LN on the critic's (tied) convs,
twin Q heads and actor MLP with 1024 hidden units, a momentum target encoder, a bilinear
contrastive head W, and CURL's schedule: critic and contrastive updates every step, actor and
targets every 2 steps. As in CURL the encoder runs separately for the critic, the actor's next
action, the target critic, the actor update (detached) and the contrastive anchor and positive.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from simoun_agent.config.shapes import conv_output_size
from simoun_agent.models.encoder import conv_trunk, weight_init
from simoun_agent.models.sac import Actor, Critic


class CurlEncoder(nn.Module):
    """CURL's PixelEncoder: convs, FC 50, LayerNorm (output_logits=True: no tanh)."""

    def __init__(self, channels: int, size: int, feature_dim: int = 50, filters: int = 32) -> None:
        super().__init__()
        self.convs = conv_trunk(channels, filters)
        self.fc = nn.Linear(filters * conv_output_size(size) ** 2, feature_dim)
        self.ln = nn.LayerNorm(feature_dim)

    def forward(self, obs: torch.Tensor, detach: bool = False) -> torch.Tensor:
        h = self.convs(obs / 255.0).flatten(1)
        if detach:
            h = h.detach()
        return self.ln(self.fc(h))


class CurlBaseline:
    """CURL's SAC + contrastive update on a replay of 9 x 100 x 100 uint8 stacks."""

    def __init__(
        self,
        action_dim: int,
        batch_size: int,
        capacity: int = 256,
        hidden_dim: int = 1024,
        image_size: int = 84,
        pre_crop_size: int = 100,
        device: str = "cpu",
        channels_last: bool = False,
    ) -> None:
        self.device = torch.device(device)
        self.batch_size = batch_size
        self.image_size = image_size
        gen = torch.Generator().manual_seed(0)
        shape = (capacity, 9, pre_crop_size, pre_crop_size)
        self.obs = torch.randint(0, 256, shape, generator=gen, dtype=torch.uint8)
        self.next_obs = torch.randint(0, 256, shape, generator=gen, dtype=torch.uint8)
        self.actions = torch.rand(capacity, action_dim, generator=gen) * 2 - 1
        self.rewards = torch.rand(capacity, generator=gen)
        self.not_done = torch.ones(capacity)

        self.critic_encoder = CurlEncoder(9, image_size)
        self.actor_encoder = CurlEncoder(9, image_size)
        self.actor_encoder.convs = self.critic_encoder.convs
        self.critic = Critic(50, action_dim, hidden_dim)
        self.actor = Actor(50, action_dim, hidden_dim, -10.0, 2.0)
        for net in (self.critic_encoder, self.actor_encoder, self.critic, self.actor):
            net.apply(weight_init)
        self.critic_encoder_target = copy.deepcopy(self.critic_encoder).requires_grad_(False)
        self.critic_target = copy.deepcopy(self.critic).requires_grad_(False)
        self.W = nn.Parameter(torch.rand(50, 50))
        self.log_alpha = torch.tensor(math.log(0.1), requires_grad=True)
        for module in (
            self.critic_encoder,
            self.actor_encoder,
            self.critic,
            self.actor,
            self.critic_encoder_target,
            self.critic_target,
        ):
            module.to(self.device)
        self.memory_format = torch.channels_last if channels_last else torch.contiguous_format
        for module in (self.critic_encoder, self.actor_encoder, self.critic_encoder_target):
            module.to(memory_format=self.memory_format)
        self.W.data = self.W.data.to(self.device)
        self.log_alpha.data = self.log_alpha.data.to(self.device)
        self.target_entropy = -float(action_dim)
        self.actor_optimizer = torch.optim.Adam(
            [*self.actor.parameters(), *self.actor_encoder.parameters()], lr=1e-3
        )
        self.critic_optimizer = torch.optim.Adam(
            [*self.critic.parameters(), *self.critic_encoder.parameters()], lr=1e-3
        )
        self.alpha_optimizer = torch.optim.Adam([self.log_alpha], lr=1e-4, betas=(0.5, 0.999))
        self.encoder_optimizer = torch.optim.Adam(self.critic_encoder.parameters(), lr=1e-3)
        self.cpc_optimizer = torch.optim.Adam([self.W], lr=1e-3)
        self.step = 0

    def _crop(self, stacks: np.ndarray) -> torch.Tensor:
        """CURL's random crop (numpy, like CURL): an independent window of each stack."""
        s = self.image_size
        top, left = torch.randint(0, stacks.shape[-1] - s + 1, (2, stacks.shape[0])).tolist()
        out = np.empty((*stacks.shape[:2], s, s), np.uint8)
        for i, (y, x) in enumerate(zip(top, left, strict=True)):
            out[i] = stacks[i, :, y : y + s, x : x + s]
        return torch.from_numpy(out)

    def sample(self):
        """CURL's ``sample_cpc``: crops of obs, next_obs and a second crop of obs (positive)."""
        idx = torch.randint(0, self.obs.shape[0], (self.batch_size,))
        obs, next_obs = self.obs[idx].numpy(), self.next_obs[idx].numpy()
        to, fmt = self.device, self.memory_format
        return (
            self._crop(obs).to(to).float().contiguous(memory_format=fmt),
            self.actions[idx].to(to),
            self.rewards[idx].to(to).unsqueeze(-1),
            self._crop(next_obs).to(to).float().contiguous(memory_format=fmt),
            self.not_done[idx].to(to).unsqueeze(-1),
            self._crop(obs).to(to).float().contiguous(memory_format=fmt),
        )

    def update(self) -> None:
        obs, action, reward, next_obs, not_done, pos = self.sample()
        alpha = self.log_alpha.exp().detach()
        with torch.no_grad():
            next_action, next_log_pi = self.actor(self.actor_encoder(next_obs))
            tq1, tq2 = self.critic_target(self.critic_encoder_target(next_obs), next_action)
            target_q = reward + not_done * 0.99 * (torch.min(tq1, tq2) - alpha * next_log_pi)
        q1, q2 = self.critic(self.critic_encoder(obs), action)
        loss = F.mse_loss(q1, target_q) + F.mse_loss(q2, target_q)
        self.critic_optimizer.zero_grad(set_to_none=True)
        loss.backward()
        self.critic_optimizer.step()

        if self.step % 2 == 0:
            pi, log_pi = self.actor(self.actor_encoder(obs, detach=True))
            aq1, aq2 = self.critic(self.critic_encoder(obs, detach=True), pi)
            actor_loss = (alpha * log_pi - torch.min(aq1, aq2)).mean()
            self.actor_optimizer.zero_grad(set_to_none=True)
            actor_loss.backward()
            self.actor_optimizer.step()
            alpha_loss = (self.log_alpha.exp() * (-log_pi - self.target_entropy).detach()).mean()
            self.alpha_optimizer.zero_grad(set_to_none=True)
            alpha_loss.backward()
            self.alpha_optimizer.step()
            with torch.no_grad():
                for online, target, tau in (
                    (self.critic, self.critic_target, 0.01),
                    (self.critic_encoder, self.critic_encoder_target, 0.05),
                ):
                    for p, tp in zip(online.parameters(), target.parameters(), strict=True):
                        tp.data.copy_(tau * p.data + (1 - tau) * tp.data)

        z_a = self.critic_encoder(obs)
        with torch.no_grad():
            z_pos = self.critic_encoder_target(pos)
        logits = z_a @ self.W @ z_pos.T
        logits = logits - logits.max(dim=1, keepdim=True).values
        cpc_loss = F.cross_entropy(logits, torch.arange(logits.shape[0], device=self.device))
        self.encoder_optimizer.zero_grad(set_to_none=True)
        self.cpc_optimizer.zero_grad(set_to_none=True)
        cpc_loss.backward()
        self.encoder_optimizer.step()
        self.cpc_optimizer.step()
        self.step += 1

    def act(self, obs: torch.Tensor) -> torch.Tensor:
        """CURL's select_action on one cropped 9 x 84 x 84 stack."""
        with torch.inference_mode():
            action, _ = self.actor(self.actor_encoder(obs.float().unsqueeze(0)), deterministic=True)
        return action
