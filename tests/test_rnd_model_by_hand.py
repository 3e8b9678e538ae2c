"""RNDModel term by term against hand computations (Burda et al. 2019): the networks, the
observation normalization, the error on the newest frame, the predictor's loss and the frames
it is trained on."""

import numpy as np
import pytest
import torch
from test_curiosity_model_by_hand import BY_HAND
from torch import nn

from simoun_agent.rnd_model import RNDConfig, RNDModel, rnd_network

SHAPE = (3, 36, 36)


def model_of(**overrides) -> RNDModel:
    """No pooling, no thread, a batch of 4 from the 4th frame, and steps only when a test asks."""
    by_hand = {**BY_HAND, "batch_size": 4, "learning_starts": 4, "update_every": 10_000}
    config = RNDConfig(**{**by_hand, "feature_dim": 16, "lr": 5e-4, "seed": 0, **overrides})
    return RNDModel(SHAPE, config=config, device="cpu")


def triplets_of(rng: np.random.Generator, n: int) -> np.ndarray:
    """Triplets whose three frames differ, so reading the wrong one shows."""
    return rng.integers(0, 256, size=(n, 3, *SHAPE), dtype=np.uint8)


def watch(model: RNDModel, triplets: np.ndarray, next_triplets: np.ndarray) -> None:
    zeros = np.zeros(len(triplets))
    model.watch(triplets, zeros, next_triplets, zeros, zeros)


def normalized_by_hand(frames: np.ndarray, seen: np.ndarray) -> torch.Tensor:
    """The paper's observation normalization: per pixel, by the mean and std of the frames
    seen, clipped to [-5, 5]."""
    seen = seen.astype(np.float64)
    x = (frames - seen.mean(axis=0)) / np.sqrt(seen.var(axis=0) + 1e-8)
    return torch.as_tensor(np.clip(x, -5, 5), dtype=torch.float32)


def test_the_networks_are_the_papers():
    target = rnd_network(3, (36, 36), 16, predictor=False)
    predictor = rnd_network(3, (36, 36), 16, predictor=True)
    convs = [m for m in target.modules() if isinstance(m, nn.Conv2d)]
    assert [(c.out_channels, c.kernel_size, c.stride) for c in convs] == [
        (32, (8, 8), (4, 4)),
        (64, (4, 4), (2, 2)),
        (64, (3, 3), (1, 1)),
    ]
    assert sum(isinstance(m, nn.LeakyReLU) for m in target.modules()) == 3
    linears = [m for m in predictor.modules() if isinstance(m, nn.Linear)]
    # 36 -> 8 -> 3 -> 1 after the three convolutions: 64 features into the first linear layer
    assert [(lin.in_features, lin.out_features) for lin in linears] == [
        (64, 16),
        (16, 16),
        (16, 16),
    ]
    assert sum(isinstance(m, nn.ReLU) for m in predictor.modules()) == 2
    assert [m.out_features for m in target.modules() if isinstance(m, nn.Linear)] == [16]
    for layer in [*convs, *linears]:
        weight = layer.weight.detach().reshape(layer.weight.shape[0], -1)
        rows, cols = weight.shape
        gram = weight @ weight.T if rows <= cols else weight.T @ weight
        # orthogonal with gain sqrt(2): the Gram matrix of the smaller side is 2 I
        torch.testing.assert_close(gram, 2 * torch.eye(min(rows, cols)), atol=1e-4, rtol=0)
        assert torch.all(layer.bias == 0)
    assert target(torch.zeros(2, 3, 36, 36)).shape == predictor(torch.zeros(2, 3, 36, 36)).shape


def test_the_model_builds_a_fixed_target_and_a_deeper_trained_predictor():
    model = model_of()
    linear_layers = [
        sum(isinstance(m, nn.Linear) for m in net.modules())
        for net in (model.target, model.predictor)
    ]
    assert linear_layers == [1, 3]
    assert not any(p.requires_grad for p in model.target.parameters())
    assert all(p.requires_grad for p in model.predictor.parameters())
    group = model.optimizer.param_groups[0]
    assert group["lr"] == 5e-4  # the config's rate (Adam's default is 1e-3)
    assert {id(p) for p in group["params"]} == {id(p) for p in model.predictor.parameters()}
    assert model._frames.dtype == np.uint8 and model._frames.shape == (8, *SHAPE)


def test_the_error_is_the_squared_distance_on_the_newest_normalized_frame():
    rng = np.random.default_rng(0)
    model = model_of()
    start, reached = triplets_of(rng, 6), triplets_of(rng, 6)
    watch(model, start, reached)
    scored = triplets_of(rng, 3)
    x = normalized_by_hand(scored[:, -1], reached[:, -1])  # statistics of the frames reached
    with torch.no_grad():
        expected = ((model.predictor(x) - model.target(x)) ** 2).mean(-1).numpy()
    np.testing.assert_allclose(model(scored), expected, rtol=1e-5)
    # the error is of the newest frame only: changing the older two changes nothing
    older_changed = scored.copy()
    older_changed[:, :2] = 255 - older_changed[:, :2]
    np.testing.assert_array_equal(model(older_changed), model(scored))


def test_normalization_clips_at_five_standard_deviations():
    model = model_of()
    seen = np.full((4, 3, *SHAPE), 100, dtype=np.uint8)
    seen[:2, :, :, :, :] = 101  # per pixel: mean 100.5, std 0.5
    watch(model, seen, seen)
    frames = np.full((2, *SHAPE), 100, dtype=np.uint8)
    frames[1] = 103  # 5 std above the mean: at the clip
    frames[1, 0, 0, 0] = 200  # far above: clipped to 5
    x = model._normalized(frames).numpy()
    np.testing.assert_allclose(x[0], -1.0, rtol=1e-6)
    np.testing.assert_allclose(x[1], 5.0, rtol=1e-6)
    frames[1, 0, 0, 0] = 0  # far below: clipped to -5
    assert model._normalized(frames).numpy()[1, 0, 0, 0] == pytest.approx(-5.0)


def test_the_loss_is_the_mean_squared_error_against_the_fixed_target():
    rng = np.random.default_rng(1)
    model = model_of()
    reached = triplets_of(rng, 4)
    watch(model, triplets_of(rng, 4), reached)
    x = normalized_by_hand(reached[:, -1], reached[:, -1])
    loss, metrics = model._loss(x)
    with torch.no_grad():
        expected = ((model.predictor(x) - model.target(x)) ** 2).mean()
    assert float(loss.detach()) == pytest.approx(float(expected), rel=1e-6)
    assert metrics["loss"] == pytest.approx(float(expected), rel=1e-6)
    assert loss.requires_grad
    loss.backward()
    assert all(p.grad is None for p in model.target.parameters())
    assert all(p.grad is not None for p in model.predictor.parameters())


def test_updates_train_the_predictor_on_the_frames_reached_and_leave_the_target():
    rng = np.random.default_rng(2)
    model = model_of(capacity=4, lr=1e-3)
    reached = triplets_of(rng, 4)
    watch(model, triplets_of(rng, 4), reached)
    np.testing.assert_array_equal(model._frames, reached[:, -1])  # the reached, newest
    target_before = [p.detach().clone() for p in model.target.parameters()]
    x = normalized_by_hand(reached[:, -1], reached[:, -1])
    with torch.no_grad():
        before = float(((model.predictor(x) - model.target(x)) ** 2).mean())
    for _ in range(60):
        model.update()
    with torch.no_grad():
        after = float(((model.predictor(x) - model.target(x)) ** 2).mean())
    assert model.updates == 60 and after < 0.5 * before
    for saved, now in zip(target_before, model.target.parameters(), strict=True):
        torch.testing.assert_close(saved, now, rtol=0, atol=0)
    # the reward reads the published copy of the trained predictor
    with torch.no_grad():
        expected = ((model.predictor(x) - model.target(x)) ** 2).mean(-1).numpy()
    np.testing.assert_allclose(model(reached), expected, rtol=1e-5)


def test_a_loaded_state_goes_on_as_the_saved_model_does():
    rng = np.random.default_rng(4)
    model = model_of()
    watch(model, triplets_of(rng, 4), triplets_of(rng, 4))
    model.update()
    clone = model_of(seed=1)
    clone.load_state_dict(model.state_dict())
    more, scored = triplets_of(rng, 3), triplets_of(rng, 2)
    for each in (model, clone):  # both watch the same frames after the load
        watch(each, more, more)
    np.testing.assert_array_equal(clone.observations.mean, model.observations.mean)
    np.testing.assert_array_equal(clone.observations.var, model.observations.var)
    assert clone.observations.count == model.observations.count == 7
    np.testing.assert_array_equal(clone(scored), model(scored))


def test_bad_feature_dim_is_refused():
    with pytest.raises(ValueError, match="feature_dim"):
        RNDConfig(feature_dim=0)


def test_frames_are_pooled_to_the_encoder_size_before_both_networks():
    model = RNDModel(
        (3, 84, 84),
        config=RNDConfig(feature_dim=8, capacity=4, batch_size=2, learning_starts=2, seed=0),
        device="cpu",
    )
    assert model.encoded_shape == (3, 42, 42) and model.pool == 2
    rng = np.random.default_rng(3)
    big = rng.integers(0, 256, size=(2, 3, 3, 84, 84), dtype=np.uint8)
    watch(model, big, big)
    pooled = big[:, -1].reshape(2, 3, 42, 2, 42, 2).astype(np.float64).mean(axis=(3, 5))
    np.testing.assert_array_equal(model._frames[:2], np.round(pooled).astype(np.uint8))
    model.close()
