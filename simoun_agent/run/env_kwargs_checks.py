"""Checks of ``--env-kwargs`` values that name something outside the value itself: a camera of
the env's MuJoCo model, a file, a class by its dotted path. The libraries take such values
without looking: MuJoCo ends the process at the first render over a camera id it lacks,
gymnasium's renderer turns an unknown camera name into the free camera, and a file or class
that is not there fails deep in the env's own code. Each is refused here, naming the flag, the
key and a value that works.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import json
import os
from pathlib import Path
from typing import Any

import gymnasium as gym

from simoun_agent.config import SetupError
from simoun_agent.run.highway_config import nested

RENDER_SIZE_KEYS = {
    "width": "the width of {env}'s rendered frames in pixels",
    "height": "the height of {env}'s rendered frames in pixels",
    "max_geom": "the most geoms drawn in {env}'s frames",
}
"""render keywords of gymnasium's MuJoCo envs that are counts of at least 1 (a render width of
0 draws nothing, a ``max_geom`` of 0 or less leaves every geom out of the picture)"""

DMC_RENDER_SIZE_KEYS = ("width", "height")
"""keys of a dm_control task's ``render_kwargs`` that are counts of at least 1"""


def check_render_keys(env: gym.Env, config: Any) -> None:
    """SetupError for a camera or render-size keyword of ``config.env_kwargs`` that the made
    ``env``'s MuJoCo model cannot render with, before the first render: gymnasium's MuJoCo
    ``camera_id``, ``camera_name``, ``width``, ``height``, ``max_geom`` and
    ``default_camera_config``, and dm_control's ``render_kwargs`` ``camera_id``, ``width`` and
    ``height``. Other envs are left alone."""
    given = config.env_kwargs
    base = env.unwrapped
    physics = getattr(getattr(base, "_env", None), "physics", None)
    if physics is not None and isinstance(given.get("render_kwargs"), dict):
        render = given["render_kwargs"]
        cameras = [physics.model.id2name(i, "camera") for i in range(physics.model.ncam)]
        for key in DMC_RENDER_SIZE_KEYS:
            _check_size(config.env, f"render_kwargs.{key}", render.get(key))
        if "camera_id" in render:
            _check_camera(config.env, "render_kwargs.camera_id", render["camera_id"], cameras)
        return
    model = getattr(base, "model", None)
    if not hasattr(model, "ncam") or not hasattr(base, "mujoco_renderer"):
        return
    import mujoco

    cameras = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, i) for i in range(model.ncam)]
    for key in RENDER_SIZE_KEYS:
        _check_size(config.env, key, given.get(key))
    if given.get("camera_id") is not None:
        _check_camera(config.env, "camera_id", given["camera_id"], cameras, by_name=False)
    if given.get("camera_name") is not None:
        _check_camera_name(config.env, given["camera_name"], cameras)
    _check_camera_config(config.env, given.get("default_camera_config"))


def _check_size(env_id: str, name: str, value: object) -> None:
    if value is None or (isinstance(value, int) and not isinstance(value, bool) and value >= 1):
        return
    meaning = RENDER_SIZE_KEYS[name.rpartition(".")[2]].format(env=env_id)
    raise SetupError(
        f"--env-kwargs: {name}={json.dumps(value)} ({meaning}) must be a whole "
        f"number of at least 1; e.g. '{json.dumps(nested(name, 84))}', or drop {name}"
    )


def cameras_text(cameras: list[str | None]) -> str:
    """``0 'track', 1 (no name)``, and the free camera -1; the model's cameras in words."""
    own = ", ".join(f"{i} {name!r}" if name else f"{i} (no name)" for i, name in enumerate(cameras))
    free = "-1, the free camera"
    return f"{own} and {free}" if own else f"only {free} (its model has no camera of its own)"


def _camera_example(name: str, cameras: list[str | None]) -> str:
    """A working value of camera key ``name`` (the first named camera, else the free one)."""
    if name == "camera_name":
        named = [camera for camera in cameras if camera]
        return f"'{json.dumps({name: named[0]})}'" if named else "no camera_name"
    return f"'{json.dumps(nested(name, 0 if cameras else -1))}'"


def _check_camera(
    env_id: str, name: str, value: object, cameras: list[str | None], by_name: bool = True
) -> None:
    """SetupError for a camera id outside ``cameras`` (or, ``by_name``, a name not among
    them): MuJoCo ends the process over an id it lacks at the first render."""
    if isinstance(value, int) and not isinstance(value, bool) and -1 <= value < len(cameras):
        return
    if by_name and isinstance(value, str) and value in cameras:
        return
    kind = "a camera id (a whole number) or name" if by_name else "a camera id (a whole number)"
    raise SetupError(
        f"--env-kwargs: {name}={json.dumps(value)} is not a camera of {env_id}; {name} is "
        f"{kind}, and its cameras are {cameras_text(cameras)}. Give e.g. "
        f"{_camera_example(name, cameras)}, or drop {name}"
    )


def _check_camera_name(env_id: str, value: object, cameras: list[str | None]) -> None:
    """SetupError for a camera name the model lacks: gymnasium's renderer would silently
    render the free camera instead."""
    if isinstance(value, str) and value in cameras:
        return
    named = [camera for camera in cameras if camera]
    listed = ", ".join(map(repr, named)) if named else "none (its model names no camera)"
    raise SetupError(
        f"--env-kwargs: camera_name={json.dumps(value)} is not a camera of {env_id} (gymnasium "
        f"would render the free camera instead, without a word); its named cameras are "
        f"{listed}. Give e.g. {_camera_example('camera_name', cameras)}, or a camera_id "
        f"instead (its cameras are {cameras_text(cameras)}), or drop camera_name"
    )


@functools.cache
def _camera_fields() -> tuple[str, ...]:
    """The settings of MuJoCo's free camera (``mujoco.MjvCamera``), which
    ``default_camera_config`` sets by name."""
    import mujoco

    return tuple(name for name in dir(mujoco.MjvCamera()) if not name.startswith("_"))


def _check_camera_config(env_id: str, value: object) -> None:
    if value is None:
        return
    fields = _camera_fields()
    example = '\'{"default_camera_config": {"distance": 4.0}}\''
    if not isinstance(value, dict):
        raise SetupError(
            f"--env-kwargs: default_camera_config={json.dumps(value)} must be a JSON object "
            f"of camera settings for {env_id}; e.g. {example}, or drop it"
        )
    unknown = [key for key in value if key not in fields]
    if unknown:
        raise SetupError(
            f"--env-kwargs: default_camera_config.{unknown[0]} is not a setting of MuJoCo's "
            f"camera; its settings are {', '.join(fields)}. Fix the key (e.g. {example}), "
            "or drop it"
        )


FILE_SUFFIXES = (".xml", ".urdf", ".json", ".yaml", ".yml", ".npz", ".npy", ".png", ".csv")
"""endings of a default value that make its keyword a file name"""


def names_file(key: str, default: object) -> bool:
    """Whether keyword ``key`` (with ``default``) takes a file's name: its name says so
    (``xml_file``, ``model_path``) or its default is a file name (``half_cheetah.xml``)."""
    if key.endswith(("_file", "_path")) or key in ("file", "path", "filename"):
        return True
    return isinstance(default, str) and default.lower().endswith(FILE_SUFFIXES)


def check_files(env_id: str, kwargs: dict, defaults: dict) -> None:
    """SetupError for a top-level ``--env-kwargs`` string that names a file (:func:`names_file`)
    which is not where the env will look for it, naming where that is and a path that works."""
    creator = _creator(env_id)
    for key, value in kwargs.items():
        if not (isinstance(value, str) and names_file(key, defaults.get(key))):
            continue
        place = _mujoco_place(value) if _is_mujoco(creator) else None
        if place is not None:
            if os.path.exists(place):
                continue
            raise _missing_file(env_id, key, value, place, mujoco=True)
        if any(os.path.exists(path) for path in _places(value, creator)):
            continue
        raise _missing_file(env_id, key, value, str(Path(value).expanduser().resolve()))


def _creator(env_id: str) -> Any:
    spec = gym.spec(env_id)
    if callable(spec.entry_point):
        return spec.entry_point
    try:
        return gym.envs.registration.load_env_creator(spec.entry_point)
    except (ImportError, AttributeError, gym.error.Error):
        return None


def _is_mujoco(creator: Any) -> bool:
    from gymnasium.envs.mujoco.mujoco_env import MujocoEnv

    return inspect.isclass(creator) and issubclass(creator, MujocoEnv)


def _mujoco_place(value: str) -> str:
    """Where gymnasium's MuJoCo envs look for the model file ``value`` (as its
    ``expand_model_path`` does): as given when it starts with ``.`` or ``/``, in the home folder
    for ``~``, else in gymnasium's MuJoCo assets folder."""
    if value.startswith((".", "/")):
        return value
    if value.startswith("~"):
        return os.path.expanduser(value)
    return str(_mujoco_assets() / value)


def _mujoco_assets() -> Path:
    from gymnasium.envs.mujoco import mujoco_env

    return Path(mujoco_env.__file__).parent / "assets"


def _places(value: str, creator: Any) -> list[str]:
    """Where an env may look for the file ``value``: as given (from the current directory), or
    next to its creator's module or in an ``assets`` folder there."""
    places = [os.path.expanduser(value)]
    module = inspect.getmodule(creator) if creator is not None else None
    source = getattr(module, "__file__", None)
    if source:
        here = Path(source).parent
        places += [str(here / value), str(here / "assets" / value)]
    return places


def _missing_file(
    env_id: str, key: str, value: str, place: str, mujoco: bool = False
) -> SetupError:
    if not mujoco:
        return SetupError(
            f"--env-kwargs: {key}={json.dumps(value)} names no file ({place} does not exist) "
            f"for {env_id}; give the path of an existing file, or drop {key}"
        )
    assets = _mujoco_assets()
    bundled = ", ".join(sorted(path.name for path in assets.glob("*.xml"))[:8])
    here = Path(value)
    fix = (
        f"give it as './{value}' (or its absolute path {here.resolve()})"
        if not value.startswith((".", "/", "~")) and here.is_file()
        else "give the absolute path of an existing MuJoCo XML file"
    )
    return SetupError(
        f"--env-kwargs: {key}={json.dumps(value)} names no file: {env_id} reads it from "
        f"{place}, which does not exist (a name without a leading ./, / or ~ is looked up in "
        f"gymnasium's MuJoCo assets folder {assets}, which holds {bundled}, ...); {fix}, or "
        f"drop {key}"
    )


def check_class_paths(env_id: str, kwargs: dict, defaults: dict, prefix: str = "") -> None:
    """SetupError for a string (at any depth of ``--env-kwargs``) whose default is the dotted
    path of a class (highway-env's ``other_vehicles_type``) but which names no class that
    imports, offering the classes of the same kind in the module it names."""
    for key, value in kwargs.items():
        default = defaults.get(key) if isinstance(defaults, dict) else None
        name = f"{prefix}{key}"
        if isinstance(value, dict) and isinstance(default, dict):
            check_class_paths(env_id, value, default, f"{name}.")
            continue
        if not (isinstance(value, str) and isinstance(default, str)):
            continue
        kind = _imported(default)
        if not inspect.isclass(kind) or inspect.isclass(_imported(value)):
            continue
        raise SetupError(
            f"--env-kwargs: {name}={json.dumps(value)} names no class that imports, and "
            f"{env_id}'s {name} is the dotted path of a class (default {json.dumps(default)}); "
            f"give one of {_class_choices(value, default, kind)}, or drop {name}"
        )


def _imported(path: str) -> object:
    """The object at the dotted ``path`` (``package.module.Name``), or None."""
    module, _, name = path.rpartition(".")
    if not module or not name.isidentifier():
        return None
    try:
        return getattr(importlib.import_module(module), name, None)
    except (ImportError, ValueError, TypeError):
        return None


def _class_choices(value: str, default: str, kind: type) -> str:
    """``the classes of that kind in highway_env.vehicle.behavior are ...``: the classes
    defined in the module ``value`` (else the default) names that share the default's parent."""
    parent = kind.__mro__[1]
    for path in (value, default):
        module_name = path.rpartition(".")[0]
        try:
            module = importlib.import_module(module_name)
        except (ImportError, ValueError, TypeError):
            continue
        found = [
            f"{module_name}.{name}"
            for name, item in vars(module).items()
            if inspect.isclass(item) and item.__module__ == module_name and issubclass(item, parent)
        ]
        if found:
            return f"the classes of that kind in {module_name}: {', '.join(found)}"
    return f"the classes of that kind, e.g. {json.dumps(default)}"
