"""What a study checks before it spends compute, and what a resumed study lets its spec change.

:func:`check_study` makes each task once and estimates the memory of each configuration, so
that ``simoun-study plan`` (and ``run``, before any trial) refuses a task the agent cannot
train on (discrete or unbounded actions, no pixels) or a setting the machine cannot hold, naming
the spec's file and line. The frame size against each recipe's encoder is checked as the spec
is read (:meth:`~simoun_lab.study.spec._Reader.check_runs`).

:func:`check_fixed_spec` lets a study resume under a spec fixed after a failure (a task that
cannot run replaced, seeds added, a budget raised for runs not finished yet), as long as every
finished run would be trained the same way under the fixed spec, and no recipe whose
evaluation started would select another setting.
"""

from __future__ import annotations

import json
import os
import re
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError, TrainConfig, resolve, to_dict
from simoun_agent.config.device import device_keys, same_setting
from simoun_agent.run.kept import (
    Damaged,
    folder_problem,
    kind_problem,
    present,
    read_json_object,
    summary_problem,
)
from simoun_agent.run.layout import CONFIG_NAME, SUMMARY_NAME
from simoun_agent.run.make_env import check_task
from simoun_agent.run.memory import SPEC_KEYS, check_memory, check_replay
from simoun_lab.study.plan import EVALUATION, TUNING, StudyRun, evaluation_runs, tuning_runs
from simoun_lab.study.spec import Source, StudySpec, key_place, spec_text
from simoun_lab.sweep.grid import devices_problem

MEMORY_KEYS = ("image_size", "agent.batch_size", "replay_capacity")
"""The keys a memory refusal asks to change, looked up in the spec to name their line."""

NOT_TRAINING = ("run_dir", "torch_threads", "progress")
"""Config keys that change where a run writes and how fast it goes, not what it learns: a
fixed spec may change them for finished runs."""


def configs(spec: StudySpec) -> list[tuple[str, str, dict[str, Any], TrainConfig]]:
    """(phase, recipe, setting, config) of each recipe x task x setting of both phases (the
    diagnostic recipes with every setting their method may select)."""
    found = []
    for phase in (spec.tuning, spec.evaluation):
        recipes = spec.recipes + (list(spec.ablations()) if phase is spec.evaluation else [])
        for task in phase.tasks:
            for recipe in recipes:
                for setting in spec.settings():
                    seed, steps = phase.seeds[task][0], phase.env_steps[task]
                    overrides = spec.overrides(recipe, task, setting, seed, steps)
                    found.append((phase.name, recipe, setting, resolve(spec.preset, overrides)))
    return found


def memory_line(spec: StudySpec, task: str) -> tuple[str, ...]:
    """Where a memory refusal points: the first memory key the spec sets (grid, the task's
    table, base), else the [base] table."""
    for key in MEMORY_KEYS:
        place = key_place(spec, task, key)
        if place is not None:
            return place
    return ("base",)


ENV_SETTINGS = ("env_module", "env_kwargs", "cameras", "action_repeat")
"""Config keys that change how a task's env is made or stepped: a task refused with one of them
that the spec sets, and made without it, is refused for that key, not for the task."""

FLAG = re.compile(r"--([a-z][a-z0-9-]*(?:\.[a-z][a-z0-9-]*)*)")
"""A command-line flag in a message (``--env-kwargs``, ``--agent.batch-size``)."""


def in_spec_terms(message: str) -> str:
    """``message`` with each config flag spelled as the spec's key (``--env-kwargs`` ->
    ``env_kwargs``), and the command line's fix for a module spelled as the spec's."""
    message = message.replace("drop the module from --env", "drop env_module")
    return FLAG.sub(lambda flag: flag[1].replace("-", "_"), message)


def setting_at_fault(
    spec: StudySpec, config: TrainConfig, overrides: dict[str, Any]
) -> tuple[str, ...] | None:
    """Where the spec gives the env setting (:data:`ENV_SETTINGS`) without which ``config``'s
    task is made and stepped, for a task refused with it; None when the task itself is at
    fault (an unknown id, discrete actions), or when no setting the spec gives is. Without it
    means the run's ``overrides`` less that key, resolved as the run is: the preset's value of
    the key then stands (highway's continuous actions in its ``env_kwargs``), not the default."""
    for key in ENV_SETTINGS:
        place = key_place(spec, config.env, key)
        if place is None:
            continue
        unset = {name: value for name, value in overrides.items() if name != key}
        try:
            check_task(resolve(spec.preset, unset))
        except SetupError:
            continue
        return place
    return None


def task_error(
    source: Source,
    spec: StudySpec,
    phase: str,
    run: tuple[TrainConfig, dict[str, Any]],
    err: SetupError,
) -> SetupError:
    """The refusal of a task the recipes cannot train on (``run``: the config of a run on it,
    and the spec's overrides it was resolved from), at the spec's line: the env setting at
    fault (:func:`setting_at_fault`) where the spec writes it, in the spec's terms, else the
    phase's tasks."""
    config, overrides = run
    said = str(err).rstrip(".")
    place = setting_at_fault(spec, config, overrides)
    if place is not None:
        return source.error(
            place,
            f"{config.env} cannot be trained with it: {in_spec_terms(said)}",
        )
    if not said.startswith(config.env):
        said = f"{config.env} cannot be trained by the recipes: {said}"
    return source.error(
        (phase, "tasks"),
        f"{said}. Replace it in [{phase}] tasks (the spec is read before anything runs).",
    )


def check_study_devices(source: Source, spec: StudySpec, config: TrainConfig) -> None:
    """Refuse [resources] gpus_per_trial when it contradicts the device a run trains on
    (:func:`~simoun_lab.sweep.grid.devices_problem`), naming the gpus_per_trial line."""
    if spec.gpus_per_trial == "auto":
        return
    gpus = float(spec.gpus_per_trial)
    place = key_place(spec, config.env, "device")
    device_said = f"[{place[0]}] device = {json.dumps(config.device)}" if place else "device"
    problem = devices_problem(
        config.device,
        gpus,
        (f"gpus_per_trial = {gpus:g}", "gpus_per_trial"),
        (device_said, "device"),
    )
    if problem:
        raise source.error(("resources", "gpus_per_trial"), problem)


def check_run_config(
    source: Source, spec: StudySpec, phase: str, config: TrainConfig, limit: int | None
) -> None:
    """``simoun-train``'s checks of one run's config against its task (its evaluation
    distractions, its action repeat against the episodes and the budget), naming the spec's
    line of the key at fault."""
    from simoun_agent.generalization import check_eval_distractions
    from simoun_agent.run.make_env import check_decisions
    from simoun_agent.run.train import check_budget

    task = config.env
    try:
        check_eval_distractions(config, "eval_distraction")
    except SetupError as err:
        place = key_place(spec, task, "eval_distraction") or ("base",)
        raise source.error(place, str(err)) from None
    for check, keys in (
        (lambda: check_decisions(config, limit), ("action_repeat",)),
        (lambda: check_budget(config), ("action_repeat",)),
    ):
        try:
            check()
        except SetupError as err:
            place = key_place(spec, task, keys[0]) or (phase, "tasks")
            raise source.error(place, f"{task}: {in_spec_terms(str(err))}") from None


def check_study(spec: StudySpec, spec_path: str) -> None:
    """Make each task once, check that the replay holds a batch of its episodes and estimate
    each configuration's memory; SetupError naming the spec's line, the task and the fix for
    the first that cannot run (the tasks first: they take a second each, a memory estimate
    several)."""
    source = Source(Path(spec_path), spec_text(Path(spec_path)))
    made: dict[str, int | None] = {}
    found = configs(spec)
    for phase, recipe, setting, config in found:
        env = json.dumps([config.env, config.env_kwargs, config.env_module], sort_keys=True)
        if env not in made:
            try:
                made[env] = check_task(config)
            except SetupError as err:
                overrides = spec.overrides(
                    recipe, config.env, setting, config.seed, config.total_env_steps
                )
                raise task_error(source, spec, phase, (config, overrides), err) from None
        check_run_config(source, spec, phase, config, made[env])
        check_study_devices(source, spec, config)
        try:
            check_replay(config, made[env], SPEC_KEYS)
        except SetupError as err:
            raise source.error(
                memory_line(spec, config.env), f"{recipe} on {config.env}: {err}"
            ) from None
    measured: set[str] = set()
    for _, recipe, setting, config in found:
        memory = {**to_dict(config), "env": None, "seed": None, "total_env_steps": None}
        key = json.dumps(memory, sort_keys=True)
        if key in measured:
            continue
        measured.add(key)
        shown = ", ".join(f"{k} = {v!r}" for k, v in setting.items())
        try:
            warning = check_memory(config, SPEC_KEYS)
        except SetupError as err:
            raise source.error(
                memory_line(spec, config.env), f"{recipe} on {config.env} with {shown}: {err}"
            ) from None
        if warning:
            print(f"{spec_path}: warning: {recipe} with {shown}: {warning}", file=sys.stderr)


def check_run_folder(where: Path, name: str) -> None:
    """SetupError naming the run ``name``'s place in the study directory or archive ``where``
    when something else than a directory stands there (a file, a link to nothing or to a folder
    it is in): the run would be taken for one not finished, and counted or trained as such."""
    path = where / name
    problem = folder_problem(path)
    if problem:
        raise SetupError(
            f"{path} (the directory of run {name}) is damaged: {problem}. Restore the run from a "
            f"copy (the study directory and its archive each keep one), or move it aside (mv "
            f"{path} {path}.damaged) and resume the study, which trains that run again"
        )


def check_folder_names(where: Path, names: Iterable[str]) -> None:
    """SetupError naming a folder in the study directory or archive ``where`` whose name is a
    part of a run's place (``names``: run names, ``evaluation/simoun/...``) in other capitals
    (``evaluation/Simoun``), as a copy through a case-insensitive file system or a rename
    leaves it: the runs in it are not at the spec's places, so they would be taken for runs not
    finished (trained again, listed as not counted) while the phase report, which walks the
    folders, counts them. A case-insensitive file system, where both names are the one folder,
    passes."""
    wanted: dict[tuple[str, ...], set[str]] = {}
    for name in names:
        parts = tuple(name.split("/"))
        for i, part in enumerate(parts):
            wanted.setdefault(parts[:i], set()).add(part)
    for parent, parts in wanted.items():
        folder = where.joinpath(*parent)
        meant_by = {part.casefold(): part for part in parts}
        for entry in _entries(folder):
            meant = meant_by.get(entry.casefold())
            if meant is not None and entry != meant and not _same(folder, entry, meant):
                raise SetupError(_stray_folder(where, parent, entry, meant))


def _entries(folder: Path) -> list[str]:
    """The names in ``folder``; none when it is not there or cannot be listed (the runs' own
    checks name a folder that cannot be read)."""
    try:
        return sorted(os.listdir(folder))
    except OSError:
        return []


def _same(folder: Path, entry: str, meant: str) -> bool:
    try:
        return os.path.samefile(folder / entry, folder / meant)
    except OSError:
        return False


_PART_KINDS = {
    TUNING: ("phase", "recipe", "setting", "task", "seed"),
    EVALUATION: ("phase", "recipe", "task", "seed"),
}
"""What each part of a run's place names (``evaluation/<recipe>/<task>/s<seed>``)."""


def _stray_folder(where: Path, parent: tuple[str, ...], entry: str, meant: str) -> str:
    stray, place = where.joinpath(*parent, entry), where.joinpath(*parent, meant)
    kinds = _PART_KINDS.get(parent[0], ()) if parent else ("phase",)
    kind = kinds[len(parent)] if len(parent) < len(kinds) else "folder"
    said = (
        f"{stray} is not a {kind} of the spec: did you mean {meant}? The study reads its runs "
        f"at the spec's places ({'/'.join([*parent, meant])}/...), and the name differs in "
        "capitals only (a copy through a case-insensitive file system, or a rename)"
    )
    if present(place):
        aside = where.parent / f"{where.name}-{'-'.join([*parent, entry])}"
        return (
            f"{said}; {place} is there too, so {stray} is a second copy, which the phase "
            f"report would count twice: move it out of {where} (mv {stray} {aside}) and run the "
            "command again"
        )
    return (
        f"{said}, so its runs would be listed as not finished, or trained again, while the phase "
        f"report counts them: rename it (mv {stray} {place}) and run the command again"
    )


def check_summary(name: str, places: list[Path]) -> None:
    """SetupError naming the run ``name``'s ``summary.json`` in one of ``places`` (the study
    directory, the archive) when it cannot be relied on
    (:func:`~simoun_agent.run.kept.summary_problem`): the run would be counted as finished and
    skipped, its damage found only when its result is read."""
    for where in places:
        path = where / name / SUMMARY_NAME
        problem = summary_problem(path)
        if problem is None:
            continue
        moves = " and ".join(
            f"mv {run_dir} {run_dir}.damaged"
            for run_dir in (place / name for place in places)
            if present(run_dir)
        )
        raise SetupError(
            f"{path} (the mark that run {name} finished) is damaged: {problem}. Restore it from "
            f"a copy (the study directory and its archive each keep one), or move the run aside "
            f"({moves}) and resume the study: the run is then trained again"
        )


def finished_config(name: str, places: list[Path]) -> dict[str, Any] | None:
    """The saved config of the run ``name`` if it finished in one of ``places``, else None."""
    for where in places:
        run_dir = where / name
        if (run_dir / SUMMARY_NAME).is_file() and present(run_dir / CONFIG_NAME):
            return read_config(run_dir / CONFIG_NAME)
    return None


def read_config(path: Path) -> dict[str, Any]:
    """A finished run's saved ``config.json``; SetupError naming the file, what is wrong and the
    fix when it is damaged: the run cannot be checked against the fixed spec without it."""
    try:
        saved = read_json_object(path)
    except Damaged as err:
        problem = str(err)
    else:
        problem = kind_problem(path.name, list(saved))
        if problem is None:
            return saved
    run_dir = path.parent
    raise SetupError(
        f"{path} is damaged: {problem}. Restore it from a copy (the study directory and its "
        f"archive each keep one), or move the run aside in both (mv {run_dir} "
        f"{run_dir}.damaged) and resume: the run is then trained again"
    )


def flat(config: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """``{"agent": {"lr": 1}}`` -> ``{"agent.lr": 1}``."""
    out: dict[str, Any] = {}
    for key, value in config.items():
        if isinstance(value, dict) and key == "agent":
            out.update(flat(value, prefix + key + "."))
        else:
            out[prefix + key] = value
    return out


def changes(saved: dict[str, Any], wanted: dict[str, Any]) -> list[str]:
    """``agent.lr: 0.001 when it ran, 0.0003 now`` for each training key that differs."""
    old, new = flat(saved), flat(wanted)
    return [
        f"{key}: {old.get(key)!r} when it ran, {new.get(key)!r} now"
        for key in sorted(set(old) | set(new))
        if key not in NOT_TRAINING and not same_setting(key, old.get(key), new.get(key))
    ]


def check_fixed_spec(
    record: dict[str, Any], spec: StudySpec, spec_path: str, places: list[Path]
) -> list[str]:
    """The spec keys that differ from the study ``record``'s; SetupError when the change
    touches a run finished in ``places`` (the study directory, the archive): a run that would
    now be trained otherwise, or an evaluation run whose recipe would be selected from other
    tuning runs or by another rule."""
    saved = StudySpec.from_json(record["spec"])
    # a key added since the record: its default; a device however it is spelled
    old, new = device_keys(saved.to_json()), device_keys(spec.to_json())
    changed = [key for key in {**old, **new} if old.get(key) != new.get(key)]
    if not changed:
        return []
    advice = (
        f"so {spec_path} cannot continue this study. Undo that change, delete the run (in the "
        "study directory and the archive) to train it again, or start a new study in another "
        "--study-dir"
    )
    evaluated = set()
    for run in tuning_runs(spec) + evaluation_runs(spec):
        config = finished_config(run.name, places)
        if config is None:
            continue
        if run.phase != TUNING:
            evaluated.add(run.of or run.recipe)  # a diagnostic ran at its method's selection
            # the setting it ran with: the one its tuning selected
            agent = config.get("agent", {})
            setting = {
                key: agent[key[6:]] if key.startswith("agent.") else config[key]
                for key in spec.grid
            }
            run = StudyRun(
                run.phase, run.recipe, run.task, run.seed, run.env_steps, setting, run.of
            )
        wanted = to_dict(resolve(spec.preset, run.trial(spec, Path(".")).overrides))
        differences = changes(config, wanted)
        if differences:
            raise SetupError(
                f"the finished run {run.name} would be trained otherwise under the changed "
                f"spec ({'; '.join(differences)}), {advice}"
            )
    for recipe in sorted(evaluated):
        before = [r.name for r in tuning_runs(saved) if r.recipe == recipe]
        after = [r.name for r in tuning_runs(spec) if r.recipe == recipe]
        if before != after or saved.selection != spec.selection:
            raise SetupError(
                f"the evaluation of {recipe} has started with the setting its tuning selected, "
                f"and the changed spec would select again (its tuning runs or selection rule "
                f"differ), {advice}"
            )
    return changed
