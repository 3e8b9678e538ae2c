"""A study spec: one TOML file that says what a study runs, read and checked before Ray starts.

Every key is checked (unknown keys, recipes, env ids, config keys and their values, seeds, a
grid key that a recipe fixes); an error names the file, the line and the fix (``SetupError``,
printed without a traceback). The layout (``docs/studies/dmc100k.toml`` is a full example)::

    description = "what the study asks"        # optional
    recipes = ["simoun", "sac"]                # simoun_agent.config.recipes; the first is the one
                                               # compared with each other in the report
    selection = "auc"                          # the rule that picks each recipe's setting

    [base]                                     # every run of both phases
    preset = "cpu"                             # optional; then config keys as --set takes them
    eval_episodes = 10

    [grid]                                     # the shared tuning grid, the same for every
    agent.n_step = [1, 3]                      # recipe; its product makes the settings

    [tuning]                                   # phase 1: every recipe x setting x seed
    tasks = ["dm_control/cartpole-swingup-v0"]
    seeds = [101, 102]                         # or "101-102", or a table per task
    env_steps = 50_000                         # or a table per task

    [evaluation]                               # phase 2: each recipe's selected setting on
    tasks = ["dm_control/cartpole-swingup-v0", "dm_control/cheetah-run-v0"]
    seeds = {"dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = [1, 2, 3]}
    env_steps = 100_000                        # held-out seeds: none may be a tuning seed

    [tasks."dm_control/cheetah-run-v0"]        # per-task config keys, both phases
    action_repeat = 4

    [resources]
    cpus_per_trial = 1                         # CPUs (torch threads) of each run
    max_concurrent_trials = 2                  # runs at a time (default: as many as fit)
    gpus_per_trial = "auto"                    # a number, or auto (1 when Ray has GPUs)

    [diagnostics]                              # optional: ablations of one method, each run
    simoun = ["simoun_no_curiosity"]           # at the method's selected setting on the
                                               # evaluation tasks and seeds, never tuned

    [generalization]                           # optional: each evaluation run's final agent
    modes = ["color_hard", "video_hard"]       # played on distraction modes (and ``train``)
    episodes = 10                              # on the run's evaluation seeds

A config key is given in one place: [base] for every run, [grid] to tune it, or the tasks'
tables per task (a run takes [base], then its task's table, then its grid setting, so a key in
two of them would drop one value without a word).

A grid key that a recipe fixes (drqv2's ``n_step = 3``) is refused, unless the top-level
``grid_overrides = ["agent.n_step"]`` names it and the grid offers the recipe's own value: then
every recipe is tuned over the same values and the recipe as published is one of its settings.
"""

from __future__ import annotations

import difflib
import itertools
import json
from collections.abc import Iterator
from dataclasses import MISSING, asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

from simoun_agent.config import PRESETS, RECIPES, SetupError, resolve, to_dict
from simoun_agent.config.keys import (
    HELP_FIX,
    config_fields,
    config_sections,
    parse_value,
)
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import did_you_mean_name, show
from simoun_agent.generalization import DISTRACTIONS, parse_distractions
from simoun_agent.run.kept import Damaged, read_text
from simoun_lab.study.given_path import blanks_note, shown
from simoun_lab.study.record_file import record_not_spec
from simoun_lab.study.selection import SELECTION_RULES
from simoun_lab.study.spec_kinds import kind_problem
from simoun_lab.study.toml_lines import key_line
from simoun_lab.sweep.grid import MAX_SEEDS, close_key_here, parse_seeds

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the same parser from PyPI (the lab extra has it)
    import tomli as tomllib

PHASES = ("tuning", "evaluation")

OFFLINE_MODES = [mode for mode, entry in DISTRACTIONS.items() if entry is not None]
"""The distraction modes a study can play: all but ``train`` (always played, as the reference),
each built procedurally, with no video files or downloads."""

SCHEMA: dict[tuple[str, ...], dict[str, str]] = {
    (): {
        "description": "one paragraph: what the study asks",
        "recipes": 'the recipes to compare, e.g. recipes = ["simoun", "drq"]',
        "selection": f"the selection rule: {', '.join(SELECTION_RULES)}",
        "base": "the [base] table: preset and config keys of every run",
        "grid": "the [grid] table: config key = [values to try]",
        "grid_overrides": "grid keys that may override a value a recipe fixes, e.g. "
        'grid_overrides = ["agent.n_step"] (the grid must offer the recipe\'s own value)',
        "tuning": "the [tuning] table: tasks, seeds, env_steps",
        "evaluation": "the [evaluation] table: tasks, seeds, env_steps",
        "tasks": 'per-task config keys: [tasks."ENV_ID"]',
        "resources": "the [resources] table: cpus_per_trial, max_concurrent_trials, gpus_per_trial",
        "diagnostics": "the [diagnostics] table: method recipe = [its ablation recipes], each "
        'evaluated at the method\'s selected setting, e.g. simoun = ["simoun_no_curiosity"]',
        "generalization": "the [generalization] table: modes, episodes",
    },
    **{
        (phase,): {
            "tasks": 'Gymnasium ids, e.g. tasks = ["dm_control/cartpole-swingup-v0"]',
            "seeds": 'seeds of each task: [1, 2], "1-5" or a table per task',
            "env_steps": "env steps of each run: an integer or a table per task",
        }
        for phase in PHASES
    },
    ("generalization",): {
        "modes": "distraction modes each evaluation run's final agent is played on, e.g. "
        f'modes = ["color_hard", "video_hard"] (from {", ".join(OFFLINE_MODES)})',
        "episodes": "episodes of each mode (and of the train mode they are compared with)",
    },
    ("resources",): {
        "cpus_per_trial": "CPUs of each run (it uses as many torch threads)",
        "max_concurrent_trials": "runs at a time",
        "gpus_per_trial": 'GPUs of each run: a number or "auto"',
    },
}
"""The keys of each fixed table, with what each holds (unknown keys get the closest one)."""

STUDY_SETS = {
    "seed": "the seeds of [tuning] and [evaluation]",
    "env": "the tasks of [tuning] and [evaluation]",
    "total_env_steps": "env_steps in [tuning] and [evaluation]",
    "run_dir": "--study-dir (the study lays out each run's directory under it)",
    "torch_threads": "cpus_per_trial in [resources] (one torch thread per CPU)",
    "agent.recipe": "the recipes list",
    "preset": "preset in [base]",
}
"""Config keys the study sets itself, and where to say them instead."""

REQUIRED = ("recipes", "grid", "tuning", "evaluation")

DEFAULT_SELECTION = "auc"
"""The selection rule of a spec that names none, and of a study saved before specs named one."""


@dataclass(frozen=True)
class Phase:
    """One phase of the study: its tasks, the seeds and the env-step budget of each."""

    name: str
    """``tuning`` or ``evaluation``"""
    tasks: list
    """Gymnasium ids, in the spec's order"""
    seeds: dict
    """task -> its seeds"""
    env_steps: dict
    """task -> env steps of each of its runs"""

    def runs(self) -> int:
        """Runs of one recipe and one setting in this phase."""
        return sum(len(self.seeds[task]) for task in self.tasks)


SAVED_KINDS: dict[str, tuple[tuple[type, ...], str]] = {
    "str": ((str,), "a string"),
    "list": ((list,), "an array"),
    "dict": ((dict,), "an object"),
    "int": ((int,), "a whole number"),
    "str | None": ((str, type(None)), "a string or null"),
    "int | None": ((int, type(None)), "a whole number or null"),
    "float | str": ((int, float, str), "a number or a string"),
}
"""What each kind of :class:`StudySpec` field is saved as in ``study.json``."""


def saved_kind_problem(name: str, kind: str, value: Any) -> str | None:
    """What is wrong with the saved value of the spec field ``name`` (of type ``kind``), else
    None: a string where the recipes' array belongs would read as another spec's recipes."""
    if kind not in SAVED_KINDS:
        return None  # a phase: read by Phase, which names what is wrong with it
    types, need = SAVED_KINDS[kind]
    if isinstance(value, bool) or not isinstance(value, types):
        return f"{name} is {json.dumps(value)}, where {need} belongs"
    if name == "recipes" and not all(isinstance(recipe, str) for recipe in value):
        return f"recipes is {json.dumps(value)}, where an array of recipe names belongs"
    return None


@dataclass(frozen=True)
class StudySpec:
    """What a study runs, as read from its TOML file; saved in ``study.json`` and compared when
    the study is resumed."""

    name: str
    """the spec file's stem (``dmc100k``)"""
    description: str
    """what the study asks"""
    recipes: list
    """recipe names; the first is compared with each of the others"""
    selection: str
    """the selection rule (:data:`~simoun_lab.study.selection.SELECTION_RULES`)"""
    preset: str | None
    """the preset every run starts from"""
    base: dict
    """flat config overrides of every run (``{"eval_episodes": 10}``)"""
    grid: dict
    """flat config key -> the values to try, the same for every recipe"""
    task_config: dict
    """task -> flat config overrides of its runs (action repeat...)"""
    tuning: Phase
    evaluation: Phase
    grid_overrides: list = field(default_factory=list)
    """grid keys allowed to override a recipe's own value (which the grid then offers)"""
    cpus_per_trial: int = 1
    """CPUs (and torch threads) of each run"""
    max_concurrent_trials: int | None = None
    """runs at a time; None: as many as the Ray cluster fits"""
    gpus_per_trial: float | str = "auto"
    """GPUs of each run, or ``auto``"""
    diagnostics: dict = field(default_factory=dict)
    """method recipe -> its ablation recipes, evaluated at the method's selected setting on the
    evaluation tasks and seeds (not tuned); the report compares each with the method"""
    generalization: list = field(default_factory=list)
    """distraction modes each finished evaluation run's final agent is played on, beside the
    train mode; empty: none"""
    generalization_episodes: int = 10
    """episodes of each generalization mode, on the run's evaluation seeds"""

    def phase(self, name: str) -> Phase:
        return self.tuning if name == "tuning" else self.evaluation

    def settings(self) -> list[dict[str, Any]]:
        """Each combination of grid values, first key slowest, values in the spec's order."""
        combos = itertools.product(*self.grid.values())
        return [dict(zip(self.grid, combo, strict=True)) for combo in combos]

    def overrides(
        self, recipe: str, task: str, setting: dict[str, Any], seed: int, env_steps: int
    ) -> dict[str, Any]:
        """The flat config overrides of one run (the study sets run_dir and torch_threads)."""
        return {
            "progress": False,
            **self.base,
            **self.task_config.get(task, {}),
            **setting,
            "agent.recipe": recipe,
            "env": task,
            "seed": seed,
            "total_env_steps": env_steps,
        }

    def to_json(self) -> dict[str, Any]:
        """The JSON form (tuples as lists), equal for a fresh and a reloaded spec."""
        return json.loads(json.dumps(asdict(self)))

    def ablations(self) -> dict[str, str]:
        """Each diagnostic recipe -> the method whose selected setting it runs at."""
        return {a: method for method, ablations in self.diagnostics.items() for a in ablations}

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> StudySpec:
        """The spec saved in ``study.json``; keys added since it was saved take their defaults,
        so an older study reads as the spec it was (no diagnostics, no generalization);
        ValueError saying what is wrong when a key every spec holds is missing, a key is
        unknown or a phase is not the object of one."""
        data = {"selection": DEFAULT_SELECTION, **data}
        known = {f.name for f in fields(cls)}
        needed = [
            f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING
        ]
        problems = [f"no {key}" for key in needed if key not in data]
        problems += [f"an unknown key {key!r}" for key in data if key not in known]
        if problems:
            raise ValueError(f"its spec has {', '.join(problems)}")
        for field_ in fields(cls):
            problem = saved_kind_problem(field_.name, str(field_.type), data.get(field_.name))
            if field_.name in data and problem:
                raise ValueError(f"its spec's {problem}")
        phases = {}
        for name in PHASES:
            try:
                phases[name] = Phase(**data[name])
            except TypeError:
                raise ValueError(
                    f"its spec's {name} is not a phase ({', '.join(f.name for f in fields(Phase))})"
                ) from None
        return cls(**{**data, **phases})


class Source:
    """The spec's text, to name the line of a key in error messages."""

    def __init__(self, path: Path, text: str) -> None:
        self.path, self.text = path, text

    def error(self, where: tuple[str, ...], problem: str) -> SetupError:
        """``PATH:LINE: [table] key: problem`` (the line of ``where``, or of its nearest
        enclosing table the text has)."""
        for depth in range(len(where), 0, -1):
            line = key_line(self.text, where[:depth])
            if line is not None:
                return SetupError(f"{self.path}:{line}: {_name(where)}: {problem}")
        return SetupError(f"{self.path}: {problem}")


def _name(where: tuple[str, ...]) -> str:
    """``("tasks", "dm_control/x", "action_repeat")`` -> ``[tasks."dm_control/x"] action_repeat``;
    top-level keys bare; config keys dotted."""
    if len(where) == 1:
        return where[0]
    if where[0] == "tasks":
        table, rest = f'[tasks."{where[1]}"]', where[2:]
    else:
        table, rest = f"[{where[0]}]", where[1:]
    return f"{table} {'.'.join(rest)}".strip()


def load_spec(path: Path | str) -> StudySpec:
    """Read and check the study spec at ``path``; raises SetupError naming the line and the fix."""
    path = Path(path)
    text = spec_text(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        record = record_not_spec(json_or_none(text), path, "the study spec")
        if record is not None:
            raise record from None
        raise SetupError(f"{path}: not valid TOML ({err}); fix the syntax there") from None
    return _Reader(Source(path, text)).spec(data, path.stem)


def json_or_none(text: str) -> Any:
    """``text`` read as JSON, None when it is not JSON."""
    try:
        return json.loads(text)
    except ValueError:
        return None


def spec_text(path: Path) -> str:
    """The text of the study spec at ``path``; SetupError naming the file, what is wrong and
    the fix when it cannot be read as UTF-8 text."""
    try:
        return read_text(path)
    except OSError as err:
        fix = blanks_note(path) or "; pass a TOML file, e.g. docs/studies/dmc100k.toml"
        raise SetupError(
            f"cannot read the study spec {shown(path)} ({err.strerror}){fix}"
        ) from None
    except Damaged as err:
        raise SetupError(
            f"cannot read the study spec {shown(path)} ({err}); pass a TOML file saved as UTF-8 "
            "text, e.g. docs/studies/dmc100k.toml"
        ) from None


class _Reader:
    """Turns the parsed TOML into a :class:`StudySpec`, checking each part as it goes."""

    def __init__(self, source: Source) -> None:
        self.source = source
        self.fields = config_fields()

    def fail(self, where: tuple[str, ...], problem: str) -> SetupError:
        return self.source.error(where, problem)

    def spec(self, data: dict[str, Any], name: str) -> StudySpec:
        self.check_keys(data, ())
        wrong_kind = kind_problem(data)
        if wrong_kind:
            raise self.fail(*wrong_kind)
        missing = [key for key in REQUIRED if key not in data]
        if missing:
            raise SetupError(
                f"{self.source.path}: no {missing[0]!r}; a study needs "
                f"{', '.join(REQUIRED)} ({SCHEMA[()][missing[0]]})"
            )
        description = data.get("description", "")
        if not isinstance(description, str):
            raise self.fail(("description",), "give a string")
        recipes = self.recipes(data["recipes"])
        selection = data.get("selection", DEFAULT_SELECTION)
        if selection not in SELECTION_RULES:
            raise self.fail(
                ("selection",),
                f"unknown selection rule {selection!r}; choose one of {', '.join(SELECTION_RULES)}",
            )
        base_table = self.table(data.get("base", {}), ("base",))
        preset = base_table.pop("preset", None)
        if preset is not None and preset not in PRESETS:
            raise self.fail(
                ("base", "preset"),
                f"unknown preset {preset!r}{did_you_mean_name(preset, list(PRESETS))}"
                + f"; choose one of {', '.join(PRESETS)}",
            )
        diagnostics = self.diagnostics(data.get("diagnostics", {}), recipes)
        # a diagnostic recipe runs with the base, task and grid values too: what it fixes counts
        every = recipes + [a for ablations in diagnostics.values() for a in ablations]
        base = self.config_table(base_table, ("base",), every)
        self.resolves(preset, base, ("base",))
        overrides = data.get("grid_overrides", [])
        if not isinstance(overrides, list) or not all(isinstance(k, str) for k in overrides):
            raise self.fail(("grid_overrides",), 'give a list of grid keys, e.g. ["agent.n_step"]')
        for key in overrides:
            if key not in self.fields:
                hint = close_key_here(key, STUDY_SETS, "the study")
                raise self.fail(
                    ("grid_overrides",), f"unknown config key {key!r}{hint}; {HELP_FIX}"
                )
        grid = self.grid(data["grid"], every, preset, base, overrides)
        tuning = self.phase(data["tuning"], "tuning")
        evaluation = self.phase(data["evaluation"], "evaluation")
        self.disjoint(tuning, evaluation)
        task_config = self.tasks(
            data.get("tasks", {}), tuning, evaluation, every, preset, base, grid
        )
        resources = self.resources(data.get("resources", {}))
        modes, episodes = self.generalization(data.get("generalization"), evaluation)
        spec = StudySpec(
            name,
            description,
            recipes,
            selection,
            preset,
            base,
            grid,
            task_config,
            tuning,
            evaluation,
            overrides,
            **resources,
            diagnostics=diagnostics,
            generalization=modes,
            generalization_episodes=episodes,
        )
        self.check_runs(spec)
        return json_round_trip(spec)

    def check_keys(self, table: dict[str, Any], where: tuple[str, ...]) -> None:
        known = SCHEMA[where]
        for key in table:
            if key not in known:
                hint = difflib.get_close_matches(key, known, n=1)
                raise self.fail(
                    (*where, key),
                    f"unknown key {key!r}"
                    + (f" (did you mean {hint[0]!r}: {known[hint[0]]}?)" if hint else "")
                    + f"; {_name(where) if where else 'the top level'} takes "
                    f"{', '.join(known)}",
                )

    def table(self, value: Any, where: tuple[str, ...]) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(where, f"give a table ([{'.'.join(where)}]), not {value!r}")
        return dict(value)

    def entries(
        self, value: Any, section: str, names: list[str], what: str, fix: str
    ) -> Iterator[tuple[str, Any, tuple[str, ...]]]:
        """``(key, entry, where)`` for each entry of the table ``[section]``; a key that is not
        one of ``names`` is refused as not ``what``, with ``fix``."""
        for key, entry in self.table(value, (section,)).items():
            where = (section, key)
            if key not in names:
                raise self.fail(where, f"{key!r} is {what} ({', '.join(names)}); {fix}")
            yield key, entry, where

    def known_recipe(self, recipe: Any, where: tuple[str, ...]) -> None:
        """Refuse a name that is no recipe, suggesting the closest one."""
        if recipe not in RECIPES:
            raise self.fail(
                where,
                f"unknown recipe {recipe!r}{did_you_mean_name(recipe, list(RECIPES))}"
                + f"; choose from {', '.join(RECIPES)} (simoun_agent/config/recipes.py)",
            )

    def recipes(self, value: Any) -> list[str]:
        where = ("recipes",)
        if not isinstance(value, list) or not value:
            raise self.fail(where, 'give a non-empty list, e.g. recipes = ["simoun", "drq"]')
        for recipe in value:
            self.known_recipe(recipe, where)
        repeated = sorted({r for r in value if value.count(r) > 1})
        if repeated:
            raise self.fail(where, f"{repeated[0]!r} is listed twice; list each recipe once")
        return list(value)

    def flat(self, table: dict[str, Any], where: tuple[str, ...]) -> dict[str, tuple]:
        """Config keys of a table, dotted (``agent.n_step``) -> (their TOML path, value); a
        table is walked unless it is a config key's value (``env_kwargs``)."""
        flat: dict[str, tuple] = {}
        sections = config_sections()

        def walk(node: dict[str, Any], prefix: str, path: tuple[str, ...]) -> None:
            for key, value in node.items():
                dotted = prefix + key
                if isinstance(value, dict) and (
                    dotted + "." in sections or dotted not in self.fields
                ):
                    walk(value, dotted + ".", (*path, key))
                else:
                    flat[dotted] = ((*path, key), value)

        walk(table, "", where)
        return flat

    def check_config_key(
        self, key: str, where: tuple[str, ...], recipes: list[str], table: str
    ) -> None:
        """A key the study does not set, that exists, and that no recipe fixes (the grid's
        keys: :meth:`check_overrides`)."""
        if key == "preset" and table == "[grid]":
            raise self.fail(
                where,
                "the grid cannot vary the preset: the config key preset only labels a run, and "
                "a preset's values are applied by preset in [base], one per study; to compare "
                "presets, run one study per preset, each spec with its own preset in [base]",
            )
        if key in STUDY_SETS:
            raise self.fail(where, f"the study sets {key} itself; give it as {STUDY_SETS[key]}")
        if key not in self.fields:
            hint = close_key_here(key, STUDY_SETS, "the study")
            raise self.fail(where, f"unknown config key {key!r}{hint}; {HELP_FIX}")
        for recipe, fixed in fixed_by(key, recipes).items():
            raise self.fail(
                where,
                f"recipe {recipe!r} fixes {key} = {show(fixed)}, and {table} would override "
                f"it, so {recipe!r} would no longer be itself; drop {key} from {table} (or "
                "compare a recipe that leaves it open)",
            )

    def check_overrides(
        self, key: str, values: list, where: tuple[str, ...], recipes: list[str], allowed: list
    ) -> None:
        """A grid key that a recipe fixes is refused, unless ``grid_overrides`` names it and
        the grid offers the recipe's own value (so the recipe as published is one setting)."""
        for recipe, fixed in fixed_by(key, recipes).items():
            if key not in allowed:
                raise self.fail(
                    where,
                    f"recipe {recipe!r} fixes {key} = {show(fixed)}, and the grid would "
                    f"override it, so {recipe!r} would no longer be itself; drop {key} from "
                    f"[grid], or, to tune it for every recipe alike, list it in grid_overrides "
                    f'= ["{key}"] (the grid must then offer {show(fixed)})',
                )
            if show(fixed) not in {show(v) for v in values}:
                raise self.fail(
                    where,
                    f"recipe {recipe!r} fixes {key} = {show(fixed)}, which the grid does not "
                    f"offer; add {show(fixed)} to its values, so that {recipe!r} as published "
                    "is one of its settings",
                )

    def typed(self, key: str, value: Any, where: tuple[str, ...]) -> Any:
        """A TOML value as the config key's type, read as ``--set KEY=VALUE`` reads it."""
        try:
            return parse_value(key, show(value), self.fields[key][0])
        except SetupError as err:
            raise self.fail(where, str(err)) from None

    def config_table(
        self, table: dict[str, Any], where: tuple[str, ...], recipes: list[str]
    ) -> dict[str, Any]:
        config = {}
        for key, (path, value) in self.flat(table, where).items():
            self.check_config_key(key, path, recipes, f"[{where[0]}]")
            config[key] = self.typed(key, value, path)
        return config

    def resolves(self, preset: str | None, overrides: dict[str, Any], where: tuple) -> None:
        """Each key alone on the preset, then all together: a bad value names its own line."""
        for key, value in overrides.items():
            try:
                resolve(preset, {key: value})
            except SetupError as err:
                raise self.fail((*where, *key.split(".")), str(err)) from None
        try:
            resolve(preset, overrides)
        except SetupError as err:
            raise self.fail(where, str(err)) from None

    def example_value(
        self, key: str, value: Any, where: tuple[str, ...], preset: str | None, base: dict
    ) -> str:
        """A valid value of ``key`` in TOML, for an example: ``value`` when it is one (a
        single value given where a list is wanted), else the value the study's base gives."""
        try:
            good = self.typed(key, value, where) if not isinstance(value, list) else None
        except SetupError:
            good = None
        if good is None:
            good = flatten(to_dict(resolve(preset, base))).get(key)
        return '"none"' if good is None else json.dumps(good)

    def grid(
        self,
        value: Any,
        recipes: list[str],
        preset: str | None,
        base: dict[str, Any],
        overrides: list[str],
    ) -> dict[str, list]:
        where = ("grid",)
        table = self.table(value, where)
        flat = self.flat(table, where)
        if not flat:
            raise self.fail(
                where,
                "the grid is empty; give at least one config key and its values, e.g. "
                "agent.n_step = [1, 3] (every recipe is tuned on the same grid)",
            )
        grid = {}
        for key, (path, values) in flat.items():
            self.check_config_key(key, path, [], "[grid]")
            if key in base:
                line = key_line(self.source.text, ("base", *key.split(".")))
                raise self.fail(
                    path,
                    f"{key} is in [base] too (line {line}), and the grid's values would override "
                    "it in every run; set it in one place only: in [grid] to tune it, or in "
                    "[base] to fix it",
                )
            if not isinstance(values, list) or not values:
                example = self.example_value(key, values, path, preset, base)
                raise self.fail(
                    path, f"give a non-empty list of values, e.g. {key} = [{example}, ...]"
                )
            typed = [self.typed(key, v, path) for v in values]
            if len({show(v) for v in typed}) < len(typed):
                raise self.fail(path, "a value is listed twice; list each value once")
            self.check_overrides(key, typed, path, recipes, overrides)
            for v in typed:
                try:
                    resolve(preset, {**base, key: v})
                except SetupError as err:
                    raise self.fail(path, f"{key} = {show(v)}: {err}") from None
            grid[key] = typed
        for key in overrides:
            if key not in grid:
                raise self.fail(
                    ("grid_overrides",),
                    f"{key!r} is no key of [grid]; list only grid keys a recipe fixes",
                )
        return grid

    def phase(self, value: Any, name: str) -> Phase:
        where = (name,)
        table = self.table(value, where)
        self.check_keys(table, where)
        for key in SCHEMA[where]:
            if key not in table:
                raise self.fail(where, f"no {key!r} ({SCHEMA[where][key]})")
        tasks = table["tasks"]
        if not isinstance(tasks, list) or not tasks or not all(isinstance(t, str) for t in tasks):
            raise self.fail((name, "tasks"), f"give a non-empty list ({SCHEMA[where]['tasks']})")
        repeated = sorted({t for t in tasks if tasks.count(t) > 1})
        if repeated:
            raise self.fail((name, "tasks"), f"{repeated[0]} is listed twice; list it once")
        from simoun_agent.run.make_env import ensure_registered

        for task in tasks:
            module, _, env_id = task.rpartition(":")  # MODULE:ID, as the env key takes it
            try:
                ensure_registered(env_id, module or None)
            except SetupError as err:
                raise self.fail((name, "tasks"), str(err)) from None
        seeds = self.per_task(table["seeds"], (name, "seeds"), tasks, self.seeds)
        env_steps = self.per_task(table["env_steps"], (name, "env_steps"), tasks, self.env_steps)
        return Phase(name, list(tasks), seeds, env_steps)

    def per_task(self, value: Any, where: tuple[str, ...], tasks: list[str], read) -> dict:
        """One value for every task, or a table with one per task."""
        if not isinstance(value, dict):
            one = read(value, where)
            return {task: one for task in tasks}
        for task in value:
            if task not in tasks:
                raise self.fail(
                    (*where, task),
                    f"{task!r} is not one of this phase's tasks ({', '.join(tasks)}); add it "
                    "to tasks or remove it here",
                )
        missing = [task for task in tasks if task not in value]
        if missing:
            raise self.fail(where, f"no value for the task {missing[0]!r}; give one per task")
        return {task: read(value[task], (*where, task)) for task in tasks}

    def seeds(self, value: Any, where: tuple[str, ...]) -> list[int]:
        if isinstance(value, str):
            try:
                seeds = parse_seeds(value)
            except SetupError as err:
                raise self.fail(where, str(err).replace("--seeds", "seeds")) from None
        elif isinstance(value, list) and all(
            isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in value
        ):
            seeds = list(value)
        else:
            raise self.fail(where, 'give non-negative integers: [1, 2, 3] or "1-3"')
        if not seeds:
            raise self.fail(where, "give at least one seed")
        if len(seeds) > MAX_SEEDS:
            raise self.fail(
                where, f"{len(seeds):,} seeds, past the cap of {MAX_SEEDS:,}; give fewer"
            )
        repeated = sorted({s for s in seeds if seeds.count(s) > 1})
        if repeated:
            raise self.fail(where, f"seed {repeated[0]} is listed twice; list each seed once")
        return seeds

    def env_steps(self, value: Any, where: tuple[str, ...]) -> int:
        if not isinstance(value, int) or isinstance(value, bool) or value < 1:
            raise self.fail(where, f"give a positive integer of env steps, not {value!r}")
        return value

    def disjoint(self, tuning: Phase, evaluation: Phase) -> None:
        tuned = {seed for seeds in tuning.seeds.values() for seed in seeds}
        for task in evaluation.tasks:
            shared = sorted(tuned & set(evaluation.seeds[task]))
            if shared:
                raise self.fail(
                    ("evaluation", "seeds", task),
                    f"seed {shared[0]} of {task} is a tuning seed too; evaluation seeds must be "
                    "held out (the selection saw the tuning seeds), so make the two sets "
                    f"disjoint, e.g. tuning seeds from 101 and evaluation seeds from 1",
                )

    def tasks(
        self,
        value: Any,
        tuning: Phase,
        evaluation: Phase,
        recipes: list[str],
        preset: str | None,
        base: dict[str, Any],
        grid: dict[str, list],
    ) -> dict[str, dict]:
        used = list(dict.fromkeys(tuning.tasks + evaluation.tasks))
        config = {}
        for task, extras, where in self.entries(
            value,
            "tasks",
            used,
            "no task of [tuning] or [evaluation]",
            "add it to a phase's tasks or remove this table",
        ):
            extras = self.config_table(self.table(extras, where), where, recipes)
            for key in extras:
                self.set_once(key, where, base, grid)
            self.resolves(preset, {**base, "env": task, **extras}, where)
            config[task] = extras
        return config

    def set_once(
        self, key: str, where: tuple[str, ...], base: dict[str, Any], grid: dict[str, list]
    ) -> None:
        """Refuse a per-task ``key`` that [base] or [grid] sets too: a run takes [base], then its
        task's table, then its grid setting, so one of the two values would be dropped without
        a word (a gridded key would override every task's own value)."""
        task = f'[tasks."{where[1]}"]'
        for table, values, dropped, there in (
            ("base", base, "[base]'s value is then used for no run of this task", "for every task"),
            (
                "grid",
                grid,
                f"the grid's values override {task}'s in every run of the task",
                "to tune it on every task",
            ),
        ):
            if key not in values:
                continue
            line = key_line(self.source.text, (table, *key.split(".")))
            raise self.fail(
                (*where, *key.split(".")),
                f"{key} is set in [{table}] too (line {line}), and {dropped}; set it in one "
                f"place only: in [{table}] {there}, or in each task's table (and drop it from "
                f"[{table}])",
            )

    def resources(self, value: Any) -> dict[str, Any]:
        where = ("resources",)
        table = self.table(value, where)
        self.check_keys(table, where)
        out: dict[str, Any] = {}
        for key in ("cpus_per_trial", "max_concurrent_trials"):
            if key in table:
                number = table[key]
                if not isinstance(number, int) or isinstance(number, bool) or number < 1:
                    raise self.fail((*where, key), f"give a positive integer, not {number!r}")
                out[key] = number
        if "gpus_per_trial" in table:
            gpus = table["gpus_per_trial"]
            number = isinstance(gpus, (int, float)) and not isinstance(gpus, bool)
            if not (gpus == "auto" or (number and gpus >= 0)):
                raise self.fail(
                    (*where, "gpus_per_trial"), f'give a number >= 0 or "auto", not {gpus!r}'
                )
            out["gpus_per_trial"] = gpus
        return out

    def diagnostics(self, value: Any, recipes: list[str]) -> dict[str, list[str]]:
        """Method -> its ablation recipes: the method is one of the study's recipes; each
        ablation is a known recipe, not compared in the study itself, listed once."""
        seen: set[str] = set()
        out = {}
        for method, ablations, where in self.entries(
            value,
            "diagnostics",
            recipes,
            "not one of the study's recipes",
            "diagnostics run at a compared recipe's selected setting",
        ):
            if not isinstance(ablations, list) or not ablations:
                raise self.fail(
                    where, f'give a non-empty list of recipes, e.g. {method} = ["{method}_no_aux"]'
                )
            for ablation in ablations:
                self.known_recipe(ablation, where)
                if ablation in recipes:
                    raise self.fail(
                        where,
                        f"{ablation!r} is one of the study's recipes, tuned and compared on its "
                        "own; a diagnostic runs at another recipe's setting, so list it in one "
                        "place",
                    )
                self.ablation_of(ablation, method, where)
                if ablation in seen:
                    raise self.fail(where, f"{ablation!r} is listed twice; list each once")
                seen.add(ablation)
            out[method] = list(ablations)
        return out

    def ablation_of(self, recipe: str, method: str, where: tuple[str, ...]) -> None:
        """Refuse a diagnostic ``recipe`` that is no ablation of ``method``: the report compares
        each with its method as the method with a part removed."""
        of = RECIPES[recipe].ablation_of
        if of == method:
            return
        if of is None:
            raise self.fail(
                where,
                f"{recipe!r} is no ablation (a method of its own); list the ablations of "
                f"{method!r} here, or compare {recipe!r} as one of the recipes",
            )
        raise self.fail(
            where,
            f"{recipe!r} is an ablation of {of!r}, not of {method!r}; list it under "
            f'{of} = ["{recipe}"], with {of!r} among the recipes',
        )

    def generalization(self, value: Any, evaluation: Phase) -> tuple[list[str], int]:
        """The distraction modes (checked, each a dm_control evaluation task's) and episodes."""
        if value is None:
            return [], StudySpec.generalization_episodes
        where = ("generalization",)
        table = self.table(value, where)
        self.check_keys(table, where)
        if "modes" not in table:
            raise self.fail(where, f"no 'modes' ({SCHEMA[where]['modes']})")
        modes = table["modes"]
        if not isinstance(modes, list) or not all(isinstance(m, str) for m in modes):
            raise self.fail((*where, "modes"), f"give a list ({SCHEMA[where]['modes']})")
        repeated = sorted({mode for mode in modes if modes.count(mode) > 1})
        if repeated:
            raise self.fail(
                (*where, "modes"), f"{repeated[0]!r} is listed twice; list each mode once"
            )
        try:
            modes = parse_distractions(modes, "modes")
        except SetupError as err:
            raise self.fail((*where, "modes"), str(err)) from None
        if "train" in modes:
            raise self.fail(
                (*where, "modes"),
                "the train mode is always played, as the return the others are divided by; "
                "list distraction modes only",
            )
        episodes = table.get("episodes", StudySpec.generalization_episodes)
        if not isinstance(episodes, int) or isinstance(episodes, bool) or episodes < 1:
            raise self.fail((*where, "episodes"), f"give a positive integer, not {episodes!r}")
        other = [task for task in evaluation.tasks if not task.startswith("dm_control/")]
        if other:
            raise self.fail(
                (*where, "modes"),
                f"the distraction modes recolour or re-render a MuJoCo scene, and the "
                f"evaluation task {other[0]} is no dm_control task; drop [generalization] or "
                "evaluate on dm_control tasks only",
            )
        return modes, episodes

    def check_runs(self, spec: StudySpec) -> None:
        """Resolve each recipe x task x setting x budget once (each diagnostic recipe with
        every setting its method may select), before anything runs."""
        checked = set()
        for phase in (spec.tuning, spec.evaluation):
            recipes = spec.recipes + (list(spec.ablations()) if phase is spec.evaluation else [])
            for task, recipe, setting in itertools.product(phase.tasks, recipes, spec.settings()):
                steps = phase.env_steps[task]
                overrides = spec.overrides(recipe, task, setting, phase.seeds[task][0], steps)
                key = json.dumps([recipe, task, steps, show(setting)])
                if key in checked:
                    continue
                checked.add(key)
                try:
                    resolve(spec.preset, overrides)
                except SetupError as err:
                    shown = ", ".join(f"{k} = {show(v)}" for k, v in setting.items())
                    raise self.fail(
                        ("recipes",), f"{recipe} on {task} with {shown}: {err}"
                    ) from None


def fixed_by(key: str, recipes: list[str]) -> dict[str, Any]:
    """recipe -> its own value of the config key ``key``, for the ``recipes`` that fix it."""
    field_name = key.removeprefix("agent.")
    return {
        recipe: RECIPES[recipe].values[field_name]
        for recipe in recipes
        if key.startswith("agent.") and field_name in RECIPES[recipe].values
    }


def json_round_trip(spec: StudySpec) -> StudySpec:
    """The spec as it reads back from ``study.json`` (tuples as lists), so both compare equal."""
    return StudySpec.from_json(spec.to_json())


def key_place(spec: StudySpec, task: str, key: str) -> tuple[str, ...] | None:
    """Where the spec gives config ``key`` for ``task``: its [grid], the task's own table, or
    [base] (the first that holds it, as they override each other); None when it does not."""
    if key in spec.grid:
        return ("grid", *key.split("."))
    if key in spec.task_config.get(task, {}):
        return ("tasks", task, *key.split("."))
    if key in spec.base:
        return ("base", *key.split("."))
    return None
