"""SimounObservation on a state-based dm_control task: pixels from render(), triplet + motion.

python examples/wrappers_dm_control.py
"""

import gymnasium as gym
import numpy as np

# simoun_wrappers first: without a display it sets MUJOCO_GL=egl before dm_control loads.
# isort: off
from simoun_wrappers import ActionRepeat, SimounObservation
import shimmy

# isort: on

gym.register_envs(shimmy)

env = gym.make(
    "dm_control/cartpole-swingup-v0",
    render_mode="rgb_array",
    render_kwargs={"width": 84, "height": 84, "camera_id": 0},
)
env = SimounObservation(ActionRepeat(env, 8), size=84)
print(env.observation_space)

obs, _ = env.reset(seed=0)
for _ in range(5):
    obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
frames, motion = obs["frames"], obs["motion"]
print(f"frames {frames.shape} {frames.dtype}, motion {motion.shape} {motion.dtype}")
print(f"motion range [{motion.min()}, {motion.max()}], moving pixels {np.mean(motion != 0):.1%}")
env.close()
