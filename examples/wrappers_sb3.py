"""fold_frames=True: the triplet as a (3C, H, W) uint8 image for Stable-Baselines3's CnnPolicy.

python examples/wrappers_sb3.py
"""

import gymnasium as gym
from stable_baselines3 import PPO

from simoun_wrappers import SimounObservation

env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), 64, fold_frames=True)
print(env.observation_space)  # Box(0, 255, (9, 64, 64), uint8)
model = PPO("CnnPolicy", env, n_steps=64, batch_size=32, n_epochs=1, seed=0, verbose=0)
model.learn(total_timesteps=128)
obs, _ = env.reset(seed=0)
action, _ = model.predict(obs, deterministic=True)
print("action", action)
