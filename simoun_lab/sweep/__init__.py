"""Sweeps: a grid of ordinary training runs on Ray Tune (``simoun-sweep``), and their report
(``simoun-report``).

Ray is an optional extra (``pip install 'simoun[lab]'``) imported only by the study engine
(:mod:`simoun_lab.engine`), :mod:`simoun_lab.sweep.trainable` (the SAC trial) and
:mod:`simoun_lab.sweep.launch`; the grid
(:mod:`simoun_lab.sweep.grid`) and the report (:mod:`simoun_lab.sweep.report`) work without
it, and ``simoun_agent`` never imports this package.

A sweep directory holds ``sweep.json`` (the grid and the base config), one run directory per
trial at ``<variant>/<env>/s<seed>`` (the same files as ``simoun-train`` writes, so each can be
inspected, evaluated or resumed alone), ``tune/`` (Ray Tune's own records) and the report
(``report.md``, ``report.csv``, ``curves_env_steps.png``, ``curves_wall_time.png``).
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
