"""Step the training environment in the calling process, or in a background process while the
agent updates.

The training loop gives an action with :meth:`step_async`, runs its gradient updates, then
collects the transition with :meth:`step_wait`. :class:`InlineEnv` steps inside ``step_wait``;
:class:`BackgroundEnv` hands the action to a worker process at ``step_async``, so physics and
rendering (11 % of a cpu-preset training step on dm_control cartpole at 48x48, the update 87 %:
``benchmarks/training_loop.py``) run on the second core while the update runs on the first.
Both see the same actions and seeds in the same order, so a run gives identical results with
either (``tests/test_train_env_runner.py``).

The worker is gymnasium's ``AsyncVectorEnv`` with one environment, autoreset disabled (the loop
resets each episode with its own seed) and the ``spawn`` start method (a fork would copy the
parent's torch threads and GL contexts).
"""

from __future__ import annotations

import functools
import multiprocessing
import signal
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AsyncVectorEnv, AutoresetMode

from simoun_agent.config import SetupError, TrainConfig
from simoun_agent.run.make_env import make_env

Transition = tuple[dict[str, np.ndarray], float, bool, bool]
"""(observation, reward, terminated, truncated) of one agent step"""


class InlineEnv:
    """The environment stepped in this process, inside :meth:`step_wait`."""

    def __init__(self, config: TrainConfig) -> None:
        self.env = make_env(config)
        self.action_space = self.env.action_space
        self.observation_space = self.env.observation_space
        self._action: np.ndarray | None = None

    def reset(self, seed: int) -> dict[str, np.ndarray]:
        return self.env.reset(seed=seed)[0]

    def step_async(self, action: np.ndarray) -> None:
        self._action = action

    def step_wait(self) -> Transition:
        obs, reward, terminated, truncated, _ = self.env.step(self._action)
        return obs, float(reward), bool(terminated), bool(truncated)

    def close(self) -> None:
        self.env.close()


class BackgroundEnv:
    """The environment stepped in a worker process between :meth:`step_async` and
    :meth:`step_wait`. A crash of the worker raises :class:`EnvProcessError` at the next call
    instead of hanging the loop."""

    def __init__(self, config: TrainConfig, timeout_s: float = 600.0) -> None:
        self.timeout_s = timeout_s
        self.vector = AsyncVectorEnv(
            [functools.partial(_worker_env, config)],
            context="spawn",
            autoreset_mode=AutoresetMode.DISABLED,
        )
        self.action_space = self.vector.single_action_space
        self.observation_space = self.vector.single_observation_space

    def reset(self, seed: int) -> dict[str, np.ndarray]:
        obs, _ = self._call(self.vector.reset, seed=[seed])
        return _first(obs)

    def step_async(self, action: np.ndarray) -> None:
        self._call(self.vector.step_async, np.asarray(action)[None])

    def step_wait(self) -> Transition:
        obs, reward, terminated, truncated, _ = self._call(
            self.vector.step_wait, timeout=self.timeout_s
        )
        return _first(obs), float(reward[0]), bool(terminated[0]), bool(truncated[0])

    def _call(self, method: Any, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(*args, **kwargs)
        except (EOFError, BrokenPipeError, ConnectionResetError, multiprocessing.TimeoutError) as e:
            raise EnvProcessError(
                f"the environment process failed ({type(e).__name__}: {e}); the run stops "
                "here. Its last checkpoint is intact: continue with --resume, or set "
                "--env-process false to step the environment in the training process"
            ) from e

    def close(self) -> None:
        """Ask the worker to close its env and join it; terminate it if it cannot answer."""
        try:
            self.vector.close()
        except (OSError, EOFError, multiprocessing.TimeoutError, gym.error.Error):
            self.vector.close(terminate=True)


def _worker_env(config: TrainConfig) -> Any:
    """``make_env`` in the worker, which leaves SIGINT and SIGTERM to the trainer: Ctrl-C and
    many schedulers signal the whole process group, and the trainer needs its worker alive to
    finish the step and write its checkpoint (it closes the worker itself)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    return make_env(config)


class EnvProcessError(SetupError):
    """The background environment process died, hung or raised."""


def _first(obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {key: value[0] for key, value in obs.items()}


EnvRunner = InlineEnv | BackgroundEnv


def make_runner(config: TrainConfig) -> EnvRunner:
    """:class:`BackgroundEnv` when ``config.env_process``, else :class:`InlineEnv`."""
    return BackgroundEnv(config) if config.env_process else InlineEnv(config)
