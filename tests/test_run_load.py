"""One loader of trained runs (simoun_agent.run.load) behind simoun-eval, simoun-analyze and the
distraction evaluation: a run trained on another device loads on this machine with cpu."""

import json

import gymnasium as gym
import numpy as np
import pytest
import torch
from test_train_resume import TINY

from simoun_agent.cli import eval as eval_cli
from simoun_agent.config import SetupError, resolve
from simoun_agent.models.encoder import ENCODERS
from simoun_agent.run import train
from simoun_agent.run.checkpoint import load_checkpoint
from simoun_agent.run.evaluate import EvaluationStopped, RandomPolicy, evaluate
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


@pytest.fixture(scope="module")
def loaded(gpu_run):
    run = load_run(gpu_run, device=torch.device("cpu"))  # a torch.device, saved as its string
    assert run.config.device == "cpu"
    yield run
    run.env.close()


@pytest.mark.parametrize(
    ("arguments", "error", "said"),
    [
        ({"path": None}, TypeError, r"^load_run\(path=\.\.\.\) must be a run directory or its "),
        ({"path": b"runs/a"}, TypeError, r"checkpoint\.pt, as a str or os\.PathLike, got bytes"),
        ({"device": "gpu"}, SetupError, r"^load_run\(device='gpu'\): device type 'gpu' is not "),
        ({"device": 0}, TypeError, r"^load_run\(device=\.\.\.\) must be a str, a torch.device"),
        ({"torch_threads": 0}, SetupError, r"^load_run\(torch_threads=\.\.\.\) must be an int"),
        ({"torch_threads": "2"}, SetupError, r"got '2' \(str\); e.g. torch_threads=1$"),
        ({"torch_threads": True}, SetupError, r"got True \(bool\)"),
    ],
)
def test_load_runs_own_arguments_are_named_not_blamed_on_the_saved_file(
    gpu_run, arguments, error, said
):
    with pytest.raises(error, match=said) as raised:
        load_run(**{"path": gpu_run, "device": "cpu", **arguments})
    assert "damaged" not in str(raised.value) and "saved config" not in str(raised.value)


def test_evaluate_takes_its_arguments_as_documented(loaded):
    episodes = []
    metrics, frames = evaluate(
        loaded.agent,
        loaded.env,
        np.int64(1),
        loaded.first_seed,
        record=np.bool_(True),
        on_episode=lambda index, episode_return: episodes.append(index),
        stop=lambda: False,
    )
    assert episodes == [0] and frames and "return_mean" in metrics


@pytest.mark.parametrize(
    ("change", "error", "said"),
    [
        ({"episodes": 0}, ValueError, r"^evaluate\(episodes=\.\.\.\) must be an int >= 1, got 0 "),
        ({"episodes": 1.5}, ValueError, r"got 1.5 \(float\); e.g. episodes=10$"),
        ({"episodes": "1"}, ValueError, r"got '1' \(str\)"),
        ({"seed": -1}, ValueError, r"^evaluate\(seed=\.\.\.\) must be an int >= 0"),
        ({"record": "yes"}, TypeError, r"^evaluate\(record=\.\.\.\) must be True or False"),
        ({"on_episode": "print"}, TypeError, r"^evaluate\(on_episode=\.\.\.\) must be a callable"),
        ({"on_episode": lambda: None}, TypeError, r"on_episode\(index, episode_return\)"),
        ({"stop": True}, TypeError, r"^evaluate\(stop=\.\.\.\) must be a callable"),
        ({"stop": lambda now: now}, TypeError, r"signature \(now\) does not take"),
        ({"stop": lambda: "no"}, TypeError, r"^evaluate\(stop=\.\.\.\) must return True \(stop\)"),
        ({"swap": True}, TypeError, r"^evaluate takes the agent first and the env second"),
        ({"env": "pendulum"}, TypeError, r"must give SimounObservation's frames .*run\.env"),
        ({"env": "agent"}, TypeError, r"^evaluate\(env=\.\.\.\) must be a Gymnasium env"),
        ({"agent": "env"}, TypeError, r"^evaluate\(agent=\.\.\.\) must have act\(frames"),
    ],
)
def test_evaluate_refuses_a_wrong_argument_naming_it_before_any_episode(
    loaded, change, error, said
):
    players = {"agent": loaded.agent, "env": loaded.env, "pendulum": gym.make("Pendulum-v1")}
    arguments = {"agent": loaded.agent, "env": loaded.env, "episodes": 1, "seed": 0}
    arguments.update({key: players.get(value, value) for key, value in change.items()})
    if arguments.pop("swap", False):
        arguments["agent"], arguments["env"] = loaded.env, loaded.agent
    with pytest.raises(error, match=said):
        evaluate(**arguments)


def test_evaluate_stopped_says_why(loaded):
    with pytest.raises(EvaluationStopped, match=r"^stop\(\) returned True at step 0 of evaluation"):
        evaluate(loaded.agent, loaded.env, 1, 0, stop=lambda: True)


@pytest.mark.parametrize(
    ("arguments", "error", "said"),
    [
        ((gym.spaces.Box(-1, 1, (2,)), 0), TypeError, r"got the action space .* here 2$"),
        ((2, -1), ValueError, r"^RandomPolicy\(seed=\.\.\.\) must be an int >= 0, got -1"),
        ((2.5, 0), ValueError, r"^RandomPolicy\(action_dim=\.\.\.\) must be a positive int"),
    ],
)
def test_random_policy_names_its_argument(arguments, error, said):
    with pytest.raises(error, match=said):
        RandomPolicy(*arguments)
    assert RandomPolicy(2, 0).act(np.zeros(1)).shape == (2,)


def test_load_run_of_an_unexpanded_home_says_python_does_not_expand_it():
    # the Python API's path check (check_path): a ValueError, as every path argument gives
    with pytest.raises(ValueError, match=r"Python does not expand ~.*os.path.expanduser") as err:
        load_run("~/simoun-no-such-run", device="cpu")
    assert type(err.value) is ValueError
    assert str(err.value).startswith("load_run(path='~/simoun-no-such-run'): ")
