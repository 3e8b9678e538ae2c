"""A kept file damaged in a way its format still reads (a list, null, a number where the
config's object belongs, a value of the wrong type; an empty or cut log) is named as damaged,
with the fix, instead of failing inside the code, and is left as it was."""

import gzip
import json
import os
import re
import shutil
from pathlib import Path

import pytest
from other_users import restored, run_as_user, unreadable
from test_train_resume import TINY

from simoun_agent import FrameReplay
from simoun_agent.cli import eval as eval_cli
from simoun_agent.cli import train as train_cli
from simoun_agent.config import SetupError, resolve, to_dict
from simoun_agent.run import train
from simoun_agent.run.logger import CsvLog, read_csv, read_log
from simoun_lab.cli import analyze as analyze_cli
from simoun_lab.cli import report as report_cli
from simoun_lab.sweep.report import DamagedRun, read_curve


@pytest.mark.parametrize("text", ["[]", "null", "3", '"config"'])
def test_a_config_json_that_is_not_an_object_is_named(text, tmp_path, capsys):
    (tmp_path / "config.json").write_text(text)
    with pytest.raises(SystemExit) as stop:
        train_cli.main(["--resume", str(tmp_path)])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f"{tmp_path / 'config.json'} holds " in err
    assert "where a JSON object of config keys belongs: it is damaged" in err
    assert "Traceback" not in err


def saved_run(run_dir, **changes):
    """A run directory holding a real saved config.json, ``changes`` written over its keys."""
    config = to_dict(resolve("cpu", {"env": "simoun/PointReach-v0"}))
    config.update(changes)
    run_dir.mkdir(exist_ok=True)
    (run_dir / "config.json").write_text(json.dumps(config))
    return run_dir


def test_a_wrong_type_in_config_json_is_named_as_the_files_key(tmp_path, capsys):
    run_dir = saved_run(tmp_path, image_size="big")
    with pytest.raises(SystemExit) as stop:
        train_cli.main(["--resume", str(run_dir)])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f'{run_dir / "config.json"}: image_size is "big", which must be an int >= 1' in err
    assert "--image-size" not in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("log", "text", "problem"),
    [
        ("eval.csv", b"", "it is empty"),
        ("train.csv", b"", "it is empty"),
        ("eval.csv", b"hello\nworld\n", "its first line has no env_step column"),
        ("eval.csv", b"env_step,return_mean\n20,1.5\n4", "line 3 has 1 fields"),
        ("eval.csv", b"env_step,return_mean\nabc,x\n", "line 2's env_step 'abc'"),
        ("train.csv", b"env_step,return\n\xff\xfe\n", "line 2 is not UTF-8 text (byte 0xff)"),
        ("eval.csv", b"env_step,return_mean\n40,1\n20,2\n", "line 3's env_step 20 does not "
         "come after line 2's 40 (rows out of order or repeated)"),
        ("train.csv", b"env_step,return\n20,1\n20,1\n", "line 3's env_step 20 does not come"),
    ],
)  # fmt: skip
def test_a_damaged_log_is_named_and_kept_on_resume(log, text, problem, tmp_path, capsys):
    run_dir = saved_run(tmp_path)
    (run_dir / log).write_bytes(text)
    before = {path.name: path.read_bytes() for path in run_dir.iterdir()}
    with pytest.raises(SystemExit) as stop:
        train_cli.main(["--resume", str(run_dir)])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f"{run_dir / log} is damaged: {problem}" in err
    assert f"mv {run_dir / log} {run_dir / log}.damaged" in err
    assert "Traceback" not in err
    assert {path.name: path.read_bytes() for path in run_dir.iterdir()} == before


def test_a_resumed_log_keeps_its_rows_up_to_the_checkpoint(tmp_path):
    path = tmp_path / "eval.csv"
    log = CsvLog(path)
    for step in (20, 40, 60):
        log.write({"env_step": step, "return_mean": step / 10})
    resumed = CsvLog(path, resume_step=40)
    assert resumed.last_row == {"env_step": "40", "return_mean": "4.0"}
    assert read_log(path) == (
        ["env_step", "return_mean"],
        [{"env_step": "20", "return_mean": "2.0"}, resumed.last_row],
    )


def test_a_log_saved_with_a_byte_order_mark_reads_as_written(tmp_path):
    path = tmp_path / "eval.csv"
    path.write_text("\ufeffenv_step,return_mean\r\n20,2.0\r\n", newline="")
    assert read_log(path) == (
        ["env_step", "return_mean"],
        [{"env_step": "20", "return_mean": "2.0"}],
    )
    assert read_csv(path) == [{"env_step": 20.0, "return_mean": 2.0}]


@pytest.fixture(scope="module")
def trained_run(tmp_path_factory):
    """A tiny run trained to its first checkpoint, as simoun-train leaves it."""
    run_dir = tmp_path_factory.mktemp("trained") / "run"
    run = train.create_run(resolve(None, {**TINY, "total_env_steps": 60, "run_dir": str(run_dir)}))
    train.train(run)
    run.env.close()
    run.eval_env.close()
    train.release(run)
    return run_dir


COMMANDS = {
    "simoun-train": lambda run: train_cli.main(["--resume", str(run), "--total-env-steps", "120"]),
    "simoun-eval": lambda run: eval_cli.main([str(run), "--episodes", "1", "--no-video"]),
    "simoun-analyze": lambda run: analyze_cli.main(
        ["masks", str(run), "--steps", "2", "--out", str(run.parent / "masks")]
    ),
    "simoun-report": lambda run: report_cli.main([str(run), "--out", str(run.parent / "report")]),
}


def refusal(command, run_dir, capsys):
    """What ``command`` says of ``run_dir``: it exits with status 2, without a traceback, and
    changes nothing in the run."""
    before = {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()}
    with pytest.raises(SystemExit) as stop:
        COMMANDS[command](run_dir)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.startswith(f"{command}")
    after = {path.name: path.read_bytes() for path in run_dir.iterdir() if path.is_file()}
    assert after == before
    return err


def zero_filled(path):
    path.write_bytes(bytes(path.stat().st_size))


def cut_short(path):
    path.write_bytes(path.read_bytes()[:1000])


def link_to_nothing(path):
    path.unlink()
    path.symlink_to(path.with_name("moved-away"))


@pytest.mark.parametrize("command", ["simoun-train", "simoun-eval", "simoun-analyze"])
@pytest.mark.parametrize(
    ("damage", "problem"),
    [
        (zero_filled, "is corrupt or incomplete: all its {size} bytes are zero"),
        (cut_short, "is corrupt or incomplete: it cannot be read (1000 bytes, cut short"),
        (link_to_nothing, "is damaged: it is a symbolic link to {path}/moved-away, which does"),
    ],
)
def test_a_damaged_checkpoint_is_named_by_every_command_that_reads_it(
    trained_run, damage, problem, command, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    path = run_dir / "checkpoint.pt"
    size = path.stat().st_size
    damage(path)
    err = refusal(command, run_dir, capsys)
    assert f"{path} {problem.format(size=size, path=run_dir)}" in err
    assert "Restore" in err and "start a new run" in err


def test_a_replay_of_another_run_is_named_on_resume(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    (replay,) = run_dir.glob("replay-*.npz")
    FrameReplay(1000, (3, 40, 40), 2).save(replay)
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{replay} (the replay of the checkpoint) is damaged: it holds another run's " in err
    assert "(frame_shape (3, 40, 40) in the file, (3, 32, 32) in the run's config)" in err
    assert "Restore this run's own replay and checkpoint from a copy" in err


def utf16(path):
    path.write_text(path.read_text(), encoding="utf-16")


def nul_in_first_line(path):
    data = path.read_bytes()
    path.write_bytes(data[:4] + b"\0" + data[4:])


def huge_step(path):
    text = path.read_text()
    path.write_text(text + "1" * 40 + text.splitlines()[-1][text.splitlines()[-1].index(",") :])


def named_pipe(path):
    path.unlink()
    os.mkfifo(path)


def finished_run(run_dir):
    """A run directory as simoun-report and a resume read it before the checkpoint."""
    saved_run(run_dir)
    (run_dir / "eval.csv").write_text("env_step,return_mean,wall_time_s\n0,1.0,1.0\n60,2.0,2.0\n")
    (run_dir / "train.csv").write_text("env_step,return\n20,1.0\n40,2.0\n")
    summary = {"env_step": 60, "wall_time_s": 2.0, "final_eval": {"return_mean": 2.0}}
    (run_dir / "summary.json").write_text(json.dumps(summary))
    return run_dir


def comment_first(path):
    path.write_text("# trained on the lab laptop\n" + path.read_text())


STEP = "env_step 1111111111111111111111111111111111111111"
KEPT_DAMAGES = [
    ("eval.csv", comment_first, "line 1 is a comment ('# trained on the lab laptop'): CSV has"),
    ("config.json", utf16, "it is saved as UTF-16 text, not UTF-8"),
    ("config.json", nul_in_first_line, "line 1 holds a NUL byte"),
    ("config.json", link_to_nothing, "it is a symbolic link to "),
    ("eval.csv", nul_in_first_line, "line 1 holds a NUL byte"),
    ("eval.csv", huge_step, f"{STEP} is past 2**63"),
    ("eval.csv", link_to_nothing, "it is a symbolic link to "),
    ("summary.json", link_to_nothing, "it is a symbolic link to "),
]
"""file, damage, what is said of it; train.csv only on resume: simoun-report does not read it"""


@pytest.mark.parametrize(
    ("command", "file", "damage", "problem"),
    [
        *(("simoun-train", *damage) for damage in KEPT_DAMAGES),
        ("simoun-train", "train.csv", nul_in_first_line, "line 1 holds a NUL byte"),
        ("simoun-train", "train.csv", huge_step, f"{STEP} is past 2**63"),
        ("simoun-train", "train.csv", comment_first, "line 1 is a comment"),
        *(("simoun-report", *damage) for damage in KEPT_DAMAGES),
        # a resume refuses a config.json that is not a file before reading it
        ("simoun-report", "config.json", named_pipe, "it is a named pipe (FIFO), not a regular"),
    ],
)
def test_a_damaged_config_or_log_is_named_on_resume_and_by_the_report(
    command, file, damage, problem, tmp_path, capsys
):
    run_dir = finished_run(tmp_path / "run")
    damage(run_dir / file)
    err = refusal(command, run_dir, capsys)
    if command == "simoun-report":
        assert "every run is damaged: .: " in err and "restore those files from a copy" in err
        if damage is huge_step:
            assert f"{file} line 4: env_step 1.11111e+39 is past 2**63" in err
        else:
            assert f"{file} is damaged: {problem}" in err
    else:
        assert f"{run_dir / file} is damaged: " in err and problem in err
        assert "Restore the file from a copy" in err


@pytest.mark.parametrize("command", ["simoun-eval", "simoun-analyze"])
def test_a_config_json_of_another_run_beside_the_checkpoint_is_named(
    trained_run, command, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    config = json.loads((run_dir / "config.json").read_text())
    (run_dir / "config.json").write_text(json.dumps({**config, "seed": config["seed"] + 1}))
    err = refusal(command, run_dir, capsys)
    assert f"{run_dir / 'config.json'} does not hold the config of the checkpoint in " in err
    assert f"(seed: {config['seed']} in the checkpoint, {config['seed'] + 1} now)" in err


def test_a_replay_of_another_seed_or_step_is_named_on_resume(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    (path,) = run_dir.glob("replay-*.npz")
    replay = FrameReplay.load(path)
    replay.rng.random()  # the same transitions drawn from by another random stream
    replay.save(path)
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{path} (the replay of the checkpoint) is not the one saved with " in err
    assert "its random state is another run's" in err and "copied or linked from another" in err


@pytest.mark.parametrize("log", ["eval.csv", "train.csv"])
def test_a_log_older_than_the_checkpoint_is_named_on_resume(trained_run, log, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    lines = (run_dir / log).read_text().splitlines(keepends=True)
    last = lines[-1].split(",")[lines[0].split(",").index("env_step")]
    (run_dir / log).write_text("".join(lines[:2]))
    first = lines[1].split(",")[lines[0].split(",").index("env_step")]
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{run_dir / log} ends at env step {first}, but the checkpoint (env step 60) " in err
    assert f"had logged rows up to env step {last}" in err
    assert f"Restore the newer {log} from a copy" in err and f"mv {run_dir / log}" in err


def test_steps_written_as_whole_floats_read_as_steps_by_resume_and_report(tmp_path):
    path = tmp_path / "eval.csv"
    path.write_text("env_step,return_mean\n0.0,1.0\n20.0,2.0\n")
    assert read_log(path)[1] == [
        {"env_step": "0", "return_mean": "1.0"},
        {"env_step": "20", "return_mean": "2.0"},
    ]
    path.write_text("env_step,return_mean,wall_time_s\n0,1.0,1.0\n20.5,2.0,2.0\n")
    with pytest.raises(SetupError, match=r"line 3's env_step '20.5' is not a step count"):
        read_log(path)
    with pytest.raises(DamagedRun, match=r"line 3: env_step 20.5 is not a step count"):
        read_curve(path)


def test_a_summary_of_another_run_is_named_by_the_report(tmp_path, capsys):
    run_dir = finished_run(tmp_path / "run")
    summary = {"env_step": 60, "wall_time_s": 2.0, "final_eval": {"return_mean": -15.96}}
    (run_dir / "summary.json").write_text(json.dumps(summary))
    err = refusal("simoun-report", run_dir, capsys)
    assert "summary.json's final return -15.96 is not the 2 of the last evaluation in " in err
    assert "(env step 60): the two files are of different runs" in err


def spaced(path):
    """``path`` written with a space after each comma, as a person or a spreadsheet may."""
    path.write_text(path.read_text().replace(",", ", "))


def test_a_log_with_a_space_after_each_comma_reads_as_written_and_resumes_under_its_header(
    trained_run, tmp_path
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    header = (run_dir / "eval.csv").read_text().splitlines()[0]
    rows = read_csv(run_dir / "eval.csv")
    spaced(run_dir / "eval.csv")
    spaced(run_dir / "train.csv")
    assert read_csv(run_dir / "eval.csv") == rows
    assert report_cli.main([str(run_dir), "--out", str(tmp_path / "report")]) == 0
    assert train_cli.main(["--resume", str(run_dir), "--total-env-steps", "80"]) == 0
    lines = (run_dir / "eval.csv").read_text().splitlines()
    assert lines[0] == header  # the resumed rows go under the run's columns, none added
    assert read_csv(run_dir / "eval.csv")[: len(rows)] == rows
    assert read_csv(run_dir / "eval.csv")[-1]["env_step"] == 80
    assert all(line.count(",") == header.count(",") for line in lines)


def test_read_csv_takes_a_str_or_a_path_and_names_any_other_argument(trained_run):
    path = trained_run / "eval.csv"
    assert read_csv(str(path)) == read_csv(path)
    assert read_csv(str(path))[-1]["env_step"] == 60
    with pytest.raises(TypeError, match=re.escape("read_csv's path must be a str or a")):
        read_csv(3)


@pytest.mark.parametrize(
    ("damage", "problem"),
    [
        (lambda p: p.write_text(p.read_text().split("\n", 1)[1]), "holds numbers where the header"),
        (lambda p: p.write_text(p.read_text().replace("env_step", "step")), "has no env_step"),
        (lambda p: p.write_text('{"env_step": 20}\n'), "it looks like JSON (it begins with '{')"),
        (lambda p: p.write_text(p.read_text().rstrip("\n") + "x\n"), "line 3: wall_time_s is "),
    ],
    ids=["header deleted", "header renamed", "json", "a word for a number"],
)
def test_read_csv_names_a_log_no_run_writes(trained_run, damage, problem, tmp_path):
    path = shutil.copy(trained_run / "eval.csv", tmp_path / "eval.csv")
    damage(path)
    with pytest.raises(ValueError, match=re.escape(problem)) as refusal:
        read_csv(path)
    assert str(refusal.value).startswith(f"{path} cannot be read as a CSV log: ")


def test_a_word_in_a_number_column_is_named_by_line_and_column_in_the_report(
    trained_run, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    path = run_dir / "eval.csv"
    path.write_text(path.read_text().rstrip("\n").rpartition(",")[0] + ",n/a\n")
    with pytest.raises(SystemExit):
        report_cli.main([str(run_dir), "--out", str(tmp_path / "report"), "--at-wall-time", "0.1"])
    assert "eval.csv is damaged: line 3: wall_time_s is 'n/a', not a number" in (
        capsys.readouterr().err
    )


def test_a_header_deleted_from_a_log_is_named_on_resume(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    path = run_dir / "eval.csv"
    path.write_text(path.read_text().split("\n", 1)[1])
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{path} is damaged: its first line (0," in err
    assert "the header line is missing" in err


def test_a_packed_replay_is_named_with_the_command_that_unpacks_it(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    (replay,) = run_dir.glob("replay-*.npz")
    with replay.open("rb") as source, gzip.open(f"{replay}.gz", "wb") as packed:
        shutil.copyfileobj(source, packed)
    replay.unlink()
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{replay} (the replay of the checkpoint) is missing, but {replay.name}.gz" in err
    assert f"gunzip -k {replay}.gz" in err


@pytest.mark.parametrize(
    ("argv", "name"),
    [
        (["eval", "--episodes", "1", "--no-video", "--overwrite"], "metrics.json"),
        (["eval", "--episodes", "1", "--distraction", "color_easy", "--overwrite"],
         "generalization.png"),
        (["bias", "--pairs", "8", "--overwrite"], "bias.json"),
        (["masks", "--steps", "2", "--overwrite"], "ep0-step1.png"),
        (["report"], "report.md"),
    ],
    ids=lambda value: value[0] if isinstance(value, list) else None,
)  # fmt: skip
def test_an_output_file_that_is_a_folder_is_refused_before_the_work(
    trained_run, argv, name, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    out = tmp_path / "out"
    (out / name).mkdir(parents=True)
    (out / name / "kept").write_text("an earlier output")
    command, *flags = argv
    main = {"eval": eval_cli.main, "report": report_cli.main}.get(command, analyze_cli.main)
    args = [str(run_dir), *flags, "--out", str(out)]
    with pytest.raises(SystemExit) as stop:
        main(args if main is not analyze_cli.main else [command, *args])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert f"cannot write {out / name} (it is a directory, not a regular file)" in err
    assert f"mv {out / name} {out / name}.aside" in err and "or pass another --out" in err
    assert "Traceback" not in err
    assert sorted(path.name for path in out.iterdir()) == [name]  # nothing written before


@pytest.mark.parametrize(
    ("source", "target", "problem"),
    [
        ("train.csv", "eval.csv", "it holds train.csv's columns (episode, return, length, "
         "env_steps_per_s), not eval.csv's"),
        ("eval.csv", "train.csv", "it holds eval.csv's columns (return_mean, return_std, "
         "return_min, return_max, length_mean), not train.csv's"),
        ("summary.json", "config.json", "it holds summary.json's keys (env_step, final_eval), "
         "not config.json's"),
    ],
)  # fmt: skip
def test_a_kept_file_copied_over_another_is_named_on_resume_and_left_as_it_was(
    trained_run, source, target, problem, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    shutil.copyfile(run_dir / source, run_dir / target)
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{run_dir / target} is damaged: {problem}" in err
    assert f"{source} was copied over it" in err


def test_logs_mixed_into_one_are_named_by_resume_and_the_report(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    path = run_dir / "eval.csv"
    lines = path.read_text().splitlines()
    path.write_text("\n".join([lines[0] + ",episode", *(line + ",3" for line in lines[1:])]))
    mixed = "it holds train.csv's columns (episode) beside its own: the run's two files were mixed"
    assert mixed in refusal("simoun-train", run_dir, capsys)
    assert mixed in refusal("simoun-report", run_dir, capsys)


@pytest.mark.parametrize("command", ["simoun-eval", "simoun-analyze"])
def test_a_summary_copied_over_config_json_is_named_by_the_readers_of_a_checkpoint(
    trained_run, command, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    (run_dir / "summary.json").write_text('{"env_step": 60, "final_eval": {"return_mean": 1}}')
    shutil.copyfile(run_dir / "summary.json", run_dir / "config.json")
    err = refusal(command, run_dir, capsys)
    assert f"{run_dir / 'config.json'} is damaged: it holds summary.json's keys" in err


def packed(path, suffix=".gz"):
    """``path`` packed in place (``gzip path``: only ``path.gz`` is left)."""
    with path.open("rb") as source, gzip.open(f"{path}{suffix}", "wb") as target:
        shutil.copyfileobj(source, target)
    path.unlink()


@pytest.mark.parametrize("command", ["simoun-train", "simoun-eval", "simoun-analyze"])
@pytest.mark.parametrize("name", ["checkpoint.pt", "config.json"])
def test_a_packed_checkpoint_or_config_is_named_with_the_command_that_unpacks_it(
    trained_run, name, command, tmp_path, capsys
):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    packed(run_dir / name)
    err = refusal(command, run_dir, capsys)
    assert f"{run_dir / name} is missing, but {name}.gz lies beside it" in err
    assert f"gunzip -k {run_dir / name}.gz" in err
    assert "stopped before its first checkpoint" not in err


@pytest.mark.parametrize("name", ["eval.csv", "train.csv"])
def test_a_packed_log_is_named_on_resume_not_started_anew(trained_run, name, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    packed(run_dir / name, ".xz")
    err = refusal("simoun-train", run_dir, capsys)
    assert f"{run_dir / name} is missing, but {name}.xz lies beside it" in err
    assert f"unxz -k {run_dir / name}.xz" in err


def test_a_packed_eval_csv_or_config_is_named_by_the_report(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    packed(run_dir / "eval.csv")
    assert "eval.csv is missing, but eval.csv.gz lies beside it" in refusal(
        "simoun-report", run_dir, capsys
    )
    (run_dir / "eval.csv.gz").unlink()
    packed(run_dir / "config.json")
    assert "config.json is missing, but config.json.gz lies beside it" in refusal(
        "simoun-report", run_dir, capsys
    )


@pytest.mark.parametrize("columns", ["return_mean", b"return_mean", 3, ("return_mean", 3)])
def test_read_csv_names_columns_that_are_no_list_of_names(trained_run, columns):
    with pytest.raises(TypeError, match=re.escape("read_csv's columns must be a list or tuple")):
        read_csv(trained_run / "eval.csv", columns=columns)
    rows = read_csv(trained_run / "eval.csv", columns=["return_mean"])
    assert rows[-1]["env_step"] == 60


def study_run(tmp_path, trained_run, place):
    """The trained run's files laid out as a study archive keeps a tuning run (no checkpoint),
    under ``tmp_path / place``, with the archive's study.json."""
    run_dir = tmp_path / place / "tuning/simoun/agent.n_step=1/point-reach/s1"
    run_dir.mkdir(parents=True)
    for name in ("config.json", "eval.csv", "train.csv"):
        shutil.copyfile(trained_run / name, run_dir / name)
    (run_dir / "trial.json").write_text("{}")
    return run_dir


@pytest.mark.parametrize("with_record", [True, False], ids=["study.json", "archive layout"])
def test_resume_of_an_archived_study_run_never_advises_overwrite(
    trained_run, with_record, tmp_path, capsys
):
    run_dir = study_run(tmp_path, trained_run, "arch")
    if with_record:
        (tmp_path / "arch/study.json").write_text("{}")
    err = refusal("simoun-train", run_dir, capsys)
    assert "--overwrite" not in err
    assert f"{run_dir} is a run of the study in {tmp_path / 'arch'}" in err
    assert "a study archive keeps no checkpoint.pt" in err and "a new --run-dir" in err
    err = refusal("simoun-eval", run_dir, capsys)
    assert "a study archive keeps no checkpoints" in err


@pytest.mark.parametrize("command", ["simoun-train", "simoun-eval", "simoun-analyze"])
@pytest.mark.parametrize("record", ["study.json", "sweep.json"])
def test_a_study_or_sweep_folder_given_as_a_run_is_named(
    trained_run, command, record, tmp_path, capsys
):
    folder = tmp_path / "folder"
    folder.mkdir()
    (folder / record).write_text("{}")
    err = refusal(command, folder, capsys)
    assert f"{folder} is a simoun-{record.split('.')[0]} directory" in err
    assert "not a run directory" in err


LFS = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\nsize 20864795\n"
)
"""A Git LFS pointer, what a clone made without git-lfs holds in place of each LFS file."""


@pytest.mark.parametrize("name", ["eval.csv", "config.json", "checkpoint.pt"])
def test_a_git_lfs_pointer_is_named_with_git_lfs_pull(name, trained_run, tmp_path, capsys):
    run_dir = Path(shutil.copytree(trained_run, tmp_path / "run"))
    (run_dir / name).write_text(LFS)
    if name == "eval.csv":
        with pytest.raises(DamagedRun) as info:
            read_curve(run_dir / name)
        said = str(info.value)
    else:
        with pytest.raises(SystemExit):
            eval_cli.main([str(run_dir), "--episodes", "1", "--no-video"])
        said = capsys.readouterr().err
    assert f"{name} is damaged" in said or f"checkpoint {run_dir / name}" in said
    assert "it is a Git LFS pointer, not the file itself" in said
    assert "git lfs install && git lfs pull" in said and "cut short" not in said


def tree(folder):
    """Every path under ``folder`` with its bytes (None for a directory)."""
    return {
        str(path.relative_to(folder)): None if path.is_dir() else path.read_bytes()
        for path in sorted(folder.rglob("*"))
    }


def new_run_refusal(run_dir, capsys, *flags):
    """What ``simoun-train`` says of a new run in ``run_dir``, asserting that it exits with
    status 2 and writes nothing in the folder above ``run_dir`` (no lock file included)."""
    folder = run_dir.parent
    before = tree(folder)
    given = {
        key: value if isinstance(value, str) else json.dumps(value) for key, value in TINY.items()
    }
    argv = [x for key, value in given.items() for x in ("--set", f"{key}={value}")]
    with pytest.raises(SystemExit) as stop:
        train_cli.main([*argv, "--run-dir", str(run_dir), *flags])
    assert stop.value.code == 2
    assert tree(folder) == before
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


@pytest.mark.parametrize("overwrite", [[], ["--overwrite"]], ids=["", "--overwrite"])
def test_a_new_run_refused_in_a_study_or_sweep_writes_nothing_there(
    trained_run, overwrite, tmp_path, capsys
):
    archived = study_run(tmp_path, trained_run, "arch")
    (tmp_path / "arch/study.json").write_text("{}")
    err = new_run_refusal(archived, capsys, *overwrite)
    assert f"{archived} is a run of the study in {tmp_path / 'arch'}" in err
    for record in ("study.json", "sweep.json"):
        folder = tmp_path / record.split(".")[0] / "folder"
        folder.mkdir(parents=True)
        (folder / record).write_text("{}")
        err = new_run_refusal(folder, capsys, *overwrite)
        assert f"--run-dir {folder} is a simoun-{record.split('.')[0]} directory" in err
        assert "Pass a --run-dir outside it" in err
    with_checkpoint = shutil.copytree(trained_run, tmp_path / "kept" / "run")
    (with_checkpoint / ".lock").unlink(missing_ok=True)
    err = new_run_refusal(with_checkpoint, capsys, *overwrite)
    assert "already holds a run with a checkpoint" in err


def test_a_refused_resume_writes_no_lock_in_the_run(trained_run, tmp_path, capsys):
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    (run_dir / ".lock").unlink(missing_ok=True)
    before = tree(run_dir)
    with pytest.raises(SystemExit):
        train_cli.main(["--resume", str(run_dir), "--total-env-steps", "20"])
    assert "there is nothing to continue" in capsys.readouterr().err
    assert tree(run_dir) == before


def test_a_refused_distraction_evaluation_makes_no_report_directory(tmp_path, capsys):
    out = tmp_path / "reports" / "dmcgb"
    not_a_run = tmp_path / "empty"
    not_a_run.mkdir()
    with pytest.raises(SystemExit) as stop:
        eval_cli.main([str(not_a_run), "--distraction", "train", "--out", str(out)])
    assert stop.value.code == 2
    assert "Traceback" not in capsys.readouterr().err
    assert not (tmp_path / "reports").exists()


@pytest.mark.parametrize(
    ("module", "args", "name"),
    [
        ("simoun_agent.cli.train", ("--resume", "{run}", "--total-env-steps=120"), "config.json"),
        ("simoun_agent.cli.eval", ("{run}", "--episodes=1", "--no-video"), "checkpoint.pt"),
        ("simoun_lab.cli.analyze", ("bias", "{run}", "--pairs=8", "--out", "{out}"), "config.json"),
    ],
)
def test_a_kept_file_the_user_may_not_read_is_named_with_the_fix_for_permissions(
    trained_run, module, args, name, tmp_path
):
    """Another user's file (``sudo cp`` leaves it root's, mode 600) is whole: the command says
    it cannot be read, whose it is and how to make it readable, never that it is damaged, to be
    restored, deleted or trained anew."""
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    (run_dir / ".lock").unlink(missing_ok=True)
    unreadable(run_dir / name)
    try:
        argv = [arg.format(run=run_dir, out=tmp_path / "out") for arg in args]
        result = run_as_user(module, *argv)
    finally:
        restored(run_dir / name)
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"{run_dir / name} cannot be read: permission denied (owner " in result.stderr
    assert "chmod" in result.stderr
    for word in ("Traceback", "damaged", "corrupt", "Restore", "delete", "start a new run"):
        assert word not in result.stderr


def test_another_users_lock_in_the_users_run_is_named_with_its_removal(trained_run, tmp_path):
    """A lock file another user left (a trainer once run with sudo) in the user's writable run:
    the lock is named, and since no process holds it, removing it is the fix."""
    run_dir = shutil.copytree(trained_run, tmp_path / "run")
    lock = run_dir / ".lock"
    lock.write_text("")
    unreadable(lock)
    try:
        result = run_as_user(
            "simoun_agent.cli.train", "--resume", str(run_dir), "--total-env-steps", "120"
        )
    finally:
        restored(lock)
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"{lock} is another user's" in result.stderr
    assert "no process holds it" in result.stderr and f"rm {lock}" in result.stderr
    assert "cannot write to the run directory" not in result.stderr
