"""The tenth reliability trial's cases: agent (see reliability_trial.py).

simoun-train and simoun-eval on kinds and surfaces the earlier trials left out: MuJoCo's own
keywords (render size, mode and camera, frame skip, model file, a number given as text), its
cameras and a namespace it has not, CarRacing without Box2D; dm_control ids with the task's
underscore spelt as a hyphen, domain and task swapped or split by a slash, the MODULE:ID form of
shimmy, a time limit given where the environment is built rather than the task, a task seed
negative or fractional, a switch given as text, PointReach's key, and a budget shorter than one
action repeat; highway-env ids no trial ran (lane keeping, u-turn), a preset's config on
another highway task, the full highway preset, a preset with its grayscale turned off, config
keys of rewards, spacing, the other vehicles' class and the view, an action given as a string,
a multi-agent or discrete action type, an observation type that needs settings of its own and a
human render mode; PointReach's kwargs as a float, null or negative, JSON with blanks around it,
a comment after it, encoded twice or split over two words, and dm_control's render keywords
given to Pendulum; the names other libraries (SB3, CleanRL) give to train's flags, a field in
the other section, several modules in one --env-module, a flag given twice, a prefix of a
flag, a short flag, several seeds as words and a flag missing its value at the end; agent
fields at edges (tau of 1 and 0, more target views than critic views, a long n-step on a small
replay, no checkpoints) and switches given a word; --set in other spellings of numbers and
booleans, with a unit, two settings in one word, a dict given as KEY=VALUE, a key of the other
section; --resume of a run's eval.csv, of a run that stopped before its first checkpoint, of a
run whose trainer was killed mid-checkpoint, of two runs, with fields given the values the run
has, the env in MODULE:ID form, a device that is no device and --set of the budget against the
flag; a --run-dir holding what simoun-eval wrote; and simoun-eval given its run as a flag, its
count as a word, the names other libraries give its flags, a run that stopped before its first
checkpoint, a killed run, a file of the run that does not exist, a checkpoint path with a
trailing slash, words after --, runs of two families under --distraction, a run folder as
--videos, --videos without a video mode, a repeated mode, a switch given a word and a device
the random policy does not use.
"""

from pathlib import Path

from reliability_eighth_agent import stopped_early
from reliability_trial import (
    DMC_RUN,
    EVAL,
    SHORT,
    eval_argv,
    evaluated,
    fifth,
    tiny,
    trained,
    video_dir,
)

CONTINUOUS = '"action": {"type": "ContinuousAction"}'
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]
DMC_EVAL = ["dmc", "--no-video", "--episodes", "1"]
PEND_RUN = trained("pend", "--env", "Pendulum-v1")


def highway(config: str) -> str:
    """--env-kwargs of a highway-env id: continuous actions and ``config``'s other keys."""
    return '{"config": {' + CONTINUOUS + (", " + config if config else "") + "}}"


def env(name: str, *flags: str) -> list[str]:
    """A short run (40 env steps) on ``name`` with ``flags``."""
    return tiny("--env", name, *SHORT, *flags)


def fast(config: str) -> list[str]:
    """A short run on highway-fast-v0 with ``config`` beside continuous actions."""
    return env("highway-fast-v0", "--env-kwargs", highway(config))


def dmc(*flags: str) -> list[str]:
    """A short run (40 env steps) on dm_control's cartpole-swingup with ``flags``."""
    return env("dm_control/cartpole-swingup-v0", *flags)


def cheetah(kwargs: str, *flags: str) -> list[str]:
    """A short run on MuJoCo's HalfCheetah-v5 with ``kwargs`` as --env-kwargs."""
    return env("HalfCheetah-v5", "--env-kwargs", kwargs, *flags)


def killed(here: Path) -> None:
    """The run as a killed simoun-train leaves it: its lock file naming a process that is gone
    (no lock held) and half a checkpoint in the temporary of an interrupted write."""
    (here / "run/.lock").write_text("999999\n")
    half = (here / "run/checkpoint.pt").read_bytes()
    (here / "run/.checkpoint.999999.tmp.pt").write_bytes(half[: len(half) // 2])


def short(*words: str) -> list[str]:
    """A short run on PointReach with ``words`` typed after TINY's flags."""
    return [*tiny(*SHORT), *words]


# (command, argv, what the refusal names[, valid[, works]])
FAMILIES = [
    # MuJoCo: its own keywords and cameras; Box2D's pixel env without Box2D
    ("train", cheetah('{"width": 64, "height": 64}'), "width", True),
    ("train", cheetah('{"camera_id": 99}'), "camera_id"),
    ("train", cheetah('{"frame_skip": 0}'), "frame_skip"),
    ("train", cheetah('{"xml_file": "cheetah.xml"}'), ("xml_file", "cheetah.xml")),
    ("train", cheetah('{"reset_noise_scale": "0.1"}'), "reset_noise_scale"),
    ("train", env("HalfCheetah-v5", "--cameras", "2"), "cameras"),
    ("train", cheetah('{"render_mode": "depth_array"}'), "render_mode"),
    ("train", cheetah('{"camera_name": "nope"}'), ("camera_name", "nope")),
    ("train", env("mujoco/HalfCheetah-v5"), "HalfCheetah-v5"),
    ("train", env("CarRacing-v3"), ("box2d", "Box2D")),
    # dm_control: ids in forms not tried, its task and environment kwargs
    ("train", env("dm_control/cartpole-swingup_sparse-v0"), "", True),
    ("train", env("dm_control/cartpole-swingup-sparse-v0"), "cartpole-swingup_sparse"),
    ("train", env("dm_control/swingup-cartpole-v0"), "cartpole-swingup-v0"),
    ("train", env("dm_control/cartpole/swingup-v0"), "cartpole-swingup-v0"),
    ("train", env("shimmy:dm_control/cartpole-swingup-v0"), "", True),
    ("train", dmc("--env-kwargs", '{"environment_kwargs": {"time_limit": 5}}'), "time_limit"),
    ("train", dmc("--env-kwargs", '{"task_kwargs": {"random": -1}}'), "random"),
    ("train", dmc("--env-kwargs", '{"task_kwargs": {"random": 3.5}}'), "random"),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"camera_id": 1}}'), "", True),
    ("train", dmc("--env-kwargs", '{"visualize_reward": "yes"}'), "visualize_reward"),
    ("train", dmc("--env-kwargs", '{"size": 32}'), "size"),
    ("train", tiny("--env", "dm_control/cartpole-swingup-v0", "--total-env-steps", "4",
                   "--run-dir", "r"), ("total_env_steps", "action_repeat")),
    # highway-env: ids no trial ran, presets on other tasks, config keys not tried
    ("train", env("lane-keeping-v0"), "lane-keeping-v0", True),
    ("train", env("u-turn-v0"), ("Discrete", "ContinuousAction")),
    ("train", tiny("--preset", "highway-cpu", "--env", "intersection-v0", *SHORT),
     ("preset", "intersection"), True),
    ("train", tiny("--preset", "highway", "--env", "highway-v0", *SHORT), "", True),
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-fast-v0", "--no-grayscale",
                   *SHORT), "", True),
    ("train", fast('"normalize_reward": "yes"'), "normalize_reward"),
    ("train", fast('"right_lane_reward": null'), "right_lane_reward"),
    ("train", fast('"ego_spacing": -1'), "ego_spacing"),
    ("train", fast('"other_vehicles_type": "highway_env.vehicle.behavior.CarefulVehicle"'),
     ("other_vehicles_type", "CarefulVehicle")),
    ("train", fast('"centering_position": [0.3]'), "centering_position"),
    ("train", fast('"observation": {"type": "GrayscaleObservation"}'),
     ("observation", "GrayscaleObservation")),
    ("train", env("highway-fast-v0", "--env-kwargs",
                  '{"config": {"action": {"type": "DiscreteMetaAction"}}}'),
     ("DiscreteMetaAction", "ContinuousAction")),
    ("train", env("highway-fast-v0", "--env-kwargs",
                  '{"config": {' + CONTINUOUS + '}, "render_mode": "human"}'), "render_mode"),
    ("train", env("parking-v0", "--cameras", "3"), "cameras", True),
    ("train", env("highway-fast-v0", "--env-kwargs", '{"config": {"action": "ContinuousAction"}}'),
     ("action", "type")),
    ("train", fast('"screen_width": 600.5'), "screen_width", True),
    ("train", env("merge-v0", "--env-kwargs",
                  '{"config": {"action": {"type": "MultiAgentAction"}}}'), "MultiAgentAction"),
    # PointReach's own kwargs, JSON with blanks or a comment, another family's keywords
    ("train", tiny("--env-kwargs", '{"size": 32.0}'), "size"),
    ("train", tiny("--env-kwargs", '{"size": null}'), "size"),
    ("train", tiny("--env-kwargs", '{"step_size": -0.2}'), "step_size"),
    ("train", tiny("--env-kwargs", ' {"max_steps": 5} ', *SHORT), "", True),
    ("train", tiny("--env-kwargs", '{"size": 32} // pixels'), "--env-kwargs"),
    ("train", tiny("--env-kwargs", '"{\\"size\\": 32}"'), "--env-kwargs"),
    ("train", [*tiny("--env-kwargs", '{"size": 32}'), '{"max_steps": 5}'], "--env-kwargs"),
    ("train", env("Pendulum-v1", "--env-kwargs", '{"render_kwargs": {"width": 64}}'),
     "render_kwargs"),
]  # fmt: skip
FLAGS = [
    # the names other libraries give to train's flags
    ("train", short("--lr", "1e-3"), "--agent.lr"),
    ("train", short("--agent-lr", "1e-3"), "--agent.lr"),
    ("train", short("--gamma", "0.99"), "--agent.discount"),
    ("train", short("--buffer-size", "100000"), "--replay-capacity"),
    ("train", short("--learning-starts", "1000"), "--warmup-agent-steps"),
    ("train", short("--frame-stack", "3"), "--agent.num-frames"),
    ("train", short("--tau", "0.005"), ("--agent.critic-tau", "--agent.encoder-tau")),
    ("train", short("--log-dir", "logs"), "--run-dir"),
    ("train", short("--cuda"), "--device"),
    ("train", short("--recipe", "drq"), "--agent.recipe"),
    ("train", short("--no-curiosity"), "--agent.no-curiosity"),
    ("train", short("--num-envs", "4"), "--num-envs"),
    ("train", short("--total-timesteps", "40"), "--total-env-steps"),
    ("train", short("--env-id", "Pendulum-v1"), "--env"),
    ("train", short("--capture-video"), "--video"),
    ("train", short("--eval-freq", "20"), "--eval-every"),
    ("train", short("--n-eval-episodes", "1"), "--eval-episodes"),
    ("train", short("--save-freq", "20"), "--checkpoint-every"),
    ("train", short("--ent-coef", "0.1"), "--agent.init-temperature"),
    ("train", short("--train-freq", "2"), ("--agent.update-every-steps", "--updates-per-step")),
    ("train", short("--target-update-interval", "2"), "--agent.target-update-every"),
    ("train", short("--policy-lr", "3e-4"), "--agent.lr"),
    ("train", short("--exp-name", "mine"), "--run-dir"),
    ("train", short("--n-step", "3"), "--agent.n-step"),
    # a field given in the other section, several modules in one flag
    ("train", short("--agent.image-size", "48"), "--image-size"),
    ("train", tiny("--set", "agent.warmup_agent_steps=10"), "warmup_agent_steps"),
    ("train", tiny("--env-module", "minigrid,shimmy"), ("--env-module", "minigrid,shimmy")),
    # a flag twice with two values, a prefix, a short flag, a value missing at the end
    ("train", short("--total-env-steps", "60"), "--total-env-steps"),
    ("train", tiny("--total-env", "40", "--run-dir", "r"), "--total-env-steps", True),
    ("train", short("-s", "3"), ("-s", "--seed")),
    ("train", [*tiny("--seed", "1"), "2", "3"], "--seed"),
    ("train", short("--agent.lr"), "--agent.lr"),
    # agent fields at edges that are valid, switches given a word
    ("train", tiny("--agent.critic-tau", "1", *SHORT), "critic_tau", True),
    ("train", tiny("--agent.encoder-tau", "0"), "encoder_tau"),
    ("train", tiny("--agent.recipe", "drq", "--agent.target-augmentations", "3", *SHORT),
     "target_augmentations", True),
    ("train", tiny("--agent.n-step", "50", "--replay-capacity", "40", *SHORT), "n_step", True),
    ("train", tiny("--agent.channels-last", "false", *SHORT), "", True),
    ("train", tiny("--agent.detach-past-frames", "maybe"), ("detach", "maybe")),
    ("train", tiny("--seed", "4294967296", *SHORT), "seed", True),
    ("train", tiny("--checkpoint-every", "0"), "checkpoint_every"),
    ("train", tiny("--preset", "cpu", "--env", "dm_control/cheetah-run-v0", *SHORT),
     "action_repeat", True),
    ("train", dmc("--eval-distraction", "[color_easy, video_hard]"),
     ("[color_easy", "--eval-distraction")),
    # --set in other spellings of numbers and booleans, two settings in one word
    ("train", tiny("--set", "agent.lr=3E-4", *SHORT), "", True),
    ("train", tiny("--set", "agent.curiosity=off", *SHORT), "curiosity", True),
    ("train", tiny("--set", "agent.augmentation=None", *SHORT), "augmentation", True),
    ("train", tiny("--set", "agent.n_step=3 agent.lr=1e-3"), ("agent.n_step", "--set")),
    ("train", tiny("--set", "env_kwargs=max_steps=5"), "env_kwargs"),
    ("train", tiny("--set", 'agent.lr="1e-3"'), "agent.lr"),
    ("train", tiny("--set", "agent.lr=1e-3,agent.n_step=3"), ("agent.lr", "--set")),
    ("train", tiny("--set", "total_env_steps=100k"), "total_env_steps"),
]  # fmt: skip
RUNS = [
    # --resume of a file of the run, of a run that stopped before its first checkpoint
    ("train", ["--resume", "{run}/eval.csv", "--total-env-steps", "60"], ("eval.csv", "--resume")),
    ("train", ["--resume", "r", "--total-env-steps", "60"], ("checkpoint", "r"), False,
     (stopped_early,)),
    # a run whose trainer was killed mid-checkpoint: its stale lock and temporary
    ("train", RESUME, "", True, (killed,)),
    # with fields given the values the run has, the env in MODULE:ID form
    ("train", [*RESUME, "--image-size", "32"], "image_size", True),
    ("train", [*RESUME, "--env", "simoun_agent.envs:simoun/PointReach-v0"],
     ("env", "env_module"), True),
    # fields it may change, given through --set or a value that is no device
    ("train", [*RESUME, "--set", "progress=false"], "", True),
    ("train", [*RESUME, "--device", "meta"], ("meta", "device")),
    ("train", [*RESUME, "--set", "total_env_steps=50"], "total_env_steps"),
    ("train", [*RESUME, "--resume", "dmc"], "--resume", False, (DMC_RUN,)),
    # a --run-dir that holds what simoun-eval wrote
    ("train", tiny("--total-env-steps", "40", "--run-dir", "o"), ("--run-dir", "o"), True,
     (evaluated,)),
]  # fmt: skip
EVALS = [
    # the run given as a flag, runs that cannot be evaluated, paths of the run
    ("eval", ["--run-dir", "{run}", *EVAL], ("--run-dir", "RUN")),
    ("eval", ["r", *EVAL], ("checkpoint", "r"), False, (stopped_early,)),
    ("eval", ["{run}/nope.pt", *EVAL], "nope.pt"),
    ("eval", eval_argv("--episodes", "1"), "", True, (killed,)),
    ("eval", ["{run}/checkpoint.pt/", *EVAL], "checkpoint.pt", True),
    ("eval", ["{run}", *EVAL, "--", "--seed", "3"], ("--", "--seed")),
    ("eval", eval_argv("--num-episodes", "1"), "--episodes"),
    ("eval", ["{run}", "1", "--no-video"], "--episodes"),
    ("eval", eval_argv("--episodes", "1", "--output-dir", "o"), "--out"),
    ("eval", ["{run}", "--episodes", "1", "--save-video"], "--video"),
    # --distraction: runs of two families, a run folder as --videos, a repeated mode
    ("eval", ["dmc", "pend", "--no-video", "--episodes", "1", "--distraction", "color_easy"],
     ("pend", "dm_control"), False, (DMC_RUN, PEND_RUN)),
    ("eval", [*DMC_EVAL, "--distraction", "video_hard", "--videos", "dmc"], "--videos", False,
     (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "color_easy", "--videos", "v"], "--videos", True,
     (DMC_RUN, video_dir)),
    ("eval", [*DMC_EVAL, "--distraction", "train,train"], "train", True, (DMC_RUN,)),
    # valid spellings and a device the random policy does not use
    ("eval", ["{run}", "--episodes", "1", "--video", "false"], "", True),
    ("eval", eval_argv("--episodes", "1", "--random-policy", "--device", "cuda"),
     ("cuda", "device"), True),
]  # fmt: skip
CASES: list[dict] = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in FAMILIES + FLAGS + RUNS + EVALS
]
