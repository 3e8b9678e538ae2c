"""No recipe's policy gets pinned at the action bounds for good: each is trained briefly on
dm_control cartpole-swingup (through shimmy) at a tiny size, and after the warm-up its
evaluation actions on fixed observations keep changing from one evaluation to the next and are
not all at the bounds.

The failure this catches: a deterministic policy whose pre-tanh output Adam drives to |x| ~ 8,
where tanh' ~ 1e-6, so the actor stays at a = -1 on every state (measured on the dmc100k study's
drqv2 runs: the same evaluation return to 8 digits for 40k env steps). A plateau the policy
leaves is no failure: only actions that are all at the bounds and no longer move are.
"""

import itertools

import numpy as np
import pytest
import torch

from simoun_agent.config import RECIPES, resolve
from simoun_agent.run import train
from simoun_agent.run.callback import TrainCallback

TINY = {
    "env": "dm_control/cartpole-swingup-v0",
    "image_size": 24,
    "total_env_steps": 3200,
    "warmup_agent_steps": 50,
    "replay_capacity": 5000,
    "eval_every": 800,
    "eval_episodes": 1,
    "checkpoint_every": 10**9,
    "video": False,
    "progress": False,
    "device": "cpu",
    "torch_threads": 1,
    "seed": 1,
    "agent.batch_size": 32,
    "agent.num_filters": 8,
    "agent.feature_dim": 16,
    "agent.aux_hidden_dim": 16,
}
"""The cpu preset (action repeat 8, hidden 256, each recipe's learning rates and schedules) at
24x24 with batch 32 and 8 filters: 400 decisions, about 350 of them followed by updates."""

BOUND = 1.0 - 1e-3
"""|a| above this is at the bound"""
MOVED = 1e-4
"""the largest change of any action between two evaluations that counts as moving"""
PROBES = 32
"""observations the actions are read on: a random-action episode's first frames"""


class ActionProbe(TrainCallback):
    """The deterministic (evaluation) actions on fixed observations, at every evaluation."""

    def on_start(self, run: train.Run) -> None:
        env = run.eval_env
        rng = np.random.default_rng(0)
        obs, _ = env.reset(seed=12_345)
        frames = [obs["frames"]]
        while len(frames) < PROBES:
            obs, *_ = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
            frames.append(obs["frames"])
        self.frames = np.stack(frames)
        self.actions: list[tuple[int, np.ndarray]] = []

    def on_evaluation(self, run: train.Run, metrics: dict[str, float]) -> None:
        with torch.no_grad():
            actions = np.stack([run.agent.act(f, deterministic=True) for f in self.frames])
        self.actions.append((run.counters.env_step, actions))


@pytest.mark.parametrize("recipe", list(RECIPES))
def test_the_policy_is_not_pinned_at_the_action_bounds(recipe, tmp_path):
    config = resolve("cpu", {**TINY, "agent.recipe": recipe, "run_dir": str(tmp_path / "run")})
    probe = ActionProbe()
    train.train(train.create_run(config), [probe])
    warmup = config.warmup_agent_steps * config.resolved_action_repeat()
    trained = [(step, actions) for step, actions in probe.actions if step > warmup]
    assert len(trained) >= 3, [step for step, _ in probe.actions]
    shown = {step: np.round(actions[:4, 0], 6).tolist() for step, actions in trained}
    for (_, before), (step, after) in itertools.pairwise(trained):
        assert np.abs(after - before).max() > MOVED, f"no action moved by env step {step}: {shown}"
    _, last = trained[-1]
    assert (np.abs(last) < BOUND).any(), f"every action at the bounds at the end: {shown}"
