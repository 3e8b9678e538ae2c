"""The MiniGrid PPO study at a tiny budget: every arm trained on Ray Tune through the command
line, archived, skipped on a rerun, reported; and the SB3 adapter over a Gymnasium vector env."""

import csv
import json
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

from simoun_agent.minigrid_study.envs import STATE_KEY, SB3VecEnv, minigrid_pixels
from simoun_agent.minigrid_study.spec import StudySpec, load_spec

TINY = {
    "tasks": [{"env_id": "MiniGrid-DoorKey-5x5-v0", "steps": 2048, "seeds": [0]}],
    "ppo": {"n_epochs": 1},
    "evaluations": 1,
    "eval_episodes": 2,
}


def study(*args: str) -> subprocess.CompletedProcess:
    command = [sys.executable, "-m", "simoun_agent.minigrid_study", *args]
    return subprocess.run(command, capture_output=True, text=True, timeout=600)


def rows(path: Path) -> list[dict[str, str]]:
    with path.open() as file:
        return list(csv.DictReader(file))


def test_a_tiny_study_runs_every_arm_resumes_and_reports(tmp_path):
    spec_file = tmp_path / "spec.json"
    spec_file.write_text(json.dumps(TINY))
    archive, work = tmp_path / "archive", tmp_path / "work"
    paths = ["--archive", str(archive), "--spec", str(spec_file)]
    done = study("run", *paths, "--work-dir", str(work))
    assert done.returncode == 0, done.stderr[-4000:]
    assert "0 of 3 runs finished" in done.stdout
    for arm in ("ppo", "consistency", "rnd"):
        run_dir = archive / "MiniGrid-DoorKey-5x5-v0" / arm / "s0"
        summary = json.loads((run_dir / "summary.json").read_text())
        assert summary["env_steps"] == 2048 and summary["steps_per_s"] > 0
        assert json.loads((run_dir / "config.json").read_text())["run"].endswith(f"{arm}/s0")
        evals = rows(run_dir / "eval.csv")
        assert [int(r["env_step"]) for r in evals] == [0, 2048]
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

    again = study("run", *paths, "--work-dir", str(work))
    assert again.returncode == 0 and "3 of 3 runs finished" in again.stdout

    other = tmp_path / "other.json"
    other.write_text(json.dumps({**TINY, "eval_episodes": 3}))
    refused = study("run", "--archive", str(archive), "--spec", str(other))
    assert refused.returncode == 2 and "another spec" in refused.stderr
    assert "Traceback" not in refused.stderr

    report = study("report", "--archive", str(archive))
    assert report.returncode == 0, report.stderr[-4000:]
    text = (archive / "report" / "report.md").read_text()
    assert "3 of 3 runs finished" in text and "| consistency |" in text and "P(rnd > ppo)" in text
    assert (archive / "report" / "MiniGrid-DoorKey-5x5-v0_success.png").is_file()


def test_the_default_spec_is_the_issue_s_design():
    spec = StudySpec()
    assert [(t.env_id, t.steps, len(t.seeds)) for t in spec.tasks] == [
        ("MiniGrid-DoorKey-6x6-v0", 400_000, 5),
        ("MiniGrid-DoorKey-8x8-v0", 1_000_000, 3),
    ]
    assert spec.arms == ("ppo", "consistency", "rnd") and len(spec.runs()) == 24
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
