"""The config flags as tyro reads them: the overrides are the keys the command line
names, whatever their value; switches, lists, dicts and none in every spelling; help shows the
named preset's values as defaults."""

import pytest

from simoun_agent.cli import train as train_cli
from simoun_agent.cli.config_flags import overrides_from
from simoun_agent.config import SetupError, resolve


def overrides(argv: list[str]) -> dict:
    return overrides_from(train_cli.parse_command(argv).flags, argv, train_cli.TrainCommand)


def test_a_value_equal_to_the_presets_still_beats_the_recipe():
    # cpu's augmentation is shift and sac's is none: the flag names it, so it wins
    argv = ["--preset", "cpu", "--agent.recipe", "sac", "--agent.augmentation", "shift"]
    given = overrides(argv)
    assert given == {"agent.recipe": "sac", "agent.augmentation": "shift"}
    assert resolve("cpu", given).agent.augmentation == "shift"
    assert resolve("cpu", {"agent.recipe": "sac"}).agent.augmentation == "none"


@pytest.mark.parametrize(
    "argv",
    [
        ["--agent.no-curiosity"],
        ["--no-agent.curiosity"],
        ["--agent.curiosity", "false"],
        ["--agent.curiosity=off"],
        ["--set", "agent.curiosity=no"],
    ],
)
def test_every_spelling_of_a_false_switch(argv):
    assert overrides(argv) == {"agent.curiosity": False}


def test_lists_dicts_and_none():
    argv = ["--eval-distraction", "video_hard,color_hard", "--eval-distraction", "color_easy"]
    argv += ["--env-kwargs", '{"a": {"b": 1}}', "--action-repeat", "none", "--seed", "1"]
    assert overrides(argv) == {
        "eval_distraction": ("video_hard", "color_hard", "color_easy"),
        "env_kwargs": {"a": {"b": 1}},
        "action_repeat": None,
        "seed": 1,  # the default's value, given: an override
    }


def test_nothing_given_is_no_override():
    assert overrides(["--preset", "cpu"]) == {}


def test_help_shows_the_named_presets_values(capsys):
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--preset", "cpu", "--help"])
    assert exit_info.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "transitions per gradient step (default: 64)" in text  # the dataclass default is 512


def test_an_unknown_preset_is_refused_before_parsing(capsys):
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--preset", "cpuu"])
    assert exit_info.value.code == 2
    expected = "simoun-train: error: unknown preset 'cpuu' (did you mean 'cpu'?); choose one of"
    assert expected in capsys.readouterr().err


def test_an_unknown_set_key_is_refused_with_the_close_match():
    with pytest.raises(SetupError, match=r"unknown config key gamma \(did you mean agent.discount"):
        overrides(["--set", "gamma=0.9"])


@pytest.mark.parametrize("spelling", ["none", "None", "null"])
def test_preset_none_is_no_preset(spelling, capsys):
    argv = ["--preset", spelling, "--help"]
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(argv)
    assert exit_info.value.code == 0
    assert train_cli.parse_command(["--preset", spelling]).flags.preset is None
    assert overrides(["--preset", spelling, "--seed", "2"]) == {"seed": 2}


def test_set_preset_is_refused_pointing_at_the_preset_flag():
    with pytest.raises(
        SetupError,
        match=r"--set preset=cpu would only label the run: .* give "
        r"--preset cpu instead",
    ):
        overrides(["--set", "preset=cpu"])
    assert overrides(["--preset", "cpu", "--set", "preset=cpu"]) == {}


def test_set_preset_of_no_preset_says_so_with_the_presets():
    with pytest.raises(SetupError) as error:
        overrides(["--set", "preset=nope"])
    assert str(error.value).startswith(
        "--set preset=nope: 'nope' is no preset; the presets are cartpole-swingup, "
    )
    assert "one is applied by --preset NAME (e.g. --preset cpu), not by --set" in str(error.value)
    with pytest.raises(SetupError, match=r"'cpux' is no preset \(did you mean 'cpu'\?\)"):
        overrides(["--set", "preset=cpux"])


@pytest.mark.parametrize(
    ("pair", "said"),
    [
        ("resume=runs/a", "--set resume=runs/a: resume is not a config key but the flag "
         "--resume; give --resume runs/a instead"),
        ("overwrite=true", "overwrite is not a config key but the flag --overwrite; give "
         "--overwrite instead"),
        ("overwrite=false", "the flag --overwrite; leave --overwrite out"),
        ("version=1", "--set version=1: version is not a config key but the flag --version, "
         "which prints the installed version; give --version alone"),
        ("help=true", "--set help=true: help is not a config key but the flag --help, which "
         "lists every flag and config key; give --help alone"),
    ],
)  # fmt: skip
def test_set_of_a_command_flag_points_at_the_flag(pair, said):
    with pytest.raises(SetupError) as error:
        overrides(["--set", pair])
    assert said in str(error.value)


def test_set_of_a_sweep_flag_points_at_the_flag(capsys):
    from simoun_lab.cli import sweep as sweep_cli

    with pytest.raises(SystemExit) as stop:
        sweep_cli.main(["--set", "sweep_dir=s"])
    assert stop.value.code == 2
    assert "sweep_dir is not a config key but the flag --sweep-dir; give --sweep-dir s" in (
        capsys.readouterr().err
    )


def test_set_with_spaces_around_the_equals_sign_says_so():
    with pytest.raises(SetupError) as error:
        overrides(["--set", "agent.lr = 3e-4"])
    assert str(error.value) == (
        "--set 'agent.lr = 3e-4': KEY=VALUE takes no spaces around '='; write --set agent.lr=3e-4"
    )


def test_set_into_env_kwargs_gives_the_json_object_to_pass():
    with pytest.raises(SetupError, match=r"""give --env-kwargs '\{"size": 32\}'$"""):
        overrides(["--set", "env_kwargs.size=32"])
    with pytest.raises(SetupError, match=r"""--env-kwargs '\{"mode": "fast"\}'$"""):
        overrides(["--set", "env_kwargs.mode=fast"])


def test_set_of_a_value_that_kept_its_quotes_names_the_quotes_and_the_form():
    with pytest.raises(SetupError) as error:
        overrides(["--set", """env_kwargs='{"size": 32}'"""])
    assert str(error.value) == (
        """cannot read env_kwargs='{"size": 32}': the value still has its outer quotes ('...'), """
        """so it is one string; drop them, so that the command gets env_kwargs={"size": 32} (in """
        """a shell, quote the whole word: --set 'env_kwargs={"size": 32}')"""
    )
    assert overrides(["--set", """env_kwargs={"size": 32}"""]) == {"env_kwargs": {"size": 32}}
    with pytest.raises(SetupError, match=r"still has its outer quotes"):
        overrides(["--set", 'seed="3"'])


def test_env_kwargs_are_merged_into_a_presets_own():
    config = resolve("highway-cpu", {"env_kwargs": {"config": {"lanes_count": 2}}})
    assert config.env_kwargs["config"]["lanes_count"] == 2
    assert config.env_kwargs["config"]["action"] == {"type": "ContinuousAction"}
    assert config.env_kwargs["config"]["offroad_terminal"] is True
    assert resolve(None, {"env_kwargs": {"a": 1}}).env_kwargs == {"a": 1}
