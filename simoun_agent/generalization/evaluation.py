"""Evaluate trained runs on the distraction suite: one result per run and mode."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from simoun_agent.generalization.suite import (
    DISTRACTIONS,
    check_mode_list,
    check_supported,
    make_distracted_env,
)
from simoun_agent.run.evaluate import evaluate
from simoun_agent.run.load import load_run
from simoun_wrappers._checks import (
    check_callable,
    check_nonnegative_int,
    check_path,
    check_positive_int,
)


@dataclass(frozen=True)
class ModeResult:
    """The evaluation return of one run under one distraction mode."""

    run: str
    """label of the run (its directory name)"""
    env: str
    """Gymnasium id of the run's task"""
    mode: str
    """distraction mode (simoun_agent.generalization.DISTRACTIONS)"""
    return_mean: float
    """mean episode return over the evaluation episodes"""
    return_std: float
    """standard deviation of the episode return over those episodes"""
    episodes: int
    """episodes played"""
    first_seed: int
    """reset seed of the first episode (episode i uses first_seed + i)"""
    env_step: int
    """environment steps the run had trained for at its checkpoint"""


def evaluate_runs(
    run_dirs: Sequence[Path],
    modes: Sequence[str],
    episodes: int,
    seed: int | None = None,
    device: str | None = None,
    videos: str | Path | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[ModeResult]:
    """Play ``episodes`` deterministic episodes of each run under each mode.

    Every mode of a run plays the same reset seeds (``seed``, default the run's evaluation
    seeds), so the modes differ only by the distraction. Raises SetupError for a run that
    cannot be loaded or a mode its env does not support, before any episode is played.
    """
    if isinstance(run_dirs, (str, os.PathLike)):
        raise TypeError(
            f"evaluate_runs(run_dirs=...) takes a list of run directories, got the one path "
            f"{str(run_dirs)!r}; e.g. run_dirs=[{str(run_dirs)!r}]"
        )
    if not isinstance(run_dirs, (list, tuple)) or not run_dirs:
        raise TypeError(
            f"evaluate_runs(run_dirs=...) takes a non-empty list of run directories, got "
            f"{type(run_dirs).__name__} {run_dirs!r:.60}; e.g. run_dirs=['runs/my-run']"
        )
    for run_dir in run_dirs:
        check_path(run_dir, "evaluate_runs(run_dirs=[...])", "run_dirs=['runs/my-run']")
    modes = check_mode_list(modes, "evaluate_runs(modes=...)", list(DISTRACTIONS))
    check_positive_int(episodes, "evaluate_runs(episodes=...)", "e.g. episodes=10")
    if seed is not None:
        check_nonnegative_int(seed, "evaluate_runs(seed=...)", "e.g. seed=0, or None")
    if videos is not None:
        check_path(videos, "evaluate_runs(videos=...)", "videos='dmcgb/videos'")
    if progress is not None:
        check_callable(
            progress,
            "evaluate_runs(progress=...)",
            "progress(message) before each run and mode",
            ("message",),
            "pass a function of one str, e.g. progress=print, or None",
        )
    loaded = [load_run(run_dir, device) for run_dir in run_dirs]
    for run in loaded:
        check_supported(run.config, modes, videos)
    labels = _labels([run.run_dir for run in loaded])
    results = []
    for run, label in zip(loaded, labels, strict=True):
        first_seed = run.first_seed if seed is None else seed
        for mode in modes:
            if progress:
                progress(f"{label}: {mode} ({episodes} episodes)")
            env = run.env if mode == "train" else make_distracted_env(run.config, mode, videos)
            metrics, _ = evaluate(run.agent, env, episodes, first_seed)
            if env is not run.env:
                env.close()
            results.append(
                ModeResult(
                    label,
                    run.config.env,
                    mode,
                    metrics["return_mean"],
                    metrics["return_std"],
                    episodes,
                    first_seed,
                    run.env_step,
                )
            )
        run.env.close()
    return results


def _labels(run_dirs: Sequence[Path]) -> list[str]:
    """Directory names, or the paths as given where two runs share a name."""
    names = [path.name for path in run_dirs]
    return [
        name if names.count(name) == 1 else str(path)
        for name, path in zip(names, run_dirs, strict=True)
    ]
