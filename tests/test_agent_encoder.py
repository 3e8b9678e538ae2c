"""Encoders (every ablation of Fig. 6) and the structural interactive module (Eq. 4-6)."""

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from simoun_agent import AgentConfig, DualPathEncoder, StructuralInteraction, make_encoder
from simoun_agent.models.interaction import inter_frame_attention, resize_bilinear, resized_linear
from simoun_wrappers import residual_motion

FRAME = (3, 32, 32)
ENCODERS = ["single", "stacked", "flare", "dual", "dual_interactive", "stacked_wide"]


def triplets(batch: int = 4, seed: int = 0) -> torch.Tensor:
    gen = torch.Generator().manual_seed(seed)
    return torch.randint(0, 256, (batch, 3, *FRAME), generator=gen, dtype=torch.uint8)


@pytest.mark.parametrize("kind", ENCODERS)
def test_every_encoder_shapes_and_dtypes(kind):
    config = AgentConfig(encoder=kind, curiosity=False, feature_dim=8, num_filters=4)
    encoder = make_encoder(config, FRAME)
    obs = triplets()
    enc = encoder(obs)
    width = 16 if kind.startswith("dual") else 8
    assert encoder.repr_dim == width
    assert enc.state.shape == (4, width) and enc.state.dtype == torch.float32
    assert enc.anchor.shape == (4, 8)
    view = encoder.key_frames(obs)
    assert view.dtype == torch.float32 and view.shape == (
        (4, *FRAME) if encoder.key_is_frame else (4, 3, *FRAME)
    )
    assert encoder.encode_key(view).shape == (4, 8)
    window = torch.cat([obs, triplets(seed=1)[:, :1]], dim=1)
    current, following = encoder.encode_transition(window)
    assert current.state.shape == following.state.shape == (4, width)
    assert current.state.requires_grad and not following.state.requires_grad
    # the state at t+1 is what a plain forward on the shifted triplet gives
    torch.testing.assert_close(following.state, encoder(window[:, 1:]).state)
    torch.testing.assert_close(current.state, encoder(window[:, :-1]).state)
    assert torch.isfinite(current.state).all()
    # only "single" ignores the earlier frames
    older_changed = obs.clone()
    older_changed[:, 0] = 255 - older_changed[:, 0]
    with torch.no_grad():
        same = torch.equal(encoder(older_changed).state, encoder(obs).state)
    assert same == (kind == "single")


def test_dual_encoder_curiosity_features_and_masks():
    encoder = DualPathEncoder(FRAME, num_filters=4, feature_dim=8, reduce_kernel=3, reduce_stride=2)
    enc = encoder(triplets(), frame_features=True)
    assert enc.motion.shape == (4, 8) and enc.appearance.shape == (4, 3, 8)
    torch.testing.assert_close(enc.appearance[:, 2], enc.anchor.detach())
    # f^a of frame t-2 is what the appearance path gives on that frame alone
    alone = encoder.encode_key(encoder.to_float(triplets()[:, 0]))
    torch.testing.assert_close(enc.appearance[:, 0], alone)
    # 32 -> 15 -> 13 -> 11 -> 9, reduced with kernel 3 stride 2 -> 4x4: X is 16 x 16
    assert enc.masks.attention.shape == (4, 16, 16)
    assert enc.masks.motion.shape == enc.masks.appearance.shape == (4, 4, 4, 4)


def test_attention_rows_sum_to_one():
    gen = torch.Generator().manual_seed(0)
    maps = [torch.randn(2, 8, 5, 5, generator=gen) for _ in range(3)]
    x = inter_frame_attention(*maps)
    assert x.shape == (2, 25, 25)
    torch.testing.assert_close(x.sum(-1), torch.ones(2, 25))
    assert (x > 0).all()


def test_beta_zero_leaves_features_unchanged_and_beta_changes_them():
    module = StructuralInteraction(channels=6)
    gen = torch.Generator().manual_seed(0)
    motion = torch.randn(2, 6, 11, 11, generator=gen)
    appearance = [torch.randn(2, 6, 11, 11, generator=gen) for _ in range(3)]
    out_m, out_a, masks = module(motion, appearance)
    assert module.beta_motion.item() == 0 and module.beta_appearance.item() == 0
    torch.testing.assert_close(out_m, motion, rtol=0, atol=0)
    torch.testing.assert_close(out_a, appearance[2], rtol=0, atol=0)
    with torch.no_grad():
        module.beta_motion.fill_(0.5)
        module.beta_appearance.fill_(0.5)
    out_m, out_a, _ = module(motion, appearance)
    assert not torch.allclose(out_m, motion) and not torch.allclose(out_a, appearance[2])
    assert masks.attention.shape == (2, 9, 9)  # 11x11 -> kernel 3 stride 3 -> 3x3


def test_default_reduction_at_84x84_is_11x11():
    encoder = DualPathEncoder((3, 84, 84))
    obs = torch.zeros(1, 3, 3, 84, 84, dtype=torch.uint8)
    with torch.no_grad():
        enc = encoder(obs)
    assert enc.masks.attention.shape == (1, 121, 121)
    assert enc.state.shape == (1, 100)


@pytest.mark.parametrize("batch", [1, 4])
@torch.no_grad()
def test_folded_resize_matches_explicit_eq6_maps(batch):
    """Batch 1 without gradient (act) resizes the masks, batch 4 folds the resize into FC."""
    torch.manual_seed(0)
    encoder = DualPathEncoder(FRAME, num_filters=4, feature_dim=8, reduce_kernel=3, reduce_stride=2)
    with torch.no_grad():
        encoder.interaction.beta_motion.fill_(0.7)
        encoder.interaction.beta_appearance.fill_(-0.3)
    obs = triplets(batch)
    x = encoder.frame_stack(obs)
    frames = [encoder.appearance_maps(x[j]) for j in range(3)]
    enhanced_m, enhanced_a, _ = encoder.interaction(encoder.motion_maps(x), frames)
    enc = encoder(obs)
    torch.testing.assert_close(enc.motion, encoder.head_motion(enhanced_m))
    torch.testing.assert_close(enc.state[:, 8:], encoder.head_appearance(enhanced_a))
    torch.testing.assert_close(enc.anchor, encoder.head_appearance(frames[2]))


def test_resize_bilinear_matches_interpolate():
    x = torch.randn(2, 3, 4, 7)
    expected = F.interpolate(x, size=(9, 17), mode="bilinear", align_corners=False)
    torch.testing.assert_close(resize_bilinear(x, (9, 17)), expected)


@pytest.mark.parametrize("batch", [1, 2, 5])
@pytest.mark.parametrize("grad", [False, True])
def test_resized_linear_equals_resize_then_linear(batch, grad):
    """Both ways (weight folded for training batches, map resized for act's one observation)."""
    gen = torch.Generator().manual_seed(batch)
    mask = torch.randn(batch, 4, 3, 5, generator=gen)
    weight = torch.randn(6, 7 * 9 * 4, generator=gen, requires_grad=grad)
    resized = F.interpolate(mask, size=(7, 9), mode="bilinear", align_corners=False)
    expected = resized.permute(0, 2, 3, 1).flatten(1) @ weight.T
    torch.testing.assert_close(resized_linear(mask, weight, (7, 9)), expected)


def test_motion_path_sees_the_residuals_of_the_frames():
    """f^m is FC + LN of E^m on [o_{t-1} - o_{t-2}, o_t - o_{t-1}] / 255 (ResidualMotion's
    channels), f^a of frame t is FC + LN of E^a on o_t / 255."""
    encoder = make_encoder(AgentConfig(encoder="dual", curiosity=False, num_filters=4), FRAME)
    obs = triplets()
    residuals = torch.from_numpy(residual_motion(obs.numpy())).float() / 255
    with torch.no_grad():
        enc = encoder(obs)
        f_m = encoder.head_motion(encoder.motion(residuals))
        f_a = encoder.head_appearance(encoder.appearance(obs[:, 2].float() / 255))
    torch.testing.assert_close(enc.motion, f_m)
    torch.testing.assert_close(enc.state, torch.cat([f_m, f_a], dim=1))


def test_inter_frame_attention_by_hand():
    """Eq. 4 with query t-1 and keys t-2, t, scores scaled by 1/sqrt(c), one loop per position."""
    gen = torch.Generator().manual_seed(1)
    prev2, query, cur = (torch.randn(1, 4, 2, 3, generator=gen, dtype=torch.float64) for _ in "abc")
    q, k2, k0 = (m[0].flatten(1).numpy() for m in (query, prev2, cur))  # (c, hw)

    def softmax(v):
        e = np.exp(np.asarray(v) - np.max(v))
        return e / e.sum()

    expected = np.zeros((6, 6))
    for i in range(6):
        s2 = softmax([q[:, i] @ k2[:, j] / 2 for j in range(6)])
        s0 = softmax([q[:, i] @ k0[:, j] / 2 for j in range(6)])
        expected[i] = softmax(s2 + s0)
    np.testing.assert_allclose(inter_frame_attention(prev2, query, cur)[0].numpy(), expected)
