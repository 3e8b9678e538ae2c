"""OnlineModel's buffer, saved state and config checks, and what CuriosityModel stores of a
transition, against values written out by hand (no thread: ``background=False``, so every step
runs inside the due ``watch`` call and its result waits there until the next one publishes it)."""

import math
import pickle

import gymnasium as gym
import numpy as np
import pytest
import torch
from test_curiosity_model_by_hand import SHAPE
from test_curiosity_model_by_hand import model_of as curiosity_model_of

from simoun_agent.curiosity_model import AgentFeatures, CuriosityConfig, CuriosityModel
from simoun_agent.rnd_model import RNDConfig, RNDModel
from simoun_wrappers import SimounObservation


def model_of(**overrides) -> CuriosityModel:
    """test_curiosity_model_by_hand's model with a buffer of 4, which wraps within a test."""
    return curiosity_model_of(**{"capacity": 4, **overrides})


def frames_of(rng: np.random.Generator, n: int) -> np.ndarray:
    """Triplets whose frames all differ, so storing the wrong one shows."""
    return rng.integers(0, 256, size=(n, 3, *SHAPE), dtype=np.uint8)


def watch(model: CuriosityModel, triplets, next_triplets, actions) -> None:
    flags = np.zeros(len(triplets), bool)
    model.watch(triplets, np.asarray(actions), next_triplets, flags, flags)


def test_a_transition_is_stored_as_frames_t_minus_2_to_t_plus_1_with_its_one_hot_action():
    rng = np.random.default_rng(0)
    model = model_of(update_every=10_000)
    triplets, next_triplets = frames_of(rng, 3), frames_of(rng, 3)
    watch(model, triplets, next_triplets, [2, 0, 1])
    for i in range(3):
        np.testing.assert_array_equal(model._windows[i, :3], triplets[i])
        np.testing.assert_array_equal(model._windows[i, 3], next_triplets[i, 2])  # frame t+1
    np.testing.assert_array_equal(model._actions[:3], [[0, 0, 1], [1, 0, 0], [0, 1, 0]])
    later, later_next = frames_of(rng, 2), frames_of(rng, 2)
    watch(model, later, later_next, [1, 1])  # capacity 4: slot 3, then the oldest, slot 0
    assert (model.size, model._head) == (4, 1)
    np.testing.assert_array_equal(model._windows[3, :3], later[0])
    np.testing.assert_array_equal(model._windows[0, :3], later[1])
    np.testing.assert_array_equal(model._windows[0, 3], later_next[1, 2])
    np.testing.assert_array_equal(model._windows[1, :3], triplets[1])  # not yet overwritten
    np.testing.assert_array_equal(model._actions[[3, 0, 1]], [[0, 1, 0], [0, 1, 0], [1, 0, 0]])


def test_a_saved_state_names_its_parts_and_keeps_the_step_in_flight_with_its_metrics():
    rng = np.random.default_rng(1)
    model = model_of()
    transitions = [(frames_of(rng, 1), frames_of(rng, 1), [i % 3]) for i in range(4)]
    for transition in transitions:  # calls 2 and 4 are due: the step of call 2 is published at 4
        watch(model, *transition)
    assert model.pending and model.updates == 1
    state = model.state_dict()
    assert set(state) == {
        "encoder",
        "momentum",
        "transition",
        "similarity",
        "optimizer",
        "published",
        "pending_metrics",
        "watch_calls",
        "updates",
        "rng",
        "generator",
    }
    in_flight = state["pending_metrics"]
    assert {"transition_loss", "contrastive_loss", "motion_contrastive_loss"} <= set(in_flight)

    clone = model_of(seed=1)
    clone.load_state_dict(state)
    assert clone.pending and (clone.updates, clone.watch_calls) == (1, 4)
    scored = frames_of(rng, 2)
    for a, b in zip(model(scored), clone(scored), strict=True):
        np.testing.assert_array_equal(a, b)  # both still read the step of call 2
    for each in (model, clone):
        watch(each, *transitions[0])
        watch(each, *transitions[1])  # call 6, due: publishes the step started at call 4
    assert clone.updates == model.updates == 2
    assert {k: v for k, v in clone.last_metrics.items() if k != "wait_ms"} == in_flight
    for a, b in zip(model(scored), clone(scored), strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_state_saved_with_no_step_in_flight_loads_none():
    model = model_of(update_every=10_000)
    state = model.state_dict()
    assert state["pending_metrics"] is None
    clone = model_of(seed=1)
    clone.load_state_dict(state)
    assert not clone.pending and clone.updates == 0


def test_a_model_pickles_with_no_step_in_flight():
    rng = np.random.default_rng(2)
    model = model_of(update_every=10_000)
    watch(model, frames_of(rng, 2), frames_of(rng, 2), [0, 1])
    clone = pickle.loads(pickle.dumps(model))
    assert not clone.pending and clone.size == 2
    scored = frames_of(rng, 2)
    for a, b in zip(model(scored), clone(scored), strict=True):
        np.testing.assert_array_equal(a, b)


def test_a_model_whose_step_failed_pickles_and_its_copy_refuses_to_go_on():
    rng = np.random.default_rng(3)
    model = model_of()
    with torch.no_grad():  # a diverged encoder: the first gradient step meets a NaN loss
        next(model.encoder.parameters()).fill_(float("nan"))
    watch(model, frames_of(rng, 1), frames_of(rng, 1), [0])
    watch(model, frames_of(rng, 1), frames_of(rng, 1), [1])  # due: the failing step runs
    clone = pickle.loads(pickle.dumps(model))
    with pytest.raises(RuntimeError, match=r"gradient step failed \(FloatingPointError"):
        clone(frames_of(rng, 1))


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("feature_dim", 0, r"CuriosityConfig\.feature_dim=0 must be an int >= 1"),
        ("num_filters", 0, r"CuriosityConfig\.num_filters=0 must be an int >= 1"),
        ("capacity", 0, r"CuriosityConfig\.capacity=0 must be an int >= 1"),
        ("capacity", 1.5, r"CuriosityConfig\.capacity=1\.5 must be an int >= 1"),
        ("update_every", 0, r"CuriosityConfig\.update_every=0 must be an int >= 1"),
        ("encoder_size", 0, r"CuriosityConfig\.encoder_size=0 must be None or an int >= 1"),
        ("batch_size", 1, r"CuriosityConfig\.batch_size=1 must be an int >= 2 \(the contrastive"),
        ("learning_starts", 1, r"CuriosityConfig needs batch_size <= learning_starts"),
        ("learning_starts", -1, r"CuriosityConfig\.learning_starts=-1 must be an int >= 0"),
        ("lr", 0.0, r"CuriosityConfig\.lr=0\.0 must be a number > 0"),
        ("lr", -1e-3, r"CuriosityConfig\.lr=-0\.001 must be a number > 0"),
        ("lr", math.inf, r"CuriosityConfig\.lr=inf must be a number > 0"),
        ("lr", math.nan, r"CuriosityConfig\.lr=nan must be a number > 0"),
        ("encoder_tau", 2, r"CuriosityConfig\.encoder_tau=2 must be a number > 0 and <= 1"),
        ("transition_weight", -1, r"CuriosityConfig\.transition_weight=-1 must be a number >= 0"),
        ("contrastive_weight", "1", r"CuriosityConfig\.contrastive_weight='1' must be a number"),
        ("random_conv_kernel", 2, r"CuriosityConfig\.random_conv_kernel=2 must be an odd int"),
        ("interactive", "yes", r"CuriosityConfig\.interactive='yes' must be True or False"),
        ("channels_last", 1, r"CuriosityConfig\.channels_last=1 must be True or False"),
        ("background", "no", r"CuriosityConfig\.background='no' must be True or False"),
        ("seed", -1, r"CuriosityConfig\.seed=-1 must be None or an int in \[0, 2\*\*32\); e\.g\."),
        ("seed", 2**32, r"CuriosityConfig\.seed=4294967296 must be None or an int in \[0"),
        ("seed", 1.0, r"CuriosityConfig\.seed=1\.0 must be None or an int"),
    ],
)
def test_a_bad_config_is_refused_naming_its_class_field_value_and_a_fix(field, value, message):
    with pytest.raises(ValueError, match=message):
        CuriosityConfig(**{field: value})


def test_the_smallest_good_values_are_accepted():
    config = CuriosityConfig(
        feature_dim=1, num_filters=1, encoder_size=1, batch_size=2, learning_starts=2, lr=1e-9
    )
    assert (config.encoder_size, config.batch_size) == (1, 2)
    config = CuriosityConfig(seed=np.int64(2**32 - 1), interactive=np.bool_(False), encoder_tau=1)
    assert config.seed == 2**32 - 1


@pytest.mark.parametrize(
    ("field", "value"),
    [("capacity", 0), ("seed", -1), ("background", "no"), ("lr", float("nan")), ("nope", 1)],
)
def test_the_shared_checks_name_the_other_models_config_too(field, value):
    with pytest.raises((ValueError, TypeError), match=rf"RNDConfig.*{field}"):
        RNDConfig(**{field: value})


def test_a_config_of_another_type_is_named_with_the_config_class():
    env = SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=48)
    for model, config in ((RNDModel, RNDConfig), (CuriosityModel, CuriosityConfig)):
        with pytest.raises(TypeError, match=rf"config must be of type {config.__name__}, got "
                           rf"dict.*{config.__name__}\(\*\*values\)"):  # fmt: skip
            model.for_env(env, config={"lr": 1e-3})
        with pytest.raises(TypeError, match=rf"config must be of type {config.__name__}, got "):
            model((3, 48, 48), config=CuriosityConfig() if model is RNDModel else RNDConfig())


def test_agent_features_refuse_an_object_without_an_encoder_naming_its_type():
    with pytest.raises(TypeError, match=r"encoder_features.*got dict"):
        AgentFeatures({})


def weights_of(model) -> dict[str, torch.Tensor]:
    return {
        f"{name}.{key}": value.clone()
        for name, part in model._stateful().items()
        if isinstance(part, torch.nn.Module)
        for key, value in part.state_dict().items()
    }


def damaged_states(state: dict) -> list[tuple[dict, str]]:
    """A model's state spoilt one part at a time, each with what the refusal must name."""
    first = next(iter(state["optimizer"]["state"]), 0)
    return [
        ({}, r"it lacks .*watch_calls, updates, rng, generator"),
        ({**state, "watch_calls": "x"}, r"its watch_calls is 'x', not an int >= 0"),
        ({**state, "updates": -1}, r"its updates is -1, not an int >= 0"),
        ({**state, "rng": {"bit_generator": "PCG64"}}, r"its rng is no state of numpy's PCG64"),
        ({**state, "generator": torch.zeros(3, dtype=torch.uint8)}, r"its generator is no state"),
        ({**state, "optimizer": {}}, r"its optimizer lacks state, param_groups"),
        (
            {**state, "optimizer": {**state["optimizer"], "param_groups": []}},
            r"its optimizer has 0 parameter groups, this one 1",
        ),
        (
            {**state, "optimizer": {**state["optimizer"], "state": {first: {"exp_avg": 1.0}}}},
            rf"its optimizer state of parameter {first!r}: exp_avg is a float",
        ),
        ({**state, "published": None}, r"its published is a NoneType, not a state dict"),
        ({**state, "pending_metrics": 3}, r"its pending_metrics is 3, not None or a dict"),
    ]


@pytest.mark.parametrize("kind", ["curiosity", "rnd"])
def test_a_state_that_does_not_fit_is_refused_whole_naming_each_part_and_nothing_loads(kind):
    env = SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=48)
    build = {
        "curiosity": lambda seed: CuriosityModel.for_env(
            env, CuriosityConfig(seed=seed, background=False), device="cpu"
        ),
        "rnd": lambda seed: RNDModel.for_env(
            env, RNDConfig(seed=seed, background=False), device="cpu"
        ),
    }[kind]
    model = build(0)
    name = type(model).__name__
    before = weights_of(model)
    state = build(1).state_dict()
    for bad, problem in damaged_states(state):
        with pytest.raises(ValueError, match=rf"{name}\.load_state_dict cannot load this state: "
                           rf".*{problem}.*Nothing was loaded"):  # fmt: skip
            model.load_state_dict(bad)
        for key, value in weights_of(model).items():
            assert torch.equal(value, before[key]), key
    with pytest.raises(TypeError, match=rf"{name}\.load_state_dict got a list, not a dict"):
        model.load_state_dict([])
    model.load_state_dict(state)  # the whole state still loads
    assert model.watch_calls == 0 and not torch.equal(
        next(iter(weights_of(model).values())), next(iter(before.values()))
    )


def test_a_state_of_larger_frames_names_the_shapes():
    small = SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=48)
    large = SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=64)
    state = CuriosityModel.for_env(large, device="cpu").state_dict()
    with pytest.raises(ValueError, match=r"head_appearance\.fc\.weight is \(50, \d+\) there, "
                       r"\(50, \d+\) here; .*built for frames of \(3, 48, 48\)"):  # fmt: skip
        CuriosityModel.for_env(small, device="cpu").load_state_dict(state)
    rnd_state = RNDModel.for_env(large, device="cpu").state_dict()
    with pytest.raises(ValueError, match=r"observation_mean is \(3, 64, 64\) there, \(3, 48, 48\)"):
        RNDModel.for_env(small, RNDConfig(encoder_size=None), device="cpu").load_state_dict(
            rnd_state
        )


@pytest.mark.parametrize(
    ("model", "config"), [(RNDModel, RNDConfig), (CuriosityModel, CuriosityConfig)]
)
def test_a_buffer_beyond_the_memory_is_refused_with_its_bytes_and_a_capacity_that_fits(
    model, config
):
    env = SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=48)
    with pytest.raises(ValueError) as raised:
        model.for_env(env, config(capacity=10**11), device="cpu")
    message = str(raised.value)
    assert message.startswith(
        f"{config.__name__}.capacity=100000000000 makes {model.__name__}'s buffer "
    )
    assert (
        "more than this machine's" in message
        and f"e.g. {config.__name__}(capacity=1000)" in message
    )
    fits = int(message.split("(about ")[1].split(" take")[0].replace(",", ""))
    smaller = config(capacity=max(fits // 1000, 64), learning_starts=64)
    assert model.for_env(env, smaller, device="cpu").size == 0
