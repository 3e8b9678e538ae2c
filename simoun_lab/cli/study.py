"""``simoun-study``: one protocol for every method, from a spec file, on Ray Tune.

    simoun-study plan docs/studies/dmc100k.toml
    simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k \\
        --archive docs/studies/dmc100k
    simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k \\
        --archive docs/studies/dmc100k --resume

``plan`` lists every run of both phases with a CPU-time estimate measured here; ``run`` tunes
(every recipe x grid setting x tuning seed), selects each recipe's setting by the spec's rule,
evaluates the selected settings on the held-out seeds and writes the report
(:mod:`simoun_lab.study.report`); ``report`` writes it again from the finished runs of a study
directory or its archive (``simoun-study report SPEC --study-dir docs/studies/NAME``). The
study is run by :mod:`simoun_lab.study.runner`; the runs go through the engine
(:mod:`simoun_lab.engine.launcher`) as ``simoun-sweep``'s do: the same trial directories, Tune
experiments, STOP file on SIGTERM and failure handling.

A MiniGrid PPO spec (a JSON file, or TOML with ``arms``) is planned, run and reported on the same
engine by :mod:`simoun_lab.minigrid_study.study_command`.
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Union

import tyro

from simoun_agent.cli.command_flags import PATH
from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import POSITIONAL, Meant
from simoun_agent.config import SetupError
from simoun_agent.run.rundir import (
    check_output_dir,
    check_output_files,
    copy_fix,
    make_output_dir,
    output_files,
)
from simoun_lab.engine.ray_start import load_ray
from simoun_lab.study.options import StudyOptions

PROG = "simoun-study"

DESCRIPTION = """Run a study from its spec file: tune every recipe on one shared grid, select
each recipe's setting by one rule, evaluate the selected settings on held-out seeds, and report
IQM with confidence intervals (Agarwal et al. 2021).

examples:
  simoun-study plan docs/studies/dmc100k.toml
  simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k \\
      --archive docs/studies/dmc100k
  simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k \\
      --archive docs/studies/dmc100k --resume
  simoun-study report docs/studies/dmc100k.toml --study-dir docs/studies/dmc100k

The spec's layout is documented in simoun_lab/study/spec.py; docs/studies/dmc100k.toml is a
full example. A MiniGrid PPO spec (SB3 PPO with or without an intrinsic reward, e.g.
docs/studies/minigrid-v2/tuning/spec.json) runs the same way:
  simoun-study run docs/studies/minigrid-v2/tuning/spec.json --study-dir runs/minigrid-v2 \\
      --archive docs/studies/minigrid-v2/tuning --resume"""


OTHER_NAMES = {
    "config": POSITIONAL,
    "spec-file": POSITIONAL,
    "log-dir": Meant(("--study-dir",), "every run's directory goes under it"),
    "logdir": Meant(("--study-dir",), "every run's directory goes under it"),
    "exp-name": Meant(("--study-dir",), "a study is named by its directory"),
}
"""Other flags for the spec simoun-study takes as its positional SPEC, and for its
--study-dir (:mod:`simoun_agent.cli.other_names`)."""


@dataclass
class Plan:
    """List every run of both phases (phase, task, recipe, grid values, seed, env steps) and
    estimate the CPU time of each from a short probe measured here, running nothing."""

    spec: Annotated[str, PATH, tyro.conf.Positional, tyro.conf.arg(metavar="SPEC")]
    """the study's TOML file"""
    probe_updates: Annotated[int, tyro.conf.arg(metavar="N")] = 20
    """agent updates timed per configuration (0: no estimate)"""


@dataclass(kw_only=True)
class Run(StudyOptions):
    """Run the tuning phase, select each recipe's setting, run the evaluation phase on the
    held-out seeds and write the report into STUDY_DIR/report (on Ray Tune)."""

    spec: Annotated[str, PATH, tyro.conf.Positional, tyro.conf.arg(metavar="SPEC")]
    """the study's TOML file"""
    # the library's options, with the command line's metavars (their docs are StudyOptions')
    study_dir: Annotated[Path, tyro.conf.arg(metavar="DIR")]
    archive: Annotated[Path | None, tyro.conf.arg(metavar="DIR")] = None
    resume: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    allow_other_commit: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    address: Annotated[str | None, tyro.conf.arg(metavar="auto|HOST:PORT|ray://HOST:PORT")] = None
    num_cpus: Annotated[int | None, tyro.conf.arg(metavar="N")] = None


@dataclass(kw_only=True)
class Report:
    """Write the report of a study's finished runs again, with this code, from its study
    directory or its archive (no Ray, nothing trained): into DIR/report."""

    spec: Annotated[str, PATH, tyro.conf.Positional, tyro.conf.arg(metavar="SPEC")]
    """the study's TOML file"""
    study_dir: Annotated[Path, tyro.conf.arg(metavar="DIR")]
    """the study directory or its archive (e.g. docs/studies/NAME)"""


Command = Union[  # noqa: UP007  (tyro 1.0 does not read the `|` of two Annotated types)
    Annotated[Plan, tyro.conf.subcommand("plan")],
    Annotated[Run, tyro.conf.subcommand("run")],
    Annotated[Report, tyro.conf.subcommand("report")],
]
"""The command line: plan a study, run it, or write its report again."""


@names_full_disk(PROG, "copy the study directory to another disk and pass the copy as --study-dir")
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simoun-study``."""
    args = parse(Command, argv, PROG, DESCRIPTION, other_names=OTHER_NAMES)
    # torch comes with the spec readers, imported once the flags are read: --help, --version and
    # a bad flag are answered in about a second
    from simoun_lab.minigrid_study.study_command import is_ppo_spec
    from simoun_lab.study.checks import check_study
    from simoun_lab.study.plan import describe
    from simoun_lab.study.runner import report_study, run_study, spec_from

    try:
        if is_ppo_spec(args.spec):
            return ppo_study(args)
        spec = spec_from(args.spec)
        if isinstance(args, Plan):
            if args.probe_updates < 0:
                raise SetupError("--probe-updates must be 0 or more")
            check_study(spec, args.spec)
            print(describe(spec, args.spec, args.probe_updates))
            return 0
        if isinstance(args, Report):
            print(f"report: {report_study(spec, args.study_dir)}")
            return 0
        options = absolute(args)
        check_switches(options)
        check_outputs(options)  # before Ray, which takes seconds to import
        ray = load_ray()
        for flag, path in outputs(options).items():
            make_output_dir(path, flag)
        return run_study(spec, args.spec, options, ray)
    except SetupError as err:
        fail(PROG, err)


def ppo_study(args: Plan | Run | Report) -> int:
    """The command on a MiniGrid PPO spec."""
    from simoun_lab.minigrid_study import study_command

    spec = study_command.load_ppo_spec(args.spec)
    if isinstance(args, Plan):
        print(study_command.plan(spec, args.spec))
        return 0
    if isinstance(args, Report):
        print(f"report: {study_command.report(spec, args.study_dir)}")
        return 0
    options = absolute(args)
    check_outputs(options)
    return study_command.run(spec, options)


def check_switches(options: Run) -> None:
    """Refuse a switch given without the flag it works with: it would be accepted and change
    nothing."""
    if options.allow_other_commit and not options.resume:
        raise SetupError(
            "--allow-other-commit works only with --resume: it lets a resumed study go on at "
            "another commit than the one it started from, and a new study starts at this one "
            "(and records it); add --resume to continue the study in --study-dir, or drop "
            "--allow-other-commit to start one"
        )


def outputs(options: Run) -> dict[str, Path]:
    """The output directories the run was given, by flag."""
    given = {"--study-dir": options.study_dir, "--archive": options.archive}
    return {flag: path for flag, path in given.items() if path is not None}


def resume_fix(options: Run, flag: str) -> str:
    """The fix for a study directory or archive that cannot be written, resumed: another
    folder holds nothing to resume, so the folder is copied and the copy resumed."""
    given = {"--study-dir": options.study_dir, "--archive": options.archive}
    others = " ".join(f"{name} {path}" for name, path in given.items() if name != flag and path)
    switch = " --allow-other-commit" if options.allow_other_commit else ""
    command = f"simoun-study run {options.spec} {others} --resume{switch}".replace("  ", " ")
    return copy_fix(given[flag], f"{command} {flag}")


def check_outputs(options: Run) -> None:
    """Refuse an output directory that cannot be written (:func:`check_output_dir`) or that
    lies inside another study's archive (:func:`~simoun_lab.study.owner.check_not_inside_study`)
    or is or lies in a simoun-sweep directory (:func:`~simoun_lab.study.owner.check_not_in_sweep`),
    a folder where the report written after the runs goes, and an archive that is, holds or lies
    in the study directory (:func:`check_archive_apart`), creating nothing."""
    from simoun_lab.study.owner import check_not_in_sweep, check_not_inside_study
    from simoun_lab.study.report import REPORT_DIR, REPORT_FILES  # numpy: after the flags

    for flag, path in outputs(options).items():
        check_output_dir(path, flag, fix=resume_fix(options, flag) if options.resume else None)
        check_not_inside_study(path, flag)
        check_not_in_sweep(path, flag)
    check_output_files(output_files(options.study_dir / REPORT_DIR, REPORT_FILES))
    if options.archive is not None:
        from simoun_lab.study.archive import check_archive_apart  # torch: after the flags

        check_archive_apart(options.archive, options.study_dir, "--study-dir", "docs/studies/NAME")


def absolute(args: Run) -> Run:
    """``args`` with absolute directories: Tune runs each trial in a working directory of its
    own."""
    return dataclasses.replace(
        args,
        study_dir=args.study_dir.absolute(),
        archive=args.archive.absolute() if args.archive else None,
    )


if __name__ == "__main__":
    sys.exit(main())
