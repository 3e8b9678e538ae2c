"""Every config value is checked when the config is built: the error names the flag, the value
and the fix. One bad value per field, and every field has a row."""

import dataclasses
import math

import numpy as np
import pytest
import torch

from simoun_agent.config import PRESETS, RECIPES, AgentConfig, SetupError, TrainConfig, resolve
from simoun_agent.config.device import device_keys, same_device, same_setting
from simoun_agent.config.keys import config_fields
from simoun_agent.config.resolve import to_dict
from simoun_agent.config.rules import Rule, check_fields, integer, rules_of, setting
from simoun_agent.config.train import check_train_config

BAD = {
    "env": "",
    "env_module": "",
    "env_kwargs": [1, 2],
    "preset": "fast",
    "seed": -1,
    "action_repeat": 0,
    "image_size": 7,
    "grayscale": "yes",
    "cameras": 0,
    "total_env_steps": -5,
    "warmup_agent_steps": -1,
    "updates_per_step": 0,
    "replay_capacity": 0,
    "eval_every": 0,
    "eval_episodes": 0,
    "eval_distraction": [1],
    "checkpoint_every": 0,
    "video": "no",
    "device": "cuda:64",  # no such device, with or without a GPU
    "torch_threads": 0,
    "env_process": "yes",
    "run_dir": "",
    "progress": 3,
    "agent.recipe": "curly",
    "agent.encoder": "triple",
    "agent.augmentation": "flip",
    "agent.shift_pad": -1,
    "agent.critic_augmentations": 0,
    "agent.target_augmentations": 2,  # with augmentation "none": every view the same
    "agent.next_state_encoder": "momentum",
    "agent.independent_next_shift": "yes",
    "agent.separate_trunks": 1,
    "agent.pixel_offset": math.nan,
    "agent.conv_init": "xavier",
    "agent.contrastive_view": "crop",
    "agent.contrastive_step": "no",
    "agent.similarity_init": "zeros",
    "agent.feature_dim": 0,
    "agent.num_filters": 0,
    "agent.hidden_dim": 0,
    "agent.aux_hidden_dim": 0,
    "agent.batch_size": 0,
    "agent.lr": 0.0,
    "agent.alpha_lr": -1e-4,
    "agent.alpha_beta": 1.0,
    "agent.discount": 1.5,
    "agent.n_step": 0,
    "agent.critic_tau": 0.0,
    "agent.encoder_tau": 2.0,
    "agent.actor_update_every": 0,
    "agent.target_update_every": 0,
    "agent.update_every_steps": 0,
    "agent.actor": "stochastic",
    "agent.exploration_std_start": -1.0,
    "agent.exploration_std_end": math.nan,
    "agent.exploration_steps": 0,
    "agent.noise_clip": -0.3,
    "agent.init_temperature": 0.0,
    "agent.log_std_min": 5.0,  # above log_std_max
    "agent.log_std_max": math.inf,
    "agent.curiosity": "sometimes",
    "agent.curiosity_scale": -0.2,
    "agent.curiosity_decay": -1.0,
    "agent.r_e_max_init": 0.0,
    "agent.r_i_max_init": -1.0,
    "agent.transition_weight": -1.0,
    "agent.contrastive_weight": math.nan,
    "agent.reward_weight": -1.0,
    "agent.num_frames": 0,
    "agent.reduce_kernel": 0,
    "agent.reduce_stride": 0,
    "agent.random_conv_kernel": 2,
    "agent.detach_past_frames": "true",
    "agent.channels_last": 1,
}


def test_every_config_field_has_a_bad_value_row():
    assert set(config_fields()) - set(BAD) == set(), "add a row for each new config field"


@pytest.mark.parametrize("key", [key for key in BAD if key in config_fields()])
def test_bad_value_names_the_flag(key):
    flag = "--" + key.replace("_", "-")
    with pytest.raises(SetupError) as error:
        resolve(None, {key: BAD[key]})
    assert flag in str(error.value), str(error.value)


@pytest.mark.parametrize(
    ("overrides", "words"),
    [
        ({"total_env_steps": -5}, ["--total-env-steps -5", "int >= 1", "500000"]),
        ({"eval_every": 0}, ["--eval-every 0", "int >= 1"]),
        ({"checkpoint_every": 0}, ["--checkpoint-every 0", "int >= 1"]),
        ({"action_repeat": 0}, ["--action-repeat 0", "int >= 1"]),
        ({"total_env_steps": 10**30}, ["--total-env-steps 1" + "0" * 30, "below 2**63"]),
        ({"eval_every": 2**63}, [f"--eval-every {2**63}", "below 2**63"]),
        (
            {"image_size": 7},
            ["--image-size 7", "too small", "--image-size 19 (TrainConfig.image_size=19) or more"],
        ),
        ({"replay_capacity": 100, "agent.batch_size": 512}, ["--replay-capacity 100", "512"]),
        ({"agent.log_std_min": 3.0}, ["--agent.log-std-min 3", "--agent.log-std-max 2"]),
        (
            {"total_env_steps": "100"},
            ["--total-env-steps '100' (TrainConfig.total_env_steps)", "(below 2**63), not a str"],
        ),
        ({"agent.lr": "1e-3"}, ["--agent.lr '1e-3'", "must be a number > 0 and <= 1, not a str"]),
        ({"image_size": np.array([64, 64])}, ["--image-size [64 64]", "not a numpy.ndarray"]),
        ({"agent.recipe": 3}, ["unknown recipe --agent.recipe 3; choose one of simoun"]),
        # a value in the wrong units: pixels for the x / 255 scale, a percentage for a rate
        (
            {"agent.recipe": "drqv2", "agent.pixel_offset": 128},
            ["--agent.pixel-offset 128", ">= -1 and <= 1", "x / 255 scale", "0.5 (DrQ-v2)"],
        ),
        ({"agent.lr": 3}, ["--agent.lr 3", "> 0 and <= 1", "1e-3"]),
        ({"agent.alpha_lr": 10.0}, ["--agent.alpha-lr 10", "> 0 and <= 1"]),
        ({"agent.discount": 1.0}, ["--agent.discount 1", "[0, 1)", "--agent.discount 0.99"]),
    ],
)
def test_messages_give_the_value_and_the_fix(overrides, words):
    with pytest.raises(SetupError) as error:
        resolve(None, overrides)
    for word in words:
        assert word in str(error.value), str(error.value)


@pytest.mark.skipif(torch.cuda.is_available(), reason="needs a torch that sees no CUDA GPU")
def test_device_cuda_without_a_gpu_names_the_flag_and_cpu():
    with pytest.raises(SetupError, match=r"--device cuda .*: .*no CUDA GPU.*--device cpu"):
        resolve(None, {"device": "cuda"})


@pytest.mark.parametrize("cls", [AgentConfig, TrainConfig])
def test_each_field_carries_its_rule_in_its_own_definition(cls):
    rules = rules_of(cls)
    assert list(rules) == [f.name for f in dataclasses.fields(cls)]
    assert all(isinstance(rule, Rule) for rule in rules.values())
    assert rules_of(cls()) == rules


def test_a_field_without_a_rule_is_refused_when_the_config_is_built():
    @dataclasses.dataclass
    class Partial:
        ruled: int = setting(1, integer(1))
        bare: int = 2

        def __post_init__(self) -> None:
            check_fields(self, "")

    with pytest.raises(TypeError, match="Partial fields without a rule: bare"):
        Partial()


def test_numpy_numbers_are_taken_as_the_python_numbers_they_hold():
    config = resolve(
        "cpu", {"image_size": np.int64(64), "seed": np.array(3), "agent.lr": np.float32(0.5)}
    )
    assert (config.image_size, config.seed, config.agent.lr) == (64, 3, 0.5)
    assert [type(v) for v in (config.image_size, config.seed, config.agent.lr)] == [int, int, float]
    assert to_dict(config)["seed"] == 3  # config.json can hold them
    with pytest.raises(SetupError, match=r"unknown preset \['cpu'\]"):
        resolve(["cpu"], {})


def test_agent_config_in_python_names_the_field_too():
    with pytest.raises(ValueError, match=r"--agent\.batch-size 0 \(AgentConfig\.batch_size\)"):
        AgentConfig(batch_size=0)


@pytest.mark.parametrize(
    ("build", "fields"),
    [
        (
            lambda: AgentConfig(log_std_min=3.0, log_std_max=2.0),
            ["AgentConfig.log_std_min", "AgentConfig.log_std_max=2.0"],
        ),
        (
            lambda: AgentConfig(augmentation="none", critic_augmentations=2),
            ["AgentConfig.augmentation='shift'", "AgentConfig.critic_augmentations=1"],
        ),
        (
            lambda: AgentConfig(shift_pad=4),
            ["AgentConfig.shift_pad", "AgentConfig.augmentation='shift'", "shift_pad=None"],
        ),
        (lambda: AgentConfig(num_frames=2), ["AgentConfig.num_frames=3"]),
        (
            lambda: AgentConfig(encoder="flare", curiosity=False, num_frames=1),
            ["AgentConfig.num_frames=3", "AgentConfig.encoder='single'"],
        ),
        (
            lambda: AgentConfig(encoder="single", curiosity=True, num_frames=1),
            ["AgentConfig.curiosity=False"],
        ),
        (
            lambda: AgentConfig(separate_trunks=True),
            ["AgentConfig.encoder='single'", "AgentConfig.separate_trunks=False"],
        ),
        (
            lambda: TrainConfig(replay_capacity=4),
            ["AgentConfig.batch_size=512", "TrainConfig.replay_capacity=512"],
        ),
        (lambda: TrainConfig(image_size=8), ["TrainConfig.image_size=19"]),
    ],
)
def test_a_cross_field_refusal_names_each_setting_to_change_in_python_too(build, fields):
    """Built in Python, a refusal names the fields as Python writes them beside the flags."""
    with pytest.raises(ValueError) as error:
        build()
    for name in fields:
        assert name in str(error.value), str(error.value)


@pytest.mark.parametrize("preset", list(PRESETS))
def test_every_preset_passes_the_checks(preset):
    resolve(preset, {})


@pytest.mark.parametrize("recipe", list(RECIPES))
def test_every_recipe_passes_the_checks(recipe):
    resolve("cpu", {"agent.recipe": recipe})


@pytest.mark.parametrize(
    ("frame_shape", "action_dim", "words"),
    [
        ((84, 84, 3), 1, "looks channel-last"),
        ((3, 7, 7), 1, "too small for the conv trunk of encoder 'dual_interactive'"),
        ((3, 48, 48), 0, "action_dim must be an int >= 1"),
    ],
)
def test_agent_constructor_names_the_problem(frame_shape, action_dim, words):
    from simoun_agent import SimounAgent

    with pytest.raises(ValueError, match=words):
        SimounAgent(frame_shape, action_dim, AgentConfig(batch_size=8, num_filters=4))


def test_the_flare_recipe_refuses_one_frame_and_takes_two():
    with pytest.raises(SetupError, match=r"--agent.num-frames 1 .*'flare' learns from the latent"):
        resolve(None, {"agent.recipe": "flare", "agent.num_frames": 1})
    assert resolve(None, {"agent.recipe": "flare", "agent.num_frames": 2}).agent.num_frames == 2


@pytest.mark.parametrize(
    ("build", "words"),
    [
        (lambda: AgentConfig(recipe=["drq"]), ("AgentConfig.recipe", "drqv2", "not a list")),
        (lambda: AgentConfig(recipe={"drq": 1}), ("AgentConfig.recipe", "sac", "not a dict")),
        (lambda: TrainConfig(preset=["cpu"]), ("TrainConfig.preset", "highway", "not a list")),
        (lambda: AgentConfig(recipe="DrQ"), ("AgentConfig.recipe", "did you mean 'drq'?")),
    ],
)
def test_a_name_field_refuses_a_wrong_type_naming_the_field_and_the_names(build, words):
    # the registries are dicts: a list or dict looked up in one is unhashable to Python
    with pytest.raises(ValueError) as refused:
        build()
    for word in words:
        assert word in str(refused.value)


def test_shift_pad_is_taken_where_a_shift_reads_it():
    assert AgentConfig(augmentation="shift", shift_pad=4).shift_pad == 4
    assert AgentConfig(contrastive_view="shift", shift_pad=2).shift_pad == 2


@pytest.mark.parametrize(
    ("build", "said"),
    [
        (
            lambda: AgentConfig(device="cuda"),
            ["device is a setting of TrainConfig", "TrainConfig(device='cuda')", "--device"],
        ),
        (
            lambda: TrainConfig(lr=1e-3),
            ["lr is a setting of AgentConfig", "TrainConfig(agent=AgentConfig(lr=0.001))"],
        ),
        (
            lambda: AgentConfig(bach_size=8),
            ["unexpected keyword argument 'bach_size'", "batch_size"],
        ),
    ],
)
def test_a_keyword_of_the_other_config_class_names_where_it_lives(build, said):
    with pytest.raises(TypeError) as raised:
        build()
    assert all(part in str(raised.value) for part in said), str(raised.value)


def test_an_agent_set_as_a_dict_is_refused_with_the_agent_config_of_its_values():
    config = TrainConfig()
    config.agent = {"lr": 1e-3}
    with pytest.raises(ValueError) as raised:
        check_train_config(config)
    said = str(raised.value)
    assert "config.agent = AgentConfig(lr=0.001)" in said
    assert "--agent.lr 0.001" in said
    assert "--agent {" not in said and "recipe=None" not in said


def test_a_run_dir_given_as_a_path_is_kept_as_a_str(tmp_path):
    assert TrainConfig(run_dir=tmp_path / "r").run_dir == str(tmp_path / "r")
    assert resolve(None, {"run_dir": tmp_path / "r"}).run_dir == str(tmp_path / "r")


def test_two_spellings_of_one_device_are_the_same_device():
    current = torch.cuda.current_device() if torch.cuda.is_available() else 0
    assert same_device("cpu:0", "cpu") and same_device("cpu", "cpu:0")
    assert same_device("cuda", f"cuda:{current}") and same_device("mps:0", "mps")
    assert not same_device("cpu", "cuda") and not same_device("cuda:0", "cuda:1")
    assert same_device(None, None) and not same_device(None, "cpu")
    assert same_setting("device", "cpu:0", "cpu") and not same_setting("seed", 1, 2)
    assert device_keys({"base": {"device": "cpu:0"}, "device": "cuda"}) == {
        "base": {"device": "cpu"},
        "device": f"cuda:{current}",
    }


@pytest.mark.parametrize(
    ("given", "said"),
    [
        (
            dict(curiosity=False, curiosity_scale=0.5),
            ["AgentConfig.curiosity_scale", "curiosity is false", "AgentConfig.curiosity=True"],
        ),
        (
            dict(exploration_std_start=0.5, exploration_std_end=0.05),
            ["AgentConfig.exploration_std_start", "AgentConfig.actor='deterministic'"],
        ),
        (
            dict(actor="deterministic", init_temperature=0.5),
            ["AgentConfig.init_temperature", "AgentConfig.actor='gaussian'"],
        ),
        (
            dict(contrastive_weight=0.0, similarity_init="uniform"),
            ["AgentConfig.similarity_init", "AgentConfig.contrastive_weight=1.0"],
        ),
        (
            dict(contrastive_view="shift", random_conv_kernel=5),
            ["AgentConfig.random_conv_kernel", "AgentConfig.contrastive_view='random_conv'"],
        ),
        (
            dict(encoder="dual", reduce_stride=2),
            ["AgentConfig.reduce_stride", "AgentConfig.encoder='dual_interactive'"],
        ),
        (
            dict(encoder="stacked", curiosity=False, detach_past_frames=False),
            ["AgentConfig.detach_past_frames", "AgentConfig.detach_past_frames=True"],
        ),
    ],
)
def test_a_setting_its_config_does_not_read_is_refused_naming_what_turns_it_on(given, said):
    with pytest.raises(ValueError) as refused:
        AgentConfig(**given)
    assert "would change nothing" in str(refused.value)
    for part in said:
        assert part in str(refused.value), str(refused.value)


def test_a_setting_at_its_default_or_its_recipes_value_passes_with_its_part_off():
    # the defaults, and a recipe's values left as the recipe gave them, are no user's setting
    assert AgentConfig(curiosity=False, curiosity_scale=0.2).curiosity_scale == 0.2
    gaussian = resolve(None, {"agent.recipe": "drqv2", "env": "dm_control/cartpole-swingup-v0"})
    assert gaussian.agent.exploration_steps == 200_000
    assert AgentConfig(recipe="drqv2", actor="gaussian").actor == "gaussian"


def test_a_rising_exploration_schedule_is_refused_as_a_swap():
    with pytest.raises(ValueError) as refused:
        AgentConfig(actor="deterministic", exploration_std_start=0.1, exploration_std_end=1.0)
    said = str(refused.value)
    assert "AgentConfig.exploration_std_end" in said and "would rise" in said
    assert "exploration_std_start=1.0" in said and "exploration_std_end=0.1" in said
    constant = dict(exploration_std_start=0.2, exploration_std_end=0.2)
    assert AgentConfig(actor="deterministic", **constant).exploration_std_end == 0.2


def test_env_kwargs_from_python_are_kept_as_json_types():
    config = TrainConfig(env_kwargs={"max_steps": np.int64(10), "config": {"range": (20, 30)}})
    assert config.env_kwargs == {"max_steps": 10, "config": {"range": [20, 30]}}
    assert type(config.env_kwargs["max_steps"]) is int
    config.env_kwargs["config"]["range"] = (np.float32(1.5), 2)  # set after it was built
    check_train_config(config)
    assert config.env_kwargs["config"]["range"] == [1.5, 2]
    assert type(config.env_kwargs["config"]["range"][0]) is float


def test_every_setting_read_only_with_a_part_is_a_field_of_the_agent():
    from simoun_agent.config.agent import READ_ONLY_WITH

    fields = {f.name for f in dataclasses.fields(AgentConfig)}
    assert {name for group in READ_ONLY_WITH for name in group.fields} <= fields
