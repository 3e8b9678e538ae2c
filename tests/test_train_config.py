"""TrainConfig, presets and command-line overrides of simoun-train."""

import json
import subprocess
import sys

import gymnasium as gym
import pytest

from simoun_agent.config import (
    PRESETS,
    RECIPES,
    Preset,
    Recipe,
    SetupError,
    TrainConfig,
    from_dict,
    resolve,
    to_dict,
)
from simoun_agent.config.envs import PAPER_ACTION_REPEAT
from simoun_agent.config.keys import config_fields, parse_value
from simoun_agent.config.presets import CPU_PRESET_TIME
from simoun_agent.config.resolve import from_flat
from simoun_agent.config.train import RESUMABLE_FIELDS


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
    # the rows of DESIGN.md's table: tasks by action repeat
    by_repeat = {8: ["cartpole-swingup"], 4: ["reacher-easy", "cheetah-run", "ball_in_cup-catch"]}
    by_repeat[2] = ["walker-walk", "finger-spin"]
    assert PAPER_ACTION_REPEAT == {task: r for r, tasks in by_repeat.items() for task in tasks}
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


HIGHWAY_TASKS = ("intersection-v0", "racetrack-v0", "parking-v0", "exit-v0", "u-turn-v0")


def test_a_highway_preset_takes_every_highway_env_id_in_a_fresh_process():
    # before anything imports highway_env, its ids are not in the registry; a highway preset
    # must not call them "not highway-env ids" for that
    code = (
        "import sys\n"
        "from simoun_agent.config import resolve\n"
        "assert 'highway_env' not in sys.modules\n"
        f"for env in {HIGHWAY_TASKS!r}:\n"
        "    assert resolve('highway-cpu', {'env': env}).env == env\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


@pytest.mark.parametrize("env", HIGHWAY_TASKS)
def test_a_highway_preset_keeps_only_the_settings_the_task_has(env):
    from gymnasium.envs.registration import load_env_creator

    config = resolve("highway", {"env": env})
    defaults = load_env_creator(gym.spec(env).entry_point).default_config()
    assert set(config.env_kwargs["config"]) <= set(defaults)
    assert config.env_kwargs["config"]["action"] == {"type": "ContinuousAction"}
    assert resolve("highway", {}).env_kwargs["config"]["lanes_count"] == 4  # its own task's


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
    with pytest.raises(SetupError, match=r"did you mean agent\.batch_size\?"):
        resolve(None, {"agent.bach_size": 64})


@pytest.mark.parametrize(
    ("typed", "meant"),
    [
        ("agent.learning_rate", "agent.lr"),  # letters alone pointed at agent.n_step
        ("learning-rate", "agent.lr"),
        ("agent.batch", "agent.batch_size"),
        ("agent.batch-size", "agent.batch_size"),  # the flag's spelling
        ("batch", "agent.batch_size"),
        ("agent.gamma", "agent.discount"),  # only the field's docstring says gamma
        ("agent.tau", "agent.critic_tau or agent.encoder_tau"),
        ("seeds", "seed"),
        ("agent.seed", "seed"),
        ("agent.lr_alpha", "agent.alpha_lr"),
        ("threads", "torch_threads"),
        ("frame_skip", "action_repeat"),
        ("total_steps", "total_env_steps"),
    ],
)
def test_misspelled_keys_suggest_the_field_meant_by_words_and_docs(typed, meant):
    with pytest.raises(SetupError) as error:
        resolve(None, {typed: 1})
    assert f"unknown config key {typed} (did you mean {meant}?)" in str(error.value)


def test_a_misspelled_key_in_a_preset_is_refused_with_the_close_match(monkeypatch):
    cpu = PRESETS["cpu"]
    broken = {**cpu.overrides, "agent": {**cpu.overrides["agent"], "bach_size": 32}}
    monkeypatch.setitem(PRESETS, "cpu", Preset(cpu.description, broken, cpu.envs))
    with pytest.raises(SetupError) as error:
        resolve("cpu", {})
    message = str(error.value)
    assert message.startswith("preset 'cpu': unknown config key agent.bach_size")
    assert "did you mean agent.batch_size?" in message and "PRESETS" in message


def test_a_misspelled_key_in_a_recipe_is_refused_with_the_close_match(monkeypatch):
    drq = RECIPES["drq"]
    monkeypatch.setitem(RECIPES, "drq", Recipe(drq.description, {**drq.values, "gamma": 0.9}))
    for preset, overrides in ((None, {"agent.recipe": "drq"}), ("cpu", {"agent.recipe": "drq"})):
        with pytest.raises(SetupError) as error:
            resolve(preset, overrides)
        message = str(error.value)
        assert message.startswith("recipe 'drq': unknown config key agent.gamma")
        assert "did you mean agent.discount?" in message and "RECIPES" in message


def test_every_shipped_preset_and_recipe_resolves():
    env = {"highway": "highway-v0"}
    for name in PRESETS:
        assert resolve(name, {"env": env.get(name, resolve(name, {}).env)}).preset == name
    for name in RECIPES:
        assert resolve(None, {"agent.recipe": name}).agent.recipe == name


def test_flat_values_with_an_unknown_key_are_refused_not_dropped():
    with pytest.raises(SetupError, match=r"unknown config key agent\.learning_rate"):
        from_flat({"agent.learning_rate": 1e-3})


def test_module_colon_id_imports_the_module_and_is_saved_as_env_module():
    config = resolve(None, {"env": "minigrid:MiniGrid-DoorKey-6x6-v0"})
    assert (config.env, config.env_module) == ("MiniGrid-DoorKey-6x6-v0", "minigrid")
    assert to_dict(config)["env_module"] == "minigrid"
    assert from_dict(to_dict(config)) == config
    same = resolve(None, {"env": "MiniGrid-DoorKey-6x6-v0", "env_module": "minigrid"})
    assert same == config
    with pytest.raises(SetupError, match="names the module 'minigrid' but --env-module is 'x'"):
        resolve(None, {"env": "minigrid:MiniGrid-DoorKey-6x6-v0", "env_module": "x"})


def test_torch_threads_is_resumable_and_what_the_agent_learns_is_not():
    assert "torch_threads" in RESUMABLE_FIELDS
    assert not {"seed", "env", "env_module", "env_kwargs", "image_size"} & set(RESUMABLE_FIELDS)
    assert not any(key.startswith("agent.") for key in RESUMABLE_FIELDS)


def test_the_cpu_preset_quotes_the_measured_wall_time():
    assert CPU_PRESET_TIME in PRESETS["cpu"].description
    assert "measured" in CPU_PRESET_TIME  # a measurement with its source, not a guess
    assert TrainConfig().env_module is None


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


@pytest.mark.parametrize(
    ("change", "said"),
    [
        (lambda c: setattr(c, "seed", -1), "--seed -1 (TrainConfig.seed) must be"),
        (lambda c: setattr(c.agent, "lr", 0), "--agent.lr 0 (AgentConfig.lr) must be"),
    ],
)
def test_a_config_changed_after_it_was_resolved_is_checked_again_before_a_run_is_built(
    change, said
):
    from simoun_agent.run.train import build

    config = resolve("cpu", {"env": "Pendulum-v1"})
    change(config)
    with pytest.raises(SetupError, match=said.replace("(", r"\(").replace(")", r"\)")):
        build(config)


@pytest.mark.parametrize(
    ("data", "said"),
    [
        (
            lambda d: resolve("cpu", {}),
            r"^from_dict\(data\) takes a dict of config keys .*got TrainConfig; it is a config "
            r"already: use it as it is .*or pass to_dict\(config\)$",
        ),
        (
            lambda d: {**d, "agent": []},
            r"^from_dict\(data\): data\['agent'\] must be a dict of AgentConfig fields, got list",
        ),
        (
            lambda d: {**d, "agent": {**d["agent"], "lr": "1e-3"}},
            r"^from_dict\(data\): data\['agent'\]\['lr'\] is '1e-3' \(str\), which must be a "
            r"number > 0 and <= 1; e.g. data\['agent'\]\['lr'\] = 0.001 \(the default\)$",
        ),
        (lambda d: {**d, "nope": 1}, r"^from_dict\(data\): unknown config key nope; to_dict"),
    ],
)
def test_from_dict_of_a_python_value_names_the_key_and_the_type_it_takes(data, said):
    with pytest.raises(SetupError, match=said) as error:
        from_dict(data(to_dict(resolve("cpu", {}))))
    assert "damaged" not in str(error.value) and "version" not in str(error.value)


def test_from_dict_of_a_file_keeps_saying_how_to_restore_it():
    saved = to_dict(resolve("cpu", {}))
    with pytest.raises(SetupError, match=r"^run/config.json: agent holds list where a JSON object"):
        from_dict({**saved, "agent": []}, "run/config.json")
    with pytest.raises(SetupError, match=r"^run/config.json: agent.lr is \"1e-3\".*restore the"):
        from_dict({**saved, "agent": {**saved["agent"], "lr": "1e-3"}}, "run/config.json")


@pytest.mark.parametrize(
    ("modes", "said"),
    [
        ("colour_easy", r"\(a list, not one string: did you mean \['color_easy'\]\?\)"),
        ("video_hard", r"\(a list, not one string: did you mean \['video_hard'\]\?\)"),
        (["colour_easy"], r"\('colour_easy': did you mean 'color_easy'\?\)"),
        (["video_hard", "vidoe_hrad"], r"\('vidoe_hrad': did you mean 'video_hard'\?\)"),
        (["train"], r"\('train' is the run's own evaluation, which always runs; leave it out\)"),
        (["zzz"], r"\('zzz' is not one\)"),
    ],
)
def test_eval_distraction_names_are_checked_at_resolve_with_the_close_match(modes, said):
    with pytest.raises(SetupError, match=said) as error:
        resolve("cpu", {"eval_distraction": modes})
    assert "in Python eval_distraction=['video_hard', 'color_easy']" in str(error.value)


def test_eval_distraction_takes_the_suites_modes():
    from simoun_agent.config.train import DISTRACTION_MODES
    from simoun_agent.generalization import DISTRACTIONS

    assert DISTRACTION_MODES == tuple(name for name in DISTRACTIONS if name != "train")
    config = resolve("cpu", {"eval_distraction": list(DISTRACTION_MODES)})
    assert tuple(config.eval_distraction) == DISTRACTION_MODES
