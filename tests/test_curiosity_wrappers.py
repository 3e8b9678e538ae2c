"""ConsistencyCuriosityReward and its vector version on real envs, against hand-computed Eq. 13."""

import math

import cloudpickle
import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode
from gymnasium.wrappers import TransformReward

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)

SIZE = 16


class ProjectionFeatures:
    """A fixed random projection: f_a = P frame, f_m = Q [o_{t-1}-o_{t-2}, o_t-o_{t-1}].

    Counts its calls and the transitions it is shown, so batching can be checked.
    """

    def __init__(self, frame_size: int, dim: int = 6, seed: int = 0, gain: float = 1.0):
        rng = np.random.default_rng(seed)
        self.p = rng.normal(size=(frame_size, dim)) / frame_size * gain
        self.q = rng.normal(size=(2 * frame_size, dim)) / frame_size * gain
        self.calls = 0
        self.watched = []

    def __call__(self, triplets):
        self.calls += 1
        frames = triplets.reshape(*triplets.shape[:2], -1).astype(np.float64)
        residual = np.concatenate([frames[:, 1] - frames[:, 0], frames[:, 2] - frames[:, 1]], -1)
        return (residual @ self.q).astype(np.float32), (frames @ self.p).astype(np.float32)

    def watch(self, triplets, actions, next_triplets, terminated, truncated):
        self.watched.append((triplets.copy(), next_triplets.copy(), len(actions)))


def hand_distance(source: ProjectionFeatures, triplet: np.ndarray) -> float:
    f_m, f_a = source(triplet[None])
    f_m, f_a = f_m[0].astype(np.float64), f_a[0].astype(np.float64)
    flow = [abs(f_a[1][k] - f_a[0][k]) + abs(f_a[2][k] - f_a[1][k]) for k in range(len(f_m))]
    return math.sqrt(sum((abs(f_m[k]) - flow[k]) ** 2 for k in range(len(f_m))))


def cartpole(**kwargs):
    return SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=SIZE, **kwargs)


def test_reward_is_eq13_by_hand_with_running_maxima():
    source = ProjectionFeatures(3 * SIZE * SIZE)
    env = ConsistencyCuriosityReward(cartpole(), source, scale=0.3, decay=1e-3, r_i_max_init=1e-6)
    env.reset(seed=0)
    r_e_max, r_i_max = 1.0, 1e-6
    for t in range(12):
        obs, reward, *_, info = env.step(t % 2)
        d = hand_distance(source, obs["frames"])
        r_e_max, r_i_max = max(r_e_max, abs(info["reward_extrinsic"])), max(r_i_max, d)
        expected = 0.3 * math.exp(-1e-3 * t) * d * r_e_max / r_i_max
        assert info["reward_intrinsic"] == pytest.approx(expected, rel=1e-5)
        assert reward == pytest.approx(info["reward_extrinsic"] + expected, rel=1e-6)
        assert info["reward_intrinsic"] <= 0.3 * r_e_max + 1e-9
    assert env.state_dict() == {
        "scored": 12,
        "normalization": {"r_e_max": r_e_max, "r_i_max": pytest.approx(r_i_max)},
    }


def test_folded_observation_gives_the_same_reward_as_the_dict_one():
    rewards = []
    for fold in (False, True):
        env = ConsistencyCuriosityReward(
            cartpole(fold_frames=fold), ProjectionFeatures(3 * SIZE * SIZE)
        )
        env.reset(seed=3)
        rewards.append([env.step(1)[4]["reward_intrinsic"] for _ in range(5)])
    np.testing.assert_allclose(rewards[0], rewards[1])
    assert max(rewards[0]) > 0


def test_intrinsic_reward_decays_with_the_global_step():
    intrinsic = []
    for step in (0, 50_000):
        env = ConsistencyCuriosityReward(cartpole(), ProjectionFeatures(3 * SIZE * SIZE))
        # Large maxima that the first steps cannot raise: only the step differs.
        env.load_state_dict({"scored": step, "normalization": {"r_e_max": 10.0, "r_i_max": 1e6}})
        env.reset(seed=1)
        intrinsic.append([env.step(0)[4]["reward_intrinsic"] for _ in range(3)])
    ratio = np.array(intrinsic[1]) / np.array(intrinsic[0])
    np.testing.assert_allclose(ratio, math.exp(-2e-5 * 50_000), rtol=1e-5)


def test_after_warm_up_intrinsic_never_exceeds_scale_times_r_e_max():
    env = ConsistencyCuriosityReward(
        SimounObservation(gym.make("simoun/PointReach-v0"), size=None),
        ProjectionFeatures(3 * 32 * 32, gain=50.0),
        r_e_max_init=1e-3,
        r_i_max_init=1e-9,
    )
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(40):
        *_, terminated, truncated, info = env.step(env.action_space.sample())
        assert info["reward_intrinsic"] <= 0.2 * env.state_dict()["normalization"]["r_e_max"] * (
            1 + 1e-6
        )
        if terminated or truncated:
            env.reset()


def test_nan_or_inf_features_and_rewards_raise_clear_errors():
    diverged = ProjectionFeatures(3 * SIZE * SIZE)
    diverged.p[0, 0] = np.inf
    env = ConsistencyCuriosityReward(cartpole(), diverged)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="returned NaN or inf features"):
        for _ in range(5):
            env.step(0)
    nan_env = TransformReward(cartpole(), lambda r: float("nan"))
    env = ConsistencyCuriosityReward(nan_env, ProjectionFeatures(3 * SIZE * SIZE))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="NaN or inf reward"):
        env.step(0)


def test_wrong_observations_are_refused_with_the_fix():
    with pytest.raises(TypeError, match="SimounObservation"):
        ConsistencyCuriosityReward(gym.make("CartPole-v1"), ProjectionFeatures(4))
    with pytest.raises(TypeError, match="FeatureSource"):
        ConsistencyCuriosityReward(cartpole(), features="encoder")
    source = ProjectionFeatures(3 * SIZE * SIZE)
    with pytest.raises(ValueError, match=r"scale must be a finite number >= 0.*scale=0.01"):
        ConsistencyCuriosityReward(cartpole(), source, scale=-0.2)
    with pytest.raises(ValueError, match=r"scale must be a finite number >= 0"):
        ConsistencyCuriosityVectorReward(make_vec(1), source, scale=float("inf"))
    with pytest.raises(ValueError, match=r"decay must be a finite number >= 0.*decay=2e-5"):
        ConsistencyCuriosityVectorReward(make_vec(1), source, decay=float("nan"))


def test_state_survives_pickling_and_async_vector_env():
    env = ConsistencyCuriosityReward(
        SimounObservation(gym.make("simoun/PointReach-v0"), size=None),
        ProjectionFeatures(3 * 32 * 32),
    )
    env.reset(seed=0)
    for _ in range(7):
        env.step(env.action_space.sample())
    clone = cloudpickle.loads(cloudpickle.dumps(env))
    assert clone.state_dict() == env.state_dict() and clone.state_dict()["scored"] == 7
    # the observation chain is rebuilt from its arguments: both start a new episode alike
    env.reset(seed=3)
    clone.reset(seed=3)
    _, r_a, *_ = env.step(np.zeros(2, np.float32))
    _, r_b, *_ = clone.step(np.zeros(2, np.float32))
    assert r_a == r_b

    def make():
        return ConsistencyCuriosityReward(
            SimounObservation(gym.make("simoun/PointReach-v0"), size=None),
            ProjectionFeatures(3 * 32 * 32),
        )

    envs = gym.vector.AsyncVectorEnv([make, make])
    try:
        envs.reset(seed=[0, 1])
        for _ in range(4):
            envs.step(np.zeros((2, 2), np.float32))
        states = envs.call("state_dict")
        assert [s["scored"] for s in states] == [4, 4]
        envs.call(
            "load_state_dict", {"scored": 99, "normalization": {"r_e_max": 2.0, "r_i_max": 3.0}}
        )
        assert (
            envs.call("state_dict")
            == ({"scored": 99, "normalization": {"r_e_max": 2.0, "r_i_max": 3.0}},) * 2
        )
    finally:
        envs.close()


def make_vec(num_envs, **vector_kwargs):
    return gym.make_vec(
        "CartPole-v1",
        num_envs=num_envs,
        vectorization_mode="sync",
        render_mode="rgb_array",
        wrappers=[lambda e: SimounObservation(e, size=SIZE)],
        vector_kwargs=vector_kwargs,
    )


def test_vector_version_scores_each_sub_env_on_its_own_triplet_in_one_call():
    source = ProjectionFeatures(3 * SIZE * SIZE)
    envs = ConsistencyCuriosityVectorReward(make_vec(3), source, r_i_max_init=1e6)
    envs.reset(seed=[0, 1, 2])
    calls = source.calls
    obs, rewards, *_, info = envs.step(np.array([0, 1, 0]))
    assert source.calls == calls + 1
    for i in range(3):
        expected = 0.2 * hand_distance(source, obs["frames"][i]) * 1.0 / 1e6
        assert info["reward_intrinsic"][i] == pytest.approx(expected, rel=1e-5)
    assert len(set(np.round(info["reward_intrinsic"], 12))) == 3
    np.testing.assert_allclose(rewards, info["reward_extrinsic"] + info["reward_intrinsic"])
    envs.close()


def test_vector_version_skips_the_next_step_autoreset_step():
    source = ProjectionFeatures(3 * SIZE * SIZE)
    envs = ConsistencyCuriosityVectorReward(make_vec(2), source)
    envs.reset(seed=[0, 5])
    rng = np.random.default_rng(0)
    for _ in range(200):
        *_, terminated, truncated, _ = envs.step(rng.integers(0, 2, size=2))
        ended = np.logical_or(terminated, truncated)
        if ended.sum() == 1:
            break
    else:
        pytest.fail("no single sub-env ended within 200 random CartPole steps")
    before, watched = envs.state_dict()["scored"], len(source.watched)
    _, rewards, _, _, info = envs.step(np.zeros(2, dtype=np.int64))
    # the step after an episode ended is only the reset: no reward, no statistics, not watched
    assert info["reward_intrinsic"][ended] == 0.0 and rewards[ended] == 0.0
    assert info["reward_intrinsic"][~ended] > 0.0
    assert envs.state_dict()["scored"] == before + 1
    assert len(source.watched) == watched + 1 and source.watched[-1][2] == 1
    envs.close()


def test_vector_same_step_mode_scores_the_final_observation():
    source = ProjectionFeatures(3 * SIZE * SIZE)
    envs = ConsistencyCuriosityVectorReward(
        make_vec(2, autoreset_mode=AutoresetMode.SAME_STEP), source, r_i_max_init=1e6
    )
    envs.reset(seed=[0, 5])
    for _ in range(200):
        _, _, terminated, truncated, info = envs.step(np.array([0, 0]))
        ended = np.flatnonzero(np.logical_or(terminated, truncated))
        if len(ended):
            i = ended[0]
            final = info["final_obs"][i]["frames"]
            expected = 0.2 * math.exp(-2e-5 * (envs.state_dict()["scored"] - 2))
            expected *= hand_distance(source, final) / 1e6
            assert info["reward_intrinsic"][i] == pytest.approx(expected, rel=1e-5)
            break
    else:
        pytest.fail("CartPole pushed left never ended within 200 steps")
    envs.close()


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")
def test_passes_check_env_and_rebuilds_from_its_spec():
    source = ProjectionFeatures(3 * SIZE * SIZE)
    env = ConsistencyCuriosityReward(cartpole(), source, scale=0.5)
    check_env(env, skip_render_check=True)
    rebuilt = gym.make(env.spec)
    assert isinstance(rebuilt, ConsistencyCuriosityReward) and rebuilt.scale == 0.5
    # a wrapper above deep-copies the spec, but not the feature source (a model's weights, buffer)
    above = gym.make(gym.wrappers.RecordEpisodeStatistics(env).spec)
    assert above.env.signal.features is source and rebuilt.signal.features is source
    rebuilt.reset(seed=0)
    assert "reward_intrinsic" in rebuilt.step(0)[4]


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_vector_version_watches_only_transitions_within_an_episode(mode):
    source = ProjectionFeatures(3 * SIZE * SIZE)
    envs = ConsistencyCuriosityVectorReward(make_vec(2, autoreset_mode=mode), source)
    envs.reset(seed=[0, 5])
    rng = np.random.default_rng(1)
    episodes_ended = 0
    for _ in range(60):
        *_, terminated, truncated, _ = envs.step(rng.integers(0, 2, size=2))
        episodes_ended += int(np.logical_or(terminated, truncated).sum())
    assert episodes_ended >= 2
    # every (triplet, next triplet) pair handed to the source is one step of one episode: the
    # next triplet is the triplet shifted by one frame (across an episode end it would not be)
    pairs = [
        (a, b)
        for triplets, nexts, _ in source.watched
        for a, b in zip(triplets, nexts, strict=True)
    ]
    assert len(pairs) == envs.state_dict()["scored"]
    for triplet, following in pairs:
        np.testing.assert_array_equal(following[:2], triplet[1:])
    envs.close()


def test_single_env_wrapper_given_a_vector_env_points_to_the_vector_wrapper():
    envs = make_vec(2)
    with pytest.raises(TypeError, match=r"use ConsistencyCuriosityVectorReward\(envs"):
        ConsistencyCuriosityReward(envs, ProjectionFeatures(3 * SIZE * SIZE))
    envs.close()


def mean_error(triplets):
    """A novelty source: one error per triplet, not (f_m, f_a)."""
    return triplets[:, -1].reshape(len(triplets), -1).mean(axis=1) / 255.0


@pytest.mark.parametrize(
    ("source", "said"),
    [
        (lambda t: (t, t, t), r"function <lambda> returned a tuple of 3 for 1 triplets"),
        (lambda t: None, r"function <lambda> returned a NoneType for 1 triplets"),
        (mean_error, r"returned a ndarray of shape \(1,\) .*goes with RNDReward"),
    ],
)
def test_a_feature_source_that_returns_no_pair_is_named_with_what_it_must_return(source, said):
    env = ConsistencyCuriosityReward(cartpole(), source)
    env.reset(seed=0)
    with pytest.raises(ValueError, match=said) as error:
        env.step(0)
    assert "must return the tuple (f_m, f_a)" in str(error.value)
    envs = ConsistencyCuriosityVectorReward(make_vec(2), source)
    envs.reset(seed=0)
    with pytest.raises(ValueError, match="must return the tuple"):
        envs.step(np.array([0, 1]))


def test_a_feature_source_without_the_triplets_argument_is_refused_when_built():
    with pytest.raises(TypeError, match=r"^features is called as features\(triplets\), which its"):
        ConsistencyCuriosityReward(cartpole(), lambda: (0, 0))
    with pytest.raises(TypeError, match=r"signature \(\) does not take"):
        ConsistencyCuriosityVectorReward(make_vec(2), lambda: (0, 0))
