"""The eleventh reliability trial's cases: agent (see reliability_trial.py).

simoun-train and simoun-eval on surfaces the earlier trials left out: MuJoCo ids no trial ran
(Hopper, Walker2d, InvertedDoublePendulum, a v3 id that needs mujoco-py) and their own keywords (a
health range of one number or reversed, a switch or a reward given as text, a reward weight null, a
frame skip with a fraction, a height of 0, both camera keywords at once, a camera by its name, a
width alone, a free-camera setting of the wrong type, a model file under ~); dm_control tasks a
domain has not (cheetah-walk, finger-turn, reacher-medium), a capital V in the version, task_kwargs
that are no dict or hold a keyword the task has not, a time limit where the task takes it, a flag
given as text, a render keyword it does not take, a camera by a name and a camera id beside
--cameras; highway-env's v1 ids and the multi-agent intersection, a highway preset on a v1 id and
on merge, config keys that open a window (manual control, onscreen rendering), an action with no
axis, a steering range reversed, a speed range of one number, a null config, no controlled vehicle,
a destination the intersection has not, more parked cars than places, the package's pip name as
--env-module, and its env stepped in a background process; Box2D, Atari and Gymnasium-Robotics ids
without their packages; PointReach's keywords at zero or capitalised, JSON with typographic quotes
or Python's True; rendering back-ends that are known but cannot run here (glfw without a display,
osmesa without its library), egl, and SDL's video driver set for a display; train given eval's
flags and eval train's (--out, --distraction, --videos, --random-policy, --eval-distraction,
--total-env-steps), other libraries' flags no trial typed (--track, --config, --checkpoint,
--render, --max-episode-steps, --render-mode, --stochastic), a switch negated in the wrong place, a
flag in capitals or joined by a colon, British spelling, a preset in capitals; agent fields at
edges or set for a part the run does not use (zero exploration noise and shift pad, a temperature
for a deterministic actor, exploration for a Gaussian one, four stacked frames, curiosity with
DrQ-v2); --set of eval's key, of a discount out of range and of two encoders; --resume of a sweep
directory, a study archive and a glob, of runs of other families (highway-env, its config or
cameras changed; MuJoCo, another version of its id), fields given the run's values in other
spellings (--no-grayscale, a seed with a leading zero, --preset none, dm_control's action repeat
given as the value it resolved to, the env's default keyword given explicitly); a --run-dir that
holds a sweep or an empty folder; and simoun-eval of a sweep directory, an evaluation's output, a
glob, runs of highway-env and MuJoCo (each under --distraction too), a dm_control run under a
back-end that cannot run, its checkpoint under --distraction, --videos given a damaged clip, a real
clip, a single file and a DAVIS folder of files that are no pictures, an empty --out folder,
--episodes and --seed in scientific notation and with a fraction, and simoun-sweep's --seeds.
"""

import os
from pathlib import Path

import numpy as np
from reliability_trial import (
    ARCH,
    DMC_RUN,
    EVAL,
    SHORT,
    SW,
    eval_argv,
    evaluated,
    fifth,
    tiny,
    trained,
)

CONTINUOUS = '"action": {"type": "ContinuousAction"}'
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]
DMC_EVAL = ["dmc", "--no-video", "--episodes", "1"]


def highway(config: str) -> str:
    """--env-kwargs of a highway-env id: continuous actions and ``config``'s other keys."""
    return '{"config": {' + CONTINUOUS + (", " + config if config else "") + "}}"


HW_RUN = trained("hw", "--env", "highway-fast-v0", "--env-kwargs", highway('"duration": 4'))
MJ_RUN = trained("mj", "--env", "InvertedPendulum-v5")


def env(name: str, *flags: str) -> list[str]:
    """A short run (40 env steps) on ``name`` with ``flags``."""
    return tiny("--env", name, *SHORT, *flags)


def kwargs(name: str, text: str, *flags: str) -> list[str]:
    """A short run on ``name`` with ``text`` as --env-kwargs."""
    return env(name, "--env-kwargs", text, *flags)


def fast(config: str) -> list[str]:
    """A short run on highway-fast-v0 with ``config`` beside continuous actions."""
    return kwargs("highway-fast-v0", highway(config))


def cheetah(text: str) -> list[str]:
    """A short run on MuJoCo's HalfCheetah-v5 with ``text``'s keywords and 50-step episodes (its
    1000-step evaluations would outlast the case)."""
    return kwargs("HalfCheetah-v5", '{"max_episode_steps": 50, ' + text + "}")


def dmc(text: str) -> list[str]:
    """A short run on dm_control's cartpole-swingup with ``text`` as --env-kwargs."""
    return kwargs("dm_control/cartpole-swingup-v0", text)


def short(*words: str) -> list[str]:
    """A short run on PointReach with ``words`` typed after TINY's flags."""
    return [*tiny(*SHORT), *words]


def variable(name: str, value: str):
    """Work: the environment variable ``name`` set to ``value`` in the case's process."""
    return lambda here: os.environ.update({name: value})


def folder(name: str):
    """Work: an empty folder ``name``."""
    return lambda here: (here / name).mkdir(parents=True)


def clip(here: Path) -> None:
    """``v/clip.mp4``: a real video of 12 grey frames, 64x64."""
    import imageio.v2 as imageio

    (here / "v").mkdir(exist_ok=True)
    frames = [np.full((64, 64, 3), 20 * i, np.uint8) for i in range(12)]
    imageio.mimwrite(here / "v/clip.mp4", frames, fps=10)


def damaged_clip(here: Path) -> None:
    """``v/clip.mp4``: an MP4 header followed by bytes that are no video (a cut download)."""
    (here / "v").mkdir()
    (here / "v/clip.mp4").write_bytes(b"\x00\x00\x00\x18ftypmp42" + bytes(range(256)) * 4)


def davis_text(here: Path) -> None:
    """``frames/bear``: a DAVIS-style folder whose .jpg files hold text."""
    (here / "frames/bear").mkdir(parents=True)
    for i in range(3):
        (here / f"frames/bear/{i:05d}.jpg").write_text("not a picture\n")


# (command, argv, what the refusal names[, valid[, works]])
FAMILIES = [
    # MuJoCo: ids no trial ran, their own keywords
    ("train", env("Hopper-v5"), "", True),
    ("train", env("HalfCheetah-v3"), ("HalfCheetah-v3", "mujoco")),
    ("train", kwargs("Walker2d-v5", '{"healthy_z_range": [0.8]}'), "healthy_z_range"),
    ("train", kwargs("Hopper-v5", '{"terminate_when_unhealthy": "false"}'),
     "terminate_when_unhealthy"),
    ("train", kwargs("HalfCheetah-v5", '{"camera_id": 0, "camera_name": "track"}'),
     ("camera_id", "camera_name")),
    ("train", cheetah('"camera_name": "track"'), "camera_name", True),
    ("train", kwargs("HalfCheetah-v5", '{"default_camera_config": {"distance": "far"}}'),
     ("default_camera_config", "distance")),
    ("train", cheetah('"width": 64'), "width", True),
    ("train", kwargs("HalfCheetah-v5", '{"ctrl_cost_weight": null}'), "ctrl_cost_weight"),
    ("train", kwargs("InvertedDoublePendulum-v5", '{"healthy_reward": "10"}'), "healthy_reward"),
    ("train", kwargs("Walker2d-v5", '{"frame_skip": 4.5}'), "frame_skip"),
    ("train", kwargs("HalfCheetah-v5", '{"height": 0}'), "height"),
    ("train", kwargs("Hopper-v5", '{"healthy_angle_range": [0.2, -0.2]}'), "healthy_angle_range"),
    ("train", kwargs("Hopper-v5", '{"xml_file": "~/models/hopper.xml"}'), ("xml_file", "~")),
    # dm_control: tasks a domain has not, tasks no trial ran, task keywords
    ("train", env("dm_control/cheetah-walk-v0"), ("cheetah-walk", "cheetah-run")),
    ("train", env("dm_control/finger-turn-v0"), ("finger-turn", "turn_easy")),
    ("train", env("dm_control/reacher-medium-v0"), ("reacher-medium", "reacher-easy")),
    ("train", env("dm_control/cartpole-swingup-V0"), ("V0", "cartpole-swingup-v0")),
    ("train", dmc('{"task_kwargs": {"swing_up": false}}'), "swing_up"),
    ("train", dmc('{"task_kwargs": 3}'), "task_kwargs"),
    ("train", dmc('{"task_kwargs": {"time_limit": 5}}'), "time_limit", True),
    ("train", dmc('{"environment_kwargs": {"flat_observation": "yes"}}'), "flat_observation",
     True),
    ("train", dmc('{"render_kwargs": {"scene_option": {"flags": 1}}}'), "scene_option"),
    ("train", dmc('{"render_kwargs": {"camera_id": "side"}}'), ("camera_id", "side")),
    ("train", env("dm_control/cartpole-swingup-v0", "--cameras", "2", "--env-kwargs",
                  '{"render_kwargs": {"camera_id": 1}}'), ("camera_id", "cameras")),
    # highway-env: v1 ids, ids no trial ran, presets on them
    ("train", kwargs("merge-v1", highway("")), "merge-v1", True),
    ("train", tiny("--preset", "highway-cpu", "--env", "racetrack-v1", *SHORT),
     ("preset", "racetrack"), True),
    ("train", tiny("--preset", "highway", "--env", "merge-v0", *SHORT), ("preset", "merge"), True),
    ("train", env("intersection-multi-agent-v1"), "intersection-multi-agent-v1"),
    # highway-env: config keys that open a window, actions without an axis, ranges, null
    ("train", fast('"manual_control": true'), "manual_control"),
    ("train", fast('"offscreen_rendering": false'), "offscreen_rendering", True),
    ("train", kwargs("highway-fast-v0", '{"config": {"action": {"type": "ContinuousAction", '
                     '"lateral": false, "longitudinal": false}}}'), ("lateral", "longitudinal")),
    ("train", kwargs("highway-fast-v0", '{"config": {"action": {"type": "ContinuousAction", '
                     '"steering_range": [0.5, -0.5]}}}'), "steering_range"),
    ("train", fast('"reward_speed_range": [20]'), "reward_speed_range"),
    ("train", fast('"controlled_vehicles": 0'), "controlled_vehicles"),
    ("train", kwargs("intersection-v1", highway('"destination": "o9"')), "destination", True),
    ("train", kwargs("highway-fast-v0", '{"config": null}'), "config"),
    ("train", kwargs("parking-v0", '{"config": {"vehicles_count": 100}}'), "vehicles_count",
     True),
    ("train", kwargs("highway-fast-v0", highway(""), "--env-module", "highway-env"),
     ("highway-env", "highway_env")),
    ("train", kwargs("highway-fast-v0", highway('"duration": 4'), "--env-process"), "", True),
    # Box2D and Atari without their packages, PointReach's keywords
    ("train", env("BipedalWalker-v3"), ("box2d", "Box2D")),
    ("train", env("ALE/Pong-v5"), ("ale_py", "ale-py")),
    ("train", env("gymnasium_robotics:FetchReach-v4"), ("gymnasium_robotics", "robotics")),
    ("train", tiny("--env-kwargs", '{"step_size": 0}'), "step_size"),
    ("train", tiny("--env-kwargs", '{"Size": 32}'), "Size"),
    ("train", tiny("--env-kwargs", '{\u201csize\u201d: 32}'), "--env-kwargs"),
    ("train", dmc('{"visualize_reward": True}'), "--env-kwargs"),
    # rendering back-ends known but unable to run here, SDL's driver set for a display
    ("train", env("HalfCheetah-v5"), "MUJOCO_GL", False, (variable("MUJOCO_GL", "glfw"),)),
    ("train", env("dm_control/cartpole-swingup-v0"), "MUJOCO_GL", True,
     (variable("MUJOCO_GL", "egl"),)),
    ("train", env("dm_control/cartpole-swingup-v0"), "MUJOCO_GL", False,
     (variable("MUJOCO_GL", "osmesa"),)),
    ("train", fast(""), "SDL_VIDEODRIVER", True, (variable("SDL_VIDEODRIVER", "x11"),)),
]  # fmt: skip
FLAGS = [
    # the other command's flags, a switch negated in the wrong place, other spellings
    ("train", short("--out", "o"), "--run-dir"),
    ("train", short("--distraction", "color_easy"), "--eval-distraction"),
    ("train", short("--videos", "v"), "--videos"),
    ("train", short("--random-policy"), "--random-policy"),
    ("train", short("--no-agent.curiosity"), "curiosity", True),
    ("train", short("--agent.LR", "1e-3"), "--agent.lr"),
    ("train", short("--Seed", "3"), "--seed"),
    ("train", short("--agent.lr:1e-3"), "--agent.lr"),
    ("train", short("--greyscale"), "--grayscale"),
    ("train", short("--agent.no-channel-last"), "--agent.no-channels-last"),
    ("train", short("--preset", "Highway-CPU"), ("Highway-CPU", "highway-cpu")),
    # other libraries' flags no trial typed: tracking, a config file, a checkpoint to start from
    ("train", short("--track"), "--track"),
    ("train", short("--config", "cfg.yaml"), "--config"),
    ("train", short("--checkpoint", "{run}/checkpoint.pt"), ("--checkpoint", "--resume")),
    ("train", short("--render"), ("--render", "--video")),
    ("train", short("--max-episode-steps", "100"), ("--max-episode-steps", "max_episode_steps")),
    # agent fields at edges, or set for a part the run does not use
    ("train", tiny("--agent.recipe", "drqv2", "--agent.curiosity"), "curiosity"),
    ("train", tiny("--agent.augmentation", "shift", "--agent.shift-pad", "0", *SHORT),
     "shift_pad", True),
    ("train", tiny("--agent.actor", "deterministic", "--agent.exploration-std-start", "0",
                   "--agent.exploration-std-end", "0", *SHORT), "exploration_std", True),
    ("train", tiny("--agent.encoder", "stacked", "--agent.num-frames", "4", *SHORT),
     ("curiosity", "num_frames"), True),
    ("train", tiny("--agent.actor", "deterministic", "--agent.init-temperature", "0.5", *SHORT),
     "init_temperature", True),
    ("train", tiny("--agent.exploration-std-start", "0.5", *SHORT), "exploration_std_start", True),
    # --set of eval's keys, a value out of range, the run directory
    ("train", tiny("--set", "episodes=3"), "episodes"),
    ("train", tiny("--set", "agent.discount=1.5"), "discount"),
    ("train", tiny("--set", "agent.encoder=stacked,dual"), "encoder"),
    ("train", tiny("--set", "distraction=color_easy"), ("'distraction'", "eval_distraction")),
]  # fmt: skip
RUNS = [
    # runs of other kinds: a sweep, a study archive, a glob
    ("train", ["--resume", "sw", "--total-env-steps", "60"], "sw", False, (SW,)),
    ("train", ["--resume", "arch", "--total-env-steps", "60"], "arch", False, (ARCH,)),
    ("train", ["--resume", "ru*", "--total-env-steps", "60"], "ru*"),
    # runs of other families
    ("train", ["--resume", "hw", "--total-env-steps", "60"], "", True, (HW_RUN,)),
    ("train", ["--resume", "hw", "--total-env-steps", "60", "--env-kwargs",
               highway('"lanes_count": 2')], "env_kwargs", False, (HW_RUN,)),
    ("train", ["--resume", "hw", "--total-env-steps", "60", "--cameras", "3"], "cameras", False,
     (HW_RUN,)),
    ("train", ["--resume", "mj", "--total-env-steps", "60", "--env", "InvertedPendulum-v4"],
     ("env", "InvertedPendulum-v4"), False, (MJ_RUN,)),
    # fields given the run's values in other spellings
    ("train", [*RESUME, "--no-grayscale"], "grayscale", True),
    ("train", ["--resume", "dmc", "--total-env-steps", "60", "--action-repeat", "8"],
     "action_repeat", True, (DMC_RUN,)),
    ("train", [*RESUME, "--seed", "01"], "seed", True),
    ("train", [*RESUME, "--preset", "none"], "preset", True),
    ("train", [*RESUME, "--env-kwargs", '{"max_steps": 20}'], "env_kwargs", True),
    # a --run-dir that holds a sweep, or nothing
    ("train", tiny("--run-dir", "sw", "--total-env-steps", "40"), ("sw", "--run-dir"), False,
     (SW,)),
    ("train", tiny("--run-dir", "e", "--total-env-steps", "40"), "", True, (folder("e"),)),
]  # fmt: skip
EVALS = [
    # what is not a run: a sweep, an evaluation's output, a glob
    ("eval", ["sw", *EVAL], "sw", False, (SW,)),
    ("eval", ["o", *EVAL], ("'o'", "o/", "checkpoint"), False, (evaluated,)),
    ("eval", ["ru*", *EVAL], "ru*"),
    # runs of other families, one under --distraction; a back-end that cannot run
    ("eval", ["hw", *EVAL], "", True, (HW_RUN,)),
    ("eval", ["hw", *EVAL, "--distraction", "color_easy"], ("dm_control", "highway"), False,
     (HW_RUN,)),
    ("eval", ["mj", *EVAL], "", True, (MJ_RUN,)),
    ("eval", DMC_EVAL, "MUJOCO_GL", False, (DMC_RUN, variable("MUJOCO_GL", "glfw"))),
    # --distraction with the checkpoint, --videos of a damaged clip, a real one, a file, frames
    ("eval", ["dmc/checkpoint.pt", *EVAL, "--distraction", "color_easy"], "", True, (DMC_RUN,)),
    ("eval", [*DMC_EVAL, "--distraction", "video_easy", "--videos", "v"],
     ("clip.mp4", "--videos"), False, (DMC_RUN, damaged_clip)),
    ("eval", [*DMC_EVAL, "--distraction", "video_hard", "--videos", "v"], "", True,
     (DMC_RUN, clip)),
    ("eval", [*DMC_EVAL, "--distraction", "video_easy", "--videos", "v/clip.mp4"],
     ("--videos", "clip.mp4"), True, (DMC_RUN, clip)),
    ("eval", [*DMC_EVAL, "--distraction", "video_easy", "--videos", "frames"],
     ("00000.jpg", "bear", "--videos"), False, (DMC_RUN, davis_text)),
    # the other command's flags, spellings and valid edges
    ("eval", [*eval_argv("--episodes", "1"), "--eval-distraction", "color_easy"],
     "--distraction"),
    ("eval", eval_argv("--episodes", "1", "--total-env-steps", "40"), "--total-env-steps"),
    ("eval", ["{run}", "--episodes", "1e1", "--no-video"], "--episodes"),
    ("eval", eval_argv("--episodes", "1", "--render-mode", "human"), "--render-mode"),
    ("eval", eval_argv("--episodes", "1", "--stochastic"), "--stochastic"),
    ("eval", eval_argv("--episodes", "1", "--seed", "3.5"), "--seed"),
    ("eval", eval_argv("--episodes", "3", "--seeds", "1,2,3"), ("--seeds", "--seed")),
    ("eval", ["mj", *EVAL, "--distraction", "video_hard"], ("dm_control", "InvertedPendulum"),
     False, (MJ_RUN,)),
    ("eval", eval_argv("--episodes", "1", "--out", "o"), "", True, (folder("o"),)),
]  # fmt: skip
CASES: list[dict] = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in FAMILIES + FLAGS + RUNS + EVALS
]
