"""TrainConfig, presets and command-line overrides of simoun-train."""

import json

import pytest

from simoun_agent.run.presets import (
    PAPER_ACTION_REPEAT,
    PRESETS,
    SetupError,
    config_fields,
    from_dict,
    parse_value,
    resolve,
    to_dict,
)


@pytest.mark.parametrize("task", sorted(PAPER_ACTION_REPEAT))
def test_paper_presets_carry_design_values(task):
    config = resolve(task, {})
    assert config.env == f"dm_control/{task}-v0"
    assert config.resolved_action_repeat() == PAPER_ACTION_REPEAT[task]
    assert config.agent.batch_size == 512
    assert config.agent.lr == (2e-4 if task == "cheetah-run" else 1e-3)
    assert config.replay_capacity == 100_000
    assert config.warmup_agent_steps == 1000


def test_action_repeat_table_matches_design():
    assert PAPER_ACTION_REPEAT == {
        "cartpole-swingup": 8,
        "reacher-easy": 4,
        "cheetah-run": 4,
        "ball_in_cup-catch": 4,
        "walker-walk": 2,
        "finger-spin": 2,
    }
    # Without a preset, a known DMC task still gets the paper's repeat; other envs get 1.
    assert resolve(None, {"env": "dm_control/walker-walk-v0"}).resolved_action_repeat() == 2
    assert resolve(None, {"env": "simoun/PointReach-v0"}).resolved_action_repeat() == 1


def test_highway_preset_is_three_viewports_with_continuous_control():
    config = resolve("highway", {})
    assert config.cameras == 3 and config.image_size == 84
    highway = config.env_kwargs["config"]
    assert highway["action"] == {"type": "ContinuousAction"}
    assert highway["duration"] * highway["policy_frequency"] == 200
    assert highway["vehicles_count"] == 20


def test_every_value_can_be_overridden_and_overrides_win_over_the_preset():
    config = resolve("cheetah-run", {"agent.lr": 3e-4, "action_repeat": 2, "seed": 7})
    assert (config.agent.lr, config.action_repeat, config.seed) == (3e-4, 2, 7)
    assert config.agent.batch_size == 512  # untouched preset value stays


def test_every_config_field_has_a_docstring():
    undocumented = [key for key, (_, _, doc) in config_fields().items() if not doc]
    assert undocumented == []


def test_config_round_trips_through_json():
    config = resolve("highway", {"agent.encoder": "dual", "agent.curiosity": True})
    assert from_dict(json.loads(json.dumps(to_dict(config)))) == config


@pytest.mark.parametrize(
    ("key", "text", "expected"),
    [
        ("agent.curiosity", "false", False),
        ("agent.lr", "3e-4", 3e-4),
        ("action_repeat", "none", None),
        ("action_repeat", "4", 4),
        ("env_kwargs", '{"config": {"lanes_count": 3}}', {"config": {"lanes_count": 3}}),
    ],
)
def test_command_line_values_are_typed(key, text, expected):
    assert parse_value(key, text, config_fields()[key][0]) == expected


def test_bad_value_names_the_key():
    with pytest.raises(SetupError, match="seed='many'"):
        parse_value("seed", "many", int)


def test_unknown_key_suggests_the_close_one():
    with pytest.raises(SetupError, match=r"did you mean agent\.batch_size"):
        resolve(None, {"agent.bach_size": 64})


def test_preset_for_another_task_is_refused_with_the_fitting_presets():
    fitting = r"meant for dm_control/cheetah-run-v0.*walker-walk or cpu"
    with pytest.raises(SetupError, match=fitting):
        resolve("cheetah-run", {"env": "dm_control/walker-walk-v0"})
    with pytest.raises(SetupError, match="meant for highway-env ids"):
        resolve("highway", {"env": "dm_control/walker-walk-v0"})


def test_invalid_agent_combination_is_a_setup_error():
    with pytest.raises(SetupError, match="curiosity"):
        resolve(None, {"agent.encoder": "single"})
    assert resolve(None, {"agent.encoder": "single", "agent.curiosity": False}).agent.encoder


def test_cpu_preset_fits_any_env_and_is_small():
    config = resolve("cpu", {"env": "simoun/PointReach-v0"})
    assert config.agent.batch_size < 512 and config.total_env_steps <= 100_000
    assert set(PRESETS) >= {"cpu", "highway", *PAPER_ACTION_REPEAT}
