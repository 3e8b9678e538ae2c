"""The sixth reliability trial's cases: lab (see reliability_trial.py).

The lab's command lines (simoun-sweep, simoun-study, simoun-report, simoun-analyze, the MiniGrid
study and the driving references) given bad values, typos, conflicting or valid combinations and
paths that do not exist, and the studies' spec files (TOML and JSON) edited by hand."""

from __future__ import annotations

import json
from pathlib import Path

from reliability_trial import (
    ARCH,
    DMC100K,
    DMC_RUN,
    DRQ_RUN,
    HIGHWAY_SPEC,
    MG,
    MGT,
    MGT_SPEC,
    SPEC,
    SW,
    V2_SPEC,
    bias,
    driving,
    fifth,
    lab_copy,
    masks,
    probe,
    put,
    report_argv,
    small_probe,
    study_run,
    sweep_tiny,
)

PPO_CHECK = lab_copy("minigrid-v2/ppo-check", "ppoc")
SPEC_COPY = put("my-dmc100k.toml", SPEC)  # the archive's spec kept under another name


def without(argv: list[str], flag: str) -> list[str]:
    """``argv`` without ``flag`` and its value."""
    at = argv.index(flag)
    return argv[:at] + argv[at + 2 :]


def made_dir(name: str):
    """Work: an empty directory ``name`` in the case's directory."""
    return lambda here: (here / name).mkdir()


def masks_done(here: Path) -> None:
    """``m``: the masks of the run already written there."""
    from simoun_lab.cli import analyze

    assert analyze.main(["masks", str(here / "run"), "--steps", "1", "--out", str(here / "m")]) == 0


def tuning_json(change) -> str:
    """The MiniGrid PPO tuning spec (docs/studies/minigrid-v2/tuning/spec.json) changed."""
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec, indent=2)


# command lines: (command, argv, what the refusal names[, valid[, works]])
FLAGS = [
    # simoun-sweep: refused before Ray starts, or (the guard) read as work started
    ("sweep", [*without(sweep_tiny(), "--env"), "--envs", "Pendulum-v1,Pendulum-v1"],
     ("Pendulum-v1", "--envs")),
    ("sweep", [*without(sweep_tiny(), "--env"), "--envs", "Pendulum-v1,"], "--envs"),
    ("sweep", sweep_tiny("--seeds", "0,2,5"), "", True),
    ("sweep", sweep_tiny("--seeds", "0..4"), "--seeds"),
    ("sweep", sweep_tiny("--seeds", "0 1 2"), "--seeds"),
    ("sweep", sweep_tiny("--grid", "agent.recipe=simoun,sacc"), "sacc"),
    ("sweep", sweep_tiny("--grid", "agent.recipe=simoun", "--grid", "agent.recipe=drq"),
     "agent.recipe"),
    ("sweep", sweep_tiny("--grid", "agent.n-step=1,3"), ("agent.n-step", "n_step"), True),
    ("sweep", sweep_tiny("--grid", "agent.lr=1e-3:1e-2"), "agent.lr"),
    ("sweep", sweep_tiny("--cpus-per-trial", "1.5"), "--cpus-per-trial"),
    ("sweep", sweep_tiny("--gpus-per-trial", "0"), "", True),
    ("sweep", sweep_tiny("--num-cpus", "-1"), "--num-cpus"),
    ("sweep", [*without(sweep_tiny(), "--image-size"), "--grid", "image_size=32,48"], "", True),
    ("sweep", sweep_tiny("--grid", "agent.lr=1e-3"), "agent.lr", True),
    ("sweep", sweep_tiny("--grid", "agent.recipe=drqv2", "--grid", "agent.n_step=1,3"),
     "n_step", True),
    ("sweep", sweep_tiny("--grid", "agent.recipe=simoun,drq", "--set", "agent.recipe=sac"),
     "agent.recipe", True),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--envs", "Acrobot-v1"], "--envs", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--preset", "cpu"], "--preset", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--set", "agent.lr=1e-3"], ("agent.lr", "--set"),
     False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--total-env-steps", "80"], "", True, (SW,)),
    ("sweep", ["--resume"], "--sweep-dir"),
    ("sweep", ["--resume", "--sweep-dir", "sw/base"], ("sw/base", "sweep.json"), False, (SW,)),
    # simoun-study: plan, run, report and their arguments
    ("study", ["plan", "spec.toml", "--probe-updates", "1.5"], "--probe-updates"),
    ("study", ["plan", "--spec", "spec.toml"], "--spec"),
    ("study", ["Plan", "spec.toml"], "Plan"),
    ("study", ["plan", "arch", "--probe-updates", "0"], "arch", False, (ARCH,)),
    ("study", ["plan", "ppoc/spec.json"], "", True, (PPO_CHECK,)),
    ("study", ["plan", "spec.TOML", "--probe-updates", "0"], "spec.TOML", True,
     (put("spec.TOML", SPEC),)),
    ("study", ["plan", "nowhere.toml"], "nowhere.toml"),
    ("study", ["report", "spec.toml"], "--study-dir"),
    ("study", ["report", "dmc100k.toml", "--study-dir", "nowhere"], "nowhere", False, (DMC100K,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch/tuning"], ("tuning", "study.json"),
     False, (ARCH, DMC100K)),
    ("study", ["report", "my-dmc100k.toml", "--study-dir", "arch"], ("my-dmc100k", "spec"), True,
     (ARCH, SPEC_COPY)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch"], "", True,
     (ARCH, put("dmc100k.toml", "# the first DMC study\n" + SPEC))),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch"], ("seeds", "another spec"), False,
     (ARCH, put("dmc100k.toml", SPEC.replace('= "1-5"', '= "1-4"', 1)))),
    ("study", ["report", "dmc100k-v2.toml", "--study-dir", "arch"], ("another spec", "dmc100k"),
     False, (ARCH, put("dmc100k-v2.toml", V2_SPEC))),
    ("study", study_run("--num-cpus", "1"), "", True),
    ("study", ["run", "spec.toml", "--study-dir", "/proc/x"], "--study-dir"),
    ("study", ["run", "nowhere.toml", "--study-dir", "s"], "nowhere.toml"),
    ("study", study_run("--resume", "--allow-other-commit"), ("--resume", "study.json")),
    ("study", ["run", "mgt/spec.json", "--study-dir", "s"], "", True, (MGT,)),
    # simoun-report
    ("report", report_argv("--at-step", "20", "--at-wall-time", "5"),
     ("--at-step", "--at-wall-time")),
    ("report", report_argv("--at-step", "2e4"), "--at-step"),
    ("report", report_argv("--at-step", "20k"), "--at-step"),
    ("report", report_argv("--at-wall-time", "1h"), "--at-wall-time"),
    ("report", report_argv("--at-wall-time", "00:05:00"), "--at-wall-time"),
    ("report", ["arch/tuning"], "", True, (ARCH,)),
    ("report", ["arch/evaluation/simoun"], "", True, (ARCH,)),
    ("report", ["{run}/eval.csv"], "eval.csv"),
    ("report", ["e"], ("e", "no run"), False, (made_dir("e"),)),
    ("report", ["mgt/MiniGrid-DoorKey-6x6-v0"], ("minigrid_study", "MiniGrid", "config.json"),
     True, (MGT,)),
    # simoun-analyze
    ("analyze", bias("--pairs", "1e3"), "--pairs"),
    ("analyze", ["bias"], "RUN"),
    ("analyze", bias("--pairs", "8", "--out", "b", "--seed", str(2**32)), "seed", True),
    ("analyze", masks("--steps", "1", "--query", "0,0"), "", True),
    ("analyze", masks("--query", "1", "2"), ("--query", "2")),
    ("analyze", masks("--steps", "1", "--out", "m"), ("--overwrite", "m"), False, (masks_done,)),
    ("analyze", ["Masks", "{run}"], "Masks"),
    ("analyze", ["bias", "dmc", "drq", "--pairs", "8"], "--out", False, (DMC_RUN, DRQ_RUN)),
    ("analyze", ["masks", "{run}/checkpoint.pt", "--steps", "1"], "", True),
    ("analyze", masks("--steps", "1", "--query", "16,16,"), "--query"),
    ("analyze", bias("--pairs", "8", "--recolour", "Conv"), "Conv"),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["report", "--archive", "mgt", "--spec", "mgt/spec.json"], "", True, (MGT,)),
    ("minigrid", ["select", "--archive", "mgt", "--spec", "none"], "", True, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "nowhere.json"], "nowhere.json", False,
     (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "spec.toml"], ("spec.toml", "JSON"),
     False, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt/MiniGrid-DoorKey-6x6-v0"], ("spec.json",
                                                                          "--archive"), False,
     (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "1.5"],
     "--concurrent", False, (MGT,)),
    ("minigrid", ["run", "--archive", "nowhere", "--work-dir", "wd"], "nowhere"),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "mgt/spec.json", "--spec",
                  "mg/spec.json"], "--spec", False, (MG, MGT)),
    ("minigrid", ["Run", "--archive", "mg"], "Run", False, (MG,)),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "0",
                       "--settings.n-steps", "32", "--settings.env-id", "MiniGrid-Empty-5x5-v0"),
     ("n-envs", "n_envs")),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id", "Pendulum-v1"),
     "Pendulum-v1"),
    ("minigrid", small_probe("--probes", "rnd,scale=0.01"), ("rnd,scale", "--probes")),
    ("minigrid", small_probe("--probes", "rnd", "--out", "p.txt"), ("p.txt", "--out"), False,
     (put("p.txt", "notes\n"),)),
    ("minigrid", small_probe("--probes", "consistency_lr1e-4"), "", True),
    ("minigrid", ["probe", "--out", "p", "--probes", "rnd", "--settings.steps", "512",
                  "--settings.env_id", "MiniGrid-Empty-5x5-v0"], "--settings.env_id"),
    # python -m simoun_agent.run.driving_reference
    ("driving", driving("--episodes", "1", "--preset", "highway-cpu", "--seed", "0"), "", True),
    ("driving", driving("--preset", "Highway"), "Highway"),
    ("driving", driving("--preset", "cpu"), ("cpu", "preset")),
    ("driving", driving("--video", "d.webm"), "--video"),
    ("driving", driving("--episodes", "1", "--json", "d.JSON"), "--json", True),
    ("driving", driving("--seed", "-5"), "--seed"),
    ("driving", driving("--episodes", "1", "--video", "nowhere/d.gif"), "--video"),
    ("driving", driving("--episodes", "1", "--video", "none"), "", True),
]  # fmt: skip

# the DMC study's spec edited by hand, given to plan: (text replaced, by, names[, valid])
DMC_EDITS = [
    ("[tuning]\ntasks", "[tunning]\ntasks", "tunning"),
    ('[evaluation]\ntasks = ["dm_control/cartpole-swingup-v0", "dm_control/cheetah-run-v0"]\n'
     'seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }\n'
     "env_steps = 100_000\n", "", "evaluation"),
    ('[base]\npreset = "cpu"\neval_every = 10_000\neval_episodes = 10\nvideo = false\n', "",
     "base", True),
    ("[resources]\ncpus_per_trial = 1          # one torch thread per run\n"
     "max_concurrent_trials = 2   # two runs at a time on a 2-core machine\n", "", "resources",
     True),
    ('selection = "auc"\n', "", "selection"),
    ('recipes = ["simoun", "drq", "drqv2", "rad", "curl"]\n', "", "recipes"),
    ('grid_overrides = ["agent.n_step"]\n', "", ("grid_overrides", "n_step")),
    ('grid_overrides = ["agent.n_step"]', 'grid_overrides = ["agent.n_step", "agent.lr"]',
     "agent.lr"),
    ("[grid]\nagent.n_step = [1, 3]", "[grid]\nagent = { n_step = [1, 3] }", "", True),
    ("[grid]\nagent.n_step = [1, 3]", "[grid.agent]\nn_step = [1, 3]", "", True),
    ("video = false", 'video = false\nagent.recipe = "drq"', "recipe"),
    ("env_steps = 100_000", 'env_steps = { "dm_control/cartpole-swingup-v0" = 100_000 }',
     "cheetah"),
    ("env_steps = 100_000", 'env_steps = { "dm_control/cartpole-swingup-v0" = 100_000, '
     '"dm_control/cheetah-run-v0" = 50_000 }', "", True),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["dm_control/walker-walk-v0"]',
     "walker", True),
    ("action_repeat = 4", "action_repeat = 4\nagent.lr = 1e-3", "lr", True),
    ("action_repeat = 4", 'action_repeat = 4\nenv = "Pendulum-v1"', "env"),
    ("action_repeat = 4", "action_repeat = 4\nseed = 3", "seed"),
    ("max_concurrent_trials = 2", 'max_concurrent_trials = 2\ngpus_per_trial = "auto"', "", True),
    ("max_concurrent_trials = 2", 'max_concurrent_trials = 2\ngpus_per_trial = "all"',
     "gpus_per_trial"),
    ("cpus_per_trial = 1 ", "cpus_per_trial = 0 ", "cpus_per_trial"),
    ("max_concurrent_trials = 2", 'max_concurrent_trials = 2\nmemory = "4G"', "memory"),
    ("env_steps = 50_000", "env_steps = 50_000\nepisodes = 10", "episodes"),
    ("env_steps = 100_000", 'env_steps = 100_000\nselection = "auc"', "selection"),
    ("eval_episodes = 10", "eval_episodes = 0", "eval_episodes"),
]  # fmt: skip
# the same spec with its recipes moved below [base] by mistake (a top-level key after a header)
MOVED = SPEC.replace('recipes = ["simoun", "drq", "drqv2", "rad", "curl"]\n', "", 1).replace(
    "video = false\n", 'video = false\nrecipes = ["simoun", "drq", "drqv2", "rad", "curl"]\n', 1
)
# the highway and the v2 specs edited: (spec text, text replaced, by, names[, valid])
OTHER_EDITS = [
    (HIGHWAY_SPEC, "seeds = [101]", "seeds = [101, 101]", "seeds"),
    (HIGHWAY_SPEC, "seeds = [101]", "seeds = []", "seeds"),
    (HIGHWAY_SPEC, "env_steps = 5_000", "env_steps = 100", ("env_steps", "eval_every"), True),
    (HIGHWAY_SPEC, 'seeds = "1-5"', 'seeds = "1-5"\nenv_steps_per_task = 10', "env_steps_per_task"),
    (HIGHWAY_SPEC, 'recipes = ["simoun", "drq", "rad"]', 'recipes = ["simoun", "drq", "rad",]', "",
     True),
    (HIGHWAY_SPEC, "agent.n_step = [3]", "agent.n_step = 3", "n_step"),
    (V2_SPEC, "\n[diagnostics]", '\n[diagnostics]\nsac = ["simoun_no_aux"]', "sac"),
    (V2_SPEC, "\nepisodes = 10", '\nepisodes = 10\nseeds = "1-2"', "seeds"),
    (V2_SPEC, 'modes = ["color_easy", "color_hard", "video_easy", "video_hard"]',
     'modes = ["color-easy"]', "color-easy"),
    (V2_SPEC, "\n[generalization]", "\n[evaluation.generalization]", "generalization"),
]  # fmt: skip
for _old, *_ in DMC_EDITS:
    assert _old in SPEC, _old
for _text, _old, *_ in OTHER_EDITS:
    assert _old in _text, _old

# the MiniGrid PPO tuning spec edited by hand, given to plan: (change, names[, valid])
JSON_EDITS = [
    (lambda s: s.update(eval_seed=100), ("eval_seed", "seeds")),
    (lambda s: s["ppo"].update(batch_size=1000), "batch_size", True),
    (lambda s: s["tasks"][0].update(steps=1000), "steps"),
    (lambda s: s.update(evaluations=1000), ("evaluations", "steps"), True),
    (lambda s: s.update(arms=["ppo", "consistency,normalization=paper,scale=0.001"]), "", True),
    (lambda s: s["tasks"][0].update(env_id="minigrid-doorkey-6x6-v0"), "minigrid-doorkey-6x6-v0"),
    (lambda s: s["ppo"].update(policy="CnnPolicy"), "policy"),
    (lambda s: s.update(eval_seed=2e6), "eval_seed"),
    (lambda s: s.update(device="auto"), "device", True),
    (lambda s: s["ppo"].update(gamma=1), "gamma", True),
    (lambda s: s.update(eval_episodes=None), "eval_episodes"),
    (lambda s: s.pop("arms"), "arms"),
    (lambda s: s.update(device="CPU"), ("CPU", "device")),
    (lambda s: s.update(notes="tuning round 2"), "notes"),
]  # fmt: skip
TRAILING_COMMA = MGT_SPEC.replace('"device": "cpu"', '"device": "cpu",', 1)
COMMENTED = MGT_SPEC.replace('"evaluations": 20,', '"evaluations": 20,  // every 20k steps', 1)
assert TRAILING_COMMA != MGT_SPEC and COMMENTED != MGT_SPEC


def json_change(change) -> str:
    """What ``change`` does to the tuning spec, for the table: each top-level key it changes."""
    old, new = json.loads(MGT_SPEC), json.loads(tuning_json(change))
    return "; ".join(
        f"{key}={json.dumps(new[key])}" if key in new else f"no {key}"
        for key in sorted(old.keys() | new.keys())
        if json.dumps(old.get(key)) != json.dumps(new.get(key))
    )


def spec_edit(name: str, text: str, names, ok: bool = False, argv=None, what: str = "") -> dict:
    """A spec case: ``text`` written to ``name`` and given to plan (or ``argv``)."""
    argv = argv or ["plan", name, "--probe-updates", "0"]
    return fifth("specs", "study", argv, names, ok, works=(put(name, text),), what=what or None)


def shown(text: str) -> str:
    return text.replace("\n", "\\n")


CASES: list[dict] = [
    *(fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
      for command, argv, names, *rest in FLAGS),
    *(spec_edit("edit.toml", SPEC.replace(old, new, 1), names, *ok, what=shown(new) or "removed")
      for old, new, names, *ok in DMC_EDITS),
    spec_edit("moved.toml", MOVED, "recipes", what="recipes below [base]"),
    *(spec_edit("other.toml", text.replace(old, new, 1), names, *ok, what=shown(new))
      for text, old, new, names, *ok in OTHER_EDITS),
    *(spec_edit("spec.json", tuning_json(change), names, *ok, argv=["plan", "spec.json"],
                what=json_change(change))
      for change, names, *ok in JSON_EDITS),
    spec_edit("spec.json", TRAILING_COMMA, "spec.json", argv=["plan", "spec.json"],
              what="a trailing comma"),
    spec_edit("spec.json", COMMENTED, "spec.json", argv=["plan", "spec.json"],
              what="a // comment"),
    fifth("specs", "minigrid", ["select", "--archive", "mgt", "--spec", "spec.json"],
          ("arms", "differ"), True,
          works=(MGT, put("spec.json", tuning_json(lambda s: s["arms"].reverse()))),
          what="arms reversed"),
    fifth("specs", "minigrid", ["report", "--archive", "mgt", "--spec", "spec.json"],
          ("evaluations", "differ"), False,
          works=(MGT, put("spec.json", tuning_json(lambda s: s.update(evaluations=21)))),
          what="evaluations=21"),
    spec_edit("bad.json", tuning_json(lambda s: s["tasks"][0].update(steps=1000)), "steps",
              argv=["run", "bad.json", "--study-dir", "s"], what="steps=1000"),
    spec_edit("bad.toml", SPEC.replace("cpus_per_trial = 1 ", "cpus_per_trial = 0 ", 1),
              "cpus_per_trial", argv=["run", "bad.toml", "--study-dir", "s"],
              what="cpus_per_trial = 0"),
]  # fmt: skip
