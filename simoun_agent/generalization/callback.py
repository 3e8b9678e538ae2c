"""Test curves during training: evaluate on distraction modes at every evaluation (DMC-GB)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import gymnasium as gym

from simoun_agent.config import TrainConfig
from simoun_agent.generalization.suite import (
    DISTRACTIONS,
    check_eval_distractions,
    check_mode_list,
    check_run_config,
    make_distracted_env,
)
from simoun_agent.run.callback import TrainCallback
from simoun_agent.run.evaluate import evaluate
from simoun_agent.run.seeds import first_eval_seed
from simoun_agent.run.state import Run
from simoun_wrappers._checks import check_path


class DistractionEvaluation(TrainCallback):
    """At each evaluation, also play the evaluation episodes under each distraction mode.

    Adds ``<mode>/return_mean`` and ``<mode>/return_std`` to the evaluation's metrics, which go
    to eval.csv, TensorBoard and the learning curve beside the training env's return. The
    episodes use the run's evaluation seeds, so every mode sees the same starts as the training
    env; the distracted envs are built when training starts and closed when it ends, however it
    ends (a signal, an error).

    Args:
        modes: distraction modes (``simoun_agent.generalization.DISTRACTIONS``, not ``train``).
        videos: a folder of video files for the ``video_*`` modes; None for procedural ones.
    """

    serves = ("eval_distraction",)

    def __init__(self, modes: Sequence[str], videos: str | Path | None = None) -> None:
        distracted = [name for name, entry in DISTRACTIONS.items() if entry is not None]
        self.modes = check_mode_list(modes, "DistractionEvaluation(modes=...)", distracted)
        if videos is not None:
            check_path(videos, "DistractionEvaluation(videos=...)", "videos='dmcgb/videos'")
        self.videos = videos
        self._envs: dict[str, gym.Env] = {}

    def on_start(self, run: Run) -> None:
        for mode in self.modes:
            self._envs[mode] = make_distracted_env(run.config, mode, self.videos)

    def on_evaluation(self, run: Run, metrics: dict[str, float]) -> None:
        config = run.config
        for mode, env in self._envs.items():
            episodes, first = config.eval_episodes, first_eval_seed(config.seed)
            result, _ = evaluate(run.agent, env, episodes, first, stop=run.stop.is_set)
            metrics[f"{mode}/return_mean"] = result["return_mean"]
            metrics[f"{mode}/return_std"] = result["return_std"]

    def on_end(self, run: Run, metrics: dict[str, float] | None) -> None:
        self.close()

    def close(self) -> None:
        """Close the distracted envs."""
        for env in self._envs.values():
            env.close()
        self._envs.clear()


def distraction_callbacks(config: TrainConfig) -> list[TrainCallback]:
    """What a run of ``config`` passes to the loop for its ``eval_distraction`` modes: one
    :class:`DistractionEvaluation`, or nothing when it names none. Raises SetupError for a bad
    mode (:func:`~simoun_agent.generalization.suite.check_eval_distractions`)."""
    check_run_config(config, "distraction_callbacks")
    modes = check_eval_distractions(config)
    return [DistractionEvaluation(modes)] if modes else []
