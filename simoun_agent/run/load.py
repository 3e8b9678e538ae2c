"""Rebuild a trained run from its directory: config, environment and agent, on this machine.

The one loader behind ``simoun-eval``, ``simoun-analyze`` and the distraction evaluation. The
machine may differ from the training one: ``device`` and ``torch_threads`` replace the saved
values before the config is checked (a run trained on ``cuda`` is refused on a machine without
a GPU unless ``device="cpu"`` is asked for), and the checkpoint's tensors are read onto the CPU
(:func:`~simoun_agent.run.checkpoint.load_checkpoint`) before the agent copies them to its
device, whatever device string they were saved from.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import torch

from simoun_agent.agent import SimounAgent
from simoun_agent.config import SetupError, TrainConfig, from_dict, to_dict
from simoun_agent.config.device import device_problem
from simoun_agent.run.checkpoint import check_config, load_checkpoint
from simoun_agent.run.kept import (
    Damaged,
    kind_problem,
    packed_problem,
    present,
    read_json_object,
)
from simoun_agent.run.layout import CONFIG_NAME
from simoun_agent.run.make_env import make_env
from simoun_agent.run.seeds import first_eval_seed
from simoun_wrappers._checks import check_path, is_int

RUN_PATH = "a run directory or its checkpoint.pt"
"""What load_run's ``path`` names."""


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


def load_run(
    path: str | os.PathLike,
    device: str | torch.device | None = None,
    torch_threads: int | None = None,
) -> LoadedRun:
    """Rebuild the run of ``path`` (its directory or checkpoint.pt); SetupError when it cannot
    (TypeError or ValueError for a ``path`` that is no path or starts with an unexpanded ``~``:
    :func:`~simoun_wrappers._checks.check_path`).

    ``device`` (a str or torch.device) and ``torch_threads`` (None: the run's own) apply before
    the config's checks; a value of theirs that this machine cannot use is refused naming the
    argument (the saved files are not at fault).
    """
    check_path(path, "load_run(path=...)", "load_run('runs/my-run')", RUN_PATH)
    machine = machine_values(device, torch_threads)
    payload = load_checkpoint(Path(path))
    check_config_file(payload)
    config = from_dict({**payload["config"], **machine}, "saved config")
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


def machine_values(device: Any, torch_threads: Any) -> dict[str, Any]:
    """load_run's ``device`` (as its string) and ``torch_threads``, the ones given, to set over
    the saved config; TypeError or SetupError naming the argument when this machine cannot use
    it."""
    values: dict[str, Any] = {}
    if device is not None:
        if not isinstance(device, (str, torch.device)):
            raise TypeError(
                f"load_run(device=...) must be a str, a torch.device or None (the run's own), "
                f"got {type(device).__name__} {device!r:.60}; e.g. device='cpu'"
            )
        values["device"] = str(device)
        if problem := device_problem(values["device"]):
            raise SetupError(f"load_run(device={values['device']!r}): {problem}")
    if torch_threads is not None:
        if not (is_int(torch_threads) and 1 <= torch_threads < 2**63):
            raise SetupError(
                f"load_run(torch_threads=...) must be an int >= 1 or None (the run's own), got "
                f"{torch_threads!r} ({type(torch_threads).__name__}); e.g. torch_threads=1"
            )
        values["torch_threads"] = int(torch_threads)
    return values


def check_config_file(payload: dict) -> None:
    """Refuse a run directory whose ``config.json`` is not the config of its ``checkpoint.pt``
    (one of them copied or linked from another run, or the file edited), as ``simoun-train
    --resume`` does: what is evaluated or analyzed must be the run its directory says it is.
    A checkpoint without a ``config.json`` beside it (copied on its own) is read as it is."""
    run_dir = payload["replay_path"].parent
    path = run_dir / CONFIG_NAME
    if packed := packed_problem(path):
        raise SetupError(
            f"{packed} and run the command again: it is checked against the checkpoint"
        )
    if not present(path):
        return
    try:
        saved = read_json_object(path)
        if problem := kind_problem(CONFIG_NAME, list(saved)):
            raise Damaged(problem)
    except Damaged as err:
        raise SetupError(
            f"{path} is damaged: {err}. It should hold the config of the checkpoint beside it; "
            "restore the file from a copy (simoun-train writes UTF-8 JSON), or move it aside "
            f"(mv {path} {path}.damaged) to read the checkpoint on its own"
        ) from None
    # Both sides read the same way, so keys a version added later compare as equal; the device
    # is this machine's choice (load_run's ``device``), so a GPU run's reads on a CPU machine.
    machine = {"device": "cpu"}
    as_saved = to_dict(from_dict({**saved, **machine}, str(path)))
    checkpoint = to_dict(from_dict({**payload["config"], **machine}, "saved config"))
    check_config({"config": checkpoint}, as_saved, run_dir, saved=path)
