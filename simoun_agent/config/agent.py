"""Hyperparameters of the Simoun SAC agent (defaults: the paper's, i.e. DrQ's setup, and CURL's),
each field a :func:`~simoun_agent.config.rules.setting` whose rule checks it when the config is
built."""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from simoun_agent.config.keywords import refuse_unknown
from simoun_agent.config.recipes import RECIPES
from simoun_agent.config.rules import (
    Rule,
    boolean,
    check_fields,
    fail,
    finite,
    integer,
    is_real,
    knob,
    one_of,
    optional_name,
    real,
    setting,
)
from simoun_agent.config.shapes import ENCODER_SHAPES

AUGMENTATIONS = ("none", "shift")
CONTRASTIVE_VIEWS = ("random_conv", "shift")
NEXT_STATE_ENCODERS = ("online", "target")
CONV_INITS = ("orthogonal", "delta_orthogonal")
SIMILARITY_INITS = ("identity", "uniform")
ACTOR_NAMES = ("gaussian", "deterministic")
"""The actors of :data:`simoun_agent.models.actors.ACTORS` (the same names: a test holds them
equal)."""


AGENT = "agent."
"""Flag prefix of AgentConfig's fields (``--agent.batch-size``)."""

_POSITIVE = integer(1)
_RATE = real(0.0, 1.0, open_low=True)
_WEIGHT = real(0.0)
_LEARNING_RATE = real(0.0, 1.0, open_low=True, fix="Adam's rates are small, e.g. 1e-3 or 3e-4")
"""an Adam rate above 1 is a value in the wrong units (a percentage, an exponent)"""


@dataclass
class AgentConfig:
    """Everything the agent needs besides the frame shape and the action size.

    ``AgentConfig(recipe="drqv2")`` is DrQ-v2's agent: a recipe gives its values
    (:data:`~simoun_agent.config.recipes.RECIPES`) to every field not given, and the fields
    given override them, as ``--agent.recipe drqv2 --agent.lr 3e-4`` does on the command line
    (``AgentConfig(recipe="drqv2", lr=3e-4)``). Its values are those for any env; a DMC task's
    own (DrQ-v2's per-task exploration schedule) come with
    ``simoun_agent.config.resolve(preset, {"agent.recipe": "drqv2", "env": ...}).agent``.
    A recipe named later (``config.recipe = "drq"``, ``dataclasses.replace``) changes the name
    only.
    A setting read only when another turns its part on (``curiosity_scale`` with curiosity, the
    exploration schedule with the deterministic actor: :data:`READ_ONLY_WITH`) is refused when
    given a value of its own with that part off, as it would change nothing.

    Example:
        >>> config = AgentConfig(recipe="drqv2", lr=3e-4)
        >>> config.actor, config.n_step, config.lr
        ('deterministic', 3, 0.0003)
    """

    recipe: str | None = setting(None, optional_name(RECIPES))
    """name of the agent recipe these values started from (simoun_agent.config.recipes: simoun, drq,
    drqv2, rad, curl, sac and the Fig. 6 encoders); applied before the user's overrides. None:
    these dataclass defaults"""
    encoder: str = setting("dual_interactive", one_of(list(ENCODER_SHAPES)))
    """one of "single", "stacked", "flare", "dual", "dual_interactive", "stacked_wide" (Fig. 6;
    the registry simoun_agent.models.encoder.ENCODERS, whose geometry is
    simoun_agent.config.shapes.ENCODER_SHAPES)"""
    augmentation: str = setting("none", one_of(AUGMENTATIONS))
    """augmentation of the frames the critic and actor see: "none", or "shift" (DrQ's random
    shift: replicate-pad, random crop back, one offset per sample for its whole window)"""
    shift_pad: int | None = setting(None, integer(0, optional=True))
    """padding of the "shift" augmentation in pixels; None: 4 px per 84 px of image height"""
    critic_augmentations: int = setting(1, _POSITIVE)
    """M of DrQ: augmented views of each sample whose critic losses are averaged (each view one
    shift offset per sample for its whole window); the auxiliary losses, curiosity and the actor
    use the first. More than 1 needs augmentation "shift" """
    target_augmentations: int = setting(1, _POSITIVE)
    """K of DrQ: augmented views of the next state whose TD targets are averaged; view k shares
    the offsets of critic view k (views beyond M get their own). More than 1 needs augmentation
    "shift" """
    next_state_encoder: str = setting("target", one_of(NEXT_STATE_ENCODERS))
    """encoder of the next state read by the target Q heads: "target", the EMA encoder (rate
    encoder_tau), as the critic target of CURL, RAD and SAC-AE holds its own encoder
    (update_critic in curl_sac.py / sac_ae.py: encoder tau 0.05, Q heads critic_tau 0.01) and DrQ's
    (drq.py, tau 0.01 for both); or "online", the online encoder without gradient (DrQ-v2:
    DrQV2Agent.update in drqv2.py). The next action is drawn from the online encoder's state.
    Configs saved before this field defaulted to "target" hold "online" explicitly"""
    independent_next_shift: bool = setting(False, boolean())
    """augmentation "shift": True shifts the triplet the TD target bootstraps from by an offset of
    its own (DrQ-v2, DrQ, RAD and CURL augment obs and next_obs by separate calls); False: it
    moves with the offset of its view's window (frames t-2 .. t+1 alike), which lets the encoder
    pass of the critic's views give the next state (the shared-frame trick)"""
    separate_trunks: bool = setting(False, boolean())
    """False: the encoder ends in FC + LayerNorm, whose state the critic reads and the actor reads
    detached. True (DrQ-v2: Actor and Critic in drqv2.py): the encoder ends at its flattened convs
    and the actor and the critic each put their own trunk Linear -> LayerNorm -> Tanh
    (feature_dim) on them; the critic's trunk belongs to the critic and so to its EMA target
    (critic_tau), the actor's is trained by the actor loss. Stacked-frame encoders without
    auxiliary losses only"""
    pixel_offset: float = setting(
        0.0,
        real(-1.0, 1.0, fix="it is on the x / 255 scale, e.g. --agent.pixel-offset 0.5 (DrQ-v2)"),
    )
    """subtracted from the pixels after x / 255 before the convs (DrQ-v2's Encoder: 0.5)"""
    conv_init: str = setting("orthogonal", one_of(CONV_INITS))
    """initialisation of the conv weights: "orthogonal" (relu gain; DrQ and DrQ-v2's
    utils.weight_init) or "delta_orthogonal" (zero but an orthogonal centre tap, relu gain; the
    weight_init of CURL's and RAD's curl_sac.py and SAC-AE's sac_ae.py)"""
    contrastive_view: str = setting("random_conv", one_of(CONTRASTIVE_VIEWS))
    """positive view of L_con: "random_conv" (Eq. 3, a random convolution of the same frames)
    or "shift" (CURL: an independently shifted view of the same input)"""
    contrastive_step: bool = setting(False, boolean())
    """False: L_con is added to the critic's loss and stepped with it (Eq. 14). True (CURL:
    CurlSacAgent.update_cpc in curl_sac.py): L_con gets its own step after the critic, actor and
    EMA updates, its anchor encoded again by the updated encoder, and, as in that code, the
    encoder is stepped twice by it (CURL's encoder_optimizer, then cpc_optimizer with W)"""
    similarity_init: str = setting("identity", one_of(SIMILARITY_INITS))
    """initial W of L_con's bilinear score: "identity" (Eq. 3's inner product) or "uniform"
    (CURL: torch.rand, uniform on [0, 1))"""
    feature_dim: int = setting(50, _POSITIVE)
    """size of each path's feature vector (f_m and f_a); single-path encoders output this size"""
    num_filters: int = setting(32, _POSITIVE)
    """filters of every conv layer ("stacked_wide" doubles it)"""
    hidden_dim: int = setting(1024, _POSITIVE)
    """hidden units of the actor and critic MLPs"""
    aux_hidden_dim: int = setting(256, _POSITIVE)
    """hidden units of the two-layer transition model G (Eq. 2) and reward model R (Eq. 7)"""
    batch_size: int = setting(512, _POSITIVE)
    """transitions per gradient step"""
    lr: float = setting(1e-3, _LEARNING_RATE)
    """Adam learning rate of the encoder, critic, actor and auxiliary heads"""
    alpha_lr: float = setting(1e-4, _LEARNING_RATE)
    """Adam learning rate of the temperature (CURL / SAC-AE value)"""
    alpha_beta: float = setting(
        0.5, Rule("a number in [0, 1) (Adam's beta1)", lambda v: is_real(v) and 0 <= v < 1)
    )
    """Adam beta1 of the temperature optimiser (CURL / SAC-AE value)"""
    discount: float = setting(
        0.99,
        Rule(
            "a number in [0, 1) (gamma)",
            lambda v: is_real(v) and 0 <= v < 1,
            "e.g. --agent.discount 0.99 (the default); at 1 the TD target, bootstrapped past "
            "time limits, grows without bound",
        ),
    )
    """gamma of the TD target (Eq. 9)"""
    n_step: int = setting(1, _POSITIVE)
    """steps of reward summed before bootstrapping in the TD target (DrQ-v2 uses 3); cut at
    episode ends, bootstrapped across truncation, never across an episode boundary"""
    critic_tau: float = setting(0.01, _RATE)
    """EMA rate of the target Q heads"""
    encoder_tau: float = setting(0.05, _RATE)
    """EMA rate of the target (momentum) encoder"""
    actor_update_every: int = setting(2, _POSITIVE)
    """update the actor and temperature every this many gradient steps"""
    target_update_every: int = setting(2, _POSITIVE)
    """update the EMA targets every this many gradient steps"""
    update_every_steps: int = setting(1, _POSITIVE)
    """the agent's gradient step(s) come at every this-many-th agent step once learning has
    started (DrQ-v2's update_every_steps 2: one critic, actor and target update every 2 agent
    steps)"""
    actor: str = setting("gaussian", one_of(ACTOR_NAMES))
    """the policy: "gaussian" (SAC, learned temperature) or "deterministic" (DrQ-v2: tanh(mu),
    scheduled exploration noise, no entropy term); the registry simoun_agent.models.actors.ACTORS"""
    exploration_std_start: float = setting(1.0, real(0.0))
    """deterministic actor: exploration noise std at env step 0 (DrQ-v2)"""
    exploration_std_end: float = setting(0.1, real(0.0))
    """deterministic actor: exploration noise std from exploration_steps on (DrQ-v2)"""
    exploration_steps: int = setting(1_000_000, _POSITIVE)
    """deterministic actor: env steps over which the std falls linearly from start to end.
    DrQ-v2's "medium" schedule is 500k of its agent steps, i.e. 1M env steps (frames) at its
    action repeat 2"""
    noise_clip: float = setting(0.3, real(0.0))
    """deterministic actor: the noise of the TD target's and the policy loss's action is clipped
    to +- this (DrQ-v2's stddev_clip)"""
    init_temperature: float = setting(0.1, real(0.0, open_low=True))
    """initial SAC temperature alpha"""
    log_std_min: float = setting(-10.0, finite())
    """lower bound of the policy's log standard deviation"""
    log_std_max: float = setting(2.0, finite())
    """upper bound of the policy's log standard deviation"""
    curiosity: bool = setting(True, boolean())
    """add the consistency-guided intrinsic reward (Eq. 13) to the TD target (dual encoders only)"""
    curiosity_scale: float = setting(0.2, _WEIGHT)
    """C of Eq. 13"""
    curiosity_decay: float = setting(2e-5, _WEIGHT)
    """lambda of Eq. 13, per environment step"""
    r_e_max_init: float = setting(1.0, real(0.0, open_low=True))
    """initial running maximum of the extrinsic reward (Eq. 13)"""
    r_i_max_init: float = setting(1.0, real(0.0, open_low=True))
    """initial running maximum of the raw consistency distance (Eq. 13)"""
    transition_weight: float = setting(1.0, _WEIGHT)
    """weight of L_tran in Eq. 14 (encoders with a motion path)"""
    contrastive_weight: float = setting(1.0, _WEIGHT)
    """weight of L_con in Eq. 14"""
    reward_weight: float = setting(1.0, _WEIGHT)
    """weight of L_re in Eq. 14"""
    num_frames: int = setting(3, _POSITIVE)
    """frames per observation (the paper uses 3: o_{t-2}, o_{t-1}, o_t)"""
    reduce_kernel: int = setting(3, _POSITIVE)
    """kernel of the reducing convs of the interactive module (35x35 -> 11x11 with stride 3)"""
    reduce_stride: int = setting(3, _POSITIVE)
    """stride of the reducing convs of the interactive module"""
    random_conv_kernel: int = setting(
        3, integer(1, odd=True, fix="an odd kernel keeps the image size: 3")
    )
    """kernel size of the random convolution that makes contrastive positives (Eq. 3). Expect
    L_con to sit at log(batch_size) for the first 100-300 updates while f_a collapses (spread
    across samples ~0.003) and then fall: measured on dm_control cartpole-swingup 48x48, batch 32"""
    detach_past_frames: bool = setting(True, boolean())
    """dual encoders: frames t-2 and t-1 go through the appearance path without gradient (as
    Flare detaches earlier frames); the interactive module and frame t still get gradients.
    False backpropagates through all three frames (about 4 more batch-sized conv backward passes
    per update)"""
    channels_last: bool = setting(True, boolean())
    """run the convs in channels-last memory format (measured ~25% faster conv forward+backward
    on our AVX-512 CPU; benchmarks/update.py --no-channels-last compares)"""

    def __post_init__(self) -> None:
        check_agent_config(self)  # every field, then cross-field


def with_recipe(generated_init: Callable[..., None]) -> Callable[..., None]:
    """``AgentConfig``'s ``__init__``: the dataclass's, given the recipe's values for every
    field the caller did not give (an unknown recipe is left to the field's rule to refuse)."""
    names = [f.name for f in dataclasses.fields(AgentConfig)]

    @functools.wraps(generated_init)
    def __init__(self: AgentConfig, *args: Any, **kwargs: Any) -> None:
        refuse_train_keywords(kwargs)
        given = {*names[: len(args)], *kwargs}
        recipe = args[0] if args else kwargs.get("recipe")
        if isinstance(recipe, str) and recipe in RECIPES:
            values = RECIPES[recipe].values_for(None)
            kwargs.update({key: value for key, value in values.items() if key not in given})
        generated_init(self, *args, **kwargs)

    return __init__


def refuse_train_keywords(kwargs: dict[str, Any]) -> None:
    """A TypeError for a keyword of ``AgentConfig`` that is no field of it, naming
    ``TrainConfig`` when the setting is that class's (``device``, ``seed``)."""
    from simoun_agent.config.train import TrainConfig  # train.py imports this module

    def where(name: str, value: Any) -> str:
        flag = "--" + name.replace("_", "-")
        extra = (
            " (a loaded run or a bare agent takes it too: load_run(path, device=...), "
            "SimounAgent(frame_shape, action_dim, config, device=...))"
            if name == "device"
            else ""
        )
        return f"set it there, TrainConfig({name}={value!r}), or {flag} on the command line{extra}"

    refuse_unknown(AgentConfig, kwargs, TrainConfig, where)


AgentConfig.__init__ = with_recipe(AgentConfig.__init__)  # type: ignore[method-assign]


def check_agent_config(config: Any) -> None:
    """Every field of an ``AgentConfig``, then the constraints between fields."""
    check_fields(config, AGENT)
    if config.log_std_min >= config.log_std_max:
        raise fail(
            config,
            AGENT,
            "log_std_min",
            f"must be below {knob(config, AGENT, 'log_std_max', config.log_std_max)}; e.g. -10 "
            "and 2",
        )
    for name in ("critic_augmentations", "target_augmentations"):
        if getattr(config, name) > 1 and config.augmentation == "none":
            raise fail(
                config,
                AGENT,
                name,
                "several views of one sample need a random augmentation, and augmentation is "
                f"'none' (every view would be the same); set "
                f"{knob(config, AGENT, 'augmentation', 'shift')} or {knob(config, AGENT, name, 1)}",
            )
    check_read_settings(config)
    check_exploration_schedule(config)
    if config.separate_trunks:
        check_separate_trunks(config)
    motion_path = ENCODER_SHAPES[config.encoder].motion_path
    if config.num_frames != 3 and motion_path:
        raise fail(
            config,
            AGENT,
            "num_frames",
            f"the dual-path encoder {config.encoder!r} needs 3 frames (o_t-2, o_t-1, o_t); "
            f"set {knob(config, AGENT, 'num_frames', 3)}",
        )
    if config.num_frames < 2 and ENCODER_SHAPES[config.encoder].latent_flow:
        raise fail(
            config,
            AGENT,
            "num_frames",
            f"the encoder {config.encoder!r} learns from the latent flow between successive "
            "frames, which one frame does not have; set "
            f"{knob(config, AGENT, 'num_frames', 3)}, or "
            f"{knob(config, AGENT, 'encoder', 'single')} for one frame",
        )
    if config.curiosity and not motion_path:
        raise fail(
            config,
            AGENT,
            "curiosity",
            f"curiosity (Eq. 13) compares the motion and appearance paths, which encoder "
            f"{config.encoder!r} does not have; set {knob(config, AGENT, 'curiosity', False)} "
            "or use a dual encoder",
        )


@dataclass(frozen=True)
class ReadOnlyWith:
    """Fields that only one part of the agent reads, and when a config uses that part. Given a
    value of their own while the part is off, they would change nothing: a user expecting
    DrQ-v2's exploration schedule on the Gaussian actor, or a curiosity scale without
    curiosity, would train as if they had not been set."""

    fields: tuple[str, ...]
    """the AgentConfig fields only the part reads"""
    part: str
    """the part, completing "is read only by ..." """
    used: Callable[[Any], bool]
    """whether a config uses the part"""
    state: Callable[[Any], str]
    """why a config that does not use the part does not, e.g. "curiosity is false" """
    turn_on: Callable[[Any], str]
    """the setting that turns the part on, as :func:`knob` writes it"""


def _uses_shift(config: Any) -> bool:
    return config.augmentation == "shift" or (
        bool(config.contrastive_weight) and config.contrastive_view == "shift"
    )


def _uses_random_conv(config: Any) -> bool:
    return bool(config.contrastive_weight) and config.contrastive_view == "random_conv"


READ_ONLY_WITH = (
    ReadOnlyWith(
        ("shift_pad",),
        "the shift (the augmentation, or CURL's contrastive view)",
        _uses_shift,
        lambda c: f"augmentation is {c.augmentation!r} and the contrastive view is no shift",
        lambda c: f"{knob(c, AGENT, 'augmentation', 'shift')} to shift the frames",
    ),
    ReadOnlyWith(
        ("curiosity_scale", "curiosity_decay", "r_e_max_init", "r_i_max_init"),
        "the intrinsic reward of Eq. 13",
        lambda c: c.curiosity,
        lambda c: "curiosity is false",
        lambda c: knob(c, AGENT, "curiosity", True) + " with a dual encoder",
    ),
    ReadOnlyWith(
        ("exploration_std_start", "exploration_std_end", "exploration_steps", "noise_clip"),
        "the deterministic actor (DrQ-v2's scheduled exploration noise)",
        lambda c: c.actor == "deterministic",
        lambda c: f"the actor is {c.actor!r}, whose exploration is SAC's learned entropy",
        lambda c: knob(c, AGENT, "actor", "deterministic"),
    ),
    ReadOnlyWith(
        ("init_temperature", "alpha_lr", "alpha_beta", "log_std_min", "log_std_max"),
        "the Gaussian actor (SAC's temperature and its policy's std bounds)",
        lambda c: c.actor == "gaussian",
        lambda c: f"the actor is {c.actor!r}, which has no temperature and no learned std",
        lambda c: knob(c, AGENT, "actor", "gaussian"),
    ),
    ReadOnlyWith(
        ("contrastive_view", "contrastive_step", "similarity_init"),
        "L_con (Eq. 3)",
        lambda c: bool(c.contrastive_weight),
        lambda c: "contrastive_weight is 0",
        lambda c: knob(c, AGENT, "contrastive_weight", 1.0),
    ),
    ReadOnlyWith(
        ("random_conv_kernel",),
        "the random convolution of L_con's positives (Eq. 3)",
        _uses_random_conv,
        lambda c: (
            "contrastive_weight is 0"
            if not c.contrastive_weight
            else f"the contrastive view is {c.contrastive_view!r}"
        ),
        lambda c: (
            f"{knob(c, AGENT, 'contrastive_weight', 1.0)} and "
            f"{knob(c, AGENT, 'contrastive_view', 'random_conv')}"
        ),
    ),
    ReadOnlyWith(
        ("reduce_kernel", "reduce_stride"),
        "the interactive module's reducing convs",
        lambda c: ENCODER_SHAPES[c.encoder].interactive,
        lambda c: f"encoder {c.encoder!r} has no interactive module",
        lambda c: knob(c, AGENT, "encoder", "dual_interactive"),
    ),
    ReadOnlyWith(
        ("detach_past_frames",),
        "the dual-path encoders' appearance path",
        lambda c: ENCODER_SHAPES[c.encoder].motion_path,
        lambda c: f"encoder {c.encoder!r} has no appearance path",
        lambda c: (
            f"{knob(c, AGENT, 'encoder', 'dual_interactive')} or "
            f"{knob(c, AGENT, 'encoder', 'dual')}"
        ),
    ),
)
"""Every AgentConfig field read only when another setting turns its part on (``shift_pad``
with a shift, the curiosity constants with curiosity, the exploration schedule with the
deterministic actor, ...). ``independent_next_shift`` is not among them: the recipes carry it
as how their method shifts once a shift is asked for."""


def check_read_settings(config: Any) -> None:
    """Refuse a field of :data:`READ_ONLY_WITH` given a value of its own (neither its default
    nor one its recipe gives) while its part is off, naming the setting that turns the part on
    and the field's default."""
    for group in READ_ONLY_WITH:
        if group.used(config):
            continue
        for name in group.fields:
            default = dataclass_default(name)
            if getattr(config, name) == default or given_by_recipe(config, name):
                continue
            raise fail(
                config,
                AGENT,
                name,
                f"is read only by {group.part}, which this config does not use "
                f"({group.state(config)}), so it would change nothing; set "
                f"{group.turn_on(config)}, or {knob(config, AGENT, name, default)}",
            )


def dataclass_default(name: str) -> Any:
    """The default of the AgentConfig field ``name``."""
    return next(f.default for f in dataclasses.fields(AgentConfig) if f.name == name)


def given_by_recipe(config: Any, name: str) -> bool:
    """Whether ``config``'s recipe gives field ``name`` its value (on any task): a recipe's
    value stays, whatever the user turned off after choosing the recipe (``drqv2`` with the
    Gaussian actor keeps its schedule, unread)."""
    recipe = RECIPES.get(config.recipe) if isinstance(config.recipe, str) else None
    if recipe is None:
        return False
    values = [recipe.values, *recipe.per_task.values()]
    return any(name in given and given[name] == getattr(config, name) for given in values)


def check_exploration_schedule(config: Any) -> None:
    """The deterministic actor's noise falls (or stays): one rising from ``start`` to ``end``
    is almost surely the two swapped, as a ``log_std_min`` above ``log_std_max`` is."""
    start, end = config.exploration_std_start, config.exploration_std_end
    if config.actor == "deterministic" and end > start:
        raise fail(
            config,
            AGENT,
            "exploration_std_end",
            f"is above {knob(config, AGENT, 'exploration_std_start', start)}: the exploration "
            f"noise would rise over training, where DrQ-v2's falls (1.0 -> 0.1); swap them, "
            f"{knob(config, AGENT, 'exploration_std_start', end)} and "
            f"{knob(config, AGENT, 'exploration_std_end', start)}, or give both the same value "
            "for a constant noise",
        )


def check_separate_trunks(config: Any) -> None:
    """Trunks on the flat conv maps need an encoder that ends at its convs, and no auxiliary
    loss reading the state (it would read the 10^4-wide maps)."""
    if not ENCODER_SHAPES[config.encoder].conv_state:
        usable = [name for name, shape in ENCODER_SHAPES.items() if shape.conv_state]
        encoders = " or ".join(knob(config, AGENT, "encoder", name) for name in usable)
        raise fail(
            config,
            AGENT,
            "separate_trunks",
            f"the actor's and critic's own trunks need an encoder that ends at its convs, and "
            f"{config.encoder!r} does not; use {encoders}, or "
            f"{knob(config, AGENT, 'separate_trunks', False)}",
        )
    for name in ("transition_weight", "contrastive_weight", "reward_weight"):
        if getattr(config, name):
            raise fail(
                config,
                AGENT,
                name,
                "the auxiliary losses read the encoder's state, which with separate trunks is "
                f"the flat conv maps; set {knob(config, AGENT, name, 0.0)} or "
                f"{knob(config, AGENT, 'separate_trunks', False)}",
            )
