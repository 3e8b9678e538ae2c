"""The distraction suite end to end: a tiny ball_in_cup run, simoun-eval --distraction."""

import csv
import json
import shutil

import numpy as np
import pytest

from simoun_agent.cli import eval as eval_cli
from simoun_agent.cli import train as train_cli
from simoun_agent.config import SetupError, resolve
from simoun_agent.generalization import (
    DISTRACTIONS,
    DistractionEvaluation,
    check_supported,
    distraction_callbacks,
    distractor,
    make_distracted_env,
    parse_distractions,
)
from simoun_agent.generalization.evaluation import ModeResult, evaluate_runs
from simoun_agent.generalization.report import REPORT_FILES, write_report

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

# A 1 s episode limit keeps ball_in_cup episodes at 50 env steps (13 decisions at repeat 4).
TINY = {
    "env": "dm_control/ball_in_cup-catch-v0",
    "env_kwargs": {"task_kwargs": {"time_limit": 1}},
    "image_size": 32,
    "seed": 2,
    "total_env_steps": 60,
    "warmup_agent_steps": 10,
    "eval_every": 1000,
    "eval_episodes": 1,
    "checkpoint_every": 1000,
    "video": False,
    "progress": False,
    "device": "cpu",
    "torch_threads": 1,
    "agent.batch_size": 8,
    "agent.num_filters": 8,
    "agent.feature_dim": 16,
    "agent.hidden_dim": 32,
    "agent.aux_hidden_dim": 32,
}
TINY_FLAGS = [
    item
    for key, value in TINY.items()
    for item in ("--" + key.replace("_", "-"), json.dumps(value).strip('"'))
]
MODES = list(DISTRACTIONS)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One tiny trained run and an exact copy of it, as two runs of one report."""
    root = tmp_path_factory.mktemp("runs")
    assert train_cli.main([*TINY_FLAGS, "--run-dir", str(root / "a")]) == 0
    shutil.copytree(root / "a", root / "b")
    return root


def test_simoun_eval_distraction_writes_table_csv_and_chart(runs, capsys):
    argv = [str(runs / "a"), str(runs / "b"), "--distraction", ",".join(MODES), "--episodes", "1"]
    assert eval_cli.main(argv) == 0
    out = runs / "generalization"
    with (out / "generalization.csv").open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert [(row["run"], row["mode"]) for row in rows] == [(r, m) for r in "ab" for m in MODES]
    by_run = {run: [row["return_mean"] for row in rows if row["run"] == run] for run in "ab"}
    assert by_run["a"] == by_run["b"]  # same weights, same seeds, same distractions
    table = (out / "generalization.md").read_text()
    assert "| run | train | color_easy | color_hard | video_easy | video_hard |" in table
    assert table.count("±") >= 10 and "ball_in_cup-catch" in table
    assert (out / "generalization.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "wrote" in capsys.readouterr().out

    # The train mode is the plain evaluation on the same episodes.
    plain = runs / "plain"
    assert (
        eval_cli.main([str(runs / "a"), "--episodes", "1", "--no-video", "--out", str(plain)]) == 0
    )
    metrics = json.loads((plain / "metrics.json").read_text())
    assert float(rows[0]["return_mean"]) == pytest.approx(metrics["return_mean"])


def test_each_mode_changes_only_the_pixels_of_the_runs_stack():
    config = resolve(None, {key: TINY[key] for key in ("env", "env_kwargs", "image_size")})
    action = np.full(2, 0.7, np.float32)  # ball_in_cup takes two forces
    frames = {}
    for mode in MODES:
        env = make_distracted_env(config, mode)
        obs, _ = env.reset(seed=9)
        obs, reward, *_ = env.step(action)
        frames[mode] = (obs["frames"], reward, env.unwrapped._env.physics.get_state().copy())
        env.close()
    plain_frames, plain_reward, plain_state = frames["train"]
    for mode in MODES[1:]:
        pixels, reward, state = frames[mode]
        assert reward == plain_reward
        np.testing.assert_array_equal(state, plain_state)
        assert np.abs(pixels.astype(int) - plain_frames).mean() > 5, mode


def test_bad_distraction_input_is_a_clear_error(runs, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        eval_cli.main([str(runs / "a"), "--distraction", "train,colr_hard"])
    assert exit_info.value.code == 2
    assert "did you mean 'color_hard'?" in capsys.readouterr().err

    (tmp_path / "clip.mp4").write_bytes(b"not a video")
    with pytest.raises(SystemExit) as exit_info:
        eval_cli.main([str(runs / "a"), "--distraction", "video_hard", "--videos", str(tmp_path)])
    assert exit_info.value.code == 2
    assert "no readable video" in capsys.readouterr().err

    with pytest.raises(SystemExit) as exit_info:
        eval_cli.main([str(runs / "a"), str(runs / "b")])
    assert "go with --distraction" in capsys.readouterr().err

    (tmp_path / "generalization.csv").write_text("run,mode\n")
    with pytest.raises(SystemExit) as exit_info:
        eval_cli.main([str(runs / "a"), "--distraction", "train", "--out", str(tmp_path)])
    assert "--overwrite" in capsys.readouterr().err

    point_reach = resolve(None, {"env": "simoun/PointReach-v0"})
    with pytest.raises(SetupError, match="needs a dm_control task"):
        check_supported(point_reach, ["train", "video_easy"])
    check_supported(point_reach, ["train"])


def test_training_with_distraction_curves_leaves_training_unchanged(runs):
    from simoun_agent.run.checkpoint import load_checkpoint
    from simoun_agent.run.logger import read_csv

    flags = ["--eval-distraction", "video_hard", "--eval-distraction", "color_easy"]
    assert train_cli.main([*TINY_FLAGS, *flags, "--run-dir", str(runs / "curves")]) == 0
    saved = json.loads((runs / "curves" / "config.json").read_text())
    assert saved["eval_distraction"] == ["video_hard", "color_easy"]
    rows = read_csv(runs / "curves" / "eval.csv")
    plain_rows = read_csv(runs / "a" / "eval.csv")
    assert [row["return_mean"] for row in rows] == [row["return_mean"] for row in plain_rows]
    for mode in ("video_hard", "color_easy"):
        assert all(np.isfinite(row[f"{mode}/return_mean"]) for row in rows)
    ours, theirs = load_checkpoint(runs / "curves"), load_checkpoint(runs / "a")
    for key, value in theirs["agent"]["actor"].items():
        np.testing.assert_array_equal(ours["agent"]["actor"][key].numpy(), value.numpy())


@pytest.mark.parametrize(
    ("flags", "message"),
    [
        (["--eval-distraction", "video_hrd"], "did you mean 'video_hard'?"),
        (["--eval-distraction", "train"], "is the run's own evaluation"),
        (
            ["--eval-distraction", "none"],
            "each one of color_easy, color_hard, video_easy, video_hard ('none': for no "
            "distraction, leave it out: the run's own evaluation always runs)",
        ),
        (["--env", "simoun/PointReach-v0", "--eval-distraction", "video_hard"], "dm_control"),
    ],
)
def test_bad_eval_distraction_is_refused_before_training(tmp_path, capsys, flags, message):
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main([*TINY_FLAGS, *flags, "--run-dir", str(tmp_path / "run")])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "run" / "config.json").exists()


@pytest.mark.parametrize(
    ("call", "error", "said"),
    [
        (
            lambda: parse_distractions(["color_easy", None]),
            TypeError,
            r"^parse_distractions\(text=\.\.\.\): item 1 of the list is NoneType None, not a mode",
        ),
        (
            lambda: parse_distractions(3),
            TypeError,
            r"^parse_distractions\(text=\.\.\.\) takes mode names, as one comma-separated str or",
        ),
        (
            lambda: make_distracted_env("dm_control/cartpole-swingup-v0", "color_easy"),
            TypeError,
            r"^make_distracted_env\(config=\.\.\.\) takes the run's TrainConfig .*got str",
        ),
        (
            lambda: check_supported({"env": "dm_control/cartpole-swingup-v0"}, ["color_easy"]),
            TypeError,
            r"^check_supported\(config=\.\.\.\) takes the run's TrainConfig",
        ),
        (lambda: distractor(None), TypeError, r"^distractor\(name=\.\.\.\) takes one mode name"),
        (
            lambda: distractor("color_easy,video_easy"),
            SetupError,
            r"^distractor\(name=\.\.\.\) takes one mode, got 'color_easy,video_easy'; call it once",
        ),
        (
            lambda: evaluate_runs("runs/a", ["train"], 1),
            TypeError,
            r"^evaluate_runs\(run_dirs=\.\.\.\) takes a list of run directories, got the one path",
        ),
        (
            lambda: evaluate_runs(["runs/a"], "train", 1),
            TypeError,
            r"^evaluate_runs\(modes=\.\.\.\) takes a list of mode names, got the str 'train'",
        ),
        (
            lambda: evaluate_runs(["runs/a"], ["trian"], 1),
            SetupError,
            r"unknown mode 'trian'; did you mean 'train'\?",
        ),
        (
            lambda: evaluate_runs(["runs/a"], ["train"], 1, progress=True),
            TypeError,
            r"^evaluate_runs\(progress=\.\.\.\) must be a callable",
        ),
        (
            lambda: evaluate_runs(["~/simoun-no-such-run"], ["train"], 1),
            ValueError,
            r"os.path.expanduser\('~/simoun-no-such-run'\)",
        ),
        (
            lambda: DistractionEvaluation("color_easy"),
            TypeError,
            r"^DistractionEvaluation\(modes=\.\.\.\) takes a list of mode names, got the str",
        ),
        (
            lambda: DistractionEvaluation(["train"]),
            SetupError,
            r"^DistractionEvaluation\(modes=\.\.\.\): unknown mode 'train'",
        ),
        (
            lambda: distraction_callbacks("dm_control/cartpole-swingup-v0"),
            TypeError,
            r"^distraction_callbacks\(config=\.\.\.\) takes the run's TrainConfig",
        ),
        (
            lambda: write_report([], "out", "title"),
            TypeError,
            r"^write_report\(results=\.\.\.\) must be a non-empty list of ModeResult",
        ),
    ],
)
def test_the_suites_functions_name_an_argument_of_the_wrong_type(call, error, said):
    with pytest.raises(error, match=said):
        call()


def test_write_report_takes_a_str_folder_and_makes_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    results = [ModeResult("a", "dm_control/cartpole-swingup-v0", "train", 1.0, 0.5, 2, 0, 60)]
    paths = write_report(results, "new/out", "cartpole under distraction")
    assert sorted(path.name for path in paths.values()) == sorted(REPORT_FILES)
    assert all((tmp_path / "new" / "out" / name).is_file() for name in REPORT_FILES)
