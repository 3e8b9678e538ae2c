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
from simoun_agent.run.load import LoadedRun, load_run
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
    modes = _check_run_args("evaluate_runs", run_dirs, modes, videos)
    _check_play_args("evaluate_runs", episodes, seed, progress)
    runs = load_runs(run_dirs, modes, device, videos)
    return play_runs(runs, modes, episodes, seed, videos, progress)


def load_runs(
    run_dirs: Sequence[Path],
    modes: Sequence[str],
    device: str | None = None,
    videos: str | Path | None = None,
) -> list[LoadedRun]:
    """Each run of ``run_dirs`` loaded, checked to support each of ``modes``: SetupError for a
    run that cannot be loaded or a mode its env does not support, before anything is played
    or written (``simoun-eval --distraction`` makes its report directory after it)."""
    modes = _check_run_args("load_runs", run_dirs, modes, videos)
    runs = [load_run(run_dir, device) for run_dir in run_dirs]
    for run in runs:
        check_supported(run.config, modes, videos)
    return runs


def play_runs(
    runs: Sequence[LoadedRun],
    modes: Sequence[str],
    episodes: int,
    seed: int | None = None,
    videos: str | Path | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[ModeResult]:
    """Play ``episodes`` episodes of each of ``runs`` (:func:`load_runs`) under each mode, as
    :func:`evaluate_runs` does; closes each run's env."""
    _check_play_args("play_runs", episodes, seed, progress)
    labels = _labels([run.run_dir for run in runs])
    results = []
    for run, label in zip(runs, labels, strict=True):
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


def _check_run_args(function: str, run_dirs: object, modes: object, videos: object) -> list[str]:
    """TypeError or ValueError naming ``function``'s argument for run directories that are
    not a non-empty list of paths, unknown modes, or a videos folder that is no path; the
    modes as a list."""
    if isinstance(run_dirs, (str, os.PathLike)):
        raise TypeError(
            f"{function}(run_dirs=...) takes a list of run directories, got the one path "
            f"{str(run_dirs)!r}; e.g. run_dirs=[{str(run_dirs)!r}]"
        )
    if not isinstance(run_dirs, (list, tuple)) or not run_dirs:
        raise TypeError(
            f"{function}(run_dirs=...) takes a non-empty list of run directories, got "
            f"{type(run_dirs).__name__} {run_dirs!r:.60}; e.g. run_dirs=['runs/my-run']"
        )
    for run_dir in run_dirs:
        check_path(run_dir, f"{function}(run_dirs=[...])", "run_dirs=['runs/my-run']")
    checked = check_mode_list(modes, f"{function}(modes=...)", list(DISTRACTIONS))
    if videos is not None:
        check_path(videos, f"{function}(videos=...)", "videos='dmcgb/videos'")
    return checked


def _check_play_args(function: str, episodes: object, seed: object, progress: object) -> None:
    """TypeError or ValueError naming ``function``'s argument for a count of episodes below 1,
    a negative seed, or a progress that is no function of one str."""
    check_positive_int(episodes, f"{function}(episodes=...)", "e.g. episodes=10")
    if seed is not None:
        check_nonnegative_int(seed, f"{function}(seed=...)", "e.g. seed=0, or None")
    if progress is not None:
        check_callable(
            progress,
            f"{function}(progress=...)",
            "progress(message) before each run and mode",
            ("message",),
            "pass a function of one str, e.g. progress=print, or None",
        )


def _labels(run_dirs: Sequence[Path]) -> list[str]:
    """Directory names, or the paths as given where two runs share a name."""
    names = [path.name for path in run_dirs]
    return [
        name if names.count(name) == 1 else str(path)
        for name, path in zip(names, run_dirs, strict=True)
    ]
