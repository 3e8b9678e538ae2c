"""Generalization under distraction (the paper's Fig. 8): suite, evaluation, table and chart.

``simoun-eval RUN_DIR [RUN_DIR ...] --distraction color_easy,color_hard,video_easy,video_hard``
evaluates runs on DMC-GB's four modes built procedurally (:mod:`simoun_wrappers.distractors`);
``simoun-train --eval-distraction video_hard`` adds them to every evaluation of a run.
"""

from simoun_agent.generalization.callback import DistractionEvaluation, distraction_callbacks
from simoun_agent.generalization.suite import (
    DISTRACTIONS,
    check_eval_distractions,
    check_supported,
    distractor,
    make_distracted_env,
    parse_distractions,
)
from simoun_wrappers._homes import missing_name

__all__ = [
    "DISTRACTIONS",
    "DistractionEvaluation",
    "check_eval_distractions",
    "check_supported",
    "distraction_callbacks",
    "distractor",
    "make_distracted_env",
    "parse_distractions",
]


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
