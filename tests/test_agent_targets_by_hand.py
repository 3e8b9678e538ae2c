"""Which network each term of the TD target reads, written out in numpy layer by layer: the
next state through the EMA target encoder (CURL's, RAD's and SAC-AE's update_critic), and
DrQ-v2's own actor and critic trunks Linear -> LayerNorm -> Tanh, the critic's inside its EMA
target (drqv2.py's Actor, Critic and DrQV2Agent.update).

Every target network is first moved away from its online twin, so a term that read the wrong
one would change a value checked here; each test also shows that the other reading gives a
different number, so it can fail.
"""

import copy

import numpy as np
import pytest
import torch
from test_agent_maths import GAMMA, STEP, TERMINATED, np64, perturb
from test_agent_update import ACTIONS, FRAME, random_window, small_config
from test_losses_by_hand import mlp_by_hand

from simoun_agent import SimounAgent
from simoun_agent.config.recipes import NO_AUXILIARY

ALPHA = 0.5


def trunk_by_hand(trunk: torch.nn.Sequential, x: np.ndarray) -> np.ndarray:
    """Linear -> LayerNorm -> Tanh in numpy from the module's weights."""
    linear, norm, squash = trunk
    assert isinstance(norm, torch.nn.LayerNorm) and isinstance(squash, torch.nn.Tanh)
    h = x @ np64(linear.weight).T + np64(linear.bias)
    centred = h - h.mean(-1, keepdims=True)
    scaled = centred / np.sqrt((centred**2).mean(-1, keepdims=True) + norm.eps)
    return np.tanh(scaled * np64(norm.weight) + np64(norm.bias))


def twin_q_by_hand(critic, trunk_out: np.ndarray, action: np.ndarray) -> np.ndarray:
    """min(Q1, Q2) of ``critic``'s heads on [trunk output, action]."""
    x = np.concatenate([trunk_out, action], 1)
    return np.minimum(mlp_by_hand(critic.q1, x), mlp_by_hand(critic.q2, x))[:, 0]


def gaussian_log_prob_by_hand(actor, state: np.ndarray, action: np.ndarray) -> np.ndarray:
    """log pi(a|s) of the tanh-Gaussian actor at its sampled ``action``: the noise is recovered
    as (atanh(a) - mu) / sigma, so mu and sigma read from another state give another value."""
    out = mlp_by_hand(actor.trunk, state)
    mu, log_std = np.split(out, 2, axis=1)
    low, high = actor.log_std_min, actor.log_std_max
    log_std = low + 0.5 * (high - low) * (np.tanh(log_std) + 1)
    noise = (np.arctanh(action) - mu) / np.exp(log_std)
    gauss = -0.5 * noise**2 - log_std - 0.5 * np.log(2 * np.pi)
    return (gauss - np.log(1 - action**2 + 1e-6)).sum(1)


def test_the_td_target_reads_the_next_state_through_the_ema_encoder_and_the_ema_q_heads():
    """y = r + gamma (1 - d) (min(Qbar1, Qbar2)(fbar', a') - alpha log pi(a'|f')), where fbar' is
    the EMA encoder's o_{t+1} and Qbar the EMA Q heads, while a' ~ pi is drawn from the online
    encoder's f' (the default next_state_encoder "target"); L_Q is Eq. 9 on the online f_t."""
    torch.manual_seed(0)
    config = small_config(encoder="stacked", init_temperature=ALPHA, discount=GAMMA, **NO_AUXILIARY)
    assert config.next_state_encoder == "target"
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    perturb(agent.encoder_target, seed=1)
    perturb(agent.critic_target, seed=2)
    window, action, reward, _ = random_window()
    before = copy.deepcopy(agent)
    with torch.no_grad():
        state = np64(before.encoder(window[:, :3]).state)
        online_next = np64(before.encoder(window[:, 1:]).state)
        ema_next = np64(before.encoder_target(window[:, 1:]).state)
    recorded = []
    handle = agent.actor.register_forward_hook(
        lambda module, args, out: recorded.append(np64(out[0]))
    )
    metrics = agent.update_window(window, action, reward, 1 - TERMINATED, STEP)
    handle.remove()
    next_action = recorded[0]  # the TD target's draw comes before the actor step's

    log_pi = gaussian_log_prob_by_hand(before.actor, online_next, next_action)
    value = twin_q_by_hand(before.critic_target, ema_next, next_action) - ALPHA * log_pi
    y = np64(reward) + GAMMA * (1 - np64(TERMINATED)) * value
    x = np.concatenate([state, np64(action)], 1)
    q1, q2 = mlp_by_hand(before.critic.q1, x)[:, 0], mlp_by_hand(before.critic.q2, x)[:, 0]
    expected = ((q1 - y) ** 2).mean() + ((q2 - y) ** 2).mean()
    assert float(metrics["critic_loss"]) == pytest.approx(expected, rel=1e-5)

    # the other readings give other numbers: the online encoder or Q heads for Qbar, the EMA
    # encoder's state for the actor's draw
    online_value = twin_q_by_hand(before.critic_target, online_next, next_action) - ALPHA * log_pi
    online_heads = twin_q_by_hand(before.critic, ema_next, next_action) - ALPHA * log_pi
    ema_log_pi = gaussian_log_prob_by_hand(before.actor, ema_next, next_action)
    for other in (online_value, online_heads, value - ALPHA * (ema_log_pi - log_pi)):
        assert np.abs(other - value).max() > 1e-3


def test_the_online_next_state_encoder_gives_the_same_target_with_the_online_features():
    """next_state_encoder "online" (DrQ-v2): the EMA encoder, however far it is from the online
    one, leaves the TD target alone."""
    losses = []
    for seed in (1, 2):
        torch.manual_seed(0)
        config = small_config(encoder="stacked", next_state_encoder="online", **NO_AUXILIARY)
        agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
        perturb(agent.encoder_target, seed=seed)
        torch.manual_seed(3)
        losses.append(agent.update_window(*random_window()[:3], 1 - TERMINATED, STEP))
    assert float(losses[0]["critic_loss"]) == float(losses[1]["critic_loss"])


def drqv2_agent() -> SimounAgent:
    """drqv2's networks at a small size, noise std 0 so that a' = mu(s') exactly."""
    torch.manual_seed(0)
    config = small_config(
        encoder="stacked",
        **NO_AUXILIARY,
        separate_trunks=True,
        pixel_offset=0.5,
        actor="deterministic",
        exploration_std_start=0.0,
        exploration_std_end=0.0,
        next_state_encoder="online",
        discount=GAMMA,
        critic_tau=0.01,
        actor_update_every=1,
        target_update_every=1,
    )
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    perturb(agent.critic_target, seed=2)  # its trunk and heads no longer the online ones
    return agent


def test_drqv2_critic_target_reads_the_online_convs_through_its_own_ema_trunk():
    """drqv2: the state is the flat conv maps of x/255 - 0.5; y = r + gamma (1 - d) min(Qbar1,
    Qbar2)(trunkbar(s'), mu(s')) with trunkbar the critic target's trunk, mu = tanh(policy(
    trunk_pi(s'))) through the actor's own trunk; L_Q reads the online critic's trunk on s_t;
    the actor loss -min Q(trunk_Q(s), mu(s)) reads the critic just stepped; the EMA moves the
    critic's trunk with its heads at critic_tau."""
    agent = drqv2_agent()
    window, action, reward, _ = random_window()
    before = copy.deepcopy(agent)
    with torch.no_grad():
        maps = before.encoder.convs(window[:, :3].flatten(1, 2).float() / 255 - 0.5)
    state = np64(maps.permute(0, 2, 3, 1).flatten(1))
    with torch.no_grad():
        np.testing.assert_allclose(np64(before.encoder(window[:, :3]).state), state, rtol=1e-6)
        next_state = np64(before.encoder(window[:, 1:]).state)
    metrics = agent.update_window(window, action, reward, 1 - TERMINATED, STEP)

    def mu(actor, s: np.ndarray) -> np.ndarray:
        return np.tanh(mlp_by_hand(actor.trunk, trunk_by_hand(actor.state_trunk, s)))

    next_action = mu(before.actor, next_state)
    target_trunk = trunk_by_hand(before.critic_target.trunk, next_state)
    y = np64(reward) + GAMMA * (1 - np64(TERMINATED)) * twin_q_by_hand(
        before.critic_target, target_trunk, next_action
    )
    x = np.concatenate([trunk_by_hand(before.critic.trunk, state), np64(action)], 1)
    q1, q2 = mlp_by_hand(before.critic.q1, x)[:, 0], mlp_by_hand(before.critic.q2, x)[:, 0]
    expected = ((q1 - y) ** 2).mean() + ((q2 - y) ** 2).mean()
    assert float(metrics["critic_loss"]) == pytest.approx(expected, rel=1e-5)
    online_trunk = trunk_by_hand(before.critic.trunk, next_state)
    other = twin_q_by_hand(before.critic_target, online_trunk, next_action)
    assert (
        np.abs(other - twin_q_by_hand(before.critic_target, target_trunk, next_action)).max() > 1e-3
    )

    stepped = agent.critic  # the actor step holds the critic fixed
    own = twin_q_by_hand(stepped, trunk_by_hand(stepped.trunk, state), mu(before.actor, state))
    assert float(metrics["actor_loss"]) == pytest.approx(-own.mean(), rel=1e-5)

    tau = agent.config.critic_tau
    for name, target in agent.critic_target.named_parameters():
        old, new = (
            dict(before.critic_target.named_parameters())[name],
            dict(stepped.named_parameters())[name],
        )
        np.testing.assert_allclose(
            np64(target), np64(old) + tau * (np64(new) - np64(old)), rtol=1e-5, atol=1e-7
        )
    assert any(name.startswith("trunk.") for name, _ in agent.critic_target.named_parameters())


def test_drqv2_actor_trunk_is_in_the_actor_s_optimiser_alone_and_the_critic_s_in_l_q_s():
    """The actor's own trunk is stepped by the actor loss and the critic's by L_Q, never the
    other way round; one update moves both."""
    agent = drqv2_agent()
    critic = {id(p) for group in agent.critic_optimizer.param_groups for p in group["params"]}
    actor = {id(p) for group in agent.actor_optimizer.param_groups for p in group["params"]}
    actor_trunk = {id(p) for p in agent.actor.state_trunk.parameters()}
    critic_trunk = {id(p) for p in agent.critic.trunk.parameters()}
    assert actor_trunk and actor_trunk <= actor and not actor_trunk & critic
    assert critic_trunk and critic_trunk <= critic and not critic_trunk & actor
    before = copy.deepcopy(agent)
    agent.update_window(*random_window()[:3], 1 - TERMINATED, STEP)
    for old, new in ((before.actor.state_trunk, agent.actor.state_trunk),
                     (before.critic.trunk, agent.critic.trunk)):  # fmt: skip
        assert all(
            not torch.equal(a, b) for a, b in zip(old.parameters(), new.parameters(), strict=True)
        )
