"""The seventh reliability trial's cases: lab (see reliability_trial.py).

The lab's command lines (simoun-sweep, simoun-study, simoun-report, simoun-analyze, the MiniGrid
study and the driving references) given bad values, typos, conflicting or valid combinations and
paths that do not exist, on flags and keys the earlier trials left alone, and the studies' spec
files (the DMC, highway and v2 TOML specs, the MiniGrid PPO JSON spec) edited by hand: wrong
types, unknown or misspelt keys, missing sections, impossible budgets and valid variants."""

from __future__ import annotations

import json

from reliability_trial import (
    ARCH,
    DMC100K,
    EV_RUN,
    HIGHWAY_SPEC,
    MGT,
    MGT_SPEC,
    SMALL_PROBE,
    SPEC,
    STUDIES,
    SW,
    SW_RUN,
    V2_SPEC,
    bias,
    driving,
    fifth,
    masks,
    plan,
    probe,
    put,
    report_argv,
    small_probe,
    study_run,
    sweep_tiny,
)

NOTES = put("notes.txt", "my notes\n")  # a plain file where a directory is wanted
HIGHWAY = put("highway.toml", HIGHWAY_SPEC)
V2 = put("dmc100k-v2.toml", V2_SPEC)
TWO_CPUS = put("two.toml", SPEC.replace("cpus_per_trial = 1 ", "cpus_per_trial = 2 ", 1))


def without(argv: list[str], flag: str) -> list[str]:
    """``argv`` without ``flag`` and its value."""
    at = argv.index(flag)
    return argv[:at] + argv[at + 2 :]


def tuning_json(change, indent: int = 2) -> str:
    """The MiniGrid PPO tuning spec (docs/studies/minigrid-v2/tuning/spec.json) changed."""
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec, indent=indent)


NO_ENV = without(sweep_tiny(), "--env")

# command lines: (command, argv, what the refusal names[, valid[, works]])
FLAGS = [
    # simoun-sweep: refused before Ray starts, or (the guard) read as work started
    ("sweep", sweep_tiny("--grid", "agent.discount=0.99,1.5"), "discount"),
    ("sweep", sweep_tiny("--grid", "image_size=32,big"), "image_size"),
    ("sweep", sweep_tiny("--grid", "env=Pendulum-v1,Acrobot-v1"), ("--envs", "env")),
    ("sweep", sweep_tiny("--grid", "seed=0,1"), ("--seeds", "seed")),
    ("sweep", sweep_tiny("--grid", "agent.recipe = simoun,drq"), ("--grid", "agent.recipe")),
    ("sweep", [*without(sweep_tiny(), "--agent.batch-size"), "--grid", "agent.batch_size=8,16"], "",
     True),
    ("sweep", sweep_tiny("--seeds", "3"), "", True),
    ("sweep", sweep_tiny("--seeds", "-1"), "--seeds"),
    ("sweep", [*NO_ENV, "--envs", "simoun/PointReach-v0,Pendulum-v1", "--seeds", "0-1"], "",
     True),
    ("sweep", [*NO_ENV, "--envs", "simoun/PointReach-v0;Pendulum-v1"], "--envs"),
    ("sweep", sweep_tiny("--gpus-per-trial", "-0.5"), "--gpus-per-trial"),
    ("sweep", sweep_tiny("--gpus-per-trial", "2"), ("--gpus-per-trial", "GPU")),
    ("sweep", sweep_tiny("--cpus-per-trial", "0"), "--cpus-per-trial"),
    ("sweep", sweep_tiny("--cpus-per-trial", "2", "--num-cpus", "1"),
     ("--cpus-per-trial", "--num-cpus")),
    ("sweep", sweep_tiny("--num-cpus", "0"), "--num-cpus"),
    ("sweep", sweep_tiny("--verbose", "3"), "--verbose"),
    ("sweep", sweep_tiny("--sweep-dir", "notes.txt"), ("notes.txt", "--sweep-dir"), False,
     (NOTES,)),
    ("sweep", sweep_tiny("--sweep-dir", "new/deeper/sw"), "", True),
    ("sweep", ["--resume", "--sweep-dir", "nowhere"], ("nowhere", "sweep.json")),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--agent.batch-size", "16"],
     "--agent.batch-size", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--env", "Pendulum-v1"], "--env", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--total-env-steps", "40"], "", True, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw/"], "", True, (SW,)),
    # simoun-study plan, run, report
    ("study", plan("--probe-updates", "-1"), "--probe-updates"),
    ("study", ["plan", "spec.toml", "highway.toml"], ("highway.toml", "one")),
    ("study", ["plan"], "SPEC"),
    ("study", ["plan", "highway.toml", "--probe-updates", "0"], "", True, (HIGHWAY,)),
    ("study", ["plan", "dmc100k-v2.toml", "--probe-updates", "0"], "", True, (V2,)),
    ("study", ["plan", str(STUDIES / "dmc100k.toml"), "--probe-updates", "0"], "", True),
    ("study", ["plan", "notes.txt"], ("notes.txt", "TOML"), False, (NOTES,)),
    ("study", study_run("--num-cpus", "0"), "--num-cpus"),
    ("study", study_run("--verbose", "5"), "--verbose"),
    ("study", study_run("--archive", "s"), ("--archive", "--study-dir")),
    ("study", study_run("--archive", "notes.txt"), ("notes.txt", "--archive"), False, (NOTES,)),
    ("study", ["run", "two.toml", "--study-dir", "s", "--num-cpus", "1"],
     ("cpus_per_trial", "--num-cpus"), False, (TWO_CPUS,)),
    ("study", ["run", "highway.toml", "--study-dir", "s"], "", True, (HIGHWAY,)),
    ("study", ["run", "spec.toml", "--study-dir", ""], "--study-dir"),
    ("study", study_run("--archive", "new/deeper/archive"), "", True),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch/study.json"],
     ("study.json", "--study-dir"), False, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--out", "r"], "--out", False,
     (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch/"], "", True, (ARCH, DMC100K)),
    ("study", ["report", str(STUDIES / "dmc100k.toml"), "--study-dir", "arch"], "", True,
     (ARCH,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", EV_RUN], ("study.json", "s1"), False,
     (ARCH, DMC100K)),
    # simoun-report
    ("report", report_argv("--at-step", "-20"), "--at-step"),
    ("report", report_argv("--at-step", "25"), ("25", "--at-step")),
    ("report", report_argv("--at-step", "0"), "--at-step", True),
    ("report", report_argv("--at-wall-time", "-1"), "--at-wall-time"),
    ("report", report_argv("--at-wall-time", "nan"), "--at-wall-time"),
    ("report", report_argv("--out", "notes.txt"), ("notes.txt", "--out"), False, (NOTES,)),
    ("report", ["{run}/"], "", True),
    ("report", ["{run}", "{run}"], ("twice", "once", "unrecognized")),
    ("report", [EV_RUN], "", True, (ARCH,)),
    ("report", ["spec.toml"], ("spec.toml", "simoun-study")),
    ("report", [SW_RUN, "--at-step", "40"], "", True, (SW,)),
    # simoun-analyze
    ("analyze", bias("--pairs", "0"), "--pairs"),
    ("analyze", bias("--pairs", "8", "--out", "b", "--device", "cpu"), "", True),
    ("analyze", bias("--pairs", "8", "--device", "gpu"), "gpu"),
    ("analyze", bias("--pairs", "8", "--recolour"), "--recolour"),
    ("analyze", masks("--steps", "0"), "--steps", True),
    ("analyze", masks("--steps", "-1"), "--steps"),
    ("analyze", masks("--steps", "100000"), "--steps", True),
    ("analyze", masks("--episodes", "0"), "--episodes"),
    ("analyze", masks("--steps", "1", "--video", "gif", "--episodes", "2"), "", True),
    ("analyze", ["masks", SW_RUN, "--steps", "1"], "", True, (SW,)),
    ("analyze", ["masks", EV_RUN, "--steps", "1"], ("checkpoint.pt", "s1"), False, (ARCH,)),
    ("analyze", masks("--steps", "1", "--out", "notes.txt"), ("notes.txt", "--out"), False,
     (NOTES,)),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["select", "--archive", "mgt/"], "", True, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "mgt"], ("--spec", "mgt"), False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "-1"],
     "--concurrent", False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "mgt"], ("--work-dir", "--archive"),
     False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--spec", "spec.toml"],
     ("spec.toml", "--spec"), False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "16"], "", True,
     (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "notes.txt"],
     ("notes.txt", "--work-dir"), False, (MGT, NOTES)),
    ("minigrid", small_probe("--probes", "rnd", steps="0"), ("--settings.steps", "steps")),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "0", "--settings.env-id", "MiniGrid-Empty-5x5-v0"),
     ("n-steps", "n_steps")),
    ("minigrid", small_probe("--probes", "rnd", "--settings.seed", "-1"), "seed"),
    ("minigrid", small_probe("--probes"), "--probes"),
    ("minigrid", small_probe("--probes", "rnd", "rnd"), "rnd"),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id", "MiniGrid-Empty-5x5"),
     "MiniGrid-Empty-5x5"),
    ("minigrid", ["probe", "--out", "p/", "--probes", "rnd", "--settings.steps", "512",
                  *SMALL_PROBE], "", True),
    # python -m simoun_agent.run.driving_reference
    ("driving", driving("--episodes", "0"), "--episodes"),
    ("driving", driving("--episodes", "-1"), "--episodes"),
    ("driving", driving("--episode", "1"), "--episodes"),
    ("driving", driving("--preset", "highway-fast"), "highway-fast"),
    ("driving", driving("--preset", "HIGHWAY-CPU"), "HIGHWAY-CPU"),
    ("driving", driving("--episodes", "1", "--json", "d.json", "--json", "e.json"), "--json"),
    ("driving", driving("--episodes", "1", "--json", "."), "--json"),
    ("driving", driving("--episodes", "1", "--seed", str(2**32)), "--seed", True),
    ("driving", driving("--episodes", "1", "--json", "notes.txt"), "--json", False, (NOTES,)),
    ("driving", driving("--episodes", "1", "--seed", "0", "--json", "references.json"), "",
     True),
]  # fmt: skip

EVAL_SEEDS = (
    'seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }'
)
EVAL_TASKS = 'tasks = ["dm_control/cartpole-swingup-v0", "dm_control/cheetah-run-v0"]'
RECIPES = 'recipes = ["simoun", "drq", "drqv2", "rad", "curl"]'
TUNING = (
    '[tuning]\ntasks = ["dm_control/cartpole-swingup-v0"]\nseeds = "101-102"\nenv_steps = 50_000\n'
)
GRID = "[grid]\nagent.n_step = [1, 3]\n"
TASKS = (
    '[tasks."dm_control/cartpole-swingup-v0"]\naction_repeat = 8\n\n'
    '[tasks."dm_control/cheetah-run-v0"]\naction_repeat = 4\n'
)
# the DMC study's spec edited by hand, given to plan: (text replaced, by, names[, valid])
DMC_EDITS = [
    ("eval_every = 10_000", "eval_every = 200_000", "eval_every", True),
    ("env_steps = 50_000", "env_steps = 50_001", ("env_steps", "action_repeat"), True),
    ("action_repeat = 8", "action_repeat = 8\nenv_steps = 1_000", "env_steps"),
    ("action_repeat = 8", "action_repeat = 8\nimage_size = 64", "image_size", True),
    ("action_repeat = 8", "action_repeat = 0", "action_repeat"),
    ("cpus_per_trial = 1 ", "cpus_per_trial = -1 ", "cpus_per_trial"),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 100", "", True),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 2\ngpus_per_trial = 1", "gpus", True),
    (EVAL_TASKS, 'tasks = ["dm_control/cartpole-swingup-v0", "dm_control/walker-walk-v0"]',
     "walker"),
    ('selection = "auc"', 'selection = "iqm"', "iqm"),
    (RECIPES, 'recipes = ["simoun", "drq", "drqv2", "rad", "curl", "drq"]', "drq"),
    ('grid_overrides = ["agent.n_step"]', "grid_overrides = []", ("n_step", "grid_overrides")),
    ('grid_overrides = ["agent.n_step"]', 'grid_overrides = ["agent.n_step", "agent.n_step"]',
     "n_step"),
    ("agent.n_step = [1, 3]", "agent.n_step = []", "n_step"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nimage_size = [48, 64]", "image_size", True),
    ('preset = "cpu"', 'preset = "cpu "', "preset"),
    ('preset = "cpu"', 'preset = "CPU"', "CPU"),
    ("video = false", 'video = "false"', "video"),
    ("video = false", 'video = false\ndevice = "cuda"', "device", True),
    ("video = false", "video = false\nagent.batch_size = 0", "batch_size"),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-5"', '"5-1"'), "seeds"),
    (EVAL_SEEDS, 'seeds = [1, 2, 3]', "seeds", True),
    ("env_steps = 100_000", "env_steps = 20_000", "", True),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["dm_control/cheetah-run-v0"]', "",
     True),
    (TUNING, "", "tuning"),
    (GRID, "", "grid"),
    (TASKS, "", "action_repeat", True),
    ('selection = "auc"', 'selection = "auc', "edit.toml"),
    ("[base]", "[base", "edit.toml"),
    ('description = """', 'notes = """', "notes"),
    (RECIPES, RECIPES.replace("recipes", "Recipes"), "Recipes"),
]  # fmt: skip
# the highway and the v2 specs edited: (spec text, text replaced, by, names[, valid])
OTHER_EDITS = [
    (HIGHWAY_SPEC, 'preset = "highway-cpu"', 'preset = "highway"', "", True),
    (HIGHWAY_SPEC, 'tasks = ["highway-fast-v0"]\nseeds = "1-5"',
     'tasks = ["highway-fast-v0", "merge-v0"]\nseeds = "1-5"', "merge", True),
    (HIGHWAY_SPEC, "eval_episodes = 10", "eval_episodes = 1000", "", True),
    (HIGHWAY_SPEC, 'seeds = "1-5"', 'seeds = "0-4"', "", True),
    (HIGHWAY_SPEC, "eval_every = 5_000", "eval_every = 5_000\naction_repeat = 2",
     "action_repeat", True),
    (HIGHWAY_SPEC, "[grid]", "[grids]", "grids"),
    (V2_SPEC, 'recipes = ["simoun", "drq", "drqv2", "rad", "curl"]',
     'recipes = ["drq", "drqv2", "rad", "curl"]', ("simoun", "diagnostics")),
    (V2_SPEC, 'modes = ["color_easy", "color_hard", "video_easy", "video_hard"]',
     'modes = ["Color_Easy"]', "Color_Easy"),
    (V2_SPEC, 'modes = ["color_easy", "color_hard", "video_easy", "video_hard"]',
     'modes = ["color_hard"]', "", True),
    (V2_SPEC, "[diagnostics]\n", "[diagnostic]\n", "diagnostic"),
]  # fmt: skip
for _old, *_ in DMC_EDITS:
    assert _old in SPEC, _old
for _text, _old, *_ in OTHER_EDITS:
    assert _old in _text, _old

# the MiniGrid PPO tuning spec edited by hand, given to plan: (change, names[, valid])
JSON_EDITS = [
    (lambda s: s["tasks"][0].update(seeds=[]), "seeds"),
    (lambda s: s["tasks"][0].update(steps=399_999), "steps", True),
    (lambda s: s["ppo"].update(n_steps=0), "n_steps"),
    (lambda s: s["ppo"].update(learning_rate=-1e-4), "learning_rate"),
    (lambda s: s["ppo"].update(clip_range=-0.2), "clip_range"),
    (lambda s: s["ppo"].update(gamma=0), "gamma", True),
    (lambda s: s.update(eval_episodes=1), "", True),
    (lambda s: s.update(arms=["consistency"]), "ppo", True),
    (lambda s: s.update(arms=["ppo", "rnd,scale=0.01", "rnd,scale=0.1"]), "", True),
    (lambda s: s.update(ppo=None), "ppo"),
    (lambda s: s.update(Evaluations=s.pop("evaluations")), "Evaluations"),
    (lambda s: s["tasks"][0].update(seeds="100-101"), "seeds", True),
    (lambda s: s["tasks"][0].update(seeds=[2**40]), "seeds", True),
    (lambda s: s["tasks"][0].update(env="MiniGrid-DoorKey-6x6-v0"), "env"),
]  # fmt: skip
SINGLE_QUOTED = MGT_SPEC.replace('"device": "cpu"', "'device': 'cpu'", 1)
assert SINGLE_QUOTED != MGT_SPEC


def spec_edit(name: str, text: str, names, ok: bool = False, argv=None, what: str = "") -> dict:
    """A spec case: ``text`` written to ``name`` and given to plan (or ``argv``)."""
    argv = argv or ["plan", name, "--probe-updates", "0"]
    return fifth("specs", "study", argv, names, ok, works=(put(name, text),), what=what or None)


def archived(command: str, text: str, names, ok: bool = False, what: str = "") -> dict:
    """The MiniGrid study's ``command`` on the tuning archive with ``text`` as its --spec."""
    return fifth("specs", "minigrid", [command, "--archive", "mgt", "--spec", "spec.json"], names,
                 ok, works=(MGT, put("spec.json", text)), what=what)  # fmt: skip


def shown(text: str) -> str:
    return text.replace("\n", "\\n")


CASES: list[dict] = [
    *(fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
      for command, argv, names, *rest in FLAGS),
    *(spec_edit("edit.toml", SPEC.replace(old, new, 1), names, *ok,
                what=shown(new) or f"removed {shown(old)[:30]}")
      for old, new, names, *ok in DMC_EDITS),
    *(spec_edit("other.toml", text.replace(old, new, 1), names, *ok, what=shown(new))
      for text, old, new, names, *ok in OTHER_EDITS),
    *(spec_edit("spec.json", tuning_json(change), names, *ok, argv=["plan", "spec.json"])
      for change, names, *ok in JSON_EDITS),
    spec_edit("spec.json", SINGLE_QUOTED, "spec.json", argv=["plan", "spec.json"],
              what="single-quoted strings"),
    spec_edit("bad.toml", SPEC.replace('selection = "auc"', 'selection = "iqm"', 1), "iqm",
              argv=["run", "bad.toml", "--study-dir", "s"], what='selection = "iqm"'),
    archived("select", tuning_json(lambda s: s["arms"].pop()), ("arms", "differ"), True,
             "the last arm removed"),
    archived("report", tuning_json(lambda s: s.update(eval_episodes=16)),
             ("eval_episodes", "differ"), what="eval_episodes=16"),
    archived("report", tuning_json(lambda s: s["ppo"].update(learning_rate=3e-4)),
             ("learning_rate", "differ"), what="learning_rate=3e-4"),
    archived("report", tuning_json(lambda s: None, indent=4), "", True, "re-indented"),
]  # fmt: skip
