"""MultiCamera: two dm_control cameras and three highway-env viewports, saved as PNGs.

python examples/wrappers_multicamera.py [output_dir]
"""

import sys
from pathlib import Path

import gymnasium as gym
import highway_env
import imageio.v3 as iio

# simoun_wrappers first: without a display it sets MUJOCO_GL=egl before dm_control loads.
# isort: off
from simoun_wrappers import MultiCamera, SimounObservation
import shimmy

# isort: on

gym.register_envs(shimmy)
gym.register_envs(highway_env)
out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)

walker = MultiCamera(gym.make("dm_control/walker-walk-v0"), ["side", "back"], size=(84, 84))
obs, _ = walker.reset(seed=0)
iio.imwrite(out / "walker_side_back.png", obs)
print("walker", obs.shape)  # (84, 168, 3)

viewports = [
    {"scaling": 2.5},  # wide view of the traffic
    {"scaling": 7.0},  # close-up of the ego vehicle
    {"centering_position": [0.2, 0.5], "scaling": 4.0},  # looking ahead
]
highway = MultiCamera(gym.make("highway-fast-v0"), viewports, size=(84, 84))
env = SimounObservation(highway, size=None)  # keep the 84 x 252 wide frames
obs, _ = env.reset(seed=0)
for _ in range(3):
    obs, *_ = env.step(env.action_space.sample())
iio.imwrite(out / "highway_three_views.png", obs["frames"][-1].transpose(1, 2, 0))
print("highway triplet", obs["frames"].shape)  # (3, 3, 84, 252)
