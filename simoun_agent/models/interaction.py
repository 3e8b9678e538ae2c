"""The structural interactive module between the motion and appearance paths (Eq. 4-6)."""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import NamedTuple

import torch
import torch.nn.functional as F
from torch import nn


class StructureMasks(NamedTuple):
    """Inter-frame attention X ``(N, hw, hw)`` and masks X^m, X^a ``(N, c, h, w)`` (Fig. 7)."""

    attention: torch.Tensor
    motion: torch.Tensor
    appearance: torch.Tensor


def inter_frame_attention(
    key_prev2: torch.Tensor, query: torch.Tensor, key_cur: torch.Tensor
) -> torch.Tensor:
    """Eq. 4: X = softmax(softmax(Fh_{t-2}^T Fh_{t-1}) + softmax(Fh_t^T Fh_{t-1})).

    Inputs are reduced maps ``(N, c, h, w)``; ``query`` is frame t-1, the keys frames t-2 and t.
    Returns ``X`` of shape ``(N, hw, hw)``: one row per query position, a distribution over key
    positions (rows sum to 1). Scores are scaled by 1/sqrt(c) as in dot-product attention so the
    inner softmaxes do not saturate at initialisation.
    """
    q = query.flatten(2).transpose(1, 2)
    scale = q.shape[-1] ** -0.5
    s_prev2 = torch.softmax(scale * (q @ key_prev2.flatten(2)), dim=-1)
    s_cur = torch.softmax(scale * (q @ key_cur.flatten(2)), dim=-1)
    return torch.softmax(s_prev2 + s_cur, dim=-1)


def structure_mask(attention: torch.Tensor, reduced: torch.Tensor) -> torch.Tensor:
    """Eq. 5: X . Fh, spatial gating of a reduced map ``(N, c, h, w)`` by ``X`` ``(N, hw, hw)``."""
    n, c, h, w = reduced.shape
    gated = attention @ reduced.flatten(2).transpose(1, 2)
    return gated.transpose(1, 2).reshape(n, c, h, w)


@functools.lru_cache(maxsize=16)
def _linear_resize_matrix(
    out_size: int, in_size: int, device: torch.device, dtype: torch.dtype
) -> torch.Tensor:
    with torch.inference_mode(False), torch.no_grad():  # cached: must not be an inference tensor
        eye = torch.eye(in_size, device=device, dtype=dtype).unsqueeze(1)
        weights = F.interpolate(eye, size=out_size, mode="linear", align_corners=False)
        return weights.squeeze(1).T.contiguous()


def resize_bilinear(maps: torch.Tensor, size: tuple[int, int]) -> torch.Tensor:
    """Bilinear resize of ``(N, c, h, w)`` to ``size`` (same result as ``F.interpolate(...,
    mode="bilinear", align_corners=False)``) as two small matmuls, whose backward on CPU is far
    cheaper than interpolate's."""
    rows = _linear_resize_matrix(size[0], maps.shape[-2], maps.device, maps.dtype)
    cols = _linear_resize_matrix(size[1], maps.shape[-1], maps.device, maps.dtype)
    return rows @ maps @ cols.T


def resized_linear(mask: torch.Tensor, weight: torch.Tensor, size: tuple[int, int]) -> torch.Tensor:
    """``resize_bilinear(mask, size)`` flattened in (h, w, c) order, times ``weight.T``. In
    training the resized map is never built: the resize is linear, so
    it folds into the weight (``weight`` is ``(D, H*W*c)`` for the full-size map; the folded
    weight is ``(D, h*w*c)``); one or two samples without gradient resize the map instead."""
    n, c, h, w = mask.shape
    d = weight.shape[0]
    needs_grad = torch.is_grad_enabled() and (mask.requires_grad or weight.requires_grad)
    if n <= 2 and not needs_grad:
        # act() on one observation: the fold (two bmm over the whole FC weight) took 1.0 ms per
        # head against 0.5 ms for resizing the map (1 thread, 35x35 / 11x11); the fold is
        # faster from 3 samples on, and with gradients at every batch size
        resized = F.interpolate(mask, size=size, mode="bilinear", align_corners=False)
        return resized.permute(0, 2, 3, 1).flatten(1) @ weight.T
    rows = _linear_resize_matrix(size[0], h, mask.device, mask.dtype)
    cols = _linear_resize_matrix(size[1], w, mask.device, mask.dtype)
    # sum over H then W as two batched matmuls on views: (h, H) @ (d, H, W*c) -> (d, h, W*c),
    # then (w, W) @ (d*h, W, c) -> (d*h, w, c); no copy of the (D, H*W*c) weight
    folded = rows.T @ weight.view(d, size[0], size[1] * c)
    folded = cols.T @ folded.view(d * h, size[1], c)
    return mask.permute(0, 2, 3, 1).flatten(1) @ folded.view(d, h * w * c).T


class StructuralInteraction(nn.Module):
    """Inter-frame attention between the two paths, modulating both feature maps (Eq. 4-6).

    Two reducing convs (one for the appearance maps, shared by the three frames, one for the motion
    map) keep the channel count and shrink the maps, e.g. 35x35 -> 11x11 with kernel 3 / stride 3,
    so X is 121 x 121. The masks X.Fh are resized back to the feature-map size bilinearly and added
    with a learnable scale per path initialised to 0 (Eq. 6), so the module starts as the identity.

    Example:
        >>> import torch
        >>> sim = StructuralInteraction(channels=32)
        >>> f_m, frames = torch.rand(2, 32, 35, 35), [torch.rand(2, 32, 35, 35) for _ in range(3)]
        >>> out_m, out_a, masks = sim(f_m, frames)
        >>> out_m.shape, masks.attention.shape
        (torch.Size([2, 32, 35, 35]), torch.Size([2, 121, 121]))
    """

    def __init__(self, channels: int, kernel_size: int = 3, stride: int = 3) -> None:
        super().__init__()
        self.reduce_appearance = nn.Conv2d(channels, channels, kernel_size, stride)
        self.reduce_motion = nn.Conv2d(channels, channels, kernel_size, stride)
        self.beta_motion = nn.Parameter(torch.zeros(()))
        self.beta_appearance = nn.Parameter(torch.zeros(()))

    def masks(
        self,
        motion: torch.Tensor,
        frames: Sequence[torch.Tensor],
        reduced: Sequence[torch.Tensor] | None = None,
    ) -> StructureMasks:
        """Eq. 4-5 from F^m_t ``(N, c, h, w)`` and the appearance maps ``frames`` of t-2, t-1, t
        (each ``(N, c, h, w)``); ``reduced`` may give their reduced maps when already computed."""
        if reduced is None:
            reduced = [self.reduce_appearance(f) for f in frames]
        attention = inter_frame_attention(*reduced)
        mask_m = structure_mask(attention, self.reduce_motion(motion))
        mask_a = structure_mask(attention, reduced[2])
        return StructureMasks(attention, mask_m, mask_a)

    def forward(
        self,
        motion: torch.Tensor,
        frames: Sequence[torch.Tensor],
        reduced: Sequence[torch.Tensor] | None = None,
    ) -> tuple[torch.Tensor, torch.Tensor, StructureMasks]:
        """Eq. 6: the enhanced F^m_t and F^a_t (``frames[2]``) as maps, and the masks.

        ``DualPathEncoder`` computes the same features without building these maps (it folds the
        resize into its FC layers, see :func:`resized_linear`)."""
        masks = self.masks(motion, frames, reduced)
        size = motion.shape[-2:]
        enhanced_m = motion + self.beta_motion * resize_bilinear(masks.motion, size)
        enhanced_a = frames[2] + self.beta_appearance * resize_bilinear(masks.appearance, size)
        return enhanced_m, enhanced_a, masks
