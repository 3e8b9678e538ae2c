"""OnlineModel's buffer, saved state and config checks, and what CuriosityModel stores of a
transition, against values written out by hand (no thread: ``background=False``, so every step
runs inside the due ``watch`` call and its result waits there until the next one publishes it)."""

import math
import pickle

import numpy as np
import pytest
import torch
from test_curiosity_model_by_hand import SHAPE
from test_curiosity_model_by_hand import model_of as curiosity_model_of

from simoun_agent.curiosity_model import AgentFeatures, CuriosityConfig, CuriosityModel
from simoun_agent.rnd_model import RNDConfig


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
        ("feature_dim", 0, r"CuriosityConfig\.feature_dim must be >= 1"),
        ("num_filters", 0, r"CuriosityConfig\.num_filters must be >= 1"),
        ("capacity", 0, r"CuriosityConfig\.capacity must be >= 1"),
        ("update_every", 0, r"CuriosityConfig\.update_every must be >= 1"),
        ("encoder_size", 0, r"CuriosityConfig\.encoder_size must be None"),
        ("batch_size", 1, r"CuriosityConfig\.batch_size must be >= 2"),
        ("learning_starts", 1, r"CuriosityConfig needs batch_size <= learning_starts"),
        ("lr", 0.0, r"CuriosityConfig\.lr must be a number > 0"),
        ("lr", -1e-3, r"CuriosityConfig\.lr must be a number > 0"),
        ("lr", math.inf, r"CuriosityConfig\.lr must be a number > 0"),
        ("lr", math.nan, r"CuriosityConfig\.lr must be a number > 0"),
    ],
)
def test_a_bad_config_is_refused_naming_its_class_and_field(field, value, message):
    with pytest.raises(ValueError, match=message):
        CuriosityConfig(**{field: value})


def test_the_smallest_good_values_are_accepted():
    config = CuriosityConfig(
        feature_dim=1, num_filters=1, encoder_size=1, batch_size=2, learning_starts=2, lr=1e-9
    )
    assert (config.encoder_size, config.batch_size) == (1, 2)


def test_the_shared_checks_name_the_other_models_config_too():
    with pytest.raises(ValueError, match=r"RNDConfig\.capacity must be >= 1"):
        RNDConfig(capacity=0)


def test_agent_features_refuse_an_object_without_an_encoder_naming_its_type():
    with pytest.raises(TypeError, match=r"encoder_features.*got dict"):
        AgentFeatures({})
