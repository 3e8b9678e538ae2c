"""Every layer of a run's configuration refuses an unknown key with its close match: the user's
overrides, a preset (top level or section), a recipe, and a saved config.json."""

import pytest

from simoun_agent.config import (
    PRESETS,
    RECIPES,
    Preset,
    Recipe,
    SetupError,
    from_dict,
    resolve,
    to_dict,
)
from simoun_agent.config.key_match import close_keys
from simoun_agent.config.keys import config_fields


def test_a_misspelled_top_level_key_in_a_preset_is_refused_with_the_close_match(monkeypatch):
    cpu = PRESETS["cpu"]
    broken = {**cpu.overrides, "total_env_step": 1000}
    monkeypatch.setitem(PRESETS, "cpu", Preset(cpu.description, broken, cpu.envs))
    with pytest.raises(SetupError) as error:
        resolve("cpu", {"agent.recipe": "drq"})
    assert str(error.value).startswith(
        "preset 'cpu': unknown config key total_env_step (did you mean total_env_steps?); "
        "fix its entry in simoun_agent.config.presets.PRESETS"
    )


def test_a_train_key_in_a_recipe_is_refused_pointing_at_the_train_key(monkeypatch):
    sac = RECIPES["sac"]
    monkeypatch.setitem(RECIPES, "sac", Recipe(sac.description, {**sac.values, "seed": 3}))
    with pytest.raises(SetupError) as error:
        resolve("cpu", {"agent.recipe": "sac"})
    assert str(error.value).startswith(
        "recipe 'sac': unknown config key agent.seed (did you mean seed?); "
        "fix its entry in simoun_agent.config.recipes.RECIPES"
    )


def test_a_saved_config_with_a_misspelled_key_is_refused_with_the_close_match():
    saved = to_dict(resolve("cpu", {}))
    saved["agent"]["bach_size"] = saved["agent"].pop("batch_size")
    with pytest.raises(SetupError) as error:
        from_dict(saved, "saved config")
    assert str(error.value).startswith(
        "saved config: unknown config key agent.bach_size (did you mean agent.batch_size?)"
    )


def test_a_section_given_as_a_key_is_answered_with_one_of_its_fields():
    with pytest.raises(SetupError) as error:
        resolve("cpu", {"agent": 1})
    assert "unknown config key agent (agent is a section: set one of its fields, e.g. agent." in (
        str(error.value)
    )


def test_an_unknown_recipe_or_preset_name_is_refused_with_the_names():
    with pytest.raises(SetupError, match=r"unknown recipe --agent.recipe 'drqv3' \(did you mean "):
        resolve(None, {"agent.recipe": "drqv3"})
    refused = r"unknown preset 'gpu' \(did you mean 'cpu'\?\); choose one of .*cpu"
    with pytest.raises(SetupError, match=refused):
        resolve("gpu", {})


def test_close_keys_read_words_through_their_synonyms():
    docs = {key: doc for key, (_, _, doc) in config_fields().items()}
    assert close_keys("frame_size", docs) == ["image_size"]
    assert close_keys("resolution", docs) == ["image_size"]
    assert close_keys("frame_skip", docs) == ["action_repeat"]


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        ("agent-lr", "agent.lr"),
        ("agent_lr", "agent.lr"),
        ("Agent.LR", "agent.lr"),
        ("agent-batch-size", "agent.batch_size"),
        ("agent.batch.size", "agent.batch_size"),
    ],
)
def test_a_key_with_another_separator_is_answered_with_the_key_itself(typed, meant):
    with pytest.raises(SetupError) as error:
        resolve("cpu", {typed: 1e-3})
    assert f"unknown config key {typed} (did you mean {meant}?)" in str(error.value)


@pytest.mark.parametrize(
    ("name", "meant"),
    [("Highway-CPU", "highway-cpu"), ("HIGHWAY_CPU", "highway-cpu"), ("CPU", "cpu")],
)
def test_a_preset_in_other_letter_case_is_answered_with_that_preset(name, meant):
    with pytest.raises(SetupError, match=rf"unknown preset '{name}' \(did you mean '{meant}'\?\)"):
        resolve(name, {})


def test_a_recipe_in_other_letter_case_is_answered_with_that_recipe():
    name = next(iter(RECIPES))
    with pytest.raises(SetupError, match=rf"\(did you mean '{name}'\?\)"):
        resolve(None, {"agent.recipe": name.upper()})
