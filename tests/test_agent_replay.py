"""FrameReplay against the triplets FrameTriplet produced along real CartPole episodes."""

import gymnasium as gym
import numpy as np
import pytest

from simoun_agent import FrameReplay
from simoun_wrappers import SimounObservation

SIZE = 16


def collect(replay: FrameReplay, steps: int, seed: int = 0) -> dict[int, tuple]:
    """Run random CartPole episodes (pixels via render) into ``replay``; the action stored is the
    transition's id, and the returned dict maps it to (obs, next_obs, reward, terminated)."""
    env = SimounObservation(
        gym.make("CartPole-v1", render_mode="rgb_array"), size=SIZE, motion=False
    )
    rng = np.random.default_rng(seed)
    obs, _ = env.reset(seed=seed)
    replay.start_episode(obs["frames"][-1])
    expected = {}
    for t in range(steps):
        next_obs, reward, terminated, truncated, _ = env.step(int(rng.integers(2)))
        truncated = truncated or rng.random() < 0.05
        reward = float(reward) + t
        replay.add(np.array([t], np.float32), reward, next_obs["frames"][-1], terminated, truncated)
        expected[t] = (obs["frames"], next_obs["frames"], reward, terminated)
        obs = next_obs
        if terminated or truncated:
            obs, _ = env.reset()
            replay.start_episode(obs["frames"][-1])
    env.close()
    return expected


def test_triplets_match_frame_triplet_across_episodes_and_wraparound():
    replay = FrameReplay(capacity=50, frame_shape=(3, SIZE, SIZE), action_dim=1, seed=0)
    expected = collect(replay, steps=160)
    assert replay.written > replay.slots, "the ring must have wrapped around"
    batches = [replay.sample(len(replay)) for _ in range(60)]
    batch = {key: np.concatenate([b[key] for b in batches]) for key in batches[0]}
    ids = batch["action"][:, 0].astype(int)
    episode_starts = sum(1 for o, _, _, _ in expected.values() if (o[0] == o[2]).all())
    assert episode_starts > 3, "the data must cross several episode boundaries"
    for i, t in enumerate(ids):
        obs, next_obs, reward, terminated = expected[t]
        np.testing.assert_array_equal(batch["obs"][i], obs)
        np.testing.assert_array_equal(batch["next_obs"][i], next_obs)
        assert batch["reward"][i] == np.float32(reward)
        assert batch["discount"][i] == (0.0 if terminated else 1.0)
    # every transition still fully stored is sampled; none of the evicted ones
    assert set(ids) == set(range(160 - len(replay), 160))
    assert batch["obs"].dtype == np.uint8 and batch["obs"].shape[1:] == (3, 3, SIZE, SIZE)


def test_terminated_does_not_bootstrap_truncated_does():
    replay = FrameReplay(capacity=10, frame_shape=(1, 2, 2), action_dim=1, seed=1)
    frame = np.zeros((1, 2, 2), np.uint8)
    replay.start_episode(frame)
    replay.add([0.0], 1.0, frame, terminated=True, truncated=False)
    replay.start_episode(frame)
    replay.add([1.0], 1.0, frame, terminated=False, truncated=True)
    pairs = set()
    for _ in range(30):
        batch = replay.sample(2)
        pairs |= set(zip(batch["action"][:, 0].tolist(), batch["discount"].tolist(), strict=True))
    discount = dict(pairs)
    assert discount == {0.0: 0.0, 1.0: 1.0}


def test_save_load_resumes_the_same_samples(tmp_path):
    replay = FrameReplay(capacity=40, frame_shape=(3, SIZE, SIZE), action_dim=1, seed=3)
    collect(replay, steps=70, seed=1)
    replay.sample(5)
    path = tmp_path / "replay.tmp"
    replay.save(path)
    loaded = FrameReplay.load(path)
    assert len(loaded) == len(replay)
    for _ in range(3):
        a, b = replay.sample(16), loaded.sample(16)
        for key in a:
            np.testing.assert_array_equal(a[key], b[key])


def test_bytes_per_transition_at_84x84_rgb():
    replay = FrameReplay(capacity=100_000, frame_shape=(3, 84, 84), action_dim=6)
    measured = replay.nbytes / replay.capacity
    assert measured == replay.bytes_per_transition
    assert measured <= 22_000, measured


def test_bad_inputs_are_refused_with_a_fix():
    replay = FrameReplay(capacity=10, frame_shape=(3, 4, 4), action_dim=2)
    frame = np.zeros((3, 4, 4), np.uint8)
    with pytest.raises(RuntimeError, match="start_episode"):
        replay.add([0, 0], 0.0, frame, False, False)
    replay.start_episode(frame)
    for bad in (np.nan, np.inf, -np.inf):
        with pytest.raises(ValueError, match="not finite"):
            replay.add([0, 0], bad, frame, False, False)
    with pytest.raises(ValueError, match="uint8 array of shape"):
        replay.add([0, 0], 0.0, frame.astype(np.float32), False, False)
    with pytest.raises(ValueError, match="uint8 array of shape"):
        replay.start_episode(np.zeros((3, 3, 4, 4), np.uint8))
    replay.add([0, 0], 0.0, frame, False, False)
    assert len(replay) == 1
    with pytest.raises(ValueError, match="holds 1; collect more"):
        replay.sample(2)


@pytest.mark.parametrize(
    ("kwargs", "said"),
    [
        ({"batch_size": 0}, "sample(batch_size=...) must be a positive int, got 0"),
        ({"batch_size": -1}, "sample(batch_size=...) must be a positive int, got -1"),
        ({"batch_size": 1.5}, "sample(batch_size=...) must be a positive int, got 1.5"),
        ({"batch_size": "4"}, "sample(batch_size=...) must be a positive int, got '4'"),
        ({"batch_size": 4, "n_step": 0}, "sample(n_step=...) must be a positive int, got 0"),
        ({"batch_size": 4, "n_step": 2.0}, "sample(n_step=...) must be a positive int, got 2.0"),
        ({"batch_size": 4, "discount": 1.5}, "sample(discount=...) must be a number in [0, 1]"),
        ({"batch_size": 4, "discount": "0.9"}, "sample(discount=...) must be a number in [0, 1]"),
    ],
)
def test_a_sample_size_or_n_step_that_is_not_a_positive_int_is_named(kwargs, said):
    replay = FrameReplay(capacity=40, frame_shape=(3, SIZE, SIZE), action_dim=1, seed=0)
    collect(replay, steps=10)
    state = replay.rng.bit_generator.state
    with pytest.raises(ValueError) as raised:
        replay.sample(**kwargs)
    assert said in str(raised.value)
    assert replay.rng.bit_generator.state == state  # nothing drawn
    assert replay.sample(np.int64(4), n_step=np.int64(2))["obs"].shape == (4, 3, 3, SIZE, SIZE)


def test_a_file_that_is_no_replay_or_a_damaged_one_is_named(tmp_path):
    replay = FrameReplay(capacity=40, frame_shape=(3, SIZE, SIZE), action_dim=1, seed=0)
    collect(replay, steps=10)
    saved = tmp_path / "replay.npz"
    replay.save(saved)
    data = saved.read_bytes()
    files = {
        "text.npz": b"not a replay",
        "other.npz": None,
        "cut.npz": data[: len(data) // 2],
        "zeros.npz": bytes(len(data)),
        "empty.npz": b"",
    }
    for name, content in files.items():
        if content is None:
            np.savez(tmp_path / name, frames=np.zeros(3))
        else:
            (tmp_path / name).write_bytes(content)
    said = {
        "text.npz": "text.npz is not a replay saved by FrameReplay.save (it is no .npz archive)",
        "other.npz": "other.npz is not a replay saved by FrameReplay.save (it holds no 'meta'",
        "cut.npz": "cut.npz is damaged: it is no readable .npz archive",
        "zeros.npz": f"zeros.npz is damaged: all its {len(data)} bytes are zero",
        "empty.npz": "empty.npz is damaged: it is empty",
    }
    for name, words in said.items():
        with pytest.raises(ValueError) as raised:
            FrameReplay.load(tmp_path / name)
        assert words in str(raised.value)
        assert "allow_pickle" not in str(raised.value)
    with pytest.raises(FileNotFoundError, match=r"replay file .*nope\.npz does not exist"):
        FrameReplay.load(tmp_path / "nope.npz")
    assert len(FrameReplay.load(saved)) == len(replay)


def episodes_replay(lengths_and_ends, n_frames=3):
    """Episodes of the given (length, "terminated" | "truncated" | "open") whose frame j of
    episode e holds the value 10 e + j and whose step j has reward j + e / 10."""
    replay = FrameReplay(200, (1, 2, 2), 1, num_frames=n_frames, seed=0)
    for e, (length, end) in enumerate(lengths_and_ends):
        replay.start_episode(np.full((1, 2, 2), 10 * e, np.uint8))
        for j in range(1, length + 1):
            last = j == length
            replay.add(
                np.zeros(1),
                j + e / 10,
                np.full((1, 2, 2), 10 * e + j, np.uint8),
                last and end == "terminated",
                last and end == "truncated",
            )
    return replay


@pytest.mark.parametrize("n_step", [1, 2, 3, 5])
def test_n_step_targets_sum_discounted_rewards_and_stop_at_episode_ends(n_step):
    gamma = 0.9
    ends = [(4, "terminated"), (6, "truncated"), (2, "terminated"), (5, "open")]
    replay = episodes_replay(ends)
    draws = [replay.sample(len(replay), n_step=n_step, discount=gamma) for _ in range(25)]
    batch = {key: np.concatenate([draw[key] for draw in draws]) for key in draws[0]}
    seen = set()
    for i in range(len(batch["reward"])):
        value = int(batch["window"][i, -2, 0, 0, 0])  # frame t: 10 e + j
        e, t = divmod(value, 10)
        length, end = ends[e]
        m = min(n_step, length - t)  # steps left in the episode from t
        expected = sum(gamma**k * (t + 1 + k + e / 10) for k in range(m))
        assert batch["reward"][i] == pytest.approx(t + 1 + e / 10)
        assert batch["return"][i] == pytest.approx(expected, rel=1e-5)
        cut_by_termination = end == "terminated" and t + m == length
        assert batch["discount"][i] == pytest.approx(
            0.0 if cut_by_termination else gamma ** (m - 1)
        )
        # bootstrapped from the frame reached (never one of another episode), reset-padded
        triplet = batch["bootstrap_obs"][i, :, 0, 0, 0].tolist()
        reached = t + m
        assert triplet == [10 * e + max(reached - 2 + k, 0) for k in range(3)]
        seen.add((e, t))
    assert len(seen) == sum(length for length, _ in ends)  # every transition was drawn


def test_one_step_sample_keeps_its_meaning():
    replay = episodes_replay([(3, "terminated"), (3, "truncated")])
    batch = replay.sample(6)
    assert np.array_equal(batch["return"], batch["reward"])
    assert np.array_equal(batch["bootstrap_obs"], batch["next_obs"])
    terminal = batch["next_obs"][:, -1, 0, 0, 0] == 3  # the terminated episode's last frame
    assert np.array_equal(batch["discount"], np.where(terminal, 0.0, 1.0))


@pytest.mark.parametrize("method", ["save", "load"])
def test_a_path_with_an_unexpanded_home_is_named(method):
    replay = FrameReplay(10, (3, 8, 8), 1)
    call = replay.save if method == "save" else FrameReplay.load
    with pytest.raises(
        ValueError, match=rf"FrameReplay\.{method}\(path='~/no-such\.npz'\).*expanduser"
    ):
        call("~/no-such.npz")
