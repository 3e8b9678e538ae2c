"""A study's record (``study.json``) told apart from a study spec: both are files of a study,
and a record given where a spec belongs would be read as a spec with unknown keys.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError

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
