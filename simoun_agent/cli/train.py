"""``simoun-train``: train the Simoun agent on any pixel or renderable Gymnasium env.

    simoun-train --env dm_control/cartpole-swingup-v0 --preset cpu
    simoun-train --preset walker-walk --agent.encoder dual --agent.curiosity false
    simoun-train --resume runs/cartpole-swingup-cpu-s1-20260101-120000

The command line over the training loop (:mod:`simoun_agent.run.train`, where the run
directory, the stops and the exit statuses are described). A run whose config names
``eval_distraction`` modes gets the distracted evaluation
(:func:`simoun_agent.generalization.distraction_callbacks`) passed to the loop.
"""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from tqdm import tqdm

from simoun_agent.cli.config_flags import add_config_arguments, overrides_from
from simoun_agent.cli.flags import add_version
from simoun_agent.config import PRESETS, RECIPES, SetupError, resolve
from simoun_agent.config.train import RESUMABLE_FIELDS
from simoun_agent.generalization import check_eval_distractions, distraction_callbacks
from simoun_agent.run import train as loop  # called through the module: tests wrap loop.train
from simoun_agent.run.memory import check_memory
from simoun_agent.run.signals import Stopped, stop_at_once


def build_parser() -> argparse.ArgumentParser:
    """The command line: a few run options and one flag per config key."""
    presets = "\n".join(f"  {name:18} {preset.description}" for name, preset in PRESETS.items())
    recipes = "\n".join(f"  {name:18} {recipe.description}" for name, recipe in RECIPES.items())
    parser = argparse.ArgumentParser(
        prog="simoun-train",
        usage="simoun-train [--preset NAME | --resume RUN_DIR] [--KEY VALUE ...] [--set KEY=VALUE]",
        description="Train the Simoun agent (vision-based SAC) on a Gymnasium environment.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=f"presets:\n{presets}\n\nagent recipes (--agent.recipe NAME):\n{recipes}\n\n"
        "examples:\n"
        "  simoun-train --env dm_control/cartpole-swingup-v0 --preset cpu\n"
        "  simoun-train --preset cheetah-run --agent.encoder dual --agent.curiosity false\n"
        "  simoun-train --preset highway --set agent.batch_size=64\n"
        "  simoun-train --preset cpu --agent.recipe drq --seed 2\n"
        "  simoun-train --resume runs/cartpole-swingup-cpu-s1-20260101-120000\n\n"
        "Values: booleans true/false, None as none, dicts as JSON (--env-kwargs '{\"a\": 1}').",
    )
    parser.add_argument(
        "--resume",
        metavar="RUN_DIR",
        help="continue a run from its last checkpoint (only "
        f"{', '.join(RESUMABLE_FIELDS)} may be changed)",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="start over in a --run-dir whose run stopped before its first checkpoint (a run "
        "with a checkpoint is never deleted: --resume it)",
    )
    add_version(parser)
    add_config_arguments(parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-train``."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        with stop_at_once():  # nothing to save during set-up
            run = setup(parser, args)
    except Stopped as stop:
        print(
            f"simoun-train: stopped by {signal.Signals(stop.signum).name} during set-up, before "
            "anything was trained",
            file=sys.stderr,
        )
        return stop.exit_code
    tqdm.write(f"run directory: {run.run_dir}")
    try:
        final = loop.train(run, distraction_callbacks(run.config))
    except KeyboardInterrupt as stop:  # Stopped after a checkpoint, or a second Ctrl-C
        return getattr(stop, "exit_code", 130)
    except loop.TrainingError as err:
        print(f"simoun-train: error: {err}", file=sys.stderr)
        return err.exit_code
    finally:
        run.env.close()
        run.eval_env.close()
        loop.release(run)
    tqdm.write(
        f"done: evaluation return {final['return_mean']:.1f} +- {final['return_std']:.1f} after "
        f"{run.counters.env_step} env steps; learning curve, logs, checkpoint"
        f"{' and video' if run.config.video else ''} in {run.run_dir}"
    )
    return 0


def setup(parser: argparse.ArgumentParser, args: argparse.Namespace) -> loop.Run:
    """The run that ``args`` ask for, new or resumed; bad input exits with status 2."""
    try:
        overrides = overrides_from(args)
        if args.resume:
            if args.preset:
                raise SetupError("--preset does not combine with --resume: a run keeps its config")
            if args.overwrite:
                raise SetupError("--overwrite starts a run over; it does not combine with --resume")
            run = loop.resume_run(Path(args.resume), overrides, check=check_eval_distractions)
        else:
            config = resolve(args.preset, overrides)
            warning = check_memory(config)  # before anything is built
            if warning:
                print(f"simoun-train: warning: {warning}", file=sys.stderr)
            run = loop.create_run(config, overwrite=args.overwrite, check=check_eval_distractions)
    except SetupError as err:
        parser.exit(2, f"simoun-train: error: {err}\n")
    return run


if __name__ == "__main__":
    sys.exit(main())
