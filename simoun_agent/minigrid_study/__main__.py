"""``python -m simoun_agent.minigrid_study run|report``: the MiniGrid PPO study's command line.

python -m simoun_agent.minigrid_study run                  # every unfinished run, locally
python -m simoun_agent.minigrid_study run --address auto   # on a running Ray cluster
python -m simoun_agent.minigrid_study report               # docs/studies/minigrid/report/
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simoun_agent.config import SetupError
from simoun_agent.minigrid_study.spec import StudySpec, load_spec

ARCHIVE = Path("docs/studies/minigrid")


def spec_for(args: argparse.Namespace) -> StudySpec:
    """``--spec``, else the archive's spec, else the defaults (the study as designed)."""
    from simoun_agent.minigrid_study.tune import SPEC_FILE

    if args.spec is not None:
        return load_spec(args.spec)
    if (args.archive / SPEC_FILE).is_file():
        return load_spec(args.archive / SPEC_FILE)
    return StudySpec()


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m simoun_agent.minigrid_study",
        description="SB3 PPO on MiniGrid pixels with no intrinsic reward, consistency curiosity "
        "or RND: train the runs on Ray Tune (resumable), then report.",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    for name, text in (("run", "train every unfinished run"), ("report", "write the report")):
        command = commands.add_parser(name, help=text)
        command.add_argument(
            "--archive", type=Path, default=ARCHIVE, help=f"the study's records (default {ARCHIVE})"
        )
        command.add_argument(
            "--spec", type=Path, default=None, help="a JSON spec (default: the archive's spec.json)"
        )
    run = commands.choices["run"]
    run.add_argument(
        "--work-dir",
        type=Path,
        default=Path("runs/minigrid_study"),
        help="Ray Tune's records and the runs in progress (default runs/minigrid_study)",
    )
    run.add_argument(
        "--address", default=None, help="a Ray cluster (auto, HOST:PORT); default local"
    )
    run.add_argument("--concurrent", type=int, default=2, help="runs at a time (default 2)")
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        spec = spec_for(args)
        if args.command == "run":
            from simoun_agent.minigrid_study.tune import run_study

            outcome = run_study(spec, args.archive, args.work_dir, args.address, args.concurrent)
            print(f"finished now: {len(outcome['finished'])}, failed: {outcome['failed']}")
            return 1 if outcome["failed"] else 0
        from simoun_agent.minigrid_study.report import write_report

        print(write_report(spec, args.archive))
    except SetupError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
