"""Eq. 13's intrinsic reward in n-step targets: every step of the return adds the
intrinsic reward of its own state, sum_{j<m} gamma^j (r^e_{t+1+j} + r^i(s_{t+j})), with r^i of
each s_{t+j} computed here from the online features of the triplet ending at frame t+j, rebuilt
from the episodes themselves (not from the replay's arrays); one episode is truncated and one
terminated inside the 3-step window, so some returns stop after one or two steps."""

import copy

import numpy as np
import pytest
import torch
from test_agent_update import ACTIONS, FRAME, small_config

from simoun_agent import FrameReplay, SimounAgent

GAMMA, N, STEP = 0.9, 3, 4000
EPISODES = {"a": ([1.0, 2.0, 3.0, 4.0], "truncated"), "b": ([10.0, 20.0, 30.0], "terminated")}
EPISODES["c"] = ([100.0, 200.0, 300.0, 400.0, 500.0], "open")
FRAME_ID = {"a": 10, "b": 20, "c": 30}
"""Frame k of episode e has FRAME_ID[e] + k in its first pixel (k = 0 is the reset frame)."""


def episodes_and_replay() -> tuple[dict[str, list[np.ndarray]], FrameReplay]:
    rng = np.random.default_rng(0)
    replay = FrameReplay(60, FRAME, ACTIONS, seed=1)
    frames = {}
    for name, (rewards, end) in EPISODES.items():
        frames[name] = []
        for k in range(len(rewards) + 1):
            image = rng.integers(0, 256, FRAME, dtype=np.uint8)
            image.flat[0] = FRAME_ID[name] + k
            frames[name].append(image)
        replay.start_episode(frames[name][0])
        for k, reward in enumerate(rewards, start=1):
            last = k == len(rewards)
            action = rng.uniform(-1, 1, ACTIONS)
            terminated, truncated = last and end == "terminated", last and end == "truncated"
            replay.add(action, reward, frames[name][k], terminated, truncated)
    return frames, replay


def triplet(frames: list[np.ndarray], index: int) -> np.ndarray:
    """Frames index-2, index-1, index of one episode, its first frame repeated before it."""
    return np.stack([frames[max(index - back, 0)] for back in (2, 1, 0)])


def steps_in_return(name: str, t: int) -> int:
    """m: the steps of the n-step return from t that stay in the episode (cut after a truncated
    or terminated step and at the newest frame)."""
    return min(N, len(EPISODES[name][0]) - t)


class Outputs:
    """The outputs of each forward call of a module, with the grad mode of the call."""

    def __init__(self, module: torch.nn.Module) -> None:
        self.calls = []
        module.register_forward_hook(
            lambda m, args, out: self.calls.append(
                (torch.is_grad_enabled(), tuple(o.detach().double() for o in out))
            )
        )

    def first(self, grad: bool) -> tuple[torch.Tensor, ...]:
        return next(out for enabled, out in self.calls if enabled == grad)


def eq13_distance(agent: SimounAgent, triplets: np.ndarray) -> np.ndarray:
    """d of Eq. 13 for each triplet, from the agent's online features (float64 here)."""
    f_m, f_a = (x.double().numpy() for x in agent.encoder_features(triplets))
    flow = np.abs(f_a[:, 1] - f_a[:, 0]) + np.abs(f_a[:, 2] - f_a[:, 1])
    return np.sqrt(((np.abs(f_m) - flow) ** 2).sum(-1))


def episode_and_step(batch: dict) -> list[tuple[str, int]]:
    """(episode, t) of each sampled transition, read from frame t's first pixel."""
    first_pixels = batch["window"][:, -2].reshape(len(batch["reward"]), -1)[:, 0]
    return [("abc"[int(p) // 10 - 1], int(p) % 10) for p in first_pixels]


def agent_and_batch() -> tuple[SimounAgent, FrameReplay, dict, list[tuple[str, int]]]:
    _, replay = episodes_and_replay()
    torch.manual_seed(0)
    config = small_config(batch_size=12, n_step=N, discount=GAMMA, r_i_max_init=1e-3)
    agent = SimounAgent(FRAME, ACTIONS, config, "cpu")
    batch = copy.deepcopy(replay).sample(12, N, GAMMA)  # the draw agent.update will make
    return agent, replay, batch, episode_and_step(batch)


def test_the_replay_marks_the_steps_inside_the_episode_and_returns_their_frames():
    frames, replay = episodes_and_replay()
    draws = [replay.sample(len(replay), N, GAMMA) for _ in range(10)]
    batch = {key: np.concatenate([draw[key] for draw in draws]) for key in draws[0]}
    seen = set()
    for i, (name, t) in enumerate(episode_and_step(batch)):
        m = steps_in_return(name, t)
        assert batch["return_mask"][i].tolist() == [1.0] * m + [0.0] * (N - m)
        window = batch["n_step_window"][i]
        assert window.shape == (3 + N, *FRAME)
        np.testing.assert_array_equal(window[:4], batch["window"][i])
        for j in range(m):  # s_{t+j} for each step of the return
            np.testing.assert_array_equal(window[j : j + 3], triplet(frames[name], t + j))
        for j in range(m, N):  # past the return: frame t+m repeated, never another episode's
            np.testing.assert_array_equal(window[j + 2], frames[name][t + m])
        seen.add((name, t))
    assert len(seen) == len(replay)
    assert {steps_in_return(*key) for key in seen} == {1, 2, 3}


def test_each_step_of_the_n_step_target_adds_the_intrinsic_reward_of_its_state():
    agent, replay, batch, keys = agent_and_batch()
    frames = episodes_and_replay()[0]
    masks = np.array([[j < steps_in_return(*key) for j in range(N)] for key in keys])
    assert set(masks.sum(1)) == {1, 2, 3}  # a truncation or termination cuts some windows
    assert any(key[0] == "a" and masks[i].sum() == 2 for i, key in enumerate(keys))
    # s_{t+j}; past the return (masked out) any state of the episode will do
    states = [
        np.stack([triplet(frames[e], min(t + j, len(frames[e]) - 1)) for e, t in keys])
        for j in range(N)
    ]
    distance = np.stack([eq13_distance(agent, s_j) for s_j in states], axis=1)  # (B, n)
    r_e_max = max(1.0, np.abs(batch["reward"]).max())
    r_i_max = max(1e-3, distance[masks].max())  # only steps inside the episode count
    r_i = 0.2 * np.exp(-2e-5 * STEP) * distance * r_e_max / r_i_max
    intrinsic = (GAMMA ** np.arange(N) * masks * r_i).sum(1)
    assert not np.allclose(intrinsic, r_i[:, 0])  # the later steps add to the target

    target_q, actor, critic = (
        Outputs(agent.critic_target),
        Outputs(agent.actor),
        Outputs(agent.critic),
    )
    metrics = agent.update(replay, STEP)

    q1_bar, q2_bar = target_q.first(grad=False)
    _, next_log_prob = actor.first(grad=False)
    q1, q2 = critic.first(grad=True)  # the critic loss's call (the actor loss's comes next)
    alpha = agent.config.init_temperature
    value = (torch.minimum(q1_bar, q2_bar) - alpha * next_log_prob)[:, 0].numpy()
    y = batch["return"] + intrinsic + GAMMA * batch["discount"] * value
    expected = ((q1[:, 0].numpy() - y) ** 2).mean() + ((q2[:, 0].numpy() - y) ** 2).mean()
    assert float(metrics["intrinsic_reward"]) == pytest.approx(intrinsic.mean(), rel=1e-5)
    assert float(metrics["critic_loss"]) == pytest.approx(expected, rel=1e-5)
    assert float(agent.running_max.r_i_max) == pytest.approx(r_i_max, rel=1e-5)


def test_without_the_mask_only_the_state_at_t_adds_its_intrinsic_reward():
    """The call without ``return_mask`` (only the state at t adds r^i) is still accepted."""
    agent, _, batch, keys = agent_and_batch()
    frames = episodes_and_replay()[0]
    first = eq13_distance(agent, np.stack([triplet(frames[e], t) for e, t in keys]))
    r_e_max = max(1.0, np.abs(batch["reward"]).max())
    expected = 0.2 * np.exp(-2e-5 * STEP) * first * r_e_max / max(1e-3, first.max())

    def put(name: str) -> torch.Tensor:
        return torch.from_numpy(batch[name])

    metrics = agent.update_window(
        put("window"), put("action"), put("reward"), put("discount"), STEP,
        bootstrap=(put("bootstrap_obs"), put("return")),
    )  # fmt: skip
    assert float(metrics["intrinsic_reward"]) == pytest.approx(expected.mean(), rel=1e-5)


def test_a_window_that_does_not_match_the_mask_is_refused():
    agent, _, batch, _ = agent_and_batch()
    tensors = {name: torch.from_numpy(value) for name, value in batch.items()}
    with pytest.raises(ValueError, match="n_step_window"):
        agent.update_window(
            tensors["window"], tensors["action"], tensors["reward"], tensors["discount"], STEP,
            bootstrap=(tensors["bootstrap_obs"], tensors["return"]),
            return_mask=tensors["return_mask"],
        )  # fmt: skip


def test_frames_past_the_end_of_the_return_change_nothing_not_even_the_running_maximum():
    """Replace every frame after t+m (where the window repeats frame t+m) by black and white
    frames, whose Eq. 13 distance exceeds every real one: the update is the same."""
    agent, _, batch, _ = agent_and_batch()
    mask = batch["return_mask"].astype(bool)
    assert not mask.all()
    changed = batch["n_step_window"].copy()
    for i, j in zip(*np.nonzero(~mask), strict=True):
        changed[i, j + 2] = 255 * (j % 2)  # frame t+j of a step past the return
    windows = {"replay": batch["n_step_window"], "changed": changed}
    states = [np.ascontiguousarray(changed[:, j : j + 3]) for j in range(N)]
    distance = np.stack([eq13_distance(agent, s_j) for s_j in states], axis=1)
    assert distance[~mask].max() > distance[mask].max()
    results = {}
    for name, window in windows.items():
        candidate = copy.deepcopy(agent)
        tensors = {key: torch.from_numpy(value) for key, value in batch.items()}
        torch.manual_seed(2)
        metrics = candidate.update_window(
            torch.from_numpy(window), tensors["action"], tensors["reward"], tensors["discount"],
            STEP, bootstrap=(tensors["bootstrap_obs"], tensors["return"]),
            return_mask=tensors["return_mask"],
        )  # fmt: skip
        results[name] = (
            float(metrics["critic_loss"]),
            float(metrics["intrinsic_reward"]),
            float(candidate.running_max.r_i_max),
        )
    assert results["changed"] == results["replay"]
