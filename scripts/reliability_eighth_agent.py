"""The eighth reliability trial's cases: agent (see reliability_trial.py).

simoun-train and simoun-eval on kinds and surfaces the earlier trials left out: agent fields no
trial gave a value yet (conv init, independent next shift, channels-last) and choices spelled
with hyphens or capitals, the couplings the help documents (target augmentations without shift,
separate trunks with auxiliary losses, curiosity on a single-path encoder, kernels larger than
the frame), edge values that are valid (a discount of 0, no warmup, a warmup longer than the
run), words and fractions where counts are taken (auto, random, none, 1e3, 0.5, thousands
separators), gymnasium.make's own keywords and env metadata given through --env-kwargs,
dm_control's environment and render kwargs, highway-env's simulation settings and a
one-dimensional action, presets crossed with the paper's other tasks, --set with a trailing
comment, in Hydra's spellings (+key=value, a bare key=value word) and against the flag of the
same key, --resume of a run another trainer holds, of a moved run, of a folder of runs, with a
negative budget and with fields that change no result, a --run-dir whose run stopped before its
first checkpoint or that holds other files, and simoun-eval on a run in training, on a moved
run, on a grayscale two-camera run under distraction, and with the distraction path's counts,
the same run twice, an --out folder, British spellings in a list of modes and a flag missing
its value.
"""

import fcntl
import shutil
from pathlib import Path

from reliability_trial import DMC_RUN, SHORT, eval_argv, fifth, put, tiny, trained

CONTINUOUS = '"action": {"type": "ContinuousAction"}'
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]
GRAY_RUN = trained(
    "gray", "--env", "dm_control/cartpole-swingup-v0", "--grayscale", "--cameras", "2"
)
DMC_EVAL = ["dmc", "--no-video", "--episodes", "1"]
HELD: list = []
"""lock files a case's setup holds open for the life of the case's process"""


def highway(config: str) -> str:
    """--env-kwargs of a highway-env id: continuous actions and ``config``'s other keys."""
    return '{"config": {' + CONTINUOUS + (", " + config if config else "") + "}}"


def env(name: str, *flags: str) -> list[str]:
    """A short run (40 env steps) on ``name`` with ``flags``."""
    return tiny("--env", name, *SHORT, *flags)


def dmc(*flags: str) -> list[str]:
    """A short run (40 env steps) on dm_control's cartpole-swingup with ``flags``."""
    return env("dm_control/cartpole-swingup-v0", *flags)


def pendulum(*flags: str) -> list[str]:
    """A short run (40 env steps) on Gymnasium's Pendulum-v1 with ``flags``."""
    return env("Pendulum-v1", *flags)


def in_training(here: Path) -> None:
    """The run's lock held as another simoun-train holds it while it trains (PID 4242)."""
    handle = (here / "run/.lock").open("a+")
    fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    handle.seek(0)
    handle.truncate()
    handle.write("4242\n")
    handle.flush()
    HELD.append(handle)


def moved(here: Path) -> None:
    """``moved/tiny``: the run copied to another folder, as a user moves a run between disks."""
    shutil.copytree(here / "run", here / "moved/tiny")


def stopped_early(here: Path) -> None:
    """``r``: a run directory whose run stopped before its first checkpoint (config only)."""
    (here / "r").mkdir()
    shutil.copy(here / "run/config.json", here / "r/config.json")


def notes_dir(here: Path) -> None:
    """``notes``: a folder that holds a user's own file."""
    (here / "notes").mkdir()
    (here / "notes/README.txt").write_text("my notes\n")


# (command, argv, what the refusal names[, valid[, works]])
AGENT_FIELDS = [
    # fields no trial gave a value: choices, other spellings, switches
    ("train", tiny("--agent.conv-init", "xavier"), ("conv_init", "xavier")),
    ("train", tiny("--agent.conv-init", "delta-orthogonal"), ("conv_init", "delta-orthogonal")),
    ("train", tiny("--agent.conv-init", "delta_orthogonal", *SHORT), "", True),
    ("train", tiny("--agent.independent-next-shift", *SHORT),
     ("independent_next_shift", "augmentation"), True),
    ("train", tiny("--agent.next-state-encoder", "ema"), ("next_state_encoder", "ema")),
    ("train", tiny("--agent.similarity-init", "Uniform"), ("similarity_init", "Uniform")),
    ("train", tiny("--agent.feature-dim", "50.0"), ("--agent.feature-dim", "feature_dim")),
    ("train", tiny("--agent.hidden-dim", "1k"), ("--agent.hidden-dim", "hidden_dim")),
    ("train", tiny("--agent.shift-pad", "4.5"), ("--agent.shift-pad", "shift_pad")),
    ("train", tiny("--agent.encoder", "dual-interactive"), ("encoder", "dual-interactive")),
    ("train", tiny("--agent.actor", "Deterministic"), ("actor", "Deterministic")),
    # the couplings the help documents
    ("train", tiny("--agent.target-augmentations", "2"),
     ("target_augmentations", "augmentation")),
    ("train", tiny("--agent.separate-trunks"), ("separate_trunks", "auxiliary")),
    ("train", tiny("--agent.encoder", "stacked", "--agent.curiosity"), "curiosity"),
    ("train", tiny("--agent.num-frames", "2"), ("num_frames", "encoder")),
    ("train", tiny("--agent.random-conv-kernel", "33"), ("random_conv_kernel", "image_size")),
    ("train", tiny("--agent.reduce-kernel", "41"), ("reduce_kernel", "image_size")),
    ("train", tiny("--agent.augmentation", "shift", "--agent.shift-pad", "64", *SHORT),
     "shift_pad", True),
    ("train", tiny("--agent.actor", "deterministic", "--agent.exploration-std-end", "-0.1"),
     "exploration_std_end"),
    ("train", tiny("--agent.log-std-min", "-5", "--agent.log-std-max", "-5"), "log_std"),
    # values at their edges, valid and not
    ("train", tiny("--agent.lr", "0"), "lr"),
    ("train", tiny("--agent.alpha-beta", "1"), "alpha_beta"),
    ("train", tiny("--agent.discount", "0", *SHORT), "discount", True),
    ("train", tiny("--warmup-agent-steps", "0", *SHORT), "warmup", True),
    ("train", tiny("--warmup-agent-steps", "5000", *SHORT), "warmup", True),
]  # fmt: skip
RUN_FLAGS = [
    # words where a number or a device is taken
    ("train", tiny("--total-env-steps", "100,000"), "--total-env-steps"),
    ("train", tiny("--torch-threads", "auto"), "--torch-threads"),
    ("train", tiny("--device", "auto"), "device"),
    ("train", tiny("--seed", "random"), "--seed"),
    ("train", tiny("--seed", "none"), "--seed"),
    ("train", tiny("--cameras", "two"), "--cameras"),
    ("train", tiny("--checkpoint-every", "none"), "--checkpoint-every"),
    ("train", tiny("--eval-episodes", "1.5"), ("--eval-episodes", "eval_episodes")),
    ("train", tiny("--warmup-agent-steps", "1e3"), ("--warmup-agent-steps", "warmup")),
    ("train", tiny("--updates-per-step", "0.5"), ("--updates-per-step", "updates_per_step")),
    ("train", tiny("--replay-capacity", "1e5"), ("--replay-capacity", "replay_capacity")),
    # switches given a value, in the help's own spelling and others
    ("train", tiny("--grayscale", "yes", *SHORT), "grayscale", True),
    # gymnasium.make's own keywords through --env-kwargs
    ("train", pendulum("--env-kwargs", '{"disable_env_checker": true}'), "", True),
    ("train", pendulum("--env-kwargs", '{"apply_api_compatibility": true}'),
     "apply_api_compatibility"),
    ("train", pendulum("--env-kwargs", '{"autoreset": true}'), "autoreset"),
    ("train", pendulum("--env-kwargs", '{"max_episode_steps": 0}'), "max_episode_steps"),
    ("train", pendulum("--env-kwargs", '{"max_episode_steps": "200"}'), "max_episode_steps"),
    ("train", pendulum("--env-kwargs", '{"render_fps": 30}'), "render_fps"),
    ("train", env("CartPole-v1", "--env-kwargs", '{"continuous": true}'),
     ("continuous", "CartPole")),
    # dm_control's kwargs
    ("train", dmc("--env-kwargs", '{"task_kwargs": {"random": "abc"}}'), "random"),
    ("train", dmc("--env-kwargs", '{"environment_kwargs": {"flat_observation": true}}'),
     "flat_observation", True),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"camera_id": -1}}'), "camera_id", True),
    ("train", dmc("--env-kwargs", '{"from_pixels": true}'), "from_pixels"),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"width": 0}}'), "width"),
    ("train", dmc("--env-kwargs", '{"environment_kwargs": {"control_timestep": 0}}'),
     "control_timestep"),
    # highway-env's simulation settings and one-dimensional actions
    ("train", env("highway-fast-v0", "--env-kwargs", highway('"simulation_frequency": 0')),
     "simulation_frequency"),
    ("train", env("highway-fast-v0", "--env-kwargs", highway('"vehicles_density": "high"')),
     "vehicles_density"),
    ("train", env("highway-fast-v0", "--env-kwargs", highway('"duration": 0')), "duration"),
    ("train", env("highway-fast-v0", "--env-kwargs",
                  '{"config": {"action": {"type": "ContinuousAction", "longitudinal": false}}}'),
     "longitudinal", True),
    ("train", env("highway-fast-v0", "--env-kwargs", highway(""), "--cameras", "2"), "cameras",
     True),
    # other ids of the families
    ("train", tiny("--env", "dmc/cartpole-swingup-v0"), ("dmc", "dm_control")),
    ("train", pendulum("--cameras", "2"), "cameras"),
]  # fmt: skip
COMBOS = [
    # presets with the paper's other tasks and recipes
    ("train", tiny("--preset", "finger-spin", "--env", "dm_control/finger-spin-v0",
                   "--action-repeat", "8", *SHORT), "action_repeat", True),
    ("train", tiny("--preset", "cpu,highway-cpu"), ("preset", "cpu,highway-cpu")),
    ("train", tiny("--preset", "cpu", "--set", "preset=highway-cpu"), "preset"),
    # --set against the flag of the same key, keys that are not config keys
    ("train", tiny("--set", "seed=3", "--seed", "4"), "seed"),
    ("train", tiny("--set", "video=False", *SHORT), "video", True),
    ("train", tiny("--set", "agent.lr=3e-4,"), "agent.lr"),
    ("train", tiny("--set", "agent.lr=1e-3  # the paper's"), "agent.lr"),
    ("train", tiny("--set", "+agent.lr=1e-3"), ("+agent.lr", "--set")),
    ("train", [*tiny(), "agent.lr=1e-3"], ("agent.lr", "--set")),
    ("train", tiny("--agent_lr", "1e-3"), "--agent.lr"),
    ("train", tiny("--set", "resume={run}"), "resume"),
    ("train", tiny("--set", "preset=nope"), ("nope", "preset")),
    ("train", tiny("--set", "env_module=minigrid", "--env", "MiniGrid-Empty-5x5-v0"),
     ("Discrete", "MiniGrid")),
]  # fmt: skip
RUNS = [
    # --resume of a run another trainer holds, of a moved run, with fields of no result
    ("train", RESUME, ("in use", "4242"), False, (in_training,)),
    ("train", ["--resume", "moved/tiny", "--total-env-steps", "60"], "", True, (moved,)),
    ("train", [*RESUME, "--device", "cuda"], ("cuda", "device")),
    ("train", ["--resume", "{run}/tb", "--total-env-steps", "60"], ("tb", "--resume")),
    ("train", ["--resume", ".", "--total-env-steps", "60"], ("--resume", "checkpoint", ". is not")),
    ("train", ["--resume", "{run}", "--total-env-steps", "-60"], "--total-env-steps"),
    ("train", [*RESUME, "--agent.conv-init", "delta_orthogonal"], "conv_init"),
    ("train", [*RESUME, "--agent.no-channels-last"], "channels_last", True),
    # --run-dir: a run that stopped before its first checkpoint, other files, a file above it
    ("train", tiny(*SHORT), ("--overwrite", "r"), False, (stopped_early,)),
    ("train", tiny(*SHORT, "--overwrite"), "", True, (stopped_early,)),
    ("train", tiny("--total-env-steps", "40", "--run-dir", "notes"), ("--run-dir", "notes"), True,
     (notes_dir,)),
    ("train", tiny("--total-env-steps", "40", "--run-dir", "kw.json/r"),
     ("--run-dir", "kw.json"), False, (put("kw.json", "{}"),)),
]  # fmt: skip
EVALS = [
    # runs in training, moved, of other observation forms
    ("eval", eval_argv("--episodes", "1"), ("in use", "4242"), True, (in_training,)),
    ("eval", ["moved/tiny", "--no-video", "--episodes", "1"], "", True, (moved,)),
    ("eval", ["gray", "--no-video", "--episodes", "1", "--distraction", "color_easy"], "", True,
     (GRAY_RUN,)),
    # distraction: counts, the same run twice, an output folder, the procedural background
    ("eval", [*DMC_EVAL[:2], "--distraction", "color_easy", "--episodes", "0"], "--episodes",
     False, (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "color_easy", "--seed", "-1"], "--seed", False,
     (DMC_RUN,)),
    ("eval", ["dmc", "dmc", "--no-video", "--episodes", "1", "--distraction", "color_easy"],
     ("twice", "same run", "more than once", "duplicate"), True, (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "color_easy", "--out", "g"], "--out", True,
     (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "colour_hard,video_easy"], "colour_hard", False,
     (DMC_RUN,)),
    # its own options at edges and in other spellings
    ("eval", eval_argv("--episodes", "one"), "--episodes"),
    ("eval", ["{run}", "--no-video", "--episodes", "1", "--out"], "--out"),
    ("eval", eval_argv("--episodes", "1", "--device", "auto"), "device"),
    ("eval", eval_argv("--episodes", "1", "--seed", "random"), "--seed"),
    ("eval", ["{run}/tb", "--no-video", "--episodes", "1"], ("tb", "checkpoint")),
    ("eval", eval_argv("--episodes", "1", "--out", "kw.json/o"), ("--out", "kw.json"), False,
     (put("kw.json", "{}"),)),
    ("eval", eval_argv("--episodes", "1", "--random-policy", "--distraction", "color_easy"),
     ("dm_control", "PointReach", "--distraction")),
]  # fmt: skip
CASES: list[dict] = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in AGENT_FIELDS + RUN_FLAGS + COMBOS + RUNS + EVALS
]
