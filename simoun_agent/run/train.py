"""``simoun-train``: train the Simoun agent on any pixel or renderable Gymnasium env.

    simoun-train --env dm_control/cartpole-swingup-v0 --preset cpu
    simoun-train --preset walker-walk --agent.encoder dual --agent.curiosity false
    simoun-train --resume runs/cartpole-swingup-cpu-s1-20260101-120000

A run directory holds ``config.json`` (the resolved config, written once set-up has
succeeded), ``eval.csv`` / ``train.csv`` / ``tb/`` (logs), ``learning_curve.png`` (redrawn at
each evaluation), ``checkpoint.pt`` + ``replay-<step>.npz`` (the latest checkpoint),
``video.mp4`` (an evaluation episode) and ``summary.json`` (written only when the run ends).

Ctrl-C or SIGTERM (a scheduler's preemption, ``kill``) finishes the current step, writes a
checkpoint atomically, prints how to resume and exits with status **130** after Ctrl-C or
**143** after SIGTERM (128 + the signal number); a second signal stops at once
(:mod:`simoun_agent.run.signals`). ``--resume`` continues. One trainer at a time holds a run
directory (:mod:`simoun_agent.run.rundir`); ``--overwrite`` starts over a run that stopped before
its first checkpoint.
"""

from __future__ import annotations

import argparse
import json
import random
import signal
import sys
import time
import typing
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import IO, Any

import gymnasium as gym
import numpy as np
import torch
from tqdm import tqdm

from simoun_agent import SimounAgent
from simoun_agent.generalization.suite import check_eval_distractions
from simoun_agent.recipes import RECIPES
from simoun_agent.replay import FrameReplay
from simoun_agent.run.checkpoint import (
    atomic_write,
    check_config,
    load_checkpoint,
    restore_rng,
    save_checkpoint,
)
from simoun_agent.run.env_runner import EnvRunner, make_runner
from simoun_agent.run.evaluate import EVAL_SEED_OFFSET, evaluate, metrics_json
from simoun_agent.run.flags import add_version
from simoun_agent.run.logger import CURVE_PNG, RunLogger
from simoun_agent.run.make_env import make_env, video_fps
from simoun_agent.run.memory import check_memory
from simoun_agent.run.presets import (
    PRESETS,
    RESUMABLE_FIELDS,
    SetupError,
    TrainConfig,
    check_keys,
    config_fields,
    dmc_task,
    from_dict,
    parse_value,
    resolve,
    to_dict,
)
from simoun_agent.run.rundir import make_output_dir, take_run_dir
from simoun_agent.run.signals import Stopped, deferred_stop
from simoun_agent.run.video import write_video

CONFIG_NAME = "config.json"
SUMMARY_NAME = "summary.json"


@dataclass
class Counters:
    """Where a run stands; saved in every checkpoint."""

    env_step: int = 0
    """environment steps taken (agent decisions x action repeat)"""
    agent_step: int = 0
    """agent decisions taken"""
    episode: int = 0
    """training episodes begun; episode i resets with seed config.seed + i"""
    updates: int = 0
    """gradient updates done"""
    wall_time_s: float = field(default=0.0, compare=False)
    """seconds spent in the training loop, summed over resumed parts (evaluations included)"""


@dataclass
class Run:
    """A run ready to train: its config, directory, environments, agent and replay."""

    config: TrainConfig
    run_dir: Path
    env: EnvRunner
    """the training environment, stepped in this process or a background one"""
    eval_env: gym.Env
    agent: SimounAgent
    replay: FrameReplay
    rng: np.random.Generator
    """the trainer's own generator (random warm-up actions)"""
    counters: Counters
    lock: IO[str] | None = None
    """the run directory's lock (:func:`~simoun_agent.run.rundir.lock_run_dir`), held while
    this process uses it"""


class TrainCallback:
    """Hooks into :func:`train`; subclass and override what you need (all do nothing here).

    Ray Tune's reporter (``simoun_agent.sweep``) and extra evaluation environments plug in here
    instead of editing the loop.
    """

    def on_evaluation(self, run: Run, metrics: dict[str, float]) -> None:
        """After each evaluation (env step ``run.counters.env_step``), before it is logged; may
        add entries to ``metrics``, which then go to eval.csv and TensorBoard too."""

    def on_logged(self, run: Run, metrics: dict[str, float]) -> None:
        """After each evaluation has been logged (``metrics`` as written to eval.csv)."""

    def on_end(self, run: Run, metrics: dict[str, float]) -> None:
        """Once, after the final evaluation, checkpoint, video and summary.json."""

    def stop_requested(self, run: Run) -> int | None:
        """Polled after every step: a signal number stops the run as if that signal had
        arrived (checkpoint, then :class:`Stopped`); None goes on. For supervisors that cannot
        signal the loop's thread, such as a Ray Tune trial."""
        return None


def default_run_dir(config: TrainConfig) -> Path:
    """``runs/<task>-<preset>-s<seed>-<UTC time>``, e.g. ``runs/cartpole-swingup-cpu-s1-...``."""
    task = dmc_task(config.env) or config.env.replace("/", "-")
    stamp = datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    return Path("runs") / f"{task}-{config.preset or 'default'}-s{config.seed}-{stamp}"


def build(config: TrainConfig) -> tuple[EnvRunner, gym.Env, SimounAgent, FrameReplay]:
    """The training env's runner (in this process or a background one), the evaluation env,
    the agent and an empty replay; seeds python, numpy and torch first."""
    if config.torch_threads:
        torch.set_num_threads(config.torch_threads)
    random.seed(config.seed)
    np.random.seed(config.seed)  # noqa: NPY002  (for libraries that draw from it)
    torch.manual_seed(config.seed)
    check_eval_distractions(config)
    env, eval_env = make_runner(config), make_env(config)
    frame_shape = env.observation_space["frames"].shape[1:]
    action_dim = env.action_space.shape[0]
    agent = SimounAgent(frame_shape, action_dim, config.agent, device=config.device)
    replay = FrameReplay(
        config.replay_capacity,
        frame_shape,
        action_dim,
        num_frames=config.agent.num_frames,
        seed=config.seed,
    )
    return env, eval_env, agent, replay


def create_run(config: TrainConfig, overwrite: bool = False) -> Run:
    """Set up a new run; the run directory gets ``config.json`` only once all of it worked.

    ``overwrite`` starts over in a directory whose run stopped before its first checkpoint.
    """
    run_dir = Path(config.run_dir) if config.run_dir else default_run_dir(config)
    if run_dir.is_dir():  # fail fast, before the envs are built: another trainer, an old run
        take_run_dir(run_dir, overwrite=overwrite).close()
    env, eval_env, agent, replay = build(config)
    make_output_dir(run_dir, "--run-dir")
    lock = take_run_dir(run_dir, overwrite=overwrite)
    config.run_dir = str(run_dir)
    write_config(run_dir, config)
    rng = np.random.default_rng(config.seed)
    return Run(config, run_dir, env, eval_env, agent, replay, rng, Counters(), lock)


def write_config(run_dir: Path, config: TrainConfig) -> None:
    text = json.dumps(to_dict(config), indent=2) + "\n"
    atomic_write(run_dir / CONFIG_NAME, lambda tmp: tmp.write_text(text))


def resume_run(run_dir: Path, overrides: dict[str, Any]) -> Run:
    """Reload a run from its directory; ``overrides`` may only change resumable fields."""
    config_path = run_dir / CONFIG_NAME
    if not config_path.is_file():
        raise SetupError(
            f"{run_dir} is not a simoun run directory (no {CONFIG_NAME}); pass the directory "
            "that simoun-train created"
        )
    try:
        saved = json.loads(config_path.read_text())
    except json.JSONDecodeError as err:
        raise SetupError(f"{config_path} is corrupt ({err}); start a new run") from None
    fixed = {k: v for k, v in overrides.items() if k not in RESUMABLE_FIELDS}
    if fixed:
        raise SetupError(
            f"a resumed run keeps its config; only {', '.join(RESUMABLE_FIELDS)} may change, "
            f"but {', '.join(fixed)} was given. Start a new run to change it."
        )
    config = from_dict(saved)
    for key, value in overrides.items():
        setattr(config, key, value)
    config.run_dir = str(run_dir)
    take_run_dir(run_dir, resume=True).close()  # fail fast; held from the end of set-up on
    payload = load_checkpoint(run_dir)
    check_config(payload, to_dict(config), run_dir)
    done = payload["state"]["env_step"]
    if config.total_env_steps <= done:
        finished = " and is finished" if (run_dir / SUMMARY_NAME).exists() else ""
        raise SetupError(
            f"--total-env-steps {config.total_env_steps}: this run is at env step {done}"
            f"{finished}, so there is nothing to continue; pass a larger --total-env-steps "
            f"(e.g. --total-env-steps {done + config.eval_every}) to train it further"
        )
    if not payload["replay_path"].is_file():
        raise SetupError(
            f"{payload['replay_path']} (the replay of the checkpoint) is missing; the run cannot "
            "continue exactly. Start a new run."
        )
    env, eval_env, agent, _ = build(config)
    try:
        agent.load_state_dict(payload["agent"])
        replay = FrameReplay.load(payload["replay_path"])
    except (RuntimeError, KeyError, ValueError, OSError) as err:
        raise SetupError(
            f"the checkpoint in {run_dir} does not fit this agent ({type(err).__name__}: "
            f"{err}); start a new run"
        ) from None
    restore_rng(payload["rng"])
    rng = np.random.default_rng()
    rng.bit_generator.state = payload["state"]["trainer_rng"]
    counters = Counters(**payload["state"]["counters"])
    lock = take_run_dir(run_dir, resume=True)
    write_config(run_dir, config)
    return Run(config, run_dir, env, eval_env, agent, replay, rng, counters, lock)


def checkpoint(run: Run) -> None:
    state = {
        "env_step": run.counters.env_step,
        "counters": asdict(run.counters),
        "trainer_rng": run.rng.bit_generator.state,
    }
    save_checkpoint(
        run.run_dir,
        config=to_dict(run.config),
        agent=run.agent,
        replay=run.replay,
        state=state,
    )


class StatusLines(TrainCallback):
    """One plain line per evaluation on stderr, instead of the progress bar when stderr is not a
    terminal (nohup, cluster jobs, CI): logs get a line per evaluation, not bar redraws."""

    def __init__(self, run: Run) -> None:
        self.start_step = run.counters.env_step
        self.start = time.perf_counter()

    def on_logged(self, run: Run, metrics: dict[str, float]) -> None:
        step, total = run.counters.env_step, run.config.total_env_steps
        elapsed = time.perf_counter() - self.start
        rate = (step - self.start_step) / elapsed if elapsed > 0 else 0.0
        eta = f", ETA {_duration((total - step) / rate)}" if rate > 0 and step < total else ""
        print(
            f"env step {step}/{total}: eval return {metrics['return_mean']:.1f} +- "
            f"{metrics['return_std']:.1f}, {rate:.1f} env steps/s, {_duration(elapsed)} "
            f"elapsed{eta}",
            file=sys.stderr,
            flush=True,
        )


def _duration(seconds: float) -> str:
    minutes, secs = divmod(int(seconds), 60)
    return f"{minutes // 60}:{minutes % 60:02d}:{secs:02d}"


def evaluate_and_log(
    run: Run, logger: RunLogger, callbacks: Sequence[TrainCallback], clock: WallClock
) -> dict[str, float]:
    """Evaluate the agent, let the callbacks see (and extend) the metrics, log them."""
    config = run.config
    metrics, _ = evaluate(
        run.agent, run.eval_env, config.eval_episodes, config.seed + EVAL_SEED_OFFSET
    )
    for callback in callbacks:
        callback.on_evaluation(run, metrics)
    run.counters.wall_time_s = clock.total()
    metrics["wall_time_s"] = run.counters.wall_time_s
    logger.evaluation(run.counters.env_step, metrics)
    for callback in callbacks:
        callback.on_logged(run, metrics)
    return metrics


class WallClock:
    """Seconds of training-loop time, continuing from what a resumed run had already spent."""

    def __init__(self, already: float) -> None:
        self.already = already
        self.start = time.perf_counter()

    def total(self) -> float:
        return self.already + time.perf_counter() - self.start


def train(run: Run, callbacks: Sequence[TrainCallback] = ()) -> dict[str, Any]:
    """The training loop; returns the final evaluation metrics (None if interrupted first)."""
    config, counters, agent, replay, env = run.config, run.counters, run.agent, run.replay, run.env
    if config.eval_distraction:
        # Imported here: the callback's module builds on this one's TrainCallback.
        from simoun_agent.generalization.callback import DistractionEvaluation

        callbacks = [DistractionEvaluation(config.eval_distraction), *callbacks]
    clock = WallClock(counters.wall_time_s)
    repeat = config.resolved_action_repeat()
    action_dim = env.action_space.shape[0]
    learning_starts = max(config.warmup_agent_steps, config.agent.batch_size)
    title = f"{config.env} ({config.preset or 'default'} preset, seed {config.seed})"
    logger = RunLogger(run.run_dir, title, resume_step=counters.env_step or None)
    next_eval = _next(counters, config.eval_every)
    next_checkpoint = _next(counters, config.checkpoint_every)
    last_eval: dict[str, float] | None = None
    show_bar = config.progress and sys.stderr.isatty()
    if config.progress and not show_bar:
        callbacks = [*callbacks, StatusLines(run)]
    if counters.env_step == 0:
        last_eval = evaluate_and_log(run, logger, callbacks, clock)
    update_metrics: dict[str, Any] = {}

    obs = None  # an episode starts at the top of the loop, so checkpoints fall between episodes
    bar = tqdm(
        total=config.total_env_steps,
        initial=counters.env_step,
        unit="step",
        desc=title.split(" ")[0],
        dynamic_ncols=True,
        disable=not show_bar,
    )
    # Entered after the envs were built, so a library that took the signals then (SDL) is found
    with deferred_stop() as interrupt:
        while counters.env_step < config.total_env_steps and not interrupt.is_set():
            if obs is None:
                obs = env.reset(seed=config.seed + counters.episode)
                replay.start_episode(obs["frames"][-1])
                episode_return, episode_length, episode_start = 0.0, 0, time.perf_counter()
            if counters.agent_step < config.warmup_agent_steps:
                action = run.rng.uniform(-1.0, 1.0, action_dim).astype(np.float32)
            else:
                action = agent.act(obs["frames"], step=counters.env_step)
            # the environment steps (in a background process with env_process) while the agent
            # updates on the transitions before this one; both runners give the same results
            env.step_async(action)
            if counters.agent_step >= learning_starts:
                for _ in range(config.updates_per_step):
                    # Actor metrics come every actor_update_every updates: keep the latest of each.
                    update_metrics.update(agent.update(replay, counters.env_step + repeat))
                    counters.updates += 1
            obs, reward, terminated, truncated = env.step_wait()
            replay.add(action, reward, obs["frames"][-1], terminated, truncated)
            counters.agent_step += 1
            counters.env_step += repeat
            episode_return += float(reward)
            episode_length += 1
            bar.update(repeat)
            for callback in callbacks:
                asked = callback.stop_requested(run)
                if asked is not None and not interrupt.is_set():
                    interrupt.signum = asked

            if not (terminated or truncated):
                continue
            elapsed = time.perf_counter() - episode_start
            logger.train_episode(
                counters.env_step,
                {
                    "episode": counters.episode,
                    "return": episode_return,
                    "length": episode_length,
                    "env_steps_per_s": episode_length * repeat / elapsed,
                    **{key: float(value) for key, value in update_metrics.items()},
                },
            )
            counters.episode += 1
            if counters.env_step >= next_eval:
                last_eval = evaluate_and_log(run, logger, callbacks, clock)
                next_eval = _next(counters, config.eval_every)
            if counters.env_step >= next_checkpoint:
                counters.wall_time_s = clock.total()
                checkpoint(run)
                next_checkpoint = _next(counters, config.checkpoint_every)
            bar.set_postfix(episode_return=f"{episode_return:.1f}", **_eval_postfix(last_eval))
            obs = None
        bar.close()

        if interrupt.is_set():
            counters.wall_time_s = clock.total()
            checkpoint(run)
            logger.close()
            release(run)
            tqdm.write(
                f"stopped by {signal.Signals(interrupt.signum).name} at env step "
                f"{counters.env_step}: checkpoint written; continue with: simoun-train --resume "
                f"{run.run_dir}"
            )
            raise Stopped(interrupt.signum)
        return finish(run, logger, last_eval, callbacks, clock)


def finish(
    run: Run,
    logger: RunLogger,
    last_eval: dict[str, float] | None,
    callbacks: Sequence[TrainCallback],
    clock: WallClock,
) -> dict[str, Any]:
    """Final evaluation (with video), checkpoint and ``summary.json``, the mark of a whole run."""
    config, counters = run.config, run.counters
    eval_seed = config.seed + EVAL_SEED_OFFSET
    logged = logger.last_eval_step == counters.env_step and last_eval is not None
    if not logged:
        last_eval = evaluate_and_log(run, logger, callbacks, clock)
    counters.wall_time_s = clock.total()
    checkpoint(run)
    logger.close()
    files = {"learning_curve": CURVE_PNG, "checkpoint": "checkpoint.pt"}
    if config.video:
        _, frames = evaluate(run.agent, run.eval_env, 1, eval_seed, record=True)
        fps = video_fps(run.eval_env, config.resolved_action_repeat())
        write_video(run.run_dir / "video.mp4", frames, fps)
        files["video"] = "video.mp4"
    summary = {
        "env_step": counters.env_step,
        "wall_time_s": counters.wall_time_s,
        "final_eval": last_eval,
        "files": files,
    }
    text = metrics_json(summary)
    atomic_write(run.run_dir / SUMMARY_NAME, lambda tmp: tmp.write_text(text))
    release(run)
    for callback in callbacks:
        callback.on_end(run, last_eval)
    return last_eval


def release(run: Run) -> None:
    """Let go of the run directory (the lock), once the run has written what it writes."""
    if run.lock is not None:
        run.lock.close()
        run.lock = None


def _next(counters: Counters, every: int) -> int:
    return (counters.env_step // every + 1) * every


def _eval_postfix(metrics: dict[str, float] | None) -> dict[str, str]:
    return {} if metrics is None else {"eval_return": f"{metrics['return_mean']:.1f}"}


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


def add_config_arguments(parser: argparse.ArgumentParser) -> None:
    """``--preset``, ``--set KEY=VALUE`` and one flag per config key (read by
    :func:`overrides_from`); shared by ``simoun-train`` and ``simoun-sweep``."""
    parser.add_argument("--preset", choices=list(PRESETS), help="start from a named preset")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a config key, e.g. --set agent.lr=3e-4 (repeatable; like the flags below)",
    )
    group = parser.add_argument_group(
        "config keys (defaults before any preset; each is also KEY for --set)"
    )
    for key, (kind, default, doc) in config_fields().items():
        if key == "preset":
            continue
        shown = json.dumps(default) if isinstance(default, dict) else repr(default)
        flag = "--" + key.replace("_", "-")
        switch = kind is bool
        hint = f"; --no-{flag[2:]} for false" if switch else ""
        group.add_argument(
            flag,
            dest=key,
            # A tuple key's flag is repeatable: --eval-distraction video_hard --eval-distraction ...
            action="append" if (typing.get_origin(kind) or kind) is tuple else "store",
            default=argparse.SUPPRESS,
            metavar=_metavar(kind),
            # a switch: --progress alone means true, and --progress false still works
            **({"nargs": "?", "const": "true"} if switch else {}),
            help=f"{doc} (default: {shown}{hint})".replace("%", "%%"),
        )
        if switch:
            group.add_argument(
                f"--no-{flag[2:]}",
                dest=key,
                action="store_const",
                const="false",
                default=argparse.SUPPRESS,
                help=argparse.SUPPRESS,
            )


def _metavar(kind: Any) -> str:
    names = {int: "INT", float: "FLOAT", str: "STR", bool: "BOOL", dict: "JSON"}
    skipped = (type(None), Ellipsis)  # Ellipsis: tuple[str, ...] shows as STR
    options = [option for option in typing.get_args(kind) or (kind,) if option not in skipped]
    return "|".join(names.get(typing.get_origin(o) or o, "VALUE") for o in options)


def overrides_from(args: argparse.Namespace) -> dict[str, Any]:
    """``{"agent.lr": 3e-4, ...}`` from the config flags and ``--set`` pairs, typed."""
    fields = config_fields()
    given = {k: v for k, v in vars(args).items() if k in fields and k != "preset"}
    for pair in args.set:
        key, sep, value = pair.partition("=")
        key = key.replace("-", "_")  # the flag's spelling: --set agent.batch-size=64
        if not sep:
            raise SetupError(f"--set takes KEY=VALUE, got {pair!r}; e.g. --set agent.lr=3e-4")
        check_keys([key])  # an unknown key fails here, with its close matches
        given[key] = value
    given = {key: ",".join(v) if isinstance(v, list) else v for key, v in given.items()}
    return {key: parse_value(key, value, fields[key][0]) for key, value in given.items()}


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-train``."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        overrides = overrides_from(args)
        if args.resume:
            if args.preset:
                raise SetupError("--preset does not combine with --resume: a run keeps its config")
            if args.overwrite:
                raise SetupError("--overwrite starts a run over; it does not combine with --resume")
            run = resume_run(Path(args.resume), overrides)
        else:
            config = resolve(args.preset, overrides)
            warning = check_memory(config)  # before anything is built
            if warning:
                print(f"simoun-train: warning: {warning}", file=sys.stderr)
            run = create_run(config, overwrite=args.overwrite)
    except SetupError as err:
        parser.exit(2, f"simoun-train: error: {err}\n")
    tqdm.write(f"run directory: {run.run_dir}")
    try:
        final = train(run)
    except KeyboardInterrupt as stop:  # Stopped after a checkpoint, or a second Ctrl-C
        return getattr(stop, "exit_code", 130)
    finally:
        run.env.close()
        run.eval_env.close()
        release(run)
    tqdm.write(
        f"done: evaluation return {final['return_mean']:.1f} +- {final['return_std']:.1f} after "
        f"{run.counters.env_step} env steps; learning curve, logs, checkpoint"
        f"{' and video' if run.config.video else ''} in {run.run_dir}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
