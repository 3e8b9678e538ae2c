"""One SimounAgent update against the paper's equations, computed by hand from what the networks
returned: the TD target (Eq. 9, 10, 13) on mixed terminal / non-terminal rows with gamma < 1 and
alpha > 0, which network (online / target) each term reads, the n-step target on a hand-built
replay, the gradient each loss sends to each module (DESIGN.md "Losses"), the actor and
temperature step (Eq. 11) and the update schedule.

Forward hooks record each network's inputs and outputs during the update; the expected values
are then written out in numpy from those records, so a wrong sign, a max for a min, a dropped
discount, a swapped network or a missing detach in the agent changes a checked value.
"""

import copy

import numpy as np
import pytest
import torch
import torch.nn.functional as F
from test_agent_update import ACTIONS, FRAME, random_window, small_config

from simoun_agent import FrameReplay, SimounAgent
from simoun_wrappers.augment import random_conv

GAMMA, ALPHA = 0.9, 0.5
TERMINATED = torch.tensor([0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0])
STEP = 5000


class Calls:
    """Each forward call of a module: grad mode, detached inputs and outputs."""

    def __init__(self, module: torch.nn.Module) -> None:
        self.calls: list[tuple[bool, tuple, tuple]] = []
        self.handle = module.register_forward_hook(self._record)

    def _record(self, module, args, output) -> None:
        outputs = output if isinstance(output, tuple) else (output,)
        self.calls.append(
            (
                torch.is_grad_enabled(),
                tuple(a.detach().clone() for a in args if isinstance(a, torch.Tensor)),
                tuple(o.detach().clone().double() for o in outputs),
            )
        )

    def with_grad(self, enabled: bool) -> list[tuple[tuple, tuple]]:
        return [(args, out) for grad, args, out in self.calls if grad == enabled]


def np64(x: torch.Tensor) -> np.ndarray:
    return x.detach().double().numpy()


def intrinsic_by_hand(agent: SimounAgent, obs: torch.Tensor, reward: torch.Tensor) -> np.ndarray:
    """Eq. 13 from the online features of the triplet at t, the running maxima raised first."""
    f_m, f_a = (np64(x) for x in agent.encoder_features(obs))
    flow = np.abs(f_a[:, 1] - f_a[:, 0]) + np.abs(f_a[:, 2] - f_a[:, 1])
    distance = np.sqrt(((np.abs(f_m) - flow) ** 2).sum(-1))
    r_e_max = max(agent.config.r_e_max_init, np.abs(np64(reward)).max())
    r_i_max = max(agent.config.r_i_max_init, distance.max())
    c, lam = agent.config.curiosity_scale, agent.config.curiosity_decay
    return c * np.exp(-lam * STEP) * distance * r_e_max / r_i_max


def mixed_twins(agent: SimounAgent, next_obs: torch.Tensor) -> None:
    """Shift the target Q2 head so that it is the smaller twin in about half the rows."""
    with torch.no_grad():
        state = agent.encoder(next_obs).state
        q1, q2 = agent.critic_target(state, agent.actor(state, deterministic=True)[0])
        agent.critic_target.q2[-1].bias.add_((q1 - q2).median())


def agent_for_targets(**overrides) -> SimounAgent:
    torch.manual_seed(0)
    # the running maximum is read by curiosity alone (elsewhere refused)
    curiosity = {"r_i_max_init": 1e-3} if overrides.get("curiosity", True) else {}
    config = small_config(init_temperature=ALPHA, discount=GAMMA, **curiosity, **overrides)
    return SimounAgent(FRAME, ACTIONS, config, "cpu")


def test_critic_loss_is_eq9_with_the_eq10_target_on_terminal_and_non_terminal_rows():
    agent = agent_for_targets()
    window, action, reward, _ = random_window()
    obs, next_obs = window[:, :3], window[:, 1:]
    mixed_twins(agent, next_obs)
    r_i = intrinsic_by_hand(agent, obs, reward)
    with torch.no_grad():
        state, next_state = agent.encoder(obs).state, agent.encoder(next_obs).state
        ema_next_state = agent.encoder_target(next_obs).state
        r_hat = np64(agent.reward_model(state, action))
    target_q, actor, online_q = Calls(agent.critic_target), Calls(agent.actor), Calls(agent.critic)
    metrics = agent.update_window(window, action, reward, 1 - TERMINATED, STEP)

    assert len(target_q.calls) == 1
    [((target_in, target_action), (q1_bar, q2_bar))] = target_q.with_grad(False)
    [((actor_in,), (next_action, next_log_prob))] = actor.with_grad(False)
    (state_in, action_in), (q1, q2) = online_q.with_grad(True)[0]
    # the target Q heads read o_{t+1} through the EMA encoder, a fresh a_{t+1} ~ pi is drawn
    # from the online encoder's state (no gradient)
    torch.testing.assert_close(target_in, ema_next_state)
    torch.testing.assert_close(actor_in, next_state)
    torch.testing.assert_close(target_action.double(), next_action)
    torch.testing.assert_close(state_in, state)
    torch.testing.assert_close(action_in, action)
    # the twins differ and each is the smaller one somewhere: max for min would change V
    assert (q1_bar < q2_bar).any() and (q1_bar > q2_bar).any()
    assert np.any(np64(TERMINATED) == 0) and np.any(np64(TERMINATED) == 1)

    value = np.minimum(np64(q1_bar), np64(q2_bar))[:, 0] - ALPHA * np64(next_log_prob)[:, 0]
    y = np64(reward) + r_i + GAMMA * (1 - np64(TERMINATED)) * value
    expected = ((np64(q1)[:, 0] - y) ** 2).mean() + ((np64(q2)[:, 0] - y) ** 2).mean()
    assert float(metrics["critic_loss"]) == pytest.approx(expected, rel=1e-5)
    assert float(metrics["intrinsic_reward"]) == pytest.approx(r_i.mean(), rel=1e-5)
    assert float(metrics["q"]) == pytest.approx(np64(q1).mean(), rel=1e-5)
    # L_re fits the extrinsic reward alone, never r_e + r_i (Eq. 7)
    assert float(metrics["reward_loss"]) == pytest.approx(((r_hat - np64(reward)) ** 2).mean())


def perturb(module: torch.nn.Module, seed: int) -> None:
    gen = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for p in module.parameters():
            p.add_(torch.randn(p.shape, generator=gen) * 0.1)


@pytest.mark.parametrize(
    ("network", "changes"),
    [
        ("critic_target", {"critic_loss", "target_q"}),
        ("encoder_target", {"critic_loss", "target_q", "contrastive_loss"}),
        ("critic", {"critic_loss", "q"}),
        ("actor", {"critic_loss", "target_q"}),
        (
            "encoder",
            {"critic_loss", "q", "target_q", "contrastive_loss", "reward_loss", "transition_loss"},
        ),
        ("reward_model", {"reward_loss"}),
        ("transition", {"transition_loss"}),
    ],
)
def test_each_term_reads_the_online_or_target_network_it_should(network, changes):
    """Perturb one network: exactly the terms that read it change. The TD target reads the
    target Q heads (never the online ones) on the momentum encoder's next state, and the actor;
    the contrastive keys read the momentum encoder too; L_re and L_tran read their own heads
    only."""
    agent = agent_for_targets()
    window, action, reward, _ = random_window()
    batch = (window, action, reward, 1 - TERMINATED, STEP)

    def one_update(candidate: SimounAgent) -> dict[str, torch.Tensor]:
        recorded = Calls(candidate.critic_target)
        torch.manual_seed(3)
        metrics = candidate.update_window(*batch)
        metrics["target_q"] = torch.cat(recorded.calls[0][2], dim=1)
        return metrics

    before = one_update(copy.deepcopy(agent))
    other = copy.deepcopy(agent)
    perturb(getattr(other, network), seed=1)
    after = one_update(other)
    keys = {"critic_loss", "q", "target_q", "contrastive_loss", "reward_loss", "transition_loss"}
    changed = {key for key in keys if not torch.allclose(before[key], after[key], rtol=1e-6)}
    assert changed == changes


def intrinsic_return_by_hand(agent: SimounAgent, batch: dict) -> np.ndarray:
    """Eq. 13 at each step j < m of the return, on the online features of the triplet ending at
    t+j, discounted by gamma^j and summed; the running maxima raised first with every distance
    of the batch (0 past the episode's end) and the one-step extrinsic rewards."""
    window, mask = torch.from_numpy(batch["n_step_window"]), batch["return_mask"].T
    distances = []
    for j in range(len(mask)):
        f_m, f_a = (np64(x) for x in agent.encoder_features(window[:, j : j + 3]))
        flow = np.abs(f_a[:, 1] - f_a[:, 0]) + np.abs(f_a[:, 2] - f_a[:, 1])
        distances.append(np.sqrt(((np.abs(f_m) - flow) ** 2).sum(-1)) * mask[j])
    distance = np.stack(distances)
    r_e_max = max(agent.config.r_e_max_init, np.abs(batch["reward"]).max())
    r_i_max = max(agent.config.r_i_max_init, distance.max())
    c, lam = agent.config.curiosity_scale, agent.config.curiosity_decay
    r_i = c * np.exp(-lam * STEP) * distance * r_e_max / r_i_max
    return (GAMMA ** np.arange(len(mask))[:, None] * mask * r_i).sum(0)


@pytest.mark.parametrize(
    ("n_step", "curiosity", "transition_weight"),
    [(3, False, 1.0), (3, True, 1.0), (2, True, 1.0), (4, True, 1.0), (3, False, 0.0)],
)
def test_n_step_target_bootstraps_from_the_frame_reached_with_the_summed_return(
    n_step, curiosity, transition_weight
):
    """The cpu preset's 3-step returns on a hand-built replay: the TD target is
    R + sum_j gamma^j r^i(s_{t+j}) + gamma * discount * V(bootstrap_obs), with FrameReplay.sample's
    R, mask and discount (checked by hand in test_n_step_return_discount_and_bootstrap_by_hand)
    and V read on the frame reached. Without L_tran and curiosity (as DrQ's n-step recipe) the
    update encodes no t+1 states at all, a path of its own."""
    agent = agent_for_targets(
        n_step=n_step, curiosity=curiosity, transition_weight=transition_weight
    )
    replay = hand_built_replay(FRAME, random_frames=True)
    batch = copy.deepcopy(replay).sample(agent.config.batch_size, n_step, GAMMA)  # the same draw
    assert (batch["return"] != batch["reward"]).any()
    assert (batch["discount"] == 0).any() and (batch["discount"] > 0).any()
    assert (batch["return_mask"].sum(1) > 1).any()
    assert n_step == 2 or (batch["return_mask"].sum(1) < 3).any()  # n = 2: the r_i step boundary
    intrinsic = intrinsic_return_by_hand(agent, batch) if curiosity else 0.0
    with torch.no_grad():
        bootstrap_state = agent.encoder(torch.from_numpy(batch["bootstrap_obs"])).state
    target_q, actor, online_q = Calls(agent.critic_target), Calls(agent.actor), Calls(agent.critic)
    metrics = agent.update(replay, STEP)

    assert len(target_q.calls) == 1
    [((target_in, _), (q1_bar, q2_bar))] = target_q.with_grad(False)
    [(_, (_, next_log_prob))] = actor.with_grad(False)
    _, (q1, q2) = online_q.with_grad(True)[0]
    torch.testing.assert_close(target_in, bootstrap_state)
    value = np.minimum(np64(q1_bar), np64(q2_bar))[:, 0] - ALPHA * np64(next_log_prob)[:, 0]
    y = batch["return"] + intrinsic + GAMMA * batch["discount"] * value
    expected = ((np64(q1)[:, 0] - y) ** 2).mean() + ((np64(q2)[:, 0] - y) ** 2).mean()
    assert float(metrics["critic_loss"]) == pytest.approx(expected, rel=1e-5)
    if curiosity:
        assert float(metrics["intrinsic_reward"]) == pytest.approx(intrinsic.mean(), rel=1e-5)


# -- the n-step return on a replay built by hand ----------------------------------------------

EPISODES = {"a": ([1.0, 2.0, 3.0, 4.0], "truncated"), "b": ([10.0, 20.0, 30.0], "terminated")}
EPISODES["c"] = ([100.0, 200.0], "open")
FRAME_ID = {"a": 10, "b": 20, "c": 30}
"""Frame k of episode e is filled with FRAME_ID[e] + k (k = 0 is the reset frame)."""


def hand_built_replay(shape=(1, 2, 2), random_frames: bool = False) -> FrameReplay:
    rng = np.random.default_rng(0)
    replay = FrameReplay(50, shape, ACTIONS, seed=0)

    def frame(value: int) -> np.ndarray:
        image = rng.integers(0, 256, shape, dtype=np.uint8) if random_frames else None
        image = np.full(shape, value, np.uint8) if image is None else image
        image.flat[0] = value  # the id survives in the first pixel
        return image

    for name, (rewards, end) in EPISODES.items():
        replay.start_episode(frame(FRAME_ID[name]))
        for k, reward in enumerate(rewards, start=1):
            last = k == len(rewards)
            replay.add(
                np.full(ACTIONS, k / 10), reward, frame(FRAME_ID[name] + k),
                last and end == "terminated", last and end == "truncated",
            )  # fmt: skip
    return replay


# (episode, t) -> (n-step return, discount, frames of bootstrap_obs), n = 3, gamma = 0.5, worked
# out on paper: the sum stops after a truncated step (and bootstraps), at a terminated one (and
# does not), and at the newest frame stored
N_STEP_BY_HAND = {
    ("a", 0): (1 + 0.5 * 2 + 0.25 * 3, 0.25, [11, 12, 13]),
    ("a", 1): (2 + 0.5 * 3 + 0.25 * 4, 0.25, [12, 13, 14]),
    ("a", 2): (3 + 0.5 * 4, 0.5, [12, 13, 14]),
    ("a", 3): (4.0, 1.0, [12, 13, 14]),
    ("b", 0): (10 + 0.5 * 20 + 0.25 * 30, 0.0, [21, 22, 23]),
    ("b", 1): (20 + 0.5 * 30, 0.0, [21, 22, 23]),
    ("b", 2): (30.0, 0.0, [21, 22, 23]),
    ("c", 0): (100 + 0.5 * 200, 0.5, [30, 31, 32]),
    ("c", 1): (200.0, 1.0, [30, 31, 32]),
}


STEPS_SUMMED = {
    ("a", 0): 3, ("a", 1): 3, ("a", 2): 2, ("a", 3): 1, ("b", 0): 3, ("b", 1): 2, ("b", 2): 1,
    ("c", 0): 2, ("c", 1): 1,
}  # fmt: skip
"""m, the rewards each n-step return of N_STEP_BY_HAND sums."""


def test_n_step_return_discount_and_bootstrap_by_hand():
    replay = hand_built_replay()
    assert len(replay) == len(N_STEP_BY_HAND)
    seen = set()
    for _ in range(20):
        batch = replay.sample(len(replay), n_step=3, discount=0.5)
        for i, window in enumerate(batch["window"][:, :, 0, 0, 0].tolist()):
            t_frame = window[-2]
            key = ("abc"[t_frame // 10 - 1], t_frame % 10)
            n_return, discount, bootstrap = N_STEP_BY_HAND[key]
            assert batch["return"][i] == pytest.approx(n_return)
            assert batch["discount"][i] == pytest.approx(discount)
            assert batch["bootstrap_obs"][i, :, 0, 0, 0].tolist() == bootstrap
            # the steps summed, and frames t-2 .. t+3 held at the frame reached (per-step r_i)
            m = STEPS_SUMMED[key]
            assert batch["return_mask"][i].tolist() == [1.0] * m + [0.0] * (3 - m)
            ahead = batch["n_step_window"][i, :, 0, 0, 0].tolist()
            assert ahead == window[:-1] + [t_frame + min(j, m) for j in (1, 2, 3)]
            # the one-step parts stay one-step (L_re, L_tran); reset padding before frame 0
            assert batch["reward"][i] == EPISODES[key[0]][0][key[1]]
            base = FRAME_ID[key[0]]
            assert window == [base + max(key[1] - 2 + j, 0) for j in range(3)] + [t_frame + 1]
            seen.add(key)
    assert seen == set(N_STEP_BY_HAND)


# -- gradients: which module each loss trains ----------------------------------------------------

GROUPS = (
    "motion path", "motion head", "appearance path", "appearance head", "reduce motion",
    "reduce appearance", "beta motion", "beta appearance", "critic trunk", "critic output",
    "transition", "reward model", "similarity", "actor", "log_alpha",
)  # fmt: skip


def parameter_groups(agent: SimounAgent) -> dict[str, list[torch.Tensor]]:
    enc, sim = agent.encoder, agent.encoder.interaction
    outputs = [*agent.critic.q1[-1].parameters(), *agent.critic.q2[-1].parameters()]
    optional = {"transition": agent.transition, "reward model": agent.reward_model}
    optional["similarity"] = agent.similarity
    groups = {
        "motion path": list(enc.motion.parameters()),
        "motion head": list(enc.head_motion.parameters()),
        "appearance path": list(enc.appearance.parameters()),
        "appearance head": list(enc.head_appearance.parameters()),
        "reduce motion": list(sim.reduce_motion.parameters()),
        "reduce appearance": list(sim.reduce_appearance.parameters()),
        "beta motion": [sim.beta_motion],
        "beta appearance": [sim.beta_appearance],
        "critic trunk": [p for p in agent.critic.parameters() if all(p is not o for o in outputs)],
        "critic output": outputs,
        "actor": list(agent.actor.parameters()),
        "log_alpha": [agent.log_alpha],
    }
    groups.update({k: list(m.parameters()) if m else [] for k, m in optional.items()})
    return groups


def trained_groups(agent: SimounAgent) -> set[str]:
    """Groups with a nonzero gradient in every parameter; a group with a zero or missing gradient
    in any parameter must have it in all of them (nothing in between)."""
    nonzero = set()
    for name, group in parameter_groups(agent).items():
        has = [p.grad is not None and bool(p.grad.any()) for p in group]
        assert all(has) or not any(has), (name, has)
        if group and all(has):
            nonzero.add(name)
    for target in (agent.encoder_target, agent.critic_target):
        assert all(p.grad is None for p in target.parameters())
    return nonzero


def agent_for_gradients(only: str, **overrides) -> SimounAgent:
    """An agent whose representation loss is L_Q plus at most one auxiliary term; for an
    auxiliary term the Q heads' output layers are zero, so L_Q sends nothing into the encoder
    (only those output layers learn) and what reaches it is the auxiliary term's alone."""
    weights = {"transition_weight": 0.0, "contrastive_weight": 0.0, "reward_weight": 0.0}
    if only != "critic":
        weights[f"{only}_weight"] = 1.0
    torch.manual_seed(0)
    config = small_config(curiosity=False, **weights, **overrides)
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    with torch.no_grad():
        interaction = agent.encoder.interaction
        interaction.beta_motion.fill_(0.5)  # beta = 0 closes the module: open it
        interaction.beta_appearance.fill_(0.5)
        if only != "critic":
            for head in (agent.critic.q1[-1], agent.critic.q2[-1]):
                head.weight.zero_()
    agent.num_updates = 1  # an update without the actor step: gradients of Eq. 14's loss only
    return agent


ENCODER_ALL = {
    "motion path", "motion head", "appearance path", "appearance head", "reduce motion",
    "reduce appearance", "beta motion", "beta appearance",
}  # fmt: skip


@pytest.mark.parametrize(
    ("only", "expected"),
    [
        # L_Q trains the whole encoder (both paths, the interactive module) and both Q heads
        ("critic", ENCODER_ALL | {"critic trunk", "critic output"}),
        # L_tran reads f^m_t: the motion path, its head, G, and the appearance path and reducing
        # convs only through the attention X of the interactive module (f^a's head is unused)
        (
            "transition",
            {"motion path", "motion head", "appearance path", "reduce motion"}
            | {"reduce appearance", "beta motion", "transition", "critic output"},
        ),
        # L_con's anchor is f^a_t before the interactive module: appearance path, head and W
        ("contrastive", {"appearance path", "appearance head", "similarity", "critic output"}),
        # L_re reads the whole state f_t = [f^m_t, f^a_t] and trains R
        ("reward", ENCODER_ALL | {"reward model", "critic output"}),
    ],
)
def test_each_loss_sends_gradient_exactly_to_the_modules_it_trains(only, expected):
    agent = agent_for_gradients(only)
    agent.update_window(*random_window(), step=0)
    assert trained_groups(agent) == expected


def test_actor_step_trains_only_the_actor_and_its_loss_is_eq11():
    agent = agent_for_targets(curiosity=False)
    window = random_window()[0]
    with torch.no_grad():
        state = agent.encoder(window[:, :3]).state
    for p in [*agent.encoder.parameters(), *agent.critic.parameters()]:
        p.grad = None
    actor, critic = Calls(agent.actor), Calls(agent.critic)
    metrics = agent.update_actor(state)
    [((actor_in,), (action, log_prob))] = actor.with_grad(True)
    [((critic_in, critic_action), (q1, q2))] = critic.with_grad(True)
    torch.testing.assert_close(actor_in, state)
    torch.testing.assert_close(critic_in, state)
    torch.testing.assert_close(critic_action.double(), action)
    expected = (ALPHA * np64(log_prob) - np.minimum(np64(q1), np64(q2))).mean()
    assert float(metrics["actor_loss"]) == pytest.approx(expected, rel=1e-5)
    assert float(metrics["entropy"]) == pytest.approx(-np64(log_prob).mean(), rel=1e-5)
    # temperature: d/d log alpha of E[alpha (-log pi - H)] with H = -|A|, the policy fixed
    excess = -np64(log_prob)[:, 0] + ACTIONS
    assert float(agent.log_alpha.grad) == pytest.approx((ALPHA * excess).mean(), rel=1e-5)
    moved = float(agent.alpha.detach()) - ALPHA
    assert np.sign(moved) == -np.sign(excess.mean())  # alpha falls while entropy exceeds H
    assert trained_groups(agent) == {"actor", "log_alpha"}


def test_actor_step_of_an_update_leaves_the_encoder_gradient_of_eq14_alone():
    """The actor sees detached features: an update with the actor step (num_updates even) leaves
    the encoder exactly the gradients of one without it."""
    grads = []
    for num_updates in (0, 1):
        agent = agent_for_targets(curiosity=False)
        agent.num_updates = num_updates
        torch.manual_seed(5)
        agent.update_window(*random_window(), step=0)
        grads.append([p.grad.clone() for p in agent.encoder.parameters()])
        assert (agent.actor.trunk[0].weight.grad is not None) == (num_updates == 0)
    for with_actor, without in zip(*grads, strict=True):
        torch.testing.assert_close(with_actor, without, rtol=0, atol=0)


def hand_gradients(agent: SimounAgent, only: str, window, action, reward) -> list[torch.Tensor]:
    """The encoder's gradient of one auxiliary loss written out from the modules (Eq. 2, 3, 7)."""
    agent = copy.deepcopy(agent)
    obs, next_obs = window[:, :3], window[:, 1:]
    enc = agent.encoder(obs)
    if only == "transition":
        with torch.no_grad():  # the target f^m_{t+1} carries no gradient
            next_motion = agent.encoder(next_obs).motion
        predicted = agent.transition(enc.motion, action)
        loss = (predicted - next_motion).pow(2).sum(-1).mean()
    elif only == "reward":
        loss = F.mse_loss(agent.reward_model(enc.state, action), reward)
    else:
        torch.manual_seed(7)  # the update's random-conv draw (its first random operation)
        with torch.no_grad():
            frame_t = obs[:, -1].float() / 255
            key = agent.encoder_target.encode_key(random_conv(frame_t, 3))
        logits = enc.anchor @ agent.similarity.weight @ key.T
        loss = F.cross_entropy(logits, torch.arange(len(logits)))
    loss.backward()
    return [p.grad for p in agent.encoder.parameters()]


@pytest.mark.parametrize("only", ["transition", "contrastive", "reward"])
def test_encoder_gradient_of_each_auxiliary_loss_is_the_hand_written_one(only):
    """With L_Q cut from the encoder (zero Q output layers), the encoder's gradient is the
    auxiliary term's; L_tran's target f^m_{t+1} and L_con's momentum keys are constants. All
    three frames get gradient here (detach_past_frames=False), as in a plain forward pass."""
    agent = agent_for_gradients(only, detach_past_frames=False)
    window, action, reward, discount = random_window()
    expected = hand_gradients(agent, only, window, action, reward)
    torch.manual_seed(7)
    agent.update_window(window, action, reward, discount, step=0)
    for p, grad in zip(agent.encoder.parameters(), expected, strict=True):
        if grad is None:
            assert p.grad is None or not p.grad.any()
        else:
            torch.testing.assert_close(p.grad, grad, rtol=1e-4, atol=1e-7)


def test_actor_and_targets_update_every_second_gradient_step():
    agent = agent_for_targets(curiosity=False)
    nets = ("actor", "critic_target", "encoder_target")
    moved = []
    for step in range(4):
        before = {n: [p.clone() for p in getattr(agent, n).parameters()] for n in nets}
        agent.update_window(*random_window(seed=step), step=step)
        moved.append(
            {
                n
                for n in nets
                if any(
                    not torch.equal(b, p)
                    for b, p in zip(before[n], getattr(agent, n).parameters(), strict=True)
                )
            }
        )
    assert moved == [set(nets), set(), set(nets), set()]
    assert agent.num_updates == 4
