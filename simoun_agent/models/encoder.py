"""Pixel encoders: the dual-path encoder (Sec. 3.2) and the ablation variants of Fig. 6.

Every encoder maps a uint8 observation ``(B, k, C, H, W)`` (k frames, oldest first) to an
:class:`Encoding`. Frames become float (x / 255 - ``AgentConfig.pixel_offset``) on the device
inside the encoder, so the replay
and the environment only ever hold uint8. ``encode_transition`` encodes the states at t and t+1
from one window of k+1 frames, sharing frames; ``encode_key`` encodes an augmented float view
(the contrastive positive, run through the momentum copy of the encoder).

Ablations (Fig. 6), registered in :data:`ENCODERS` and built by :func:`make_encoder` from
``AgentConfig.encoder``:

========================  ================================================================
``single``                one conv path on frame t only
``stacked``               one conv path on the k frames folded into kC channels (CURL, DrQ)
``stacked_wide``          ``stacked`` with twice the filters
``flare``                 per-frame convs, flattened latents and their differences with the
                          earlier frame detached, FC + LayerNorm (Shang et al. 2021)
``dual``                  motion path on the residuals + appearance path per frame
``dual_interactive``      ``dual`` with the structural interactive module (the paper's model)
========================  ================================================================
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import torch
from torch import nn

from simoun_agent.config.agent import AgentConfig
from simoun_agent.config.shapes import (
    ENCODER_SHAPES,
    TRUNK,
    EncoderShape,
    check_frame_shape,
    conv_output_size,
)
from simoun_agent.models.interaction import StructuralInteraction, StructureMasks, resized_linear


class Encoding(NamedTuple):
    """What one encoder pass produces (``None`` where the encoder has no such part)."""

    state: torch.Tensor
    """(B, repr_dim) the state representation f_t fed to the actor and critic"""
    anchor: torch.Tensor | None = None
    """(B, feature_dim) contrastive anchor (Eq. 3): f^a_t before interaction, or the state"""
    motion: torch.Tensor | None = None
    """(B, feature_dim) f^m_t as used in the state (after the interactive module)"""
    appearance: torch.Tensor | None = None
    """(B, 3, feature_dim) f^a of frames t-2, t-1, t before interaction, detached; only with
    ``frame_features=True``"""
    masks: StructureMasks | None = None
    """attention X and masks X^m, X^a of the interactive module"""


def conv_trunk(in_channels: int, num_filters: int) -> nn.Sequential:
    """The convs of :data:`~simoun_agent.config.shapes.TRUNK` with ReLU: four 3x3 convs, strides
    2, 1, 1, 1 (the paths of Sec. 3.2, CURL's encoder); its last map's side is
    :func:`~simoun_agent.config.shapes.conv_output_size`."""
    layers: list[nn.Module] = []
    for i, conv in enumerate(TRUNK):
        layer = nn.Conv2d(num_filters if i else in_channels, num_filters, conv.kernel, conv.stride)
        layers += [layer, nn.ReLU(inplace=True)]
    return nn.Sequential(*layers)


def trunk_dim(frame_shape: tuple[int, int, int], num_filters: int) -> int:
    """Length of the flattened last maps of :func:`conv_trunk` on frames of ``(C, H, W)``."""
    _, height, width = frame_shape
    return num_filters * conv_output_size(height) * conv_output_size(width)


def flatten_maps(maps: torch.Tensor) -> torch.Tensor:
    """Feature maps ``(N, c, h, w)`` -> ``(N, h * w * c)``, in (h, w, c) order: a free view of a
    channels-last map."""
    return maps.permute(0, 2, 3, 1).flatten(1)


class FlatMaps(nn.Module):
    """The flattened conv maps as the state (DrQ-v2's Encoder, whose output the actor's and the
    critic's own trunks read)."""

    def forward(self, maps: torch.Tensor) -> torch.Tensor:
        return flatten_maps(maps)


class Head(nn.Module):
    """FC + LayerNorm from a feature map ``(N, c, h, w)`` to a vector (Alg. 1, lines 11-12)."""

    def __init__(self, in_features: int, feature_dim: int) -> None:
        super().__init__()
        self.fc = nn.Linear(in_features, feature_dim)
        self.norm = nn.LayerNorm(feature_dim)

    def linear(self, maps: torch.Tensor) -> torch.Tensor:
        """The FC layer alone."""
        return self.fc(flatten_maps(maps))

    def modulation(self, mask: torch.Tensor, size: tuple[int, int]) -> torch.Tensor:
        """FC weights (no bias) applied to ``mask`` resized bilinearly to ``size``."""
        return resized_linear(mask, self.fc.weight, size)

    def forward(self, maps: torch.Tensor) -> torch.Tensor:
        return self.norm(self.linear(maps))


def weight_init(module: nn.Module, conv: str = "orthogonal") -> None:
    """Orthogonal weights and zero biases for linear layers; conv layers by ``conv``
    (``AgentConfig.conv_init``): "orthogonal" with relu gain (DrQ, DrQ-v2), or "delta_orthogonal"
    (Xiao et al. 2018: every tap zero but the centre one, an orthogonal matrix with relu gain; CURL,
    RAD, SAC-AE)."""
    if isinstance(module, nn.Linear):
        nn.init.orthogonal_(module.weight)
        nn.init.zeros_(module.bias)
    elif isinstance(module, nn.Conv2d):
        gain = nn.init.calculate_gain("relu")
        nn.init.zeros_(module.bias)
        if conv == "orthogonal":
            nn.init.orthogonal_(module.weight, gain)
            return
        kernel_h, kernel_w = module.weight.shape[-2:]
        with torch.no_grad():
            module.weight.zero_()
            nn.init.orthogonal_(module.weight[:, :, kernel_h // 2, kernel_w // 2], gain)


class PixelEncoder(nn.Module):
    """Base class: uint8 frames ``(B, k, C, H, W)`` in, :class:`Encoding` out.

    Subclasses define :meth:`forward` and :meth:`encode_key`, and may override
    :meth:`encode_transition` to share frames between the states at t and t+1.
    """

    repr_dim: int
    key_is_frame: bool
    """True: the contrastive view is frame t ``(B, C, H, W)``; False: the whole stack"""
    pixel_offset: float = 0.0
    """subtracted from x / 255 (``AgentConfig.pixel_offset``; set by :func:`make_encoder`)"""

    def __init__(self, channels_last: bool = True) -> None:
        super().__init__()
        self.memory_format = torch.channels_last if channels_last else torch.contiguous_format

    def to_float(self, obs: torch.Tensor) -> torch.Tensor:
        """uint8 -> float x / 255 - pixel_offset."""
        x = obs.float().div_(255.0)
        return x.sub_(self.pixel_offset) if self.pixel_offset else x

    def frame_stack(self, obs: torch.Tensor) -> torch.Tensor:
        """uint8 ``(B, n, C, H, W)`` -> float ``(n, B, C, H, W)`` (x / 255 - pixel_offset) whose
        frames ``[j]`` are already in the conv memory format (one uint8 transpose instead of a
        float copy per frame)."""
        if self.memory_format == torch.channels_last:
            x = self.to_float(obs.permute(1, 0, 3, 4, 2).contiguous())
            return x.permute(0, 1, 4, 2, 3)
        return self.to_float(obs.transpose(0, 1).contiguous())

    def trunk_input(self, x: torch.Tensor) -> torch.Tensor:
        return x.contiguous(memory_format=self.memory_format)

    def key_frames(self, obs: torch.Tensor) -> torch.Tensor:
        """The float frames whose augmented view gives the contrastive positive (Eq. 3)."""
        return self.to_float(obs[:, -1] if self.key_is_frame else obs)

    def forward(self, obs: torch.Tensor, frame_features: bool = False) -> Encoding:
        raise NotImplementedError

    def encode_key(self, view: torch.Tensor) -> torch.Tensor:
        """Contrastive features ``(B, feature_dim)`` of an augmented float view (Eq. 3)."""
        raise NotImplementedError

    def encode_transition(
        self, window: torch.Tensor, frame_features: bool = False, next_frame_features: bool = False
    ) -> tuple[Encoding, Encoding]:
        """Encodings of the triplets at t (with gradient) and t+1 (without) from the uint8 window
        ``(B, k+1, C, H, W)`` of frames t-k+1 .. t+1; ``frame_features`` / ``next_frame_features``
        ask for the per-frame f^a of the one at t / at t+1."""
        current = self(window[:, :-1], frame_features)
        with torch.no_grad():
            following = self(window[:, 1:], next_frame_features)
        return current, following


class OnePathEncoder(PixelEncoder):
    """Base of the ablations with one conv path, ``convs`` (a :func:`conv_trunk` on
    ``in_channels``), whose flattened last maps on frames of ``frame_shape`` are ``latent_dim``
    long: the state is the contrastive features of the whole float stack."""

    key_is_frame = False

    def __init__(
        self,
        in_channels: int,
        frame_shape: tuple[int, int, int],
        num_filters: int,
        channels_last: bool,
    ) -> None:
        super().__init__(channels_last)
        self.convs = conv_trunk(in_channels, num_filters)
        self.latent_dim = trunk_dim(frame_shape, num_filters)

    def forward(self, obs: torch.Tensor, frame_features: bool = False) -> Encoding:
        f = self.encode_key(self.to_float(obs))
        return Encoding(state=f, anchor=f)


class StackedEncoder(OnePathEncoder):
    """Ablations "stacked" / "stacked_wide": one conv path on the k frames folded into kC
    channels (CURL / DrQ's encoder). With ``head=False`` the state is the flattened conv maps
    (DrQ-v2's Encoder), on which the actor and the critic put their own trunks."""

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_frames: int,
        num_filters: int,
        feature_dim: int,
        channels_last: bool = True,
        head: bool = True,
    ) -> None:
        super().__init__(num_frames * frame_shape[0], frame_shape, num_filters, channels_last)
        self.head = Head(self.latent_dim, feature_dim) if head else FlatMaps()
        self.repr_dim = feature_dim if head else self.latent_dim

    def encode_key(self, view: torch.Tensor) -> torch.Tensor:
        stack = view if view.ndim == 4 else view.flatten(1, 2)
        return self.head(self.convs(self.trunk_input(stack)))


class SingleFrameEncoder(StackedEncoder):
    """Ablation "single": one conv path on frame t only (a stack of one frame)."""

    key_is_frame = True

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_filters: int,
        feature_dim: int,
        channels_last: bool = True,
        head: bool = True,
    ) -> None:
        super().__init__(frame_shape, 1, num_filters, feature_dim, channels_last, head)

    def forward(self, obs: torch.Tensor, frame_features: bool = False) -> Encoding:
        return super().forward(obs[:, -1:], frame_features)


class FlareEncoder(OnePathEncoder):
    """Ablation "flare" (latent flow, Shang et al. 2021): each frame through one conv path, then
    the flattened latents and their differences with the earlier frame detached, FC + LayerNorm."""

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_frames: int,
        num_filters: int,
        feature_dim: int,
        channels_last: bool = True,
    ) -> None:
        super().__init__(frame_shape[0], frame_shape, num_filters, channels_last)
        self.fc = nn.Linear((2 * num_frames - 1) * self.latent_dim, feature_dim)
        self.norm = nn.LayerNorm(feature_dim)
        self.repr_dim = feature_dim

    def encode_key(self, view: torch.Tensor) -> torch.Tensor:
        n, k = view.shape[:2]
        maps = self.convs(self.trunk_input(view.flatten(0, 1)))
        z = maps.permute(0, 2, 3, 1).reshape(n, k, -1)
        flow = z[:, 1:] - z[:, :-1].detach()
        return self.norm(self.fc(torch.cat([z.flatten(1), flow.flatten(1)], dim=1)))


class DualPathEncoder(PixelEncoder):
    """The motion path E^m and appearance path E^a of Sec. 3.2, optionally with the structural
    interactive module (Eq. 4-6); the state is f = [f^m_t, f^a_t].

    The motion path sees the residuals [o_{t-1} - o_{t-2}, o_t - o_{t-1}] computed on the fly from
    the uint8 frames (as float); the appearance path sees each frame. f^a in the state is that of
    frame t (after the interactive module when there is one).

    Example:
        >>> import torch
        >>> enc = DualPathEncoder((3, 84, 84))
        >>> obs = torch.randint(0, 256, (2, 3, 3, 84, 84), dtype=torch.uint8)
        >>> enc(obs).state.shape
        torch.Size([2, 100])
    """

    key_is_frame = True

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_filters: int = 32,
        feature_dim: int = 50,
        interactive: bool = True,
        reduce_kernel: int = 3,
        reduce_stride: int = 3,
        detach_past_frames: bool = True,
        channels_last: bool = True,
    ) -> None:
        super().__init__(channels_last)
        c = frame_shape[0]
        flat = trunk_dim(frame_shape, num_filters)
        self.appearance = conv_trunk(c, num_filters)
        self.motion = conv_trunk(2 * c, num_filters)
        self.head_appearance = Head(flat, feature_dim)
        self.head_motion = Head(flat, feature_dim)
        self.interaction = (
            StructuralInteraction(num_filters, reduce_kernel, reduce_stride)
            if interactive
            else None
        )
        self.detach_past_frames = detach_past_frames
        self.repr_dim = 2 * feature_dim

    def appearance_maps(self, frame: torch.Tensor) -> torch.Tensor:
        """E^a on float frames ``(B, C, H, W)`` -> F^a ``(B, c, h, w)``."""
        return self.appearance(self.trunk_input(frame))

    def motion_maps(self, frames: Sequence[torch.Tensor]) -> torch.Tensor:
        """E^m on the residual pair [(o_{t-1} - o_{t-2}), (o_t - o_{t-1})] of three float frames
        ``(B, C, H, W)``, channels concatenated -> F^m_t ``(B, c, h, w)``."""
        pair = torch.cat([frames[1] - frames[0], frames[2] - frames[1]], dim=1)
        return self.motion(self.trunk_input(pair))

    def encode_key(self, view: torch.Tensor) -> torch.Tensor:
        return self.head_appearance(self.appearance_maps(view))

    def encode_maps(
        self,
        motion: torch.Tensor,
        frames: Sequence[torch.Tensor],
        reduced: Sequence[torch.Tensor] | None = None,
        anchor: bool = True,
        frame_features: bool = False,
    ) -> Encoding:
        """From F^m_t and the F^a of frames t-2, t-1, t (each ``(B, c, h, w)``) to the features:
        the interactive module (Eq. 4-6, reusing ``reduced`` appearance maps when given), then
        FC + LayerNorm per path (Alg. 1, lines 6-14)."""
        masks = None
        if self.interaction is None:
            plain = f_a = self.head_appearance(frames[2])
            f_m = self.head_motion(motion)
        else:
            # Eq. 6 then FC + LN: FC(F + beta * resize(X.Fh)) = FC(F) + beta * (W R)(X.Fh), so the
            # enhanced maps are never built and f^a_t before / after interaction share FC(F^a_t)
            masks = self.interaction.masks(motion, frames, reduced)
            size = tuple(motion.shape[-2:])
            beta_m, beta_a = self.interaction.beta_motion, self.interaction.beta_appearance
            hm, ha = self.head_motion, self.head_appearance
            f_m = hm.norm(hm.linear(motion) + beta_m * hm.modulation(masks.motion, size))
            linear_a = ha.linear(frames[2])
            f_a = ha.norm(linear_a + beta_a * ha.modulation(masks.appearance, size))
            plain = ha.norm(linear_a)
        appearance = None
        if frame_features:
            with torch.no_grad():
                earlier = [self.head_appearance(frames[0]), self.head_appearance(frames[1])]
            appearance = torch.stack([*earlier, plain.detach()], dim=1)
        return Encoding(
            state=torch.cat([f_m, f_a], dim=1),
            anchor=plain if anchor else None,
            motion=f_m,
            appearance=appearance,
            masks=masks,
        )

    def forward(self, obs: torch.Tensor, frame_features: bool = False) -> Encoding:
        if obs.shape[1] != 3:
            raise ValueError(
                f"DualPathEncoder needs 3 frames (t-2, t-1, t) per observation, got shape "
                f"{tuple(obs.shape)}; use FrameTriplet / SimounObservation with num_frames=3"
            )
        x = self.frame_stack(obs)
        stack = self.appearance_maps(x.flatten(0, 1))
        frames = stack.unflatten(0, x.shape[:2]).unbind(0)
        reduced = None
        if self.interaction is not None:  # one call for the three frames, not three
            reduced = self.interaction.reduce_appearance(stack).unflatten(0, x.shape[:2]).unbind(0)
        return self.encode_maps(self.motion_maps(x), frames, reduced, True, frame_features)

    def encode_transition(
        self, window: torch.Tensor, frame_features: bool = False, next_frame_features: bool = False
    ) -> tuple[Encoding, Encoding]:
        """Each unique frame through each path once, with gradient only where a loss needs it:
        F^a of frame t with gradient, of t+1 without, of t-2 and t-1 without when
        ``detach_past_frames`` (else with); F^m of the pair ending at t with gradient, of the pair
        ending at t+1 without; each reduced appearance map of the interactive module once."""
        x = self.frame_stack(window)
        with torch.set_grad_enabled(torch.is_grad_enabled() and not self.detach_past_frames):
            past = [self.appearance_maps(x[0]), self.appearance_maps(x[1])]
        frames = [*past, self.appearance_maps(x[2])]
        reduced = None
        if self.interaction is not None:
            reduced = [self.interaction.reduce_appearance(f) for f in frames]
        current = self.encode_maps(self.motion_maps(x[:3]), frames, reduced, True, frame_features)
        with torch.no_grad():
            frames_next = [frames[1], frames[2].detach(), self.appearance_maps(x[3])]
            reduced_next = None
            if reduced is not None:
                reduced_next = [
                    reduced[1].detach(),
                    reduced[2].detach(),
                    self.interaction.reduce_appearance(frames_next[2]),
                ]
            following = self.encode_maps(
                self.motion_maps(x[1:]), frames_next, reduced_next, False, next_frame_features
            )
        return current, following


@dataclass(frozen=True)
class EncoderEntry:
    """How to build one registered encoder, and what it offers the losses."""

    build: Callable[[AgentConfig, tuple[int, int, int]], PixelEncoder]
    """(config, frame shape (C, H, W)) -> the encoder"""
    shape: EncoderShape
    """its paths and convs, as the configuration knows them
    (:data:`simoun_agent.config.shapes.ENCODER_SHAPES`)"""
    description: str
    """one line for help texts"""

    @property
    def motion_path(self) -> bool:
        """True: separate motion and appearance paths (L_tran on f^m, curiosity of Eq. 13)."""
        return self.shape.motion_path


def _dual(name: str) -> Callable[[AgentConfig, tuple[int, int, int]], PixelEncoder]:
    """The builder of the dual-path encoder ``name``, with the interactive module when its
    shape has one."""

    def build(c: AgentConfig, shape: tuple[int, int, int]) -> PixelEncoder:
        return DualPathEncoder(
            shape,
            c.num_filters,
            c.feature_dim,
            interactive=ENCODER_SHAPES[name].interactive,
            reduce_kernel=c.reduce_kernel,
            reduce_stride=c.reduce_stride,
            detach_past_frames=c.detach_past_frames,
            channels_last=c.channels_last,
        )

    return build


def _stacked(filters_per_path: int) -> Callable[[AgentConfig, tuple[int, int, int]], PixelEncoder]:
    """A builder of the stacked encoder with ``filters_per_path`` times ``num_filters`` filters."""

    def build(c: AgentConfig, shape: tuple[int, int, int]) -> PixelEncoder:
        return StackedEncoder(
            shape,
            c.num_frames,
            filters_per_path * c.num_filters,
            c.feature_dim,
            c.channels_last,
            not c.separate_trunks,
        )

    return build


ENCODERS: dict[str, EncoderEntry] = {
    "single": EncoderEntry(
        lambda c, shape: SingleFrameEncoder(
            shape, c.num_filters, c.feature_dim, c.channels_last, not c.separate_trunks
        ),
        shape=ENCODER_SHAPES["single"],
        description="one conv path on frame t only",
    ),
    "stacked": EncoderEntry(
        _stacked(filters_per_path=1),
        shape=ENCODER_SHAPES["stacked"],
        description="one conv path on the frames folded into channels (CURL, DrQ)",
    ),
    "stacked_wide": EncoderEntry(
        _stacked(filters_per_path=2),
        shape=ENCODER_SHAPES["stacked_wide"],
        description="stacked with twice the filters (about the dual path's parameter count)",
    ),
    "flare": EncoderEntry(
        lambda c, shape: FlareEncoder(
            shape, c.num_frames, c.num_filters, c.feature_dim, c.channels_last
        ),
        shape=ENCODER_SHAPES["flare"],
        description="per-frame convs with latent differences (Flare, Shang et al. 2021)",
    ),
    "dual": EncoderEntry(
        _dual("dual"),
        shape=ENCODER_SHAPES["dual"],
        description="motion path on residuals + appearance path per frame (Sec. 3.2)",
    ),
    "dual_interactive": EncoderEntry(
        _dual("dual_interactive"),
        shape=ENCODER_SHAPES["dual_interactive"],
        description="dual with the structural interactive module (Eq. 4-6), the paper's model",
    ),
}
"""The encoders of Fig. 6 by ``AgentConfig.encoder`` name; a new encoder is one entry here and
one in :data:`simoun_agent.config.shapes.ENCODER_SHAPES` (its paths and convs)."""


def make_encoder(config: AgentConfig, frame_shape: tuple[int, int, int]) -> PixelEncoder:
    """Build the encoder named by ``config.encoder`` (the variants of Fig. 6) from
    :data:`ENCODERS`, initialised by ``config.conv_init``, reading x / 255 - ``pixel_offset``, in
    its conv memory format.

    A ``config`` that is no AgentConfig, or a ``frame_shape`` the encoder cannot take
    (channel-last, too small for its conv trunk), is refused naming the argument, as
    ``SimounAgent`` refuses them."""
    if not isinstance(config, AgentConfig):
        raise TypeError(
            f"make_encoder(config=...) must be an AgentConfig, got {type(config).__name__} "
            f"{config!r:.60}; e.g. make_encoder(AgentConfig(encoder='dual'), (3, 84, 84)), or "
            "AgentConfig(**values) for a dict"
        )
    check_frame_shape(frame_shape, config)
    encoder = ENCODERS[config.encoder].build(config, tuple(frame_shape))
    encoder.apply(functools.partial(weight_init, conv=config.conv_init))
    encoder.pixel_offset = config.pixel_offset
    return encoder.to(memory_format=encoder.memory_format)
