"""The study's arms: what each adds to the PPO learner's reward, one registry entry each.

An arm is named by its entry and, optionally, settings of that entry's keyword arguments:
``"consistency"`` (the entry's defaults) or ``"consistency,normalization=standardize,scale=0.01"``
(keys sorted, so one setting has one name). The name is the run's directory in the archive.
"""

from __future__ import annotations

import inspect
import json
from collections.abc import Callable
from difflib import get_close_matches
from typing import Any

import torch
from gymnasium.vector import VectorEnv

from simoun_agent.config import SetupError
from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_agent.rnd_model import RNDConfig, RNDModel
from simoun_wrappers import ConsistencyCuriosityVectorReward
from simoun_wrappers.intrinsic_normalization import NORMALIZATIONS
from simoun_wrappers.intrinsic_reward import (
    ConstantBonusVectorReward,
    check_scale,
    check_weighting,
)
from simoun_wrappers.rnd import RNDVectorReward

__all__ = ["ARMS", "arm_name", "arm_settings", "build_arm", "parse_arm"]


FOREGROUND = {"background": False}
"""The intrinsic models take their gradient steps on the learner's thread. The rewards are the
same as with the update thread by design, but beside PPO's own torch work in the same process
the thread's runs part by a float's last bit within the first rollout (measured: two runs of one
seed, 1e-11 apart in the first rollout's mean intrinsic reward, apart in the third digit by the
third), and over 400k env steps that can decide a run; on the learner's thread they are equal
bit for bit. Runs of commits before this setting ran the thread."""


def no_intrinsic(envs: VectorEnv, seed: int, device: torch.device) -> VectorEnv:
    """PPO on the env's own reward."""
    return envs


def consistency(
    envs: VectorEnv,
    seed: int,
    device: torch.device,
    scale: float = 0.2,
    normalization: str = "paper",
    progress: float | None = None,
    **changes: Any,
) -> VectorEnv:
    """+ Simoun's consistency curiosity, CuriosityModel at its defaults but for ``changes``
    (``CuriosityConfig`` fields, for the probe; an arm's name cannot set them) and
    :data:`FOREGROUND`. The defaults are the wrapper's as first shipped: Eq. 13 as written
    (``"paper"``, C 0.2, decay 2e-5); the other normalizations get no decay (the wrapper's
    rule)."""
    config = CuriosityConfig(seed=seed, **{**FOREGROUND, **changes})
    model = CuriosityModel.for_env(envs, config, device=device)
    return ConsistencyCuriosityVectorReward(
        envs, model, scale=scale, normalization=normalization, progress=progress
    )


def rnd(
    envs: VectorEnv,
    seed: int,
    device: torch.device,
    scale: float = 0.05,
    normalization: str = "reward_std",
    progress: float | None = None,
) -> VectorEnv:
    """+ random network distillation, RNDModel at its defaults but for :data:`FOREGROUND`; the
    defaults are the wrapper's as first shipped (``"reward_std"``, scale 0.05, a warm-up of 1024
    transitions)."""
    return RNDVectorReward(
        envs,
        RNDModel.for_env(envs, RNDConfig(seed=seed, **FOREGROUND), device=device),
        scale=scale,
        normalization=normalization,
        progress=progress,
    )


def constant(envs: VectorEnv, seed: int, device: torch.device, scale: float = 0.1) -> VectorEnv:
    """+ a constant bonus of ``scale`` a step: the control arm for a survival bonus."""
    return ConstantBonusVectorReward(envs, scale=scale)


ARMS: dict[str, Callable[..., VectorEnv]] = {
    "ppo": no_intrinsic,
    "consistency": consistency,
    "rnd": rnd,
    "constant": constant,
}
"""arm entry -> the training vector env it gives PPO, from the pixel vector env, the run's seed,
the device of the intrinsic-reward model and the arm's settings"""

FIXED = ("envs", "seed", "device")
"""the arguments every entry takes from the run, not from the arm's name"""

SETTING_CHECKS: dict[str, Callable[[Any], object]] = {
    "scale": check_scale,
    "progress": lambda progress: check_weighting(0.0, 0, progress),
}
"""an arm setting -> the wrappers' own check of it, so a value they would refuse when the run
starts is refused when the spec is read"""


def parse_arm(name: str) -> tuple[str, dict[str, Any]]:
    """The entry and the settings an arm's name gives, each value checked against the entry's
    signature; a :class:`SetupError` names an unknown entry, key or value with the fix."""
    entry, *pairs = str(name).split(",")
    if entry not in ARMS:
        close = get_close_matches(entry, ARMS, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise SetupError(f"arm {name!r}: unknown arm {entry!r}{hint}; choose from {list(ARMS)}")
    parameters = inspect.signature(ARMS[entry]).parameters
    settable = [
        key
        for key, parameter in parameters.items()
        if key not in FIXED and parameter.kind is not parameter.VAR_KEYWORD
    ]
    settings: dict[str, Any] = {}
    for pair in pairs:
        key, sep, text = pair.partition("=")
        if not sep or key not in settable:
            close = get_close_matches(key, settable, n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SetupError(
                f"arm {name!r}: {pair!r} is not KEY=VALUE with a key of {entry!r}{hint}; its "
                f"keys: {settable or 'none'}"
            )
        if key in settings:
            raise SetupError(f"arm {name!r}: {key!r} is given twice; give it once")
        try:
            value = json.loads(text)
        except json.JSONDecodeError:
            value = text
        if key == "normalization" and (not isinstance(value, str) or value not in NORMALIZATIONS):
            raise SetupError(
                f"arm {name!r}: normalization={value!r} is not one of {list(NORMALIZATIONS)}"
            )
        if key in SETTING_CHECKS:
            try:
                SETTING_CHECKS[key](value)
            except ValueError as err:
                raise SetupError(f"arm {name!r}: {key}={text!r} is not valid: {err}") from None
        settings[key] = value
    return entry, settings


def arm_settings(name: str) -> tuple[str, dict[str, Any]]:
    """The entry and every setting the arm ``name`` runs with, its entry's defaults filled in:
    two names of one arm (keys in another order, a default spelled out) give the same."""
    entry, settings = parse_arm(name)
    parameters = inspect.signature(ARMS[entry]).parameters
    defaults = {
        key: parameter.default
        for key, parameter in parameters.items()
        if key not in FIXED and parameter.kind is not parameter.VAR_KEYWORD
    }
    return entry, {**defaults, **settings}


def arm_name(entry: str, settings: dict[str, Any]) -> str:
    """The canonical name of ``entry`` with ``settings`` (keys sorted): what :func:`parse_arm`
    reads back."""
    pairs = [f"{key}={json.dumps(value).strip(chr(34))}" for key, value in sorted(settings.items())]
    return ",".join([entry, *pairs])


def build_arm(name: str, envs: VectorEnv, seed: int, device: torch.device) -> VectorEnv:
    """The training vector env the arm ``name`` gives PPO."""
    entry, settings = parse_arm(name)
    return ARMS[entry](envs, seed, device, **settings)
