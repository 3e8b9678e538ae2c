"""Evaluation episodes with deterministic actions (the library under ``simoun-eval``,
:mod:`simoun_agent.cli.eval`, and the training loop's evaluations)."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from typing import Any

import gymnasium as gym
import numpy as np
import torch

from simoun_agent.config import SetupError
from simoun_agent.run import driving_metrics


class EvaluationStopped(Exception):
    """An evaluation abandoned between two steps because its ``stop()`` said so; nothing of it
    is returned, so no partial evaluation is ever logged."""


class NonFiniteReward(SetupError):
    """An evaluation episode got a NaN or infinite reward: its return would be logged, plotted
    and reported as if it were a score."""

    def __init__(self, reward: float, episode: int, step: int, seed: int) -> None:
        super().__init__(
            f"the evaluation env returned the reward {reward} at step {step} of evaluation "
            f"episode {episode} (reset seed {seed}); rewards must be finite numbers: fix the "
            "environment"
        )
        self.reward = reward


def evaluate(
    agent: Any,
    env: gym.Env,
    episodes: int,
    seed: int,
    record: bool = False,
    on_episode: Callable[[int, float], None] | None = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[dict[str, float], list[np.ndarray]]:
    """Play ``episodes`` episodes with deterministic actions; episode ``i`` resets with seed
    ``seed + i`` (a run's own: :func:`simoun_agent.run.seeds.first_eval_seed`).

    Leaves every global RNG as it found it, so evaluating does not change what training does
    next (a resumed run stays bit-exact). highway-env runs add the driving measures of
    :mod:`simoun_agent.run.driving_metrics`.

    ``on_episode(index, return)`` is called after each episode (progress reports). ``stop()`` is
    asked before every step: True raises :class:`EvaluationStopped` (a Ctrl-C during training).
    A NaN or infinite reward raises :class:`NonFiniteReward`.

    Returns:
        metrics (return_mean/std/min/max, length_mean, and driving measures) and, when
        ``record``, the first episode's frames as the agent saw them.
    """
    driving = driving_metrics.is_driving_env(env)
    returns, lengths, drives, frames = [], [], [], []
    with torch.random.fork_rng():
        for episode in range(episodes):
            obs, _ = env.reset(seed=seed + episode)
            drive = driving_metrics.DrivingEpisode() if driving else None
            if drive:
                drive.start(env)
            if record and episode == 0:
                frames.append(obs["frames"][-1])
            total, length, done = 0.0, 0, False
            while not done:
                if stop is not None and stop():
                    raise EvaluationStopped
                action = agent.act(obs["frames"], deterministic=True)
                obs, reward, terminated, truncated, info = env.step(action)
                if not math.isfinite(reward):
                    raise NonFiniteReward(float(reward), episode, length + 1, seed + episode)
                total += float(reward)
                length += 1
                done = terminated or truncated
                if drive:
                    drive.step(env, reward, info)
                if record and episode == 0:
                    frames.append(obs["frames"][-1])
            returns.append(total)
            lengths.append(length)
            if on_episode is not None:
                on_episode(episode, total)
            if drive:
                drives.append(drive)
    metrics = {
        "return_mean": float(np.mean(returns)),
        "return_std": float(np.std(returns)),
        "return_min": float(np.min(returns)),
        "return_max": float(np.max(returns)),
        "length_mean": float(np.mean(lengths)),
    }
    if drives:
        metrics.update(driving_metrics.summarize(drives))
    return metrics, frames


class RandomPolicy:
    """Uniform actions in [-1, 1]^action_dim: the baseline a trained agent has to beat.

    It has the agent's ``act`` signature, so :func:`evaluate` plays it on the same episodes
    (``simoun-eval RUN_DIR --random-policy``).
    """

    def __init__(self, action_dim: int, seed: int) -> None:
        self.action_dim = action_dim
        self._rng = np.random.default_rng(seed)

    def act(self, frames: np.ndarray, deterministic: bool = False) -> np.ndarray:
        return self._rng.uniform(-1.0, 1.0, self.action_dim).astype(np.float32)


def metrics_json(data: dict[str, Any]) -> str:
    """``data`` as strict JSON: NaN (e.g. the crash speed of a run without crashes) as null."""

    def clean(value: Any) -> Any:
        if isinstance(value, dict):
            return {key: clean(item) for key, item in value.items()}
        return None if isinstance(value, float) and math.isnan(value) else value

    return json.dumps(clean(data), indent=2, allow_nan=False) + "\n"
