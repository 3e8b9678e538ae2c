"""What the probe (:mod:`simoun_lab.minigrid_study.probe`) is given, apart from the probe: the
command line reads it without importing torch, SB3 or MiniGrid, so ``--help`` and a bad flag are
answered at once."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

__all__ = ["PROBE_NAMES", "ProbeSettings", "check_probes", "check_settings"]

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


def check_settings(
    settings: ProbeSettings, name: Callable[[str], str] = lambda field: f"settings.{field}"
) -> None:
    """Raise ValueError naming the first value of ``settings`` a probe cannot run with: a count
    below 1, a seed below 0, or fewer ``steps`` than two blocks (the summary leaves the first
    out). ``name`` spells a field where the user gave it (``settings.n_envs`` in Python,
    ``--settings.n-envs`` on the command line)."""
    for field in ("n_envs", "n_steps", "steps"):
        if getattr(settings, field) < 1:
            raise ValueError(
                f"{name(field)} {getattr(settings, field)}: must be 1 or more "
                f"(default {getattr(ProbeSettings(), field)})"
            )
    if settings.seed < 0:
        raise ValueError(f"{name('seed')} {settings.seed}: must be 0 or more")
    block = settings.n_envs * settings.n_steps
    if settings.steps < 2 * block:
        raise ValueError(
            f"{name('steps')} {settings.steps}: fewer than two blocks of {name('n_envs')} x "
            f"{name('n_steps')} = {block} transitions (the summary leaves the first block out); "
            f"give {name('steps')} {2 * block} or more"
        )


def check_probes(names: list[str]) -> None:
    """Raise ValueError naming ``--probes`` when it names no probe (an empty table would replace
    the archived probe.csv and probe.md), an unknown one, or one twice (its rows would be written
    twice under one name, mixed in its means)."""
    if not names:
        raise ValueError(
            f"--probes is given no probe, so there is nothing to probe; name one or more of "
            f"{', '.join(PROBE_NAMES)}, or leave --probes out to probe them all"
        )
    unknown = [n for n in names if n not in PROBE_NAMES]
    if unknown:
        raise ValueError(f"--probes {unknown}: unknown; choose from {list(PROBE_NAMES)}")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise ValueError(f"--probes names {', '.join(twice)} more than once; name each probe once")
