"""FrameReplay by hand: which transitions a wrapped ring still holds, the n-step sums at the
ring's newest frame and at every kind of episode end, what each batch key holds, the ring's size
for 50-step episodes, seeding, files, and the misuse messages.

Every expected value comes from the list of frames written, (episode, step) each, and the
definitions of the docstrings (a transition is sampleable while the frames of its window, up to
``num_frames`` before its next frame within its episode, are among the newest ``slots`` frames),
never from the replay's own arrays.
"""

import inspect
import io
import json

import numpy as np
import pytest

from simoun_agent import FrameReplay

FRAME = (2, 1, 1)  # pixel 0 holds the episode, pixel 1 the step
# an episode ends terminated, truncated, abandoned (the next start_episode comes without either
# flag, as after an interrupted evaluation) or stays open (the newest frames)
EPISODES = [(5, "terminated"), (3, "truncated"), (7, "abandoned"), (4, "truncated")]
EPISODES += [(6, "terminated"), (9, "open")]


def frame(episode: int, step: int) -> np.ndarray:
    return np.array([episode, step], np.uint8).reshape(FRAME)


def reward(episode: int, step: int) -> float:
    return 100.0 * episode + step


def write(replay: FrameReplay, episodes, after=None) -> list[tuple[int, int]]:
    """Write ``episodes`` [(length, end)]; the action of step j of episode e is [e, j]. Calls
    ``after(written)`` after each frame; returns (episode, step) of every frame, oldest first."""
    written = []
    for e, (length, end) in enumerate(episodes):
        replay.start_episode(frame(e, 0))
        written.append((e, 0))
        if after:
            after(written)
        for j in range(1, length + 1):
            last = j == length
            terminated, truncated = last and end == "terminated", last and end == "truncated"
            replay.add([e, j], reward(e, j), frame(e, j), terminated, truncated)
            written.append((e, j))
            if after:
                after(written)
    return written


def sampleable(written: list[tuple[int, int]], slots: int, num_frames: int) -> set:
    """The transitions (episode, step of their next frame) whose window is still stored."""
    oldest = max(0, len(written) - slots)
    return {
        (e, j) for i, (e, j) in enumerate(written) if j >= 1 and i - min(j, num_frames) >= oldest
    }


def drawn(replay: FrameReplay, draws: int = 30, **kwargs) -> dict[str, np.ndarray]:
    batches = [replay.sample(len(replay), **kwargs) for _ in range(draws)]
    return {key: np.concatenate([b[key] for b in batches]) for key in batches[0]}


@pytest.mark.parametrize("gamma", [0.9, None])
def test_n_step_batches_of_a_wrapped_ring_by_hand(gamma):
    """n = 3 on a ring that wrapped: every key of every sampleable transition, the sums cut at
    each kind of episode end and at the newest frame (whose slot + 1 holds the oldest frame)."""
    n, replay = 3, FrameReplay(capacity=25, frame_shape=FRAME, action_dim=2, seed=0)
    written = write(replay, EPISODES)
    assert replay.written == len(written) > replay.slots  # wrapped
    assert written[-replay.slots] == (2, 1)  # the abandoned episode is stored, its reset not
    expected_set = sampleable(written, replay.slots, 3)
    assert len(replay) == len(expected_set)
    batch = drawn(replay, n_step=n) if gamma is None else drawn(replay, n_step=n, discount=gamma)
    g = 1.0 if gamma is None else gamma  # the default discount
    seen = set()
    for i in range(len(batch["reward"])):
        e, j = (int(v) for v in batch["window"][i, -1, :, 0, 0])  # frame t+1
        length, end = EPISODES[e]
        m = min(n, length - j + 1)  # steps of the sum: to the episode's last frame at most
        reached = j + m - 1
        assert batch["action"][i].tolist() == [e, j]
        assert batch["reward"][i] == reward(e, j)
        assert batch["truncated"][i] == (end == "truncated" and j == length)
        expected_return = sum(g**k * reward(e, j + k) for k in range(m))
        assert batch["return"][i] == pytest.approx(expected_return, rel=1e-6)
        stopped = end == "terminated" and reached == length
        assert batch["discount"][i] == pytest.approx(0.0 if stopped else g ** (m - 1))
        assert batch["return_mask"][i].tolist() == [1.0] * m + [0.0] * (n - m)

        def steps(key: str, i: int = i, e: int = e) -> list[int]:
            assert (batch[key][i, :, 0, 0, 0] == e).all()  # never a frame of another episode
            return batch[key][i, :, 1, 0, 0].tolist()

        assert steps("window") == [max(j - 3 + k, 0) for k in range(4)]
        assert steps("obs") == steps("window")[:3] and steps("next_obs") == steps("window")[1:]
        assert steps("bootstrap_obs") == [max(reached - 2 + k, 0) for k in range(3)]
        ahead = [min(j + k, reached) for k in range(1, n)]
        assert steps("n_step_window") == steps("window") + ahead
        seen.add((e, j))
    assert seen == expected_set  # every stored transition is drawn, no evicted one
    dtypes = {key: value.dtype for key, value in batch.items()}
    frames = ("obs", "next_obs", "window", "bootstrap_obs", "n_step_window")
    floats = ("action", "reward", "return", "discount", "return_mask")
    assert dtypes == {
        **dict.fromkeys(frames, np.uint8),
        **dict.fromkeys(floats, np.float32),
        "truncated": np.bool_,
    }


def test_len_and_the_samples_follow_the_ring_frame_by_frame():
    """After each frame written to a ring of 10 slots: ``written``, ``len`` and the set sampled
    against the hand count, while one-step episodes put step-1 frames at the ring's oldest slot
    (their reset frame gone, so their window is not whole)."""
    replay = FrameReplay(capacity=6, frame_shape=FRAME, action_dim=2, seed=1)
    episodes = [(1, "terminated"), (3, "truncated"), (1, "abandoned"), (4, "terminated")]
    episodes += [(1, "truncated"), (1, "terminated"), (5, "open")]
    checked = []

    def check(written):
        assert replay.written == len(written)
        expected = sampleable(written, replay.slots, 3)
        assert len(replay) == len(expected)
        if expected:
            ids = drawn(replay, draws=12)["action"].astype(int)
            assert {tuple(a) for a in ids} == expected
        checked.append(len(expected))

    written = write(replay, episodes, after=check)
    assert len(written) == 23 > 2 * replay.slots and max(checked) >= 6


@pytest.mark.parametrize("capacity", [2, 10, 52, 99, 100, 120])
def test_capacity_transitions_fit_with_episodes_of_50_steps(capacity):
    """The docstring's promise, at every frame once the ring is full; capacity // 50 slots for
    the reset frames left one transition short unless capacity % 50 was 0 or 1."""
    replay = FrameReplay(capacity=capacity, frame_shape=FRAME, action_dim=2)
    low = []

    def check(written):
        if len(written) > replay.slots:
            low.append(len(replay))

    write(replay, [(50, "truncated")] * (3 * capacity // 50 + 4), after=check)
    assert min(low) >= capacity


def test_memory_is_the_ring_of_uint8_frames_with_their_steps():
    """capacity 99 at 84x84 RGB, 6 actions: 99 + ceil(98 / 50) + 3 = 104 slots of one frame,
    the float32 action and reward, two flags and the uint8 step."""
    replay = FrameReplay(capacity=99, frame_shape=(3, 84, 84), action_dim=6)
    assert replay.nbytes == 104 * (3 * 84 * 84 + 4 * 6 + 4 + 1 + 1 + 1)
    assert replay.bytes_per_transition == replay.nbytes / 99


def test_the_seed_fixes_the_samples():
    def samples(seed):
        replay = FrameReplay(capacity=20, frame_shape=FRAME, action_dim=2, seed=seed)
        write(replay, EPISODES)
        return [replay.sample(8, n_step=2)["action"] for _ in range(3)]

    first, again, other = samples(5), samples(5), samples(6)
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    assert not all(np.array_equal(a, b) for a, b in zip(first, other, strict=True))


def same_samples(a: FrameReplay, b: FrameReplay) -> None:
    assert len(a) == len(b)
    for _ in range(3):
        x, y = (r.sample(len(a), n_step=3, discount=0.9) for r in (a, b))
        assert x.keys() == y.keys()
        for key in x:
            np.testing.assert_array_equal(x[key], y[key])


def test_save_to_a_file_object_holds_only_the_frames_written_and_loads_both_ways():
    replay = FrameReplay(capacity=1000, frame_shape=FRAME, action_dim=2, seed=2)
    write(replay, EPISODES[:2])
    file = io.BytesIO()
    replay.save(file)
    file.seek(0)
    with np.load(file) as data:
        assert data["frames"].shape[0] == 6 + 4  # not the 1023 slots
    saved = file.getvalue()
    same_samples(replay, FrameReplay.load(io.BytesIO(saved)))
    into = FrameReplay(capacity=1000, frame_shape=FRAME, action_dim=2)
    assert into.load(io.BytesIO(saved)) is into
    same_samples(FrameReplay.load(io.BytesIO(saved)), into)


def test_a_file_written_before_the_ring_grew_loads_with_its_own_ring():
    """Files without "slots" had capacity + capacity // 50 + num_frames slots (103 here, now
    104): frame i of a wrapped ring sits in slot i % 103, so the loaded buffer keeps 103."""
    old = FrameReplay(capacity=99, frame_shape=FRAME, action_dim=2, seed=4)
    old._allocate(103)  # the ring as the code before this size wrote it
    write(old, [(40, "truncated"), (45, "terminated"), (50, "open")])
    assert old.written > 103
    file = io.BytesIO()
    old.save(file)
    file.seek(0)
    with np.load(file) as data:
        arrays = {key: data[key] for key in data.files}
    meta = json.loads(arrays["meta"].tobytes().decode())
    del meta["slots"]
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), np.uint8)
    file = io.BytesIO()
    np.savez(file, **arrays)
    file.seek(0)
    loaded = FrameReplay.load(file)
    assert loaded.slots == 103
    same_samples(old, loaded)
    for replay in (old, loaded):  # and on after more frames
        replay.add([9, 9], 1.0, frame(2, 51), False, False)
    same_samples(old, loaded)


def test_load_shows_the_signature_users_call():
    assert list(inspect.signature(FrameReplay.load).parameters) == ["path"]
    replay = FrameReplay(capacity=5, frame_shape=FRAME, action_dim=2)
    assert list(inspect.signature(replay.load).parameters) == ["path"]


def test_misuse_is_refused_naming_the_call_and_the_smallest_sizes_work():
    for capacity, num_frames, named in ((0, 3, "capacity"), (5, 0, "num_frames")):
        with pytest.raises(ValueError, match=f"{named} must be an int >= 1, got 0"):
            FrameReplay(capacity, FRAME, 2, num_frames=num_frames)
    replay = FrameReplay(capacity=5, frame_shape=FRAME, action_dim=2, seed=0)
    with pytest.raises(ValueError, match=r"start_episode\(frame\) must be a uint8 array"):
        replay.start_episode(np.zeros(FRAME, np.float32))
    replay.start_episode(frame(0, 0))
    with pytest.raises(ValueError, match=r"add\(next_frame\) must be a uint8 array"):
        replay.add([0, 0], 0.0, np.zeros((2, 2), np.uint8), False, False)
    for action in ([1.0], [1.0, 2.0, 3.0], [np.nan, 0.0]):
        with pytest.raises(ValueError, match="action must hold 2 finite numbers"):
            replay.add(action, 0.0, frame(0, 1), False, False)
    replay.add(np.array([[3.0], [4.0]]), 0.0, frame(0, 1), False, False)  # any shape of 2
    replay.add(np.array([[5.0, 6.0]]), 0.0, frame(0, 2), False, False)
    assert {tuple(a) for a in drawn(replay, draws=10)["action"]} == {(3.0, 4.0), (5.0, 6.0)}
    for terminated in (True, False):
        replay.add([0, 0], 0.0, frame(0, 3), terminated, not terminated)
        with pytest.raises(
            RuntimeError, match=r"^FrameReplay\.add\(\) called with no open episode"
        ):
            replay.add([0, 0], 0.0, frame(0, 4), False, False)
        replay.start_episode(frame(1, 0))
    smallest = FrameReplay(capacity=1, frame_shape=FRAME, action_dim=2, num_frames=1)
    write(smallest, [(3, "open")])
    assert len(smallest) == 1
    assert drawn(smallest, draws=3)["window"][:, :, 1, 0, 0].tolist() == [[2, 3]] * 3
