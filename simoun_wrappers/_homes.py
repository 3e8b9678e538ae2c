"""Where a public name of the project's packages is defined, for the packages' ``__getattr__``:
``from simoun_wrappers import SimounParallelObservation`` names the module to import it from
(``simoun_wrappers.pettingzoo``), where Python's own ImportError names only the package. Every
package with submodules, subpackages included (``from simoun_lab.analysis import
layer_activations`` names ``simoun_lab.analysis.layers``), defines
``__getattr__(name)`` as ``raise missing_name(__name__, name)``.

The modules are read as source (``ast``), never imported: asking ``simoun_wrappers`` for a name
must not import torch or PettingZoo."""

from __future__ import annotations

import ast
import functools
import importlib.util
from pathlib import Path

PACKAGES = ("simoun_wrappers", "simoun_agent", "simoun_lab")
"""The packages searched, after the one asked."""


def search_order(package: str) -> tuple[str, ...]:
    """The packages searched for a name that ``package`` lacks: itself (a subpackage such as
    ``simoun_lab.analysis`` first, for the names of its own submodules), then its top-level
    package, then the other packages."""
    top = package.partition(".")[0]
    return tuple(dict.fromkeys((package, top, *PACKAGES)))


def defined_names(tree: ast.Module) -> set[str]:
    """The names a module's top level defines (classes, functions, assignments), not those it
    imports."""
    names: set[str] = set()
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def package_modules(package: str) -> list[tuple[str, Path]]:
    """``(module name, source file)`` of every module of ``package``, shallow ones first."""
    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        return []
    root = Path(next(iter(spec.submodule_search_locations)))
    modules = []
    for path in root.rglob("*.py"):
        parts = path.relative_to(root).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(part.startswith("_") and part != "__main__" for part in parts):
            continue
        modules.append((".".join((package, *parts)), path))
    return sorted(modules, key=lambda item: (item[0].count("."), item[0]))


def is_submodule(package: str, name: str) -> bool:
    """Whether ``package`` has a submodule ``name`` (found, not imported)."""
    spec = importlib.util.find_spec(package)
    locations = spec.submodule_search_locations if spec is not None else None
    if not locations:
        return False
    root = Path(next(iter(locations)))
    return (root / f"{name}.py").is_file() or (root / name / "__init__.py").is_file()


@functools.cache
def homes(package: str) -> dict[str, str]:
    """Public name -> the first module of ``package`` defining it."""
    found: dict[str, str] = {}
    for module, path in package_modules(package):
        try:
            tree = ast.parse(path.read_text(encoding="utf-8"))
        except (OSError, SyntaxError, UnicodeDecodeError):
            continue
        for name in defined_names(tree):
            if not name.startswith("_"):
                found.setdefault(name, module)
    return found


def missing_name(package: str, name: str) -> Exception:
    """What ``package.__getattr__(name)`` raises for a name it does not have: an ImportError
    naming the module that defines it (this package's first, then the others'), or an
    AttributeError, as Python's own, for a name defined nowhere (``hasattr`` stays False)."""
    plain = AttributeError(f"module {package!r} has no attribute {name!r}")
    if name.startswith("_") or is_submodule(package, name):
        # an AttributeError lets ``from package import submodule`` import the submodule
        return plain
    for searched in search_order(package):
        module = homes(searched).get(name)
        if module is not None and module != package:
            return ImportError(
                f"cannot import name {name!r} from {package!r}: it is defined in {module}; "
                f"import it from there: from {module} import {name}",
                name=package,
            )
    return plain
