"""How the contrastive loss (Eq. 3, random-convolution positives) evolves on real frames.

Fills a replay with random actions on dm_control cartpole-swingup, then runs the agent's full
update and prints, every ``--every`` updates, L_con (log(batch) is chance) and the spread of the
anchors f^a(o_t) across a fixed probe batch (a spread near 0 means the appearance features no
longer tell frames apart).

    python benchmarks/contrastive_probe.py --updates 400
"""

from __future__ import annotations

import argparse
import math

import gymnasium as gym
import numpy as np
import torch

from simoun_agent import AgentConfig, FrameReplay, SimounAgent
from simoun_wrappers import SimounObservation


def random_replay(size: int, steps: int, seed: int) -> FrameReplay:
    """``steps`` transitions of uniform random actions, in 250-step episodes."""
    import shimmy  # after simoun_wrappers (imported above), which sets MUJOCO_GL=egl

    gym.register_envs(shimmy)
    env = gym.make(
        "dm_control/cartpole-swingup-v0",
        render_mode="rgb_array",
        render_kwargs={"width": size, "height": size, "camera_id": 0},
    )
    env = SimounObservation(env, size=size, motion=False)
    replay = FrameReplay(steps, (3, size, size), 1, seed=seed)
    rng = np.random.default_rng(seed)
    obs, _ = env.reset(seed=seed)
    replay.start_episode(obs["frames"][-1])
    for t in range(steps):
        action = rng.uniform(-1, 1, 1).astype(np.float32)
        obs, reward, terminated, truncated, _ = env.step(action)
        truncated = truncated or (t + 1) % 250 == 0
        replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            obs, _ = env.reset()
            replay.start_episode(obs["frames"][-1])
    env.close()
    return replay


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--updates", type=int, default=400)
    parser.add_argument("--every", type=int, default=25, help="print every N updates")
    parser.add_argument("--size", type=int, default=48, help="frame height and width")
    parser.add_argument("--batch", type=int, default=32)
    parser.add_argument("--steps", type=int, default=1500, help="random-action transitions")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    torch.set_num_threads(1)
    torch.manual_seed(args.seed)

    replay = random_replay(args.size, args.steps, args.seed)
    agent = SimounAgent((3, args.size, args.size), 1, AgentConfig(batch_size=args.batch), "cpu")
    probe = torch.from_numpy(replay.sample(64)["window"][:, :3])
    print(f"chance level log(batch) = {math.log(args.batch):.3f}")
    print(f"{'update':>6}  {'L_con':>6}  {'anchor spread':>13}")
    for update in range(args.updates):
        metrics = agent.update(replay, update)
        if update % args.every == 0 or update == args.updates - 1:
            with torch.no_grad():
                spread = agent.encoder(probe).anchor.std(0).mean()
            print(f"{update:6d}  {float(metrics['contrastive_loss']):6.3f}  {float(spread):13.4f}")


if __name__ == "__main__":
    main()
