"""The package's import-time promises: headless defaults set, torch not loaded."""

import os
import subprocess
import sys


def test_import_sets_headless_defaults_and_leaves_torch_unloaded():
    code = (
        "import os, sys, simoun_wrappers, simoun_wrappers.pettingzoo; "
        "print(os.environ['MUJOCO_GL'], os.environ['SDL_VIDEODRIVER'], 'torch' in sys.modules)"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "SDL_VIDEODRIVER")}
    out = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
    )
    assert out.stdout.split() == ["egl", "offscreen", "False"]
