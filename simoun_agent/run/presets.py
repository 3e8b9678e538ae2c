"""Training configuration: the ``TrainConfig`` dataclass, named presets and command-line overrides.

A run's configuration is resolved in four layers: the dataclass defaults (the paper's DrQ-style
setup), then a named preset, then a named agent recipe (``--agent.recipe drq``,
:mod:`simoun_agent.recipes`), then the user's overrides (``--agent.batch-size 64`` or
``--set agent.batch_size=64``). The resolved config is saved as ``config.json`` in the run
directory and checked again when the run is resumed.
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import itertools
import json
import textwrap
import types
import typing
from dataclasses import dataclass, field
from typing import Any

from simoun_agent.config import AgentConfig
from simoun_agent.config_checks import check_train_config
from simoun_agent.run.key_match import did_you_mean


class SetupError(ValueError):
    """A bad input the user can fix (unknown env or key, foreign checkpoint, ...).

    The command-line tools print its message, which names the problem and the fix, without a
    traceback.
    """


PAPER_ACTION_REPEAT = {
    "cartpole-swingup": 8,
    "reacher-easy": 4,
    "cheetah-run": 4,
    "ball_in_cup-catch": 4,
    "walker-walk": 2,
    "finger-spin": 2,
}
"""Action repeat of the paper's six DeepMind Control tasks (DrQ's values)."""

HIGHWAY_CONFIG = {
    "action": {"type": "ContinuousAction"},
    "lanes_count": 4,
    "vehicles_count": 20,
    "vehicles_density": 1.0,
    "duration": 40,
    "policy_frequency": 5,
    "simulation_frequency": 15,
}
"""highway-env settings of the ``highway`` preset: continuous [acceleration, steering] control at
5 decisions per simulated second, episodes of 40 s (200 decisions), 4 lanes and 20 other vehicles
at highway-env's default density 1.0 (the paper's CARLA setup drives among 20 moving cars)."""


@dataclass
class TrainConfig:
    """Everything a training run needs; saved with the run as ``config.json``."""

    env: str = "dm_control/cartpole-swingup-v0"
    """Gymnasium id: a dm_control task through shimmy, a highway-env id, any pixel/renderable env;
    MODULE:ID (Gymnasium's form, e.g. minigrid:MiniGrid-DoorKey-6x6-v0) imports MODULE first and
    is saved as env ID plus env_module MODULE"""
    env_module: str | None = None
    """module imported before the env is made, for ids that a package registers on import (e.g.
    ale_py, minigrid); saved with the run, so --resume and simoun-eval import it too"""
    env_kwargs: dict = field(default_factory=dict)
    """extra keyword arguments for gymnasium.make (JSON on the command line)"""
    preset: str | None = None
    """name of the preset this config started from (informational)"""
    seed: int = 1
    """seed of every random stream (episodes, replay, torch, numpy, python): each is a child of
    numpy's SeedSequence(seed), so runs of different seeds share no episode"""
    action_repeat: int | None = None
    """env steps per agent decision (frame skip); None: the paper's value for its six DMC tasks,
    else 1"""
    image_size: int = 84
    """height and width of each camera view fed to the agent"""
    grayscale: bool = False
    """feed grayscale frames (1 channel) instead of RGB"""
    cameras: int = 1
    """viewports concatenated along the width (dm_control camera ids 0..n-1; highway-env: 3 views
    around the ego vehicle)"""
    total_env_steps: int = 500_000
    """length of the run in environment steps (agent decisions x action repeat)"""
    warmup_agent_steps: int = 1000
    """agent decisions taken uniformly at random before learning starts"""
    updates_per_step: int = 1
    """gradient updates per agent decision once learning has started"""
    replay_capacity: int = 100_000
    """transitions kept in the replay buffer"""
    eval_every: int = 10_000
    """environment steps between evaluations (run at the next episode end)"""
    eval_episodes: int = 10
    """episodes per evaluation (deterministic actions)"""
    eval_distraction: tuple[str, ...] = ()
    """distraction modes also evaluated at every evaluation, as test curves beside the training
    env's (dm_control tasks; repeat the flag, e.g. --eval-distraction video_hard; modes in
    simoun_agent.generalization.DISTRACTIONS)"""
    checkpoint_every: int = 50_000
    """environment steps between checkpoints (written at the next episode end). One that does
    not fit on the disk keeps the previous one and is tried again at the next; after 3 failures
    in a row, or at a stop or the run's end, the run stops with exit status 75 (free space, then
    --resume)"""
    video: bool = True
    """record one evaluation episode to video.mp4 at the end of the run"""
    device: str | None = None
    """torch device; None: cuda when available, else cpu"""
    torch_threads: int | None = None
    """torch intra-op threads; None: torch's default"""
    env_process: bool = False
    """step the training environment in a background process while the agent updates (a
    second core works on physics and rendering; results are identical either way)"""
    run_dir: str | None = None
    """output directory; None: runs/<env>-<preset>-s<seed>-<date>"""
    progress: bool = True
    """show a progress bar"""
    agent: AgentConfig = field(default_factory=AgentConfig)
    """the agent's hyperparameters (simoun_agent.config.AgentConfig)"""

    def __post_init__(self) -> None:
        module, env_id = split_env_id(self.env) if isinstance(self.env, str) else (None, self.env)
        if module:
            if self.env_module not in (None, module):
                raise ValueError(
                    f"--env {self.env} names the module {module!r} but --env-module is "
                    f"{self.env_module!r}; give the module once"
                )
            self.env, self.env_module = env_id, module
        check_train_config(self)

    def resolved_action_repeat(self) -> int:
        """The action repeat to use: the explicit value, the paper's for a DMC task, or 1."""
        if self.action_repeat is not None:
            return self.action_repeat
        return PAPER_ACTION_REPEAT.get(dmc_task(self.env), 1)


RESUMABLE_FIELDS = (
    "total_env_steps",
    "eval_every",
    "checkpoint_every",
    "progress",
    "video",
    "env_process",
    "torch_threads",
    "eval_distraction",
)
"""Fields a resumed run may change: how long and how it runs and reports, not what it learns
(torch_threads changes speed only); every other field must match the saved config."""


def split_env_id(env: str) -> tuple[str | None, str]:
    """``"minigrid:MiniGrid-DoorKey-6x6-v0"`` -> ``("minigrid", "MiniGrid-DoorKey-6x6-v0")``,
    Gymnasium's MODULE:ID form (``gym.make`` imports MODULE to register ID); ``(None, env)``
    for a plain id."""
    module, sep, env_id = env.rpartition(":")
    return (module, env_id) if sep else (None, env)


def dmc_task(env_id: str) -> str | None:
    """``"dm_control/cartpole-swingup-v0"`` -> ``"cartpole-swingup"``; None for other ids."""
    if not env_id.startswith("dm_control/"):
        return None
    return env_id.removeprefix("dm_control/").rsplit("-v", 1)[0]


@dataclass(frozen=True)
class Preset:
    """A named set of overrides and the environments it was tuned for."""

    description: str
    overrides: dict
    envs: str = "any"
    """"any", "highway" (any highway-env id) or one exact env id"""

    def accepts(self, env_id: str) -> bool:
        if self.envs == "any":
            return True
        if self.envs == "highway":
            return is_highway(env_id)
        return env_id == self.envs


def is_highway(env_id: str) -> bool:
    """True for ids registered by highway-env (``highway-v0``, ``merge-v0``, ...)."""
    import gymnasium as gym

    spec = gym.registry.get(env_id)
    if spec is None:
        return env_id.split("-v")[0] in {"highway", "highway-fast", "merge", "roundabout"}
    entry = spec.entry_point if isinstance(spec.entry_point, str) else ""
    return entry.startswith("highway_env")


def _dmc_preset(task: str) -> Preset:
    lr = 2e-4 if task == "cheetah-run" else 1e-3
    return Preset(
        description=f"paper setup for DMC {task}: action repeat {PAPER_ACTION_REPEAT[task]}, "
        f"batch 512, lr {lr:g}, replay 100k, 500k env steps",
        overrides={
            "env": f"dm_control/{task}-v0",
            "action_repeat": PAPER_ACTION_REPEAT[task],
            "agent": {"batch_size": 512, "lr": lr},
        },
        envs=f"dm_control/{task}-v0",
    )


PRESETS: dict[str, Preset] = {task: _dmc_preset(task) for task in PAPER_ACTION_REPEAT}
PRESETS["highway"] = Preset(
    description="highway-env driving: 3 viewports around the ego vehicle -> 84x252, continuous "
    "[acceleration, steering], 40 s episodes, 20 vehicles at density 1",
    overrides={
        "env": "highway-v0",
        "env_kwargs": {"config": HIGHWAY_CONFIG},
        "action_repeat": 1,
        "cameras": 3,
        "total_env_steps": 100_000,
        "eval_every": 5_000,
        "eval_episodes": 5,
        "agent": {"batch_size": 128},
    },
    envs="highway",
)
CPU_PRESET_TIME = (
    "about 30 min alone on 2 cores, 40-55 min beside a second run (measured 2026-11-29/30, "
    "before per-step n-step curiosity made an update 1.31x slower)"
)
"""Wall time of one cpu-preset run (a reviewer's seed-1 run alone: 1,804 s; the README's three
main-job runs: 39, 39 and 56 min, two side by side): the one figure the help text and the README
quote; update both together."""

PRESETS["cpu"] = Preset(
    description=f"sized for 2 CPU cores (the main job, {CPU_PRESET_TIME}): "
    "dm_control/cartpole-swingup-v0 "
    "(action repeat 8) for 100k env steps, 48x48 frames, 16 filters, batch 64, random shift, "
    "3-step returns, one torch thread",
    overrides={
        "total_env_steps": 100_000,
        "warmup_agent_steps": 250,
        "replay_capacity": 32_000,
        "eval_every": 10_000,
        "eval_episodes": 5,
        "checkpoint_every": 20_000,
        "image_size": 48,
        "torch_threads": 1,
        # shift + 3-step returns: the best Simoun setting of docs/study.md at 30k env steps
        # (249 +- 48 over 3 seeds, against 171 +- 43 without either)
        "agent": {
            "batch_size": 64,
            "num_filters": 16,
            "hidden_dim": 256,
            "augmentation": "shift",
            "n_step": 3,
        },
    },
)


def field_docs(cls: type) -> dict[str, str]:
    """The docstring under each field of a dataclass (cleanrl style), read from its source."""
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    except (OSError, TypeError):
        return {}
    body = tree.body[0].body
    docs = {}
    for node, following in itertools.pairwise(body):
        if (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and isinstance(following, ast.Expr)
            and isinstance(following.value, ast.Constant)
            and isinstance(following.value.value, str)
        ):
            docs[node.target.id] = " ".join(following.value.value.split())
    return docs


def config_sections(cls: type | None = None) -> dict[str, type]:
    """Nested config sections by key prefix: ``{"": TrainConfig, "agent.": AgentConfig, ...}``.

    A field whose type is a dataclass is a section; a new section is one such field.
    """
    cls = cls or TrainConfig
    sections = {"": cls}
    for name, kind in typing.get_type_hints(cls).items():
        if dataclasses.is_dataclass(kind):
            sections.update(
                {name + "." + sub: inner for sub, inner in config_sections(kind).items()}
            )
    return sections


def config_fields() -> dict[str, tuple[type, Any, str]]:
    """Every overridable key (``"seed"``, ``"agent.lr"``, ...) -> (type, default, doc)."""
    keys = {}
    for prefix, cls in config_sections().items():
        hints = typing.get_type_hints(cls)
        docs = field_docs(cls)
        for f in dataclasses.fields(cls):
            if dataclasses.is_dataclass(hints[f.name]):
                continue
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            keys[prefix + f.name] = (hints[f.name], default, docs.get(f.name, ""))
    return keys


def parse_value(key: str, text: str, kind: Any) -> Any:
    """Convert a command-line string to the field's type, or raise SetupError naming the key."""
    options = typing.get_args(kind) if _is_union(kind) else (kind,)
    if type(None) in options and text.lower() in ("none", "null"):
        return None
    errors = []
    for option in options:
        if option is type(None):
            continue
        try:
            return _parse_one(text, option)
        except ValueError as error:
            errors.append(str(error))
    raise SetupError(f"cannot read {key}={text!r}: {'; '.join(errors)}")


def _is_union(kind: Any) -> bool:
    return typing.get_origin(kind) in (typing.Union, types.UnionType)


def _parse_one(text: str, kind: Any) -> Any:
    origin = typing.get_origin(kind) or kind
    if origin is bool:
        lowered = text.lower()
        if lowered in ("1", "true", "yes", "on"):
            return True
        if lowered in ("0", "false", "no", "off"):
            return False
        raise ValueError("expected true or false")
    if origin in (int, float, str):
        try:
            return origin(text)
        except ValueError:
            raise ValueError(f"expected {origin.__name__}") from None
    words = origin in (list, tuple) and set(typing.get_args(kind)) in ({str}, {str, Ellipsis})
    if words and not text.lstrip().startswith("["):
        # A list of words may be given plainly: --set eval_distraction=video_hard,color_hard
        value = [item.strip() for item in text.split(",") if item.strip()]
        return tuple(value) if origin is tuple else value
    if origin in (dict, list, tuple):
        try:
            value = json.loads(text)
        except json.JSONDecodeError:
            raise ValueError(f"expected JSON for a {origin.__name__}") from None
        return tuple(value) if origin is tuple else value
    raise ValueError(f"unsupported type {kind}")


HELP_FIX = "`simoun-train --help` lists every key"


def check_keys(keys: Any, source: str = "", fix: str = HELP_FIX) -> None:
    """Raise SetupError naming every key of ``keys`` that no config field has, each with its
    close matches (:mod:`simoun_agent.run.key_match`); ``source`` says where the keys came from
    (none: the user) and ``fix`` how to correct them. The user's overrides, presets and recipes
    all pass here."""
    known = config_fields()
    unknown = [key for key in keys if key not in known]
    if unknown:
        docs = {key: doc for key, (_, _, doc) in known.items()}
        named = ", ".join(key + did_you_mean(key, docs) for key in unknown)
        where = f"{source}: " if source else ""
        raise SetupError(f"{where}unknown config key {named}; {fix}")


def resolve(preset: str | None, overrides: dict[str, Any]) -> TrainConfig:
    """Build a TrainConfig from the defaults, a preset and ``{"agent.lr": 3e-4, ...}`` overrides.

    Every layer (the preset, the recipe, the overrides) is checked for unknown keys the same
    way. Raises SetupError for an unknown preset or key, or a preset meant for another
    environment.
    """
    check_keys(overrides)
    values: dict[str, Any] = {}
    if preset is not None:
        values.update(preset_values(preset))
        chosen = PRESETS[preset]
        env_id = split_env_id(overrides.get("env", values.get("env", TrainConfig.env)))[1]
        if not chosen.accepts(env_id):
            meant = "highway-env ids" if chosen.envs == "highway" else chosen.envs
            fitting = [name for name, other in PRESETS.items() if other.envs != "any"]
            fitting = [name for name in fitting if PRESETS[name].accepts(env_id)] + ["cpu"]
            raise SetupError(
                f"preset {preset!r} is meant for {meant}, not {env_id!r}; drop --env to train "
                f"on {meant}, or use a preset for {env_id!r}: {' or '.join(fitting)} (or no "
                "preset for the paper defaults)"
            )
    recipe = overrides.get("agent.recipe", values.get("agent.recipe"))
    if recipe is not None:
        values.update(recipe_values(recipe))
    values.update(overrides)
    return from_flat(values)


def preset_values(name: str) -> dict[str, Any]:
    """The flat overrides of the preset ``name`` with ``"preset": name``; SetupError for an
    unknown preset or a preset entry with an unknown key."""
    if name not in PRESETS:
        raise SetupError(f"unknown preset {name!r}; choose one of {', '.join(PRESETS)}")
    values = _flatten(PRESETS[name].overrides)
    check_keys(values, f"preset {name!r}", "fix its entry in simoun_agent.run.presets.PRESETS")
    return {**values, "preset": name}


def recipe_values(name: str) -> dict[str, Any]:
    """The flat overrides (``{"agent.encoder": "stacked", ...}``) of the recipe ``name``;
    SetupError for an unknown recipe or a recipe entry with an unknown key."""
    from simoun_agent.recipes import RECIPES

    if name not in RECIPES:
        import difflib

        hint = difflib.get_close_matches(name, RECIPES, n=1)
        raise SetupError(
            f"unknown recipe --agent.recipe {name!r}"
            + (f" (did you mean {hint[0]!r}?)" if hint else "")
            + f"; choose one of {', '.join(RECIPES)}"
        )
    values = {"agent." + key: value for key, value in RECIPES[name].values.items()}
    check_keys(values, f"recipe {name!r}", "fix its entry in simoun_agent.recipes.RECIPES")
    return values


def _flatten(nested: dict, prefix: str = "") -> dict[str, Any]:
    """``{"agent": {"lr": 1e-3}, "seed": 1}`` -> ``{"agent.lr": 1e-3, "seed": 1}``: the dicts
    of config sections are walked, any other dict (``env_kwargs``) is a value."""
    sections = config_sections()
    flat = {}
    for key, value in nested.items():
        if isinstance(value, dict) and prefix + key + "." in sections:
            flat.update(_flatten(value, prefix + key + "."))
        else:
            flat[prefix + key] = value
    return flat


def from_flat(values: dict[str, Any]) -> TrainConfig:
    """TrainConfig from flat keys (``"agent.lr"``) over the dataclass defaults; SetupError for a
    key no field has (nothing is dropped silently)."""
    check_keys(values)
    try:
        return _build(TrainConfig, "", values)
    except ValueError as err:
        raise SetupError(str(err)) from None


def _build(cls: type, prefix: str, values: dict[str, Any]) -> Any:
    hints = typing.get_type_hints(cls)
    kwargs = {}
    for f in dataclasses.fields(cls):
        if dataclasses.is_dataclass(hints[f.name]):
            kwargs[f.name] = _build(hints[f.name], prefix + f.name + ".", values)
        elif prefix + f.name in values:
            kwargs[f.name] = values[prefix + f.name]
    return cls(**kwargs)


def to_dict(config: TrainConfig) -> dict[str, Any]:
    """JSON-ready nested dict of a config (tuples become lists)."""
    return json.loads(json.dumps(dataclasses.asdict(config)))


def from_dict(data: dict[str, Any]) -> TrainConfig:
    """Inverse of :func:`to_dict`; raises SetupError for keys this version does not know."""
    flat = _flatten(data)
    known = config_fields()
    unknown = sorted(set(flat) - set(known))
    if unknown:
        raise SetupError(f"saved config has keys this version does not know: {unknown}")
    for key, value in flat.items():
        kind = known[key][0]
        if isinstance(value, list) and (typing.get_origin(kind) or kind) is tuple:
            flat[key] = tuple(value)
    return from_flat(flat)
