"""``simoun-eval RUN_DIR [RUN_DIR ...] --distraction MODES``: the generalization report."""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import sys
from pathlib import Path

from simoun_agent.config import SetupError
from simoun_agent.generalization.evaluation import evaluate_runs
from simoun_agent.generalization.report import TABLE_CSV, write_report
from simoun_agent.generalization.suite import parse_distractions
from simoun_agent.run.rundir import make_output_dir
from simoun_agent.run.signals import Stopped, stop_at_once


def default_out(run_dirs: list[Path]) -> Path:
    """``<run dir>/generalization`` for one run, ``<their common folder>/generalization`` for
    several (a run given by its checkpoint.pt counts as its folder)."""
    folders = [path if path.is_dir() else path.parent for path in run_dirs]
    return Path(os.path.commonpath([folder.resolve() for folder in folders])) / "generalization"


def evaluate_distractions(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    """Evaluate ``args.checkpoint`` (one or several runs) on ``args.distraction``'s modes and
    write the table, CSV and bar chart; bad input exits through ``parser`` without traceback."""
    if args.random_policy:
        parser.error("--random-policy does not combine with --distraction")
    run_dirs = [Path(path) for path in args.checkpoint]
    created, out = False, None
    try:
        modes = parse_distractions(args.distraction)
        missing = [str(path) for path in run_dirs if not path.exists()]
        if missing:
            raise SetupError(
                f"no such run directory or checkpoint: {', '.join(missing)}; pass directories "
                "that simoun-train created"
            )
        out = Path(args.out) if args.out else default_out(run_dirs)
        if (out / TABLE_CSV).exists() and not args.overwrite:
            raise SetupError(
                f"{out} holds an earlier generalization report; pass --overwrite to replace it, "
                "or --out DIR to write this one elsewhere"
            )
        created = make_output_dir(out)
        with stop_at_once():
            results = evaluate_runs(
                run_dirs,
                modes,
                args.episodes,
                seed=args.seed,
                device=args.device,
                videos=args.videos,
                progress=_status if args.progress else None,
            )
    except SetupError as err:
        # a run or mode refused while loading: leave no empty report directory behind
        if created:
            shutil.rmtree(out, ignore_errors=True)
        parser.exit(2, f"{parser.prog}: error: {err}\n")
    except Stopped as stop:
        if created:
            shutil.rmtree(out, ignore_errors=True)
        print(f"{parser.prog}: stopped by {signal.Signals(stop.signum).name}", file=sys.stderr)
        return stop.exit_code
    envs = sorted({result.env.removeprefix("dm_control/") for result in results})
    steps = sorted({result.env_step for result in results})
    title = (
        f"{', '.join(envs)}: return under distraction after "
        f"{', '.join(str(step) for step in steps)} env steps"
    )
    paths = write_report(results, out, title)
    print(paths["table"].read_text(), end="")
    print(f"wrote {paths['table']}, {paths['csv']} and {paths['chart']}")
    return 0


def _status(line: str) -> None:
    print(line, file=sys.stderr, flush=True)
