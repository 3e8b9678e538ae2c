"""The SimounAgent paths the other hand checks do not take, each against a hand computation:
DrQ's K/M averaging, ``next_state_encoder="target"``, the deterministic actor's exploration
schedule, the initial running maxima, the checkpoint counters and the misuse messages of acting.
"""

import copy
import io
from dataclasses import asdict

import numpy as np
import pytest
import torch
from test_agent_maths import (
    ALPHA,
    GAMMA,
    STEP,
    TERMINATED,
    Calls,
    agent_for_targets,
    intrinsic_by_hand,
    mixed_twins,
    np64,
    perturb,
)
from test_agent_update import ACTIONS, FRAME, random_window, small_config

from simoun_agent import SimounAgent
from simoun_wrappers.augment import random_shift


@pytest.mark.parametrize(("k", "m"), [(2, 2), (3, 2), (2, 1), (1, 2)])
def test_drq_target_averages_v_over_k_views_and_l_q_over_m_views(k, m):
    """DrQ: V is the mean of the K target views' min(Qbar) - alpha log pi, each view bootstrapping
    from o_{t+1} under its own shift (view j shares the offsets of critic view j); L_Q is the
    mean over the M critic views of Eq. 9 against that one target; L_re and L_tran read view 0."""
    agent = agent_for_targets(augmentation="shift", critic_augmentations=m, target_augmentations=k)
    window, action, reward, _ = random_window()
    mixed_twins(agent, window[:, 1:])
    torch.manual_seed(11)  # the views are the update's first random draws
    views = [random_shift(window, agent.shift_pad) for _ in range(max(k, m))]
    assert all(not torch.equal(views[0], v) for v in views[1:])
    r_i = intrinsic_by_hand(agent, views[0][:, :3], reward)
    net = copy.deepcopy(agent)
    with torch.no_grad():
        states = [net.encoder(v[:, :3]) for v in views[:m]]
        next_states = [net.encoder(v[:, 1:]) for v in views[:k]]
        r_hat = np64(net.reward_model(states[0].state, action))
        predicted = np64(net.transition(states[0].motion, action))
    target_q, actor = Calls(agent.critic_target), Calls(agent.actor)
    torch.manual_seed(11)
    metrics = agent.update_window(window, action, reward, 1 - TERMINATED, STEP)

    [((actor_in,), (next_action, next_log_prob))] = actor.with_grad(False)
    [((target_in, _), _)] = target_q.with_grad(False)
    expected_in = torch.cat([s.state for s in next_states])
    torch.testing.assert_close(actor_in, expected_in)  # view j's action from view j's state
    torch.testing.assert_close(target_in, expected_in)
    batch = len(action)
    values, smaller = [], []
    with torch.no_grad():
        for j, state in enumerate(next_states):
            rows = slice(j * batch, (j + 1) * batch)
            q_bar = net.critic_target(state.state, next_action[rows].float())
            q1_bar, q2_bar = (np64(q)[:, 0] for q in q_bar)
            smaller.append(q1_bar < q2_bar)
            values.append(np.minimum(q1_bar, q2_bar) - ALPHA * np64(next_log_prob[rows])[:, 0])
        y = np64(reward) + r_i + GAMMA * (1 - np64(TERMINATED)) * np.mean(values, axis=0)
        per_view, q_mean = [], []
        for state in states:
            q1, q2 = (np64(q)[:, 0] for q in net.critic(state.state, action))
            per_view.append(((q1 - y) ** 2).mean() + ((q2 - y) ** 2).mean())
            q_mean.append(q1.mean())
        next_motion = np64(next_states[0].motion)
    assert np.any(smaller) and not np.all(smaller)  # max for min would change V
    if k > 1:
        assert not np.allclose(values[0], values[1])  # the mean is not view 0's value
    if m > 1:
        assert not np.isclose(per_view[0], per_view[1])
    assert float(metrics["critic_loss"]) == pytest.approx(np.mean(per_view), rel=1e-5)
    assert float(metrics["q"]) == pytest.approx(np.mean(q_mean), rel=1e-5)
    assert float(metrics["reward_loss"]) == pytest.approx(((r_hat - np64(reward)) ** 2).mean())
    transition = ((predicted - next_motion) ** 2).sum(-1).mean()
    assert float(metrics["transition_loss"]) == pytest.approx(transition, rel=1e-5)


@pytest.mark.parametrize("views", [1, 2])
def test_target_next_state_encoder_feeds_the_target_q_heads_and_the_online_one_the_actor(views):
    """next_state_encoder="target" (DrQ): Qbar reads the EMA encoder's o_{t+1} (every target
    view), the next action is still drawn from the online encoder's state; perturbing the EMA
    encoder changes the TD target, perturbing it under "online" does not."""
    shift = {"augmentation": "shift"} if views > 1 else {}
    overrides = dict(next_state_encoder="target", target_augmentations=views, **shift)
    agent = agent_for_targets(**overrides)
    perturb(agent.encoder_target, seed=2)  # no longer a copy of the online encoder
    window, action, reward, _ = random_window()
    torch.manual_seed(11)
    shifted = (
        [random_shift(window, agent.shift_pad) for _ in range(views)] if views > 1 else [window]
    )
    with torch.no_grad():
        online = torch.cat([agent.encoder(v[:, 1:]).state for v in shifted])
        target = torch.cat([agent.encoder_target(v[:, 1:]).state for v in shifted])
    assert not torch.allclose(online, target)
    target_q, actor = Calls(agent.critic_target), Calls(agent.actor)
    torch.manual_seed(11)
    agent.update_window(window, action, reward, 1 - TERMINATED, STEP)
    [((actor_in,), _)] = actor.with_grad(False)
    [((target_in, _), _)] = target_q.with_grad(False)
    torch.testing.assert_close(actor_in, online)
    torch.testing.assert_close(target_in, target)


@pytest.mark.parametrize(("encoder", "changes"), [("target", True), ("online", False)])
def test_perturbing_the_ema_encoder_moves_the_td_target_only_when_it_reads_the_next_state(
    encoder, changes
):
    agent = agent_for_targets(next_state_encoder=encoder)
    batch = (*random_window()[:3], 1 - TERMINATED, STEP)

    def target_q(candidate: SimounAgent) -> torch.Tensor:
        recorded = Calls(candidate.critic_target)
        torch.manual_seed(3)
        candidate.update_window(*batch)
        return torch.cat(recorded.calls[0][2], dim=1)

    other = copy.deepcopy(agent)
    perturb(other.encoder_target, seed=1)
    assert (not torch.allclose(target_q(copy.deepcopy(agent)), target_q(other))) == changes


def schedule_by_hand(step: int) -> float:
    """DrQ-v2's linear(0.2, 0.05, 1000) as written in its recipe."""
    mix = min(step / 1000, 1.0)
    return (1 - mix) * 0.2 + mix * 0.05


def deterministic_agent() -> SimounAgent:
    torch.manual_seed(0)
    config = small_config(
        actor="deterministic",
        discount=GAMMA,
        curiosity=False,
        exploration_std_start=0.2,
        exploration_std_end=0.05,
        exploration_steps=1000,
        noise_clip=10.0,  # the clip never binds: the noise is the schedule's std times N(0, 1)
    )
    return SimounAgent(FRAME, ACTIONS, config, "cpu")


def noise_over_std(agent: SimounAgent, step: int) -> tuple[np.ndarray, np.ndarray, dict]:
    """One update at ``step``: (target smoothing noise, policy-loss noise) / std(step), on the
    entries the [-1, 1] clamp left alone, and the metrics."""
    actor, target_q, critic = Calls(agent.actor), Calls(agent.critic_target), Calls(agent.critic)
    torch.manual_seed(4)
    metrics = agent.update_window(*random_window()[:3], 1 - TERMINATED, step)
    [(_, (mu_next,))] = actor.with_grad(False)
    [((_, smoothed_next), _)] = target_q.with_grad(False)
    [(_, (mu,))] = actor.with_grad(True)
    (_, smoothed), _ = critic.with_grad(True)[1]  # [0]: L_Q at the batch's actions
    std = schedule_by_hand(step)
    noises = []
    for a, m in ((smoothed_next, mu_next), (smoothed, mu)):
        noise = (np64(a) - np64(m)) / std
        noises.append(np.where(np.abs(np64(a)) < 1, noise, np.nan))
    return noises[0], noises[1], metrics


def test_deterministic_actor_noise_follows_the_exploration_schedule_of_the_update_step():
    """The same N(0, 1) draws at steps 0, 400 and 2000 give noise std(step) * z in both the TD
    target's smoothed action and the policy loss's, with DrQ-v2's linear schedule."""
    agent = deterministic_agent()
    runs = {step: noise_over_std(copy.deepcopy(agent), step) for step in (0, 400, 2000)}
    for step, (_, _, metrics) in runs.items():
        assert float(metrics["exploration_std"]) == pytest.approx(schedule_by_hand(step))
        assert "alpha" not in metrics and "entropy" not in metrics
    for part in (0, 1):
        z = [runs[step][part] for step in runs]
        both = np.isfinite(z[0]) & np.isfinite(z[1]) & np.isfinite(z[2])
        assert both.sum() > 8 and np.abs(z[0][both]).max() > 0.5
        np.testing.assert_allclose(z[1][both], z[0][both], rtol=1e-4, atol=1e-5)
        np.testing.assert_allclose(z[2][both], z[0][both], rtol=1e-4, atol=1e-5)


def test_act_explores_with_the_std_of_its_step_defaulting_to_the_latest_update():
    agent = deterministic_agent()
    obs = random_window()[0][0, :3].numpy()
    with torch.no_grad():
        mu = np64(agent.actor(agent.encoder(torch.from_numpy(obs)[None]).state))[0]
    np.testing.assert_allclose(agent.act(obs, deterministic=True), mu, rtol=1e-6)

    def noise(**kwargs) -> np.ndarray:
        torch.manual_seed(9)
        return agent.act(obs, **kwargs) - mu

    z = noise(step=0) / schedule_by_hand(0)
    np.testing.assert_allclose(noise(), z * schedule_by_hand(0), rtol=1e-5, atol=1e-7)  # step 0
    assert np.abs(z).max() > 0.1 and np.all(np.abs(mu + z * 0.2) < 1)
    np.testing.assert_allclose(noise(step=600), z * schedule_by_hand(600), rtol=1e-4, atol=1e-6)
    trained = copy.deepcopy(agent)
    trained.update_window(*random_window()[:3], 1 - TERMINATED, 600)
    assert trained.env_step == 600
    agent.env_step = 600  # as the update leaves it, with the weights unchanged
    np.testing.assert_allclose(noise(), z * schedule_by_hand(600), rtol=1e-4, atol=1e-6)
    state = agent.encoder(torch.from_numpy(obs)[None]).state.detach()
    for step, std in ((None, schedule_by_hand(600)), (0, 0.2)):  # the actor step's default too
        metrics = copy.deepcopy(agent).update_actor(state, step)
        assert float(metrics["exploration_std"]) == pytest.approx(std)


def test_gaussian_act_samples_unless_deterministic_and_returns_the_tanh_mean_when_it_is():
    agent = agent_for_targets()
    obs = random_window()[0][0, :3].numpy()
    with torch.no_grad():
        mean = np64(agent.actor(agent.encoder(torch.from_numpy(obs)[None]).state, True)[0])[0]
    torch.manual_seed(1)
    first = agent.act(obs)
    second = agent.act(obs)
    assert not np.allclose(first, second)  # exploration by default
    np.testing.assert_allclose(agent.act(obs, deterministic=True), mean, rtol=1e-6)
    np.testing.assert_allclose(agent.act(obs, True), agent.act(obs, True), rtol=0)
    assert first.dtype == np.float32 and not isinstance(first, torch.Tensor)


def test_running_maxima_start_at_their_own_initial_values_below_which_eq13_is_scaled():
    """Rewards and distances below both initial maxima leave them there, so Eq. 13 reads
    r_e_max_init and r_i_max_init, each its own value."""
    torch.manual_seed(0)
    config = small_config(init_temperature=ALPHA, discount=GAMMA, r_e_max_init=50.0)
    config.curiosity_scale, config.curiosity_decay = 0.3, 1e-4  # not the defaults
    config.r_i_max_init = 1e4  # above every distance of the batch, and not 50
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    window, action, reward, discount = random_window()
    assert float(reward.abs().max()) < 50
    r_i = intrinsic_by_hand(agent, window[:, :3], reward)
    fresh = SimounAgent(FRAME, ACTIONS, small_config(r_e_max_init=50.0, r_i_max_init=7.0))
    assert fresh.running_max.state_dict() == {"r_e_max": 50.0, "r_i_max": 7.0}
    metrics = agent.update_window(window, action, reward, discount, STEP)
    assert agent.running_max.state_dict() == {"r_e_max": 50.0, "r_i_max": 1e4}
    assert float(metrics["intrinsic_reward"]) == pytest.approx(r_i.mean(), rel=1e-5)


@pytest.mark.parametrize("actor", ["gaussian", "deterministic"])
def test_checkpoint_round_trip_keeps_every_counter_and_resumes_bit_exact(actor):
    torch.manual_seed(0)
    config = small_config(actor=actor, curiosity=actor == "gaussian")
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    for update in range(3):
        agent.update_window(*random_window(seed=update), step=1234 + update)
    buffer = io.BytesIO()
    torch.save(agent.state_dict(), buffer)
    buffer.seek(0)
    resumed = SimounAgent(FRAME, ACTIONS, config, "cpu")
    state = torch.load(buffer, weights_only=False)
    networks = {"encoder", "encoder_target", "critic", "critic_target", "actor", "reward_model"}
    networks |= {"similarity", "transition", "critic_optimizer", "actor_optimizer"}
    alpha = {"log_alpha", "alpha_optimizer"} if actor == "gaussian" else set()
    assert set(state) == networks | alpha | {"running_max", "num_updates", "env_step", "config"}
    assert state["config"] == asdict(config)  # what a resume compares its config against
    resumed.load_state_dict(state)
    assert (resumed.env_step, resumed.num_updates) == (1236, 3)
    assert resumed.running_max.state_dict() == agent.running_max.state_dict()
    assert (resumed.log_alpha is None) == (actor == "deterministic")
    if resumed.log_alpha is not None:
        assert torch.equal(resumed.log_alpha, agent.log_alpha)
    obs = random_window()[0][0, :3].numpy()
    for candidate in (agent, resumed):  # act's default step is the restored env_step
        torch.manual_seed(8)
        candidate.action = candidate.act(obs)
        torch.manual_seed(8)
        candidate.metrics = candidate.update_window(*random_window(seed=7), step=1300)
    np.testing.assert_array_equal(agent.action, resumed.action)
    for name, value in agent.metrics.items():
        assert torch.equal(value, resumed.metrics[name]), name
    for name, net in agent.modules().items():
        for a, b in zip(net.parameters(), resumed.modules()[name].parameters(), strict=True):
            assert torch.equal(a, b), name


def test_checkpoint_without_env_step_loads_as_step_0_and_one_without_a_network_is_refused():
    agent = SimounAgent(FRAME, ACTIONS, small_config(), "cpu")
    agent.update_window(*random_window(), step=77)
    state = agent.state_dict()
    assert (state["env_step"], state["num_updates"]) == (77, 1)
    old = {key: value for key, value in state.items() if key != "env_step"}
    resumed = SimounAgent(FRAME, ACTIONS, small_config(), "cpu")
    resumed.env_step = 5
    resumed.load_state_dict(old)
    assert (resumed.env_step, resumed.num_updates) == (0, 1)
    with pytest.raises(ValueError, match="does not fit this agent: it lacks critic_target"):
        resumed.load_state_dict({k: v for k, v in state.items() if k != "critic_target"})


def test_bad_observations_are_refused_with_the_problem_and_the_fix():
    agent = SimounAgent(FRAME, ACTIONS, small_config(), "cpu")
    frames = np.zeros((3, *FRAME), np.uint8)
    with pytest.raises(ValueError) as whole:
        agent.act({"frames": frames, "motion": frames})
    assert "SimounObservation's whole dict (keys ['frames', 'motion'])" in str(whole.value)
    assert "agent.act(obs['frames'])" in str(whole.value)
    cases = [
        (frames.astype(np.float32), False, "(3, 3, 32, 32)", "float32 (3, 3, 32, 32)"),
        (frames[None], False, "(3, 3, 32, 32)", "uint8 (1, 3, 3, 32, 32)"),
        (frames[1:], False, "(3, 3, 32, 32)", "uint8 (2, 3, 32, 32)"),
        (frames, True, "(B, 3, 3, 32, 32)", "uint8 (3, 3, 32, 32)"),
        (torch.zeros(2, 3, *FRAME), True, "(B, 3, 3, 32, 32)", "torch.float32 (2, 3, 3, 32, 32)"),
    ]
    for bad, batched, want, got in cases:
        call = agent.encoder_features if batched else agent.act
        with pytest.raises(ValueError) as error:
            call(bad)
        message = str(error.value)
        assert f"expected uint8 frames of shape {want} (frames t-2, t-1, t, channel-first)" in (
            message
        )
        assert f"got {got}; pass the 'frames' entry of SimounObservation unchanged" in message
    features = agent.encoder_features(torch.zeros(2, 3, *FRAME, dtype=torch.uint8))
    assert [tuple(f.shape) for f in features] == [(2, 16), (2, 3, 16)]


def test_contrastive_shift_view_is_an_independent_shift_of_the_unshifted_frames():
    """contrastive_view="shift" (CURL): the key is the EMA encoder on an independently shifted
    copy of frames t-2 .. t; L_con is Eq. 3's cross-entropy with the diagonal as positives."""
    agent = agent_for_targets(contrastive_view="shift")
    window, action, reward, discount = random_window()
    torch.manual_seed(5)  # with augmentation "none" the key's shift is the first random draw
    key_view = random_shift(window[:, :3], agent.shift_pad)
    with torch.no_grad():
        anchor = agent.encoder(window[:, :3]).anchor
        key = agent.encoder_target.encode_key(agent.encoder.key_frames(key_view))
        logits = np64(anchor @ agent.similarity.weight @ key.T)
    logits -= logits.max(1, keepdims=True)
    expected = -np.mean(np.diag(logits) - np.log(np.exp(logits).sum(1)))
    torch.manual_seed(5)
    metrics = agent.update_window(window, action, reward, discount, STEP)
    assert float(metrics["contrastive_loss"]) == pytest.approx(expected, rel=1e-5)


def test_random_conv_kernel_of_the_config_makes_the_contrastive_key():
    losses = []
    for kernel in (3, 5):
        agent = agent_for_targets(random_conv_kernel=kernel)
        torch.manual_seed(5)
        losses.append(float(agent.update_window(*random_window(), step=STEP)["contrastive_loss"]))
    assert losses[0] != pytest.approx(losses[1], rel=1e-4)


@pytest.mark.parametrize(("weight", "head"), [("reward", "reward_model"),
    ("transition", "transition"), ("contrastive", "similarity")])  # fmt: skip
def test_each_auxiliary_weight_scales_its_heads_gradient(weight, head):
    """Eq. 14: the head of one auxiliary term gets weight * its loss's gradient (nothing else
    reads it), with the config's weight passed through."""
    grads = []
    for value in (1.0, 0.25):
        agent = agent_for_targets(curiosity=False, **{f"{weight}_weight": value})
        agent.num_updates = 1  # no actor step
        torch.manual_seed(5)
        agent.update_window(*random_window(), step=STEP)
        grads.append([p.grad for p in getattr(agent, head).parameters()])
    for full, quarter in zip(*grads, strict=True):
        assert full.abs().max() > 0
        torch.testing.assert_close(quarter, 0.25 * full, rtol=1e-5, atol=1e-9)


def test_zero_weight_terms_build_no_head_and_report_no_loss():
    agent = agent_for_targets(transition_weight=0.0, contrastive_weight=0.0)
    assert agent.transition is None and agent.similarity is None
    metrics = agent.update_window(*random_window(), step=STEP)
    assert "transition_loss" not in metrics and "contrastive_loss" not in metrics
    assert "reward_loss" in metrics and set(agent.modules()) >= {"reward_model"}


def test_construction_reads_the_optimiser_settings_shift_pad_and_shapes_from_the_config():
    config = small_config(lr=3e-4, alpha_lr=2e-4, alpha_beta=0.6, shift_pad=3, augmentation="shift")
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    assert [g["lr"] for g in agent.critic_optimizer.param_groups] == [3e-4]
    assert [g["lr"] for g in agent.actor_optimizer.param_groups] == [3e-4]
    [alpha_group] = agent.alpha_optimizer.param_groups
    assert (alpha_group["lr"], alpha_group["betas"]) == (2e-4, (0.6, 0.999))
    assert (agent.shift_pad, agent.action_dim, agent.env_step, agent.num_updates) == (3, 2, 0, 0)
    wide = SimounAgent((3, 32, 64), ACTIONS, small_config(), "cpu")
    assert wide.shift_pad == 2  # 4 px per 84 px of the height, 32 px
