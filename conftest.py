"""Suite-wide pytest set-up: headless defaults, one torch thread, doctests of the packages.

``--doctest-modules`` (pyproject's ``addopts``) runs every ``>>>`` example of ``simoun_wrappers``,
``simoun_agent`` and ``simoun_lab``, as Gymnasium does. A module that imports an optional
dependency which is not installed (pettingzoo without the ``multiagent`` extra, say) cannot be
imported to collect its examples: it is left out of collection, and the report header names it
and the missing package, so nothing is skipped silently.
"""

from __future__ import annotations

import ast
import importlib.util
from functools import cache
from pathlib import Path

import pytest

import simoun_wrappers  # noqa: F401  (headless rendering defaults, before dm_control/pygame load)

ROOT = Path(__file__).parent
PACKAGES = (ROOT / "simoun_wrappers", ROOT / "simoun_agent", ROOT / "simoun_lab")


@pytest.fixture(autouse=True)
def one_torch_thread():
    """One torch thread per test: the suite runs on two xdist workers on two cores, and the
    tensors are small, so a second thread per worker only spin-waits (measured up to 10x slower)."""
    import torch

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)


@cache
def missing_imports(path: Path) -> tuple[str, ...]:
    """Top-level packages that ``path`` imports at module level and that are not installed."""
    names = set()
    for node in ast.parse(path.read_text(encoding="utf-8")).body:
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return tuple(sorted(name for name in names if importlib.util.find_spec(name) is None))


def package_module(path: Path) -> bool:
    return path.suffix == ".py" and any(path.is_relative_to(pkg) for pkg in PACKAGES)


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    if package_module(collection_path) and missing_imports(collection_path):
        return True
    return None


def pytest_report_header(config: pytest.Config) -> list[str]:
    left_out = [
        f"{path.relative_to(ROOT)} (needs {', '.join(missing)})"
        for pkg in PACKAGES
        for path in sorted(pkg.rglob("*.py"))
        if (missing := missing_imports(path))
    ]
    return [f"doctests not collected, optional dependency missing: {m}" for m in left_out]
