"""Flags of other libraries (Stable-Baselines3 and rl-zoo, CleanRL, the DrQ-v2, CURL and RAD
configs, Hydra) that a user of the commands types by habit, with what each is called here.

Matching an unknown flag by spelling alone would offer a flag of another meaning
(``--buffer-size``: ``--image-size``; ``--save-freq``: ``--env-module``), so
:func:`simoun_agent.cli.flags.refuse_unknown` reads these tables first. Each command passes
its own table to :func:`simoun_agent.cli.flags.parse`: :data:`RUN_CONFIG_NAMES` for the
commands that take the run config's flags, joined with a few names of its own. A table entry
for one of the command's own flags says what to do instead of giving that flag several values
(``--seed 1 2 3``).

Names are written with dashes and in lower case: ``--buffer_size`` and ``--Buffer-Size`` find
``buffer-size``.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Meant:
    """What another library's flag is called here."""

    flags: tuple[str, ...] = ()
    """this command's flags of that meaning, best first (those it has are offered)"""
    note: str = ""
    """how it differs, or, with no flags, why it is not supported here and what to use"""
    positional: bool = False
    """it names what the command takes as its positional argument (a run, a directory)"""


POSITIONAL = Meant(positional=True)
"""A flag for what the command takes as its positional argument (``simoun-eval --run-dir``)."""


def name_key(flag: str) -> str:
    """The table key of a typed flag: ``--Buffer_Size`` -> ``buffer-size``."""
    return flag.lstrip("-").lower().replace("_", "-")


ONE_ENV = (
    "a run steps one environment (there are no vectorised envs); to train several runs at "
    "once, simoun-sweep runs them as parallel trials (e.g. --seeds 0-3)"
)

ONE_SEED = (
    "a run has one seed; for several, simoun-sweep --seeds 1,2,3 trains one run per seed (or "
    "run simoun-train once per seed)"
)

LEARNED_TEMPERATURE = "the gaussian actor's temperature is always learned; this sets its start"

ONE_LR = "one Adam learning rate serves the encoder, critic, actor and auxiliary heads"

NO_WINDOW = (
    "frames are rendered off screen (rgb_array) for the agent and the video: no window opens"
)

TIME_LIMIT = (
    "an episode's step limit is the env's keyword, e.g. --env-kwargs "
    "'{\"max_episode_steps\": {value}}'"
)

NO_CONFIG_FILE = (
    "there is no config file flag: --preset picks a preset, and --set KEY=VALUE (or each key's "
    "own flag) changes it; a config kept in a file is passed in Python, "
    "simoun_agent.config.resolve(preset, overrides)"
)

RUN_CONFIG_NAMES: dict[str, Meant] = {
    # replay and schedule
    "buffer-size": Meant(("--replay-capacity",)),
    "replay-buffer-size": Meant(("--replay-capacity",)),
    "learning-starts": Meant(("--warmup-agent-steps",)),
    "init-steps": Meant(("--warmup-agent-steps",)),
    "num-seed-frames": Meant(("--warmup-agent-steps",), "counted in agent decisions"),
    "total-timesteps": Meant(("--total-env-steps",)),
    "n-timesteps": Meant(("--total-env-steps",)),
    "num-train-steps": Meant(("--total-env-steps",)),
    "num-train-frames": Meant(("--total-env-steps",)),
    "train-freq": Meant(("--agent.update-every-steps", "--updates-per-step")),
    "gradient-steps": Meant(("--updates-per-step",)),
    "eval-freq": Meant(("--eval-every",)),
    "eval-every-frames": Meant(("--eval-every",)),
    "n-eval-episodes": Meant(("--eval-episodes",)),
    "num-eval-episodes": Meant(("--eval-episodes",)),
    "save-freq": Meant(("--checkpoint-every",)),
    "checkpoint-freq": Meant(("--checkpoint-every",)),
    "save-snapshot": Meant(("--checkpoint-every",), "every run writes checkpoint.pt"),
    "save-model": Meant(("--checkpoint-every",), "every run writes checkpoint.pt"),
    # where a run goes
    "log-dir": Meant(("--run-dir",), "the run's logs, curves and checkpoint all go there"),
    "logdir": Meant(("--run-dir",), "the run's logs, curves and checkpoint all go there"),
    "log-folder": Meant(("--run-dir",)),
    "tensorboard-log": Meant(("--run-dir",), "its TensorBoard logs go to RUN_DIR/tb"),
    "exp-name": Meant(("--run-dir",), "a run is named by its directory"),
    "experiment": Meant(("--run-dir",), "a run is named by its directory"),
    "trained-agent": Meant(("--resume",)),
    # the agent
    "learning-rate": Meant(("--agent.lr",)),
    "q-lr": Meant(("--agent.lr",), ONE_LR),
    "policy-lr": Meant(("--agent.lr",), ONE_LR),
    "critic-lr": Meant(("--agent.lr",), ONE_LR),
    "actor-lr": Meant(("--agent.lr",), ONE_LR),
    "gamma": Meant(("--agent.discount",)),
    "n-steps": Meant(
        ("--agent.n-step",), "a PPO rollout length has no counterpart in this off-policy agent"
    ),
    "nstep": Meant(("--agent.n-step",)),
    "ent-coef": Meant(("--agent.init-temperature",), LEARNED_TEMPERATURE),
    "alpha": Meant(("--agent.init-temperature",), LEARNED_TEMPERATURE),
    "autotune": Meant(("--agent.init-temperature",), LEARNED_TEMPERATURE),
    "policy-delay": Meant(("--agent.actor-update-every",)),
    "policy-frequency": Meant(("--agent.actor-update-every",)),
    "actor-update-freq": Meant(("--agent.actor-update-every",)),
    "frame-stack": Meant(("--agent.num-frames",)),
    "frame-skip": Meant(("--action-repeat",)),
    "frameskip": Meant(("--action-repeat",)),
    "stddev-schedule": Meant(
        (
            "--agent.exploration-std-start",
            "--agent.exploration-std-end",
            "--agent.exploration-steps",
        ),
        "with --agent.actor deterministic; DrQ-v2's linear(start,end,steps) is these three",
    ),
    "stddev-clip": Meant(("--agent.noise-clip",)),
    "data-augs": Meant(("--agent.augmentation",)),
    "algo": Meant(("--agent.recipe",)),
    "agent": Meant(("--agent.recipe",)),
    "hyperparams": Meant(("--set",), "one KEY=VALUE each, e.g. --set agent.lr=3e-4"),
    # the environment
    "env-id": Meant(("--env",)),
    "domain-name": Meant(("--env",), "a dm_control task is one id: dm_control/DOMAIN-TASK-v0"),
    "task-name": Meant(("--env",), "a dm_control task is one id: dm_control/DOMAIN-TASK-v0"),
    "task": Meant(("--env",), "a dm_control task is one id: dm_control/DOMAIN-TASK-v0"),
    "num-envs": Meant(note=ONE_ENV),
    "n-envs": Meant(note=ONE_ENV),
    "vec-env": Meant(note=ONE_ENV),
    "num-threads": Meant(("--torch-threads",)),
    "cuda": Meant(("--device",), "e.g. --device cuda"),
    "render": Meant(("--video",), NO_WINDOW),
    "render-mode": Meant(("--video",), NO_WINDOW),
    "max-episode-steps": Meant(("--env-kwargs",), TIME_LIMIT),
    "config": Meant(("--preset", "--set"), NO_CONFIG_FILE),
    "config-file": Meant(("--preset", "--set"), NO_CONFIG_FILE),
    "config-path": Meant(("--preset", "--set"), NO_CONFIG_FILE),
    "config-name": Meant(("--preset", "--set"), NO_CONFIG_FILE),
    "cfg": Meant(("--preset", "--set"), NO_CONFIG_FILE),
    "capture-video": Meant(("--video",)),
    "save-video": Meant(("--video",)),
    "verbose": Meant(("--progress", "--no-progress")),
    "track": Meant(
        note="runs log to CSV files and TensorBoard (RUN_DIR/tb) in their run directory; "
        "there is no Weights & Biases logging"
    ),
    "max-grad-norm": Meant(note="the agent's gradients are not clipped"),
}
"""Other libraries' names for keys of the run config (``simoun-train``, ``simoun-sweep``;
``simoun-eval`` names the run's setting)."""
