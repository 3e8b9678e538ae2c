"""The eleventh reliability trial's cases: lab (see reliability_trial.py).

The lab's command lines on surfaces the earlier trials left alone: simoun-sweep's --grid values
written with a capital E, as none, on/off or true/false, in hex, with a trailing comma or the
flag's own dashes, a top-level key under agent. or an agent key without its prefix, a per-trial
zero or negative size (feature_dim, aux_hidden_dim, num_filters, actor_update_every,
init_temperature, eval_episodes), values in the wrong units (a learning rate of 3, a pixel offset
of 128), a grid key that a base flag (not --set) also gives; --seeds in exponent form, with
leading zeros or as a hundred seeds; --envs naming a dm_control task without its version, mixing
families with an action repeat or with --env-kwargs only one of them takes; --gpus-per-trial
none, --verbose 1.0, a --sweep-dir with a blank or that is a study's archive; --resume given the
original command again or while a trial of the sweep still trains, a saved value repeated or
changed (--eval-every, --seeds, --cpus-per-trial, --image-size), flags that do not change the
sweep (--verbose, --gpus-per-trial auto), --run-dir, --env-module, --overwrite, an exponent
budget, and the sweep directory as ./sw, through .. or moved to another folder. simoun-study:
plan given --probe-updates twice, with underscores or as -p, a relative path from the wrong
folder, flags of run (--verbose, --num-cpus); run given plan's --probe-updates, an archive inside
the study directory, a study directory inside the archive or in a MiniGrid archive, a blank in
--study-dir, a MiniGrid spec with --num-cpus; report given run's flags or simoun-report's
--at-step, a path through .., the archive under another name, --study-dir twice, the archive's
report folder. simoun-report with -o, --overwrite, a letter O in --at-step, --out twice or
unwritable, a fractional wall time, a checkpoint file, sweep.json, the run's tb folder, --out
inside the sweep, a sweep whose trial still trains. simoun-analyze masks with --steps or --query
given twice, a query split by a semicolon or a blank, an MPS device, an empty --out, two runs;
bias on a CUDA device, with a fractional seed, on a run given with and without a slash, on a
study archive and on a MiniGrid PPO run. The MiniGrid study's run given --resume, --num-cpus,
--allow-other-commit or another study's archive as --work-dir; report given --at-step or a --spec
with a trailing blank; select given --selection, --archive twice or a copy of the archive's spec;
probe a task id without its version, a seed of 1.5, negative steps, --settings.env-id twice, a
step count with an underscore and --probes twice. The DMC study's TOML spec edited by hand in new
ways: base keys the study owns (env) or too small (image_size 8), a repeated or misspelt grid
value or key, grid_overrides without the agent. prefix, tuning seeds as a comma list, a misspelt
[resources] key or a device there, eval_every in a phase table or with units, a selection rule in
the evaluation table, a task table or tuning task without its dm_control/ prefix, per-task
evaluation seeds as a number, a recipe or a misspelt env_kwargs key in a task's table; the v2
spec's diagnostics with a method as an ablation, an ablation twice or spelt with hyphens, a tasks
key in [generalization], a quoted generalization episode count; the highway spec with its preset
spelt highway_cpu, env_kwargs as a table, as JSON text or with a misspelt highway config key, and
a task without its version or the slower highway-v0. The MiniGrid PPO JSON spec edited in new
ways: tasks as an object, a task id without its version, repeated seeds, a task without steps, a
misspelt or unknown normalization, arms spelt Arms, eval_every in place of evaluations; and valid
edits (a second task, an entropy bonus)."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
from pathlib import Path

from reliability_trial import (
    ARCH,
    DMC100K,
    DRQ_RUN,
    HIGHWAY_SPEC,
    MG,
    MGT,
    MGT_SPEC,
    SPEC,
    SW,
    SW_RUN,
    V2_SPEC,
    bias,
    fifth,
    lab_copy,
    masks,
    put,
    sweep_tiny,
)

SHORT = ("--total-env-steps", "40")
RESUME = ["--resume", "--sweep-dir", "sw"]
MGT_FILE = put("mgt.json", MGT_SPEC)
SMALL = ["--settings.n-envs", "2", "--settings.n-steps", "32", "--settings.env-id",
         "MiniGrid-Empty-5x5-v0"]  # fmt: skip
PROBE = ["probe", "--out", "p", "--probes", "rnd"]
BACKUP = lab_copy("dmc100k", "backup")  # the study's archive kept under another name


def moved_sweep(here: Path) -> None:
    """``sw`` moved to ``moved/sw2``, as a user tidying their sweeps does."""
    (here / "moved").mkdir()
    shutil.move(here / "sw", here / "moved/sw2")


HELD = []  # lock files kept open for the life of the case


def trial_in_use(here: Path) -> None:
    """``sw``'s trial unfinished and still training: its lock held, as a trainer holds it, by
    a sweep started earlier in another terminal."""
    (here / SW_RUN / "summary.json").unlink()
    handle = (here / SW_RUN / ".lock").open("a+")
    fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    HELD.append(handle)


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


def probe_on(env_id: str, *extra: str) -> list[str]:
    """A small RND probe (512 env steps, blocks of 2 x 32) of ``env_id``, with ``extra``."""
    return [*PROBE, "--settings.steps", "512", "--settings.n-envs", "2", "--settings.n-steps",
            "32", "--settings.env-id", env_id, *extra]  # fmt: skip


# command lines: (command, argv, what the refusal names[, valid[, works]])
FLAGS = [
    # simoun-sweep --grid values written another way
    ("sweep", grid("agent.lr=1E-3,3E-4"), "", True),
    ("sweep", grid("action_repeat=none,2"), "action_repeat", True),
    ("sweep", grid("agent.hidden_dim=16,0x20"), ("hidden_dim", "0x20")),
    ("sweep", grid("agent.batch_size=8,16,"), ("--grid", "agent.batch_size")),
    ("sweep", grid("--agent.lr=1e-3,3e-4"), ("--agent.lr", "agent.lr")),
    ("sweep", grid("agent.eval_every=20,40"), ("agent.eval_every", "eval_every")),
    ("sweep", grid("lr=1e-3,3e-4"), ("agent.lr", "'lr'")),
    ("sweep", grid("agent.curiosity=on,off"), "curiosity", True),
    ("sweep", grid("agent.curiosity=true,false"), "", True),
    ("sweep", bare("--eval-episodes", "--grid", "eval_episodes=1,0"), "eval_episodes"),
    ("sweep", sweep_tiny(*SHORT, "--agent.lr", "3e-4", "--grid", "agent.lr=1e-3,3e-4"),
     "agent.lr"),
    ("sweep", bare("--agent.feature-dim", "--grid", "agent.feature_dim=8,0"), "feature_dim"),
    ("sweep", bare("--agent.aux-hidden-dim", "--grid", "agent.aux_hidden_dim=16,-16"),
     "aux_hidden_dim"),
    ("sweep", grid("agent.init_temperature=0.1,0"), "init_temperature"),
    ("sweep", grid("agent.actor_update_every=2,0"), "actor_update_every"),
    ("sweep", grid("agent.lr=3e-4,3"), "agent.lr"),
    ("sweep", grid("agent.pixel_offset=0,128"), ("pixel_offset", "128")),
    ("sweep", bare("--agent.num-filters", "--grid", "agent.num_filters=4,0"), "num_filters"),
    # --seeds, --envs and the resources
    ("sweep", sweep_tiny(*SHORT, "--seeds", "1e2"), "--seeds"),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "00-02"), "--seeds", True),
    ("sweep", sweep_tiny(*SHORT, "--seeds", "0-99"), "", True),
    ("sweep", bare("--env", "--envs", "simoun/PointReach-v0,dm_control/cartpole-swingup"),
     "cartpole-swingup"),
    ("sweep", bare("--env", "--envs", "simoun/PointReach-v0,Pendulum-v1", "--action-repeat", "2"),
     "", True),
    ("sweep", sweep_tiny(*SHORT, "--cpus-per-trial", "2", "--num-cpus", "2"), "", True),
    ("sweep", sweep_tiny(*SHORT, "--gpus-per-trial", "none"), "--gpus-per-trial"),
    ("sweep", sweep_tiny(*SHORT, "--verbose", "1.0"), "--verbose"),
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", "my sweeps/sw"), "", True),
    ("sweep", bare("--env", "--envs", "simoun/PointReach-v0,Pendulum-v1", "--env-kwargs",
                   '{"max_speed": 1}'), "max_speed"),
    # --resume given flags again, changed, or that do not change the sweep
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", "sw", "--resume"), "", True, (SW,)),
    ("sweep", [*RESUME, "--verbose", "0"], "", True, (SW,)),
    ("sweep", [*RESUME, "--eval-every", "20"], "", True, (SW,)),
    ("sweep", [*RESUME, "--eval-every", "40"], "--eval-every", True, (SW,)),
    ("sweep", [*RESUME, "--seeds", "1"], "--seeds", True, (SW,)),
    ("sweep", [*RESUME, "--cpus-per-trial", "1"], "--cpus-per-trial", True, (SW,)),
    ("sweep", [*RESUME, "--gpus-per-trial", "auto"], "", True, (SW,)),
    ("sweep", [*RESUME, "--total-env-steps", "4e1"], "--total-env-steps", False, (SW,)),
    ("sweep", [*RESUME, "--run-dir", "r"], "--run-dir", False, (SW,)),
    ("sweep", [*RESUME, "--env-module", "minigrid"], "--env-module", False, (SW,)),
    ("sweep", [*RESUME, "--image-size", "48"], "--image-size", False, (SW,)),
    ("sweep", [*RESUME, "--overwrite"], "--overwrite", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "./sw"], "", True, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw/base/.."], "", True, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "moved/sw2"], "", True, (SW, moved_sweep)),
    ("sweep", RESUME, ("in use", "PID"), False, (SW, trial_in_use)),
    ("sweep", sweep_tiny(*SHORT, "--sweep-dir", "arch"), ("arch", "--sweep-dir"), False, (ARCH,)),
    # simoun-study
    ("study", ["plan", "spec.toml", "--probe-updates", "0", "--probe-updates", "5"],
     "--probe-updates"),
    ("study", ["plan", "spec.toml", "--probe_updates", "0"], "--probe-updates", True),
    ("study", ["plan", "spec.toml", "-p", "0"], ("--probe-updates", "-p")),
    ("study", ["plan", "docs/studies/dmc100k.toml", "--probe-updates", "0"],
     "docs/studies/dmc100k.toml"),
    ("study", ["plan", "spec.toml", "--verbose", "1"], "--verbose"),
    ("study", ["plan", "spec.toml", "--num-cpus", "1"], "--num-cpus"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--probe-updates", "0"], "--probe-updates"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--archive", "s/archive"],
     ("--archive", "s/archive")),
    ("study", ["run", "dmc100k.toml", "--study-dir", "arch/s", "--archive", "arch"],
     ("--study-dir", "arch/s"), False, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--num-cpus", "1"], "--num-cpus",
     False, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--verbose", "1"], "--verbose",
     False, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--at-step", "50000"],
     "--at-step", False, (ARCH, DMC100K)),
    ("study", ["run", "spec.toml", "--study-dir", "my studies/s", "--num-cpus", "1"], "", True),
    ("study", ["run", "mgt/spec.json", "--study-dir", "s", "--num-cpus", "1"], "--num-cpus", True,
     (MGT,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "./arch/tuning/.."], "", True,
     (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "backup"], "", True, (BACKUP, DMC100K)),
    ("study", ["run", "spec.toml", "--study-dir", "mgt"], ("mgt", "--study-dir"), False, (MGT,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch", "--study-dir", "arch"],
     "--study-dir", True, (ARCH, DMC100K)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch/report"],
     ("arch/report", "study.json"), False, (ARCH, DMC100K)),
    # simoun-report
    ("report", ["{run}", "-o", "r"], ("--out", "-o")),
    ("report", ["{run}", "--at-step", "40", "--out", "r"], "", True),
    ("report", ["{run}", "--at-wall-time", "0.5"], "--at-wall-time", True),
    ("report", ["{run}/checkpoint.pt"], "checkpoint.pt"),
    ("report", ["sw/sweep.json"], "sweep.json", False, (SW,)),
    ("report", ["{run}/tb"], ("tb", "no run")),
    ("report", ["sw", "--out", "sw/report"], "", True, (SW,)),
    ("report", ["sw"], "", True, (SW, trial_in_use)),
    ("report", ["{run}", "--out", "/proc/r"], ("/proc/r", "--out")),
    ("report", ["{run}", "--out", "r", "--out", "s"], "--out"),
    ("report", ["{run}", "--overwrite"], "--overwrite"),
    ("report", ["{run}", "--at-step", "4O"], ("--at-step", "4O")),
    # simoun-analyze
    ("analyze", masks("--steps", "1", "--query", "0;0"), "--query"),
    ("analyze", masks("--steps", "1", "--query", "16 16"), "--query"),
    ("analyze", masks("--steps", "1", "--steps", "2"), "--steps"),
    ("analyze", masks("--steps", "1", "--query", "0,0", "--query", "1,1"), "--query"),
    ("analyze", masks("--steps", "1", "--device", "mps"), "mps"),
    ("analyze", masks("--steps", "1", "--out", ""), "--out"),
    ("analyze", ["masks", "{run}", "drq", "--steps", "1"], "drq", False, (DRQ_RUN,)),
    ("analyze", bias("--pairs", "8", "--out", "b", "--seed", "1.5"), "--seed"),
    ("analyze", ["bias", "arch", "--pairs", "8", "--out", "b"], "arch", False, (ARCH,)),
    ("analyze", ["bias", "mgt/MiniGrid-DoorKey-6x6-v0/ppo/s100", "--pairs", "8", "--out", "b"],
     ("MiniGrid", "minigrid", "s100"), False, (MGT,)),
    ("analyze", ["masks", "{run}/eval.csv", "--steps", "1"], "eval.csv"),
    ("analyze", ["masks", "sw", "--steps", "1"], ("sw", "config.json"), False, (SW,)),
    ("analyze", masks("--steps", "1", "--episodes", "2.5"), "--episodes"),
    ("analyze", masks("--steps", "1", "--device", "cpu"), "", True),
    ("analyze", bias("--pairs", "8", "--out", "b", "--device", "cuda"), ("cuda", "--device")),
    ("analyze", ["bias", "{run}", "{run}/", "--pairs", "8", "--out", "b"], ("twice", "once")),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--resume"], "--resume", False,
     (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--num-cpus", "1"],
     "--num-cpus", False, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--at-step", "1000"], "--at-step", False, (MGT,)),
    ("minigrid", ["report", "--archive", "mgt", "--spec", "mgt/spec.json "], "mgt/spec.json",
     False, (MGT,)),
    ("minigrid", probe_on("MiniGrid-DoorKey-6x6"), "MiniGrid-DoorKey-6x6"),
    ("minigrid", probe_on("MiniGrid-Empty-5x5-v0", "--settings.seed", "1.5"), "seed"),
    ("minigrid", [*PROBE, "--settings.steps", "-512", *SMALL], "steps"),
    ("minigrid", [*PROBE, "--settings.steps", "512", *SMALL, "--settings.env-id",
                  "MiniGrid-Empty-6x6-v0"], "--settings.env-id"),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--allow-other-commit"],
     "--allow-other-commit", False, (MGT,)),
    ("minigrid", ["select", "--archive", "mgt", "--selection", "final"], "--selection", False,
     (MGT,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "mg"], ("mg", "--work-dir"), False,
     (MGT, MG)),
    ("minigrid", ["select", "--archive", "mgt", "--archive", "mg"], "--archive", False,
     (MGT, MG)),
    ("minigrid", [*PROBE, "--settings.steps", "1_024", *SMALL], "--settings.steps", True),
    ("minigrid", [*PROBE, "--probes", "consistency", "--settings.steps", "512", *SMALL],
     "--probes"),
    ("minigrid", ["select", "--archive", "mgt", "--spec", "mgt.json"], "", True,
     (MGT, MGT_FILE)),
]  # fmt: skip

GRID = "agent.n_step = [1, 3]"
TUNING_SEEDS = 'seeds = "101-102"'
EVAL_SEEDS = (
    'seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }'
)
# the DMC study's spec edited by hand, given to plan: (text replaced, by, names[, valid])
SPEC_EDITS = [
    (TUNING_SEEDS, 'seeds = "101,102"', "", True),
    ('preset = "cpu"', 'preset = "cpu"\nenv = "dm_control/cartpole-swingup-v0"', "env"),
    ('preset = "cpu"', 'preset = "cpu"\nimage_size = 8', "image_size"),
    (GRID, "agent.n_step = [1, 3, 1]", "agent.n_step"),
    (GRID, "agent.nstep = [1, 3]", "agent.nstep"),
    ("env_steps = 50_000", "env_steps = 50_000\neval_every = 5_000", "eval_every"),
    ("env_steps = 100_000", 'env_steps = 100_000\nselection = "final"', "selection"),
    ("max_concurrent_trials = 2 ", 'max_concurrent_trials = 2\ndevice = "cpu" ', "device"),
    ("action_repeat = 8", 'action_repeat = 8\nagent.recipe = "drq"', "recipe"),
    ("action_repeat = 4", "action_repeat = 4\nenv_kwargs = { nope = 1 }", "nope"),
    ('grid_overrides = ["agent.n_step"]', 'grid_overrides = ["n_step"]', "n_step"),
    ("cpus_per_trial = 1 ", "cpu_per_trial = 1 ", "cpu_per_trial"),
    ('[tasks."dm_control/cartpole-swingup-v0"]', '[tasks."cartpole-swingup"]', "cartpole-swingup"),
    ('tasks = ["dm_control/cartpole-swingup-v0"]\nseeds',
     'tasks = ["cartpole-swingup"]\nseeds', "cartpole-swingup"),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-3"', "3"), ("seeds", "cheetah-run")),
    ("eval_every = 10_000", 'eval_every = "10k"', ("eval_every", "10k")),
]  # fmt: skip
for _old, *_ in SPEC_EDITS:
    assert _old in SPEC, _old

DIAGNOSTICS = 'simoun = ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]'
# the v2 spec (diagnostics, generalization) and the highway spec edited: (spec, old, new, names)
OTHER_EDITS = [
    (V2_SPEC, DIAGNOSTICS, 'simoun = ["sac"]', "sac"),
    (V2_SPEC, DIAGNOSTICS, 'simoun = ["simoun_no_aux", "simoun_no_aux"]', "simoun_no_aux"),
    (V2_SPEC, DIAGNOSTICS, 'simoun = ["simoun-no-aux"]', "simoun-no-aux"),
    (V2_SPEC, '"video_hard"]\nepisodes = 10',
     '"video_hard"]\nepisodes = 10\ntasks = ["dm_control/cheetah-run-v0"]',
     ("tasks", "generalization")),
    (HIGHWAY_SPEC, 'preset = "highway-cpu"', 'preset = "highway_cpu"', "highway_cpu"),
    (V2_SPEC, '"video_hard"]\nepisodes = 10', '"video_hard"]\nepisodes = "10"', "episodes"),
    (HIGHWAY_SPEC, "video = false", "video = false\nenv_kwargs = { config = { duration = 40 } }",
     "env_kwargs", True),
    (HIGHWAY_SPEC, "video = false",
     'video = false\nenv_kwargs = \'{"config": {"duration": 40}}\'', "env_kwargs", True),
    (HIGHWAY_SPEC, "video = false", "video = false\nenv_kwargs = { config = { durration = 40 } }",
     "durration"),
    (HIGHWAY_SPEC, 'tasks = ["highway-fast-v0"]\nseeds = [101]',
     'tasks = ["highway-fast"]\nseeds = [101]', "highway-fast"),
    (HIGHWAY_SPEC, 'tasks = ["highway-fast-v0"]\nseeds = "1-5"',
     'tasks = ["highway-v0"]\nseeds = "1-5"', ("highway-v0", "tuning"), True),
]  # fmt: skip
for _spec, _old, *_ in OTHER_EDITS:
    assert _old in _spec, _old


def tuning_json(change) -> str:
    """The MiniGrid PPO tuning spec (docs/studies/minigrid-v2/tuning/spec.json) changed."""
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec, indent=2)


def arms(*extra: str):
    """A change: the spec's arms are ppo and ``extra``."""
    return lambda s: s.update(arms=["ppo", *extra])


def task(**change):
    """A change: the spec's one task updated with ``change``."""
    return lambda s: s["tasks"][0].update(change)


def ppo(**change):
    """A change: the spec's ppo table updated with ``change``."""
    return lambda s: s["ppo"].update(change)


def second_task(s: dict) -> None:
    s["tasks"].append({"env_id": "MiniGrid-DoorKey-8x8-v0", "steps": 400000, "seeds": [100]})


# the MiniGrid PPO tuning spec edited by hand, given to plan: (what, change, names[, valid])
JSON_EDITS = [
    ("tasks an object", lambda s: s.update(tasks=s["tasks"][0]), "tasks"),
    ("ent_coef 0.01", ppo(ent_coef=0.01), "", True),
    ("env_id MiniGrid-DoorKey-6x6", task(env_id="MiniGrid-DoorKey-6x6"), "MiniGrid-DoorKey-6x6"),
    ("seeds [100, 100]", task(seeds=[100, 100]), "seeds"),
    ("a task without steps", lambda s: s["tasks"][0].pop("steps"), "steps"),
    ("a second task, DoorKey-8x8", second_task, "", True),
    ("Arms in capitals", lambda s: s.update(Arms=s.pop("arms")), "Arms"),
    ("eval_every 20000 in place of evaluations",
     lambda s: (s.pop("evaluations"), s.update(eval_every=20_000)), "eval_every"),
    ("arm rnd,normalisation=paper", arms("rnd,normalisation=paper,scale=0.01"), "normalisation"),
    ("arm rnd,normalization=zscore", arms("rnd,normalization=zscore,scale=0.01"), "zscore"),
]  # fmt: skip


def shown(text: str) -> str:
    return text.replace("\n", "\\n")


def spec_edit(name: str, text: str, names, ok: bool = False, what=None):
    """A spec case: ``text`` written to ``name`` and given to ``simoun-study plan``."""
    argv = ["plan", name] + (["--probe-updates", "0"] if name.endswith(".toml") else [])
    return fifth("specs", "study", argv, names, ok, works=(put(name, text),), what=what)


CASES: list[dict] = [
    *(fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
      for command, argv, names, *rest in FLAGS),
    *(spec_edit("edit.toml", SPEC.replace(old, new, 1), names, *ok, what=shown(new))
      for old, new, names, *ok in SPEC_EDITS),
    *(spec_edit("edit.toml", spec.replace(old, new, 1), names, *ok, what=shown(new))
      for spec, old, new, names, *ok in OTHER_EDITS),
    *(spec_edit("spec.json", tuning_json(change), names, *ok, what=what)
      for what, change, names, *ok in JSON_EDITS),
]  # fmt: skip
