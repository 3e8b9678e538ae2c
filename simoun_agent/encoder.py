"""Pixel encoders: the dual-path encoder (Sec. 3.2) and the ablation variants of Fig. 6.

Every encoder maps a uint8 observation ``(B, k, C, H, W)`` (k frames, oldest first) to an
:class:`Encoding`. Frames become float (x / 255) on the device inside ``forward``, so the replay
and the environment only ever hold uint8. An optional ``key_view`` (augmented input, float) is run
through the same convs in the same call and returned as ``Encoding.key``: the agent passes it to
the momentum encoder to get the contrastive positives without a second conv call.
"""

from __future__ import annotations

from typing import NamedTuple

import torch
from torch import nn

from simoun_agent.config import AgentConfig
from simoun_agent.interaction import StructuralInteraction, StructureMasks


class Encoding(NamedTuple):
    """What one encoder pass produces (``None`` where the encoder has no such part)."""

    state: torch.Tensor
    """(B, repr_dim) the state representation f_t fed to the actor and critic"""
    anchor: torch.Tensor
    """(B, feature_dim) contrastive anchor (Eq. 3): f^a_t without interaction, or the state"""
    key: torch.Tensor | None = None
    """(B, feature_dim) features of ``key_view`` when one was given"""
    motion: torch.Tensor | None = None
    """(B, feature_dim) f^m_t as used in the state (after the interactive module)"""
    appearance: torch.Tensor | None = None
    """(B, 3, feature_dim) f^a of frames t-2, t-1, t without interaction (no gradient for t-2,
    t-1); only when ``frame_features=True``"""
    masks: StructureMasks | None = None
    """attention X and masks X^m, X^a of the interactive module"""


def conv_output_size(size: int) -> int:
    """Side of the last feature map of :func:`conv_trunk` (84 -> 41 -> 39 -> 37 -> 35)."""
    return (size - 3) // 2 + 1 - 6


def conv_trunk(in_channels: int, num_filters: int) -> nn.Sequential:
    """Four 3x3 convs with ReLU, strides 2, 1, 1, 1 (the paths of Sec. 3.2, CURL's encoder)."""
    layers: list[nn.Module] = []
    for i in range(4):
        layers += [
            nn.Conv2d(in_channels if i == 0 else num_filters, num_filters, 3, 2 if i == 0 else 1),
            nn.ReLU(),
        ]
    return nn.Sequential(*layers)


class Head(nn.Module):
    """FC + LayerNorm from a feature map ``(N, c, h, w)`` to a vector (Alg. 1, lines 11-12).

    The map is flattened in (h, w, c) order: a free view of a channels-last tensor.
    """

    def __init__(self, in_features: int, feature_dim: int) -> None:
        super().__init__()
        self.fc = nn.Linear(in_features, feature_dim)
        self.norm = nn.LayerNorm(feature_dim)

    def forward(self, maps: torch.Tensor) -> torch.Tensor:
        return self.norm(self.fc(maps.permute(0, 2, 3, 1).flatten(1)))


def weight_init(module: nn.Module) -> None:
    """Orthogonal weights and zero biases for linear and conv layers (DrQ / SAC-AE practice)."""
    if isinstance(module, (nn.Linear, nn.Conv2d)):
        gain = nn.init.calculate_gain("relu") if isinstance(module, nn.Conv2d) else 1.0
        nn.init.orthogonal_(module.weight, gain)
        nn.init.zeros_(module.bias)


class PixelEncoder(nn.Module):
    """Base class: uint8 frames in, :class:`Encoding` out."""

    repr_dim: int
    key_is_frame: bool
    """True: the contrastive view is frame t ``(B, C, H, W)``; False: the whole stack"""

    def __init__(self, channels_last: bool = True) -> None:
        super().__init__()
        self.memory_format = torch.channels_last if channels_last else torch.contiguous_format

    def to_float(self, obs: torch.Tensor) -> torch.Tensor:
        """uint8 -> float in [0, 1]."""
        return obs.float().div_(255.0)

    def key_frames(self, obs: torch.Tensor) -> torch.Tensor:
        """The float frames whose augmented view is the contrastive positive (Eq. 3)."""
        x = self.to_float(obs[:, -1] if self.key_is_frame else obs)
        return x

    def trunk_input(self, x: torch.Tensor) -> torch.Tensor:
        return x.contiguous(memory_format=self.memory_format)

    def forward(
        self, obs: torch.Tensor, key_view: torch.Tensor | None = None, frame_features: bool = False
    ) -> Encoding:
        raise NotImplementedError


class SingleFrameEncoder(PixelEncoder):
    """Ablation "single": one conv path on frame t only."""

    key_is_frame = True

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_filters: int,
        feature_dim: int,
        channels_last: bool = True,
    ) -> None:
        super().__init__(channels_last)
        c, h, w = frame_shape
        self.convs = conv_trunk(c, num_filters)
        self.head = Head(num_filters * conv_output_size(h) * conv_output_size(w), feature_dim)
        self.repr_dim = feature_dim

    def forward(self, obs, key_view=None, frame_features=False):
        x = self.to_float(obs[:, -1])
        if key_view is not None:
            x = torch.cat([x, key_view])
        f = self.head(self.convs(self.trunk_input(x)))
        n = obs.shape[0]
        return Encoding(state=f[:n], anchor=f[:n], key=None if key_view is None else f[n:])


class StackedEncoder(PixelEncoder):
    """Ablations "stacked" / "stacked_wide": one conv path on the k frames folded into kC
    channels."""

    key_is_frame = False

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_frames: int,
        num_filters: int,
        feature_dim: int,
        channels_last: bool = True,
    ) -> None:
        super().__init__(channels_last)
        c, h, w = frame_shape
        self.convs = conv_trunk(num_frames * c, num_filters)
        self.head = Head(num_filters * conv_output_size(h) * conv_output_size(w), feature_dim)
        self.repr_dim = feature_dim

    def forward(self, obs, key_view=None, frame_features=False):
        x = self.to_float(obs)
        if key_view is not None:
            x = torch.cat([x, key_view])
        f = self.head(self.convs(self.trunk_input(x.flatten(1, 2))))
        n = obs.shape[0]
        return Encoding(state=f[:n], anchor=f[:n], key=None if key_view is None else f[n:])


class FlareEncoder(PixelEncoder):
    """Ablation "flare" (latent flow, Shang et al. 2021): each frame through one conv path, then
    the flattened latents and their differences with the earlier frame detached, FC + LayerNorm."""

    key_is_frame = False

    def __init__(
        self,
        frame_shape: tuple[int, int, int],
        num_frames: int,
        num_filters: int,
        feature_dim: int,
        channels_last: bool = True,
    ) -> None:
        super().__init__(channels_last)
        c, h, w = frame_shape
        self.convs = conv_trunk(c, num_filters)
        latent = num_filters * conv_output_size(h) * conv_output_size(w)
        self.fc = nn.Linear((2 * num_frames - 1) * latent, feature_dim)
        self.norm = nn.LayerNorm(feature_dim)
        self.repr_dim = feature_dim

    def forward(self, obs, key_view=None, frame_features=False):
        x = self.to_float(obs)
        if key_view is not None:
            x = torch.cat([x, key_view])
        n, k = x.shape[:2]
        maps = self.convs(self.trunk_input(x.flatten(0, 1)))
        z = maps.permute(0, 2, 3, 1).reshape(n, k, -1)
        flow = z[:, 1:] - z[:, :-1].detach()
        f = self.norm(self.fc(torch.cat([z.flatten(1), flow.flatten(1)], dim=1)))
        b = obs.shape[0]
        return Encoding(state=f[:b], anchor=f[:b], key=None if key_view is None else f[b:])


class DualPathEncoder(PixelEncoder):
    """The motion path E^m and appearance path E^a of Sec. 3.2, optionally with the structural
    interactive module (Eq. 4-6); the state is f = [f^m_t, f^a_t].

    The motion path sees the residuals [o_{t-1} - o_{t-2}, o_t - o_{t-1}] computed on the fly from
    the uint8 triplet; the appearance path sees the three frames (and the contrastive view) in
    one batched conv call.

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
        reduce_kernel: int = 5,
        reduce_stride: int = 3,
        channels_last: bool = True,
    ) -> None:
        super().__init__(channels_last)
        c, h, w = frame_shape
        flat = num_filters * conv_output_size(h) * conv_output_size(w)
        self.appearance = conv_trunk(c, num_filters)
        self.motion = conv_trunk(2 * c, num_filters)
        self.head_appearance = Head(flat, feature_dim)
        self.head_motion = Head(flat, feature_dim)
        self.interaction = (
            StructuralInteraction(num_filters, reduce_kernel, reduce_stride)
            if interactive
            else None
        )
        self.repr_dim = 2 * feature_dim

    def forward(self, obs, key_view=None, frame_features=False):
        b, k = obs.shape[:2]
        if k != 3:
            raise ValueError(
                f"DualPathEncoder needs 3 frames per observation, got shape {tuple(obs.shape)}"
            )
        x = self.to_float(obs)
        frames = x.flatten(0, 1)
        if key_view is not None:
            frames = torch.cat([frames, key_view])
        maps = self.appearance(self.trunk_input(frames))
        per_frame = maps[: b * k].unflatten(0, (b, k))
        motion_maps = self.motion(
            self.trunk_input(torch.cat([x[:, 1] - x[:, 0], x[:, 2] - x[:, 1]], 1))
        )
        masks = None
        heads_in = [per_frame[:, 2]]
        if self.interaction is not None:
            motion_maps, enhanced, masks = self.interaction(motion_maps, per_frame)
            heads_in.insert(0, enhanced)
        if key_view is not None:
            heads_in.append(maps[b * k :])
        f_a = self.head_appearance(torch.cat(heads_in)).split(b)
        f_m = self.head_motion(motion_maps)
        anchor = f_a[1] if self.interaction is not None else f_a[0]
        appearance = None
        if frame_features:
            with torch.no_grad():
                earlier = self.head_appearance(per_frame[:, :2].flatten(0, 1)).unflatten(0, (b, 2))
            appearance = torch.cat([earlier, anchor.detach().unsqueeze(1)], dim=1)
        return Encoding(
            state=torch.cat([f_m, f_a[0]], dim=1),
            anchor=anchor,
            key=f_a[-1] if key_view is not None else None,
            motion=f_m,
            appearance=appearance,
            masks=masks,
        )


def make_encoder(config: AgentConfig, frame_shape: tuple[int, int, int]) -> PixelEncoder:
    """Build the encoder named by ``config.encoder`` (the variants of Fig. 6)."""
    kind, cl = config.encoder, config.channels_last
    if kind in ("dual", "dual_interactive"):
        encoder = DualPathEncoder(
            frame_shape,
            config.num_filters,
            config.feature_dim,
            kind == "dual_interactive",
            config.reduce_kernel,
            config.reduce_stride,
            cl,
        )
    elif kind == "single":
        encoder = SingleFrameEncoder(frame_shape, config.num_filters, config.feature_dim, cl)
    elif kind == "flare":
        encoder = FlareEncoder(
            frame_shape, config.num_frames, config.num_filters, config.feature_dim, cl
        )
    else:
        filters = config.num_filters * (2 if kind == "stacked_wide" else 1)
        encoder = StackedEncoder(frame_shape, config.num_frames, filters, config.feature_dim, cl)
    encoder.apply(weight_init)
    return encoder.to(memory_format=encoder.memory_format)
