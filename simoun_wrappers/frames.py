"""Frame stacking: the last k observations on a new leading axis, reset-padded."""

from __future__ import annotations

import math
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded
from gymnasium.vector.utils import batch_space
from gymnasium.wrappers import FrameStackObservation

from simoun_wrappers._checks import (
    check_action,
    check_positive_int,
    check_reset_seed,
    keyword_reset,
    plain,
)

MAX_STACK_BYTES = 2**30
"""The largest stack ``FrameTriplet`` or ``FrameStack`` builds (1 GiB: over 12,000 RGB frames of
84 x 84)."""


def check_stack_bytes(num_frames: int, shape: tuple[int, ...], dtype: np.dtype) -> None:
    """Raise ValueError when ``num_frames`` frames of ``shape`` and ``dtype`` take more than
    :data:`MAX_STACK_BYTES`: refused before anything tries to allocate them all."""
    stack_bytes = num_frames * math.prod(shape) * np.dtype(dtype).itemsize
    if stack_bytes > MAX_STACK_BYTES:
        raise ValueError(
            f"num_frames={num_frames} makes stacks of {stack_bytes / 2**30:.1f} GiB per "
            f"observation of shape {shape} (at most {MAX_STACK_BYTES // 2**30} GiB); "
            f"use num_frames=3 for a triplet."
        )


class FrameRing:
    """The last ``num_frames`` frames in a preallocated ring buffer, oldest first on read.

    ``reset(frame)`` fills every slot with ``frame`` (reset padding); ``push(frame)`` overwrites
    the oldest slot. Both return a fresh ``(num_frames, *frame.shape)`` array made by one copy,
    so callers may keep or hand out what they get.

    Example:
        >>> import numpy as np
        >>> ring = FrameRing(3, shape=(1,), dtype=np.uint8)
        >>> ring.reset(np.array([7], dtype=np.uint8)).ravel().tolist()
        [7, 7, 7]
        >>> ring.push(np.array([8], dtype=np.uint8)).ravel().tolist()
        [7, 7, 8]
    """

    def __init__(self, num_frames: int, shape: tuple[int, ...], dtype: np.dtype) -> None:
        self._buffer = np.zeros((num_frames, *shape), dtype=dtype)
        self._head = 0  # slot of the oldest frame, the next one to overwrite

    def reset(self, frame: np.ndarray) -> np.ndarray:
        self._buffer[:] = frame
        self._head = 0
        return self._buffer.copy()

    def push(self, frame: np.ndarray) -> np.ndarray:
        self._buffer[self._head] = frame
        self._head = (self._head + 1) % len(self._buffer)
        return np.concatenate((self._buffer[self._head :], self._buffer[: self._head]))


class FrameTriplet(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Stack the last ``num_frames`` observations on a new leading axis, reset-padded.

    Step for step equal to ``gymnasium.wrappers.FrameStackObservation(env, num_frames,
    padding_type="reset")``, with the same observation space, but each step writes one frame
    into a ring buffer and copies the stack once (no deepcopy of the whole stack). Every
    returned array is fresh. With the default ``num_frames=3`` the observation is Simoun's
    triplet ``[o_{t-2}, o_{t-1}, o_t]``. ``step()`` before the first ``reset()`` raises
    gymnasium's ``ResetNeeded`` (``OrderEnforcing``'s convention): there is no stack to push to.

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import FrameTriplet
        >>> env = FrameTriplet(gym.make("CartPole-v1"))
        >>> env.observation_space.shape
        (3, 4)
        >>> obs, _ = env.reset(seed=0)
        >>> bool((obs[0] == obs[2]).all())
        True
    """

    def __init__(self, env: gym.Env, num_frames: int = 3) -> None:
        """Wrap ``env``, whose observation space must be a ``Box``.

        Args:
            env: the environment to wrap.
            num_frames: how many consecutive observations to stack (``k``).
        """
        check_single_env(env, "FrameTriplet")
        gym.utils.RecordConstructorArgs.__init__(self, num_frames=plain(num_frames))
        gym.Wrapper.__init__(self, env)
        check_positive_int(num_frames, "num_frames", "use 3 for a triplet.")
        space = env.observation_space
        if not isinstance(space, spaces.Box):
            raise TypeError(
                f"FrameTriplet stacks Box observations, got {space}; select or build an image "
                f"first, e.g. SimounObservation(env) or gymnasium.wrappers.AddRenderObservation."
            )
        check_stack_bytes(num_frames, space.shape, space.dtype)  # before batch_space allocates
        self.num_frames = int(num_frames)
        self.observation_space = batch_space(space, n=self.num_frames)
        # What reset() and step() hand each observation to: a FrameRing here, a FrameStack (same
        # reset and push) in SimounObservation's chain (simoun_wrappers.stack.StreamTriplet).
        self._ring = FrameRing(self.num_frames, space.shape, space.dtype)
        self._has_reset = False

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        seed = check_reset_seed(seed, type(self).__name__)
        obs, info = self.env.reset(seed=seed, options=options)
        self._has_reset = True
        return self._ring.reset(obs), info

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        if not self._has_reset:
            # The ring holds no frames yet: stepping would return a stack of zero frames.
            raise ResetNeeded(
                "Cannot call env.step() before calling env.reset(): FrameTriplet fills its "
                "frame stack in reset(); call env.reset(seed=...) first."
            )
        check_action(action, self.action_space, type(self).__name__)
        obs, reward, terminated, truncated, info = self.env.step(action)
        return self._ring.push(obs), reward, terminated, truncated, info


def frame_stack_in(env: gym.Env) -> gym.Wrapper | None:
    """The outermost frame-stacking wrapper inside ``env`` (``FrameTriplet``, hence
    ``SimounObservation``, or gymnasium's ``FrameStackObservation``), or None."""
    inner = env
    while isinstance(inner, gym.Wrapper):
        if isinstance(inner, (FrameTriplet, FrameStackObservation)):
            return inner
        inner = inner.env
    return None


def check_single_env(env: Any, owner: str) -> None:
    """Raise TypeError unless ``env`` is one ``gymnasium.Env``: a vector env is told to wrap
    each of its sub-envs (``gym.make_vec(..., wrappers=[...])``), anything else names the type
    expected and the type given.

    Args:
        env: the env ``owner`` was given.
        owner: the wrapper being built, as the user writes it (``"SimounObservation"``).
    """
    if isinstance(env, gym.Env):
        return
    if isinstance(env, gym.vector.VectorEnv):
        raise TypeError(
            f"{owner} wraps one env, got the vector env {type(env).__name__}: wrap each sub-env "
            f"instead, gym.make_vec(env_id, num_envs, wrappers=[lambda e: {owner}(e, ...)])"
        )
    raise TypeError(
        f"{owner}'s env must be a gymnasium.Env, got {type(env).__name__} ({env!r:.60}); "
        f"e.g. {owner}(gym.make(env_id, render_mode='rgb_array'), ...)"
    )


def refuse_over_frame_stack(env: gym.Env, owner: str, why: str, right_order: str) -> None:
    """Raise TypeError when ``env`` already stacks frames: ``owner`` belongs under the stack.

    Args:
        env: the env ``owner`` was given.
        owner: the wrapper being built, as the user wrote it.
        why: what would go wrong over the stack (a clause, lower case).
        right_order: the composition to use instead, with a word on what it does.

    Example:
        >>> import gymnasium as gym
        >>> env = FrameTriplet(gym.make("CartPole-v1"))
        >>> refuse_over_frame_stack(env, "ActionRepeat", "it would repeat", "ActionRepeat(env)")
        Traceback (most recent call last):
        ...
        TypeError: ActionRepeat goes under the frame stack, not over it: ...
    """
    stack = frame_stack_in(env)
    if stack is not None:
        raise TypeError(
            f"{owner} goes under the frame stack, not over it: {env} already stacks frames "
            f"({type(stack).__name__} inside), and {why}. Swap the order: {right_order}."
        )
