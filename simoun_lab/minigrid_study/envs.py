"""MiniGrid from pixels for Stable-Baselines3 PPO: the env chain, its symbolic state, and an SB3
``VecEnv`` over a Gymnasium vector env (so the vector intrinsic-reward wrappers sit under PPO).

The chain is what a user writes: ``RGBImgPartialObsWrapper`` (the agent's 7x7-tile view drawn at
8 px a tile, 56x56 RGB) + ``ImgObsWrapper`` -> ``SimounObservation(size=None, fold_frames=True)``
(the triplet folded to a ``(9, 56, 56)`` uint8 image, what SB3's ``CnnPolicy`` takes).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import minigrid  # noqa: F401  (registers the MiniGrid-* ids)
import numpy as np
from gymnasium.vector import AutoresetMode, SyncVectorEnv, VectorEnv
from minigrid.core.world_object import Door
from minigrid.wrappers import ImgObsWrapper, RGBImgPartialObsWrapper
from stable_baselines3.common.vec_env import VecEnv

from simoun_wrappers import SimounObservation

__all__ = ["STATE_KEY", "MiniGridState", "SB3VecEnv", "minigrid_pixels", "pixel_vector_env"]

STATE_KEY = "minigrid_state"
"""the ``info`` key of :class:`MiniGridState`"""


class MiniGridState(gym.Wrapper):
    """Adds the agent's symbolic state to ``info[STATE_KEY]``: int64 ``[x, y, direction,
    carrying (0/1), door open (0/1)]`` after every reset and step.

    A state-visitation count over these tuples is the novelty the study correlates the intrinsic
    rewards with; it is read from the env, never shown to the agent.
    """

    def _state(self) -> np.ndarray:
        env = self.env.unwrapped
        doors = [obj for obj in env.grid.grid if isinstance(obj, Door)]
        door_open = int(any(door.is_open for door in doors))
        x, y = env.agent_pos
        carrying = int(env.carrying is not None)
        return np.array([x, y, env.agent_dir, carrying, door_open], dtype=np.int64)

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        obs, info = self.env.reset(**kwargs)
        return obs, {**info, STATE_KEY: self._state()}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict[str, Any]]:
        obs, reward, terminated, truncated, info = self.env.step(action)
        return obs, reward, terminated, truncated, {**info, STATE_KEY: self._state()}


def minigrid_pixels(env_id: str, **make_kwargs: Any) -> gym.Env:
    """``env_id`` from pixels: the partial view at 56x56, as a folded Simoun triplet."""
    env = gym.make(env_id, **make_kwargs)
    env = ImgObsWrapper(RGBImgPartialObsWrapper(MiniGridState(env)))
    return SimounObservation(env, size=None, fold_frames=True)


def pixel_vector_env(env_id: str, num_envs: int) -> VectorEnv:
    """``num_envs`` copies of :func:`minigrid_pixels` in one process, autoreset in the same step
    (what SB3 expects: the ending step returns the next episode's first observation)."""
    return SyncVectorEnv(
        [lambda: minigrid_pixels(env_id) for _ in range(num_envs)],
        autoreset_mode=AutoresetMode.SAME_STEP,
    )


def unbatch(info: dict[str, Any], num_envs: int) -> list[dict[str, Any]]:
    """A Gymnasium vector ``info`` (arrays with ``_key`` masks) as one dict per sub-env."""
    infos: list[dict[str, Any]] = [{} for _ in range(num_envs)]
    for key, value in info.items():
        if key.startswith("_"):
            continue
        mask = info.get(f"_{key}", np.ones(num_envs, dtype=bool))
        nested = isinstance(value, dict)
        parts = unbatch(value, num_envs) if nested else value
        for i in np.flatnonzero(mask):
            infos[i][key] = parts[i]
    return infos


class SB3VecEnv(VecEnv):
    """A Gymnasium ``VectorEnv`` (``AutoresetMode.SAME_STEP``) as a Stable-Baselines3 ``VecEnv``.

    SB3 wants the infos of a step as one dict per sub-env, and for a sub-env whose episode ended
    the infos of that ending step, ``"terminal_observation"`` and ``"TimeLimit.truncated"``:
    Gymnasium gives them as ``info["final_obs"]`` and ``info["final_info"]``. Keys the wrappers
    add at the top level (``"reward_extrinsic"``, ``"reward_intrinsic"``) belong to the step
    itself and are kept for every sub-env.
    """

    def __init__(self, envs: VectorEnv) -> None:
        mode = envs.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
        if mode != AutoresetMode.SAME_STEP:
            raise ValueError(
                f"SB3VecEnv needs a vector env with autoreset_mode=AutoresetMode.SAME_STEP (SB3 "
                f"resets in the step that ends an episode), got {mode}; build it with "
                "SyncVectorEnv(fns, autoreset_mode=AutoresetMode.SAME_STEP)."
            )
        self.envs = envs
        super().__init__(envs.num_envs, envs.single_observation_space, envs.single_action_space)
        self._actions: np.ndarray | None = None

    def reset(self) -> np.ndarray:
        seeds = None if all(s is None for s in self._seeds) else list(self._seeds)
        obs, info = self.envs.reset(seed=seeds)
        self.reset_infos = unbatch(info, self.num_envs)
        self._reset_seeds()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = actions

    def step_wait(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[dict[str, Any]]]:
        obs, rewards, terminated, truncated, info = self.envs.step(self._actions)
        dones = np.logical_or(terminated, truncated)
        final_infos = unbatch(info.get("final_info", {}), self.num_envs)
        step_info = {k: v for k, v in info.items() if "final_" not in k}
        infos = unbatch(step_info, self.num_envs)
        for i in np.flatnonzero(dones):
            infos[i] = {
                **infos[i],
                **final_infos[i],
                "terminal_observation": info["final_obs"][i],
                "TimeLimit.truncated": bool(truncated[i] and not terminated[i]),
            }
        return obs, np.asarray(rewards, dtype=np.float32), dones, infos

    def close(self) -> None:
        self.envs.close()

    def get_attr(self, attr_name: str, indices: Any = None) -> list[Any]:
        values = self.envs.unwrapped.get_attr(attr_name)
        return [values[i] for i in self._get_indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices: Any = None) -> None:
        chosen = set(self._get_indices(indices))
        current = self.envs.unwrapped.get_attr(attr_name)
        self.envs.unwrapped.set_attr(
            attr_name, [value if i in chosen else current[i] for i in range(self.num_envs)]
        )

    def env_method(
        self, method_name: str, *method_args: Any, indices: Any = None, **method_kwargs: Any
    ) -> list[Any]:
        values = self.envs.unwrapped.call(method_name, *method_args, **method_kwargs)
        return [values[i] for i in self._get_indices(indices)]

    def env_is_wrapped(self, wrapper_class: type, indices: Any = None) -> list[bool]:
        return [False for _ in self._get_indices(indices)]

    def get_images(self) -> Sequence[np.ndarray | None]:
        return [None] * self.num_envs
