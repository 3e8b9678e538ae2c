"""simoun_lab.stats against hand-worked examples and against the rliable package itself
(Agarwal et al. 2021) on the same scores: the same point estimates and, since the resampling
draws rliable's indices from the same seeded stream, the same bootstrap intervals."""

import numpy as np
import pytest
from rliable import library as rly
from rliable import metrics

from simoun_lab import stats


def as_tasks(matrix):
    """rliable's runs x tasks matrix as simoun's task -> runs mapping."""
    return {f"task{j}": matrix[:, j] for j in range(matrix.shape[1])}


def seed_rliable(seed):
    """rliable's bootstrap draws its indices from numpy's global generator: seeding that is how
    an rliable result is made reproducible."""
    np.random.seed(seed)  # noqa: NPY002


def rliable_ci(scores, func, seed, reps=2000):
    """rliable's point estimate and 95 % percentile interval."""
    seed_rliable(seed)
    point, interval = rly.get_interval_estimates({"x": scores}, func, reps=reps)
    return float(np.ravel(point["x"])[0]), *np.ravel(interval["x"])


def test_iqm_by_hand():
    assert stats.iqm(np.arange(1.0, 9.0)) == 4.5  # (3 + 4 + 5 + 6) / 4
    assert stats.iqm(np.array([1.0, 2.0, 3.0, 100.0])) == 2.5  # 1 and 100 cut
    assert stats.iqm(np.array([1.0, 2.0, 9.0])) == 4.0  # int(0.75) = 0 cut: the mean
    five = np.array([0.0, 10.0, 20.0, 30.0, 1000.0])
    assert stats.iqm(five) == 20.0  # one cut at each end
    tasks = {"a": np.array([1.0, 2.0, 3.0, 4.0]), "b": np.array([5.0, 6.0, 7.0, 8.0])}
    assert stats.aggregate_iqm(tasks) == 4.5  # over all 8 runs of both tasks
    with pytest.raises(ValueError, match="at least one run"):
        stats.iqm(np.zeros(0))


@pytest.mark.parametrize("shape", [(3, 1), (5, 2), (8, 3), (10, 5)])
def test_iqm_equals_rliable(shape):
    matrix = np.random.default_rng(sum(shape)).normal(size=shape)
    assert stats.aggregate_iqm(as_tasks(matrix)) == pytest.approx(metrics.aggregate_iqm(matrix))
    assert stats.aggregate_mean(as_tasks(matrix)) == pytest.approx(metrics.aggregate_mean(matrix))


@pytest.mark.parametrize(("runs", "tasks", "seed"), [(3, 1, 0), (5, 3, 11), (10, 2, 4)])
def test_bootstrap_intervals_equal_rliable(runs, tasks, seed):
    matrix = np.random.default_rng(seed).uniform(size=(runs, tasks))
    ours = stats.stratified_bootstrap_ci(as_tasks(matrix), stats.aggregate_iqm, seed=seed)
    theirs = rliable_ci(matrix, lambda s: np.array([metrics.aggregate_iqm(s)]), seed)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
    ours = stats.stratified_bootstrap_ci(as_tasks(matrix), stats.aggregate_mean, seed=seed)
    theirs = rliable_ci(matrix, lambda s: np.array([metrics.aggregate_mean(s)]), seed)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
    assert ours[1] < ours[0] < ours[2]


def test_bootstrap_is_stratified_and_seeded():
    """Resamples draw each task's runs from that task only, keeping its number of runs; the
    same seed gives the same interval, another seed another one."""
    scores = {"low": np.array([0.0, 0.5, 1.0]), "high": np.array([10.0, 10.5, 11.0, 11.5, 12.0])}
    replicates = stats.bootstrap_replicates(
        scores, lambda s: [s["low"].max(), s["high"].min(), len(s["low"]), len(s["high"])], 500
    )
    assert replicates[:, 0].max() <= 1.0 and replicates[:, 1].min() >= 10.0
    assert set(replicates[:, 2]) == {3} and set(replicates[:, 3]) == {5}
    first = stats.stratified_bootstrap_ci(scores, stats.aggregate_iqm, seed=1)
    assert stats.stratified_bootstrap_ci(scores, stats.aggregate_iqm, seed=1) == first
    other = stats.bootstrap_replicates(scores, stats.aggregate_iqm, 500, seed=2)
    assert not np.array_equal(other, stats.bootstrap_replicates(scores, stats.aggregate_iqm, 500))
    constant = stats.stratified_bootstrap_ci({"t": np.full(4, 0.3)}, stats.aggregate_iqm)
    assert constant == pytest.approx((0.3, 0.3, 0.3))


def test_probability_of_improvement_by_hand():
    x = {"a": np.array([2.0, 3.0]), "b": np.array([5.0, 6.0])}
    y = {"a": np.array([1.0, 3.0]), "b": np.array([7.0])}
    # task a: 2>1, 2<3, 3>1, 3=3 (a half) -> 2.5 / 4; task b: both below 7 -> 0
    assert stats.probability_of_improvement(x, y) == pytest.approx((2.5 / 4 + 0.0) / 2)
    assert stats.probability_of_improvement(y, x) == pytest.approx((1.5 / 4 + 1.0) / 2)
    assert stats.probability_of_improvement(x, x) == 0.5
    with pytest.raises(ValueError, match=r"same tasks.*\['b'\]"):
        stats.probability_of_improvement(x, {"a": y["a"]})


def test_probability_of_improvement_and_its_interval_equal_rliable():
    rng = np.random.default_rng(3)
    # rounded so that ties occur, as they do between equal evaluation returns
    x, y = rng.uniform(size=(5, 3)).round(1), rng.uniform(size=(4, 3)).round(1)
    assert stats.probability_of_improvement(as_tasks(x), as_tasks(y)) == pytest.approx(
        metrics.probability_of_improvement(x, y)
    )
    seed_rliable(9)
    point, interval = rly.get_interval_estimates(
        {"x,y": [x, y]},
        lambda a, b: np.array([metrics.probability_of_improvement(a, b)]),
        reps=500,  # scipy's Mann-Whitney test in rliable takes 2 ms a resample
    )
    ours = stats.probability_of_improvement_ci(as_tasks(x), as_tasks(y), reps=500, seed=9)
    theirs = (float(np.ravel(point["x,y"])[0]), *np.ravel(interval["x,y"]))
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)


def test_difference_of_iqms_and_its_interval_equal_rliable():
    rng = np.random.default_rng(4)
    x, y = rng.uniform(size=(5, 2)), rng.uniform(size=(4, 2))
    seed_rliable(7)
    point, interval = rly.get_interval_estimates(
        {"x,y": [x, y]},
        lambda a, b: np.array([metrics.aggregate_iqm(a) - metrics.aggregate_iqm(b)]),
        reps=300,
    )
    ours = stats.difference_ci(as_tasks(x), as_tasks(y), reps=300, seed=7)
    theirs = (float(np.ravel(point["x,y"])[0]), *np.ravel(interval["x,y"]))
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
    # by hand: IQM of 5 runs x 2 tasks cuts 2 of 10 at each end, of 4 x 2 cuts 2 of 8
    assert ours[0] == pytest.approx(np.sort(x.ravel())[2:8].mean() - np.sort(y.ravel())[2:6].mean())


def test_performance_profile_and_its_band_equal_rliable():
    matrix = np.random.default_rng(5).uniform(size=(6, 2))
    taus = np.linspace(0.0, 1.0, 21)
    seed_rliable(2)
    profile, band = rly.create_performance_profile({"x": matrix}, taus, reps=2000)
    point, low, high = stats.stratified_bootstrap_band(
        as_tasks(matrix), lambda s: stats.performance_profile(s, taus), seed=2
    )
    np.testing.assert_allclose(point, profile["x"], atol=1e-12)
    np.testing.assert_allclose(np.stack([low, high]), band["x"], atol=1e-12)
    by_hand = stats.performance_profile({"t": np.array([0.1, 0.5, 0.9])}, np.array([0.0, 0.5]))
    np.testing.assert_array_equal(by_hand, [1.0, 1 / 3])  # strictly above tau


def test_iqm_over_steps_is_the_iqm_at_each_step():
    curves = {"t": np.array([[0.0, 1.0], [1.0, 2.0], [2.0, 3.0], [9.0, 30.0]])}
    np.testing.assert_array_equal(stats.iqm_over_steps(curves), [1.5, 2.5])


def test_normalize_divides_dm_control_returns_by_1000_and_leaves_others():
    returns = np.array([250.0, 1000.0])
    np.testing.assert_array_equal(
        stats.normalize("dm_control/cartpole-swingup-v0", returns), [0.25, 1.0]
    )
    np.testing.assert_array_equal(stats.normalize("simoun/PointReach-v0", returns), returns)
    assert stats.max_return("simoun/PointReach-v0") is None


CURVES = np.array([[0.1, 0.5, 0.7], [0.2, 0.4, 0.6]])
"""Two runs' learning curves over three evaluation steps."""


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda: stats.aggregate_iqm(np.array([0.7, 0.65])), TypeError, r"scores must be a dict"),
        (lambda: stats.aggregate_mean([0.7]), TypeError, r"aggregate_mean\(\{'cheetah-run'"),
        (lambda: stats.aggregate_iqm({}), ValueError, r"scores has no tasks"),
        (lambda: stats.aggregate_mean({"t": []}), ValueError, r"\['t'\] has no runs"),
        (lambda: stats.aggregate_iqm({"t": 0.5}), ValueError, r"\{task: \[score\]\}"),
        (lambda: stats.aggregate_iqm({"t": ["a"]}), TypeError, r"\['t'\] must be an array of n"),
        (lambda: stats.aggregate_iqm({"t": CURVES}), ValueError, r"\[:, -1\]"),
        (
            lambda: stats.probability_of_improvement({"t": CURVES}, {"t": [1.0, 2.0]}),
            ValueError,
            r"x\['t'\] must be a 1-D array.*if these are learning curves",
        ),
        (
            lambda: stats.probability_of_improvement({"t": [1.0]}, {"t": CURVES}),
            ValueError,
            r"y\['t'\] must be a 1-D array",
        ),
        (
            lambda: stats.iqm_over_steps({"t": [1.0, 2.0, 3.0]}),
            ValueError,
            r"must be a 2-D array of learning curves.*looks like final scores",
        ),
        (
            lambda: stats.iqm_over_steps({"a": CURVES, "b": CURVES[:, :2]}),
            ValueError,
            r"one step grid.*\{'a': 3, 'b': 2\}.*\[:, :2\]",
        ),
        (
            lambda: stats.performance_profile({"t": [0.2, 0.6]}, 0.5),
            ValueError,
            r"taus must be a 1-D array.*taus=np.array\(\[0.5\]\)",
        ),
        (
            lambda: stats.normalize(np.array([500.0]), "dm_control/cheetah-run-v0"),
            TypeError,
            r"normalize\('dm_control/cheetah-run-v0', returns\)",
        ),
        (lambda: stats.normalize("Pendulum-v1", "500"), TypeError, r"returns must be an array"),
        (lambda: stats.iqm({"t": [1.0]}), TypeError, r"use aggregate_iqm\(scores\)"),
        (
            lambda: stats.iqm_over_steps({"t": [[0.1, 0.2, 0.3], [0.1, 0.2]]}),
            ValueError,
            r"scores\['t'\] has runs of different lengths \(\[3, 2\] values\).*\[:2\]",
        ),
        (
            lambda: stats.aggregate_iqm({"simoun": np.zeros((5, 3))}),
            ValueError,
            r"5 runs over 3 steps.*\[:, -1\].*rliable's matrix of 5 runs x 3 tasks.*m\[:, j\]",
        ),
        (
            lambda: stats.aggregate_iqm({"t": np.array([[0.5], [0.6], [0.7]])}),
            ValueError,
            r"np\.ravel\(r\)",
        ),
    ],
)
def test_scores_of_the_wrong_kind_are_refused_naming_the_argument(call, error, message):
    with pytest.raises(error, match=message):
        call()


@pytest.mark.parametrize(
    "call",
    [
        lambda: stats.iqm([0.7, float("nan"), 0.72, 0.8]),
        lambda: stats.aggregate_iqm({"t": [0.7, float("inf")]}),
        lambda: stats.aggregate_mean({"t": [float("nan")]}),
        lambda: stats.probability_of_improvement({"t": [1.0, float("nan")]}, {"t": [0.5, 0.6]}),
        lambda: stats.iqm_over_steps({"t": np.where(CURVES > 0.6, np.nan, CURVES)}),
        lambda: stats.stratified_bootstrap_ci({"t": [1.0, float("nan")]}, stats.aggregate_iqm),
    ],
)
def test_non_finite_scores_are_refused(call):
    """A NaN sorts last (the IQM trims it as the best run) and compares as a loss: refused."""
    with pytest.raises(ValueError, match=r"NaN or infinite value.*np.isfinite"):
        call()


SCORES = {"t": np.arange(8.0)}


@pytest.mark.parametrize(
    ("arguments", "error", "message"),
    [
        (
            {"reps": 0},
            ValueError,
            r"reps \(the number of bootstrap resamples\) must be an int >= 1",
        ),
        ({"reps": 2.5}, TypeError, r"reps .* must be an int >= 1, got float 2.5; e.g. reps=2000"),
        ({"seed": -1}, ValueError, r"seed must be an int in \[0, 4294967295\].*seed=0"),
        ({"seed": "0"}, TypeError, r"seed must be an int"),
        ({"confidence": "95%"}, TypeError, r"confidence must be a number in \(0, 1\)"),
        ({"confidence": 95}, ValueError, r"looks like a percent: confidence=0.95"),
        ({"statistic": "iqm"}, TypeError, r"statistic must be a function.*stats.aggregate_iqm"),
        ({"statistic": stats.iqm}, TypeError, r"statistic\(scores\) \(iqm\).*aggregate_iqm"),
        ({"statistic": stats.iqm_over_steps}, ValueError, r"iqm_over_steps: scores\['t'\]"),
        (
            {"statistic": lambda s: stats.performance_profile(s, np.array([1.0, 2.0]))},
            ValueError,
            r"returns one number.*stratified_bootstrap_band",
        ),
    ],
)
def test_bootstrap_arguments_are_checked(arguments, error, message):
    arguments = {"statistic": stats.aggregate_iqm, **arguments}
    with pytest.raises(error, match=message):
        stats.stratified_bootstrap_ci(SCORES, **arguments)


@pytest.mark.parametrize(
    "call",
    [
        lambda: stats.probability_of_improvement_ci(SCORES, SCORES, reps=0),
        lambda: stats.difference_ci(SCORES, SCORES, reps=1.0),
        lambda: stats.bootstrap_replicates(SCORES, stats.aggregate_iqm, reps=-3),
        lambda: stats.stratified_bootstrap_band(SCORES, stats.aggregate_iqm, reps=True),
    ],
)
def test_every_resampling_function_checks_reps(call):
    with pytest.raises((TypeError, ValueError), match=r"reps .* must be an int >= 1"):
        call()


def test_valid_scores_in_other_forms_still_work():
    """Lists, numpy integers and a task of one run stay accepted."""
    assert stats.aggregate_iqm({"t": [1, 2, 3, 4]}) == 2.5
    assert stats.aggregate_mean({"a": [1.0], "b": (3.0, 5.0)}) == 2.5
    assert stats.stratified_bootstrap_ci({"t": [0.3]}, stats.aggregate_iqm, reps=np.int64(10))[
        0
    ] == pytest.approx(0.3)
    np.testing.assert_allclose(stats.iqm_over_steps({"t": CURVES.tolist()}), [0.15, 0.45, 0.65])
    assert stats.performance_profile({"t": [0.2, 0.6]}, [0.5]).tolist() == [0.5]


@pytest.mark.parametrize(
    ("replicates", "error", "message"),
    [
        (np.array([]), ValueError, r"replicates must hold at least one resample"),
        (np.array(0.5), ValueError, r"replicates must hold at least one resample"),
        (np.array([0.1, np.nan, 0.3]), ValueError, r"replicates has 1 NaN"),
        ((0.57, 0.2, 0.88), TypeError, r"interval \(point, low, high\).*bootstrap_replicates"),
        ({"t": [0.1]}, TypeError, r"replicates must be an array of numbers"),
    ],
)
def test_percentile_interval_checks_its_replicates(replicates, error, message):
    with pytest.raises(error, match=message):
        stats.percentile_interval(replicates)


def test_percentile_interval_takes_replicates_and_refuses_an_interval():
    scores = {"t": [0.2, 0.6, 0.9]}
    low, high = stats.percentile_interval(stats.bootstrap_replicates(scores, stats.aggregate_iqm))
    assert low <= high
    with pytest.raises(TypeError, match="stratified_bootstrap_ci returns it"):
        stats.percentile_interval(stats.stratified_bootstrap_ci(scores, stats.aggregate_iqm))


@pytest.mark.parametrize(
    ("env_id", "message"),
    [
        (
            "cheetah-run",
            r"'cheetah-run' is not an env id.*did you mean 'dm_control/cheetah-run-v0'",
        ),
        ("cheetah-run-v0", r"did you mean 'dm_control/cheetah-run-v0'"),
        ("no-such-task", r"'no-such-task' is not an env id.*'dm_control/'"),
    ],
)
def test_normalize_refuses_an_id_that_names_no_env(env_id, message):
    with pytest.raises(ValueError, match=message):
        stats.normalize(env_id, [500.0])


def test_normalize_refuses_a_return_above_the_task_maximum():
    with pytest.raises(ValueError, match=r"at most its maximum return 1000.*got 1500 at index 1"):
        stats.normalize("dm_control/cheetah-run-v0", [500.0, 1500.0])
    with pytest.raises(ValueError, match=r"at most its maximum return 1 "):
        stats.normalize("MiniGrid-DoorKey-6x6-v0", [0.5, 2.0])
    assert stats.normalize("dm_control/cheetah-run-v0", [1000.0]) == pytest.approx([1.0])
    # envs without a known maximum keep their raw returns, whatever their size
    np.testing.assert_array_equal(stats.normalize("Pendulum-v1", [-1500.0]), [-1500.0])
    np.testing.assert_array_equal(stats.normalize("highway-fast-v0", [30.0]), [30.0])
