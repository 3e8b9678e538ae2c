"""The highway-cpu preset on the real highway-fast-v0, and the reference drivers read against it."""

from __future__ import annotations

import itertools

import imageio.v2 as imageio
import numpy as np
import pytest

from simoun_agent.config import resolve
from simoun_agent.run.driving_reference import REFERENCES, reference_metrics
from simoun_agent.run.make_env import make_env

pytest.importorskip("highway_env")


def test_preset_is_one_gray_view_at_five_decisions_per_second_ending_off_road():
    config = resolve("highway-cpu", {})
    env = make_env(config)
    assert env.observation_space["frames"].shape == (3, 1, 64, 64)
    highway = env.unwrapped.config
    assert highway["duration"] * highway["policy_frequency"] == 150
    assert highway["simulation_frequency"] == highway["policy_frequency"] == 5
    assert highway["offroad_terminal"]
    env.reset(seed=0)
    decisions, terminated, truncated = 0, False, False
    while not (terminated or truncated):  # full lock to one side leaves the 3-lane road
        _, _, terminated, truncated, _ = env.step(np.array([0.0, 1.0], np.float32))
        decisions += 1
    assert terminated and not env.unwrapped.vehicle.on_road and decisions < 20


def test_the_triplet_at_reset_repeats_the_first_drawn_frame_so_motion_starts_at_zero():
    env = make_env(resolve("highway-cpu", {}))
    for seed in (0, 1):
        frames = env.reset(seed=seed)[0]["frames"].astype(np.int16)
        assert frames[-1].std() > 10  # a drawn road, not a blank padding frame
        assert not np.diff(frames, axis=0).any()  # o_{t-2} = o_{t-1} = o_t: no motion spike
        after = env.step(np.zeros(2, np.float32))[0]["frames"].astype(np.int16)
        # one decision later only the cars move: a few pixels, nothing like the whole frame
        assert 0 < np.count_nonzero(after[-1] - after[-2]) < 0.1 * after[-1].size


def test_three_cameras_give_the_papers_layout_of_three_views_side_by_side():
    env = make_env(resolve("highway-cpu", {"cameras": 3}))
    frames = env.reset(seed=0)[0]["frames"]
    assert frames.shape == (3, 1, 64, 192)
    views = np.split(frames[-1, 0], 3, axis=1)
    assert not any(np.array_equal(a, b) for a, b in itertools.pairwise(views))


def test_lane_keeping_beats_the_zero_action_and_does_not_crash(tmp_path):
    video = tmp_path / "lane-keeping.gif"
    metrics = reference_metrics(resolve("highway-cpu", {}), episodes=3, seed=1000, video=video)
    assert list(metrics) == list(REFERENCES)
    keeper, zero, random = (metrics[name] for name in REFERENCES[::-1])
    assert keeper["crash_rate"] == 0.0 and keeper["length_mean"] >= 150
    assert keeper["return_mean"] > zero["return_mean"] + 20
    assert random["length_mean"] < 20  # random steering leaves the road, which ends the episode
    assert 15 < keeper["mean_speed"] < 31 and keeper["distance_m"] > 450
    # its first episode as the agent sees it, one frame per decision, enlarged (the GIF encoder
    # may merge two equal consecutive frames)
    frames = imageio.mimread(video)
    assert 140 <= len(frames) <= 151 and frames[0].shape == (256, 256, 3)
    assert len({frame.tobytes() for frame in frames}) > 100  # the road moves past
