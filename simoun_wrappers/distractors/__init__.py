"""Distractors for dm_control tasks (DMC-GB's colour and video modes, without data downloads).

``ColorShift`` recolours the skybox, floor and body in the loaded model at each reset;
``MovingBackground`` replaces the background of rendered frames, found by segmentation, with a
moving procedural texture or video files. Both change only what is rendered.
"""

from simoun_wrappers.distractors.color import ColorShift
from simoun_wrappers.distractors.moving_background import MovingBackground

__all__ = ["ColorShift", "MovingBackground"]
