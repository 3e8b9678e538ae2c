"""Every random stream of a run, derived from its one seed (``TrainConfig.seed``).

``numpy.random.SeedSequence(seed)`` has one child per :class:`Stream` (child ``i`` is
``SeedSequence(seed).spawn(...)[i]``, addressed directly as ``spawn_key=(i,)``), so the streams
of one run are independent of each other and of every other seed's. Episode reset seeds are
blocks of consecutive integers whose start each run draws from its stream:

- training episode ``i`` resets with ``(T + i) mod 2**31``, in ``[0, 2**31)``;
- evaluation episode ``i`` resets with ``2**31 + E + i``, in ``[2**31, 2**32)`` (numpy's seed
  range ends there, and dm_control's ``RandomState`` needs it).

So no training start is ever an evaluation start, of this run or any other, and every evaluation
of a run plays the same episodes (comparable curves). Two runs share a start only when their
blocks overlap, which is a chance of (n1 + n2) / 2**31 for blocks of n1 and n2 episodes: 1e-6
for two runs of 1000 training episodes. (The scheme before it, ``seed + i`` and
``seed + 1,000,000 + i``, gave seeds 1 and 2 all but one of the same starts.)

    >>> first_eval_seed(1) != first_eval_seed(2)
    True
    >>> train_episode_seed(1, 0) < 2**31 <= first_eval_seed(1) < 2**32
    True
"""

from __future__ import annotations

import enum

import numpy as np

SEED_SCHEME = "seedsequence/1"
"""Saved in every checkpoint: the name of this scheme, so a run started under another one is
recognised instead of silently switching episodes halfway."""

HALF = 2**31
"""Training seeds lie below, evaluation seeds at or above."""
EVAL_EPISODES_MAX = 2**20
"""Evaluation blocks start low enough in their half that this many episodes stay below 2**32."""


class Stream(enum.IntEnum):
    """The children of a run's ``SeedSequence``, one per consumer. Append new streams: an
    existing index must keep meaning the same stream, or old runs' seeds would change."""

    TRAIN_EPISODES = 0
    """reset seeds of the training episodes"""
    EVAL_EPISODES = 1
    """reset seeds of the evaluation episodes"""
    REPLAY = 2
    """the replay's sampling of batches"""
    WARMUP_ACTIONS = 3
    """the uniformly random actions before learning starts"""
    NETWORK_INIT = 4
    """torch's generator while the networks are built (initial weights)"""
    TORCH = 5
    """torch's generator from then on (augmentation, SAC's sampling noise)"""
    GLOBAL = 6
    """python's ``random`` and numpy's global generator (for libraries that draw from them)"""
    ACTION_SPACES = 7
    """the environments' ``action_space.sample()``"""


def stream(seed: int, which: Stream) -> np.random.SeedSequence:
    """The ``which`` child of ``SeedSequence(seed)``; ``np.random.default_rng`` takes it."""
    return np.random.SeedSequence(seed, spawn_key=(int(which),))


def int_seed(seed: int, which: Stream) -> int:
    """A 32-bit seed from the ``which`` stream, for APIs that take an int (``torch.manual_seed``,
    ``random.seed``, ``np.random.seed``, ``Space.seed``)."""
    return int(stream(seed, which).generate_state(1, np.uint32)[0])


def train_episode_seed(seed: int, episode: int) -> int:
    """Reset seed of training episode ``episode`` (0, 1, ...) of the run with seed ``seed``."""
    return (int_seed(seed, Stream.TRAIN_EPISODES) + episode) % HALF


def first_eval_seed(seed: int) -> int:
    """Reset seed of evaluation episode 0; episode ``i`` uses this + ``i``, at every
    evaluation."""
    return HALF + int_seed(seed, Stream.EVAL_EPISODES) % (HALF - EVAL_EPISODES_MAX)
