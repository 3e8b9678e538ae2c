"""The runs of a study's two phases, each an ordinary sweep trial in its own run directory.

Tuning: every recipe x grid setting x tuning task x tuning seed, at
``<study>/tuning/<recipe>/<setting>/<task>/s<seed>``. Evaluation: every recipe with the setting
its tuning selected x evaluation task x held-out seed, at
``<study>/evaluation/<recipe>/<task>/s<seed>``; the spec's diagnostic recipes (ablations of one
method) run there too, each at its method's selected setting. A run's path under the study
directory is its name, in Ray Tune's tables and in the archive. :func:`describe` is
``simoun-study plan``'s listing of them, with the CPU time each should take
(:mod:`simoun_lab.study.probe`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError, resolve
from simoun_agent.config.envs import env_label
from simoun_agent.config.rules import show
from simoun_agent.run.layout import SUMMARY_NAME
from simoun_lab.study import probe
from simoun_lab.study.spec import StudySpec, key_place
from simoun_lab.sweep.grid import Trial, path_part, typed

TUNING, EVALUATION = "tuning", "evaluation"


def setting_label(setting: dict[str, Any]) -> str:
    """``{"agent.n_step": 3}`` -> ``agent.n_step=3`` (the sweep's variant names)."""
    return ",".join(f"{key}={show(value)}" for key, value in setting.items())


@dataclass(frozen=True)
class StudyRun:
    """One training run of the study."""

    phase: str
    """``tuning`` or ``evaluation``"""
    recipe: str
    task: str
    """Gymnasium id"""
    seed: int
    env_steps: int
    """the run's budget (total_env_steps)"""
    setting: dict | None
    """grid values; None for an evaluation run before its recipe's setting is selected"""
    of: str | None = None
    """for a diagnostic run: the method whose selected setting it runs at"""

    @property
    def variant(self) -> str:
        """``tuning/<recipe>/<setting>`` or ``evaluation/<recipe>``."""
        if self.phase == TUNING:
            return f"{TUNING}/{self.recipe}/{path_part(setting_label(self.setting))}"
        return f"{EVALUATION}/{self.recipe}"

    @property
    def name(self) -> str:
        """The run directory relative to the study directory."""
        return f"{self.variant}/{path_part(env_label(self.task))}/s{self.seed}"

    def trial(self, spec: StudySpec, study_dir: Path) -> Trial:
        """The sweep trial that trains this run (its setting must be known)."""
        if self.setting is None:
            raise ValueError(f"{self.name}: its setting is selected by the tuning phase")
        run_dir = Path(study_dir, self.name)
        overrides = spec.overrides(self.recipe, self.task, self.setting, self.seed, self.env_steps)
        overrides.update(run_dir=str(run_dir), torch_threads=spec.cpus_per_trial)
        return Trial(
            self.variant, self.task, self.seed, str(run_dir), spec.preset, typed(overrides)
        )

    def finished(self, study_dir: Path) -> bool:
        return (Path(study_dir, self.name) / SUMMARY_NAME).is_file()


def tuning_runs(spec: StudySpec) -> list[StudyRun]:
    """Tuning runs, by task, recipe, setting (grid order) and seed."""
    phase = spec.tuning
    return [
        StudyRun(TUNING, recipe, task, seed, phase.env_steps[task], setting)
        for task in phase.tasks
        for recipe in spec.recipes
        for setting in spec.settings()
        for seed in phase.seeds[task]
    ]


def evaluation_runs(spec: StudySpec, selected: dict[str, dict] | None = None) -> list[StudyRun]:
    """Evaluation runs, by task, recipe (the compared ones, then the diagnostic ones) and seed,
    with each recipe's ``selected`` setting, a diagnostic recipe with its method's (None before
    the tuning phase has chosen)."""
    phase = spec.evaluation
    of = {recipe: None for recipe in spec.recipes} | spec.ablations()
    return [
        StudyRun(
            EVALUATION,
            recipe,
            task,
            seed,
            phase.env_steps[task],
            None if selected is None else selected[method or recipe],
            method,
        )
        for task in phase.tasks
        for recipe, method in of.items()
        for seed in phase.seeds[task]
    ]


def check_layout(spec: StudySpec) -> None:
    """Two runs may not share a directory (settings that differ only in characters a
    directory name drops)."""
    seen: dict[str, StudyRun] = {}
    for run in tuning_runs(spec):
        other = seen.setdefault(run.name, run)
        if other is not run:
            raise SetupError(
                f"the grid settings {setting_label(other.setting)} and "
                f"{setting_label(run.setting)} would share the run directory {run.name}; make "
                "their values differ in letters or digits"
            )


def settings_of(spec: StudySpec, run: StudyRun) -> list[dict[str, Any]]:
    """The run's setting, or every grid setting for an evaluation run not yet selected."""
    return [run.setting] if run.setting is not None else spec.settings()


def cost_identity(run: StudyRun, setting: dict[str, Any]) -> tuple:
    """What a run's cost depends on: recipe, task, setting and budget (not the seed)."""
    return (run.recipe, run.task, setting_label(setting), run.env_steps)


def estimate_runs(spec: StudySpec, runs: list[StudyRun], updates: int) -> dict[str, float]:
    """Each run's estimated CPU seconds, by run name, from a probe measured now with
    ``updates`` timed updates per configuration, an evaluation run's generalization episodes
    included; an evaluation run before the selection gets its recipe's slowest grid setting."""
    configs = {}
    for run in runs:
        for setting in settings_of(spec, run):
            key = cost_identity(run, setting)
            if key not in configs:
                costed = StudyRun(run.phase, run.recipe, run.task, run.seed, run.env_steps, setting)
                configs[key] = resolve(spec.preset, costed.trial(spec, Path(".")).overrides)
    costs = probe.measure(list(configs.values()), updates)
    seconds = {
        key: probe.run_cpu_seconds(config, costs[probe.cost_key(config)])
        for key, config in configs.items()
    }
    episodes = generalization_episodes(spec)
    played = {
        key: episodes * probe.episode_cpu_seconds(costs[probe.cost_key(config)])
        for key, config in configs.items()
    }
    return {
        run.name: max(
            seconds[cost_identity(run, setting)]
            + (played[cost_identity(run, setting)] if run.phase == EVALUATION else 0.0)
            for setting in settings_of(spec, run)
        )
        for run in runs
    }


def generalization_episodes(spec: StudySpec) -> int:
    """Episodes each evaluation run's final agent plays after training: every distraction mode
    and the train mode, ``generalization_episodes`` each (0 when the spec asks for none)."""
    if not spec.generalization:
        return 0
    return (len(spec.generalization) + 1) * spec.generalization_episodes


def selected_by(run: StudyRun) -> str:
    """The setting column of a run whose setting the tuning phase has not selected yet."""
    return "(selected)" if run.of is None else f"({run.of}'s)"


def duration(seconds: float) -> str:
    """``42 s``, ``12.5 min`` or ``3.1 h``."""
    if seconds < 90:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.1f} min" if seconds < 5400 else f"{seconds / 3600:.1f} h"


def sparse_evaluation_notes(spec: StudySpec) -> list[str]:
    """A note for each phase and task whose runs evaluate less often than their budget (an
    ``eval_every`` beyond ``env_steps``): simoun-train then evaluates only at step 0 and at the
    end, which the spec may mean (a final score) or not (a learning curve, an area under it)."""

    notes = []
    for phase in (spec.tuning, spec.evaluation):
        for task in phase.tasks:
            steps = phase.env_steps[task]
            seed = phase.seeds[task][0]
            every = {
                resolve(spec.preset, spec.overrides(recipe, task, setting, seed, steps)).eval_every
                for recipe in spec.recipes
                for setting in spec.settings()
            }
            if max(every) <= steps:
                continue
            place = key_place(spec, task, "eval_every")
            said = _table(place) if place else "the preset's default"
            reads = f"; the {spec.selection} selection rule reads" if phase is spec.tuning else ""
            notes.append(
                f"note: the {phase.name} runs on {env_label(task)} evaluate every "
                f"{max(every)} env steps ({said}), more than their {steps}: each is evaluated "
                f"only at step 0 and at the end{reads and reads + ' those two points'}; for a "
                f"learning curve, give an eval_every below {steps}"
            )
    return notes


def _table(place: tuple[str, ...]) -> str:
    """``("tasks", "x", "eval_every")`` -> ``eval_every in [tasks."x"]``."""
    table = f'[tasks."{place[1]}"]' if place[0] == "tasks" else f"[{place[0]}]"
    return f"eval_every in {table}"


def describe(spec: StudySpec, spec_path: str, updates: int) -> str:
    """``simoun-study plan``: every run of both phases (phase, task, recipe, setting, seed,
    env steps) with its estimated CPU time, and the totals; ``updates`` 0: no estimate."""
    tuning, evaluation = tuning_runs(spec), evaluation_runs(spec)
    runs = tuning + evaluation
    estimates = estimate_runs(spec, runs, updates) if updates > 0 else {}
    header = ("phase", "task", "recipe", "setting", "seed", "env steps", "CPU (est.)")
    rows = [
        (
            run.phase,
            env_label(run.task),
            run.recipe,
            setting_label(run.setting) if run.setting is not None else selected_by(run),
            str(run.seed),
            str(run.env_steps),
            duration(estimates[run.name]) if estimates else "",
        )
        for run in runs
    ]
    widths = [max(len(row[i]) for row in [header, *rows]) for i in range(len(header))]
    lines = [
        f"study {spec.name} ({spec_path}): {len(spec.recipes)} recipes x {len(spec.settings())} "
        f"grid settings; tuning on {', '.join(env_label(t) for t in spec.tuning.tasks)}, then "
        "each recipe's selected setting evaluated on "
        f"{', '.join(env_label(t) for t in spec.evaluation.tasks)}",
        "",
    ]
    for row in [header, *rows]:
        cells = [
            cell.rjust(width) if i >= 4 else cell.ljust(width)
            for i, (cell, width) in enumerate(zip(row, widths, strict=True))
        ]
        lines.append("  ".join(cells).rstrip())
    diagnostic = sum(run.of is not None for run in evaluation)
    lines += [
        "",
        f"runs: {len(tuning)} tuning + {len(evaluation)} evaluation = {len(runs)}"
        + (f" ({diagnostic} of the evaluation runs are diagnostics)" if diagnostic else ""),
    ]
    lines += sparse_evaluation_notes(spec)
    if spec.generalization:
        lines.append(
            "after training, each evaluation run's final agent plays "
            f"{spec.generalization_episodes} episodes of each of train, "
            f"{', '.join(spec.generalization)} ({generalization_episodes(spec)} episodes a run)"
        )
    if not estimates:
        return "\n".join(lines)
    tuning_s = sum(estimates[run.name] for run in tuning)
    evaluation_s = sum(estimates[run.name] for run in evaluation)
    total = tuning_s + evaluation_s
    at_once = spec.max_concurrent_trials or max(1, (os.cpu_count() or 1) // spec.cpus_per_trial)
    configs = len({cost_identity(run, s) for run in runs for s in settings_of(spec, run)})
    lines += [
        f"estimated CPU time: tuning {duration(tuning_s)}, evaluation {duration(evaluation_s)}, "
        f"total {duration(total)}; with {at_once} runs at a time, each on {spec.cpus_per_trial} "
        f"CPU of its own, about {duration(total / at_once)} of wall time",
        f"measured here on {probe.machine()}, in process CPU time with {spec.cpus_per_trial} "
        f"torch thread(s): for each of {configs} configurations (recipe x task x setting x "
        f"budget), {probe.ACTIONS} actions and {updates} agent updates (after "
        f"{probe.WARMUP_UPDATES} untimed); for each environment, 2 x batch + 20 random env "
        "decisions and one evaluation episode. Evaluation runs are counted with their recipe's "
        "slowest grid setting (a diagnostic run with its method's), generalization episodes as "
        "evaluation episodes of the undistracted env; checkpoints and logging are not counted.",
    ]
    return "\n".join(lines)
