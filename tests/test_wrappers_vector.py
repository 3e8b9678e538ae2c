"""Per-env Simoun wrappers inside gym.make_vec, across autoresets."""

from functools import partial

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

from simoun_wrappers import SimounObservation


def _is_padded(frames: np.ndarray) -> bool:
    return bool((frames == frames[0]).all())


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_first_obs_after_autoreset_is_a_reset_padded_triplet(mode):
    envs = gym.make_vec(
        "CartPole-v1",
        num_envs=2,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": mode},
        render_mode="rgb_array",
        wrappers=[partial(SimounObservation, size=16)],
    )
    assert envs.single_observation_space["frames"].shape == (3, 3, 16, 16)
    obs, _ = envs.reset(seed=0)
    assert all(_is_padded(f) for f in obs["frames"])
    envs.action_space.seed(0)
    done = np.zeros(2, dtype=bool)
    checked = moved = 0
    for _ in range(80):
        obs, _, terminated, truncated, info = envs.step(envs.action_space.sample())
        # NEXT_STEP: the step after an episode end returns the reset obs; SAME_STEP: the same one.
        first_obs = done if mode == AutoresetMode.NEXT_STEP else terminated | truncated
        for i in np.flatnonzero(first_obs):
            assert _is_padded(obs["frames"][i]) and not obs["motion"][i].any()
            checked += 1
        moved += int(obs["motion"][~first_obs].any())
        if mode == AutoresetMode.SAME_STEP and (terminated | truncated).any():
            final = info["final_obs"][np.flatnonzero(terminated | truncated)[0]]
            assert not _is_padded(final["frames"])
        done = terminated | truncated
    assert checked >= 2 and moved > 10
    envs.close()
