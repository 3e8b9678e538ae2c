"""A reliability trial: inputs a new user gets wrong, run against the commands, the wrappers'
Python API and the files users keep, each classified by what the user is told.

    python scripts/reliability_trial.py                 # every case, a table on stdout
    python scripts/reliability_trial.py --area files    # one area
    python scripts/reliability_trial.py --area flags --command sweep   # one command's cases
    python scripts/reliability_trial.py --markdown out.md
    python scripts/reliability_trial.py --set third --only 0,5,12   # three of one trial's cases
    python scripts/reliability_trial.py --set fifth --timeout 90    # the fifth trial
    python scripts/reliability_trial.py --set sixth --timeout 90    # the sixth trial
    python scripts/reliability_trial.py --set seventh --timeout 90  # the seventh trial
    python scripts/reliability_trial.py --set eighth --timeout 90   # the eighth trial
    python scripts/reliability_trial.py --set ninth --timeout 90    # the ninth trial
    python scripts/reliability_trial.py --set tenth --timeout 90    # the tenth trial
    python scripts/reliability_trial.py --set eleventh --timeout 90 # the eleventh trial

Each case runs in a forked child in a directory of its own (a copy of a tiny trained run where
it needs one) and is stopped after 20 s (``--timeout``; spec cases that import Ray want about 90 s
on a loaded machine): a case that passes its checks is not left to train.
A case is

- clear: refused with status 2 (a command) or a ValueError/TypeError-like error (the API), the
  message naming the argument, flag or file the case is about, no traceback; or, for a case
  marked ``ok`` (valid input, or a file the command does not need), it went on without error,
  or was refused naming what the case names (a case that names something allows either);
- unclear: refused, but the message does not name what the case is about;
- wrong: a traceback, an error from inside a library, accepted where it must be refused, or
  still running where it should have been refused (work started).

The fifth trial's cases of the commands that start Ray (simoun-sweep, ``simoun-study run``,
``python -m simoun_lab.minigrid_study run``) run with ``RAY_ADDRESS`` set to a value Ray's
connection refuses at once (:data:`GUARD`): a case that gets that far has started its work, and
is wrong unless marked ``ok``; no case joins a Ray cluster or starts one.

The classification is mechanical; docs/reliability.md records how the last trial's cases read to
a person. Add a case to a list below, never change one: the next trial reruns them all.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import shutil
import sys
import tempfile
import time
import traceback
from pathlib import Path

import gymnasium as gym
import minigrid  # noqa: F401  (registers the MiniGrid-* ids)
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from flag_lists import override  # noqa: E402  (the tests' helper, found through ROOT)

SPEC = (ROOT / "docs/studies/dmc100k.toml").read_text()

TINY = [
    "--env", "simoun/PointReach-v0", "--image-size", "32", "--warmup-agent-steps", "10",
    "--eval-every", "20", "--eval-episodes", "1", "--checkpoint-every", "20", "--device", "cpu",
    "--torch-threads", "1", "--agent.batch-size", "8", "--agent.num-filters", "4",
    "--agent.feature-dim", "8", "--agent.hidden-dim", "16", "--agent.aux-hidden-dim", "16",
    "--no-progress", "--no-video",
]  # fmt: skip


def tiny(*extra: str) -> list[str]:
    """TINY with ``extra``'s flags in place of TINY's own (a flag given twice is its own case)."""
    return override(TINY, *extra)


def sweep_tiny(*extra: str) -> list[str]:
    """:func:`tiny` for simoun-sweep, which sets torch_threads itself (--cpus-per-trial)."""
    flags = tiny(*extra)
    at = flags.index("--torch-threads")
    return flags[:at] + flags[at + 2 :]


COMMANDS = {
    "train": "simoun_agent.cli.train",
    "eval": "simoun_agent.cli.eval",
    "sweep": "simoun_lab.cli.sweep",
    "study": "simoun_lab.cli.study",
    "report": "simoun_lab.cli.report",
    "analyze": "simoun_lab.cli.analyze",
    "minigrid": "simoun_lab.minigrid_study.__main__",
    "driving": "simoun_agent.run.driving_reference",
}


def cli(area: str, command: str, argv: list[str], names: str, ok: bool = False, setup=None):
    """A command-line case: ``command``'s main on ``argv`` ({run} is a copy of the tiny run)."""
    return {
        "area": area,
        "command": command,
        "argv": argv,
        "names": names,
        "ok": ok,
        "setup": setup,
    }


def api(code: str, names: str, ok: bool = False):
    """A Python API case: ``code`` run with gym, np, w (simoun_wrappers) and pickle in scope."""
    return {"area": "api", "code": code, "names": names, "ok": ok}


def refused(code: str, names: str, *values: str) -> list[dict]:
    """One API case per value, each put into ``code``'s ``{}`` and to be refused naming
    ``names``."""
    return [api(code.format(value), names) for value in values]


# command lines: flags, values, combinations
FLAG_CASES = [
    cli("flags", "train", tiny("--total-env-step", "5"), "--total-env-steps"),
    cli("flags", "train", tiny("--batch-size", "8"), "--agent.batch-size"),
    cli("flags", "train", tiny("--discount", "0.9"), "--agent.discount"),
    cli("flags", "train", tiny("--envs", "Pendulum-v1"), "--env"),
    cli("flags", "train", tiny("--run_dir", "x"), "--run-dir"),
    cli("flags", "train", tiny("--agent.lr", "-1"), "lr"),
    cli("flags", "train", tiny("--agent.lr", "nan"), "lr"),
    cli("flags", "train", tiny("--agent.lr", "inf"), "lr"),
    cli("flags", "train", tiny("--agent.discount", "1.5"), "discount"),
    cli("flags", "train", tiny("--agent.batch-size", "0"), "batch_size"),
    cli("flags", "train", tiny("--agent.batch-size", "8.5"), "--agent.batch-size"),
    cli("flags", "train", tiny("--total-env-steps", "0"), "total_env_steps"),
    cli("flags", "train", tiny("--total-env-steps", "-5"), "total_env_steps"),
    cli("flags", "train", tiny("--eval-every", "0"), "eval_every"),
    cli("flags", "train", tiny("--eval-episodes", "0"), "eval_episodes"),
    cli("flags", "train", tiny("--checkpoint-every", "-1"), "checkpoint_every"),
    cli("flags", "train", tiny("--seed", "-1"), "seed"),
    cli("flags", "train", tiny("--seed", "1e3"), "--seed"),
    cli("flags", "train", tiny("--action-repeat", "0"), "action_repeat"),
    cli("flags", "train", tiny("--torch-threads", "0"), "torch_threads"),
    cli("flags", "train", tiny("--device", "cuda:9"), "device"),
    cli("flags", "train", tiny("--device", "tpu"), "device"),
    cli("flags", "train", tiny("--env", "Pendulum-v9"), "Pendulum"),
    cli("flags", "train", tiny("--env", "CartPole-v1"), "CartPole"),
    cli("flags", "train", tiny("--env", "nosuchmodule:Foo-v0"), "nosuchmodule"),
    cli("flags", "train", tiny("--env-kwargs", "[1]"), "--env-kwargs"),
    cli("flags", "train", tiny("--env-kwargs", '{"nope": 1}'), "nope"),
    cli("flags", "train", tiny("--agent.recipe", "curll"), "recipe"),
    cli("flags", "train", tiny("--agent.augmentation", "crop"), "augmentation"),
    cli("flags", "train", tiny("--agent.n-step", "0"), "n_step"),
    cli("flags", "train", tiny("--set", "agent.lr"), "--set"),
    cli("flags", "train", tiny("--set", "=3"), "--set"),
    cli("flags", "train", tiny("--set", "agent=3"), "agent"),
    cli("flags", "train", tiny("--set", "agent.nope=3"), "agent.nope"),
    cli("flags", "train", tiny("--set", "seed=abc"), "seed"),
    cli("flags", "train", tiny("--eval-distraction", "colour_hard"), "colour_hard"),
    cli("flags", "train", tiny("--progress", "maybe"), "--progress"),
    cli("flags", "train", tiny("--image-size", "8"), "image"),
    cli("flags", "train", tiny("--image-size", "100000"), "image"),
    cli("flags", "train", tiny("--agent.replay-capacity", "1"), "replay"),
    cli("flags", "train", tiny("--resume"), "--resume"),
    cli("flags", "train", ["--resume", "{run}", "--preset", "cpu"], "--preset"),
    cli("flags", "train", ["--resume", "{run}", "--overwrite"], "--overwrite"),
    cli("flags", "train", ["--resume", "{run}", "--total-env-steps", "10"], "total"),
    cli("flags", "train", ["--resume", "{run}", "--agent.lr", "0.1"], "agent.lr"),
    cli("flags", "train", ["--resume", "{run}", "--seed", "9"], "seed"),
    cli("flags", "train", tiny("--run-dir", "{run}"), "run"),
    cli("flags", "train", tiny("--total-env-steps", "100000", "--run-dir", "r"), "", ok=True),
    cli("flags", "train", ["--preset", "highway", "--env", "Pendulum-v1"], "highway"),
    cli("flags", "train", tiny("--preset", "cpu", "--preset=cpux"), "--preset"),
    cli("flags", "train", tiny("--env-module", "nosuchmodule"), "nosuchmodule"),
    cli("flags", "train", tiny("--", "--seed", "3"), "--"),
    cli("flags", "eval", ["{run}", "--episodes", "0"], "--episodes"),
    cli("flags", "eval", ["{run}", "--episodes", "-3"], "--episodes"),
    cli("flags", "eval", ["{run}", "--episode", "3"], "--episodes"),
    cli("flags", "eval", ["{run}", "--seed", "-1"], "--seed"),
    cli("flags", "eval", ["{run}", "--torch-threads", "0"], "--torch-threads"),
    cli("flags", "eval", ["{run}", "--distraction", "colour_easy"], "colour_easy"),
    cli("flags", "eval", ["{run}", "--distraction", "color_easy"], "dm_control"),
    cli("flags", "eval", ["{run}", "--out", "/proc/nope"], "--out"),
    cli("flags", "eval", ["{run}", "--videos", "nowhere"], "--videos"),
    cli("flags", "eval", ["{run}", "{run}"], "several"),
    cli("flags", "eval", [], "run directory"),
    cli("flags", "eval", ["{run}", "--device", "tpu"], "device"),
    cli("flags", "eval", ["{run}", "--episodes", "1", "--no-video"], "", ok=True),
    cli("flags", "eval", ["{run}", "--episodes", "1", "--episodes", "1"], "", ok=True),
    cli("flags", "report", ["{run}", "--at-step", "0"], "--at-step"),
    cli("flags", "report", ["{run}", "--at-wall-time", "-1"], "--at-wall-time"),
    cli("flags", "report", ["{run}", "--at-step", "20", "--at-wall-time", "5"], "--at-"),
    cli("flags", "report", ["{run}", "--at-steps", "20"], "--at-step"),
    cli("flags", "report", ["{run}", "--out", "/proc/x"], "--out"),
    cli("flags", "report", [], "DIR"),
    cli("flags", "report", ["{run}", "--at-step", "20"], "", ok=True),
    cli("flags", "report", ["{run}", "--at-step", "7"], "", ok=True),
    cli("flags", "analyze", ["masks", "{run}", "--steps", "a,b"], "--steps"),
    cli("flags", "analyze", ["masks", "{run}", "--steps", "-1"], "--steps"),
    cli("flags", "analyze", ["masks", "{run}", "--query", "1"], "--query"),
    cli("flags", "analyze", ["masks", "{run}", "--query", "999,999"], "--query"),
    cli("flags", "analyze", ["masks", "{run}", "--episodes", "0"], "--episodes"),
    cli("flags", "analyze", ["masks", "{run}", "--video", "avi"], "--video"),
    cli("flags", "analyze", ["masks", "{run}", "--step", "2"], "--steps"),
    cli("flags", "analyze", ["masks", "{run}", "--out", "a", "--out", "b"], "--out"),
    cli("flags", "analyze", ["bias", "{run}", "{run}"], "--out"),
    cli("flags", "analyze", ["bias", "{run}", "--episodes", "0"], "--episodes"),
    cli("flags", "analyze", ["mask", "{run}"], "masks"),
    cli("flags", "analyze", ["masks", "{run}", "--device", "tpu"], "device"),
    cli("flags", "sweep", sweep_tiny("--grid", "agent.lr"), "--grid"),
    cli("flags", "sweep", sweep_tiny("--grid", "agent.lrr=1,2"), "agent.lr"),
    cli("flags", "sweep", sweep_tiny("--grid", "agent.lr=1e-3,abc"), "agent.lr"),
    cli("flags", "sweep", sweep_tiny("--grid", "agent.recipe=simoun,drqq"), "drqq"),
    cli("flags", "sweep", sweep_tiny("--seeds", "5-2"), "--seeds"),
    cli("flags", "sweep", sweep_tiny("--seeds", "a-b"), "--seeds"),
    cli("flags", "sweep", sweep_tiny("--seeds", ""), "--seeds"),
    cli("flags", "sweep", sweep_tiny("--seeds", "1,1"), "--seeds"),
    cli("flags", "sweep", sweep_tiny("--envs", "Pendulum-v9"), "Pendulum-v9"),
    cli("flags", "sweep", sweep_tiny("--envs", ","), "--envs"),
    cli("flags", "sweep", sweep_tiny("--cpus-per-trial", "0"), "--cpus-per-trial"),
    cli("flags", "sweep", sweep_tiny("--gpus-per-trial", "lots"), "--gpus-per-trial"),
    cli("flags", "sweep", sweep_tiny("--gpus-per-trial", "-1"), "--gpus-per-trial"),
    cli("flags", "sweep", sweep_tiny("--num-cpus", "0"), "--num-cpus"),
    cli("flags", "sweep", sweep_tiny("--verbose", "3"), "--verbose"),
    cli("flags", "sweep", ["--resume"], "--sweep-dir"),
    cli("flags", "sweep", ["--resume", "--sweep-dir", "nowhere"], "nowhere"),
    cli("flags", "sweep", sweep_tiny("--sweep-dir", "{run}"), "sweep-dir"),
    cli("flags", "sweep", sweep_tiny("--learning-rate", "3"), "--agent.lr"),
    cli("flags", "sweep", sweep_tiny("--sweep-dir", "a", "--sweep-dir", "b"), "--sweep-dir"),
    cli("flags", "sweep", sweep_tiny("--seeds", "1", "--seeds", "2"), "--seeds"),
    cli("flags", "sweep", sweep_tiny("--address", "nohost:1"), "--address"),
    cli("flags", "study", ["plan"], "SPEC"),
    cli("flags", "study", ["plann", "spec.toml"], "plan"),
    cli("flags", "study", ["plan", "spec.toml", "--probe-updates", "-1"], "--probe-updates"),
    cli("flags", "study", ["plan", "spec.toml", "--probe-update", "1"], "--probe-updates"),
    cli(
        "flags",
        "study",
        ["plan", "spec.toml", "--probe-updates", "1", "--probe-updates", "2"],
        "--probe-updates",
    ),
    cli("flags", "study", ["run", "spec.toml"], "--study-dir"),
    cli(
        "flags",
        "study",
        ["run", "spec.toml", "--study-dir", "a", "--study-dir", "b"],
        "--study-dir",
    ),
    cli(
        "flags", "study", ["run", "spec.toml", "--study-dir", "a", "--num-cpus", "0"], "--num-cpus"
    ),
    cli("flags", "study", ["run", "spec.toml", "--studydir", "a"], "--study-dir"),
    cli("flags", "study", ["report", "spec.toml", "--study-dir", "nowhere"], "nowhere"),
    cli("flags", "study", ["report", "spec.toml", "--study-dir", "{run}"], "study"),
    cli("flags", "study", ["plan", "spec.toml", "--resume"], "--resume"),
    cli("flags", "minigrid", ["run", "--concurrent", "0", "--archive", "."], "--concurrent"),
    cli("flags", "minigrid", ["run", "--work-dir", "a", "--work-dir", "b"], "--work-dir"),
    cli("flags", "minigrid", ["report", "--archiv", "x"], "--archive"),
    cli("flags", "minigrid", ["reprot"], "report"),
    cli("flags", "minigrid", ["report", "--archive", "nowhere"], "nowhere"),
    cli("flags", "minigrid", ["report", "--archive", "{run}"], "spec.json"),
    cli("flags", "minigrid", ["probe", "--probes", "rndd", "--out", "p"], "rndd"),
    cli("flags", "minigrid", ["probe", "--settings.steps", "0", "--out", "p"], "steps"),
    cli("flags", "minigrid", ["probe", "--settings.n-envs", "0", "--out", "p"], "n_envs"),
    cli(
        "flags",
        "minigrid",
        ["probe", "--settings.env-id", "MiniGrid-Nope-v0", "--out", "p"],
        "MiniGrid-Nope-v0",
    ),
    cli("flags", "minigrid", ["select", "--archive", "nowhere"], "nowhere"),
    cli("flags", "minigrid", ["report", "--spec", "nowhere.json", "--archive", "."], "nowhere"),
    cli("flags", "driving", ["--episodes", "0"], "--episodes"),
    cli("flags", "driving", ["--episodes", "-1"], "--episodes"),
    cli("flags", "driving", ["--seed", "-1"], "--seed"),
    cli("flags", "driving", ["--preset", "cpux"], "cpux"),
    cli("flags", "driving", ["--preset", "cpu"], "--preset"),
    cli("flags", "driving", ["--video", "x.txt"], "--video"),
    cli("flags", "driving", ["--video", "nowhere/x.gif"], "--video"),
    cli("flags", "driving", ["--episdoes", "2"], "--episodes"),
    cli("flags", "driving", ["--episodes", "1", "--episodes", "2"], "--episodes"),
]

# the files users keep: a tiny run damaged one file at a time
DAMAGES = {
    "config.json": {
        "missing": None,
        "empty": b"",
        "truncated": "half",
        "not JSON": b"{oops",
        "a list": b"[]",
        "null": b"null",
        "unknown key": "config+nope",
        "wrong type": "config+image_size",
    },
    "eval.csv": {
        "missing": None,
        "empty": b"",
        "header only": b"env_step,return_mean\n",
        "truncated": "half",
        "text": b"hello\nworld\n",
        "non-numeric": "eval+abc",
    },
    "summary.json": {"missing": None, "empty": b"", "truncated": "half", "a list": b"[]"},
    "checkpoint.pt": {
        "missing": None,
        "empty": b"",
        "truncated": "half",
        "garbage": b"\x00garbage" * 50,
        "text": b"not a checkpoint\n",
    },
    "replay": {"missing": None, "truncated": "half"},
    "train.csv": {"missing": None, "empty": b""},
}

FILE_COMMANDS = {
    "eval": ["{run}", "--episodes", "1", "--no-video"],
    "train": ["--resume", "{run}", "--total-env-steps", "60"],
    "report": ["{run}"],
    "analyze": ["masks", "{run}", "--steps", "1"],
}


def damage(run: Path, name: str, how) -> None:
    """Damage ``run``'s file ``name`` as ``how`` says (None: delete; bytes: write them)."""
    path = next(run.glob("replay-*.npz")) if name == "replay" else run / name
    if callable(how):
        how(path)
    elif how is None:
        path.unlink()
    elif how == "half":
        data = path.read_bytes()
        path.write_bytes(data[: len(data) // 2])
    elif how == "config+nope":
        config = json.loads(path.read_text())
        config["nope"] = 1
        path.write_text(json.dumps(config))
    elif how == "config+image_size":
        config = json.loads(path.read_text())
        config["image_size"] = "big"
        path.write_text(json.dumps(config))
    elif how == "eval+abc":
        lines = path.read_text().splitlines()
        path.write_text("\n".join([lines[0], "abc," * (lines[0].count(",")) + "x"]) + "\n")
    else:
        path.write_bytes(how)


FILE_CASES = [
    cli(
        "files", command, argv, "replay" if name == "replay" else name, ok=True,
        setup=(name, how),
    )
    for name, ways in DAMAGES.items()
    for how in ways.values()
    for command, argv in FILE_COMMANDS.items()
]  # fmt: skip
for case, (name, way) in zip(
    FILE_CASES,
    [(n, w) for n, ways in DAMAGES.items() for w in ways for _ in FILE_COMMANDS],
    strict=True,
):
    case["what"] = f"{name} {way}"


def spec_case(text: str, names: str, suffix: str = ".toml", ok: bool = False):
    return cli("specs", "study", ["plan", f"spec{suffix}", "--probe-updates", "0"], names, ok,
               setup=("spec", (suffix, text)))  # fmt: skip


SPEC_CASES = [
    spec_case("", "recipes"),
    spec_case("recipes = [", "spec"),
    spec_case(SPEC.replace('recipes = ["simoun"', 'recipes = ["simoun", "simoun"'), "simoun"),
    spec_case(SPEC.replace('"simoun", "drq"', '"simoun", "drqq"'), "drqq"),
    spec_case(SPEC.replace('selection = "auc"', 'selection = "best"'), "selection"),
    spec_case(SPEC.replace("eval_episodes = 10", "eval_episodes = 0"), "eval_episodes"),
    spec_case(SPEC.replace("eval_episodes = 10", "eval_episode = 10"), "eval_episode"),
    spec_case(SPEC.replace('seeds = "101-102"', 'seeds = "102-101"'), "seeds"),
    spec_case(SPEC.replace('seeds = "101-102"', 'seeds = "1-2"'), "seed"),
    spec_case(SPEC.replace("env_steps = 50_000", "env_steps = 0"), "env_steps"),
    spec_case(SPEC.replace("env_steps = 50_000", 'env_steps = "50k"'), "env_steps"),
    spec_case(SPEC.replace("agent.n_step = [1, 3]", "agent.n_step = []"), "n_step"),
    spec_case(SPEC.replace("agent.n_step = [1, 3]", "agent.n_stp = [1, 3]"), "n_stp"),
    spec_case(SPEC.replace("agent.n_step = [1, 3]", "agent.n_step = 3"), "n_step"),
    spec_case(SPEC.replace('grid_overrides = ["agent.n_step"]', ""), "n_step"),
    spec_case(SPEC.replace('cartpole-swingup-v0"]\nseeds', 'cartpole-swingup-v9"]\nseeds'), "v9"),
    spec_case(SPEC.replace("cpus_per_trial = 1 ", "cpus_per_trial = 0 "), "cpus_per_trial"),
    spec_case(
        SPEC.replace("max_concurrent_trials = 2", "max_concurrent_trials = -1"),
        "max_concurrent_trials",
    ),
    spec_case(SPEC.replace("[resources]", "[resource]"), "resource"),
    spec_case(SPEC.replace('preset = "cpu"', 'preset = "cpux"'), "cpux"),
    spec_case(SPEC.replace("action_repeat = 8", "action_repeat = 0"), "action_repeat"),
    spec_case(SPEC.replace("video = false", 'video = "no"'), "video"),
    spec_case(SPEC + '\n[diagnostics]\nsimoun = ["simoun_no_nothing"]\n', "simoun_no_nothing"),
    spec_case(SPEC + '\n[generalization]\nmodes = ["colour_hard"]\n', "colour_hard"),
    spec_case(json.dumps({"recipes": ["simoun"]}), "TOML", suffix=".json"),
    spec_case("\x00\x01binary", "spec"),
    cli("specs", "study", ["plan", "nowhere.toml"], "nowhere.toml"),
    cli("specs", "study", ["plan", "."], "."),
    *(
        cli(
            "specs",
            "minigrid",
            ["report", "--spec", "spec.json", "--archive", "."],
            names,
            setup=("spec", (".json", text)),
        )
        for text, names in (
            ("{", "spec.json"),
            ("[]", "spec.json"),
            ('{"nope": 1}', "nope"),
            ("", "spec.json"),
        )
    ),
    cli("specs", "sweep", ["--resume", "--sweep-dir", "{run}"], "sweep.json"),
    cli("specs", "report", ["."], "config.json", setup=("sweep", b"{")),
    *(
        cli("specs", "sweep", ["--resume", "--sweep-dir", "."], "sweep.json", setup=("sweep", text))
        for text in (b"{", b"", b'{"grid": 3}')
    ),
]

P = "gym.make('Pendulum-v1', render_mode='rgb_array')"
M = "gym.make('MiniGrid-Empty-5x5-v0', render_mode='rgb_array')"
API_CASES = [
    *refused(
        f"w.SimounObservation({P}, size={{}})",
        "size",
        "0",
        "-84",
        "'84'",
        "84.0",
        "(84,)",
        "(84, 0)",
        "(84, 84, 3)",
    ),
    api(f"w.SimounObservation({P}, size=[84, 84]).reset(seed=0)", "", ok=True),
    api(f"w.SimounObservation({P}, size=np.int64(40)).reset(seed=0)", "", ok=True),
    *refused(f"w.SimounObservation({P}, grayscale={{}})", "grayscale", "'yes'", "None"),
    api(f"w.SimounObservation({P}, motion='no')", "motion"),
    api(f"w.SimounObservation({P}, fold_frames=1)", "fold_frames"),
    *refused(f"w.SimounObservation({P}, num_frames={{}})", "num_frames", "0", "2", "2.5"),
    *refused(f"w.SimounObservation({P}, source={{}})", "source", "'pixel'", "3"),
    api("w.SimounObservation(gym.make('Pendulum-v1'))", "render_mode"),
    api("w.SimounObservation('Pendulum-v1')", "env"),
    api("w.SimounObservation(None)", "env"),
    api("w.SimounObservation(gym.make_vec('Pendulum-v1', 2, render_mode='rgb_array'))", "vector"),
    api(f"e = w.SimounObservation({P}, size=40); e.step(e.action_space.sample())", "reset"),
    api(f"e = w.SimounObservation({P}, size=40); e.reset(seed=0); e.step(np.zeros(5))", "action"),
    *refused(
        f"e = w.SimounObservation({P}, size=40); e.reset(seed={{}})", "seed", "-1", "'a'", "1.5"
    ),
    api(
        f"e = w.SimounObservation({P}, size=40); e.reset(seed=0); pickle.loads(pickle.dumps(e))",
        "",
        ok=True,
    ),
    api(f"e = w.SimounObservation({P}, size=40); e.close(); e.close()", "", ok=True),
    api(
        f"e = w.SimounObservation({M}, size=40); e.reset(seed=0); e.step(0); e.step(1)", "", ok=True
    ),
    api(f"w.SimounObservation(w.SimounObservation({P}, size=40))", "SimounObservation"),
    api(f"w.FrameTriplet({P})", "frame"),
    api(f"w.FrameTriplet(w.SimounObservation({P}, size=40), num_frames=0)", "num_frames"),
    api(f"w.ResidualMotion({P})", "frame"),
    api("w.residual_motion(np.zeros((2, 3, 8, 8), np.uint8))", "frames"),
    api("w.residual_motion(np.zeros((3, 3, 8, 8), np.float32))", "uint8"),
    api("w.residual_motion([[1, 2]])", "frames"),
    api("w.residual_motion(np.zeros((3, 8, 8), np.uint8))", "frames"),
    *refused(f"w.ActionRepeat({P}, {{}})", "repeat", "0", "-1", "2.0", "'2'", "True"),
    api(f"w.ActionRepeat({P}, np.int32(2)).reset(seed=0)", "", ok=True),
    api(f"w.RandomConvolution({P})", "frame"),
    api(f"w.RandomConvolution(w.SimounObservation({P}, size=40), kernel_size=0)", "kernel_size"),
    api(f"w.RandomConvolution(w.SimounObservation({P}, size=40), kernel_size=2)", "kernel_size"),
    api(f"w.RandomConvolution(w.SimounObservation({P}, size=40), kernel_size=99)", "kernel"),
    api(f"w.RandomConvolution(w.SimounObservation({P}, size=40), source='x')", "source"),
    api("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), kernel_size=4)", "kernel_size"),
    api("import torch; w.random_conv(torch.zeros(3, 8, 8))", "batch"),
    api("w.random_conv(np.zeros((2, 3, 8, 8), np.float32))", "tensor"),
    api("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), clamp=(1, 0))", "clamp"),
    api(f"w.ColorShift({P}, level='extreme')", "level"),
    api(f"w.ColorShift({P}, level='easy', seed=-1)", "seed"),
    api(f"w.MovingBackground({P}, level='hardest')", "level"),
    api(f"w.MovingBackground({P}, videos='nowhere')", "nowhere"),
    api(f"w.MultiCamera({P}, cameras=[])", "cameras"),
    api(f"w.MultiCamera({P}, cameras=[1, 2])", "camera"),
    api(f"w.MultiCamera({P}, cameras=[lambda e: e.render()], size=0)", "size"),
    api(f"w.MultiCamera({P}, cameras=[lambda e: None], size=40).reset(seed=0)", "camera"),
    api(
        f"w.MultiCamera({P}, cameras=[lambda e: np.zeros((4, 4))], size=40).reset(seed=0)", "camera"
    ),
    api(f"w.ConstantBonusReward({P}, scale='0.1')", "scale"),
    api(f"w.ConstantBonusReward({P}, scale=float('nan'))", "scale"),
    api(f"w.ConstantBonusReward({P}, scale=0.1, decay=-1)", "decay"),
    api(f"w.ConstantBonusReward({P}, scale=0.1, decay=float('inf'))", "decay"),
    api(f"w.ConstantBonusReward({P}, scale=0.1).reset(seed=0)", "", ok=True),
    api(f"pickle.loads(pickle.dumps(w.ConstantBonusReward({P}, scale=0.1)))", "", ok=True),
    api(f"w.ConsistencyCuriosityReward({P}, features=None)", "features"),
    api(f"w.ConsistencyCuriosityReward({P}, features=3)", "features"),
    api(f"w.RNDReward({P}, novelty=None)", "novelty"),
    api(f"w.check_sb3_policy({P}, 'MlpPolicyy')", "MlpPolicy"),
    api(f"w.check_sb3_policy({P}, 3)", "policy"),
    api(f"w.check_sb3_policy(w.SimounObservation({M}, size=40), 'CnnPolicy')", "MultiInput"),
    api("w.check_sb3_policy(None, 'CnnPolicy')", "env"),
]

for mode in ("NEXT_STEP", "SAME_STEP"):
    vec = (
        f"gym.make_vec('Pendulum-v1', 2, vectorization_mode='sync', render_mode='rgb_array', "
        f"vector_kwargs={{'autoreset_mode': gym.vector.AutoresetMode.{mode}}}, "
        "wrappers=[lambda e: w.SimounObservation(e, size=40)])"
    )
    API_CASES += [
        api(
            f"v = {vec}; v.reset(seed=0); [v.step(v.action_space.sample()) for _ in range(3)]",
            "",
            ok=True,
        ),
        api(
            f"v = w.ConstantBonusVectorReward({vec}, scale=0.1); v.reset(seed=0); "
            "[v.step(v.action_space.sample()) for _ in range(3)]",
            "",
            ok=True,
        ),
        api(f"w.ConstantBonusReward({vec}, scale=0.1)", "Vector"),
        api(f"v = {vec}; v.reset(seed=[0])", "seed"),
        api(f"v = {vec}; v.reset(seed=0); v.step(np.zeros((3, 1), np.float32))", "action"),
        api(f"w.SimounObservation({vec})", "vector"),
    ]

# the second trial's API cases: every public wrapper, the PettingZoo wrapper and the agent's API
S = f"w.SimounObservation({P}, size=16)"
C = "gym.make('CartPole-v1', render_mode='rgb_array')"
NOV = "import functools; nov = functools.partial(np.mean, axis=(1, 2, 3, 4)); "
FEAT = (
    "def feat(t):\n"
    "    f = t.reshape(*t.shape[:2], -1)[..., :4].astype(np.float32)\n"
    "    return f[:, 2] - f[:, 1], f\n"
)
DMC = (
    "import shimmy; gym.register_envs(shimmy); "
    "d = gym.make('dm_control/cartpole-swingup-v0', render_mode='rgb_array'); "
)
PZ = (
    "import pettingzoo; from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
    "pz = pettingzoo.make('parallel', 'butterfly/pistonball-v6', n_pistons=3, "
    "render_mode='rgb_array'); "
)
AEC = "import pettingzoo; aec = pettingzoo.make('aec', 'butterfly/pistonball-v6', n_pistons=3); "
AGENT = (
    "from simoun_agent import AgentConfig, FrameReplay, SimounAgent; cfg = AgentConfig("
    "batch_size=8, num_filters=4, feature_dim=8, hidden_dim=16, aux_hidden_dim=16); "
)
A = "SimounAgent((3, 32, 32), 1, cfg, device='cpu')"
REWARD = f"gym.wrappers.TransformReward({P}, lambda r: {{}})"
NAN, INF = REWARD.format("float('nan')"), REWARD.format("float('inf')")
STEP = "e.reset(seed=0); e.step(e.action_space.sample())"


def vec(mode: str, env: str = "Pendulum-v1", wrap: str = "w.SimounObservation(e, size=16)") -> str:
    """A 2-env sync vector env of ``env`` in autoreset ``mode``, each sub-env wrapped by
    ``wrap``."""
    return (
        f"gym.make_vec('{env}', 2, vectorization_mode='sync', render_mode='rgb_array', "
        f"vector_kwargs={{'autoreset_mode': gym.vector.AutoresetMode.{mode}}}, "
        f"wrappers=[lambda e: {wrap}])"
    )


# (code with one {} for the value, the name the refusal must give, the values)
SECOND_REFUSED = [
    (f"w.SimounObservation({P}, size={{}})", "size",
     "True", "float('nan')", "10**6", "(16, '16')", "(16, None)"),
    (f"w.SimounObservation({P}, num_frames={{}})", "num_frames",
     "True", "3.0", "'3'", "None", "-1", "10**9"),
    (f"w.SimounObservation({P}, {{}})", "grayscale", "grayscale=1"),
    (f"w.SimounObservation({P}, {{}})", "motion", "motion=None"),
    (f"w.SimounObservation({P}, {{}})", "fold_frames", "fold_frames='True'"),
    (f"w.SimounObservation({P}, source={{}})", "source", "None", "'RENDER'"),
    (f"w.ActionRepeat({P}, {{}})", "repeat", "None", "1.5", "np.float64(2)", "[2]", "'two'"),
    (f"w.FrameTriplet({P}, num_frames={{}})", "num_frames",
     "True", "'3'", "3.0", "None", "-2", "10**9"),
    (f"w.RandomConvolution({P}, kernel_size={{}})", "kernel_size",
     "True", "3.0", "'3'", "None", "-3"),
    (f"w.RandomConvolution({P}, source={{}})", "source", "'pixels'"),
    (f"w.MultiCamera({P}, cameras=[lambda e: e.render()], size={{}})", "size", "True", "-1"),
    (f"w.MultiCamera({P}, cameras={{}})", "cameras", "'side'", "None"),
    (f"w.MultiCamera({P}, cameras=[{{}}])", "dm_control", "0", "'side'"),
    (f"w.MultiCamera({P}, cameras=[{{}}])", "highway", "{'scaling': 2.0}"),
    (f"w.ConstantBonusReward({S}, scale={{}})", "scale",
     "True", "-0.1", "None", "float('inf')", "np.float32('nan')"),
    (f"w.ConstantBonusReward({S}, scale=0.1, decay={{}})", "decay",
     "None", "'0'", "True", "-1e-3"),
    (NOV + f"w.RNDReward({S}, nov, warmup={{}})", "warmup", "-1", "1.5", "True", "None"),
    (NOV + f"w.RNDReward({S}, nov, progress={{}})", "progress", "0", "2", "True", "'0.5'"),
    (NOV + f"w.RNDReward({S}, nov, normalization={{}})", "normalization",
     "'nope'", "None", "3"),
    (NOV + f"w.RNDReward({S}, nov, scale={{}})", "scale", "-1", "'big'"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, r_e_max_init={{}})", "r_e_max_init",
     "0", "-1", "float('nan')", "'1'"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, r_i_max_init={{}})", "r_i_max_init",
     "0", "True"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, {{}})", "decay", "decay=-1"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, {{}})", "normalization",
     "normalization='paperr'"),
    (f"w.ConsistencyCuriosityReward({S}, features={{}})", "features", "np.zeros(3)", "'model'"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), kernel_size={})", "kernel_size",
     "True", "3.0"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), clamp={})", "clamp",
     "(0, float('nan'))", "(0, 1, 2)", "'01'"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), generator={})", "generator", "3"),
    ("import torch; w.random_conv({})", "float",
     "torch.zeros(2, 3, 8, 8, dtype=torch.uint8)"),
    ("import torch; w.random_conv({})", "kernel_size", "torch.zeros(2, 3, 2, 2)"),
    ("w.residual_motion({})", "uint8",
     "np.zeros((3, 1, 4, 4), np.int16)", "None", "np.zeros((3, 1, 4, 4), bool)"),
    (f"w.check_sb3_policy(w.SimounObservation({P}, size=40, fold_frames=True), {{}})", "policy",
     "None", "'cnnpolicy'"),
    (f"w.check_sb3_policy(w.SimounObservation({P}, size=40, fold_frames=True), {{}})",
     "CnnPolicy", "'MlpPolicy'"),
    (f"w.check_sb3_policy(w.SimounObservation({P}, size=16, fold_frames=True), {{}})", "36",
     "'CnnPolicy'"),
    (DMC + "w.ColorShift(d, level={})", "level", "None", "'EASY'"),
    (DMC + "w.ColorShift(d, seed={})", "seed", "1.5", "'0'", "True"),
    (DMC + "w.MovingBackground(d, {})", "videos", "videos=3"),
    (DMC + "w.MovingBackground(d, {})", "seed", "seed=-5"),
    (PZ + "SPO(pz, {})", "size", "size=True"),
    (PZ + "SPO(pz, {})", "num_frames", "num_frames=0", "num_frames=1.5"),
    (PZ + "SPO(pz, {})", "grayscale", "grayscale='no'"),
    (PZ + "SPO(pz, {})", "source", "source='x'"),
    (AGENT + "SimounAgent({}, 1, cfg, device='cpu')", "frame_shape",
     "(3, 32.0, 32)", "'3,32,32'", "None", "(0, 32, 32)", "(3, 32)"),
    (AGENT + "SimounAgent({}, 1, cfg, device='cpu')", "(3, 32, 32)", "(32, 32, 3)"),
    (AGENT + "SimounAgent({}, 1, cfg, device='cpu')", "too small", "(3, 4, 4)"),
    (AGENT + "SimounAgent((3, 32, 32), {}, cfg, device='cpu')", "action_dim",
     "1.0", "'1'", "True", "0", "None"),
    (AGENT + "SimounAgent((3, 32, 32), {}, cfg, device='cpu')", "continuous",
     "gym.spaces.Discrete(2)"),
    (AGENT + "SimounAgent((3, 32, 32), 1, {}, device='cpu')", "config",
     "{'lr': 1e-3}", "'cpu'", "AgentConfig"),
    (AGENT + "SimounAgent((3, 32, 32), 1, cfg, device={})", "device", "'tpu'", "'cuda:7'", "3"),
    (AGENT + f"{A}.act({{}})", "frames",
     "np.zeros((3, 3, 16, 16), np.uint8)", "np.zeros((3, 32, 32), np.uint8)",
     "{'frames': np.zeros((3, 3, 32, 32), np.uint8)}"),
    (AGENT + f"{A}.act({{}})", "uint8", "np.zeros((3, 3, 32, 32), np.float32)"),
    (AGENT + "FrameReplay({}, (3, 32, 32), 1)", "capacity", "0", "10.5", "'100'", "None"),
    (AGENT + "FrameReplay(100, (3, 32, 32), 1, {})", "num_frames", "num_frames=0"),
    (AGENT + "FrameReplay(100, (3, 32, 32), 1, {})", "seed", "seed=-1"),
    (AGENT + "FrameReplay(100, (3, 32, 32), {})", "action_dim", "0", "1.5"),
    (AGENT + "AgentConfig({})", "lr", "lr='0.001'", "lr=0"),
    (AGENT + "AgentConfig({})", "batch_size", "batch_size=8.0", "batch_size=True"),
    (AGENT + "AgentConfig({})", "discount", "discount=float('nan')"),
    (AGENT + "AgentConfig({})", "encoder", "encoder='dual-path'"),
    (AGENT + "AgentConfig({})", "nope", "nope=1"),
    (AGENT + "AgentConfig({})", "n_step", "n_step=0"),
    (AGENT + "AgentConfig({})", "feature_dim", "feature_dim=-8"),
    (AGENT + "AgentConfig({})", "augmentation", "augmentation=None"),
    (AGENT + "AgentConfig({})", "curiosity", "curiosity='yes'"),
    ("from simoun_agent.config import resolve; resolve({})", "cpux", "'cpux', {}"),
    ("from simoun_agent.config import resolve; resolve({})", "agent.lr",
     "'cpu', {'agent.lrr': 1e-3}", "'cpu', {'agent.lr': 'abc'}"),
    ("from simoun_agent.config import resolve; resolve({})", "overrides",
     "'cpu', [('agent.lr', 1e-3)]"),
    ("from simoun_agent.config import resolve; resolve({})", "drqq",
     "None, {'agent.recipe': 'drqq'}"),
    ("from simoun_agent.config import resolve; resolve({})", "seed", "'cpu', {'seed': -1}"),
]  # fmt: skip

# (code, the name the refusal must give, or "" for a valid input that must go on)
SECOND_CODES = [
    # envs of every observation kind
    ("w.SimounObservation(gym.make('MiniGrid-Empty-5x5-v0'))", "render_mode"),
    ("w.SimounObservation(gym.make('FrozenLake-v1'))", "render_mode"),
    ("w.SimounObservation(gym.make('CartPole-v1'))", "render_mode"),
    ("e = w.SimounObservation(gym.make('FrozenLake-v1', render_mode='rgb_array'), size=16); "
     + STEP, ""),
    ("import minigrid.wrappers as mw; "
     "w.SimounObservation(mw.RGBImgObsWrapper(gym.make('MiniGrid-Empty-5x5-v0')))", "image"),
    ("e = w.SimounObservation(gym.wrappers.GrayscaleObservation(gym.wrappers.AddRenderObservation("
     f"{C})), size=16); " + STEP, ""),
    ("w.SimounObservation(gym.wrappers.TransformObservation(gym.wrappers.AddRenderObservation("
     f"{C}), lambda o: o / 255.0, gym.spaces.Box(0, 1, (400, 600, 3))), source='observation')",
     "uint8"),
    ("e = w.SimounObservation(gym.wrappers.ResizeObservation(gym.wrappers.AddRenderObservation("
     f"{C}), (4, 4)), size=None); " + STEP, ""),
    ("w.RandomConvolution(gym.wrappers.ResizeObservation(gym.wrappers.AddRenderObservation("
     f"{C}), (4, 4)), kernel_size=5)", "kernel_size"),
    ("w.SimounObservation(gym.make('Pendulum-v1', render_mode='human'))", "render_mode"),
    ("w.SimounObservation(gym.make('Pendulum-v1', render_mode='rgb_array_list'))", "render_mode"),
    ("w.RandomConvolution(gym.make('Pendulum-v1'))", "render_mode"),
    (DMC.replace(", render_mode='rgb_array'", "") + "w.MovingBackground(d)", "render_mode"),
    (f"w.ResidualMotion(w.FrameTriplet({P}))", "uint8"),
    (f"w.ResidualMotion(w.SimounObservation({P}, size=16, motion=False))", "(k, C, H, W)"),
    (f"w.ResidualMotion(w.SimounObservation({P}, size=16, fold_frames=True))", "(k, C, H, W)"),
    (f"w.FrameTriplet({S})", "Box"),
    ("w.FrameTriplet(gym.make('FrozenLake-v1'))", "Box"),
    (f"w.ConstantBonusReward({P}, scale=0.1)", "SimounObservation"),
    (f"w.ConstantBonusReward(w.SimounObservation({P}, size=16, num_frames=4), scale=0.1)",
     "num_frames"),
    (f"e = w.ConstantBonusReward(w.SimounObservation({P}, size=16, fold_frames=True), 0.1); "
     + STEP, ""),
    ("w.residual_motion(np.zeros((1, 3, 1, 4, 4), np.uint8))", ""),
    ("import torch; w.random_conv(torch.zeros(0, 3, 8, 8))", ""),
    ("w.check_sb3_policy(gym.spaces.Discrete(3), 'MlpPolicy')", ""),
    (f"w.check_sb3_policy({vec('NEXT_STEP', wrap=f'{S[:-1]}, fold_frames=True)')}, 'CnnPolicy')",
     "36"),
    (f"w.check_sb3_policy({vec('SAME_STEP')}, 'MultiInputPolicy')", "fold_frames"),
    # wrappers in the wrong order or twice
    (f"w.ActionRepeat({S}, 2)", "under"),
    (f"e = w.ActionRepeat(w.ActionRepeat({P}, 2), 2); " + STEP, ""),
    (f"w.RandomConvolution({S})", "under"),
    (f"w.MultiCamera({S}, cameras=[lambda e: e.render()])", "under"),
    ("w.SimounObservation(gym.wrappers.FrameStackObservation(gym.wrappers.AddRenderObservation("
     f"{C}), 3))", "FrameStackObservation"),
    (f"w.SimounObservation(w.ConstantBonusReward({S}, scale=0.1))", "already"),
    (f"e = w.ConstantBonusReward(w.ConstantBonusReward({S}, 0.1), 0.1); " + STEP, ""),
    (DMC + "w.MovingBackground(w.SimounObservation(d, size=16))", "under"),
    (PZ + "SPO(SPO(pz, size=16))", "SimounParallelObservation"),
    # single envs and vector envs swapped
    (f"w.ConstantBonusVectorReward({S}, scale=0.1)", "ConstantBonusReward("),
    (NOV + f"w.RNDVectorReward({S}, nov)", "RNDReward("),
    (FEAT + f"w.ConsistencyCuriosityVectorReward({S}, feat)", "ConsistencyCuriosityReward("),
    ("w.ConstantBonusVectorReward(gym.make_vec('Pendulum-v1', 2), scale=0.1)",
     "SimounObservation"),
    # PettingZoo envs, parallel and AEC
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); "
     "e.step({a: e.action_space(a).sample() for a in e.agents})", ""),
    (AEC + "from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; SPO(aec)",
     "parallel"),
    (f"from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; SPO({P})",
     "ParallelEnv"),
    ("from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
     f"SPO({vec('NEXT_STEP')})", "ParallelEnv"),
    ("from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; SPO(None)",
     "ParallelEnv"),
    ("import pettingzoo; from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO;"
     " SPO(pettingzoo.make('parallel', 'classic/rps-v2'))", "render_mode"),
    (PZ.replace(", render_mode='rgb_array'", "") + "SPO(pz, source='render')", "render_mode"),
    (PZ + "e = SPO(pz, size=16); e.step({a: e.action_space(a).sample() for a in e.agents})",
     "reset"),
    (PZ + "SPO(pz, size=16).reset(seed='a')", "seed"),
    (PZ + "w.SimounObservation(pz)", "gymnasium.Env"),
    (AEC + "w.ActionRepeat(aec, 2)", "gymnasium.Env"),
    (AEC + "w.FrameTriplet(aec)", "gymnasium.Env"),
    (PZ + "w.ConstantBonusReward(pz, scale=0.1)", "gymnasium.Env"),
    (PZ + NOV + "w.RNDReward(pz, nov)", "gymnasium.Env"),
    # step before reset, after the episode ended, actions and seeds
    (f"w.FrameTriplet({P}).step(np.zeros(1, np.float32))", "reset"),
    (f"w.ActionRepeat({P}, 2).step(np.zeros(1, np.float32))", "reset"),
    (f"w.RandomConvolution({P}).step(np.zeros(1, np.float32))", "reset"),
    (f"w.ConstantBonusReward({S}, 0.1).step(np.zeros(1, np.float32))", "reset"),
    (NOV + f"w.RNDReward({S}, nov).step(np.zeros(1, np.float32))", "reset"),
    (f"e = w.SimounObservation({C}, size=16); e.reset(seed=0); e.step(2)", "action"),
    (f"e = w.ActionRepeat({C}, 2); e.reset(seed=0); e.step(np.array([0.5]))", "action"),
    (f"e = w.ConstantBonusReward({S}, 0.1); e.reset(seed=0); e.step(np.array([100.0]))", ""),
    (f"e = w.SimounObservation({P}, size=16); e.reset(seed=0); e.step('a')", "action"),
    (f"w.FrameTriplet({P}).reset(seed='0')", "seed"),
    (f"w.ActionRepeat({P}, 2).reset(seed=1.5)", "seed"),
    (f"w.RandomConvolution({P}).reset(seed=-1)", "seed"),
    (f"w.RandomConvolution({P}).reset(seed='a')", "seed"),
    (f"w.RandomConvolution({P}).reset(seed=np.int64(3))", ""),
    (DMC + "w.ColorShift(d).reset(seed=-1)", "seed"),
    (DMC + "w.MovingBackground(d).reset(seed=1.5)", "seed"),
    (f"w.ConstantBonusReward({S}, 0.1).reset(seed=[0])", "seed"),
    # rewards that are NaN or inf
    (f"e = w.ConstantBonusReward(w.SimounObservation({NAN}, size=16)"
     ", 0.1); " + STEP, "NaN"),
    (NOV + f"e = w.RNDReward(w.SimounObservation({NAN}, size=16), nov,"
     " warmup=0); " + STEP, "NaN"),
    (FEAT + "e = w.ConsistencyCuriosityReward(w.SimounObservation("
     f"{INF}, size=16), feat); " + STEP, "inf"),
    (f"e = w.ActionRepeat({NAN}, 2); " + STEP, ""),
    (f"e = w.ConstantBonusReward({S}, scale=1e308); e.reset(seed=0); "
     "[e.step(e.action_space.sample()) for _ in range(3)]", ""),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((3, 32, 32), "
     "np.uint8)); r.add(np.zeros(1), float('nan'), np.zeros((3, 32, 32), np.uint8), False, "
     "False)", "reward"),
    # the agent's API
    (AGENT + f"{A}.act(np.zeros((3, 3, 32, 32), np.uint8))", ""),
    (AGENT + "SimounAgent([3, 32, 32], np.int64(2), cfg, device='cpu')", ""),
    (AGENT + "SimounAgent(np.array([3, 32, 32]), 1, cfg, device='cpu')", ""),
    (AGENT + f"{A}.update(FrameReplay(100, (3, 32, 32), 1), 0)", "batch_size"),
    (AGENT + "r = FrameReplay(100, (3, 16, 16), 1); r.start_episode(np.zeros((3, 16, 16), "
     "np.uint8)); [r.add(np.zeros(1), 0.0, np.zeros((3, 16, 16), np.uint8), False, False) for _ "
     f"in range(9)]; {A}.update(r, 9)", "frame_shape"),
    (AGENT + "FrameReplay(100, (3, 32, 32), 1).add(np.zeros(1), 0.0, np.zeros((3, 32, 32), "
     "np.uint8), False, False)", "start_episode"),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((3, 32, 32), "
     "np.uint8)); r.add(np.zeros(1), 'a', np.zeros((3, 32, 32), np.uint8), False, False)",
     "reward"),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((3, 32, 32), "
     "np.float32))", "uint8"),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((3, 32, 32), "
     "np.uint8)); r.add(np.zeros(3), 0.0, np.zeros((3, 32, 32), np.uint8), False, False)",
     "action"),
    ("from simoun_agent.config import resolve; resolve('cpu', {'agent.recipe': 'drq'})", ""),
    ("from simoun_agent.config import TrainConfig; TrainConfig(total_env_steps=0)",
     "total_env_steps"),
    ("from simoun_agent.config import from_dict; from_dict([])", "object"),
    (f"from simoun_agent.rnd_model import RNDModel; RNDModel.for_env({P})", "SimounObservation"),
    (f"from simoun_agent.rnd_model import RNDModel; m = RNDModel.for_env({S}); m.close()", ""),
    ("from simoun_agent.curiosity_model import CuriosityModel; CuriosityModel((32, 32, 3))",
     "frame_shape"),
    ("from simoun_agent.curiosity_model import AgentFeatures; AgentFeatures(3)",
     "encoder_features"),
]  # fmt: skip

# every wrapper pickled and deep-copied after a step, and stepped again
COPIED = [
    f"w.FrameTriplet({P})",
    f"w.ActionRepeat({P}, 2)",
    f"w.RandomConvolution({P})",
    f"import operator; w.MultiCamera({P}, cameras=[operator.methodcaller('render')], size=16)",
    f"w.ConstantBonusReward({S}, 0.1)",
    NOV + f"w.RNDReward({S}, nov, warmup=0)",
    DMC + "w.ColorShift(d, seed=0)",
    DMC + "w.MovingBackground(d, seed=0)",
]


def copy_case(how: str, wrapper: str) -> dict:
    """``wrapper`` pickled or deep-copied as made (a rendering env such as Pendulum holds pygame
    surfaces after its first render, which do not pickle), the copy then reset and stepped."""
    setup, _, made = wrapper.rpartition("; ")
    prefix = f"{setup}; " if setup else ""
    return api(f"import copy; {prefix}e = {made}; c = {how}; c.reset(seed=1); "
               "c.step(c.action_space.sample())", "", ok=True)  # fmt: skip


SECOND_API_CASES = [
    *(case for code, names, *values in SECOND_REFUSED for case in refused(code, names, *values)),
    *(api(code, names, ok=not names) for code, names in SECOND_CODES),
    *(copy_case(how, wrapper) for how in ("pickle.loads(pickle.dumps(e))", "copy.deepcopy(e)")
      for wrapper in COPIED),
    api(FEAT + f"import copy; e = w.ConsistencyCuriosityReward({S}, feat); "
        "c = copy.deepcopy(e); c.reset(seed=0); c.step(c.action_space.sample())", "", ok=True),
    api(PZ + "import copy; e = SPO(pz, size=16); e.reset(seed=0); c = copy.deepcopy(e); "
        "c.step({a: c.action_space(a).sample() for a in c.agents})", "", ok=True),
]  # fmt: skip
for mode in ("NEXT_STEP", "SAME_STEP"):
    SECOND_API_CASES += [
        api(f"w.{wrapper}({vec(mode)}{args})", "make_vec")
        for wrapper, args in (
            [("FrameTriplet", ""), ("ActionRepeat", ", 2"), ("RandomConvolution", "")]
            if mode == "NEXT_STEP"
            else [("ResidualMotion", ""), ("MultiCamera", ", [0]"), ("ColorShift", "")]
        )
    ]
    cartpole = vec(mode, "CartPole-v1")
    SECOND_API_CASES += [
        api(NOV + f"v = w.RNDVectorReward({cartpole}, nov, warmup=0); v.reset(seed=0); "
            "[v.step(v.action_space.sample()) for _ in range(30)]", "", ok=True),
        api(FEAT + f"v = w.ConsistencyCuriosityVectorReward({cartpole}, feat); v.reset(seed=0); "
            "[v.step(v.action_space.sample()) for _ in range(30)]", "", ok=True),
        api(NOV + f"w.RNDReward({cartpole}, nov)", "RNDVectorReward"),
        api(FEAT + f"w.ConsistencyCuriosityReward({cartpole}, feat)",
            "ConsistencyCuriosityVectorReward"),
        api(f"w.ConstantBonusVectorReward({cartpole}, 0.1).step(np.zeros(2, np.int64))", "reset"),
        api(f"v = w.ConstantBonusVectorReward({cartpole}, 0.1); v.reset(seed='a')", "seed"),
        api("v = w.ConstantBonusVectorReward(" + vec(mode, wrap="w.SimounObservation("
            "gym.wrappers.TransformReward(e, lambda r: float('nan')), size=16)") + ", 0.1); "
            "v.reset(seed=0); v.step(v.action_space.sample())", "NaN"),
        api(f"e = w.SimounObservation({C}, size=16); e.reset(seed=0); "
            "[e.step(1) for _ in range(40)]" if mode == "NEXT_STEP" else
            f"e = w.ConstantBonusReward(w.SimounObservation(w.ActionRepeat({C}, 2), size=16), "
            "0.1); e.reset(seed=0); [e.step(1) for _ in range(40)]", "", ok=True),
    ]  # fmt: skip

# the second trial's cases, new inputs of every area, run alone with --set second
BAD_INTS = ("1e3", "nan", "inf", "", "3.0", "9" * 30)
BAD_FLOATS = ("", "1e400", "0x10", "1,5", "-0")
INT_FLAGS = {
    "train": (tiny, "--seed", "--total-env-steps", "--eval-every", "--agent.batch-size",
              "--image-size", "--cameras"),
    "eval": (lambda *f: ["{run}", "--no-video", *f], "--episodes", "--seed", "--torch-threads"),
    "report": (lambda *f: ["{run}", *f], "--at-step"),
    "analyze": (lambda *f: ["masks", "{run}", *f], "--episodes"),
    "sweep": (sweep_tiny, "--cpus-per-trial", "--num-cpus"),
    "study": (lambda *f: ["run", "spec.toml", "--study-dir", "s", *f], "--num-cpus"),
    "minigrid": (lambda *f: ["run", "--archive", "a", *f], "--concurrent"),
    "driving": (lambda *f: list(f), "--episodes", "--seed"),
}  # fmt: skip
FLOAT_FLAGS = {
    "train": (tiny, "--agent.lr", "--agent.discount", "--agent.critic-tau"),
    "report": (lambda *f: ["{run}", *f], "--at-wall-time"),
    "sweep": (sweep_tiny, "--gpus-per-trial"),
}


def flag_names(flag: str) -> tuple[str, ...]:
    """What a refusal of ``flag`` may call it: the flag, or its config key."""
    return flag, flag.removeprefix("--").replace("-", "_")


SUBCOMMANDS = {
    "train": [[]], "eval": [[]], "sweep": [[]], "report": [[]], "driving": [[]],
    "study": [[], ["plan"], ["run"], ["report"]],
    "analyze": [[], ["masks"], ["bias"]],
    "minigrid": [[], ["run"], ["report"], ["select"], ["probe"]],
}  # fmt: skip
CASE_CHOICES = [
    ("train", tiny("--agent.recipe", "SAC"), "recipe"),
    ("train", tiny("--agent.augmentation", "Shift"), "augmentation"),
    ("train", tiny("--device", "CPU"), "device"),
    ("train", tiny("--eval-distraction", "Color_Easy"), "Color_Easy"),
    ("train", tiny("--preset", "CPU"), "preset"),
    ("eval", ["{run}", "--distraction", "COLOR_EASY"], "COLOR_EASY"),
    ("analyze", ["masks", "{run}", "--video", "GIF"], "--video"),
    ("analyze", ["bias", "{run}", "--recolour", "Conv", "--out", "b"], "--recolour"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--verbose", "one"], "--verbose"),
    ("driving", ["--preset", "Highway-CPU"], "preset"),
    ("sweep", sweep_tiny("--grid", "agent.recipe=SAC,drq"), "SAC"),
]
WRONG_ENVS = [
    ("ALE/Pong-v5", "ALE"), ("nosuchns/Foo-v0", "nosuchns"), ("MiniGrid-Empty-5x5-v0", "MiniGrid"),
    ("FrozenLake-v1", "FrozenLake"), ("pendulum-v1", "pendulum-v1"), ("Pendulum-v1 ", "Pendulum"),
    ("dm_control/cartpole-swingup", "cartpole-swingup"), ("", "--env"),
]  # fmt: skip
BAD_SETS = [
    ("agent.lr==3", "agent.lr"), ("agent.lr=", "agent.lr"), (" agent.lr=1e-3", "agent.lr"),
    ("agent.lr=1e-3,2e-3", "agent.lr"), ("AGENT.LR=1e-3", "AGENT.LR"), ("agent..lr=1", "agent..lr"),
    ("agent.lr 1e-3", "--set"), ("env_kwargs={bad", "env_kwargs"),
]  # fmt: skip
SECOND_FLAG_CASES = [
    *(
        cli("flags", command, build(flag, value), flag_names(flag))
        for table, values in ((INT_FLAGS, BAD_INTS), (FLOAT_FLAGS, BAD_FLOATS))
        for command, (build, *flags) in table.items()
        for flag in flags
        for value in values
    ),
    *(
        cli("flags", command, [*sub, ask], "", ok=True)
        for command, subs in SUBCOMMANDS.items()
        for sub in subs
        for ask in ("--help", "--version")
    ),
    *(cli("flags", command, argv, names) for command, argv, names in CASE_CHOICES),
    *(cli("flags", "train", tiny("--env", env), names) for env, names in WRONG_ENVS),
    cli("flags", "sweep", [*sweep_tiny()[2:], "--envs", "MiniGrid-Empty-5x5-v0"], "MiniGrid"),
    cli(
        "flags", "minigrid", ["probe", "--settings.env-id", "Pendulum-v1", "--out", "p"], "Pendulum"
    ),
    *(cli("flags", "train", tiny("--set", text), names) for text, names in BAD_SETS),
    cli("flags", "train", tiny("--run-dir", "{run}/config.json"), "--run-dir"),
    cli("flags", "train", tiny("--run-dir", "/sys/nope"), "/sys/nope"),
    cli("flags", "train", tiny("--run-dir", "", "--total-env-steps", "40"), "--run-dir"),
    cli("flags", "train", tiny("--run-dir", "runs/é ü", "--total-env-steps", "40"), "", ok=True),
    cli("flags", "train", ["--resume", "{run}"], "total"),
    cli("flags", "train", ["--resume", "{run}", "--env", "Pendulum-v1"], "env"),
    cli("flags", "train", ["--resume", "{run}/config.json"], "--resume"),
    cli("flags", "train", ["--resume", "nowhere"], "nowhere"),
    cli("flags", "train", tiny("--env-kwargs", "{'a': 1}"), "--env-kwargs"),
    cli("flags", "eval", ["{run}/config.json", "--no-video"], "config.json"),
    cli("flags", "eval", ["{run}", "--no-video", "--out", "{run}/config.json"], "--out"),
    cli("flags", "eval", ["{run}", "--no-video", "--out", "/sys/nope"], "--out"),
    cli("flags", "eval", ["{run}/checkpoint.pt", "--episodes", "1", "--no-video"], "", ok=True),
    cli("flags", "eval", ["{run}", "--episodes", "1", "--no-video", "--out", "e é"], "", ok=True),
    cli("flags", "report", ["{run}/eval.csv"], "eval.csv"),
    cli("flags", "report", ["{run}", "--out", "{run}/config.json"], "--out"),
    cli("flags", "report", ["{run}", "--out", "r é/x"], "", ok=True),
    cli("flags", "analyze", ["masks", "{run}/config.json"], "config.json"),
    cli("flags", "analyze", ["masks", "{run}", "--out", "{run}/config.json"], "--out"),
    cli("flags", "analyze", ["masks", "{run}", "--query", "1.5,2"], "--query"),
    cli("flags", "analyze", ["masks", "{run}", "--steps", "1,,2"], "--steps"),
    cli("flags", "analyze", ["bias", "--out", "b"], "RUN"),
    cli("flags", "study", ["report", "spec.toml", "--study-dir", "spec.toml"], "--study-dir"),
    cli("flags", "study", ["run", "spec.toml", "--study-dir", "spec.toml"], "--study-dir"),
    cli("flags", "sweep", sweep_tiny("--sweep-dir", "{run}/config.json"), "--sweep-dir"),
    cli("flags", "minigrid", ["report", "--archive", "{run}/config.json"], "--archive"),
    cli("flags", "minigrid", ["select", "--archive", "{run}/config.json"], "--archive"),
    cli("flags", "driving", ["--video", "."], "--video"),
    cli("flags", "driving", ["--video", "/sys/x.gif"], "--video"),
]


def edit_text(change):
    """A damage that rewrites a text file through ``change`` (its text to the new text)."""
    return lambda path: path.write_text(change(path.read_text()), newline="")


def edit_json(change):
    """A damage that rewrites a JSON file through ``change`` (in place on its value)."""

    def write(path: Path) -> None:
        data = json.loads(path.read_text())
        change(data)
        path.write_text(json.dumps(data))

    return write


def csv_rows(change):
    """A damage that rewrites a CSV's rows (lists of cells, the header first) through ``change``."""
    return edit_text(
        lambda text: "\n".join(",".join(row) for row in change([line.split(",")
                                                                for line in text.splitlines()]))
        + "\n"
    )  # fmt: skip


def into_directory(path: Path) -> None:
    path.unlink()
    path.mkdir()


CSV_DAMAGES = {
    "BOM": edit_text(lambda text: "\ufeff" + text),
    "CRLF": edit_text(lambda text: text.replace("\n", "\r\n")),
    "an extra column": csv_rows(lambda rows: [[*row, "extra" if i == 0 else "1"]
                                              for i, row in enumerate(rows)]),
    "a column missing": csv_rows(lambda rows: [row[:1] + row[2:] for row in rows]),
    "rows out of order": csv_rows(lambda rows: [rows[0], *reversed(rows[1:])]),
    "a step twice": csv_rows(lambda rows: [*rows, rows[-1]]),
    "a short row": csv_rows(lambda rows: [*rows[:-1], rows[-1][:2]]),
}  # fmt: skip
SECOND_DAMAGES = {
    "eval.csv": {
        **CSV_DAMAGES,
        "a nan return": csv_rows(lambda rows: [*rows[:-1], [rows[-1][0], "nan", *rows[-1][2:]]]),
        "a negative step": csv_rows(lambda rows: [rows[0], ["-20", *rows[1][1:]], *rows[2:]]),
    },
    "train.csv": {k: CSV_DAMAGES[k] for k in ("BOM", "CRLF", "an extra column", "a step twice")},
    "summary.json": {
        "a string step": edit_json(lambda data: data.update(env_step="forty")),
        "an empty object": edit_json(lambda data: data.clear()),
        "a directory": into_directory,
    },
    "config.json": {
        "BOM": edit_text(lambda text: "\ufeff" + text),
        "an older version (a key missing)": edit_json(lambda data: data["agent"].pop("n_step")),
        "an older version (a section missing)": edit_json(lambda data: data.pop("agent")),
        "a number as a string": edit_json(lambda data: data.update(seed="1")),
        "a directory": into_directory,
    },
    "checkpoint.pt": {"a directory": into_directory},
}
SECOND_FILE_CASES = [
    {**cli("files", command, argv, name, ok=True, setup=(name, how)), "what": f"{name} {way}"}
    for name, ways in SECOND_DAMAGES.items()
    for way, how in ways.items()
    for command, argv in FILE_COMMANDS.items()
]

SPEC_EDITS = {  # text replaced: (by, what the refusal names[, valid])
    'selection = "auc"': [
        ('selection = "auc"\nnope = 1', 'nope'),
        ('selection = 3', 'selection'),
        ('selection = "AUC"', 'selection'),
    ],
    'env_steps = 50_000': [
        ('env_steps = 50_000\nnope = 1', 'nope'),
        ('env_steps = 5e4', 'env_steps'),
        ('env_steps = true', 'env_steps'),
        ('env_steps = 1e400', 'env_steps'),
    ],
    'env_steps = 100_000': [
        ('env_steps = 100_000\nnope = 1', 'nope'),
        ('env_steps = nan', 'env_steps'),
    ],
    'max_concurrent_trials = 2': [
        ('max_concurrent_trials = 2\nnope = 1', 'nope'),
        ('max_concurrent_trials = 2\ngpus_per_trial = -1', 'gpus'),
    ],
    'video = false': [
        ('video = false\nagent.nope = 1', 'agent.nope'),
    ],
    'action_repeat = 4': [
        ('action_repeat = 4\nnope = 1', 'nope'),
    ],
    '[tasks."dm_control/cheetah-run-v0"]': [
        ('[tasks."dm_control/cheetah-run-v9"]', 'v9'),
    ],
    'recipes = ["simoun", "drq", "drqv2", "rad", "curl"]': [
        ('recipes = "simoun"', 'recipes'),
        ('recipes = []', 'recipes'),
        ('recipes = ["SIMOUN"]', 'SIMOUN'),
    ],
    'grid_overrides = ["agent.n_step"]': [
        ('grid_overrides = "agent.n_step"', 'grid_overrides'),
        ('grid_overrides = ["agent.n_stp"]', 'agent.n_stp'),
    ],
    'description = """': [
        ('description = 3\nd = """', 'description'),
    ],
    'tasks = ["dm_control/cartpole-swingup-v0"]': [
        ('tasks = "dm_control/cartpole-swingup-v0"', 'tasks'),
        ('tasks = []', 'tasks'),
        ('tasks = ["Pendulum-v1"]', '', True),
        ('tasks = ["MiniGrid-Empty-5x5-v0"]', 'MiniGrid'),
    ],
    'seeds = "101-102"': [
        ('seeds = 101', 'seeds'),
        ('seeds = "101-1e3"', 'seeds'),
        ('seeds = "101,101"', 'seeds'),
        ('seeds = "-1-2"', 'seeds'),
    ],
    'seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }': [
        ('seeds = "100-104"', 'seed'),
    ],
    '"dm_control/cheetah-run-v0" = "1-3" }': [
        ('"dm_control/cheetah-run-v0" = "102-104" }', "102"),
        ('}', 'cheetah'),
    ],
    'cpus_per_trial = 1 ': [
        ('cpus_per_trial = 1.5 ', 'cpus_per_trial'),
        ('cpus_per_trial = "1" ', 'cpus_per_trial'),
    ],
    'eval_every = 10_000': [
        ('eval_every = 1.5', 'eval_every'),
        ('eval_every = "often"', 'eval_every'),
    ],
    'agent.n_step = [1, 3]': [
        ('agent.n_step = [1, "three"]', 'n_step'),
        ('agent.n_step = [1, 3, 3]', 'n_step'),
        ('agent.n_step = [1, 3]\nagent.lr = [1e400]', 'lr'),
    ],
    'action_repeat = 8': [
        ('action_repeat = 2.5', 'action_repeat'),
    ],
    '[resources]': [
        ('[[resources]]', 'resources'),
    ],
    '[grid]': [
        ('grid = 3\n[grid2]', 'grid'),
    ],
}  # fmt: skip
MINIGRID_SPEC = (ROOT / "docs/studies/minigrid/spec.json").read_text()
MINIGRID_EDITS = [  # (a change to the spec's JSON value, what the refusal names)
    (lambda s: s["tasks"][0].update(nope=1), "nope"),
    (lambda s: s["ppo"].update(nope=1), "nope"),
    (lambda s: s.update(tasks={}), "tasks"),
    (lambda s: s.update(tasks=["MiniGrid-DoorKey-6x6-v0"]), "tasks"),
    (lambda s: s.update(tasks=[]), "tasks"),
    (lambda s: s["tasks"][0].update(steps="400k"), "steps"),
    (lambda s: s["tasks"][0].update(steps=4e5), "steps"),
    (lambda s: s["tasks"][0].pop("env_id"), "env_id"),
    (lambda s: s["tasks"][0].update(seeds=3), "seeds"),
    (lambda s: s["tasks"][0].update(seeds=["0"]), "seeds"),
    (lambda s: s["tasks"][0].update(env_id="MiniGrid-Nope-v0"), "MiniGrid-Nope-v0"),
    (lambda s: s["tasks"][0].update(env_id="Pendulum-v1"), "Pendulum-v1"),
    (lambda s: s.update(arms="ppo"), "arms"),
    (lambda s: s.update(arms=["PPO"]), "PPO"),
    (lambda s: s["ppo"].update(learning_rate="fast"), "learning_rate"),
    (lambda s: s["ppo"].update(n_envs=0), "n_envs"),
    (lambda s: s["ppo"].update(gamma=1.5), "gamma"),
    (lambda s: s.update(evaluations=0.5), "evaluations"),
    (lambda s: s.update(eval_seed=2), ""),
    (lambda s: s.update(eval_seed="1e6"), "eval_seed"),
    (lambda s: s.update(device="tpu"), "device"),
    (lambda s: s.update(ppo=[]), "ppo"),
]


def minigrid_spec(change) -> str:
    spec = json.loads(MINIGRID_SPEC)
    change(spec)
    return json.dumps(spec)


SECOND_SPEC_CASES = [
    *(spec_case(SPEC.replace(old, new, 1), names, ok=bool(ok))
      for old, edits in SPEC_EDITS.items() for new, names, *ok in edits),
    spec_case(SPEC.replace("\n", "\r\n"), "", ok=True),
    spec_case("\ufeff" + SPEC, "spec.toml"),
    *(
        cli("specs", "minigrid", [("report", "select")[i % 2], "--spec", "spec.json", "--archive",
            "."], names, setup=("spec", (".json", minigrid_spec(change))))
        for i, (change, names) in enumerate(MINIGRID_EDITS)
    ),
]  # fmt: skip
SECOND_COMMAND_CASES = SECOND_FLAG_CASES + SECOND_FILE_CASES + SECOND_SPEC_CASES
for _case in SECOND_COMMAND_CASES + SECOND_API_CASES:
    _case["set"] = "second"

# the third trial's cases, new kinds in every area, run alone with --set third


def eq(build, flag: str, value: str) -> list[str]:
    """``build``'s argv with ``flag value`` given as the one word ``flag=value``."""
    argv = build(flag, value)
    at = len(argv) - 1 - argv[::-1].index(flag)
    return [*argv[:at], f"{flag}={value}", *argv[at + 2 :]]


def call(work):
    """A setup that runs ``work`` on the case's directory (its copy of the tiny run in ``run``)."""
    return ("call", work)


def symlinks(here: Path) -> None:
    """``loop`` points at itself, ``dangling`` at nothing, ``link`` at the run."""
    (here / "loop").symlink_to("loop")
    (here / "dangling").symlink_to("nowhere/x")
    (here / "link").symlink_to("run")


def report_output(here: Path) -> None:
    """``output-of-report``: what simoun-report wrote for the run."""
    from simoun_lab.cli import report

    assert report.main([str(here / "run"), "--out", str(here / "output-of-report")]) == 0


def runs_dir(*changes):
    """A setup making ``mix``: a copy of the run per change, each change run on the copy."""

    def make(here: Path) -> None:
        (here / "mix").mkdir()
        for i, change in enumerate(changes):
            copy = here / "mix" / f"run{i}"
            shutil.copytree(here / "run", copy)
            if change is not None:
                change(copy)

    return make


def config_edit(change):
    """A change to a run copy's config.json value."""
    return lambda run: edit_json(change)(run / "config.json")


RUN = ["{run}"]
EVAL = ["--episodes", "1", "--no-video"]
SHORT = ["--total-env-steps", "40", "--run-dir", "r"]


def masks(*f: str) -> list[str]:
    return ["masks", "{run}", *f]


def bias(*f: str) -> list[str]:
    return ["bias", "{run}", *f]


def eval_argv(*f: str) -> list[str]:
    return ["{run}", "--no-video", *f]


def report_argv(*f: str) -> list[str]:
    return ["{run}", *f]


def plan(*f: str) -> list[str]:
    return ["plan", "spec.toml", *f]


def study_run(*f: str) -> list[str]:
    return ["run", "spec.toml", "--study-dir", "s", *f]


def minigrid_run(*f: str) -> list[str]:
    return ["run", "--archive", ".", "--spec", str(ROOT / "docs/studies/minigrid/spec.json"), *f]


def probe(*f: str) -> list[str]:
    return ["probe", "--out", "p", *f]


def driving(*f: str) -> list[str]:
    return list(f)


EQ_REFUSED = [  # (command, argv builder, flag, value, what the refusal names)
    ("train", tiny, "--seed", "-1", None), ("train", tiny, "--total-env-steps", "0", None),
    ("train", tiny, "--agent.lr", "-1", None), ("train", tiny, "--image-size", "8", "image"),
    ("train", tiny, "--agent.recipe", "curll", "recipe"), ("train", tiny, "--device", "tpu", None),
    ("train", tiny, "--env", "Pendulum-v9", "Pendulum-v9"),
    ("train", tiny, "--eval-distraction", "colour_hard", "colour_hard"),
    ("train", tiny, "--action-repeat", "0", None), ("train", tiny, "--agent.batch-size", "0", None),
    ("train", tiny, "--preset", "cpux", "cpux"),
    ("train", tiny, "--env-kwargs", '{"nope": 1}', "nope"),
    ("train", tiny, "--set", "agent.nope=1", "agent.nope"),
    ("eval", eval_argv, "--episodes", "0", None), ("eval", eval_argv, "--seed", "-2", None),
    ("eval", eval_argv, "--torch-threads", "0", None),
    ("eval", eval_argv, "--distraction", "colour_hard", "colour_hard"),
    ("eval", eval_argv, "--device", "tpu", None),
    ("report", report_argv, "--at-step", "0", None),
    ("report", report_argv, "--at-wall-time", "-5", None),
    ("analyze", masks, "--steps", "-1", None), ("analyze", masks, "--query", "1", None),
    ("analyze", masks, "--video", "avi", None), ("analyze", masks, "--episodes", "0", None),
    ("analyze", bias, "--pairs", "0", None), ("analyze", bias, "--recolour", "paint", None),
    ("sweep", sweep_tiny, "--seeds", "5-2", None),
    ("sweep", sweep_tiny, "--grid", "agent.lr", None),
    ("sweep", sweep_tiny, "--cpus-per-trial", "0", None),
    ("sweep", sweep_tiny, "--verbose", "5", None),
    ("sweep", sweep_tiny, "--gpus-per-trial", "-1", None),
    ("study", plan, "--probe-updates", "-1", None), ("study", study_run, "--num-cpus", "0", None),
    ("study", study_run, "--verbose", "3", None),
    ("minigrid", minigrid_run, "--concurrent", "0", None),
    ("minigrid", probe, "--settings.steps", "0", ("--settings.steps", "steps")),
    ("minigrid", probe, "--probes", "rndd", "rndd"),
    ("driving", driving, "--episodes", "0", None), ("driving", driving, "--preset", "cpux", "cpux"),
    ("driving", driving, "--video", "x.txt", None),
]  # fmt: skip
EQ_VALID = [
    ("report", report_argv("--at-step=20")),
    ("eval", ["{run}", "--episodes=1", "--no-video"]),
    ("study", ["plan", "spec.toml", "--probe-updates=0"]),
    ("analyze", masks("--steps=1")),
    ("train", tiny("--total-env-steps=40", "--run-dir=r")),
]
NO_VIDEO = [arg for arg in TINY if arg != "--no-video"]
SWITCH_VALUES = [  # a switch given =value: (command, argv, the switch, valid)
    ("train", [*NO_VIDEO, *SHORT, "--no-video=true"], "--no-video", True),
    ("train", [*NO_VIDEO, *SHORT, "--video=false"], "--video", True),
    ("eval", eval_argv("--episodes", "1", "--overwrite=yes"), "--overwrite", True),
    ("eval", eval_argv("--episodes", "1", "--random-policy=false"), "--random-policy", True),
    ("analyze", masks("--steps", "1", "--overwrite=no"), "--overwrite", True),
    ("study", study_run("--resume=true"), ("--resume", "--study-dir"), False),
    ("sweep", ["--resume=1", "--sweep-dir", "x"], ("--resume", "--sweep-dir"), False),
]
EXTRA_WORDS = [
    ("report", ["{run}", "extra"]), ("study", ["plan", "spec.toml", "extra"]),
    ("minigrid", ["report", "extra"]), ("driving", ["extra"]),
    ("sweep", [*sweep_tiny(), "extra"]), ("train", [*tiny(), "extra"]),
]  # fmt: skip
BLANKS = [  # empty or blank option values
    ("eval", eval_argv("--out", " "), "--out"), ("report", report_argv("--out", ""), "--out"),
    ("sweep", sweep_tiny("--sweep-dir", " "), "--sweep-dir"),
    ("study", ["run", "spec.toml", "--study-dir", ""], "--study-dir"),
    ("minigrid", ["report", "--archive", " "], "--archive"),
    ("analyze", masks("--out", " "), "--out"), ("driving", ["--json", ""], "--json"),
    ("train", tiny("--total-env-steps", "40", "--run-dir", " "), "--run-dir"),
]  # fmt: skip
ODD_TEXT = [  # unicode, whitespace and very long words
    ("train", tiny("--env", "Pendulum\u2011v1"), "Pendulum"),
    ("train", tiny("--agent.recipe", "simoun "), "recipe"),
    ("train", tiny("--agent.recipe", "\uff53\uff49\uff4d\uff4f\uff55\uff4e"), "recipe"),
    ("train", tiny("--device", " cpu"), "device"),
    ("train", tiny("--preset", "cpu\u200b"), "preset"),
    ("train", [*tiny(), "\u2013-seed", "3"], "\u2013-seed"),
    ("train", [*tiny(), "\u2014seed", "3"], "\u2014seed"),
    ("train", [*tiny(), "--seed\u00a0", "3"], "--seed"),
    ("train", [*tiny(), "--" + "a" * 3000], "--aaaa"),
    ("train", tiny("--run-dir", "x" * 5000), "--run-dir"),
    ("train", tiny("--run-dir", "a" * 300 + "/r"), "--run-dir"),
    ("eval", eval_argv("--out", "o" * 5000), "--out"),
    ("report", report_argv("--out", "o" * 300), "--out"),
    ("sweep", sweep_tiny("--sweep-dir", "s" * 300), "--sweep-dir"),
    ("study", ["run", "spec.toml", "--study-dir", "s" * 300], "--study-dir"),
    ("train", tiny("--set", "agent.lr\u200b=1e-3"), "agent.lr"),
    ("sweep", sweep_tiny("--grid", "agent.n_step=1,\u00a03"), "agent.n_step", True),
    ("train", tiny("--env-kwargs", '{"size": 32}\u00a0'), "--env-kwargs"),
]
ODD_ENVS = [
    ("Pendulum-v0", "Pendulum"), ("Pendulum", "Pendulum"),
    ("dm_control/cartpole-swingup-v1", "cartpole-swingup"),
    ("dm_control/cartpole_swingup-v0", "cartpole"), ("dm_control/Cartpole-swingup-v0", "Cartpole"),
    ("gym/Pendulum-v1", "gym/Pendulum"), (":Pendulum-v1", ("--env", ":Pendulum")),
    ("Pendulum-v1:", ("--env", "Pendulum-v1:")), ("dm_control/", "dm_control"),
    ("minigrid:MiniGrid-Empty-5x5-v0", "MiniGrid"), ("Blackjack-v1", "Blackjack"),
    ("Acrobot-v1", "Acrobot"), ("LunarLander-v3", "LunarLander"),
    ("simoun/PointReach-v9", "PointReach"), ("simoun/pointreach-v0", "pointreach"),
    ("dm_control/cartpole-swingup-v0/extra", "dm_control"),
]  # fmt: skip
ENV_KWARGS = [
    ('"a"', "--env-kwargs"), ("null", "--env-kwargs"), ("3", "--env-kwargs"),
    ('{"size": 1e400}', "size"), ('{"size": NaN}', "size"), ('{"max_steps": -5}', "max_steps"),
    ('{"step_size": "big"}', "step_size"), ('{"render_mode": "human"}', "render_mode"),
    ('{"size": {"a": 1}}', "size"), ('{"size": 99999999999999999999999}', "size"),
    ('{"size": 32, "size": 16}', ("size", "--env-kwargs")), ("{} x", "--env-kwargs"),
    ('{"size": 0}', "size"), ('{"": 1}', ("--env-kwargs", "''")),
]  # fmt: skip
SYMLINKS = [  # (command, argv, names, valid): loop -> itself, dangling -> nothing, link -> the run
    ("train", tiny("--total-env-steps", "40", "--run-dir", "loop"), ("loop", "--run-dir"), False),
    ("train", tiny("--total-env-steps", "40", "--run-dir", "dangling"), ("dangling", "--run-dir"),
     False),
    ("eval", ["loop", *EVAL], "loop", False), ("eval", ["link", *EVAL], "", True),
    ("report", ["link"], "", True), ("analyze", ["masks", "loop"], "loop", False),
    ("train", ["--resume", "loop"], "loop", False),
    ("train", ["--resume", "link", "--total-env-steps", "60"], "", True),
    ("sweep", sweep_tiny("--sweep-dir", "loop"), ("loop", "--sweep-dir"), False),
    ("study", ["run", "spec.toml", "--study-dir", "loop"], ("loop", "--study-dir"), False),
    ("minigrid", ["report", "--archive", "loop"], ("loop", "--archive"), False),
    ("eval", eval_argv("--episodes", "1", "--out", "loop"), ("loop", "--out"), False),
]  # fmt: skip
REPORT_OUT = "output-of-report"
OUTPUTS = [  # one command given another's output: (command, argv, names, valid)
    ("eval", [REPORT_OUT, *EVAL], (REPORT_OUT, "config.json"), False),
    ("train", ["--resume", REPORT_OUT], (REPORT_OUT, "config.json"), False),
    ("analyze", ["masks", REPORT_OUT], (REPORT_OUT, "config.json"), False),
    ("report", [REPORT_OUT], (REPORT_OUT,), False),
    ("study", ["report", "spec.toml", "--study-dir", REPORT_OUT], (REPORT_OUT, "--study-dir"),
     False),
    ("minigrid", ["select", "--archive", REPORT_OUT], (REPORT_OUT, "--archive"), False),
    ("sweep", ["--resume", "--sweep-dir", REPORT_OUT], ("sweep.json",), False),
    ("train", tiny("--total-env-steps", "40", "--run-dir", REPORT_OUT), (REPORT_OUT, "--run-dir"),
     True),
    ("eval", ["{run}/tb", *EVAL], ("config.json", "/tb"), False),
    ("train", ["--resume", "{run}/tb"], ("config.json", "/tb"), False),
    ("eval", eval_argv("--episodes", "1", "--out", "{run}"), "--out", True),
    ("report", report_argv("--out", "{run}"), "--out", True),
    ("analyze", masks("--steps", "1", "--out", "{run}"), "--out", True),
]  # fmt: skip


def nest(run: Path) -> None:
    """Move the run two directories deeper."""
    (run.parent / "a" / "b").mkdir(parents=True)
    shutil.move(run, run.parent / "a" / "b" / "run")


def truncate_eval(run: Path) -> None:
    path = run / "eval.csv"
    path.write_text("\n".join(path.read_text().splitlines()[:2]) + "\n")


MIXES = [  # report on a directory of runs: (the runs' changes, extra argv, names, valid)
    ((None, config_edit(lambda c: c.update(env="Pendulum-v1"))), [], ("Pendulum", "env"), True),
    ((None, config_edit(lambda c: c.update(image_size=48))), [], "image_size", True),
    ((None, lambda run: (run.parent / "notes").mkdir()), [], "notes", True),
    ((None, lambda run: (run.parent / "README.md").write_text("runs\n")), [], "README", True),
    ((None, None), [], "seed", True),
    ((nest,), [], "", True),
    ((None, lambda run: (run / "eval.csv").unlink()), [], "eval.csv", True),
    ((None, config_edit(lambda c: c["agent"].update(recipe="drq"))), [], "recipe", True),
    ((None, truncate_eval), ["--at-step", "20"], "--at-step", True),
    ((None, lambda run: (run.parent / "loop").symlink_to("loop")), [], "loop", True),
]
BUDGETS = [  # (command, argv, names, valid)
    ("report", report_argv("--at-step", "100000"), "--at-step", True),
    ("report", report_argv("--at-step", "40"), "", True),
    ("report", report_argv("--at-wall-time", "1e9"), "--at-wall-time", True),
    ("report", report_argv("--at-wall-time", "0.0001"), "--at-wall-time", True),
    ("train", ["--resume", "{run}", "--total-env-steps", "40"], "total", False),
    ("train", ["--resume", "{run}", "--total-env-steps", "41"], "", True),
    ("train", tiny("--total-env-steps", "5", "--run-dir", "r"), "warmup", True),
    ("train", tiny("--eval-every", "1000", *SHORT), "", True),
    ("analyze", masks("--steps", "100000"), "--steps", False),
    ("analyze", masks("--steps", "0"), "", True),
    ("train", ["--resume", "{run}", "--total-env-steps", "60", "--eval-every", "0"], "eval_every",
     False),
]  # fmt: skip
KINDS_IN_FIXING = [  # kinds other changes fix: (command, argv, names)
    ("sweep", sweep_tiny("--seeds", "0-100000"), "--seeds"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--archive", "s"], "--archive"),
    ("study", ["run", "spec.toml", "--study-dir", "s", "--archive", "./s/"], "--archive"),
    ("sweep", sweep_tiny("--sweep-dir", "/proc/x"), "--sweep-dir"),
    ("minigrid", probe("--settings.n-steps", "0"), ("--settings.n-steps", "n_steps")),
    ("minigrid", probe("--probes"), "--probes"),
]
THIRD_FLAG_CASES = [
    *(cli("flags", command, eq(build, flag, value), names or flag_names(flag))
      for command, build, flag, value, names in EQ_REFUSED),
    *(cli("flags", command, argv, "", ok=True) for command, argv in EQ_VALID),
    *(cli("flags", command, argv, names, ok=ok) for command, argv, names, ok in SWITCH_VALUES),
    *(cli("flags", command, argv, "extra") for command, argv in EXTRA_WORDS),
    *(cli("flags", command, argv, names, ok=bool(ok))
      for command, argv, names, *ok in BLANKS + ODD_TEXT),
    *(cli("flags", "train", tiny("--env", env), names) for env, names in ODD_ENVS),
    cli("flags", "train", tiny("--env", "simoun_agent.envs:simoun/PointReach-v0", *SHORT), "",
        ok=True),
    cli("flags", "train", tiny("--env-module", "simoun_agent.envs:x"), "--env-module"),
    cli("flags", "train", tiny("--env-module", "..x"), ("--env-module", "..x")),
    cli("flags", "train", tiny("--env-module", "os.path.nope"), "os.path.nope"),
    cli("flags", "sweep", [*sweep_tiny()[2:], "--envs", "Pendulum-v1,Pendulum-v1"],
        ("--envs", "Pendulum")),
    *(cli("flags", "train", tiny("--env-kwargs", text), names) for text, names in ENV_KWARGS),
    cli("flags", "train", tiny("--set", 'env_kwargs={"size": 0}'), "size"),
    *(cli("flags", command, argv, names, ok=ok, setup=call(symlinks))
      for command, argv, names, ok in SYMLINKS),
    *(cli("flags", command, argv, names, ok=ok, setup=call(report_output))
      for command, argv, names, ok in OUTPUTS),
    *(cli("flags", "report", ["mix", *extra], names, ok=ok, setup=call(runs_dir(*changes)))
      for changes, extra, names, ok in MIXES),
    cli("flags", "report", ["mix"], ("no run", "empty", "config.json", "eval.csv"),
        setup=call(runs_dir())),
    *(cli("flags", command, argv, names, ok=ok) for command, argv, names, ok in BUDGETS),
    *(cli("flags", command, argv, names) for command, argv, names in KINDS_IN_FIXING),
]  # fmt: skip


def write_bytes(change):
    """A damage that rewrites a file's bytes through ``change``."""
    return lambda path: path.write_bytes(change(path.read_bytes()))


def symlink_to(target: str):
    """A damage that replaces a file by a symlink to ``target`` (relative to the run)."""

    def link(path: Path) -> None:
        path.unlink()
        path.symlink_to(target)

    return link


def rename_replay(path: Path) -> None:
    path.rename(path.with_name("replay-20.npz"))


THIRD_DAMAGES = {
    "eval.csv": {
        "the header twice": csv_rows(lambda rows: [rows[0], rows[1], rows[0], *rows[2:]]),
        "CRLF on one line only": edit_text(lambda text: text.replace("\n", "\r\n", 1)),
        "trailing binary garbage": write_bytes(lambda data: data + b"\x00\xff\xfegarbage"),
        "a NUL byte in the header": edit_text(lambda text: "\x00" + text),
        "a 40-digit step": csv_rows(lambda rows: [*rows[:-1], ["9" * 40, *rows[-1][1:]]]),
        "a dangling symlink": symlink_to("nowhere.csv"),
        "a symlink to itself": symlink_to("eval.csv"),
        "an inf return": csv_rows(lambda rows: [*rows[:-1], [rows[-1][0], "inf",
                                                              *rows[-1][2:]]]),
        "every cell quoted": csv_rows(lambda rows: [[f'"{c}"' for c in row] for row in rows]),
        "a blank line after the header": edit_text(lambda text: text.replace("\n", "\n\n", 1)),
    },
    "train.csv": {
        "the header twice": csv_rows(lambda rows: [rows[0], rows[1], rows[0], *rows[2:]]),
    },
    "summary.json": {
        "a NaN step": edit_text(lambda text: text.replace('"env_step": 40', '"env_step": NaN')),
        "trailing garbage": edit_text(lambda text: text + "}"),
    },
    "config.json": {
        "one level deeper": edit_text(lambda text: json.dumps({"config": json.loads(text)})),
        "an older version (env missing)": edit_json(lambda data: data.pop("env")),
        "UTF-16": write_bytes(lambda data: data.decode().encode("utf-16")),
        "a key twice": edit_text(lambda text: text.replace('"seed": 1,',
                                                           '"seed": 1,\n  "seed": 2,')),
        "another run's env": edit_json(lambda data: data.update(env="Pendulum-v1")),
    },
    "checkpoint.pt": {
        "zero-filled": write_bytes(lambda data: bytes(len(data))),
        "a dangling symlink": symlink_to("nowhere.pt"),
    },
    "replay": {
        "named for another step": rename_replay,
        "zero-filled": write_bytes(lambda data: bytes(len(data))),
    },
    ".lock": {"held by a live process (pid 1)": edit_text(lambda text: "1\n")},
}  # fmt: skip
THIRD_FILE_CASES = [
    {**cli("files", command, argv, names, ok=True, setup=(name, how)), "what": f"{name} {way}"}
    for name, ways in THIRD_DAMAGES.items()
    for names in [(name, "in use") if name == ".lock" else name]
    for way, how in ways.items()
    for command, argv in FILE_COMMANDS.items()
]

EVAL_TASKS = 'tasks = ["dm_control/cartpole-swingup-v0", "dm_control/cheetah-run-v0"]'
EVAL_SEEDS = (
    'seeds = { "dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cheetah-run-v0" = "1-3" }'
)
RECIPES = 'recipes = ["simoun", "drq", "drqv2", "rad", "curl"]'
THIRD_SPEC_EDITS = [  # (text replaced, by, what the refusal names[, valid])
    ("env_steps = 50_000", "env_steps = 1979-05-27", "env_steps"),
    ('seeds = "101-102"', "seeds = 07:32:00", "seeds"),
    ("[tuning]", "[[tuning]]", "tuning"),
    ('selection = "auc"', 'selection = "auc"\nselection = "auc"', ("spec.toml", "selection")),
    ("[resources]", "[base]\nseed = 3\n\n[resources]", ("spec.toml", "base")),
    ("env_steps = 50_000", "env_steps = 99999999999999999999999", "env_steps"),
    ("env_steps = 50_000", "env_steps = -50_000", "env_steps"),
    ("env_steps = 100_000", "env_steps = -1", "env_steps"),
    (EVAL_TASKS, "tasks = []", "tasks"),
    (RECIPES, 'recipes = ["simon", "drq"]', "simon"),
    (RECIPES, 'recipes = ["simoun", "drq-v2"]', "drq-v2"),
    (RECIPES, 'recipes = ["simoun", "curl_sac"]', "curl_sac"),
    (RECIPES, 'recipes = ["simoun", 3]', "recipes"),
    ('selection = "auc"', 'selection = ""', "selection"),
    ("eval_episodes = 10", "eval_episodes = -1", "eval_episodes"),
    ("[base]\n", "[base]\nseed = 5\n", "seed"),
    ("[base]\n", "[base]\ntotal_env_steps = 100\n", "total_env_steps"),
    ("[base]\n", '[base]\nenv = "Pendulum-v1"\n', "env"),
    ("[base]\n", '[base]\nrun_dir = "x"\n', "run_dir"),
    ("[base]\n", "[base]\nagent.lr = -1\n", "lr"),
    ("[base]\n", "[base]\nagent = 3\n", "agent"),
    ("[base]\n", "[base]\nagent.n_step = 3\n", "n_step"),
    ("agent.n_step = [1, 3]", "agent.n_step = [3]", "n_step", True),
    ("agent.n_step = [1, 3]", "agent.n-step = [1, 3]", "n-step"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nseed = [1, 2]", "seed"),
    ("agent.n_step = [1, 3]", "agent.n_step = [{a = 1}, 3]", "n_step"),
    ('seeds = "101-102"', 'seeds = " 101 - 102 "', "seeds", True),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-5"', '"1-20000"'), "seeds"),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-3" }', '"1-3", "dm_control/walker-walk-v0" = "1-2" }'),
     "walker"),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-3"', "3"), ("seeds", "cheetah")),
    ("[resources]", '[tasks."dm_control/walker-walk-v0"]\naction_repeat = 2\n\n[resources]',
     "walker-walk"),
    ("action_repeat = 4", "action_repeat = 4\nimage_size = 0", "image_size"),
    ("action_repeat = 4", "action_repeat = -4", "action_repeat"),
    ("cpus_per_trial = 1 ", "cpus_per_trial = 100000 ", "cpus_per_trial", True),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 0", "max_concurrent_trials"),
    ('description = """', 'description = """' + "x" * 1_000_000, "", True),
    ('selection = "auc"', 'sélection = "auc"', ("sélection", "spec.toml")),
    ('seeds = "101-102"', "seeds = 1.5", "seeds"),
    ('seeds = "101-102"', 'seeds = ""', "seeds"),
    ('seeds = "101-102"', 'seeds = "101-102-103"', "seeds"),
    ("env_steps = 50_000", "env_steps = 200_000", "", True),
    ('preset = "cpu"', 'preset = "cpu"\npreset = "highway"', ("spec.toml", "preset")),
    ("[grid]\nagent.n_step = [1, 3]", "[grid]", "n_step"),
    ('preset = "cpu"', 'preset = ""', "preset"),
    ('"dm_control/cartpole-swingup-v0" = "1-5"',
     '"dm_control/cartpole-swingup-v0" = "1-5", "dm_control/cartpole-swingup-v0" = "6-7"',
     "spec.toml"),
    ('selection = "auc"', 'selection = "a\x00uc"', "spec.toml"),
]  # fmt: skip
THIRD_SPEC_TEXTS = [  # whole specs: (text, names[, valid])
    (SPEC + '\n[diagnostics]\ndrqq = ["simoun_no_aux"]\n', "drqq"),
    (SPEC + '\n[diagnostics]\nsimoun = "simoun_no_aux"\n', ("diagnostics", "simoun_no_aux")),
    (SPEC + '\n[generalization]\nmodes = ["color_hard"]\nepisodes = 0\n', "episodes"),
    (SPEC + "\n[generalization]\nmodes = []\n", "modes", True),
    ("# nothing here\n", "recipes"),
]


def spec_file(name: str, make):
    """A setup that lays out ``name`` (a spec) with ``make(path)``."""
    return call(lambda here: make(here / name))


SPEC_FILES = [  # (file name, how it is made)
    ("spec_dir.toml", lambda path: path.mkdir()),
    ("dangling.toml", lambda path: path.symlink_to("nowhere.toml")),
    ("spec16.toml", lambda path: path.write_bytes(SPEC.encode("utf-16"))),
]
THIRD_MINIGRID_EDITS = [  # (a change to the spec's JSON value, what the refusal names)
    (lambda s: s["tasks"][0].update(seeds=[0, 0]), "seeds"),
    (lambda s: s["tasks"][0].update(steps=-5), "steps"),
    (lambda s: s.update(eval_episodes=0), "eval_episodes"),
    (lambda s: s.update(evaluations=10**30), "evaluations"),
    (lambda s: s["ppo"].update(gamma=float("nan")), "gamma"),
    (lambda s: s.update(arms=[]), "arms"),
    (lambda s: s.update(arms=["ppo", "ppo"]), "arms"),
    (lambda s: s["ppo"].update(batch_size=100000), "batch_size", True),
    (lambda s: s.update(eval_seed=-1), "eval_seed"),
    (lambda s: s["tasks"][0].update(env_id="MiniGrid-DoorKey-6x6-v0 "), ("env_id", "DoorKey")),
]


def minigrid_spec_case(i: int, text: str, names, name: str = "spec.json", setup=None, ok=False):
    return cli("specs", "minigrid", [("report", "select")[i % 2], "--spec", name, "--archive",
               "."], names, ok, setup=setup or ("spec", (".json", text)))  # fmt: skip


for _old, _new, *_ in THIRD_SPEC_EDITS:
    assert _old in SPEC, _old

THIRD_SPEC_CASES = [
    *(spec_case(SPEC.replace(old, new, 1), names, ok=bool(ok))
      for old, new, names, *ok in THIRD_SPEC_EDITS),
    *(spec_case(text, names, ok=bool(ok)) for text, names, *ok in THIRD_SPEC_TEXTS),
    *(cli("specs", "study", ["plan", name, "--probe-updates", "0"], name,
          setup=spec_file(name, make)) for name, make in SPEC_FILES),
    *(minigrid_spec_case(i, minigrid_spec(change), names, ok=bool(ok))
      for i, (change, names, *ok) in enumerate(THIRD_MINIGRID_EDITS)),
    minigrid_spec_case(0, MINIGRID_SPEC.replace('"arms": [', '"arms": ["rnd"],\n  "arms": [', 1),
                       "arms"),
    minigrid_spec_case(1, "", "spec16.json", "spec16.json", spec_file(
        "spec16.json", lambda path: path.write_bytes(MINIGRID_SPEC.encode("utf-16")))),
]  # fmt: skip

BJ = "gym.make('Blackjack-v1', render_mode='rgb_array')"
RENDERED = "gym.wrappers.AddRenderObservation(gym.make('CartPole-v1', render_mode='rgb_array'))"


def image_env(change: str, space: str) -> str:
    """CartPole whose observation is its render put through ``change`` into ``space``."""
    return f"gym.wrappers.TransformObservation({RENDERED}, lambda o: {change}, {space})"


IMAGE_4D = image_env("o[None]", "gym.spaces.Box(0, 255, (1, 400, 600, 3), np.uint8)")
IMAGE_RGBA = image_env(
    "np.concatenate([o, o[..., :1]], -1)", "gym.spaces.Box(0, 255, (400, 600, 4), np.uint8)"
)
IMAGE_CHW = image_env("o.transpose(2, 0, 1)", "gym.spaces.Box(0, 255, (3, 400, 600), np.uint8)")
IMAGE_HW1 = image_env("o[..., :1]", "gym.spaces.Box(0, 255, (400, 600, 1), np.uint8)")
MB = image_env("(o > 0).astype(np.int8)[0, :4, 0]", "gym.spaces.MultiBinary(4)")
S40 = f"w.SimounObservation({P}, size=40, fold_frames=True)"
S64 = f"w.SimounObservation({P}, size=64)"
RND = "from simoun_agent.rnd_model import RNDModel; "
CUR = "from simoun_agent.curiosity_model import CuriosityModel; "
FRAMES = "np.zeros((3, 3, 32, 32), np.uint8)"
FILLED = (
    "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((3, 32, 32), np.uint8)); "
    "[r.add(np.zeros(1), 0.0, np.zeros((3, 32, 32), np.uint8), False, False) for _ in range(9)]; "
)
ADD = (
    "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((3, 32, 32), np.uint8)); "
    "r.add({})"
)
FRAME = "np.zeros((3, 32, 32), np.uint8)"
POINT = "import simoun_agent.envs; gym.make('simoun/PointReach-v0', {})"


def vec1(
    env: str = "Pendulum-v1", wrap: str = "w.SimounObservation(e, size=16)", mode: str = "sync"
) -> str:
    """A vector env of one ``env``, wrapped by ``wrap``."""
    return (f"gym.make_vec('{env}', 1, vectorization_mode='{mode}', render_mode='rgb_array', "
            f"wrappers=[lambda e: {wrap}])")  # fmt: skip


STEPS3 = "v.reset(seed=0); [v.step(v.action_space.sample()) for _ in range(3)]"
CLOSED = [  # wrappers closed twice, then one stepped or reset after close
    f"w.FrameTriplet({P})", f"w.ActionRepeat({P}, 2)", f"w.RandomConvolution({P})",
    f"import operator; w.MultiCamera({P}, cameras=[operator.methodcaller('render')], size=16)",
    f"w.ConstantBonusReward({S}, 0.1)", NOV + f"w.RNDReward({S}, nov, warmup=0)",
    DMC + "w.ColorShift(d, seed=0)",
]  # fmt: skip
RENDER_AS = "class R(gym.Wrapper):\n    def render(self):\n        return {}\n"
# (code, the name the refusal must give, or "" for a valid input that must go on[, valid: the
# input may go on, or be refused naming the name])
THIRD_CODES = [
    # every observation-space kind
    (f"e = w.SimounObservation({BJ}, size=16); " + STEP, ""),
    ("w.FrameTriplet(gym.make('Blackjack-v1'))", "Box"),
    ("w.ResidualMotion(gym.make('Blackjack-v1'))", ("Box", "(k, C, H, W)")),
    ("w.RandomConvolution(gym.make('Blackjack-v1'))", "render_mode"),
    (f"w.FrameTriplet({MB})", "Box"),
    (f"e = w.SimounObservation({MB}, size=16); " + STEP, ""),
    (f"w.SimounObservation({MB}, source='observation')", ("observation", "image", "MultiBinary")),
    *((f"w.SimounObservation({image_env(f'o.astype(np.{t})', space)}, source='observation')",
       "uint8") for t, space in (
        ("int32", "gym.spaces.Box(0, 255, (400, 600, 3), np.int32)"),
        ("float16", "gym.spaces.Box(0, 255, (400, 600, 3), np.float16)"),
        ("uint16", "gym.spaces.Box(0, 255, (400, 600, 3), np.uint16)"),
        ("bool_", "gym.spaces.Box(0, 1, (400, 600, 3), np.bool_)"),
    )),
    (f"w.SimounObservation({IMAGE_4D}, source='observation')", ("shape", "(H, W", "rank")),
    ("w.SimounObservation(gym.make('Pendulum-v1'), source='observation')",
     ("uint8", "image", "observation")),
    (f"e = w.SimounObservation({IMAGE_RGBA}, source='observation', size=16); " + STEP,
     ("channel", "RGB", "4"), True),
    (f"e = w.SimounObservation({IMAGE_CHW}, source='observation', size=16); " + STEP,
     ("channel", "(H, W", "shape"), True),
    (f"e = w.SimounObservation({IMAGE_HW1}, source='observation', size=16); " + STEP, ""),
    ("w.FrameTriplet(gym.make('MiniGrid-Empty-5x5-v0'))", "Box"),
    ("e = w.ActionRepeat(gym.make('Blackjack-v1'), 2); " + STEP, ""),
    (f"e = w.ConstantBonusReward(w.SimounObservation({BJ}, size=16), 0.1); " + STEP, ""),
    (f"w.check_sb3_policy(w.SimounObservation({BJ}, size=40, fold_frames=True), 'CnnPolicy')", ""),
    ("w.check_sb3_policy(gym.spaces.Tuple((gym.spaces.Discrete(2), gym.spaces.Discrete(3))), "
     "'MlpPolicy')", "Tuple"),
    ("w.check_sb3_policy(gym.spaces.MultiBinary(4), 'MlpPolicy')", ""),
    # vector envs of one env
    (f"v = w.ConstantBonusVectorReward({vec1()}, 0.1); " + STEPS3, ""),
    (NOV + f"v = w.RNDVectorReward({vec1('CartPole-v1')}, nov, warmup=0); " + STEPS3, ""),
    (FEAT + f"v = w.ConsistencyCuriosityVectorReward({vec1('CartPole-v1')}, feat); " + STEPS3, ""),
    (f"w.check_sb3_policy({vec1(wrap='w.SimounObservation(e, size=40, fold_frames=True)')}, "
     "'CnnPolicy')", ""),
    (f"v = w.ConstantBonusVectorReward({vec1(mode='async')}, 0.1); " + STEPS3 + "; v.close()", ""),
    (f"w.ConstantBonusReward({vec1()}, 0.1)", ("Vector", "ConstantBonusVectorReward")),
    (RND + f"m = RNDModel.for_env({vec1(wrap='w.SimounObservation(e, size=64)')}); m.close()", ""),
    # close twice; step or reset after close
    *((f"e = {made}; e.reset(seed=0); e.close(); e.close()" if "; " not in made else
       f"{made.rpartition('; ')[0]}; e = {made.rpartition('; ')[2]}; e.reset(seed=0); e.close(); "
       "e.close()", "") for made in CLOSED),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.close(); e.close()", ""),
    (f"v = w.ConstantBonusVectorReward({vec('NEXT_STEP')}, 0.1); v.reset(seed=0); v.close(); "
     "v.close()", ""),
    (f"e = w.ConstantBonusReward({S}, 0.1); e.reset(seed=0); e.close(); "
     "e.step(e.action_space.sample())", "close", True),
    (RND + f"m = RNDModel.for_env({S64}); e = w.RNDReward({S64}, m, warmup=0); e.reset(seed=0); "
     "e.step(e.action_space.sample()); m.close(); [e.step(e.action_space.sample()) for _ in "
     "range(3)]", "close", True),
    (DMC + "e = w.ColorShift(d, seed=0); e.reset(seed=0); e.close(); e.reset(seed=1)", "close",
     True),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.close(); "
     "e.step({a: e.action_space(a).sample() for a in e.agents})", "close", True),
    (f"v = w.ConstantBonusVectorReward({vec('SAME_STEP')}, 0.1); v.reset(seed=0); v.close(); "
     "v.step(v.action_space.sample())", "close", True),
    # the agent's API: odd batches and dtypes
    (AGENT + f"{A}.act({FRAMES}, deterministic='no')", "deterministic"),
    (AGENT + f"{A}.act({FRAMES}, deterministic=None)", "deterministic"),
    (AGENT + f"{A}.act({FRAMES}, step=-1)", "step"),
    (AGENT + f"{A}.act({FRAMES}, step='a')", "step"),
    (AGENT + f"{A}.act({FRAMES}, step=1.5)", "step"),
    (AGENT + f"import torch; {A}.act(torch.zeros((3, 3, 32, 32), dtype=torch.uint8))", ""),
    (AGENT + f"{A}.act(np.zeros((1, 3, 3, 32, 32), np.uint8))", "frames"),
    (AGENT + f"{A}.act(np.zeros((32, 32, 3, 3), np.uint8).transpose(2, 3, 0, 1))", ""),
    (AGENT + f"{A}.act(np.zeros((3, 3, 32, 32), np.int64))", "uint8"),
    (AGENT + f"{A}.act({FRAMES}.tolist())", ("uint8", "frames")),
    (AGENT + f"{A}.act({FRAMES}, True, None)", ""),
    (AGENT + f"{A}.encoder_features({FRAMES})", ("(B,", "triplets", "frames")),
    (AGENT + f"{A}.encoder_features(np.zeros((0, 3, 3, 32, 32), np.uint8))", ""),
    (AGENT + f"{A}.encoder_features(np.zeros((2, 3, 3, 32, 32), np.float32))", "uint8"),
    (AGENT + f"{A}.update(None, 0)", "replay"),
    (AGENT + FILLED + f"{A}.update(r, -1)", "step"),
    (AGENT + FILLED + f"{A}.update(r, 'a')", "step"),
    (AGENT + FILLED + f"{A}.update(r, 9)", ""),
    (AGENT + ADD.format(f"np.zeros(1), 0.0, {FRAME}, 'no', False"), "terminated"),
    (AGENT + ADD.format(f"np.zeros(1), float('inf'), {FRAME}, False, False"), "reward"),
    (AGENT + ADD.format(f"np.zeros(1, np.int64), 0.0, {FRAME}, False, False"), ""),
    (AGENT + ADD.format(f"[0.5], np.float32(1), {FRAME}, False, False"), ""),
    (AGENT + ADD.format(f"np.array([np.nan]), 0.0, {FRAME}, False, False"), "action"),
    (AGENT + ADD.format("np.zeros(1), 0.0, np.zeros((3, 16, 16), np.uint8), False, False"),
     ("(3, 32, 32)", "frame")),
    (AGENT + FILLED + "r.sample(0)", "batch_size"),
    (AGENT + FILLED + "r.sample(-1)", "batch_size"),
    (AGENT + FILLED + "r.sample(1.5)", "batch_size"),
    (AGENT + "FrameReplay(100, (3, 32, 32), 1).sample(4)",
     ("empty", "start_episode", "add", "holds 0")),
    (AGENT + FILLED + "r.save('nowhere/x.npz')", "nowhere"),
    (AGENT + "FrameReplay.load('nope.npz')", "nope.npz"),
    (AGENT + "open('x.npz', 'w').write('not a replay'); FrameReplay.load('x.npz')", "x.npz"),
    (AGENT + f"{A}.load_state_dict({{}})", "state"),
    (AGENT + "import dataclasses; b = SimounAgent((3, 32, 32), 1, dataclasses.replace(cfg, "
     f"feature_dim=16), device='cpu'); {A}.load_state_dict(b.state_dict())",
     ("feature_dim", "state", "shape")),
    (AGENT + "AgentConfig(batch_size=10**30)", "batch_size"),
    (AGENT + "AgentConfig(lr=float('inf'))", "lr"),
    (AGENT + "AgentConfig(recipe='curll')", "recipe"),
    (AGENT + "AgentConfig(actor='deterministicc')", "actor"),
    (AGENT + "AgentConfig(conv_init='xavier')", "conv_init"),
    (AGENT + "AgentConfig(critic_augmentations=2)", ("critic_augmentations", "augmentation")),
    # renders, online models and PointReach: kinds other changes fix
    (f"w.MultiCamera({P}, cameras=[lambda e: [[0, 0, 0]]], size=16).reset(seed=0)", "camera"),
    (f"w.MultiCamera({P}, cameras=[lambda e: np.zeros((0, 4, 3), np.uint8)], size=16)"
     ".reset(seed=0)", "camera"),
    ("import itertools; c = itertools.count(); e = w.MultiCamera("
     f"{P}, cameras=[lambda e: np.zeros((8 + next(c), 8, 3), np.uint8)], size=None); " + STEP,
     "camera"),
    (RENDER_AS.format("None") + f"w.SimounObservation(R({P}), size=16).reset(seed=0)", "render"),
    (RENDER_AS.format("[[0, 0, 0]]") + f"w.SimounObservation(R({P}), size=16).reset(seed=0)",
     "render"),
    (RND + f"m = RNDModel.for_env({S64}); m(np.zeros((2, 3, 3, 16, 16), np.uint8))", "frame"),
    (CUR + "m = CuriosityModel((3, 32, 32), gym.spaces.Box(-1, 1, (2,))); z = np.zeros((4, 3, 3, "
     "32, 32), np.uint8); m.watch(z, np.zeros((4, 5)), z, np.zeros(4, bool), np.zeros(4, bool))",
     "action"),
    (POINT.format("size=0"), "size"),
    (POINT.format("max_steps=0"), "max_steps"),
    (POINT.format("step_size=float('nan')"), "step_size"),
    (POINT.format("size='32'"), "size"),
    # wrappers and functions given odd values
    (f"w.ColorShift({M})", "dm_control"),
    (f"w.MultiCamera({P}, cameras=(c for c in [0]))", "cameras"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8, dtype=torch.float64))", ""),
    ("import torch; w.random_conv(torch.zeros(2, 1, 8, 8))", ""),
    ("import torch; w.random_conv(torch.zeros(1, 2, 3, 8, 8))", "", True),
    ("w.residual_motion(np.zeros((3, 1, 0, 0), np.uint8))", "frames", True),
    (f"w.SimounObservation({P}, size=16).reset(seed=0, options={{'x': 1}})", ""),
]  # fmt: skip
THIRD_API_CASES = [
    api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in THIRD_CODES
]
THIRD_COMMAND_CASES = THIRD_FLAG_CASES + THIRD_FILE_CASES + THIRD_SPEC_CASES
for _case in THIRD_COMMAND_CASES + THIRD_API_CASES:
    _case["set"] = "third"


# the fourth trial's cases, run alone with --set fourth: flags in combination, environment
# variables, device forms, paths users type, runs damaged in new ways, spec values at their
# boundaries and the API's arguments at theirs


def environ(**values: str):
    """A setup that sets environment variables in the case's process only."""
    return call(lambda here: os.environ.update(values))


SHORT_TINY = tiny(*SHORT)
# agent fields at a bad value through their flag: (flag, value, the config key)
AGENT_FLAG_VALUES = [
    ("--agent.critic-tau", "0", "critic_tau"), ("--agent.critic-tau", "1.5", "critic_tau"),
    ("--agent.encoder-tau", "-0.1", "encoder_tau"), ("--agent.alpha-lr", "0", "alpha_lr"),
    ("--agent.actor-update-every", "0", "actor_update_every"),
    ("--agent.target-update-every", "-2", "target_update_every"),
    ("--agent.update-every-steps", "0", "update_every_steps"),
    ("--agent.exploration-std-start", "-1", "exploration_std_start"),
    ("--agent.exploration-steps", "0", "exploration_steps"),
    ("--agent.noise-clip", "-0.3", "noise_clip"),
    ("--agent.init-temperature", "0", "init_temperature"),
    ("--agent.log-std-min", "nan", "log_std_min"), ("--agent.log-std-max", "inf", "log_std_max"),
    ("--agent.curiosity-scale", "-0.2", "curiosity_scale"),
    ("--agent.curiosity-decay", "nan", "curiosity_decay"),
    ("--agent.r-e-max-init", "0", "r_e_max_init"), ("--agent.r-i-max-init", "-1", "r_i_max_init"),
    ("--agent.transition-weight", "-1", "transition_weight"),
    ("--agent.contrastive-weight", "inf", "contrastive_weight"),
    ("--agent.reward-weight", "nan", "reward_weight"), ("--agent.num-frames", "0", "num_frames"),
    ("--agent.reduce-kernel", "0", "reduce_kernel"),
    ("--agent.reduce-stride", "-3", "reduce_stride"),
    ("--agent.random-conv-kernel", "4", "random_conv_kernel"),
    ("--agent.shift-pad", "-4", "shift_pad"),
    ("--agent.critic-augmentations", "0", "critic_augmentations"),
    ("--agent.target-augmentations", "0", "target_augmentations"),
    ("--agent.next-state-encoder", "online-ish", "next_state_encoder"),
    ("--agent.contrastive-view", "shiftt", "contrastive_view"),
    ("--agent.similarity-init", "random", "similarity_init"),
    ("--agent.encoder", "resnet", "encoder"), ("--agent.pixel-offset", "nan", "pixel_offset"),
    ("--agent.feature-dim", "0", "feature_dim"), ("--agent.num-filters", "0", "num_filters"),
    ("--agent.hidden-dim", "-16", "hidden_dim"), ("--agent.aux-hidden-dim", "0", "aux_hidden_dim"),
    ("--agent.alpha-beta", "inf", "alpha_beta"), ("--agent.actor", "tanh", "actor"),
    ("--warmup-agent-steps", "-1", "warmup_agent_steps"),
    ("--updates-per-step", "0", "updates_per_step"),
    ("--replay-capacity", "0", "replay_capacity"), ("--cameras", "0", "cameras"),
]  # fmt: skip
# a run resumed with a flag it may not change: (the flag and its value, what the refusal names)
RESUME_FIXED = [
    (["--image-size", "48"], "image_size"),
    (["--grayscale"], "grayscale"),
    (["--cameras", "2"], "cameras"),
    (["--action-repeat", "2"], "action_repeat"),
    (["--env-kwargs", '{"size": 32}'], "env_kwargs"),
    (["--agent.recipe", "drq"], "recipe"),
    (["--warmup-agent-steps", "5"], "warmup_agent_steps"),
    (["--replay-capacity", "100"], "replay_capacity"),
    (["--agent.batch-size", "4"], "batch_size"),
    (["--set", "agent.n_step=3"], "n_step"),
    (["--env-module", "minigrid"], "env_module"),
    (["--updates-per-step", "2"], "updates_per_step"),
    (["--run-dir", "elsewhere"], "run"),
    (["--agent.no-curiosity"], "curiosity"),
    (["--eval-episodes", "2"], "eval_episodes"),
]
RESUME_ALLOWED = [  # every flag --resume may change, each given with the new total
    ["--eval-every", "20"],
    ["--checkpoint-every", "20"],
    ["--no-progress"],
    ["--no-video"],
    ["--torch-threads", "1"],
    ["--progress"],
    ["--no-env-process"],
]
# flags that conflict or make no sense together: (command, argv, names[, valid])
COMBOS = [
    ("train", tiny("--agent.log-std-min", "3", "--agent.log-std-max", "2"), ("log_std", "log-std")),
    ("train", tiny("--agent.exploration-std-start", "0.1", "--agent.exploration-std-end", "1.0",
                   *SHORT), "exploration_std", True),
    ("train", tiny("--eval-every", "30", "--total-env-steps", "20", "--run-dir", "r"),
     ("eval_every", "total_env_steps"), True),
    ("train", tiny("--checkpoint-every", "1000", *SHORT), "checkpoint_every", True),
    ("train", tiny("--agent.batch-size", "64", "--agent.replay-capacity", "16"),
     ("batch_size", "replay")),
    ("train", tiny("--replay-capacity", "16", "--agent.batch-size", "64"),
     ("batch_size", "replay_capacity", "--agent.batch-size", "--replay-capacity")),
    ("train", tiny("--agent.recipe", "drqv2", "--agent.actor", "gaussian", *SHORT), "actor", True),
    ("train", tiny("--agent.recipe", "simoun_no_curiosity", "--agent.curiosity", *SHORT),
     "curiosity", True),
    ("train", tiny("--agent.augmentation", "none", "--agent.shift-pad", "4", *SHORT),
     "shift_pad", True),
    ("train", tiny("--agent.num-frames", "1", "--agent.encoder", "dual_interactive"),
     ("num_frames", "encoder")),
    ("train", tiny("--grayscale", "--agent.recipe", "curl", *SHORT), "grayscale", True),
    ("train", tiny("--image-size", "33", *SHORT), "image_size", True),
    ("train", tiny("--cameras", "3", *SHORT), "cameras", True),
    ("train", tiny("--set", "agent.lr=1e-3", "--agent.lr", "2e-3", *SHORT), "agent.lr", True),
    ("train", tiny("--set", "seed=2", "--set", "seed=3", *SHORT), "seed", True),
    ("train", tiny("--env-module", "minigrid", "--env", "simoun/PointReach-v0", *SHORT),
     "env_module", True),
    ("train", tiny("--overwrite", *SHORT), "--overwrite", True),
    ("train", tiny("--overwrite", "--run-dir", "{run}"), ("--overwrite", "checkpoint", "--resume")),
    ("train", tiny("--eval-distraction", "color_easy"), ("color_easy", "dm_control")),
    ("train", tiny("--env-process", *SHORT), "env_process", True),
    ("train", tiny("--action-repeat", "none", *SHORT), "", True),
    ("train", tiny("--agent.shift-pad", "none", *SHORT), "", True),
    ("train", tiny("--preset", "cheetah-run", *SHORT), ("preset", "cheetah"), True),
    ("train", tiny("--preset", "highway-cpu", *SHORT), ("preset", "highway"), True),
    ("train", tiny("--preset", "walker-walk", "--env", "Pendulum-v1", *SHORT),
     ("preset", "walker"), True),
    ("train", ["--preset", "cpu", "--env", "MiniGrid-Empty-5x5-v0", "--env-module", "minigrid"],
     "MiniGrid"),
    ("eval", eval_argv("--videos", "somewhere"), ("--videos", "--distraction")),
    ("eval", eval_argv("--distraction", "color_easy,color_easy"), ("color_easy", "dm_control")),
    ("eval", eval_argv("--distraction", ""), "--distraction"),
    ("eval", eval_argv("--random-policy", "--episodes", "1"), "", True),
    ("eval", eval_argv("--episodes", "1", "--out", "{run}", "--overwrite"), "--out", True),
    ("eval", eval_argv("--seed", str(2**32), "--episodes", "1"), "seed", True),
    ("report", report_argv("--at-wall-time", "nan"), "--at-wall-time"),
    ("report", report_argv("--at-wall-time", "inf"), "--at-wall-time"),
    ("report", report_argv("--at-step", "20", "--out", "{run}/eval.csv"), "--out"),
    ("sweep", sweep_tiny("--grid", "seed=1,2", "--seeds", "0-1"), "seed"),
    ("sweep", sweep_tiny("--grid", "run_dir=a,b"), "run_dir"),
    ("sweep", sweep_tiny("--grid", "total_env_steps=40,60", "--grid", "total_env_steps=80"),
     "total_env_steps"),
    ("sweep", sweep_tiny("--grid", "env=Pendulum-v1,Acrobot-v1"), ("env", "--envs")),
    ("sweep", sweep_tiny("--cpus-per-trial", "2", "--num-cpus", "1"),
     ("--cpus-per-trial", "--num-cpus")),
    ("sweep", sweep_tiny("--address", "auto", "--num-cpus", "2"), ("--address", "--num-cpus")),
    ("sweep", ["--resume", "--sweep-dir", "nowhere", "--grid", "agent.lr=1,2"],
     ("--grid", "--resume", "nowhere")),
    ("sweep", sweep_tiny("--grid", "agent.n_step=1,3", "--sweep-dir", "{run}/tb"), "--sweep-dir"),
    ("sweep", sweep_tiny("--gpus-per-trial", "1", "--device", "cpu"),
     ("--gpus-per-trial", "GPU")),
    ("minigrid", probe("--probes", "rnd", "rnd"), ("rnd", "--probes")),
    ("minigrid", probe("--settings.seed", "-1"), ("seed", "--settings.seed")),
    ("minigrid", probe("--settings.n-envs", "2.5"), ("n-envs", "n_envs")),
    ("minigrid", probe("--out", "{run}/config.json"), "--out"),
    ("minigrid", ["run", "--archive", "/proc/nope", "--concurrent", "1"], ("/proc/nope",
                                                                           "--archive")),
    ("driving", driving("--json", "/proc/x.json"), "--json"),
    ("driving", driving("--json", "."), "--json"),
    ("driving", driving("--seed", str(2**64)), "--seed"),
    ("driving", driving("--video", "v.gif", "--json", "v.gif"), ("--video", "--json")),
]  # fmt: skip
WRONG_SUBCOMMAND = [  # a flag given to a command or subcommand it belongs to another
    ("analyze", masks("--pairs", "8"), "--pairs"), ("analyze", bias("--query", "1,2"), "--query"),
    ("analyze", bias("--steps", "1"), "--steps"), ("analyze", masks("--recolour", "conv"),
                                                   "--recolour"),
    ("analyze", bias("--video", "gif"), "--video"),
    ("study", plan("--study-dir", "s"), "--study-dir"), ("study", plan("--archive", "a"),
                                                         "--archive"),
    ("study", plan("--num-cpus", "1"), "--num-cpus"),
    ("minigrid", ["report", "--archive", ".", "--concurrent", "2"], "--concurrent"),
    ("minigrid", probe("--archive", "."), "--archive"),
    ("minigrid", ["select", "--archive", ".", "--probes", "rnd"], "--probes"),
    ("minigrid", ["report", "--archive", ".", "--settings.steps", "5"], "--settings.steps"),
    ("eval", eval_argv("--pairs", "8"), "--pairs"), ("eval", eval_argv("--at-step", "20"),
                                                      "--at-step"),
    ("eval", eval_argv("--agent.lr", "0.1"), "--agent.lr"), ("eval", eval_argv("--preset", "cpu"),
                                                             "--preset"),
    ("report", report_argv("--episodes", "1"), "--episodes"),
    ("report", report_argv("--device", "cpu"), "--device"),
    ("train", tiny("--episodes", "1"), "--episodes"), ("train", tiny("--grid", "agent.lr=1,2"),
                                                        "--grid"),
    ("train", tiny("--sweep-dir", "s"), "--sweep-dir"), ("driving", driving("--device", "cpu"),
                                                         "--device"),
    ("driving", driving("--env", "highway-v0"), "--env"),
    ("sweep", sweep_tiny("--resume-from", "x"), "--resume"),
    ("sweep", sweep_tiny("--episodes", "2"), "--episodes"),
]  # fmt: skip
DEVICES = [  # (command, argv builder) x device forms a user types
    ("train", tiny),
    ("eval", eval_argv),
    ("analyze", masks),
]
DEVICE_FORMS = [  # (value, what the refusal names[, valid])
    ("cuda:0", ("cuda", "device")),
    ("mps", ("mps", "device")),
    ("cpu:1", "device", True),
    ("cuda:-1", ("cuda", "device")),
    ("gpu", ("gpu", "device")),
    ("meta", ("meta", "device")),
]
SET_TYPES = [  # --set of every config section with a wrong type: (text, names[, valid])
    ("env_kwargs=3", "env_kwargs"),
    ("agent.curiosity=maybe", "curiosity"),
    ("video=2", "video"),
    ("device=3", "device"),
    ("action_repeat=none", "", True),
    ("total_env_steps=1e5", "total_env_steps"),
    ("agent.lr=1e-3e", "agent.lr"),
    ("eval_distraction=[]", "", True),
    ("agent.shift_pad=none", "", True),
    ("progress=yes", "progress"),
    ("agent.actor=null", "actor"),
    ("image_size=-1", "image_size"),
    ("cameras=1.5", "cameras"),
    ("agent.n_step=[1,3]", "n_step"),
    ('agent={"lr": 1}', "agent"),
    ("grayscale=1", "grayscale", True),
    ("env_module=", "env_module", True),
    ("run_dir=none", "", True),
    ("agent.recipe=none", "", True),
    ("torch_threads=-1", "torch_threads"),
]
ENV_VARS = [  # environment variables users set: (command, argv, variables, names[, valid])
    ("train", tiny(*SHORT), {"OMP_NUM_THREADS": "0"}, "OMP_NUM_THREADS", True),
    ("train", tiny(*SHORT), {"OMP_NUM_THREADS": "abc"}, "OMP_NUM_THREADS", True),
    ("train", tiny("--device", "cuda"), {"CUDA_VISIBLE_DEVICES": ""}, ("cuda", "device")),
    (
        "train",
        tiny(*SHORT, "--env", "dm_control/cartpole-swingup-v0"),
        {"MUJOCO_GL": "bogus"},
        "MUJOCO_GL",
        True,
    ),
    ("eval", eval_argv("--episodes", "1"), {"MUJOCO_GL": "bogus"}, "MUJOCO_GL", True),
    (
        "train",
        tiny(*SHORT),
        {"PYTORCH_ENABLE_MPS_FALLBACK": "1", "CUDA_VISIBLE_DEVICES": "-1"},
        "",
        True,
    ),
    (
        "sweep",
        sweep_tiny("--sweep-dir", "s"),
        {"RAY_ADDRESS": "nohost:1"},
        ("RAY_ADDRESS", "nohost"),
    ),
    (
        "train",
        tiny("--run-dir", "$HOME/runs/x", "--total-env-steps", "40"),
        {},
        ("$HOME", "--run-dir"),
        True,
    ),
    (
        "train",
        tiny("--run-dir", "~/runs/x", "--total-env-steps", "40"),
        {"HOME": "/proc"},
        ("~", "--run-dir", "/proc"),
        True,
    ),
    ("eval", ["~/no-such-run", *EVAL], {}, ("~/no-such-run", "no-such-run")),
    ("report", ["~/no-such-run"], {}, ("~/no-such-run", "no-such-run")),
]
PATHS = [  # paths users type: (command, argv, names[, valid])
    ("train", tiny("--run-dir", "a\nb", "--total-env-steps", "40"), "--run-dir", True),
    ("train", tiny("--run-dir", 'it\'s "quoted"', "--total-env-steps", "40"), "", True),
    (
        "train",
        tiny("--run-dir", "{run}/sub", "--total-env-steps", "40"),
        ("--run-dir", "run"),
        True,
    ),
    ("train", tiny("--run-dir", "{run}/tb", "--total-env-steps", "40"), ("--run-dir", "tb"), True),
    ("train", tiny("--run-dir", "./r/../r2/", "--total-env-steps", "40"), "", True),
    ("train", tiny("--run-dir", "-r", "--total-env-steps", "40"), "--run-dir", True),
    ("train", tiny("--run-dir", "/dev/null", "--total-env-steps", "40"), "--run-dir"),
    ("train", tiny("--run-dir", ".", "--total-env-steps", "40"), ("--run-dir", "."), True),
    ("eval", ["{run}/", *EVAL, "--episodes", "1"], "", True),
    ("eval", ["{run}/./tb/..", *EVAL, "--episodes", "1"], "", True),
    ("eval", eval_argv("--episodes", "1", "--out", "o\nut"), "--out", True),
    ("eval", eval_argv("--episodes", "1", "--out", "/dev/null"), "--out"),
    ("report", ["{run}", "--out", "{run}/tb"], "--out", True),
    ("report", ["{run}", "--out", "-"], "--out", True),
    ("analyze", masks("--steps", "1", "--out", "/dev/null"), "--out"),
    ("study", ["run", "spec.toml", "--study-dir", "{run}"], ("--study-dir", "run")),
    ("minigrid", ["report", "--archive", "{run}/tb"], ("--archive", "tb", "spec.json")),
    ("sweep", sweep_tiny("--sweep-dir", "/dev/null"), "--sweep-dir"),
]
FOURTH_FLAG_CASES = [
    *(cli("flags", "train", tiny(flag, value), (flag, key)) for flag, value, key in
      AGENT_FLAG_VALUES),
    *(cli("flags", "train", ["--resume", "{run}", "--total-env-steps", "60", *flags],
          (names, flags[0])) for flags, names in RESUME_FIXED),
    *(cli("flags", "train", ["--resume", "{run}", "--total-env-steps", "60", *flags], "", ok=True)
      for flags in RESUME_ALLOWED),
    *(cli("flags", command, argv, names, ok=bool(ok)) for command, argv, names, *ok in COMBOS),
    *(cli("flags", command, argv, names) for command, argv, names in WRONG_SUBCOMMAND),
    *(cli("flags", command, build("--device", value), names, ok=bool(ok))
      for command, build in DEVICES for value, names, *ok in DEVICE_FORMS),
    *(cli("flags", "train", tiny("--set", text, *(SHORT if ok else ())), names or "",
          ok=bool(ok)) for text, names, *ok in SET_TYPES),
    *({**cli("flags", command, argv, names, ok=bool(ok), setup=environ(**variables)),
       "what": " ".join(f"{key}={value}" for key, value in variables.items()) or "no variable"}
      for command, argv, variables, names, *ok in ENV_VARS),
    *(cli("flags", command, argv, names, ok=bool(ok)) for command, argv, names, *ok in PATHS),
]  # fmt: skip


def fifo(path: Path) -> None:
    path.unlink()
    os.mkfifo(path)


def checkpoint_edit(change):
    """A damage that loads the checkpoint, changes its payload and saves it back."""

    def edit(path: Path) -> None:
        import torch

        payload = torch.load(path, weights_only=False)
        change(payload)
        torch.save(payload, path)

    return edit


def replay_edit(change):
    """A damage that rewrites the replay's arrays through ``change`` (a dict, in place)."""

    def edit(path: Path) -> None:
        with np.load(path, allow_pickle=False) as data:
            arrays = dict(data)
        change(arrays)
        with open(path, "wb") as f:
            np.savez(f, **arrays)

    return edit


def copy_replay(path: Path) -> None:
    shutil.copy(path, path.with_name("replay-20.npz"))


def cut_mid_row(path: Path) -> None:
    data = path.read_bytes().rstrip(b"\n")
    path.write_bytes(data[: data.rfind(b",") + 1])


FOURTH_DAMAGES = {
    "eval.csv": {
        "rows past total_env_steps": csv_rows(lambda rows: [*rows, ["100000", *rows[-1][1:]]]),
        "truncated mid-row": cut_mid_row,
        "a FIFO": fifo,
        "only the header of another run's columns": edit_text(lambda text: "step,score\n"),
        "a row of empty cells": csv_rows(lambda rows: [*rows, [""] * len(rows[0])]),
    },
    "train.csv": {
        "truncated mid-row": cut_mid_row,
        "a directory": into_directory,
        "rows past total_env_steps": csv_rows(lambda rows: [*rows, ["100000", *rows[-1][1:]]]),
    },
    "summary.json": {
        "steps the logs do not have": edit_json(lambda data: data.update(env_step=100000)),
        "a negative step": edit_json(lambda data: data.update(env_step=-40)),
        "a JSON string": write_bytes(lambda data: b'"done"'),
    },
    "config.json": {
        "another run's image size": edit_json(lambda data: data.update(image_size=48)),
        "another run's network": edit_json(lambda data: data["agent"].update(num_filters=8)),
        "a total below the checkpoint's step": edit_json(
            lambda data: data.update(total_env_steps=20)),
        "a FIFO": fifo,
        "a null seed": edit_json(lambda data: data.update(seed=None)),
    },
    "checkpoint.pt": {
        "an older format (rng missing)": checkpoint_edit(lambda p: p.pop("rng")),
        "an older format (format missing)": checkpoint_edit(lambda p: p.pop("format")),
        "a format from the future": checkpoint_edit(lambda p: p.update(format=999)),
        "the agent missing": checkpoint_edit(lambda p: p.pop("agent")),
        "another step in its state": checkpoint_edit(lambda p: p["state"].update(env_step=20)),
        "a replay file named that is not there": checkpoint_edit(
            lambda p: p.update(replay_file="replay-99.npz")),
        "an empty dict": checkpoint_edit(lambda p: p.clear()),
        "a symlink to config.json": symlink_to("config.json"),
    },
    "replay": {
        "an array missing": replay_edit(lambda a: a.pop(sorted(a)[0])),
        "a directory": into_directory,
        "a second replay file beside it": copy_replay,
    },
}  # fmt: skip
FOURTH_FILE_CASES = [
    {
        **cli(
            "files",
            command,
            argv,
            (name, "replay") if "replay" in way else name,
            ok=True,
            setup=(name, how),
        ),
        "what": f"{name} {way}",
    }
    for name, ways in FOURTH_DAMAGES.items()
    for way, how in ways.items()
    for command, argv in FILE_COMMANDS.items()
]

FOURTH_SPEC_EDITS = [  # (text replaced, by, what the refusal names[, valid])
    ("eval_every = 10_000", "eval_every = 0", "eval_every"),
    ("eval_every = 10_000", "eval_every = 1", "eval_every", True),
    ("eval_episodes = 10", "eval_episodes = 1", "", True),
    ("eval_episodes = 10", "eval_episodes = 2.5", "eval_episodes"),
    ("eval_episodes = 10", "eval_episodes = true", "eval_episodes"),
    ("video = false", "video = 1", "video"),
    ('preset = "cpu"', 'preset = "highway-cpu"', ("preset", "highway"), True),
    ('preset = "cpu"', "preset = 3", "preset"),
    ('seeds = "101-102"', 'seeds = "101-101"', "", True),
    ('seeds = "101-102"', "seeds = [101, 102]", "seeds", True),
    ('seeds = "101-102"', 'seeds = "0-0"', "seeds", True),
    ("env_steps = 50_000", "env_steps = 1", "env_steps", True),
    ("env_steps = 50_000", "env_steps = 50_000.5", "env_steps"),
    ("env_steps = 50_000", 'env_steps = "50000"', "env_steps"),
    ("env_steps = 100_000", "env_steps = 0", "env_steps"),
    ("env_steps = 100_000", "env_steps = 1e5", "env_steps"),
    ("env_steps = 100_000", "env_steps = 10_000", "env_steps", True),
    ("action_repeat = 8", "action_repeat = true", "action_repeat"),
    ("action_repeat = 8", 'action_repeat = "8"', "action_repeat"),
    ("action_repeat = 8", "action_repeat = 1", "", True),
    ("action_repeat = 4", "action_repeat = 1000", "action_repeat", True),
    ("cpus_per_trial = 1 ", "cpus_per_trial = 0.5 ", "cpus_per_trial", True),
    ("cpus_per_trial = 1 ", "cpus_per_trial = true ", "cpus_per_trial"),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 1.5", "max_concurrent_trials"),
    ("max_concurrent_trials = 2", "max_concurrent_trials = true", "max_concurrent_trials"),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 2\ngpus_per_trial = 0.5",
     "gpus_per_trial", True),
    ("max_concurrent_trials = 2", "max_concurrent_trials = 2\nnum_cpus = 0", "num_cpus"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nagent.lr = [0.0]", "lr"),
    ("agent.n_step = [1, 3]", 'agent.n_step = ["1", "3"]', "n_step"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nagent.discount = [1.5]", "discount"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nagent.batch_size = [true]", "batch_size"),
    ("agent.n_step = [1, 3]", 'agent.n_step = [1, 3]\nagent.recipe = ["drq"]', "recipe"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nagent.lr = [1e-3, 3e-4]", "agent.lr", True),
    ("agent.n_step = [1, 3]", 'agent.n_step = [1, 3]\nenv = ["Pendulum-v1"]', "env"),
    ("agent.n_step = [1, 3]", "agent.n_step = [1, 3]\nagent.lr = []", "lr"),
    ("agent.n_step = [1, 3]", "agent.n_step = [0, 3]", "n_step"),
    (RECIPES, 'recipes = ["simoun", "simoun_no_aux"]', "simoun_no_aux", True),
    (RECIPES, 'recipes = ["sac"]', "", True),
    (RECIPES, 'recipes = [""]', "recipes"),
    (RECIPES, 'recipes = ["simoun", "SAC"]', "SAC"),
    ('selection = "auc"', 'selection = "final"', "selection", True),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["simoun/PointReach-v0"]',
     "PointReach", True),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["highway-fast-v0"]', "highway", True),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["ALE/Pong-v5"]', "ALE"),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["CartPole-v1"]', "CartPole"),
    ('tasks = ["dm_control/cartpole-swingup-v0"]',
     'tasks = ["dm_control/cartpole-swingup-v0", "dm_control/cartpole-swingup-v0"]',
     "cartpole-swingup"),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["FrozenLake-v1"]', "FrozenLake"),
    ('tasks = ["dm_control/cartpole-swingup-v0"]', 'tasks = ["dm_control/walker-walk-v0"]',
     "walker", True),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-5"', '"1-1"'), "", True),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-5"', '"101-105"'), ("101", "seed")),
    (EVAL_SEEDS, EVAL_SEEDS.replace('"1-3"', '""'), ("seeds", "cheetah")),
]  # fmt: skip
FOURTH_MINIGRID_EDITS = [  # (a change to the spec's JSON value, what the refusal names[, valid])
    *((lambda s, arm=arm: s.update(arms=["ppo", arm]), names) for arm, names in (
        ("consistency,normalization=paperx,scale=0.01", "paperx"),
        ("consistency,scale=-1", "scale"), ("consistency,scale=nan", "scale"),
        ("consistency,scale=0.01,scale=0.02", "scale"), ("consistency,nope=1", "nope"),
        ("consistency,", "consistency,"), ("ppo,scale=0.1", "scale"),
        ("rnd,progress=2", "progress"), ("consistency,scale=", "scale"),
        ("consistency,scale=1e400", "scale"), ("Consistency", "Consistency"),
        ("rnd,normalization=", "normalization"), ("consistency,progress=-0.5", "progress"),
        ("consistency,normalization=standardize,scale=0.01,", "consistency"),
        ("consistency, scale=0.01", "scale"), ("rnd,scale=true", "scale"),
    )),
    (lambda s: s.update(arms=["ppo", "consistency,normalization=raw"]), "", True),
    (lambda s: s.update(arms=["ppo", "consistency,scale=0.01,normalization=standardize",
                              "consistency,normalization=standardize,scale=0.01"]), "arms"),
    (lambda s: s["ppo"].update(n_steps=1), "n_steps", True),
    (lambda s: s["ppo"].update(n_epochs=0), "n_epochs"),
    (lambda s: s["ppo"].update(clip_range=0), "clip_range", True),
    (lambda s: s["ppo"].update(ent_coef=-1), "ent_coef"),
    (lambda s: s["ppo"].update(gae_lambda=1.5), "gae_lambda"),
    (lambda s: s["ppo"].update(batch_size=0), "batch_size"),
    (lambda s: s["ppo"].update(learning_rate=0), "learning_rate"),
    (lambda s: s["ppo"].update(n_envs=1.5), "n_envs"),
    (lambda s: s["ppo"].update(n_envs=True), "n_envs"),
    (lambda s: s.update(evaluations=True), "evaluations"),
    (lambda s: s.update(eval_episodes="32"), "eval_episodes"),
    (lambda s: s["tasks"][0].update(seeds=[True]), "seeds"),
    (lambda s: s["tasks"][0].update(steps=0), "steps"),
    (lambda s: s["tasks"][0].update(env_id="MiniGrid-Empty-5x5-v0"), "", True),
    (lambda s: s.update(device="cuda:0"), ("device", "cuda"), True),
    (lambda s: s.pop("ppo"), "ppo", True),
    (lambda s: s["tasks"].append(s["tasks"][0]), ("DoorKey-6x6", "tasks")),
]  # fmt: skip
for _old, _new, *_ in FOURTH_SPEC_EDITS:
    assert _old in SPEC, _old


def spec_change(change) -> str:
    """What ``change`` does to the MiniGrid spec, for the table: each top-level key it changes."""
    old, new = json.loads(MINIGRID_SPEC), json.loads(minigrid_spec(change))
    return "; ".join(
        f"{key}={json.dumps(new[key])}" if key in new else f"no {key}"
        for key in sorted(old.keys() | new.keys())
        if old.get(key) != new.get(key)
    )


FOURTH_SPEC_CASES = [
    *({**spec_case(SPEC.replace(old, new, 1), names, ok=bool(ok)), "what": new}
      for old, new, names, *ok in FOURTH_SPEC_EDITS),
    *({**minigrid_spec_case(1 if ok else i, minigrid_spec(change), names, ok=bool(ok)),
       "what": spec_change(change)}
      for i, (change, names, *ok) in enumerate(FOURTH_MINIGRID_EDITS)),
]  # fmt: skip

TS = f"w.SimounObservation({M}, size=16)"  # triplets of a discrete-action env
FOURTH_REFUSED = [  # (code with one {}, the name the refusal must give, the values)
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, normalization={{}})", "normalization",
     "'Paper'", "''", "None", "3", "'paper '"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, scale={{}})", "scale",
     "-1", "True", "np.float32('nan')", "'0.2'", "float('inf')"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, progress={{}})", "progress",
     "-1", "float('nan')", "'half'"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, warmup={{}})", "warmup", "-1", "2.5"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, decay={{}})", "decay",
     "float('nan')", "'0'"),
    (NOV + f"w.RNDReward({S}, nov, decay={{}})", "decay", "-0.1", "float('inf')"),
    (NOV + f"w.RNDReward({S}, nov, scale={{}})", "scale", "float('inf')", "np.float64('nan')"),
    (NOV + f"w.RNDReward({S}, nov, progress={{}})", "progress", "float('nan')", "-0.5"),
    (NOV + f"w.RNDReward({S}, nov, normalization={{}})", "normalization", "'Reward_Std'"),
    (f"w.SimounObservation({P}, {{}})", "grayscale", "grayscale='false'", "grayscale=0.0"),
    (f"w.SimounObservation({P}, {{}})", "fold_frames", "fold_frames=[True]", "fold_frames=None"),
    (f"w.SimounObservation({P}, {{}})", "motion", "motion=0", "motion='true'"),
    (f"w.SimounObservation({P}, size={{}})", "size", "(16, 16.0)", "(-16, 16)", "(16, 16, 16)",
     "'16x16'"),
    (f"w.FrameTriplet({P}, num_frames={{}})", "num_frames", "np.float64(3)", "[3]"),
    (f"w.RandomConvolution({P}, kernel_size={{}})", "kernel_size", "np.float32(3)", "[3]", "0"),
    (f"w.RandomConvolution({P}, source={{}})", "source", "None", "'Auto'"),
    (f"w.ActionRepeat({P}, {{}})", "repeat", "np.nan", "float('inf')", "-np.int64(2)"),
    (f"w.MultiCamera({P}, cameras=[lambda e: e.render()], size={{}})", "size",
     "(16,)", "(16, 0)", "1.5", "'16'"),
    (DMC + "w.ColorShift(d, {})", "level", "level=1", "level=''"),
    (DMC + "w.MovingBackground(d, {})", "level", "level=None", "level='Easy'"),
    (DMC + "w.MovingBackground(d, {})", "seed", "seed=1.5", "seed='0'"),
    (AGENT + "AgentConfig({})", "encoder", "encoder='resnet'"),
    (AGENT + "AgentConfig({})", "shift_pad", "shift_pad=-1", "shift_pad=2.5"),
    (AGENT + "AgentConfig({})", "critic_augmentations", "critic_augmentations=0"),
    (AGENT + "AgentConfig({})", "target_augmentations", "target_augmentations=-1"),
    (AGENT + "AgentConfig({})", "next_state_encoder", "next_state_encoder='x'"),
    (AGENT + "AgentConfig({})", "independent_next_shift", "independent_next_shift='yes'"),
    (AGENT + "AgentConfig({})", "separate_trunks", "separate_trunks=2"),
    (AGENT + "AgentConfig({})", "pixel_offset", "pixel_offset=float('nan')"),
    (AGENT + "AgentConfig({})", "contrastive_view", "contrastive_view='crop'"),
    (AGENT + "AgentConfig({})", "contrastive_step", "contrastive_step=None"),
    (AGENT + "AgentConfig({})", "similarity_init", "similarity_init='zeros'"),
    (AGENT + "AgentConfig({})", "num_filters", "num_filters='32'", "num_filters=0"),
    (AGENT + "AgentConfig({})", "hidden_dim", "hidden_dim=-1"),
    (AGENT + "AgentConfig({})", "aux_hidden_dim", "aux_hidden_dim=0"),
    (AGENT + "AgentConfig({})", "alpha_lr", "alpha_lr=0"),
    (AGENT + "AgentConfig({})", "discount", "discount=-0.1"),
    (AGENT + "AgentConfig({})", "n_step", "n_step=True"),
    (AGENT + "AgentConfig({})", "critic_tau", "critic_tau=0", "critic_tau=1.5"),
    (AGENT + "AgentConfig({})", "encoder_tau", "encoder_tau=-0.5"),
    (AGENT + "AgentConfig({})", "actor_update_every", "actor_update_every=0"),
    (AGENT + "AgentConfig({})", "exploration_std_start", "exploration_std_start=-1"),
    (AGENT + "AgentConfig({})", "exploration_steps", "exploration_steps=0"),
    (AGENT + "AgentConfig({})", "noise_clip", "noise_clip=float('nan')"),
    (AGENT + "AgentConfig({})", "init_temperature", "init_temperature=0"),
    (AGENT + "AgentConfig({})", "log_std_min", "log_std_min=float('inf')"),
    (AGENT + "AgentConfig({})", "curiosity_scale", "curiosity_scale=-1"),
    (AGENT + "AgentConfig({})", "r_e_max_init", "r_e_max_init=0"),
    (AGENT + "AgentConfig({})", "transition_weight", "transition_weight=float('nan')"),
    (AGENT + "AgentConfig({})", "num_frames", "num_frames=0"),
    (AGENT + "AgentConfig({})", "reduce_kernel", "reduce_kernel=0"),
    (AGENT + "AgentConfig({})", "reduce_stride", "reduce_stride=0"),
    (AGENT + "AgentConfig({})", "random_conv_kernel", "random_conv_kernel=2"),
    (AGENT + "AgentConfig({})", "detach_past_frames", "detach_past_frames=None"),
    (AGENT + "AgentConfig({})", "channels_last", "channels_last='x'"),
    (AGENT + "AgentConfig({})", "log_std", "log_std_min=3.0, log_std_max=2.0"),
]  # fmt: skip
STATE = "e.state_dict()"
FOURTH_CODES = [  # (code, the name the refusal must give, or "" for valid input[, valid])
    # wrapping twice, and in an order the docs do not show
    (NOV + f"e = w.RNDReward(w.RNDReward({S}, nov, warmup=0), nov, warmup=0); " + STEP, ""),
    (f"e = w.SimounObservation(w.ActionRepeat({P}, 2), size=16); " + STEP, ""),
    (f"e = w.ActionRepeat({S}, 2); " + STEP, "ActionRepeat"),
    (f"w.ConstantBonusReward({P}, 0.1)", ("triplet", "SimounObservation")),
    (NOV + f"w.RNDReward({P}, nov)", ("triplet", "SimounObservation")),
    (f"e = w.RandomConvolution(w.ConstantBonusReward({S}, 0.1)); " + STEP, "RandomConvolution"),
    (f"e = w.ResidualMotion(w.ConstantBonusReward({S}, 0.1)); " + STEP, "ResidualMotion"),
    (f"e = w.FrameTriplet(w.FrameTriplet({P})); " + STEP, ""),
    (f"w.ResidualMotion(w.ResidualMotion({S}))", ("ResidualMotion", "frame", "(k, C, H, W)"),
     True),
    (f"e = w.SimounObservation(w.ConstantBonusReward({S}, 0.1), size=16); " + STEP,
     "SimounObservation", True),
    (f"e = w.ConstantBonusReward({TS}, 0.1); e.reset(seed=0); e.step(2)", ""),
    # state_dict / load_state_dict round trips, good and bad
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat); {STEP}; "
     f"e.load_state_dict({STATE})", ""),
    (NOV + f"e = w.RNDReward({S}, nov, warmup=0); {STEP}; e.load_state_dict({STATE})", ""),
    (f"e = w.ConstantBonusReward({S}, 0.1); {STEP}; e.load_state_dict({STATE})", ""),
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat); e.load_state_dict({{}})", "state"),
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat); e.load_state_dict(None)", "state"),
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat); f = w.ConsistencyCuriosityReward("
     f"{S}, feat, normalization='standardize'); {STEP}; f.load_state_dict({STATE})",
     ("normalization", "paper", "standardize")),
    (NOV + f"e = w.RNDReward({S}, nov, warmup=0); {STEP}; s = {STATE}; "
     "s[next(iter(s))] = 'garbage'; e.load_state_dict(s)", "state"),
    (NOV + f"e = w.RNDReward({S}, nov, warmup=0); {STEP}; s = {STATE}; s['nope'] = 1; "
     "e.load_state_dict(s)", ("nope", "state"), True),
    (f"e = w.ConstantBonusReward({S}, 0.1); e.load_state_dict([1, 2])", "state"),
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat); {STEP}; "
     f"pickle.loads(pickle.dumps({STATE}))", ""),
    # rewards that are NaN or inf from the env, in every reward wrapper and mode
    (FEAT + f"e = w.ConsistencyCuriosityReward(w.SimounObservation({NAN}, size=16), feat, "
     "normalization='standardize'); " + STEP, "NaN"),
    (NOV + f"e = w.RNDReward(w.SimounObservation({INF}, size=16), nov, warmup=0, "
     "normalization='paper'); " + STEP, "inf"),
    (f"e = w.ConstantBonusReward(w.SimounObservation({INF}, size=16), 0.1); " + STEP, "inf"),
    (f"e = w.FrameTriplet({NAN}); " + STEP, ""),
    # the vector forms in both autoreset modes
    *((FEAT + f"v = w.ConsistencyCuriosityVectorReward({vec(mode, 'CartPole-v1')}, feat, "
       "normalization='paperx')", "paperx") for mode in ("NEXT_STEP", "SAME_STEP")),
    *((NOV + f"v = w.RNDVectorReward({vec(mode, 'CartPole-v1')}, nov, warmup=0, "
       "normalization='return_std'); " + STEPS3, "") for mode in ("NEXT_STEP", "SAME_STEP")),
    *((FEAT + f"v = w.ConsistencyCuriosityVectorReward({vec(mode, 'CartPole-v1')}, feat, "
       "progress=0.5); " + STEPS3 + "; [v.step(v.action_space.sample()) for _ in range(300)]", "")
      for mode in ("NEXT_STEP", "SAME_STEP")),
    *((f"v = w.ConstantBonusVectorReward({vec(mode)}, 0.1, decay=-1)", "decay")
      for mode in ("NEXT_STEP", "SAME_STEP")),
    (f"v = w.ConstantBonusVectorReward(w.ConstantBonusVectorReward({vec('NEXT_STEP')}, 0.1), "
     "0.1); " + STEPS3, ""),
    (f"v = w.ConstantBonusVectorReward({vec('NEXT_STEP', wrap='e')}, 0.1)",
     ("triplet", "SimounObservation")),
    (f"w.ConstantBonusVectorReward({S}, 0.1)", ("vector", "ConstantBonusReward")),
    (NOV + f"v = w.RNDVectorReward({vec('SAME_STEP')}, nov, warmup=0); v.reset(seed=0); "
     "v.step(np.zeros((2, 1), np.float32)); v.reset(seed=1); v.step(np.zeros((2, 1), "
     "np.float32))", ""),
    # observations and wrappers at their boundaries
    (f"e = w.SimounObservation({P}, size=1); " + STEP, "size", True),
    (f"e = w.SimounObservation({P}, size=(16, 64)); " + STEP, ""),
    (f"e = w.SimounObservation({P}, size=16, grayscale=np.bool_(True)); " + STEP, ""),
    (f"e = w.SimounObservation({P}, size=16, num_frames=np.int64(3)); " + STEP, ""),
    (f"e = w.FrameTriplet({P}, num_frames=1); " + STEP, ""),
    (f"e = w.RandomConvolution({P}, kernel_size=1); " + STEP, ""),
    (f"e = w.ActionRepeat({P}, 10**9); " + STEP, ""),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), kernel_size=-3)", "kernel_size"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), clamp=(0,))", "clamp"),
    ("w.residual_motion(np.zeros((0, 3, 8, 8), np.uint8))", "frames"),
    (f"w.MultiCamera({P}, cameras='render')", "cameras"),
    (f"w.MultiCamera({P}, cameras=[lambda e: e.render(), lambda e: e.render()], size=16)"
     ".reset(seed=0)", ""),
    (DMC + "w.MovingBackground(d, level='easy', videos='.')", ("videos", "video")),
    (DMC + "w.ColorShift(d, level='hard', seed=np.int64(3)).reset(seed=0)", ""),
]  # fmt: skip
FOURTH_API_CASES = [
    *(
        api(code.format(value), names)
        for code, names, *values in FOURTH_REFUSED
        for value in values
    ),
    *(api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in FOURTH_CODES),
]
FOURTH_COMMAND_CASES = FOURTH_FLAG_CASES + FOURTH_FILE_CASES + FOURTH_SPEC_CASES
for _case in FOURTH_COMMAND_CASES + FOURTH_API_CASES:
    _case["set"] = "fourth"


# the fifth trial's cases, run alone with --set fifth: every subcommand of the lab's commands
# (the analyses, the studies, the MiniGrid study, the driving references) with bad values, paths
# and combinations; presets crossed with env families; the lab's archives damaged (a study
# directory, a MiniGrid archive, a sweep directory); the Python API's agent, replay, online
# models, configs and wrappers stacked with Gymnasium's own, re-made from their specs, copied

GUARD = "no-ray-in-this-trial"
"""``RAY_ADDRESS`` of the fifth trial's cases of the commands that start Ray (simoun-sweep,
``simoun-study run``, the MiniGrid study's ``run``): a value that ``connect`` refuses before it
reaches any cluster, so a case that gets that far stops there, and is read as work started (the
Ray cluster of a study may be running on this machine; no case may join it or start another)."""
STUDIES = ROOT / "docs/studies"
MGT_SPEC = (STUDIES / "minigrid-v2/tuning/spec.json").read_text()
HIGHWAY_SPEC = (STUDIES / "highway50k.toml").read_text()
V2_SPEC = (STUDIES / "dmc100k-v2.toml").read_text()


def setup(*works):
    """A setup running each of ``works`` (functions of the case's directory) in turn."""
    return call(lambda here: [work(here) for work in works])


def lab_copy(source: str, name: str):
    """Work: the repository's archive ``docs/studies/<source>`` copied to the case's ``name``."""
    return lambda here: shutil.copytree(STUDIES / source, here / name)


def spoil(name: str, how):
    """Work: the case's file ``name`` (a path in its directory) damaged as :func:`damage` does."""
    return lambda here: damage(here, name, how)


def put(name: str, data: bytes | str):
    """Work: the case's file ``name`` written with ``data``."""
    raw = data.encode() if isinstance(data, str) else data
    return lambda here: (here / name).write_bytes(raw)


def trained(name: str, *flags: str):
    """Work: a tiny run trained with ``flags`` in place of TINY's (40 env steps) at the case's
    ``name``; trained once per pass, beside the cases, and copied."""

    def make(here: Path) -> None:
        kept = here.parent / f"kept-{name}"
        if not kept.is_dir():
            from simoun_agent.cli import train

            part = here.parent / f"kept-{name}.part"
            shutil.rmtree(part, ignore_errors=True)
            argv = [*tiny(*flags), "--total-env-steps", "40", "--run-dir", str(part)]
            assert train.main(argv) == 0, argv
            part.rename(kept)
        shutil.copytree(kept, here / name)

    return make


def sweep_dir(here: Path) -> None:
    """``sw``: a sweep directory as simoun-sweep leaves it (its sweep.json, one finished trial, a
    copy of the tiny run)."""
    from simoun_lab.sweep.grid import SweepSpec

    config = json.loads((here / "run/config.json").read_text())
    base = {
        key: config[key]
        for key in ("env", "image_size", "warmup_agent_steps", "eval_every", "eval_episodes",
                    "checkpoint_every", "device", "progress", "video", "total_env_steps")
    }  # fmt: skip
    base.update(
        {
            f"agent.{key}": config["agent"][key]
            for key in ("batch_size", "num_filters", "feature_dim", "hidden_dim", "aux_hidden_dim")
        }
    )
    spec = SweepSpec.create(None, base, [], None, None)
    (here / "sw").mkdir()
    spec.save(here / "sw")
    shutil.copytree(here / "run", spec.trials(here / "sw")[0].run_dir)


def remove_tree(path: Path) -> None:
    shutil.rmtree(path)


def tree_to_file(path: Path) -> None:
    shutil.rmtree(path)
    path.write_text("not a directory\n")


def utf16(path: Path) -> None:
    path.write_bytes(path.read_text().encode("utf-16"))


def bom(path: Path) -> None:
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes())


def emptied(path: Path) -> None:
    shutil.rmtree(path)
    path.mkdir()


def video_dir(here: Path) -> None:
    """``v``: a folder of videos that holds no video."""
    (here / "v").mkdir()
    (here / "v/notes.txt").write_text("not a video\n")


def evaluated(here: Path) -> None:
    """An evaluation of the run already in ``o``."""
    from simoun_agent.cli import eval as evaluate

    evaluate.main([str(here / "run"), "--no-video", "--episodes", "1", "--out", str(here / "o")])


def starts_ray(command: str, argv: list[str]) -> bool:
    """Whether ``command argv`` may start Ray: simoun-sweep, and the studies' ``run``."""
    return command == "sweep" or (command in ("study", "minigrid") and argv[:1] == ["run"])


def fifth(area: str, command: str, argv: list[str], names, ok: bool = False, works=(), what=None):
    """A fifth-trial command case; those of the commands that start Ray run with the guard."""
    case = cli(area, command, argv, names, ok, setup(*works) if works else None)
    if starts_ray(command, argv):
        case["guard"] = True
    if what is not None:
        case["what"] = what
    return case


ARCH, MG, MGT, SW = (
    lab_copy("dmc100k", "arch"),
    lab_copy("minigrid", "mg"),
    lab_copy("minigrid-v2/tuning", "mgt"),
    sweep_dir,
)
DMC_RUN = trained("dmc", "--env", "dm_control/cartpole-swingup-v0")
DRQ_RUN = trained("drq", "--agent.recipe", "drq")
SMALL_PROBE = ["--settings.n-envs", "2", "--settings.n-steps", "32", "--settings.env-id",
               "MiniGrid-Empty-5x5-v0"]  # fmt: skip


def small_probe(*f: str, steps: str = "512") -> list[str]:
    """A probe of ``steps`` env steps on MiniGrid-Empty-5x5 (seconds), with ``f`` added."""
    return probe("--settings.steps", steps, *SMALL_PROBE, *f)


HIGHWAY = put("highway.toml", HIGHWAY_SPEC)
DMC100K = put("dmc100k.toml", SPEC)  # a study is named for its spec file
# (command, argv, what the refusal names[, valid[, works]])
FIFTH_FLAGS = [
    # simoun-analyze bias and masks
    ("analyze", bias("--pairs", "-1"), "--pairs"),
    ("analyze", bias("--pairs", "1", "--out", "b"), "--pairs", True),
    ("analyze", bias("--seed", "-1"), "--seed"),
    ("analyze", bias("--seed", "abc"), "--seed"),
    ("analyze", bias("--recolour", "model", "--pairs", "8"), ("model", "dm_control")),
    ("analyze", ["bias", "{run}", "{run}", "--out", "b", "--pairs", "8"], ("twice", "once")),
    ("analyze", ["bias", "{run}", "{run}/checkpoint.pt", "--out", "b", "--pairs", "8"],
     ("twice", "once")),
    ("analyze", ["bias", "{run}", REPORT_OUT, "--out", "b"], (REPORT_OUT, "config.json"), False,
     (report_output,)),
    ("analyze", bias("--pairs", "8", "--out", "{run}/config.json"), "--out"),
    ("analyze", bias("--pairs", "8", "--out", "b", "--overwrite"), "", True),
    ("analyze", bias("--pairs", "8", "--device", "cuda"), ("cuda", "device")),
    ("analyze", ["bias", "--pairs", "8", "--out", "b", "{run}"], "", True),
    ("analyze", ["{run}"], ("masks", "bias")),
    ("analyze", ["masks"], "RUN"),
    ("analyze", ["masks", "{run}", "{run}"], ("RUN", "one run", "unrecognized", "extra")),
    ("analyze", masks("--query", "-1,5"), "--query"),
    ("analyze", masks("--query", "a,b"), "--query"),
    ("analyze", masks("--query", "1,2,3"), "--query"),
    ("analyze", masks("--query", "32,0", "--steps", "1"), "--query"),
    ("analyze", masks("--query", "31,31", "--steps", "1"), "", True),
    ("analyze", masks("--steps", "2,2"), "--steps", True),
    ("analyze", masks("--steps", "2;3"), "--steps"),
    ("analyze", masks("--episodes", "1.5"), "--episodes"),
    ("analyze", masks("--episodes", "-1"), "--episodes"),
    ("analyze", masks("--video", "mp4", "--steps", "1"), "", True),
    ("analyze", masks("--video", "--steps", "1"), "", True),
    ("analyze", masks("--video", "webm"), "--video"),
    ("analyze", ["masks", "{run}/replay-40.npz"], ("replay-40.npz", "checkpoint.pt")),
    ("analyze", ["masks", "{run}/eval.csv"], "eval.csv"),
    ("analyze", ["masks", "drq", "--steps", "1"], ("dual", "drq", "encoder"), False, (DRQ_RUN,)),
    ("analyze", ["bias", "drq", "{run}", "--out", "b", "--pairs", "8"], "", True, (DRQ_RUN,)),
    ("analyze", ["bias", "dmc", "--recolour", "model", "--pairs", "8"], "", True, (DMC_RUN,)),
    # simoun-eval
    ("eval", eval_argv("--distraction", "train", "--episodes", "1"), ("train", "dm_control"),
     True),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy", "--episodes", "1"], "", True,
     (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "video_easy", "--videos", "nowhere",
              "--episodes", "1"], ("--videos", "nowhere"), False, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "video_easy", "--videos", "v", "--episodes",
              "1"], ("--videos", "video"), False, (DMC_RUN, video_dir)),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy", "--torch-threads", "1",
              "--episodes", "1"], "--torch-threads", False, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy", "--random-policy",
              "--episodes", "1"], ("--random-policy", "--distraction"), True, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy, color_hard", "--episodes", "1"],
     "--distraction", True, (DMC_RUN,)),
    ("eval", ["dmc", "--no-video", "--distraction", "color_easy", "--videos", ".", "--episodes",
              "1"], "--videos", True, (DMC_RUN,)),
    ("eval", ["{run}", "dmc", "--no-video", "--distraction", "color_easy", "--episodes", "1"],
     ("dm_control", "PointReach"), False, (DMC_RUN,)),
    ("eval", eval_argv("--episodes", "1", "--out", "o"), ("--overwrite", "o"), False,
     (evaluated,)),
    ("eval", ["{run}", "--episodes", "1"], "", True),
    ("eval", eval_argv("--seed", "none", "--episodes", "1"), "", True),
    ("eval", eval_argv("--episodes", "1", "--progress"), "", True),
    # simoun-report
    ("report", report_argv("--at-step", "20", "--at-step", "40"), "--at-step"),
    ("report", ["sw"], "", True, (SW,)),
    ("report", ["sw", "--at-step", "20"], "", True, (SW,)),
    ("report", ["mg"], ("minigrid_study", "MiniGrid"), True, (MG,)),
    ("report", ["mgt"], ("minigrid_study", "MiniGrid"), True, (MGT,)),
    ("report", ["arch"], ("simoun-study", "study"), True, (ARCH,)),
    ("report", ["."], "", True),
    ("report", report_argv("--out", "{run}/rep"), "--out", True),
    ("report", report_argv("--at-wall-time", "1e-300"), "--at-wall-time", True),
    # simoun-study
    ("study", ["plan", "spec.yaml", "--probe-updates", "0"], ("spec.yaml", "TOML"), False,
     (put("spec.yaml", "recipes:\n  - simoun\nselection: auc\n"),)),
    ("study", ["plan", "mgt/spec.json"], "", True, (MGT,)),
    ("study", ["plan", "mgt/spec.json", "--probe-updates", "5"], "--probe-updates", True, (MGT,)),
    ("study", ["report", "dmc100k.toml", "--study-dir", "arch"], "", True, (ARCH, DMC100K)),
    ("study", ["report", "highway.toml", "--study-dir", "arch"], ("another spec", "highway"),
     False, (ARCH, HIGHWAY)),
    ("study", ["report", "mgt/spec.json", "--study-dir", "arch"], ("spec.json", "study.json"),
     False, (ARCH, MGT)),
    ("study", ["report", "spec.toml", "--study-dir", "mgt"], ("study.json", "spec.json"), False,
     (MGT,)),
    ("study", ["report", "mgt/spec.json", "--study-dir", "mgt"], "", True, (MGT,)),
    ("study", ["report", "mg/spec.json", "--study-dir", "mg"], "", True, (MG,)),
    ("study", ["report", "spec.toml", "--study-dir", "arch", "--resume"], "--resume", False,
     (ARCH,)),
    ("study", study_run("--resume"), ("--resume", "study.json")),
    ("study", study_run("--allow-other-commit"), "--allow-other-commit", True),
    ("study", ["run", "mgt/spec.json", "--study-dir", "s", "--allow-other-commit"],
     "--allow-other-commit", False, (MGT,)),
    ("study", ["run", "spec.toml", "--study-dir", "arch"], ("--resume", "already"), False,
     (ARCH,)),
    ("study", study_run("--archive", "arch"), ("--resume", "already"), False, (ARCH,)),
    ("study", study_run("--address", "localhost"), "--address"),
    ("study", study_run("--address", ":6379"), "--address"),
    ("study", study_run("--address", "ray://"), "--address"),
    ("study", study_run("--verbose", "2", "--address", "localhost:abc"), "--address"),
    ("study", study_run("--num-cpus", "1", "--address", "localhost"), ("--num-cpus", "--address")),
    ("study", ["status"], ("plan", "run", "report")),
    # python -m simoun_lab.minigrid_study
    ("minigrid", ["status"], ("run", "report", "select", "probe")),
    ("minigrid", [], ("run", "report", "select", "probe")),
    ("minigrid", ["run", "--archive", "mg", "--work-dir", "wd"], "", True, (MG,)),
    ("minigrid", ["run", "--archive", "mg", "--work-dir", "wd", "--concurrent", "0"],
     "--concurrent", False, (MG,)),
    ("minigrid", ["run", "--archive", "mg", "--work-dir", "/proc/x"], "--work-dir", False, (MG,)),
    ("minigrid", ["run", "--archive", "mg", "--work-dir", "wd", "--spec", "mgt/spec.json"],
     ("spec", "differ"), False, (MG, MGT)),
    ("minigrid", ["run", "--archive", "mg", "--work-dir", "wd", "--address", "nohost"],
     "--address", True, (MG,)),
    ("minigrid", ["run", "--archive", "mgt", "--work-dir", "wd", "--address", "localhost"],
     "--address", False, (MGT,)),
    ("minigrid", ["select", "--archive", "mg"], "", True, (MG,)),
    ("minigrid", ["report", "--archive", "mgt"], "", True, (MGT,)),
    ("minigrid", ["select", "--archive", "mgt", "--spec", "mg/spec.json"], ("spec", "differ"),
     False, (MG, MGT)),
    ("minigrid", ["select", "--archive", "arch"], ("spec.json", "arch"), False, (ARCH,)),
    ("minigrid", ["report", "--archive", "sw"], ("spec.json", "sw"), False, (SW,)),
    ("minigrid", small_probe("--probes", "rnd"), "", True),
    ("minigrid", small_probe("--probes", "rnd", steps="64"), ("--settings.steps", "steps")),
    ("minigrid", small_probe("--probes", "rnd", steps="8"), ("--settings.steps", "steps")),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "100"), ("--settings.steps",
                                                                        "steps")),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id", "MiniGrid-DoorKey-6x6"),
     "MiniGrid-DoorKey-6x6"),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "2",
                       "--settings.n-steps", "32", "--settings.env-id",
                       "minigrid:MiniGrid-Empty-5x5-v0"), ("env-id", "minigrid:"), True),
    ("minigrid", small_probe("--probes", "rnd,consistency"), "rnd,consistency"),
    ("minigrid", small_probe("--probes", "RND"), "RND"),
    ("minigrid", small_probe("--probes", "rnd", "--settings.seed", "0"), ("seed", "0"), True),
    ("minigrid", ["probe", "--out", "nowhere/deeper/p", "--probes", "rnd"], "--out"),
    ("minigrid", ["probe", "--out", ".", "--probes", "rnd", "--settings.steps", "512",
                  *SMALL_PROBE], "", True),
    ("minigrid", probe("--probes", "rnd", "--settings.steps", "512", "--settings.n-envs", "1",
                       "--settings.n-steps", "32", "--settings.env-id",
                       "MiniGrid-Empty-5x5-v0"), "", True),
    ("minigrid", small_probe("--probes", "rnd", "--settings.device", "cpu"),
     "--settings.device"),
    # python -m simoun_agent.run.driving_reference
    ("driving", driving("--preset", "walker-walk"), "walker-walk"),
    ("driving", driving("--episodes", "1", "--video", "x.GIF"), "--video", True),
    ("driving", driving("--video", "x"), "--video"),
    ("driving", driving("--json", "x.txt"), "--json"),
    ("driving", driving("--json", "nowhere/x.json"), "--json"),
    ("driving", driving("--seed", "1.5"), "--seed"),
    ("driving", driving("--episodes", "2.0"), "--episodes"),
    ("driving", driving("--episodes", "1", "--json", "{run}/config.json"), "--json", True),
    ("driving", driving("--episodes", "1", "--json", "d.json", "--video", "d.gif"), "", True),
    ("driving", driving("--episodes", "1", "--video", "d.mp4"), "", True),
    ("driving", driving("--episodes", "1", "--preset", "highway"), "", True),
    # simoun-train: presets crossed with env families, env kwargs, repeats
    ("train", tiny("--preset", "reacher-easy", *SHORT), ("preset", "reacher"), True),
    ("train", tiny("--preset", "finger-spin", "--env", "Pendulum-v1", *SHORT), ("preset",
                                                                                 "finger"), True),
    ("train", tiny("--preset", "ball_in_cup-catch", *SHORT), ("preset", "ball_in_cup"), True),
    ("train", tiny("--preset", "highway-cpu", "--env", "dm_control/cartpole-swingup-v0", *SHORT),
     ("preset", "highway"), True),
    ("train", tiny("--preset", "cpu", "--env", "highway-fast-v0", *SHORT), ("Discrete",
                                                                            "ContinuousAction")),
    ("train", tiny("--env", "highway-fast-v0", "--env-kwargs",
                   '{"config": {"action": {"type": "ContinuousAction"}}}', *SHORT), "", True),
    ("train", tiny("--env", "dm_control/cartpole-swingup-v0", "--cameras", "3", *SHORT),
     "cameras"),
    ("train", tiny("--env", "dm_control/cartpole-swingup-v0", "--cameras", "2", *SHORT), "",
     True),
    ("train", tiny("--env", "Pendulum-v1", "--cameras", "2"), "cameras"),
    ("train", tiny("--env", "Pendulum-v1", "--env-kwargs", '{"g": "x"}', *SHORT), ("'g'", "g=")),
    ("train", tiny("--env", "Pendulum-v1", "--env-kwargs", '{"max_episode_steps": 10}', *SHORT),
     "", True),
    ("train", tiny("--env", "Pendulum-v1", "--env-kwargs", '{"max_episode_steps": 0}'),
     "max_episode_steps"),
    ("train", tiny("--env-kwargs", '{"render_mode": "rgb_array"}', *SHORT), "render_mode", True),
    ("train", tiny("--action-repeat", "3", *SHORT), "action_repeat", True),
    ("train", tiny("--action-repeat", "8", *SHORT), "warmup", True),
    ("train", tiny("--eval-every", "7", *SHORT), "eval_every", True),
    ("train", tiny("--device", "cuda"), ("cuda", "device")),
    ("train", tiny("--torch-threads", "64", *SHORT), "torch_threads", True),
    ("train", [*tiny("--env", "dm_control/cartpole-swingup-v0", "--eval-distraction",
                     "color_easy", *SHORT), "--eval-distraction", "color_easy"], "color_easy",
     True),
    ("train", tiny("--env", "highway-fast-v0", "--eval-distraction", "color_easy"),
     ("dm_control", "color_easy")),
    ("train", tiny("--grayscale", "--env", "dm_control/cartpole-swingup-v0", *SHORT), "", True),
    ("train", tiny("--agent.recipe", "sac", *SHORT), "", True),
    ("train", tiny("--agent.recipe", "stacked_wide", *SHORT), "", True),
    ("train", tiny("--agent.recipe", "drqv2", "--agent.n-step", "5", *SHORT), "n_step", True),
    # simoun-sweep: refused before Ray starts, or (the guard) read as work started
    ("sweep", sweep_tiny("--address", "localhost"), "--address"),
    ("sweep", sweep_tiny("--address", ":6379"), "--address"),
    ("sweep", sweep_tiny("--address", "ray://"), "--address"),
    ("sweep", sweep_tiny("--grid", "agent.recipe="), ("agent.recipe", "--grid")),
    ("sweep", sweep_tiny("--grid", "agent.lr=1e-3,1e-3"), ("agent.lr", "--grid")),
    ("sweep", sweep_tiny("--grid", "agent.lr=0.001,1e-3"), ("agent.lr", "--grid")),
    ("sweep", sweep_tiny("--grid", "=1,2"), "--grid"),
    ("sweep", sweep_tiny("--grid", "agent.recipe=simoun;drq"), "simoun;drq"),
    ("sweep", sweep_tiny("--seeds", "0-1", "--seed", "3"), ("--seeds", "--seed")),
    ("sweep", sweep_tiny("--envs", "Pendulum-v1"), ("--envs", "--env")),
    ("sweep", sweep_tiny("--set", "torch_threads=2"), "torch_threads"),
    ("sweep", sweep_tiny("--grid", "agent.batch_size=8,0"), "batch_size"),
    ("sweep", sweep_tiny("--verbose", "-1"), "--verbose"),
    ("sweep", sweep_tiny("--gpus-per-trial", "auto", "--device", "cuda"), ("cuda", "device")),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--seeds", "0-3"], "--seeds", False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--total-env-steps", "20"], "--total-env-steps",
     False, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--grid", "agent.lr=1e-3,3e-4"], "--grid", False,
     (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw"], "", True, (SW,)),
    ("sweep", ["--resume", "--sweep-dir", "sw", "--cpus-per-trial", "2"], "--cpus-per-trial",
     False, (SW,)),
    ("sweep", sweep_tiny("--sweep-dir", "sw"), ("--resume", "already"), False, (SW,)),
]  # fmt: skip
FIFTH_FLAG_CASES = [
    fifth("flags", command, argv, names, *rest[:1], works=rest[1] if len(rest) > 1 else ())
    for command, argv, names, *rest in FIFTH_FLAGS
]

EV_RUN = "arch/evaluation/simoun/cartpole-swingup/s1"
TU_RUN = "arch/tuning/simoun/agent.n_step=1/cartpole-swingup/s101"
# a study archive damaged, given to simoun-study report: (path, way, how, names[, valid])
STUDY_DAMAGES = [
    ("arch/study.json", "missing", None, "study.json"),
    ("arch/study.json", "empty", b"", "study.json"),
    ("arch/study.json", "not JSON", b"{oops", "study.json"),
    ("arch/study.json", "truncated", "half", "study.json"),
    ("arch/study.json", "a list", b"[]", "study.json"),
    ("arch/study.json", "UTF-16", utf16, "study.json", True),
    ("arch/study.json", "a directory", into_directory, "study.json"),
    ("arch/study.json", "without its spec", edit_json(lambda d: d.pop("spec")), "study.json"),
    ("arch/study.json", "another study's spec",
     edit_json(lambda d: d["spec"].update(recipes=["simoun"])), ("recipes", "another spec")),
    ("arch/study.json", "without its parts", edit_json(lambda d: d.pop("parts")),
     ("study.json", "parts"), True),
    ("arch/study.json", "a part without its commit",
     edit_json(lambda d: d["parts"][0].pop("commit")), ("study.json", "commit"), True),
    ("arch/study.json", "an older spec (selection missing)",
     edit_json(lambda d: d["spec"].pop("selection")), ("study.json", "selection"), True),
    ("arch/selection.json", "not JSON", b"{", "selection.json", True),
    ("arch/selection.json", "missing", None, "selection.json", True),
    ("arch/report", "a file", tree_to_file, "report"),
    (f"{EV_RUN}/eval.csv", "empty", b"", "eval.csv"),
    (f"{EV_RUN}/eval.csv", "non-numeric", "eval+abc", "eval.csv"),
    (f"{EV_RUN}/eval.csv", "header only", b"env_step,return_mean\n", "eval.csv"),
    (f"{EV_RUN}/summary.json", "missing", None, ("summary.json", "s1"), True),
    (f"{EV_RUN}/summary.json", "not JSON", b"{", "summary.json"),
    (f"{EV_RUN}/config.json", "not JSON", b"{", "config.json"),
    (f"{EV_RUN}/config.json", "missing", None, "config.json"),
    (f"{EV_RUN}/trial.json", "not JSON", b"{", "trial.json", True),
    (EV_RUN, "removed", remove_tree, ("s1", "missing"), True),
    (f"{TU_RUN}/eval.csv", "empty", b"", "eval.csv"),
    (f"{TU_RUN}/summary.json", "a list", b"[]", "summary.json"),
    (f"{TU_RUN}/config.json", "another recipe's",
     edit_json(lambda d: d["agent"].update(recipe="drq")), ("config.json", "recipe")),
]  # fmt: skip
MG_RUN, MGT_RUN = "mg/MiniGrid-DoorKey-6x6-v0/ppo/s0", "mgt/MiniGrid-DoorKey-6x6-v0/ppo/s100"
# a MiniGrid run damaged: (its file, way, how, names[, valid])
MINIGRID_DAMAGES = [
    ("summary.json", "missing", None, "summary.json", True),
    ("summary.json", "not JSON", b"{", "summary.json"),
    ("summary.json", "a list", b"[]", "summary.json"),
    ("summary.json", "a string step", edit_json(lambda d: d.update(env_steps="many")),
     ("summary.json", "env_steps")),
    ("summary.json", "a NaN success rate",
     edit_json(lambda d: d.update(final_success_rate=float("nan"))),
     ("summary.json", "final_success_rate")),
    ("eval.csv", "missing", None, "eval.csv"),
    ("eval.csv", "empty", b"", "eval.csv"),
    ("eval.csv", "non-numeric", "eval+abc", "eval.csv"),
    ("eval.csv", "rows out of order", csv_rows(lambda rows: [rows[0], *reversed(rows[1:])]),
     "eval.csv"),
    ("eval.csv", "a success rate of 2",
     csv_rows(lambda rows: [*rows[:-1], [*rows[-1][:2], "2.0", *rows[-1][3:]]]),
     ("eval.csv", "success_rate")),
    ("config.json", "not JSON", b"{", "config.json"),
    ("config.json", "another spec's",
     edit_json(lambda d: d["spec"]["ppo"].update(gamma=0.5)), ("config.json", "gamma")),
    ("train.csv", "missing", None, "train.csv", True),
]  # fmt: skip
MINIGRID_COMMANDS = [  # (command, argv, its archive, the damaged run, the works)
    ("minigrid", ["report", "--archive", "mg"], "mg", MG_RUN, (MG,)),
    ("minigrid", ["select", "--archive", "mgt"], "mgt", MGT_RUN, (MGT,)),
    ("study", ["report", "mg/spec.json", "--study-dir", "mg"], "mg", MG_RUN, (MG,)),
]
ARCHIVE_SPEC_DAMAGES = [  # the archive's spec.json: (way, how, valid)
    ("missing", None, False), ("not JSON", b"{", False),
    ("UTF-8 with a byte-order mark", bom, True),
]  # fmt: skip
SW_RUN = "sw/base/simoun-PointReach-v0/s1"
# a sweep directory damaged, given to simoun-report and simoun-sweep --resume (guarded):
# (path, way, how, names[, valid])
SWEEP_DAMAGES = [
    ("sw/sweep.json", "without its seeds", edit_json(lambda d: d.pop("seeds")), "sweep.json"),
    ("sw/sweep.json", "seeds as a string", edit_json(lambda d: d.update(seeds="1")),
     ("sweep.json", "seeds")),
    ("sw/sweep.json", "no envs", edit_json(lambda d: d.update(envs=[])), ("sweep.json", "envs")),
    ("sw/sweep.json", "a grid value that is not a list",
     edit_json(lambda d: d.update(grid={"agent.lr": 0.001})), ("sweep.json", "grid")),
    ("sw/sweep.json", "an unknown preset", edit_json(lambda d: d.update(preset="cpux")), "cpux"),
    ("sw/sweep.json", "an unknown base key", edit_json(lambda d: d["base"].update(nope=1)),
     "nope"),
    ("sw/sweep.json", "cpus_per_trial 0", edit_json(lambda d: d.update(cpus_per_trial=0)),
     ("sweep.json", "cpus_per_trial")),
    ("sw/sweep.json", "an extra key", edit_json(lambda d: d.update(nope=1)), "sweep.json"),
    ("sw/sweep.json", "null", b"null", "sweep.json"),
    ("sw/sweep.json", "a directory", into_directory, "sweep.json"),
    ("sw/sweep.json", "UTF-8 with a byte-order mark", bom, "sweep.json", True),
    (f"{SW_RUN}/summary.json", "missing", None, ("summary.json", GUARD), True),
    (f"{SW_RUN}/config.json", "missing", None, "config.json"),
    (f"{SW_RUN}/config.json", "another env's",
     edit_json(lambda d: d.update(env="Pendulum-v1")), ("config.json", "Pendulum")),
    (SW_RUN, "emptied", emptied, ("s1", GUARD), True),
    ("sw/notes.txt", "a stray file", b"notes\n", "", True),
]  # fmt: skip
SWEEP_COMMANDS = [("report", ["sw"]), ("sweep", ["--resume", "--sweep-dir", "sw"])]
# the tiny run with files no earlier trial damaged: (file, way, how)
RUN_DAMAGES = [
    ("tb", "a file", tree_to_file),
    ("learning_curve.png", "a directory", into_directory),
    (".lock", "empty", b""),
    (".lock", "not a process id", b"abc\n"),
    (".lock", "process id 0", b"0\n"),
    (".lock", "process id -1", b"-1\n"),
    (".lock", "a directory", into_directory),
]  # fmt: skip
# the first trial's damages, given to two commands that read a run and no trial gave them
FIFTH_FILE_COMMANDS = {
    "analyze": ["bias", "{run}", "--pairs", "8", "--out", "b"],
    "eval": ["{run}", "--random-policy", "--episodes", "1", "--no-video"],
}
FIRST_DAMAGES = [
    ("config.json", "missing", None), ("config.json", "not JSON", b"{oops"),
    ("checkpoint.pt", "missing", None), ("checkpoint.pt", "truncated", "half"),
    ("checkpoint.pt", "garbage", b"\x00garbage" * 50), ("replay", "missing", None),
    ("eval.csv", "missing", None),
]  # fmt: skip


FIFTH_FILE_CASES = [
    *(fifth("files", "study", ["report", "dmc100k.toml", "--study-dir", "arch"], names, *ok,
            works=(ARCH, DMC100K, spoil(path, how)), what=f"{path} {way}")
      for path, way, how, names, *ok in STUDY_DAMAGES),
    *(fifth("files", command, argv, names, *ok, works=(*works, spoil(f"{run}/{name}", how)),
            what=f"{run}/{name} {way}")
      for name, way, how, names, *ok in MINIGRID_DAMAGES
      for command, argv, _, run, works in MINIGRID_COMMANDS),
    *(fifth("files", command, argv, "spec.json", ok, works=(*works, spoil(f"{archive}/spec.json",
            how)), what=f"{archive}/spec.json {way}")
      for way, how, ok in ARCHIVE_SPEC_DAMAGES for command, argv, archive, _, works in
      MINIGRID_COMMANDS),
    *(fifth("files", command, argv, names, *ok, works=(SW, spoil(path, how)),
            what=f"{path} {way}")
      for path, way, how, names, *ok in SWEEP_DAMAGES for command, argv in SWEEP_COMMANDS),
    *({**cli("files", command, argv, name, ok=True, setup=(name, how)), "what": f"{name} {way}"}
      for name, way, how in RUN_DAMAGES for command, argv in FILE_COMMANDS.items()),
    *({**cli("files", command, argv, "replay" if name == "replay" else name, ok=True,
             setup=(name, how)), "what": f"{name} {way}"}
      for name, way, how in FIRST_DAMAGES for command, argv in FIFTH_FILE_COMMANDS.items()),
]  # fmt: skip

PPO_TOML = """arms = ["ppo", "rnd,scale=0.01"]
evaluations = 2
eval_episodes = 2

[[tasks]]
env_id = "MiniGrid-Empty-5x5-v0"
steps = 2048
seeds = [0, 1]

[ppo]
n_envs = 2
n_steps = 64
"""
# MiniGrid PPO specs given to simoun-study plan: (a change to the JSON value, names[, valid])
PPO_JSON_EDITS = [
    (lambda s: s.update(arms=["ppo", "rndd"]), "rndd"),
    (lambda s: s.update(arms="ppo"), "arms"),
    (lambda s: s.update(tasks=[]), "tasks"),
    (lambda s: s["tasks"][0].update(steps="400k"), "steps"),
    (lambda s: s["tasks"][0].update(env_id="Pendulum-v1"), "Pendulum-v1"),
    (lambda s: s["ppo"].update(n_env=8), "n_env"),
    (lambda s: s.update(evaluations=0), "evaluations"),
    (lambda s: s.update(device="tpu"), "device"),
    (lambda s: s.update(recipes=["simoun"]), "recipes"),
]  # fmt: skip
PPO_JSON_TEXTS = [("{", "spec.json"), ("", "spec.json"), ("[]", "spec.json"),
                  ("\ufeff" + MGT_SPEC, "spec.json", True)]  # fmt: skip
PPO_TOML_EDITS = [  # (text replaced, by, names[, valid])
    ("evaluations = 2", "evaluations = 2", "", True),
    ("evaluations = 2", 'evaluations = 2\nrecipes = ["simoun"]', ("arms", "recipes")),
    ("[[tasks]]", "[tasks]", "tasks"),
    ("steps = 2048", 'steps = "2k"', "steps"),
    ("n_envs = 2", "n_env = 2", "n_env"),
    ('arms = ["ppo", "rnd,scale=0.01"]', 'arms = ["ppo", "drq"]', "drq"),
    ('arms = ["ppo", "rnd,scale=0.01"]', "arms = []", "arms"),
    ("seeds = [0, 1]", 'seeds = "0-1"', "seeds", True),
    ("evaluations = 2", 'evaluations = 2\nselection = "auc"', "selection"),
]  # fmt: skip
# the other study specs of docs/studies edited: (spec text, text replaced, by, names[, valid])
OTHER_SPEC_EDITS = [
    (HIGHWAY_SPEC, 'preset = "highway-cpu"', 'preset = "cpu"', "preset", True),
    (HIGHWAY_SPEC, '"highway-fast-v0"', '"highway-v0"', "highway-v0", True),
    (HIGHWAY_SPEC, "video = false", "video = false\ncameras = 0", "cameras"),
    (HIGHWAY_SPEC, "video = false",
     'video = false\nenv_kwargs = { config = { action = { type = "DiscreteMetaAction" } } }',
     ("Discrete", "env_kwargs")),
    (HIGHWAY_SPEC, "seeds = [101]", "seeds = [1]", "seeds"),
    (HIGHWAY_SPEC, "max_concurrent_trials = 2",
     'max_concurrent_trials = 2\n\n[generalization]\nmodes = ["color_easy"]',
     ("dm_control", "generalization")),
    (HIGHWAY_SPEC, "env_steps = 5_000", "env_steps = 50_000", "", True),
    (HIGHWAY_SPEC, 'recipes = ["simoun", "drq", "rad"]',
     'recipes = ["simoun", "drq", "rad", "drqv2"]', ("n_step", "grid_overrides"), True),
    (V2_SPEC, 'simoun = ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]',
     "simoun = []", "diagnostics", True),
    (V2_SPEC, 'simoun = ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]',
     'drq = ["simoun_no_aux"]', ("drq", "simoun_no_aux")),
    (V2_SPEC, 'simoun = ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]',
     'simoun = ["drq"]', "drq"),
    (V2_SPEC, 'simoun = ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]',
     'simoun = ["simoun_no_curiosity", "simoun_no_curiosity"]', "simoun_no_curiosity"),
    (V2_SPEC, 'simoun = ["simoun_no_curiosity", "simoun_no_interaction", "simoun_no_aux"]',
     'simoun = ["simoun"]', "simoun"),
    (V2_SPEC, 'modes = ["color_easy", "color_hard", "video_easy", "video_hard"]',
     'modes = ["color_easy", "color_easy"]', "color_easy"),
    (V2_SPEC, 'modes = ["color_easy", "color_hard", "video_easy", "video_hard"]',
     'modes = ["train"]', "train", True),
    (V2_SPEC, 'modes = ["color_easy", "color_hard", "video_easy", "video_hard"]',
     'modes = "color_easy"', "modes"),
    (V2_SPEC, "\nepisodes = 10", "\nepisodes = 1.5", "episodes"),
    (V2_SPEC, "\nepisodes = 10", '\nepisodes = 10\nvideos = "nowhere"', "videos"),
    (V2_SPEC, "\nepisodes = 10\n", "\n", "episodes", True),
]  # fmt: skip
for _text, _old, *_ in OTHER_SPEC_EDITS:
    assert _old in _text, _old
for _old, *_ in PPO_TOML_EDITS:
    assert _old in PPO_TOML, _old
RUN_SPEC_EDITS = [  # a bad spec given to simoun-study run (guarded): (replaced, by, names)
    ('"simoun", "drq"', '"simoun", "drqq"', "drqq"),
    ('seeds = "101-102"', 'seeds = "1-2"', "seed"),
    ("env_steps = 50_000", "env_steps = 0", "env_steps"),
]  # fmt: skip


def mgt_spec(change) -> str:
    spec = json.loads(MGT_SPEC)
    change(spec)
    return json.dumps(spec)


FIFTH_SPEC_CASES = [
    *(fifth("specs", "study", ["plan", "spec.json"], names, *ok,
            works=(put("spec.json", mgt_spec(change)),))
      for change, names, *ok in PPO_JSON_EDITS),
    *(fifth("specs", "study", ["plan", "spec.json"], names, *ok, works=(put("spec.json", text),))
      for text, names, *ok in PPO_JSON_TEXTS),
    *(fifth("specs", "study", ["plan", "ppo.toml"], names, *ok,
            works=(put("ppo.toml", PPO_TOML.replace(old, new, 1)),), what=new.replace("\n", "\\n"))
      for old, new, names, *ok in PPO_TOML_EDITS),
    *(fifth("specs", "study", ["plan", "other.toml", "--probe-updates", "0"], names, *ok,
            works=(put("other.toml", text.replace(old, new, 1)),), what=new.replace("\n", "\\n"))
      for text, old, new, names, *ok in OTHER_SPEC_EDITS),
    *(fifth("specs", "study", ["run", "bad.toml", "--study-dir", "s"], names,
            works=(put("bad.toml", SPEC.replace(old, new, 1)),), what=new.replace("\n", "\\n"))
      for old, new, names in RUN_SPEC_EDITS),
]  # fmt: skip

MS = f"w.SimounObservation({M}, size=16)"  # triplets of MiniGrid (a Dict observation)
C64 = f"w.SimounObservation({C}, size=64)"
M64 = f"w.SimounObservation({M}, size=64)"
RNDC = RND + "from simoun_agent.rnd_model import RNDConfig; "
CURC = CUR + "from simoun_agent.curiosity_model import CuriosityConfig; "
RESOLVE = "from simoun_agent.config import resolve; "
STATE = AGENT + f"s = {A}.state_dict(); "
LOAD = f"; {A}.load_state_dict(s)"
STEP_COPY = "c.reset(seed=1); c.step(c.action_space.sample())"


def vec_mode(mode: str, env: str = "CartPole-v1") -> str:
    """A 2-env sync vector env of ``env`` in autoreset ``mode`` (DISABLED too), each sub-env
    wrapped by a 16x16 SimounObservation."""
    return vec(mode, env)


# the documented rewards of a vector env's sub-envs at their autoreset steps, checked
BONUS_AT_RESETS = (
    "v = w.ConstantBonusVectorReward({vec}, 0.1); v.reset(seed=0); ended = np.zeros(2, bool)\n"
    "for _ in range(60):\n"
    "    _, r, t, u, i = v.step(np.ones(2, np.int64))\n"
    "    want = {want}\n"
    "    assert np.allclose(i['reward_intrinsic'], want), (i['reward_intrinsic'], want)\n"
    "    ended = t | u\n"
)
EPISODE_RETURN = (
    "e = gym.wrappers.RecordEpisodeStatistics(w.ConstantBonusReward(w.SimounObservation("
    f"{C}, size=16), 0.1)); e.reset(seed=0); done = False\n"
    "while not done:\n"
    "    _, r, t, u, i = e.step(1); done = t or u\n"
    "assert abs(i['episode']['r'] - 1.1 * i['episode']['l']) < 1e-6, i['episode']\n"
)
FIFTH_REFUSED = [  # (code with one {}, the name the refusal must give, the values)
    (RNDC + "RNDConfig({})", "capacity", "capacity=0"),
    (RNDC + "RNDConfig({})", "batch_size", "batch_size=0"),
    (RNDC + "RNDConfig({})", "lr", "lr=-1", "lr=float('nan')"),
    (RNDC + "RNDConfig({})", "update_every", "update_every=0"),
    (RNDC + "RNDConfig({})", "encoder_size", "encoder_size=0"),
    (RNDC + "RNDConfig({})", "seed", "seed=-1"),
    (RNDC + "RNDConfig({})", "background", "background='no'"),
    (RNDC + "RNDConfig({})", "learning_starts", "learning_starts=-1"),
    (RNDC + "RNDConfig({})", "nope", "nope=1"),
    (CURC + "CuriosityConfig({})", "batch_size", "batch_size=1"),
    (CURC + "CuriosityConfig({})", "num_filters", "num_filters=0"),
    (CURC + "CuriosityConfig({})", "encoder_tau", "encoder_tau=2"),
    (CURC + "CuriosityConfig({})", "transition_weight", "transition_weight=-1"),
    (CURC + "CuriosityConfig({})", "random_conv_kernel", "random_conv_kernel=2"),
    (CURC + "CuriosityConfig({})", "interactive", "interactive='yes'"),
    (CURC + "CuriosityConfig({})", "capacity", "capacity=1.5"),
    (PZ + "SPO(pz, {})", "size", "size=(16, 0)"),
    (PZ + "SPO(pz, {})", "fold_frames", "fold_frames='x'"),
    (PZ + "SPO(pz, {})", "motion", "motion=None"),
    (RESOLVE + "resolve({})", "preset", "'', {}", "3, {}"),
    (RESOLVE + "resolve({})", "overrides", "'cpu', None"),
    (RESOLVE + "resolve({})", "agent", "'cpu', {'agent': {'lr': 1e-3}}"),
    (RESOLVE + "resolve({})", "lr", "'cpu', {'agent.lr': None}"),
    (RESOLVE + "resolve({})", "seed", "'cpu', {'seed': 1.5}"),
    (RESOLVE + "resolve({})", "CPU", "'CPU', {}"),
]  # fmt: skip
# (code, the name the refusal must give, or "" for valid input[, valid: either])
FIFTH_CODES = [
    # the agent: saving, loading, states of another agent or damaged
    (AGENT + f"a = {A}; a.save('agent.pt')", ("save", "state_dict")),
    (AGENT + f"import torch; torch.save({A}.state_dict(), 'a.pt'); b = {A}; "
     f"b.load_state_dict(torch.load('a.pt')); b.act({FRAMES})", ""),
    (AGENT + f"import torch; torch.save({A}.state_dict(), 'a.pt'); b = {A}; "
     f"b.load_state_dict(torch.load('a.pt', weights_only=False)); b.act({FRAMES})", ""),
    (STATE + "s['num_updates'] = 'x'" + LOAD, "num_updates"),
    (STATE + "s.pop('running_max')" + LOAD, "running_max"),
    (AGENT + "s = SimounAgent((3, 32, 32), 2, cfg, device='cpu').state_dict()" + LOAD,
     ("action_dim", "(2")),
    (STATE + "s['critic'] = {k: v.numpy() for k, v in s['critic'].items()}" + LOAD, "critic"),
    (STATE + "s['log_alpha'] = 0.1" + LOAD, "log_alpha"),
    (STATE + "s['critic_optimizer'] = {}" + LOAD, "critic_optimizer"),
    (STATE + "s['running_max'] = None" + LOAD, "running_max"),
    (AGENT + f"pickle.loads(pickle.dumps({A}.state_dict()))", ""),
    (AGENT + f"import copy; copy.deepcopy({A}).act({FRAMES})", ""),
    # the agent: act, update and encoder_features given odd values
    (AGENT + f"{A}.act({FRAMES}, deterministic=np.bool_(True))", ""),
    (AGENT + f"{A}.act({FRAMES}, step=np.int64(5))", ""),
    (AGENT + f"import torch; {A}.act(torch.zeros((3, 3, 32, 32)))", "uint8"),
    (AGENT + f"r = FrameReplay(100, (3, 32, 32), 1); r.start_episode({FRAME}); [r.add(np.zeros("
     f"1), 0.0, {FRAME}, False, False) for _ in range(3)]; {A}.update(r, 3)", "batch_size", True),
    (AGENT + FILLED + f"{A}.update(r, np.int64(9))", ""),
    (AGENT + FILLED + f"{A}.update(r, True)", "step"),
    (AGENT + FILLED + f"{A}.update(r, 2**70)", "step"),
    (AGENT + f"{A}.update(FrameReplay(100, (3, 32, 32), 2), 0)", ("action", "2")),
    (AGENT + "import dataclasses; SimounAgent((3, 32, 32), 1, dataclasses.replace(cfg, "
     "encoder='single'), device='cpu').encoder_features(np.zeros((2, 3, 3, 32, 32), np.uint8))",
     ("encoder_features", "dual")),
    (AGENT + "SimounAgent((1, 32, 32), 1, cfg, device='cpu').act(np.zeros((3, 1, 32, 32), "
     "np.uint8))", ""),
    (AGENT + "import torch; SimounAgent((3, 32, 32), 1, cfg, device=torch.device('cpu')).act("
     f"{FRAMES})", ""),
    (AGENT + "SimounAgent((3, 32, 32), 1, cfg, device='cuda')", ("cuda", "device")),
    (AGENT + "SimounAgent((3, 48, 64), 1, cfg, device='cpu').act(np.zeros((3, 3, 48, 64), "
     "np.uint8))", ""),
    # the replay: episodes, actions, flags, frames, sampling, files and sizes
    (AGENT + f"r = FrameReplay(100, (3, 32, 32), 1); r.start_episode({FRAME}); "
     f"r.start_episode({FRAME})", "start_episode", True),
    (AGENT + ADD.format(f"[0.1, 0.2], 0.0, {FRAME}, False, False"), "action"),
    (AGENT + ADD.format(f"np.zeros((1, 1)), 0.0, {FRAME}, False, False"), ""),
    (AGENT + ADD.format(f"np.zeros(1), None, {FRAME}, False, False"), "reward"),
    (AGENT + ADD.format(f"np.zeros(1), 0.0, {FRAME}, np.bool_(True), False"), ""),
    (AGENT + ADD.format(f"np.zeros(1), 0.0, {FRAME}, 1, 0"), "terminated", True),
    (AGENT + ADD.format(f"np.zeros(1), 0.0, {FRAME}.tolist(), False, False"),
     ("next_frame", "uint8")),
    (AGENT + ADD.format("np.zeros(1), 0.0, np.zeros((32, 32, 3), np.uint8), False, False"),
     ("(3, 32, 32)", "next_frame")),
    (AGENT + FILLED + "r.sample(4, n_step=0)", "n_step"),
    (AGENT + FILLED + "r.sample(4, n_step=3, discount=1.5)", "discount"),
    (AGENT + FILLED + "r.sample(4, discount=float('nan'))", "discount"),
    (AGENT + FILLED + "r.sample(4, n_step=2.5)", "n_step"),
    (AGENT + FILLED + "r.sample(np.int64(4))", ""),
    (AGENT + FILLED + "r.save('x'); FrameReplay.load('x').sample(4)", ""),
    (AGENT + FILLED + "r.save('x.npz'); FrameReplay(50, (3, 32, 32), 1).load('x.npz')",
     "capacity"),
    (AGENT + "import io; FrameReplay.load(io.BytesIO(b''))", ("damaged", "empty", "replay")),
    (AGENT + FILLED + "r.save(None)", "path"),
    (AGENT + FILLED + "r.save('.')", "directory"),
    (AGENT + f"r = FrameReplay(100, (3, 32, 32), 1, num_frames=2); r.start_episode({FRAME}); "
     f"[r.add(np.zeros(1), 0.0, {FRAME}, False, False) for _ in range(5)]; r.sample(4)", ""),
    (AGENT + "FrameReplay(10**12, (3, 32, 32), 1)", ("capacity", "memory", "bytes")),
    (AGENT + "FrameReplay(100, np.array([3, 32, 32]), 1)", ""),
    (AGENT + "FrameReplay(100, (3, 32, 32), np.int64(1), seed=np.int64(3))", ""),
    (AGENT + FILLED + "r.save('r.npz'); import os; os.truncate('r.npz', 100); "
     "FrameReplay.load('r.npz')", "r.npz"),
    (AGENT + "import io; b = io.BytesIO(); " + FILLED + "r.save(b); b.seek(0); "
     "FrameReplay.load(b).sample(4)", ""),
    # the online models on odd observation spaces, configs, calls and states
    (RND + f"RNDModel.for_env(w.SimounObservation({P}, size=64, fold_frames=True))", ""),
    (RND + "RNDModel.for_env(gym.make('Pendulum-v1'))", ("SimounObservation", "triplet")),
    (RND + f"m = RNDModel.for_env({M64}); m.close()", ""),
    (RNDC + f"RNDModel.for_env({S64}, RNDConfig(feature_dim=0))", "feature_dim"),
    (RND + f"RNDModel.for_env({S64}, config={{'lr': 1e-3}})", "config"),
    (RND + f"RNDModel.for_env({S64}, device='tpu')", "device"),
    (CUR + f"m = CuriosityModel.for_env({C64}); m.close()", ""),
    (CUR + f"m = CuriosityModel.for_env(w.SimounObservation({BJ}, size=64)); m.close()", ""),
    (CUR + f"m = CuriosityModel.for_env({vec1(wrap='w.SimounObservation(e, size=64)')}); "
     "m.close()", ""),
    (CUR + f"m = CuriosityModel.for_env(w.SimounObservation({P}, size=64, grayscale=True)); "
     "m.close()", ""),
    (RND + f"m = RNDModel.for_env({S64}); m(np.zeros((2, 3, 3, 64, 64), np.float32))", "uint8"),
    (RND + f"m = RNDModel.for_env({S64}); m(np.zeros((2, 3, 3, 64, 64), np.uint8).tolist())",
     ("uint8", "triplets")),
    (RND + f"m = RNDModel.for_env({S64}); m.load_state_dict({{}})", "state"),
    (RND + f"m = RNDModel.for_env({S64}); m.close(); m.close()", ""),
    (RND + f"m = RNDModel.for_env({S64}); z = np.zeros((2, 3, 3, 64, 64), np.uint8); "
     "m.watch(z, np.zeros((2, 1)), z[:1], np.zeros(2, bool), np.zeros(2, bool))",
     "next_triplets"),
    (CUR + f"m = CuriosityModel.for_env({S64}); z = np.zeros((2, 3, 3, 64, 64), np.uint8); "
     "m.watch(z, np.zeros((2, 1)), z, np.zeros(3, bool), np.zeros(2, bool))", "terminated"),
    (CUR + f"s = CuriosityModel.for_env({S64}).state_dict(); CuriosityModel.for_env("
     f"w.SimounObservation({P}, size=48)).load_state_dict(s)", ("state", "shape")),
    (RND + f"m = RNDModel.for_env({S64}); pickle.loads(pickle.dumps(m))", "", True),
    # random_conv given odd values
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), clamp=[0, 1])", "clamp", True),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), clamp=(0, float('inf')))", "clamp",
     True),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), clamp=(True, 1))", "clamp"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), generator=np.random.default_rng(0))",
     "generator"),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), kernel_size=np.int64(3))", ""),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8, dtype=torch.bfloat16))", ""),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8, requires_grad=True)).sum().backward()",
     ""),
    ("import torch; w.random_conv(torch.zeros(2, 0, 8, 8))", ("channel", "C"), True),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8)[:, :, ::2])", ""),
    ("import torch; w.random_conv(torch.zeros(2, 3, 8, 8), kernel_size=5, "
     "generator=torch.Generator().manual_seed(0))", ""),
    # resolve, from_dict and TrainConfig
    (RESOLVE + "resolve('highway', {'env': 'Pendulum-v1'})", ("highway", "preset"), True),
    (RESOLVE + "resolve('cpu', {'total_env_steps': '100'})", "total_env_steps", True),
    (RESOLVE + "resolve('cpu', {'agent.recipe': 'drqv2', 'agent.n_step': 1})", "n_step", True),
    ("from simoun_agent.config import from_dict; from_dict({'agent': []})", "agent"),
    ("from simoun_agent.config import from_dict; from_dict({'nope': 1})", "nope"),
    ("from simoun_agent.config import TrainConfig; TrainConfig(image_size=8)", "image_size"),
    ("from simoun_agent.config import TrainConfig; TrainConfig(env=3)", "env"),
    ("from simoun_agent.config import TrainConfig; TrainConfig(agent={'lr': 1e-3})", "agent"),
    # check_sb3_policy on spaces and policy classes
    ("w.check_sb3_policy(gym.spaces.Box(0, 255, (84, 84, 3), np.uint8), 'CnnPolicy')", ""),
    ("w.check_sb3_policy(gym.spaces.Box(0, 255, (3, 84, 84), np.uint8), 'CnnPolicy')", ""),
    ("w.check_sb3_policy(gym.spaces.Box(0, 1, (84, 84, 3), np.float32), 'CnnPolicy')",
     ("uint8", "normalize_images")),
    ("w.check_sb3_policy(gym.spaces.Dict({'a': gym.spaces.Discrete(2)}), 'MlpPolicy')",
     "MultiInputPolicy"),
    ("import stable_baselines3; w.check_sb3_policy(gym.spaces.Box(-1, 1, (3,)), "
     "stable_baselines3.PPO)", "policy"),
    ("from stable_baselines3.common.policies import ActorCriticCnnPolicy; w.check_sb3_policy("
     "gym.spaces.Box(0, 255, (84, 84, 3), np.uint8), ActorCriticCnnPolicy)", ""),
    ("w.check_sb3_policy(gym.spaces.Text(5), 'MlpPolicy')", "Text"),
    ("w.check_sb3_policy(gym.spaces.Box(0, 255, (16, 16, 3), np.uint8), 'CnnPolicy')", "36"),
    # wrappers' arguments
    (f"e = w.SimounObservation({P}, size=(16, 16), grayscale=True, fold_frames=True); " + STEP,
     ""),
    (f"w.SimounObservation({P}, num_frames=1)", ("num_frames", "motion"), True),
    (f"e = w.SimounObservation({P}, size=16, num_frames=1, motion=False); " + STEP, ""),
    (f"e = w.SimounObservation({P}, size=np.array([16, 16])); " + STEP, "size", True),
    (f"e = w.ActionRepeat({P}, repeat=2); " + STEP, ""),
    (f"w.ActionRepeat({P})", "repeat"),
    (f"e = w.MultiCamera({P}, cameras=[lambda e: e.render()], size=(16, 32)); " + STEP, ""),
    (f"w.MultiCamera({P}, cameras=[lambda e: e.render().astype(np.float32)], size=16)"
     ".reset(seed=0)", ("uint8", "camera")),
    (DMC + "e = w.ColorShift(w.SimounObservation(d, size=16)); " + STEP, ""),
    (DMC + "import os; os.mkdir('v'); open('v/a.txt', 'w').write('x'); "
     "w.MovingBackground(d, videos='v').reset(seed=0)", ("videos", "video")),
    (DMC + "e = w.ColorShift(d, level='hard'); " + STEP, ""),
    (f"e = w.RandomConvolution({P}, kernel_size=31); " + STEP, ""),
    # intrinsic rewards stacked with Gymnasium's wrappers, in either order
    (f"e = gym.wrappers.NormalizeReward(w.ConstantBonusReward({S}, 0.1)); " + STEP, ""),
    (f"e = w.ConstantBonusReward(gym.wrappers.NormalizeReward({S}), 0.1); " + STEP, ""),
    (f"e = gym.wrappers.RecordEpisodeStatistics(w.ConstantBonusReward({S}, 0.1)); " + STEP, ""),
    (f"e = w.ConstantBonusReward(gym.wrappers.RecordEpisodeStatistics({S}), 0.1); " + STEP, ""),
    (f"e = gym.wrappers.FrameStackObservation(w.ConstantBonusReward({S}, 0.1), 2); " + STEP, ""),
    (f"w.ConstantBonusReward(gym.wrappers.FrameStackObservation({S}, 2), 0.1)",
     ("FrameStackObservation", "triplet")),
    (NOV + f"e = w.RNDReward(gym.wrappers.NormalizeReward({S}), nov, warmup=0); " + STEP, ""),
    (NOV + f"e = gym.wrappers.NormalizeReward(w.RNDReward({S}, nov, warmup=0)); " + STEP, ""),
    (FEAT + f"e = w.ConsistencyCuriosityReward(gym.wrappers.RecordEpisodeStatistics({S}), feat); "
     + STEP, ""),
    (FEAT + f"e = gym.wrappers.RecordEpisodeStatistics(w.ConsistencyCuriosityReward({S}, feat)); "
     + STEP, ""),
    (NOV + f"e = gym.wrappers.ClipReward(w.RNDReward({S}, nov, warmup=0), -1, 1); " + STEP, ""),
    (EPISODE_RETURN, ""),
    *((f"v = gym.wrappers.vector.NormalizeReward(w.ConstantBonusVectorReward({vec(mode)}, 0.1)); "
       + STEPS3, "") for mode in ("NEXT_STEP", "SAME_STEP")),
    *((f"v = w.ConstantBonusVectorReward(gym.wrappers.vector.RecordEpisodeStatistics("
       f"{vec(mode)}), 0.1); " + STEPS3, "") for mode in ("NEXT_STEP", "SAME_STEP")),
    *((NOV + "v = w.RNDVectorReward(gym.wrappers.vector.NormalizeReward("
       + vec(mode, "CartPole-v1") + "), nov, warmup=0); " + STEPS3, "")
      for mode in ("NEXT_STEP", "SAME_STEP")),
    # the vector forms: rewards at the autoreset steps as documented, DISABLED, async, copies
    (BONUS_AT_RESETS.format(vec=vec_mode("NEXT_STEP"), want="np.where(ended, 0.0, 0.1)"), ""),
    (BONUS_AT_RESETS.format(vec=vec_mode("SAME_STEP"), want="np.full(2, 0.1)"), ""),
    (f"v = w.ConstantBonusVectorReward({vec_mode('DISABLED')}, 0.1); v.reset(seed=0)\n"
     "for _ in range(40):\n"
     "    _, r, t, u, i = v.step(np.ones(2, np.int64)); e = t | u\n"
     "    if e.any(): v.reset(options={'reset_mask': e})\n", ""),
    (NOV + f"v = w.RNDVectorReward({vec1('CartPole-v1', mode='async')}, nov, warmup=0); "
     + STEPS3 + "; v.close()", ""),
    *((f"import copy; v = w.ConstantBonusVectorReward({vec(mode, 'MiniGrid-Empty-5x5-v0')}, "
       "0.1); c = copy.deepcopy(v); " + STEPS3.replace("v.", "c."), "")
      for mode in ("NEXT_STEP", "SAME_STEP")),
    (f"import copy; v = w.ConstantBonusVectorReward({vec('NEXT_STEP', 'MiniGrid-Empty-5x5-v0')}"
     ", 0.1); v.reset(seed=0); c = copy.deepcopy(v); c.step(np.zeros(2, np.int64))", ""),
    # gym.make(spec) re-making a wrapped env
    (f"e = gym.make(w.SimounObservation({P}, size=16).spec); " + STEP, ""),
    (f"e = gym.make(w.ActionRepeat({P}, 2).spec); " + STEP, ""),
    (f"e = gym.make(w.FrameTriplet({P}).spec); " + STEP, ""),
    (f"e = gym.make(w.RandomConvolution({P}).spec); " + STEP, ""),
    (f"e = gym.make(w.ConstantBonusReward({S}, 0.1).spec); e.reset(seed=0); "
     "assert 'reward_intrinsic' in e.step(e.action_space.sample())[4]", ""),
    (NOV + f"e = gym.make(w.RNDReward({S}, nov, warmup=0).spec); " + STEP, ""),
    (FEAT + f"e = gym.make(w.ConsistencyCuriosityReward({S}, feat).spec); " + STEP, ""),
    (f"import operator; e = gym.make(w.MultiCamera({P}, cameras=[operator.methodcaller("
     "'render')], size=16).spec); " + STEP, ""),
    (DMC + "e = gym.make(w.ColorShift(d, seed=0).spec); " + STEP, ""),
    (f"e = gym.make({MS}.spec); " + STEP, ""),
    (f"w.SimounObservation({P}, size=16).spec.to_json()", ""),
    # copies of wrappers after steps, on an env that pickles (MiniGrid renders with numpy)
    (f"e = {MS}; {STEP}; c = pickle.loads(pickle.dumps(e)); " + STEP_COPY, ""),
    (f"import copy; e = w.RandomConvolution({M}); {STEP}; c = copy.deepcopy(e); " + STEP_COPY,
     ""),
    (f"e = w.ConstantBonusReward({MS}, 0.1); {STEP}; c = pickle.loads(pickle.dumps(e)); "
     + STEP_COPY, ""),
    (NOV + f"e = w.RNDReward({MS}, nov, warmup=0); {STEP}; c = pickle.loads(pickle.dumps(e)); "
     + STEP_COPY, ""),
    (f"e = w.ActionRepeat({M}, 2); {STEP}; c = pickle.loads(pickle.dumps(e)); " + STEP_COPY, ""),
    (RND + f"import copy; m = RNDModel.for_env({M64}); e = w.RNDReward({M64}, m, warmup=0); "
     f"{STEP}; c = copy.deepcopy(e); " + STEP_COPY, ""),
]  # fmt: skip
FIFTH_API_CASES = [
    *(api(code.format(value), names) for code, names, *values in FIFTH_REFUSED
      for value in values),
    *(api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in FIFTH_CODES),
]  # fmt: skip
FIFTH_COMMAND_CASES = FIFTH_FLAG_CASES + FIFTH_FILE_CASES + FIFTH_SPEC_CASES
for _case in FIFTH_COMMAND_CASES + FIFTH_API_CASES:
    _case["set"] = "fifth"


CASES = (
    FLAG_CASES + FILE_CASES + SPEC_CASES + API_CASES + SECOND_COMMAND_CASES + SECOND_API_CASES
    + THIRD_COMMAND_CASES + THIRD_API_CASES + FOURTH_COMMAND_CASES + FOURTH_API_CASES
    + FIFTH_COMMAND_CASES + FIFTH_API_CASES
)  # fmt: skip


AREAS = ("agent", "lab", "files", "api")
"""the areas of a trial kept as modules: ``reliability_<trial>_<area>.py`` in this directory"""
MODULE_TRIALS = ("sixth", "seventh", "eighth", "ninth", "tenth", "eleventh")
"""the trials whose cases live in those modules, each with a list ``CASES`` made with this
module's helpers (imported when the trial is selected: they import this module)"""


def module_cases(trial: str) -> list[dict]:
    """Every case of ``trial``'s modules, marked as that trial's."""
    import importlib

    cases = []
    for area in AREAS:
        for case in importlib.import_module(f"reliability_{trial}_{area}").CASES:
            case["set"] = trial
            cases.append(case)
    return cases


def tiny_run(where: Path) -> Path:
    """A tiny finished simoun-train run (40 env steps, PointReach 32x32)."""
    from simoun_agent.cli import train

    run = where / "tiny"
    status = train.main([*TINY, "--total-env-steps", "40", "--run-dir", str(run)])
    assert status == 0, status
    return run


def prepare(case: dict, here: Path, run: Path) -> list[str]:
    """Lay out ``here`` for ``case``; its argv with {run} filled."""
    shutil.copytree(run, here / "run")
    (here / "spec.toml").write_text(SPEC)
    setup = case.get("setup")
    if setup and setup[0] == "spec":
        suffix, text = setup[1]
        (here / f"spec{suffix}").write_text(text)
    elif setup and setup[0] == "sweep":
        (here / "sweep.json").write_bytes(setup[1])
    elif setup and setup[0] == "call":
        setup[1](here)
    elif setup:
        damage(here / "run", *setup)
    return [arg.replace("{run}", str(here / "run")) for arg in case["argv"]]


def child(case: dict, here: Path, run: Path, out: Path) -> None:
    os.chdir(here)
    fd = os.open(out, os.O_WRONLY | os.O_CREAT)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    status: object = 0
    kinds = ""  # the error's class and its bases, for classify
    if case.get("guard"):
        os.environ["RAY_ADDRESS"] = GUARD
    try:
        if "code" in case:
            import pickle

            import simoun_wrappers as w

            exec(case["code"], {"gym": gym, "np": np, "w": w, "pickle": pickle})
        else:
            import importlib

            argv = prepare(case, here, run)
            status = importlib.import_module(COMMANDS[case["command"]]).main(argv)
    except SystemExit as stop:
        status = stop.code
    except Exception as err:  # the API's errors, read below
        origin = traceback.extract_tb(err.__traceback__)[-1].filename
        status = f"{type(err).__name__} from {origin}: {err}"
        if type(err).__module__.startswith("simoun"):
            kinds = " ".join(kind.__name__ for kind in type(err).__mro__)
    sys.stdout.flush()
    sys.stderr.flush()
    with open(out, "a") as f:
        f.write(f"\n@@KINDS {kinds}\n@@STATUS {status}\n")
    os._exit(0)


def named(case: dict, text: str) -> bool:
    """Whether ``text`` names what ``case`` is about (one of its names, where it has several)."""
    names = case["names"]
    return any(name in text for name in ((names,) if isinstance(names, str) else names))


def classify(case: dict, text: str, timed_out: bool) -> tuple[str, str]:
    """(clear | unclear | wrong, the message's first line)."""
    status = text.rpartition("@@STATUS ")[2].strip() if "@@STATUS" in text else "?"
    body, mark, kinds = text.rpartition("@@STATUS")[0].rpartition("\n@@KINDS ")
    body, kinds = (body, kinds) if mark else (kinds, "")
    lines = [line for line in body.splitlines() if "error" in line.lower() or "Error" in line]
    message = lines[-1] if lines else status
    if timed_out:
        return ("clear" if case["ok"] else "wrong"), "still running after its checks"
    if GUARD in body:
        return ("clear" if case["ok"] else "wrong"), "went on to start Ray (stopped by the guard)"
    if "Traceback" in body:
        return "wrong", message
    if "code" in case:
        if status == "0":
            return ("clear" if case["ok"] else "wrong"), "accepted"
        kind, _, rest = status.partition(" from ")
        inside = "/site-packages/" in rest.partition(":")[0]
        # an error class of the project's own counts as the refusal it derives from (Damaged is
        # a ValueError): the child lists the class and its bases
        # an ImportError naming the module that holds a name is the packages' refusal of a name
        # imported from the wrong one
        refusals = {"ValueError", "TypeError", "ResetNeeded", "SetupError", "FileNotFoundError",
                    "InvalidAction", "Error", "ImportError"}  # fmt: skip
        if inside or not {kind, *kinds.split()} & refusals:
            return "wrong", status
        if case["ok"]:  # valid input may be refused only where the case names what for
            return ("clear" if case["names"] and named(case, status) else "wrong"), status
        return ("clear" if named(case, status) else "unclear"), status
    if status in ("0", "None"):
        return ("clear" if case["ok"] else "wrong"), "accepted"
    if named(case, body):
        return "clear", message
    return "unclear", message


def run_case(case: dict, work: Path, run: Path, index: int, timeout: float) -> tuple[str, str]:
    here = work / f"case{index}"
    here.mkdir()
    out = here.with_suffix(".out")
    process = multiprocessing.get_context("fork").Process(target=child, args=(case, here, run, out))
    process.start()
    process.join(timeout)
    timed_out = process.is_alive()
    if timed_out:
        process.kill()
        process.join()
    text = out.read_text(errors="replace") if out.exists() else ""
    shutil.rmtree(here, ignore_errors=True)
    return classify(case, text, timed_out)


def one_line(text: str) -> str:
    """``text`` on one line, for a table row (code and messages may span several)."""
    return text.replace("\n", "\\n")


def describe(case: dict) -> str:
    if "code" in case:
        return case["code"]
    return f"{case['command']} {' '.join(case['argv'])}" + (
        f" [{case['what']}]" if "what" in case else ""
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--area", choices=("flags", "files", "specs", "api"), action="append")
    parser.add_argument(
        "--command", choices=(*COMMANDS, "api"), action="append", help="only its cases"
    )
    parser.add_argument(
        "--set",
        choices=("first", "second", "third", "fourth", "fifth", *MODULE_TRIALS),
        help="only that trial's cases (default: all)",
    )
    parser.add_argument(
        "--only",
        type=lambda text: {int(i) for i in text.split(",")},
        help="only these cases, by their numbers in the selection, e.g. 0,5,12",
    )
    parser.add_argument(
        "--timeout", type=float, default=20.0, help="seconds a case may run (default: 20)"
    )
    parser.add_argument("--markdown", type=Path, help="also write the table here")
    args = parser.parse_args()
    for name in COMMANDS.values():  # imported once, before the children fork
        __import__(name)
    every = CASES + [
        case for trial in MODULE_TRIALS if args.set in (None, trial) for case in module_cases(trial)
    ]
    cases = [
        case
        for case in every
        if (args.area is None or case["area"] in args.area)
        and (args.command is None or case.get("command", "api") in args.command)
        and (args.set is None or case.get("set", "first") == args.set)
    ]
    numbers = [i for i in range(len(cases)) if args.only is None or i in args.only]
    counts = {"clear": 0, "unclear": 0, "wrong": 0}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        run = tiny_run(work)
        for index in numbers:
            case = cases[index]
            start = time.monotonic()
            verdict, message = run_case(case, work, run, index, args.timeout)
            counts[verdict] += 1
            rows.append((index, case["area"], describe(case), verdict, message))
            print(f"{index}\t{case['area']}\t{verdict}\t{time.monotonic() - start:.0f} s\t"
                  f"{describe(case)[:110]}\t{message[:200]}", flush=True)  # fmt: skip
    print(f"cases {len(numbers)}: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    if args.markdown:
        from simoun_agent import table

        args.markdown.write_text(
            table.markdown_table(
                ["#", "area", "case", "verdict", "message"],
                [
                    [str(i), a, f"`{one_line(d)}`", v, one_line(m).replace("|", "/")]
                    for i, a, d, v, m in rows
                ],
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
