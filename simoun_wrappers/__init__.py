"""Gymnasium and PettingZoo wrappers for the Simoun method.

Importing the package sets headless rendering defaults when there is no display (``MUJOCO_GL=egl``,
``SDL_VIDEODRIVER=offscreen``) and ``SDL_NO_SIGNAL_HANDLERS=1`` always; see ``_headless``.
"""

from simoun_wrappers import _headless  # noqa: F401  (must run before dm_control/pygame load)
from simoun_wrappers._homes import missing_name
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
from simoun_wrappers.intrinsic_reward import ConstantBonusReward, ConstantBonusVectorReward
from simoun_wrappers.motion import ResidualMotion, residual_motion
from simoun_wrappers.observation import SimounObservation
from simoun_wrappers.rnd import RNDReward, RNDVectorReward
from simoun_wrappers.sb3_check import check_sb3_policy

__all__ = [
    "ActionRepeat",
    "ColorShift",
    "ConsistencyCuriosityReward",
    "ConsistencyCuriosityVectorReward",
    "ConstantBonusReward",
    "ConstantBonusVectorReward",
    "FeatureSource",
    "FrameTriplet",
    "MovingBackground",
    "MultiCamera",
    "RNDReward",
    "RNDVectorReward",
    "RandomConvolution",
    "ResidualMotion",
    "SimounObservation",
    "check_sb3_policy",
    "random_conv",
    "residual_motion",
]


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
