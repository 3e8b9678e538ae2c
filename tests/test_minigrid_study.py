"""The MiniGrid PPO study at a tiny budget: every arm trained on Ray Tune through the command
line, killed mid-way and resumed from the archive, skipped on a rerun, reported; a run resumed
from its own checkpoint; and the SB3 adapter over a Gymnasium vector env."""

import contextlib
import csv
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
import ray  # noqa: F401  (the lab extra: a missing install fails instead of skipping)
import torch
from gymnasium.vector import AutoresetMode
from test_train_failures import named_unwritten_file, under_file_size_limit

from simoun_agent.config import SetupError
from simoun_lab.minigrid_study.__main__ import main
from simoun_lab.minigrid_study.checkpoint import CHECKPOINT, restore
from simoun_lab.minigrid_study.envs import STATE_KEY, SB3VecEnv, minigrid_pixels
from simoun_lab.minigrid_study.run import train_run
from simoun_lab.minigrid_study.spec import StudySpec, load_spec, spec_from_dict
from simoun_lab.minigrid_study.study_command import is_ppo_spec, load_ppo_spec
from simoun_lab.minigrid_study.training import set_up

TINY = {
    "tasks": [{"env_id": "MiniGrid-DoorKey-5x5-v0", "steps": 2048, "seeds": [0]}],
    "ppo": {"n_epochs": 1},
    "evaluations": 2,
    "eval_episodes": 2,
}
"""two PPO rollouts of 1024 env steps per run, an evaluation after each: a checkpoint between"""

RUN = "MiniGrid-DoorKey-5x5-v0/ppo/s0"
"""the run whose archived checkpoint the study is killed at"""


def rows(path: Path) -> list[dict[str, str]]:
    with path.open() as file:
        return list(csv.DictReader(file))


def study(*args: str) -> tuple[int, str]:
    """``python -m simoun_lab.minigrid_study ARGS`` in this process (on the module's Ray
    instance): its exit status (returned, or exited with) and what it printed."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        try:
            status = main(list(args))
        except SystemExit as exit_info:
            status = exit_info.code
    return status, out.getvalue()


@pytest.fixture(scope="module")
def tiny_study(ray_address, tmp_path_factory):
    """The tiny study started on the command line and killed (driver, Ray and trials) once the
    archive holds a checkpoint of ``RUN``; then, its work directory deleted (a fresh machine),
    run to its end: (paths, what the killed study printed, what the resumed one printed, the
    env step of the archived checkpoint)."""
    root = tmp_path_factory.mktemp("minigrid_study")
    spec_file = root / "spec.json"
    spec_file.write_text(json.dumps(TINY))
    archive, work = root / "archive", root / "work"
    archive.mkdir()  # a study's archive is never created by default
    paths = ["--archive", str(archive), "--spec", str(spec_file), "--work-dir", str(work)]
    archived = archive / RUN / CHECKPOINT
    command = [sys.executable, "-m", "simoun_lab.minigrid_study", "run", *paths]
    with (root / "killed.txt").open("w") as printed:
        process = subprocess.Popen(command, start_new_session=True, stdout=printed)
        deadline = time.monotonic() + 600  # generous: the suite may share a loaded machine
        while not archived.is_file():
            assert process.poll() is None and time.monotonic() < deadline
            time.sleep(0.05)
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    assert not archived.with_name("summary.json").exists()
    saved_step = torch.load(archived, weights_only=False)["env_step"]
    shutil.rmtree(work)
    status, resumed = study("run", *paths)
    assert status == 0, resumed[-4000:]
    return paths, (root / "killed.txt").read_text(), resumed, saved_step


def test_a_tiny_study_runs_every_arm_resumes_and_reports(tiny_study):
    paths, killed, _, _ = tiny_study
    archive, spec_file = Path(paths[1]), Path(paths[3])
    assert "0 of 3 runs finished" in killed
    for arm in ("ppo", "consistency", "rnd"):
        run_dir = archive / "MiniGrid-DoorKey-5x5-v0" / arm / "s0"
        summary = json.loads((run_dir / "summary.json").read_text())
        assert summary["env_steps"] == 2048 and summary["steps_per_s"] > 0
        assert json.loads((run_dir / "config.json").read_text())["run"].endswith(f"{arm}/s0")
        assert not (run_dir / CHECKPOINT).exists()  # removed once the run finished
        evals = rows(run_dir / "eval.csv")
        assert [int(r["env_step"]) for r in evals] == [0, 1024, 2048]
        assert all(0 <= float(r["success_rate"]) <= 1 for r in evals)
        train = rows(run_dir / "train.csv")
        assert [int(float(r["env_step"])) for r in train] == [1024, 2048]
        assert all(float(r["update_s"]) > 0 and float(r["env_s"]) > 0 for r in train)
        intrinsic = [float(r["intrinsic_mean"]) for r in train]
        if arm == "ppo":
            assert intrinsic == [0.0, 0.0]
        elif arm == "consistency":
            assert all(0 < value <= 0.2 for value in intrinsic)  # r_i <= C * r_e_max
        else:  # RND's first 1024 transitions are its warm-up
            assert intrinsic[0] == 0.0 and intrinsic[1] > 0
    assert load_spec(archive / "spec.json") == load_spec(spec_file)

    again, printed = study("run", *paths)
    assert again == 0 and "3 of 3 runs finished" in printed

    other = spec_file.with_name("other.json")
    other.write_text(json.dumps({**TINY, "eval_episodes": 3}))
    refused, printed = study("run", "--archive", str(archive), "--spec", str(other))
    assert refused == 2 and "another spec" in printed and "Traceback" not in printed

    status, printed = study("report", "--archive", str(archive))
    assert status == 0, printed[-4000:]
    text = (archive / "report" / "report.md").read_text()
    assert "3 of 3 runs finished" in text and "| consistency |" in text and "P(rnd > ppo)" in text
    assert "## Is it a survival bonus?" in text
    assert "| MiniGrid-DoorKey-5x5-v0 | consistency | 10-30 % | " in text
    assert (archive / "report" / "MiniGrid-DoorKey-5x5-v0_success.png").is_file()
    assert (archive / "report" / "MiniGrid-DoorKey-5x5-v0_intrinsic.png").is_file()


def test_a_run_goes_on_from_its_archived_checkpoint_when_its_run_directory_is_gone(tiny_study):
    """The study was killed once the archive held a run's checkpoint; with the work directory
    deleted, the rerun went on from the archived checkpoint and, finished, removed it."""
    paths, _, resumed, saved_step = tiny_study
    assert saved_step == 1024  # the first rollout after the evaluation at 1024
    line = next(x for x in resumed.splitlines() if x.startswith("from the archive's checkpoints"))
    assert RUN in line.split(": ")[1].split(", ")
    run_dir = Path(paths[1]) / RUN
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["env_steps"] == 2048
    assert [p["env_step_start"] for p in summary["parts"]] == [0, saved_step]
    walls = [float(r["wall_s"]) for r in rows(run_dir / "eval.csv")]
    assert walls == sorted(walls)  # training time counts on from the saved seconds


def simoun_study(*args: str) -> tuple[int, str]:
    """``simoun-study ARGS`` in this process: its exit status and what it printed."""
    from simoun_lab.cli import study as study_cli

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
        try:
            status = study_cli.main(list(args))
        except SystemExit as exit_info:
            status = exit_info.code
    return status, out.getvalue()


TINY_TOML = """\
arms = ["ppo", "consistency", "rnd"]
evaluations = 2
eval_episodes = 2

[[tasks]]
env_id = "MiniGrid-DoorKey-5x5-v0"
steps = 2048
seeds = [0]

[ppo]
n_epochs = 1
"""
"""TINY in TOML, as simoun-study reads a MiniGrid spec beside the SAC ones"""


def test_simoun_study_plans_resumes_and_reports_a_minigrid_spec(tiny_study, tmp_path):
    paths, _, _, _ = tiny_study
    archive, spec_file, work = Path(paths[1]), Path(paths[3]), Path(paths[5])
    toml_spec = tmp_path / "tiny.toml"
    toml_spec.write_text(TINY_TOML)
    assert load_ppo_spec(str(toml_spec)) == load_spec(spec_file)

    status, printed = simoun_study("plan", str(toml_spec))
    assert status == 0 and "a MiniGrid PPO study, 3 runs" in printed
    assert "MiniGrid-DoorKey-5x5-v0/rnd/s0  2,048" in printed

    where = ["--study-dir", str(work), "--archive", str(archive)]
    status, printed = simoun_study("run", str(spec_file), *where)
    assert status == 2 and "already holds a MiniGrid study" in printed and "--resume" in printed
    status, printed = simoun_study(
        "run", str(toml_spec), *where, "--resume", "--allow-other-commit"
    )
    assert status == 2 and "drop the flag" in printed
    status, printed = simoun_study("run", str(toml_spec), *where, "--resume")
    assert status == 0 and "3 of 3 runs finished" in printed and "0 to run" in printed
    status, printed = simoun_study(
        "run", str(toml_spec), "--study-dir", str(tmp_path / "new"), "--resume"
    )
    assert status == 2 and "no study to resume" in printed

    assert study("report", "--archive", str(archive))[0] == 0
    report = archive / "report" / "report.md"
    before = report.read_bytes()
    report.unlink()
    status, printed = simoun_study("report", str(toml_spec), "--study-dir", str(archive))
    assert status == 0, printed[-4000:]
    assert report.read_bytes() == before  # the engine's command writes the same report
    other = tmp_path / "other.toml"
    other.write_text(TINY_TOML.replace("eval_episodes = 2", "eval_episodes = 3"))
    status, printed = simoun_study("report", str(other), "--study-dir", str(archive))
    assert status == 2 and "another spec" in printed


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (TINY_TOML.replace("evaluations", "evaluation"), "unknown key(s) ['evaluation']"),
        (TINY_TOML.replace("n_epochs", "epochs"), "ppo: unknown key(s) ['epochs']"),
        (TINY_TOML.replace('"rnd"', '"rdn"'), "rdn"),
    ],
)
def test_simoun_study_refuses_a_bad_minigrid_toml_spec_naming_the_key(text, said, tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text(text)
    status, printed = simoun_study("plan", str(spec))
    assert status == 2 and said in printed and "Traceback" not in printed


def test_the_minigrid_study_reads_a_toml_spec_and_tells_a_sac_one_apart(tmp_path):
    toml_spec = tmp_path / "tiny.toml"
    toml_spec.write_text(TINY_TOML)
    renamed = tmp_path / "tiny.spec"
    renamed.write_text(TINY_TOML)
    assert load_spec(toml_spec) == load_spec(renamed) == load_ppo_spec(str(toml_spec))
    assert load_spec(toml_spec).arms == ("ppo", "consistency", "rnd")
    sac = tmp_path / "spec.toml"
    sac.write_text(Path("docs/studies/dmc100k.toml").read_text())
    with pytest.raises(SetupError) as refused:
        load_spec(sac)
    said = str(refused.value)
    assert said.startswith(f"the spec file {sac} is a SAC study's spec (it has recipes)")
    assert f"simoun-study plan {sac}" in said and "comment" not in said
    broken = tmp_path / "broken.toml"
    broken.write_text(TINY_TOML.replace("evaluations = 2", "evaluations = "))
    with pytest.raises(SetupError, match=f"the spec file {broken} is not valid TOML .*line 2"):
        load_spec(broken)


def test_a_sac_spec_is_not_read_as_a_minigrid_one():
    assert is_ppo_spec("docs/studies/minigrid-v2/tuning/spec.json")
    assert not is_ppo_spec("docs/studies/dmc100k.toml")
    assert not is_ppo_spec("no/such/spec.toml")  # the SAC reader names the missing file


def test_a_task_with_fewer_than_three_seeds_gets_no_interval_and_enters_no_pooled_score(tmp_path):
    from simoun_lab.minigrid_study.report import Records, improvement_lines, score_table

    study_dir = Path(__file__).parent.parent / "docs" / "studies" / "minigrid"
    small, large = "MiniGrid-DoorKey-6x6-v0", "MiniGrid-DoorKey-8x8-v0"
    for arm in ("ppo", "consistency", "rnd"):
        for name in (f"{small}/{arm}/s0", f"{small}/{arm}/s1", f"{small}/{arm}/s2"):
            shutil.copytree(study_dir / name, tmp_path / name)
        shutil.copytree(study_dir / large / arm / "s0", tmp_path / large / arm / "s0")
    records = Records(load_spec(study_dir / "spec.json"), tmp_path)
    row = next(
        x for x in score_table(records, "success_rate").splitlines() if x.startswith("| rnd |")
    )
    small_cell, large_cell, pooled = row.strip("| ").split(" | ")[1:]
    assert small_cell.endswith("(n=3)") and "[" in small_cell
    large_score = records.final(large, "rnd", "success_rate")[0]
    assert large_cell == f"{large_score:.2f} (n=1, no CI)"
    assert small_cell.startswith(pooled)  # the pooled score is the 6x6 score alone
    [_, rnd_line] = improvement_lines(records)
    assert rnd_line.endswith(f"({small})")

    for name in (f"{small}/{arm}/s{seed}" for arm in ("ppo", "rnd") for seed in (1, 2)):
        shutil.rmtree(tmp_path / name)
    records = Records(load_spec(study_dir / "spec.json"), tmp_path)
    [_, rnd_line] = improvement_lines(records)
    assert rnd_line == "- P(rnd > ppo) on success rate: no task has 3 seeds yet"
    rnd_row = next(
        x for x in score_table(records, "success_rate").splitlines() if x.startswith("| rnd |")
    )
    assert rnd_row.endswith("| — |")


def test_the_default_spec_is_the_v1_design():
    spec = StudySpec()
    assert [(t.env_id, t.steps, len(t.seeds)) for t in spec.tasks] == [
        ("MiniGrid-DoorKey-6x6-v0", 400_000, 5),
        ("MiniGrid-DoorKey-8x8-v0", 1_000_000, 3),
    ]
    assert spec.arms == ("ppo", "consistency", "rnd") and len(spec.runs()) == 24
    first = [(run.task.env_id, run.seed, run.arm) for run in spec.runs()[:4]]
    assert first == [("MiniGrid-DoorKey-6x6-v0", 0, arm) for arm in spec.arms] + [
        ("MiniGrid-DoorKey-6x6-v0", 1, "ppo")
    ]
    committed = Path(__file__).resolve().parents[1] / "docs/studies/minigrid/spec.json"
    assert load_spec(committed) == spec


def test_sb3_vec_env_gives_the_ending_step_its_own_info():
    envs = gym.vector.SyncVectorEnv(
        [lambda: minigrid_pixels("MiniGrid-Empty-5x5-v0", max_steps=5) for _ in range(2)],
        autoreset_mode=AutoresetMode.SAME_STEP,
    )
    venv = SB3VecEnv(envs)
    venv.seed(3)
    obs = venv.reset()
    assert obs.shape == (2, 9, 56, 56) and venv.reset_infos[0][STATE_KEY].shape == (5,)
    for _ in range(5):
        obs, _, dones, infos = venv.step(np.array([0, 0]))  # turn left: time out
    assert dones.all() and all(info["TimeLimit.truncated"] for info in infos)
    # the ending step's state: 5 left turns from the start direction, not the reset's
    start = venv.reset_infos[0][STATE_KEY]
    assert infos[0][STATE_KEY][2] == (start[2] - 5) % 4
    assert infos[0]["terminal_observation"].shape == (9, 56, 56)
    assert venv.get_attr("max_steps") == [5, 5]
    venv.close()
    with pytest.raises(ValueError, match=r"AutoresetMode\.SAME_STEP"):
        SB3VecEnv(gym.vector.SyncVectorEnv([lambda: minigrid_pixels("MiniGrid-Empty-5x5-v0")]))


def test_an_ended_run_goes_on_from_its_checkpoint(tmp_path):
    """A run killed after its first checkpoint is resumed from it: the learner, the RNGs and the
    intrinsic model come back as saved, and the records go on without a gap or a repeat."""
    spec = spec_from_dict(
        {**TINY, "tasks": [{**TINY["tasks"][0], "steps": 3072}], "evaluations": 3}, "test"
    )
    (run,) = [r for r in spec.runs() if r.arm == "consistency"]
    run_dir = tmp_path / "run"
    code = (
        "import sys, json; from pathlib import Path\n"
        "from simoun_lab.minigrid_study.spec import spec_from_dict\n"
        "from simoun_lab.minigrid_study.run import train_run\n"
        "spec = spec_from_dict(json.loads(sys.argv[1]), 'test')\n"
        "run = [r for r in spec.runs() if r.arm == 'consistency'][0]\n"
        "train_run(spec, run, Path(sys.argv[2]))\n"
    )
    process = subprocess.Popen([sys.executable, "-c", code, json.dumps(spec.to_json()), run_dir])
    deadline = time.monotonic() + 600  # generous: the suite may share a loaded machine
    while not (run_dir / CHECKPOINT).is_file():
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.02)
    process.kill()
    process.wait()
    assert not (run_dir / "summary.json").exists()
    saved = torch.load(run_dir / CHECKPOINT, weights_only=False)
    assert saved["env_step"] == 1024  # the first rollout after the evaluation at 1024

    training = set_up(spec, run, tmp_path / "probe")
    fresh = {k: v.clone() for k, v in training.ppo.policy.state_dict().items()}
    assert restore(run_dir / CHECKPOINT, training) == 1024
    policy = training.ppo.policy.state_dict()
    assert any(not torch.equal(fresh[k], policy[k]) for k in fresh)  # trained weights came back
    assert all(torch.equal(policy[k], saved["policy"][k]) for k in policy)
    assert training.ppo.num_timesteps == 1024 and training.ppo._n_updates == 1
    assert torch.equal(torch.get_rng_state(), saved["rng"]["torch"])
    env_rng = [g.bit_generator.state for g in training.timed.get_attr("np_random")]
    assert env_rng == saved["env_rng"]
    model = training.envs.signal.source
    assert model.updates == saved["intrinsic"]["model"]["updates"] > 0
    assert [r["env_step"] for r in training.log.eval_rows] == [0, 1024]
    training.close()

    summary = train_run(spec, run, run_dir)
    assert summary["env_steps"] == 3072
    assert [p["env_step_start"] for p in summary["parts"]] == [0, 1024]
    evals = rows(run_dir / "eval.csv")
    assert [int(r["env_step"]) for r in evals] == [0, 1024, 2048, 3072]
    walls = [float(r["wall_s"]) for r in evals]
    assert walls == sorted(walls)  # training time counts on from the saved seconds
    train = rows(run_dir / "train.csv")
    assert [int(float(r["env_step"])) for r in train] == [1024, 2048, 3072]
    assert not (run_dir / CHECKPOINT).exists()


@pytest.mark.parametrize("arm", ["consistency", "rnd"])
def test_a_run_of_an_intrinsic_arm_is_the_same_bit_for_bit_when_trained_again(arm, tmp_path):
    """The intrinsic models step on the learner's thread, so one seed gives one run."""
    spec = spec_from_dict(
        {**TINY, "tasks": [{**TINY["tasks"][0], "steps": 1536}], "ppo": {"n_steps": 64}}, "test"
    )
    (run,) = [r for r in spec.runs() if r.arm == arm]
    for copy in ("a", "b"):
        train_run(spec, run, tmp_path / copy)
    first, second = (rows(tmp_path / copy / "train.csv") for copy in ("a", "b"))
    learned = [{k: v for k, v in r.items() if not k.endswith("_s")} for r in first]
    assert learned == [{k: v for k, v in r.items() if not k.endswith("_s")} for r in second]
    assert float(first[-1]["intrinsic_mean"]) != 0.0  # the model trained and paid
    assert (
        rows(tmp_path / "a" / "eval.csv")[-1]["return_mean"]
        == (rows(tmp_path / "b" / "eval.csv")[-1]["return_mean"])
    )


def test_survival_row_by_hand():
    from simoun_lab.minigrid_study.report import survival_row

    row = {"intrinsic_mean": 0.3, "intrinsic_std": 0.4, "novelty_corr": -0.1}
    # 0.09 / (0.09 + 0.16); 0.3 / (1 - 0.9); a negative correlation
    assert survival_row(row, gamma=0.9) == pytest.approx([0.36, 3.0, 1.0])
    row = {"intrinsic_mean": -0.2, "intrinsic_std": 0.0, "novelty_corr": 0.5}
    assert survival_row(row, gamma=0.5) == pytest.approx([1.0, -0.4, 0.0])
    share, value, negative = survival_row(
        {"intrinsic_mean": 0.0, "intrinsic_std": 0.0, "novelty_corr": float("nan")}, gamma=0.99
    )
    assert np.isnan(share) and value == 0.0 and np.isnan(negative)


def test_the_report_compares_the_arms_on_the_seeds_all_of_them_finished(tmp_path):
    import shutil

    from simoun_lab.minigrid_study.report import Records

    study_dir = Path(__file__).parent.parent / "docs" / "studies" / "minigrid"
    task = "MiniGrid-DoorKey-6x6-v0"
    for name in ("ppo/s0", "consistency/s0", "rnd/s0", "ppo/s1"):
        shutil.copytree(study_dir / task / name, tmp_path / task / name)
    records = Records(load_spec(study_dir / "spec.json"), tmp_path)
    assert len(records.finished) == 4
    assert sorted(r.name for r in records.used) == [
        f"{task}/{a}/s0" for a in ("consistency", "ppo", "rnd")
    ]
    assert len(records.final(task, "ppo", "success_rate")) == 1
    # the exploration column: distinct states reached, averaged over the bracket's rollouts
    from simoun_lab.minigrid_study.report import intrinsic_table

    rows = records.train[f"{task}/ppo/s0"]
    last_tenth = rows[int(0.9 * len(rows)) :]
    visited = np.mean([row["states_visited"] for row in last_tenth])
    line = next(
        x
        for x in intrinsic_table(records).splitlines()
        if x.startswith(f"| {task} | ppo | 90-100 % |")
    )
    assert line.endswith(f"| {visited:.0f} |") and 100 < visited < 400


V1_ARCHIVE = Path("docs/studies/minigrid")
V1_RUNS = [f"MiniGrid-DoorKey-6x6-v0/{arm}/s0" for arm in ("ppo", "consistency", "rnd")]


@pytest.fixture
def v1_copy(tmp_path: Path) -> Path:
    """One seed of each arm of the committed MiniGrid study, with its spec."""
    archive = tmp_path / "archive"
    for name in V1_RUNS:
        shutil.copytree(V1_ARCHIVE / name, archive / name)
    shutil.copy(V1_ARCHIVE / "spec.json", archive / "spec.json")
    return archive


def edit_csv(path: Path, edit) -> None:
    lines = path.read_text().splitlines()
    path.write_text("\n".join(edit(lines)) + "\n")


def edit_json(path: Path, edit) -> None:
    data = json.loads(path.read_text())
    edit(data)
    path.write_text(json.dumps(data))


def with_success(lines: list[str], rate: str) -> list[str]:
    """eval.csv's lines with the last row's success_rate (its third column) set to ``rate``."""
    last = lines[-1].split(",")
    return [*lines[:-1], ",".join([*last[:2], rate, *last[3:]])]


@pytest.mark.parametrize("command", ["report", "select"])
@pytest.mark.parametrize(
    ("file", "damage", "said"),
    [
        (
            "eval.csv",
            lambda p: edit_csv(p, lambda lines: [lines[0], *reversed(lines[1:])]),
            "line 3: env_step 400000 is negative or does not come after the line before (rows "
            "out of order or repeated)",
        ),
        (
            "eval.csv",
            lambda p: edit_csv(p, lambda lines: with_success(lines, "2.0")),
            ": success_rate is 2, not a rate in [0, 1]",
        ),
        (
            "eval.csv",
            lambda p: edit_csv(p, lambda lines: with_success(lines, "nan")),
            ": success_rate is nan, not a finite number",
        ),
        (
            "summary.json",
            lambda p: edit_json(p, lambda d: d.update(final_success_rate=float("nan"))),
            "final_success_rate is NaN, not a rate in [0, 1]",
        ),
        ("config.json", lambda p: p.write_text("{"), "it is not JSON"),
        ("config.json", lambda p: p.unlink(), "it is missing, but its run finished"),
        (
            "config.json",
            lambda p: edit_json(p, lambda d: d["spec"]["ppo"].update(gamma=0.5)),
            "its run was trained with another spec than the archive's (ppo differ: ppo.gamma "
            "0.5 where the spec has 0.99)",
        ),
        (
            "config.json",
            lambda p: edit_json(p, lambda d: d.update(run="MiniGrid-DoorKey-6x6-v0/ppo/s1")),
            "its run is \"MiniGrid-DoorKey-6x6-v0/ppo/s1\", not 'MiniGrid-DoorKey-6x6-v0/rnd/s0'",
        ),
    ],
)
def test_a_damaged_file_of_a_finished_run_is_named_not_counted(
    command, file, damage, said, v1_copy
):
    path = v1_copy / V1_RUNS[2] / file
    damage(path)
    status, printed = study(command, "--archive", str(v1_copy))
    assert status == 2 and "Traceback" not in printed, printed[-2000:]
    assert f"{path} is damaged: " in printed and said in printed
    assert not (v1_copy / "report").exists() and not (v1_copy / "selection.md").exists()


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("", "it is empty"),
        ("garbage", "it is not JSON"),
        ('{"run": "MiniGrid-DoorKey-6x6-v0/rnd/s0", "env_st', "it is not JSON"),
        ("[1, 2]", "it holds an array, not a JSON object"),
    ],
)
def test_run_over_an_archive_names_an_unreadable_summary_before_it_counts(text, said, v1_copy):
    path = v1_copy / V1_RUNS[2] / "summary.json"
    path.write_text(text)
    status, printed = study("run", "--archive", str(v1_copy))
    assert status == 2 and "Traceback" not in printed, printed[-2000:]
    assert f"{path} is damaged: {said}" in printed
    assert "runs finished in" not in printed  # refused before any run is skipped or trained


def test_a_finished_run_without_its_train_csv_is_named_by_the_report(v1_copy):
    path = v1_copy / V1_RUNS[1] / "train.csv"
    path.unlink()
    status, printed = study("report", "--archive", str(v1_copy))
    assert status == 2 and f"{path} is damaged: it is missing, but its run finished" in printed


def test_select_with_another_spec_than_the_archives_writes_nothing(v1_copy, tmp_path):
    status, _ = study("select", "--archive", str(v1_copy))
    assert status == 0
    kept = {name: (v1_copy / name).read_bytes() for name in ("selection.md", "selection.json")}
    other = Path("docs/studies/minigrid-v2/tuning/spec.json")
    status, printed = study("select", "--archive", str(v1_copy), "--spec", str(other))
    assert status == 2 and "Traceback" not in printed
    assert (
        f"--spec {other} is another spec than the one the archive's runs were trained with"
        in printed
    )
    assert "leave --spec out to use the archive's" in printed
    assert kept == {name: (v1_copy / name).read_bytes() for name in kept}
    # an archive with no finished run of its spec keeps its selection too
    for name in V1_RUNS:
        (v1_copy / name / "summary.json").unlink()
    status, printed = study("select", "--archive", str(v1_copy))
    assert status == 2 and "holds no finished run of its spec: nothing to select from" in printed
    assert kept == {name: (v1_copy / name).read_bytes() for name in kept}


def test_a_report_directory_that_is_a_file_is_named(v1_copy):
    (v1_copy / "report").write_text("notes\n")
    status, printed = study("report", "--archive", str(v1_copy))
    assert status == 2 and "Traceback" not in printed
    assert f"{v1_copy / 'report'} is where the report is written, but it is a file" in printed


def test_a_report_figure_that_does_not_fit_is_named_with_the_fix_and_left_unwritten(v1_copy):
    done = under_file_size_limit(
        "simoun_lab.minigrid_study.__main__", ["report", "--archive", str(v1_copy)]
    )
    fix = "copy the archive to another disk and pass the copy as --archive"
    path = named_unwritten_file(done, "python -m simoun_lab.minigrid_study", fix)
    assert path.parent == v1_copy / "report" and path.suffix == ".png" and not path.exists()


def test_a_sac_study_archive_is_told_apart_from_a_minigrid_one(tmp_path, capsys):
    from simoun_lab.cli import study as study_cli

    archive = tmp_path / "dmc100k"
    archive.mkdir()
    shutil.copy("docs/studies/dmc100k/study.json", archive / "study.json")
    status, printed = study("report", "--archive", str(archive))
    assert status == 2 and f"--archive {archive} holds runs of a SAC study" in printed
    with pytest.raises(SystemExit) as exit_info:
        study_cli.main(["report", str(V1_ARCHIVE / "spec.json"), "--study-dir", str(archive)])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and "Traceback" not in err
    assert f"--study-dir {archive} holds runs of a SAC study ({archive / 'study.json'})" in err


@pytest.mark.parametrize(
    ("edit", "said"),
    [
        (('"device": "cpu"', '"device": "cpu",'), "a comma after the last item, line 47: JSON "
         "allows none there; remove it"),
        (("101\n", "101,\n"), "a comma after the last item, line 8: JSON allows none "
         "there; remove it"),
        (('"evaluations": 20,', '"evaluations": 20, // twenty'), "a comment, line 44: JSON has "
         "no comments; remove it"),
        (('"evaluations": 20,', '"evaluations": 20'), "Expecting ',' delimiter, line 45 column 3"),
    ],
)  # fmt: skip
def test_a_hand_edited_json_spec_is_told_where_and_why_it_is_not_json(edit, said, tmp_path):
    text = Path("docs/studies/minigrid-v2/tuning/spec.json").read_text()
    path = tmp_path / "spec.json"
    path.write_text(text.replace(*edit))
    with pytest.raises(SetupError) as refused:
        load_spec(path, "--spec")
    assert str(refused.value) == f"--spec {path} is not valid JSON: {said}"
    with pytest.raises(SetupError) as refused:
        load_ppo_spec(str(path))
    assert str(refused.value).startswith(f"the study spec {path} is not valid JSON: {said}")


def test_a_study_record_given_as_a_minigrid_spec_is_named_with_its_spec(tmp_path):
    docs = Path(__file__).resolve().parents[1] / "docs" / "studies"
    record = shutil.copy(docs / "dmc100k" / "study.json", tmp_path / "study.json")
    with pytest.raises(SetupError) as refused:
        load_spec(record)
    said = str(refused.value)
    assert f"the spec file {record} is a study's record" in said and "not a study spec" in said
    assert "docs/studies/dmc100k.toml" in said and "unknown key" not in said


def tree_bytes(root: Path) -> dict[str, bytes]:
    """Every file under ``root`` by its path under it, with its bytes."""
    return {
        str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()
    }


def test_a_minigrid_run_refuses_a_sac_archive_and_a_folder_inside_any_archive(tmp_path):
    sac = Path(shutil.copytree("docs/studies/dmc100k", tmp_path / "arch"))
    mgt = Path(shutil.copytree("docs/studies/minigrid-v2/tuning", tmp_path / "mgt"))
    kept = {root: tree_bytes(root) for root in (sac, mgt)}
    spec = str(mgt / "spec.json")
    work = tmp_path / "s"
    for resume in ([], ["--resume"]):
        status, printed = simoun_study("run", spec, "--study-dir", str(work), "--archive",
                                       str(sac), *resume)  # fmt: skip
        assert status == 2 and "Traceback" not in printed
        assert f"--archive {sac} holds a SAC study, 'dmc100k' ({sac / 'study.json'})" in printed
        assert "drop --resume" not in printed
    status, printed = simoun_study("run", spec, "--study-dir", str(sac))
    assert status == 2 and f"--study-dir {sac} holds a SAC study, 'dmc100k'" in printed
    for inside, owner in ((sac / "tuning", sac), (mgt / "MiniGrid-DoorKey-6x6-v0", mgt)):
        status, printed = simoun_study("run", spec, "--study-dir", str(work), "--archive",
                                       str(inside))  # fmt: skip
        assert status == 2 and f"--archive {inside} lies inside {owner}, the archive of" in printed
    status, printed = simoun_study("run", "docs/studies/dmc100k.toml", "--study-dir", str(work),
                                   "--archive", str(sac / "tuning"))  # fmt: skip
    assert status == 2 and f"lies inside {sac}, the archive of a SAC study" in printed
    for args in (["run", "--archive", str(sac)], ["run", "--archive", str(sac / "tuning")],
                 ["select", "--archive", str(sac / "tuning" / "drq")]):  # fmt: skip
        status, printed = (
            study(*args, "--work-dir", str(work)) if args[0] == "run" else study(*args)
        )
        assert status == 2 and "Traceback" not in printed
        assert f"{sac}" in printed and "SAC study, 'dmc100k'" in printed
    assert {root: tree_bytes(root) for root in (sac, mgt)} == kept
    assert not work.exists() and not (sac / "spec.json").exists()


@pytest.mark.parametrize(
    ("ppo", "said"),
    [
        ({"batch_size": 2048}, "ppo: batch_size 2048 is larger than one rollout (n_envs x "
         "n_steps = 8 x 128 = 1024 transitions): SB3 would train on mini-batches of 1024 while "
         "every run records 2048; set batch_size to a divisor of 1024 (e.g. 1024), or n_steps "
         "to 256"),
        ({"batch_size": 100}, "batch_size 100 does not divide one rollout (n_envs x n_steps = "
         "8 x 128 = 1024 transitions): each epoch would end on a truncated mini-batch of 24 "
         "transitions; set batch_size to a divisor of 1024 (e.g. 64 or 128), or n_steps to 150"),
        ({"batch_size": 1}, "batch_size 1: SB3's PPO normalizes each mini-batch's advantages"),
        ({"n_envs": 1, "n_steps": 1, "batch_size": 2}, "one rollout is n_envs x n_steps = 1 x 1"),
    ],
)  # fmt: skip
def test_a_batch_size_sb3_would_truncate_or_refuse_is_refused_at_plan(ppo, said, tmp_path):
    values = json.loads(Path("docs/studies/minigrid-v2/tuning/spec.json").read_text())
    path = tmp_path / "spec.json"
    path.write_text(json.dumps({**values, "ppo": {**values["ppo"], **ppo}}))
    status, printed = simoun_study("plan", str(path))
    assert status == 2 and said in printed and str(path) in printed, printed
    assert "Traceback" not in printed
    good = {**values["ppo"], "n_envs": 3, "n_steps": 100, "batch_size": 75}
    assert spec_from_dict({**values, "ppo": good}, "x").ppo.batch_size == 75


def test_a_file_that_is_no_minigrid_spec_is_named_with_a_fix_other_than_the_command(
    tmp_path, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    docs = Path(__file__).resolve().parents[1] / "docs" / "studies"
    shutil.copytree(docs / "dmc100k-drqv2-easy", "ez")
    shutil.copy(docs / "dmc100k.toml", "spec.json")
    Path("sac.json").write_text(json.dumps({"recipes": ["drq"], "grid": {}}))
    mg = Path("mg")
    mg.mkdir()
    shutil.copy(docs / "minigrid-v2" / "tuning" / "spec.json", mg / "spec.json")
    (mg / "selection.json").write_text(json.dumps({"arms": {}, "selected": {}}))
    cases = {
        "ez/selection.json": "is the selection a SAC study wrote (each recipe's selected "
        "setting), not a study spec; pass the spec the study was run from, "
        "docs/studies/dmc100k-drqv2-easy.toml (named in ez/study.json)",
        "mg/selection.json": "is the selection a MiniGrid PPO study wrote (each arm's selected "
        "setting), not a study spec; pass the spec the archive's runs were trained with, "
        "mg/spec.json",
        "spec.json": "it is TOML saved under a .json name, and simoun-study reads a .json spec "
        "as a MiniGrid one; rename it to .toml (mv spec.json spec.toml) and plan it with "
        "simoun-study plan spec.toml",
        "sac.json": "written as JSON: simoun-study reads a .json spec as a MiniGrid one and a "
        "SAC spec from TOML; write it as TOML in sac.toml",
    }
    for path, said in cases.items():
        status, printed = simoun_study("plan", path)
        assert status == 2 and said in printed, printed
        assert f"simoun-study plan {path}" not in printed and "Traceback" not in printed
        status, printed = study("select", "--archive", "mg", "--spec", path)
        if path == "ez/selection.json":  # a SAC study's spec is no answer to the MiniGrid command
            said = "selected setting), not a study spec; leave --spec out to use the archive's"
        assert status == 2 and said in printed, printed


def test_a_spec_path_with_a_trailing_blank_is_quoted_and_the_path_without_it_named(
    tmp_path, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    shutil.copy(Path(__file__).resolve().parents[1] / "docs/studies/dmc100k.toml", "dmc.toml")
    Path("mg.json").write_text(json.dumps(TINY))
    status, printed = simoun_study("plan", "dmc.toml ")
    assert status == 2 and "cannot read the study spec 'dmc.toml ' (No such file" in printed
    assert (
        "'dmc.toml ' has a blank (a space or tab) at its start or end, and dmc.toml is" in printed
    )
    status, printed = simoun_study("plan", " mg.json")
    assert status == 2 and "the study spec ' mg.json': no such file; ' mg.json' has a " in printed
    status, printed = simoun_study("plan", "none.toml")
    assert "cannot read the study spec none.toml (No such file" in printed
    assert "has a blank" not in printed


def test_report_and_select_given_a_folder_of_an_archive_are_told_the_archive(tmp_path):
    mgt = Path(shutil.copytree("docs/studies/minigrid-v2/tuning", tmp_path / "mgt"))
    task = mgt / "MiniGrid-DoorKey-6x6-v0"
    for command in ("report", "select"):
        status, printed = study(command, "--archive", str(task))
        assert status == 2 and "Traceback" not in printed
        assert f"--archive {task} is a folder inside {mgt}, the archive of a MiniGrid" in printed
        assert f"pass the archive (--archive {mgt})" in printed
        assert "outside" not in printed  # run's advice, for a study written there
    status, printed = simoun_study("report", str(mgt / "spec.json"), "--study-dir", str(task))
    assert status == 2 and f"pass the archive (--study-dir {mgt})" in printed


@pytest.mark.parametrize(
    ("name", "unpack"), [("mgt.zip", "unzip {p} -d {d}"), ("mgt.tar.gz", "tar -xf {p} -C {d}")]
)
def test_an_archive_given_as_a_packed_file_is_told_to_unpack_it(name, unpack, tmp_path):
    packed = tmp_path / name
    packed.write_bytes(b"PK\x05\x06" + bytes(18))
    for command in ("report", "select"):
        status, printed = study(command, "--archive", str(packed))
        assert status == 2 and "no such directory" not in printed
        assert f"--archive {packed} is a file, not a study's archive" in printed
        assert unpack.format(p=packed, d=tmp_path) in printed


def test_load_spec_from_python_names_its_file_not_the_flag(tmp_path):
    path = tmp_path / "s.json"
    path.write_text('{"tasks": [\n')
    with pytest.raises(SetupError, match=r"^the spec file .*s\.json is not valid JSON") as info:
        load_spec(path)
    assert "--spec" not in str(info.value)
    with pytest.raises(SetupError, match=r"^--spec .*s\.json is not valid JSON"):
        load_spec(path, "--spec")


def test_a_minigrid_run_refuses_another_studys_archive_or_a_sweep_as_its_work_dir(tmp_path):
    other = Path(shutil.copytree("docs/studies/minigrid-v2/tuning", tmp_path / "mg"))
    sweep = tmp_path / "sw"
    sweep.mkdir()
    (sweep / "sweep.json").write_text("{}")
    kept = {root: tree_bytes(root) for root in (other, sweep)}
    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(TINY))
    archive = tmp_path / "arch"
    archive.mkdir()
    for work, said in (
        (other, f"--work-dir {other} is the archive of another study, a MiniGrid PPO study "
                f"({other / 'spec.json'})"),
        (sweep, f"--work-dir {sweep} is a simoun-sweep directory ({sweep / 'sweep.json'})"),
        (sweep / "w", f"--work-dir {sweep / 'w'} lies inside {sweep}, a simoun-sweep directory"),
    ):  # fmt: skip
        status, printed = study("run", "--archive", str(archive), "--spec", str(spec),
                                "--work-dir", str(work))  # fmt: skip
        assert status == 2 and said in printed and "Traceback" not in printed, printed
        if work == other:
            assert "pass a new directory to --work-dir" in printed
    status, printed = simoun_study("run", str(spec), "--study-dir", str(other), "--archive",
                                   str(archive))  # fmt: skip
    assert status == 2 and f"--study-dir {other} is the archive of another study" in printed
    assert {root: tree_bytes(root) for root in (other, sweep)} == kept
    assert not any(archive.iterdir())


def test_a_minigrid_study_whose_run_still_trains_is_refused_before_ray(tmp_path):
    from simoun_agent.run.rundir import lock_run_dir

    spec = tmp_path / "spec.json"
    spec.write_text(json.dumps(TINY))
    archive, work = tmp_path / "arch", tmp_path / "work"
    archive.mkdir()
    run_dir = work / "runs" / RUN
    run_dir.mkdir(parents=True)
    with lock_run_dir(run_dir):  # as a study's trial holds it while it trains
        status, printed = study("run", "--archive", str(archive), "--spec", str(spec),
                                "--work-dir", str(work))  # fmt: skip
        again, said = simoun_study("run", str(spec), "--study-dir", str(work), "--archive",
                                   str(archive))  # fmt: skip
    for code, text in ((status, printed), (again, said)):
        assert code == 2 and "Traceback" not in text, text
        assert (
            f"run {RUN} of the study in {work / 'runs'} is in use by another trainer (PID " in text
        )
        assert f"{os.getpid()}): the study is still running in another process" in text
        assert "runs finished in" not in text
    assert not any(archive.iterdir())


def test_a_minigrid_trial_holds_its_run_directorys_lock_while_it_trains(tiny_study):
    from simoun_agent.run.rundir import lock_holder

    paths, _, _, _ = tiny_study
    run_dir = Path(paths[paths.index("--work-dir") + 1]) / "runs" / RUN
    assert (run_dir / ".lock").is_file() and lock_holder(run_dir) is None  # released at its end
