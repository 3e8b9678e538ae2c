"""The seventh reliability trial's cases: agent (see reliability_trial.py).

simoun-train and simoun-eval on kinds and surfaces the earlier trials left out: counts written
with units or as fractions, --env-kwargs given as a file or in Python's spelling, highway-env
config keys the env itself rejects, dm_control cameras and task kwargs, MiniGrid and BabyAI
ids, an action repeat longer than the episode, presets crossed with recipes and env families,
--set against the flag of the same key, --resume with a checkpoint file, a smaller budget or
flags it may change given bad values, paths with a literal ~ or naming a file of the run, and
simoun-eval on runs of other recipes and envs, on folders that hold no run, and with its own
options misspelled.
"""

from pathlib import Path

from reliability_trial import DMC_RUN, DRQ_RUN, SHORT, eval_argv, fifth, put, tiny, trained

CONTINUOUS = '"action": {"type": "ContinuousAction"}'
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]
PEND_RUN = trained("pend", "--env", "Pendulum-v1")
DMC_EVAL = ["dmc", "--no-video", "--episodes", "1"]


def highway(config: str) -> str:
    """--env-kwargs of a highway-env id: continuous actions and ``config``'s other keys."""
    return '{"config": {' + CONTINUOUS + (", " + config if config else "") + "}}"


def env(name: str, *flags: str) -> list[str]:
    """A short run (40 env steps) on ``name`` with ``flags``."""
    return tiny("--env", name, *SHORT, *flags)


def dmc(*flags: str) -> list[str]:
    """A short run (40 env steps) on dm_control's cartpole-swingup with ``flags``."""
    return env("dm_control/cartpole-swingup-v0", *flags)


def empty_dir(here: Path) -> None:
    """``e``: an empty folder."""
    (here / "e").mkdir()


def empty_clip(here: Path) -> None:
    """``v``: a folder of videos whose one DAVIS-style folder of frames is empty."""
    (here / "v/clip").mkdir(parents=True)


# (command, argv, what the refusal names[, valid[, works]])
TRAIN_VALUES = [
    # counts with units, fractions and signs
    ("train", tiny("--total-env-steps", "40k"), "--total-env-steps"),
    ("train", tiny("--replay-capacity", "1M"), "--replay-capacity"),
    ("train", tiny("--eval-every", "5k"), "--eval-every"),
    ("train", tiny("--agent.discount", "99%"), "discount"),
    ("train", tiny("--agent.lr", "1/1000"), ("lr", "--agent.lr")),
    ("train", tiny("--seed", "+3", *SHORT), "seed", True),
    ("train", tiny("--replay-capacity", "100_000", *SHORT), "replay_capacity", True),
    ("train", tiny("--action-repeat", "0"), "action_repeat"),
    ("train", tiny("--eval-episodes", "0", *SHORT), "eval_episodes"),
    ("train", tiny("--image-size", "8"), "image_size"),
    ("train", tiny("--image-size", "16", *SHORT), "image_size", True),
    ("train", tiny("--agent.batch-size", "1", *SHORT), "batch_size", True),
    ("train", tiny("--agent.discount", "1.0", *SHORT), "discount", True),
    # several values where one is taken, values in the wrong units
    ("train", tiny("--agent.lr", "3e-4,1e-3"), ("lr", "--agent.lr")),
    ("train", tiny("--seed", "1,2,3"), "--seed"),
    ("train", tiny("--seed", "0-4"), "--seed"),
    ("train", tiny("--env", "dm_control/cartpole-swingup-v0,dm_control/cheetah-run-v0"),
     "--env"),
    ("train", tiny("--agent.recipe", "drqv2", "--agent.pixel-offset", "128"), "pixel_offset"),
    ("train", tiny("--agent.encoder-tau", "5"), "encoder_tau"),
    ("train", tiny("--env-kwargs", '{"size": 32}', "--set", 'env_kwargs={"size": 16}'),
     "env_kwargs"),
    # --env-kwargs as a file or in another language's spelling
    ("train", tiny("--env-kwargs", "kw.json"), ("--env-kwargs", "kw.json"), False,
     (put("kw.json", '{"size": 32}'),)),
    ("train", tiny("--env-kwargs", "@kw.json"), ("--env-kwargs", "@kw.json"), False,
     (put("kw.json", '{"size": 32}'),)),
    ("train", tiny("--env-kwargs", "{'size': 32}"), "--env-kwargs"),
    ("train", tiny("--env-kwargs", '{"size": 32,}'), "--env-kwargs"),
    ("train", tiny("--env-kwargs", "size=32"), "--env-kwargs"),
    ("train", tiny("--env-kwargs", '{"size": true}'), "size"),
    ("train", tiny("--env-kwargs", '{"max_steps": 5}', "--env-kwargs", '{"size": 32}', *SHORT),
     "--env-kwargs", True),
]  # fmt: skip
TRAIN_ENVS = [
    # highway-env: config values the env itself rejects, other ids and views
    ("train", env("highway-fast-v0", "--env-kwargs", highway('"vehicles_count": -5')),
     "vehicles_count"),
    ("train", env("highway-fast-v0", "--env-kwargs", highway('"policy_frequency": 0')),
     "policy_frequency"),
    ("train", env("highway-fast-v0", "--env-kwargs", highway('"duration": "40s"')), "duration"),
    ("train", env("merge-v0", "--env-kwargs", highway("")), "merge", True),
    ("train", env("roundabout-v0"), ("Discrete", "ContinuousAction")),
    ("train", env("highway-fast-v0", "--env-kwargs", highway(""), "--cameras", "4"), "cameras",
     True),
    ("train", env("highway-fast-v0", "--env-kwargs",
                  highway('"observation": {"type": "GrayscaleObservation"}')), "observation",
     True),
    # dm_control: cameras and task kwargs
    ("train", env("dm_control/walker-walk-v0", "--cameras", "9"), ("cameras", "camera")),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"camera_id": "fixed"}}'), "camera_id",
     True),
    ("train", dmc("--env-kwargs", '{"task_kwargs": {"time_limit": 0}}'), "time_limit"),
    ("train", dmc("--env-kwargs", '{"task_kwargs": {"randome": 3}}'), "randome"),
    ("train", dmc("--env-kwargs", '{"visualize_reward": true}'), "visualize_reward", True),
    ("train", env("dm_control/cartpole-swingup-v0", "--eval-distraction", "video-hard"),
     ("video-hard", "video_hard")),
    ("train", dmc("--set", "eval_distraction=color_easy,video_hard"), "eval_distraction", True),
    # MiniGrid and BabyAI: discrete actions
    ("train", env("MiniGrid-DoorKey-5x5-v0", "--env-kwargs", '{"max_steps": 10}'),
     ("Discrete", "MiniGrid")),
    ("train", env("minigrid:BabyAI-GoToRedBall-v0"), ("Discrete", "BabyAI")),
    # classic control: discrete ids, an action repeat longer than the episode
    ("train", env("MountainCar-v0"), ("Discrete", "MountainCar")),
    ("train", tiny("--env", "Pendulum-v1", "--action-repeat", "250", "--total-env-steps", "500",
                   "--run-dir", "r"), ("action_repeat", "episode", "max_episode_steps")),
    ("train", env("Pendulum-v1", "--env-kwargs", '{"max_episode_steps": 30}', "--action-repeat",
                  "40"), ("action_repeat", "max_episode_steps")),
    # module forms
    ("train", tiny("--env-module", "minigrid.py"), "minigrid.py"),
    ("train", tiny("--env-module", "no_such_package"), "no_such_package"),
    ("train", tiny("--env", "gymnasium:Pendulum-v1", *SHORT), "", True),
]  # fmt: skip
TRAIN_COMBOS = [
    # presets x recipes x env families
    ("train", tiny("--preset", "cpu", "--agent.recipe", "drqv2", *SHORT), "", True),
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-fast-v0", "--agent.recipe",
                   "curl", *SHORT), "", True),
    ("train", tiny("--preset", "cheetah-run", "--env", "dm_control/cheetah-run-v0",
                   "--agent.recipe", "rad", *SHORT), "", True),
    ("train", tiny("--preset", "cartpole-swingup", "--env", "dm_control/cartpole-swingup-v0",
                   "--action-repeat", "4", *SHORT), "", True),
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-fast-v0", "--cameras", "3",
                   *SHORT), "", True),
    ("train", tiny("--preset", "cpu-fast"), ("cpu-fast", "preset")),
    ("train", [*tiny("--preset", "cpu"), "--preset", "highway-cpu"], "preset"),
    ("train", tiny("--agent.recipe", "drqv2", "--agent.encoder", "dual_interactive"),
     ("encoder", "separate_trunks")),
    ("train", [*tiny("--agent.recipe", "drq"), "--agent.recipe", "curl"], "recipe"),
    ("train", tiny("--agent.recipe", "simoun-no-aux"), ("simoun-no-aux", "simoun_no_aux")),
    ("train", tiny("--agent.recipe", "sac", "--agent.critic-augmentations", "2"),
     ("augmentation", "critic_augmentations")),
    # --set against flags and its own spellings
    ("train", tiny("--set", "agent.recipe=drq", "--agent.recipe", "curl"), "recipe"),
    ("train", dmc("--set", "cameras=2", "--cameras", "2"), "cameras", True),
    ("train", tiny("--set", "env_kwargs='{\"size\": 32}'"), "env_kwargs"),
    ("train", tiny("--set", "agent.encoder=Dual"), ("Dual", "encoder")),
    ("train", tiny("--set", "agent.no_curiosity=true"), ("no_curiosity", "curiosity")),
    ("train", tiny("--set"), "--set"),
    ("train", tiny("--set", "agent.recipe=nope"), "nope"),
    # help and version
    ("train", ["-V"], ("-V", "--version")),
    ("train", ["help"], "help"),
    ("train", ["--agent.recipe", "drq", "--help"], "", True),
    ("train", ["--help=all"], "--help"),
]  # fmt: skip
TRAIN_RUNS = [
    # --resume: the checkpoint file, a smaller budget, bad values of flags it may change
    ("train", ["--resume", "{run}/checkpoint.pt", "--total-env-steps", "60"],
     ("--resume", "checkpoint.pt"), True),
    ("train", ["--resume", "{run}/config.json", "--total-env-steps", "60"],
     ("--resume", "config.json")),
    ("train", ["--resume", "~/runs/tiny", "--total-env-steps", "60"], "~"),
    ("train", ["--resume", "{run}", "--total-env-steps", "20"], "--total-env-steps"),
    ("train", ["--resume", "{run}", "--total-env-steps", "40"], "--total-env-steps", True),
    ("train", ["--resume", "{run}"], "--total-env-steps", True),
    ("train", ["--resume", "{run}/", "--total-env-steps", "60"], "", True),
    ("train", [*RESUME, "--preset", "cpu"], "preset"),
    ("train", [*RESUME, "--set", "video=false"], "video", True),
    ("train", [*RESUME, "--set", "agent.lr=2e-3"], "lr"),
    ("train", [*RESUME, "--overwrite"], "--overwrite"),
    ("train", [*RESUME, "--eval-every", "0"], "eval_every"),
    ("train", [*RESUME, "--checkpoint-every", "-5"], "checkpoint_every"),
    ("train", [*RESUME, "--torch-threads", "0"], "torch_threads"),
    ("train", ["--resume", "dmc", "--total-env-steps", "60", "--eval-distraction", "bogus"],
     "bogus", False, (DMC_RUN,)),
    ("train", ["--resume", "drq", "--total-env-steps", "60"], "", True, (DRQ_RUN,)),
    # --run-dir: a file of a run, a literal ~, new nested folders
    ("train", tiny("--total-env-steps", "40", "--run-dir", "{run}/config.json"),
     ("--run-dir", "config.json")),
    ("train", tiny("--total-env-steps", "40", "--run-dir", "kw.json"), ("--run-dir", "kw.json"),
     False, (put("kw.json", "{}"),)),
    ("train", tiny("--total-env-steps", "40", "--run-dir", "deep/new/folder"), "", True),
]  # fmt: skip
EVALS = [
    # what the RUN argument is given
    ("eval", ["{run}/checkpoint.pt", "--no-video", "--episodes", "1"], "", True),
    ("eval", ["{run}/config.json", "--no-video", "--episodes", "1"],
     ("config.json", "checkpoint")),
    ("eval", ["{run}/eval.csv", "--no-video", "--episodes", "1"], ("eval.csv", "checkpoint")),
    ("eval", ["e", "--no-video", "--episodes", "1"], ("'e'", "e/", "checkpoint"), False,
     (empty_dir,)),
    ("eval", [".", "--no-video", "--episodes", "1"], ("checkpoint", "RUN")),
    ("eval", ["~/runs/tiny", "--no-video", "--episodes", "1"], "~"),
    ("eval", ["{run}", "{run}", "--no-video", "--episodes", "1"], ("--distraction", "RUN")),
    ("eval", [], ("RUN", "run directory")),
    ("eval", ["help"], "help"),
    ("eval", ["--version"], "", True),
    ("eval", ["-v"], "-v"),
    # runs of other recipes and envs
    ("eval", ["drq", "--no-video", "--episodes", "1"], "", True, (DRQ_RUN,)),
    ("eval", ["pend", "--no-video", "--episodes", "1"], "", True, (PEND_RUN,)),
    ("eval", ["pend", "--no-video", "--episodes", "1", "--distraction", "color_easy"],
     ("dm_control", "Pendulum"), False, (PEND_RUN,)),
    ("eval", ["dmc", "--episodes", "1", "--video", "--out", "o"], "", True, (DMC_RUN,)),
    # its own options
    ("eval", eval_argv("--episodes", "1k"), "--episodes"),
    ("eval", eval_argv("--episodes", "-1"), "--episodes"),
    ("eval", eval_argv("--episodes", "0"), "--episodes"),
    ("eval", eval_argv("--episodes", "1", "--out", "o"), "--out", False, (put("o", "a file\n"),)),
    ("eval", eval_argv("--episodes", "1", "--out", "{run}/checkpoint.pt"), "--out"),
    ("eval", eval_argv("--episodes", "1", "--torch-threads", "0"), "--torch-threads"),
    ("eval", eval_argv("--episodes", "1", "--seed", "-5"), "--seed"),
    ("eval", eval_argv("--episodes", "1", "--seed", "1,2"), "--seed"),
    ("eval", ["--episodes", "1", "--no-video", "{run}"], "", True),
    ("eval", eval_argv("--episodes", "1", "--device", "cpu", "--device", "cpu"), "--device",
     True),
    ("eval", eval_argv("--episodes", "1", "--no-progress", "--progress"), "--progress", True),
    ("eval", eval_argv("--episodes", "1", "--random-policy", "--random-policy"),
     "--random-policy", True),
    # distraction modes
    ("eval", [*DMC_EVAL, "--distraction", "video_hard", "--videos", "v"], ("clip", "--videos"),
     False, (DMC_RUN, empty_clip)),
    ("eval", [*DMC_EVAL, "--distraction", "color_easy,"], "--distraction", True, (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "video_easy", "--videos", "clip.txt"],
     ("--videos", "clip.txt"), False, (DMC_RUN, put("clip.txt", "not a folder\n"))),
    ("eval", [*DMC_EVAL, "--distraction", "color-hard"], ("color-hard", "color_hard"), False,
     (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "none"], ("none", "--distraction"), True, (DMC_RUN,)),
]  # fmt: skip
CASES: list[dict] = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in TRAIN_VALUES + TRAIN_ENVS + TRAIN_COMBOS + TRAIN_RUNS + EVALS
]
