"""Stable-Baselines3 on Simoun's frames: fold_frames=True with CnnPolicy, the supported path.

SB3 treats only a 3-D uint8 Box as an image. SimounObservation's default Dict holds a 4-D
(3, C, H, W) frame stack that MultiInputPolicy would flatten into an MLP on raw pixels, and
CnnPolicy refuses the Dict; fold_frames=True makes the triplet one (3C, H, W) image for SB3's
NatureCNN (frames of at least 36x36). check_sb3_policy says the same before SB3 builds anything.

python examples/wrappers_sb3.py
"""

import gymnasium as gym
from stable_baselines3 import PPO

from simoun_wrappers import SimounObservation, check_sb3_policy

env = SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), 64, fold_frames=True)
print(env.observation_space)  # Box(0, 255, (9, 64, 64), uint8)
policy = check_sb3_policy(env, "CnnPolicy")  # raises, with the fix, for a policy that won't fit
model = PPO(policy, env, n_steps=64, batch_size=32, n_epochs=1, seed=0, verbose=0)
model.learn(total_timesteps=128)
obs, _ = env.reset(seed=0)
action, _ = model.predict(obs, deterministic=True)
print("action", action)
