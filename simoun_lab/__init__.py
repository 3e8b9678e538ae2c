"""The lab: experiments built on the product (:mod:`simoun_agent`, :mod:`simoun_wrappers`).

Sweeps of training runs on Ray Tune (:mod:`simoun_lab.sweep`) and their reports, studies that
compare recipes under one protocol (:mod:`simoun_lab.study`), the MiniGrid PPO study
(:mod:`simoun_lab.minigrid_study`), the paper's analyses of trained runs
(:mod:`simoun_lab.analysis`) and the statistics of their reports (:mod:`simoun_lab.stats`);
the commands are :mod:`simoun_lab.cli`. The lab imports the product; the product never imports
the lab.
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
