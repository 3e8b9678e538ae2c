"""The tenth reliability trial's cases: lab (see reliability_trial.py).

The lab's command lines on surfaces the earlier trials left alone: simoun-sweep's --grid of
agent keys whose per-trial checks tie them to other keys (critic or target augmentations without
the shift, separate trunks on an encoder with auxiliary losses), of choices spelt with hyphens or
another name, of one key in two --grid flags or in --set too, of keys the sweep sets itself
(torch_threads) or that take other types (env_kwargs, env_module, updates_per_step), of a key and
its values separated by a colon or semicolons, and valid grids of encoders, grayscale, recipes and
two keys in one --grid; --seeds written with blanks, as a slice, twice or as mixed ranges and
lists; --envs separated by blanks, ending in a comma, lower-cased or a MiniGrid id; --sweep-dir
given as an unexpanded ~, an existing file, an empty string or a folder inside the sweep;
--resume with --envs, --env, --preset, --set or a recipe. simoun-study plan given two specs, a
flag of run, fractional or exponent probe counts and a spec named without its suffix; report and
run given a part of an archive, a sweep, a run, a spec file or an unexpanded ~ as the study
directory, another study's archive without --resume, --archive to report and a MiniGrid spec;
simoun-report given a run's config.json, a spec file, two directories, an empty --out, budgets
written with a decimal comma or in hex, a study's phase folder and a MiniGrid task folder; the
MiniGrid study's probe with no probes, a misspelt probe, a MODULE:ID or BabyAI task, a fractional
budget and an earlier probe's folder, and run/select given a file, an unexpanded ~, a run, a
missing spec, a fractional --concurrent or a task folder. The DMC study's TOML spec edited by hand
in new ways: config keys the phases own put in [grid] or [base] (seed, seeds, total_env_steps,
action_repeat beside its per-task values), nested or mixed grid values, grid_overrides naming a
key outside the grid, evaluation seeds that miss a task or name a misspelt one, an evaluation
phase that drops a task its seeds still name, per-task seeds or string values, a fractional CPU
count or a quoted concurrency, recipes spelt with hyphens, capitals or blanks, a selection list,
evaluations rarer than the tuning budget, a negative budget, tables in capitals, as arrays or
given twice; and valid edits (a shorter evaluation budget, a budget no action repeat divides, a
spec with no preset, no description or no selection). The MiniGrid PPO JSON spec edited in new
ways: arms in capitals, with blanks, a semicolon or another method's name, scale 0 or negative,
one arm spelt twice; unknown keys in ppo or a task, a device that is no torch device or empty, a
budget shorter than one rollout, a rollout longer than the budget, a string or fractional count
or seed, a trailing comma, NaN, a file saved as UTF-16; and valid edits (no PPO baseline arm, no
ppo table, cuda:0, a count written 128.0, a budget no rollout divides)."""

from __future__ import annotations

import json
from pathlib import Path

from reliability_trial import (
    ARCH,
    DMC100K,
    HIGHWAY_SPEC,
    MG,
    MGT,
    MGT_SPEC,
    SPEC,
    SW,
    SW_RUN,
    fifth,
    put,
    sweep_tiny,
)

SHORT = ("--total-env-steps", "40")
RESUME = ["--resume", "--sweep-dir", "sw"]
MGT_FILE = put("mgt.json", MGT_SPEC)
HIGHWAY = put("highway.toml", HIGHWAY_SPEC)
PROBE = ["probe", "--out", "p", "--probes", "rnd", "--settings.steps", "512"]
SMALL = ["--settings.n-envs", "2", "--settings.n-steps", "32", "--settings.env-id",
         "MiniGrid-Empty-5x5-v0"]  # fmt: skip


def grid(*values: str) -> list[str]:
    """The tiny sweep's flags (40 env steps), then ``--grid`` with each of ``values``."""
    flags = sweep_tiny(*SHORT)
    for value in values:
        flags += ["--grid", value]
    return flags


def bare(flag: str, *extra: str) -> list[str]:
    """The tiny sweep's flags (40 env steps) with ``extra``, less the base ``flag`` and its
    value: the key a case gives in --envs is not given as a base flag too."""
    flags = sweep_tiny(*SHORT, *extra)
    at = flags.index(flag)
    return flags[:at] + flags[at + 2 :]


def probe_on(env_id: str = "MiniGrid-Empty-5x5-v0", n_envs: str = "2", *extra: str) -> list[str]:
    """A small RND probe (512 env steps, blocks of ``n_envs`` x 32) of ``env_id``."""
    return [*PROBE, "--settings.n-envs", n_envs, "--settings.n-steps", "32",
            "--settings.env-id", env_id, *extra]  # fmt: skip


def earlier_probe(here: Path) -> None:
    """``p``: the folder of an earlier probe (its probe.csv and probe.md)."""
    (here / "p").mkdir()
    (here / "p/probe.csv").write_text("probe,spearman\nrnd,0.5\n")
    (here / "p/probe.md").write_text("# probe\n")


# command lines: (command, argv, what the refusal names[, valid[, works]])
FLAGS = [
    # simoun-sweep --grid: per-trial checks that tie a key to another, spellings, separators
    ("sweep", grid("agent.critic_augmentations=1,2"), ("critic_augmentations", "augmentation")),
    ("sweep", grid("agent.separate_trunks=false,true"), "separate_trunks"),
    ("sweep", grid("agent.encoder=single,stacked"), "", True),
    ("sweep", grid("agent.encoder=dual_interactive,dual-interactive"), "dual-interactive"),
    ("sweep", grid("agent.conv_init=orthogonal,delta-orthogonal"), "delta-orthogonal"),
    ("sweep", grid("agent.target_augmentations=2,1"), ("target_augmentations", "augmentation")),
    ("sweep", grid("agent.pixel_offset=0,abc"), ("pixel_offset", "abc")),
    ("sweep", grid("agent.next_state_encoder=target,ema"), "ema"),
    ("sweep", grid("agent.contrastive_view=random_conv,random-conv"), "random-conv"),
    ("sweep", grid("agent.similarity_init=identity,eye"), "eye"),
    ("sweep", grid("env_kwargs=1,2"), "env_kwargs"),
    ("sweep", grid("updates_per_step=1,0"), "updates_per_step"),
    ("sweep", grid("env_module=nosuchmodule,none"), "nosuchmodule"),
    ("sweep", grid("grayscale=true,false"), "", True),
    ("sweep", grid("grayscale=yes,no"), "grayscale", True),
    ("sweep", grid("agent.lr=1e-3", "agent.lr=3e-4"), "agent.lr"),
    ("sweep", grid("agent.lr:1e-3,3e-4"), ("--grid", "agent.lr:1e-3,3e-4")),
    ("sweep", grid("agent.n_step=1;3"), ("agent.n_step", "1;3")),
    ("sweep", grid("agent.hidden_dim=16,32.5"), ("hidden_dim", "32.5")),
    ("sweep", grid("agent.lr=3e-4,-1e-3"), ("lr", "-1e-3", "-0.001")),
    ("sweep", grid("torch_threads=1,2"), ("torch_threads", "--cpus-per-trial")),
    ("sweep", grid("agent.recipe=simoun_no_aux,drqv2_easy"), "", True),
    ("sweep", grid("agent.n_step=1,3", "agent.lr=1e-3,3e-4"), "", True),
    ("sweep", sweep_tiny(*SHORT, "--set", "agent.lr=1e-3", "--grid", "agent.lr=1e-3,3e-4"),
     "agent.lr"),
    ("sweep", sweep_tiny(*SHORT, "--run-dir", "r"), ("--run-dir", "--sweep-dir")),
    # --seeds and --envs written another way
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0 1 2"), "--seeds"),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0:3"), "--seeds"),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0-1,5"), "--seeds", True),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0-1", "--seeds", "2"), "--seeds"),
    ("sweep", bare("--env", "--envs", "simoun/PointReach-v0,"), "--envs", True),
    ("sweep", bare("--env", "--envs", "simoun/PointReach-v0 Pendulum-v1"), "--envs"),
    ("sweep", bare("--env", "--envs", "MiniGrid-Empty-5x5-v0"), "MiniGrid-Empty-5x5-v0"),
    ("sweep", bare("--env", "--envs", "simoun/PointReach-v0,pendulum-v1"), "pendulum-v1"),
    # --sweep-dir
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", "~/sw"), ("~/sw", "expanduser")),
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", "spec.toml"), "spec.toml"),
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", ""), "--sweep-dir"),
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", "/proc/sw"), "/proc/sw"),
    ("sweep", ["--resume", "--sweep-dir", "sw/"], "", True, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw/base"], ("sw/base", "sweep.json"), False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", SW_RUN], (SW_RUN, "sweep.json"), False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--sweep-dir", "sw2"], "--sweep-dir", False,
     (SW,)),
    # --resume with flags that change the sweep
    ("sweep", [*RESUME, "--envs", "Pendulum-v1"], "--envs", False, (SW,)),
    ("sweep", [*RESUME, "--preset", "cpu"], "--preset", False, (SW,)),
    ("sweep", [*RESUME, "--set", "agent.lr=3e-4"], "agent.lr", False, (SW,)),
    ("sweep", [*RESUME, "--env", "Pendulum-v1"], "--env", False, (SW,)),
    ("sweep", [*RESUME, "--agent.recipe", "drq"], "recipe", False, (SW,)),
    ("sweep", ["--sweep-dir", "sw", "--resume", "--total-env-steps", "40"], "", True, (SW,)),
    ("sweep", sweep_tiny(*SHORT, "--gpus-per-trial", "AUTO"), "--gpus-per-trial", True),
    # simoun-study plan
    ("study", ["plan", "spec.toml", "dmc100k.toml"], "dmc100k.toml", False, (DMC100K,)),
    ("study", ["plan", "--probe-updates", "0", "spec.toml"], "", True),
    ("study", ["plan", "spec.toml", "--study-dir", "s"], "--study-dir"),
    ("study", ["plan", "spec.toml", "--probe-updates", "0", "--resume"], "--resume"),
    ("study", ["plan", "spec.toml", "--probe-updates", "2.5"], "--probe-updates"),
    ("study", ["plan", "spec.toml", "--probe-updates", "1e2"], "--probe-updates"),
    ("study", ["plan", "spec", "--probe-updates", "0"], ("spec.toml", "'spec'")),
    # simoun-study report and run
    ("study", ["report", "spec.toml"], "--study-dir"),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch/"], "", True, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch/tuning"],
     ("arch/tuning", "study.json"), False, (ARCH, DMC100K)),
    ("study", ["report", "mgt.json", "--study-dir", "mgt"], "minigrid_study", True,
     (MGT, MGT_FILE)),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--resume"], ("--resume", "s"), True),
    ("study", ["run", "spec.toml", "--study-dir", "spec.toml"], ("--study-dir", "spec.toml")),
    ("study", ["run", "spec.toml", "--study-dir", "~/s"], ("~/s", "expanduser")),
    ("study", ["run", "spec.toml", "--study-dir", "sw"], ("sw", "sweep"), False, (SW,)),
    ("study", ["run", "spec.toml", "--study-dir", "run"], ("run", "simoun-train")),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--archive", "spec.toml"],
     ("--archive", "spec.toml")),
    ("study", ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "mg"],
     ("mg", "MiniGrid"), False, (MG, DMC100K)),
    ("study", ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch"],
     ("--resume", "arch"), False, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--archive", "arch"], "--archive",
     False, (ARCH, DMC100K)),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--allow-other-commit"],
     "--allow-other-commit", True),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--num-cpus", "1"], "", True),
    # simoun-report
    ("report", ["run/config.json"], ("config.json", "run")),
    ("report", ["."], "", True),
    ("report", ["{run}", "{run}"], ("one", "unrecognized")),
    ("report", ["{run}", "--out", ""], "--out"),
    ("report", ["{run}", "--at-wall-time", "1,5"], "--at-wall-time"),
    ("report", ["{run}", "--at-step", "0x28"], "--at-step"),
    ("report", ["spec.toml"], "spec.toml"),
    ("report", ["arch/evaluation"], ("simoun-study", "arch/evaluation"), True, (ARCH,)),
    ("report", ["mgt/MiniGrid-DoorKey-6x6-v0"], ("minigrid_study", "MiniGrid"), False, (MGT,)),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["probe", "--out", "p", "--settings.steps", "512", *SMALL, "--probes"],
     "--probes"),
    ("minigrid", probe_on("minigrid:MiniGrid-Empty-5x5-v0"), "minigrid:", True),
    ("minigrid", ["probe", "--out", "p", "--probes", "rnd", "--settings.steps", "512.0", *SMALL],
     "--settings.steps"),
    ("minigrid", ["probe", "--out", "p", "--probes", "consistency_lr1e-3", "--settings.steps",
                  "512", *SMALL], "consistency_lr1e-3"),
    ("minigrid", probe_on("BabyAI-GoToRedBall-v0"), "BabyAI", True),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "1.5"],
     "--concurrent", False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--spec", "mgt/spec.toml"],
     "mgt/spec.toml", False, (MGT,)),
    ("minigrid", ["select", "--archive", "run"], ("run", "simoun-train"), False),
    ("minigrid", probe_on(), "", True, (earlier_probe,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--concurrent", "64"],
     "--concurrent", True, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "spec.toml"],
     ("--work-dir", "spec.toml"), False, (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "~/wd"], ("~/wd", "expanduser"),
     False, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "highway.toml"], "highway.toml",
     False, (MGT, HIGHWAY)),
    ("minigrid", ["select", "--archive", "mgt/MiniGrid-DoorKey-6x6-v0"],
     ("mgt/MiniGrid-DoorKey-6x6-v0", "spec.json"), False, (MGT,)),
]  # fmt: skip

GRID = "agent.n_step = [1, 3]"
TUNING = 'seeds = "101-102"\nenv_steps = 50_000'
CARTPOLE = '[tasks."dm_control/cartpole-swingup-v0"]\naction_repeat = 8'
CHEETAH = '[tasks."dm_control/cheetah-run-v0"]\naction_repeat = 4'
EVAL_TASKS = 'tasks = ["dm_control/cartpole-swingup-v0", "dm_control/cheetah-run-v0"]'
RECIPES = 'recipes = ["simoun", "drq", "drqv2", "rad", "curl"]'
DESCRIPTION = SPEC[SPEC.index('description = """') : SPEC.index("recipes = ")]
# the DMC study's spec edited by hand, given to plan: (text replaced, by, names[, valid])
SPEC_EDITS = [
    (GRID, GRID + "\nseed = [1, 2]", ("seed", "seeds")),
    (GRID, GRID + "\ntotal_env_steps = [10_000, 20_000]", ("total_env_steps", "env_steps")),
    (GRID, GRID + "\naction_repeat = [4, 8]", "action_repeat"),
    (GRID, "agent.n_step = [[1, 3]]", "agent.n_step"),
    (GRID, "agent.n_step = [1, 3.5]", ("agent.n_step", "3.5")),
    ('grid_overrides = ["agent.n_step"]', 'grid_overrides = ["agent.n_step", "agent.lr"]',
     ("agent.lr", "grid_overrides")),
    ("env_steps = 100_000", "env_steps = 25_000", "env_steps", True),
    (EVAL_TASKS, 'tasks = ["dm_control/cheetah-run-v0"]', ("cartpole-swingup", "seeds")),
    (CARTPOLE, CARTPOLE + '\nseeds = "1-3"', "seeds"),
    (CARTPOLE, CARTPOLE.replace("= 8", '= "8"'), "action_repeat"),
    (CHEETAH, CHEETAH + "\nagent.lr = 1e-3", "agent.lr", True),
    ("cpus_per_trial = 1 ", "cpus_per_trial = 0.5 ", "cpus_per_trial"),
    (RECIPES, 'recipes = ["simoun", "drq", "drqv2-easy"]', "drqv2-easy"),
    (RECIPES, 'recipes = ["Simoun", "drq"]', "Simoun"),
    ('selection = "auc"', 'selection = "auc "', "selection", True),
    ("eval_every = 10_000", "eval_every = 60_000", ("eval_every", "env_steps")),
    ('preset = "cpu"\n', "", "", True),
    ("[tuning]", "[Tuning]", "Tuning"),
    ("[tuning]", "[[tuning]]", "tuning"),
    ("video = false", 'video = false\nseeds = "1-3"', "seeds"),
    ('"dm_control/cheetah-run-v0" = "1-3"', '"dm_control/cheetah-run-v1" = "1-3"',
     "cheetah-run-v1"),
    ('seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }',
     'seeds = { "dm_control/cartpole-swingup-v0" = "1-5" }', "cheetah-run"),
    ("max_concurrent_trials = 2 ", 'max_concurrent_trials = "2" ', "max_concurrent_trials"),
    ('selection = "auc"', 'selection = ["auc"]', "selection"),
    ("env_steps = 100_000", "env_steps = -100_000", "env_steps"),
    (RECIPES, 'recipes = ["simoun drq"]', "simoun drq"),
    (TUNING, TUNING.replace("50_000", "50_001"), "env_steps", True),
    (DESCRIPTION, "", "", True),
    ('selection = "auc"\n', "", "selection", True),
    ("[resources]", "[grid]\nagent.lr = [1e-3]\n\n[resources]", ("grid", "edit.toml")),
]  # fmt: skip
for _old, *_ in SPEC_EDITS:
    assert _old in SPEC, _old


def tuning_json(change) -> str:
    """The MiniGrid PPO tuning spec (docs/studies/minigrid-v2/tuning/spec.json) changed."""
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec, indent=2)


def arms(*extra: str):
    """A change: the spec's arms are ppo and ``extra``."""
    return lambda s: s.update(arms=["ppo", *extra])


# the MiniGrid PPO tuning spec edited by hand, given to plan: (text, names[, valid[, what]])
JSON_TEXTS = [
    (tuning_json(arms("RND,scale=0.01")), "RND"),
    (tuning_json(arms("rnd, scale=0.01")), "rnd", True),
    (tuning_json(arms("rnd,scale=1e-2")), "", True),
    (tuning_json(arms("rnd,scale=0")), "scale"),
    (tuning_json(arms("rnd,scale=-0.01")), "scale"),
    (tuning_json(arms("rnd,scale=0.01", "rnd,scale=0.010")), ("arms", "rnd,scale=0.01")),
    (tuning_json(lambda s: s.update(arms=["rnd,scale=0.01"])), "", True),
    (tuning_json(lambda s: s.pop("ppo")), "ppo", True),
    (tuning_json(lambda s: s["ppo"].update(lr=3e-4)), "lr"),
    (tuning_json(lambda s: s["ppo"].update(n_steps=128.0)), "n_steps", True),
    (tuning_json(lambda s: s["ppo"].update(clip_range=-0.2)), "clip_range"),
    (tuning_json(lambda s: s.update(device="gpu")), "gpu"),
    (tuning_json(lambda s: s.update(device="cuda:0")), "cuda", True),
    (tuning_json(lambda s: s.update(eval_episodes=1.5)), "eval_episodes"),
    (tuning_json(lambda s: s.update(seed=0)), "seed"),
    (tuning_json(lambda s: s["tasks"][0].update(seed=100)), "seed"),
    (tuning_json(lambda s: s["tasks"][0].update(steps=400_001)), "steps", True),
    (tuning_json(lambda s: s["tasks"][0].update(steps=1000)), ("steps", "1024")),
    (tuning_json(lambda s: s["ppo"].update(n_steps=100_000)), ("n_steps", "steps")),
    (tuning_json(lambda s: s["ppo"].update(n_envs="8")), "n_envs"),
    (tuning_json(lambda s: s.update(eval_seed=2000000.5)), "eval_seed"),
    (tuning_json(lambda s: s.update(device="")), "device"),
    (tuning_json(arms("rnd;scale=0.01")), "rnd;scale=0.01"),
    (tuning_json(arms("curiosity,scale=0.01")), "curiosity"),
    (MGT_SPEC.replace('"device": "cpu"\n', '"device": "cpu",\n'), "spec.json", False,
     "a trailing comma after the last key"),
    (MGT_SPEC.replace('"learning_rate": 0.00025', '"learning_rate": NaN'), "learning_rate",
     False, "learning_rate NaN"),
    (MGT_SPEC.encode("utf-16"), "spec.json", False, "saved as UTF-16"),
]  # fmt: skip


def shown(text: str) -> str:
    return text.replace("\n", "\\n").replace("\t", "\\t")


def edited(old: str, new: str) -> str:
    """What a spec edit did, for the table: the new text, or the start of the text removed."""
    return shown(new) if new else f"removed: {shown(old)[:48]}"


def spec_edit(name: str, text: str | bytes, names, ok: bool = False, argv=None, what=None):
    """A spec case: ``text`` written to ``name`` and given to plan (or ``argv``)."""
    argv = argv or ["plan", name, "--probe-updates", "0"]
    return fifth("specs", "study", argv, names, ok, works=(put(name, text),), what=what)


CASES: list[dict] = [
    *(fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
      for command, argv, names, *rest in FLAGS),
    *(spec_edit("edit.toml", SPEC.replace(old, new, 1), names, *ok, what=edited(old, new))
      for old, new, names, *ok in SPEC_EDITS),
    *(spec_edit("spec.json", text, names, *rest[:1], argv=["plan", "spec.json"],
                what=rest[1] if len(rest) > 1 else None)
      for text, names, *rest in JSON_TEXTS),
]  # fmt: skip
