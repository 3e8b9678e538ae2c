"""``simoun-study``: one protocol for every method, from a spec file, on Ray Tune.

    simoun-study plan docs/studies/dmc100k.toml
    simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k \\
        --archive docs/studies/dmc100k
    simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k \\
        --archive docs/studies/dmc100k --resume

``plan`` lists every run of both phases with a CPU-time estimate measured here; ``run`` tunes
(every recipe x grid setting x tuning seed), selects each recipe's setting by the spec's rule,
evaluates the selected settings on the held-out seeds and writes the report
(:mod:`simoun_agent.study.report`). The study is run by :mod:`simoun_agent.study.runner`; the
runs go through ``simoun-sweep``'s code: the same trial directories, Tune experiments, STOP file
on SIGTERM and failure handling.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simoun_agent.cli.flags import add_version
from simoun_agent.config import SetupError
from simoun_agent.study.plan import describe
from simoun_agent.study.runner import run_study, spec_from
from simoun_agent.sweep.launch import load_ray


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="simoun-study",
        description="Run a study from its spec file: tune every recipe on one shared grid, "
        "select each recipe's setting by one rule, evaluate the selected settings on held-out "
        "seeds, and report IQM with confidence intervals (Agarwal et al. 2021).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
        epilog="examples:\n"
        "  simoun-study plan docs/studies/dmc100k.toml\n"
        "  simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k "
        "--archive docs/studies/dmc100k\n"
        "  simoun-study run docs/studies/dmc100k.toml --study-dir runs/studies/dmc100k "
        "--archive docs/studies/dmc100k --resume\n\n"
        "The spec's layout is documented in simoun_agent/study/spec.py; "
        "docs/studies/dmc100k.toml is a full example.",
    )
    add_version(parser)
    commands = parser.add_subparsers(dest="command", required=True, metavar="{plan,run}")
    planning = commands.add_parser(
        "plan",
        help="list every run of both phases and estimate their CPU time, running nothing",
        description="List every run of both phases (phase, task, recipe, grid values, seed, "
        "env steps) and estimate the CPU time of each from a short probe measured here.",
    )
    planning.add_argument("spec", metavar="SPEC", help="the study's TOML file")
    planning.add_argument(
        "--probe-updates",
        type=int,
        default=20,
        metavar="N",
        help="agent updates timed per configuration (default: 20; 0: no estimate)",
    )
    running = commands.add_parser(
        "run",
        help="run the study (tuning, selection, evaluation, report) on Ray Tune",
        description="Run the tuning phase, select each recipe's setting, run the evaluation "
        "phase on the held-out seeds and write the report into STUDY_DIR/report.",
    )
    running.add_argument("spec", metavar="SPEC", help="the study's TOML file")
    running.add_argument(
        "--study-dir",
        required=True,
        metavar="DIR",
        help="where the runs and the report go; on a cluster, a directory every machine sees",
    )
    running.add_argument(
        "--archive",
        metavar="DIR",
        help="copy each finished run's CSVs, config.json and summary.json (no checkpoints, "
        "replays, videos or tb/) here as it completes, with the study record, the selection "
        "and the report, e.g. docs/studies/NAME; a resumed study counts archived runs as done",
    )
    running.add_argument(
        "--resume",
        action="store_true",
        help="continue the study: finished runs (in --study-dir, else in --archive) are kept, "
        "the others go on from their checkpoints or start",
    )
    running.add_argument(
        "--allow-other-commit",
        action="store_true",
        help="resume even though the code is at another commit than the study started from",
    )
    running.add_argument(
        "--address",
        metavar="auto|HOST:PORT|ray://HOST:PORT",
        help="run on a Ray cluster (auto: the one `ray start` made here); default: a local "
        "Ray instance",
    )
    running.add_argument(
        "--num-cpus", type=int, metavar="N", help="CPUs of the local Ray instance (default: all)"
    )
    running.add_argument(
        "--verbose", type=int, default=1, choices=(0, 1, 2), help="Tune's output (default: 1)"
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-study``."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        spec = spec_from(args.spec)
        if args.command == "plan":
            if args.probe_updates < 0:
                raise SetupError("--probe-updates must be 0 or more")
            print(describe(spec, args.spec, args.probe_updates))
            return 0
        # absolute: Tune runs each trial in a working directory of its own
        args.study_dir = Path(args.study_dir).absolute()
        args.archive = Path(args.archive).absolute() if args.archive else None
        ray = load_ray()
        return run_study(spec, args, ray)
    except SetupError as err:
        parser.exit(2, f"simoun-study: error: {err}\n")


if __name__ == "__main__":
    sys.exit(main())
