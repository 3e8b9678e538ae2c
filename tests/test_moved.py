"""The lab's former names under simoun_agent (simoun_agent.moved): each is the module of its new
name in simoun_lab, submodules included, with a DeprecationWarning that points at the importing
line; ``python -m`` with a former name runs the new command."""

import importlib
import os
import subprocess
import sys
from importlib.machinery import PathFinder
from pathlib import Path

import pytest

import simoun_agent
from simoun_agent.moved import MOVED, MovedFinder

ROOT = Path(__file__).resolve().parent.parent


def forget(monkeypatch: pytest.MonkeyPatch, prefix: str) -> None:
    """Drop ``prefix`` and its submodules from sys.modules, so the next import finds them."""
    for name in [n for n in sys.modules if n == prefix or n.startswith(prefix + ".")]:
        monkeypatch.delitem(sys.modules, name)


@pytest.mark.parametrize("old", sorted(MOVED))
def test_a_former_name_is_the_module_of_its_new_name_with_a_warning(old, monkeypatch):
    forget(monkeypatch, old)
    with pytest.warns(DeprecationWarning, match=f"^{old} is now {MOVED[old]};"):
        module = importlib.import_module(old)
    assert module is importlib.import_module(MOVED[old])


def test_a_former_submodule_is_the_new_one_warning_at_the_importing_line(monkeypatch):
    forget(monkeypatch, "simoun_agent.study")
    import simoun_lab.study.report
    import simoun_lab.study.spec

    with pytest.warns(DeprecationWarning, match=r"^simoun_agent\.study(\.spec)? is now") as caught:
        from simoun_agent.study.spec import load_spec
    assert load_spec is simoun_lab.study.spec.load_spec
    assert len(caught) == 2 and {w.filename for w in caught} == {__file__}
    with pytest.warns(DeprecationWarning, match="simoun_agent.study.report is now"):
        import simoun_agent.study.report
    assert simoun_agent.study.report is simoun_lab.study.report


def test_a_former_package_directory_left_behind_does_not_hide_the_new_package(
    tmp_path, monkeypatch
):
    """An update removes a package's files but not its ``__pycache__``; the path finder would
    take that directory for an empty namespace package."""
    (tmp_path / "study" / "__pycache__").mkdir(parents=True)
    monkeypatch.setattr(simoun_agent, "__path__", [*simoun_agent.__path__, str(tmp_path)])
    forget(monkeypatch, "simoun_agent.study")
    assert sys.meta_path.index(MovedFinder) < sys.meta_path.index(PathFinder)
    with pytest.warns(DeprecationWarning):
        module = importlib.import_module("simoun_agent.study")
    assert module is importlib.import_module("simoun_lab.study")


@pytest.mark.parametrize(
    ("old", "usage"),
    [
        ("simoun_agent.minigrid_study", "usage: python -m simoun_lab.minigrid_study"),
        ("simoun_agent.cli.report", "usage: simoun-report"),
    ],
)
def test_python_m_with_a_former_name_warns_and_runs_the_new_command(old, usage):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PYTHONWARNINGS": ""}
    done = subprocess.run(
        [sys.executable, "-m", old, "--help"],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(usage)
    assert f"DeprecationWarning: {old} is now {MOVED[old]};" in done.stderr
