"""A reliability trial: inputs a new user gets wrong, run against the commands, the wrappers'
Python API and the files users keep, each classified by what the user is told.

    python scripts/reliability_trial.py                 # every case, a table on stdout
    python scripts/reliability_trial.py --area files    # one area
    python scripts/reliability_trial.py --area flags --command sweep   # one command's cases
    python scripts/reliability_trial.py --markdown out.md

Each case runs in a forked child in a directory of its own (a copy of a tiny trained run where
it needs one) and is stopped after 20 s (``--timeout``; spec cases that import Ray want about 90 s
on a loaded machine): a case that passes its checks is not left to train.
A case is

- clear: refused with status 2 (a command) or a ValueError/TypeError-like error (the API), the
  message naming the argument, flag or file the case is about, no traceback; or, for a case
  marked ``ok`` (valid input, or a file the command does not need), it went on without error;
- unclear: refused, but the message does not name what the case is about;
- wrong: a traceback, an error from inside a library, accepted where it must be refused, or
  still running where it should have been refused (work started).

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

CASES = FLAG_CASES + FILE_CASES + SPEC_CASES + API_CASES + SECOND_COMMAND_CASES + SECOND_API_CASES


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
    elif setup:
        damage(here / "run", *setup)
    return [arg.replace("{run}", str(here / "run")) for arg in case["argv"]]


def child(case: dict, here: Path, run: Path, out: Path) -> None:
    os.chdir(here)
    fd = os.open(out, os.O_WRONLY | os.O_CREAT)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    status: object = 0
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
    sys.stdout.flush()
    sys.stderr.flush()
    with open(out, "a") as f:
        f.write(f"\n@@STATUS {status}\n")
    os._exit(0)


def named(case: dict, text: str) -> bool:
    """Whether ``text`` names what ``case`` is about (one of its names, where it has several)."""
    names = case["names"]
    return any(name in text for name in ((names,) if isinstance(names, str) else names))


def classify(case: dict, text: str, timed_out: bool) -> tuple[str, str]:
    """(clear | unclear | wrong, the message's first line)."""
    status = text.rpartition("@@STATUS ")[2].strip() if "@@STATUS" in text else "?"
    body = text.rpartition("@@STATUS")[0]
    lines = [line for line in body.splitlines() if "error" in line.lower() or "Error" in line]
    message = lines[-1] if lines else status
    if timed_out:
        return ("clear" if case["ok"] else "wrong"), "still running after its checks"
    if "Traceback" in body:
        return "wrong", message
    if "code" in case:
        if status == "0":
            return ("clear" if case["ok"] else "wrong"), "accepted"
        if case["ok"]:
            return "wrong", status
        kind, _, rest = status.partition(" from ")
        inside = "/site-packages/" in rest.partition(":")[0]
        if inside or kind not in {"ValueError", "TypeError", "ResetNeeded", "SetupError",
                                   "FileNotFoundError", "InvalidAction", "Error"}:  # fmt: skip
            return "wrong", status
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
        "--set", choices=("first", "second"), help="only that trial's cases (default: all)"
    )
    parser.add_argument(
        "--timeout", type=float, default=20.0, help="seconds a case may run (default: 20)"
    )
    parser.add_argument("--markdown", type=Path, help="also write the table here")
    args = parser.parse_args()
    for name in COMMANDS.values():  # imported once, before the children fork
        __import__(name)
    cases = [
        case
        for case in CASES
        if (args.area is None or case["area"] in args.area)
        and (args.command is None or case.get("command", "api") in args.command)
        and (args.set is None or case.get("set", "first") == args.set)
    ]
    counts = {"clear": 0, "unclear": 0, "wrong": 0}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        run = tiny_run(work)
        for index, case in enumerate(cases):
            start = time.monotonic()
            verdict, message = run_case(case, work, run, index, args.timeout)
            counts[verdict] += 1
            rows.append((index, case["area"], describe(case), verdict, message))
            print(f"{index}\t{case['area']}\t{verdict}\t{time.monotonic() - start:.0f} s\t"
                  f"{describe(case)[:110]}\t{message[:200]}", flush=True)  # fmt: skip
    print(f"cases {len(cases)}: " + ", ".join(f"{k} {v}" for k, v in counts.items()))
    if args.markdown:
        from simoun_agent import table

        args.markdown.write_text(
            table.markdown_table(
                ["#", "area", "case", "verdict", "message"],
                [[str(i), a, f"`{d}`", v, m.replace("|", "/")] for i, a, d, v, m in rows],
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
