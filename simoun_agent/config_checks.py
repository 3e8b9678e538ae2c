"""Checks of every config value, each error naming the flag, the value and the fix.

``AgentConfig`` and ``TrainConfig`` call :func:`check_fields` from ``__post_init__`` with a
table of :class:`Rule` per field, then their cross-field checks, so a bad value fails when the
config is built (command line, preset, Python or a saved ``config.json``), not deep inside torch
later. Errors are ``ValueError``; the command-line tools print them without a traceback.

Example:
    >>> from simoun_agent.config import AgentConfig
    >>> AgentConfig(batch_size=0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ValueError: --agent.batch-size 0 (AgentConfig.batch_size) must be an int >= 1; e.g. ...
"""

from __future__ import annotations

import dataclasses
import json
import math
import numbers
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from gymnasium import spaces


@dataclass(frozen=True)
class Rule:
    """What one field accepts: ``ok(value)``, described as ``need`` (``"an int >= 1"``)."""

    need: str
    """the accepted values in words, completing "must be ..." """
    ok: Callable[[Any], bool]
    """True for an accepted value"""
    fix: str = ""
    """advice after the error; empty: suggest the field's default"""


def _is_int(value: Any) -> bool:
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _is_real(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)


def integer(low: int, optional: bool = False, fix: str = "", odd: bool = False) -> Rule:
    """An int ``>= low`` (odd when ``odd``), or None when ``optional``."""
    need = f"an {'odd ' if odd else ''}int >= {low}" + (" or none" if optional else "")
    return Rule(
        need,
        lambda v: (optional and v is None) or (_is_int(v) and v >= low and (not odd or v % 2)),
        fix,
    )


def real(low: float, high: float | None = None, open_low: bool = False, fix: str = "") -> Rule:
    """A finite number in ``[low, high]`` (``(low, ...`` when ``open_low``)."""
    bounds = f"> {low:g}" if open_low else f">= {low:g}"
    need = f"a number {bounds}" + (f" and <= {high:g}" if high is not None else "")
    return Rule(
        need,
        lambda v: (
            _is_real(v) and (v > low if open_low else v >= low) and (high is None or v <= high)
        ),
        fix,
    )


def finite() -> Rule:
    return Rule("a finite number", _is_real)


def boolean() -> Rule:
    return Rule("true or false", lambda v: isinstance(v, bool))


def one_of(options: Sequence[str]) -> Rule:
    return Rule("a known name", lambda v: v in options, f"choose one of {', '.join(options)}")


def text(optional: bool = False, fix: str = "") -> Rule:
    need = "a non-empty string" + (" or none" if optional else "")
    return Rule(need, lambda v: (optional and v is None) or (isinstance(v, str) and v != ""), fix)


def json_object(fix: str = "") -> Rule:
    return Rule("a JSON object (a dict)", lambda v: isinstance(v, dict), fix)


def flag_name(prefix: str, name: str) -> str:
    """``("agent.", "batch_size")`` -> ``"--agent.batch-size"``, the command-line flag."""
    return "--" + prefix + name.replace("_", "-")


def shown(value: Any) -> str:
    """``value`` as typed on the command line: true/false, none, JSON dicts."""
    if isinstance(value, bool):
        return str(value).lower()
    if value is None:
        return "none"
    if isinstance(value, dict):
        return json.dumps(value)
    return str(value)


def check_fields(config: Any, rules: dict[str, Rule], prefix: str) -> None:
    """Raise ValueError for the first field of ``config`` that breaks its rule.

    Every field must have a rule (a new field without one is a programming error), so nothing
    reaches the agent unchecked.
    """
    cls = type(config).__name__
    unruled = [f.name for f in dataclasses.fields(config) if f.name not in rules]
    if unruled:
        raise TypeError(f"{cls} fields without a check in {__name__}: {', '.join(unruled)}")
    for f in dataclasses.fields(config):
        rule = rules.get(f.name)
        if rule is None or dataclasses.is_dataclass(getattr(config, f.name)):
            continue
        value = getattr(config, f.name)
        if not rule.ok(value):
            flag = flag_name(prefix, f.name)
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            fix = rule.fix or f"e.g. {flag} {shown(default)} (the default)"
            raise ValueError(f"{flag} {shown(value)} ({cls}.{f.name}) must be {rule.need}; {fix}")


def fail(prefix: str, name: str, value: Any, problem: str) -> ValueError:
    """A ValueError for a cross-field problem: ``--flag value: problem``."""
    return ValueError(f"{flag_name(prefix, name)} {shown(value)}: {problem}")


@lru_cache(maxsize=64)
def _encoder_fits(agent_json: str, channels: int, height: int, width: int) -> bool:
    import torch

    from simoun_agent.config import AgentConfig
    from simoun_agent.models.encoder import ENCODERS

    config = AgentConfig(**json.loads(agent_json))
    frames = torch.zeros(2, config.num_frames, channels, height, width, dtype=torch.uint8)
    try:
        # Shapes only: on the meta device nothing is allocated or computed (a few ms).
        with torch.device("meta"), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "Initializing zero-element tensors is a no-op"
            encoder = ENCODERS[config.encoder].build(config, (channels, height, width))
            encoder(frames.to("meta"))
    except (RuntimeError, ValueError):
        return False
    return True


def min_image_size(agent: Any, channels: int, cameras: int) -> int | None:
    """The smallest square camera view the encoder of ``agent`` (an AgentConfig) accepts, found
    by building it on torch's meta device; None if no size up to 512 fits."""
    key = _agent_key(agent)
    for size in range(1, 513):
        if _encoder_fits(key, channels, size, size * cameras):
            return size
    return None


def image_fits(agent: Any, size: int, channels: int, cameras: int) -> bool:
    """Whether the encoder of ``agent`` accepts ``size`` x ``size * cameras`` frames."""
    return _encoder_fits(_agent_key(agent), channels, size, size * cameras)


def _agent_key(agent: Any) -> str:
    return json.dumps(dataclasses.asdict(agent), sort_keys=True)


def device_problem(device: str) -> str | None:
    """Why torch cannot use ``device`` on this machine, or None when it can."""
    import torch

    try:
        parsed = torch.device(device)
    except (RuntimeError, TypeError) as err:
        return f"not a torch device ({err}); use cpu, cuda, cuda:N or mps"
    if parsed.type == "cuda":
        if not torch.cuda.is_available():
            return (
                f"this torch ({torch.__version__}) sees no CUDA GPU; use --device cpu, or leave "
                "--device unset to pick cuda only when there is one"
            )
        count = torch.cuda.device_count()
        if parsed.index is not None and parsed.index >= count:
            return f"there are {count} CUDA device(s), numbered 0..{count - 1}; use one of them"
    elif parsed.type == "mps" and not torch.backends.mps.is_available():
        return "MPS is not available on this machine; use --device cpu"
    elif parsed.type not in ("cpu", "cuda", "mps"):
        return f"device type {parsed.type!r} is not supported here; use cpu, cuda or mps"
    return None


AGENT = "agent."
"""Flag prefix of AgentConfig's fields (``--agent.batch-size``)."""


@lru_cache(maxsize=1)
def agent_rules() -> dict[str, Rule]:
    """The rule of every ``AgentConfig`` field (built on first use: the registries need torch)."""
    from simoun_agent.config import AUGMENTATIONS, CONTRASTIVE_VIEWS, NEXT_STATE_ENCODERS
    from simoun_agent.models.actors import ACTORS
    from simoun_agent.models.encoder import ENCODERS
    from simoun_agent.recipes import RECIPES

    positive = integer(1)
    rate = real(0.0, 1.0, open_low=True)
    weight = real(0.0)
    return {
        "recipe": Rule(f"none or one of {', '.join(RECIPES)}", lambda v: v is None or v in RECIPES),
        "encoder": one_of(list(ENCODERS)),
        "augmentation": one_of(AUGMENTATIONS),
        "shift_pad": integer(0, optional=True),
        "critic_augmentations": positive,
        "target_augmentations": positive,
        "next_state_encoder": one_of(NEXT_STATE_ENCODERS),
        "contrastive_view": one_of(CONTRASTIVE_VIEWS),
        "feature_dim": positive,
        "num_filters": positive,
        "hidden_dim": positive,
        "aux_hidden_dim": positive,
        "batch_size": positive,
        "lr": real(0.0, open_low=True),
        "alpha_lr": real(0.0, open_low=True),
        "alpha_beta": Rule(
            "a number in [0, 1) (Adam's beta1)", lambda v: _is_real(v) and 0 <= v < 1
        ),
        "discount": real(0.0, 1.0),
        "n_step": positive,
        "critic_tau": rate,
        "encoder_tau": rate,
        "actor_update_every": positive,
        "target_update_every": positive,
        "actor": one_of(list(ACTORS)),
        "exploration_std_start": real(0.0),
        "exploration_std_end": real(0.0),
        "exploration_steps": positive,
        "noise_clip": real(0.0),
        "init_temperature": real(0.0, open_low=True),
        "log_std_min": finite(),
        "log_std_max": finite(),
        "curiosity": boolean(),
        "curiosity_scale": weight,
        "curiosity_decay": weight,
        "r_e_max_init": real(0.0, open_low=True),
        "r_i_max_init": real(0.0, open_low=True),
        "transition_weight": weight,
        "contrastive_weight": weight,
        "reward_weight": weight,
        "num_frames": positive,
        "reduce_kernel": positive,
        "reduce_stride": positive,
        "random_conv_kernel": integer(1, odd=True, fix="an odd kernel keeps the image size: 3"),
        "detach_past_frames": boolean(),
        "channels_last": boolean(),
    }


def check_agent_config(config: Any) -> None:
    """Every field of an ``AgentConfig``, then the constraints between fields."""
    from simoun_agent.models.encoder import ENCODERS

    check_fields(config, agent_rules(), AGENT)
    if config.log_std_min >= config.log_std_max:
        raise fail(
            AGENT,
            "log_std_min",
            config.log_std_min,
            f"must be below --agent.log-std-max {config.log_std_max:g}; e.g. -10 and 2",
        )
    for name in ("critic_augmentations", "target_augmentations"):
        if getattr(config, name) > 1 and config.augmentation == "none":
            raise fail(
                AGENT,
                name,
                getattr(config, name),
                "several views of one sample need a random augmentation, and augmentation is "
                f"'none' (every view would be the same); set --agent.augmentation shift or "
                f"--agent.{name.replace('_', '-')} 1",
            )
    motion_path = ENCODERS[config.encoder].motion_path
    if config.num_frames != 3 and motion_path:
        raise fail(
            AGENT,
            "num_frames",
            config.num_frames,
            f"the dual-path encoder {config.encoder!r} needs 3 frames (o_t-2, o_t-1, o_t); "
            "set --agent.num-frames 3 (AgentConfig(num_frames=3))",
        )
    if config.curiosity and not motion_path:
        raise fail(
            AGENT,
            "curiosity",
            True,
            f"curiosity (Eq. 13) compares the motion and appearance paths, which encoder "
            f"{config.encoder!r} does not have; set --agent.curiosity false "
            "(AgentConfig(curiosity=False)) or use a dual encoder",
        )


@lru_cache(maxsize=1)
def train_rules() -> dict[str, Rule]:
    """The rule of every ``TrainConfig`` field but ``agent`` (checked by ``AgentConfig``)."""
    from simoun_agent.run.presets import PRESETS

    positive = integer(1)
    return {
        "env": text(fix="e.g. --env dm_control/cartpole-swingup-v0"),
        "env_module": text(optional=True, fix="e.g. --env-module minigrid, or none"),
        "env_kwargs": json_object(fix='e.g. --env-kwargs \'{"config": {"lanes_count": 3}}\''),
        "preset": Rule(f"none or one of {', '.join(PRESETS)}", lambda v: v is None or v in PRESETS),
        "seed": Rule(
            "an int in [0, 2**32)", lambda v: _is_int(v) and 0 <= v < 2**32, "e.g. --seed 1"
        ),
        "action_repeat": integer(
            1,
            optional=True,
            fix="e.g. --action-repeat 8, or none for the paper's value of a DMC task (1 otherwise)",
        ),
        "image_size": positive,
        "grayscale": boolean(),
        "cameras": positive,
        "total_env_steps": positive,
        "warmup_agent_steps": integer(0),
        "updates_per_step": positive,
        "replay_capacity": positive,
        "eval_every": positive,
        "eval_episodes": positive,
        "eval_distraction": Rule(
            "a list of distraction mode names",
            lambda v: isinstance(v, (tuple, list)) and all(isinstance(m, str) and m for m in v),
            "e.g. --eval-distraction video_hard (simoun_agent.generalization.DISTRACTIONS)",
        ),
        "checkpoint_every": positive,
        "video": boolean(),
        "device": text(optional=True, fix="e.g. --device cpu, cuda, cuda:0 or mps"),
        "torch_threads": integer(1, optional=True),
        "env_process": boolean(),
        "run_dir": text(optional=True),
        "progress": boolean(),
        "agent": Rule("an AgentConfig", lambda v: dataclasses.is_dataclass(v)),
    }


def check_train_config(config: Any) -> None:
    """Every field of a ``TrainConfig``, then the constraints between fields."""
    check_fields(config, train_rules(), "")
    if config.device is not None and (problem := device_problem(config.device)):
        raise fail("", "device", config.device, problem)
    if config.replay_capacity < config.agent.batch_size:
        raise fail(
            "",
            "replay_capacity",
            config.replay_capacity,
            f"the replay must hold at least one batch (--agent.batch-size "
            f"{config.agent.batch_size}); raise --replay-capacity or lower the batch size",
        )
    channels = 1 if config.grayscale else 3
    if not image_fits(config.agent, config.image_size, channels, config.cameras):
        smallest = min_image_size(config.agent, channels, config.cameras)
        raise fail(
            "",
            "image_size",
            config.image_size,
            f"too small for the conv trunk of encoder {config.agent.encoder!r}; it needs "
            f"--image-size {smallest} or more (the paper uses 84)",
        )


def check_agent_inputs(frame_shape: Sequence[int], action_dim: int, config: Any) -> None:
    """What ``SimounAgent`` is built for: channel-first frames its encoder accepts, and at least
    one action dimension. Raises ValueError naming the argument and the fix."""
    shape = tuple(frame_shape)
    if len(shape) != 3 or not all(_is_int(v) and v > 0 for v in shape):
        raise ValueError(
            f"frame_shape must be (C, H, W) positive ints, got {shape!r}; pass "
            "env.observation_space['frames'].shape[1:] of a SimounObservation env"
        )
    channels, height, width = shape
    if channels not in (1, 3) and width in (1, 3):
        raise ValueError(
            f"frame_shape {shape} looks channel-last (H, W, C); pass it channel-first, "
            f"({width}, {channels}, {height}), as SimounObservation's frames are"
        )
    if isinstance(action_dim, spaces.Space) and not isinstance(action_dim, spaces.Box):
        raise ValueError(
            f"SimounAgent is a SAC agent for continuous actions (a 1-D Box), got the action space "
            f"{action_dim}; use the env's continuous version (e.g. highway-env's "
            f"ContinuousAction, LunarLander continuous=True), or a discrete-action learner such "
            f"as SB3's PPO or DQN with 'CnnPolicy' on SimounObservation(env, fold_frames=True)"
        )
    if not _is_int(action_dim) or action_dim < 1:
        raise ValueError(
            f"action_dim must be an int >= 1, got {action_dim!r}; pass env.action_space.shape[0] "
            "of a continuous (Box) action space"
        )
    if not _encoder_fits(_agent_key(config), channels, height, width):
        smallest = min_image_size(config, channels, cameras=1)
        raise ValueError(
            f"frames of {height}x{width} are too small for the conv trunk of encoder "
            f"{config.encoder!r}, which needs at least {smallest}x{smallest}; resize them, e.g. "
            f"SimounObservation(env, size={max(smallest, 84)})"
        )
