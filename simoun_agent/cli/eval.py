"""``simoun-eval``: evaluate a trained run, deterministic episodes, metrics and a video.

``simoun-eval RUN_DIR_OR_CHECKPOINT`` rebuilds the run's environment and agent from the
checkpoint (:func:`simoun_agent.run.load.load_run`), plays evaluation episodes
(:func:`simoun_agent.run.evaluate.evaluate`) and writes ``eval-<step>/metrics.json`` and
``eval-<step>/video.mp4`` next to the checkpoint (or under ``--out``); an earlier evaluation
there is kept unless ``--overwrite``. ``--distraction MODES`` evaluates one or several runs under
distraction instead (:mod:`simoun_agent.generalization`). Ctrl-C or SIGTERM stops it at once
(exit 130 or 143) without leaving a half-written directory.
"""

from __future__ import annotations

import shutil
import signal
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated

import tyro
from tqdm import tqdm

from simoun_agent.cli.command_flags import PATH
from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import POSITIONAL, RUN_CONFIG_NAMES, Meant
from simoun_agent.config import SetupError
from simoun_agent.config.device import device_problem
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.layout import METRICS_NAME, VIDEO_NAME
from simoun_agent.run.rundir import check_output_dir, make_output_dir
from simoun_agent.run.signals import Stopped, stop_at_once


class EpisodeProgress:
    """Progress of ``simoun-eval``: a bar on a terminal, else one plain line per episode on
    stderr (logs of nohup or cluster jobs do not fill with bar redraws); nothing when off."""

    def __init__(self, episodes: int, enabled: bool) -> None:
        self.episodes = episodes
        self.enabled = enabled
        self.bar = tqdm(total=episodes, unit="episode") if enabled and sys.stderr.isatty() else None

    def episode(self, index: int, episode_return: float) -> None:
        if self.bar is not None:
            self.bar.update(1)
            self.bar.set_postfix(episode_return=f"{episode_return:.1f}")
        elif self.enabled:
            print(
                f"episode {index + 1}/{self.episodes}: return {episode_return:.1f}",
                file=sys.stderr,
                flush=True,
            )

    def __enter__(self) -> EpisodeProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.bar is not None:
            self.bar.close()


PROG = "simoun-eval"

DESCRIPTION = """Evaluate a simoun-train checkpoint: deterministic episodes, metrics and a video.

example: simoun-eval runs/cartpole-swingup-cpu-s1-20260101-120000 --episodes 10"""


OTHER_NAMES = RUN_CONFIG_NAMES | {
    "run-dir": POSITIONAL,
    "log-dir": POSITIONAL,
    "logdir": POSITIONAL,
    "load-path": POSITIONAL,
    "model-path": POSITIONAL,
    "trained-agent": POSITIONAL,
    "n-eval-episodes": Meant(("--episodes",)),
    "num-eval-episodes": Meant(("--episodes",)),
    "resume": POSITIONAL,
    "max-episode-steps": Meant(
        note="simoun-eval plays the run's own episodes, whose step limit is the run's env_kwargs, "
        "chosen when it is trained (simoun-train --env-kwargs '{\"max_episode_steps\": {value}}')"
    ),
    "config": Meant(note="simoun-eval reads the run's own config.json: give the run directory"),
    "distraction": Meant(note="comma-separate the modes, e.g. --distraction train,video_hard"),
    "num-envs": Meant(note="simoun-eval plays its episodes one after another on one env"),
    "deterministic": Meant(
        note="simoun-eval always plays the agent's deterministic action; --random-policy plays "
        "the random baseline"
    ),
}
"""Other libraries' flags with what simoun-eval calls them, the run itself its positional RUN
(:mod:`simoun_agent.cli.other_names`); a run config key's is named as the run's setting."""


@dataclass
class EvalCommand:
    """What ``simoun-eval`` is asked."""

    checkpoint: Annotated[tuple[str, ...], PATH, tyro.conf.Positional, tyro.conf.arg(metavar="RUN")]
    """a run directory or its checkpoint.pt (several with --distraction)"""
    episodes: int = 10
    """episodes to play"""
    seed: int | None = None
    """first episode seed (none: the run's eval seeds)"""
    out: Annotated[str | None, PATH] = None
    """output directory (none: <run dir>/eval-<step>)"""
    video: bool = True
    """record the first episode to video.mp4"""
    progress: bool = True
    """show a progress bar, or one line per episode when stderr is not a terminal"""
    overwrite: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    """replace an earlier evaluation in the output directory"""
    random_policy: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    """play uniformly random actions on the same episodes instead of the agent (the baseline;
    writes to <run dir>/eval-<step>-random)"""
    device: str | None = None
    """torch device (none: cuda if available)"""
    torch_threads: int | None = None
    """torch intra-op threads (none: the run's torch_threads, else torch's default; not with
    --distraction, where each run uses its own)"""
    distraction: Annotated[str | None, tyro.conf.arg(metavar="MODES")] = None
    """evaluate under distraction modes instead, comma-separated from train, color_easy,
    color_hard, video_easy, video_hard (dm_control runs); writes a mean ± std table and a bar
    chart to <run dir>/generalization, or <common folder>/generalization for several runs"""
    videos: Annotated[str | None, PATH, tyro.conf.arg(metavar="DIR")] = None
    """with --distraction: a folder of video files (or of DAVIS-style folders of frames) for the
    video_* modes (none: a procedural moving background)"""


@names_full_disk(PROG, "pass --out DIR on another disk")
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simoun-eval``."""
    args = parse(
        EvalCommand,
        argv,
        PROG,
        DESCRIPTION,
        switches=("--video", "--progress"),
        reads_runs=True,
        other_names=OTHER_NAMES,
        siblings={"simoun-train": train_command()},
    )
    if not args.checkpoint:  # tyro accepts no value for a variable number of them
        fail(PROG, "give the run to evaluate: a run directory or its checkpoint.pt")
    if args.episodes < 1:
        fail(PROG, "--episodes must be at least 1")
    if args.seed is not None and not 0 <= args.seed < 2**32:
        fail(PROG, f"--seed {args.seed}: seeds lie in [0, 2**32); e.g. --seed 0")
    if args.device is not None and (problem := device_problem(args.device)):
        fail(PROG, f"--device {args.device}: {problem}")
    if args.torch_threads is not None and args.torch_threads < 1:
        fail(PROG, f"--torch-threads {args.torch_threads}: must be at least 1; e.g. 1")
    if args.distraction is not None and args.torch_threads is not None:
        fail(
            PROG,
            "--torch-threads goes with one run; with --distraction each run's own "
            "torch_threads (from its config.json) applies: drop --torch-threads",
        )
    if args.distraction is not None:
        return evaluate_distractions(args)
    if len(args.checkpoint) > 1 or args.videos is not None:
        fail(
            PROG,
            "several runs and --videos go with --distraction (e.g. --distraction "
            "train,video_hard); otherwise evaluate one run at a time",
        )
    # torch, the agent and the env are imported once the flags are checked: --help, --version
    # and a bad flag are answered in about a second
    from simoun_agent.run.evaluate import RandomPolicy, evaluate, metrics_json
    from simoun_agent.run.load import load_run
    from simoun_agent.run.make_env import video_fps
    from simoun_agent.run.memory import threads_warning
    from simoun_agent.run.seeds import first_eval_seed
    from simoun_agent.run.video import write_video

    warning = threads_warning(args.torch_threads)
    if warning:
        print(f"{PROG}: warning: {warning}", file=sys.stderr)
    try:
        # The machine may differ from the training one: --device applies before the checks.
        run = load_run(Path(args.checkpoint[0]), args.device, args.torch_threads)
        config, env, step = run.config, run.env, run.env_step
        suffix = "-random" if args.random_policy else ""
        default_out = run.run_dir / f"eval-{step}{suffix}"
        out = Path(args.out) if args.out else default_out
        if out.is_dir() and any(out.iterdir()) and not args.overwrite:
            env.close()
            raise SetupError(
                f"{out} holds an earlier evaluation; pass --overwrite to replace it, or --out DIR "
                "to write this one elsewhere"
            )
        created = make_output_dir(out, files=(METRICS_NAME, VIDEO_NAME))
        seed = args.seed if args.seed is not None else first_eval_seed(config.seed)
        agent = RandomPolicy(env.action_space.shape[0], seed) if args.random_policy else run.agent
    except SetupError as err:
        fail(PROG, err)
    try:
        with stop_at_once(), EpisodeProgress(args.episodes, args.progress) as progress:
            metrics, frames = evaluate(
                agent, env, args.episodes, seed, record=args.video, on_episode=progress.episode
            )
    except Stopped as stop:
        env.close()
        if created:
            shutil.rmtree(out, ignore_errors=True)
        print(f"simoun-eval: stopped by {signal.Signals(stop.signum).name}", file=sys.stderr)
        return stop.exit_code
    metrics.update(
        env_step=step, episodes=args.episodes, first_seed=seed, random_policy=args.random_policy
    )
    text = metrics_json(metrics)
    atomic_write(out / METRICS_NAME, lambda tmp: tmp.write_text(text))
    if frames:
        write_video(out / VIDEO_NAME, frames, video_fps(env, config.resolved_action_repeat()))
    env.close()
    print(text, end="")
    print(f"wrote {out}/{METRICS_NAME}" + (f" and {out}/{VIDEO_NAME}" if args.video else ""))
    return 0


def train_command() -> type:
    """simoun-train's command, whose flags an unknown flag of simoun-eval is named as (imported
    here: the two commands name each other's flags)."""
    from simoun_agent.cli.train import TrainCommand

    return TrainCommand


def evaluate_distractions(args: EvalCommand) -> int:
    """Evaluate ``args.checkpoint`` (one or several runs) on ``args.distraction``'s modes and
    write the table, CSV and bar chart; bad input exits with status 2, without traceback."""
    if args.random_policy:
        fail(PROG, "--random-policy does not combine with --distraction")
    from simoun_agent.generalization.evaluation import load_runs, play_runs
    from simoun_agent.generalization.report import (
        REPORT_FILES,
        TABLE_CSV,
        default_out,
        write_report,
    )
    from simoun_agent.generalization.suite import parse_distractions

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
        check_output_dir(out, "--out", REPORT_FILES)
        with stop_at_once():
            # every run and mode is refused or taken before the report directory is made
            runs = load_runs(run_dirs, modes, device=args.device, videos=args.videos)
            created = make_output_dir(out, files=REPORT_FILES)
            results = play_runs(
                runs,
                modes,
                args.episodes,
                seed=args.seed,
                videos=args.videos,
                progress=_status if args.progress else None,
            )
    except SetupError as err:
        if created:
            shutil.rmtree(out, ignore_errors=True)
        fail(PROG, err)
    except Stopped as stop:
        if created:
            shutil.rmtree(out, ignore_errors=True)
        print(f"{PROG}: stopped by {signal.Signals(stop.signum).name}", file=sys.stderr)
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


if __name__ == "__main__":
    sys.exit(main())
