"""The grid of a sweep: ``--grid KEY=V1,V2`` (repeatable), ``--seeds 0-4``, ``--envs A,B`` over a
base config, expanded into one :class:`Trial` (one ordinary training run) per combination.

No Ray here: the grid is parsed, checked and saved (``sweep.json``) before Ray starts, so bad
input fails fast and a resumed sweep can be compared with the one it continues.

Example:
    >>> spec = SweepSpec.create(
    ...     None, {"agent.curiosity": False}, ["agent.encoder=stacked,single"], "0-1", None
    ... )
    >>> [(t.variant, t.seed) for t in spec.trials("sweep")]  # doctest: +NORMALIZE_WHITESPACE
    [('agent.encoder=stacked', 0), ('agent.encoder=stacked', 1),
     ('agent.encoder=single', 0), ('agent.encoder=single', 1)]
"""

from __future__ import annotations

import itertools
import json
import math
import re
import sys
import typing
from collections import Counter
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError, TrainConfig, resolve, to_dict
from simoun_agent.config.device import same_setting
from simoun_agent.config.envs import env_label
from simoun_agent.config.key_match import close_keys
from simoun_agent.config.keys import HELP_FIX, close_match, config_fields, parse_value
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import show
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import (
    Damaged,
    folder_problem,
    kind_problem,
    present,
    read_json_object,
    summary_problem,
)
from simoun_agent.run.layout import CHECKPOINT_NAME, CONFIG_NAME, SUMMARY_NAME
from simoun_agent.run.rundir import folder_kind
from simoun_lab.sweep.saved import saved_problem

SWEEP_FILE = "sweep.json"
"""The sweep's grid and base config, written once in the sweep directory."""

BASE_VARIANT = "base"
"""Variant name of a sweep without ``--grid`` (seeds and envs only)."""

DEDICATED = {
    "seed": "--seeds",
    "env": "--envs",
    "run_dir": "--sweep-dir (each trial's run directory is <variant>/<env>/s<seed> under it)",
    "torch_threads": "--cpus-per-trial (each trial gets one torch thread per CPU)",
}
"""Config keys a sweep sets itself, and the flag to use instead."""


MAX_SEEDS = 10_000
"""Seeds a sweep or study runs at most: more is a typo (``0-100000``), and a range that large
would be built in memory before anything could refuse it."""


def parse_seeds(text: str) -> list[int]:
    """``"0-4"`` -> [0, 1, 2, 3, 4]; ``"0,2,5"`` and mixes like ``"0-2,7"`` work too; at most
    :data:`MAX_SEEDS` seeds."""
    listed = listed_values(text)
    if listed is not None:
        raise SetupError(
            f"--seeds {text!r}: --seeds takes the seeds comma-separated, not a list in brackets; "
            f"write --seeds {','.join(listed)}"
        )
    check_commas("--seeds", text, spaces=False)
    seeds: list[int] = []
    for part in text.split(","):
        match = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if match is None:
            raise SetupError(
                f"--seeds {text!r}: cannot read {part!r}; give non-negative integers and ranges, "
                "e.g. --seeds 0-4 or --seeds 0,2,5"
            )
        first, last = int(match[1]), int(match[2] or match[1])
        if last < first:
            raise SetupError(
                f"--seeds {text!r}: the range {part.strip()!r} runs backwards; write it low-high, "
                f"e.g. --seeds {last}-{first}"
            )
        if len(seeds) + last - first + 1 > MAX_SEEDS:
            raise SetupError(
                f"--seeds {text!r} names {len(seeds) + last - first + 1:,} seeds or more, past the "
                f"cap of {MAX_SEEDS:,}; give fewer, e.g. --seeds 0-4"
            )
        seeds += range(first, last + 1)
    counts = Counter(seeds)
    duplicates = sorted(seed for seed, count in counts.items() if count > 1)
    if duplicates:
        raise SetupError(f"--seeds {text!r} names seed {duplicates[0]} twice; list each seed once")
    return seeds


def split_values(text: str) -> list[str]:
    """Split on the commas outside brackets and quotes, so JSON values keep theirs."""
    values, depth, quoted, start = [], 0, False, 0
    for i, char in enumerate(text):
        if char == '"' and text[i - 1 : i] != "\\":
            quoted = not quoted
        elif not quoted and char in "[{":
            depth += 1
        elif not quoted and char in "]}":
            depth -= 1
        elif not quoted and depth == 0 and char == ",":
            values.append(text[start:i])
            start = i + 1
    values.append(text[start:])
    return [value.strip() for value in values]


OTHER_SEPARATORS = ";|"
"""Separators a list flag is sometimes given with instead of commas."""


def check_commas(flag: str, text: str, key: str = "", spaces: bool = True) -> None:
    """Raise SetupError when the list ``text`` of ``flag`` (``--envs``, ``--seeds``, or
    ``--grid`` with ``key``) separates its values by ``;``, ``|`` (or, with ``spaces``, blanks)
    instead of commas: read as one value, it would be refused for a false reason, or taken as
    one."""
    for value in split_values(text):
        if value[:1] in '[{"':
            continue  # a JSON value may hold any of these
        found = [sep for sep in OTHER_SEPARATORS if sep in value]
        if spaces and len(value.split()) > 1:
            found.append(" ")
        if found:
            parts = [part for part in re.split(r"[;|\s]+", text) if part]
            given = f"{key}={text}" if key else text
            raise SetupError(
                f"{flag} {given!r}: values separated by {found[0]!r}; {flag} takes "
                f"comma-separated values, e.g. {flag} {key}{'=' if key else ''}{','.join(parts)}"
            )


def check_key(key: str, flag: str) -> None:
    """Raise SetupError for a key that is no config key (with the closest ones), that the sweep
    sets itself, or that only labels a run (``preset``, :func:`preset_grid_problem`)."""
    if key in DEDICATED:
        raise SetupError(f"{flag} cannot set {key}: the sweep sets it; use {DEDICATED[key]}")
    if key == "preset":
        raise SetupError(preset_grid_problem(flag))
    known = config_fields()
    if key not in known:
        hint = close_key_here(key, DEDICATED, "the sweep")
        raise SetupError(f"{flag}: unknown config key {key!r}{hint}; {HELP_FIX}")


def preset_grid_problem(flag: str) -> str:
    """Why ``preset`` cannot be a grid key: the config key only names the preset a run started
    from, and the preset's values (env, image size, budget) are applied by ``--preset`` to the
    whole sweep, whose one base config its budget, resume and report rest on; each trial would
    train the sweep's own preset under another name."""
    return (
        f"{flag}: --grid cannot vary the preset: the config key preset only labels a run, and a "
        "preset's values are applied by --preset, one per sweep; to compare presets, run one "
        "sweep per preset, each with its own --preset and --sweep-dir (e.g. --preset cpu "
        "--sweep-dir sweeps/cpu)"
    )


def close_key_here(key: str, set_here: dict[str, str], setter: str) -> str:
    """``" (did you mean agent.lr?)"`` for an unknown config ``key``, naming only keys that can
    be given where it was: the keys of ``set_here`` are set by ``setter`` itself (each mapped
    to where to give it instead), so the closest of them is answered with that place."""
    if any(known.startswith(key + ".") for known in config_fields()):
        return close_match(key)  # a section: one of its fields
    docs = {known: doc for known, (_, _, doc) in config_fields().items()}
    matches = close_keys(key, docs)
    allowed = [match for match in matches if match not in set_here]
    if allowed:
        return f" (did you mean {' or '.join(allowed)}?)"
    if matches:
        return f" ({setter} sets {matches[0]} itself: give it as {set_here[matches[0]]})"
    return ""


def parse_grid(pairs: list[str]) -> dict[str, list[Any]]:
    """``["agent.recipe=drq,sac"]`` -> ``{"agent.recipe": ["drq", "sac"]}``, values typed."""
    grid: dict[str, list[Any]] = {}
    fields = config_fields()
    for pair in pairs:
        key, sep, text = pair.partition("=")
        key = key.strip()
        if not sep:
            raise SetupError(
                f"--grid takes KEY=V1,V2,..., got {pair!r}; e.g. --grid agent.recipe=simoun,drq"
            )
        check_key(key, f"--grid {pair}")
        if key in grid:
            raise SetupError(f"--grid names {key} twice; give all its values in one --grid")
        check_commas("--grid", text.strip(), key, spaces=False)
        texts = split_values(text)
        if not text.strip() or any(not value for value in texts):
            raise SetupError(
                f"--grid {pair!r} has an empty value; give at least one, comma-separated, e.g. "
                f"--grid {key}=V1,V2"
            )
        listed = listed_values(text)
        if listed is not None and text_valued(fields[key][0]):
            # a text key reads "['simoun','drq']" as one value, refused later for a false reason
            raise SetupError(list_form_problem(key, text, listed, "a list in brackets"))
        values = [grid_value(key, text, value, fields[key][0]) for value in texts]
        if len(set(map(show, values))) < len(values):
            raise SetupError(f"--grid {pair!r} repeats a value; list each value once")
        grid[key] = values
    return grid


def grid_value(key: str, text: str, value: str, kind: Any) -> Any:
    """One value of ``--grid key=text`` read as ``key``'s type; SetupError naming ``--grid`` and
    its comma-separated form when it cannot be read, built from the values given when the whole
    ``text`` is written as a list (``[1e-3,3e-4]``) or a range (``1-3``)."""
    try:
        return parse_value(key, value, kind)
    except SetupError as err:
        said = f"--grid '{key}={text}'"
        values = listed_values(text) or range_values(text)
        if values is None:
            raise SetupError(
                f"{said}: {err}; --grid takes comma-separated values, e.g. --grid {key}=V1,V2"
            ) from None
        form = "a list in brackets" if text.strip()[:1] in "[(" else "a range"
        raise SetupError(list_form_problem(key, text, values, form)) from None


def list_form_problem(key: str, text: str, values: list[str], form: str) -> str:
    """The refusal of ``--grid key=text`` written as ``form`` (a bracketed list, a range) of
    ``values``, with the comma-separated form --grid takes."""
    return (
        f"--grid {f'{key}={text}'!r}: --grid takes each value, comma-separated, not {form}; write "
        f"--grid {key}={','.join(values)}"
    )


def text_valued(kind: Any) -> bool:
    """Whether a config key of type ``kind`` holds text (``str``, ``str | None``): any value
    reads as one, a bracketed list too."""
    args = set(typing.get_args(kind)) or {kind}
    return str in args and args <= {str, type(None)}


def listed_values(text: str) -> list[str] | None:
    """The values of ``text`` written as a bracketed list (``[1e-3, 3e-4]``, ``(1, 3)``), else
    None."""
    stripped = text.strip()
    if len(stripped) < 2 or (stripped[0], stripped[-1]) not in (("[", "]"), ("(", ")")):
        return None
    values = [value.strip().strip("'\"") for value in stripped[1:-1].split(",")]
    return values if all(values) else None


GRID_RANGE = re.compile(r"\s*(\d+)\s*(?:-|\.\.|:|\u2013)\s*(\d+)\s*")
"""A range of whole numbers as a list flag is sometimes given it: ``1-3``, ``1..3``, ``1:3``."""


def range_values(text: str) -> list[str] | None:
    """The whole numbers of ``text`` written as a range low-high (``1-3``: 1, 2, 3; at most
    :data:`MAX_SEEDS`), else None."""
    match = GRID_RANGE.fullmatch(text)
    if match is None:
        return None
    first, last = sorted((int(match[1]), int(match[2])))
    if last - first >= MAX_SEEDS:
        return None
    return [str(number) for number in range(first, last + 1)]


def gpus_wanted(wanted: str) -> float | None:
    """``--gpus-per-trial``'s value as a number, None for ``auto``; read before Ray starts, so
    a bad value is answered at once."""
    if wanted == "auto":
        return None
    try:
        gpus = float(wanted)
    except ValueError:
        raise SetupError(
            f"--gpus-per-trial takes a number or auto, got {wanted!r}; e.g. --gpus-per-trial 1"
        ) from None
    if not (math.isfinite(gpus) and gpus >= 0):
        raise SetupError(f"--gpus-per-trial must be a finite number, 0 or more, got {wanted}")
    return gpus


def path_part(text: str) -> str:
    """A safe directory name: env ids and values keep letters, digits and ``.=,+-_``."""
    return re.sub(r"[^A-Za-z0-9.=,+_-]", "-", text)


@dataclass(frozen=True)
class Trial:
    """One training run of the sweep."""

    variant: str
    """the grid values of this run, e.g. ``agent.recipe=drq`` (``base`` without a grid)"""
    env: str
    """Gymnasium id"""
    seed: int
    """the run's seed"""
    run_dir: str
    """its run directory, ``<sweep>/<variant>/<env>/s<seed>``"""
    preset: str | None
    """the base preset"""
    overrides: dict
    """flat config overrides (base, grid values, env, seed, run_dir, torch_threads)"""

    @property
    def name(self) -> str:
        return f"{self.variant}/{env_label(self.env)}/s{self.seed}"


@dataclass
class SweepSpec:
    """What a sweep runs; saved as ``sweep.json`` and compared when the sweep is resumed."""

    preset: str | None
    """the base preset (``--preset``)"""
    base: dict
    """the base config overrides, flat (``{"agent.lr": 3e-4}``), as ``simoun-train`` takes them"""
    grid: dict
    """config key -> the values to try (their product makes the variants)"""
    seeds: list
    """seeds of every variant x env"""
    envs: list
    """Gymnasium ids of every variant"""
    cpus_per_trial: int = 1
    """CPUs Ray reserves per trial; the trial runs with as many torch threads"""

    @classmethod
    def create(
        cls,
        preset: str | None,
        base: dict[str, Any],
        grid_pairs: list[str],
        seeds: str | None,
        envs: str | None,
        cpus_per_trial: int = 1,
    ) -> SweepSpec:
        """Parse and check the sweep's flags (raises SetupError naming the flag and the fix)."""
        for key in ("run_dir", "torch_threads"):
            if key in base:
                raise SetupError(f"a sweep sets {key} itself; drop it and use {DEDICATED[key]}")
        if "seed" in base and seeds is not None:
            raise SetupError("give the seeds once: --seeds (e.g. --seeds 0-4), not --seed too")
        if "env" in base and envs is not None:
            raise SetupError("give the envs once: --envs A,B, not --env too")
        if cpus_per_trial < 1:
            raise SetupError(f"--cpus-per-trial must be at least 1, got {cpus_per_trial}")
        grid = parse_grid(grid_pairs)
        both = sorted(set(grid) & set(base))
        if both:
            raise SetupError(
                f"{both[0]} is given both as a base flag and in --grid; keep it in one place"
            )
        base_config = resolve(preset, base)
        if envs is None and base_config.env_module is not None:
            # each trial sets the bare id; the module that registers it (--env MODULE:ID) has
            # to reach the trials' own processes too
            base = {**base, "env_module": base_config.env_module}
        seed_list = parse_seeds(seeds) if seeds is not None else [base_config.seed]
        if envs is not None:
            listed = listed_values(envs)
            if listed is not None:
                raise SetupError(
                    f"--envs {envs!r}: --envs takes the ids comma-separated, not a list in "
                    f"brackets; write --envs {','.join(listed)}"
                )
            check_commas("--envs", envs)
        env_list = split_values(envs) if envs is not None else [base_config.env]
        if not all(env_list):
            raise SetupError(f"--envs {envs!r} has an empty id; e.g. --envs simoun/PointReach-v0")
        twice = [env for env, count in Counter(env_list).items() if count > 1]
        if twice:
            raise SetupError(f"--envs {envs!r} names {twice[0]} twice; list each env once")
        spec = cls(preset, _plain(base), _plain(grid), seed_list, env_list, cpus_per_trial)
        spec.check_trials()
        return spec

    def variants(self) -> list[dict[str, Any]]:
        """Each combination of grid values, in the order given (one ``{}`` without a grid)."""
        combos = itertools.product(*self.grid.values())
        return [dict(zip(self.grid, combo, strict=True)) for combo in combos]

    def trials(self, sweep_dir: Path | str) -> list[Trial]:
        """Every trial: variants x envs x seeds, each with its own run directory."""
        trials = []
        for values in self.variants():
            variant = ",".join(f"{key}={show(value)}" for key, value in values.items())
            variant = variant or BASE_VARIANT
            for env, seed in itertools.product(self.envs, self.seeds):
                run_dir = Path(sweep_dir, path_part(variant), path_part(env_label(env)), f"s{seed}")
                overrides = {
                    "progress": False,
                    **self.base,
                    **values,
                    "env": env,
                    "seed": seed,
                    "run_dir": str(run_dir),
                    "torch_threads": self.cpus_per_trial,
                }
                trials.append(
                    Trial(variant, env, seed, str(run_dir), self.preset, typed(overrides))
                )
        return trials

    def check_trials(self, source: str = "--grid / --envs") -> None:
        """Resolve every trial's config now (unknown recipe, a value its key refuses, a preset
        meant for another env...), before anything runs; two trials may not share a directory.
        ``source`` is where the grid came from, for the messages."""
        seen: dict[str, Trial] = {}
        for trial in self.trials("."):
            try:
                resolve(trial.preset, trial.overrides)
            except SetupError as err:
                note = grid_note(str(err), trial, self.grid) if source.startswith("--grid") else ""
                raise SetupError(f"trial {trial.name} (from {source}): {err}{note}") from None
            if trial.run_dir in seen:
                first = seen[trial.run_dir]
                fix = "make their --grid values differ in letters or digits"
                if first.env != trial.env:
                    fix = (
                        f"--envs gives {first.env} and {trial.env}, one task by its name "
                        f"({env_label(trial.env)}); keep one of them"
                    )
                raise SetupError(
                    f"trials {first.name} and {trial.name} would share the run directory "
                    f"{trial.run_dir}; {fix}"
                )
            seen[trial.run_dir] = trial

    def total_env_steps(self) -> int:
        """The env-step budget of every trial (the base flags', else the preset's)."""
        return resolve(self.preset, self.base).total_env_steps

    def extended(self, total_env_steps: int) -> SweepSpec:
        """This sweep with every trial trained to ``total_env_steps``: its finished trials go on
        from their final checkpoints. A sweep can grow, never shrink."""
        if "total_env_steps" in self.grid:
            raise SetupError(
                "--total-env-steps cannot extend this sweep: its --grid sets total_env_steps; "
                "start a new sweep in another --sweep-dir"
            )
        current = self.total_env_steps()
        if total_env_steps < current:
            raise SetupError(
                f"--total-env-steps {total_env_steps} is below the sweep's {current}: a sweep is "
                f"extended, never shortened; pass a larger value (e.g. --total-env-steps "
                f"{2 * current}) or start a new sweep in another --sweep-dir"
            )
        return replace(self, base={**self.base, "total_env_steps": total_env_steps})

    def save(self, sweep_dir: Path) -> None:
        text = json.dumps(asdict(self), indent=2) + "\n"
        atomic_write(sweep_dir / SWEEP_FILE, lambda tmp: tmp.write_text(text))

    @classmethod
    def load(cls, sweep_dir: Path) -> SweepSpec:
        """The sweep saved in ``sweep_dir`` (its directory, or its ``sweep.json`` itself);
        SetupError when there is none, or when the file is damaged."""
        sweep_dir = Path(sweep_dir)
        if sweep_dir.name == SWEEP_FILE and not sweep_dir.is_dir():
            sweep_dir = sweep_dir.parent  # the file itself: read it, not sweep.json/sweep.json
        path = sweep_dir / SWEEP_FILE
        if not present(path) and (kind := folder_kind(sweep_dir)) is not None:
            raise SetupError(
                f"{sweep_dir} holds no sweep ({SWEEP_FILE} is missing): it is {kind}; pass the "
                "--sweep-dir of a sweep that simoun-sweep started"
            )
        if not present(path):
            raise SetupError(
                f"{sweep_dir} holds no sweep ({SWEEP_FILE} is missing); pass the --sweep-dir of "
                "a sweep that simoun-sweep started, or drop --resume to start one"
            )
        try:
            data = read_json_object(path)
        except Damaged as err:
            problem = str(err)
        else:
            problem = saved_problem(data) or ""
        if not problem:
            spec = cls(**data)
            try:
                spec.check_trials(SWEEP_FILE)
            except SetupError as err:
                problem = str(err)
        if problem:
            raise SetupError(
                f"{path} is damaged ({problem}); restore it from a copy (it records the sweep's "
                "base, grid, seeds and envs), or start a new sweep in a new --sweep-dir"
            )
        return spec


DAMAGED_DIR = "its directory is damaged: "


def trial_problem(trial: Trial, grid: dict[str, list[Any]]) -> str | None:
    """What is wrong with a started trial's run directory: its config.json missing while other
    files are there, damaged, or recording another env, seed or ``grid`` value than the trial's
    (a run copied in from elsewhere, a config.json replaced); None for a trial not started (no
    directory, or an empty one) and for one whose config.json is its own. The answer starts
    with the name config.json, or with "its directory" when no run's directory stands in the
    trial's place (:func:`~simoun_agent.run.kept.folder_problem`)."""
    run_dir = Path(trial.run_dir)
    problem = folder_problem(run_dir)
    if problem:
        return DAMAGED_DIR + problem
    if not run_dir.is_dir() or not any(run_dir.iterdir()):
        return None
    path = run_dir / CONFIG_NAME
    if not present(path):
        return f"{CONFIG_NAME} is missing, though the run's other files are there"
    try:
        record = read_json_object(path)
    except Damaged as err:
        return f"{CONFIG_NAME} is damaged: {err}"
    if problem := kind_problem(CONFIG_NAME, list(record)):
        return f"{CONFIG_NAME} is damaged: {problem}"
    saved = flatten(record)
    for key in ("env", "seed", *grid):
        recorded, wanted = _plain(saved.get(key)), _plain(trial.overrides[key])
        if key in saved and not same_setting(key, recorded, wanted):
            return (
                f"{CONFIG_NAME} records {key} {show(recorded)}, but the sweep's trial "
                f"{trial.name} has {show(wanted)}: it is another run's config"
            )
    return None


RESUMED_AS_GIVEN = ("run_dir", "torch_threads", "total_env_steps", "progress")
"""The keys a started trial's config.json may hold apart from the sweep's: the sweep directory
moved, ``--cpus-per-trial`` and ``--total-env-steps`` given with ``--resume``, and the progress
bar, none of which changes what the trial learns."""


def config_differences(trial: Trial) -> dict[str, tuple[Any, Any]]:
    """Each key the started trial's config.json (read whole by :func:`trial_problem`) records
    with another value than the sweep gives the trial (its base, preset and grid, resolved):
    key -> (saved, given by the sweep); :data:`RESUMED_AS_GIVEN` and keys a run of an older
    version did not save are left out. A resumed trial goes on with its saved config, so such
    a key means ``sweep.json`` was changed after the trial started, or, for a key the sweep
    leaves to its default, that this version's default differs."""
    path = Path(trial.run_dir) / CONFIG_NAME
    if not present(path):
        return {}
    saved = flatten(read_json_object(path))
    wanted = flatten(to_dict(resolve(trial.preset, trial.overrides)))
    return {
        key: (_plain(saved[key]), _plain(value))
        for key, value in wanted.items()
        if key in saved
        and key not in RESUMED_AS_GIVEN
        and not same_setting(key, _plain(saved[key]), _plain(value))
    }


def differences_refusal(trial: Trial, sweep_dir: Path, differences: dict) -> SetupError:
    """The refusal of a trial whose config.json differs from the sweep (:func:`config_differences`),
    with the causes its keys allow and the fixes."""
    values = "; ".join(
        f"{key} {show(saved)} where the sweep gives {show(given)}"
        for key, (saved, given) in differences.items()
    )
    defaults = any(key not in trial.overrides for key in differences)
    cause = " or this version of simoun gives a default another value" if defaults else ""
    version = ", resume with the version of simoun that started the sweep" if defaults else ""
    return SetupError(
        f"trial {trial.name} was trained with {values} ({Path(trial.run_dir, CONFIG_NAME)}), and "
        f"a resumed trial keeps its own config: {Path(sweep_dir, SWEEP_FILE)} was changed after "
        f"the trial started,{cause}. Restore {SWEEP_FILE} as it was (the values the trial was "
        f"trained with){version}, or start a new sweep in a new --sweep-dir"
    )


def check_trial_dirs(spec: SweepSpec, sweep_dir: Path) -> None:
    """SetupError naming the first trial whose run directory is not its own
    (:func:`trial_problem`), or whose config.json differs from what ``sweep.json`` gives it
    (:func:`config_differences`), or whose summary.json cannot be relied on
    (:func:`~simoun_agent.run.kept.summary_problem`), before the sweep counts it as finished or
    goes on from it."""
    for trial in spec.trials(sweep_dir):
        problem = trial_problem(trial, spec.grid)
        if problem and not problem.startswith(CONFIG_NAME):
            run_dir = trial.run_dir
            raise SetupError(
                f"trial {trial.name}: {run_dir} (its run directory) is damaged: "
                f"{problem.removeprefix(DAMAGED_DIR)}; restore the trial from a copy (or point "
                f"the link at it), or remove what stands there (rm {run_dir}) so that the trial "
                "trains anew"
            )
        if problem:
            run_dir = trial.run_dir
            raise SetupError(
                f"trial {trial.name}: {Path(run_dir, CONFIG_NAME)} {problem.partition(' ')[2]}; "
                f"restore {CONFIG_NAME} from a copy, or move the run directory aside (mv "
                f"{run_dir} {run_dir}.aside) so that the trial trains anew"
            )
        differences = config_differences(trial)
        if differences:
            raise differences_refusal(trial, sweep_dir, differences)
        problem = summary_problem(Path(trial.run_dir) / SUMMARY_NAME)
        if problem:  # else the trial would count as finished, its result left to the report
            raise damaged_summary(trial, problem)


def damaged_summary(trial: Trial, problem: str) -> SetupError:
    """The refusal of a trial whose summary.json says ``problem``: with its checkpoint kept,
    removing the file lets the resume write the trial's end again without training."""
    run_dir, path = trial.run_dir, Path(trial.run_dir, SUMMARY_NAME)
    rewrite = (
        f"remove it (rm {path}) so that the resume writes the trial's end again from its "
        "checkpoint, without training, "
        if Path(run_dir, CHECKPOINT_NAME).is_file()
        else ""
    )
    return SetupError(
        f"trial {trial.name}: {path} is damaged: {problem}; {rewrite}restore {SUMMARY_NAME} from "
        f"a copy, or move the run directory aside (mv {run_dir} {run_dir}.aside) so that the "
        "trial trains anew"
    )


def check_runnable(
    trials: list[Trial], envs_flag: str, grid: dict[str, list[Any]] | None = None
) -> None:
    """Run ``simoun-train``'s checks of a new run on every trial, before Ray starts any: make
    each trial's env once, check each trial's config against its env (its evaluation
    distractions, action repeat and budget) and estimate each configuration's memory on this
    machine. SetupError naming the flag (or the ``grid`` key, ``--grid``) and the fix for the
    first that cannot run (an unknown id with its close matches, discrete actions, a
    distraction mode the env cannot take, frames or a replay the memory cannot hold).
    ``envs_flag`` is the flag that gave the envs."""
    # here, not at the top: reading and saving a grid needs neither torch nor the env suites
    from simoun_agent.run.make_env import check_decisions, check_task
    from simoun_agent.run.memory import check_memory, check_replay
    from simoun_agent.run.train import budget_warning

    grid = grid or {}
    made: dict[str, int | None] = {}
    measured: set[str] = set()
    for trial in trials:
        config = resolve(trial.preset, trial.overrides)
        made_as = [config.env, config.env_kwargs, config.env_module, config.cameras]
        env = json.dumps(made_as, sort_keys=True)
        if env not in made:
            try:
                made[env] = check_task(config)
            except SetupError as err:
                raise task_refusal(trial, err, envs_flag, grid) from None
        try:
            check_trial_config(config, grid)
            check_decisions(config, made[env])  # the action repeat may differ by trial
            check_replay(config, made[env])
        except SetupError as err:
            raise SetupError(
                f"trial {trial.name}: {err}{grid_note(str(err), trial, grid)}"
            ) from None
        memory = {**asdict(config), "env": None, "seed": None, "run_dir": None}
        key = json.dumps(memory, sort_keys=True, default=str)
        if key not in measured:
            measured.add(key)
            try:
                warning = check_memory(config)
            except SetupError as err:
                note = grid_note(str(err), trial, grid)
                raise SetupError(f"trial {trial.name}: {err}{note}") from None
            for said in (warning, budget_warning(config)):
                if said:
                    said += grid_note(said, trial, grid)
                    print(f"simoun-sweep: warning: trial {trial.name}: {said}", file=sys.stderr)


ENV_KEYS = ("env_module", "env_kwargs", "cameras", "action_repeat")
"""Config keys that change how a trial's env is made or stepped: a task refused with one of
them from ``--grid``, and made without it, is refused for that grid value, not for ``--envs``."""

DROP_MODULE = ", or drop the module from --env"
"""The fix a refused module is given when it came with ``--env MODULE:ID``."""


def task_refusal(
    trial: Trial, err: SetupError, envs_flag: str, grid: dict[str, list[Any]]
) -> SetupError:
    """The refusal of ``trial``'s task (``err``, from making it): for the grid value of an env
    setting (:data:`ENV_KEYS`) without which the task is made, that value and the fix in
    ``--grid``; else the task, as ``envs_flag`` gave it."""
    from simoun_agent.run.make_env import check_task

    for key in ENV_KEYS:
        if key not in grid:
            continue
        without = {k: v for k, v in trial.overrides.items() if k != key}
        try:
            check_task(resolve(trial.preset, without))
        except SetupError:
            continue
        said = str(err).replace(DROP_MODULE, "")
        return SetupError(f"trial {trial.name}: {said}; {value_note(key, trial, grid[key])}")
    return SetupError(f"{envs_flag} {trial.env}: {err}")


def grid_note(said: str, trial: Trial, grid: dict[str, list[Any]]) -> str:
    """For each ``grid`` key whose flag the message ``said`` about ``trial`` names (its fix
    advises ``--action-repeat 40``), the note that the trial's value came from ``--grid`` and
    that the fix goes there (:func:`value_note`). Empty when the message names no gridded key."""
    notes = [
        value_note(key, trial, values)
        for key, values in grid.items()
        if re.search(re.escape(key_flag(key)) + r"(?![\w.-])", said) is not None
    ]
    return "".join(f"; {note}" for note in notes)


def key_flag(key: str) -> str:
    """``agent.n_step`` -> ``--agent.n-step``."""
    return "--" + key.replace("_", "-")


def value_note(key: str, trial: Trial, values: list[Any]) -> str:
    """The note that ``trial``'s value of ``key`` came from ``--grid`` (of ``values``) and that
    the fix goes there: the key's base flag is refused beside ``--grid``."""
    flag, value = key_flag(key), show(trial.overrides[key])
    given = f"{key}={','.join(show(v) for v in values)}"
    return (
        f"{flag} {value} is this trial's value from --grid {given}: make the fix in "
        f"--grid (leave {value} out of its values, or replace it by a value that works), "
        f"not as a base {flag}, which --grid refuses beside it"
    )


def check_trial_config(config: TrainConfig, grid: dict[str, list[Any]]) -> None:
    """``simoun-train``'s checks of a new run's config on its own (its evaluation distractions
    against its env, one agent decision within its budget), the modes named as the sweep was
    given them (``--grid eval_distraction`` when the grid sets them)."""
    from simoun_agent.generalization import check_eval_distractions
    from simoun_agent.run.train import check_budget

    gridded = "eval_distraction" in grid
    check_eval_distractions(config, "--grid eval_distraction" if gridded else "--eval-distraction")
    check_budget(config)


def check_devices(trials: list[Trial], gpus: float | None, grid: dict[str, list[Any]]) -> None:
    """Refuse ``--gpus-per-trial`` (``gpus``; None: auto, which follows the device) when it
    contradicts a trial's ``--device`` (or ``--grid device``) (:func:`devices_problem`)."""
    if gpus is None:
        return
    for trial in trials:
        # as given, not resolved: resolving asks this machine for the device, and the trials
        # may run on other machines of the cluster
        device = trial.overrides.get("device", resolve(trial.preset, {}).device)
        if "device" in grid:
            given, key = f"--grid device={device} (trial {trial.name})", "--grid device"
        else:
            given, key = f"--device {device}", "--device"
        problem = devices_problem(
            device, gpus, (f"--gpus-per-trial {gpus:g}", "--gpus-per-trial"), (given, key)
        )
        if problem:
            raise SetupError(problem)


def devices_problem(
    device: str | None, gpus: float, gpus_given: tuple[str, str], device_given: tuple[str, str]
) -> str | None:
    """What is contradictory in a trial that trains on ``device`` with ``gpus`` GPUs reserved,
    each given as (what was said, the key to change): GPUs reserved for a trial that trains on
    the CPU (or on MPS, which Ray does not count) cap the trials run at once for nothing, and
    Ray hides the GPUs from a trial that reserves none, so a CUDA device fails in it. None when
    they fit (a device left unset takes cuda when the trial sees a GPU, else the CPU)."""
    if device is None:
        return None
    (gpus_said, gpus_key), (device_said, device_key) = gpus_given, device_given
    cuda = device.startswith("cuda")
    if gpus > 0 and not cuda:
        return (
            f"{gpus_said} and {device_said} contradict each other: each trial would reserve "
            f"{gpus:g} GPU{'s' * (gpus != 1)} it never uses, and the GPUs, not the CPUs, would "
            f"cap how many trials run at once; drop {gpus_key} (auto reserves none for a "
            f"{device} trial) or set it to 0, or set {device_key} to cuda to train on the GPUs"
        )
    if gpus == 0 and cuda:
        return (
            f"{gpus_said} and {device_said} contradict each other: Ray shows no GPU to a trial "
            f"that reserves none, so it could not train on {device}; set {gpus_key} to 1 (or "
            f"drop it: auto gives each trial one when the cluster has GPUs), or set {device_key} "
            "to cpu"
        )
    return None


def typed(overrides: dict[str, Any]) -> dict[str, Any]:
    """Lists back to tuples for tuple-typed keys (JSON has no tuples)."""
    fields = config_fields()
    return {
        key: tuple(value)
        if isinstance(value, list) and typing.get_origin(fields[key][0]) is tuple
        else value
        for key, value in overrides.items()
    }


def _plain(value: Any) -> Any:
    """The JSON form (tuples as lists), so a fresh spec compares equal to a loaded one."""
    return json.loads(json.dumps(value))
