"""CuriosityModel's loss, its action encoding, what it builds and what it reports, against values
written out by hand (no thread unless a test says so: ``background=False`` runs every step inside
its due ``watch`` call)."""

import time

import numpy as np
import pytest
import torch
from gymnasium import spaces

from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel, encode_actions
from simoun_agent.models.encoder import DualPathEncoder
from simoun_wrappers.augment import random_conv

SHAPE = (3, 24, 24)
ACTIONS = spaces.Discrete(3)


SMALL = {"num_filters": 8, "feature_dim": 16, "aux_hidden_dim": 32, "update_every": 2, "seed": 0}
"""Small networks and a step every 2nd call: the CuriosityConfig of the model tests."""
BY_HAND = {
    "encoder_size": None,
    "capacity": 8,
    "batch_size": 2,
    "learning_starts": 2,
    "background": False,
}
"""No pooling, no thread, a batch of 2 from the 2nd transition: numbers a test can write out."""


def model_of(shape=SHAPE, **overrides) -> CuriosityModel:
    config = CuriosityConfig(**{**SMALL, **BY_HAND, **overrides})
    return CuriosityModel(shape, ACTIONS, config, "cpu")


def triplets_of(rng: np.random.Generator, n: int, shape=SHAPE) -> np.ndarray:
    return rng.integers(0, 256, size=(n, 3, *shape), dtype=np.uint8)


def watch(model: CuriosityModel, rng: np.random.Generator, n: int = 2) -> None:
    flags = np.zeros(n, bool)
    model.watch(
        triplets_of(rng, n, model.frame_shape),
        rng.integers(0, 3, n),
        triplets_of(rng, n, model.frame_shape),
        flags,
        flags,
    )


def info_nce(logits: torch.Tensor) -> torch.Tensor:
    """Cross-entropy of each row against its own column: -mean_i log softmax(logits_i)_i."""
    return -(logits.diag() - logits.logsumexp(dim=1)).mean()


def test_the_loss_weighs_its_three_terms_each_computed_by_hand():
    weights = dict(transition_weight=0.3, contrastive_weight=1.7, motion_contrastive_weight=0.6)
    model = model_of(**weights)
    generator = torch.Generator().manual_seed(5)
    with torch.no_grad():  # a learned W, not the identity it starts as (= the plain inner product)
        model.similarity.weight.add_(0.5 * torch.randn(16, 16, generator=generator))
    rng = np.random.default_rng(3)
    window = torch.as_tensor(rng.integers(0, 256, (4, 4, *SHAPE), dtype=np.uint8))
    action = torch.eye(3)[[2, 0, 1, 1]]
    augmentation = model.generator.get_state()
    loss, metrics = model._loss(window, action)

    model.generator.set_state(augmentation)  # the same random convolution, drawn again
    with torch.no_grad():
        now, following = model.encoder.encode_transition(window)
        frame_t = window[:, 2].float() / 255.0  # the anchor frame, not t+1 (window[:, 3])
        key = model.momentum.encode_key(
            random_conv(frame_t, model.config.random_conv_kernel, model.generator)
        )
        predicted = model.transition(now.motion, action)
        l_tran = (predicted - following.motion).pow(2).sum(dim=1).mean()
        l_con = info_nce(now.anchor @ model.similarity.weight @ key.T)
        l_motion = info_nce(predicted @ following.motion.T)
    expected = 0.3 * l_tran + 1.7 * l_con + 0.6 * l_motion
    assert float(loss.detach()) == pytest.approx(float(expected), rel=1e-5)
    assert metrics["transition_loss"] == pytest.approx(float(l_tran), rel=1e-5)
    assert metrics["contrastive_loss"] == pytest.approx(float(l_con), rel=1e-5)
    assert metrics["motion_contrastive_loss"] == pytest.approx(float(l_motion), rel=1e-5)
    # the batch std of each feature, averaged over features: near 0 means a collapse
    motion_std = now.motion.std(dim=0).mean()
    assert metrics["motion_std"] == pytest.approx(float(motion_std), rel=1e-5)
    assert metrics["appearance_std"] == pytest.approx(float(now.anchor.std(dim=0).mean()), rel=1e-5)


@pytest.mark.parametrize(
    "space, actions, encoded",
    [
        (spaces.Discrete(3, start=1), [1, 3], [[1, 0, 0], [0, 0, 1]]),
        (
            spaces.MultiDiscrete([3, 2], start=[1, -1]),
            [[3, -1], [1, 0]],
            [[0, 0, 1, 1, 0], [1, 0, 0, 0, 1]],
        ),
        # asymmetric bounds: 2 (a - low) / (high - low) - 1 per dimension
        (
            spaces.Box(np.float32([-2, 1]), np.float32([4, 3])),
            [[-2.0, 2.0], [1.0, 3.0]],
            [[-1, 0], [0, 1]],
        ),
        (spaces.Box(-np.inf, np.inf, (2, 2)), [[[1.5, -2.0], [0.0, 7.0]]], [[1.5, -2.0, 0.0, 7.0]]),
        (spaces.MultiBinary(3), [[1, 0, 1]], [[1, 0, 1]]),
    ],
    ids=["discrete", "multi_discrete", "bounded_box", "unbounded_box", "multi_binary"],
)
def test_actions_are_encoded_as_float32_rows_by_hand(space, actions, encoded):
    out = encode_actions(space, np.asarray(actions))
    assert out.dtype == np.float32
    np.testing.assert_allclose(out, encoded, rtol=0, atol=1e-6)


def test_the_model_builds_what_its_config_names():
    config = dict(num_filters=6, lr=3e-3, channels_last=False)
    model = model_of(**config)
    assert isinstance(model.encoder, DualPathEncoder) and model.encoder.interaction is not None
    assert model_of(interactive=False).encoder.interaction is None
    convs = [m for m in model.encoder.modules() if isinstance(m, torch.nn.Conv2d)]
    assert {m.out_channels for m in convs} == {6}
    assert model.optimizer.param_groups[0]["lr"] == 3e-3
    assert model.encoder.memory_format == torch.contiguous_format
    assert model_of().encoder.memory_format == torch.channels_last
    assert not any(p.requires_grad for p in model.momentum.parameters())  # EMA only
    assert not any(p.requires_grad for p in model.published.parameters())  # a frozen copy
    assert model._windows.shape == (8, 4, *SHAPE) and model._windows.dtype == np.uint8
    assert (model.feature_version, model.updates, model.last_metrics) == (0, 0, {})


def test_frames_below_the_smallest_side_are_refused_naming_what_needs_it():
    # too short, wide enough: the check looks at H as well as W
    needs = (
        r"CuriosityConfig\.encoder_size=None\); "
        r"the conv paths and the interactive module need H, W"
    )
    with pytest.raises(ValueError, match=needs + r" >= 19\. .*SimounObservation\(env, size=32\)"):
        model_of(shape=(3, 16, 40))
    with pytest.raises(ValueError, match=r"encoder_size=None\); the conv paths need H, W >= 15\."):
        model_of(shape=(3, 14, 40), interactive=False)
    model_of(shape=(3, 16, 40), interactive=False)  # 16 >= 15 without the module


def test_pooled_frames_stay_uint8():
    model = model_of(shape=(3, 48, 48), encoder_size=24)
    frames = np.random.default_rng(0).integers(0, 256, (2, 3, 3, 48, 48), dtype=np.uint8)
    pooled = model._pooled(frames)
    assert pooled.dtype == np.uint8 and pooled.shape == (2, 3, 3, 24, 24)
    by_hand = frames.reshape(2, 3, 3, 24, 2, 24, 2).mean(axis=(4, 6))
    np.testing.assert_array_equal(pooled, np.round(by_hand).astype(np.uint8))


def test_every_stored_slot_is_sampled_the_first_included():
    model = model_of(capacity=4)
    rng = np.random.default_rng(0)
    watch(model, rng, 4)
    drawn = np.concatenate([model._batch_indices() for _ in range(50)])
    assert set(drawn.tolist()) == {0, 1, 2, 3}


def test_bad_triplets_are_refused_naming_the_argument_and_the_model():
    model = model_of()
    rng = np.random.default_rng(0)
    good, flags = triplets_of(rng, 1), np.zeros(1, bool)
    for bad, name in [
        ((good.astype(np.float32), good), "triplets"),
        ((good, good[:, :, :, :8]), "next_triplets"),
    ]:
        with pytest.raises(
            ValueError, match=rf"CuriosityModel expects {name} as uint8 .*CuriosityModel\.for_env"
        ):
            model.watch(bad[0], np.zeros(1, int), bad[1], flags, flags)


def test_update_and_wait_times_are_milliseconds_spent_inside_the_calls():
    model = model_of()
    rng = np.random.default_rng(0)
    start = time.perf_counter()
    while model.updates == 0:
        watch(model, rng)
    spent_ms = 1000.0 * (time.perf_counter() - start)
    metrics = model.last_metrics
    assert 0.0 < metrics["update_ms"] <= spent_ms
    assert 0.0 <= metrics["wait_ms"] <= spent_ms


def test_a_failed_step_is_raised_by_the_next_feature_call_before_its_due_watch():
    model = model_of(update_every=4)
    rng = np.random.default_rng(0)
    with torch.no_grad():  # a diverged encoder: its first gradient step meets a NaN loss
        next(model.encoder.parameters()).fill_(float("nan"))
    while not model.pending:
        watch(model, rng)
    message = r"CuriosityModel.s gradient step failed \(FloatingPointError: the CuriosityModel loss"
    with pytest.raises(RuntimeError, match=message + r" is nan.*lower CuriosityConfig\.lr"):
        model(triplets_of(rng, 1))


def test_the_update_thread_is_a_named_daemon():
    model = model_of(background=True)
    rng = np.random.default_rng(0)
    while model._thread is None:
        watch(model, rng)
    thread = model._thread.thread
    # a daemon, so a process whose model was never closed still exits
    assert thread.daemon and thread.name == "simoun-online-update"
    model.close()
