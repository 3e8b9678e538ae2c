"""Build the environment stack a run trains on, from a Gymnasium id and a TrainConfig.

``make_env(config)`` gives ``SimounObservation(MultiCamera?(ActionRepeat(RescaleAction(env))))``:
the agent acts in ``[-1, 1]^n`` (rescaled to the env's bounds), each decision is repeated
``action_repeat`` times, and observations are ``{"frames": (3, C, H, W) uint8}`` triplets (the
agent computes the motion channels itself, so the wrapper's are switched off).
"""

from __future__ import annotations

import contextlib
import difflib
import functools
import importlib
import importlib.util
import inspect
import json
import math
import numbers
import re
from collections.abc import Callable
from dataclasses import replace

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import find_highest_version, load_env_creator, parse_env_id
from gymnasium.wrappers import RescaleAction

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent.config import SetupError, TrainConfig
from simoun_agent.config.envs import is_highway
from simoun_agent.config.resolve import merged
from simoun_agent.config.rules import plain_json
from simoun_agent.run.env_kwargs_checks import check_class_paths, check_files, check_render_keys
from simoun_agent.run.env_packages import unregistered_package
from simoun_agent.run.highway_config import check_highway_config, nested
from simoun_agent.run.render_backend import backend_failure, named_backend, probe_render
from simoun_wrappers import ActionRepeat, MultiCamera, SimounObservation
from simoun_wrappers.observation import check_render, image_layout

HIGHWAY_VIEWPORTS = (
    {"centering_position": [0.85, 0.5], "scaling": 2.0},
    {"centering_position": [0.5, 0.5], "scaling": 1.0},
    {"centering_position": [0.15, 0.5], "scaling": 2.0},
)
"""Three 84x84 views around the ego vehicle, left to right: about 36 m behind it, an 84 m
overview, about 36 m ahead (traffic drives to the right). They stand in for the paper's three
roof cameras on CARLA. ``centering_position`` is where the ego vehicle sits in a view (fractions
of its size) and ``scaling`` is pixels per metre, scaled with the image size."""

HIGHWAY_FORWARD_VIEWPORT = {"centering_position": [0.25, 0.5], "scaling": 1.5}
"""The one view of a single-camera highway-env run: the ego vehicle a quarter of the way in from
the left edge, so an 84x84 view shows 14 m behind it and 42 m ahead (1.5 px per metre; the
scaling grows with the image size, so every size shows the same 56 m of road). 42 m is about
1.5 s of headway at highway speed: a slower car ahead is in view before a gap-keeping driver
has to brake for it."""

HIGHWAY_DROPPED_OBSERVATION = {
    "type": "GrayscaleObservation",
    "observation_shape": (8, 8),
    "stack_size": 1,
    "weights": [0.2989, 0.587, 0.114],
}
"""What a highway-env env observes when its config names no observation: MultiCamera draws the
frames the agent sees and drops the env's own observation, so it should cost next to nothing.
Process CPU per observation on a loaded 2-core machine: highway-env's default Kinematics (built
with pandas) 16.4 ms, about half of a highway-fast-v0 step; this one-frame 8x8 render 1.0 ms
(a lidar, 1.5 ms, would be drawn into every view)."""

_SUITES = {"dm_control/": ("shimmy", "dmc"), "": ("highway_env", "highway")}


def import_env_module(module: str) -> None:
    """Import ``module`` (``--env-module`` or the MODULE of ``--env MODULE:ID``), whose import
    registers ids; raise SetupError, with a pip hint only when a top-level package is missing
    (a module missing inside an installed package is not fixed by installing anything)."""
    try:
        importlib.import_module(module)
    except ModuleNotFoundError as err:
        missing = err.name or module
        top = missing.split(".")[0]
        if importlib.util.find_spec(top) is not None:
            raise SetupError(
                f"--env-module {module!r} cannot be imported: {top!r} is installed but has no "
                f"module {missing!r}; give the full dotted name of the module of {top} whose "
                "import registers the ids, or drop the module from --env"
            ) from None
        if not (module == missing or module.startswith(missing + ".")):
            raise SetupError(
                f"importing --env-module {module!r} failed: it needs {missing!r}, which is not "
                f"installed; pip install {top.replace('_', '-')}"
            ) from None
        raise SetupError(
            f"--env-module {module!r} is not installed, so the ids it registers are unknown; "
            f"pip install {top.replace('_', '-')} (or the package that provides {module}), or "
            "drop the module from --env"
        ) from None
    except ImportError as err:  # a module of the package that the package itself cannot import
        raise SetupError(
            f"importing --env-module {module!r} failed ({err}); fix or reinstall the package "
            "that provides it, or drop the module from --env"
        ) from None


def ensure_registered(env_id: str, module: str | None = None) -> None:
    """Import ``module`` and the suite that registers ``env_id``; raise SetupError with close
    matches if the id is still unknown.

    dm_control ids are registered by shimmy and highway-env ids by highway_env, on import; other
    packages by the ``module`` named with ``--env-module`` (or ``--env MODULE:ID``).
    """
    if module is not None:
        import_env_module(module)
    if env_id in gym.registry:
        return
    for prefix, (suite, extra) in _SUITES.items():
        if not env_id.startswith(prefix):
            continue
        try:
            importlib.import_module(suite)
        except ImportError as err:
            if backend_failure(err, env_id) is not None:  # installed, but cannot render here
                raise
            if prefix:
                raise SetupError(
                    f"{env_id!r} needs {suite}, which is not installed; "
                    f'pip install "simoun[{extra}]"'
                ) from None
        if env_id in gym.registry:
            return
    several = [part.strip() for part in env_id.split(",")]
    if len(several) > 1 and all(part in gym.registry for part in several):
        raise SetupError(
            f"{env_id!r} is {len(several)} environment ids joined by commas; an env takes one "
            f"id (e.g. {several[0]}): train one run per env, or sweep them with simoun-sweep "
            f"--envs {','.join(several)}"
        )
    packaged = unregistered_package(env_id) if module is None else None
    if packaged is not None:
        raise packaged
    matches = close_env_ids(f"{module}:{env_id}" if module else env_id)
    hint = f"did you mean {', '.join(matches)}?" if matches else "no registered id is close."
    if module is not None:
        raise SetupError(
            f"unknown environment id {env_id!r}: importing {module!r} did not register it; "
            f"{hint} Pass an id that {module} registers."
        )
    raise SetupError(
        f"unknown environment id {env_id!r}; {hint} Pass a registered Gymnasium id "
        "(e.g. dm_control/cartpole-swingup-v0, highway-v0, simoun/PointReach-v0), or "
        "MODULE:ID (e.g. minigrid:MiniGrid-DoorKey-6x6-v0) for an id that a package registers "
        "on import."
    )


def close_env_ids(typed: str, n: int = 5) -> list[str]:
    """Registered ids close to ``typed`` (``--env`` as given), those that differ from it only by
    case, separators (``:`` for ``/``, ``-`` for ``_``) or a missing version first
    (``dm_control/cartpole-swingup-v0`` for ``dm_control:cartpole-swingup-v0`` or
    ``cartpole-swingup``), then those difflib finds. Every suite that is installed is
    imported first, so that its ids can be offered."""
    for suite, _ in _SUITES.values():
        with contextlib.suppress(ImportError):
            importlib.import_module(suite)
    ids = list(gym.registry)
    spelled = [i for i in ids if _spelling(i) == _spelling(typed)]
    names = _names(typed)
    unversioned = sorted((i for i in ids if _names(i) & names), key=_plain_newest_first)
    close = difflib.get_close_matches(typed, ids, n=n, cutoff=0.6)
    return list(dict.fromkeys(spelled + unversioned + close))[:n]


def _spelling(env_id: str) -> str:
    """``env_id`` without case or separators: ``dmcontrolcartpoleswingupv0``."""
    return re.sub(r"[-_:/\s]", "", env_id.lower())


def _plain_newest_first(env_id: str) -> tuple[int, str, int]:
    """Sort key: ids without a namespace first, then by name, the newest version first."""
    version = re.search(r"-v(\d+)$", env_id)
    return env_id.count("/"), _unversioned(env_id), -int(version.group(1)) if version else 0


def _unversioned(env_id: str) -> str:
    return re.sub(r"-v\d+$", "", env_id)


def _names(env_id: str) -> set[str]:
    """The spellings of ``env_id`` without its version: whole, and its name after a namespace
    or module (``cartpoleswingup`` of ``dm_control:cartpole-swingup-v0``)."""
    bare = _unversioned(env_id)
    return {_spelling(bare), _spelling(re.split(r"[:/]", bare)[-1])}


def env_keywords(env_id: str) -> tuple[list[str], bool]:
    """The keyword arguments ``gym.make(env_id, ...)`` passes on to the env's creator (its
    registered kwargs and the creator's named parameters), and whether it takes any others
    (``**kwargs``). Raises SetupError when the creator cannot be loaded (a missing extra)."""
    spec = gym.spec(env_id)
    try:
        creator = (
            spec.entry_point if callable(spec.entry_point) else load_env_creator(spec.entry_point)
        )
    except MAKE_ERRORS as err:
        raise unmakeable(env_id, err) from None
    try:
        parameters = inspect.signature(creator).parameters.values()
    except (TypeError, ValueError):  # a builtin or C extension: nothing to read
        return sorted(spec.kwargs), True
    named = [
        p.name
        for p in parameters
        if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY) and p.name != "self"
    ]
    open_ended = any(p.kind is p.VAR_KEYWORD for p in parameters)
    return sorted({*spec.kwargs, *named}), open_ended


MAKE_ERRORS = (ImportError, gym.error.Error)
"""what loading or calling an env's creator raises when the env cannot be made here at all: a
package it imports is missing (``phys2d/Pendulum-v0`` needs jax), an id that gymnasium keeps
only to say where it went (the MuJoCo v2 and v3 ids), a deprecated version"""


def unmakeable(env_id: str, err: Exception) -> SetupError:
    """The SetupError for ``env_id`` that cannot be made (:data:`MAKE_ERRORS`): the env's own
    reason, what to install when a module is missing, and the newest registered version of
    the same env when there is one."""
    reason = str(err).strip().rstrip(".") or type(err).__name__
    missing = getattr(err, "name", None) if isinstance(err, ModuleNotFoundError) else None
    if missing:
        top = missing.split(".")[0]
        reason = f"it needs the module {missing!r}, which is not installed (pip install {top})"
    newer = _newest_version(env_id)
    fix = f"use --env {newer} instead, or pick another --env" if newer else "pick another --env"
    return SetupError(f"--env {env_id} cannot be made: {reason}; {fix}")


def _newest_version(env_id: str) -> str | None:
    """The newest registered version of ``env_id``'s env when it is not ``env_id`` itself
    (``InvertedPendulum-v5`` for ``InvertedPendulum-v2``), else None."""
    try:
        namespace, name, version = parse_env_id(env_id)
        newest = find_highest_version(namespace, name)
    except gym.error.Error:
        return None
    if newest is None or newest == version:
        return None
    return f"{namespace + '/' if namespace else ''}{name}-v{newest}"


GYM_MAKE_KEYWORDS = ("max_episode_steps", "disable_env_checker")
"""``--env-kwargs`` keys that ``gymnasium.make`` takes itself rather than passing them on to the
env's creator"""

REGISTRATION_SETTINGS = ("order_enforce", "autoreset", "apply_api_compatibility")
"""settings of an env's registration (``gymnasium.register``) that ``gymnasium.make`` 1.x does not
take as keywords"""


def check_env_kwargs(env_id: str, kwargs: dict) -> None:
    """Refuse ``--env-kwargs`` keys that neither ``gymnasium.make`` nor the env's creator take,
    before it is made, naming the accepted ones; ``render_mode`` is refused too (simoun sets
    rgb_array), and so are values of the wrong kind for a keyword with a number or string
    default. Numpy scalars and tuples are read as the numbers and lists they hold."""
    kwargs = plain_json(kwargs)
    if "render_mode" in kwargs:
        raise SetupError(
            f"--env-kwargs sets render_mode={kwargs['render_mode']!r}; simoun makes {env_id} "
            "with render_mode='rgb_array' itself (it learns from the rendered frames): drop it"
        )
    _check_make_keywords(env_id, kwargs)
    accepted, open_ended = env_keywords(env_id)
    own = {key: value for key, value in kwargs.items() if key not in GYM_MAKE_KEYWORDS}
    settings = [key for key in own if key in REGISTRATION_SETTINGS and key not in accepted]
    if settings:
        raise SetupError(
            f"--env-kwargs: {', '.join(map(repr, settings))} is a setting of {env_id}'s "
            f"registration (gymnasium.register), not a keyword that gymnasium.make "
            f"{gym.__version__} or the env takes; drop it (simoun resets each episode itself)"
        )
    unknown = [key for key in own if key not in accepted]
    if unknown and not open_ended:
        close = {key: difflib.get_close_matches(key, accepted, n=1) for key in unknown}
        named = ", ".join(
            repr(key) + (f" (did you mean {close[key][0]!r}?)" if close[key] else "")
            for key in unknown
        )
        listed = ", ".join(key for key in accepted if key != "render_mode") or "none"
        raise SetupError(f"--env-kwargs: {env_id} takes no keyword {named}; it accepts: {listed}")
    _check_value_kinds(env_id, own)


def _check_make_keywords(env_id: str, kwargs: dict) -> None:
    """SetupError for a value of a gymnasium.make keyword that make would misread."""
    if "max_episode_steps" in kwargs:
        steps = kwargs["max_episode_steps"]
        if isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps < 1:
            raise SetupError(
                f"--env-kwargs: max_episode_steps={steps!r} (gymnasium.make's episode step limit "
                f"for {env_id}) must be a whole number of at least 1, e.g. "
                "'{\"max_episode_steps\": 200}'; drop it for the registered limit"
            )
    if "disable_env_checker" in kwargs and not isinstance(kwargs["disable_env_checker"], bool):
        raise SetupError(
            f"--env-kwargs: disable_env_checker={kwargs['disable_env_checker']!r} (a keyword of "
            "gymnasium.make) must be true or false"
        )


def _creator_defaults(env_id: str) -> dict:
    """The default value of each keyword of ``env_id``'s creator (its registered kwargs over its
    signature's defaults, and the ``default_config()`` of an env class that has one, as
    highway-env's, for its ``config`` keyword); only the registered ones when the creator
    cannot be read."""
    spec = gym.spec(env_id)
    try:
        creator = (
            spec.entry_point if callable(spec.entry_point) else load_env_creator(spec.entry_point)
        )
        parameters = inspect.signature(creator).parameters.values()
    except (gym.error.Error, ImportError, AttributeError, TypeError, ValueError):
        return dict(spec.kwargs)
    defaults = {p.name: p.default for p in parameters if p.default is not p.empty}
    if "config" in defaults and callable(getattr(creator, "default_config", None)):
        defaults["config"] = creator.default_config()
    return {**defaults, **spec.kwargs}


def _is_number(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


DMC_OBJECT_KWARGS = {
    "render_kwargs": {"width": 84, "height": 84, "camera_id": 0},
    "task_kwargs": {"time_limit": 10},
    "environment_kwargs": {"flat_observation": True},
}
"""keywords of shimmy's dm_control envs that take a JSON object (their default is None, or they
come through ``**kwargs``), each with an example"""


def _check_value_kinds(env_id: str, kwargs: dict) -> None:
    """SetupError for a value of another kind than the creator's default (a string where a
    number goes, a number where a string goes, anything but true or false for a switch,
    anything but a JSON object where one goes): the env would take it and fail later, mid-run,
    or read it another way; for a highway-env config value that breaks the task
    (:func:`check_highway_config`); and for a negative count (:func:`_check_counts`)."""
    defaults = _creator_defaults(env_id)
    for key, value in kwargs.items():
        if value is not None:  # many creators take None for "their own default"
            _check_object(env_id, key, value, defaults.get(key))
            _check_scalar_kind(env_id, key, value, defaults.get(key))
    if is_highway(env_id):
        check_highway_config(env_id, kwargs.get("config"), defaults.get("config"))
    _check_counts(env_id, kwargs, defaults)
    check_files(env_id, kwargs, defaults)
    check_class_paths(env_id, kwargs, defaults)


def _check_scalar_kind(env_id: str, key: str, value: object, default: object) -> None:
    if isinstance(default, bool) and not isinstance(value, bool):
        kind = "true or false"
    elif _is_number(default) and not _is_number(value):
        kind = "a number"
    elif isinstance(default, str) and not isinstance(value, str):
        kind = "a string"
    else:
        return
    raise SetupError(
        f"--env-kwargs: {key}={value!r} does not fit {env_id}: its {key!r} is {kind} "
        f"(default {default!r}); e.g. '{json.dumps({key: default})}', or drop it"
    )


def _check_object(env_id: str, key: str, value: object, default: object) -> None:
    """SetupError for a keyword that takes a JSON object (highway-env's ``config``, dm_control's
    ``render_kwargs``) given something else, such as a file name."""
    if env_id.startswith("dm_control/") and key in DMC_OBJECT_KWARGS:
        example = DMC_OBJECT_KWARGS[key]
    elif isinstance(default, dict):
        example = _object_example(default)
    else:
        return
    if isinstance(value, dict):
        return
    what = "highway-env settings" if key == "config" and is_highway(env_id) else "settings"
    file = (
        " (a file's settings go in as its contents, not its name)" if isinstance(value, str) else ""
    )
    raise SetupError(
        f"--env-kwargs: {key} must be a JSON object of {what} for {env_id}, got "
        f"{json.dumps(value)}; "
        f"e.g. '{json.dumps({key: example})}'{file}, or drop {key}"
    )


def _object_example(default: dict) -> dict:
    """One plain setting of ``default`` as an example of the object (``{"lanes_count": 3}``)."""
    plain = [key for key, value in default.items() if _is_number(value)]
    preferred = "lanes_count" if "lanes_count" in plain else (plain or [None])[0]
    return {} if preferred is None else {preferred: default[preferred]}


def _check_counts(env_id: str, kwargs: dict, defaults: dict, prefix: str = "") -> None:
    """SetupError for a negative number given to a keyword (or a key of a dict keyword, such as
    highway-env's ``config``, at any depth) whose default is a whole number of at least 1: such
    a keyword is a count, size, frequency or duration (``vehicles_count``, ``lanes_count``,
    ``size``), and envs take a negative one without a word and run a degenerate task. A zero
    default is left alone: those are often rewards, where a negative value is a penalty."""
    for key, value in kwargs.items():
        default = defaults.get(key) if isinstance(defaults, dict) else None
        name = f"{prefix}{key}"
        if isinstance(value, dict) and isinstance(default, dict):
            _check_counts(env_id, value, default, f"{name}.")
        elif _is_count(default) and _is_number(value) and value < 0:
            example = json.dumps(nested(name, default))
            raise SetupError(
                f"--env-kwargs: {name}={value!r} is negative, and {env_id}'s {name} is a count "
                f"(default {default!r}); give a whole number of at least 0, e.g. "
                f"'{example}', or drop {name}"
            )


def _is_count(default: object) -> bool:
    return isinstance(default, int) and not isinstance(default, bool) and default >= 1


def _refused_kwargs(env_id: str, kwargs: dict, err: TypeError) -> SetupError:
    """The SetupError for a TypeError that gym.make raised over a keyword (an env whose creator
    takes ``**kwargs`` and passes them on, e.g. shimmy's dm_control envs)."""
    accepted, _ = env_keywords(env_id)
    listed = ", ".join(key for key in accepted if key != "render_mode")
    known = f"; its creator names {listed}" if listed else ""
    message = str(err).split(" was raised from the environment creator")[0]
    return SetupError(
        f"--env-kwargs {json.dumps(kwargs)} does not fit {env_id} ({message}){known}. Fix or "
        "drop --env-kwargs"
    )


def _make_base(config: TrainConfig) -> gym.Env:
    """``gym.make`` the env with rgb_array rendering at the run's image size, and render it once
    when it draws with MuJoCo; a SetupError for a rendering back-end that cannot run here (an
    unknown ``MUJOCO_GL``, which dm_control and mujoco read on import, or one they know that
    this machine cannot run: :mod:`render_backend`)."""
    with named_backend(config.env):
        env = _make_rendering_env(config)
    probe_render(env, config.env)
    return env


def _make_kwargs(config: TrainConfig) -> dict:
    """The keywords ``gym.make`` is given for ``config``: simoun's own settings (dm_control's
    render size, highway-env's dropped observation) with its ``--env-kwargs`` merged over them
    key by key, as ``--env-kwargs`` is merged over a preset's: a ``render_kwargs`` that names
    only the camera keeps the run's frame size."""
    own: dict = {}
    if config.env.startswith("dm_control/"):
        own["render_kwargs"] = {
            "width": config.image_size,
            "height": config.image_size,
            "camera_id": 0,
        }
    if is_highway(config.env):
        own["config"] = {"observation": _dropped_observation(config.env_kwargs)}
    return merged(own, config.env_kwargs)


def _dropped_observation(env_kwargs: dict) -> dict:
    """The highway-env observation simoun sets under ``env_kwargs``: its dropped one, which a
    ``config.observation`` of another ``type`` replaces whole (the settings of one observation
    class mean nothing to another), and one without a type or of the same type is merged into
    key by key."""
    given = env_kwargs.get("config", {})
    observation = given.get("observation") if isinstance(given, dict) else None
    own_type = HIGHWAY_DROPPED_OBSERVATION["type"]
    if isinstance(observation, dict) and observation.get("type", own_type) != own_type:
        return {}
    return dict(HIGHWAY_DROPPED_OBSERVATION)


def _make_rendering_env(config: TrainConfig) -> gym.Env:
    ensure_registered(config.env, config.env_module)
    check_env_kwargs(config.env, config.env_kwargs)
    _check_camera_choice(config)
    env = _gym_make(config)
    try:
        check_render_keys(env, config)
    except SetupError:
        env.close()
        raise
    return env


def _check_camera_choice(config: TrainConfig) -> None:
    """SetupError for a dm_control ``render_kwargs.camera_id`` beside ``--cameras`` above 1:
    the views are then cameras 0..N-1, rendered by their ids, and the camera chosen would be
    dropped without a word."""
    render = config.env_kwargs.get("render_kwargs")
    if not (
        config.env.startswith("dm_control/")
        and config.cameras > 1
        and isinstance(render, dict)
        and "camera_id" in render
    ):
        return
    raise SetupError(
        f"--cameras {config.cameras} with --env-kwargs render_kwargs.camera_id="
        f"{json.dumps(render['camera_id'])}: --cameras N shows {config.env}'s cameras 0..N-1 "
        f"side by side (here 0..{config.cameras - 1}), so the camera_id would be ignored; for "
        "the one camera of your choice pass --cameras 1 with render_kwargs.camera_id, or drop "
        "camera_id to see cameras 0..N-1"
    )


def _gym_make(config: TrainConfig) -> gym.Env:
    """``gym.make`` ``config``'s env with rgb_array rendering (without it for a creator that
    takes no render_mode); SetupError for what making it raises, naming ``--env-kwargs`` and
    the key at fault when the run gives any."""
    kwargs = _make_kwargs(config)
    try:
        with named_backend(config.env):
            try:
                return gym.make(config.env, render_mode="rgb_array", **kwargs)
            except TypeError as err:
                if "render_mode" not in str(err):
                    raise
            # an env whose creator takes no render_mode: it may still return image observations
            return gym.make(config.env, **kwargs)
    except TypeError as err:
        if "keyword argument" in str(err):
            raise _refused_kwargs(config.env, config.env_kwargs, err) from None
        raise _refused_by_env(config, err) from None
    except MAKE_ERRORS as err:
        raise unmakeable(config.env, err) from None
    except SetupError:
        raise
    except Exception as err:
        # an env that checks its own arguments refuses a bad value this way; without env
        # kwargs, only a ValueError is the env's word on its arguments. With them, whatever
        # the env raises (a missing file, a class path that does not import) follows from them
        if not (config.env_kwargs or isinstance(err, ValueError)):
            raise
        raise _refused_by_env(config, err) from None


def _kwargs_text(kwargs: dict) -> str:
    """``--env-kwargs`` as the keywords the env is called with: ``g='x', max_speed=8``."""
    return ", ".join(f"{key}={value!r}" for key, value in kwargs.items())


def _refused_by_env(config: TrainConfig, err: Exception) -> SetupError:
    """The SetupError for an error an env raised while it was made, naming ``--env-kwargs``
    (and the key at fault, when one is) when the run gives any."""
    message = one_line(err)
    if not isinstance(err, (ValueError, TypeError)):  # the kind says what went wrong
        message = f"{type(err).__name__}: {message}"
    if not config.env_kwargs:
        return SetupError(f"gymnasium.make({config.env!r}) failed: {message}")
    culprit = faulty_key(config)
    if culprit and no_continuous_actions(config, culprit):
        # highway-env then fails deep in the task's reward code: its error explains nothing
        return SetupError(
            f"{config.env} does not support continuous actions ({culprit}, which the agents "
            "need to drive); pick a highway-env task that does, e.g. highway-fast-v0"
        )
    if culprit:
        return SetupError(
            f"--env-kwargs {json.dumps(config.env_kwargs)}: {config.env} cannot use {culprit} "
            f"(making it failed: {message}). Fix or drop that key"
        )
    return SetupError(
        f"--env-kwargs {json.dumps(config.env_kwargs)}: {config.env} made with the keys "
        f"{', '.join(config.env_kwargs)} failed ({message}). Fix those values or drop "
        "--env-kwargs"
    )


def one_line(err: Exception) -> str:
    """``err``'s text on one line, without gymnasium's appended keywords (it re-raises a
    creator's TypeError with every keyword, simoun's own too)."""
    text = str(err).split(" was raised from the environment creator")[0]
    return " ".join(text.split()) or type(err).__name__


def no_continuous_actions(config: TrainConfig, culprit: str) -> bool:
    """Whether ``culprit`` (:func:`faulty_key`) is the continuous action type a highway-env
    task cannot be made with (the type itself, or the action that holds it: another key of
    the action at fault is named as itself)."""
    action = config.env_kwargs.get("config", {}).get("action", {})
    return (
        is_highway(config.env)
        and culprit.startswith(("config.action.type=", "config.action="))
        and isinstance(action, dict)
        and action.get("type") == "ContinuousAction"
    )


def _first_step(env: gym.Env) -> bool:
    """Reset ``env``, take one middle action and render; whether that step ended the episode.
    Raises :class:`UnusableRender` for a render that holds no frame (a side of 0, not a uint8
    (H, W, 3) image) when the agent's frames would come from the renders."""
    env.reset(seed=0)
    space = env.action_space
    middle = (space.low + space.high) / 2 if isinstance(space, spaces.Box) else space.sample()
    _, _, terminated, truncated, _ = env.step(middle)
    frame = env.render()
    if image_layout(env.observation_space) is None:  # the frames come from the renders
        try:
            check_render(frame, "simoun")
        except (TypeError, ValueError):
            raise UnusableRender(frame) from None
    return bool(terminated or truncated)


class UnusableRender(ValueError):
    """An env's rgb_array render that holds no frame to learn from (a side of 0, not a uint8
    (H, W, 3) image); its text says what the render returned."""

    def __init__(self, frame: object) -> None:
        if isinstance(frame, np.ndarray):
            what = f"an array of shape {frame.shape} and dtype {frame.dtype}"
        else:
            what = "None" if frame is None else f"a {type(frame).__name__}"
        super().__init__(
            f"its render() returned {what}, and simoun learns from uint8 (H, W, 3) frames with "
            "H, W >= 1"
        )


def check_first_step(env: gym.Env, config: TrainConfig) -> None:
    """Reset ``env`` (made with ``config``'s ``--env-kwargs``), take one middle action and render:
    an env that stores a keyword's value unchecked fails here, before a run is spent, rather
    than at its first training step, and so does one whose render holds no frame (a render
    width of 0)."""
    try:
        ended = _first_step(env)
    except UnusableRender as err:
        culprit = faulty_key(config)
        at_fault = f"; {culprit} is the value that spoils it" if culprit else ""
        raise SetupError(
            f"--env-kwargs {json.dumps(config.env_kwargs)}: {config.env} made with "
            f"{_kwargs_text(config.env_kwargs)} renders no usable frame: {err}{at_fault}. "
            f"Give it a render width and height of at least 1{_render_example(config)}, or drop "
            "the render settings from --env-kwargs"
        ) from None
    except SetupError:
        raise
    except Exception as err:  # whatever the env raises follows from the kwargs it was given
        culprit = faulty_key(config)
        at_fault = f"; {culprit} is the value it cannot use" if culprit else ""
        raise SetupError(
            f"--env-kwargs {json.dumps(config.env_kwargs)}: {config.env} was made with "
            f"{_kwargs_text(config.env_kwargs)} but failed at its first reset and step "
            f"({type(err).__name__}: {one_line(err)}){at_fault}. Fix the values or drop "
            "--env-kwargs"
        ) from None
    if ended:
        # an episode that ends at its first step holds no decision to learn from, and every
        # evaluation returns the one step's reward: the run would train on nothing
        culprit = faulty_key(config)
        at_fault = f"; {culprit} is the value that ends it" if culprit else ""
        raise SetupError(
            f"--env-kwargs {json.dumps(config.env_kwargs)}: an episode of {config.env} made "
            f"with {_kwargs_text(config.env_kwargs)} ends at its first step, so the agent "
            f"would have no decision to learn from{at_fault}. Give it a longer episode (a time "
            "limit, duration or step limit of several steps) or drop that key"
        )


def _render_example(config: TrainConfig) -> str:
    """`` (e.g. '{"render_kwargs": ...}')``: the render settings of a dm_control task at the
    run's image size, which simoun gives it under --env-kwargs; empty for others."""
    if not config.env.startswith("dm_control/"):
        return ""
    render = {"width": config.image_size, "height": config.image_size, "camera_id": 0}
    return f" (e.g. '{json.dumps({'render_kwargs': render})}')"


MAX_PROBED_KEYS = 12
"""``--env-kwargs`` values tried one by one for the one at fault (each try makes the env)."""


def faulty_key(config: TrainConfig) -> str | None:
    """``config.lanes_count=0``: the one ``--env-kwargs`` value (a nested dict's too) without
    which ``config``'s env is made, reset and stepped, when the env's own error does not say
    which it cannot use; None when no single value is at fault."""
    paths = _leaves(config.env_kwargs)
    if len(paths) > MAX_PROBED_KEYS:
        return None
    for path in paths:
        if _works(config, _without(config.env_kwargs, path)):
            value = functools.reduce(lambda d, k: d[k], path, config.env_kwargs)
            return f"{'.'.join(path)}={json.dumps(value)}"
    return None


def _leaves(kwargs: dict, prefix: tuple[str, ...] = ()) -> list[tuple[str, ...]]:
    """The key path of every value of ``kwargs``, a nested dict's too, deepest first: a value
    is tried before the dict that holds it (``config.action.type``, then ``config.action``)."""
    paths: list[tuple[str, ...]] = []
    for key, value in kwargs.items():
        if isinstance(value, dict) and value:
            paths += _leaves(value, (*prefix, key))
        paths.append((*prefix, key))
    return sorted(paths, key=len, reverse=True)


def _without(kwargs: dict, path: tuple[str, ...]) -> dict:
    """``kwargs`` without the value at ``path`` (copied where it changes)."""
    head, *rest = path
    if not rest:
        return {key: value for key, value in kwargs.items() if key != head}
    return {**kwargs, head: _without(kwargs[head], tuple(rest))}


def _works(config: TrainConfig, kwargs: dict) -> bool:
    """Whether ``config``'s env, made with ``kwargs`` for its ``--env-kwargs``, is made, reset
    and stepped without its episode ending at that first step."""
    try:
        env = gym.make(
            config.env, render_mode="rgb_array", **_make_kwargs(replace(config, env_kwargs=kwargs))
        )
    except Exception:  # any failure to make it counts against these kwargs
        return False
    try:
        check_render_keys(env, replace(config, env_kwargs=kwargs))
        return not _first_step(env)
    except Exception:
        return False
    finally:
        env.close()


def _check_env(env: gym.Env, env_id: str) -> None:
    if not isinstance(env.action_space, spaces.Box) or len(env.action_space.shape) != 1:
        highway = (
            "; for highway-env use --preset highway, or --env-kwargs "
            '\'{"config": {"action": {"type": "ContinuousAction"}}}\''
            if is_highway(env_id)
            else ""
        )
        raise SetupError(
            f"{env_id} has action space {env.action_space}; the Simoun agent is a SAC agent for "
            f"continuous actions and needs a 1-D Box. Pick a continuous-control env{highway}."
        )
    if not np.all(np.isfinite(env.action_space.low) & np.isfinite(env.action_space.high)):
        raise SetupError(
            f"{env_id} has unbounded actions {env.action_space}; rescaling [-1, 1] actions needs "
            "finite bounds. Wrap the env with gymnasium.wrappers.ClipAction or bounds of your own."
        )
    has_pixels = image_layout(env.observation_space) is not None
    renders = env.render_mode == "rgb_array" and "rgb_array" in env.metadata.get("render_modes", [])
    if not (has_pixels or renders):
        raise SetupError(
            f"{env_id} gives no frames to learn from: {_no_render_reason(env, env_id)}, "
            f"{_observation_reason(env, env_id)}"
        )


def _no_render_reason(env: gym.Env, env_id: str) -> str:
    """Why ``env`` renders no rgb_array frames: its creator takes no ``render_mode`` (its
    metadata may still list rgb_array), or it has no such mode."""
    modes = env.metadata.get("render_modes", [])
    if "rgb_array" in modes and env.render_mode != "rgb_array":
        return (
            f"its constructor does not accept render_mode (gym.make({env_id!r}, "
            "render_mode='rgb_array') raises TypeError), so it cannot be made to render "
            f"rgb_array frames, though its metadata lists the render modes {modes}"
        )
    return f"it has no rgb_array rendering (its render modes are {modes})"


def _observation_reason(env: gym.Env, env_id: str) -> str:
    """Why ``env``'s observations are no frames either, and the fix; for highway-env, whose
    observation simoun replaces with a tiny one (its views come from renders), that they
    cannot stand in."""
    if is_highway(env_id):
        return (
            "and simoun draws the agent's views of a highway-env task with that renderer (in "
            "place of the task's own observation). Pick a highway-env task that takes "
            "render_mode (e.g. highway-fast-v0)"
        )
    return (
        f"and its observations are no images either (observation space "
        f"{env.observation_space}, where (H, W, 3), (H, W, 1) or (H, W) frames are needed). "
        "Simoun learns from pixels: use an env that renders rgb_array images, or wrap yours so "
        "it returns (H, W, 3) uint8 images."
    )


def check_task(config: TrainConfig) -> int | None:
    """Make ``config``'s env and close it: SetupError when the agent cannot train on it (an
    unknown id, actions that are not a bounded 1-D Box, no pixels, cameras it lacks, env kwargs
    it fails on at its first step), before a run is spent; returns its episodes' step limit
    (None: it has none)."""
    base = env = _make_base(config)
    try:
        _check_env(env, config.env)
        if config.env_kwargs:
            check_first_step(env, config)
        if config.cameras > 1 and not is_highway(config.env):
            # highway-env's viewports are drawn by viewers that outlive the wrapper: made only
            # for the run
            env = _multi_camera(env, config)
        limit = episode_limit(base)
        check_decisions(config, limit)
        return limit
    finally:
        env.close()


MIN_EPISODE_DECISIONS = 2
"""Agent decisions an episode must hold at least: with one, every action is the episode's
last, and nothing the agent sees follows from what it did."""


def check_decisions(config: TrainConfig, limit: int | None) -> None:
    """SetupError when ``config``'s action repeat leaves fewer than
    :data:`MIN_EPISODE_DECISIONS` agent decisions in an episode of ``limit`` env steps (None:
    episodes without a limit, nothing to check)."""
    repeat = config.resolved_action_repeat()
    if limit is None or limit // repeat >= MIN_EPISODE_DECISIONS:
        return
    if limit < MIN_EPISODE_DECISIONS:
        source = "--env-kwargs" if config.env_kwargs else config.env
        raise SetupError(
            f"{source}: an episode of {config.env} ends after {limit} env step, which holds "
            "no agent decision whose outcome the agent could see; give it a longer episode "
            f"(e.g. --env-kwargs '{{\"max_episode_steps\": {MIN_EPISODE_DECISIONS * 50}}}')"
        )
    given = "" if config.action_repeat is not None else ", the paper's value for this task"
    decisions = max(1, math.ceil(limit / repeat))
    raise SetupError(
        f"--action-repeat {repeat} (TrainConfig.action_repeat{given}): an episode of "
        f"{config.env} ends after {limit} env steps, so it would hold {decisions} agent "
        f"decision{'s' if decisions != 1 else ''} and the agent could not learn from what its "
        f"actions lead to; set --action-repeat {limit // MIN_EPISODE_DECISIONS} or less (the "
        "paper uses 2 to 8)"
    )


def episode_limit(env: gym.Env) -> int | None:
    """The env steps after which ``env``'s episodes end at the latest: its registered limit
    (an ``--env-kwargs`` max_episode_steps included), a dm_control task's time limit, or the
    ``max_steps`` of an env that truncates its own episodes (MiniGrid, PointReach); None when
    it has none."""
    spec = env.spec
    if spec is not None and spec.max_episode_steps:
        return spec.max_episode_steps
    base = env.unwrapped
    dm_limit = getattr(getattr(base, "_env", None), "_step_limit", None)
    if isinstance(dm_limit, (int, float)) and math.isfinite(dm_limit) and dm_limit > 0:
        return int(dm_limit)
    own = getattr(base, "max_steps", None)
    return own if isinstance(own, int) and own > 0 else None


def make_env(
    config: TrainConfig, distractor: Callable[[gym.Env], gym.Env] | None = None
) -> gym.Env:
    """The wrapped environment for ``config``; raises SetupError for an unusable env.

    ``distractor`` wraps the bare env before anything else (e.g. a ``ColorShift`` or
    ``MovingBackground``, see :mod:`simoun_agent.generalization`), so that every rendered view
    above it shows the distraction.
    """
    env = _make_base(config)
    _check_env(env, config.env)
    if distractor is not None:
        env = distractor(env)
    bound = np.ones(env.action_space.shape, dtype=env.action_space.dtype)
    env = RescaleAction(env, -bound, bound)
    env = ActionRepeat(env, config.resolved_action_repeat())
    size: int | None = config.image_size
    if config.cameras > 1 or is_highway(config.env):
        env = _multi_camera(env, config)
        size = None
    try:
        return SimounObservation(
            env,
            size=size,
            grayscale=config.grayscale,
            num_frames=config.agent.num_frames,
            motion=False,
        )
    except (TypeError, ValueError) as err:  # the env's frames: its first render, their size
        source = f"--env-kwargs {json.dumps(config.env_kwargs)}" if config.env_kwargs else "--env"
        raise SetupError(f"{source}: {config.env} gives no frames to learn from: {err}") from None


def _multi_camera(env: gym.Env, config: TrainConfig) -> MultiCamera:
    """``MultiCamera`` over ``env`` with ``config``'s views; a SetupError naming ``--cameras``
    when the env lacks the cameras asked for."""
    views = _cameras(config)
    physics = getattr(getattr(env.unwrapped, "_env", None), "physics", None)
    have = getattr(getattr(physics, "model", None), "ncam", None)
    if isinstance(have, int) and config.cameras > have:
        raise SetupError(
            f"--cameras {config.cameras}: {config.env} has only {have} camera"
            f"{'s' if have != 1 else ''}; pass --cameras {have} or fewer"
        )
    try:
        return MultiCamera(env, views, size=config.image_size)
    except ValueError as err:
        raise SetupError(
            f"--cameras {config.cameras}: {config.env} cannot show {config.cameras} views "
            f"({err}); pass a smaller --cameras"
        ) from None


def _cameras(config: TrainConfig) -> list:
    if is_highway(config.env):
        if config.cameras > len(HIGHWAY_VIEWPORTS):
            raise SetupError(
                f"highway-env runs have at most {len(HIGHWAY_VIEWPORTS)} viewports, got "
                f"cameras={config.cameras}; set cameras to 1, 2 or 3."
            )
        zoom = config.image_size / 84
        # one camera looks ahead; several are the paper's layout, behind to ahead
        views = [HIGHWAY_FORWARD_VIEWPORT] if config.cameras == 1 else HIGHWAY_VIEWPORTS
        views = views[: config.cameras]
        return [{**view, "scaling": view["scaling"] * zoom} for view in views]
    if config.env.startswith("dm_control/"):
        return list(range(config.cameras))
    raise SetupError(
        f"cameras={config.cameras} needs a dm_control or highway-env task, not {config.env}; "
        "set cameras=1, or build a MultiCamera with your own view callables."
    )


def control_timestep(env: gym.Env) -> float | None:
    """Seconds of simulated time per inner env step, or None when the env does not say.

    shimmy's dm_control envs report a wrong ``render_fps`` (the control timestep x 1000), so
    their timestep comes from dm_control itself; highway-env's from its policy frequency.
    """
    base = env.unwrapped
    dm_env = getattr(base, "_env", None)
    if dm_env is not None and hasattr(dm_env, "control_timestep"):
        return float(dm_env.control_timestep())
    config = getattr(base, "config", None)
    if isinstance(config, dict) and "policy_frequency" in config:
        return 1.0 / config["policy_frequency"]
    fps = base.metadata.get("render_fps")
    return 1.0 / fps if fps else None


def video_fps(env: gym.Env, action_repeat: int) -> float:
    """Frames per second of real-time video with one frame per agent decision."""
    timestep = control_timestep(env)
    return 1.0 / (timestep * action_repeat) if timestep else 30.0
