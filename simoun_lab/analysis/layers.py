"""The layers the information-bias analysis reads, for every encoder of Fig. 6.

Each path's last feature map, averaged over its positions (one value per channel, the units of
Kowal et al.), and the fused state f_t fed to the actor and critic. For the interactive dual
encoder the path maps are the enhanced maps of Eq. 6, the ones its FC layers read.
"""

from __future__ import annotations

import functools

import numpy as np
import torch

from simoun_agent.config import SetupError
from simoun_agent.models.encoder import (
    DualPathEncoder,
    FlareEncoder,
    PixelEncoder,
    SingleFrameEncoder,
    StackedEncoder,
)
from simoun_lab.analysis.runs import (
    check_batch_size,
    check_encoder,
    check_fits,
    observation_batch,
)

PATH, MOTION, APPEARANCE, STATE = "path", "motion path", "appearance path", "fused state"
"""Layer names: the conv path of a single-path encoder, the two paths of a dual encoder, f_t."""


def pooled(maps: torch.Tensor) -> torch.Tensor:
    """``(B, c, h, w)`` -> ``(B, c)``: each channel averaged over its positions."""
    return maps.float().mean(dim=(2, 3))


@functools.singledispatch
def feature_layers(encoder: PixelEncoder, obs: torch.Tensor) -> dict[str, torch.Tensor]:
    """``{layer name: (B, units)}`` for uint8 observations ``(B, k, C, H, W)``."""
    raise SetupError(
        f"the information-bias analysis does not know the layers of {type(encoder).__name__}; "
        "register a function for it with simoun_lab.analysis.layers.feature_layers.register"
    )


@feature_layers.register
def _stacked(encoder: StackedEncoder, obs: torch.Tensor) -> dict[str, torch.Tensor]:
    stack = encoder.to_float(obs).flatten(1, 2)
    maps = encoder.convs(encoder.trunk_input(stack))
    return {PATH: pooled(maps), STATE: encoder.head(maps)}


@feature_layers.register
def _single(encoder: SingleFrameEncoder, obs: torch.Tensor) -> dict[str, torch.Tensor]:
    return _stacked(encoder, obs[:, -1:])


@feature_layers.register
def _flare(encoder: FlareEncoder, obs: torch.Tensor) -> dict[str, torch.Tensor]:
    # the conv path sees one frame at a time: its map of frame t stands for the path
    frame_t = encoder.to_float(obs[:, -1])
    return {PATH: pooled(encoder.convs(encoder.trunk_input(frame_t))), STATE: encoder(obs).state}


@feature_layers.register
def _dual(encoder: DualPathEncoder, obs: torch.Tensor) -> dict[str, torch.Tensor]:
    x = encoder.frame_stack(obs)
    frames = [encoder.appearance_maps(x[j]) for j in range(3)]
    motion = encoder.motion_maps(x)
    appearance = frames[2]
    if encoder.interaction is not None:
        motion, appearance, _ = encoder.interaction(motion, frames)
    state = encoder(obs).state
    return {MOTION: pooled(motion), APPEARANCE: pooled(appearance), STATE: state}


def layer_activations(
    encoder: PixelEncoder, observations: torch.Tensor | np.ndarray, batch_size: int = 64
) -> dict[str, torch.Tensor]:
    """:func:`feature_layers` over many uint8 observations ``(N, k, C, H, W)`` (a torch tensor
    or a numpy array), in batches, without gradient, on CPU."""
    check_encoder(encoder, "layer_activations")
    check_batch_size(batch_size, "layer_activations")
    batch = observation_batch(observations, "layer_activations")
    check_fits(encoder, batch, "layer_activations", feature_layers)
    parts: dict[str, list[torch.Tensor]] = {}
    device = next(encoder.parameters()).device
    with torch.inference_mode():
        for start in range(0, len(batch), batch_size):
            chunk = batch[start : start + batch_size].to(device)
            for name, value in feature_layers(encoder, chunk).items():
                parts.setdefault(name, []).append(value.float().cpu())
    return {name: torch.cat(values) for name, values in parts.items()}
