"""SimounObservation: the one-line entry point from any pixel or renderable env to Simoun inputs."""

from __future__ import annotations

import functools
import operator
from copy import deepcopy
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import EnvSpec, WrapperSpec
from gymnasium.wrappers import AddRenderObservation, TransformObservation

from simoun_wrappers._checks import (
    check_action,
    check_bool,
    check_positive_int,
    check_reset_seed,
    is_int,
    keyword_reset,
    plain,
    refuse_after_close,
    refuse_step_before_reset,
)

# LUMA, frame_shape and to_frame (the per-frame step) are importable from this module too.
from simoun_wrappers.distractors._dm_control import is_closed_dm_control
from simoun_wrappers.frames import check_single_env, frame_stack_in
from simoun_wrappers.stack import LUMA as LUMA
from simoun_wrappers.stack import FrameStack, StreamTriplet
from simoun_wrappers.stack import frame_shape as frame_shape
from simoun_wrappers.stack import to_frame as to_frame

_SOURCES = ("auto", "observation", "render")


def image_layout(space: gym.Space) -> tuple[int, int, int] | None:
    """``(H, W, C)`` of a channel-last ``(H, W, C)`` (C in 1, 3) or ``(H, W)`` Box, else None.

    The dtype is not checked: callers decide what a non-uint8 image means.
    """
    if not isinstance(space, spaces.Box):
        return None
    if len(space.shape) == 3 and space.shape[-1] in (1, 3):
        return space.shape
    if len(space.shape) == 2:
        return (*space.shape, 1)
    return None


MAX_FRAME_BYTES = 2**28
"""The largest RGB frame ``size`` may ask for (256 MiB: about 9,459 x 9,459 pixels), far above any
frame a pixel agent learns from."""


def plain_size(size: Any) -> Any:
    """A numpy int, an array of integers or a pair of numpy ints given as ``size`` as the Python
    int (0-d) or tuple (1-D, pair) it holds, as a shape read off a space may be; anything else as
    it is (``parse_size`` checks
    it). Recorded for ``env.spec`` this way, the size stays JSON."""
    if isinstance(size, np.ndarray) and size.dtype.kind in "iu" and size.ndim <= 1:
        return size.item() if size.ndim == 0 else tuple(size.tolist())
    if isinstance(size, np.integer):
        return int(size)
    if isinstance(size, (tuple, list)) and all(is_int(v) for v in size):
        return tuple(int(v) for v in size)
    return size


def parse_size(size: int | tuple[int, int] | None) -> tuple[int, int] | None:
    """``size`` as ``(H, W)``; an int means a square; None stays None (keep the image's size)."""
    if size is None:
        return None
    size = plain_size(size)
    if is_int(size):
        pair = (size, size)
    else:
        pair = tuple(size) if isinstance(size, (tuple, list)) else (size,)
    if len(pair) != 2 or not all(is_int(v) and v > 0 for v in pair):
        raise ValueError(
            f"size must be a positive int or an (H, W) pair of positive ints, got {size!r}; "
            f"e.g. size=84 or size=(84, 252), or None to keep the image's size."
        )
    height, width = int(pair[0]), int(pair[1])
    if height * width * 3 > MAX_FRAME_BYTES:
        # refused here: the resize would otherwise fail deep in OpenCV or numpy with MemoryError
        raise ValueError(
            f"size {size!r} makes RGB frames of {height * width * 3 / 2**30:.1f} GiB each (at "
            f"most {MAX_FRAME_BYTES // 2**20} MiB); pass a smaller size, e.g. size=84 or "
            f"size=(84, 252)."
        )
    return height, width


def check_stack_options(
    num_frames: int, motion: bool, fold_frames: bool, source: str, grayscale: bool = False
) -> None:
    """Reject bad ``SimounObservation`` options (shared with ``SimounParallelObservation``)."""
    switches = {"grayscale": grayscale, "motion": motion, "fold_frames": fold_frames}
    for name, value in switches.items():
        check_bool(value, name)
    if source not in _SOURCES:
        raise ValueError(f"source must be one of {_SOURCES}, got {source!r}.")
    check_positive_int(num_frames, "num_frames", "use 3 for a triplet.")
    if motion and not fold_frames and num_frames < 2:
        raise ValueError(
            f"motion=True needs at least 2 frames to take differences, got "
            f"num_frames={num_frames}; use num_frames=3 (the triplet) or motion=False."
        )


def minigrid_object_grid(env: gym.Env) -> bool:
    """Whether ``env`` observes MiniGrid's encoded grid (object id, colour, state per cell) through
    ``ImgObsWrapper``, with no ``RGBImgObsWrapper`` / ``RGBImgPartialObsWrapper`` under it to make
    pixels (and no ``AddRenderObservation`` over it). Found by class, so minigrid need not be
    installed."""

    def is_minigrid(wrapper: gym.Env, *names: str) -> bool:
        return any(
            c.__name__ in names and c.__module__.split(".")[0] == "minigrid"
            for c in type(wrapper).__mro__
        )

    grid = False
    inner = env
    while isinstance(inner, gym.Wrapper):
        if isinstance(inner, AddRenderObservation) and not grid:
            return False
        if is_minigrid(inner, "RGBImgObsWrapper", "RGBImgPartialObsWrapper"):
            return False
        grid = grid or is_minigrid(inner, "ImgObsWrapper")
        inner = inner.env
    return grid


def layout_hint(space: gym.Space) -> str | None:
    """What a uint8 ``(C, H, W)`` Box holds, and how to convert it to an ``(H, W, C)`` image; None
    for anything else. Channel-first planes ``(C, H, W)`` may be one image or a stack of grayscale
    frames (highway-env's ``GrayscaleObservation``): only the user knows which, so no guess."""
    if not isinstance(space, spaces.Box) or space.dtype != np.uint8:
        return None
    shape = space.shape
    if len(shape) == 3 and shape[-1] not in (1, 3, 4) and shape[0] < min(shape[1:]):
        c, h, w = shape
        stack = (
            f"if they are {c} stacked grayscale frames, give the env one frame per observation "
            f"(this wrapper stacks frames itself)"
        )
        if c not in (1, 3, 4):
            return f"{c} channel-first planes {shape}, not an image of 1 or 3 channels: {stack}"
        return (
            f"{c} channel-first planes {shape}, but images must be channel-last (H, W, C). If "
            f"they are one image, transpose it: TransformObservation(env, lambda o: "
            f"o.transpose(1, 2, 0), Box(0, 255, ({h}, {w}, {c}), np.uint8)); {stack}"
        )
    return None


def _rgba(space: gym.Space) -> bool:
    return isinstance(space, spaces.Box) and len(space.shape) == 3 and space.shape[-1] == 4


def _drop_alpha(env: gym.Env) -> gym.Env:
    """``env`` with the alpha channel of its ``(H, W, 4)`` image observations dropped."""
    height, width, _ = env.observation_space.shape
    rgb = spaces.Box(0, 255, (height, width, 3), dtype=env.observation_space.dtype)
    return TransformObservation(env, operator.itemgetter((Ellipsis, slice(0, 3))), rgb)


def pixel_env(
    env: gym.Env, source: str = "auto", owner: str = "SimounObservation"
) -> tuple[gym.Env, bool]:
    """An env whose observation is the ``(H, W, C)`` image to use, and whether it comes from
    ``render()``.

    ``source`` is ``"auto"``, ``"observation"`` or ``"render"``; ``owner`` names the caller in
    error messages. ``"auto"`` takes a uint8 image observation, or the ``"pixels"`` entry of a
    Dict observation (gymnasium's ``AddRenderObservation(render_only=False)``, dm_control's
    pixel wrapper through shimmy), else ``render()`` when the render mode is ``"rgb_array"``; an
    image-shaped observation that is not uint8 (say a float (H, W) state matrix such as
    highway-env's kinematics) then goes to ``render()`` too, and is an error only when there is
    nothing to render. RGBA images lose their alpha channel. Refused with a fix: MiniGrid's
    object-id grid (``ImgObsWrapper`` without an ``RGBImg*`` wrapper) and channel-first planes,
    unless ``source="render"`` asks for ``render()``.
    """
    if source not in _SOURCES:
        raise ValueError(f"source must be one of {_SOURCES}, got {source!r}.")
    chain = env
    if source != "render":
        if minigrid_object_grid(env):
            raise TypeError(
                f"{owner} needs pixels, but MiniGrid's ImgObsWrapper gives the "
                f"{env.observation_space.shape} grid of object ids, colours and states (one "
                f"cell per value), which is not an image. Make pixels under it: "
                f"ImgObsWrapper(RGBImgPartialObsWrapper(env)) for the agent's view, or "
                f"ImgObsWrapper(RGBImgObsWrapper(env)) for the whole grid (minigrid.wrappers); "
                f"or pass source='render' to use the env's rgb_array renders."
            )
        space = env.observation_space
        if isinstance(space, spaces.Dict) and isinstance(space.spaces.get("pixels"), spaces.Box):
            chain = TransformObservation(env, operator.itemgetter("pixels"), space["pixels"])
        if _rgba(chain.observation_space):
            chain = _drop_alpha(chain)
    layout = image_layout(chain.observation_space)
    is_uint8 = layout is not None and chain.observation_space.dtype == np.uint8
    hint = layout_hint(chain.observation_space)
    if source != "render" and hint is not None:
        renders = (
            " Or pass source='render' to use the env's rgb_array renders instead."
            if env.render_mode == "rgb_array"
            else ""
        )
        raise TypeError(
            f"{owner} takes (H, W, C) uint8 images; this env's observations are {hint}.{renders}"
        )
    use_observation = source == "observation" or (
        source == "auto" and layout is not None and (is_uint8 or env.render_mode != "rgb_array")
    )
    if use_observation:
        if layout is None:
            raise TypeError(
                f"{owner}(source='observation') needs image observations (H, W, C) "
                f"or (H, W), got {env.observation_space}; use source='render' with "
                f"render_mode='rgb_array' instead."
            )
        if not is_uint8:
            raise TypeError(
                f"{owner} expects uint8 images in [0, 255], got "
                f"{chain.observation_space.dtype} observations of shape "
                f"{chain.observation_space.shape}; convert them first, e.g. TransformObservation("
                f"env, lambda o: (o * 255).astype(np.uint8), Box(0, 255, shape, np.uint8)), or "
                f"pass source='render' to use the env's rgb_array renders."
            )
        return chain, False

    if env.render_mode != "rgb_array":
        changer = render_mode_changer(env)
        if changer is not None:
            name = type(changer).__name__
            made = (
                f" (gym.make adds it for render_mode={changer.render_mode!r})"
                if isinstance(changer, gym.wrappers.RenderCollection)
                else ""
            )
            raise ValueError(
                f"{owner} needs pixels: the env has no image observations (observation space "
                f"{env.observation_space}), and {name} turned the render mode 'rgb_array' into "
                f"{changer.render_mode!r}{made}, which gives no single frame to take. Create the "
                f"env with render_mode='rgb_array', e.g. "
                f"gym.make(env_id, render_mode='rgb_array'); to keep {name}, put {owner} under "
                f"it: {name}({owner}(env, ...))."
            )
        raise ValueError(
            f"{owner} needs pixels: the env has neither image observations "
            f"(observation space {env.observation_space}) nor render_mode='rgb_array' "
            f"(render_mode={env.render_mode!r}). Create it with "
            f"gym.make(env_id, render_mode='rgb_array'), or wrap it so that it returns "
            f"(H, W, 3) uint8 images."
        )
    try:
        pixels = AddRenderObservation(env, render_only=True)
    except TypeError as err:
        # gymnasium's error names neither the wrapper that needs the renders nor what they must
        # be; its wrapper has reset the env, so rendering again shows what it got
        if "expects env.render() to return" not in str(err):
            raise
        check_render(env.render(), owner)
        raise
    frame = check_render(pixels.render(), owner)
    if image_layout(pixels.observation_space) is None:
        raise ValueError(
            f"{owner} expects env.render() to return an (H, W, 3) image, got shape "
            f"{frame.shape}; check the env's render_mode and render_kwargs."
        )
    # each step's render is checked too: the space above holds only the first one's shape
    pixels = TransformObservation(
        pixels,
        functools.partial(check_render, owner=owner, shape=pixels.observation_space.shape),
        pixels.observation_space,
    )
    if _rgba(pixels.observation_space):
        pixels = _drop_alpha(pixels)
    return pixels, True


def render_mode_changer(env: gym.Env) -> gym.Wrapper | None:
    """The wrapper in ``env`` that turned the ``"rgb_array"`` render mode of the env under it into
    another (gymnasium's ``RenderCollection`` makes it ``"rgb_array_list"``), or None."""
    inner = env
    while isinstance(inner, gym.Wrapper):
        if inner.render_mode != "rgb_array" and inner.env.render_mode == "rgb_array":
            return inner
        inner = inner.env
    return None


def check_render(frame: Any, owner: str, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """``frame``, an ``rgb_array`` render that ``owner`` takes its pixels from, or a TypeError
    (not a uint8 array) or ValueError (a side of 0, or not ``shape``, the first render's) that
    names the env's render and what it must return."""
    return check_image(
        frame,
        owner,
        "the env's render() (render_mode='rgb_array')",
        (
            "Use an env whose rgb_array render is such an image, or convert it in a wrapper's "
            "render().",
            "Give the env a fixed render size (e.g. its render width and height), and check its "
            "render_kwargs.",
        ),
        shape,
        noun="render",
    )


def check_image(
    frame: Any,
    owner: str,
    source: str,
    fixes: tuple[str, str],
    shape: tuple[int, ...] | None = None,
    rgb: bool = False,
    noun: str = "image",
) -> np.ndarray:
    """``frame``, an image ``owner`` takes from ``source`` (an env's render, a camera), or a
    TypeError (not a uint8 array) or ValueError (a side of 0; not 2-D or 3-D, a gray image
    being taken; not ``(H, W, 3)`` when ``rgb``; or not ``shape``, the first image's) that names
    the source and what it must return. ``fixes`` holds the fix of each error, in that order;
    ``noun`` is what the source returns (a "render", an "image")."""
    if shape is None:
        expected = "an (H, W, 3) uint8 image with H, W >= 1"
    else:
        expected = f"uint8 images of its first {noun}'s shape {shape}"
    what = None
    if not isinstance(frame, np.ndarray):
        what = "None" if frame is None else f"a {type(frame).__name__}"
    elif frame.dtype != np.uint8:
        what = f"a {frame.dtype} array"
    if what is not None:
        raise TypeError(
            f"{owner} takes its frames from {source}, which returned {what}; it must return "
            f"{expected} at every step. {fixes[0]}"
        )
    if shape is None:
        layout = frame.ndim == 3 and frame.shape[2] == 3 if rgb else frame.ndim in (2, 3)
        if not layout or 0 in frame.shape:
            what = f"an array of shape {frame.shape}"
    elif frame.shape != shape:
        what = f"an image of shape {frame.shape}"
    if what is not None:
        raise ValueError(
            f"{owner} takes its frames from {source}, which returned {what}; it must return "
            f"{expected} at every step. {fixes[1]}"
        )
    return frame


def _rebuilt(cls: type, source_env: gym.Env, kwargs: dict) -> gym.Env:
    return cls(source_env, **kwargs)


class ChainWrapper(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """A wrapper built as a chain of inner wrappers over ``source_env``, recorded as itself only.

    Subclasses call ``RecordConstructorArgs.__init__`` with their own arguments, then
    ``ChainWrapper.__init__(self, chain, source_env)``. ``spec`` is the source env's spec plus
    this wrapper: recording the inner wrappers too would apply them twice when
    ``gym.make(env.spec)`` rebuilds the chain.
    """

    def __init__(self, chain: gym.Env, source_env: gym.Env) -> None:
        gym.Wrapper.__init__(self, chain)
        self._source_env = source_env
        self._has_reset = False
        """whether the user reset this wrapper: reading pixels from render() resets the env
        while the chain is built"""
        self._closed = False

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        self._refuse_closed("reset")
        seed = check_reset_seed(seed, type(self).__name__)
        result = self.env.reset(seed=seed, options=options)
        self._has_reset = True
        return result

    def step(self, action: Any) -> tuple[Any, Any, bool, bool, dict[str, Any]]:
        self._refuse_closed("step")
        check_action(action, self.action_space, type(self).__name__)
        refuse_step_before_reset(self._has_reset, type(self).__name__)
        return self.env.step(action)

    def _refuse_closed(self, call: str) -> None:
        # a closed dm_control task is named by the distractor or camera over it, with the id
        # to make it anew: that refusal comes from the call itself
        if not is_closed_dm_control(self._source_env):
            refuse_after_close(self._closed, type(self).__name__, call)

    def close(self) -> None:
        self._closed = True
        super().close()

    def __reduce__(self) -> tuple:
        """Pickled as its arguments around the pickled source env, since gymnasium's wrappers in
        the chain (AddRenderObservation) hold lambdas: it pickles whenever
        the source env does. The copy is built anew, so it is reset before its first step."""
        return (_rebuilt, (type(self), self._source_env, dict(self._saved_kwargs)))

    def __deepcopy__(self, memo: dict) -> ChainWrapper:
        # a deep copy keeps the state (frames, RNGs): copy.deepcopy would use __reduce__
        copied = object.__new__(type(self))
        memo[id(self)] = copied
        copied.__dict__.update(deepcopy(self.__dict__, memo))
        return copied

    @property
    def spec(self) -> EnvSpec | None:
        if self._cached_spec is None and self._source_env.spec is not None:
            spec = deepcopy(self._source_env.spec)
            spec.additional_wrappers += (
                WrapperSpec(
                    name=self.class_name(),
                    entry_point=f"{type(self).__module__}:{type(self).__name__}",
                    kwargs=dict(self._saved_kwargs),
                ),
            )
            self._cached_spec = spec
        return self._cached_spec


class SimounObservation(ChainWrapper):
    """Turn a pixel or renderable env into Simoun's inputs: frame triplet and motion channels.

    Pixels come from the observation when it is an image (``(H, W, C)`` or ``(H, W)`` uint8,
    or ``(H, W, 4)`` RGBA whose alpha is dropped) or a Dict with a ``"pixels"`` image entry
    (which wins over ``render()``; ``source="render"`` picks the renders), otherwise from
    ``render()`` when ``render_mode="rgb_array"`` (gymnasium's ``AddRenderObservation``).
    Observations that hold pixels in another layout are refused with the conversion to make:
    channel-first ``(C, H, W)`` planes (one image or stacked grayscale frames: only you know
    which) and MiniGrid's ``ImgObsWrapper`` object-id grid (put
    ``RGBImgPartialObsWrapper`` under it). Frames are resized (OpenCV area interpolation, as
    gymnasium's ``ResizeObservation``), optionally made grayscale (``GrayscaleObservation``'s
    weights), made channel-first ``(C, H, W)`` (:func:`to_frame`), stacked with reset padding and
    given residual motion channels (:func:`residual_motion`) by a ``FrameStack``, the pipeline that
    ``SimounParallelObservation`` runs per agent. The observation is

    - ``{"frames": (k, C, H, W) uint8, "motion": ((k-1)*C, H, W) int16}`` (default),
    - ``{"frames": (k, C, H, W) uint8}`` with ``motion=False``,
    - a ``(k*C, H, W)`` uint8 Box with ``fold_frames=True``: the frames folded on the channel
      axis, which Stable-Baselines3's ``CnnPolicy`` treats as an image. Motion is then left
      out, whatever ``motion`` says: SB3 has no image form for int16 channels, and
      ``simoun_wrappers.motion.residual_motion(obs.reshape(k, C, H, W))`` recovers it exactly.

    Wrapper order: ``ActionRepeat``, ``MultiCamera``, ``RandomConvolution`` and the distractors
    go under this wrapper, the reward wrappers over it; over an env that already stacks frames
    (a ``SimounObservation``, ``FrameTriplet`` or ``FrameStackObservation`` inside) it raises.
    With Stable-Baselines3 use ``fold_frames=True`` and ``CnnPolicy``
    (``check_sb3_policy(env, policy)`` says why the Dict form does not fit).

    ``env.spec`` records this wrapper alone (not its inner gymnasium wrappers), so
    ``gym.make(env.spec)`` rebuilds the same chain. When pixels come from ``render()``,
    ``metadata["render_modes"]`` is narrowed to ``["rgb_array"]``, the only mode it works with.
    ``step()`` before the first ``reset()`` raises gymnasium's ``ResetNeeded``.

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import SimounObservation
        >>> env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=64)
        >>> obs, _ = env.reset(seed=0)
        >>> obs["frames"].shape, obs["motion"].shape, obs["motion"].dtype
        ((3, 3, 64, 64), (6, 64, 64), dtype('int16'))
        >>> folded = SimounObservation(
        ...     gym.make("CartPole-v1", render_mode="rgb_array"), size=64, fold_frames=True
        ... )
        >>> folded.observation_space
        Box(0, 255, (9, 64, 64), uint8)
    """

    def __init__(
        self,
        env: gym.Env,
        size: int | tuple[int, int] | None = 84,
        grayscale: bool = False,
        num_frames: int = 3,
        motion: bool = True,
        fold_frames: bool = False,
        source: str = "auto",
    ) -> None:
        """Wrap ``env``.

        Args:
            env: an env with image observations or ``render_mode="rgb_array"``.
            size: frame size, an int (square) or ``(H, W)``; None keeps the image's size
                (e.g. over ``MultiCamera``).
            grayscale: convert RGB frames to one luminance channel.
            num_frames: frames per stack (3: the triplet ``[o_{t-2}, o_{t-1}, o_t]``).
            motion: add the residual motion channels (needs ``num_frames >= 2``).
            fold_frames: return a ``(num_frames*C, H, W)`` uint8 Box for SB3's ``CnnPolicy``
                (no motion key).
            source: ``"auto"`` (image observation if there is one, else ``render()``),
                ``"observation"`` or ``"render"``.
        """
        check_single_env(env, "SimounObservation")
        # parsed before it is recorded: recording deep-copies it, which a generator refuses
        size = plain_size(size)
        hw = parse_size(size)
        gym.utils.RecordConstructorArgs.__init__(
            self,
            size=size,
            grayscale=plain(grayscale),
            num_frames=plain(num_frames),
            motion=plain(motion),
            fold_frames=plain(fold_frames),
            source=source,
        )
        check_stack_options(num_frames, motion, fold_frames, source, grayscale)
        stack = frame_stack_in(env)
        if stack is not None:
            raise TypeError(
                f"SimounObservation stacks frames itself, but {env} already does "
                f"({type(stack).__name__} inside): over it, the triplet would be lost to a "
                f"render() or taken as one image. Apply SimounObservation once, to the unstacked "
                f"env (drop FrameStackObservation; set num_frames={num_frames} here instead)."
            )
        chain, from_render = pixel_env(env, source)
        stack = FrameStack(
            image_layout(chain.observation_space), hw, grayscale, num_frames, motion, fold_frames
        )
        ChainWrapper.__init__(self, StreamTriplet(chain, stack), env)
        if from_render:
            self.metadata = {**env.metadata, "render_modes": ["rgb_array"]}
