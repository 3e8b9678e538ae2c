"""Pictures of the structure masks X^m and X^a (Eq. 5) over the frames the agent saw (Fig. 7).

A mask ``X . Fh`` is a ``(c, h, w)`` map on the reduced grid of the interactive module. Its heat
map is the magnitude across channels (the L2 norm of each position's c values), brought to the
image size bilinearly and drawn with a perceptual colour map over frame o_t. The attention row of
a query position is X[q, :] (Eq. 4): where, in frames t-2 and t, the module looks from position q
of frame t-1.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F

from simoun_agent.config import SetupError
from simoun_agent.models.encoder import PixelEncoder
from simoun_agent.models.interaction import StructureMasks
from simoun_agent.run.atomic import atomic_write
from simoun_lab.analysis.runs import (
    check_batch_size,
    check_encoder,
    check_fits,
    observation_batch,
)

COLORMAP = "magma"
"""Perceptual colour map of the heat maps (uniform in lightness, readable in grey)."""

OVERLAY_ALPHA = 0.6
"""Opacity of a heat map drawn over its frame."""

HEAT_NAMES = {
    "motion": "X^m: motion mask (Eq. 5)",
    "appearance": "X^a: appearance mask (Eq. 5)",
    "attention": "X row of query {query} (Eq. 4)",
}
"""Heat map keys and their panel titles."""


def require_masks(encoder: PixelEncoder, name: str) -> None:
    """SetupError unless ``encoder`` has the structural interactive module."""
    if getattr(encoder, "interaction", None) is None:
        raise SetupError(
            f"this run's encoder {name!r} has no structural interactive module, so it has no "
            "structure masks X^m, X^a (Eq. 5) to draw; masks need a run trained with "
            "agent.encoder=dual_interactive. The information-bias analysis works for every "
            "encoder: simoun-analyze bias RUN_DIR"
        )


def structure_masks(
    encoder: PixelEncoder, observations: np.ndarray, batch_size: int = 32
) -> StructureMasks:
    """Masks of uint8 observations ``(N, 3, C, H, W)`` (a numpy array or a torch tensor), on
    CPU (attention ``(N, hw, hw)``, masks ``(N, c, h, w)``)."""
    check_encoder(encoder, "structure_masks")
    check_batch_size(batch_size, "structure_masks")
    batch = observation_batch(observations, "structure_masks")
    check_fits(encoder, batch, "structure_masks")
    device = next(encoder.parameters()).device
    parts: list[StructureMasks] = []
    with torch.inference_mode():
        for start in range(0, len(batch), batch_size):
            chunk = batch[start : start + batch_size].to(device)
            masks = encoder(chunk).masks
            parts.append(StructureMasks(*(part.float().cpu() for part in masks)))
    return StructureMasks(*(torch.cat(column) for column in zip(*parts, strict=True)))


def mask_heat(mask: torch.Tensor, size: tuple[int, int]) -> np.ndarray:
    """``(N, c, h, w)`` mask -> ``(N, H, W)`` magnitude across channels, resized bilinearly."""
    magnitude = torch.linalg.vector_norm(mask, dim=1, keepdim=True)
    resized = F.interpolate(magnitude, size=size, mode="bilinear", align_corners=False)
    return resized[:, 0].numpy()


def query_index(query: tuple[int, int], image: tuple[int, int], grid: tuple[int, int]) -> int:
    """Row of X for pixel ``query`` (row, col) of an ``image``-sized frame: the position of the
    ``grid``-sized reduced map at the same fraction of the height and width."""
    row, col = query
    if not (0 <= row < image[0] and 0 <= col < image[1]):
        raise SetupError(
            f"--query {row},{col} is outside the {image[0]} x {image[1]} frame; pass ROW,COL "
            f"with 0 <= ROW < {image[0]} and 0 <= COL < {image[1]}"
        )
    return (row * grid[0] // image[0]) * grid[1] + col * grid[1] // image[1]


def attention_heat(
    attention: torch.Tensor, index: int, grid: tuple[int, int], size: tuple[int, int]
) -> np.ndarray:
    """Row ``index`` of X ``(N, hw, hw)`` as ``(N, H, W)`` over the image, resized bilinearly."""
    row = attention[:, index].reshape(-1, 1, *grid)
    return F.interpolate(row, size=size, mode="bilinear", align_corners=False)[:, 0].numpy()


def heat_maps(
    masks: StructureMasks, size: tuple[int, int], query: tuple[int, int] | None
) -> dict[str, np.ndarray]:
    """``{"motion", "appearance"[, "attention"]: (N, H, W)}`` for images of ``size``."""
    heats = {
        "motion": mask_heat(masks.motion, size),
        "appearance": mask_heat(masks.appearance, size),
    }
    if query is not None:
        grid = tuple(masks.motion.shape[-2:])
        heats["attention"] = attention_heat(
            masks.attention, query_index(query, size, grid), grid, size
        )
    return heats


def to_rgb(frame: np.ndarray) -> np.ndarray:
    """Channel-first uint8 ``(C, H, W)`` (C = 1 or 3) -> ``(H, W, 3)``."""
    image = frame.transpose(1, 2, 0)
    return np.repeat(image, 3, axis=2) if image.shape[2] == 1 else np.ascontiguousarray(image)


def overlay(frame: np.ndarray, heat: np.ndarray) -> np.ndarray:
    """``(H, W, 3)`` uint8: the heat map, scaled to its own range, blended over the frame."""
    from matplotlib import colormaps

    span = float(np.ptp(heat))
    scaled = (heat - heat.min()) / span if span > 0 else np.zeros_like(heat)
    colours = colormaps[COLORMAP](scaled)[..., :3] * 255.0
    blended = (1 - OVERLAY_ALPHA) * to_rgb(frame) + OVERLAY_ALPHA * colours
    return blended.round().astype(np.uint8)


def is_wide(frame: np.ndarray) -> bool:
    """Multi-camera frames (e.g. 84 x 252) are laid out one panel per row."""
    return frame.shape[2] >= 2 * frame.shape[1]


def composite(frame: np.ndarray, heats: dict[str, np.ndarray]) -> np.ndarray:
    """Frame and overlays side by side (one above the other for wide frames), ``(3, H', W')``."""
    panels = [to_rgb(frame)] + [overlay(frame, heat) for heat in heats.values()]
    return np.concatenate(panels, axis=0 if is_wide(frame) else 1).transpose(2, 0, 1)


def draw_figure(
    path: Path,
    frame: np.ndarray,
    heats: dict[str, np.ndarray],
    title: str,
    query: tuple[int, int] | None = None,
) -> Path:
    """Write a PNG: o_t, then each heat map over it with a colour bar of its own values."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    height, width = frame.shape[1:]
    count = 1 + len(heats)
    wide = is_wide(frame)
    panel = (7.0, 7.0 * height / width) if wide else (3.2 * width / height + 0.9, 3.2)
    rows, cols = (count, 1) if wide else (1, count)
    figure = Figure(figsize=(panel[0] * cols, (panel[1] + 0.5) * rows + 0.4), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(rows, cols, squeeze=False).ravel()
    image = to_rgb(frame)
    axes[0].imshow(image, interpolation="nearest")
    axes[0].set_title("o_t")
    for ax, (name, heat) in zip(axes[1:], heats.items(), strict=True):
        ax.imshow(image, interpolation="nearest")
        shown = ax.imshow(heat, cmap=COLORMAP, alpha=OVERLAY_ALPHA, interpolation="nearest")
        figure.colorbar(shown, ax=ax, fraction=0.046, pad=0.02)
        ax.set_title(HEAT_NAMES[name].format(query=query))
        if name == "attention" and query is not None:
            ax.plot(query[1], query[0], marker="+", color="cyan", markersize=12, mew=2)
    for ax in axes:
        ax.set_axis_off()
    figure.suptitle(title)
    atomic_write(path, lambda tmp: figure.savefig(tmp, format="png", dpi=100))
    return path


def default_steps(length: int, count: int = 4) -> list[int]:
    """``count`` steps evenly spread from 2 (three real frames) to the episode's last."""
    first = min(2, length)
    return sorted({int(s) for s in np.linspace(first, length, count).round()})
