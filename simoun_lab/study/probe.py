"""Estimate the CPU time of a study's runs from a short probe measured here, before anything runs.

For each group of runs that share an environment (task, image size, action repeat...), the probe
builds that environment with the training code (:func:`~simoun_agent.run.env_runner.make_runner`)
and times random-action steps and one evaluation episode (which gives the episode length); for
each agent configuration it builds the agent and times its actions and a few gradient updates
on a replay of those steps. Times are this process's CPU seconds (``time.process_time``) with
the study's torch threads, so other load on the machine inflates them less than wall time.
A run's estimate adds up its env steps, actions, updates, evaluations and set-up
(:func:`run_cpu_seconds`); checkpoints and logging are left out.
"""

from __future__ import annotations

import math
import os
import socket
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from simoun_agent.config import TrainConfig, to_dict

NOT_COST = {"seed", "total_env_steps", "run_dir", "eval_every", "eval_episodes", "video"}
"""Config keys that change how long a run is, not what a step of it costs."""

WARMUP_UPDATES = 2
"""Updates run before the timed ones: the first pay for memory allocation and lazy set-up."""

ACTIONS = 20
"""Actions timed per agent configuration."""


@dataclass(frozen=True)
class Cost:
    """What one configuration's steps cost here, in CPU seconds."""

    env_step_s: float
    """one agent decision of the training environment (action repeat included), rendering and
    wrappers"""
    eval_step_s: float
    """one decision of an evaluation episode (the evaluation environment's step)"""
    episode_decisions: int
    """decisions in one evaluation episode"""
    act_s: float
    """one action of the agent"""
    update_s: float
    """one gradient update"""
    setup_s: float
    """building the environments and the agent"""


def cost_key(config: TrainConfig) -> str:
    """What makes two runs cost the same per step: the config without seed, budget and
    evaluation schedule."""
    flat = to_dict(config)
    return repr(sorted((k, repr(v)) for k, v in flat.items() if k not in NOT_COST))


def env_key(config: TrainConfig) -> str:
    """What makes two runs share an environment: the config without its agent (except the frames
    per observation, which the replay needs) and without seed and budget."""
    flat = {k: v for k, v in to_dict(config).items() if k not in NOT_COST and k != "agent"}
    return repr(sorted((k, repr(v)) for k, v in flat.items())) + repr(config.agent.num_frames)


class _RandomPolicy:
    """Uniform random actions, to time environment steps and an evaluation episode."""

    def __init__(self, action_dim: int, seed: int) -> None:
        self.action_dim = action_dim
        self.rng = np.random.default_rng(seed)

    def act(self, frames: np.ndarray, deterministic: bool = False) -> np.ndarray:
        return self.rng.uniform(-1.0, 1.0, self.action_dim).astype(np.float32)


def measure(configs: list[TrainConfig], updates: int) -> dict[str, Cost]:
    """Probe ``configs`` (runs' configs; one probe per distinct :func:`cost_key`) with
    ``updates`` timed updates each; returns the cost of each key."""
    import torch

    from simoun_agent.agent import SimounAgent
    from simoun_agent.replay import FrameReplay
    from simoun_agent.run.env_runner import make_runner
    from simoun_agent.run.evaluate import evaluate
    from simoun_agent.run.make_env import make_env

    distinct = {cost_key(config): config for config in configs}
    groups: dict[str, list[TrainConfig]] = {}
    for config in distinct.values():
        groups.setdefault(env_key(config), []).append(config)
    costs = {}
    for group in groups.values():
        first = group[0]
        if first.torch_threads:
            torch.set_num_threads(first.torch_threads)
        torch.manual_seed(first.seed)
        start = time.process_time()
        runner, eval_env = make_runner(first), make_env(first)
        env_setup = time.process_time() - start
        try:
            frame_shape = runner.observation_space["frames"].shape[1:]
            action_dim = runner.action_space.shape[0]
            policy = _RandomPolicy(action_dim, first.seed)
            decisions = 2 * max(c.agent.batch_size for c in group) + 20
            replay = FrameReplay(
                decisions + 1, frame_shape, action_dim, first.agent.num_frames, first.seed
            )
            obs, env_s = _fill(runner, replay, policy, decisions, first.seed)
            start = time.process_time()
            metrics, _ = evaluate(policy, eval_env, 1, first.seed)
            episode = max(1, round(metrics["length_mean"]))
            episode_s = (time.process_time() - start) / episode
            for config in group:
                start = time.process_time()
                agent = SimounAgent(frame_shape, action_dim, config.agent, device=config.device)
                agent_setup = time.process_time() - start
                start = time.process_time()
                for _ in range(ACTIONS):
                    agent.act(obs["frames"])
                act_s = (time.process_time() - start) / ACTIONS
                for _ in range(WARMUP_UPDATES):
                    agent.update(replay, decisions)
                start = time.process_time()
                for _ in range(updates):
                    agent.update(replay, decisions)
                update_s = (time.process_time() - start) / max(updates, 1)
                costs[cost_key(config)] = Cost(
                    env_s, episode_s, episode, act_s, update_s, env_setup + agent_setup
                )
        finally:
            runner.close()
            eval_env.close()
    return costs


def _fill(runner: Any, replay: Any, policy: _RandomPolicy, decisions: int, seed: int):
    """Step ``runner`` with random actions into ``replay`` for ``decisions`` decisions; the
    last observation and the CPU seconds per decision."""
    obs, episode = runner.reset(seed=seed), 0
    replay.start_episode(obs["frames"][-1])
    spent = 0.0
    for _ in range(decisions):
        action = policy.act(obs["frames"])
        start = time.process_time()
        runner.step_async(action)
        obs, reward, terminated, truncated = runner.step_wait()
        spent += time.process_time() - start
        replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            episode += 1
            obs = runner.reset(seed=seed + episode)
            replay.start_episode(obs["frames"][-1])
    return obs, spent / decisions


def evaluations(config: TrainConfig) -> int:
    """Evaluations a run makes: at step 0, every ``eval_every`` env steps, and a final one
    when the budget is no multiple of it."""
    every, total = config.eval_every, config.total_env_steps
    return 1 + total // every + (1 if total % every else 0)


def run_cpu_seconds(config: TrainConfig, cost: Cost) -> float:
    """The CPU seconds one run of ``config`` should take, from its probed ``cost``: its
    decisions' env steps and actions (random during warm-up), its updates, its evaluation
    episodes (and video episode), and set-up."""
    decisions = math.ceil(config.total_env_steps / config.resolved_action_repeat())
    learning_starts = max(config.warmup_agent_steps, config.agent.batch_size)
    updating = max(0, decisions - learning_starts)
    updates = math.ceil(updating / config.agent.update_every_steps) * config.updates_per_step
    acting = max(0, decisions - config.warmup_agent_steps)
    episodes = evaluations(config) * config.eval_episodes + (1 if config.video else 0)
    played = episodes * cost.episode_decisions * (cost.eval_step_s + cost.act_s)
    return (
        cost.setup_s
        + decisions * cost.env_step_s
        + acting * cost.act_s
        + updates * cost.update_s
        + played
    )


def episode_cpu_seconds(cost: Cost) -> float:
    """One evaluation episode's CPU seconds: its decisions' env steps and actions (as
    :func:`run_cpu_seconds` counts an evaluation's)."""
    return cost.episode_decisions * (cost.eval_step_s + cost.act_s)


def machine() -> str:
    """Where the probe ran: host, CPUs and the 1-minute load average."""
    load = os.getloadavg()[0]
    return f"{socket.gethostname()} ({os.cpu_count()} CPUs, load average {load:.2f} over 1 min)"
