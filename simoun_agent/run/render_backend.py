"""The rendering back-end an env draws its frames with, chosen by environment variables: MuJoCo's
(dm_control and Gymnasium's MuJoCo envs) by ``MUJOCO_GL`` and ``PYOPENGL_PLATFORM``,
highway-env's pygame by ``SDL_VIDEODRIVER``. A back-end the libraries know but that cannot run
on the machine (GLFW or an X11 driver without a display, OSMesa without its library) fails deep
inside them, on import or at the first render; :func:`named_backend` turns that failure into a
SetupError naming the variable, its value and a value that works.

Example:
    >>> with named_backend("dm_control/cartpole-swingup-v0"):
    ...     pass
"""

from __future__ import annotations

import contextlib
import ctypes.util
import gc
import os
import sys
import warnings
from traceback import extract_tb

import gymnasium as gym

from simoun_agent.config import SetupError
from simoun_wrappers._headless import has_display

MUJOCO_GL_WORKING = ("egl", "osmesa", "glfw")
"""the ``MUJOCO_GL`` rendering back-ends dm_control and mujoco render with"""

RENDERING_PACKAGES = ("OpenGL", "glfw", "dm_control/_render", "mujoco/egl", "mujoco/osmesa")
"""folders of the packages that open an OpenGL context: an error raised inside one of them is
the back-end's, not the env's"""


class named_backend:
    """``with named_backend(env_id):`` runs the block; a failure of the rendering back-end inside
    it (:func:`backend_failure`) is raised as a SetupError naming the environment variable that
    chose the back-end, and what the failure left half made is freed without a word."""

    def __init__(self, env_id: str) -> None:
        self.env_id = env_id
        self._warnings = warnings.catch_warnings()

    def __enter__(self) -> None:
        self._warnings.__enter__()
        # GLFW warns of each failed step before the error that says it cannot render
        warnings.filterwarnings("ignore", module="glfw")

    def __exit__(self, kind: type | None, err: BaseException | None, trace: object) -> None:
        self._warnings.__exit__(None, None, None)
        if err is None or not isinstance(err, Exception) or isinstance(err, SetupError):
            return
        failure = backend_failure(err, self.env_id)
        if failure is None:
            return
        del trace  # the failed frames hold the half-made context: free them before raising
        _drop_quietly(err)
        raise failure from None


def probe_render(env: gym.Env, env_id: str) -> None:
    """Render the bare MuJoCo env ``env`` (dm_control's or Gymnasium's) once, so that a
    back-end that cannot run here is named, and ``env`` closed, before anything else is built;
    any other failure of that render is left to the checks that follow, which name the setting
    at fault."""
    base = env.unwrapped
    dm_control = hasattr(getattr(base, "_env", None), "physics")
    if not (dm_control or hasattr(base, "mujoco_renderer")):
        return
    try:
        with named_backend(env_id):
            base.render()
    except SetupError:
        _close_quietly(env)
        raise
    except Exception:  # the env's own render errors are named by the checks at its first step
        return


def backend_failure(err: BaseException, env_id: str) -> SetupError | None:
    """The SetupError for ``err`` when the rendering back-end raised it (dm_control's or mujoco's
    refusal of a ``MUJOCO_GL`` they do not know, pygame's error while ``SDL_VIDEODRIVER`` picks
    a driver, mujoco's FatalError for a missing OpenGL context, an
    error raised inside an OpenGL package); None for any other error."""
    if isinstance(err, RuntimeError) and "MUJOCO_GL" in str(err):
        return _unknown_gl(env_id)
    if _is_pygame_error(err):
        return _sdl_failure(err, env_id)
    if _is_opengl_failure(err):
        return _gl_failure(err, env_id)
    return None


def _is_pygame_error(err: BaseException) -> bool:
    """Whether ``err`` is pygame's refusal of the video driver (``x11 not available``, ``No
    available video device``), not one of its other errors."""
    pygame = sys.modules.get("pygame")
    text = str(err).lower()
    about_driver = "not available" in text or "video" in text
    return pygame is not None and isinstance(err, pygame.error) and about_driver


def _is_opengl_failure(err: BaseException) -> bool:
    mujoco = sys.modules.get("mujoco")
    if mujoco is not None and isinstance(err, mujoco.FatalError) and "OpenGL" in str(err):
        return True
    if "PYOPENGL_PLATFORM" in str(err):
        return True
    folders = [frame.filename.replace(os.sep, "/") for frame in extract_tb(err.__traceback__)]
    return any(f"/{package}/" in name for name in folders for package in RENDERING_PACKAGES)


def _reason(err: BaseException) -> str:
    text = " ".join(str(err).split()) or type(err).__name__
    return f"{type(err).__name__}: {text[:200]}"


def _unknown_gl(env_id: str) -> SetupError:
    value = os.environ.get("MUJOCO_GL", "")
    return SetupError(
        f"MUJOCO_GL={value!r} is not a rendering back-end dm_control and mujoco know, so "
        f"{env_id} cannot be made; set MUJOCO_GL to {' or '.join(MUJOCO_GL_WORKING)} "
        "(egl on a machine without a display), or unset it"
    )


def _sdl_failure(err: BaseException, env_id: str) -> SetupError:
    value = os.environ.get("SDL_VIDEODRIVER")
    chosen = f"SDL_VIDEODRIVER={value}" if value else "SDL's default video driver"
    return SetupError(
        f"{chosen} cannot draw {env_id}'s frames on this machine (pygame: {_reason(err)}); "
        "set SDL_VIDEODRIVER=offscreen, or unset it (simoun sets offscreen when there is no "
        "display)"
    )


def _gl_failure(err: BaseException, env_id: str) -> SetupError:
    gl = os.environ.get("MUJOCO_GL")
    platform = os.environ.get("PYOPENGL_PLATFORM")
    said = f"({_reason(err)})"
    if platform and gl and platform != gl and gl != "glfw":
        return SetupError(
            f"PYOPENGL_PLATFORM={platform} does not match MUJOCO_GL={gl}, so {env_id} cannot "
            f"render {said}; unset PYOPENGL_PLATFORM (dm_control and mujoco set it from "
            f"MUJOCO_GL), or set PYOPENGL_PLATFORM={gl}"
        )
    chosen = f"MUJOCO_GL={gl}" if gl else "MUJOCO_GL unset (GLFW, the libraries' default)"
    if gl == "egl":
        return SetupError(
            f"{chosen} cannot render {env_id} on this machine {said}; install an EGL driver "
            "(libegl1 with Mesa, or the NVIDIA driver), or set MUJOCO_GL=osmesa with libOSMesa "
            "installed"
        )
    return SetupError(
        f"{chosen} cannot render {env_id} on this machine: {_why(gl)} {said}; set "
        "MUJOCO_GL=egl, or unset it (simoun sets egl when there is no display)"
    )


def _why(gl: str | None) -> str:
    """Why the back-end ``gl`` (``MUJOCO_GL``) cannot run here, as far as can be told."""
    if gl == "osmesa" and ctypes.util.find_library("OSMesa") is None:
        return "OSMesa needs the library libOSMesa, which is not installed"
    if gl in (None, "glfw") and not has_display():
        return "GLFW opens a window, and this machine has no display (DISPLAY is unset)"
    return "the back-end failed to open an OpenGL context"


def _close_quietly(env: gym.Env) -> None:
    """Close ``env``, whose renderer never opened: closing it may fail in turn, and says nothing
    the SetupError does not."""
    hook = sys.unraisablehook
    sys.unraisablehook = lambda _: None
    try:
        with contextlib.suppress(Exception):
            env.close()
        gc.collect()
    finally:
        sys.unraisablehook = hook


def _drop_quietly(err: BaseException) -> None:
    """Free what the failed render left half made (an OpenGL context, a viewer) now, without the
    'Exception ignored' lines their destructors print when they fail too; GLFW, which failed,
    is kept quiet until the process ends (it warns again when it is torn down)."""
    warnings.filterwarnings("ignore", module="glfw")
    hook = sys.unraisablehook
    sys.unraisablehook = lambda _: None
    try:
        err.__traceback__ = None
        err.__context__ = None
        gc.collect()
    finally:
        sys.unraisablehook = hook
