"""Checkpoints and resume of simoun-train: bit-exact continuation and refused bad inputs."""

import json
import shutil

import pytest
import torch

from simoun_agent.cli import train as train_cli
from simoun_agent.config import SetupError, resolve
from simoun_agent.run import train
from simoun_agent.run.checkpoint import load_checkpoint
from simoun_agent.run.logger import read_csv

TINY = {
    "env": "simoun/PointReach-v0",
    "image_size": 32,
    "total_env_steps": 120,
    "warmup_agent_steps": 20,
    "replay_capacity": 1000,
    "eval_every": 60,
    "eval_episodes": 1,
    "checkpoint_every": 60,
    "video": False,
    "progress": False,
    "device": "cpu",
    "torch_threads": 1,
    "seed": 3,
    "agent.batch_size": 8,
    "agent.num_filters": 8,
    "agent.feature_dim": 16,
    "agent.hidden_dim": 32,
    "agent.aux_hidden_dim": 32,
}


def tiny_config(run_dir, **overrides):
    return resolve(None, {**TINY, "run_dir": str(run_dir), **overrides})


def weights(agent):
    return {
        f"{name}.{key}": value
        for name, module in agent.modules().items()
        for key, value in module.state_dict().items()
    }


def without_wall_time(row: dict) -> dict:
    return {key: value for key, value in row.items() if key != "wall_time_s"}


def test_stopped_and_resumed_run_ends_with_the_same_weights(tmp_path):
    straight = train.create_run(tiny_config(tmp_path / "straight"))
    train.train(straight)

    stopped = train.create_run(tiny_config(tmp_path / "stopped", total_env_steps=60))
    train.train(stopped)
    resumed = train.resume_run(tmp_path / "stopped", {"total_env_steps": 120})
    assert resumed.counters.env_step == 60
    train.train(resumed)

    assert resumed.counters == straight.counters
    expected, got = weights(straight.agent), weights(resumed.agent)
    assert expected.keys() == got.keys()
    different = [key for key in expected if not torch.equal(expected[key], got[key])]
    assert different == []
    assert torch.equal(straight.agent.log_alpha, resumed.agent.log_alpha)
    # A resumed run's logs hold each evaluation once, as the straight run's do.
    # every column but the wall time, which differs between any two runs
    straight_eval = [without_wall_time(row) for row in read_csv(tmp_path / "straight" / "eval.csv")]
    resumed_eval = [without_wall_time(row) for row in read_csv(tmp_path / "stopped" / "eval.csv")]
    assert resumed_eval == straight_eval


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory):
    run_dir = tmp_path_factory.mktemp("runs") / "finished"
    train.train(train.create_run(tiny_config(run_dir, total_env_steps=40, warmup_agent_steps=10)))
    return run_dir


def test_finished_run_directory_is_complete(finished_run):
    names = {path.name for path in finished_run.iterdir()}
    assert {"config.json", "checkpoint.pt", "replay-40.npz", "summary.json"} <= names
    assert {"eval.csv", "train.csv", "learning_curve.png", "tb"} <= names
    assert json.loads((finished_run / "summary.json").read_text())["env_step"] == 40
    assert not [name for name in names if ".tmp" in name]


def test_resume_with_another_config_is_refused(finished_run):
    with pytest.raises(SetupError, match=r"only total_env_steps.*agent\.lr was given another"):
        train.resume_run(finished_run, {"agent.lr": 3e-4})


def test_resume_with_the_saved_values_of_fixed_keys_is_accepted(finished_run, tmp_path):
    run_dir = tmp_path / "copy"
    shutil.copytree(finished_run, run_dir)
    saved = json.loads((run_dir / "config.json").read_text())
    same = {
        "total_env_steps": 60,
        "seed": saved["seed"],
        "env_kwargs": saved["env_kwargs"],
        "action_repeat": saved["action_repeat"],
        "agent.lr": saved["agent"]["lr"],
        "run_dir": f"{run_dir}/",  # the directory resumed, spelled another way
    }
    run = train.resume_run(run_dir, same)
    try:
        assert run.config.seed == saved["seed"]
    finally:
        run.env.close()
        run.eval_env.close()
        train.release(run)


def test_resume_takes_the_runs_env_and_action_repeat_in_another_spelling(finished_run, tmp_path):
    run_dir = tmp_path / "copy"
    shutil.copytree(finished_run, run_dir)
    same = {
        "total_env_steps": 60,
        "env": "simoun_agent.envs:simoun/PointReach-v0",  # MODULE:ID of the run's own id
        "env_module": None,
        "action_repeat": 1,  # the repeat the run resolved (it saved none)
    }
    run = train.resume_run(run_dir, same)
    try:
        assert run.config.env == "simoun/PointReach-v0" and run.config.env_module is None
        assert run.config.action_repeat is None
    finally:
        run.env.close()
        run.eval_env.close()
        train.release(run)
    for other in ({"env": "simoun_agent.envs:Pendulum-v1"}, {"action_repeat": 2}):
        with pytest.raises(SetupError, match=r"was given another value than the run's"):
            train.resume_run(run_dir, other)


def test_checkpoint_from_another_config_is_refused(finished_run, tmp_path):
    other = tmp_path / "other"
    config = json.loads((finished_run / "config.json").read_text())
    config["agent"]["lr"] = 5e-4
    other.mkdir()
    (other / "config.json").write_text(json.dumps(config))
    (other / "checkpoint.pt").write_bytes((finished_run / "checkpoint.pt").read_bytes())
    with pytest.raises(
        SetupError,
        match=r"config\.json does not hold the config of the checkpoint in .* \(agent\.lr: 0\.001 "
        r"in the checkpoint, 0\.0005 now\): the file was edited or damaged",
    ):
        train.resume_run(other, {})


@pytest.mark.parametrize("damage", ["truncate", "garbage"])
def test_corrupt_checkpoint_is_refused(finished_run, tmp_path, damage):
    data = (finished_run / "checkpoint.pt").read_bytes()
    broken = tmp_path / "checkpoint.pt"
    broken.write_bytes(data[: len(data) // 2] if damage == "truncate" else b"not a checkpoint")
    with pytest.raises(SetupError, match=r"corrupt or incomplete.*start a new run"):
        load_checkpoint(broken)


def test_resume_of_a_directory_without_a_run_is_refused(tmp_path):
    with pytest.raises(SetupError, match="not a simoun run directory"):
        train.resume_run(tmp_path, {})


def test_existing_run_directory_is_not_overwritten(finished_run):
    with pytest.raises(SetupError, match=r"already holds a run.*--resume"):
        train.create_run(tiny_config(finished_run))


def test_unwritable_output_directory_leaves_nothing_behind(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    with pytest.raises(SetupError, match="cannot write to the output directory"):
        train.create_run(tiny_config(blocker / "run"))


def test_cli_reports_bad_input_without_a_traceback_and_creates_no_run(tmp_path, capsys):
    run_dir = tmp_path / "run"
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--env", "dm_control/cartpole-swingup-v9", "--run-dir", str(run_dir)])
    assert exit_info.value.code == 2
    assert "did you mean dm_control/cartpole-swingup-v0" in capsys.readouterr().err
    assert not run_dir.exists()


def test_a_damaged_replay_is_named_and_kept(finished_run, tmp_path):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    replay = run_dir / "replay-40.npz"
    replay.write_bytes(replay.read_bytes()[: replay.stat().st_size // 2])
    before = {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()}
    with pytest.raises(
        SetupError, match=r"replay-40.npz \(the replay of the checkpoint\) is damaged"
    ):
        train.resume_run(run_dir, {"total_env_steps": 60})
    assert {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()} == before


def test_a_missing_checkpoint_is_named_with_both_fixes(finished_run, tmp_path):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    (run_dir / "checkpoint.pt").unlink()
    with pytest.raises(SetupError, match=r"has no checkpoint\.pt: .* moved or deleted") as refusal:
        train.resume_run(run_dir, {"total_env_steps": 60})
    assert "Restore it from a copy" in str(refusal.value)


@pytest.mark.parametrize("text", ["", "garbage", '{"env_step": 40, "final_', "[40]"])
def test_a_finished_runs_unreadable_summary_is_named_and_its_fix_rewrites_it(
    finished_run, tmp_path, text
):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    path = run_dir / "summary.json"
    path.write_text(text)
    with pytest.raises(SetupError, match=r"summary\.json is damaged: .*cannot say whether") as err:
        train.resume_run(run_dir, {"total_env_steps": 40})
    assert f"rm {path}" in str(err.value)
    path.unlink()  # the fix the message gives: the run's end is written again, nothing trained
    run = train.resume_run(run_dir, {"total_env_steps": 40})
    train.train(run)
    summary = json.loads(path.read_text())
    assert summary["env_step"] == 40
    kept = json.loads((finished_run / "summary.json").read_text())
    assert summary["final_eval"] == kept["final_eval"]
    assert (run_dir / "eval.csv").read_text() == (finished_run / "eval.csv").read_text()


def test_a_config_json_that_lost_a_section_is_named_not_blamed_on_overrides(finished_run, tmp_path):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    config = json.loads((run_dir / "config.json").read_text())
    del config["agent"]
    (run_dir / "config.json").write_text(json.dumps(config))
    with pytest.raises(
        SetupError, match=r"config\.json does not hold the config of the checkpoint"
    ):
        train.resume_run(run_dir, {"total_env_steps": 60})


@pytest.mark.parametrize("name", ["summary.json", "eval.csv", "config.json", "checkpoint.pt"])
def test_a_kept_file_that_is_a_directory_is_named_and_nothing_changes(finished_run, tmp_path, name):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    (run_dir / name).unlink()
    (run_dir / name).mkdir()
    before = {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()}
    with pytest.raises(SetupError, match=rf"{name} is not a file.*; move it aside"):
        train.resume_run(run_dir, {"total_env_steps": 60})
    assert {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()} == before


def into_file(path):
    shutil.rmtree(path)
    path.write_text("not a directory\n")


def into_directory(path):
    path.unlink(missing_ok=True)
    path.mkdir()


@pytest.mark.parametrize(
    ("name", "damage", "said"),
    [
        ("tb", into_file, "is a file where the run writes its TensorBoard logs (a directory)"),
        ("learning_curve.png", into_directory, "it is a directory, not a regular file"),
        ("video.mp4", into_directory, "it is a directory, not a regular file"),
        (".lock", into_directory, "it is a directory, not a regular file"),
    ],
)
def test_a_path_the_run_writes_of_the_wrong_kind_is_named_before_training(
    finished_run, tmp_path, capsys, name, damage, said
):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    damage(run_dir / name)
    before = {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()}
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--resume", str(run_dir), "--total-env-steps", "60"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"{run_dir / name} " in err and said in err
    assert f"move it aside (mv {run_dir / name} {run_dir / name}.aside)" in err
    assert "cannot write to the run directory" not in err and "Traceback" not in err
    assert {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()} == before


def test_resume_takes_the_runs_checkpoint_file_for_its_directory(finished_run, tmp_path):
    run_dir = tmp_path / "copy"
    shutil.copytree(finished_run, run_dir)
    checkpoint = run_dir / "checkpoint.pt"
    assert train_cli.resumed_dir(str(checkpoint)) == run_dir
    assert train_cli.main(["--resume", str(checkpoint), "--total-env-steps", "60"]) == 0
    assert read_csv(run_dir / "eval.csv")[-1]["env_step"] == 60


def link_to_nothing(path):
    if path.is_dir():
        shutil.rmtree(path)
    path.unlink(missing_ok=True)
    path.symlink_to(f"/nowhere/{path.name}")


@pytest.mark.parametrize(
    ("name", "fix"),
    [
        ("tb", "Point the link at a directory that exists, or remove it (rm {path}) and the run"),
        ("learning_curve.png", "Remove the link (rm {path}): the run writes the file anew"),
    ],
)
def test_a_path_the_run_writes_that_links_to_nothing_is_named_before_training(
    finished_run, tmp_path, capsys, name, fix
):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    path = run_dir / name
    link_to_nothing(path)
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--resume", str(run_dir), "--total-env-steps", "60"])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert f"it is a symbolic link to /nowhere/{name}, which does not exist" in err
    assert fix.format(path=path) in err and "Traceback" not in err
    assert path.is_symlink()  # left as it was


def trained_on_a_gpu(run_dir):
    """``run_dir``'s config.json and checkpoint as a run trained with device cuda leaves them."""
    config = json.loads((run_dir / "config.json").read_text())
    (run_dir / "config.json").write_text(json.dumps({**config, "device": "cuda"}))
    payload = torch.load(run_dir / "checkpoint.pt", weights_only=False)
    payload["config"]["device"] = "cuda"
    torch.save(payload, run_dir / "checkpoint.pt")


def test_a_run_trained_on_a_gpu_resumes_with_device_cpu(finished_run, tmp_path, capsys):
    run_dir = tmp_path / "run"
    shutil.copytree(finished_run, run_dir)
    trained_on_a_gpu(run_dir)
    resume = ["--resume", str(run_dir), "--total-env-steps", "60"]
    if not torch.cuda.is_available():  # the advice given where the GPU is missing
        with pytest.raises(SystemExit):
            train_cli.main(resume)
        assert "use --device cpu (device='cpu')" in capsys.readouterr().err
    assert train_cli.main([*resume, "--device", "cpu"]) == 0
    assert json.loads((run_dir / "config.json").read_text())["device"] == "cpu"
    assert json.loads((run_dir / "summary.json").read_text())["env_step"] == 60
