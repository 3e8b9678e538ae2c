"""The geometry of the registered encoders, and the frame sizes it allows, in closed form.

Every path of every encoder (:data:`simoun_agent.models.encoder.ENCODERS`, built from
:data:`TRUNK`) is the same stack of unpadded convs; the interactive module (Eq. 4) adds one
reducing conv of ``AgentConfig.reduce_kernel`` / ``reduce_stride`` on the trunk's maps. A frame
side fits when the last conv still has an output, so the smallest side is the trunk run
backwards from one pixel: 15 for the plain trunk, 19 with the interactive module's 3x3 stride-3
reduction (84 -> 41 -> 39 -> 37 -> 35 -> 11 forwards).

Example:
    >>> from simoun_agent.config import AgentConfig
    >>> conv_output_size(84), min_image_size(AgentConfig())
    (35, 19)
    >>> min_image_size(AgentConfig(encoder="stacked", curiosity=False))
    15
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from gymnasium import spaces

from simoun_agent.config.rules import is_int


@dataclass(frozen=True)
class Conv:
    """One unpadded square convolution."""

    kernel: int
    """side of the kernel"""
    stride: int
    """step between outputs"""

    def output_size(self, size: int) -> int:
        """Side of the output for an input of side ``size`` (below 1: no output)."""
        return (size - self.kernel) // self.stride + 1

    def input_size(self, size: int) -> int:
        """The smallest input side with an output of side ``size``."""
        return (size - 1) * self.stride + self.kernel


TRUNK: tuple[Conv, ...] = (Conv(3, 2), Conv(3, 1), Conv(3, 1), Conv(3, 1))
"""The conv trunk of every encoder path: four 3x3 convs, strides 2, 1, 1, 1 (Sec. 3.2, CURL's
encoder); :func:`simoun_agent.models.encoder.conv_trunk` builds it from here."""


@dataclass(frozen=True)
class EncoderShape:
    """What the configuration knows of one registered encoder: its paths and its convs."""

    motion_path: bool
    """True: separate motion and appearance paths, so L_tran acts on f^m and the consistency
    curiosity (Eq. 13) can compare them; False: one path, L_tran acts on the state"""
    interactive: bool = False
    """the structural interactive module reduces the trunk's maps with one conv of kernel
    ``reduce_kernel`` and stride ``reduce_stride`` (Eq. 4), which needs an output too"""
    conv_state: bool = False
    """one conv path on a stack of frames, whose flattened maps can be the state that the actor
    and the critic put their own trunks on (``AgentConfig.separate_trunks``, DrQ-v2)"""
    latent_flow: bool = False
    """reads the differences between successive frames' latents (Flare's latent flow), which
    needs two frames or more"""


ENCODER_SHAPES: dict[str, EncoderShape] = {
    "single": EncoderShape(motion_path=False, conv_state=True),
    "stacked": EncoderShape(motion_path=False, conv_state=True),
    "stacked_wide": EncoderShape(motion_path=False, conv_state=True),
    "flare": EncoderShape(motion_path=False, latent_flow=True),
    "dual": EncoderShape(motion_path=True),
    "dual_interactive": EncoderShape(motion_path=True, interactive=True),
}
"""Every encoder of :data:`simoun_agent.models.encoder.ENCODERS` by name (the same names: a test
holds them equal); ``AgentConfig.encoder`` must be one of them."""


class EncoderSettings(Protocol):
    """The fields of an ``AgentConfig`` that decide its encoder's geometry."""

    encoder: str
    reduce_kernel: int
    reduce_stride: int


def encoder_convs(agent: EncoderSettings) -> tuple[Conv, ...]:
    """Every conv a frame side passes through in the encoder of ``agent``, in order."""
    shape = ENCODER_SHAPES[agent.encoder]
    reduce = (Conv(agent.reduce_kernel, agent.reduce_stride),) if shape.interactive else ()
    return (*TRUNK, *reduce)


def conv_output_size(size: int, convs: Sequence[Conv] = TRUNK) -> int:
    """Side of the last map of ``convs`` for an input of side ``size`` (84 -> 41 -> 39 -> 37 ->
    35 through :data:`TRUNK`); below 1 when the input is too small."""
    for conv in convs:
        size = conv.output_size(size)
    return size


def min_image_size(agent: EncoderSettings) -> int:
    """The smallest frame side the encoder of ``agent`` (an AgentConfig) accepts."""
    size = 1
    for conv in reversed(encoder_convs(agent)):
        size = conv.input_size(size)
    return size


def frame_fits(agent: EncoderSettings, height: int, width: int) -> bool:
    """Whether the encoder of ``agent`` accepts frames of ``height`` x ``width``."""
    return min(height, width) >= min_image_size(agent)


class ContrastiveSettings(Protocol):
    """The fields of an ``AgentConfig`` that decide whether L_con's positive is a random
    convolution of the frames, and of which kernel."""

    contrastive_view: str
    contrastive_weight: float
    random_conv_kernel: int


def uses_random_conv(agent: ContrastiveSettings) -> bool:
    """Whether the agent of ``agent`` runs a random convolution over its frames (the
    contrastive positive of Eq. 3): an L_con of weight above 0 with the view "random_conv"."""
    return bool(agent.contrastive_weight) and agent.contrastive_view == "random_conv"


def kernel_fits(agent: ContrastiveSettings, height: int, width: int) -> bool:
    """Whether the random convolution of ``agent`` (when it has one) fits frames of ``height``
    x ``width``: a kernel wider than the frame would see only its zero padding."""
    return not uses_random_conv(agent) or agent.random_conv_kernel <= min(height, width)


def largest_odd(size: int) -> int:
    """The largest odd number up to ``size`` (at least 1): the widest random-convolution kernel
    a frame side of ``size`` takes."""
    return max(1, size if size % 2 else size - 1)


def check_channel_first(shape: tuple[int, int, int]) -> None:
    """Refuse a frame shape that looks channel-last (H, W, C), with the channel-first one."""
    channels, height, width = shape
    if channels not in (1, 3) and width in (1, 3):
        raise ValueError(
            f"frame_shape {shape} looks channel-last (H, W, C); pass it channel-first, "
            f"({width}, {channels}, {height}), as SimounObservation's frames are"
        )


class AgentSettings(EncoderSettings, ContrastiveSettings, Protocol):
    """The fields of an ``AgentConfig`` that decide which frames its agent takes."""


def check_agent_inputs(frame_shape: Sequence[int], action_dim: Any, agent: AgentSettings) -> None:
    """What ``SimounAgent`` is built for: channel-first frames its encoder accepts, and at least
    one action dimension. Raises ValueError naming the argument and the fix."""
    check_frame_shape(frame_shape, agent)
    if isinstance(action_dim, spaces.Space) and not isinstance(action_dim, spaces.Box):
        raise ValueError(
            f"SimounAgent is a SAC agent for continuous actions (a 1-D Box), got the action space "
            f"{action_dim}; use the env's continuous version (e.g. highway-env's "
            f"ContinuousAction, LunarLander continuous=True), or a discrete-action learner such "
            f"as SB3's PPO or DQN with 'CnnPolicy' on SimounObservation(env, fold_frames=True)"
        )
    if not is_int(action_dim) or action_dim < 1:
        raise ValueError(
            f"action_dim must be an int >= 1, got {action_dim!r}; pass env.action_space.shape[0] "
            "of a continuous (Box) action space"
        )


def check_frame_shape(frame_shape: Any, agent: AgentSettings) -> None:
    """A ValueError naming ``frame_shape`` unless it is channel-first (C, H, W) positive ints
    whose frames the encoder of ``agent`` (and its random convolution) accepts: what
    ``SimounAgent`` and ``make_encoder`` are built for."""
    shape = tuple(frame_shape) if isinstance(frame_shape, Sequence) else (frame_shape,)
    if hasattr(frame_shape, "tolist"):  # a numpy array of the three sizes
        shape = tuple(frame_shape.tolist())
    if len(shape) != 3 or not all(is_int(v) and v > 0 for v in shape):
        raise ValueError(
            f"frame_shape must be (C, H, W) positive ints, got {shape!r}; pass "
            "env.observation_space['frames'].shape[1:] of a SimounObservation env"
        )
    check_channel_first(shape)
    height, width = shape[1:]
    if not frame_fits(agent, height, width):
        smallest = min_image_size(agent)
        reduce = conv_output_size(min(height, width))  # the widest reducing conv that fits
        lower = (
            f", or lower AgentConfig.reduce_kernel={agent.reduce_kernel} to {reduce} or less"
            if ENCODER_SHAPES[agent.encoder].interactive and reduce >= 1
            else ""
        )
        raise ValueError(
            f"frames of {height}x{width} are too small for the conv trunk of encoder "
            f"{agent.encoder!r}, which needs at least {smallest}x{smallest}; resize them, e.g. "
            f"SimounObservation(env, size={max(smallest, 84)}){lower}"
        )
    if not kernel_fits(agent, height, width):
        side = min(height, width)
        raise ValueError(
            f"AgentConfig.random_conv_kernel={agent.random_conv_kernel} is wider than the "
            f"{height}x{width} frames, which the random convolution of L_con's positives "
            f"(Eq. 3) runs over; set random_conv_kernel=3 (Lee et al. 2020) or another odd "
            f"value up to {largest_odd(side)}, resize the frames to at least "
            f"{agent.random_conv_kernel}x{agent.random_conv_kernel} (SimounObservation(env, "
            f"size=...)), or contrastive_view='shift'"
        )
