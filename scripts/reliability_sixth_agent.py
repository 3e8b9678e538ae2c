"""The sixth reliability trial's cases: agent (see reliability_trial.py).

simoun-train and simoun-eval on surfaces the earlier trials left out: Gymnasium's classic
control and MuJoCo ids with their own kwargs and render modes, dm_control tasks beyond the
paper's six, highway-env's other ids and its config dict, MiniGrid's module forms, presets and
recipes crossed with env families, --set spellings, action repeat and frame size spelled as
other libraries spell them, --resume with values equal to the saved ones, evaluation flags that
belong to training, and switches given both ways.
"""

from reliability_trial import DMC_RUN, SHORT, eval_argv, fifth, put, tiny, video_dir

CONTINUOUS = '"action": {"type": "ContinuousAction"}'
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]


def highway(config: str) -> str:
    """--env-kwargs of a highway-env id: continuous actions and ``config``'s other keys."""
    return '{"config": {' + CONTINUOUS + (", " + config if config else "") + "}}"


def dmc(*flags: str) -> list[str]:
    """A short run (40 env steps) on dm_control's cartpole-swingup with ``flags``."""
    return tiny("--env", "dm_control/cartpole-swingup-v0", *SHORT, *flags)


def pendulum(*flags: str) -> list[str]:
    """A short run (40 env steps) on Gymnasium's Pendulum-v1 with ``flags``."""
    return tiny("--env", "Pendulum-v1", *SHORT, *flags)


# (command, argv, what the refusal names[, valid[, works]])
TRAIN_ENVS = [
    # Gymnasium classic control and MuJoCo: their own kwargs and render modes
    ("train", pendulum("--env-kwargs", '{"render_mode": "human"}'), "render_mode"),
    ("train", pendulum("--env-kwargs", '{"render_mode": "rgb_array"}'), "render_mode", True),
    ("train", pendulum("--env-kwargs", '{"render_mode": null}'), "render_mode", True),
    ("train", pendulum("--env-kwargs", '{"render_mode": "rgb_array_list"}'), "render_mode", True),
    ("train", pendulum("--env-kwargs", '{"g": 9.81}'), "", True),
    ("train", pendulum("--env-kwargs", '{"G": 9.81}'), "'G'"),
    ("train", pendulum("--env-kwargs", '{"width": 64, "height": 64}'), "width"),
    ("train", pendulum("--env-kwargs", '{"max_episode_steps": 2.5}'), "max_episode_steps"),
    ("train", pendulum("--action-repeat", "4"), "", True),
    ("train", tiny("--env", "MountainCarContinuous-v0", *SHORT, "--env-kwargs",
                   '{"max_episode_steps": 30}'), "", True),
    ("train", tiny("--env", "LunarLanderContinuous-v3", *SHORT), ("LunarLander", "box2d", "Box2D"),
     True),
    ("train", tiny("--env", "LunarLander-v3", "--env-kwargs", '{"continuous": true}', *SHORT),
     ("LunarLander", "box2d", "Box2D"), True),
    ("train", tiny("--env", "InvertedPendulum-v5", *SHORT), "", True),
    ("train", tiny("--env", "InvertedPendulum-v2", *SHORT), ("InvertedPendulum-v2", "mujoco")),
    ("train", tiny("--env", "phys2d/Pendulum-v0", *SHORT), ("phys2d", "jax")),
    # dm_control beyond the paper's six tasks, its kwargs and cameras
    ("train", tiny("--env", "dm_control/point_mass-easy-v0", *SHORT), "", True),
    ("train", dmc("--env-kwargs", '{"render_mode": "human"}'), "render_mode"),
    ("train", dmc("--env-kwargs", '{"task_kwargs": {"random": 3}}'), "task_kwargs", True),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"camera_id": 5}}'), ("camera_id", "camera")),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"width": 64, "height": 64}}'),
     ("render_kwargs", "width"), True),
    ("train", tiny("--env", "dm_control/reacher-easy-v0", "--cameras", "3", *SHORT), "cameras",
     True),
    ("train", dmc("--action-repeat", "8"), "", True),
    ("train", dmc("--action-repeat", "3"), "action_repeat", True),
    ("train", dmc("--action-repeat", "1000"), ("action_repeat", "total_env_steps")),
    ("train", dmc("--cameras", "2", "--grayscale"), "", True),
    ("train", dmc("--eval-distraction", "video_easy,color_hard"), "", True),
    ("train", dmc("--eval-distraction", "train"), "train", True),
    ("train", pendulum("--eval-distraction", "video_hard"), ("dm_control", "video_hard")),
    ("train", tiny("--eval-distraction", "none", *SHORT), ("none", "--eval-distraction"), True),
    ("train", tiny("--set", "eval_distraction=color_easy"), ("eval_distraction", "color_easy")),
    # highway-env: other ids, its config dict
    ("train", tiny("--env", "parking-v0", *SHORT), "parking", True),
    ("train", tiny("--env", "racetrack-v0", "--env-kwargs", '{"config": {"duration": 4}}', *SHORT),
     "racetrack", True),
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-fast-v0", "--env-kwargs",
                   '{"config": {"lanes_count": 2}}', *SHORT),
     ("ContinuousAction", "env_kwargs", "Discrete"), True),
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-v0", *SHORT), "preset", True),
    ("train", tiny("--env", "highway-fast-v0", "--env-kwargs", highway('"lanes_count": 0'),
                   *SHORT), "lanes_count"),
    ("train", tiny("--env", "highway-fast-v0", "--env-kwargs",
                   '{"config": {"action": {"type": "ContinousAction"}}}', *SHORT),
     "ContinousAction"),
    ("train", tiny("--env", "highway-fast-v0", "--env-kwargs", '{"lanes_count": 3}', *SHORT),
     ("lanes_count", "config")),
    ("train", tiny("--env", "highway-fast-v0", "--env-kwargs",
                   highway('"observation": {"type": "Kinematics"}'), *SHORT), "observation", True),
    # MiniGrid and the MODULE:ID form
    ("train", tiny("--env", "minigrid:MiniGrid-DoorKey-6x6"), ("MiniGrid-DoorKey-6x6", "v0")),
    ("train", tiny("--env", "minigrid:MiniGrid-Empty-5x5-v0", "--env-module", "ale_py"),
     ("--env-module", "ale_py")),
    ("train", tiny("--env", "simoun_agent.envs:simoun/PointReach-v0", "--env-module",
                   "simoun_agent.envs", *SHORT), "", True),
    # simoun/PointReach-v0's own kwargs
    ("train", tiny("--env-kwargs", '{"size": "32"}'), "size"),
    ("train", tiny("--env-kwargs", '{"max_steps": 5}', *SHORT), "", True),
    ("train", tiny("--env-kwargs", '{"size": 16}', "--image-size", "64", *SHORT), "size", True),
]  # fmt: skip
TRAIN_FLAGS = [
    # frame size and action repeat as other libraries spell them
    ("train", tiny("--frame-size", "64"), "--image-size"),
    ("train", tiny("--resolution", "64"), "--image-size"),
    ("train", tiny("--image-size", "84x84"), "--image-size"),
    ("train", tiny("--image-size", "64.0"), "--image-size"),
    ("train", tiny("--image-size", "-32"), ("image_size", "--image-size")),
    ("train", tiny("--image-size", "1024"), ("image_size", "replay", "memory")),
    ("train", tiny("--frame-skip", "4"), "--action-repeat"),
    ("train", tiny("--action-repeat", "-1"), ("action_repeat", "--action-repeat")),
    ("train", tiny("--action-repeat", "2.5"), "--action-repeat"),
    ("train", tiny("--set", "action_repeat=2.0"), "action_repeat"),
    # presets
    ("train", tiny("--preset", "cartpole_swingup"), ("cartpole_swingup", "preset")),
    ("train", tiny("--preset", "ball-in-cup-catch"), ("ball-in-cup-catch", "preset")),
    ("train", tiny("--preset", "cpu", "--env", "dm_control/walker-walk-v0", *SHORT), "", True),
    ("train", tiny("--preset", "walker-walk", "--env", "dm_control/walker-run-v0"),
     ("walker-walk", "walker-run")),
    ("train", tiny("--preset", "none", *SHORT), "preset", True),
    ("train", tiny("--preset", ""), "--preset"),
    ("train", tiny("--set", "preset=cpu", *SHORT), "preset", True),
    # recipes
    ("train", tiny("--agent.recipe", "drq-v2"), ("drq-v2", "recipe")),
    ("train", tiny("--agent.recipe", "rad,drq"), ("rad,drq", "recipe")),
    ("train", tiny("--agent.recipe", "simoun_no_aux", *SHORT), "", True),
    ("train", tiny("--set", "agent.recipe=drq", *SHORT), "", True),
    ("train", tiny("--agent.recipe", "simoun_no_interaction", "--agent.encoder",
                   "dual_interactive", *SHORT), "encoder", True),
    ("train", tiny("--agent.recipe", "drqv2_easy", "--env", "dm_control/cheetah-run-v0", *SHORT),
     "", True),
    ("train", tiny("--agent.recipe", "curl", "--agent.contrastive-weight", "0", *SHORT),
     "contrastive", True),
    ("train", tiny("--agent.recipe", "flare", "--agent.num-frames", "1"), "num_frames"),
    ("train", tiny("--agent.recipe", "sac", "--agent.augmentation", "shift", *SHORT), "", True),
    ("train", tiny("--agent.recipe", "simoun_no_curiosity", "--agent.curiosity-scale", "0.5",
                   *SHORT), "curiosity", True),
    # --set spellings
    ("train", tiny("--set", "agent.lr=3e-4", "agent.batch_size=8"), ("--set", "agent.batch_size")),
    ("train", tiny("--set", "agent.lr = 3e-4"), ("agent.lr", "--set")),
    ("train", tiny("--set", "agent.lr:3e-4"), "--set"),
    ("train", tiny("--set", "env_kwargs.size=32"), "env_kwargs"),
    ("train", tiny("--set", "agent.batch-size=8", *SHORT), ("batch_size", "batch-size"), True),
    ("train", tiny("--set", "--agent.lr=3e-4"), ("--set", "--agent.lr")),
    ("train", tiny("--set", "seed=0x10"), "seed"),
    # switches and values given both ways, or meant for one thing
    ("train", tiny("--no-video", "--video", *SHORT), "--video", True),
    ("train", tiny("--agent.curiosity", "--agent.no-curiosity", *SHORT), "curiosity", True),
    ("train", tiny("--env", "Pendulum-v1", "--set", "env=MountainCarContinuous-v0", *SHORT),
     "env", True),
    ("train", tiny("--warmup-agent-steps", "40", *SHORT), "warmup", True),
    ("train", tiny("--replay-capacity", "8", *SHORT), "", True),
    ("train", tiny("--checkpoint-every", "1", *SHORT), "", True),
    # help and version wherever they are typed
    ("train", ["-h"], "", True),
    ("train", ["--version", "--env", "nope"], "", True),
    ("train", ["--preset", "walker-walk", "--help"], "", True),
    ("train", ["--preset", "nope", "--help"], "nope", True),
    ("train", ["--version=1"], "--version"),
]  # fmt: skip
TRAIN_RESUME = [
    ("train", [*RESUME, "--eval-distraction", "color_easy"], ("color_easy", "dm_control")),
    ("train", ["--resume", "dmc", "--total-env-steps", "60", "--eval-distraction", "color_easy"],
     "", True, (DMC_RUN,)),
    ("train", ["--resume", "{run}", "--total-env-steps", "6e1"], "--total-env-steps"),
    ("train", [*RESUME, "--env-kwargs", "{}"], "env_kwargs", True),
    ("train", [*RESUME, "--seed", "1"], "seed", True),
    ("train", [*RESUME, "--agent.recipe", "simoun"], "recipe", True),
    ("train", [*RESUME, "--set", "total_env_steps=80"], "total_env_steps", True),
    ("train", [*RESUME, "--device", "cpu:0"], "device", True),
    ("train", [*RESUME, "--env-process"], "", True),
    ("train", [*RESUME, "--run-dir", "{run}"], ("--run-dir", "run_dir"), True),
    ("train", ["--resume", "{run}", "--resume", "{run}", "--total-env-steps", "60"], "", True),
    ("train", ["--resume", "{run}", "--help"], "", True),
    ("train", ["--resume={run}", "--total-env-steps=60"], "", True),
    ("train", [*RESUME, "--action-repeat", "none"], "action_repeat", True),
    ("train", [*RESUME, "--eval-every", "5"], "eval_every", True),
]  # fmt: skip
BAD_CLIP = put("v/clip.mp4", b"not a video at all\n")
EVALS = [
    # training flags given to the evaluation
    ("eval", eval_argv("--episodes", "1", "--env", "Pendulum-v1"), "--env"),
    ("eval", eval_argv("--episodes", "1", "--action-repeat", "2"), "--action-repeat"),
    ("eval", eval_argv("--episodes", "1", "--image-size", "64"), "--image-size"),
    ("eval", eval_argv("--episodes", "1", "--eval-episodes", "5"), "--episodes"),
    ("eval", eval_argv("--episodes", "1", "--set", "seed=2"), "--set"),
    ("eval", eval_argv("--episodes", "1", "--cameras", "2"), "--cameras"),
    # its own options, other spellings and edges
    ("eval", eval_argv("--episodes", "1", "--video-path", "x.mp4"), ("--video", "--out")),
    ("eval", eval_argv("--episodes", "1", "--render"), ("--render", "--video")),
    ("eval", eval_argv("--episodes", "1", "--deterministic"), "--deterministic"),
    ("eval", eval_argv("--episodes", "1", "--torch-threads", "2.0"), "--torch-threads"),
    ("eval", eval_argv("--episodes", "1", "--device", "cuda"), ("cuda", "device")),
    ("eval", eval_argv("--episodes", "1", "--seed", str(2**32 - 1)), "", True),
    ("eval", ["{run}", "--episodes", "1", "--video"], "", True),
    ("eval", eval_argv("--episodes", "1", "--random-policy", "--out", "o"), "", True),
    ("eval", eval_argv("--episodes", "1", "--out", "o", "--overwrite"), "", True),
    ("eval", ["{run}", "--episodes", "1", "--no-video", "--video"], "--video", True),
    ("eval", ["{run}", "--episodes", "0", "--help"], "", True),
    ("eval", ["{run}", "--version"], "", True),
    ("eval", ["-h"], "", True),
    ("eval", eval_argv("--episodes", "1", "--checkpoint", "{run}"), ("--checkpoint", "RUN")),
    # distraction modes and their videos
    ("eval", ["dmc", "--no-video", "--distraction", "all", "--episodes", "1"], "all", False,
     (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy", "--distraction", "color_hard",
              "--episodes", "1"], "--distraction", False, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "video_easy", "--videos", "dmc/config.json",
              "--episodes", "1"], "--videos", False, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "video_easy", "--videos", "v",
              "--episodes", "1"], ("clip.mp4", "--videos"), False, (DMC_RUN, video_dir, BAD_CLIP)),
    ("eval", ["dmc", "--no-video", "--distraction", "train", "--seed", "5", "--episodes", "1"],
     "", True, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy", "--episodes", "1", "--out",
              "dmc/config.json"], "--out", False, (DMC_RUN,)),
]  # fmt: skip
CASES: list[dict] = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in TRAIN_ENVS + TRAIN_FLAGS + TRAIN_RESUME + EVALS
]
