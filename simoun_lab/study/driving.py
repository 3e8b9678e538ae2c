"""The paper's Table 2 measures of a driving study, as its report reads them.

Each evaluation row of a highway-env run's ``eval.csv`` holds the driving measures of
:mod:`simoun_agent.run.driving_metrics` beside the return; a run's last row gives its final
measures. A study tells a driving study by these columns, whatever its env ids. The reference
drivers (:mod:`simoun_agent.run.driving_reference`) are read from the study directory's
``references.json``, which that module's ``--json`` writes: played at report time they would
cost minutes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.driving_metrics import columns
from simoun_agent.run.kept import Damaged, present, read_json_object

MEASURES = columns(
    "return_mean", "crash_rate", "distance_m", "mean_speed", "mean_abs_steer", "brake_fraction"
)
"""The table's measures: eval.csv column (a key of the reference drivers' metrics too), header,
format."""

REFERENCES_JSON = "references.json"
"""The reference drivers' metrics in the study directory, written by ``python -m
simoun_agent.run.driving_reference --json``: ``command``, ``preset``, ``episodes``, ``seed`` (of
the first episode) and ``drivers`` (driver -> its metrics)."""

REFERENCE_COMMAND = (
    "python -m simoun_agent.run.driving_reference --episodes 20 --seed 1000 "
    f"--json DIR/{REFERENCES_JSON}"
)
"""The command that writes :data:`REFERENCES_JSON` (DIR: the study directory); its seeds are
those of docs/driving.md's committed table."""


def final_measures(rows: list[dict[str, float]]) -> dict[str, float] | None:
    """The last evaluation row's :data:`MEASURES`; None when the rows lack any of their columns
    (a run on an env without an ego vehicle) or there are no rows."""
    if not rows or any(key not in rows[-1] for key, _, _ in MEASURES):
        return None
    return {key: rows[-1][key] for key, _, _ in MEASURES}


REFERENCE_KEYS = ("command", "preset", "episodes", "seed", "drivers")


def read_references(study_dir: Path) -> dict[str, Any] | None:
    """The study directory's :data:`REFERENCES_JSON`, None when there is none; SetupError when
    it is not one that the reference command wrote (not JSON, a key or a measure missing)."""
    path = study_dir / REFERENCES_JSON
    if not present(path):
        return None
    fix = f"write it again with `{REFERENCE_COMMAND.replace('DIR', str(study_dir))}`"
    try:
        references = read_json_object(path)
    except Damaged as err:
        raise SetupError(f"{path} is damaged: {err}; {fix}") from None
    if missing := [key for key in REFERENCE_KEYS if key not in references]:
        raise SetupError(f"{path} lacks {', '.join(missing)}; {fix}")
    if not isinstance(references["drivers"], dict):
        raise SetupError(f"{path}: drivers is not a JSON object of drivers; {fix}")
    for driver, metrics in references["drivers"].items():
        if not isinstance(metrics, dict):
            raise SetupError(f"{path}: driver {driver!r} is not a JSON object of measures; {fix}")
        if lacking := [key for key, _, _ in MEASURES if key not in metrics]:
            raise SetupError(f"{path}: driver {driver!r} lacks {', '.join(lacking)}; {fix}")
    return references
