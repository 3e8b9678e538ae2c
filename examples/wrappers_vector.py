"""Per-env Simoun wrappers in a vector env; after an autoreset the triplet is reset-padded.

python examples/wrappers_vector.py
"""

from functools import partial

import gymnasium as gym
import numpy as np

from simoun_wrappers import SimounObservation

envs = gym.make_vec(
    "CartPole-v1",
    num_envs=4,
    vectorization_mode="sync",
    render_mode="rgb_array",
    wrappers=[partial(SimounObservation, size=64, grayscale=True)],
)
print(envs.single_observation_space)
obs, _ = envs.reset(seed=0)
ended = np.zeros(envs.num_envs, dtype=bool)
for _ in range(60):
    obs, reward, terminated, truncated, _ = envs.step(envs.action_space.sample())
    for i in np.flatnonzero(ended):  # NEXT_STEP autoreset: this obs starts a new episode
        frames = obs["frames"][i]
        print(f"env {i} restarted; padded triplet: {bool((frames == frames[0]).all())}")
    ended = terminated | truncated
envs.close()
