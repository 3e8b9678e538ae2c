"""No recipe's policy gets pinned at the action bounds: the agent of one recipe of each policy
path (the recipes that differ only in the representation share one) is trained on the
transitions of dm_control cartpole-swingup (through shimmy, the cpu preset at 24x24), and its
evaluation actions on fixed observations keep changing from one probe to the next and are not
all at the bounds at the end.

The failure this catches: a deterministic policy whose pre-tanh output Adam drives to |x| ~ 8,
where tanh' ~ 1e-6, so the actor stays at a = -1 on every state (measured on the dmc100k study's
drqv2 runs: the same evaluation return to 8 digits for 40k env steps). It needs only a critic
whose Q slope in the action has the same sign at every state, which random-action cartpole data
gives within a few hundred updates; a plateau the policy leaves is no failure, only actions that
are all at the bounds and no longer move are.

Rendering dominates the cost of a cartpole step (tens of ms per frame on a CPU), so the
transitions are collected once, with uniform random actions as in the warm-up, and every recipe
trains on a copy of that replay: one gradient step per ``update_every_steps`` agent steps, as
the training loop takes them. The drqv2 values of the dmc100k study's runs (one shared FC +
LayerNorm, an update every agent step) are the case that must be caught.
"""

import copy
import dataclasses
import itertools

import numpy as np
import pytest
import torch

from simoun_agent import FrameReplay, SimounAgent
from simoun_agent.config import RECIPES, resolve
from simoun_agent.run.make_env import make_env

SMALL = {
    "env": "dm_control/cartpole-swingup-v0",
    "image_size": 24,
    "seed": 1,
    "agent.batch_size": 16,
    "agent.num_filters": 8,
    "agent.feature_dim": 16,
    "agent.aux_hidden_dim": 16,
}
"""The cpu preset (action repeat 8, hidden 256, each recipe's learning rates and schedules) at
24x24 with batch 16 and 8 filters."""

COLLECTED = 128
"""agent steps of uniform random actions in the replay (one 125-step episode and the start of
the next)"""
AGENT_STEPS = 240
"""agent steps trained for: 240 gradient steps at one per agent step, 120 at one per 2 (drqv2
with DRQV2_PINNED has every action at the bounds after about 200)"""
PROBE_EVERY = 60
"""agent steps between two readings of the actions"""
BOUND = 1.0 - 1e-3
"""|a| above this is at the bound"""
MOVED = 1e-4
"""the largest change of any action between two readings that counts as moving"""
PROBES = 32
"""observations the actions are read on: the first frames of a random-action episode"""

DRQV2_PINNED = {
    "agent.separate_trunks": False,
    "agent.pixel_offset": 0.0,
    "agent.independent_next_shift": False,
    "agent.update_every_steps": 1,
    "agent.target_update_every": 2,
    "agent.exploration_steps": 1_000_000,
}
"""drqv2 with the values its dmc100k study runs had: the encoder's FC + LayerNorm shared by
actor and critic (the actor reading it detached), pixels x / 255, one shift offset for obs and
next obs, a critic and actor update every agent step with the targets every 2nd, the medium
tasks' schedule on cartpole-swingup.
Its policy sat at a = -1 for good in the dmc100k study; here it must be caught."""


REPRESENTATION = {"encoder", "transition_weight", "contrastive_weight", "reward_weight"}
REPRESENTATION |= {"curiosity", "recipe"}
"""Fields that change the state the actor and the critic read, not how they learn from it."""


def policy_path(recipe: str) -> dict:
    """The recipe's resolved agent config on the test task, its representation fields left out:
    what decides how the actor and the critic are trained."""
    agent = resolve("cpu", {**SMALL, "agent.recipe": recipe}).agent
    return {k: v for k, v in dataclasses.asdict(agent).items() if k not in REPRESENTATION}


PATH_OF = {name: policy_path(name) for name in RECIPES}


def first_of_each_path() -> list[str]:
    trained = []
    for name, path in PATH_OF.items():
        if all(PATH_OF[other] != path for other in trained):
            trained.append(name)
    return trained


TRAINED = first_of_each_path()
"""One recipe of each policy path, the first in RECIPES' order (simoun for its ablations and the
Fig. 6 encoders, which differ from it in the representation alone; drqv2 for drqv2_easy, whose
schedule is drqv2's own on cartpole-swingup)."""


@pytest.fixture(scope="module")
def collected() -> tuple[FrameReplay, np.ndarray]:
    """The replay of COLLECTED random agent steps and the PROBES observations."""
    config = resolve("cpu", SMALL)
    env = make_env(config)
    rng = np.random.default_rng(0)
    replay = FrameReplay(COLLECTED + 8, env.observation_space["frames"].shape[1:], 1, seed=0)
    probes = []
    obs, _ = env.reset(seed=12_345)
    replay.start_episode(obs["frames"][-1])
    for _ in range(COLLECTED):
        if len(probes) < PROBES:
            probes.append(obs["frames"])
        action = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        obs, reward, terminated, truncated, _ = env.step(action)
        replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            obs, _ = env.reset(seed=int(rng.integers(2**31)))
            replay.start_episode(obs["frames"][-1])
    env.close()
    return replay, np.stack(probes)


def probe_actions(
    overrides: dict, collected: tuple[FrameReplay, np.ndarray]
) -> list[tuple[int, np.ndarray]]:
    """Train the agent of ``overrides`` on a copy of the collected replay for AGENT_STEPS agent
    steps; its deterministic actions on the probes every PROBE_EVERY agent steps."""
    config = resolve("cpu", {**SMALL, **overrides})
    replay, probes = copy.deepcopy(collected[0]), collected[1]
    torch.manual_seed(config.seed)
    agent = SimounAgent(probes.shape[2:], 1, config.agent, device="cpu")
    repeat = config.resolved_action_repeat()
    readings = []
    for agent_step in range(1, AGENT_STEPS + 1):
        if agent_step % config.agent.update_every_steps == 0:
            agent.update(replay, (COLLECTED + agent_step) * repeat)
        if agent_step % PROBE_EVERY == 0:
            with torch.no_grad():
                actions = np.stack([agent.act(frames, deterministic=True) for frames in probes])
            readings.append((agent_step, actions))
    return readings


def pinned(readings: list[tuple[int, np.ndarray]]) -> str | None:
    """What pins the policy, or None: no action moved between two readings, or every action is
    at the bounds at the end."""
    shown = {step: np.round(actions[:4, 0], 6).tolist() for step, actions in readings}
    for (_, before), (step, after) in itertools.pairwise(readings):
        if np.abs(after - before).max() <= MOVED:
            return f"no action moved by agent step {step}: {shown}"
    if (np.abs(readings[-1][1]) >= BOUND).all():
        return f"every action at the bounds at the end: {shown}"
    return None


def test_every_recipe_shares_its_policy_path_with_a_trained_one():
    """A recipe that gets an actor, critic or optimiser setting of its own becomes a case of
    its own: the cases are the distinct paths, and they are more than one."""
    assert TRAINED[:2] == ["simoun", "drq"] and {"drqv2", "rad", "curl", "sac"} <= set(TRAINED)
    assert "drqv2_easy" not in TRAINED and "simoun_no_aux" not in TRAINED
    trained = [PATH_OF[name] for name in TRAINED]
    for name, path in PATH_OF.items():
        assert path in trained, name
    assert len({str(path) for path in trained}) == len(trained)


@pytest.mark.parametrize("recipe", TRAINED)
def test_the_policy_is_not_pinned_at_the_action_bounds(recipe, collected):
    readings = probe_actions({"agent.recipe": recipe}, collected)
    assert len(readings) == AGENT_STEPS // PROBE_EVERY
    assert pinned(readings) is None


def test_drqv2_with_the_values_of_its_pinned_study_runs_is_caught(collected):
    readings = probe_actions({"agent.recipe": "drqv2", **DRQV2_PINNED}, collected)
    assert pinned(readings) is not None
    assert (np.abs(readings[-1][1]) >= BOUND).all()
