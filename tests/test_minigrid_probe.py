"""The novelty probe of the MiniGrid study: its correlation by hand, a reward that is the novelty
itself (r = 1) or its negation (r = -1), and the command line on the real consistency model."""

import csv
import subprocess
import sys
from collections import Counter

import numpy as np
import pytest
from gymnasium.vector import VectorWrapper

from simoun_lab.minigrid_study.envs import STATE_KEY
from simoun_lab.minigrid_study.probe import PROBED, ProbeSettings, pearson, probe, write_probe
from simoun_lab.minigrid_study.probe_settings import PROBE_NAMES


def test_pearson_by_hand():
    # x - mean = (-1, 0, 1), y - mean = (-7/3, -1/3, 8/3): r = 5 / sqrt(2 * 38/3)
    assert pearson(np.array([1.0, 2.0, 3.0]), np.array([2.0, 4.0, 7.0])) == pytest.approx(
        5 / np.sqrt(2 * 38 / 3)
    )
    assert np.isnan(pearson(np.array([1.0, 1.0]), np.array([0.0, 1.0])))


class NoveltyReward(VectorWrapper):
    """info["reward_intrinsic"] = sign / sqrt(N(s)) of the state each sub-env reached (the
    ending state of an episode that ended, not the next episode's first)."""

    def __init__(self, envs, sign):
        super().__init__(envs)
        self.sign, self.visits = sign, Counter()

    def step(self, actions):
        obs, rewards, terminated, truncated, info = self.env.step(actions)
        states = info[STATE_KEY].copy()
        for i in np.flatnonzero(terminated | truncated):
            states[i] = info["final_info"][STATE_KEY][i]
        novelty = []
        for state in map(tuple, states):
            self.visits[state] += 1
            novelty.append(self.sign * self.visits[state] ** -0.5)
        info = {
            **info,
            "reward_intrinsic": np.array(novelty),
            "_reward_intrinsic": ~np.isnan(novelty),
        }
        return obs, rewards, terminated, truncated, info


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_reward_that_is_the_novelty_correlates_one(monkeypatch, sign):
    monkeypatch.setitem(PROBED, "novelty", lambda envs, seed, device: NoveltyReward(envs, sign))
    # 5x5 episodes time out at 250 steps: blocks of 2 x 200 transitions cross episode ends
    settings = ProbeSettings("MiniGrid-DoorKey-5x5-v0", steps=1600, n_envs=2, n_steps=200, seed=3)
    rows = probe("novelty", settings)
    assert [r["env_step"] for r in rows] == [400, 800, 1200, 1600]
    assert [r["novelty_corr"] for r in rows] == pytest.approx([sign] * 4)
    assert [r["novelty_corr_moving"] for r in rows] == pytest.approx([sign] * 4)
    visited = [r["states_visited"] for r in rows]
    assert visited == sorted(visited) and visited[0] > 1


def test_the_command_lines_default_probes_are_every_probe():
    # the command line reads the names without torch; the probes themselves need it
    assert tuple(PROBED) == PROBE_NAMES


def test_an_unknown_probe_is_refused_with_the_choices(tmp_path):
    with pytest.raises(ValueError, match=r"--probes \['nope'\].*consistency"):
        write_probe(ProbeSettings(), ["nope"], tmp_path)


def test_an_empty_probe_list_is_refused_and_leaves_the_archived_table(tmp_path):
    (tmp_path / "probe.csv").write_text("probe,seed\nrnd,0\n")
    with pytest.raises(ValueError, match=r"--probes is given no probe.*leave --probes out"):
        write_probe(ProbeSettings(), [], tmp_path)
    assert (tmp_path / "probe.csv").read_text() == "probe,seed\nrnd,0\n"


@pytest.mark.parametrize(
    ("settings", "said"),
    [
        (ProbeSettings(n_steps=0), "settings.n_steps 0: must be 1 or more"),
        (ProbeSettings(n_envs=0), "settings.n_envs 0: must be 1 or more"),
        (ProbeSettings(steps=100), "settings.steps 100: fewer than two blocks"),
    ],
)
def test_a_probe_count_that_makes_no_block_is_refused_naming_it(settings, said, tmp_path):
    with pytest.raises(ValueError, match=said):
        write_probe(settings, ["rnd"], tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_the_command_line_probes_the_consistency_model(tmp_path):
    command = [
        sys.executable,
        "-m",
        "simoun_lab.minigrid_study",
        "probe",
        "--probes",
        "consistency",
        "--settings.steps",
        "1024",
        "--settings.n-steps",
        "32",
        "--out",
        str(tmp_path),
    ]
    done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    with (tmp_path / "probe.csv").open() as file:
        rows = list(csv.DictReader(file))
    assert [int(r["env_step"]) for r in rows] == [256, 512, 768, 1024]
    assert all(float(r["intrinsic_mean"]) > 0 for r in rows)  # Eq. 13 is positive
    table = (tmp_path / "probe.md").read_text()
    assert "| consistency | " in table and "of 3 |" in table


class StillReward(VectorWrapper):
    """info["reward_intrinsic"] = 1 for a still triplet (three equal frames) and 0 otherwise,
    judged on the ending observation of an episode that ended."""

    def step(self, actions):
        obs, rewards, terminated, truncated, info = self.env.step(actions)
        frames = np.array(obs)
        for i in np.flatnonzero(terminated | truncated):
            frames[i] = info["final_obs"][i]
        frames = frames.reshape(len(frames), 3, -1)
        still = np.all(frames == frames[:, :1], axis=(1, 2)).astype(float)
        info = {**info, "reward_intrinsic": still, "_reward_intrinsic": np.ones(len(still), bool)}
        return obs, rewards, terminated, truncated, info


def test_the_probe_tells_still_triplets_from_moving_ones(monkeypatch):
    monkeypatch.setitem(PROBED, "still", lambda envs, seed, device: StillReward(envs))
    settings = ProbeSettings("MiniGrid-DoorKey-5x5-v0", steps=1600, n_envs=2, n_steps=200, seed=3)
    rows = probe("still", settings)
    # a random policy's no-ops and moves into walls: 4 of MiniGrid's 7 actions change nothing
    assert all(0.2 < r["still_fraction"] < 0.9 for r in rows)
    assert [r["still_mean"] for r in rows] == [1.0] * 4
    assert [r["moving_mean"] for r in rows] == [0.0] * 4
    assert [r["intrinsic_mean"] for r in rows] == pytest.approx([r["still_fraction"] for r in rows])
    assert all(np.isnan(r["novelty_corr_moving"]) for r in rows)  # constant 0 when moving
