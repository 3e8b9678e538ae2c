"""The eighth reliability trial's cases: lab (see reliability_trial.py).

The lab's command lines on surfaces the earlier trials left alone: simoun-sweep's --grid values
(empty, repeated under another spelling, keys that are not config values), --seeds ranges,
--envs with MODULE:ID and spaces, a sweep directory that is a run or an existing sweep, the
flags --resume may and may not change; simoun-study on the drqv2-easy supplement and its archive,
MiniGrid specs written as TOML, the v1 MiniGrid spec, an archive of another study, and run's
--archive and --allow-other-commit; simoun-report on whole archives, at wall-time budgets no run
reaches, with --out into the run itself; the MiniGrid study's options before the subcommand, its
default archive from another directory, the ppo-check archive, another study's spec for an
archive, a TOML --spec, and probe settings a block does not divide. The studies' spec files
edited by hand in new ways: flag spellings and quoted dotted keys in TOML, text pasted from a
document (an en dash, curly quotes, thousands separators), a file saved in Latin-1, base keys
that clash with the study's resources, the drqv2-easy spec's recipes and seeds, and the MiniGrid
JSON spec with underscores in numbers, Infinity, a key given twice, arms spelled two ways and
MODULE:ID task ids."""

from __future__ import annotations

import json

from reliability_trial import (
    ARCH,
    DMC100K,
    HIGHWAY_SPEC,
    MG,
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
PPOC = lab_copy("minigrid-v2/ppo-check", "ppoc")
HIGHWAY = put("highway.toml", HIGHWAY_SPEC)


def toml_value(value) -> str:
    """``value`` (a JSON scalar or a list of them) written as TOML."""
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    return json.dumps(value)


def ppo_toml(spec: dict) -> str:
    """The MiniGrid PPO spec ``spec`` written as TOML, as a user would convert it by hand."""
    lines = [f"{key} = {toml_value(value)}" for key, value in spec.items() if key not in
             ("tasks", "ppo")]  # fmt: skip
    for task in spec["tasks"]:
        lines += ["", "[[tasks]]", *(f"{k} = {toml_value(v)}" for k, v in task.items())]
    lines += ["", "[ppo]", *(f"{k} = {toml_value(v)}" for k, v in spec["ppo"].items())]
    return "\n".join(lines) + "\n"


MGT_TOML = ppo_toml(json.loads(MGT_SPEC))
MGT_TOML_FILE = put("mgt.toml", MGT_TOML)
NO_ENV = [*sweep_tiny()]
NO_ENV[NO_ENV.index("--env") : NO_ENV.index("--env") + 2] = []


def tuning_json(change) -> str:
    """The MiniGrid PPO tuning spec (docs/studies/minigrid-v2/tuning/spec.json) changed."""
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec, indent=2)


# command lines: (command, argv, what the refusal names[, valid[, works]])
FLAGS = [
    # simoun-sweep: refused before Ray starts, or (the guard) read as work started
    ("sweep", sweep_tiny("--grid", "agent.recipe=simoun,,drq"), ("--grid", "agent.recipe")),
    ("sweep", sweep_tiny("--grid", "agent.recipe="), ("--grid", "agent.recipe")),
    ("sweep", sweep_tiny("--grid", "agent.lr=1e-3,0.001"), "agent.lr"),
    ("sweep", sweep_tiny("--grid", "run_dir=a,b"), ("run_dir", "--grid")),
    ("sweep", sweep_tiny("--grid", "total_env_steps=40,80"), "total_env_steps", True),
    ("sweep", sweep_tiny("--grid", "agent.discount:0.9,0.99"), ("--grid", "agent.discount")),
    ("sweep", sweep_tiny("--grid", "Agent.lr=1e-3,3e-4"), "Agent.lr"),
    ("sweep", sweep_tiny("--grid", "eval_distraction=color_easy,color_hard"),
     ("eval_distraction", "dm_control")),
    ("sweep", sweep_tiny("--seeds", "4-0"), "--seeds"),
    ("sweep", sweep_tiny("--grid", "agent.n_step=1;3"), ("agent.n_step", "--grid")),
    ("sweep", sweep_tiny("--grid", "agent.lr=[1e-3,3e-4]"), "agent.lr"),
    ("sweep", sweep_tiny("--grid", "agent.n_step=1-3"), "n_step"),
    ("sweep", sweep_tiny("--sweep-dir", ""), "--sweep-dir"),
    ("sweep", [*NO_ENV, "--envs", ""], "--envs"),
    ("sweep", [*NO_ENV, "--envs", "minigrid:MiniGrid-Empty-5x5-v0"], ("MiniGrid", "--envs"),
     True),
    ("sweep", [*NO_ENV, "--envs", "simoun/PointReach-v0, Pendulum-v1"], ("Pendulum-v1", "--envs"),
     True),
    ("sweep", sweep_tiny("--envs", "Pendulum-v1"), ("--env", "--envs"), True),
    ("sweep", sweep_tiny("--gpus-per-trial", "AUTO"), "--gpus-per-trial", True),
    ("sweep", sweep_tiny("--gpus-per-trial", "0.5", "--device", "cpu"),
     ("--gpus-per-trial", "--device", "GPU")),
    ("sweep", sweep_tiny("--cpus-per-trial", "auto"), "--cpus-per-trial"),
    ("sweep", sweep_tiny("--num-cpus", "1.5"), "--num-cpus"),
    ("sweep", sweep_tiny("--sweep-dir", "{run}"), ("--sweep-dir", "config.json")),
    ("sweep", sweep_tiny("--sweep-dir", "sw"), ("--resume", "sw"), False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--seeds", "1-3"], "--seeds", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--grid", "agent.n_step=1,3"], "--grid", False,
     (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--seed", "3"], "--seed", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--cpus-per-trial", "2"], "--cpus-per-trial",
     True, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--total-env-steps", "20"],
     ("--total-env-steps", "40"), False, (SW,)),
    # simoun-study plan, run, report
    ("study", ["plan", EZ_NAME, "--probe-updates", "0"], "", True, (EZ_FILE,)),
    ("study", ["plan", "arch/study.json"], "study.json", False, (ARCH,)),
    ("study", ["plan", "mg/spec.json"], "", True, (MG,)),
    ("study", ["plan", "mgt.toml"], "", True, (MGT_TOML_FILE,)),
    ("study", ["plan", "spec.toml", "--probe-updates"], "--probe-updates"),
    ("study", ["plan", "~/spec.toml"], "~/spec.toml"),
    ("study", ["plan", "spec.toml", "--study-dir", "s"], "--study-dir"),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--archive", "x"], "--archive",
     False, (ARCH, DMC100K)),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--allow-other-commit"],
     ("--allow-other-commit", "--resume")),
    ("study", ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch"], ("--resume",
                                                                                "arch"), False,
     (ARCH, DMC100K)),
    ("study", ["run", "highway.toml", "--study-dir", "s", "--archive", "arch", "--resume"],
     ("arch", "highway", "another spec"), False, (ARCH, HIGHWAY)),
    ("study", ["run", "spec.toml", "--study-dir", "{run}"], ("--study-dir", "config.json")),
    ("study", ["run", "mgt.toml", "--study-dir", "s"], "", True, (MGT_TOML_FILE,)),
    ("study", ["run", "spec.toml"], "--study-dir"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--num-cpus", "two"], "--num-cpus"),
    ("study", ["run", "mg/spec.json", "--study-dir", "s", "--archive", "mgt", "--resume"],
     ("differ", "another spec", "mgt"), False, (MG, MGT)),
    ("study", ["report", EZ_NAME, "--study-dir", "arch"], ("another spec", "differ", "dmc100k"),
     False, (ARCH, EZ_FILE)),
    ("study", ["run", EZ_NAME, "--study-dir", "s", "--archive", "ez", "--resume"], "", True,
     (EZ, EZ_FILE)),
    ("study", ["report", EZ_NAME, "--study-dir", "ez"], "", True, (EZ, EZ_FILE)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "ez"],
     ("another spec", "dmc100k-drqv2-easy", "differ"), False, (EZ, DMC100K)),
    ("study", ["report", "mgt/spec.json", "--study-dir", "mgt"], "", True, (MGT,)),
    ("study", ["report", "mg/spec.json", "--study-dir", "mgt"], ("differ", "another spec"),
     False, (MG, MGT)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "mgt"], ("mgt", "study.json",
                                                                 "MiniGrid"), False,
     (MGT, DMC100K)),
    # simoun-report
    ("report", ["{run}", "--at-wall-time", "1e9"], "--at-wall-time"),
    ("report", ["{run}", "--at-wall-time", "0"], "--at-wall-time", True),
    ("report", ["{run}", "--at-wall-time", "inf"], "--at-wall-time"),
    ("report", ["{run}", "--at-step", "40.0"], "--at-step"),
    ("report", ["{run}", "--at-step", "20", "--at-step", "40"], "--at-step"),
    ("report", ["arch"], "simoun-study", True, (ARCH,)),
    ("report", ["ez/selection.json"], "selection.json", False, (EZ,)),
    ("report", ["mgt"], ("minigrid_study", "MiniGrid"), True, (MGT,)),
    ("report", ["{run}", "--out", "{run}"], "--out", True),
    ("report", ["{run}", "--out", ""], "--out"),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["--archive", "mgt", "report"], ("--archive", "report"), False, (MGT,)),
    ("minigrid", ["report"], ("docs/studies/minigrid", "--archive")),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "mgt.toml"], "", True,
     (MGT, MGT_TOML_FILE)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "bad.toml"], "bad.toml", False,
     (MGT, put("bad.toml", MGT_TOML.replace("[ppo]", "[ppo")))),
    ("minigrid", ["select", "--archive", "ppoc"], ("ppoc", "run"), False, (PPOC,)),
    ("minigrid", ["report", "--archive", "ppoc"], ("ppoc", "run"), False, (PPOC,)),
    ("minigrid", ["select", "--archive", "mgt", "--spec", "ppoc/spec.json"],
     ("differ", "DoorKey-5x5", "another"), False, (MGT, PPOC)),
    ("minigrid", ["report", "--archive", "mg", "--spec", "mgt/spec.json"],
     ("differ", "another"), False, (MG, MGT)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "0"],
     "--concurrent", False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--spec", "ppoc/spec.json"],
     ("differ", "DoorKey-5x5", "another"), False, (MGT, PPOC)),
    ("minigrid", ["run", "--archive", "fresh", "--work-dir", "wd", "--spec", "ppoc/spec.json"],
     "fresh", True, (PPOC,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "two"],
     "--concurrent", False, (MGT,)),
    ("minigrid", ["select", "--archive", "mgt", "--spec"], "--spec", False, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--out", "r"], "--out", False, (MGT,)),
    ("minigrid", ["select", "--archive", "mgt", "--work-dir", "wd"], "--work-dir", False,
     (MGT,)),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "60k", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id", "MiniGrid-Empty-5x5-v0"),
     ("--settings.steps", "60k")),
    ("minigrid", small_probe("--probes", "RND"), "RND"),
    ("minigrid", small_probe("--probes", "rnd", steps="50"), "steps"),
    ("minigrid", small_probe("--probes", "rnd", steps="100"), "steps", True),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id",
                       "minigrid:MiniGrid-Empty-5x5-v0"), ("minigrid:", "env"), True),
    ("minigrid", small_probe("--probes", "rnd", "--settings.seed", "0"), "seed", True),
    ("minigrid", small_probe("--probes", ""), "--probes"),
    ("minigrid", small_probe("--probes", "rnd,consistency"), ("rnd,consistency", "--probes")),
    ("minigrid", ["probe", "--probes", "rnd", "--settings.steps", "512", *SMALL_PROBE], "--out",
     True),
]  # fmt: skip

EZ_RECIPES = 'recipes = ["drqv2_easy"]'
EZ_SEEDS = 'seeds = { "dm_control/cartpole-swingup-v0" = "1-5" }'
# the DMC study's spec (or the drqv2-easy supplement's) edited by hand, given to plan:
# (spec text, text replaced, by, names[, valid])
SPEC_EDITS = [
    (SPEC, "eval_every = 10_000", "eval-every = 10_000", "eval-every"),
    (SPEC, "video = false", 'video = false\n"agent.lr" = 1e-3', "agent.lr", True),
    (SPEC, "video = false", 'video = false\neval_distraction = ["color_hard"]',
     "eval_distraction", True),
    (SPEC, "video = false", "video = false\nenv_kwargs = { nope = 1 }", ("nope", "env_kwargs")),
    (SPEC, "video = false", "video = false\ntorch_threads = 4", ("torch_threads",
                                                               "cpus_per_trial")),
    (SPEC, "video = false", "video = false\ncheckpoint_every = 0", "checkpoint_every"),
    (SPEC, "video = false", 'video = false\nenv_module = "nosuchmodule"', "nosuchmodule"),
    (SPEC, "max_concurrent_trials = 2", 'max_concurrent_trials = 2\ngpus_per_trial = "AUTO"',
     ("gpus_per_trial", "AUTO")),
    (SPEC, "action_repeat = 8", "action-repeat = 8", "action-repeat"),
    (SPEC, 'seeds = "101-102"', 'seeds = "101\u2013102"', "seeds"),
    (SPEC, 'recipes = ["simoun", "drq", "drqv2", "rad", "curl"]',
     "recipes = [\u201csimoun\u201d, \u201cdrq\u201d]", "edit.toml"),
    (SPEC, "env_steps = 50_000", "env_steps = 50,000", "edit.toml"),
    (SPEC, "[evaluation]", "[Evaluation]", "Evaluation"),
    (SPEC, 'grid_overrides = ["agent.n_step"]', 'grid_overrides = ["agent.n-step"]',
     "agent.n-step"),
    (EZ_SPEC, EZ_RECIPES, 'recipes = ["drqv2-easy"]', "drqv2-easy"),
    (EZ_SPEC, EZ_RECIPES, 'recipes = ["drqv2_easy", "drqv2"]', "", True),
    (EZ_SPEC, EZ_SEEDS, EZ_SEEDS.replace("cartpole-swingup", "cheetah-run"),
     ("cheetah", "cartpole", "seeds")),
    (EZ_SPEC, 'preset = "cpu"', 'preset = "cpu"\nagent.recipe = "drqv2_easy"', "recipe"),
]  # fmt: skip
for _text, _old, *_ in SPEC_EDITS:
    assert _old in _text, _old

LATIN1 = SPEC.replace("Simoun against DrQ", "Simoun (r\u00e9sum\u00e9) against DrQ", 1)
assert LATIN1 != SPEC
# the MiniGrid PPO tuning spec edited by hand, given to plan:
# (text, names[, valid[, what[, file name]]])
JSON_TEXTS = [
    (MGT_SPEC.replace('"steps": 400000', '"steps": 400_000'), "spec.json", False,
     "steps 400_000"),
    (MGT_SPEC.replace('"clip_range": 0.2', '"clip_range": Infinity'), "clip_range", False,
     "clip_range Infinity"),
    (MGT_SPEC.replace('"device": "cpu"', '"device": "cpu",\n  "device": "cuda"'),
     ("device", "twice"), False, "device given twice"),
    (tuning_json(lambda s: s.update(arms=["ppo", "rnd,scale=0.01", "RND,scale=0.01"])), "RND"),
    (tuning_json(lambda s: s.update(arms=["ppo", "rnd,scale=1e-2", "rnd,scale=0.01"])),
     ("rnd,scale=1e-2", "arms")),
    (tuning_json(lambda s: s["tasks"][0].update(env_id="minigrid:MiniGrid-DoorKey-6x6-v0")),
     ("minigrid:", "env_id"), True),
    (tuning_json(lambda s: s["tasks"][0].update(seeds=[100, 101.0])), "seeds"),
    (tuning_json(lambda s: s["ppo"].update(batch_size=48)), "batch_size", True),
    (tuning_json(lambda s: s["tasks"][0].update(seeds=[100, -1])), "seeds"),
    (tuning_json(lambda s: s.update(device="")), "device"),
    (tuning_json(lambda s: s["tasks"].append({"env_id": "MiniGrid-DoorKey-8x8-v0"})),
     ("steps", "tasks[1]")),
    (MGT_TOML.replace("[ppo]", "[PPO]"), "PPO", False, "[PPO] in a TOML spec", "ppo.toml"),
]  # fmt: skip


def shown(text: str) -> str:
    return text.replace("\n", "\\n")


def spec_edit(name: str, text: str | bytes, names, ok: bool = False, argv=None, what=None):
    """A spec case: ``text`` written to ``name`` and given to plan (or ``argv``)."""
    argv = argv or ["plan", name, "--probe-updates", "0"]
    return fifth("specs", "study", argv, names, ok, works=(put(name, text),), what=what)


CASES: list[dict] = [
    *(fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
      for command, argv, names, *rest in FLAGS),
    *(spec_edit("edit.toml", text.replace(old, new, 1), names, *ok, what=shown(new))
      for text, old, new, names, *ok in SPEC_EDITS),
    spec_edit("edit.toml", LATIN1.encode("latin-1"), "edit.toml", what="saved as Latin-1"),
    *(spec_edit(rest[2] if len(rest) > 2 else "spec.json", text, names, *rest[:1],
                argv=["plan", rest[2] if len(rest) > 2 else "spec.json"],
                what=rest[1] if len(rest) > 1 else None)
      for text, names, *rest in JSON_TEXTS),
]  # fmt: skip
