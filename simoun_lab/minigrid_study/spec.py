"""The study's design as data: tasks, budgets, seeds, arms, PPO's hyperparameters, evaluation.

A spec is a JSON file (``docs/studies/minigrid/spec.json`` is the study's); every value has a
default here, so a spec names only what it changes. One ``StudySpec`` gives every arm the same
PPO settings, budgets, seeds and evaluation episodes.
"""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_lab.minigrid_study.arms import ARMS, parse_arm

__all__ = ["PPOSettings", "Run", "StudySpec", "Task", "load_spec", "spec_from_dict"]


@dataclass(frozen=True)
class PPOSettings:
    """Stable-Baselines3 PPO's settings, the same for every arm: rl-baselines3-zoo's
    ``hyperparams/ppo.yml`` entry for MiniGrid-DoorKey-5x5-v0 (its only DoorKey entry, after
    lcswillems/rl-starter-files). Two departures, for pixels: ``CnnPolicy`` (the zoo's entry is
    ``MlpPolicy`` on the symbolic grid), and no ``VecNormalize`` (the zoo's ``normalize: true``):
    SB3 scales images by 1/255 itself, and normalizing the reward would rescale each arm's
    intrinsic reward by a different running statistic."""

    n_envs: int = 8
    """sub-envs stepped together (zoo: 8)"""
    n_steps: int = 128
    """steps per sub-env per rollout (zoo: 128), so 1024 transitions per update"""
    batch_size: int = 64
    """minibatch size (zoo: 64)"""
    n_epochs: int = 10
    """passes over each rollout (zoo: 10)"""
    learning_rate: float = 2.5e-4
    """Adam learning rate (zoo: 2.5e-4)"""
    gamma: float = 0.99
    """discount (zoo: 0.99)"""
    gae_lambda: float = 0.95
    """GAE lambda (zoo: 0.95)"""
    ent_coef: float = 0.0
    """entropy bonus weight (zoo: 0.0)"""
    clip_range: float = 0.2
    """PPO's ratio clip (zoo: 0.2)"""

    def kwargs(self) -> dict[str, Any]:
        """The settings as ``stable_baselines3.PPO`` keyword arguments (``n_envs`` left out)."""
        return {k: v for k, v in dataclasses.asdict(self).items() if k != "n_envs"}


@dataclass(frozen=True)
class Task:
    """A MiniGrid task, its budget and its training seeds."""

    env_id: str
    """a registered MiniGrid id, e.g. MiniGrid-DoorKey-6x6-v0"""
    steps: int
    """env steps per run (all sub-envs together)"""
    seeds: tuple[int, ...]
    """training seeds: one run per arm and seed"""


def default_tasks() -> tuple[Task, ...]:
    return (
        Task("MiniGrid-DoorKey-6x6-v0", 400_000, (0, 1, 2, 3, 4)),
        Task("MiniGrid-DoorKey-8x8-v0", 1_000_000, (0, 1, 2)),
    )


@dataclass(frozen=True)
class StudySpec:
    """Tasks x arms x seeds, each run trained and evaluated the same way."""

    tasks: tuple[Task, ...] = field(default_factory=default_tasks)
    """the tasks with their budgets and seeds"""
    arms: tuple[str, ...] = ("ppo", "consistency", "rnd")
    """arms: entries of ``simoun_lab.minigrid_study.arms.ARMS``, each optionally with settings
    (``"rnd,normalization=return_std,scale=0.01"``)"""
    ppo: PPOSettings = field(default_factory=PPOSettings)
    """PPO's settings, shared by every arm"""
    evaluations: int = 20
    """evaluations per run, evenly spaced over its budget (and one before training)"""
    eval_episodes: int = 32
    """episodes per evaluation, on the env seeds ``eval_seed``, ``eval_seed + 1``, ...: fixed,
    the same for every run, and never used to seed training"""
    eval_seed: int = 1_000_000
    """first held-out env seed of the evaluation episodes"""
    device: str = "cpu"
    """torch device of PPO and of the intrinsic-reward models"""

    def __post_init__(self) -> None:
        if not self.arms:
            raise SetupError(f"spec arms: none given; choose from {list(ARMS)}")
        for arm in self.arms:
            parse_arm(arm)
        if len(set(self.arms)) != len(self.arms):
            raise SetupError(f"spec arms {list(self.arms)}: an arm is listed twice")
        for task in self.tasks:
            if task.steps < self.ppo.n_envs * self.ppo.n_steps:
                raise SetupError(
                    f"task {task.env_id}: steps={task.steps} is less than one PPO rollout "
                    f"(n_envs x n_steps = {self.ppo.n_envs * self.ppo.n_steps}); raise steps"
                )
            if not task.seeds or len(set(task.seeds)) != len(task.seeds):
                raise SetupError(f"task {task.env_id}: seeds {task.seeds} must be distinct, >= 1")
        if self.evaluations < 1 or self.eval_episodes < 1:
            raise SetupError(
                f"evaluations={self.evaluations} and eval_episodes={self.eval_episodes} must be "
                ">= 1"
            )

    def runs(self) -> list[Run]:
        """Every run of the study in the order they run: tasks outermost, then seeds, then arms,
        so a study stopped part way has every arm on the same seeds (a balanced comparison)."""
        return [
            Run(task, arm, seed) for task in self.tasks for seed in task.seeds for arm in self.arms
        ]

    def to_json(self) -> dict[str, Any]:
        """The spec as JSON values (tuples as lists), as :func:`spec_from_dict` reads it."""
        return json.loads(json.dumps(dataclasses.asdict(self)))


@dataclass(frozen=True)
class Run:
    """One training run: a task, an arm, a seed."""

    task: Task
    arm: str
    seed: int

    @property
    def name(self) -> str:
        """``<task>/<arm>/s<seed>``: the run's directory under the study's archive."""
        return f"{self.task.env_id}/{self.arm}/s{self.seed}"


def build(cls: type, values: dict[str, Any], where: str) -> Any:
    """``cls(**values)``, or a SetupError naming the unknown key and the known ones."""
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(values) - known)
    if unknown:
        raise SetupError(f"{where}: unknown key(s) {unknown}; known keys: {sorted(known)}")
    return cls(**values)


def spec_from_dict(values: dict[str, Any], where: str) -> StudySpec:
    """The spec ``values`` describe (as :meth:`StudySpec.to_json` writes it; missing keys take
    their defaults); ``where`` names the source in errors."""
    values = dict(values)
    if "tasks" in values:
        values["tasks"] = tuple(
            build(Task, {**t, "seeds": tuple(t.get("seeds", ()))}, f"{where}: tasks[{i}]")
            for i, t in enumerate(values["tasks"])
        )
    if "ppo" in values:
        values["ppo"] = build(PPOSettings, values["ppo"], f"{where}: ppo")
    if "arms" in values:
        values["arms"] = tuple(values["arms"])
    return build(StudySpec, values, where)


def json_kind(value: Any) -> str:
    """What JSON calls ``value``'s kind (an array, null, a number...), for messages."""
    kinds = {list: "an array", type(None): "null", bool: "true/false", str: "a string"}
    return kinds.get(type(value), "a number")


def load_spec(path: Path) -> StudySpec:
    """The spec in the JSON file ``path``."""
    try:
        values = json.loads(Path(path).read_text())
    except FileNotFoundError:
        raise SetupError(f"--spec {path}: no such file") from None
    except json.JSONDecodeError as err:
        raise SetupError(f"--spec {path}: not valid JSON ({err})") from None
    if not isinstance(values, dict):
        raise SetupError(
            f"--spec {path} holds {json_kind(values)}, not the object of a study spec "
            '({"tasks": [...], "arms": [...], ...}); write one as docs/studies/minigrid-v2/'
            "tuning/spec.json does, or leave --spec out to use the archive's"
        )
    return spec_from_dict(values, str(path))
