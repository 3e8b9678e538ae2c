"""SimounAgent: gradient routing, EMA targets, curiosity in the TD target, resume, bad input."""

import io

import numpy as np
import pytest
import torch
import torch.nn.functional as F

from simoun_agent import AgentConfig, FrameReplay, SimounAgent
from simoun_agent.config.shapes import ENCODER_SHAPES
from simoun_agent.losses import contrastive_loss
from simoun_wrappers.augment import random_conv

FRAME = (3, 32, 32)
ACTIONS = 2
ENCODERS = ["single", "stacked", "flare", "dual", "dual_interactive", "stacked_wide"]


def small_config(**overrides) -> AgentConfig:
    values = dict(
        batch_size=8,
        hidden_dim=32,
        aux_hidden_dim=16,
        num_filters=8,
        feature_dim=16,
    )
    values.update(overrides)
    if ENCODER_SHAPES[values.get("encoder", "dual_interactive")].interactive:
        # the reducing convs are read by the interactive module alone (elsewhere refused)
        values = dict(reduce_kernel=3, reduce_stride=2) | values
    return AgentConfig(**values)


def random_replay(transitions: int = 40, seed: int = 0) -> FrameReplay:
    rng = np.random.default_rng(seed)
    replay = FrameReplay(100, FRAME, ACTIONS, seed=seed)
    for t in range(transitions):
        if t % 15 == 0:
            replay.start_episode(rng.integers(0, 256, FRAME, dtype=np.uint8))
        frame = rng.integers(0, 256, FRAME, dtype=np.uint8)
        end = t % 15 == 14
        replay.add(rng.uniform(-1, 1, ACTIONS), rng.normal(), frame, end and t % 2 == 0, end)
    return replay


def random_window(batch: int = 8, seed: int = 0) -> tuple[torch.Tensor, ...]:
    gen = torch.Generator().manual_seed(seed)
    window = torch.randint(0, 256, (batch, 4, *FRAME), generator=gen, dtype=torch.uint8)
    action = torch.rand(batch, ACTIONS, generator=gen) * 2 - 1
    reward = torch.randn(batch, generator=gen) * 3
    return window, action, reward, torch.ones(batch)


def params(module: torch.nn.Module) -> list[torch.Tensor]:
    return [p.detach().clone() for p in module.parameters()]


def changed(before: list[torch.Tensor], module: torch.nn.Module) -> bool:
    return any(not torch.equal(b, p) for b, p in zip(before, module.parameters(), strict=True))


@pytest.mark.parametrize("kind", ENCODERS)
def test_updates_stay_finite_and_change_the_weights(kind):
    torch.manual_seed(0)
    agent = SimounAgent(
        FRAME, ACTIONS, small_config(encoder=kind, curiosity=kind.startswith("dual")), "cpu"
    )
    replay = random_replay()
    nets = ("encoder", "critic", "actor", "encoder_target", "critic_target", "reward_model")
    before = {name: params(getattr(agent, name)) for name in nets}
    for step in range(3):
        metrics = agent.update(replay, step)
        assert all(torch.isfinite(v).all() for v in metrics.values()), metrics
    for name in nets:
        assert changed(before[name], getattr(agent, name)), name
    # the third update (num_updates 2) also steps the actor and temperature
    expected = {"critic_loss", "q", "transition_loss", "contrastive_loss", "reward_loss"}
    expected |= {"actor_loss", "alpha", "entropy"}
    assert set(metrics) == expected | ({"intrinsic_reward"} if kind.startswith("dual") else set())
    assert agent.num_updates == 3


def test_critic_loss_reaches_both_paths_and_the_interactive_module():
    torch.manual_seed(0)
    config = small_config(
        curiosity=False, transition_weight=0, contrastive_weight=0, reward_weight=0
    )
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    interaction = agent.encoder.interaction
    with torch.no_grad():  # with beta = 0 only beta itself gets a gradient; open the module up
        interaction.beta_motion.fill_(0.5)
        interaction.beta_appearance.fill_(0.5)
    agent.update_window(*random_window(), step=0)
    modules = {
        "motion path": agent.encoder.motion,
        "appearance path": agent.encoder.appearance,
        "motion head": agent.encoder.head_motion,
        "appearance head": agent.encoder.head_appearance,
        "interactive module": interaction,
    }
    for name, module in modules.items():
        for p in module.parameters():
            assert p.grad is not None and p.grad.abs().sum() > 0, name
    assert agent.reward_model is None  # L_re switched off: no reward model, critic loss only


def test_beta_gets_a_gradient_at_initialisation():
    torch.manual_seed(0)
    agent = SimounAgent(FRAME, ACTIONS, small_config(curiosity=False), "cpu")
    agent.update_window(*random_window(), step=0)
    assert agent.encoder.interaction.beta_motion.grad.abs() > 0
    assert agent.encoder.interaction.beta_appearance.grad.abs() > 0


def test_actor_loss_leaves_the_encoder_and_critic_untouched():
    torch.manual_seed(0)
    agent = SimounAgent(FRAME, ACTIONS, small_config(curiosity=False), "cpu")
    window = random_window()[0]
    encoder_before, critic_before, actor_before = (
        params(agent.encoder),
        params(agent.critic),
        params(agent.actor),
    )
    state = agent.encoder(window[:, :3]).state
    agent.update_actor(state.detach())
    assert all(p.grad is None for p in agent.encoder.parameters())
    assert all(p.grad is None for p in agent.critic.parameters())
    assert not changed(encoder_before, agent.encoder)
    assert not changed(critic_before, agent.critic)
    assert changed(actor_before, agent.actor)
    assert all(p.requires_grad for p in agent.critic.parameters())


@pytest.mark.parametrize(("raw", "bound"), [(100.0, 2.0), (-100.0, -10.0)])
def test_policy_log_std_stays_in_its_bounds(raw, bound):
    """With mu = 0 the deterministic action is 0, so log pi = -(log_std + log(2 pi) / 2) per
    dimension: the log-std must saturate at log_std_max = 2 and log_std_min = -10."""
    agent = SimounAgent(FRAME, ACTIONS, small_config(curiosity=False), "cpu")
    last = agent.actor.trunk[-1]
    with torch.no_grad():
        last.weight.zero_()
        last.bias.copy_(torch.tensor([0.0] * ACTIONS + [raw] * ACTIONS))
        action, log_prob = agent.actor(torch.randn(3, agent.encoder.repr_dim), deterministic=True)
    assert torch.equal(action, torch.zeros(3, ACTIONS))
    expected = -ACTIONS * (bound + 0.5 * np.log(2 * np.pi))
    torch.testing.assert_close(log_prob, torch.full((3, 1), expected), atol=1e-4, rtol=0)


def test_ema_targets_move_by_tau():
    agent = SimounAgent(FRAME, ACTIONS, small_config(curiosity=False), "cpu")
    with torch.no_grad():
        for p in agent.encoder.parameters():
            p.add_(1.0)
        for p in agent.critic.parameters():
            p.add_(1.0)
    pairs = ((agent.encoder, agent.encoder_target, 0.05), (agent.critic, agent.critic_target, 0.01))
    before = [(params(online), params(target)) for online, target, _ in pairs]
    agent.update_targets()
    for (online, target, tau), (on_before, tg_before) in zip(pairs, before, strict=True):
        for o, t_old, t_new in zip(on_before, tg_before, target.parameters(), strict=True):
            torch.testing.assert_close(t_new, t_old + tau * (o - t_old))
        assert not changed(on_before, online)


def test_losses_of_one_update_match_eq_2_7_9_13_on_terminal_transitions():
    """Terminated transitions: the TD target is r_e + r_i (Eq. 9, 13) with no bootstrap; L_re
    (Eq. 7) fits r_e alone; L_tran (Eq. 2) predicts f^m of the triplet shifted by one frame."""
    torch.manual_seed(0)
    config = small_config(r_e_max_init=0.5, r_i_max_init=1e-3)
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    assert float(agent.alpha.detach()) == pytest.approx(0.1)
    window, action, reward, _ = random_window()
    discount = torch.zeros(len(reward))  # every transition terminated: no bootstrap
    f_m, f_a = (x.numpy().astype(np.float64) for x in agent.encoder_features(window[:, :3]))
    flow = np.abs(f_a[:, 1] - f_a[:, 0]) + np.abs(f_a[:, 2] - f_a[:, 1])
    distance = np.sqrt(((np.abs(f_m) - flow) ** 2).sum(-1))
    r_e_max = max(0.5, np.abs(reward.numpy()).max())
    r_i_max = max(1e-3, distance.max())
    step = 10_000
    expected = 0.2 * np.exp(-2e-5 * step) * distance * r_e_max / r_i_max
    with torch.no_grad():
        state = agent.encoder(window[:, :3]).state
        q1, q2 = agent.critic(state, action)
        target = (reward + torch.from_numpy(expected).float()).unsqueeze(-1)
        l_q = F.mse_loss(q1, target) + F.mse_loss(q2, target)
        l_re = F.mse_loss(agent.reward_model(state, action), reward)
        next_motion = agent.encoder(window[:, 1:]).motion
        l_tran = (agent.transition(state[:, :16], action) - next_motion).pow(2).sum(-1).mean()
    metrics = agent.update_window(window, action, reward, discount, step)
    np.testing.assert_allclose(float(metrics["intrinsic_reward"]), expected.mean(), rtol=1e-4)
    np.testing.assert_allclose(float(metrics["critic_loss"]), float(l_q), rtol=1e-4)
    np.testing.assert_allclose(float(metrics["reward_loss"]), float(l_re), rtol=1e-4)
    np.testing.assert_allclose(float(metrics["transition_loss"]), float(l_tran), rtol=1e-4)
    np.testing.assert_allclose(float(agent.running_max.r_i_max), r_i_max, rtol=1e-5)
    np.testing.assert_allclose(float(agent.running_max.r_e_max), r_e_max, rtol=1e-6)


def test_contrastive_loss_pairs_online_f_a_with_momentum_keys_of_random_conv_views():
    """Eq. 3 in the update: anchor f^a(o_t) of the online appearance path before the interactive
    module, key from the momentum encoder on random_conv(o_t / 255), scored by the bilinear W."""
    torch.manual_seed(0)
    agent = SimounAgent(FRAME, ACTIONS, small_config(curiosity=False), "cpu")
    with torch.no_grad():
        agent.encoder.interaction.beta_appearance.fill_(0.5)
        for p in agent.encoder_target.parameters():  # make the momentum encoder differ
            p.mul_(1.5)
        agent.similarity.weight.add_(torch.randn(16, 16) * 0.1)
    window, action, reward, discount = random_window()
    obs = window[:, :3]
    torch.manual_seed(7)
    with torch.no_grad():
        key = agent.encoder_target.encode_key(random_conv(obs[:, -1].float() / 255, 3))
        anchor = agent.encoder.head_appearance(agent.encoder.appearance(obs[:, -1].float() / 255))
        logits = (anchor @ agent.similarity.weight @ key.T).double()
        expected = (logits.logsumexp(1) - logits.diagonal()).mean()
    torch.manual_seed(7)
    metrics = agent.update_window(window, action, reward, discount, step=0)
    np.testing.assert_allclose(float(metrics["contrastive_loss"]), float(expected), rtol=1e-4)


def test_contrastive_loss_sends_no_gradient_to_the_keys():
    gen = torch.Generator().manual_seed(0)
    anchor = torch.randn(5, 3, generator=gen, requires_grad=True)
    key = torch.randn(5, 3, generator=gen, requires_grad=True)
    contrastive_loss(anchor, key).backward()
    assert key.grad is None and anchor.grad.abs().sum() > 0


def test_resume_from_state_dict_is_bit_exact(tmp_path):
    torch.manual_seed(0)
    config = small_config()
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    replay = random_replay()
    for step in range(3):
        agent.update(replay, step)
    buffer = io.BytesIO()
    torch.save({"agent": agent.state_dict(), "rng": torch.get_rng_state()}, buffer)
    replay.save(tmp_path / "replay.npz")
    for step in range(3, 6):
        agent.update(replay, step)
    agent.act(replay.sample(1)["obs"][0])

    buffer.seek(0)
    saved = torch.load(buffer, weights_only=False)
    resumed = SimounAgent(FRAME, ACTIONS, config, "cpu")
    resumed.load_state_dict(saved["agent"])
    torch.set_rng_state(saved["rng"])
    resumed_replay = FrameReplay.load(tmp_path / "replay.npz")
    for step in range(3, 6):
        resumed.update(resumed_replay, step)
    resumed.act(resumed_replay.sample(1)["obs"][0])
    for name, net in agent.modules().items():
        for a, b in zip(net.parameters(), resumed.modules()[name].parameters(), strict=True):
            assert torch.equal(a, b), name
    assert torch.equal(agent.log_alpha, resumed.log_alpha)
    assert resumed.num_updates == agent.num_updates == 6


def test_act_returns_bounded_float32_and_refuses_bad_observations():
    agent = SimounAgent(FRAME, ACTIONS, small_config(), "cpu")
    obs = np.zeros((3, *FRAME), np.uint8)
    for deterministic in (False, True):
        action = agent.act(obs, deterministic=deterministic)
        assert action.shape == (ACTIONS,) and action.dtype == np.float32
        assert np.all(np.abs(action) <= 1)
    with pytest.raises(ValueError, match=r"uint8 frames of shape \(3, 3, 32, 32\)"):
        agent.act(obs.astype(np.float32))
    with pytest.raises(ValueError, match=r"uint8 frames of shape \(3, 3, 32, 32\)"):
        agent.act(obs[None])
    with pytest.raises(ValueError, match="got uint8 \\(3, 32, 32\\)"):
        agent.act(obs[0])


def test_config_refuses_curiosity_without_two_paths():
    with pytest.raises(ValueError, match="curiosity=False"):
        AgentConfig(encoder="stacked")
    with pytest.raises(ValueError, match="choose one of"):
        AgentConfig(encoder="resnet")
