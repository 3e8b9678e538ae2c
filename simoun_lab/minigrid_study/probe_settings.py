"""What the probe (:mod:`simoun_lab.minigrid_study.probe`) is given, apart from the probe: the
command line reads it without importing torch, SB3 or MiniGrid, so ``--help`` and a bad flag are
answered at once."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PROBE_NAMES", "ProbeSettings"]

PROBE_NAMES = (
    "consistency",
    "consistency_lr1e-4",
    "consistency_capacity10k",
    "consistency_no_interactive",
    "rnd",
)
"""The names of :data:`simoun_lab.minigrid_study.probe.PROBED`'s probes, in its order: the
command's default ``--probes``."""


@dataclass(frozen=True)
class ProbeSettings:
    """What every probe shares."""

    env_id: str = "MiniGrid-DoorKey-6x6-v0"
    """the MiniGrid task"""
    steps: int = 60_000
    """env steps per probe (all sub-envs together)"""
    n_envs: int = 8
    """sub-envs, as the study's PPO"""
    n_steps: int = 128
    """vector steps per block (a block is one of the study's PPO rollouts)"""
    seed: int = 100
    """env, action and model seed: disjoint from the study's training seeds (0-4) and its
    held-out evaluation seeds (1,000,000 on)"""
