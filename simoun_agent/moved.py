"""The lab's former names under ``simoun_agent``, kept for one release with a DeprecationWarning.

The lab (sweeps, studies, the MiniGrid study, analyses, statistics and their commands) is the
package :mod:`simoun_lab`. Code written against the former names still runs: ``import
simoun_agent.study``, ``from simoun_agent.study.spec import load_spec`` and ``python -m
simoun_agent.minigrid_study`` give the module of the new name, warning. :class:`MovedFinder`, on
``sys.meta_path`` once :mod:`simoun_agent` is imported, maps each name under :data:`MOVED`,
submodules included, to the module object of its new name, so a former name never loads a
second copy (whose classes would differ from the new module's, failing ``isinstance`` and
``except``). The new names are strings here: ``simoun_agent`` imports the lab only when a
former name is asked for.
"""

from __future__ import annotations

import importlib
import sys
import warnings
from collections.abc import Sequence
from importlib.machinery import ModuleSpec
from types import CodeType, ModuleType

MOVED = {
    "simoun_agent.analysis": "simoun_lab.analysis",
    "simoun_agent.cli.analyze": "simoun_lab.cli.analyze",
    "simoun_agent.cli.report": "simoun_lab.cli.report",
    "simoun_agent.cli.study": "simoun_lab.cli.study",
    "simoun_agent.cli.sweep": "simoun_lab.cli.sweep",
    "simoun_agent.minigrid_study": "simoun_lab.minigrid_study",
    "simoun_agent.stats": "simoun_lab.stats",
    "simoun_agent.study": "simoun_lab.study",
    "simoun_agent.sweep": "simoun_lab.sweep",
}
"""Former name -> new name; the former name's submodules follow it."""

RUN_AS_MAIN = """\
import runpy, warnings
warnings.warn({message!r}, DeprecationWarning)
runpy.run_module({new!r}, run_name="__main__", alter_sys=True)
"""
"""``python -m FORMER``: warning from ``__main__`` itself, where Python shows a
DeprecationWarning by default, then running the new module as ``__main__``."""


def new_name(name: str) -> str | None:
    """The name of the module formerly called ``name``; None when it did not move.

    >>> new_name("simoun_agent.study.spec"), new_name("simoun_agent.run")
    ('simoun_lab.study.spec', None)
    """
    for old, new in MOVED.items():
        if name == old or name.startswith(old + "."):
            return new + name[len(old) :]
    return None


def deprecation(old: str, new: str) -> str:
    """The warning for the former name ``old`` of ``new``."""
    return f"{old} is now {new}; the former name works until the next release"


class MovedLoader:
    """Loads a former name as the module of its new name."""

    def __init__(self, new: str) -> None:
        self.new = new

    def create_module(self, spec: ModuleSpec) -> None:
        return None  # a placeholder module, which exec_module replaces in sys.modules

    def exec_module(self, module: ModuleType) -> None:
        # stacklevel 2 names the importing line: warnings skips the import system's frames
        warnings.warn(deprecation(module.__name__, self.new), DeprecationWarning, stacklevel=2)
        sys.modules[module.__name__] = importlib.import_module(self.new)

    def get_code(self, name: str) -> CodeType:
        """The code ``python -m`` runs for the former name ``name`` (:data:`RUN_AS_MAIN`)."""
        source = RUN_AS_MAIN.format(message=deprecation(name, self.new), new=self.new)
        return compile(source, f"<{name}, now {self.new}>", "exec")


class MovedFinder:
    """A ``sys.meta_path`` finder of the former names in :data:`MOVED`."""

    @staticmethod
    def find_spec(
        name: str, path: Sequence[str] | None = None, target: ModuleType | None = None
    ) -> ModuleSpec | None:
        new = new_name(name)
        return None if new is None else ModuleSpec(name, MovedLoader(new))


def install() -> None:
    """Put :class:`MovedFinder` first on ``sys.meta_path`` (once): ahead of the path finder,
    which would otherwise take a former package's directory, left behind by an update with
    only its ``__pycache__``, for an empty namespace package."""
    if MovedFinder not in sys.meta_path:
        sys.meta_path.insert(0, MovedFinder)
