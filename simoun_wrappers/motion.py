"""Residual motion channels: the differences between consecutive frames of a stack."""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from simoun_wrappers._checks import check_action, check_reset_seed, keyword_reset
from simoun_wrappers.frames import check_single_env


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


def motion_space(frames: spaces.Box) -> spaces.Box:
    """The space of :func:`residual_motion`'s channels for stacks in ``frames``, a ``(k, C, H, W)``
    Box: int16 ``((k-1)*C, H, W)`` in [-255, 255]."""
    k, c, h, w = frames.shape
    return spaces.Box(-255, 255, ((k - 1) * c, h, w), dtype=np.int16)


class ResidualMotion(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Add residual motion channels to a stacked ``(k, C, H, W)`` uint8 observation.

    The observation becomes ``{"frames": (k, C, H, W) uint8, "motion": ((k-1)*C, H, W) int16}``
    with ``motion = [o_{t-1} - o_{t-2}, o_t - o_{t-1}]`` for a triplet (see ``residual_motion``):
    exact, negative differences kept, no uint8 wrap-around.

    Example:
        >>> import gymnasium as gym
        >>> import numpy as np
        >>> from gymnasium.wrappers import AddRenderObservation, ResizeObservation
        >>> from gymnasium.wrappers import TransformObservation
        >>> from simoun_wrappers import FrameTriplet, ResidualMotion
        >>> env = gym.make("CartPole-v1", render_mode="rgb_array")
        >>> env = ResizeObservation(AddRenderObservation(env), (32, 32))
        >>> chw = gym.spaces.Box(0, 255, (3, 32, 32), np.uint8)
        >>> env = TransformObservation(env, lambda o: o.transpose(2, 0, 1), chw)
        >>> env = ResidualMotion(FrameTriplet(env))
        >>> env.observation_space["motion"]
        Box(-255, 255, (6, 32, 32), int16)
    """

    def __init__(self, env: gym.Env) -> None:
        """Wrap ``env``, whose observation space must be a uint8 ``Box`` of shape ``(k, C, H, W)``.

        Args:
            env: a stacked-frame environment, e.g. ``FrameTriplet`` over channel-first images.
        """
        check_single_env(env, "ResidualMotion")
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.ObservationWrapper.__init__(self, env)
        space = env.observation_space
        if not isinstance(space, spaces.Box) or space.dtype != np.uint8 or len(space.shape) != 4:
            raise TypeError(
                f"ResidualMotion expects a uint8 Box of shape (k, C, H, W), got {space}; "
                f"stack channel-first uint8 frames first, e.g. SimounObservation(env) does it all."
            )
        k = space.shape[0]
        if k < 2:
            raise ValueError(
                f"ResidualMotion needs at least 2 stacked frames to take differences, got k={k}; "
                f"stack more frames (FrameTriplet(env, num_frames=3)) or drop the motion channels."
            )
        self.observation_space = spaces.Dict({"frames": space, "motion": motion_space(space)})

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        seed = check_reset_seed(seed, "ResidualMotion")
        return super().reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[dict[str, Any], SupportsFloat, bool, bool, dict[str, Any]]:
        check_action(action, self.action_space, "ResidualMotion")
        return super().step(action)

    def observation(self, observation: np.ndarray) -> dict[str, Any]:
        return {"frames": observation, "motion": residual_motion(observation)}
