"""The intrinsic reward's normalizations (simoun_wrappers.intrinsic_normalization) by value on
hand-computed numbers, their guards, and each of them through the wrappers on real envs
(CartPole's pixels, MiniGrid), with the NovelD progress variant and the constant bonus."""

import gc
import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, SyncVectorEnv

from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity import consistency_reward
from simoun_wrappers.curiosity_reward import ConsistencyCuriosityReward
from simoun_wrappers.intrinsic_normalization import (
    NORMALIZATIONS,
    PaperMaxima,
    Raw,
    ReturnStd,
    RewardStd,
    Standardize,
    make_normalization,
)
from simoun_wrappers.intrinsic_reward import ConstantBonusReward, ConstantBonusVectorReward
from simoun_wrappers.rnd import RNDReward, RNDVectorReward

ALL = np.ones(3, dtype=bool)
ENV0 = np.zeros(3, dtype=np.int64)


def pstd(values) -> float:
    """Population standard deviation by hand."""
    mean = sum(values) / len(values)
    return math.sqrt(sum((v - mean) ** 2 for v in values) / len(values))


def test_paper_is_the_raw_value_times_r_e_max_over_r_i_max_raised_first():
    norm = PaperMaxima(r_e_max_init=1.0, r_i_max_init=1.0)
    out = norm(np.array([0.5, 2.0, 1.0]), np.array([0.0, -3.0, 1.0]), ENV0, ALL)
    # maxima raised with the batch first: r_e_max = |-3| = 3, r_i_max = 2
    np.testing.assert_allclose(out, [0.5 * 3 / 2, 2.0 * 3 / 2, 1.0 * 3 / 2])
    out = norm(np.array([4.0]), np.array([0.0]), np.zeros(1, int), np.ones(1, bool))
    np.testing.assert_allclose(out, [4.0 * 3 / 4])
    # rows outside the count are normalized but do not raise the maxima
    out = norm(np.array([8.0]), np.array([9.0]), np.zeros(1, int), np.zeros(1, bool))
    np.testing.assert_allclose(out, [8.0 * 3 / 4])
    assert norm.state_dict() == {"r_e_max": 3.0, "r_i_max": 4.0}


def test_reward_std_divides_by_the_std_of_the_raw_values_without_centring():
    norm = RewardStd()
    out = norm(np.array([1.0, 2.0, 6.0]), np.zeros(3), ENV0, ALL)
    np.testing.assert_allclose(out, np.array([1.0, 2.0, 6.0]) / pstd([1, 2, 6]))
    out = norm(np.array([3.0]), np.zeros(1), np.zeros(1, int), np.ones(1, bool))
    np.testing.assert_allclose(out, [3.0 / pstd([1, 2, 6, 3])])


def test_standardize_subtracts_the_running_mean_and_divides_by_the_std():
    norm = Standardize()
    out = norm(np.array([1.0, 2.0, 6.0]), np.zeros(3), ENV0, ALL)
    np.testing.assert_allclose(out, (np.array([1.0, 2.0, 6.0]) - 3.0) / pstd([1, 2, 6]))
    assert abs(out.sum()) < 1e-12  # zero mean over what it has seen
    out = norm(np.array([5.0]), np.zeros(1), np.zeros(1, int), np.ones(1, bool))
    np.testing.assert_allclose(out, [(5.0 - 3.5) / pstd([1, 2, 6, 5])])


def test_return_std_keeps_one_discounted_return_per_sub_env_never_reset():
    norm = ReturnStd(gamma=0.9)
    envs = np.array([0, 1])
    out = norm(np.array([1.0, 3.0]), np.zeros(2), envs, np.ones(2, bool))
    # R_0 = 1, R_1 = 3: std of the returns [1, 3] is 1
    np.testing.assert_allclose(out, [1.0, 3.0])
    out = norm(np.array([2.0, 0.0]), np.zeros(2), envs, np.ones(2, bool))
    # R_0 = 0.9 * 1 + 2 = 2.9, R_1 = 0.9 * 3 + 0 = 2.7: returns seen [1, 3, 2.9, 2.7]
    np.testing.assert_allclose(norm.returns, [2.9, 2.7])
    np.testing.assert_allclose(out, np.array([2.0, 0.0]) / pstd([1, 3, 2.9, 2.7]))
    # only sub-env 1 this time (sub-env 0 is resetting): R_1 = 0.9 * 2.7 + 1 = 3.43
    out = norm(np.array([1.0]), np.zeros(1), np.array([1]), np.ones(1, bool))
    np.testing.assert_allclose(norm.returns, [2.9, 3.43])
    np.testing.assert_allclose(out, [1.0 / pstd([1, 3, 2.9, 2.7, 3.43])])


def test_a_std_of_zero_gives_zero_not_a_division_by_zero():
    for cls in (RewardStd, Standardize, ReturnStd):
        norm = cls()
        out = norm(np.array([2.0]), np.zeros(1), np.zeros(1, int), np.ones(1, bool))
        np.testing.assert_array_equal(out, [0.0])  # one value: no spread yet
        out = norm(np.array([2.0, 2.0, 2.0]), np.zeros(3), ENV0, ALL)
        assert np.all(np.isfinite(out))


def test_state_dicts_round_trip():
    for name in NORMALIZATIONS:
        norm, clone = make_normalization(name), make_normalization(name)
        norm(np.array([1.0, 2.0, 5.0]), np.array([0.0, 1.0, 0.0]), np.array([0, 1, 2]), ALL)
        clone.load_state_dict(norm.state_dict())
        batch = (np.array([3.0, 0.5, 1.0]), np.zeros(3), np.array([0, 1, 2]), ALL)
        np.testing.assert_array_equal(clone(*batch), norm(*batch))


def test_bad_names_and_values_are_refused_with_the_fix():
    with pytest.raises(ValueError, match=r"'standardise'.*did you mean 'standardize'"):
        make_normalization("standardise")
    with pytest.raises(ValueError, match=r"gamma must be a number in \[0, 1\)"):
        ReturnStd(gamma=1.0)
    with pytest.raises(ValueError, match="r_i_max_init must be a finite number > 0"):
        PaperMaxima(r_i_max_init=0.0)
    assert isinstance(make_normalization(Raw()), Raw)


def cartpole() -> gym.Env:
    return SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=16)


class Brightness:
    """A novelty source by hand: the newest frame's mean pixel value / 255."""

    def __call__(self, triplets):
        return triplets[:, -1].reshape(len(triplets), -1).mean(axis=1) / 255.0


class Features:
    """A feature source by hand: f_m the newest frame's mean / 255, f_a zeros, so d = f_m."""

    def __call__(self, triplets):
        newest = triplets[:, -1].reshape(len(triplets), -1).mean(axis=1, keepdims=True) / 255
        return newest.astype(np.float32), np.zeros((len(triplets), 3, 1), np.float32)


def test_the_paper_form_through_the_wrapper_is_eq13():
    env = ConsistencyCuriosityReward(cartpole(), Features(), scale=0.3, decay=1e-2)
    env.reset(seed=0)
    r_i_max = 1.0
    for t in range(6):
        obs, _, _, _, info = env.step(t % 2)
        d = float(Features()(obs["frames"][None])[0][0, 0])
        r_i_max = max(r_i_max, d)
        expected = consistency_reward(np.array([d]), t, 1.0, r_i_max, 0.3, 1e-2)[0]
        assert info["reward_intrinsic"] == pytest.approx(expected, rel=1e-6)


def test_each_normalization_through_the_wrapper_by_hand():
    """The wrapper's reward is scale * exp(-decay t) * normalize(raw), every normalization."""
    for name in ("standardize", "return_std", "reward_std", "none"):
        env = RNDReward(cartpole(), Brightness(), scale=0.5, warmup=0, normalization=name)
        hand = make_normalization(name)
        env.reset(seed=1)
        for t in range(5):
            obs, _, _, _, info = env.step(t % 2)
            raw = Brightness()(obs["frames"][None])
            expected = 0.5 * hand(raw, np.ones(1), np.zeros(1, int), np.ones(1, bool))[0]
            assert info["reward_intrinsic"] == pytest.approx(expected, rel=1e-9, abs=1e-12), name


def test_standardize_lets_a_still_agent_earn_nothing_on_average():
    """The property the on-policy forms are for: on a MiniGrid task, an agent that stands still
    (turning in place, the frames repeat) earns far less than the goal's reward with the
    zero-mean form, where the paper's form pays it every step."""
    pytest.importorskip("minigrid")
    from minigrid.wrappers import ImgObsWrapper, RGBImgPartialObsWrapper

    def still_sum(normalization: str, scale: float) -> float:
        env = gym.make("MiniGrid-Empty-5x5-v0")
        env = SimounObservation(ImgObsWrapper(RGBImgPartialObsWrapper(env)), size=16)
        env = RNDReward(env, Brightness(), scale=scale, warmup=0, normalization=normalization)
        env.reset(seed=0)
        rng = np.random.default_rng(0)
        for _ in range(60):  # a random walk sets the statistics
            _, _, terminated, truncated, _ = env.step(int(rng.integers(3)))
            if terminated or truncated:
                env.reset()
        earned = 0.0
        env.reset(seed=1)
        for _ in range(40):  # then stand still: 'toggle' on an empty cell changes nothing
            _, _, terminated, truncated, info = env.step(5)
            earned += info["reward_intrinsic"]
            assert not terminated
        return earned

    assert still_sum("paper", 0.2) > 1.0  # the survival bonus: more than the goal's reward
    assert abs(still_sum("standardize", 0.01)) < 1.0


def test_progress_pays_only_for_a_rise_in_novelty():
    """NovelD: max(x(s') - alpha x(s), 0), with x of the previous and the reached triplet."""
    env = RNDReward(cartpole(), Brightness(), scale=1.0, warmup=0, normalization="none",
                    progress=0.5)  # fmt: skip
    obs, _ = env.reset(seed=0)
    for t in range(5):
        before = Brightness()(obs["frames"][None])[0]
        obs, _, _, _, info = env.step(t % 2)
        after = Brightness()(obs["frames"][None])[0]
        assert info["reward_intrinsic"] == pytest.approx(max(after - 0.5 * before, 0.0))
    with pytest.raises(ValueError, match=r"progress must be None or a number in \(0, 1\]"):
        RNDReward(cartpole(), Brightness(), progress=2.0)


def test_a_non_finite_intrinsic_value_stops_with_the_step_and_the_value():
    class Diverging(Brightness):
        calls = 0

        def __call__(self, triplets):
            self.calls += 1
            values = super().__call__(triplets)
            return values * np.inf if self.calls > 3 else values

    env = RNDReward(cartpole(), Diverging(), warmup=0)
    env.reset(seed=0)
    for _ in range(3):
        env.step(0)
    with pytest.raises(ValueError, match=r"non-finite intrinsic value inf at transition 3"):
        env.step(0)


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_the_constant_bonus_pays_its_scale_on_every_scored_step(mode):
    env = ConstantBonusReward(cartpole(), scale=0.07)
    env.reset(seed=0)
    _, reward, *_, info = env.step(0)
    assert info["reward_intrinsic"] == 0.07 and reward == pytest.approx(1.07)
    envs = ConstantBonusVectorReward(
        SyncVectorEnv([cartpole, cartpole], autoreset_mode=mode), scale=0.07
    )
    envs.reset(seed=[0, 1])
    ended = np.zeros(2, dtype=bool)
    for _ in range(30):
        _, _, terminated, truncated, info = envs.step(np.array([0, 0]))
        skipped = ended if mode == AutoresetMode.NEXT_STEP else np.zeros(2, dtype=bool)
        np.testing.assert_array_equal(info["reward_intrinsic"], np.where(skipped, 0.0, 0.07))
        ended = terminated | truncated
    with pytest.raises(ValueError, match="scale must be a finite number >= 0"):
        ConstantBonusReward(cartpole(), scale=-1.0)


def test_return_std_in_a_vector_env_follows_each_sub_env():
    envs = RNDVectorReward(
        SyncVectorEnv([cartpole, cartpole], autoreset_mode=AutoresetMode.NEXT_STEP),
        Brightness(),
        scale=1.0,
        warmup=0,
        normalization=ReturnStd(gamma=0.5),
    )
    obs, _ = envs.reset(seed=[0, 1])
    hand = ReturnStd(gamma=0.5)
    for t in range(4):
        obs, _, _, _, info = envs.step(np.array([t % 2, 1 - t % 2]))
        raw = Brightness()(obs["frames"])
        expected = hand(raw, np.ones(2), np.array([0, 1]), np.ones(2, bool))
        np.testing.assert_allclose(info["reward_intrinsic"], expected, rtol=1e-12)
    np.testing.assert_allclose(envs.normalization.returns, hand.returns)


@pytest.mark.parametrize(
    ("normalization", "state", "said"),
    [
        (Standardize(), {}, "lack mean, var, count"),
        (Standardize(), None, "a NoneType, not a dict"),
        (ReturnStd(), {"r_e_max": 1.0, "r_i_max": 1.0}, "saved with normalization 'paper'"),
        (PaperMaxima(), {"r_e_max": float("nan"), "r_i_max": 1.0}, "r_e_max is nan"),
        (PaperMaxima(), {"r_e_max": 0.0, "r_i_max": 1.0}, "r_e_max is 0.0, not > 0"),
        (
            ReturnStd(),
            {"mean": 0.0, "var": 1.0, "count": 2.0, "returns": ["a"]},
            "returns is ['a'], not a list of finite numbers",
        ),
    ],
)
def test_a_normalization_refuses_a_state_that_does_not_fit_and_keeps_its_own(
    normalization, state, said
):
    before = normalization.state_dict()
    with pytest.raises(ValueError, match="cannot load this state") as error:
        normalization.load_state_dict(state)
    assert said in str(error.value) and "Nothing was loaded" in str(error.value)
    assert normalization.state_dict() == before


def test_a_normalization_loads_its_own_state():
    source = ReturnStd(gamma=0.5)
    source(np.array([2.0, 4.0]), np.zeros(2), np.array([0, 1]), np.ones(2, bool))
    copy = ReturnStd(gamma=0.5)
    copy.load_state_dict(source.state_dict())
    assert copy.state_dict() == source.state_dict()


@pytest.mark.parametrize("gamma", [np.float32(0.99), np.float64(0.5), np.int64(0), 0])
def test_return_std_takes_numpy_scalars_as_numbers(gamma):
    assert ReturnStd(gamma=gamma).gamma == float(gamma)


@pytest.mark.parametrize("gamma", [False, True, np.bool_(False), "0.99", float("nan"), np.inf])
def test_return_std_refuses_a_bool_a_string_and_a_non_finite_gamma(gamma):
    with pytest.raises(ValueError, match=r"gamma must be a number in \[0, 1\)"):
        ReturnStd(gamma=gamma)


def test_an_instance_of_the_paper_form_means_what_its_name_means():
    by_name = ConsistencyCuriosityReward(cartpole(), Features(), normalization="paper")
    by_instance = ConsistencyCuriosityReward(cartpole(), Features(), normalization=PaperMaxima())
    assert by_instance.decay == by_name.decay == 2e-5
    other = ConsistencyCuriosityReward(cartpole(), Features(), normalization=ReturnStd())
    assert other.decay == 0.0


def test_initial_maxima_are_applied_by_the_paper_name_and_refused_where_unused():
    env = ConsistencyCuriosityReward(cartpole(), Features(), r_e_max_init=5.0)
    assert env.state_dict()["normalization"] == {"r_e_max": 5.0, "r_i_max": 1.0}
    with pytest.raises(ValueError) as error:
        ConsistencyCuriosityReward(
            cartpole(), Features(), normalization=PaperMaxima(), r_e_max_init=5.0
        )
    said = str(error.value)
    assert "r_e_max_init=5.0" in said and "PaperMaxima(r_e_max_init=1.0" in said
    assert "normalization=PaperMaxima(r_e_max_init=5.0)" in said
    with pytest.raises(ValueError, match=r"r_i_max_init=0\.5 is used by normalization='paper'"):
        ConsistencyCuriosityReward(
            cartpole(), Features(), normalization="reward_std", r_i_max_init=0.5
        )


def return_std_envs(num_envs: int) -> RNDVectorReward:
    envs = SyncVectorEnv([cartpole] * num_envs, autoreset_mode=AutoresetMode.NEXT_STEP)
    return RNDVectorReward(envs, Brightness(), warmup=0, normalization="return_std")


def test_a_return_std_state_loads_only_into_as_many_sub_envs():
    two = return_std_envs(2)
    two.reset(seed=0)
    two.step(np.array([0, 1]))
    three = return_std_envs(3)
    before = three.state_dict()
    with pytest.raises(ValueError) as error:
        three.load_state_dict(two.state_dict())
    said = str(error.value)
    assert "returns holds 2 values, one per sub-env" in said and "num_envs=3" in said
    assert three.state_dict() == before
    single = RNDReward(cartpole(), Brightness(), warmup=0, normalization="return_std")
    with pytest.raises(ValueError, match="this wrapper has 1 sub-env "):
        single.load_state_dict(two.state_dict())
    again = return_std_envs(2)
    again.load_state_dict(two.state_dict())  # as many sub-envs, or a state before any step
    again.load_state_dict(return_std_envs(2).state_dict())


def test_an_instance_held_by_one_wrapper_is_refused_by_another():
    # a training and an evaluation env on one instance would mix their running statistics
    norm = ReturnStd(gamma=0.999)
    train = RNDReward(cartpole(), Brightness(), normalization=norm)
    with pytest.raises(ValueError, match=r"normalization=ReturnStd\(gamma=0.999\).*'return_std'"):
        RNDReward(cartpole(), Brightness(), normalization=norm)
    assert train.normalization is norm
    # the spec deep-copies the instance, so re-making the wrapper gives it its own
    assert gym.make(train.spec).normalization is not norm
    del train
    gc.collect()
    assert RNDReward(cartpole(), Brightness(), normalization=norm).normalization is norm


def test_an_instance_without_statistics_may_serve_several_wrappers():
    bonus = Raw()
    first = RNDReward(cartpole(), Brightness(), normalization=bonus)
    second = RNDReward(cartpole(), Brightness(), normalization=bonus)
    assert first.normalization is second.normalization is bonus


def test_a_normalization_of_the_wrong_type_is_refused_naming_the_names():
    with pytest.raises(ValueError, match=r"normalization=\['none'\] is not one of .*'return_std'"):
        RNDReward(cartpole(), Brightness(), normalization=["none"])


@pytest.mark.parametrize("cls", list(NORMALIZATIONS.values()))
@pytest.mark.parametrize(
    ("envs", "counted", "error", "said"),
    [
        (np.array([0.0, 1.0, 0.0]), ALL, TypeError, "envs must be the sub-env index"),
        (np.array([0, -1, 0]), ALL, TypeError, "envs must be the sub-env index"),
        (ENV0, np.array([1, 1, 0]), TypeError, "counted must be a bool mask"),
        (ENV0, np.ones(2, bool), ValueError, r"counted must have shape \(3,\) like raw"),
    ],
)
def test_a_normalization_called_directly_checks_its_arguments_naming_them(
    cls, envs, counted, error, said
):
    # a 0/1 int mask would fancy-index rows 1, 1, 0 and raise the statistics with wrong rows
    call = rf"{cls.__name__}\(\)\(raw, extrinsic, envs, counted\)"
    with pytest.raises(error, match=rf"{call}: {said}"):
        cls()(np.array([1.0, 3.0, 2.0]), np.zeros(3), envs, counted)
    assert cls()(np.array([1.0, 3.0, 2.0]), np.zeros(3), ENV0, ALL).shape == (3,)
