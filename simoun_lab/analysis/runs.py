"""Play a reloaded run (:func:`simoun_agent.run.load.load_run`) deterministically."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch

from simoun_agent.agent import SimounAgent
from simoun_agent.config import SetupError
from simoun_agent.models.encoder import PixelEncoder
from simoun_agent.run.evaluate import check_players
from simoun_agent.run.rundir import make_output_dir
from simoun_wrappers._checks import is_int


@dataclass
class Episode:
    """One deterministic episode of the agent."""

    seed: int
    """the reset seed"""
    observations: np.ndarray
    """(T + 1, k, C, H, W) uint8: entry s is the triplet after s decisions (0: the reset one)"""
    actions: np.ndarray
    """(T, action_dim) the actions taken"""
    rewards: np.ndarray
    """(T,) the rewards received"""

    @property
    def length(self) -> int:
        """Decisions taken (T)."""
        return len(self.actions)


def play_episode(agent: SimounAgent, env: gym.Env, seed: int) -> Episode:
    """One episode from ``reset(seed=seed)`` with deterministic actions."""
    example = "e.g. play_episode(run.agent, run.env, run.first_seed) for run = load_run(path)"
    check_players(agent, env, "play_episode", example)
    if not (is_int(seed) and seed >= 0):
        raise (ValueError if is_int(seed) else TypeError)(
            f"play_episode(seed=...) must be an int >= 0 (the episode's reset seed), got "
            f"{type(seed).__name__} {seed!r:.60}; {example}"
        )
    obs, _ = env.reset(seed=seed)
    observations, actions, rewards = [obs["frames"]], [], []
    done = False
    with torch.random.fork_rng():
        while not done:
            action = agent.act(obs["frames"], True)
            obs, reward, terminated, truncated, _ = env.step(action)
            observations.append(obs["frames"])
            actions.append(action)
            rewards.append(reward)
            done = terminated or truncated
    return Episode(seed, np.stack(observations), np.stack(actions), np.asarray(rewards, np.float64))


def prepare_output(out: Path, names: list[str], overwrite: bool, flag: str = "--out") -> None:
    """Create ``out``; refuse when it cannot be written, when it already holds one of ``names``
    (glob patterns) and ``overwrite`` is off, or when one of them is something else than a file
    (a directory), which the write after the work would fail on."""
    existing = (
        sorted(p.name for pattern in names for p in out.glob(pattern)) if out.is_dir() else []
    )
    if existing and not overwrite:
        shown = ", ".join(existing[:3]) + (" ..." if len(existing) > 3 else "")
        raise SetupError(
            f"{out} already holds results ({shown}); pass --overwrite to replace them, or "
            f"another {flag}"
        )
    make_output_dir(out, flag, names)


def check_encoder(encoder: object, function: str) -> None:
    """A TypeError naming ``function``'s ``encoder`` unless it is a PixelEncoder: an agent, or
    the observations in its place, would fail inside torch."""
    if isinstance(encoder, PixelEncoder):
        return
    hint = (
        "pass its encoder, agent.encoder"
        if isinstance(getattr(encoder, "encoder", None), PixelEncoder)
        else "pass a run's encoder, load_run(path).agent.encoder"
    )
    raise TypeError(
        f"{function}(encoder=...) must be a PixelEncoder, got {type(encoder).__name__}; {hint}, "
        f"e.g. {function}(run.agent.encoder, observations)"
    )
