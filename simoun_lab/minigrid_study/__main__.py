"""``python -m simoun_lab.minigrid_study run|report``: the MiniGrid PPO study's command line.

python -m simoun_lab.minigrid_study run                  # every unfinished run, locally
python -m simoun_lab.minigrid_study run --address auto   # on a running Ray cluster
python -m simoun_lab.minigrid_study report               # docs/studies/minigrid/report/
python -m simoun_lab.minigrid_study probe                # docs/studies/minigrid/probe/
python -m simoun_lab.minigrid_study select --archive A   # a tuning archive's selection
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Union

import tyro

from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import Meant
from simoun_agent.config import SetupError
from simoun_agent.run.rundir import check_output_dir
from simoun_lab.minigrid_study.probe_settings import PROBE_NAMES, ProbeSettings

# The study's modules (torch, SB3, MiniGrid) are imported once the flags are read: --help,
# --version and a bad flag are answered in about a second.
if TYPE_CHECKING:
    from simoun_lab.minigrid_study.spec import StudySpec

ARCHIVE = Path("docs/studies/minigrid")

PROG = "python -m simoun_lab.minigrid_study"


def spec_for(spec: Path | None, archive: Path, new: bool = False) -> StudySpec:
    """``spec``, else the archive's spec, else the defaults (the study as designed) for the
    archive that holds them (``archive`` is ARCHIVE, or ``new``: a ``run`` may start a study in
    an empty directory). An archive that is not there is refused rather than made up: a
    mistyped ``--archive`` would otherwise start the whole study, or report on nothing."""
    from simoun_agent.run.kept import present
    from simoun_lab.minigrid_study.runner import SPEC_FILE, load_saved_spec
    from simoun_lab.minigrid_study.spec import StudySpec, load_spec
    from simoun_lab.minigrid_study.study_command import refuse_sac_study
    from simoun_lab.study.owner import check_not_inside_archive, check_not_inside_study

    check_archive_folder(archive, new)
    refuse_sac_study(archive, "--archive")
    # a run writes a study into --archive, report and select read one from it
    (check_not_inside_study if new else check_not_inside_archive)(archive, "--archive")
    if spec is not None:
        given = load_spec(spec, "--spec")
        if present(archive / SPEC_FILE):
            check_archive_spec(given, spec, archive / SPEC_FILE)
        return given
    if present(archive / SPEC_FILE):
        return load_saved_spec(archive / SPEC_FILE)
    if new and (archive == ARCHIVE or not any(archive.iterdir())):
        return StudySpec()
    raise SetupError(
        f"--archive {archive} holds no {SPEC_FILE}, so it is not a study's archive; pass the "
        "archive a run wrote, or --spec FILE for the spec its runs were trained with"
    )


def check_archive_folder(archive: Path, new: bool) -> None:
    """Refuse an ``archive`` that is no directory: not there (a mistyped ``--archive`` would
    otherwise start the whole study, or report on nothing), or a file, such as the archive
    packed for sending (``mg.tar.gz``), which must be unpacked first. ``new``: a ``run``, which
    may start a study in a directory created for it."""
    from simoun_agent.run.kept import packed_folder_advice

    if archive.is_dir():
        return
    where = f"{archive.absolute()}" if archive == ARCHIVE else f"--archive {archive}"
    if archive.exists():
        raise SetupError(
            f"{where} is a file, not a study's archive (a directory); "
            f"{packed_folder_advice(archive)}"
        )
    in_clone = " (run it from the root of a clone of simoun)" if archive == ARCHIVE else ""
    start = "; to start a new study, create the directory first" if new else ""
    raise SetupError(f"no study archive at {where}: no such directory{in_clone}{start}")


def check_archive_spec(spec: StudySpec, path: Path, saved: Path) -> None:
    """Refuse the spec ``spec`` (read from ``--spec path``) when the archive's runs were
    trained with another (``saved``): its report or selection would mix the two designs."""
    from simoun_lab.engine.launcher import changed_keys
    from simoun_lab.minigrid_study.runner import read_saved_spec
    from simoun_lab.minigrid_study.spec import spec_from_dict

    archived = spec_from_dict(read_saved_spec(saved), str(saved)).to_json()
    changed = sorted(changed_keys(archived, spec.to_json()))
    if changed:
        raise SetupError(
            f"--spec {path} is another spec than the one the archive's runs were trained with "
            f"({saved}; keys {', '.join(changed)} differ); leave --spec out to use the "
            "archive's, or pass the --archive of the study that spec ran"
        )


OTHER_NAMES = {
    "log-dir": Meant(("--work-dir", "--archive")),
    "logdir": Meant(("--work-dir", "--archive")),
    "tensorboard-log": Meant(("--work-dir",)),
    "n-envs": Meant(("--settings.n-envs",)),
    "num-envs": Meant(("--settings.n-envs",)),
}
"""Other libraries' flags (SB3's, rl-zoo's) with what the study's command line calls them
(:mod:`simoun_agent.cli.other_names`)."""


@dataclass
class Report:
    """Write the report."""

    archive: Path = ARCHIVE
    """the study's records"""
    spec: Path | None = None
    """a JSON spec, or a TOML one with the same keys (None: the archive's spec.json)"""


@dataclass
class Run(Report):
    """Train every unfinished run."""

    work_dir: Path = Path("runs/minigrid_study")
    """Ray Tune's records and the run directories (a run in progress keeps its checkpoint
    there, and a rerun goes on from it)"""
    address: str | None = None
    """a Ray cluster (auto, HOST:PORT); None: local"""
    concurrent: int = 2
    """runs at a time"""


@dataclass
class Probe:
    """Correlate each probed intrinsic reward with novelty under a random policy (no PPO)."""

    settings: ProbeSettings = field(default_factory=ProbeSettings)
    probes: list[str] = field(default_factory=lambda: list(PROBE_NAMES))
    """probes of ``simoun_lab.minigrid_study.probe.PROBED``"""
    out: Path = ARCHIVE / "probe"
    """where probe.csv and probe.md go"""


@dataclass
class Select(Report):
    """Apply the tuning phase's selection rule to a tuning archive (selection.md, .json)."""


Command = Union[  # noqa: UP007  (tyro 1.0 does not read the `|` of two Annotated types)
    Annotated[Run, tyro.conf.subcommand("run")],
    Annotated[Report, tyro.conf.subcommand("report")],
    Annotated[Select, tyro.conf.subcommand("select")],
    Annotated[Probe, tyro.conf.subcommand("probe")],
]


DESCRIPTION = (
    "SB3 PPO on MiniGrid pixels with no intrinsic reward, consistency curiosity or RND: train the "
    "runs on Ray Tune (resumable), then report; probe an intrinsic reward's link to novelty "
    "without PPO."
)


@names_full_disk(PROG, "copy the archive to another disk and pass the copy as --archive")
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    args = parse(Command, argv, PROG, DESCRIPTION, other_names=OTHER_NAMES)
    if isinstance(args, Probe):
        from simoun_lab.minigrid_study.probe_settings import check_probes, check_settings
        from simoun_lab.minigrid_study.spec import MINIGRID_ID

        try:
            check_probes(args.probes)
            check_settings(args.settings, lambda field: "--settings." + field.replace("_", "-"))
            check_output_dir(args.out, "--out", ("probe.md", "probe.csv"))
            if not args.out.parent.is_dir():
                raise SetupError(
                    f"--out {args.out}: its folder {args.out.parent.absolute()} does not exist; "
                    "run from the root of a clone of simoun, or pass an --out whose folder exists"
                )
            if not MINIGRID_ID.ok(args.settings.env_id):
                raise SetupError(
                    f"--settings.env-id {args.settings.env_id}: must be {MINIGRID_ID.need}"
                )
            from simoun_lab.minigrid_study.probe import write_probe  # torch, once the flags pass

            print(write_probe(args.settings, args.probes, args.out))
        except ValueError as err:
            fail(PROG, err)
        return 0
    try:
        if isinstance(args, Run):
            from simoun_lab.minigrid_study.study_command import check_run_places

            check_run_places({"--archive": args.archive, "--work-dir": args.work_dir})
        spec = spec_for(args.spec, args.archive, new=isinstance(args, Run))
        if isinstance(args, Run):
            from simoun_lab.minigrid_study.runner import run_study
            from simoun_lab.study.archive import check_archive_apart

            check_output_dir(args.archive, "--archive")
            check_output_dir(args.work_dir, "--work-dir")
            check_archive_apart(args.archive, args.work_dir, "--work-dir", str(ARCHIVE))
            outcome = run_study(spec, args.archive, args.work_dir, args.address, args.concurrent)
            print(f"finished now: {len(outcome['finished'])}, failed: {outcome['failed']}")
            return 1 if outcome["failed"] else 0
        if isinstance(args, Select):
            from simoun_lab.minigrid_study.select import write_selection

            print(write_selection(spec, args.archive))
            return 0
        from simoun_lab.minigrid_study.report import write_report
        from simoun_lab.minigrid_study.runner import SPEC_FILE, finished_runs, refuse_foreign_runs

        if not finished_runs(spec, args.archive):
            source = str(args.spec or args.archive / SPEC_FILE)
            refuse_foreign_runs(spec, args.archive, source)
            raise SetupError(
                f"--archive {args.archive} holds no finished run of its spec: nothing to report "
                f"yet; train them with: {PROG} run --archive {args.archive}"
            )
        print(write_report(spec, args.archive))
    except SetupError as err:
        fail(PROG, err)
    return 0


if __name__ == "__main__":
    sys.exit(main())
