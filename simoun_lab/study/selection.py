"""Choosing each recipe's setting from its tuning runs, by a named rule.

A rule scores one run from its evaluation curve; a setting's score is the mean over the tuning
tasks of the mean over each task's seeds (so every task weighs the same), and each recipe gets
its best setting. Returns are normalized by the task's maximum first
(:func:`simoun_lab.stats.normalize`: 1000 for dm_control), so tasks of different scales
compare. A new rule is one entry of :data:`SELECTION_RULES`.

Example:
    >>> import numpy as np
    >>> steps, returns = np.array([0.0, 10_000.0]), np.array([0.0, 500.0])
    >>> SELECTION_RULES["auc"].score("dm_control/cartpole-swingup-v0", steps, returns)
    0.25
    >>> best_setting([({"agent.n_step": 1}, 0.25), ({"agent.n_step": 3}, 0.25000000001)])
    {'agent.n_step': 1}
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from simoun_lab.stats import normalize
from simoun_lab.sweep.report import area_under_curve


@dataclass(frozen=True)
class SelectionRule:
    """How one tuning run is scored."""

    description: str
    """what the report says the rule does"""
    score: Callable[[str, np.ndarray, np.ndarray], float]
    """(env id, env steps, evaluation returns) -> the run's score"""


def normalized_auc(env_id: str, steps: np.ndarray, returns: np.ndarray) -> float:
    """The area under the normalized evaluation curve over the env-step span, divided by the
    span: the run's average normalized return over its budget (early learning counts)."""
    return area_under_curve(steps, normalize(env_id, returns))


def normalized_final(env_id: str, steps: np.ndarray, returns: np.ndarray) -> float:
    """The last evaluation's normalized return."""
    return float(normalize(env_id, returns[-1:])[0])


SELECTION_RULES: dict[str, SelectionRule] = {
    "auc": SelectionRule(
        "the highest mean normalized area under the evaluation curve (trapezoid of the "
        "evaluation return divided by the task maximum, over env steps, divided by the env-step "
        "span: the run's average normalized return over its budget), averaged over the tuning "
        "seeds of each tuning task, then over the tuning tasks",
        normalized_auc,
    ),
    "final": SelectionRule(
        "the highest mean normalized final evaluation return (divided by the task maximum), "
        "averaged over the tuning seeds of each tuning task, then over the tuning tasks",
        normalized_final,
    ),
}
"""Selection rules by name (``selection = "auc"`` in a study spec; auc is the default)."""

TIE_DECIMALS = 6
"""Settings whose scores agree to this many decimals tie: a millionth of the task maximum (a
thousandth of a return point on dm_control), far below the spread between seeds."""

TIE_RULE = (
    f"scores equal to {TIE_DECIMALS} decimals tie, and a tie goes to the setting listed first "
    "in the grid (the first key varies slowest, values in the spec's order)"
)


def best_setting(scored: list[tuple[dict, float]]) -> dict:
    """The setting with the highest score (ties by :data:`TIE_RULE`), from ``(setting, score)``
    pairs in grid order; a NaN score (a run without two evaluations) never wins."""
    rounded = [(setting, round(score, TIE_DECIMALS)) for setting, score in scored]
    valid = [(setting, score) for setting, score in rounded if not np.isnan(score)]
    if not valid:
        raise ValueError("no setting has a score: every tuning run lacks two evaluations")
    best = max(score for _, score in valid)
    return next(setting for setting, score in valid if score == best)
