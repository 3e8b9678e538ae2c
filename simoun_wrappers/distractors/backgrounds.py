"""Moving background sources for ``MovingBackground``: procedural (seeded) or video files."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np

from simoun_wrappers._checks import check_path

VIDEO_SUFFIXES = (".mp4", ".avi", ".mov", ".mkv", ".webm", ".gif")
"""File endings read as videos from a ``videos`` folder (DMC-GB ships mp4 files)."""

IMAGE_SUFFIXES = (".jpg", ".jpeg", ".png")
"""File endings of the frames of a clip given as a sub-folder of images, in name order (DAVIS's
``JPEGImages/480p/<sequence>/00000.jpg`` layout)."""

MAX_VIDEO_SIDE = 256
"""Video frames are shrunk on loading so that their longer side is at most this many pixels:
agents see 84x84 frames, and a DAVIS clip at full size would hold hundreds of MB."""

TEXTURE_SIDE = 128
"""Side of the procedural texture, which tiles the plane (it is periodic)."""


class ProceduralBackground:
    """A drifting, periodic colour texture with a few discs moving over it, drawn per step.

    ``start(rng)`` draws a new texture, drift velocity and discs; ``frame(t, h, w)`` is the
    background at step ``t``: the texture shifted by ``t`` times its velocity (at least one
    texture pixel per step) and the discs at their positions, so it changes every step.
    """

    def start(self, rng: np.random.Generator) -> None:
        side = TEXTURE_SIDE
        y, x = np.mgrid[0:side, 0:side] / side
        texture = np.zeros((side, side, 3))
        # A sum of sinusoids with whole wave numbers is smooth and tiles the plane.
        for _ in range(6):
            ky, kx = rng.integers(-4, 5, size=2)
            wave = np.sin(2 * np.pi * (ky * y + kx * x) + rng.uniform(0, 2 * np.pi))
            texture += wave[..., None] * rng.uniform(-1, 1, size=3)
        low, high = texture.min(), texture.max()
        self._texture = ((texture - low) / max(high - low, 1e-9) * 255).astype(np.uint8)
        self._drift = _velocity(rng, 1.0, 3.0)
        count = int(rng.integers(3, 6))
        self._disc_start = rng.uniform(0, 1, size=(count, 2))
        self._disc_velocity = np.stack([_velocity(rng, 0.01, 0.04) for _ in range(count)])
        self._disc_radius = rng.uniform(0.06, 0.15, size=count)
        self._disc_color = rng.integers(0, 256, size=(count, 3))

    def frame(self, t: int, height: int, width: int) -> np.ndarray:
        shift = np.round(self._drift * t).astype(int)
        texture = np.roll(self._texture, tuple(shift), axis=(0, 1))
        image = cv2.resize(texture, (width, height), interpolation=cv2.INTER_LINEAR)
        side = min(height, width)
        centres = (self._disc_start + self._disc_velocity * t) % 1.0
        for (cy, cx), radius, color in zip(
            centres, self._disc_radius, self._disc_color, strict=True
        ):
            center = (int(cx * width), int(cy * height))
            cv2.circle(image, center, max(1, int(radius * side)), color.tolist(), -1)
        return image


def _velocity(rng: np.random.Generator, low: float, high: float) -> np.ndarray:
    angle = rng.uniform(0, 2 * np.pi)
    return rng.uniform(low, high) * np.array([np.sin(angle), np.cos(angle)])


class VideoBackground:
    """Frames of video files played in a loop: a random video and first frame per episode.

    Args:
        folder: a folder of video files (``VIDEO_SUFFIXES``), e.g. DMC-GB's
            ``src/env/data/video_hard``, and/or of sub-folders of frames (``IMAGE_SUFFIXES``),
            e.g. DAVIS's ``JPEGImages/480p``.

    Raises a ValueError when the folder holds no readable video, naming what was tried.
    """

    def __init__(self, folder: str | Path) -> None:
        check_path(
            folder,
            "videos",
            "videos='davis/JPEGImages/480p'",
            "a folder path or None (the procedural background)",
        )
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise ValueError(
                f"videos={str(folder)!r} is not a folder; pass a folder of video files "
                f"({', '.join(VIDEO_SUFFIXES)}), or videos=None for the procedural background."
            )
        candidates = sorted(
            path
            for path in self.folder.iterdir()
            if path.suffix.lower() in VIDEO_SUFFIXES or (path.is_dir() and _images(path))
        )
        self.paths = [path for path in candidates if _readable(path)]
        if not self.paths:
            tried = ", ".join(path.name for path in candidates) or "none"
            raise ValueError(
                f"no readable video in {self.folder} (video files and image folders tried: "
                f"{tried}); put {', '.join(VIDEO_SUFFIXES)} files that imageio can read "
                f"(imageio-ffmpeg installed) or folders of {', '.join(IMAGE_SUFFIXES)} frames "
                f"there, or pass videos=None for the procedural background."
            )
        self._loaded: tuple[Path, list[np.ndarray]] | None = None

    def start(self, rng: np.random.Generator) -> None:
        path = self.paths[int(rng.integers(len(self.paths)))]
        if self._loaded is None or self._loaded[0] != path:
            self._loaded = (path, _read_frames(path))
        self._first = int(rng.integers(len(self._loaded[1])))

    def frame(self, t: int, height: int, width: int) -> np.ndarray:
        frames = self._loaded[1]
        image = frames[(self._first + t) % len(frames)]
        return cv2.resize(image, (width, height), interpolation=cv2.INTER_AREA)


def _images(folder: Path) -> list[Path]:
    return sorted(path for path in folder.iterdir() if path.suffix.lower() in IMAGE_SUFFIXES)


def _frames(path: Path) -> Iterator[np.ndarray]:
    """The frames of a video file or of a folder of images, decoded one at a time."""
    import imageio.v3 as iio

    if path.is_dir():
        return (iio.imread(image) for image in _images(path))
    return iio.imiter(path)


def _readable(path: Path) -> bool:
    try:
        frame = next(iter(_frames(path)))
    except Exception:  # any decoder failure means "not a video we can play"
        return False
    return isinstance(frame, np.ndarray) and frame.ndim == 3 and frame.shape[2] in (3, 4)


def _read_frames(path: Path) -> list[np.ndarray]:
    frames = []
    for frame in _frames(path):
        image = np.ascontiguousarray(frame[..., :3], dtype=np.uint8)
        scale = MAX_VIDEO_SIDE / max(image.shape[:2])
        if scale < 1:
            size = (round(image.shape[1] * scale), round(image.shape[0] * scale))
            image = cv2.resize(image, size, interpolation=cv2.INTER_AREA)
        frames.append(image)
    return frames
