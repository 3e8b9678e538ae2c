"""The ninth reliability trial's cases: lab (see reliability_trial.py).

The lab's command lines on surfaces the earlier trials left alone, the newest checks first:
simoun-sweep's checks of simoun-train run on every trial (an evaluation distraction given as the
base flag, a budget shorter than one decision, frames too small for the encoder, a replay of one
transition, each given by a flag or by a --grid key), --gpus-per-trial against --device, MPS and
a --grid of devices (also on --resume of a CPU sweep), --grid values written as tuples, quoted
lists, reversed or dotted ranges and JSON with commas, --seeds and --envs as bracketed lists or
with repeats; simoun-study plan, run and report given a study's record (study.json,
selection.json) as a spec, an archive of another study (with --allow-other-commit, of another
family, a part of an archive, the study directory as its own archive); simoun-report on the
drqv2-easy archive, a sweep's variant folder, a MiniGrid run and a report folder, with budgets
in units; the MiniGrid study's run, select and report on a DMC archive, a study record as --spec,
and probe settings outside MiniGrid or with no sub-envs. The studies' spec files edited by hand
in new ways: a device in [base] or per task against gpus_per_trial, config keys the study sets
itself (seed, total_env_steps, run_dir), budgets shorter than one decision, phase keys of the
wrong type, per-task tables of a task no phase runs, repeated recipes, a byte-order mark and
tabs; the MiniGrid JSON spec with comments, string numbers, seeds as a range, an evaluation seed
inside the training seeds, no arms and an arm of PPO with a scale."""

from __future__ import annotations

import json

from reliability_trial import (
    ARCH,
    DMC100K,
    HIGHWAY_SPEC,
    MGT,
    MGT_SPEC,
    SMALL_PROBE,
    SPEC,
    STUDIES,
    SW,
    fifth,
    lab_copy,
    probe,
    put,
    small_probe,
    sweep_tiny,
)

EZ_SPEC = (STUDIES / "dmc100k-drqv2-easy.toml").read_text()
EZ_NAME = "dmc100k-drqv2-easy.toml"  # a study is named for its spec file
EZ = lab_copy("dmc100k-drqv2-easy", "ez")
EZ_FILE = put(EZ_NAME, EZ_SPEC)
HIGHWAY = put("highway.toml", HIGHWAY_SPEC)
MGT_FILE = put("mgt.json", MGT_SPEC)
SHORT = ("--total-env-steps", "40")
RESUME = ["--resume", "--sweep-dir", "sw"]
MGT_RUN = "mgt/MiniGrid-DoorKey-6x6-v0/ppo/s100"


def bare(flag: str, *extra: str) -> list[str]:
    """The tiny sweep's flags (40 env steps) with ``extra``, less the base ``flag`` and its value:
    the key a case gives in --grid (or --envs) is not given as a base flag too."""
    flags = sweep_tiny(*SHORT, *extra)
    at = flags.index(flag)
    return flags[:at] + flags[at + 2 :]


def gpu_spec(*lines: str) -> str:
    """The DMC study's spec with ``lines`` added after its [resources] table's last line."""
    old = "max_concurrent_trials = 2   # two runs at a time on a 2-core machine"
    return SPEC.replace(old, "\n".join((old, *lines)), 1)


# command lines: (command, argv, what the refusal names[, valid[, works]])
FLAGS = [
    # simoun-sweep: simoun-train's checks on every trial, before Ray starts (the guard)
    ("sweep", sweep_tiny("--eval-distraction", "color_hard", *SHORT),
     ("color_hard", "dm_control")),
    ("sweep", sweep_tiny("--total-env-steps", "5", "--action-repeat", "8"),
     ("--total-env-steps", "action_repeat", "action-repeat")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "action_repeat=1,100"), ("action_repeat", "--grid")),
    ("sweep", bare("--total-env-steps", "--grid", "total_env_steps=0,40"), "total_env_steps"),
    ("sweep", bare("--image-size", "--grid", "image_size=8,32"), "image_size"),
    ("sweep", sweep_tiny(*SHORT, "--grid", "replay_capacity=1,1000"), "replay_capacity"),
    ("sweep", bare("--eval-every", "--grid", "eval_every=0,20"), "eval_every"),
    ("sweep", bare("--agent.batch-size", "--grid", "agent.batch_size=0,8"), "batch_size"),
    ("sweep", bare("--warmup-agent-steps", "--grid", "warmup_agent_steps=10,100000"), "warmup",
     True),
    ("sweep", bare("--checkpoint-every", "--grid", "checkpoint_every=20,40"), "", True),
    ("sweep", sweep_tiny(*SHORT, "--set", "agent.recipe=drq", "--grid", "agent.lr=1e-3,3e-4"),
     "", True),
    # --gpus-per-trial against --device
    ("sweep", sweep_tiny(*SHORT, "--device", "cuda", "--gpus-per-trial", "0"),
     ("--gpus-per-trial", "cuda")),
    ("sweep", sweep_tiny(*SHORT, "--device", "mps", "--gpus-per-trial", "1"),
     ("--gpus-per-trial", "mps")),
    ("sweep", bare("--device", "--grid", "device=cpu,cuda", "--gpus-per-trial", "1"),
     ("--gpus-per-trial", "device")),
    ("sweep", sweep_tiny(*SHORT, "--device", "cpu", "--gpus-per-trial", "0"), "", True),
    ("sweep", sweep_tiny(*SHORT, "--device", "cuda:0", "--gpus-per-trial", "1"),
     ("cuda", "GPU"), True),
    ("sweep", sweep_tiny(*SHORT, "--gpus-per-trial", "1/2"), "--gpus-per-trial"),
    ("sweep", sweep_tiny(*SHORT, "--gpus-per-trial", "50%"), "--gpus-per-trial"),
    ("sweep", [*RESUME, "--gpus-per-trial", "1"], "--gpus-per-trial", False, (SW,)),
    ("sweep", [*RESUME, "--gpus-per-trial", "0"], "--gpus-per-trial", True, (SW,)),
    ("sweep", [*RESUME, "--device", "cuda"], "--device", False, (SW,)),
    ("sweep", [*RESUME, "--num-cpus", "1"], "", True, (SW,)),
    ("sweep", [*RESUME, "--eval-distraction", "color_hard"], "--eval-distraction", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw/sweep.json"], ("sweep.json", "--sweep-dir"), False,
     (SW,)),
    # --grid, --seeds and --envs as a list or a range
    ("sweep", sweep_tiny(*SHORT, "--grid", "agent.lr=(1e-3, 3e-4)"), ("--grid", "agent.lr")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "agent.n_step=1..3"), ("--grid", "agent.n_step")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "agent.n_step=3-1"), ("--grid", "agent.n_step")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "agent.recipe=['simoun','drq']"),
     ("--grid", "agent.recipe")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "agent.lr=1e-3, 3e-4"), ("--grid", "agent.lr"), True),
    ("sweep", sweep_tiny(*SHORT, "--grid",
                        'env_kwargs={"max_episode_steps": 10, "disable_env_checker": true}'),
     ("env_kwargs", "--grid")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "preset=cpu,highway-cpu"), ("preset", "--preset")),
    ("sweep", sweep_tiny(*SHORT, "--grid", "agent.recipe=SIMOUN,drq"), "SIMOUN"),
    ("sweep", sweep_tiny(*SHORT, "--grid", "device=cpu,cpu"), ("--grid", "device")),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "[0,1,2]"), "--seeds"),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0,1,1"), "--seeds"),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0-1", "--seed", "3"), "--seed", True),
    ("sweep", bare("--env", "--envs", "[Pendulum-v1, simoun/PointReach-v0]"), "--envs"),
    ("sweep", bare("--env", "--envs", "Pendulum-v1,Pendulum-v1"), ("--envs", "Pendulum")),
    ("sweep", bare("--env", "--envs", "CartPole-v1"), ("CartPole", "--envs")),
    ("sweep", sweep_tiny(*SHORT, "--verbose", "-1"), "--verbose"),
    ("sweep", sweep_tiny(*SHORT, "--grid", "cameras=1,0"), "cameras"),
    # simoun-study: a study's record given as its spec, another study's archive
    ("study", ["plan", "ez/study.json"], "study.json", False, (EZ,)),
    ("study", ["plan", "ez/selection.json"], "selection.json", False, (EZ,)),
    ("study", ["plan", "mgt"], "mgt", False, (MGT,)),
    ("study", ["plan", "mgt/spec.json", "--probe-updates", "5"], "--probe-updates", True, (MGT,)),
    ("study", ["plan", "spec.toml", "--probe-updates", "-1"], "--probe-updates"),
    ("study", ["plan", "dmc100k.toml "], "dmc100k.toml", False, (DMC100K,)),
    ("study", ["plan", "spec.json"], "spec.json", False, (put("spec.json", SPEC),)),
    ("study", ["report", "arch/study.json", "--study-dir", "arch"], "study.json", False, (ARCH,)),
    ("study", ["run", "arch/study.json", "--study-dir", "s"], "study.json", False, (ARCH,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "sw"], ("sw", "study.json"), False,
     (SW, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "{run}"], ("study.json", "run"), False,
     (DMC100K,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--probe-updates", "0"],
     "--probe-updates", False, (ARCH, DMC100K)),
    ("study", ["report", "highway.toml", "--study-dir", "ez"],
     ("another spec", "differ", "highway"), False, (EZ, HIGHWAY)),
    ("study", ["run", "highway.toml", "--study-dir", "s", "--archive", "arch", "--resume",
               "--allow-other-commit"], ("another spec", "dmc100k", "arch"), False,
     (ARCH, HIGHWAY)),
    ("study", ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "ez", "--resume",
               "--allow-other-commit"], ("another spec", "ez", "dmc100k-drqv2-easy"), False,
     (EZ, DMC100K)),
    ("study", ["run", "mgt.json", "--study-dir", "s", "--archive", "arch", "--resume"],
     ("arch", "another spec", "MiniGrid"), False, (ARCH, MGT_FILE)),
    ("study", ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch/tuning",
               "--resume"], ("arch/tuning", "study.json"), False, (ARCH, DMC100K)),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--archive", "s"],
     ("--archive", "--study-dir")),
    ("study", ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch/", "--resume",
               "--allow-other-commit"], "", True, (ARCH, DMC100K)),
    ("study", ["run", EZ_NAME, "--study-dir", "s", "--archive", "ez", "--resume",
               "--allow-other-commit"], "", True, (EZ, EZ_FILE)),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--num-cpus", "0"], "--num-cpus"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--verbose", "3"], "--verbose"),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--resume"], "--resume", False,
     (ARCH, DMC100K)),
    ("study", ["plan", "spec.toml", "--archive", "arch"], "--archive", False, (ARCH,)),
    ("study", ["run", "gpu.toml", "--study-dir", "s"], ("gpus_per_trial", "gpu.toml"), False,
     (put("gpu.toml", gpu_spec("gpus_per_trial = 1")),)),
    # simoun-report
    ("report", ["ez"], "simoun-study", True, (EZ,)),
    ("report", ["sw", "--at-step", "40"], "", True, (SW,)),
    ("report", [MGT_RUN], ("minigrid_study", "MiniGrid"), False, (MGT,)),
    ("report", ["arch/report"], ("arch/report", "report"), False, (ARCH,)),
    ("report", ["{run}", "--at-wall-time", "1h"], "--at-wall-time"),
    ("report", ["{run}", "--at-step", "20k"], "--at-step"),
    ("report", ["{run}", "--at-wall-time", "1e-3"], "--at-wall-time"),
    ("report", ["{run}", "--at-step", "40", "--out", "{run}/config.json"], "--out"),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["report", "--archive", "arch"], ("arch", "simoun-study"), False, (ARCH,)),
    ("minigrid", ["select", "--archive", "arch"], ("arch", "simoun-study"), False, (ARCH,)),
    ("minigrid", ["run", "--archive", "arch", "--work-dir", "wd"], ("arch", "simoun-study"),
     False, (ARCH,)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "arch/study.json"], "study.json", False,
     (MGT, ARCH)),
    ("minigrid", ["select", "--archive", "mgt", "--spec", "ez/selection.json"],
     ("selection.json", "--spec"), False, (MGT, EZ)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", ""], "--work-dir", False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--spec", "mgt/spec.json"], "",
     True, (MGT,)),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "0",
                       "--settings.n-steps", "32", "--settings.env-id", "MiniGrid-Empty-5x5-v0"),
     "n-envs"),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "0", "--settings.env-id", "MiniGrid-Empty-5x5-v0"),
     "n-steps"),
    ("minigrid", ["select", "--archive", "mgt", "--concurrent", "2"], "--concurrent", False,
     (MGT,)),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id", "MiniGrid-Empty-5x5"),
     "MiniGrid-Empty-5x5"),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id", "CartPole-v1"),
     "CartPole-v1"),
    ("minigrid", small_probe("--probes", "rnd", "rnd"), "rnd", True),
    ("minigrid", small_probe("--probes", "rnd", "--settings.seed", "1000000"), "seed", True),
    ("minigrid", ["probe", "--out", "/proc/p", "--probes", "rnd", "--settings.steps", "512",
                  *SMALL_PROBE], "--out"),
    ("minigrid", ["probe", "--out", "p.txt", "--probes", "rnd", "--settings.steps", "512",
                  *SMALL_PROBE], ("p.txt", "--out"), False, (put("p.txt", "notes\n"),)),
]  # fmt: skip

TASKS = '[tasks."dm_control/cheetah-run-v0"]\naction_repeat = 4'
RESOURCES = "max_concurrent_trials = 2   # two runs at a time on a 2-core machine"
# the DMC study's spec edited by hand, given to plan: (text replaced, by, names[, valid])
SPEC_EDITS = [
    ("video = false", 'video = false\ndevice = "cuda"', ("gpus_per_trial", "device", "cuda"),
     True),
    (RESOURCES, RESOURCES + "\ngpus_per_trial = 0", "", True),
    ("video = false", "video = false\nseed = 3", ("seed", "seeds")),
    ("video = false", "video = false\ntotal_env_steps = 1000", ("total_env_steps", "env_steps")),
    ("video = false", 'video = false\nrun_dir = "runs/x"', "run_dir"),
    ("video = false", 'video = false\nagent.lr = "3e-4"', "agent.lr", True),
    ("video = false", 'video = false\nenv_kwargs = "{}"', "env_kwargs"),
    ("video = false", "video = false\naction_repeat = 2", "", True),
    ("env_steps = 50_000", "env_steps = 5", ("env_steps", "action_repeat")),
    ("env_steps = 50_000", "env_steps = 50_000.0", "env_steps"),
    ("env_steps = 50_000", 'env_steps = "50k"', "env_steps"),
    ("env_steps = 100_000", 'env_steps = { "dm_control/cartpole-swingup-v0" = 100_000 }',
     ("env_steps", "cheetah-run")),
    ('seeds = "101-102"', "seeds = [101, 102, 101]", ("seeds", "101")),
    ('seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }',
     'seeds = "1-5"', "", True),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', "tasks = []", "tasks"),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = "dm_control/cartpole-swingup-v0"',
     "tasks", True),
    ("agent.n_step = [1, 3]", "agent.n_step = 3", ("agent.n_step", "grid"), True),
    ("agent.n_step = [1, 3]", '"agent.n_step" = [1, 3]', "agent.n_step", True),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nagent.n_step = [1]", ("n_step", "edit.toml")),
    ("agent.n_step = [1, 3]", "", ("grid_overrides", "n_step")),
    (TASKS, TASKS + '\n\n[tasks."dm_control/walker-walk-v0"]\naction_repeat = 2', "walker-walk"),
    (TASKS, TASKS.replace("= 4", "= 0"), "action_repeat"),
    ('[tasks."dm_control/cheetah-run-v0"]', '[tasks."cheetah-run"]', "cheetah-run"),
    ('recipes = ["simoun", "drq", "drqv2", "rad", "curl"]', 'recipes = ["simoun", "simoun"]',
     ("recipes", "simoun")),
    ('recipes = ["simoun", "drq", "drqv2", "rad", "curl"]', 'recipes = "simoun"', "recipes"),
    ("cpus_per_trial = 1 ", "cpus_per_trial = 3 ", "cpus_per_trial", True),
    (RESOURCES, "max_concurrent_trials = 2\n\n[generalization]\nmodes = [\"train\"]", "", True),
    (RESOURCES, RESOURCES + '\n\n[generalization]\nmodes = ["color_hard"]\nepisodes = 2.5',
     "episodes"),
    ('preset = "cpu"', '\tpreset = "cpu"', "", True),
]  # fmt: skip
for _old, *_ in SPEC_EDITS:
    assert _old in SPEC, _old

CUDA = 'video = false\ndevice = "cuda"'
CPU_TASK = TASKS + '\ndevice = "cpu"'
# a device and gpus_per_trial edited in two places, given to plan: (text, names, what)
DEVICE_EDITS = [
    (gpu_spec("gpus_per_trial = 0").replace("video = false", CUDA, 1),
     ("gpus_per_trial", "cuda"), 'device = "cuda" in [base], gpus_per_trial = 0'),
    (gpu_spec("gpus_per_trial = 1").replace("video = false", CUDA, 1).replace(TASKS, CPU_TASK),
     ("gpus_per_trial", "cheetah-run", "cpu"),
     'device = "cuda" in [base], "cpu" for cheetah-run, gpus_per_trial = 1'),
]  # fmt: skip


def tuning_json(change) -> str:
    """The MiniGrid PPO tuning spec (docs/studies/minigrid-v2/tuning/spec.json) changed."""
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec, indent=2)


# the MiniGrid PPO tuning spec edited by hand, given to plan: (text, names[, valid[, what]])
JSON_TEXTS = [
    (tuning_json(lambda s: s.update(device="cuda")), "cuda", True),
    (tuning_json(lambda s: s.update(evaluations=0)), "evaluations"),
    (tuning_json(lambda s: s.update(eval_seed=100)), ("eval_seed", "100")),
    (tuning_json(lambda s: s.update(arms=[])), "arms"),
    (tuning_json(lambda s: s.update(arms=["ppo", "ppo,scale=0.01"])), ("ppo,scale=0.01", "scale")),
    (tuning_json(lambda s: s["tasks"][0].update(seeds="100-101")), "seeds", True),
    (MGT_SPEC.replace('"steps": 400000', '"steps": 4e5'), "steps", True, "steps 4e5"),
    (tuning_json(lambda s: s["ppo"].update(learning_rate="2.5e-4")), "learning_rate"),
    (tuning_json(lambda s: s["ppo"].update(gamma=1.0)), "", True),
    (tuning_json(lambda s: s["ppo"].update(ent_coef=-0.01)), "ent_coef"),
    (tuning_json(lambda s: s["ppo"].update(n_envs=0)), "n_envs"),
    (tuning_json(lambda s: s["ppo"].update(n_epochs=0)), "n_epochs"),
    (tuning_json(lambda s: s["ppo"].update(batch_size=2048)), ("batch_size", "1024")),
    (tuning_json(lambda s: s["ppo"].update(gae_lambda=1.5)), "gae_lambda"),
    (tuning_json(lambda s: s.update(eval_episodes=0)), "eval_episodes"),
    (tuning_json(lambda s: s["tasks"].append(dict(s["tasks"][0]))),
     ("MiniGrid-DoorKey-6x6-v0", "tasks")),
    ("// the tuning phase\n" + MGT_SPEC, "spec.json", False, "a // comment on top"),
    (MGT_SPEC.replace("\n", "\r\n"), "", True, "CRLF line endings"),
]  # fmt: skip


def shown(text: str) -> str:
    return text.replace("\n", "\\n").replace("\t", "\\t")


def spec_edit(name: str, text: str | bytes, names, ok: bool = False, argv=None, what=None):
    """A spec case: ``text`` written to ``name`` and given to plan (or ``argv``)."""
    argv = argv or ["plan", name, "--probe-updates", "0"]
    return fifth("specs", "study", argv, names, ok, works=(put(name, text),), what=what)


CASES: list[dict] = [
    *(fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
      for command, argv, names, *rest in FLAGS),
    *(spec_edit("edit.toml", SPEC.replace(old, new, 1), names, *ok, what=shown(new))
      for old, new, names, *ok in SPEC_EDITS),
    *(spec_edit("edit.toml", text, names, what=what) for text, names, what in DEVICE_EDITS),
    spec_edit("edit.toml", b"\xef\xbb\xbf" + SPEC.encode(), "edit.toml", True,
              what="saved with a byte-order mark"),
    spec_edit("edit.toml", EZ_SPEC.replace("[base]\n", '[base]\ndevice = "cuda"\n', 1),
              ("gpus_per_trial", "device", "cuda"), True,
              argv=["run", "edit.toml", "--study-dir", "s"],
              what='drqv2-easy spec: device = "cuda" in [base], given to run'),
    *(spec_edit("spec.json", text, names, *rest[:1], argv=["plan", "spec.json"],
                what=rest[1] if len(rest) > 1 else None)
      for text, names, *rest in JSON_TEXTS),
]  # fmt: skip
