"""Named agent recipes: Simoun, its baselines (DrQ, DrQ-v2, RAD, CURL, pixel SAC) and the Fig. 6
encoders.

A recipe is a small set of ``AgentConfig`` values, applied after a preset and before the user's
overrides (``simoun-train --agent.recipe drq --agent.lr 3e-4``), so every method runs in the
same code with the same replay, networks and training loop, and differs only where its paper
says it does. A recipe may give other values for named DMC tasks (``per_task``: DrQ-v2's
exploration schedule is its task's, from its cfgs/task/*.yaml). The recipe's name is saved with
the resolved values in ``config.json``. A baseline named after a paper cites the published file
and function it follows and lists, in ``deviations``, every way it differs from that code,
the preset's smaller scale included.

The paper says it follows DrQ's training setup. Its SAC as the dataclass defaults give it
(init temperature 0.1, temperature lr 1e-4 with Adam beta1 0.5, critic tau 0.01, a critic
target whose own encoder is an EMA of the online one at tau 0.05 and reads the TD target's next
state, actor and targets updated every 2 steps) is that of CURL's and SAC-AE's code
(CurlSacAgent in curl_sac.py, SacAeAgent in sac_ae.py), as DESIGN.md fixes it; where DrQ's
differs (temperature lr 1e-3 with beta1 0.9, target encoder tau 0.01), simoun's deviations say so.

Example:
    >>> from simoun_agent.config.recipes import RECIPES
    >>> drq = RECIPES["drq"].values
    >>> drq["critic_augmentations"], drq["target_augmentations"], drq["next_state_encoder"]
    (2, 2, 'target')
    >>> RECIPES["drqv2"].values["actor"], RECIPES["drqv2"].values["n_step"]
    ('deterministic', 3)
    >>> RECIPES["drqv2"].values_for("cartpole-swingup")["exploration_steps"]
    200000
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass, field
from typing import Any

from simoun_agent.config.envs import dmc_task, split_env_id


@dataclass(frozen=True)
class Recipe:
    """One method or ablation as ``AgentConfig`` values."""

    description: str
    """one line for help texts and reports; a baseline's names its paper (authors, year) and the
    published file and function it follows"""
    values: dict[str, Any]
    """AgentConfig field -> value"""
    deviations: tuple[str, ...] = ()
    """every way a baseline differs from the published code it is named after"""
    per_task: dict[str, dict[str, Any]] = field(default_factory=dict)
    """DMC task (``cartpole-swingup``) -> AgentConfig values that replace ``values`` on that task,
    as the published code configures each task"""
    ablation_of: str | None = None
    """the method this recipe is an ablation of (the method with a part removed or replaced),
    which a study's ``[diagnostics]`` lists it under; None for a method"""

    def values_for(self, task: str | None) -> dict[str, Any]:
        """The recipe's values on ``task``: a DMC task name (``cartpole-swingup``; its
        ``cartpole_swingup`` spelling too), an env id (``dm_control/cartpole-swingup-v0``; any
        other env's takes :attr:`values`), or None for any other env. A name close to a task of
        :attr:`per_task` but none of them (a typo, which would drop the task's own values
        silently) is refused with a ValueError naming it and the task meant."""
        if task is None:
            return dict(self.values)
        if not isinstance(task, str):
            raise TypeError(
                f"Recipe.values_for(task=...) takes a DMC task name, an env id or None, got "
                f"{type(task).__name__} {task!r:.60}; e.g. values_for('cartpole-swingup')"
            )
        if "/" in task or ":" in task:  # an env id
            task = dmc_task(split_env_id(task)[1])
            if task is None:
                return dict(self.values)
        return {**self.values, **self.per_task.get(self.task_key(task), {})}

    def task_key(self, task: str) -> str:
        """The key of :attr:`per_task` that the DMC task name ``task`` spells (case, ``_`` for
        ``-`` and a ``-v0`` suffix aside), or ``task`` itself when it names none; a ValueError
        for a name one typo away from a key (real DMC tasks are further from each other:
        ``cartpole-swingup_sparse`` is 0.82 alike to ``cartpole-swingup``)."""
        keys = {_spelling(key): key for key in self.per_task}
        spelt = _spelling(task)
        if spelt in keys:
            return keys[spelt]
        close = difflib.get_close_matches(spelt, list(keys), n=1, cutoff=0.85)
        if close:
            raise ValueError(
                f"Recipe.values_for({task!r}): no DMC task of that name; did you mean "
                f"{keys[close[0]]!r}? The recipe has values of its own for "
                f"{', '.join(self.per_task)}; any other task takes its base values"
            )
        return task


def _spelling(task: str) -> str:
    """``task`` as compared with the keys of ``Recipe.per_task``: lower case, ``-`` for ``_``
    (DrQ-v2's ``cartpole_swingup``), without a version suffix."""
    return re.sub(r"-v\d+$", "", task.strip().lower().replace("_", "-"))


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
    "the encoder's FC + LayerNorm is shared by actor and critic and the actor reads it detached, "
    "and the TD target's next action is drawn from that online state; the published code gives "
    "the actor its own encoder, convs tied to the critic's, whose FC + LayerNorm the actor loss "
    "trains (detach_encoder cuts only the convs) and which draws the next action"
)
FROM_PRESET = (
    "the scale comes from the preset: batch size, learning rate, action repeat, replay size, "
    "warm-up, image size, filters and hidden size (DMC presets: batch 512, lr 1e-3 (2e-4 on "
    "cheetah-run), action repeat 8 on cartpole-swingup and 4 on cheetah-run, replay 100k, 1000 "
    "random agent steps, 84x84, 32 filters, hidden 1024; the cpu preset: batch 64, lr 1e-3, "
    "action repeat 8, replay 32k, 250 random agent steps, 48x48, 16 filters, hidden 256)"
)
SHIFT_NOT_CROP = (
    "random shift (replicate-pad 4 px per 84 px of height, crop back) for the RL input{} instead "
    "of the random crop of 100x100 renders to 84x84 of its code (utils.random_crop)"
)
STACK = "3 stacked frames are the triplet o_{t-2}, o_{t-1}, o_t (the same)"

SAC_HEADS_DELTA = {"conv_init": "delta_orthogonal", "independent_next_shift": True}
"""What CURL's and RAD's curl_sac.py share with SAC-AE's sac_ae.py besides the defaults' SAC:
delta-orthogonal conv init (weight_init) and, with an augmentation, obs and next_obs augmented
by separate calls."""


def _encoder_ablation(encoder: str, what: str) -> Recipe:
    return Recipe(
        f"Fig. 6 ablation: {what}, with Simoun's L_tran + L_con + L_re and no curiosity",
        {"encoder": encoder, **SIMOUN_LOSSES, "curiosity": False},
        ablation_of="simoun",
    )


SIMOUN = {"encoder": "dual_interactive", **SIMOUN_LOSSES, "curiosity": True}
"""The paper's model."""

SIMOUN_DEVIATIONS = (
    "no published code: its SAC is that of CURL's curl_sac.py (CurlSacAgent.update_critic: the "
    "next state through the critic target's EMA encoder, tau 0.05; Q heads 0.01), the code CCLF "
    "builds on, whose curiosity constants C and lambda Eq. 13 uses",
    "the paper follows DrQ's training setup, whose temperature Adam has lr 1e-3 and beta1 0.9 and "
    "whose target encoder moves at tau 0.01 (drq.py); these are CURL's 1e-4, 0.5 and 0.05",
    PIXEL_SAC_HEADS,
    "with augmentation 'shift', one offset per sample for the whole window, so o_t and o_{t+1} "
    "move alike and the critic's encoder pass gives the next state (DrQ and CURL shift obs and "
    "next_obs independently)",
    "conv init orthogonal with relu gain (DrQ's utils.weight_init; CURL's is delta-orthogonal)",
    FROM_PRESET,
)
"""How ``simoun`` (and its ablations) differ from the SAC code the paper builds on."""

SIMOUN_PARTS = {
    "curiosity": {"curiosity": False},
    "interaction": {"encoder": "dual"},
    "aux": {"transition_weight": 0.0, "contrastive_weight": 0.0, "reward_weight": 0.0},
}
"""Each part of Simoun that the ``simoun_no_<part>`` ablations remove, as the values that
remove it: the intrinsic reward (Eq. 13), the interactive module (Eq. 5-8), the auxiliary
losses L_tran, L_con and L_re (Eq. 2, 3, 7)."""


def _simoun_without(part: str) -> Recipe:
    return Recipe(
        f"Simoun with one part removed, the rest as 'simoun': no {part} "
        f"({', '.join(f'{key}={value}' for key, value in SIMOUN_PARTS[part].items())})",
        {**SIMOUN, **SIMOUN_PARTS[part]},
        SIMOUN_DEVIATIONS,
        ablation_of="simoun",
    )


DRQV2_SCHEDULES = {"easy": 200_000, "medium": 1_000_000, "hard": 4_000_000}
"""DrQ-v2's stddev_schedule 'linear(1.0,0.1,N)' of cfgs/task/{easy,medium,hard}.yaml, N = 100k,
500k and 2M agent steps, counted here in env steps at its action repeat 2."""

DRQV2_TASKS = {
    "cartpole-swingup": ("easy", {}),
    "ball_in_cup-catch": ("easy", {}),
    "finger-spin": ("easy", {}),
    "walker-walk": ("easy", {"n_step": 1}),
    "cheetah-run": ("medium", {}),
    "reacher-easy": ("medium", {}),
}
"""The paper's six DMC tasks in DrQ-v2's cfgs/task/*.yaml: the schedule each inherits (cup_catch,
finger_spin, cartpole_swingup and walker_walk easy; cheetah_run and reacher_easy medium), and
walker_walk's own nstep 1 (its batch 512 is the DMC presets' too)."""

DRQV2 = {
    "encoder": "stacked",
    "augmentation": "shift",
    **NO_AUXILIARY,
    "separate_trunks": True,
    "pixel_offset": 0.5,
    "independent_next_shift": True,
    "actor": "deterministic",
    "exploration_std_start": 1.0,
    "exploration_std_end": 0.1,
    "exploration_steps": DRQV2_SCHEDULES["medium"],
    "noise_clip": 0.3,
    "n_step": 3,
    "next_state_encoder": "online",
    "lr": 1e-4,
    "critic_tau": 0.01,
    "update_every_steps": 2,
    "actor_update_every": 1,
    "target_update_every": 1,
}
"""DrQ-v2 as facebookresearch/drqv2's drqv2.py and cfgs/config.yaml give it, with the medium
tasks' schedule for tasks DrQ-v2 has no config for."""

DRQV2_DEVIATIONS = (
    "the schedule counts env steps, twice DrQ-v2's agent steps at its action repeat 2 "
    "(utils.schedule reads global_step); at the presets' action repeat 8 or 4 it decays per env "
    "step, so 4x or 2x fewer agent steps than DrQ-v2 take it from 1.0 to 0.1",
    "action repeat from the preset (8 on cartpole-swingup, 4 on cheetah-run at the DMC and cpu "
    "presets); DrQ-v2 uses 2 on every task (cfgs/config.yaml), so per env step it takes 4x or "
    "2x as many decisions and updates as here",
    "warm-up from the preset: uniform actions for warmup_agent_steps (cpu: 250, i.e. 2,000 env "
    "steps at action repeat 8), updates from max(warm-up, batch size) on; DrQ-v2 takes 2,000 "
    "uniform agent steps (num_expl_steps) and updates from 4,000 frames on (num_seed_frames)",
    "actions clamped to [-1, 1] with the identity as gradient (DrQ-v2's TruncatedNormal._clamp: "
    "to [-1 + 1e-6, 1 - 1e-6])",
    "batch 256 (walker_walk 512), replay 1M, 84x84 frames, 32 filters and hidden 1024 in "
    "DrQ-v2; " + FROM_PRESET,
    "the shift pads 4 px per 84 px of height on the uint8 frames and crops back (the same "
    "pixels as RandomShiftsAug's grid_sample at integer offsets, pad 4 at 84x84)",
    "tasks without a DrQ-v2 config take its medium schedule",
    STACK,
)
"""How both DrQ-v2 recipes differ from drqv2.py, whatever their schedule."""

DRQV2_CITED = (
    "DrQ-v2 (Yarats, Fergus, Lazaric & Pinto 2022; facebookresearch/drqv2 drqv2.py, DrQV2Agent): "
    "convs alone as the encoder on x/255 - 0.5 (Encoder), actor and critic each with their own "
    "trunk Linear -> LayerNorm -> Tanh (Actor, Critic), the critic's inside its EMA target (tau "
    "0.01); deterministic actor tanh(mu) explored with noise of std 1.0 -> 0.1 {}, clipped at "
    "0.3 in the TD target and the actor loss (-min Q), no entropy term; 3-step returns; obs and "
    "next obs shifted independently (RandomShiftsAug); the next state through the online convs; "
    "one critic, actor and target update every 2 agent steps (update_every_steps); lr 1e-4"
)

CURL_RAD = "CURL's and RAD's curl_sac.py"

RECIPES: dict[str, Recipe] = {
    "simoun": Recipe(
        "the paper's model: dual path + interactive module, L_tran + L_con + L_re, curiosity; "
        "SAC as CURL's curl_sac.py (CurlSacAgent), the TD target through the EMA target encoder",
        SIMOUN,
        SIMOUN_DEVIATIONS,
    ),
    **{f"simoun_no_{part}": _simoun_without(part) for part in SIMOUN_PARTS},
    "drq": Recipe(
        "DrQ (Kostrikov, Yarats & Fergus 2021; denisyarats/drq drq.py, DRQAgent.update_critic): "
        "SAC on stacked frames with random shift, the TD target averaged over K=2 and the critic "
        "loss over M=2 augmented views, each view of obs and next obs shifted independently, "
        "the next state through the EMA target encoder (tau 0.01 for encoder and Q heads), "
        "temperature init 0.1, lr 1e-3, Adam beta1 0.9; no auxiliary losses",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            "critic_augmentations": 2,
            "target_augmentations": 2,
            "independent_next_shift": True,
            "next_state_encoder": "target",
            "encoder_tau": 0.01,
            "critic_tau": 0.01,
            "init_temperature": 0.1,
            "alpha_lr": 1e-3,
            "alpha_beta": 0.9,
        },
        (
            "the critic loss is the mean over the M views (the paper's equation); DrQ's code "
            "sums them, which Adam turns into the same step up to its epsilon",
            "the encoder's FC + LayerNorm ends without tanh (drq.py's Encoder, output_logits "
            "False, ends in tanh)",
            PIXEL_SAC_HEADS,
            "the log-probability's tanh correction is log(1 - a^2 + 1e-6) (DrQ: the exact "
            "TanhTransform Jacobian)",
            "batch 128 in DrQ's config.yaml ('512 to reproduce the results in the paper'), "
            "replay 100k, 1000 seed steps, hidden 1024, 84x84, 32 filters, action repeat per task; "
            + FROM_PRESET,
            STACK,
        ),
    ),
    "drqv2": Recipe(
        DRQV2_CITED.format(
            "linear over 200k env steps on its easy tasks (cartpole-swingup, ...), 1M on its "
            "medium ones (cheetah-run, ...) as cfgs/task/*.yaml give"
        ),
        DRQV2,
        DRQV2_DEVIATIONS,
        per_task={
            task: {"exploration_steps": DRQV2_SCHEDULES[level], **extra}
            for task, (level, extra) in DRQV2_TASKS.items()
        },
    ),
    "drqv2_easy": Recipe(
        DRQV2_CITED.format("linear over 200k env steps (the easy tasks' schedule) on every task"),
        {**DRQV2, "exploration_steps": DRQV2_SCHEDULES["easy"]},
        (
            "the easy tasks' schedule (cfgs/task/easy.yaml) on every task; recipe 'drqv2' takes "
            "each task's own",
            *DRQV2_DEVIATIONS,
        ),
    ),
    "rad": Recipe(
        "RAD (Laskin, Lee, Stooke, Pinto, Abbeel & Srinivas 2020; MishaLaskin/rad curl_sac.py, "
        "RadSacAgent): SAC on stacked frames with random shift, obs and next obs augmented "
        "independently, the next state through the critic target's EMA encoder (tau 0.05, Q "
        "heads 0.01; update_critic), delta-orthogonal conv init, temperature init 0.1, lr 1e-4, "
        "beta1 0.5; no auxiliary losses",
        {"encoder": "stacked", "augmentation": "shift", **NO_AUXILIARY, **SAC_HEADS_DELTA},
        (
            SHIFT_NOT_CROP.format("") + "; RAD's 'translate' is the closest",
            PIXEL_SAC_HEADS,
            "batch 128 (scripts/run.sh), 1000 random init steps, hidden 1024, 84x84, 32 "
            "filters, action repeat per task in RAD; " + FROM_PRESET,
            STACK,
        ),
    ),
    "curl": Recipe(
        "CURL (Laskin, Srinivas & Abbeel 2020; MishaLaskin/curl curl_sac.py, CurlSacAgent): "
        "stacked frames, random shift with obs and next obs augmented independently, InfoNCE "
        "whose positive is an independently shifted view, keys from the critic target's EMA "
        "encoder, bilinear W initialised uniform on [0, 1), the contrastive loss in its own step "
        "after the critic, actor and EMA updates (update_cpc), the next state through the EMA "
        "encoder (tau 0.05, Q heads 0.01; update_critic), delta-orthogonal conv init",
        {
            "encoder": "stacked",
            "augmentation": "shift",
            **NO_AUXILIARY,
            **SAC_HEADS_DELTA,
            "contrastive_weight": 1.0,
            "contrastive_view": "shift",
            "contrastive_step": True,
            "similarity_init": "uniform",
        },
        (
            SHIFT_NOT_CROP.format(" and both contrastive views"),
            PIXEL_SAC_HEADS,
            "batch 128 (scripts/run.sh; train.py's default 32), 1000 random init steps, hidden "
            "1024, 84x84, 32 filters, action repeat per task in CURL; " + FROM_PRESET,
            STACK,
        ),
    ),
    "sac": Recipe(
        "pixel SAC (Haarnoja et al. 2018) on stacked frames, the SAC:pixel baseline of CURL as "
        "SAC-AE's code has it (denisyarats/pytorch_sac_ae sac_ae.py, SacAeAgent without a "
        "decoder): no augmentation, no auxiliary losses, the next state through the critic "
        "target's EMA encoder (tau 0.05, Q heads 0.01; update_critic), delta-orthogonal conv init",
        {"encoder": "stacked", "augmentation": "none", **NO_AUXILIARY, **SAC_HEADS_DELTA},
        (
            "the encoder's FC + LayerNorm ends without tanh (SAC-AE's PixelEncoder in encoder.py "
            "ends in tanh)",
            PIXEL_SAC_HEADS,
            "batch 128, replay 1M, 1000 init steps, hidden 1024, 84x84, 32 filters in SAC-AE's "
            "train.py; " + FROM_PRESET,
            STACK,
        ),
    ),
    "single": _encoder_ablation("single", "one conv path on frame t only"),
    "stacked": _encoder_ablation("stacked", "stacked frames"),
    "stacked_wide": _encoder_ablation("stacked_wide", "stacked frames with twice the filters"),
    "flare": _encoder_ablation("flare", "latent flow (Flare)"),
    "dual": _encoder_ablation("dual", "dual path without the interactive module"),
    "dual_interactive": _encoder_ablation("dual_interactive", "dual path + interactive module"),
}
"""Every recipe by name (``--agent.recipe NAME``); a new method or ablation is one entry."""
