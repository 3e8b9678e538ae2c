"""Where a PPO run's time goes: env stepping (the wrapped vector env, intrinsic reward included)
against the rest (the policy's forward passes while collecting, and PPO's update)."""

from __future__ import annotations

import time

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.vec_env import VecEnvWrapper

__all__ = ["RolloutClock", "TimedVecEnv"]


class TimedVecEnv(VecEnvWrapper):
    """Adds up the wall time spent in ``step_wait`` of the env below (``step_s``)."""

    def __init__(self, venv) -> None:
        super().__init__(venv)
        self.step_s = 0.0

    def reset(self) -> np.ndarray:
        return self.venv.reset()

    def step_wait(self):
        start = time.perf_counter()
        result = self.venv.step_wait()
        self.step_s += time.perf_counter() - start
        return result


class RolloutClock(BaseCallback):
    """Per rollout: wall seconds collecting it, of which in ``env.step``, and seconds of the PPO
    update that follows, in ``rows`` (the last update is timed when training ends)."""

    def __init__(self, timed: TimedVecEnv) -> None:
        super().__init__()
        self.timed = timed
        self.rows: list[dict[str, float]] = []
        self._marks: dict[str, float] = {}

    def _on_rollout_start(self) -> None:
        now = time.perf_counter()
        if "end" in self._marks:
            self.rows[-1]["update_s"] = now - self._marks["end"]
        self._marks = {"start": now, "env": self.timed.step_s}

    def _on_step(self) -> bool:
        return True

    def _on_rollout_end(self) -> None:
        now = time.perf_counter()
        self.rows.append(
            {
                "env_step": float(self.num_timesteps),
                "collect_s": now - self._marks["start"],
                "env_s": self.timed.step_s - self._marks["env"],
            }
        )
        self._marks["end"] = now

    def _on_training_end(self) -> None:
        if "end" in self._marks and "update_s" not in self.rows[-1]:
            self.rows[-1]["update_s"] = time.perf_counter() - self._marks["end"]
