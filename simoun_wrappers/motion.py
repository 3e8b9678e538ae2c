"""Residual motion channels: the differences between consecutive frames of a stack."""

from __future__ import annotations

import numpy as np


def residual_motion(frames: np.ndarray) -> np.ndarray:
    """Residual motion ``[o_{t-1} - o_{t-2}, o_t - o_{t-1}]`` of a frame stack (paper Sec. 3.2).

    Args:
        frames: uint8 array ``(..., k, C, H, W)`` with ``k >= 2``, oldest frame first.

    Returns:
        int16 array ``(..., (k-1)*C, H, W)``: the ``k-1`` differences of consecutive frames,
        concatenated on the channel axis. Values lie in [-255, 255]; nothing wraps around.

    Example:
        >>> import numpy as np
        >>> stack = np.array([0, 200, 50], dtype=np.uint8).reshape(3, 1, 1, 1)
        >>> residual_motion(stack).ravel().tolist()
        [200, -150]
    """
    frames = np.asarray(frames)
    if frames.dtype != np.uint8:
        raise TypeError(
            f"residual_motion expects uint8 frames, got {frames.dtype}; pass the raw image "
            f"stack (e.g. the 'frames' of SimounObservation), not normalised floats."
        )
    if frames.ndim < 4 or frames.shape[-4] < 2:
        raise ValueError(
            f"residual_motion expects a (..., k, C, H, W) stack with k >= 2 frames, got shape "
            f"{frames.shape}; stack frames first, e.g. with FrameTriplet(env, num_frames=3)."
        )
    diff = np.diff(frames.astype(np.int16), axis=-4)
    *lead, k1, c, h, w = diff.shape
    return diff.reshape(*lead, k1 * c, h, w)
