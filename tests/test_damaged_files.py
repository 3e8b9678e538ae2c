"""A kept file damaged in a way its format still reads (a list, null, a number where the
config's object belongs, a value of the wrong type; an empty or cut log) is named as damaged,
with the fix, instead of failing inside the code, and is left as it was."""

import json

import pytest

from simoun_agent.cli import train as train_cli
from simoun_agent.config import resolve, to_dict
from simoun_agent.run.logger import CsvLog, read_csv, read_log


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
        ("train.csv", b"env_step,return\n\xff\xfe\n", "it is not a CSV file"),
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
