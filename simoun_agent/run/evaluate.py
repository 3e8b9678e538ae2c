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
from simoun_wrappers._checks import (
    check_bool,
    check_callable,
    check_nonnegative_int,
    check_positive_int,
    is_int,
)


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
    A NaN or infinite reward raises :class:`NonFiniteReward`. Arguments of the wrong kind
    raise TypeError or ValueError naming them, before any episode is played.

    Returns:
        metrics (return_mean/std/min/max, length_mean, and driving measures) and, when
        ``record``, the first episode's frames as the agent saw them.
    """
    check_players(agent, env)
    check_episodes(episodes, seed)
    check_options(record, on_episode, stop)
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
                if stop is not None and asked_to_stop(stop):
                    raise EvaluationStopped(
                        f"stop() returned True at step {length} of evaluation episode {episode}: "
                        "the evaluation was abandoned"
                    )
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


def check_players(agent: Any, env: Any, function: str = "evaluate", example: str = "") -> None:
    """A TypeError unless ``agent`` acts (``act(frames, deterministic=True)``) and ``env`` is
    a Gymnasium env giving SimounObservation's frames; the two swapped are named as such.
    ``function`` (taking the agent first, the env second) is named, with ``example``, a call
    that works."""
    example = example or f"e.g. {function}(run.agent, run.env, episodes, run.first_seed)"
    if isinstance(agent, gym.Env) and callable(getattr(env, "act", None)):
        raise TypeError(
            f"{function} takes the agent first and the env second, got the env "
            f"{type(agent).__name__} as agent and the {type(env).__name__} as env; swap them, "
            f"{example}"
        )
    if not callable(getattr(agent, "act", None)):
        raise TypeError(
            f"{function}(agent=...) must have act(frames, deterministic) (a SimounAgent or a "
            f"RandomPolicy), got {type(agent).__name__}; {example}"
        )
    if not isinstance(env, gym.Env):
        raise TypeError(
            f"{function}(env=...) must be a Gymnasium env, got {type(env).__name__}; {example}"
        )
    space = env.observation_space
    if not (isinstance(space, gym.spaces.Dict) and "frames" in space.spaces):
        raise TypeError(
            f"{function}(env=...) must give SimounObservation's frames (a Dict observation with "
            f"'frames'), but {env} gives {space}; pass the run's own env (run.env), or wrap it "
            "as the run did: simoun_wrappers.SimounObservation(env, size=...)"
        )


def check_episodes(episodes: Any, seed: Any) -> None:
    """A ValueError unless ``episodes`` is an int >= 1 and ``seed`` an int >= 0."""
    if not (is_int(episodes) and episodes >= 1):
        raise ValueError(
            f"evaluate(episodes=...) must be an int >= 1, got {episodes!r} "
            f"({type(episodes).__name__}); e.g. episodes=10"
        )
    if not (is_int(seed) and seed >= 0):
        raise ValueError(
            f"evaluate(seed=...) must be an int >= 0 (episode i resets with seed + i), got "
            f"{seed!r} ({type(seed).__name__}); e.g. seed=run.first_seed, the run's own "
            "evaluation seeds"
        )


def check_options(record: Any, on_episode: Any, stop: Any) -> None:
    """A TypeError unless ``record`` is a bool and ``on_episode`` and ``stop`` are None or
    callables their calls fit (a truthy ``record="no"`` would record)."""
    check_bool(record, "evaluate(record=...)")
    if on_episode is not None:
        check_callable(
            on_episode,
            "evaluate(on_episode=...)",
            "on_episode(index, episode_return)",
            (0, 0.0),
            "pass a function of the episode's index and return, e.g. "
            "on_episode=lambda i, r: print(i, r), or None",
        )
    if stop is not None:
        check_callable(
            stop,
            "evaluate(stop=...)",
            "stop() before every step",
            (),
            "pass a function of no arguments that returns True to stop, e.g. "
            "stop=lambda: False, or None",
        )


def asked_to_stop(stop: Callable[[], bool]) -> bool:
    """What ``stop()`` answered, a bool; a TypeError for anything else (a truthy ``'no'``
    would stop the evaluation)."""
    answer = stop()
    if not isinstance(answer, (bool, np.bool_)):
        raise TypeError(
            f"evaluate(stop=...) must return True (stop) or False (go on), got "
            f"{type(answer).__name__} {answer!r:.60}; e.g. stop=threading.Event().is_set"
        )
    return bool(answer)


class RandomPolicy:
    """Uniform actions in [-1, 1]^action_dim: the baseline a trained agent has to beat.

    It has the agent's ``act`` signature, so :func:`evaluate` plays it on the same episodes
    (``simoun-eval RUN_DIR --random-policy``).
    """

    def __init__(self, action_dim: int, seed: int) -> None:
        if isinstance(action_dim, gym.spaces.Box) and len(action_dim.shape) == 1:
            raise TypeError(
                f"RandomPolicy(action_dim=...) takes the number of action dimensions, got the "
                f"action space {action_dim}; pass env.action_space.shape[0], here "
                f"{action_dim.shape[0]}"
            )
        check_positive_int(
            action_dim,
            "RandomPolicy(action_dim=...)",
            "pass the number of action dimensions, env.action_space.shape[0]",
        )
        check_nonnegative_int(
            seed, "RandomPolicy(seed=...)", "e.g. seed=0 (the policy's own random stream)"
        )
        self.action_dim = int(action_dim)
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
