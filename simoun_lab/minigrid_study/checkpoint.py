"""Mid-run checkpoints of a study run, so that a run whose process was ended (a machine
handed back, a preempted cluster node) goes on from its last checkpoint instead of from scratch.

A checkpoint is written atomically at the first rollout after each evaluation (after PPO's
update, with an empty rollout buffer). It holds PPO's policy and optimizer and its step and
update counters; the global torch, numpy and Python RNG states (PPO samples its actions from
torch's, its minibatches from numpy's); each training sub-env's RNG (the layouts of its next
episodes); the intrinsic reward's running statistics and its model's weights, optimizer,
counters and RNG; and the run's records so far. What a resume changes, said in the run's
``summary.json`` (``parts``): the episodes in progress at the checkpoint start again from a
reset, and the intrinsic model's buffer (not kept: 1,000 transitions) refills from new
transitions before its next gradient step.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import torch
from stable_baselines3.common.callbacks import BaseCallback

from simoun_agent.run.atomic import atomic_write
from simoun_lab.minigrid_study.training import Training

__all__ = ["CHECKPOINT", "RunCheckpoint", "intrinsic_state", "load_intrinsic_state", "restore"]

CHECKPOINT = "checkpoint.pt"
"""a run's checkpoint, in its run directory until the run has finished"""


def intrinsic_state(envs: Any) -> dict[str, Any] | None:
    """The intrinsic-reward wrapper's statistics and its model's state (None: no wrapper)."""
    if not hasattr(envs, "signal"):
        return None
    source = envs.signal.source
    return {"signal": envs.state_dict(), "model": None if source is None else source.state_dict()}


def load_intrinsic_state(envs: Any, state: dict[str, Any] | None) -> None:
    """Restore what :func:`intrinsic_state` returned into the wrapper ``envs``."""
    if state is not None:
        envs.load_state_dict(state["signal"])
        if state["model"] is not None:
            envs.signal.source.load_state_dict(state["model"])


class RunCheckpoint(BaseCallback):
    """Writes ``path`` at the first rollout after each evaluation of the run ``training``
    (a :class:`~simoun_lab.minigrid_study.training.Training`), then calls ``on_save`` with
    it (the study hands it to Ray Tune, which keeps it beyond the run directory)."""

    def __init__(
        self, path: Path, training: Training, on_save: Callable[[Path], None] | None = None
    ) -> None:
        super().__init__()
        self.path, self.training, self.on_save = path, training, on_save
        self.saved_evaluations = 0

    def _on_training_start(self) -> None:
        # after the log's evaluation at step 0, which is no reason to save
        self.saved_evaluations = len(self.training.log.eval_rows)

    def _on_step(self) -> bool:
        return True

    def _on_rollout_start(self) -> None:
        if len(self.training.log.eval_rows) > self.saved_evaluations:
            self.save()

    def save(self) -> None:
        """Write the checkpoint now (atomically: an interrupted write keeps the previous one)."""
        training, ppo = self.training, self.training.ppo
        state = {
            "env_step": ppo.num_timesteps,
            "n_updates": ppo._n_updates,
            "policy": ppo.policy.state_dict(),
            "optimizer": ppo.policy.optimizer.state_dict(),
            "rng": {
                "torch": torch.get_rng_state(),
                # SB3 draws its minibatches from numpy's legacy global RNG
                "numpy": np.random.get_state(),  # noqa: NPY002
                "python": random.getstate(),
            },
            "env_rng": [g.bit_generator.state for g in training.timed.get_attr("np_random")],
            "intrinsic": intrinsic_state(training.envs),
            "log": training.log.state(),
        }
        atomic_write(self.path, lambda tmp: torch.save(state, tmp))
        self.saved_evaluations = len(training.log.eval_rows)
        if self.on_save is not None:
            self.on_save(self.path)


def restore(path: Path, training: Training) -> int:
    """Load the checkpoint at ``path`` into ``training``, set up afresh (PPO built, envs not
    reset); returns its env step."""
    state = torch.load(path, weights_only=False)
    ppo = training.ppo
    ppo.policy.load_state_dict(state["policy"])
    ppo.policy.optimizer.load_state_dict(state["optimizer"])
    ppo.num_timesteps = state["env_step"]
    ppo._n_updates = state["n_updates"]
    torch.set_rng_state(state["rng"]["torch"])
    np.random.set_state(state["rng"]["numpy"])  # noqa: NPY002
    random.setstate(state["rng"]["python"])
    generators = training.timed.get_attr("np_random")
    for generator, saved in zip(generators, state["env_rng"], strict=True):
        generator.bit_generator.state = saved
    load_intrinsic_state(training.envs, state["intrinsic"])
    training.log.load(state["log"])
    return int(state["env_step"])
