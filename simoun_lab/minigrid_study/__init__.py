"""Does an intrinsic reward help PPO on MiniGrid from pixels? The MiniGrid study.

Stable-Baselines3 PPO (``CnnPolicy``, rl-baselines3-zoo's MiniGrid settings, the same for every
arm) on MiniGrid-DoorKey-6x6 (400k env steps, 5 seeds) and -8x8 (1M, 3 seeds), three arms: no
intrinsic reward, + consistency curiosity (``ConsistencyCuriosityVectorReward`` with
``CuriosityModel``), + random network distillation (``RNDVectorReward`` with ``RNDModel``).
Runs on Ray Tune through the lab's study engine, resumable by run; records and report in
``docs/studies/minigrid/``.

Modules, each with one job: :mod:`~simoun_lab.minigrid_study.spec` (the design as data),
:mod:`~simoun_lab.minigrid_study.envs` (pixels, symbolic state, SB3 over a Gymnasium vector
env), :mod:`~simoun_lab.minigrid_study.arms` (the arms' registry),
:mod:`~simoun_lab.minigrid_study.timing` (env vs update time),
:mod:`~simoun_lab.minigrid_study.study_log` (evaluations and per-rollout records),
:mod:`~simoun_lab.minigrid_study.training` (a run set up to train),
:mod:`~simoun_lab.minigrid_study.checkpoint` (mid-run resume),
:mod:`~simoun_lab.minigrid_study.run` (one run), :mod:`~simoun_lab.minigrid_study.trial` (a
run as the study engine's trial), :mod:`~simoun_lab.minigrid_study.runner` (the runs on the
engine, :mod:`simoun_lab.engine`), :mod:`~simoun_lab.minigrid_study.report` and
:mod:`~simoun_lab.minigrid_study.probe` (an intrinsic reward against novelty, no PPO). Run it with
``python -m simoun_lab.minigrid_study run`` (needs the ``sb3``, ``minigrid`` and ``lab``
extras).
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
