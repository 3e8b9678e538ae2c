"""MultiCamera: several views rendered at the same step, side by side in one image."""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable, Mapping
from typing import Any, SupportsFloat

import cv2
import gymnasium as gym
import numpy as np
from gymnasium import spaces

from simoun_wrappers._checks import (
    check_action,
    check_reset_seed,
    keyword_reset,
    plain,
    refuse_step_before_reset,
)
from simoun_wrappers._spec import CheckedSpecWrapper
from simoun_wrappers.augment import RandomConvolution
from simoun_wrappers.distractors._dm_control import check_open, dm_control_physics
from simoun_wrappers.frames import check_single_env, refuse_over_frame_stack
from simoun_wrappers.observation import check_image, parse_size, plain_size

Camera = int | str | Mapping[str, Any] | Callable[[gym.Env], np.ndarray]
"""A dm_control camera id or name, a highway-env viewport dict, or a callable env -> image."""

_VIEWPORT_KEYS = ("centering_position", "scaling")


def _dm_control_view(env: gym.Env, camera: int | str, hw: tuple[int, int] | None) -> Callable:
    physics = dm_control_physics(
        env,
        "MultiCamera",
        f"camera {camera!r} is a dm_control camera id or name, but {env.unwrapped} is not a "
        f"dm_control env through shimmy; for other envs pass callables env -> (H, W, 3) uint8 "
        f"image, or viewport dicts for highway-env.",
    )
    model = physics.model
    names = [model.id2name(i, "camera") for i in range(model.ncam)]
    if isinstance(camera, str) and camera not in names:
        raise ValueError(
            f"unknown camera name {camera!r}; this env's cameras are {names} (or ids "
            f"0..{model.ncam - 1}, and -1 for the free camera). Pass one of those."
        )
    if isinstance(camera, (int, np.integer)) and not -1 <= camera < model.ncam:
        raise ValueError(
            f"camera id {camera} out of range; this env has {model.ncam} cameras {names}, so "
            f"use an id in -1..{model.ncam - 1} (-1 is the free camera) or a name."
        )
    kwargs = {} if hw is None else {"height": hw[0], "width": hw[1]}
    # A distractor below (MovingBackground) may composite what the cameras see.
    try:
        render = env.get_wrapper_attr("render_camera")
    except AttributeError:
        render = physics.render
    return functools.partial(render, camera_id=camera, **kwargs)  # picklable, unlike a lambda


def _highway_view(env: gym.Env, viewport: Mapping[str, Any], hw: tuple[int, int] | None):
    unknown = sorted(set(viewport) - set(_VIEWPORT_KEYS))
    if unknown:
        raise ValueError(
            f"viewport keys {unknown} not understood; a highway-env viewport dict takes "
            f"{list(_VIEWPORT_KEYS)}, e.g. {{'centering_position': [0.3, 0.5], 'scaling': 3.0}}."
        )
    base = env.unwrapped
    if not (hasattr(base, "road") and isinstance(getattr(base, "config", None), dict)):
        raise TypeError(
            f"viewport dict {dict(viewport)} describes a highway-env view, but {base} is not a "
            f"highway-env env; for other envs pass callables env -> (H, W, 3) uint8 image."
        )
    from highway_env.envs.common.graphics import EnvViewer

    config = {**base.config, "offscreen_rendering": True, **viewport}
    if hw is not None:
        config["screen_height"], config["screen_width"] = hw
    viewer = EnvViewer(base, config=config)

    def render() -> np.ndarray:
        viewer.display()
        return viewer.get_image()

    return render


class MultiCamera(CheckedSpecWrapper, gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """Observe N views of the same step, resized to ``size`` and side by side: ``(H, N*W, 3)``.

    Each entry of ``cameras`` is one view:

    - an int or str: a dm_control camera id or name (envs made through shimmy; every DMC task
      has at least two cameras, e.g. walker ``"side"`` and ``"back"``), rendered by the
      physics at ``size``;
    - a dict: a highway-env viewport with ``centering_position`` and/or ``scaling``, drawn by
      its own offscreen ``EnvViewer`` at ``size`` (a few ms; ``env.render()`` is never called,
      so highway-env's per-frame auto-rendering stays off);
    - a callable ``env -> (H, W, 3) uint8``, resized to ``size`` with OpenCV area interpolation.

    The paper's CARLA setup, three 84x84 cameras, gives an 84 x 252 image. ``size=None`` keeps
    every view's own size, which must then agree. The wrapper's ``render()`` returns the same
    side-by-side image, so its only render mode is ``"rgb_array"``. Compose with
    ``SimounObservation(MultiCamera(env, ...), size=None)`` to stack the wide frames, and
    ``RandomConvolution(MultiCamera(env, ...))`` to convolve them. The views are drawn from the
    env's cameras, not from its observation, so over an env that already stacks frames or
    applies ``RandomConvolution`` (which would be silently dropped) it raises, naming the order
    to use.
    ``close()`` leaves the highway viewers alone: ``EnvViewer.close()`` quits pygame for all.
    The constructor resets ``env`` once (unseeded) to learn the views' sizes: highway-env has
    no road to draw before a reset. That episode is not the user's: ``step()`` before the
    first ``reset()`` raises Gymnasium's ``ResetNeeded``. ``env.spec.to_json()`` writes
    cameras given as names, ids or viewport dicts; a camera function makes it raise a
    TypeError naming ``cameras`` (``gym.make(env.spec)`` still re-makes the env in-process).

    Example:
        >>> import gymnasium as gym
        >>> import shimmy
        >>> from simoun_wrappers import MultiCamera
        >>> gym.register_envs(shimmy)
        >>> env = MultiCamera(gym.make("dm_control/walker-walk-v0"), ["side", "back"], (64, 64))
        >>> obs, _ = env.reset(seed=0)
        >>> obs.shape, obs.dtype
        ((64, 128, 3), dtype('uint8'))
    """

    def __init__(
        self,
        env: gym.Env,
        cameras: Iterable[Camera],
        size: int | tuple[int, int] | None = (84, 84),
    ) -> None:
        """Wrap ``env``.

        Args:
            env: the environment to render views of.
            cameras: one entry per view (see the class docstring), left to right: a list, a
                tuple or any other iterable, read once here (a generator is fine).
            size: every view's ``(H, W)`` (an int means square); None keeps each view's size,
                which every view must then keep at every step.
        """
        check_single_env(env, "MultiCamera")
        if isinstance(cameras, (str, bytes, Mapping)) or not isinstance(cameras, Iterable):
            raise TypeError(
                f"cameras must be a list of views (or another iterable of them), got "
                f"{cameras!r}; e.g. ['side', 'back'] or [0, 1] for dm_control, a list of "
                "viewport dicts for highway-env."
            )
        # read once, here: a generator cannot be recorded (deep-copied) or pickled with the
        # wrapper, and would be empty when read again
        cameras = tuple(cameras)
        size = plain_size(size)
        self._hw = parse_size(size)
        self._dm_control = any(isinstance(c, (int, np.integer, str)) for c in cameras)
        """whether a view renders the physics of a dm_control task, which close() frees"""
        gym.utils.RecordConstructorArgs.__init__(self, cameras=plain(cameras), size=size)
        gym.ObservationWrapper.__init__(self, env)
        refuse_over_frame_stack(
            env,
            "MultiCamera",
            "its views are rendered from the env's cameras, so the triplet and its motion "
            "channels would be dropped",
            "SimounObservation(MultiCamera(env, cameras), size=None) stacks the side-by-side views",
        )
        refuse_over_random_convolution(env)
        if len(cameras) == 0:
            raise ValueError("cameras is empty; pass at least one view, e.g. [0].")
        self._shape: tuple[int, ...] | None = None
        """the views' shape under ``size=None`` (the first images'), which every later image
        must keep: the observation space holds it; None while the constructor reads it"""
        self._views = [
            functools.partial(self._checked, camera, self._make_view(camera)) for camera in cameras
        ]
        # the user's episode starts with their own reset(seed=...): step() refuses until then
        self.env.reset()
        self._has_reset = False
        shapes = [view().shape for view in self._views]
        if len(set(shapes)) != 1:
            raise ValueError(
                f"views of different sizes: {shapes}; pass size=(H, W) so that every view is "
                f"rendered or resized to the same size."
            )
        if self._hw is None:
            self._shape = shapes[0]
        height, width, _ = shapes[0]
        self.observation_space = spaces.Box(
            0, 255, (height, width * len(cameras), 3), dtype=np.uint8
        )
        self.metadata = {**env.metadata, "render_modes": ["rgb_array"]}

    def _make_view(self, camera: Camera) -> Callable[[], np.ndarray]:
        if isinstance(camera, (int, np.integer, str)):
            return _dm_control_view(self.env, camera, self._hw)
        if isinstance(camera, Mapping):
            return _highway_view(self.env, camera, self._hw)
        if callable(camera):
            return functools.partial(camera, self.env)
        raise TypeError(
            f"camera {camera!r} not understood; use a dm_control camera id or name, a "
            f"highway-env viewport dict, or a callable env -> (H, W, 3) uint8 image."
        )

    def _checked(self, camera: Camera, view: Callable[[], Any]) -> np.ndarray:
        """The image of ``view`` (the view of ``camera``), checked as ``SimounObservation``
        checks renders (uint8, ``(H, W, 3)``, no side of 0 and, under ``size=None``, the first
        image's shape at every step), then resized to ``size``."""
        size_fix = "Make the camera return such an image" + (
            " (under size=None every view keeps its first size; pass size=(H, W) to resize "
            "them to one)."
            if self._hw is None
            else "."
        )
        image = check_image(
            view(),
            "MultiCamera",
            f"camera {camera!r}",
            ("Make the camera return such an image, e.g. np.asarray(image, np.uint8).", size_fix),
            self._shape,
            rgb=True,
        )
        if self._hw is not None and image.shape[:2] != self._hw:
            image = cv2.resize(image, self._hw[::-1], interpolation=cv2.INTER_AREA)
        return image

    @property
    def render_mode(self) -> str:
        return "rgb_array"

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        seed = check_reset_seed(seed, "MultiCamera")
        self._check_open()
        result = super().reset(seed=seed, options=options)
        self._has_reset = True
        return result

    def step(self, action: Any) -> tuple[np.ndarray, SupportsFloat, bool, bool, dict[str, Any]]:
        check_action(action, self.action_space, "MultiCamera")
        refuse_step_before_reset(self._has_reset, "MultiCamera")
        self._check_open()
        return super().step(action)

    def render(self) -> np.ndarray:
        """The current views side by side, as in the observation."""
        self._check_open()
        return self.observation(None)

    def _check_open(self) -> None:
        if self._dm_control:
            check_open(self.env, "MultiCamera")

    def observation(self, observation: Any) -> np.ndarray:
        return np.concatenate([view() for view in self._views], axis=1)


def refuse_over_random_convolution(env: gym.Env) -> None:
    """Raise TypeError when ``env`` holds a ``RandomConvolution``: views rendered from the
    cameras never pass through it, so ``MultiCamera`` over it would silently drop it."""
    inner = env
    while isinstance(inner, gym.Wrapper):
        if isinstance(inner, RandomConvolution):
            raise TypeError(
                f"MultiCamera goes under RandomConvolution, not over it: its views are rendered "
                f"from the env's cameras, so the convolution in {env} would never reach them. "
                f"Swap the order: RandomConvolution(MultiCamera(env, cameras)) convolves the "
                f"side-by-side image with the episode's kernel."
            )
        inner = inner.env
