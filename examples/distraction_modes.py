"""The five modes of the distraction suite side by side: what an agent sees in each.

Rows are modes (train, color_easy, color_hard, video_easy, video_hard), columns successive
agent steps of one episode with the same seed and actions; the image is written to
docs/distraction-modes.png (or --out).

python examples/distraction_modes.py [--env dm_control/ball_in_cup-catch-v0] [--steps 4]
"""

import argparse
from pathlib import Path

import cv2
import imageio.v2 as imageio
import numpy as np

from simoun_agent.config import resolve
from simoun_agent.generalization import DISTRACTIONS, make_distracted_env

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--env", default="dm_control/ball_in_cup-catch-v0")
parser.add_argument("--steps", type=int, default=4, help="agent steps shown per mode")
parser.add_argument("--out", default="docs/distraction-modes.png")
args = parser.parse_args()

config = resolve(None, {"env": args.env, "image_size": 84})
rows = []
for mode in DISTRACTIONS:
    env = make_distracted_env(config, mode)
    obs, _ = env.reset(seed=0)
    frames = [obs["frames"][-1]]
    for step in range(args.steps - 1):
        obs, *_ = env.step(np.full(env.action_space.shape, np.sin(step), np.float32))
        frames.append(obs["frames"][-1])
    env.close()
    row = np.concatenate([frame.transpose(1, 2, 0) for frame in frames], axis=1)
    label = np.full((row.shape[0], 110, 3), 255, np.uint8)
    cv2.putText(label, mode, (4, row.shape[0] // 2), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (0, 0, 0))
    rows.append(np.concatenate([label, row], axis=1))
Path(args.out).parent.mkdir(parents=True, exist_ok=True)
imageio.imwrite(args.out, np.concatenate(rows, axis=0))
print(f"wrote {args.out}")
