"""Named presets: overrides of ``TrainConfig`` defaults sized for a task or a machine.

A preset is the second layer of a run's configuration (after the dataclass defaults, before
the recipe and the user's overrides: :func:`simoun_agent.config.resolve.resolve`); its keys
are checked like the user's, so a misspelled one is refused with its close match.
"""

from __future__ import annotations

from dataclasses import dataclass

import gymnasium as gym
from gymnasium.envs.registration import load_env_creator

from simoun_agent.config.envs import PAPER_ACTION_REPEAT, is_highway, registered_spec

HIGHWAY_CONFIG = {
    "action": {"type": "ContinuousAction"},
    "lanes_count": 4,
    "vehicles_count": 20,
    "vehicles_density": 1.0,
    "duration": 40,
    "policy_frequency": 5,
    "simulation_frequency": 15,
}
"""highway-env settings of the ``highway`` preset: continuous [acceleration, steering] control at
5 decisions per simulated second, episodes of 40 s (200 decisions), 4 lanes and 20 other vehicles
at highway-env's default density 1.0 (the paper's CARLA setup drives among 20 moving cars)."""


HIGHWAY_FAST_CONFIG = {
    "action": {"type": "ContinuousAction"},
    "policy_frequency": 5,
    "simulation_frequency": 5,
    "duration": 30,
    "offroad_terminal": True,
}
"""highway-env settings of the ``highway-cpu`` preset on ``highway-fast-v0`` (3 lanes, 20 other
vehicles, collisions checked for the ego vehicle only): continuous [acceleration, steering]
control, 5 decisions per simulated second with one simulator step per decision (5/5 Hz: 2.4x
the steps per second of 5/15 Hz, and the lowest rate highway-env's maintainer calls stable), 30 s
episodes (150 decisions) that end when the ego vehicle leaves the road, instead of idling there
at reward 0 until the time limit (highway-env's default)."""


@dataclass(frozen=True)
class Preset:
    """A named set of overrides and the environments it was tuned for."""

    description: str
    """one line for help texts"""
    overrides: dict
    """TrainConfig values, nested as the config is (``{"agent": {"batch_size": 64}}``)"""
    envs: str = "any"
    """"any", "highway" (any highway-env id) or one exact env id"""

    def accepts(self, env_id: str) -> bool:
        if self.envs == "any":
            return True
        if self.envs == "highway":
            return is_highway(env_id)
        return env_id == self.envs


def fit_highway_config(config: dict, env_id: str) -> dict:
    """A highway preset's highway-env ``config`` for the highway-env task ``env_id``: the keys
    the task's ``default_config()`` has (``lanes_count`` is highway-v0's, not
    intersection-v0's: highway-env would ignore it there, and simoun refuses a key a task lacks);
    ``config`` itself when the task's settings cannot be read."""
    spec = registered_spec(env_id, "highway_env")
    try:
        creator = load_env_creator(spec.entry_point) if spec is not None else None
        defaults = creator.default_config()
    except (AttributeError, ImportError, TypeError, gym.error.Error):
        return config
    return {key: value for key, value in config.items() if key in defaults}


def _dmc_preset(task: str) -> Preset:
    lr = 2e-4 if task == "cheetah-run" else 1e-3
    return Preset(
        description=f"paper setup for DMC {task}: action repeat {PAPER_ACTION_REPEAT[task]}, "
        f"batch 512, lr {lr:g}, replay 100k, 500k env steps",
        overrides={
            "env": f"dm_control/{task}-v0",
            "action_repeat": PAPER_ACTION_REPEAT[task],
            "agent": {"batch_size": 512, "lr": lr},
        },
        envs=f"dm_control/{task}-v0",
    )


def _highway_preset(
    description: str, env: str, config: dict, cameras: int, overrides: dict
) -> Preset:
    """A preset for the highway-env ``env`` with its ``config``, ``cameras`` views and the other
    ``overrides``; action repeat 1, as highway-env's own ``policy_frequency`` sets how often the
    agent decides."""
    return Preset(
        description=description,
        overrides={
            "env": env,
            "env_kwargs": {"config": config},
            "action_repeat": 1,
            "cameras": cameras,
            **overrides,
        },
        envs="highway",
    )


PRESETS: dict[str, Preset] = {task: _dmc_preset(task) for task in PAPER_ACTION_REPEAT}
PRESETS["highway"] = _highway_preset(
    "highway-env driving: 3 viewports around the ego vehicle -> 84x252, continuous "
    "[acceleration, steering], 40 s episodes, 20 vehicles at density 1",
    "highway-v0",
    HIGHWAY_CONFIG,
    cameras=3,
    overrides={
        "total_env_steps": 100_000,
        "eval_every": 5_000,
        "eval_episodes": 5,
        "agent": {"batch_size": 128},
    },
)
CPU_PRESET_TIME = "52-81 min wall beside a second run on 2 loaded cores (measured: dmc100k v1)"
"""Time of one cpu-preset run: the dmc100k study's 5 evaluation seeds on cartpole-swingup
(docs/main-job), 3,101-4,858 s wall at a load average of 5-8 (1,916-1,997 s of process CPU
time where a run went in one part): the one figure the help text and the README quote; update
both together."""

PRESETS["cpu"] = Preset(
    description=f"sized for 2 CPU cores (the main job, {CPU_PRESET_TIME}): "
    "dm_control/cartpole-swingup-v0 "
    "(action repeat 8) for 100k env steps, 48x48 frames, 16 filters, batch 64, random shift, "
    "3-step returns, one torch thread",
    overrides={
        "total_env_steps": 100_000,
        "warmup_agent_steps": 250,
        "replay_capacity": 32_000,
        "eval_every": 10_000,
        "eval_episodes": 5,
        "checkpoint_every": 20_000,
        "image_size": 48,
        "torch_threads": 1,
        # shift + 3-step returns: the best Simoun setting of docs/study.md at 30k env steps
        # (249 +- 48 over 3 seeds, against 171 +- 43 without either)
        "agent": {
            "batch_size": 64,
            "num_filters": 16,
            "hidden_dim": 256,
            "augmentation": "shift",
            "n_step": 3,
        },
    },
)

PRESETS["highway-cpu"] = _highway_preset(
    "highway-env driving sized for 2 CPU cores: highway-fast-v0, one 64x64 grayscale "
    "view ahead of the ego vehicle (--cameras 3: the paper's three views, 64x192), continuous "
    "[acceleration, steering] at 5 decisions/s, 150-decision episodes ending off-road, batch 32, "
    "8 filters, hidden 256, random shift, 3-step returns, one torch thread",
    "highway-fast-v0",
    HIGHWAY_FAST_CONFIG,
    cameras=1,
    overrides={
        "image_size": 64,
        "grayscale": True,
        "total_env_steps": 50_000,
        "warmup_agent_steps": 1_000,
        "replay_capacity": 50_000,
        "eval_every": 5_000,
        "eval_episodes": 10,
        "checkpoint_every": 10_000,
        "torch_threads": 1,
        "agent": {
            "batch_size": 32,
            "num_filters": 8,
            "hidden_dim": 256,
            "augmentation": "shift",
            "n_step": 3,
        },
    },
)
"""Why these sizes. Measured on the project's 2-core machine while it was loaded by other work
(load average 4-15): timings in process CPU seconds, one torch thread, each comparison within one
run; the quiet machine is faster, the ratios are what carry over.

Frame size. Every view shows the same 56 m of road (the scaling grows with the image), so size
buys resolution only: at 48 px a car is 4.3 x 1.7 px, at 64 px 5.7 x 2.3 px, at 84 px 7.5 x 3
px. The environment does not care: 48, 64 and 84 px stepped at 12, 13 and 12 steps/s in one
run (wall clock; the simulation, not the render, is the cost). The agent does: one Simoun
update at batch 32 took 202 ms at 48 px with 16 filters, 445 ms at 64 px with 16 filters, 207
ms at 64 px with 8 filters and 222 ms at 64 px with 16 filters and batch 16 (at batch 64, 84 px
cost 1.45x and the three-view 64x192 frame 3.0x what 64 px did). 64 px with 8 filters costs
what 48 px with 16 does, with cars a third larger; batch 32 keeps 31 negatives for L_con.
Gray: the road, its markings and the cars differ in brightness, and one channel cuts the first
conv and the replay by 3.

Speed. ``python benchmarks/driving.py --decisions 100 --warmup 100 --repeats 1`` (the env alone
against the agent training on it, in one run) measured at load average 11.7: env alone 40.8 and
agent training 4.1 env steps per CPU second, a ratio of 0.100 (wall clock 5.1 and 0.6: the
machine gave the run a fraction of a core). Its yardstick, the cpu preset's update, took 442 ms
of CPU there against 107 ms on the quiet machine; scaled by it, the agent trains at about 17 env
steps/s on 2 quiet cores, where 16 filters (about 11) would have missed the 10 a second that a
50k-decision run in under 1.5 h needs. The paper's three views (``--cameras 3``) triple the
update."""
