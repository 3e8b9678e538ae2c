"""Named presets: overrides of ``TrainConfig`` defaults sized for a task or a machine.

A preset is the second layer of a run's configuration (after the dataclass defaults, before
the recipe and the user's overrides: :func:`simoun_agent.config.resolve.resolve`); its keys
are checked like the user's, so a misspelled one is refused with its close match.
"""

from __future__ import annotations

from dataclasses import dataclass

from simoun_agent.config.envs import PAPER_ACTION_REPEAT, is_highway

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


PRESETS: dict[str, Preset] = {task: _dmc_preset(task) for task in PAPER_ACTION_REPEAT}
PRESETS["highway"] = Preset(
    description="highway-env driving: 3 viewports around the ego vehicle -> 84x252, continuous "
    "[acceleration, steering], 40 s episodes, 20 vehicles at density 1",
    overrides={
        "env": "highway-v0",
        "env_kwargs": {"config": HIGHWAY_CONFIG},
        "action_repeat": 1,
        "cameras": 3,
        "total_env_steps": 100_000,
        "eval_every": 5_000,
        "eval_episodes": 5,
        "agent": {"batch_size": 128},
    },
    envs="highway",
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
