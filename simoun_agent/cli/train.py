"""``simoun-train``: train the Simoun agent on any pixel or renderable Gymnasium env.

    simoun-train --env dm_control/cartpole-swingup-v0 --preset cpu
    simoun-train --preset walker-walk --agent.encoder dual --agent.no-curiosity
    simoun-train --resume runs/cartpole-swingup-cpu-s1-20260101-120000

The command line over the training loop (:mod:`simoun_agent.run.train`, where the run
directory, the stops and the exit statuses are described). A run whose config names
``eval_distraction`` modes gets the distracted evaluation
(:func:`simoun_agent.generalization.distraction_callbacks`) passed to the loop.
"""

from __future__ import annotations

import signal
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import tyro

from simoun_agent.cli.command_flags import PATH
from simoun_agent.cli.config_flags import (
    PRESETS_LIST,
    RECIPES_HELP,
    ConfigFlags,
    config_default,
    config_switches,
    overrides_from,
)
from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import ONE_SEED, RUN_CONFIG_NAMES, Meant
from simoun_agent.config import SetupError, TrainConfig, resolve
from simoun_agent.config.train import RESUMABLE_FIELDS
from simoun_agent.run.layout import CHECKPOINT_NAME

if TYPE_CHECKING:
    from simoun_agent.run.train import Run

PROG = "simoun-train"

DESCRIPTION = f"""Train the Simoun agent (vision-based SAC) on a Gymnasium environment.

{PRESETS_LIST}

{RECIPES_HELP}

examples:
  simoun-train --env dm_control/cartpole-swingup-v0 --preset cpu
  simoun-train --preset cheetah-run --agent.encoder dual --agent.no-curiosity
  simoun-train --preset highway --set agent.batch_size=64
  simoun-train --preset cpu --agent.recipe drq --seed 2
  simoun-train --resume runs/cartpole-swingup-cpu-s1-20260101-120000

Values: booleans as switches (--no-video; --video false works too), None as none, dicts as
JSON (--env-kwargs '{{"a": 1}}')."""


RESUMED = Meant(("--resume",), "give the run directory or its checkpoint.pt: --resume {value}")

OTHER_NAMES = RUN_CONFIG_NAMES | {
    "seed": Meant(note=ONE_SEED),
    "seeds": Meant(("--seed",), ONE_SEED),
    "checkpoint": RESUMED,
    "load-checkpoint": RESUMED,
    "resume-from": RESUMED,
    "load-path": RESUMED,
    "model-path": RESUMED,
    # simoun-eval's flags
    "episodes": Meant(("--eval-episodes",)),
    "distraction": Meant(("--eval-distraction",)),
    "out": Meant(("--run-dir",)),
    "videos": Meant(
        note="simoun-train takes no background videos (its --video records an evaluation video, "
        "and its --eval-distraction video_* modes use a procedural moving background); to "
        "evaluate a trained run on your videos: simoun-eval RUN --distraction video_hard "
        "--videos DIR"
    ),
    "random-policy": Meant(
        note="a run's first --warmup-agent-steps agent steps take uniformly random actions; the "
        "random baseline of a trained run is simoun-eval RUN --random-policy"
    ),
}
"""Other libraries' flags with what simoun-train calls them
(:mod:`simoun_agent.cli.other_names`), simoun-eval's among them; ``seed`` says what to do for
several seeds."""


@dataclass
class TrainCommand:
    """What ``simoun-train`` is asked: a new run (its config flags) or one to resume."""

    resume: Annotated[
        str | None,
        PATH,
        tyro.conf.arg(
            metavar="RUN_DIR",
            help="continue a run (its directory, or its checkpoint.pt) from its last checkpoint "
            "(only "
            f"{', '.join(RESUMABLE_FIELDS)} may be changed)",
        ),
    ] = None
    overwrite: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    """start over in a --run-dir whose run stopped before its first checkpoint (a run with a
    checkpoint is never deleted: --resume it)"""
    flags: Annotated[ConfigFlags, tyro.conf.arg(name="")] = field(default_factory=ConfigFlags)
    """the run config"""


@names_full_disk(
    PROG, "pass --run-dir DIR on another disk (a run resumed: copy it there and --resume the copy)"
)
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simoun-train``."""
    argv = list(sys.argv[1:] if argv is None else argv)
    command = parse_command(argv)
    # torch and the trainer are imported once the flags are read: --help, --version and a bad
    # flag are answered in about a second
    from tqdm import tqdm

    from simoun_agent.generalization import distraction_callbacks
    from simoun_agent.run import train as loop  # called through the module: tests wrap loop.train
    from simoun_agent.run.signals import Stopped, stop_at_once

    try:
        with stop_at_once():  # nothing to save during set-up
            run = setup(command, argv)
    except Stopped as stop:
        print(
            f"simoun-train: stopped by {signal.Signals(stop.signum).name} during set-up, before "
            "anything was trained",
            file=sys.stderr,
        )
        return stop.exit_code
    tqdm.write(f"run directory: {run.run_dir}")
    try:
        with warnings.catch_warnings():  # said once, as a simoun-train warning, in setup
            warnings.simplefilter("ignore", loop.UntrainedRunWarning)
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


def parse_command(argv: Sequence[str]) -> TrainCommand:
    """``argv`` read with tyro over the defaults of the preset it names; bad input exits with
    status 2."""
    try:
        default = TrainCommand(flags=ConfigFlags(config=config_default(argv)))
    except SetupError as err:
        fail(PROG, err)
    from simoun_agent.cli.eval import EvalCommand  # the commands name each other's flags

    return parse(
        TrainCommand,
        argv,
        PROG,
        DESCRIPTION,
        default,
        config_switches(),
        other_names=OTHER_NAMES,
        siblings={"simoun-eval": EvalCommand},
    )


def resumed_dir(given: str) -> Path:
    """The run directory ``--resume`` names: the path given, or the directory of the run's
    checkpoint file when that is given (as ``simoun-eval`` takes either)."""
    path = Path(given)
    if path.name == CHECKPOINT_NAME and path.is_file():
        return path.parent
    return path


def setup(command: TrainCommand, argv: Sequence[str]) -> Run:
    """The run that ``command`` (parsed from ``argv``) asks for, new or resumed; bad input
    exits with status 2."""
    from simoun_agent.generalization import check_eval_distractions
    from simoun_agent.run import train as loop
    from simoun_agent.run.memory import check_memory, threads_warning

    try:
        overrides = overrides_from(command.flags, argv, TrainCommand)
        if command.resume:
            if command.flags.preset:
                raise SetupError("--preset does not combine with --resume: a run keeps its config")
            if command.overwrite:
                raise SetupError("--overwrite starts a run over; it does not combine with --resume")
            run = loop.resume_run(
                resumed_dir(command.resume), overrides, check=check_eval_distractions
            )
            untrained = loop.budget_warning(run.config) if run.counters.updates == 0 else None
            if untrained:  # a longer --total-env-steps given to a resume may clear it
                print(f"{PROG}: warning: {untrained}", file=sys.stderr)
        else:
            config = resolve(command.flags.preset, overrides)
            for warning in (check_memory(config), loop.budget_warning(config)):
                if warning:  # before anything is built
                    print(f"simoun-train: warning: {warning}", file=sys.stderr)
            run = loop.create_run(config, overwrite=command.overwrite, check=check_new_run)
    except SetupError as err:
        fail(PROG, err)
    warning = threads_warning(run.config.torch_threads)
    if warning:
        print(f"{PROG}: warning: {warning}", file=sys.stderr)
    return run


def check_new_run(config: TrainConfig) -> None:
    """The checks of a new run's config before its envs are built: its evaluation distractions,
    and, when it gives ``--env-kwargs``, one env made, reset and stepped with them (an env may
    store a value it cannot use and fail only at its first step)."""
    from simoun_agent.generalization import check_eval_distractions
    from simoun_agent.run.make_env import check_task

    check_eval_distractions(config)
    if config.env_kwargs:
        check_task(config)


if __name__ == "__main__":
    sys.exit(main())
