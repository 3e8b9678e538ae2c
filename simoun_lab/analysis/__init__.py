"""The paper's analyses for trained runs: structure masks (Fig. 7) and information bias (Fig. 5).

The command ``simoun-analyze`` (:mod:`simoun_lab.cli.analyze`) runs both; the estimator
(:func:`simoun_lab.analysis.bias.information_bias`) works on any features.
"""

from simoun_lab.analysis.bias import BiasEstimate, information_bias
from simoun_wrappers._homes import missing_name

__all__ = ["BiasEstimate", "information_bias"]


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
