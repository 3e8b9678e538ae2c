"""Write evaluation episodes to video files through imageio."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from simoun_agent.run.atomic import atomic_write

MIN_VIDEO_SIDE = 256


def to_video_frame(frame: np.ndarray) -> np.ndarray:
    """A channel-first ``(C, H, W)`` uint8 frame as an ``(H', W', 3)`` image, upscaled.

    Frames the agent sees are small (84x84); they are enlarged by a whole factor with
    nearest-neighbour interpolation, so the video shows the agent's pixels as they are.
    """
    image = np.ascontiguousarray(frame.transpose(1, 2, 0))
    if image.shape[2] == 1:
        image = np.repeat(image, 3, axis=2)
    factor = max(1, -(-MIN_VIDEO_SIDE // min(image.shape[:2])))
    if factor > 1:
        image = cv2.resize(
            image,
            (image.shape[1] * factor, image.shape[0] * factor),
            interpolation=cv2.INTER_NEAREST,
        )
    return image


def write_video(path: Path, frames: Sequence[np.ndarray], fps: float) -> Path:
    """Write ``(C, H, W)`` uint8 frames to ``path`` (``.mp4`` through ffmpeg, or ``.gif``).

    The file is written under a temporary name and renamed, so a video on disk is complete.
    """
    import imageio.v2 as imageio

    images = [to_video_frame(frame) for frame in frames]

    def write(tmp: Path) -> None:
        if tmp.suffix == ".gif":
            imageio.mimsave(tmp, images, duration=1000 / fps, loop=0)
        else:
            # macro_block_size=1: our frame sizes are even, which is all libx264 needs.
            with imageio.get_writer(tmp, fps=fps, macro_block_size=1) as writer:
                for image in images:
                    writer.append_data(image)

    atomic_write(Path(path), write)
    return Path(path)
