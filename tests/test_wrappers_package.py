"""The package's import-time promises: headless defaults set only without a display, SDL's
signal handlers always off, torch not loaded."""

import os
import subprocess
import sys

import pytest

RENDER_VARIABLES = ("MUJOCO_GL", "SDL_VIDEODRIVER", "SDL_NO_SIGNAL_HANDLERS")
DISPLAYS = ("DISPLAY", "WAYLAND_DISPLAY")
SHOW = (
    "import os, sys, simoun_wrappers, simoun_wrappers.pettingzoo; "
    f"print(*(os.environ.get(k, '-') for k in {RENDER_VARIABLES}), 'torch' in sys.modules)"
)


def import_with(**display: str) -> list[str]:
    """What importing simoun_wrappers leaves in the environment, given only ``display``."""
    env = {k: v for k, v in os.environ.items() if k not in RENDER_VARIABLES + DISPLAYS}
    env.update(display)
    out = subprocess.run(
        [sys.executable, "-c", SHOW], env=env, capture_output=True, text=True, timeout=300
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.split()


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="display rule for Linux")
def test_import_without_a_display_sets_headless_defaults_and_leaves_torch_unloaded():
    assert import_with() == ["egl", "offscreen", "1", "False"]
    assert import_with(DISPLAY="") == ["egl", "offscreen", "1", "False"]  # empty is no display


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="display rule for Linux")
@pytest.mark.parametrize("display", [{"DISPLAY": ":99"}, {"WAYLAND_DISPLAY": "wayland-9"}])
def test_import_with_a_display_leaves_rendering_to_the_desktop(display):
    """A fake display value: nothing connects to it, the import only reads the variable."""
    assert import_with(**display) == ["-", "-", "1", "False"]


def test_values_the_user_set_win():
    env = {k: v for k, v in os.environ.items() if k not in DISPLAYS}
    env.update(MUJOCO_GL="osmesa", SDL_VIDEODRIVER="x11", SDL_NO_SIGNAL_HANDLERS="0")
    out = subprocess.run(
        [sys.executable, "-c", SHOW], env=env, capture_output=True, text=True, timeout=300
    )
    assert out.stdout.split() == ["osmesa", "x11", "0", "False"], out.stderr


@pytest.mark.parametrize(
    ("statement", "home"),
    [
        ("from simoun_wrappers import SimounParallelObservation", "simoun_wrappers.pettingzoo"),
        ("from simoun_wrappers import ReturnStd", "simoun_wrappers.intrinsic_normalization"),
        ("from simoun_wrappers import RNDModel", "simoun_agent.rnd_model"),
        ("from simoun_lab import iqm", "simoun_lab.stats"),
        ("from simoun_agent import load_run", "simoun_agent.run.load"),
    ],
)
def test_a_name_of_a_submodule_imported_from_the_package_names_its_module(statement, home):
    name = statement.split()[-1]
    with pytest.raises(ImportError) as raised:
        exec(statement, {})
    assert f"from {home} import {name}" in str(raised.value)


def test_the_package_lookup_keeps_hasattr_submodules_and_torch_free_imports():
    check = (
        "import sys, simoun_wrappers, simoun_lab\n"
        "assert not hasattr(simoun_wrappers, 'nope') and not hasattr(simoun_lab, 'nope')\n"
        "try:\n    from simoun_wrappers import RNDModel\nexcept ImportError:\n    pass\n"
        "from simoun_wrappers import pettingzoo\n"
        "from simoun_lab import stats\n"
        "assert 'torch' not in sys.modules, 'torch imported'\n"
        "import simoun_agent\nassert not hasattr(simoun_agent, 'nope')\n"
        "from simoun_agent import run\n"
    )
    out = subprocess.run([sys.executable, "-c", check], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr


@pytest.mark.parametrize(
    ("statement", "home"),
    [
        ("from simoun_lab.analysis import layer_activations", "simoun_lab.analysis.layers"),
        ("from simoun_lab.analysis import play_episode", "simoun_lab.analysis.runs"),
        ("from simoun_lab.sweep import write_report", "simoun_lab.sweep.report"),
        ("from simoun_lab.study import load_spec", "simoun_lab.study.spec"),
        ("from simoun_agent.run import load_run", "simoun_agent.run.load"),
        ("from simoun_agent.models import SimounAgent", "simoun_agent.agent"),
        (
            "from simoun_agent.generalization import ModeResult",
            "simoun_agent.generalization.evaluation",
        ),
    ],
)
def test_a_subpackage_names_the_module_of_a_name_it_lacks(statement, home):
    name = statement.split()[-1]
    with pytest.raises(ImportError) as raised:
        exec(statement, {})
    assert f"from {home}" in str(raised.value) and f"import {name}" in str(raised.value)


def test_a_subpackage_lookup_keeps_its_submodules_and_hasattr():
    import simoun_lab.analysis

    assert not hasattr(simoun_lab.analysis, "nope")
    from simoun_lab.analysis import layers

    assert layers.__name__ == "simoun_lab.analysis.layers"
