"""Rebuild a trained run from its directory: config, environment and agent, on this machine.

The one loader behind ``simoun-eval``, ``simoun-analyze`` and the distraction evaluation. The
machine may differ from the training one: ``device`` and ``torch_threads`` replace the saved
values before the config is checked (a run trained on ``cuda`` is refused on a machine without
a GPU unless ``device="cpu"`` is asked for), and the checkpoint's tensors are read onto the CPU
(:func:`~simoun_agent.run.checkpoint.load_checkpoint`) before the agent copies them to its
device, whatever device string they were saved from.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import torch

from simoun_agent.agent import SimounAgent
from simoun_agent.config import TrainConfig, from_dict
from simoun_agent.run.checkpoint import load_checkpoint
from simoun_agent.run.make_env import make_env
from simoun_agent.run.seeds import first_eval_seed


@dataclass
class LoadedRun:
    """A run rebuilt from its checkpoint, ready to be evaluated or looked at."""

    run_dir: Path
    """the run directory (where checkpoint.pt lives)"""
    config: TrainConfig
    """the run's config, as saved in the checkpoint, with this machine's device and threads"""
    env: gym.Env
    """the run's own environment stack (make_env)"""
    agent: SimounAgent
    """the agent with the checkpoint's weights, on ``config.device``"""
    env_step: int
    """environment steps the run had taken at this checkpoint"""

    @property
    def first_seed(self) -> int:
        """Seed of episode 0: the run's evaluation episodes, never its training ones."""
        return first_eval_seed(self.config.seed)


def load_run(path: Path, device: str | None = None, torch_threads: int | None = None) -> LoadedRun:
    """Rebuild the run of ``path`` (its directory or checkpoint.pt); SetupError when it cannot.

    ``device`` and ``torch_threads`` (None: the run's own) apply before the config's checks.
    """
    payload = load_checkpoint(Path(path))
    machine = {"device": device, "torch_threads": torch_threads}
    config = from_dict(
        {**payload["config"], **{key: value for key, value in machine.items() if value is not None}}
    )
    if config.torch_threads:
        # torch's default of one thread per core oversubscribes a shared machine: 3 episodes
        # of a cpu-preset checkpoint took 63 and 47 s with 2 threads, 19 and 31 s with the
        # run's one (simoun-eval RUN --episodes 3 --torch-threads N, 2 busy cores)
        torch.set_num_threads(config.torch_threads)
    env = make_env(config)
    agent = SimounAgent(
        env.observation_space["frames"].shape[1:],
        env.action_space.shape[0],
        config.agent,
        device=config.device,
    )
    agent.load_state_dict(payload["agent"])
    run_dir = payload["replay_path"].parent
    return LoadedRun(run_dir, config, env, agent, int(payload["state"]["env_step"]))
