"""What a training run is made of (:class:`Run`) and where it stands (:class:`Counters`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import gymnasium as gym
import numpy as np

from simoun_agent.agent import SimounAgent
from simoun_agent.config import TrainConfig
from simoun_agent.replay import FrameReplay
from simoun_agent.run.env_runner import EnvRunner
from simoun_agent.run.signals import StopRequest


@dataclass
class Counters:
    """Where a run stands; saved in every checkpoint."""

    env_step: int = 0
    """environment steps taken (agent decisions x action repeat)"""
    agent_step: int = 0
    """agent decisions taken"""
    episode: int = 0
    """training episodes begun; episode i resets with seed ``seeds.train_episode_seed(seed, i)``"""
    updates: int = 0
    """gradient updates done"""
    eval_pending: bool = True
    """an evaluation is due at ``env_step`` and not yet logged: a new run's first, or one that a
    stop abandoned, which the resumed run plays first"""
    wall_time_s: float = field(default=0.0, compare=False)
    """seconds spent in the training loop, summed over resumed parts (evaluations included)"""


@dataclass
class Run:
    """A run ready to train: its config, directory, environments, agent and replay."""

    config: TrainConfig
    run_dir: Path
    env: EnvRunner
    """the training environment, stepped in this process or a background one"""
    eval_env: gym.Env
    agent: SimounAgent
    replay: FrameReplay
    rng: np.random.Generator
    """the trainer's own generator (random warm-up actions)"""
    counters: Counters
    lock: IO[str] | None = None
    """the run directory's lock (:func:`~simoun_agent.run.rundir.lock_run_dir`), held while
    this process uses it"""
    stop: StopRequest = field(default_factory=StopRequest)
    """set by the first stop signal or a callback's
    :meth:`~simoun_agent.run.callback.TrainCallback.stop_requested`; the
    loop and every evaluation poll ``run.stop.is_set()`` between steps"""

    def close(self) -> None:
        """Close the run's envs and let go of its directory (the lock), for a run that will not
        be trained (:func:`~simoun_agent.run.train.train` lets go of it when it ends): another
        run may then be created in the directory."""
        if self.lock is not None:
            self.lock.close()
            self.lock = None
        self.env.close()
        self.eval_env.close()
