"""The ninth reliability trial's cases: agent (see reliability_trial.py).

simoun-train and simoun-eval on kinds and surfaces the earlier trials left out, above all the
newest checks: frame sizes at their edges against the encoder's convs, the random convolution's
kernel where no random convolution is made (a shift view, no L_con), and dm_control renders
made negative or fractional; highway-env config limits on keys and tasks no trial gave a value
(a policy frequency above the task's default simulation frequency, fractions of lanes and
vehicles, a switch where a count goes, strings where a number or a switch goes, a misspelt key,
a lane that does not exist, reversed ranges, a config given as a file name, the intersection's
spawn probability and vehicles, the racetrack's speed limit and other vehicles, the viewer's
scale and screen, a preset's config crossed with the user's); bare KEY=VALUE words in new places
(first on the line, after a switch of another key, with a leading + or after --, given to
simoun-eval, with --resume); --set of command flags other than --resume (--overwrite, --help,
--version), of misspelt keys (no section, a capital, an underscore for the dot, no value), of a
dict in Python's spelling and of a British distraction word; presets crossed with other env
families; recipes with fields at their edges or that they do not use; --resume with flags it
keeps given their own values, another seed or env, a count in exponent form, --set of a field it
may change, and a checkpoint path with a trailing slash; ids of dm_control, MuJoCo, highway-env
and MiniGrid in forms not tried (hyphens for underscores, the family left out, MODULE:ID of the
family's package); --env-kwargs of another family's config or in YAML; outputs under /proc; and
simoun-eval with train's flags (--env-kwargs, --resume), --distraction words (all, capitals,
train on a run that is not dm_control), runs joined by a comma, its --torch-threads under
--distraction, a short -n and a device in capitals.
"""

from reliability_trial import DMC_RUN, SHORT, eval_argv, fifth, tiny

CONTINUOUS = '"action": {"type": "ContinuousAction"}'
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]
DMC_EVAL = ["dmc", "--no-video", "--episodes", "1"]


def highway(config: str) -> str:
    """--env-kwargs of a highway-env id: continuous actions and ``config``'s other keys."""
    return '{"config": {' + CONTINUOUS + (", " + config if config else "") + "}}"


def env(name: str, *flags: str) -> list[str]:
    """A short run (40 env steps) on ``name`` with ``flags``."""
    return tiny("--env", name, *SHORT, *flags)


def fast(config: str) -> list[str]:
    """A short run on highway-fast-v0 (5 simulation steps, 1 decision per second) with ``config``
    beside continuous actions."""
    return env("highway-fast-v0", "--env-kwargs", highway(config))


def dmc(*flags: str) -> list[str]:
    """A short run (40 env steps) on dm_control's cartpole-swingup with ``flags``."""
    return env("dm_control/cartpole-swingup-v0", *flags)


# (command, argv, what the refusal names[, valid[, works]])
FRAMES = [
    # the random convolution's kernel: edges, and where no random convolution is made
    ("train", tiny("--agent.random-conv-kernel", "31", *SHORT), "random_conv_kernel", True),
    ("train", tiny("--agent.random-conv-kernel", "-3"), "random_conv_kernel"),
    ("train", tiny("--agent.random-conv-kernel", "33", "--agent.contrastive-view", "shift",
                   *SHORT), "random_conv_kernel", True),
    ("train", tiny("--agent.random-conv-kernel", "33", "--agent.contrastive-weight", "0", *SHORT),
     "random_conv_kernel", True),
    # frame sides at the encoder's smallest and one below
    ("train", tiny("--image-size", "19", *SHORT), "image_size", True),
    ("train", tiny("--image-size", "18"), ("image_size", "--image-size")),
    ("train", tiny("--agent.recipe", "stacked", "--image-size", "15", *SHORT), "image_size",
     True),
    ("train", tiny("--agent.reduce-kernel", "10", "--agent.reduce-stride", "1"),
     ("reduce_kernel", "--agent.reduce-kernel")),
    ("train", tiny("--cameras", "3", "--image-size", "12"), ("image_size", "--image-size")),
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-fast-v0", "--image-size", "12"),
     ("image_size", "--image-size")),
    # dm_control renders made tiny or negative
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"width": 12, "height": 12}}'), "height",
     True),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"height": -1}}'), "height"),
    ("train", dmc("--env-kwargs", '{"render_kwargs": {"height": 84.5}}'), "height"),
    ("train", dmc("--env-kwargs", '{"environment_kwargs": {"n_sub_steps": 0}}'), "n_sub_steps"),
]  # fmt: skip
HIGHWAY = [
    # the frequencies against the task's own defaults (5 simulation steps per second)
    ("train", fast('"policy_frequency": 10'), ("policy_frequency", "simulation_frequency")),
    ("train", fast('"simulation_frequency": 3'), "simulation_frequency", True),
    # counts given as fractions, switches or misspelt keys
    ("train", fast('"lanes_count": 2.5'), "lanes_count"),
    ("train", fast('"lanes_count": true'), "lanes_count"),
    ("train", fast('"vehicles_count": 0'), "vehicles_count", True),
    ("train", fast('"vehicles_density": 0'), "vehicles_density"),
    ("train", fast('"controlled_vehicles": 2'), "controlled_vehicles"),
    ("train", fast('"lane_count": 4'), ("lane_count", "lanes_count")),
    ("train", fast('"collision_reward": "-1"'), "collision_reward"),
    ("train", fast('"scaling": 0'), "scaling"),
    ("train", fast('"policy_frequency": "5"'), "policy_frequency"),
    ("train", fast('"offroad_terminal": "yes"'), "offroad_terminal"),
    ("train", fast('"initial_lane_id": 5'), "initial_lane_id"),
    ("train", fast('"reward_speed_range": [30, 20]'), "reward_speed_range"),
    ("train", env("highway-fast-v0", "--env-kwargs", '{"config": {"action": {"type": '
                  '"ContinuousAction", "acceleration_range": [5, -5]}}}'), "acceleration_range"),
    ("train", fast('"screen_width": 10'), "screen_width", True),
    ("train", env("highway-fast-v0", "--env-kwargs", '{"config": "highway.json"}'),
     ("config", "highway.json")),
    # other tasks' own keys
    ("train", env("intersection-v0", "--env-kwargs", highway('"spawn_probability": 1.5')),
     "spawn_probability"),
    ("train", env("intersection-v0", "--env-kwargs", highway('"initial_vehicle_count": -1')),
     "initial_vehicle_count"),
    ("train", env("racetrack-v0", "--env-kwargs", '{"config": {"speed_limit": -10}}'),
     "speed_limit"),
    ("train", env("racetrack-v0", "--env-kwargs", '{"config": {"other_vehicles": 2.5}}'),
     "other_vehicles"),
    # a preset's config crossed with the user's
    ("train", tiny("--preset", "highway-cpu", "--env", "highway-fast-v0", "--env-kwargs",
                   '{"config": {"policy_frequency": 50}}', *SHORT), "policy_frequency"),
]  # fmt: skip
WORDS = [
    # bare KEY=VALUE words in new places
    ("train", ["seed=3", *tiny(*SHORT)], ("seed=3", "--set")),
    ("train", [*tiny("--grayscale"), "image_size=48"], ("image_size=48", "--set")),
    ("train", [*tiny(), "+seed=3"], ("+seed=3", "--set")),
    ("train", [*tiny(), "preset=cpu"], ("preset=cpu", "--preset")),
    ("train", [*RESUME, "agent.lr=1e-3"], ("agent.lr=1e-3", "--set")),
    ("eval", ["{run}", "episodes=1", "--no-video"], ("episodes=1", "--episodes")),
    # the flags' own = form, valid
    ("train", tiny("--agent.recipe=drq", "--seed=3", *SHORT), "", True),
    # --set of command flags and of misspelt keys
    ("train", tiny("--set", "overwrite=true"), ("overwrite", "--overwrite")),
    ("train", tiny("--set", "help=true"), ("help", "--help")),
    ("train", tiny("--set", "version=1"), ("version", "--version")),
    ("train", tiny("--set", "recipe=drq"), ("recipe", "agent.recipe")),
    ("train", tiny("--set", "Seed=3"), ("Seed", "seed")),
    ("train", tiny("--set", "agent_lr=1e-3"), ("agent_lr", "agent.lr")),
    ("train", tiny("--set", "agent.lr"), ("agent.lr", "--set")),
    ("train", [*tiny(), "--", "agent.lr=1e-3"], ("agent.lr=1e-3", "--set")),
    ("train", tiny("--set", "env_kwargs={'size': 32}"), "env_kwargs"),
    ("train", dmc("--set", "eval_distraction=colour_easy"), ("colour_easy", "color_easy")),
    ("train", tiny("--set", "preset=highway_cpu"), ("highway_cpu", "highway-cpu")),
    # --set of keys it takes, in forms the flags take
    ("train", tiny("--set", 'env_kwargs={"max_steps": 5}', *SHORT), "env_kwargs", True),
]  # fmt: skip
COMBOS = [
    # presets with envs of another family
    ("train", tiny("--preset", "highway-cpu", "--env", "dm_control/cartpole-swingup-v0", *SHORT),
     ("highway-cpu", "preset")),
    ("train", tiny("--preset", "cpu", "--env", "highway-fast-v0", *SHORT),
     ("Discrete", "ContinuousAction")),
    # recipes: names in capitals, fields at their edges or that the recipe does not use
    ("train", tiny("--agent.recipe", "DrQ"), ("DrQ", "drq")),
    ("train", tiny("--agent.recipe", "flare", "--agent.num-frames", "2", *SHORT), "num_frames",
     True),
    ("train", tiny("--agent.recipe", "drqv2", "--agent.exploration-steps", "40", *SHORT),
     "exploration_steps", True),
    ("train", tiny("--agent.recipe", "rad", "--agent.contrastive-step", *SHORT),
     "contrastive_step", True),
    # ids of the families in forms not tried
    ("train", env("dm_control/ball_in_cup-catch-v0"), "", True),
    ("train", env("dm_control/ball-in-cup-catch-v0"), ("ball-in-cup", "ball_in_cup")),
    ("train", env("cartpole-swingup"), ("cartpole-swingup", "dm_control")),
    ("train", env("dm_control:cartpole-swingup-v0"), ("dm_control:cartpole-swingup-v0",
                                                      "dm_control/")),
    ("train", env("Reacher-v5"), "", True),
    ("train", env("highway_env:highway-fast-v0", "--env-kwargs", highway("")), "", True),
    ("train", env("MiniGrid-LavaCrossingS9N1-v0", "--env-module", "minigrid"),
     ("Discrete", "MiniGrid")),
    # --env-kwargs of another family's config, or in YAML
    ("train", env("Pendulum-v1", "--env-kwargs", highway("")), ("config", "Pendulum")),
    ("train", tiny("--env-kwargs", "size: 32"), "--env-kwargs"),
    # outputs where none can be written
    ("train", tiny("--run-dir", "/proc/r", "--total-env-steps", "40"), ("--run-dir", "/proc")),
]  # fmt: skip
RUNS = [
    # --resume with flags it keeps given their own values, and with others
    ("train", [*RESUME, "--env", "simoun/PointReach-v0"], "env", True),
    ("train", [*RESUME, "--agent.lr", "1e-3"], "lr", True),
    ("train", [*RESUME, "--seed", "2"], "seed"),
    ("train", [*RESUME, "--env", "Pendulum-v1"], ("env", "Pendulum")),
    ("train", [*RESUME, "--set", "eval_every=20"], "eval_every", True),
    ("train", [*RESUME, "--set", "torch_threads=0"], "torch_threads"),
    ("train", [*RESUME, "--checkpoint-every", "1e3"], "--checkpoint-every"),
    ("train", ["--resume", "{run}/checkpoint.pt/", "--total-env-steps", "60"],
     ("checkpoint.pt", "--resume"), True),
]  # fmt: skip
EVALS = [
    # train's flags given to simoun-eval
    ("eval", eval_argv("--episodes", "1", "--env-kwargs", '{"size": 16}'), "--env-kwargs"),
    ("eval", eval_argv("--episodes", "1", "--resume", "{run}"), "--resume"),
    ("eval", ["{run}", "--no-video", "-n", "1"], ("-n", "--episodes")),
    # --distraction's words
    ("eval", [*DMC_EVAL, "--distraction", "all"], ("all", "--distraction"), False, (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "TRAIN"], ("TRAIN", "train"), False, (DMC_RUN,)),
    ("eval", eval_argv("--episodes", "1", "--distraction", "train"), ("dm_control", "train"),
     True),
    ("eval", [*DMC_EVAL, "--distraction", "color_easy", "--torch-threads", "1"],
     "--torch-threads", False, (DMC_RUN,)),
    ("eval", ["dmc,dmc", "--no-video", "--episodes", "1", "--distraction", "color_easy"],
     "dmc,dmc", False, (DMC_RUN,)),
    # values its help documents, and edges
    ("eval", eval_argv("--episodes", "1", "--device", "CPU"), ("CPU", "device"), True),
    ("eval", eval_argv("--episodes", "1", "--out", "/proc/o"), ("--out", "/proc")),
]  # fmt: skip
CASES: list[dict] = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in FRAMES + HIGHWAY + WORDS + COMBOS + RUNS + EVALS
]
