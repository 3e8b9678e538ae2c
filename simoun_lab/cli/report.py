"""``simoun-report DIR``: tables and figures of a sweep or of a directory of ``simoun-train``
runs, per variant and env, over seeds (:mod:`simoun_lab.sweep.report` describes them).

    simoun-report sweeps/baselines
    simoun-report runs/ --out runs/report
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import tyro

from simoun_agent.cli.command_flags import PATH
from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import POSITIONAL
from simoun_agent.config import SetupError
from simoun_lab.sweep.report import BUDGET_FLAGS, write_report

PROG = "simoun-report"

DESCRIPTION = (
    "Tables (Markdown, CSV) and figures (PNG) of a sweep or of a directory of simoun-train "
    "runs, per variant and env, over seeds: mean ± std, and on returns normalized by the "
    "task's maximum the IQM and mean with 95 % stratified-bootstrap confidence intervals, "
    "probabilities of improvement, performance profiles and IQM curves (Agarwal et al. 2021). "
    "A row counts each seed once (the run that finished, or reached the budget, then the most "
    "recent; the others are listed) and runs of one evaluation grid (eval_every: runs on "
    "another grid than most of their row are listed and left out)."
)


BUDGET = tyro.conf.create_mutex_group(required=False, title="equal budget (one of)")


OTHER_NAMES = {name: POSITIONAL for name in ("log-dir", "logdir", "run-dir", "sweep-dir", "runs")}
"""Other flags for the directory simoun-report takes as its positional DIR
(:mod:`simoun_agent.cli.other_names`)."""


@dataclass
class ReportCommand:
    """What ``simoun-report`` is asked."""

    root: Annotated[str, PATH, tyro.conf.Positional, tyro.conf.arg(metavar="DIR")]
    """a sweep directory or a directory of runs"""
    out: Annotated[str | None, PATH, tyro.conf.arg(metavar="DIR")] = None
    """where to write the report (none: DIR; for a single run directory, report-<name> beside
    it, so the run directory is left as simoun-train wrote it)"""
    at_step: Annotated[int | None, BUDGET, tyro.conf.arg(metavar="N")] = None
    """compare at an equal budget of N env steps: a run counts, finished or not, only with an
    evaluation at N, or the nearest within half its eval_every (listed in the report; runs
    evaluated elsewhere are listed as short)"""
    at_wall_time: Annotated[float | None, BUDGET, tyro.conf.arg(metavar="SECONDS")] = None
    """compare at an equal wall-time budget: a run counts, finished or not, if it trained past
    SECONDS (an evaluation at or after it), with its last evaluation at or before SECONDS (runs
    that stopped earlier are listed as short)"""


def budget_of(args: ReportCommand) -> tuple[str, float] | None:
    """The equal budget ``--at-step`` or ``--at-wall-time`` asks for (None: compare the runs at
    their ends); exits naming the flag when its value is no budget."""
    if args.at_step is not None:
        # step 0 is a budget too: the evaluation of the untrained agent, which every run logs
        if args.at_step < 0:
            fail(
                PROG,
                f"--at-step {args.at_step}: give a number of env steps >= 0, e.g. --at-step "
                "100000 (or 0, the evaluation before any training)",
            )
        return ("env_step", args.at_step)
    if args.at_wall_time is not None:
        if not (math.isfinite(args.at_wall_time) and args.at_wall_time > 0):
            fail(
                PROG,
                f"--at-wall-time {args.at_wall_time:g}: give a positive finite number of "
                "seconds, e.g. --at-wall-time 3600",
            )
        return ("wall_time_s", args.at_wall_time)
    return None


@names_full_disk(PROG, "pass --out DIR on another disk")
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simoun-report``."""
    args = parse(ReportCommand, argv, PROG, DESCRIPTION, other_names=OTHER_NAMES)
    budget = budget_of(args)
    try:
        out = Path(args.out) if args.out else None
        written = write_report(Path(args.root), out, budget, budget_flags=BUDGET_FLAGS)
    except SetupError as err:
        fail(PROG, err)
    print((Path(written[0])).read_text(), end="")
    print(f"written: {', '.join(map(str, written))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
