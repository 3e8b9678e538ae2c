"""Named agent recipes: Simoun, its baselines (DrQ, DrQ-v2, RAD, CURL, pixel SAC) and the Fig. 6
encoders.

A recipe is a small set of ``AgentConfig`` values, applied after a preset and before the user's
overrides (``simoun-train --agent.recipe drq --agent.lr 3e-4``), so every method runs in the
same code with the same replay, networks and training loop, and differs only where its paper
says it does. The recipe's name is saved with the resolved values in ``config.json``. A
baseline named after a paper cites it and lists, in ``deviations``, every way it differs from
that paper's published method.

Shared by every recipe unless it says otherwise: CURL / SAC-AE's SAC settings (init
temperature 0.1, temperature lr 1e-4 with Adam beta1 0.5, critic tau 0.01, encoder tau 0.05,
actor and targets updated every 2 steps), which the paper's agent follows too.

Example:
    >>> from simoun_agent.recipes import RECIPES
    >>> drq = RECIPES["drq"].values
    >>> drq["critic_augmentations"], drq["target_augmentations"], drq["next_state_encoder"]
    (2, 2, 'target')
    >>> RECIPES["drqv2"].values["actor"], RECIPES["drqv2"].values["n_step"]
    ('deterministic', 3)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Recipe:
    """One method or ablation as ``AgentConfig`` values."""

    description: str
    """one line for help texts and reports; a baseline's names its paper (authors, year)"""
    values: dict[str, Any]
    """AgentConfig field -> value"""
    deviations: tuple[str, ...] = ()
    """every way a baseline differs from the published method it is named after"""


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

PIXEL_SAC_HEADS = (
    "the encoder's FC + LayerNorm (no final tanh) is shared by actor and critic, and the actor "
    "reads it detached; the paper's agent has its own actor encoder whose convs are tied to the "
    "critic's and whose FC + LayerNorm + tanh the actor loss trains"
)
FROM_PRESET = (
    "batch size, learning rate, action repeat, replay size and warm-up come from the preset "
    "(DMC presets: batch 512, lr 1e-3 (2e-4 on cheetah-run), replay 100k, 1000 random steps)"
)
SHARED_OFFSET = (
    "one shift offset per sample for the whole window, so o_t and o_{t+1} of a view move alike; "
    "the paper shifts the current and next observations independently"
)
STACK = "3 stacked frames are the triplet o_{t-2}, o_{t-1}, o_t (the same)"


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
        "DrQ (Kostrikov, Yarats & Fergus 2021): SAC on stacked frames with random shift, the TD "
        "target averaged over K=2 and the critic loss over M=2 augmented views, the next state "
        "through the EMA target encoder (tau 0.01 for encoder and Q heads), temperature init "
        "0.1, lr 1e-3, Adam beta1 0.9; no auxiliary losses",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "critic_augmentations": 2,
            "target_augmentations": 2,
            "next_state_encoder": "target",
            "encoder_tau": 0.01,
            "critic_tau": 0.01,
            "init_temperature": 0.1,
            "alpha_lr": 1e-3,
            "alpha_beta": 0.9,
        },
        (
            SHARED_OFFSET + "; target view k reuses the offsets of critic view k",
            "the critic loss is the mean over the M views (the paper's equation); DrQ's code "
            "sums them, which Adam turns into the same step up to its epsilon",
            "the next action is drawn from the online encoder's state (DrQ: from the actor's "
            "encoder, whose convs are the online ones)",
            PIXEL_SAC_HEADS,
            FROM_PRESET,
            STACK,
        ),
    ),
    "drqv2": Recipe(
        "DrQ-v2 (Yarats, Fergus, Lazaric & Pinto 2022): deterministic actor explored with noise "
        "of std 1.0 -> 0.1 (linear over 1M env steps), noise clipped at 0.3 in the TD target and "
        "the actor loss (-min Q), no entropy term, 3-step returns, random shift, the online "
        "encoder for the next state, lr 1e-4, actor every update, targets every 2 with tau 0.01",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "actor": "deterministic",
            "exploration_std_start": 1.0,
            "exploration_std_end": 0.1,
            "exploration_steps": 1_000_000,
            "noise_clip": 0.3,
            "n_step": 3,
            "next_state_encoder": "online",
            "lr": 1e-4,
            "critic_tau": 0.01,
            "actor_update_every": 1,
            "target_update_every": 2,
        },
        (
            "one gradient step per agent step (simoun-train's updates_per_step 1), the actor "
            "every step and the targets every 2: the targets move at DrQ-v2's rate per env "
            "step, the critic and actor take twice its updates (DrQ-v2 updates all three once "
            "every 2 agent steps)",
            "the schedule counts env steps: 1M is DrQ-v2's 500k agent steps at its action "
            "repeat 2; at another action repeat it decays per env step, not per agent step",
            "the encoder ends in FC + LayerNorm (no tanh) shared by actor and critic, the actor "
            "reading it detached; DrQ-v2's encoder is the convs alone and actor and critic each "
            "put their own FC + LayerNorm + tanh on the flat conv features; pixels are x/255 "
            "(DrQ-v2: x/255 - 0.5)",
            SHARED_OFFSET,
            "actions clamped to [-1, 1] with the identity as gradient (DrQ-v2: to "
            "[-1 + 1e-6, 1 - 1e-6])",
            FROM_PRESET + "; DrQ-v2 uses batch 256, a 1M replay and 4000 random frames",
            STACK,
        ),
    ),
    "rad": Recipe(
        "RAD (Laskin, Lee, Stooke, Pinto, Abbeel & Srinivas 2020): SAC on stacked frames with "
        "random shift, no auxiliary losses; what 'drq' meant before it averaged DrQ's K/M views",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "alpha_lr": 1e-3,
            "alpha_beta": 0.9,
        },
        (
            "random shift (replicate-pad 4 px per 84 px, crop back) instead of RAD's default "
            "random crop of 100x100 renders to 84x84 (its 'translate' is the closest)",
            "temperature lr 1e-3 with Adam beta1 0.9 (DrQ's values, kept from the old 'drq' "
            "recipe); RAD's code uses 1e-4 and 0.5",
            PIXEL_SAC_HEADS,
            FROM_PRESET,
            STACK,
        ),
    ),
    "curl": Recipe(
        "CURL (Laskin, Srinivas & Abbeel 2020): stacked frames, random shift, InfoNCE whose "
        "positive is an independently shifted view, keys from the momentum encoder, bilinear W",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "contrastive_weight": 1.0,
            "contrastive_view": "shift",
        },
        (
            "random shift (replicate-pad 4 px per 84 px, crop back) for the RL input and both "
            "contrastive views instead of CURL's random crop of 100x100 renders to 84x84",
            PIXEL_SAC_HEADS,
            FROM_PRESET,
            STACK,
        ),
    ),
    "sac": Recipe(
        "pixel SAC (Haarnoja et al. 2018) on stacked frames: no augmentation, no auxiliary "
        "losses (the SAC:pixel baseline of CURL / SAC-AE)",
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

RECIPES["drqv2_easy"] = Recipe(
    "DrQ-v2 with its easy tasks' exploration schedule (std 1.0 -> 0.1 over 200k env steps: "
    "cartpole_swingup, cup_catch, finger_spin, walker_walk, ...), otherwise 'drqv2'",
    {**RECIPES["drqv2"].values, "exploration_steps": 200_000},
    (
        "the schedule is DrQ-v2's for its easy tasks, 'linear(1.0,0.1,100000)' in agent steps "
        "at action repeat 2 (cfgs/task/easy.yaml), counted here in env steps",
        RECIPES["drqv2"].deviations[0],
        *RECIPES["drqv2"].deviations[2:],
    ),
)
"""The dmc100k study's supplement (issue 20): DrQ-v2 with the schedule its config gives
cartpole_swingup; 'drqv2' has its medium tasks' (1M env steps)."""
