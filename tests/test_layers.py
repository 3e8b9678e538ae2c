"""The packages' layers: ``simoun_wrappers`` <- ``simoun_agent`` <- ``simoun_lab``, each importing
only the ones before it (docs/architecture.md), so the wrappers install and run without the
agent, and the product without the lab. A command imports torch, Ray and the trainers only once
its flags are read, so ``--help``, ``--version`` and a bad flag are answered in about a second."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest
import tomllib

ROOT = Path(__file__).resolve().parent.parent
FORBIDDEN = {
    "simoun_wrappers": {"simoun_agent", "simoun_lab"},
    "simoun_agent": {"simoun_lab"},
}
"""A package -> the packages it must not import."""


def imports(path: Path) -> list[str]:
    """Every module ``path`` imports by absolute name, at the top or inside a function."""
    names = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            names.append(node.module)
    return names


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_a_package_imports_no_package_above_it(package):
    files = sorted((ROOT / package).rglob("*.py"))
    assert len(files) > 10
    upward = [
        f"{path.relative_to(ROOT)}: {name}"
        for path in files
        for name in imports(path)
        if name.split(".")[0] in FORBIDDEN[package]
    ]
    assert upward == []


def test_the_product_commands_load_nothing_of_the_lab():
    code = (
        "import sys, simoun_agent.cli.train, simoun_agent.cli.eval; "
        "print([m for m in sys.modules if m.split('.')[0] == 'simoun_lab'])"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    assert done.stdout.strip() == "[]", done.stdout + done.stderr


HEAVY = ("torch", "ray", "stable_baselines3", "dm_control", "highway_env")
"""What a command imports only once its flags are read (seconds each)."""

ANSWER_FLAGS = f"""
import contextlib, importlib, io, sys
main = getattr(importlib.import_module(sys.argv[1]), sys.argv[2])
codes = []
for argv in (["--help"], ["--version"], ["--no-such-flag"]):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        try:
            main(argv)
        except SystemExit as done:
            codes.append(done.code)
print(codes, sorted(m for m in sys.modules if m.split(".")[0] in {HEAVY}))
"""


def entry_points() -> list[str]:
    """Every command: pyproject's console scripts and the MiniGrid study's ``python -m``."""
    scripts = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"]
    return [*sorted(scripts.values()), "simoun_lab.minigrid_study.__main__:main"]


@pytest.mark.parametrize("entry_point", entry_points())
def test_a_command_answers_help_version_and_a_bad_flag_before_torch_or_ray(entry_point):
    done = subprocess.run(
        [sys.executable, "-c", ANSWER_FLAGS, *entry_point.split(":")],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert done.stdout.strip() == "[0, 0, 2] []", done.stdout + done.stderr
