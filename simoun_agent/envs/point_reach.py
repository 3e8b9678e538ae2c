"""A tiny pixel task for tests: steer a dot onto a target, seen only through a 32x32 image."""

from __future__ import annotations

from typing import ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from simoun_wrappers._checks import check_finite_positive, check_positive_int


class PointReach(gym.Env):
    """Move a red dot to the green target at the centre of a 32x32 RGB image.

    The observation is the image only (``uint8 (32, 32, 3)``), so a policy must read the
    dot's position from pixels. The action is a velocity in ``[-1, 1]^2`` scaled by
    ``step_size``; the reward is ``-distance`` to the target (so a return near 0 is good),
    and episodes are truncated after ``max_steps`` steps. Small and fast enough for a
    learning test that runs in a couple of minutes on a CPU.

    Example:
        >>> import gymnasium as gym
        >>> import simoun_agent.envs  # registers "simoun/PointReach-v0"
        >>> env = gym.make("simoun/PointReach-v0")
        >>> obs, info = env.reset(seed=0)
        >>> obs.shape, obs.dtype
        ((32, 32, 3), dtype('uint8'))
    """

    metadata: ClassVar[dict] = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(
        self,
        render_mode: str | None = None,
        size: int = 32,
        max_steps: int = 20,
        step_size: float = 0.2,
    ):
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        check_positive_int(size, "size", "pass the image's side in pixels, e.g. size=32")
        check_positive_int(
            max_steps, "max_steps", "pass the steps before truncation, e.g. max_steps=20"
        )
        check_finite_positive(
            step_size, "step_size", "pass the distance of a full action, e.g. step_size=0.2"
        )
        self.render_mode = render_mode
        self.size = size
        self.max_steps = max_steps
        self.step_size = step_size
        self.observation_space = spaces.Box(0, 255, (size, size, 3), np.uint8)
        self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
        self._position = np.zeros(2)
        self._steps = 0

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        self._position = self.np_random.uniform(-0.9, 0.9, size=2)
        self._steps = 0
        return self._image(), {"distance": self._distance()}

    def step(self, action):
        action = np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self._position = np.clip(self._position + self.step_size * action, -1.0, 1.0)
        self._steps += 1
        distance = self._distance()
        truncated = self._steps >= self.max_steps
        return self._image(), -distance, False, truncated, {"distance": distance}

    def render(self) -> np.ndarray | None:
        return self._image() if self.render_mode == "rgb_array" else None

    def _distance(self) -> float:
        return float(np.linalg.norm(self._position))

    def _image(self) -> np.ndarray:
        image = np.zeros((self.size, self.size, 3), np.uint8)
        self._draw(image, np.zeros(2), (0, 200, 0))
        self._draw(image, self._position, (255, 40, 40))
        return image

    def _draw(self, image: np.ndarray, position: np.ndarray, color: tuple[int, int, int]) -> None:
        """Paint a 3x3 square centred on ``position`` (in [-1, 1]^2, y pointing up)."""
        col, row = np.rint((position * [1, -1] + 1) / 2 * (self.size - 1)).astype(int)
        image[max(row - 1, 0) : row + 2, max(col - 1, 0) : col + 2] = color
