"""Every loss and target of simoun_agent.losses (Eq. 2, 3, 7, 9, 10, 11, 14, the temperature
loss), the tanh-Gaussian policy and the heads, against numpy formulas written out here.

Each expected value is computed in float64 numpy from the inputs (and from the modules' weights,
layer by layer), never by calling the function under test. The batches mix terminal and
non-terminal rows, the twin Q values differ in both directions, gamma and alpha are not 1, so a
flipped sign, a max for a min, a dropped discount or a missing detach changes a value checked
here. The gradient checks say which inputs each loss trains and which it must hold fixed.
"""

import ast
import math
from pathlib import Path

import numpy as np
import pytest
import torch

from simoun_agent import losses
from simoun_agent.losses import (
    actor_loss,
    contrastive_loss,
    critic_loss,
    deterministic_actor_loss,
    deterministic_value,
    intrinsic_return,
    reward_loss,
    soft_value,
    td_target,
    temperature_loss,
    total_loss,
    transition_loss,
)
from simoun_agent.models.actors import DeterministicActor, exploration_std
from simoun_agent.models.networks import BilinearSimilarity, RewardModel, TransitionModel
from simoun_agent.models.sac import Actor, Critic

B, D, A = 6, 5, 2


def rand(*shape: int, seed: int, scale: float = 1.0, grad: bool = False) -> torch.Tensor:
    gen = torch.Generator().manual_seed(seed)
    return (torch.randn(*shape, generator=gen) * scale).requires_grad_(grad)


def np64(x: torch.Tensor) -> np.ndarray:
    return x.detach().numpy().astype(np.float64)


def mlp_by_hand(layers: torch.nn.Sequential, x: np.ndarray) -> np.ndarray:
    """Linear / ReLU layers applied one by one in numpy from the module's weights."""
    for layer in layers:
        if isinstance(layer, torch.nn.Linear):
            x = x @ np64(layer.weight).T + np64(layer.bias)
        else:
            assert isinstance(layer, torch.nn.ReLU), layer
            x = np.maximum(x, 0.0)
    return x


def grad_is_zero(t: torch.Tensor) -> bool:
    return t.grad is None or not t.grad.any()


# -- Eq. 2, 3, 7: the auxiliary losses ---------------------------------------------------------


def test_transition_loss_is_eq2_squared_l2_per_sample_then_batch_mean():
    torch.manual_seed(0)
    model = TransitionModel(D, A, hidden_dim=8)
    motion, action = rand(B, D, seed=1, grad=True), rand(B, A, seed=2)
    next_motion = rand(B, D, seed=3, grad=True)
    loss = transition_loss(model(motion, action), next_motion)
    predicted = mlp_by_hand(model.net, np.concatenate([np64(motion), np64(action)], 1))
    expected = ((predicted - np64(next_motion)) ** 2).sum(1).mean()
    assert float(loss.detach()) == pytest.approx(expected, rel=1e-5)
    loss.backward()
    assert next_motion.grad is None  # the target f^m_{t+1} is detached
    assert motion.grad.abs().sum() > 0
    assert all(p.grad is not None and p.grad.abs().sum() > 0 for p in model.parameters())


def imported_modules(source: str) -> list[str]:
    """Every module an ``import`` or ``from ... import`` of ``source`` names, anywhere in it
    (``TYPE_CHECKING`` blocks included); a relative import counts as ``simoun_agent``'s."""
    names = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            names += [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            names.append("simoun_agent" if node.level else node.module)
    return names


def test_losses_import_nothing_from_simoun_agent():
    """The losses take tensors, so the networks can import them and not the other way round."""
    names = imported_modules(Path(losses.__file__).read_text())
    assert "torch" in names  # the walk sees the module's imports
    assert not [name for name in names if name.split(".")[0] == "simoun_agent"], names


def test_transition_model_reads_motion_then_action():
    model = TransitionModel(D, A, hidden_dim=8)
    motion, action = rand(B, D, seed=1), rand(B, A, seed=2)
    expected = mlp_by_hand(model.net, np.concatenate([np64(motion), np64(action)], 1))
    np.testing.assert_allclose(np64(model(motion, action)), expected, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("bilinear", [True, False])
def test_contrastive_loss_is_eq3_infonce_with_the_diagonal_as_positives(bilinear):
    anchor = rand(B, D, seed=1, grad=True)
    key = rand(B, D, seed=2, grad=True)
    similarity = None
    weight = np.eye(D)
    if bilinear:
        similarity = BilinearSimilarity(D)
        with torch.no_grad():  # an asymmetric W: a transposed score would change the value
            similarity.weight.add_(rand(D, D, seed=3, scale=0.5))
        weight = np64(similarity.weight)
    loss = contrastive_loss(anchor, key, similarity.weight if bilinear else None)
    logits = np64(anchor) @ weight @ np64(key).T
    log_sum_exp = np.log(np.exp(logits).sum(1))
    expected = (log_sum_exp - np.diag(logits)).mean()
    assert float(loss.detach()) == pytest.approx(expected, rel=1e-5)
    loss.backward()
    assert key.grad is None  # keys come from the momentum encoder, without gradient
    assert anchor.grad.abs().sum() > 0
    if bilinear:
        assert similarity.weight.grad.abs().sum() > 0


def test_contrastive_loss_stays_finite_for_large_scores():
    """Scores of a few hundred (long feature vectors) overflow exp in float32 unless the row
    maximum is subtracted first; the value must still be Eq. 3's."""
    anchor, key = rand(B, D, seed=1, scale=20.0), rand(B, D, seed=2, scale=20.0)
    logits = np64(anchor) @ np64(key).T
    shifted = logits - logits.max(1, keepdims=True)
    expected = (np.log(np.exp(shifted).sum(1)) - np.diag(shifted)).mean()
    assert np.abs(logits).max() > 100
    assert float(contrastive_loss(anchor, key)) == pytest.approx(expected, rel=1e-4)


def test_reward_loss_is_eq7_mean_squared_error_against_the_given_reward():
    torch.manual_seed(0)
    model = RewardModel(D, A, hidden_dim=8)
    state, action = rand(B, D, seed=1, grad=True), rand(B, A, seed=2)
    reward = rand(B, seed=3, scale=3.0)
    loss = reward_loss(model(state, action), reward)
    predicted = mlp_by_hand(model.net, np.concatenate([np64(state), np64(action)], 1))[:, 0]
    assert float(loss.detach()) == pytest.approx(((predicted - np64(reward)) ** 2).mean(), rel=1e-5)
    loss.backward()
    assert state.grad.abs().sum() > 0  # L_re trains the encoder through f_t


# -- Eq. 9, 10: the soft Bellman target and the critic loss ------------------------------------

Q1 = torch.tensor([[1.0], [-2.0], [0.5], [3.0], [-1.0], [0.0]])
Q2 = torch.tensor([[2.0], [-3.0], [0.5], [1.0], [-0.5], [-4.0]])
"""Twin values that differ, with Q1 < Q2 in some rows and Q1 > Q2 in others."""
LOG_PROB = torch.tensor([[-1.5], [0.7], [2.0], [-0.2], [-3.0], [1.1]])
REWARD = torch.tensor([0.5, -1.0, 2.0, 0.0, 1.5, -0.3])
DISCOUNT = torch.tensor([1.0, 0.0, 0.81, 1.0, 0.0, 0.9])
"""1: bootstrap; 0: terminated; gamma^(m-1) of a cut n-step return."""
GAMMA, ALPHA = 0.9, 0.3


def test_soft_value_is_eq10_clipped_double_q_minus_alpha_log_pi():
    value = soft_value(Q1, Q2, LOG_PROB, torch.tensor(ALPHA))
    expected = np.minimum(np64(Q1), np64(Q2)) - ALPHA * np64(LOG_PROB)
    assert value.shape == (B, 1)
    np.testing.assert_allclose(np64(value), expected, rtol=1e-6)


def test_td_target_is_eq9_reward_plus_discounted_value_without_bootstrap_at_termination():
    value = torch.tensor([[4.0], [5.0], [-2.0], [1.0], [7.0], [3.0]])
    target = td_target(REWARD, DISCOUNT, GAMMA, value)
    expected = np64(REWARD) + GAMMA * np64(DISCOUNT) * np64(value)[:, 0]
    assert target.shape == (B, 1)
    np.testing.assert_allclose(np64(target)[:, 0], expected, rtol=1e-6)
    # the terminated rows (discount 0) are the reward alone
    np.testing.assert_allclose(np64(target)[[1, 4], 0], np64(REWARD)[[1, 4]])


def test_critic_loss_is_eq9_both_heads_against_one_detached_target():
    q1, q2 = Q1.clone().requires_grad_(True), Q2.clone().requires_grad_(True)
    target = torch.tensor([[0.0], [1.0], [-1.0], [2.0], [0.5], [-2.0]], requires_grad=True)
    loss = critic_loss(q1, q2, target)
    y = np64(target)
    expected = ((np64(Q1) - y) ** 2).mean() + ((np64(Q2) - y) ** 2).mean()
    assert float(loss.detach()) == pytest.approx(expected, rel=1e-6)
    loss.backward()
    assert target.grad is None  # the target is a constant of the regression
    np.testing.assert_allclose(np64(q1.grad), 2 * (np64(Q1) - y) / B, rtol=1e-6)
    np.testing.assert_allclose(np64(q2.grad), 2 * (np64(Q2) - y) / B, rtol=1e-6)


# -- Eq. 11 and the temperature ------------------------------------------------------------------


def test_actor_loss_is_eq11_alpha_log_pi_minus_the_smaller_q_with_alpha_fixed():
    log_alpha = torch.tensor(math.log(ALPHA), requires_grad=True)
    log_prob = LOG_PROB.clone().requires_grad_(True)
    q1, q2 = Q1.clone().requires_grad_(True), Q2.clone().requires_grad_(True)
    loss = actor_loss(log_alpha.exp(), log_prob, q1, q2)
    expected = (ALPHA * np64(LOG_PROB) - np.minimum(np64(Q1), np64(Q2))).mean()
    assert float(loss.detach()) == pytest.approx(expected, rel=1e-6)
    loss.backward()
    assert grad_is_zero(log_alpha)  # the temperature has its own loss
    np.testing.assert_allclose(np64(log_prob.grad), np.full((B, 1), ALPHA / B), rtol=1e-6)
    # the minimum's gradient goes to the smaller head of each row (-1/B), none to the other
    smaller_is_1 = np64(Q1) < np64(Q2)
    np.testing.assert_allclose(np64(q1.grad)[smaller_is_1], -1 / B)
    np.testing.assert_allclose(np64(q2.grad)[~smaller_is_1 & (np64(Q1) > np64(Q2))], -1 / B)
    assert not np64(q1.grad)[np64(Q1) > np64(Q2)].any()


def test_temperature_loss_is_alpha_times_entropy_excess_with_the_policy_fixed():
    target_entropy = -float(A)
    log_alpha = torch.tensor(math.log(ALPHA), requires_grad=True)
    log_prob = LOG_PROB.clone().requires_grad_(True)
    loss = temperature_loss(log_alpha, log_prob, target_entropy)
    excess = -np64(LOG_PROB) - target_entropy
    assert float(loss.detach()) == pytest.approx((ALPHA * excess).mean(), rel=1e-6)
    loss.backward()
    assert log_prob.grad is None  # the policy is held fixed
    # d/d log alpha of alpha * excess is alpha * excess (alpha = exp(log alpha))
    assert float(log_alpha.grad) == pytest.approx((ALPHA * excess).mean(), rel=1e-6)


@pytest.mark.parametrize(("entropy", "direction"), [(5.0, -1), (-5.0, +1)])
def test_a_gradient_step_on_the_temperature_moves_entropy_toward_its_target(entropy, direction):
    """Entropy above the target (-|A|) lowers alpha, below it raises alpha (SAC's rule)."""
    log_alpha = torch.tensor(math.log(ALPHA), requires_grad=True)
    log_prob = torch.full((B, 1), -entropy)
    temperature_loss(log_alpha, log_prob, -float(A)).backward()
    stepped = float(log_alpha.detach() - 0.1 * log_alpha.grad)
    assert np.sign(stepped - math.log(ALPHA)) == direction


# -- Eq. 14 ------------------------------------------------------------------------------------


def test_total_loss_is_eq14_weighted_sum_skipping_absent_and_zero_weight_terms():
    critic, tran, con, re = (torch.tensor(v) for v in (1.5, 0.25, 2.0, 0.75))
    assert float(total_loss(critic, tran, con, re, 0.5, 2.0, 3.0)) == pytest.approx(
        1.5 + 0.5 * 0.25 + 2.0 * 2.0 + 3.0 * 0.75
    )
    assert float(total_loss(critic, None, con, None, 0.5, 2.0, 3.0)) == pytest.approx(1.5 + 4.0)
    nan = torch.tensor(float("nan"))  # a weight of 0 drops the term entirely
    assert float(total_loss(critic, nan, con, re, 0.0, 1.0, 1.0)) == pytest.approx(1.5 + 2.75)


# -- the networks the losses read: tanh-Gaussian policy and twin critic --------------------------


def actor_and_state(seed: int = 0) -> tuple[Actor, torch.Tensor]:
    torch.manual_seed(seed)
    actor = Actor(D, A, hidden_dim=16, log_std_min=-5.0, log_std_max=1.0)
    return actor, rand(B, D, seed=seed + 1)


def test_policy_log_prob_is_the_tanh_gaussian_density_with_the_squash_correction():
    actor, state = actor_and_state()
    torch.manual_seed(11)
    action, log_prob = actor(state)
    torch.manual_seed(11)
    noise = np64(torch.randn(B, A))  # the policy's own draw (randn_like of mu, same generator)
    mu, raw = np.split(mlp_by_hand(actor.trunk, np64(state)), 2, axis=1)
    log_std = -5.0 + 0.5 * (1.0 - -5.0) * (np.tanh(raw) + 1)
    pre_tanh = mu + noise * np.exp(log_std)
    gaussian = -0.5 * noise**2 - log_std - 0.5 * np.log(2 * np.pi)
    squash = np.log(1 - np.tanh(pre_tanh) ** 2)
    np.testing.assert_allclose(np64(action), np.tanh(pre_tanh), rtol=1e-5, atol=1e-6)
    assert np.abs(np.tanh(pre_tanh)).max() < 0.99  # away from the 1e-6 guard of log(1 - a^2)
    np.testing.assert_allclose(np64(log_prob)[:, 0], (gaussian - squash).sum(1), atol=1e-4)
    assert log_prob.shape == (B, 1)


def test_policy_log_prob_matches_torch_distributions():
    actor, state = actor_and_state(seed=3)
    action, log_prob = actor(state)
    mu, raw = actor.trunk(state).chunk(2, dim=-1)
    log_std = -5.0 + 3.0 * (torch.tanh(raw) + 1)
    dist = torch.distributions.TransformedDistribution(
        torch.distributions.Normal(mu, log_std.exp()),
        [torch.distributions.TanhTransform(cache_size=1)],
    )
    expected = dist.log_prob(action.detach().clone()).sum(-1)
    np.testing.assert_allclose(np64(log_prob)[:, 0], np64(expected), atol=1e-3)


def test_deterministic_action_is_tanh_of_the_mean():
    actor, state = actor_and_state()
    action, _ = actor(state, deterministic=True)
    mu = mlp_by_hand(actor.trunk, np64(state))[:, :A]
    np.testing.assert_allclose(np64(action), np.tanh(mu), rtol=1e-5, atol=1e-6)


def test_twin_critic_heads_read_state_then_action_each_with_its_own_weights():
    torch.manual_seed(0)
    critic = Critic(D, A, hidden_dim=16)
    state, action = rand(B, D, seed=1), rand(B, A, seed=2)
    q1, q2 = critic(state, action)
    x = np.concatenate([np64(state), np64(action)], 1)
    np.testing.assert_allclose(np64(q1), mlp_by_hand(critic.q1, x), rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(np64(q2), mlp_by_hand(critic.q2, x), rtol=1e-5, atol=1e-6)
    assert not torch.allclose(q1, q2)


# -- DrQ-v2's deterministic actor and the per-step curiosity of n-step targets -------------------


def test_deterministic_value_and_actor_loss_are_the_clipped_double_q_without_entropy():
    value = deterministic_value(Q1, Q2)
    np.testing.assert_allclose(np64(value), np.minimum(np64(Q1), np64(Q2)))
    q1, q2 = Q1.clone().requires_grad_(True), Q2.clone().requires_grad_(True)
    loss = deterministic_actor_loss(q1, q2)
    assert float(loss.detach()) == pytest.approx(-np.minimum(np64(Q1), np64(Q2)).mean())
    loss.backward()
    smaller_is_1 = np64(Q1) < np64(Q2)
    np.testing.assert_allclose(np64(q1.grad)[smaller_is_1], -1 / B)
    assert not np64(q1.grad)[np64(Q1) > np64(Q2)].any()


def test_intrinsic_return_discounts_each_step_and_stops_at_the_mask():
    intrinsic = torch.tensor([[1.0, 2.0, 3.0], [10.0, 20.0, 30.0], [100.0, 200.0, 300.0]])
    mask = torch.tensor([[1.0, 1.0, 1.0], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    expected = [1 + 0.5 * 10 + 0.25 * 100, 2 + 0.5 * 20, 3.0]
    np.testing.assert_allclose(np64(intrinsic_return(intrinsic, mask, 0.5)), expected)
    np.testing.assert_allclose(np64(intrinsic_return(intrinsic[:1], mask[:1], 0.5)), [1, 2, 3])


def test_exploration_std_is_drqv2_linear_schedule():
    assert [exploration_std(s, 1.0, 0.1, 100) for s in (-5, 0, 25, 100, 10**6)] == pytest.approx(
        [1.0, 1.0, 0.775, 0.1, 0.1]
    )


def test_smoothed_action_clips_the_noise_clamps_the_action_and_passes_the_gradient():
    torch.manual_seed(0)
    actor = DeterministicActor(D, A, 16, std_start=5.0, std_end=5.0, std_steps=1, noise_clip=0.3)
    state = rand(B, D, seed=1, scale=10.0, grad=True)  # |mu| near 1: some actions get clamped
    torch.manual_seed(4)
    action = actor.smoothed(state, step=0)
    torch.manual_seed(4)
    noise = np.clip(5.0 * np64(torch.randn(B, A)), -0.3, 0.3)
    mu = np.tanh(mlp_by_hand(actor.trunk, np64(state)))
    np.testing.assert_allclose(np64(action), np.clip(mu + noise, -1, 1), rtol=1e-5, atol=1e-6)
    assert np.abs(noise).max() == pytest.approx(0.3)  # std 5: the clip is what bounds it
    # the clamp's gradient is the identity: d a / d mu = 1 even where the action is clamped
    assert (np.abs(mu + noise) > 1).any()
    expected = torch.autograd.grad(actor(state).sum(), state)[0]
    torch.testing.assert_close(torch.autograd.grad(action.sum(), state)[0], expected)
