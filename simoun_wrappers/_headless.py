"""Headless rendering defaults, applied before dm_control or pygame load.

``MUJOCO_GL=egl`` lets dm_control render without a display (Mesa's llvmpipe on CPU-only
machines). highway-env draws through pygame, whose ``dummy`` SDL video driver renders
black frames; ``offscreen`` renders real ones. Both are defaults: a value the user set wins.
"""

import os
import warnings

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("SDL_VIDEODRIVER", "offscreen")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

if os.environ["SDL_VIDEODRIVER"] == "dummy":
    warnings.warn(
        "SDL_VIDEODRIVER=dummy makes highway-env render black frames; "
        "unset it or set SDL_VIDEODRIVER=offscreen.",
        stacklevel=2,
    )
