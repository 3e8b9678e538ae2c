"""Headless rendering defaults, applied before dm_control or pygame load, only without a display.

On a Linux machine with no display (no ``DISPLAY`` or ``WAYLAND_DISPLAY``: a server, a container,
a cluster job) ``MUJOCO_GL=egl`` lets dm_control render (Mesa's llvmpipe on CPU-only machines),
and ``SDL_VIDEODRIVER=offscreen`` lets highway-env draw through pygame (SDL's ``dummy`` driver
renders black frames). With a display, and on macOS and Windows, both are left unset so that
``render_mode="human"`` windows appear and dm_control picks its own backend.
``SDL_NO_SIGNAL_HANDLERS=1`` is set everywhere: it keeps SDL from installing its own
SIGINT/SIGTERM handlers, which turn the signals into quit events that nobody reads (a job
scheduler's SIGTERM would then be ignored until its SIGKILL). All are defaults: a value the
user set wins.

dm_control reads ``MUJOCO_GL`` once, when it is first imported (``import shimmy`` does it): if
that happened before this module ran, on a machine without a display, it has chosen GLFW and
every render will fail, so a warning says how to fix the import order.
"""

import os
import sys
import warnings


def has_display() -> bool:
    """Whether windows can open: always on macOS and Windows; on Linux and other Unixes only
    with ``DISPLAY`` (X11) or ``WAYLAND_DISPLAY`` set to a non-empty value."""
    if sys.platform == "darwin" or sys.platform.startswith("win"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


_mujoco_gl_was_set = "MUJOCO_GL" in os.environ

if not has_display():
    os.environ.setdefault("MUJOCO_GL", "egl")
    os.environ.setdefault("SDL_VIDEODRIVER", "offscreen")
os.environ.setdefault("SDL_NO_SIGNAL_HANDLERS", "1")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

if os.environ.get("SDL_VIDEODRIVER") == "dummy":
    warnings.warn(
        "SDL_VIDEODRIVER=dummy makes highway-env render black frames; "
        "unset it or set SDL_VIDEODRIVER=offscreen.",
        stacklevel=2,
    )


def dm_control_without_display() -> bool:
    """Whether dm_control was already loaded, with ``MUJOCO_GL`` unset, on a Linux machine with
    no display: then it picked GLFW, which cannot make an OpenGL context there."""
    render = sys.modules.get("dm_control._render")
    return (
        render is not None
        and not _mujoco_gl_was_set
        and getattr(render, "BACKEND", None) in (None, "glfw")
        and sys.platform.startswith("linux")
        and not has_display()
    )


if dm_control_without_display():
    warnings.warn(
        "dm_control was imported before simoun_wrappers with MUJOCO_GL unset and no display, "
        "so it chose the GLFW renderer and rendering will fail with mujoco.FatalError ('an "
        "OpenGL platform library has not been loaded'). Import simoun_wrappers before shimmy "
        "or dm_control, or export MUJOCO_GL=egl before starting Python.",
        stacklevel=2,
    )
