"""Gymnasium and PettingZoo wrappers for the Simoun method."""

from simoun_wrappers import _headless  # noqa: F401  (must run before dm_control/pygame load)
from simoun_wrappers.action_repeat import ActionRepeat
from simoun_wrappers.augment import RandomConvolution, random_conv
from simoun_wrappers.cameras import MultiCamera
from simoun_wrappers.curiosity import FeatureSource
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)
from simoun_wrappers.distractors import ColorShift, MovingBackground
from simoun_wrappers.frames import FrameTriplet
from simoun_wrappers.motion import ResidualMotion, residual_motion
from simoun_wrappers.observation import SimounObservation

__all__ = [
    "ActionRepeat",
    "ColorShift",
    "ConsistencyCuriosityReward",
    "ConsistencyCuriosityVectorReward",
    "FeatureSource",
    "FrameTriplet",
    "MovingBackground",
    "MultiCamera",
    "RandomConvolution",
    "ResidualMotion",
    "SimounObservation",
    "random_conv",
    "residual_motion",
]
