"""A kept file damaged in a way JSON still reads (a list, null, a number where the config's
object belongs) is named as damaged, with the fix, instead of failing inside the code."""

import pytest

from simoun_agent.cli import train as train_cli


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
