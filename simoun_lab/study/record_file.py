"""A study's record (``study.json``) and selection (``selection.json``) told apart from a study
spec: all are files of a study, and one given where a spec belongs would be read as a spec with
unknown keys.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.kept import Damaged, read_json_object
from simoun_lab.study.given_path import shown

RECORD_KEYS = ("spec_file", "spec_text", "spec", "parts")
"""Keys every study record holds (:func:`simoun_lab.study.runner.open_study` writes them)."""


def record_not_spec(values: Any, path: Path | str, label: str) -> SetupError | None:
    """The refusal of the study record ``values``, read from ``path`` where a spec was asked
    for (``label``: the argument or flag that gave it), naming the spec it was run from; None
    when ``values`` is no study record."""
    if not (isinstance(values, dict) and all(key in values for key in RECORD_KEYS)):
        return None
    source = values["spec_file"]
    named = f", {source}" if isinstance(source, str) and source else ""
    return SetupError(
        f"{label} {path} is a study's record (the study.json that simoun-study run keeps in a "
        f"study directory and its archive), not a study spec; pass the spec file the study was "
        f"run from{named} (the record keeps its text as spec_text, should the file be gone)"
    )


SELECTION_KEYS = {
    "SAC": ("rule", "recipes", "ties"),
    "MiniGrid PPO": ("arms", "selected"),
}
"""Keys of the ``selection.json`` a study of each kind writes (each recipe's or arm's selected
setting): ``simoun-study run``'s, and ``python -m simoun_lab.minigrid_study select``'s."""


def selection_not_spec(values: Any, path: Path | str, label: str) -> SetupError | None:
    """The refusal of a study's selection (``selection.json``), read from ``path`` where a spec
    was asked for (``label``: the argument or flag that gave it), naming the spec beside it
    when its archive keeps one; None when ``values`` is no selection."""
    if not isinstance(values, dict):
        return None
    kinds = [kind for kind, keys in SELECTION_KEYS.items() if all(key in values for key in keys)]
    if not kinds or any(isinstance(values.get(key), list) for key in ("arms", "recipes")):
        return None  # a spec: its arms or recipes are a list
    fix = f"pass {spec_beside(Path(path))}"
    if label == "--spec" and kinds[0] == "SAC":  # the MiniGrid study's own command
        fix = (
            "leave --spec out to use the archive's spec.json, or pass a MiniGrid spec such as "
            "docs/studies/minigrid-v2/tuning/spec.json"
        )
    return SetupError(
        f"{label} {shown(path)} is the selection a {kinds[0]} study wrote (each "
        f"{'recipe' if kinds[0] == 'SAC' else 'arm'}'s selected setting), not a study spec; {fix}"
    )


def spec_beside(path: Path) -> str:
    """The spec of the archive that holds the file ``path``, as advice: the spec file its
    study record names, or its MiniGrid ``spec.json``; else the spec file the study ran from."""
    record, saved = path.parent / "study.json", path.parent / "spec.json"
    try:
        source = read_json_object(record).get("spec_file")
    except (OSError, Damaged):
        source = None
    if isinstance(source, str) and source:
        return f"the spec the study was run from, {shown(source)} (named in {shown(record)})"
    if saved.is_file() and saved != path:
        return f"the spec the archive's runs were trained with, {shown(saved)}"
    return "the spec file the study was run from (a .toml, or a MiniGrid spec.json)"
