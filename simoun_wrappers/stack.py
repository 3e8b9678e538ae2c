"""A per-stream frame stack: its space and its output, shared by the Gymnasium and PettingZoo
wrappers (one stream per env, one per agent)."""

from __future__ import annotations

import cv2
import gymnasium as gym
import numpy as np
from gymnasium import spaces

from simoun_wrappers.frames import FrameRing, FrameTriplet, check_stack_bytes
from simoun_wrappers.motion import motion_space, residual_motion

LUMA = np.array([0.2125, 0.7154, 0.0721])
"""RGB weights of one luminance channel: gymnasium's ``GrayscaleObservation``'s, so frames match
those of its wrappers."""


def frame_shape(
    layout: tuple[int, int, int], size: tuple[int, int] | None, grayscale: bool
) -> tuple[int, int, int]:
    """``(C, H, W)`` of the frames :func:`to_frame` makes from ``(H, W, C)`` images."""
    height, width, channels = layout
    if size is not None:
        height, width = size
    return (1 if grayscale else channels), height, width


def to_frame(image: np.ndarray, size: tuple[int, int] | None, grayscale: bool) -> np.ndarray:
    """An ``(H, W[, C])`` uint8 image as one channel-first ``(C, H, W)`` frame: resized to
    ``size`` (OpenCV area interpolation, as gymnasium's ``ResizeObservation``), made one
    luminance channel when ``grayscale`` and RGB (:data:`LUMA`). The per-frame step of
    ``SimounObservation`` and ``SimounParallelObservation``."""
    if size is not None and image.shape[:2] != size:
        image = cv2.resize(image, size[::-1], interpolation=cv2.INTER_AREA)
    if image.ndim == 2:
        image = image[:, :, None]
    if grayscale and image.shape[2] == 3:
        image = np.sum(np.multiply(image, LUMA), axis=-1).astype(np.uint8)[:, :, None]
    return image.transpose(2, 0, 1)


Observation = np.ndarray | dict[str, np.ndarray]


class FrameStack:
    """One stream of images as Simoun's observation: ``SimounObservation``'s pipeline, held once
    per Gymnasium env and once per PettingZoo agent.

    Each ``(H, W[, C])`` uint8 image becomes a channel-first frame (:func:`to_frame`); the last
    ``num_frames`` frames are kept in a :class:`FrameRing` (``reset`` repeats the first frame,
    ``push`` adds one); the stack is given as ``observation_space`` says:

    - ``{"frames": (k, C, H, W) uint8, "motion": ((k-1)*C, H, W) int16}`` (default),
    - ``{"frames": (k, C, H, W) uint8}`` with ``motion=False``,
    - a ``(k*C, H, W)`` uint8 Box with ``fold_frames=True`` (motion left out).

    Every observation holds fresh arrays. A stack over :data:`MAX_STACK_BYTES` is refused
    before it is allocated.

    Example:
        >>> import numpy as np
        >>> stack = FrameStack((2, 2, 1), size=None, grayscale=False, num_frames=3)
        >>> stack.observation_space["motion"]
        Box(-255, 255, (2, 2, 2), int16)
        >>> obs = stack.reset(np.zeros((2, 2), np.uint8))
        >>> obs = stack.push(np.full((2, 2), 100, np.uint8))
        >>> obs["frames"][:, 0, 0, 0].tolist(), obs["motion"][:, 0, 0].tolist()
        ([0, 0, 100], [0, 100])
    """

    def __init__(
        self,
        layout: tuple[int, int, int],
        size: tuple[int, int] | None,
        grayscale: bool,
        num_frames: int,
        motion: bool = True,
        fold_frames: bool = False,
    ) -> None:
        """Stack images of ``layout`` ``(H, W, C)``. The other arguments are
        ``SimounObservation``'s, checked (``check_stack_options``), ``size`` parsed
        (``parse_size``)."""
        shape = frame_shape(layout, size, grayscale)
        check_stack_bytes(num_frames, shape, np.uint8)
        self.num_frames = int(num_frames)
        self._size = size
        self._grayscale = grayscale
        self._fold = fold_frames
        self._motion = motion and not fold_frames
        frames = spaces.Box(0, 255, (self.num_frames, *shape), dtype=np.uint8)
        if self._fold:
            channels, height, width = shape
            folded = (self.num_frames * channels, height, width)
            self.observation_space: spaces.Space = spaces.Box(0, 255, folded, dtype=np.uint8)
        elif self._motion:
            self.observation_space = spaces.Dict({"frames": frames, "motion": motion_space(frames)})
        else:
            self.observation_space = spaces.Dict({"frames": frames})
        self._ring = FrameRing(self.num_frames, shape, np.uint8)

    def reset(self, image: np.ndarray) -> Observation:
        """The observation of a new stream: ``image``'s frame in every slot (reset padding)."""
        return self._observation(self._ring.reset(to_frame(image, self._size, self._grayscale)))

    def push(self, image: np.ndarray) -> Observation:
        """The observation once ``image``'s frame replaces the oldest one."""
        return self._observation(self._ring.push(to_frame(image, self._size, self._grayscale)))

    def _observation(self, stack: np.ndarray) -> Observation:
        if self._fold:
            return stack.reshape(self.observation_space.shape)
        if self._motion:
            return {"frames": stack, "motion": residual_motion(stack)}
        return {"frames": stack}


class StreamTriplet(FrameTriplet):
    """``FrameTriplet`` that stacks through a :class:`FrameStack`: one Gymnasium env's images in,
    Simoun's observation out (the stacking step of ``SimounObservation``'s chain).

    Being a ``FrameTriplet``, it refuses ``step()`` before ``reset()`` and is found by the
    wrappers that belong under a frame stack (``frame_stack_in``).
    """

    def __init__(self, env: gym.Env, stack: FrameStack) -> None:
        """Wrap ``env``, whose observations are the images ``stack`` was made for."""
        gym.utils.RecordConstructorArgs.__init__(self, stack=stack)
        gym.Wrapper.__init__(self, env)
        # FrameTriplet.__init__ is not called: it would build a ring for the images, while the
        # stack holds its own for the frames made from them.
        self.num_frames = stack.num_frames
        self.observation_space = stack.observation_space
        self._ring = stack
        self._has_reset = False
