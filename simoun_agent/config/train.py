"""Training configuration: the ``TrainConfig`` dataclass, each field with its rule.

How a run's config is resolved from presets, recipes and the user's overrides:
:mod:`simoun_agent.config.resolve`.
"""

from __future__ import annotations

import dataclasses
import functools
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from simoun_agent.config.agent import AGENT, AgentConfig, check_agent_config, dataclass_default
from simoun_agent.config.device import device_problem
from simoun_agent.config.envs import PAPER_ACTION_REPEAT, dmc_task, split_env_id
from simoun_agent.config.keywords import refuse_unknown
from simoun_agent.config.presets import PRESETS
from simoun_agent.config.rules import (
    Rule,
    boolean,
    check_fields,
    closest_name,
    fail,
    integer,
    is_int,
    json_object,
    knob,
    module_name,
    optional_name,
    path,
    setting,
    show,
    text,
    with_rule,
)
from simoun_agent.config.shapes import (
    ENCODER_SHAPES,
    conv_output_size,
    frame_fits,
    kernel_fits,
    largest_odd,
    min_image_size,
)

_POSITIVE = integer(1)

DISTRACTION_MODES = ("color_easy", "color_hard", "video_easy", "video_hard")
"""DMC-GB's test modes, the names ``eval_distraction`` takes (the suite's wrappers of them:
:data:`simoun_agent.generalization.DISTRACTIONS`, whose ``train`` is the run's own env)."""

_UNDISTRACTED = ("train", "none", "null", "off", "no", "clean")
"""What a user writes for the run's own, undistracted evaluation."""


def _is_modes(value: Any) -> bool:
    return isinstance(value, (tuple, list)) and all(
        isinstance(name, str) and name in DISTRACTION_MODES for name in value
    )


def _closest_modes(value: Any) -> str:
    """The fix of a refused ``eval_distraction``: one string given for the list (its names
    corrected), the undistracted evaluation named (it always runs), or a misspelled mode's
    close match; empty when there is none."""
    if isinstance(value, str):
        names = [name.strip() for name in value.split(",") if name.strip()]
        corrected = [_closest_mode(name) or name for name in names]
        return f" (a list, not one string: did you mean {corrected!r}?)"
    if not isinstance(value, (tuple, list)):
        return ""
    wrong = [name for name in value if name not in DISTRACTION_MODES]
    if not wrong or not isinstance(wrong[0], str):
        return ""
    if wrong[0] == "train":
        return " ('train' is the run's own evaluation, which always runs; leave it out)"
    if wrong[0].lower() in _UNDISTRACTED:
        return (
            f" ({wrong[0]!r}: for no distraction, leave it out: the run's own evaluation always "
            "runs)"
        )
    close = _closest_mode(wrong[0])
    return f" ({wrong[0]!r}: did you mean {close!r}?)" if close else f" ({wrong[0]!r} is not one)"


def _closest_mode(name: str) -> str | None:
    return closest_name(name, DISTRACTION_MODES)


_DISTRACTION_MODES_RULE = Rule(
    f"a list of distraction modes, each one of {', '.join(DISTRACTION_MODES)}",
    _is_modes,
    "e.g. --eval-distraction video_hard,color_easy, or in Python "
    "eval_distraction=['video_hard', 'color_easy']",
    _closest_modes,
)


@dataclass
class TrainConfig:
    """Everything a training run needs; saved with the run as ``config.json``."""

    env: str = setting(
        "dm_control/cartpole-swingup-v0", text(fix="e.g. --env dm_control/cartpole-swingup-v0")
    )
    """Gymnasium id: a dm_control task through shimmy, a highway-env id, any pixel/renderable env;
    MODULE:ID (Gymnasium's form, e.g. minigrid:MiniGrid-DoorKey-6x6-v0) imports MODULE first and
    is saved as env ID plus env_module MODULE"""
    env_module: str | None = setting(
        None, module_name(optional=True, fix="e.g. --env-module minigrid, or none")
    )
    """module imported before the env is made, for ids that a package registers on import (e.g.
    ale_py, minigrid); saved with the run, so --resume and simoun-eval import it too"""
    env_kwargs: dict = field(
        default_factory=dict,
        metadata=with_rule(json_object(fix='e.g. --env-kwargs \'{"config": {"lanes_count": 3}}\'')),
    )
    """extra keyword arguments for gymnasium.make (JSON on the command line)"""
    preset: str | None = setting(None, optional_name(PRESETS))
    """name of the preset this config started from (informational)"""
    seed: int = setting(
        1, Rule("an int in [0, 2**32)", lambda v: is_int(v) and 0 <= v < 2**32, "e.g. --seed 1")
    )
    """seed of every random stream (episodes, replay, torch, numpy, python): each is a child of
    numpy's SeedSequence(seed), so runs of different seeds share no episode"""
    action_repeat: int | None = setting(
        None,
        integer(
            1,
            optional=True,
            fix="e.g. --action-repeat 8, or none for the paper's value of a DMC task (1 otherwise)",
        ),
    )
    """env steps per agent decision (frame skip); None: the paper's value for its six DMC tasks,
    else 1"""
    image_size: int = setting(84, _POSITIVE)
    """height and width of each camera view fed to the agent"""
    grayscale: bool = setting(False, boolean())
    """feed grayscale frames (1 channel) instead of RGB"""
    cameras: int = setting(1, _POSITIVE)
    """viewports concatenated along the width (dm_control camera ids 0..n-1; highway-env: 3 views
    around the ego vehicle)"""
    total_env_steps: int = setting(500_000, _POSITIVE)
    """length of the run in environment steps (agent decisions x action repeat)"""
    warmup_agent_steps: int = setting(1000, integer(0))
    """agent decisions taken uniformly at random before learning starts"""
    updates_per_step: int = setting(1, _POSITIVE)
    """gradient updates per agent decision once learning has started (at every
    ``agent.update_every_steps``-th decision)"""
    replay_capacity: int = setting(100_000, _POSITIVE)
    """transitions kept in the replay buffer"""
    eval_every: int = setting(10_000, _POSITIVE)
    """environment steps between evaluations (run at the next episode end)"""
    eval_episodes: int = setting(10, _POSITIVE)
    """episodes per evaluation (deterministic actions)"""
    eval_distraction: tuple[str, ...] = setting((), _DISTRACTION_MODES_RULE)
    """distraction modes also evaluated at every evaluation, as test curves beside the training
    env's (dm_control tasks; repeat the flag, e.g. --eval-distraction video_hard; modes in
    simoun_agent.generalization.DISTRACTIONS)"""
    checkpoint_every: int = setting(50_000, _POSITIVE)
    """environment steps between checkpoints (written at the next episode end). One that does
    not fit on the disk keeps the previous one and is tried again at the next; after 3 failures
    in a row, or at a stop or the run's end, the run stops with exit status 75 (free space, then
    --resume)"""
    video: bool = setting(True, boolean())
    """record one evaluation episode to video.mp4 at the end of the run"""
    device: str | None = setting(
        None, text(optional=True, fix="e.g. --device cpu, cuda, cuda:0 or mps")
    )
    """torch device; None: cuda when available, else cpu"""
    torch_threads: int | None = setting(None, integer(1, optional=True))
    """torch intra-op threads; None: torch's default"""
    env_process: bool = setting(False, boolean())
    """step the training environment in a background process while the agent updates (a
    second core works on physics and rendering; results are identical either way)"""
    run_dir: str | None = setting(None, path(optional=True, fix="e.g. --run-dir runs/my-run"))
    """output directory; None: runs/<env>-<preset>-s<seed>-<date>"""
    progress: bool = setting(True, boolean())
    """true/false: a progress bar on a terminal (false, or no terminal: one line per
    evaluation)"""
    agent: AgentConfig = field(
        default_factory=AgentConfig,
        metadata=with_rule(Rule("an AgentConfig", lambda v: dataclasses.is_dataclass(v))),
    )
    """the agent's hyperparameters (simoun_agent.config.AgentConfig)"""

    def __post_init__(self) -> None:
        module, env_id = split_env_id(self.env) if isinstance(self.env, str) else (None, self.env)
        if module:
            if self.env_module not in (None, module):
                raise ValueError(
                    f"--env {self.env} names the module {module!r} but --env-module is "
                    f"{self.env_module!r}; give the module once"
                )
            self.env, self.env_module = env_id, module
        if isinstance(self.run_dir, os.PathLike):  # kept as a str: config.json is JSON
            self.run_dir = os.fspath(self.run_dir)
        check_train_config(self)

    def resolved_action_repeat(self) -> int:
        """The action repeat to use: the explicit value, the paper's for a DMC task, or 1."""
        if self.action_repeat is not None:
            return self.action_repeat
        return PAPER_ACTION_REPEAT.get(dmc_task(self.env), 1)


RESUMABLE_FIELDS = (
    "total_env_steps",
    "eval_every",
    "checkpoint_every",
    "progress",
    "video",
    "env_process",
    "torch_threads",
    "device",
    "eval_distraction",
)
"""Fields a resumed run may change: how long and how it runs and reports, not what it learns
(torch_threads changes speed only; device is where the run goes on: a run trained on a GPU
resumes on a machine without one); every other field must match the saved config."""


def refuse_agent_keywords(generated_init: Callable[..., None]) -> Callable[..., None]:
    """``TrainConfig``'s ``__init__``, refusing a keyword that is no field of it and naming
    ``AgentConfig`` when the setting is that class's (``lr``, ``batch_size``)."""

    @functools.wraps(generated_init)
    def __init__(self: TrainConfig, *args: Any, **kwargs: Any) -> None:
        refuse_unknown(TrainConfig, kwargs, AgentConfig, on_the_agent)
        generated_init(self, *args, **kwargs)

    return __init__


def on_the_agent(name: str, value: Any) -> str:
    """Where an agent setting goes, in Python and on the command line."""
    flag = "--agent." + name.replace("_", "-")
    return (
        f"set it on the agent, TrainConfig(agent=AgentConfig({name}={value!r})), or "
        f"{flag} {show(value)} on the command line"
    )


TrainConfig.__init__ = refuse_agent_keywords(TrainConfig.__init__)  # type: ignore[method-assign]


def check_agent_field(config: TrainConfig) -> None:
    """A ValueError unless ``config.agent`` is an AgentConfig, with the fix in the form the user
    is in: a dict set in Python becomes the ``AgentConfig(...)`` call of its values (there is no
    ``--agent`` flag; its fields are ``--agent.NAME``)."""
    agent = config.agent
    if isinstance(agent, AgentConfig):
        return
    if isinstance(agent, Mapping) and agent and all(isinstance(key, str) for key in agent):
        call = ", ".join(f"{key}={value!r}" for key, value in agent.items())
        flags = " ".join(f"--agent.{key.replace('_', '-')} {show(v)}" for key, v in agent.items())
        fix = (
            f"in Python set config.agent = AgentConfig({call}) (from simoun_agent.config); on "
            f"the command line {flags}"
        )
    else:
        fix = (
            "in Python set e.g. config.agent = AgentConfig(lr=1e-3) or AgentConfig(recipe='drq') "
            "(from simoun_agent.config); on the command line --agent.NAME VALUE, e.g. "
            "--agent.lr 0.001"
        )
    raise ValueError(
        f"TrainConfig.agent must be an AgentConfig, got {type(agent).__name__} {agent!r:.60}; {fix}"
    )


def check_train_config(config: TrainConfig) -> None:
    """Every field of a ``TrainConfig`` and of its ``AgentConfig`` (checked again: either may
    have been changed since it was built), then the constraints between fields."""
    check_agent_field(config)
    check_fields(config, "")
    if isinstance(config.agent, AgentConfig):
        check_agent_config(config.agent)
    if config.device is not None and (problem := device_problem(config.device)):
        raise fail(config, "", "device", problem)
    if config.replay_capacity < config.agent.batch_size:
        batch = config.agent.batch_size
        raise fail(
            config,
            "",
            "replay_capacity",
            f"the replay must hold at least one batch "
            f"({knob(config.agent, AGENT, 'batch_size', batch)}); set "
            f"{knob(config, '', 'replay_capacity', batch)} or more, or lower the batch size",
        )
    check_frame_size(config)


def check_frame_size(config: TrainConfig) -> None:
    """The frame size against every conv that runs over the frames: the encoder's (its
    reducing conv too) and the random convolution of L_con's positives. Each refusal names
    every flag that would fix it, the agent's as well as ``--image-size``."""
    size, agent = config.image_size, config.agent
    if not frame_fits(agent, size, size * config.cameras):
        raise fail(config, "", "image_size", too_small_for_encoder(config))
    if not kernel_fits(agent, size, size * config.cameras):
        kernel = agent.random_conv_kernel
        raise fail(
            agent,
            AGENT,
            "random_conv_kernel",
            f"the random convolution of L_con's positives (Eq. 3) runs over the {size}x{size} "
            f"frames of {knob(config, '', 'image_size', size)}, and a kernel wider than the "
            f"frame sees only its padding; set {knob(agent, AGENT, 'random_conv_kernel', 3)} "
            f"(the paper's; any odd value up to {largest_odd(size)}), or "
            f"{knob(config, '', 'image_size', kernel)} or more, or "
            f"{knob(agent, AGENT, 'contrastive_view', 'shift')} and "
            f"{knob(agent, AGENT, 'random_conv_kernel', 3)} (a shift reads no kernel)",
        )


def reducing_resets(agent: AgentConfig) -> list[str]:
    """The reducing conv settings of ``agent`` away from their defaults, each as the setting
    that puts it back: an encoder without the interactive module reads none, and refuses them
    (:data:`~simoun_agent.config.agent.READ_ONLY_WITH`)."""
    return [
        knob(agent, AGENT, name, dataclass_default(name))
        for name in ("reduce_kernel", "reduce_stride")
        if getattr(agent, name) != dataclass_default(name)
    ]


def too_small_for_encoder(config: TrainConfig) -> str:
    """Why ``config.image_size`` is too small for its encoder, and every setting that fixes it:
    the image size, and for the interactive encoder its reducing kernel and an encoder without
    that conv, where the trunk alone fits."""
    agent, size = config.agent, config.image_size
    fixes = [f"{knob(config, '', 'image_size', min_image_size(agent))} or more"]
    if not ENCODER_SHAPES[agent.encoder].interactive:
        return (
            f"too small for the conv trunk of encoder {agent.encoder!r}; set {fixes[0]} (the "
            "paper uses 84)"
        )
    widest = conv_output_size(size)  # the side of the trunk's last map: the widest reducing conv
    if widest >= 1:
        fixes.append(
            knob(agent, AGENT, "reduce_kernel", widest) + (" or less" if widest > 1 else "")
        )
        fixes.append(
            f"{knob(agent, AGENT, 'encoder', 'dual')}, which has no reducing conv"
            + "".join(f" and {reset}" for reset in reducing_resets(agent))
        )
    return (
        f"too small for the conv trunk of encoder {agent.encoder!r} with "
        f"{knob(agent, AGENT, 'reduce_kernel', agent.reduce_kernel)}; set "
        f"{', or '.join(fixes)} (the paper uses 84, with a reducing kernel of 3)"
    )
