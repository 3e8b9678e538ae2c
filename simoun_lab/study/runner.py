"""Running a study from its spec (the library under ``simoun-study``,
:mod:`simoun_lab.cli.study`): the study record, both phases on Ray Tune through the engine
(:mod:`simoun_lab.engine.launcher`, which archives each run as it finishes), the selection
between them and the report at the end.
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
from pathlib import Path
from types import ModuleType
from typing import Any

from simoun_agent.config import SetupError, resolve
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import (
    Damaged,
    json_kind,
    packed_folder_advice,
    present,
    read_json_object,
)
from simoun_agent.run.layout import CHECKPOINT_NAME, SUMMARY_NAME
from simoun_lab.engine.launcher import changed_keys, run_trials
from simoun_lab.engine.ray_start import connect
from simoun_lab.engine.trial import check_no_live_runs
from simoun_lab.study import archive as archiving
from simoun_lab.study.archive import GENERALIZATION_CSV
from simoun_lab.study.checks import (
    check_fixed_spec,
    check_folder_names,
    check_run_folder,
    check_study,
    check_summary,
)
from simoun_lab.study.choice import SELECTION_FILE, Choice, choose, save_choices
from simoun_lab.study.generalization import play_modes, playable, to_play
from simoun_lab.study.options import StudyOptions
from simoun_lab.study.owner import check_not_inside_study
from simoun_lab.study.plan import (
    EVALUATION,
    TUNING,
    StudyRun,
    check_layout,
    evaluation_runs,
    setting_label,
    tuning_runs,
)
from simoun_lab.study.provenance import code_version, same_code
from simoun_lab.study.record_file import RECORD_KEYS
from simoun_lab.study.report import REPORT_DIR, REPORT_MD, write_study_report
from simoun_lab.study.spec import StudySpec, load_spec, spec_text
from simoun_lab.sweep import launch
from simoun_lab.sweep.trainable import STOP_FILE, SacTrial

STUDY_FILE = "study.json"
"""The study record, in the study directory and the archive: the spec (its file, text and
parsed form) and each part's code version."""

PPO_SPEC_FILE = "spec.json"
"""What a MiniGrid PPO study's archive holds in place of ``study.json``
(:data:`simoun_lab.minigrid_study.runner.SPEC_FILE`, not imported: it brings SB3 along)."""


def spec_from(path: str) -> StudySpec:
    spec = load_spec(path)
    check_layout(spec)
    return spec


def load_record(study_dir: Path, archive: Path | None, resuming: bool = True) -> dict[str, Any]:
    """The saved study record, from the study directory, else from the archive; SetupError
    with the advice of the command asked (``run --resume``, or ``report``: ``resuming``
    False) when neither holds one."""
    for where in (study_dir, archive):
        if where is not None and present(where / STUDY_FILE):
            return read_record(where / STUDY_FILE)
    places = " or ".join(str(p) for p in (study_dir, archive) if p is not None)
    for where in (study_dir, archive):
        if where is not None and present(where / PPO_SPEC_FILE):
            raise SetupError(
                f"{where} holds runs of a MiniGrid PPO study ({where / PPO_SPEC_FILE}), not of "
                f"the SAC study of this spec; give that study its own spec (simoun-study "
                f"report {where / PPO_SPEC_FILE} --study-dir {where}), or pass the directory "
                "of a SAC study"
            )
    missing = missing_note([p for p in (study_dir, archive) if p is not None])
    if not resuming:
        raise SetupError(
            f"no study to report: {places} holds no {STUDY_FILE}{missing}; pass the "
            "--study-dir of a study that ran (or its archive, e.g. docs/studies/NAME)"
        )
    raise SetupError(
        f"no study to resume: {places} holds no {STUDY_FILE}{missing}; drop --resume to start "
        "the study, or pass the --study-dir (or --archive) of the study to continue"
    )


def missing_note(places: list[Path]) -> str:
    """Why ``places`` that hold no study record hold none, when no directory is among them: a
    file there (a packed archive, with the command that unpacks it), else nothing at all."""
    if any(place.is_dir() for place in places):
        return ""
    files = [place for place in places if place.exists()]
    if files:
        return f" ({files[0]} is a file, not a directory: {packed_folder_advice(files[0])})"
    return " (no such directory)"


PART_KEYS = ("commit", "dirty", "version")
"""Keys every part of a study record holds: the code it ran (:func:`code_version`)."""


def read_record(path: Path) -> dict[str, Any]:
    """The study record at ``path``; SetupError naming the file, what is wrong and the fix when
    it is damaged (:func:`record_problem`)."""
    try:
        record = read_json_object(path)
    except Damaged as err:
        problem = str(err)
    else:
        problem = record_problem(record)
        if problem is None:
            return record
    raise SetupError(
        f"{path} is damaged: {problem}. Restore it from a copy (the study directory and its "
        f"archive each keep one, e.g. docs/studies/NAME/{STUDY_FILE})"
    )


def record_problem(record: dict[str, Any]) -> str | None:
    """What is wrong with a study record that :func:`open_study` could not have written: a key
    of :data:`RECORD_KEYS` missing, a spec that is not an object, no parts; None if nothing."""
    missing = [key for key in RECORD_KEYS if key not in record]
    if missing:
        return f"it has no {', '.join(missing)}, which every study record holds"
    if not isinstance(record["spec"], dict):
        return f"its spec is {json_kind(record['spec'])}, not a JSON object"
    parts = record["parts"]
    if not (isinstance(parts, list) and parts and all(isinstance(p, dict) for p in parts)):
        return "its parts are not an array of JSON objects, one per part the study ran"
    for number, part in enumerate(parts, start=1):
        missing = [key for key in PART_KEYS if key not in part]
        if missing:
            return f"its part {number} has no {', '.join(missing)}, which every part records"
    try:
        StudySpec.from_json(record["spec"])
    except ValueError as err:
        return str(err)
    return None


def record_path(study_dir: Path, archive: Path | None) -> Path:
    """Where :func:`load_record` read the study record: the study directory's, else the
    archive's."""
    if archive is None or present(study_dir / STUDY_FILE):
        return study_dir / STUDY_FILE
    return archive / STUDY_FILE


def places(options: StudyOptions) -> list[Path]:
    """The study directory and the archive (when given): where finished runs are kept."""
    return [p for p in (options.study_dir, options.archive) if p is not None]


def unplanned_runs(record: dict[str, Any], where: list[Path]) -> list[str]:
    """The finished tuning runs in ``where`` that the study ``record``'s spec does not plan."""
    planned = {run.name for run in tuning_runs(StudySpec.from_json(record["spec"]))}
    found = {
        str(path.parent.relative_to(place))
        for place in where
        for path in (place / TUNING).rglob(SUMMARY_NAME)
    }
    return sorted(found - planned)


def another_study(
    record: dict[str, Any], spec: StudySpec, spec_path: str, path: Path
) -> SetupError:
    """The error for a resumed study whose record at ``path`` is of another study: its spec's
    name (the stem of the file it ran from) is not this spec's, and the finished runs are not
    the record's (a spec fixed to go on may be renamed; its runs stay those of the record)."""
    return SetupError(
        f"{path} is the record of another study ({record['spec'].get('name')!r}, run from "
        f"{record['spec_file']}), not of {spec_path} ({spec.name!r}), whose finished runs are "
        f"here: it was copied from another study. Restore this study's {STUDY_FILE} from a "
        "copy (the study directory and its archive each keep one), or pass the --study-dir and "
        "--archive of the study it records"
    )


def check_same_spec(record: dict[str, Any], spec: StudySpec, problem: str, fix: str) -> None:
    """Refuse ``spec`` when it is not the one the study ``record`` was started with: the error
    says ``problem``, the keys that differ and ``fix``. A record saved before a spec key
    existed has that key's default (read through :meth:`StudySpec.from_json`)."""
    saved, wanted = StudySpec.from_json(record["spec"]).to_json(), spec.to_json()
    changed = changed_keys(saved, wanted)
    if changed == ["name"]:
        raise SetupError(
            f"{problem}: a study is named for its spec file, and the saved {STUDY_FILE} names "
            f"study {saved['name']!r} where this spec file names {wanted['name']!r} (the specs "
            f"are otherwise the same); pass the spec under the name {saved['name']}"
            f"{Path(record['spec_file']).suffix or '.toml'} (a copy or a rename of this file)"
        )
    if changed:
        raise SetupError(
            f"{problem} ({', '.join(changed)} differ from the saved {STUDY_FILE}); {fix}"
        )


def planned_names(spec: StudySpec) -> set[str]:
    """The names of every run ``spec`` plans (an evaluation run's name holds no setting)."""
    return {run.name for run in tuning_runs(spec) + evaluation_runs(spec)}


def finished_names(where: Path) -> set[str]:
    """The names of the finished runs of both phases under ``where``."""
    return {
        str(path.parent.relative_to(where))
        for phase in (TUNING, EVALUATION)
        for path in (where / phase).rglob(SUMMARY_NAME)
    }


def of_this_spec(record: dict[str, Any], spec: StudySpec, where: Path) -> bool:
    """Whether the study ``record`` kept in ``where`` is a study of ``spec``: its name, or,
    for a spec fixed under another name, a finished run under ``where`` that ``spec`` plans."""
    if record["spec"].get("name") == spec.name:
        return True
    return bool(finished_names(where) & planned_names(spec))


def check_own_places(spec: StudySpec, spec_path: str, options: StudyOptions) -> None:
    """Refuse a --study-dir or --archive that holds another study, before anything is read
    from it or written into it: a MiniGrid PPO study's runs, or the record of a study that is
    not ``spec``'s (:func:`of_this_spec`), which running this study would write over."""
    for where, flag in ((options.study_dir, "--study-dir"), (options.archive, "--archive")):
        if where is None:
            continue
        check_not_inside_study(where, flag)
        if present(where / PPO_SPEC_FILE) and not present(where / STUDY_FILE):
            raise SetupError(
                f"{flag} {where} holds runs of a MiniGrid PPO study ({where / PPO_SPEC_FILE}), "
                f"not of the SAC study of {spec_path}; pass another {flag} (a new directory, or "
                "the one of this study)"
            )
        if not present(where / STUDY_FILE):
            continue
        record = read_record(where / STUDY_FILE)
        if of_this_spec(record, spec, where):
            continue
        theirs = record["spec"].get("name")
        raise SetupError(
            f"{flag} {where} holds another study, {theirs!r} (run from {record['spec_file']}), "
            f"not the study {spec.name!r} of {spec_path}; this study would write its record and "
            f"runs over that one. Pass the {flag} of this study, or a new directory; to continue "
            f"{theirs!r}, pass its spec ({record['spec_file']})"
        )


def open_study(spec: StudySpec, spec_path: str, options: StudyOptions) -> dict[str, Any]:
    """The study record, new or resumed (same study, same spec and, unless allowed, same
    commit)."""
    study_dir, archive = options.study_dir, options.archive
    check_own_places(spec, spec_path, options)  # first: the other checks read what is there
    code = code_version()
    part = {"started_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"), **code}
    if not options.resume:
        for where, flag in ((study_dir, "--study-dir"), (archive, "--archive")):
            if where is not None and (where / STUDY_FILE).is_file():
                raise SetupError(
                    f"{where} already holds a study; continue it with --resume, or pass another "
                    f"{flag}"
                )
        if study_dir.exists() and any(study_dir.iterdir()):
            raise SetupError(f"{study_dir} is not empty; pass a new --study-dir")
        text = spec_text(Path(spec_path))
        return {"spec_file": spec_path, "spec_text": text, "spec": spec.to_json(), "parts": [part]}
    record = load_record(study_dir, archive)
    try:
        changed = check_fixed_spec(record, spec, spec_path, places(options))
    except SetupError:
        if record["spec"].get("name") != spec.name and unplanned_runs(record, places(options)):
            raise another_study(record, spec, spec_path, record_path(study_dir, archive)) from None
        raise
    if changed:  # a fix that leaves every finished run as it ran: the study goes on under it
        part["spec_changed"] = {"keys": changed, "before": record["spec_text"]}
        record.update(spec_file=spec_path, spec_text=spec_text(Path(spec_path)))
        record["spec"] = spec.to_json()
    first = record["parts"][0]
    if not same_code(first, code) and not options.allow_other_commit:
        raise SetupError(
            f"this study ran from commit {first['commit'] or first['version']}, and the code is "
            f"now at {code['commit'] or code['version']}: the code under study must not change "
            "within a study, or its runs would compare two versions of the methods. Check out "
            f"{first['commit'] or first['version']} to resume, start a new study, or pass "
            "--allow-other-commit if the change cannot affect the runs (the report lists every "
            "commit)"
        )
    record["parts"].append({**part, "allowed_other_commit": not same_code(first, code)})
    return record


def save_record(record: dict[str, Any], places: list[Path]) -> None:
    text = json.dumps(record, indent=2) + "\n"
    for where in places:
        where.mkdir(parents=True, exist_ok=True)
        atomic_write(where / STUDY_FILE, lambda tmp: tmp.write_text(text))


class Phases:
    """Runs the study's phases on Ray Tune through the engine, each run a SAC trial."""

    def __init__(
        self, spec: StudySpec, spec_path: str, options: StudyOptions, ray: ModuleType
    ) -> None:
        self.spec, self.options, self.ray = spec, options, ray
        self.study_dir, self.archive = options.study_dir, options.archive
        self.gpus: float | None = None
        self.started = False
        """whether Ray was started here (then the study shuts it down)"""
        self.todo: list = []
        """the trials of the phase running now"""
        self.resume = f"simoun-study run {spec_path} --study-dir {options.study_dir} --resume" + (
            f" --archive {options.archive}" if options.archive else ""
        )

    def connect(self) -> None:
        """Start (or join) Ray, once: only when there is something to run."""
        if self.gpus is not None:
            return
        self.started = connect(self.ray, self.options.address, self.options.num_cpus)
        device = self.spec.base.get("device", resolve(self.spec.preset, {}).device)
        wanted = str(self.spec.gpus_per_trial)
        self.gpus = launch.gpus_per_trial(self.ray, wanted, device)
        launch.check_fits(self.ray, self.spec.cpus_per_trial, self.gpus)

    def generalize(self, runs: list[StudyRun]) -> list[str]:
        """Play each finished run's final agent on the spec's distraction modes (Ray tasks with a
        trial's resources, as many at a time as trials), archiving each ``generalization.csv``
        as it is written; the runs that could not be played, with why."""
        names = [run.name for run in runs if run.finished(self.study_dir)]
        todo = to_play(self.study_dir, self.archive, names)
        print(f"generalization: {len(todo)} runs to play, {len(names) - len(todo)} played")
        missing = [n for n in todo if not playable(self.study_dir / n)]
        todo = [n for n in todo if n not in missing]
        failed = [f"{name}: no {CHECKPOINT_NAME} (restored from the archive)" for name in missing]
        if not todo:
            return failed
        self.connect()
        remote = self.ray.remote(num_cpus=self.spec.cpus_per_trial, num_gpus=self.gpus)(play_modes)
        at_once = self.spec.max_concurrent_trials or len(todo)
        waiting, running = list(todo), {}
        while waiting or running:
            while waiting and len(running) < at_once:
                name = waiting.pop(0)
                args = (str(self.study_dir / name), self.spec.generalization)
                running[remote.remote(*args, self.spec.generalization_episodes)] = name
            (done,), _ = self.ray.wait(list(running), num_returns=1)
            name = running.pop(done)
            try:
                self.ray.get(done)
            except self.ray.exceptions.RayTaskError as err:
                failed.append(f"{name}: {err.cause!r}")
                continue
            if self.archive is not None:
                archiving.copy_file(
                    self.study_dir / name / GENERALIZATION_CSV,
                    self.archive / name / GENERALIZATION_CSV,
                )
        return failed

    def restore(self, runs: list[StudyRun]) -> int:
        """Bring back archived finished runs whose run directories are gone; how many."""
        if self.archive is None:
            return 0
        return sum(archiving.restore_run(self.study_dir, self.archive, r.name) for r in runs)

    def sync(self, runs: list[StudyRun]) -> None:
        """Archive every finished run not archived yet (those the live callback missed)."""
        if self.archive is not None:
            for run in runs:
                archiving.archive_run(self.study_dir, self.archive, run.name)

    def run(self, phase: str, runs: list[StudyRun]) -> dict[str, list]:
        """Run the unfinished ``runs`` of ``phase``; the sweep's outcome of those it ran."""
        places = [where for where in (self.study_dir, self.archive) if where is not None]
        for where in places:  # a run's folder renamed in other capitals is not trained anew
            check_folder_names(where, [run.name for run in runs])
        for run in runs:  # before anything is restored or trained: a damaged run is named
            for where in places:
                check_run_folder(where, run.name)
            check_summary(run.name, places)
        restored = self.restore(runs)
        todo = [run for run in runs if not run.finished(self.study_dir)]
        stop_file = str(self.study_dir / STOP_FILE)
        self.todo = [
            SacTrial(run.trial(self.spec, self.study_dir), run.name, stop_file, archiving.RUN_FILES)
            for run in todo
        ]
        print(
            f"{phase}: {len(todo)} runs to run, {len(runs) - len(todo)} already finished"
            + (f" ({restored} restored from {self.archive})" if restored else ""),
            flush=True,
        )
        if not todo:
            self.sync(runs)
            return {}
        self.connect()
        outcome = run_trials(
            self.todo,
            self.study_dir / "tune",
            {"cpu": self.spec.cpus_per_trial, "gpu": self.gpus},
            self.options.verbose,
            self.archive,
            self.spec.max_concurrent_trials,
            name=f"{phase}-",
        )
        self.sync(runs)
        return outcome


def run_study(spec: StudySpec, spec_path: str, options: StudyOptions, ray: ModuleType) -> int:
    """Tune, select, evaluate, report the study of ``spec`` (read from ``spec_path``); the exit
    status (the sweep's: 130/143 stopped, 1 failed)."""
    study_dir, archive = options.study_dir, options.archive
    check_study(spec, spec_path)
    check_no_live_runs(study_dir, "the study")  # before its record gains a part
    record = open_study(spec, spec_path, options)
    save_record(record, [study_dir] + ([archive] if archive is not None else []))
    phases = Phases(spec, spec_path, options, ray)
    choices: dict[str, Choice] | None = None
    terminated: list[bool] = []
    try:
        with launch.stop_trials_on_sigterm(study_dir) as terminated:
            outcome = phases.run(TUNING, tuning_runs(spec))
            if not (outcome.get("failed") or outcome.get("stopped")):
                choices = choose(spec, study_dir)
                save_choices(choices, spec, study_dir / SELECTION_FILE)
                if archive is not None:
                    archiving.copy_file(study_dir / SELECTION_FILE, archive / SELECTION_FILE)
                say_choices(choices)
                selected = {recipe: choice.setting for recipe, choice in choices.items()}
                evaluation = evaluation_runs(spec, selected)
                outcome = phases.run(EVALUATION, evaluation)
                if spec.generalization and not (outcome.get("failed") or outcome.get("stopped")):
                    for problem in phases.generalize(evaluation):
                        print(f"generalization not played: {problem}", flush=True)
    except KeyboardInterrupt:
        outcome = {"stopped": phases.todo}
    finally:
        if phases.started:
            ray.shutdown()
    written, unwritten = [], None
    if choices is not None:
        try:
            write_study_report(spec, study_dir, record, choices)
        except SetupError as err:  # the runs are done: say so, and what keeps the report back
            again = f"simoun-study report {spec_path} --study-dir {study_dir}"
            unwritten = f"{err}; then write it with: {again}"
        else:
            written = [study_dir / REPORT_DIR / REPORT_MD]
            if archive is not None:
                archiving.archive_tree(study_dir / REPORT_DIR, archive / REPORT_DIR)
    return launch.summarize(
        outcome, study_dir, written, bool(terminated), phases.resume, unwritten=unwritten
    )


def report_study(spec: StudySpec, study_dir: Path) -> Path:
    """Write the report of the finished runs in ``study_dir`` (a study directory or its
    archive) again, with this code, into ``study_dir/report``; returns its ``report.md``."""
    record = load_record(study_dir, None, resuming=False)
    check_same_spec(
        record,
        spec,
        f"{study_dir} holds a study of another spec",
        f"pass the spec it was run with ({record['spec_file']})",
    )
    # a run's folder renamed in other capitals: the report would count its runs as not finished
    check_folder_names(study_dir, [run.name for run in tuning_runs(spec) + evaluation_runs(spec)])
    for run in tuning_runs(spec):  # before the selection reads them: a damaged run is named
        check_run_folder(study_dir, run.name)
    code = code_version()
    commit = f"{code['commit']}{' with uncommitted changes' if code['dirty'] else ''}"
    write_study_report(spec, study_dir, record, choose(spec, study_dir), rewritten_by=commit)
    return study_dir / REPORT_DIR / REPORT_MD


def say_choices(choices: dict[str, Choice]) -> None:
    for recipe, choice in choices.items():
        print(f"selected for {recipe}: {setting_label(choice.setting)} (score {choice.score:.4g})")
