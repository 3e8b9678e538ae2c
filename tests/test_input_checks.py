"""Inputs a new user gets wrong, refused before anything is spent and named with a fix that
works: paths that do not exist, keys given twice, misspelled names and values, switches given a
word that is not true/false, wrong types and vector envs given to the wrappers; and the
command-line conventions (--version, a pipe closed early, --no-progress still reporting)."""

import csv
import json
import pickle
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import gymnasium as gym
import minigrid  # noqa: F401  (registers the MiniGrid-* ids)
import numpy as np
import pytest
from flag_lists import override
from gymnasium.wrappers import TransformReward
from test_cli_conventions import TINY

from simoun_agent.cli import eval as eval_cli
from simoun_agent.cli import train as train_cli
from simoun_agent.cli.config_flags import check_given_once, overrides_from
from simoun_agent.config import resolve, to_dict
from simoun_agent.run import memory
from simoun_agent.run.logger import read_csv
from simoun_lab.cli import report as report_cli
from simoun_lab.minigrid_study import __main__ as minigrid_cli
from simoun_lab.sweep.report import write_report
from simoun_wrappers import (
    ActionRepeat,
    FrameTriplet,
    MultiCamera,
    RandomConvolution,
    SimounObservation,
    check_sb3_policy,
)

ROOT = Path(__file__).resolve().parents[1]


def refused(capsys, main, argv) -> str:
    """The error ``main`` prints for ``argv``, refused with status 2 (exit or return)."""
    try:
        status = main(argv)
    except SystemExit as stop:
        status = stop.code
    assert status == 2
    return capsys.readouterr().err


# paths that do not exist are refused, never made up


def test_a_mistyped_minigrid_archive_starts_nothing(tmp_path, capsys):
    typo = tmp_path / "minigridd"
    err = refused(capsys, minigrid_cli.main, ["run", "--archive", str(typo)])
    assert f"no study archive at --archive {typo}: no such directory" in err
    assert not typo.exists()
    err = refused(capsys, minigrid_cli.main, ["report", "--archive", str(tmp_path)])
    assert "holds no spec.json, so it is not a study's archive" in err


def test_the_minigrid_report_outside_the_clone_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    err = refused(capsys, minigrid_cli.main, ["report"])
    assert "no study archive at" in err and "from the root of a clone" in err
    err = refused(capsys, minigrid_cli.main, ["probe", "--probes", "rnd"])
    assert "does not exist" in err
    assert list(tmp_path.iterdir()) == []


def test_a_probe_named_twice_is_refused_before_probing(tmp_path, capsys):
    out = tmp_path / "probe"
    err = refused(capsys, minigrid_cli.main, ["probe", "--probes", "rnd", "rnd", "--out", str(out)])
    assert "--probes names rnd more than once; name each probe once" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("text", "kind"), [("[]", "an array"), ("null", "null"), ("3", "a number")]
)
def test_a_minigrid_spec_that_is_not_an_object_is_named(text, kind, tmp_path, capsys):
    spec = tmp_path / "spec.json"
    spec.write_text(text)
    argv = ["report", "--spec", str(spec), "--archive", str(tmp_path)]
    err = refused(capsys, minigrid_cli.main, argv)
    assert f"--spec {spec} holds {kind}, not the object of a study spec" in err


MINIGRID_SPEC = json.loads(Path("docs/studies/minigrid/spec.json").read_text())


@pytest.mark.parametrize(
    ("change", "said"),
    [
        ({"tasks": {}}, "tasks is {}, which must be a non-empty array of task objects"),
        ({"tasks": [{"steps": 5000, "seeds": [0]}]},
         "tasks[0]: no 'env_id'; give it: a registered MiniGrid id"),
        ({"tasks": [{**MINIGRID_SPEC["tasks"][0], "steps": "400k"}]},
         'tasks[0]: steps is "400k", which must be an int >= 1'),
        ({"tasks": [{**MINIGRID_SPEC["tasks"][0], "seeds": 3}]}, "tasks[0]: seeds is 3"),
        ({"tasks": [{**MINIGRID_SPEC["tasks"][0], "env_id": "Pendulum-v1"}]},
         'tasks[0]: env_id is "Pendulum-v1", which must be a registered MiniGrid id'),
        ({"ppo": []}, "ppo is [], which must be an object of PPO settings"),
        ({"ppo": {"learning_rate": "fast"}}, 'ppo: learning_rate is "fast", which must be a'),
        ({"arms": "ppo"}, 'arms is "ppo", which must be a non-empty array of arm names'),
        ({"evaluations": 0.5}, "evaluations is 0.5, which must be an int >= 1"),
        ({"device": "tpu"}, 'device is "tpu", which must be a torch device name'),
        ({"device": ["cpu"]}, 'device is ["cpu"], which must be a torch device name: cpu, cuda, '
         'cuda:N or mps, e.g. "device": "cpu"'),
        ({"ppo": {"n_steps": 128.0}},
         'ppo: n_steps is 128.0, which must be an int >= 1 (below 2**63), e.g. "n_steps": 128'),
        ({"tasks": [{**MINIGRID_SPEC["tasks"][0], "steps": [400000]}]},
         'tasks[0]: steps is [400000], which must be an int >= 1 (below 2**63), e.g. "steps": '
         "400000"),
    ],
)  # fmt: skip
def test_a_minigrid_spec_value_of_the_wrong_kind_is_named(change, said, tmp_path, capsys):
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps({**MINIGRID_SPEC, **change}))
    for command in ("report", "select"):
        err = refused(capsys, minigrid_cli.main, [command, "--spec", str(spec), "--archive", "."])
        assert f"{spec}: {said}" in err, err


def test_a_report_of_a_directory_that_does_not_exist_is_refused(tmp_path, capsys):
    err = refused(capsys, report_cli.main, [str(tmp_path / "nope")])
    assert f"{tmp_path / 'nope'} does not exist; pass a sweep directory" in err
    assert list(tmp_path.iterdir()) == []
    (tmp_path / "eval.csv").write_text("env_step,return_mean\n")
    err = refused(capsys, report_cli.main, [str(tmp_path / "eval.csv")])
    assert "eval.csv is a file, not a directory" in err


# every name a user types is checked; a key given twice is refused


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        (["--seed", "1", "--seed", "2"], "seed is given twice with different values"),
        (["--seed", "1", "--set", "seed=2"], "(--seed 1 and --set seed=2)"),
        (["--set", "agent.lr=1e-3", "--set", "agent.lr=2e-3"], "agent.lr is given twice"),
        (["--video", "--no-video"], "video is given twice"),
        (["--preset", "cpu", "--preset", "highway"], "--preset is given twice (cpu and highway)"),
        (["--preset", "cpux"], "unknown preset 'cpux' (did you mean 'cpu'?)"),
        (["--agent.encoder", "duall"], "must be a known name (did you mean 'dual'?)"),
        (["--video=maybe"], "--video is a switch: it takes true or false"),
        (["--learning-rate", "1e-3"], "--learning-rate: simoun-train calls it --agent.lr"),
        (["--agent.gamma=0.9"], "unknown flag --agent.gamma (did you mean --agent.discount?)"),
        (["--frame-skip", "4"], "--frame-skip: simoun-train calls it --action-repeat"),
        (["--xyzzy"], "unknown flag --xyzzy; `simoun-train --help` lists every flag"),
    ],
)
def test_the_command_line_refuses_with_the_fix(flags, said, tmp_path, capsys):
    err = refused(capsys, train_cli.main, [*TINY, "--run-dir", str(tmp_path / "r"), *flags])
    assert said in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()


def test_the_same_value_twice_is_harmless():
    check_given_once(["--seed", "3", "--video", "--progress=false", "--no-progress"], ["seed=3"])
    # a list key's flag is meant to be repeated
    check_given_once(["--eval-distraction", "color_easy", "--eval-distraction", "color_hard"], [])


def test_a_misspelled_sb3_policy_is_not_reported_as_fitting():
    env = SimounObservation(gym.make("MiniGrid-Empty-5x5-v0", render_mode="rgb_array"), size=40)
    folded = SimounObservation(
        gym.make("MiniGrid-Empty-5x5-v0", render_mode="rgb_array"), size=40, fold_frames=True
    )
    assert check_sb3_policy(folded, "CnnPolicy") == "CnnPolicy"
    for typo, match in (("CnnPolicyy", "'CnnPolicy'"), ("cnnpolicy", "'CnnPolicy'")):
        with pytest.raises(ValueError, match=f"did you mean {match}"):
            check_sb3_policy(folded, typo)
    with pytest.raises(TypeError, match="env must be a gymnasium Env"):
        check_sb3_policy("MiniGrid-Empty-5x5-v0", "CnnPolicy")
    env.close()
    folded.close()


# command-line conventions


def test_the_minigrid_study_answers_version(capsys):
    with pytest.raises(SystemExit) as stop:
        minigrid_cli.main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.startswith("python -m simoun_lab.minigrid_study ")


@pytest.mark.parametrize("module", ["simoun_lab.cli.report", "simoun_lab.minigrid_study"])
def test_a_pipe_closed_early_ends_quietly(module):
    # help is longer than a pipe's buffer only with many lines: read one byte and close
    with subprocess.Popen(
        [sys.executable, "-m", module, "--help"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=ROOT,
        env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin", "COLUMNS": "40"},
    ) as process:
        process.stdout.read(1)
        process.stdout.close()
        err = process.stderr.read().decode()
    assert "Traceback" not in err and "BrokenPipe" not in err


def test_no_progress_still_prints_a_line_per_evaluation(tmp_path, capsys):
    argv = [*TINY, "--run-dir", str(tmp_path / "r"), "--total-env-steps", "40", "--no-progress"]
    assert train_cli.main([*argv, "--no-video"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "/40: eval return" in line]
    steps = [int(row["env_step"]) for row in read_csv(tmp_path / "r" / "eval.csv")]
    assert len(steps) >= 2
    assert [line.split("/")[0] for line in lines] == [f"env step {step}" for step in steps]


# wrappers behave like gymnasium's


def minigrid_pixels() -> gym.Env:
    return gym.make("MiniGrid-Empty-5x5-v0", render_mode="rgb_array")


@pytest.mark.parametrize(
    "wrap",
    [
        lambda env: SimounObservation(env, size=24),
        lambda env: SimounObservation(env, size=24, fold_frames=True, grayscale=True),
        lambda env: SimounObservation(RandomConvolution(ActionRepeat(env, 2)), size=24),
    ],
)
def test_wrappers_pickle_when_the_env_does(wrap):
    env = wrap(minigrid_pixels())
    env.reset(seed=0)
    env.step(0)
    copy = pickle.loads(pickle.dumps(env))
    assert copy.observation_space == env.observation_space
    assert copy.spec == env.spec
    first, _ = copy.reset(seed=1)
    assert copy.observation_space.contains(first)
    copy.step(0)


@pytest.mark.parametrize(
    ("build", "said"),
    [
        (
            lambda: SimounObservation("MiniGrid-Empty-5x5-v0"),
            "env must be a gymnasium.Env, got str",
        ),
        (lambda: SimounObservation(minigrid_pixels(), size=24.5), "size must be a positive int"),
        (lambda: FrameTriplet(minigrid_pixels(), "3"), "num_frames must be a positive int"),
        (lambda: ActionRepeat(None, 2), "ActionRepeat's env must be a gymnasium.Env, got NoneType"),
    ],
)
def test_wrong_argument_types_name_the_argument(build, said):
    with pytest.raises((TypeError, ValueError)) as error:
        build()
    assert said in str(error.value)


@pytest.mark.parametrize(
    ("wrapper", "wrap"),
    [
        ("SimounObservation", lambda env: SimounObservation(env, size=24)),
        ("ActionRepeat", lambda env: ActionRepeat(env, 2)),
        ("FrameTriplet", FrameTriplet),
        ("MultiCamera", lambda env: MultiCamera(env, [lambda e: e.render()])),
    ],
)
def test_a_vector_env_is_told_to_wrap_each_sub_env(wrapper, wrap):
    envs = gym.make_vec("MiniGrid-Empty-5x5-v0", 2, render_mode="rgb_array")
    with pytest.raises(TypeError, match=rf"wrap each sub-env .*wrappers=\[lambda e: {wrapper}"):
        wrap(envs)
    envs.close()


def test_action_repeat_never_turns_finite_rewards_into_inf():
    env = ActionRepeat(TransformReward(minigrid_pixels(), lambda _: 1e308), 4)
    env.reset(seed=0)
    reward = env.step(0)[1]
    assert np.isfinite(reward) and reward == sys.float_info.max


# reports never pool unlike things; damaged files are named


def write_run(root: Path, name: str, env: str, seed: int, final: float, lr: float = 1e-3) -> Path:
    """A finished run's files as simoun-train writes them (evaluations at 0 and 100)."""
    run_dir = root / name
    run_dir.mkdir(parents=True)
    config = to_dict(resolve(None, {"env": env, "seed": seed, "agent.lr": lr}))
    (run_dir / "config.json").write_text(json.dumps(config))
    (run_dir / "eval.csv").write_text(
        f"env_step,return_mean,wall_time_s\n0,0.0,1.0\n100,{final},2.0\n"
    )
    summary = {"env_step": 100, "wall_time_s": 2.0, "final_eval": {"return_mean": final}}
    (run_dir / "summary.json").write_text(json.dumps(summary))
    return run_dir


CARTPOLE, WALKER, POINT = (
    "dm_control/cartpole-swingup-v0",
    "dm_control/walker-walk-v0",
    "simoun/PointReach-v0",
)


def test_runs_configured_differently_on_two_tasks_are_two_variants(tmp_path):
    for seed in range(3):
        write_run(tmp_path, f"cartpole-s{seed}", CARTPOLE, seed, 500.0 + seed)
        write_run(tmp_path, f"walker-s{seed}", WALKER, seed, 100.0 + seed, lr=2e-4)
    write_report(tmp_path)
    with (tmp_path / "aggregate.csv").open() as f:
        rows = {row["variant"]: row for row in csv.DictReader(f)}
    assert set(rows) == {"agent.lr=0.001", "agent.lr=0.0002"}
    assert float(rows["agent.lr=0.001"]["iqm"]) == pytest.approx(0.501)
    assert rows["agent.lr=0.0002"]["tasks"] == "walker-walk"


def test_raw_returns_enter_no_statistic_across_tasks(tmp_path):
    for seed in range(3):
        write_run(tmp_path, f"cartpole-s{seed}", CARTPOLE, seed, 500.0)
        write_run(tmp_path, f"point-s{seed}", POINT, seed, -485.0)
    write_report(tmp_path)
    with (tmp_path / "aggregate.csv").open() as f:
        (row,) = csv.DictReader(f)
    assert row["tasks"] == "cartpole-swingup" and float(row["iqm"]) == pytest.approx(0.5)
    text = (tmp_path / "report.md").read_text()
    assert "simoun-PointReach-v0 (no known maximum) enter no statistic across tasks" in text


DAMAGES = {
    "config.json": ('{"env": ', "config.json is damaged: it is not JSON (Expecting value"),
    "config.json ": ("", "config.json is damaged: it is empty"),
    "config.json  ": ("[1]", "config.json is damaged: it holds an array, not a JSON object"),
    "eval.csv": ("", "eval.csv holds no evaluation, but the run finished"),
    "eval.csv ": (
        "env_step,return_mean,wall_time_s\nx,1,2\n",
        "eval.csv is damaged: line 2: env_step is 'x', not a number",
    ),
    "eval.csv  ": (
        "env_step,return_mean,wall_time_s\n0,nan,1\n",
        "eval.csv line 2 has an empty, NaN or infinite value",
    ),
    "eval.csv   ": (
        "step,score\n0,1\n",
        "eval.csv is damaged: it has no return_mean column, which every eval.csv of a run holds",
    ),
    "summary.json": ("{}", "summary.json has no finite final_eval.return_mean"),
}
"""file (padded to be unique) -> what it is overwritten with, and what the report says"""


def test_a_damaged_run_is_named_and_left_out(tmp_path):
    for seed in range(2):
        write_run(tmp_path, f"s{seed}", CARTPOLE, seed, 500.0 + seed)
    for seed, (file, (text, _)) in enumerate(DAMAGES.items(), start=2):
        (write_run(tmp_path, f"s{seed}", CARTPOLE, seed, 0.0) / file.strip()).write_text(text)
    write_report(tmp_path)
    text = (tmp_path / "report.md").read_text()
    assert "## Damaged runs (not counted)" in text
    for seed, (_, named) in enumerate(DAMAGES.values(), start=2):
        assert f"- s{seed}: {named}" in text
    with (tmp_path / "report.csv").open() as f:
        (row,) = csv.DictReader(f)
    assert row["n"] == "2" and float(row["final_return_mean"]) == pytest.approx(500.5)


def test_a_study_report_of_a_missing_directory_gives_the_report_advice(tmp_path, capsys):
    from simoun_lab.cli import study as study_cli

    spec = str(ROOT / "docs" / "studies" / "dmc100k.toml")
    err = refused(capsys, study_cli.main, ["report", spec, "--study-dir", str(tmp_path / "x")])
    assert "no study to report" in err and "(no such directory)" in err
    assert "--resume" not in err


# advice that works: every setting that must change, in the interface the user is in


def advised(err: str) -> dict[str, int]:
    """The ``--key N`` settings a refusal's ``Set ...`` sentence asks for, as config keys."""
    sentence = err[err.index("Set ") :].split(" (or", 1)[0]
    pairs = [part.split() for part in sentence.removeprefix("Set ").split(" and ")]
    return {flag[2:].replace("-", "_"): int(value) for flag, value in pairs}


def test_a_memory_refusal_names_both_settings_when_both_must_change_and_they_fit(tmp_path, capsys):
    base = resolve(None, overrides_from(train_cli.parse_command(TINY).flags, TINY))
    host = memory.device_memory("cpu")[1]
    per_frame = memory.replay_bytes(base) / base.replay_capacity
    two, one = (replace(base, agent=replace(base.agent, batch_size=b)) for b in (2, 1))
    per_window = memory.update_bytes(two) - memory.update_bytes(one)
    # the replay and the update each fill 80% of this machine: lowering one alone cannot fit
    capacity, batch = int(0.8 * host / per_frame), int(0.8 * host / per_window)
    argv = [*TINY, "--replay-capacity", str(capacity), "--run-dir", str(tmp_path / "run")]
    argv[argv.index("--agent.batch-size") + 1] = str(batch)
    err = refused(capsys, train_cli.main, argv)
    settings = advised(err)
    assert set(settings) == {"replay_capacity", "agent.batch_size"}, err
    fixed = replace(
        base,
        replay_capacity=settings["replay_capacity"],
        agent=replace(base.agent, batch_size=settings["agent.batch_size"]),
    )
    assert memory.check_memory(fixed) is None  # it fits, without even a warning
    assert not (tmp_path / "run").exists()


# interruptions keep the evaluation grid


def test_at_step_counts_a_resumed_run_at_its_nearest_evaluation_and_says_so(tmp_path):
    def run(seed: int, last: int) -> None:
        run_dir = write_run(tmp_path, f"s{seed}", CARTPOLE, seed, 500.0)
        config = json.loads((run_dir / "config.json").read_text())
        (run_dir / "config.json").write_text(json.dumps({**config, "eval_every": 100}))
        csv_text = f"env_step,return_mean,wall_time_s\n0,0.0,1.0\n{last},500,2.0\n"
        (run_dir / "eval.csv").write_text(csv_text)
        summary = json.loads((run_dir / "summary.json").read_text())
        (run_dir / "summary.json").write_text(json.dumps({**summary, "env_step": last}))

    for seed in range(3):
        run(seed, 100)
    run(3, 103)  # stopped mid-episode and resumed: 3 steps off the grid
    run(4, 160)  # more than half an eval_every off: short of the budget
    write_report(tmp_path, budget=("env_step", 100))
    text = (tmp_path / "report.md").read_text()
    assert "## Runs counted at the evaluation nearest to 100 env steps" in text
    assert "- s3: its evaluation at 103 env steps (eval_every 100)" in text
    assert "- s4: no evaluation at 100 env steps" in text
    with (tmp_path / "report.csv").open() as f:
        (row,) = csv.DictReader(f)
    assert row["n"] == "4"


# every command refuses an option given twice with different values


@pytest.mark.parametrize(
    ("main", "flags", "said"),
    [
        (eval_cli.main, ["--episodes", "1", "--episodes", "2"], "(--episodes 1 and --episodes 2)"),
        (eval_cli.main, ["--video", "--no-video"], "(--video and --no-video)"),
        (eval_cli.main, ["--seed=1", "--seed", "2"], "--seed is given twice"),
        (report_cli.main, ["--at-step", "5", "--at-step", "6"], "--at-step is given twice"),
    ],
)
def test_every_command_refuses_an_option_given_twice(main, flags, said, tmp_path, capsys):
    err = refused(capsys, main, [str(tmp_path), *flags])
    assert said in err and "give it once" in err


# paths: one that does not exist, or a file where a directory is expected, is named as such


def test_a_missing_or_wrong_kind_of_path_is_named_as_such(tmp_path, capsys):
    absent, text = tmp_path / "absent", tmp_path / "notes.txt"
    text.write_text("not a run")
    err = refused(capsys, eval_cli.main, [str(absent)])
    assert f"{absent} does not exist" in err
    err = refused(capsys, eval_cli.main, [str(text)])
    assert "is a file that is not a checkpoint (.pt)" in err and "Delete" not in err
    err = refused(capsys, train_cli.main, ["--resume", str(absent)])
    assert f"--resume {absent} does not exist" in err
    err = refused(capsys, train_cli.main, ["--resume", str(text)])
    assert f"--resume {text} is a file, not a directory" in err
    err = refused(capsys, train_cli.main, [*TINY, "--run-dir", str(text)])
    assert f"the output directory {text} is a file, not a directory" in err
    assert sorted(path.name for path in tmp_path.iterdir()) == ["notes.txt"]


def test_frames_too_large_for_torch_to_size_are_refused_by_the_memory_check(tmp_path, capsys):
    # 100,000 pixels a side at a batch of 512: an attention map of more than 2**63 bytes
    argv = override(TINY, "--image-size", "100000", "--agent.batch-size", "512")
    argv += ["--run-dir", str(tmp_path / "run")]
    err = refused(capsys, train_cli.main, argv)
    assert "--image-size 100000 with --agent.batch-size 512" in err
    assert "Lower --image-size" in err
    assert not (tmp_path / "run").exists()


# a resumed run's new values keep their fields' rules


@pytest.mark.parametrize(
    ("flags", "said"),
    [
        (["--eval-every", "0"], "--eval-every 0 (TrainConfig.eval_every) must be an int >= 1"),
        (["--checkpoint-every", "0"], "--checkpoint-every 0 (TrainConfig.checkpoint_every) must"),
        (["--torch-threads", "0"], "--torch-threads 0 (TrainConfig.torch_threads) must be an int"),
    ],
)
def test_a_resumed_run_checks_the_values_it_may_change(flags, said, tmp_path, capsys):
    from test_damaged_files import finished_run

    run_dir = finished_run(tmp_path / "run")
    before = {path.name: path.read_bytes() for path in run_dir.iterdir()}
    argv = ["--resume", str(run_dir), "--total-env-steps", "90", *flags]
    err = refused(capsys, train_cli.main, argv)
    assert said in err and "Traceback" not in err
    assert {path.name: path.read_bytes() for path in run_dir.iterdir()} == before


@pytest.mark.parametrize(
    ("module", "said"),
    [
        ("..x", "--env-module ..x (TrainConfig.env_module) must be an importable absolute module"),
        ("simoun_agent.envs:x", "--env-module simoun_agent.envs:x (TrainConfig.env_module) must"),
        ("os.path.nope", "'os' is installed but has no module 'os.path.nope'"),
    ],
)
def test_an_env_module_that_cannot_be_imported_is_named_without_a_pip_hint(
    module, said, tmp_path, capsys
):
    argv = [*TINY, "--env-module", module, "--run-dir", str(tmp_path / "r")]
    err = refused(capsys, train_cli.main, argv)
    assert said in err and "pip install" not in err and "Traceback" not in err
    assert not (tmp_path / "r").exists()


def utf16(text: str) -> bytes:
    return text.encode("utf-16")


def nul_byte(text: str) -> bytes:
    return text.encode().replace(b"\n", b"\n\0", 1)


def latin1(text: str) -> bytes:
    return ("# r\xe9sum\xe9\n" + text).encode("latin-1")


@pytest.mark.parametrize(
    ("encode", "said"),
    [
        (utf16, "it is saved as UTF-16 text, not UTF-8"),
        (nul_byte, "line 2 holds a NUL byte"),
        (latin1, "line 1 is not UTF-8 text (byte 0xe9)"),
    ],
)
def test_a_spec_that_is_not_utf8_is_named_by_every_spec_reader(encode, said, tmp_path, capsys):
    from simoun_lab.cli import study as study_cli
    from simoun_lab.cli import sweep as sweep_cli

    toml = tmp_path / "spec16.toml"
    toml.write_bytes(encode(Path("docs/studies/dmc100k.toml").read_text()))
    err = refused(capsys, study_cli.main, ["plan", str(toml)])
    assert f"cannot read the study spec {toml} ({said}" in err and "saved as UTF-8 text" in err
    spec = tmp_path / "spec16.json"
    spec.write_bytes(encode(json.dumps(MINIGRID_SPEC, indent=1)))
    for argv, label in (
        (["select", "--spec", str(spec), "--archive", "."], "--spec"),
        (["plan", str(spec)], "the study spec"),
    ):
        main = minigrid_cli.main if argv[0] == "select" else study_cli.main
        err = refused(capsys, main, argv)
        assert f"{label} {spec} cannot be read ({said}" in err and "saved as UTF-8 text" in err
    sweep = tmp_path / "sweep"
    sweep.mkdir()
    (sweep / "sweep.json").write_bytes(encode('{\n"base": {},\n"grid": {}\n}'))
    err = refused(capsys, sweep_cli.main, ["--resume", "--sweep-dir", str(sweep)])
    assert f"{sweep / 'sweep.json'} is damaged ({said}" in err


def test_a_minigrid_spec_that_gives_a_key_twice_is_refused_naming_it(tmp_path, capsys):
    from simoun_lab.cli import study as study_cli

    spec = tmp_path / "spec.json"
    text = json.dumps(MINIGRID_SPEC, indent=1)
    spec.write_text(text.replace('"arms": [', '"arms": ["rnd"],\n "arms": [', 1))
    said = f"{spec}: the key 'arms' is given twice; give each key once"
    assert f"--spec {said}" in refused(capsys, minigrid_cli.main, ["select", "--spec", str(spec)])
    assert f"the study spec {said}" in refused(capsys, study_cli.main, ["plan", str(spec)])
