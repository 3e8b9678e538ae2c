"""Named agent recipes: Simoun, its baselines (DrQ, CURL, pixel SAC) and the Fig. 6 encoders.

A recipe is a small set of ``AgentConfig`` values, applied after a preset and before the user's
overrides (``simoun-train --agent.recipe drq --agent.lr 3e-4``), so every method runs in the
same code with the same replay, networks and training loop, and differs only where its paper
says it does. The recipe's name is saved with the resolved values in ``config.json``.

Shared by every recipe unless it says otherwise: CURL / SAC-AE's SAC settings (init
temperature 0.1, temperature lr 1e-4 with Adam beta1 0.5, critic tau 0.01, encoder tau 0.05,
actor and targets updated every 2 steps), which the paper's agent follows too.

Example:
    >>> from simoun_agent.recipes import RECIPES
    >>> RECIPES["drq"].values["encoder"], RECIPES["drq"].values["augmentation"]
    ('stacked', 'shift')
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Recipe:
    """One method or ablation as ``AgentConfig`` values."""

    description: str
    """one line for help texts and reports"""
    values: dict[str, Any]
    """AgentConfig field -> value"""


NO_AUXILIARY = {
    "transition_weight": 0.0,
    "contrastive_weight": 0.0,
    "reward_weight": 0.0,
    "curiosity": False,
}
"""Plain SAC on the encoder: no L_tran, L_con, L_re and no intrinsic reward."""

SIMOUN_LOSSES = {"transition_weight": 1.0, "contrastive_weight": 1.0, "reward_weight": 1.0}
"""Eq. 14's representation losses, given to every Fig. 6 encoder so the ablation compares
encoders, not losses (single-path encoders apply L_tran to their state)."""


def _encoder_ablation(encoder: str, what: str) -> Recipe:
    return Recipe(
        f"Fig. 6 ablation: {what}, with Simoun's L_tran + L_con + L_re and no curiosity",
        {"encoder": encoder, **SIMOUN_LOSSES, "curiosity": False},
    )


RECIPES: dict[str, Recipe] = {
    "simoun": Recipe(
        "the paper's model: dual path + interactive module, L_tran + L_con + L_re, curiosity",
        {"encoder": "dual_interactive", **SIMOUN_LOSSES, "curiosity": True},
    ),
    "drq": Recipe(
        "DrQ (Kostrikov et al. 2021): stacked frames, random shift, no auxiliary losses, "
        "temperature lr 1e-3 with Adam beta1 0.9",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "alpha_lr": 1e-3,
            "alpha_beta": 0.9,
        },
    ),
    "curl": Recipe(
        "CURL (Laskin et al. 2020): stacked frames, random shift, InfoNCE whose positive is an "
        "independently shifted view, keys from the momentum encoder, bilinear W",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "contrastive_weight": 1.0,
            "contrastive_view": "shift",
        },
    ),
    "sac": Recipe(
        "pixel SAC: stacked frames, no augmentation, no auxiliary losses",
        {"encoder": "stacked", "augmentation": "none", **NO_AUXILIARY},
    ),
    "single": _encoder_ablation("single", "one conv path on frame t only"),
    "stacked": _encoder_ablation("stacked", "stacked frames"),
    "stacked_wide": _encoder_ablation("stacked_wide", "stacked frames with twice the filters"),
    "flare": _encoder_ablation("flare", "latent flow (Flare)"),
    "dual": _encoder_ablation("dual", "dual path without the interactive module"),
    "dual_interactive": _encoder_ablation("dual_interactive", "dual path + interactive module"),
}
"""Every recipe by name (``--agent.recipe NAME``); a new method or ablation is one entry."""
