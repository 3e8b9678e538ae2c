"""Random convolution: per-sample kernels on a torch batch, per-episode kernels on an env.

python examples/wrappers_random_conv.py
"""

import gymnasium as gym
import torch

from simoun_wrappers import RandomConvolution, SimounObservation
from simoun_wrappers.augment import random_conv

# A batch of 8 uint8 triplets as the agent samples them: scale to [0, 1] first.
triplets = torch.randint(0, 256, (8, 3, 3, 84, 84), dtype=torch.uint8)
views = random_conv(triplets.float() / 255, generator=torch.Generator().manual_seed(0))
print("augmented", views.shape, views.dtype, f"range [{views.min():.2f}, {views.max():.2f}]")

# The env wrapper keeps one kernel per episode and a new one at each reset.
env = SimounObservation(RandomConvolution(gym.make("CartPole-v1", render_mode="rgb_array")), 64)
for episode in range(3):
    obs, _ = env.reset(seed=episode)
    print(f"episode {episode}: mean colour {obs['frames'][0].mean(axis=(1, 2)).round(1)}")
