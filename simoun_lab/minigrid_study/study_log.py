"""What a study run records while it trains: evaluations on fixed held-out env seeds, and per
PPO rollout the training episodes and what the intrinsic reward looks like."""

from __future__ import annotations

import time
from collections import Counter
from typing import Any

import numpy as np
import torch
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback

from simoun_lab.minigrid_study.envs import STATE_KEY, SB3VecEnv
from simoun_lab.minigrid_study.spec import Run, StudySpec
from simoun_lab.minigrid_study.timing import RolloutClock

__all__ = ["StudyLog", "evaluate"]


def evaluate(ppo: PPO, envs: SB3VecEnv, first_seed: int) -> dict[str, float]:
    """One episode per sub-env of ``envs`` (seeds ``first_seed``, ``first_seed + 1``, ...),
    actions sampled from the policy under a fixed torch seed; success rate and mean return."""
    envs.seed(first_seed)
    obs = envs.reset()
    returns = np.zeros(envs.num_envs)
    running = np.ones(envs.num_envs, dtype=bool)
    success = np.zeros(envs.num_envs, dtype=bool)
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(first_seed)
        while running.any():
            actions, _ = ppo.predict(obs, deterministic=False)
            obs, rewards, dones, infos = envs.step(actions)
            returns += np.where(running, rewards, 0.0)
            for i in np.flatnonzero(dones & running):
                # DoorKey pays only for reaching the goal, so a positive return is a success
                success[i] = rewards[i] > 0 and not infos[i]["TimeLimit.truncated"]
            running &= ~dones
    return {"success_rate": float(success.mean()), "return_mean": float(returns.mean())}


class StudyLog(BaseCallback):
    """Evaluations at even intervals, and per rollout the training episodes and what the
    intrinsic reward looks like: its mean and std, its Pearson correlation with the novelty
    ``1 / sqrt(N(s))`` of the state reached (N: visits so far of the symbolic state: position,
    direction, carrying, door open), and its mean on still triplets (three equal frames: a
    no-op, a move into a wall) against the others."""

    def __init__(
        self, spec: StudySpec, run: Run, eval_envs: SB3VecEnv, clock: RolloutClock
    ) -> None:
        super().__init__()
        self.spec, self.run, self.eval_envs, self.clock = spec, run, eval_envs, clock
        self.interval = run.task.steps // spec.evaluations
        self.next_eval = 0
        self.start = time.perf_counter()
        self.eval_s = 0.0
        """seconds spent evaluating, left out of the training wall time"""
        self._rollout_eval_s = 0.0
        self._resumed_wall_s: float | None = None
        """training seconds of the earlier parts of a resumed run (None: a fresh start)"""
        self.parts: list[dict[str, Any]] = []
        """when each part of the run started and from which env step (more than one: resumed)"""
        self.visits: Counter[tuple[int, ...]] = Counter()
        self.eval_rows: list[dict[str, float]] = []
        self.rollout_rows: list[dict[str, float]] = []
        self._reset_rollout()
        n = spec.ppo.n_envs
        self._returns, self._intrinsic_returns = np.zeros(n), np.zeros(n)

    def _reset_rollout(self) -> None:
        self._intrinsic: list[float] = []
        self._novelty: list[float] = []
        self._still: list[bool] = []
        self._episodes: list[tuple[float, float, bool]] = []

    def training_wall_s(self) -> float:
        """Seconds since training started, evaluations left out (earlier parts of a resumed run
        included)."""
        return time.perf_counter() - self.start - self.eval_s

    def state(self) -> dict[str, Any]:
        """The records so far, for a checkpoint taken between rollouts."""
        return {
            "eval_rows": self.eval_rows,
            "rollout_rows": self.rollout_rows,
            "clock_rows": self.clock.rows,
            "visits": list(self.visits.items()),
            "next_eval": self.next_eval,
            "eval_s": self.eval_s,
            "training_wall_s": self.training_wall_s(),
            "parts": self.parts,
        }

    def load(self, state: dict[str, Any]) -> None:
        """Go on from :meth:`state`: training time counts on from the saved seconds, and
        training starts without the evaluation at step 0."""
        self.eval_rows, self.rollout_rows = state["eval_rows"], state["rollout_rows"]
        self.clock.rows = state["clock_rows"]
        self.visits = Counter({tuple(key): count for key, count in state["visits"]})
        self.next_eval, self.eval_s = state["next_eval"], state["eval_s"]
        self._resumed_wall_s = state["training_wall_s"]
        self.parts = state["parts"]

    def evaluate_now(self) -> None:
        """Evaluate the policy now and add a row to ``eval_rows``."""
        start, wall = time.perf_counter(), self.training_wall_s()
        scores = evaluate(self.model, self.eval_envs, self.spec.eval_seed)
        self.eval_rows.append({"env_step": self.num_timesteps, "wall_s": wall, **scores})
        spent = time.perf_counter() - start
        self.eval_s += spent
        self._rollout_eval_s += spent

    def _on_training_start(self) -> None:
        if self._resumed_wall_s is not None:
            self.start = time.perf_counter() - self._resumed_wall_s - self.eval_s
            return
        self.start = time.perf_counter()
        self.evaluate_now()
        self.next_eval = self.interval

    def _on_step(self) -> bool:
        infos, dones = self.locals["infos"], self.locals["dones"]
        rewards, new_obs = self.locals["rewards"], self.locals["new_obs"]
        for i, info in enumerate(infos):
            extrinsic = float(info.get("reward_extrinsic", rewards[i]))
            intrinsic = float(info.get("reward_intrinsic", 0.0))
            state = tuple(int(v) for v in info[STATE_KEY])
            self.visits[state] += 1
            frames = info.get("terminal_observation", new_obs[i])
            frames = frames.reshape(3, -1)
            self._intrinsic.append(intrinsic)
            self._novelty.append(1.0 / np.sqrt(self.visits[state]))
            self._still.append(bool(np.all(frames == frames[:1])))
            self._returns[i] += extrinsic
            self._intrinsic_returns[i] += intrinsic
            if dones[i]:
                won = extrinsic > 0 and not info["TimeLimit.truncated"]
                self._episodes.append((self._returns[i], self._intrinsic_returns[i], won))
                self._returns[i] = self._intrinsic_returns[i] = 0.0
        if self.num_timesteps >= self.next_eval:
            self.evaluate_now()
            self.next_eval += self.interval
        return True

    def _on_rollout_end(self) -> None:
        intrinsic, novelty = np.array(self._intrinsic), np.array(self._novelty)
        still = np.array(self._still)
        episodes = np.array(self._episodes, dtype=np.float64).reshape(-1, 3)
        varies = intrinsic.std() > 0 and novelty.std() > 0
        row = {
            "env_step": self.num_timesteps,
            "wall_s": self.training_wall_s(),
            "eval_s": self._rollout_eval_s,
            "episodes": len(episodes),
            "success_rate": episodes[:, 2].mean() if len(episodes) else np.nan,
            "return_extrinsic": episodes[:, 0].mean() if len(episodes) else np.nan,
            "return_intrinsic": episodes[:, 1].mean() if len(episodes) else np.nan,
            "intrinsic_mean": intrinsic.mean(),
            "intrinsic_std": intrinsic.std(),
            "novelty_corr": np.corrcoef(intrinsic, novelty)[0, 1] if varies else np.nan,
            "still_fraction": still.mean(),
            "intrinsic_still_mean": intrinsic[still].mean() if still.any() else np.nan,
            "intrinsic_moving_mean": intrinsic[~still].mean() if (~still).any() else np.nan,
            "states_visited": len(self.visits),
        }
        self.rollout_rows.append(row)
        self._rollout_eval_s = 0.0
        self._reset_rollout()
