"""simoun_agent.models by hand: Eq. 5's mask, the resizes in float64, Flare's latent flow, the
dual encoder's per-frame features, its frame count check, what make_encoder takes from the
config, which frames the appearance path learns from, the defaults and the initialisation, the
actors' bounds and the heads' layer counts.

Expected values are written out from the definitions (loops, numpy, or the module's own layers
composed as the docstring says), never by calling the function under test on the same path.
"""

import numpy as np
import pytest
import torch
import torch.nn.functional as F
from test_agent_encoder import FRAME, triplets
from test_losses_by_hand import mlp_by_hand, np64, rand
from torch import nn

from simoun_agent import AgentConfig, DualPathEncoder, StructuralInteraction, make_encoder
from simoun_agent.models.actors import DeterministicActor
from simoun_agent.models.encoder import ENCODERS
from simoun_agent.models.interaction import resize_bilinear, resized_linear, structure_mask
from simoun_agent.models.networks import RewardModel, TransitionModel
from simoun_agent.models.sac import Actor, Critic


def test_structure_mask_is_eq5_the_attention_weighted_sum_over_key_positions():
    gen = torch.Generator().manual_seed(0)
    attention = torch.softmax(torch.randn(2, 6, 6, generator=gen, dtype=torch.float64), -1)
    reduced = torch.randn(2, 3, 2, 3, generator=gen, dtype=torch.float64)  # (N, c, h, w)
    x, fh = attention.numpy(), reduced.flatten(2).numpy()  # fh: (N, c, hw)
    expected = np.zeros((2, 3, 6))
    for n in range(2):
        for c in range(3):
            for p in range(6):
                expected[n, c, p] = sum(x[n, p, q] * fh[n, c, q] for q in range(6))
    got = structure_mask(attention, reduced)
    np.testing.assert_allclose(got.numpy(), expected.reshape(2, 3, 2, 3))


@pytest.mark.parametrize("batch", [1, 5])  # 1: the map resized; 5: the resize folded into FC
def test_resizes_keep_float64(batch):
    gen = torch.Generator().manual_seed(batch)
    mask = torch.randn(batch, 4, 3, 5, generator=gen, dtype=torch.float64)
    weight = torch.randn(6, 7 * 9 * 4, generator=gen, dtype=torch.float64)
    resized = F.interpolate(mask, size=(7, 9), mode="bilinear", align_corners=False)
    torch.testing.assert_close(resize_bilinear(mask, (7, 9)), resized)
    expected = resized.permute(0, 2, 3, 1).flatten(1) @ weight.T
    torch.testing.assert_close(resized_linear(mask, weight, (7, 9)), expected)


def test_flare_state_is_ln_fc_of_the_latents_and_their_differences():
    """[z_{t-2}, z_{t-1}, z_t, z_{t-1} - z_{t-2}, z_t - z_{t-1}], each z the conv latent of one
    frame flattened in (h, w, c) order, then FC + LayerNorm."""
    config = AgentConfig(encoder="flare", curiosity=False, feature_dim=8, num_filters=4)
    encoder = make_encoder(config, FRAME)
    obs = triplets()
    with torch.no_grad():
        z = [
            encoder.convs(obs[:, j].float() / 255).permute(0, 2, 3, 1).flatten(1) for j in range(3)
        ]
        features = torch.cat([*z, z[1] - z[0], z[2] - z[1]], dim=1)
        expected = encoder.norm(encoder.fc(features))
        torch.testing.assert_close(encoder(obs).state, expected)


def dual(interactive: bool = True, **kwargs) -> DualPathEncoder:
    """A small dual encoder whose interactive module is on (beta non-zero)."""
    torch.manual_seed(0)
    encoder = DualPathEncoder(
        FRAME, num_filters=4, feature_dim=8, interactive=interactive, reduce_stride=2, **kwargs
    )
    if interactive:
        with torch.no_grad():
            encoder.interaction.beta_motion.fill_(1.0)
            encoder.interaction.beta_appearance.fill_(1.0)
    return encoder


def test_frame_features_are_f_a_of_frames_t_minus_2_t_minus_1_and_t_before_interaction():
    encoder = dual()
    window = torch.cat([triplets(), triplets(seed=1)[:, :1]], dim=1)  # frames t-2 .. t+1
    with torch.no_grad():
        alone = [encoder.encode_key(window[:, j].float() / 255) for j in range(4)]
        enc = encoder(window[:, :3], frame_features=True)
        current, following = encoder.encode_transition(window, True, True)
    for got, first in ((enc, 0), (current, 0), (following, 1)):
        for j in range(3):
            torch.testing.assert_close(got.appearance[:, j], alone[first + j])
    torch.testing.assert_close(enc.anchor, alone[2])
    assert not torch.allclose(enc.state[:, 8:], alone[2])  # f^a_t in the state is after it


def test_parts_not_asked_for_or_not_built_are_none():
    window = torch.cat([triplets(), triplets(seed=1)[:, :1]], dim=1)
    for encoder in (dual(), dual(interactive=False)):
        with torch.no_grad():
            encodings = [encoder(window[:, :3]), *encoder.encode_transition(window)]
        assert [e.appearance for e in encodings] == [None] * 3
        assert all((e.masks is None) == (encoder.interaction is None) for e in encodings)


def test_the_dual_encoder_takes_three_frames_of_any_channel_count_and_refuses_four():
    gray = DualPathEncoder((1, 32, 32), num_filters=4, feature_dim=8, interactive=False)
    obs = triplets()[:, :, :1]  # (B, 3, 1, H, W)
    with torch.no_grad():
        f_a = gray.head_appearance(gray.appearance(obs[:, 2].float() / 255))
        torch.testing.assert_close(gray(obs).state[:, 8:], f_a)
    four = torch.cat([triplets(), triplets(seed=1)[:, :1]], dim=1)
    with pytest.raises(ValueError, match=r"needs 3 frames .* got shape \(4, 4, 3, 32, 32\)"):
        dual()(four)


def test_make_encoder_builds_the_dual_encoders_from_every_config_value():
    values = dict(num_filters=4, feature_dim=6)
    reducing = dict(reduce_kernel=2, reduce_stride=2)  # the interactive module's alone
    for name, detach, channels_last in (("dual_interactive", False, False), ("dual", True, True)):
        config = AgentConfig(
            encoder=name,
            curiosity=False,
            detach_past_frames=detach,
            channels_last=channels_last,
            **values,
            **(reducing if name == "dual_interactive" else {}),
        )
        encoder = make_encoder(config, (1, 24, 28))
        assert encoder.appearance[0].in_channels == 1 and encoder.motion[0].in_channels == 2
        assert encoder.appearance[-2].out_channels == encoder.motion[-2].out_channels == 4
        # 24 x 28 -> 11 x 13 -> 9 x 11 -> 7 x 9 -> 5 x 7 maps of 4 channels into FC -> 6
        assert encoder.head_motion.fc.weight.shape == (6, 4 * 5 * 7)
        assert encoder.detach_past_frames is detach
        assert encoder.memory_format == (
            torch.channels_last if channels_last else torch.contiguous_format
        )
        if name == "dual":
            assert encoder.interaction is None
        else:
            for conv in (encoder.interaction.reduce_appearance, encoder.interaction.reduce_motion):
                assert conv.kernel_size == (2, 2) and conv.stride == (2, 2)


def test_every_encoder_takes_its_conv_memory_format_from_the_config():
    for name in ENCODERS:
        for channels_last in (True, False):
            config = AgentConfig(
                encoder=name, curiosity=False, channels_last=channels_last, num_filters=4
            )
            encoder = make_encoder(config, FRAME)
            layout = torch.channels_last if channels_last else torch.contiguous_format
            assert encoder.memory_format == layout, (name, channels_last)


@pytest.mark.parametrize("detach", [True, False, None])  # None: the default
def test_with_detached_past_frames_the_appearance_path_learns_from_frame_t_only(detach):
    """Frame t all zeros: its share of the first appearance conv's weight gradient is zero, so
    what is left comes from frames t-2, t-1 (through the attention, beta 1), none when they
    are detached."""
    kwargs = {} if detach is None else {"detach_past_frames": detach}
    encoder = dual(**kwargs)
    window = torch.cat([triplets(), triplets(seed=1)[:, :1]], dim=1)
    window[:, 2] = 0
    current, _ = encoder.encode_transition(window)
    current.state.square().sum().backward()
    first_conv = encoder.appearance[0].weight.grad
    assert encoder.head_appearance.fc.weight.grad.abs().sum() > 0
    assert (first_conv.abs().sum() == 0) == (detach is not False)


def test_the_defaults_are_the_papers_as_the_config_has_them():
    paper = AgentConfig()
    encoder = DualPathEncoder((3, 84, 84))
    assert encoder.appearance[0].out_channels == paper.num_filters == 32
    assert encoder.head_appearance.fc.out_features == paper.feature_dim == 50
    assert encoder.detach_past_frames is paper.detach_past_frames is True
    for module in (encoder.interaction, StructuralInteraction(channels=8)):
        conv = module.reduce_appearance
        assert conv.kernel_size == (paper.reduce_kernel,) * 2 == (3, 3)
        assert conv.stride == (paper.reduce_stride,) * 2 == (3, 3)


def test_initial_weights_are_orthogonal_with_the_relu_gain_for_convs_and_zero_biases():
    encoder = make_encoder(AgentConfig(encoder="dual_interactive", num_filters=4), FRAME)
    layers = [m for m in encoder.modules() if isinstance(m, (nn.Conv2d, nn.Linear))]
    assert {type(m) for m in layers} == {nn.Conv2d, nn.Linear} and len(layers) > 8
    for layer in layers:
        w = np64(layer.weight).reshape(layer.weight.shape[0], -1)
        gram = w @ w.T if w.shape[0] <= w.shape[1] else w.T @ w
        gain2 = 2.0 if isinstance(layer, nn.Conv2d) else 1.0  # calculate_gain("relu") ** 2
        np.testing.assert_allclose(gram, gain2 * np.eye(len(gram)), atol=1e-5)
        assert not layer.bias.detach().any()


def test_gaussian_actor_with_three_actions_and_saturated_tanh():
    """mu is the first half of the trunk's output; at |mu| >> 1 the action rounds to +-1 and
    the 1e-6 guard of log(1 - a^2) keeps log pi finite (Eq. 11 and the temperature read it)."""
    torch.manual_seed(0)
    actor = Actor(5, 3, hidden_dim=16, log_std_min=-5.0, log_std_max=1.0)
    for scale in (1.0, 1000.0):
        state = rand(4, 5, seed=1, scale=scale)
        action, log_prob = actor(state, deterministic=True)
        mu, raw = np.split(mlp_by_hand(actor.trunk, np64(state)), 2, axis=1)
        np.testing.assert_allclose(np64(action), np.tanh(mu), rtol=1e-5, atol=1e-6)
        log_std = -5.0 + 3.0 * (np.tanh(raw) + 1)
        a = action.detach().numpy()
        squash = np.log1p(-(a**2) + np.float32(1e-6))  # in float32, as the guard rounds
        expected = (-log_std - 0.5 * np.log(2 * np.pi) - squash).sum(1)
        np.testing.assert_allclose(np64(log_prob)[:, 0], expected, rtol=1e-4, atol=1e-3)
    assert (np.abs(a) == 1.0).any()  # the large scale saturated some actions


def test_heads_have_the_layers_their_docstrings_name():
    """Actor and critic trunks: three FC layers (two hidden); G and R: two FC layers."""
    torch.manual_seed(0)
    x = rand(4, 9, seed=2)
    heads = {
        "actor": (Actor(5, 2, 16, -5.0, 1.0).trunk, 3, x[:, :5]),
        "critic": (Critic(7, 2, 16).q1, 3, x),
        "transition": (TransitionModel(6, 3, 16).net, 2, x),
        "reward": (RewardModel(7, 2, 16).net, 2, x),
    }
    for name, (net, count, inputs) in heads.items():
        layers = [m for m in net if isinstance(m, nn.Linear)]
        assert len(layers) == count, name
        h = np64(inputs)
        for i, layer in enumerate(layers):
            h = h @ np64(layer.weight).T + np64(layer.bias)
            h = np.maximum(h, 0.0) if i < count - 1 else h
        np.testing.assert_allclose(np64(net(inputs)), h, rtol=1e-5, atol=1e-6, err_msg=name)


def test_deterministic_actor_clamps_at_both_bounds_when_acting_and_smoothing():
    torch.manual_seed(0)
    actor = DeterministicActor(5, 2, 16, std_start=5.0, std_end=5.0, std_steps=1, noise_clip=0.3)
    state = rand(64, 5, seed=1, scale=10.0)  # |mu| near 1 in both directions
    mu = np.tanh(mlp_by_hand(actor.trunk, np64(state)))
    torch.manual_seed(3)
    acted = np64(actor.act(state, deterministic=False, step=0))
    torch.manual_seed(3)
    smoothed = np64(actor.smoothed(state, step=0))
    torch.manual_seed(3)
    noise = np64(torch.randn(64, 2))
    unclamped = mu + 5.0 * noise
    np.testing.assert_allclose(acted, np.clip(unclamped, -1, 1), rtol=1e-5, atol=1e-6)
    assert (unclamped > 1).any() and (unclamped < -1).any()
    clipped = mu + np.clip(5.0 * noise, -0.3, 0.3)
    np.testing.assert_allclose(smoothed, np.clip(clipped, -1, 1), rtol=1e-5, atol=1e-6)
    assert (clipped > 1).any() and (clipped < -1).any()
