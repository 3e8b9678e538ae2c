"""The study's arms: what each adds to the PPO learner's reward, one registry entry each."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import torch
from gymnasium.vector import VectorEnv

from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_agent.rnd_model import RNDConfig, RNDModel
from simoun_wrappers import ConsistencyCuriosityVectorReward
from simoun_wrappers.rnd import RNDVectorReward

__all__ = ["ARMS"]


def no_intrinsic(envs: VectorEnv, seed: int, device: torch.device) -> VectorEnv:
    """PPO on the env's own reward."""
    return envs


def consistency(envs: VectorEnv, seed: int, device: torch.device, **changes: Any) -> VectorEnv:
    """+ Simoun's consistency curiosity (Eq. 13), the wrapper at its defaults and CuriosityModel
    at its defaults but for ``changes`` (``CuriosityConfig`` fields: none in the study's arm)."""
    model = CuriosityModel.for_env(envs, CuriosityConfig(seed=seed, **changes), device=device)
    return ConsistencyCuriosityVectorReward(envs, model)


def rnd(envs: VectorEnv, seed: int, device: torch.device) -> VectorEnv:
    """+ random network distillation, RNDModel and wrapper at their defaults."""
    return RNDVectorReward(envs, RNDModel.for_env(envs, RNDConfig(seed=seed), device=device))


ARMS: dict[str, Callable[[VectorEnv, int, torch.device], VectorEnv]] = {
    "ppo": no_intrinsic,
    "consistency": consistency,
    "rnd": rnd,
}
"""arm name -> the training vector env it gives PPO, from the pixel vector env, the run's seed
and the device of the intrinsic-reward model"""
