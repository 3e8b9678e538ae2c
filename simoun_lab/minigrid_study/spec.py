"""The study's design as data: tasks, budgets, seeds, arms, PPO's hyperparameters, evaluation.

A spec is a JSON file (``docs/studies/minigrid/spec.json`` is the study's), or a TOML file
(``.toml``) with the same keys, as ``simoun-study`` reads it; every value has a default here, so
a spec names only what it changes. One ``StudySpec`` gives every arm the same PPO settings,
budgets, seeds and evaluation episodes.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import tomllib

from simoun_agent.config import SetupError
from simoun_agent.config.keys import json_value
from simoun_agent.config.rules import Rule, integer, is_int, real, rules_of, setting, with_rule
from simoun_agent.run.kept import Damaged, json_kind, json_problem, read_text
from simoun_lab.minigrid_study.arms import ARMS, arm_settings
from simoun_lab.study.given_path import blanks_note, shown
from simoun_lab.study.record_file import record_not_spec, selection_not_spec

__all__ = ["PPOSettings", "Run", "StudySpec", "Task", "load_spec", "spec_from_dict"]


@dataclass(frozen=True)
class PPOSettings:
    """Stable-Baselines3 PPO's settings, the same for every arm: rl-baselines3-zoo's
    ``hyperparams/ppo.yml`` entry for MiniGrid-DoorKey-5x5-v0 (its only DoorKey entry, after
    lcswillems/rl-starter-files). Two departures, for pixels: ``CnnPolicy`` (the zoo's entry is
    ``MlpPolicy`` on the symbolic grid), and no ``VecNormalize`` (the zoo's ``normalize: true``):
    SB3 scales images by 1/255 itself, and normalizing the reward would rescale each arm's
    intrinsic reward by a different running statistic."""

    n_envs: int = setting(8, integer(1))
    """sub-envs stepped together (zoo: 8)"""
    n_steps: int = setting(128, integer(1))
    """steps per sub-env per rollout (zoo: 128), so 1024 transitions per update"""
    batch_size: int = setting(64, integer(1))
    """minibatch size (zoo: 64)"""
    n_epochs: int = setting(10, integer(1))
    """passes over each rollout (zoo: 10)"""
    learning_rate: float = setting(2.5e-4, real(0, open_low=True))
    """Adam learning rate (zoo: 2.5e-4)"""
    gamma: float = setting(0.99, real(0, 1))
    """discount (zoo: 0.99)"""
    gae_lambda: float = setting(0.95, real(0, 1))
    """GAE lambda (zoo: 0.95)"""
    ent_coef: float = setting(0.0, real(0))
    """entropy bonus weight (zoo: 0.0)"""
    clip_range: float = setting(0.2, real(0, open_low=True))
    """PPO's ratio clip (zoo: 0.2)"""

    def __post_init__(self) -> None:
        problem = minibatch_problem(self.n_envs, self.n_steps, self.batch_size)
        if problem:
            raise SetupError(problem)

    def kwargs(self) -> dict[str, Any]:
        """The settings as ``stable_baselines3.PPO`` keyword arguments (``n_envs`` left out)."""
        return {k: v for k, v in dataclasses.asdict(self).items() if k != "n_envs"}


def minibatch_problem(n_envs: int, n_steps: int, batch_size: int) -> str | None:
    """What SB3's PPO would refuse or quietly change in these settings, with the fix: a rollout
    (``n_envs x n_steps`` transitions) or a mini-batch of one transition (each mini-batch's
    advantages are normalized), a ``batch_size`` larger than the rollout (SB3 trains on the
    whole rollout, while every run records ``batch_size``) or one that does not divide it
    (each epoch ends on a truncated mini-batch); None when they fit."""
    rollout = n_envs * n_steps
    said = f"n_envs x n_steps = {n_envs} x {n_steps} = {rollout} transitions"
    if rollout < 2:
        return (
            f"one rollout is {said}; SB3's PPO normalizes advantages over it and needs 2 or "
            "more: raise n_steps (e.g. 128)"
        )
    if batch_size < 2:
        return (
            f"batch_size {batch_size}: SB3's PPO normalizes each mini-batch's advantages and "
            f"needs mini-batches of 2 or more; set batch_size to a divisor of {rollout} "
            f"({said}), e.g. {nearest_divisors(rollout, 64)[0]}"
        )
    if rollout % batch_size == 0:
        return None
    below, above = nearest_divisors(rollout, batch_size)
    fit = batch_size // math.gcd(batch_size, n_envs)  # the fewest n_steps a batch divides
    steps = fit * math.ceil(n_steps / fit)
    if batch_size > rollout:
        problem = (
            f"batch_size {batch_size} is larger than one rollout ({said}): SB3 would train "
            f"on mini-batches of {rollout} while every run records {batch_size}"
        )
    else:
        problem = (
            f"batch_size {batch_size} does not divide one rollout ({said}): each epoch "
            f"would end on a truncated mini-batch of {rollout % batch_size} transitions"
        )
    choices = " or ".join(str(size) for size in dict.fromkeys((below, above)) if size > 1)
    return (
        f"{problem}; set batch_size to a divisor of {rollout} (e.g. {choices}), or n_steps "
        f"to {steps} (a rollout of {n_envs * steps} transitions)"
    )


def nearest_divisors(number: int, near: int) -> tuple[int, int]:
    """The divisors of ``number`` nearest ``near``, at most and at least it (``number`` when
    ``near`` is larger)."""
    divisors = [d for d in range(1, number + 1) if number % d == 0]
    below = max((d for d in divisors if d <= near), default=1)
    above = min((d for d in divisors if d >= near), default=number)
    return below, above


def is_minigrid_id(value: Any) -> bool:
    """A registered MiniGrid or BabyAI task id."""
    import minigrid  # noqa: F401  (registers the MiniGrid-* ids)

    return (
        isinstance(value, str)
        and value.startswith(("MiniGrid-", "BabyAI-"))
        and (value in gym.registry)
    )


def items(value: Any, ok) -> bool:
    """A non-empty array (a tuple once read) whose every item is ``ok``."""
    return isinstance(value, list | tuple) and len(value) > 0 and all(ok(item) for item in value)


MINIGRID_ID = Rule("a registered MiniGrid id, e.g. MiniGrid-DoorKey-6x6-v0", is_minigrid_id)
SEEDS = Rule(
    "a non-empty array of whole numbers >= 0, e.g. [0, 1, 2]",
    lambda v: items(v, lambda s: is_int(s) and 0 <= s < 2**63),
)
TASKS = Rule(
    'a non-empty array of task objects, e.g. [{"env_id": "MiniGrid-DoorKey-6x6-v0", '
    '"steps": 400000, "seeds": [0, 1, 2]}]',
    lambda v: items(v, lambda task: isinstance(task, dict | Task)),
)
ARM_NAMES = Rule(
    'a non-empty array of arm names, e.g. ["ppo", "rnd"]', lambda v: items(v, str.__instancecheck__)
)
PPO = Rule(
    'an object of PPO settings, e.g. {"n_envs": 8}', lambda v: isinstance(v, dict | PPOSettings)
)
DEVICE = Rule(
    "a torch device name: cpu, cuda, cuda:N or mps",
    lambda v: isinstance(v, str) and re.fullmatch(r"cpu|mps|cuda(:[0-9]+)?", v) is not None,
)


@dataclass(frozen=True)
class Task:
    """A MiniGrid task, its budget and its training seeds."""

    env_id: str = field(metadata=with_rule(MINIGRID_ID))
    """a registered MiniGrid id, e.g. MiniGrid-DoorKey-6x6-v0"""
    steps: int = field(metadata=with_rule(integer(1)))
    """env steps per run (all sub-envs together)"""
    seeds: tuple[int, ...] = field(metadata=with_rule(SEEDS))
    """training seeds: one run per arm and seed"""


def default_tasks() -> tuple[Task, ...]:
    return (
        Task("MiniGrid-DoorKey-6x6-v0", 400_000, (0, 1, 2, 3, 4)),
        Task("MiniGrid-DoorKey-8x8-v0", 1_000_000, (0, 1, 2)),
    )


@dataclass(frozen=True)
class StudySpec:
    """Tasks x arms x seeds, each run trained and evaluated the same way."""

    tasks: tuple[Task, ...] = field(default_factory=default_tasks, metadata=with_rule(TASKS))
    """the tasks with their budgets and seeds"""
    arms: tuple[str, ...] = setting(("ppo", "consistency", "rnd"), ARM_NAMES)
    """arms: entries of ``simoun_lab.minigrid_study.arms.ARMS``, each optionally with settings
    (``"rnd,normalization=return_std,scale=0.01"``)"""
    ppo: PPOSettings = field(default_factory=PPOSettings, metadata=with_rule(PPO))
    """PPO's settings, shared by every arm"""
    evaluations: int = setting(20, integer(1))
    """evaluations per run, evenly spaced over its budget (and one before training)"""
    eval_episodes: int = setting(32, integer(1))
    """episodes per evaluation, on the env seeds ``eval_seed``, ``eval_seed + 1``, ...: fixed,
    the same for every run, and never used to seed training"""
    eval_seed: int = setting(1_000_000, integer(0))
    """first held-out env seed of the evaluation episodes"""
    device: str = setting("cpu", DEVICE)
    """torch device of PPO and of the intrinsic-reward models"""

    def __post_init__(self) -> None:
        if not self.arms:
            raise SetupError(f"spec arms: none given; choose from {list(ARMS)}")
        if len(set(self.arms)) != len(self.arms):
            raise SetupError(f"spec arms {list(self.arms)}: an arm is listed twice")
        seen: dict[tuple, str] = {}
        for arm in self.arms:
            entry, settings = arm_settings(arm)
            same = (entry, tuple(sorted(settings.items())))
            if same in seen:
                raise SetupError(
                    f"spec arms: {seen[same]!r} and {arm!r} are one arm spelled two ways "
                    "(the same settings); list it once"
                )
            seen[same] = arm
        tasks = [task.env_id for task in self.tasks]
        for env_id in tasks:
            if tasks.count(env_id) > 1:
                raise SetupError(
                    f"spec tasks: {env_id} is listed {tasks.count(env_id)} times; list it once "
                    "(its runs share one directory per arm and seed), with all its seeds"
                )
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
    """``cls`` from the JSON object ``values`` (arrays as tuples), or a SetupError naming an
    unknown or missing key, or a value its field's rule refuses, with the fix."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(values) - set(fields))
    if unknown:
        raise SetupError(f"{where}: unknown key(s) {unknown}; known keys: {sorted(fields)}")
    rules = rules_of(cls)
    for name, f in fields.items():
        if name not in values:
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise SetupError(f"{where}: no {name!r}; give it: {rules[name].need}")
        elif not rules[name].ok(values[name]):
            raise SetupError(
                f"{where}: {name} is {json.dumps(values[name])}, which must be "
                f"{rules[name].need}{example(cls, f)}"
            )
    try:
        return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in values.items()})
    except SetupError as err:  # a check of the values together: name the file too
        raise SetupError(f"{where}: {err}") from None


def example(cls: type, f: dataclasses.Field) -> str:
    """``, e.g. "n_steps": 128``: the field's default (a default task's value for a task's
    field), as JSON; empty when the field's rule gives an example itself."""
    rule = rules_of(cls)[f.name]
    if "e.g." in rule.need:
        return ""
    if f.default is not dataclasses.MISSING:
        value = f.default
    elif f.default_factory is not dataclasses.MISSING:
        value = f.default_factory()
    else:
        value = getattr(default_tasks()[0], f.name)
    return f", e.g. {json.dumps(f.name)}: {json.dumps(value)}"


def spec_from_dict(values: dict[str, Any], where: str) -> StudySpec:
    """The spec ``values`` describe (as :meth:`StudySpec.to_json` writes it; missing keys take
    their defaults); ``where`` names the source in errors."""
    values = dict(values)
    for name in ("tasks", "ppo"):  # checked as JSON before they are read into dataclasses
        rule = rules_of(StudySpec)[name]
        if name in values and not rule.ok(values[name]):
            raise SetupError(
                f"{where}: {name} is {json.dumps(values[name])}, which must be {rule.need}"
            )
    if "tasks" in values:
        values["tasks"] = tuple(
            build(Task, t, f"{where}: tasks[{i}]") for i, t in enumerate(values["tasks"])
        )
    if "ppo" in values:
        values["ppo"] = build(PPOSettings, values["ppo"], f"{where}: ppo")
    return build(StudySpec, values, where)


SAC_SPEC_KEYS = ("recipes", "tuning", "base", "grid")
"""Top-level keys of a SAC study's TOML spec (``simoun-study``), none of them a PPO spec's
(nor a misspelling of one)."""


def load_spec(path: Path, label: str = "the spec file") -> StudySpec:
    """The spec in the JSON file ``path``, or in the TOML file when it ends in ``.toml`` or is
    TOML and not JSON; errors name it as ``label`` (the flag it was given by, ``--spec``; by
    default as the file given to this function, since a caller in Python passed no flag)."""
    is_toml = Path(path).suffix.lower() == ".toml"
    as_toml = is_toml
    try:
        text = read_text(Path(path))
        values = toml_values(text, path, label) if is_toml else json_value(text)
    except FileNotFoundError:
        raise SetupError(f"{label} {shown(path)}: no such file{blanks_note(path)}") from None
    except Damaged as err:
        kind = "TOML" if is_toml else "JSON"
        raise SetupError(
            f"{label} {shown(path)} cannot be read ({err}); pass a {kind} spec saved as UTF-8 text"
        ) from None
    except json.JSONDecodeError as err:
        # a TOML spec under another name reads as TOML, as simoun-study reads it
        values, as_toml = toml_values(text, path, label, quiet=True), True
        if not values:
            problem = json_problem(text, err)
            raise SetupError(f"{label} {shown(path)} is not valid JSON: {problem}") from None
    except ValueError as err:  # a key given twice
        raise SetupError(f"{label} {shown(path)}: {err}") from None
    for refusal in (record_not_spec, selection_not_spec):
        refused = refusal(values, path, label)
        if refused is not None:
            raise refused
    if not isinstance(values, dict):
        raise SetupError(
            f"{label} {path} holds {json_kind(values)}, not the object of a study spec "
            '({"tasks": [...], "arms": [...], ...}); write one as docs/studies/minigrid-v2/'
            "tuning/spec.json does"
            + (", or leave --spec out to use the archive's" if label == "--spec" else "")
        )
    sac = [key for key in SAC_SPEC_KEYS if key in values]
    if sac and "arms" not in values:
        raise SetupError(sac_spec_problem(path, label, sac[0], as_toml))
    return spec_from_dict(values, str(path))


def sac_spec_problem(path: Path, label: str, key: str, as_toml: bool) -> str:
    """The refusal of a SAC study's spec (it has ``key``) given as a MiniGrid spec by ``label``
    at ``path``, read as TOML when ``as_toml``: simoun-study takes a ``.toml`` file as a SAC
    spec and a ``.json`` file as a MiniGrid one, so the fix is the name (a TOML spec saved as
    ``.json``), the format (a SAC spec written as JSON), or the command (a ``.toml`` given to
    the MiniGrid study's own command)."""
    said = f"{label} {shown(path)} is a SAC study's spec (it has {key}), not a MiniGrid PPO spec"
    example = "or pass a MiniGrid spec such as docs/studies/minigrid-v2/tuning/spec.json"
    toml = Path(path).with_suffix(".toml")
    if not as_toml:
        return (
            f"{said}, written as JSON: simoun-study reads a .json spec as a MiniGrid one and a "
            f"SAC spec from TOML; write it as TOML in {shown(toml)} (docs/studies/dmc100k.toml "
            f"shows the layout) and plan it with simoun-study plan {shown(toml)}, {example}"
        )
    if Path(path).suffix.lower() != ".toml":
        return (
            f"{said}: it is TOML saved under a {Path(path).suffix or 'bare'} name, and "
            f"simoun-study reads a .json spec as a MiniGrid one; rename it to .toml (mv "
            f"{shown(path)} {shown(toml)}) and plan it with simoun-study plan {shown(toml)}, "
            f"{example}"
        )
    return f"{said}; plan and run it with simoun-study (simoun-study plan {shown(path)}), {example}"


def toml_values(text: str, path: Path, label: str, quiet: bool = False) -> dict | None:
    """The tables of the TOML ``text`` read from ``path``; SetupError naming the file and the
    line of a syntax error (None instead when ``quiet``)."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        if quiet:
            return None
        raise SetupError(
            f"{label} {path} is not valid TOML ({err}); fix the syntax there"
        ) from None
