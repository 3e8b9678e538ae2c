"""``simoun-report DIR``: tables and figures of a sweep or of a directory of ``simoun-train``
runs, per variant and env, over seeds (:mod:`simoun_agent.sweep.report` describes them).

    simoun-report sweeps/baselines
    simoun-report runs/ --out runs/report
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from simoun_agent.config import SetupError
from simoun_agent.sweep.report import write_report


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-report``."""
    parser = argparse.ArgumentParser(
        prog="simoun-report",
        description="Tables (Markdown, CSV) and figures (PNG) of a sweep or of a directory of "
        "simoun-train runs, per variant and env, over seeds: mean ± std, and on returns "
        "normalized by the task's maximum the IQM and mean with 95 % stratified-bootstrap "
        "confidence intervals, probabilities of improvement, performance profiles and IQM "
        "curves (Agarwal et al. 2021). A row counts each seed once (the run that finished, or "
        "reached the budget, then the most recent; the others are listed) and runs of one "
        "evaluation grid (eval_every: runs on another grid than most of their row are listed "
        "and left out).",
    )
    parser.add_argument("root", metavar="DIR", help="a sweep directory or a directory of runs")
    parser.add_argument(
        "--out",
        metavar="DIR",
        help="where to write the report (default: DIR; for a single run directory, "
        "report-<name> beside it, so the run directory is left as simoun-train wrote it)",
    )
    equal = parser.add_mutually_exclusive_group()
    equal.add_argument(
        "--at-step",
        type=int,
        metavar="N",
        help="compare at an equal budget of N env steps: a run counts, finished or not, only "
        "with an evaluation at exactly N (runs evaluated elsewhere are listed as short)",
    )
    equal.add_argument(
        "--at-wall-time",
        type=float,
        metavar="SECONDS",
        help="compare at an equal wall-time budget: a run counts, finished or not, if it "
        "trained past SECONDS (an evaluation at or after it), with its last evaluation at or "
        "before SECONDS (runs that stopped earlier are listed as short)",
    )
    args = parser.parse_args(argv)
    budget = None
    if args.at_step is not None:
        budget = ("env_step", args.at_step)
    elif args.at_wall_time is not None:
        budget = ("wall_time_s", args.at_wall_time)
    if budget is not None and budget[1] <= 0:
        parser.exit(2, "simoun-report: error: --at-step / --at-wall-time must be positive\n")
    try:
        written = write_report(Path(args.root), Path(args.out) if args.out else None, budget)
    except SetupError as err:
        parser.exit(2, f"simoun-report: error: {err}\n")
    print((Path(written[0])).read_text(), end="")
    print(f"written: {', '.join(map(str, written))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
