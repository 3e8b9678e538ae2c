"""The simoun-train / simoun-eval commands end to end: Ctrl-C, resume, evaluation output."""

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from simoun_agent.cli import eval as eval_cli
from simoun_agent.cli import train as train_cli

TINY_FLAGS = [
    "--env", "simoun/PointReach-v0",
    "--image-size", "32",
    "--warmup-agent-steps", "20",
    "--eval-every", "1000",
    "--eval-episodes", "1",
    "--checkpoint-every", "1000",
    "--progress", "false",
    "--device", "cpu",
    "--torch-threads", "1",
    "--agent.batch-size", "8",
    "--agent.num-filters", "8",
    "--agent.feature-dim", "16",
    "--agent.hidden-dim", "32",
    "--agent.aux-hidden-dim", "32",
]  # fmt: skip


def test_ctrl_c_writes_a_checkpoint_and_resume_finishes_the_run(tmp_path):
    run_dir = tmp_path / "run"
    command = [
        sys.executable,
        "-m",
        "simoun_agent.cli.train",
        *TINY_FLAGS,
        "--run-dir",
        str(run_dir),
    ]
    process = subprocess.Popen(
        [*command, "--total-env-steps", "100000", "--video", "false"],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    deadline = time.monotonic() + 120
    while not (run_dir / "train.csv").exists() and process.poll() is None:
        assert time.monotonic() < deadline, "training did not start within 120 s"
        time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    output, _ = process.communicate(timeout=120)
    assert process.returncode == 130, output
    assert "checkpoint written" in output and "--resume" in output
    assert (run_dir / "checkpoint.pt").exists()
    assert not (run_dir / "summary.json").exists()  # an interrupted run does not look finished
    stopped_at = json.loads((run_dir / "config.json").read_text())["total_env_steps"]
    assert stopped_at == 100000

    resume = ["--resume", str(run_dir), "--total-env-steps", "60", "--video", "true"]
    assert train_cli.main(resume) == 0
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["env_step"] >= 60
    assert (run_dir / "video.mp4").stat().st_size > 0


def test_simoun_eval_writes_metrics_and_video(tmp_path, capsys):
    run_dir = tmp_path / "run"
    flags = [*TINY_FLAGS, "--run-dir", str(run_dir), "--total-env-steps", "40", "--video", "false"]
    assert train_cli.main(flags) == 0
    assert eval_cli.main([str(run_dir), "--episodes", "2", "--out", str(tmp_path / "ev")]) == 0
    metrics = json.loads((tmp_path / "ev" / "metrics.json").read_text())
    assert metrics["episodes"] == 2 and metrics["env_step"] == 40
    assert -40 < metrics["return_mean"] <= 0  # PointReach pays -distance for 20 steps
    assert (tmp_path / "ev" / "video.mp4").stat().st_size > 0
    assert '"return_mean"' in capsys.readouterr().out


def test_simoun_eval_random_policy_is_a_seeded_baseline_on_the_same_episodes(tmp_path):
    run_dir = tmp_path / "run"
    flags = [*TINY_FLAGS, "--run-dir", str(run_dir), "--total-env-steps", "40", "--video", "false"]
    assert train_cli.main(flags) == 0
    returns = []
    for _ in range(2):
        argv = [str(run_dir), "--episodes", "2", "--random-policy", "--no-video", "--overwrite"]
        assert eval_cli.main(argv) == 0
        metrics = json.loads((run_dir / "eval-40-random" / "metrics.json").read_text())
        assert metrics["random_policy"] is True and metrics["episodes"] == 2
        returns.append(metrics["return_mean"])
    assert returns[0] == returns[1]  # seeded: the same actions on the same episodes
    assert not (run_dir / "eval-40-random" / "video.mp4").exists()


def test_simoun_eval_refuses_a_corrupt_checkpoint(tmp_path, capsys):
    (tmp_path / "checkpoint.pt").write_bytes(b"\x00" * 100)
    with pytest.raises(SystemExit) as exit_info:
        eval_cli.main([str(tmp_path)])
    assert exit_info.value.code == 2
    assert "corrupt or incomplete" in capsys.readouterr().err


def test_help_lists_every_preset_and_config_key(capsys):
    with pytest.raises(SystemExit):
        train_cli.main(["--help"])
    text = capsys.readouterr().out
    for name in ("cartpole-swingup", "highway", "cpu", "--agent.batch-size", "--action-repeat"):
        assert name in text


def test_setup_script_announces_every_step_before_it_runs():
    """scripts/setup.sh runs for minutes with pip kept quiet: each command that installs is
    preceded by its own numbered step line, so a log shows where it is."""
    path = Path(__file__).parents[1] / "scripts" / "setup.sh"
    script = path.read_text().splitlines()
    commands = [
        i for i, line in enumerate(script) if re.match(r"(python3 -m venv|\.venv/bin/)", line)
    ]
    steps = [int(m.group(1)) for line in script if (m := re.match(r"step (\d+) ", line))]
    total = int(re.search(r"\[\$1/(\d+)", "\n".join(script)).group(1))
    assert steps == list(range(1, total + 1)) and len(commands) == total
    assert all(script[i - 1].startswith("step ") for i in commands)
    assert subprocess.run(["bash", "-n", str(path)], timeout=120).returncode == 0


def test_an_action_repeat_longer_than_the_run_is_refused_before_training(tmp_path, capsys):
    argv = [*TINY_FLAGS, "--action-repeat", "1000", "--total-env-steps", "40"]
    with pytest.raises(SystemExit) as stop:
        train_cli.main([*argv, "--run-dir", str(tmp_path / "run")])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "--action-repeat 1000 (TrainConfig.action_repeat) is longer than the whole run" in err
    assert "(--total-env-steps 40, TrainConfig.total_env_steps)" in err
    assert "set --action-repeat 40 or less" in err
    assert "warning" not in err
    assert not (tmp_path / "run" / "config.json").exists()


def test_a_warmup_that_takes_the_whole_run_is_warned_of(tmp_path, capsys):
    tiny = [flag for flag in TINY_FLAGS if flag not in ("--warmup-agent-steps", "20")]
    argv = [*tiny, "--warmup-agent-steps", "40", "--total-env-steps", "40", "--no-video"]
    assert train_cli.main([*argv, "--run-dir", str(tmp_path / "run")]) == 0
    err = capsys.readouterr().err
    assert (
        "simoun-train: warning: --warmup-agent-steps 40 takes all the run's 40 agent decisions "
        "(--total-env-steps 40 at action repeat 1): it ends before its first update"
    ) in err
    assert err.count("before its first update") == 1  # said once, not again by train()
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["trained"] is False and summary["updates"] == 0


def test_a_run_without_an_update_is_warned_of_in_python_and_marked_untrained(tmp_path):
    from simoun_agent.config import resolve
    from simoun_agent.run.train import UntrainedRunWarning, create_run, train

    base = {
        "env": "simoun/PointReach-v0",
        "image_size": 32,
        "warmup_agent_steps": 20,
        "total_env_steps": 40,
        "eval_episodes": 1,
        "progress": False,
        "video": False,
        "device": "cpu",
        "torch_threads": 1,
        "agent.batch_size": 8,
        "agent.num_filters": 8,
        "agent.feature_dim": 16,
        "agent.hidden_dim": 32,
    }
    untrained = resolve(None, {**base, "run_dir": tmp_path / "untrained"})
    untrained.warmup_agent_steps = 1000  # set after the config was built, as in a notebook
    with pytest.warns(UntrainedRunWarning, match=r"--warmup-agent-steps 1000 takes all"):
        train(create_run(untrained))
    summary = json.loads((tmp_path / "untrained" / "summary.json").read_text())
    assert summary["trained"] is False and summary["updates"] == 0
    trained = resolve(None, {**base, "run_dir": tmp_path / "trained"})
    train(create_run(trained))
    summary = json.loads((tmp_path / "trained" / "summary.json").read_text())
    assert summary["trained"] is True and summary["updates"] > 0
