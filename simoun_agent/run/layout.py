"""The run directory's layout: every file name a run writes, defined once.

A run directory holds ``config.json`` (the resolved config, written once set-up has
succeeded), ``eval.csv`` / ``train.csv`` / ``tb/`` (logs), ``learning_curve.png``,
``checkpoint.pt`` + ``replay-<step>.npz`` (the latest checkpoint), ``video.mp4`` and
``summary.json`` (written only when the run ends); ``.lock`` names the trainer that holds it.
``simoun-eval`` writes ``eval-<step>/metrics.json`` and ``video.mp4`` beside the checkpoint.
"""

from __future__ import annotations

CONFIG_NAME = "config.json"
SUMMARY_NAME = "summary.json"
CHECKPOINT_NAME = "checkpoint.pt"
REPLAY_GLOB = "replay-*.npz"
"""the replay files of checkpoints: ``replay-<env step>.npz``"""
EVAL_CSV = "eval.csv"
TRAIN_CSV = "train.csv"
TENSORBOARD_DIR = "tb"
CURVE_PNG = "learning_curve.png"
VIDEO_NAME = "video.mp4"
LOCK_NAME = ".lock"
METRICS_NAME = "metrics.json"
"""an evaluation's metrics, in ``eval-<step>/`` (``simoun-eval``)"""
TRAINER_FILES = (CONFIG_NAME, EVAL_CSV, TRAIN_CSV, CURVE_PNG, VIDEO_NAME)
"""What a run writes before its first checkpoint (with ``tb/``): removed by ``--overwrite``."""


def replay_name(env_step: int) -> str:
    """The replay file of the checkpoint at ``env_step``."""
    return f"replay-{env_step}.npz"
