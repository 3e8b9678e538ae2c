"""RNDReward / RNDVectorReward and RNDModel on real MiniGrid pixels, against hand computations."""

import functools

import gymnasium as gym
import minigrid  # noqa: F401  (registers the MiniGrid-* ids)
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode
from minigrid.wrappers import ImgObsWrapper, RGBImgPartialObsWrapper

from simoun_agent.rnd_model import RNDConfig, RNDModel
from simoun_wrappers import SimounObservation
from simoun_wrappers.rnd import RNDReward, RNDVectorReward

TINY = dict(feature_dim=32, batch_size=16, capacity=64, learning_starts=16, seed=0)


def pixels(env_id: str = "MiniGrid-Empty-5x5-v0", **kwargs) -> gym.Env:
    """The agent's 7x7-tile view at 8 px a tile (56x56 RGB), as a Simoun triplet."""
    env = ImgObsWrapper(RGBImgPartialObsWrapper(gym.make(env_id, **kwargs)))
    return SimounObservation(env, size=None)


class Brightness:
    """A novelty source by hand: the newest frame's mean pixel value; records what it watched."""

    def __init__(self):
        self.watched = []

    def __call__(self, triplets):
        return triplets[:, -1].reshape(len(triplets), -1).mean(axis=1) / 255.0

    def watch(self, triplets, actions, next_triplets, terminated, truncated):
        self.watched.append((triplets.copy(), next_triplets.copy(), len(actions)))


def frames_of(env: gym.Env, actions, seed: int) -> np.ndarray:
    """The triplets an action sequence reaches, from a seeded reset."""
    obs, _ = env.reset(seed=seed)
    triplets = [obs["frames"]]
    for action in actions:
        obs, *_ = env.step(action)
        triplets.append(obs["frames"])
    return np.stack(triplets)


def test_predictor_error_falls_on_seen_frames_and_stays_high_on_unseen_ones():
    seen = frames_of(pixels(), [1, 1, 2, 0, 2], seed=0)  # turns and steps in an empty room
    unseen = frames_of(pixels("MiniGrid-DoorKey-5x5-v0"), [2, 1, 2], seed=3)  # key, door, wall
    config = RNDConfig(**TINY, update_every=10_000, background=False, lr=1e-3)
    model = RNDModel((3, 56, 56), config=config, device="cpu")
    for _ in range(4):  # the seen frames fill the buffer and set the observation statistics
        model.watch(seen, np.zeros(len(seen)), seen, np.zeros(len(seen)), np.zeros(len(seen)))
    before_seen, before_unseen = model(seen).mean(), model(unseen).mean()
    for _ in range(150):
        model.update()
    after_seen, after_unseen = model(seen).mean(), model(unseen).mean()
    assert model.updates == 150 and model.last_metrics["loss"] < 0.05 * before_seen
    assert after_seen < 0.05 * before_seen
    assert after_unseen > 0.2 * before_unseen and after_unseen > 100 * after_seen


def test_reward_is_the_error_over_its_running_std_after_the_warm_up():
    source = Brightness()
    env = RNDReward(pixels(), source, scale=0.3, warmup=7)
    env.reset(seed=0)
    errors, intrinsic = [], []
    for t in range(14):
        obs, reward, *_, info = env.step([0, 1, 2][t % 3])
        errors.append(source(obs["frames"][None])[0])
        intrinsic.append(info["reward_intrinsic"])
        assert reward == pytest.approx(info["reward_extrinsic"] + info["reward_intrinsic"])
    assert intrinsic[:7] == [0.0] * 7  # the warm-up gives no reward
    for t in range(7, 14):
        counted = np.array(errors[3 : t + 1])  # from warmup // 2 = 3 on
        expected = 0.3 * errors[t] / np.sqrt(counted.var())
        assert intrinsic[t] == pytest.approx(expected, rel=1e-6)
    assert env.state_dict()["scored"] == 14
    assert env.state_dict()["normalization"]["mean"] == pytest.approx(np.mean(errors[3:]), rel=1e-9)
    assert len(source.watched) == 14


def test_each_sub_env_counts_towards_the_warm_up_in_order():
    envs = RNDVectorReward(make_vec(2, AutoresetMode.NEXT_STEP), Brightness(), warmup=3)
    envs.reset(seed=[0, 1])
    first = envs.step(np.array([0, 1]))[4]["reward_intrinsic"]  # transitions 0, 1
    second = envs.step(np.array([0, 1]))[4]["reward_intrinsic"]  # transitions 2, 3
    assert np.all(first == 0.0)
    assert second[0] == 0.0 and second[1] > 0
    envs.close()


def test_the_error_statistics_load_into_a_new_wrapper():
    source = Brightness()
    env = RNDReward(pixels(), source, scale=0.3, warmup=2)
    env.reset(seed=0)
    for t in range(6):
        env.step(t % 3)
    clone = RNDReward(pixels(), source, scale=0.3, warmup=2)
    clone.load_state_dict(env.state_dict())
    assert clone.state_dict() == env.state_dict()
    for each in (env, clone):
        each.reset(seed=1)
    for t in range(4):  # the same steps from the same statistics: the same rewards
        assert clone.step(t % 3)[4]["reward_intrinsic"] == env.step(t % 3)[4]["reward_intrinsic"]
    assert clone.state_dict() == env.state_dict()


def test_the_defaults_are_the_studys():
    env = RNDReward(pixels(), Brightness())
    assert env.scale == 0.05 and env.warmup == 1024


def make_vec(num_envs: int, mode: AutoresetMode) -> gym.vector.VectorEnv:
    # 5x5 rooms with 12 steps a life: episodes end often under random actions
    return gym.vector.SyncVectorEnv(
        [lambda: pixels(max_steps=12) for _ in range(num_envs)], autoreset_mode=mode
    )


def test_vector_version_skips_the_next_step_autoreset_step():
    source = Brightness()
    envs = RNDVectorReward(make_vec(2, AutoresetMode.NEXT_STEP), source, warmup=0)
    envs.reset(seed=[0, 1])
    for _ in range(12):
        *_, terminated, truncated, _ = envs.step(np.array([0, 1]))  # turn, turn: time out
    ended = np.logical_or(terminated, truncated)
    assert ended.all()
    scored, watched = envs.state_dict()["scored"], len(source.watched)
    _, rewards, _, _, info = envs.step(np.array([2, 2]))
    # the step after an episode ended only resets: no reward, no statistics, not watched
    assert np.all(info["reward_intrinsic"] == 0.0) and np.all(rewards == 0.0)
    assert envs.state_dict()["scored"] == scored and len(source.watched) == watched
    _, _, _, _, info = envs.step(np.array([2, 2]))
    assert np.all(info["reward_intrinsic"] > 0) and envs.state_dict()["scored"] == scored + 2
    envs.close()


def test_vector_same_step_mode_scores_the_final_observation():
    source = Brightness()
    envs = RNDVectorReward(make_vec(2, AutoresetMode.SAME_STEP), source, scale=1.0, warmup=0)
    envs.reset(seed=[0, 1])
    for _ in range(12):
        _, _, terminated, truncated, info = envs.step(np.array([0, 1]))
    assert np.logical_or(terminated, truncated).all()
    final = np.stack([info["final_obs"][i]["frames"] for i in range(2)])
    std = np.sqrt(envs.state_dict()["normalization"]["var"])
    np.testing.assert_allclose(info["reward_intrinsic"], source(final) / std, rtol=1e-6)
    # the last transition watched ends on the final triplet, not on the next episode's first
    np.testing.assert_array_equal(source.watched[-1][1], final)
    assert envs.state_dict()["scored"] == 24
    envs.close()


def test_the_thread_changes_no_reward_and_a_seed_fixes_them():
    rewards = []
    for background in (True, False, True):
        config = RNDConfig(**TINY, update_every=2, background=background)
        env = pixels("MiniGrid-DoorKey-5x5-v0")
        model = RNDModel.for_env(env, config, device="cpu")
        env = RNDReward(env, model, warmup=4)
        env.reset(seed=0)
        rewards.append([env.step([0, 1, 2][t % 3])[4]["reward_intrinsic"] for t in range(40)])
        assert model.updates == (40 - 16) // 2  # one step due at each even call from 16 on
        env.close()
    # equal up to float rounding: torch's kernels may round differently in another thread
    np.testing.assert_allclose(rewards[0], rewards[1], rtol=1e-6, atol=0)
    np.testing.assert_allclose(rewards[0], rewards[2], rtol=1e-6, atol=0)
    assert len(set(rewards[0][4:])) > 30  # the rewards vary from step to step


def test_state_dict_restores_the_errors():
    config = RNDConfig(**TINY, update_every=2, background=False)
    env = pixels()
    model = RNDModel.for_env(env, config, device="cpu")
    env = RNDReward(env, model, warmup=0)
    env.reset(seed=0)
    for t in range(30):
        obs, *_ = env.step(t % 3)
    state, frames = model.state_dict(), obs["frames"][None]
    clone = RNDModel.for_env(pixels(), RNDConfig(**{**TINY, "seed": 1}), device="cpu")
    assert not np.allclose(clone(frames), model(frames))
    clone.load_state_dict(state)
    np.testing.assert_array_equal(clone(frames), model(frames))
    assert clone.updates == model.updates == 7


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped version")
def test_passes_check_env_and_rebuilds_from_its_spec():
    source = Brightness()
    # check_env asks for the same reward from the same seed and action; a reward whose
    # statistics move with every step is not, so the warm-up keeps it at 0 for the check
    env = RNDReward(pixels(), source, scale=0.5, warmup=10_000)
    # minigrid's RGBImgPartialObsWrapper records no constructor arguments, so its chain cannot
    # be rebuilt from env.spec (check_env's close check does that): rebuild CartPole's instead
    check_env(env, skip_render_check=True, skip_close_check=True)
    assert len(source.watched) > 0
    env = RNDReward(
        SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=36),
        source,
        scale=0.5,
        warmup=10_000,
    )
    rebuilt = gym.make(env.spec)
    assert isinstance(rebuilt, RNDReward) and rebuilt.scale == 0.5
    assert rebuilt.signal.source is source and rebuilt.warmup == 10_000


def test_bad_arguments_are_refused_with_the_fix():
    with pytest.raises(TypeError, match="SimounObservation"):
        RNDReward(gym.make("MiniGrid-Empty-5x5-v0"), Brightness())
    with pytest.raises(TypeError, match=r"NoveltySource.*got str"):
        RNDReward(pixels(), novelty="rnd")
    with pytest.raises(ValueError, match=r"scale must be a finite number >= 0"):
        RNDReward(pixels(), Brightness(), scale=-1.0)
    with pytest.raises(ValueError, match=r"warmup must be an int >= 0.*warmup=1024"):
        RNDVectorReward(make_vec(1, AutoresetMode.NEXT_STEP), Brightness(), warmup=-1)
    with pytest.raises(ValueError, match=r"RND's convolutions need H, W >= 36.*size=42"):
        RNDModel((3, 32, 32), config=RNDConfig(encoder_size=None))
    with pytest.raises(ValueError, match=r"batch_size <= learning_starts <= capacity"):
        RNDConfig(batch_size=64, learning_starts=32)
    # a FeatureSource is callable too; its (f_m, f_a) output is named as the mistake
    env = RNDReward(pixels(), lambda triplets: (np.zeros((1, 4)), np.zeros((1, 3, 4))))
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"function returned a tuple for 1 triplets.*goes with"):
        env.step(0)
    for errors, problem in (
        ([0.1, 0.2], r"returned shape \(2,\) for 1 triplets"),
        ([-0.1], r"source function returned \[-0.1\]: errors must be >= 0"),
        ([np.nan], r"RNDSignal gave the non-finite intrinsic value nan at transition 0"),
    ):
        env = RNDReward(pixels(), lambda triplets, errors=errors: np.array(errors))
        env.reset(seed=0)
        with pytest.raises(ValueError, match=problem):
            env.step(0)
    env = RNDReward(pixels(), lambda triplets: np.zeros(len(triplets)), warmup=0)
    env.reset(seed=0)
    assert env.step(0)[4]["reward_intrinsic"] == 0.0  # a zero error is an error like any


@pytest.mark.parametrize(
    ("novelty", "said"),
    [
        (lambda: 0.0, r"signature \(\) does not take \(too many positional arguments\)"),
        (lambda a, b: a, r"signature \(a, b\) does not take \(missing a required argument: 'b'\)"),
    ],
)
def test_a_novelty_source_that_cannot_take_the_triplets_is_refused_when_built(novelty, said):
    start = r"^novelty is called as novelty\(triplets\), which its "
    with pytest.raises(TypeError, match=start + said):
        RNDReward(pixels(), novelty, warmup=0)
    with pytest.raises(TypeError, match=r"it must take one argument .*RNDModel.for_env\(env\)"):
        RNDVectorReward(make_vec(1, AutoresetMode.NEXT_STEP), novelty, warmup=0)


def test_sources_whose_signature_takes_the_triplets_are_accepted():
    # a partial, a builtin-backed callable, an optional second argument and a model all bind
    for novelty in (
        functools.partial(np.mean, axis=(1, 2, 3, 4)),
        lambda triplets, scale=1.0: np.zeros(len(triplets)),
        Brightness(),
        RNDModel.for_env(pixels(), RNDConfig(**TINY, background=False), device="cpu"),
    ):
        env = RNDReward(pixels(), novelty, warmup=0)
        env.reset(seed=0)
        env.step(0)
        env.close()
