"""The lab's one study engine: a :class:`~simoun_lab.engine.trial.Trial` is what one run offers
(the SAC trainer, :class:`simoun_lab.sweep.trainable.SacTrial`, and the SB3 PPO MiniGrid trainer,
:class:`simoun_lab.minigrid_study.trial.MiniGridTrial`), and
:mod:`~simoun_lab.engine.launcher` runs a list of them on Ray Tune, archiving each finished run's
files and each in-progress checkpoint, and resuming from either.
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
