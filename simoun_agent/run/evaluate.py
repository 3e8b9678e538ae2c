"""Evaluation episodes with deterministic actions, and the ``simoun-eval`` command.

``simoun-eval RUN_DIR_OR_CHECKPOINT`` rebuilds the run's environment and agent from the
checkpoint, plays evaluation episodes and writes ``eval-<step>/metrics.json`` and
``eval-<step>/video.mp4`` next to the checkpoint (or under ``--out``); an earlier evaluation
there is kept unless ``--overwrite``. Ctrl-C or SIGTERM stops it at once (exit 130 or 143)
without leaving a half-written directory.
"""

from __future__ import annotations

import argparse
import json
import math
import shutil
import signal
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from tqdm import tqdm

from simoun_agent.config import SetupError
from simoun_agent.run import driving_metrics
from simoun_agent.run.flags import add_version, bool_argv
from simoun_agent.run.rundir import make_output_dir
from simoun_agent.run.seeds import first_eval_seed
from simoun_agent.run.signals import Stopped, stop_at_once


class EvaluationStopped(Exception):
    """An evaluation abandoned between two steps because its ``stop()`` said so; nothing of it
    is returned, so no partial evaluation is ever logged."""


def evaluate(
    agent: Any,
    env: gym.Env,
    episodes: int,
    seed: int,
    record: bool = False,
    on_episode: Callable[[int, float], None] | None = None,
    stop: Callable[[], bool] | None = None,
) -> tuple[dict[str, float], list[np.ndarray]]:
    """Play ``episodes`` episodes with deterministic actions; episode ``i`` resets with seed
    ``seed + i`` (a run's own: :func:`simoun_agent.run.seeds.first_eval_seed`).

    Leaves every global RNG as it found it, so evaluating does not change what training does
    next (a resumed run stays bit-exact). highway-env runs add the driving measures of
    :mod:`simoun_agent.run.driving_metrics`.

    ``on_episode(index, return)`` is called after each episode (progress reports). ``stop()`` is
    asked before every step: True raises :class:`EvaluationStopped` (a Ctrl-C during training).

    Returns:
        metrics (return_mean/std/min/max, length_mean, and driving measures) and, when
        ``record``, the first episode's frames as the agent saw them.
    """
    driving = driving_metrics.is_driving_env(env)
    returns, lengths, drives, frames = [], [], [], []
    with torch.random.fork_rng():
        for episode in range(episodes):
            obs, _ = env.reset(seed=seed + episode)
            drive = driving_metrics.DrivingEpisode() if driving else None
            if drive:
                drive.start(env)
            if record and episode == 0:
                frames.append(obs["frames"][-1])
            total, length, done = 0.0, 0, False
            while not done:
                if stop is not None and stop():
                    raise EvaluationStopped
                action = agent.act(obs["frames"], deterministic=True)
                obs, reward, terminated, truncated, info = env.step(action)
                total += float(reward)
                length += 1
                done = terminated or truncated
                if drive:
                    drive.step(env, reward, info)
                if record and episode == 0:
                    frames.append(obs["frames"][-1])
            returns.append(total)
            lengths.append(length)
            if on_episode is not None:
                on_episode(episode, total)
            if drive:
                drives.append(drive)
    metrics = {
        "return_mean": float(np.mean(returns)),
        "return_std": float(np.std(returns)),
        "return_min": float(np.min(returns)),
        "return_max": float(np.max(returns)),
        "length_mean": float(np.mean(lengths)),
    }
    if drives:
        metrics.update(driving_metrics.summarize(drives))
    return metrics, frames


class RandomPolicy:
    """Uniform actions in [-1, 1]^action_dim: the baseline a trained agent has to beat.

    It has the agent's ``act`` signature, so :func:`evaluate` plays it on the same episodes
    (``simoun-eval RUN_DIR --random-policy``).
    """

    def __init__(self, action_dim: int, seed: int) -> None:
        self.action_dim = action_dim
        self._rng = np.random.default_rng(seed)

    def act(self, frames: np.ndarray, deterministic: bool = False) -> np.ndarray:
        return self._rng.uniform(-1.0, 1.0, self.action_dim).astype(np.float32)


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


def metrics_json(data: dict[str, Any]) -> str:
    """``data`` as strict JSON: NaN (e.g. the crash speed of a run without crashes) as null."""

    def clean(value: Any) -> Any:
        if isinstance(value, dict):
            return {key: clean(item) for key, item in value.items()}
        return None if isinstance(value, float) and math.isnan(value) else value

    return json.dumps(clean(data), indent=2, allow_nan=False) + "\n"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="simoun-eval",
        description="Evaluate a simoun-train checkpoint: deterministic episodes, metrics and a "
        "video.",
        epilog="example: simoun-eval runs/cartpole-swingup-cpu-s1-20260101-120000 --episodes 10",
    )
    parser.add_argument(
        "checkpoint",
        nargs="+",
        help="a run directory or its checkpoint.pt (several with --distraction)",
    )
    parser.add_argument("--episodes", type=int, default=10, help="episodes to play (default 10)")
    parser.add_argument(
        "--seed", type=int, default=None, help="first episode seed (default: the run's eval seeds)"
    )
    parser.add_argument(
        "--out", default=None, help="output directory (default: <run dir>/eval-<step>)"
    )
    parser.add_argument(
        "--video",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="record the first episode to video.mp4 (default: on)",
    )
    parser.add_argument(
        "--progress",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="show a progress bar, or one line per episode when stderr is not a terminal",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an earlier evaluation in the output directory",
    )
    parser.add_argument(
        "--random-policy",
        action="store_true",
        help="play uniformly random actions on the same episodes instead of the agent "
        "(the baseline; writes to <run dir>/eval-<step>-random)",
    )
    parser.add_argument("--device", default=None, help="torch device (default: cuda if available)")
    parser.add_argument(
        "--torch-threads",
        type=int,
        default=None,
        metavar="INT",
        help="torch intra-op threads (default: the run's torch_threads, else torch's default; "
        "not with --distraction, where each run uses its own)",
    )
    parser.add_argument(
        "--distraction",
        metavar="MODES",
        default=None,
        help="evaluate under distraction modes instead, comma-separated from train, color_easy, "
        "color_hard, video_easy, video_hard (dm_control runs); writes a mean ± std table and a "
        "bar chart to <run dir>/generalization, or <common folder>/generalization for several runs",
    )
    parser.add_argument(
        "--videos",
        metavar="DIR",
        default=None,
        help="with --distraction: a folder of video files (or of DAVIS-style folders of frames) "
        "for the video_* modes (default: a procedural moving background)",
    )
    add_version(parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-eval``."""
    from simoun_agent import SimounAgent
    from simoun_agent.config import from_dict
    from simoun_agent.run.checkpoint import load_checkpoint
    from simoun_agent.run.make_env import make_env, video_fps
    from simoun_agent.run.video import write_video

    parser = build_parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(bool_argv(argv, ("--video", "--progress")))
    if args.episodes < 1:
        parser.error("--episodes must be at least 1")
    if args.seed is not None and not 0 <= args.seed < 2**32:
        parser.error(f"--seed {args.seed}: seeds lie in [0, 2**32); e.g. --seed 0")
    if args.torch_threads is not None and args.torch_threads < 1:
        parser.error(f"--torch-threads {args.torch_threads}: must be at least 1; e.g. 1")
    if args.distraction is not None and args.torch_threads is not None:
        parser.error(
            "--torch-threads goes with one run; with --distraction each run's own "
            "torch_threads (from its config.json) applies: drop --torch-threads"
        )
    if args.distraction is not None:
        from simoun_agent.generalization.cli import evaluate_distractions

        return evaluate_distractions(parser, args)
    if len(args.checkpoint) > 1 or args.videos is not None:
        parser.error(
            "several runs and --videos go with --distraction (e.g. --distraction "
            "train,video_hard); otherwise evaluate one run at a time"
        )
    try:
        payload = load_checkpoint(Path(args.checkpoint[0]))
        saved = payload["config"]
        # The machine may differ from the training one: --device applies before the checks.
        machine = {"device": args.device, "torch_threads": args.torch_threads}
        config = from_dict({**saved, **{k: v for k, v in machine.items() if v is not None}})
        if config.torch_threads:
            # torch's default of one thread per core oversubscribes a shared machine: 3 episodes
            # of a cpu-preset checkpoint took 63 and 47 s with 2 threads, 19 and 31 s with the
            # run's one (simoun-eval RUN --episodes 3 --torch-threads N, 2 busy cores)
            torch.set_num_threads(config.torch_threads)
        env = make_env(config)
        step = payload["state"]["env_step"]
        suffix = "-random" if args.random_policy else ""
        default_out = payload["replay_path"].parent / f"eval-{step}{suffix}"
        out = Path(args.out) if args.out else default_out
        if out.is_dir() and any(out.iterdir()) and not args.overwrite:
            raise SetupError(
                f"{out} holds an earlier evaluation; pass --overwrite to replace it, or --out DIR "
                "to write this one elsewhere"
            )
        created = make_output_dir(out)
        seed = args.seed if args.seed is not None else first_eval_seed(config.seed)
        if args.random_policy:
            agent = RandomPolicy(env.action_space.shape[0], seed)
        else:
            agent = SimounAgent(
                env.observation_space["frames"].shape[1:],
                env.action_space.shape[0],
                config.agent,
                device=config.device,
            )
            agent.load_state_dict(payload["agent"])
    except SetupError as err:
        parser.exit(2, f"simoun-eval: error: {err}\n")
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
    (out / "metrics.json").write_text(text)
    if frames:
        write_video(out / "video.mp4", frames, video_fps(env, config.resolved_action_repeat()))
    env.close()
    print(text, end="")
    print(f"wrote {out}/metrics.json" + (f" and {out}/video.mp4" if args.video else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
