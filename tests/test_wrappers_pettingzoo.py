"""SimounParallelObservation on PettingZoo butterfly envs and on agents that join mid-episode."""

import warnings
from typing import ClassVar

import gymnasium as gym
import numpy as np
import pettingzoo
import pytest
from pettingzoo import ParallelEnv

from simoun_wrappers import SimounObservation
from simoun_wrappers.motion import residual_motion
from simoun_wrappers.pettingzoo import SimounParallelObservation

with warnings.catch_warnings():
    # pettingzoo.test imports the classic envs by their deprecated path. pyproject's filter for
    # it loses to dm_control, which (imported by shimmy in other test modules) puts an "always"
    # DeprecationWarning filter in front of the list at import time.
    warnings.simplefilter("ignore", DeprecationWarning)
    from pettingzoo.test import parallel_api_test


class JoiningAgents(ParallelEnv):
    """Agent ``a0`` from the start, ``a1`` joins at step 2; ``a0`` leaves at step 4; 6 steps.

    Each agent sees an 8x8 RGB image whose brightness encodes the step and the agent.
    """

    metadata: ClassVar[dict] = {"name": "joining_agents_v0", "render_modes": []}

    def __init__(self, observation_space: gym.Space | None = None):
        self.possible_agents = ["a0", "a1"]
        self.agents = []
        self.t = 0
        space = observation_space or gym.spaces.Box(0, 255, (8, 8, 3), np.uint8)
        self._observation_spaces = dict.fromkeys(self.possible_agents, space)
        self._action_spaces = {a: gym.spaces.Discrete(2) for a in self.possible_agents}

    def observation_space(self, agent):
        return self._observation_spaces[agent]

    def action_space(self, agent):
        return self._action_spaces[agent]

    def _obs(self):
        return {a: np.full((8, 8, 3), 20 * self.t + 7 * int(a[1]), np.uint8) for a in self.agents}

    def reset(self, seed=None, options=None):
        self.t, self.agents = 0, ["a0"]
        return self._obs(), {a: {} for a in self.agents}

    def step(self, actions):
        self.t += 1
        if self.t == 2:
            self.agents = ["a0", "a1"]
        obs = self._obs()
        terminated = {a: a == "a0" and self.t == 4 for a in self.agents}
        truncated = {a: self.t == 6 for a in self.agents}
        rewards = dict.fromkeys(self.agents, 0.0)
        infos = {a: {} for a in self.agents}
        self.agents = [a for a in self.agents if not (terminated[a] or truncated[a])]
        return obs, rewards, terminated, truncated, infos


def test_parallel_api_test_pistonball():
    env = SimounParallelObservation(
        pettingzoo.make("parallel", "butterfly/pistonball-v6", n_pistons=3, max_cycles=30), 24
    )
    parallel_api_test(env, num_cycles=30)
    obs, _ = env.reset(seed=0)
    for agent, o in obs.items():
        assert env.observation_space(agent).contains(o)
        assert o["frames"].shape == (3, 3, 24, 24)


def test_parallel_api_test_cooperative_pong_grayscale_folded():
    env = SimounParallelObservation(
        pettingzoo.make(
            "parallel", "butterfly/cooperative_pong-v6", max_cycles=30, render_mode="rgb_array"
        ),
        size=(20, 24),
        grayscale=True,
        fold_frames=True,
    )
    parallel_api_test(env, num_cycles=30)
    assert env.observation_space("paddle_0") == gym.spaces.Box(0, 255, (3, 20, 24), np.uint8)


def test_render_source_gives_every_agent_the_global_frame():
    pistons = pettingzoo.make(
        "parallel", "butterfly/pistonball-v6", n_pistons=3, max_cycles=10, render_mode="rgb_array"
    )
    env = SimounParallelObservation(pistons, size=(20, 28), source="render")
    space = env.observation_space("piston_0")  # answered before reset: no render needed
    assert space["frames"].shape == (3, 3, 20, 28)
    parallel_api_test(env, num_cycles=10)
    obs, _ = env.reset(seed=0)
    obs, *_ = env.step({agent: env.action_space(agent).sample() for agent in env.agents})
    first, second = obs["piston_0"]["frames"], obs["piston_1"]["frames"]
    np.testing.assert_array_equal(first, second)
    assert not np.shares_memory(first, second) and first.std() > 5


def test_agents_joining_mid_episode_get_reset_padded_triplets():
    env = SimounParallelObservation(JoiningAgents(), size=None)
    parallel_api_test(env, num_cycles=10)
    obs, _ = env.reset()
    obs, *_ = env.step({"a0": 0})
    obs, *_ = env.step({"a0": 0})
    joined = obs["a1"]["frames"]
    assert (joined == joined[0]).all() and joined[0, 0, 0, 0] == 20 * 2 + 7
    assert not obs["a1"]["motion"].any()
    np.testing.assert_array_equal(obs["a0"]["frames"][:, 0, 0, 0], [0, 20, 40])
    np.testing.assert_array_equal(obs["a0"]["motion"], residual_motion(obs["a0"]["frames"]))
    obs, *_ = env.step({"a0": 0, "a1": 1})
    np.testing.assert_array_equal(obs["a1"]["frames"][:, 0, 0, 0], [47, 47, 67])


def test_errors_name_the_fix():
    with pytest.raises(ValueError, match=r"at least 2 frames.*motion=False"):
        SimounParallelObservation(JoiningAgents(), num_frames=1)
    with pytest.raises(ValueError, match=r"source must be one of"):
        SimounParallelObservation(JoiningAgents(), source="camera")
    with pytest.raises(ValueError, match=r"neither image observations.*render_mode='rgb_array'"):
        SimounParallelObservation(JoiningAgents(gym.spaces.Box(-1.0, 1.0, (4,), np.float32)))
    huge = SimounParallelObservation(JoiningAgents(), size=None, num_frames=10**9)
    with pytest.raises(ValueError, match=r"num_frames=1000000000 makes stacks of .* GiB"):
        huge.reset()


class Replay(gym.Env):
    """Replays one agent's recorded images, so SimounObservation sees exactly what it saw."""

    def __init__(self, images: list[np.ndarray]):
        self.images = images
        self.observation_space = gym.spaces.Box(0, 255, images[0].shape, np.uint8)
        self.action_space = gym.spaces.Discrete(1)

    def reset(self, *, seed=None, options=None):
        self.t = 0
        return self.images[0], {}

    def step(self, action):
        self.t += 1
        return self.images[self.t], 0.0, False, False, {}


@pytest.mark.parametrize("options", [{"grayscale": True, "fold_frames": True}, {}])
def test_per_agent_frames_equal_simoun_observation(options):
    def pong():
        return pettingzoo.make(
            "parallel", "butterfly/cooperative_pong-v6", max_cycles=30, render_mode="rgb_array"
        )

    raw, ours = pong(), SimounParallelObservation(pong(), size=(20, 24), **options)
    images, stacks = [raw.reset(seed=3)[0]["paddle_1"]], [ours.reset(seed=3)[0]["paddle_1"]]
    for _ in range(6):
        actions = {agent: 1 for agent in raw.agents}
        images.append(raw.step(actions)[0]["paddle_1"])
        stacks.append(ours.step(actions)[0]["paddle_1"])
    single = SimounObservation(Replay(images), size=(20, 24), **options)
    expected = [single.reset()[0]] + [single.step(0)[0] for _ in range(6)]
    assert single.observation_space == ours.observation_space("paddle_1")
    for got, want in zip(stacks, expected, strict=True):
        for key in want if isinstance(want, dict) else [None]:
            np.testing.assert_array_equal(
                got if key is None else got[key], want if key is None else want[key]
            )


@pytest.mark.parametrize(
    "make",
    [
        lambda: gym.make("CartPole-v1", render_mode="rgb_array"),
        lambda: gym.make_vec("CartPole-v1", 2, vectorization_mode="sync"),
        lambda: None,
    ],
)
def test_anything_but_a_parallel_env_is_refused_naming_what_to_use(make):
    with pytest.raises(TypeError, match=r"wraps a PettingZoo ParallelEnv, got .*SimounObservation"):
        SimounParallelObservation(make())


def test_wrapping_twice_is_refused():
    pistons = pettingzoo.make("parallel", "butterfly/pistonball-v6", n_pistons=3)
    with pytest.raises(
        TypeError, match=r"stacks frames itself.*Apply SimounParallelObservation once"
    ):
        SimounParallelObservation(SimounParallelObservation(pistons, size=16))


def test_agent_names_actions_and_seeds_are_checked_naming_the_agents():
    env = SimounParallelObservation(JoiningAgents(), size=8)
    for call in (env.observation_space, env.action_space):
        with pytest.raises(ValueError, match=r"'nope'\): no such agent.*\['a0', 'a1'\]"):
            call("nope")
    with pytest.raises(ValueError, match=r"reset\(seed=...\) takes None or an int"):
        env.reset(seed=True)
    env.reset(seed=np.int64(0))
    with pytest.raises(TypeError, match="takes a dict of one action per agent"):
        env.step([0])
    with pytest.raises(ValueError, match=r"actions for \['a9'\], which are no agents"):
        env.step({"a0": 0, "a9": 0})
    with pytest.raises(ValueError, match=r"\['a0'\]\.step got the action 2.*Discrete\(2\)"):
        env.step({"a0": 2})
    env.step({"a0": 0})
    # a1 joins at step 2: it acts from the step after the one that showed it
    env.step({"a0": 0})
    with pytest.raises(ValueError, match=r"got no action for \['a1'\]"):
        env.step({"a0": 0})
    env.step({"a0": 0, "a1": 1})


def test_a_render_sized_space_before_reset_names_reset():
    pistons = pettingzoo.make(
        "parallel", "butterfly/pistonball-v6", n_pistons=3, render_mode="rgb_array"
    )
    env = SimounParallelObservation(pistons, size=None, source="render")
    with pytest.raises(gym.error.ResetNeeded, match=r"call env.reset\(seed=...\) before"):
        env.observation_space("piston_0")
    env.reset(seed=0)
    assert env.observation_space("piston_0")["frames"].shape[0] == 3


def test_a_step_after_the_episode_ended_says_to_reset():
    env = SimounParallelObservation(
        pettingzoo.make(
            "parallel",
            "butterfly/pistonball-v6",
            n_pistons=3,
            max_cycles=2,
            render_mode="rgb_array",
        ),
        size=16,
    )
    env.reset(seed=0)
    while env.agents:
        env.step({agent: env.action_space(agent).sample() for agent in env.agents})
    with pytest.raises(gym.error.ResetNeeded, match=r"after the episode ended.*env\.reset\(\)"):
        env.step({})
    env.reset(seed=1)
    assert env.agents


def test_auto_renders_when_the_agents_see_float_vectors_not_images():
    from pettingzoo.butterfly import knights_archers_zombies_v11

    kaz = knights_archers_zombies_v11.parallel_env(render_mode="rgb_array", max_cycles=5)
    env = SimounParallelObservation(kaz, size=16)
    obs, _ = env.reset(seed=0)
    while env.agents:
        env.step({a: env.action_space(a).sample() for a in env.agents})
    agent = env.possible_agents[0]
    assert obs[agent]["frames"].shape == (3, 3, 16, 16)
    assert env.observation_space(agent)["frames"].shape == (3, 3, 16, 16)
    with pytest.raises(TypeError, match="uint8 image, got Box"):
        SimounParallelObservation(
            knights_archers_zombies_v11.parallel_env(render_mode="rgb_array"),
            source="observation",
        )


@pytest.mark.parametrize("call", ["step", "reset"])
def test_a_reset_or_step_after_close_is_refused(call):
    pz = pettingzoo.make(
        "parallel", "butterfly/pistonball-v6", n_pistons=3, render_mode="rgb_array"
    )
    env = SimounParallelObservation(pz, size=16)
    env.reset(seed=0)
    actions = {a: env.action_space(a).sample() for a in env.agents}
    env.close()
    with pytest.raises(ValueError, match=rf"SimounParallelObservation\.{call}\(\) after close"):
        env.step(actions) if call == "step" else env.reset(seed=0)


def test_observation_spaces_hold_the_wrapped_spaces_of_observation_space():
    pistons = pettingzoo.make("parallel", "butterfly/pistonball-v6", n_pistons=3)
    env = SimounParallelObservation(pistons, size=16)
    assert set(env.observation_spaces) == set(pistons.possible_agents)
    for agent, space in env.observation_spaces.items():
        assert space is env.observation_space(agent)  # not pistonball's (457, 120, 3) images
    obs, _ = env.reset(seed=0)
    assert all(env.observation_spaces[agent].contains(obs[agent]) for agent in obs)
