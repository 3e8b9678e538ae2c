"""``simoun-study`` on a MiniGrid PPO spec: plan, run and report it with the command that runs
the SAC studies, on the same engine.

A spec is a MiniGrid PPO study's when it is a JSON file (``docs/studies/minigrid-v2/tuning/
spec.json``) or a TOML file with a top-level ``arms`` key holding the same keys; a SAC study's
spec has ``recipes`` instead. The options keep their meaning: ``--study-dir`` holds Ray Tune's
records and the runs in progress (each with its checkpoint), ``--archive`` the finished runs,
the spec and each in-progress checkpoint (``--study-dir`` itself when left out), ``--resume``
goes on with the runs an archive holds.
"""

from __future__ import annotations

import os
from pathlib import Path

import tomllib

from simoun_agent.config import SetupError
from simoun_agent.run.kept import Damaged, packed_folder_advice, present, read_text
from simoun_lab.minigrid_study.spec import StudySpec, load_spec
from simoun_lab.study.given_path import shown
from simoun_lab.study.owner import (
    check_not_in_sweep,
    check_not_inside_archive,
    check_not_inside_study,
    check_not_other_archive,
    sac_study,
)
from simoun_lab.study.runner import PPO_SPEC_FILE, STUDY_FILE, StudyOptions

__all__ = ["check_run_places", "is_ppo_spec", "load_ppo_spec", "plan", "report", "run"]


def _toml(path: Path) -> dict | None:
    """The TOML file's tables, or None when it cannot be read or parsed (the SAC reader then
    names the problem)."""
    try:
        return tomllib.loads(read_text(path))
    except (OSError, Damaged, tomllib.TOMLDecodeError):
        return None


def is_ppo_spec(path: str) -> bool:
    """Whether the spec at ``path`` is a MiniGrid PPO study's (see the module's docstring)."""
    if Path(path).suffix.lower() == ".json":
        return True
    data = _toml(Path(path))
    return data is not None and "arms" in data and "recipes" not in data


def load_ppo_spec(path: str) -> StudySpec:
    """The MiniGrid PPO spec at ``path``, JSON or TOML (by its suffix, as
    :func:`~simoun_lab.minigrid_study.spec.load_spec` reads it); SetupError naming the file and
    key."""
    return load_spec(Path(path), label="the study spec")


def plan(spec: StudySpec, path: str) -> str:
    """Every run of the spec, in the order they run, with its budget."""
    runs = spec.runs()
    lines = [f"{path}: a MiniGrid PPO study, {len(runs)} runs (task / arm / seed, env steps)"]
    lines += [f"  {run.name}  {run.task.steps:,}" for run in runs]
    total = sum(run.task.steps for run in runs)
    lines.append(f"{total:,} env steps in all; two runs at a time, one torch thread each")
    return "\n".join(lines)


def _runner():
    """The runner, imported when a study runs or is reported: it imports SB3 and MiniGrid, which
    a SAC study's command does not need."""
    from simoun_lab.minigrid_study import runner

    return runner


def run(spec: StudySpec, options: StudyOptions) -> int:
    """Train every unfinished run of ``spec`` (:func:`~simoun_lab.minigrid_study.runner.
    run_study`); 1 when a run failed."""
    if options.allow_other_commit:
        raise SetupError(
            "--allow-other-commit is for SAC study specs; a MiniGrid PPO study goes on at any "
            "commit (each run records its own): drop the flag"
        )
    archive = options.archive if options.archive is not None else options.study_dir
    check_run_places({"--study-dir": options.study_dir, "--archive": archive})
    runner = _runner()
    started = present(archive / runner.SPEC_FILE)
    if started and not options.resume:
        raise SetupError(
            f"{archive} already holds a MiniGrid study ({runner.SPEC_FILE}); pass --resume to "
            "go on with its runs, or a new --archive (or --study-dir) to start another"
        )
    if options.resume and not started:
        raise SetupError(
            f"no study to resume: {archive} holds no {runner.SPEC_FILE}; drop --resume to start "
            "the study, or pass the --archive of the study to continue"
        )
    archive.mkdir(parents=True, exist_ok=True)
    outcome = runner.run_study(
        spec,
        archive,
        options.study_dir,
        options.address,
        options.num_cpus or 2,
        options.verbose,
    )
    print(f"finished now: {len(outcome['finished'])}, failed: {outcome['failed']}")
    return 1 if outcome["failed"] else 0


def check_run_places(places: dict[str, Path]) -> None:
    """Refuse, by its flag, a directory of ``places`` where a MiniGrid study would run that
    belongs to another study or sweep: a SAC study's directory or archive (its ``study.json``),
    a MiniGrid study's archive given as the working directory beside another ``--archive``
    (:func:`~simoun_lab.study.owner.check_not_other_archive`), a folder inside any study's
    archive (:func:`~simoun_lab.study.owner.check_not_inside_study`), or a simoun-sweep
    directory or a folder inside one (:func:`~simoun_lab.study.owner.check_not_in_sweep`);
    before anything is written into it."""
    archive = places.get("--archive")
    for flag, where in places.items():
        study = sac_study(where)
        if study is not None:
            raise SetupError(
                f"{flag} {shown(where)} holds {study}, not a MiniGrid PPO study: running this "
                f"spec there would write its {PPO_SPEC_FILE} and runs into that study's; pass a "
                f"new {flag} (or the one of this MiniGrid study), and continue that study with "
                f"its own spec ({shown(where / STUDY_FILE)} names it)"
            )
        if archive is None or os.path.realpath(where) != os.path.realpath(archive):
            check_not_other_archive(where, flag)
        check_not_inside_study(where, flag)
        check_not_in_sweep(where, flag)


def refuse_sac_study(study_dir: Path, flag: str = "--study-dir") -> None:
    """Refuse a SAC study's directory (its ``study.json`` and no MiniGrid ``spec.json``): its
    runs are of another kind of study, which a MiniGrid spec cannot report."""
    record = study_dir / STUDY_FILE
    if present(record) and not present(study_dir / PPO_SPEC_FILE):
        raise SetupError(
            f"{flag} {study_dir} holds runs of a SAC study ({record}), not of a MiniGrid "
            f"PPO study; report it with the TOML spec it was run with (simoun-study report "
            f"SPEC.toml --study-dir {study_dir}; {record} names it), or pass the archive of a "
            "MiniGrid study"
        )


def report(spec: StudySpec, study_dir: Path) -> Path:
    """The MiniGrid report of the archive ``study_dir``, written into it."""
    from simoun_lab.minigrid_study.report import write_report

    runner = _runner()
    saved = study_dir / runner.SPEC_FILE
    if present(study_dir) and not study_dir.is_dir():
        raise SetupError(
            f"--study-dir {study_dir} is a file, not a study's archive (a directory); "
            f"{packed_folder_advice(study_dir)}"
        )
    refuse_sac_study(study_dir)
    check_not_inside_archive(study_dir, "--study-dir")
    if present(saved) and runner.load_saved_spec(saved) != spec:
        raise SetupError(
            f"--study-dir {study_dir} holds runs of another spec ({saved}); pass the spec it "
            "was run with"
        )
    if not runner.finished_runs(spec, study_dir):
        runner.refuse_foreign_runs(spec, study_dir, str(saved if present(saved) else "the spec"))
        raise SetupError(
            f"--study-dir {study_dir} holds no finished run of this spec: nothing to report yet"
        )
    return write_report(spec, study_dir)
