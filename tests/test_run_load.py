"""One loader of trained runs (simoun_agent.run.load) behind simoun-eval, simoun-analyze and the
distraction evaluation: a run trained on another device loads on this machine with cpu."""

import json

import pytest
import torch
from test_train_resume import TINY

from simoun_agent.cli import eval as eval_cli
from simoun_agent.config import SetupError, resolve
from simoun_agent.models.encoder import ENCODERS
from simoun_agent.run import train
from simoun_agent.run.checkpoint import load_checkpoint
from simoun_agent.run.layout import CHECKPOINT_NAME, CONFIG_NAME
from simoun_agent.run.load import load_run
from simoun_lab.cli import analyze as analyze_cli

TRAINED_ON = "cuda:0"
"""The device string the run's checkpoint is made to say it trained on."""


@pytest.fixture(scope="module")
def gpu_run(tmp_path_factory):
    """A tiny trained run whose checkpoint and config.json say it trained on ``cuda:0`` (as a
    GPU machine's run would), its tensors saved from that device as the checkpoint stores them."""
    run_dir = tmp_path_factory.mktemp("gpu") / "run"
    encoder = "dual_interactive"
    overrides = {
        **TINY,
        "total_env_steps": 60,
        "run_dir": str(run_dir),
        "agent.encoder": encoder,
        "agent.curiosity": ENCODERS[encoder].motion_path,
    }
    run = train.create_run(resolve(None, overrides))
    train.train(run)
    run.env.close()
    run.eval_env.close()
    payload = torch.load(run_dir / CHECKPOINT_NAME, weights_only=False)
    payload["config"]["device"] = TRAINED_ON
    torch.save(payload, run_dir / CHECKPOINT_NAME)
    saved = json.loads((run_dir / CONFIG_NAME).read_text())
    (run_dir / CONFIG_NAME).write_text(json.dumps({**saved, "device": TRAINED_ON}))
    return run_dir


def test_load_run_rebuilds_a_gpu_run_on_cpu(gpu_run):
    payload = load_checkpoint(gpu_run)
    assert payload["config"]["device"] == TRAINED_ON
    tensors = [value for value in payload["agent"]["encoder"].values()]
    assert tensors and all(value.device.type == "cpu" for value in tensors)  # map_location
    if not torch.cuda.is_available():
        with pytest.raises(SetupError, match="--device cpu"):
            load_run(gpu_run)
    run = load_run(gpu_run, device="cpu")
    try:
        assert run.config.device == "cpu"
        assert run.agent.device == torch.device("cpu")
        assert run.env_step == 60
        assert run.run_dir == gpu_run
        loaded = run.agent.encoder.state_dict()
        for key, value in payload["agent"]["encoder"].items():
            assert torch.equal(loaded[key], value), key
    finally:
        run.env.close()


def test_simoun_eval_evaluates_a_gpu_run_on_cpu(gpu_run, tmp_path, capsys):
    out = tmp_path / "eval"
    flags = ["--device", "cpu", "--episodes", "1", "--no-video", "--no-progress"]
    assert eval_cli.main([str(gpu_run), *flags, "--out", str(out)]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["env_step"] == 60 and metrics["episodes"] == 1


def test_distraction_evaluation_of_a_gpu_run_on_cpu(gpu_run, tmp_path, capsys):
    out = tmp_path / "generalization"
    flags = ["--distraction", "train", "--device", "cpu", "--episodes", "1", "--no-progress"]
    assert eval_cli.main([str(gpu_run), *flags, "--out", str(out)]) == 0
    rows = (out / "generalization.csv").read_text().splitlines()
    assert len(rows) == 2 and "train" in rows[1]


def test_simoun_analyze_draws_masks_of_a_gpu_run_on_cpu(gpu_run, tmp_path):
    out = tmp_path / "masks"
    argv = ["masks", str(gpu_run), "--steps", "2", "--device", "cpu", "--out", str(out)]
    assert analyze_cli.main(argv) == 0
    assert (out / "ep0-step0002.npz").is_file()
