"""The packages' layers: ``simoun_wrappers`` <- ``simoun_agent`` <- ``simoun_lab``, each importing
only the ones before it (docs/architecture.md), so the wrappers install and run without the
agent, and the product without the lab."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

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
