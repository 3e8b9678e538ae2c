"""Statistics for comparing RL methods over a few seeds, as Agarwal et al. (2021, "Deep RL at
the edge of the statistical precipice", the ``rliable`` package) define them, in numpy only.

Scores are given per task as ``{task: array of runs}`` (one score per seed), normalized by the
task's maximum return (:func:`normalize`). Tasks may have different numbers of runs.

- :func:`iqm` / :func:`aggregate_iqm`: the interquartile mean, the 25 % trimmed mean over all
  runs (of all tasks): robust to one outlying seed, less noisy than the median.
- :func:`stratified_bootstrap_ci`: a percentile confidence interval from resampling the runs
  with replacement within each task (the tasks stay fixed).
- :func:`probability_of_improvement`: the chance that a run of X beats a run of Y on a task,
  averaged over tasks.
- :func:`performance_profile`: the fraction of runs scoring above each threshold.

The resampling draws its indices from ``numpy.random.RandomState(seed)`` in the order that
rliable draws them from numpy's global generator, so with ``numpy.random.seed(seed)`` before
an rliable call both give the same resamples and the same intervals (tests/test_stats.py).

>>> iqm(np.arange(1.0, 9.0))  # 8 runs: the lowest 2 and highest 2 are cut, mean of 3..6
4.5
>>> probability_of_improvement({"t": np.array([2.0, 3.0])}, {"t": np.array([1.0, 3.0])})
0.625
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np

Scores = Mapping[str, np.ndarray]
"""task -> scores of its runs, shape (runs,) (or (runs, steps) for curves)"""

TRIM = 0.25
"""Fraction of runs cut from each end for the interquartile mean (rliable, scipy's trim_mean)."""

NORMALIZERS: dict[str, float] = {"dm_control/": 1000.0, "MiniGrid-": 1.0}
"""Env-id prefix -> the task's maximum return, by which returns are divided. dm_control
episodes are 1000 control steps with a reward in [0, 1] each (action repeat sums the rewards of
the repeated steps, so the episode's total stays at most 1000); a MiniGrid episode pays one
reward below 1 on success (1 - 0.9 x steps used / step limit). Envs without an entry (highway-env,
whose return depends on its configured duration; PointReach; Pendulum) have no known maximum
return and keep their raw returns (:func:`normalize` divides by 1)."""


def max_return(env_id: str) -> float | None:
    """The maximum return that :data:`NORMALIZERS` knows for ``env_id``, or None.

    >>> max_return("dm_control/cartpole-swingup-v0"), max_return("Pendulum-v1")
    (1000.0, None)
    """
    for prefix, maximum in NORMALIZERS.items():
        if env_id.startswith(prefix):
            return maximum
    return None


def normalize(env_id: str, returns: np.ndarray) -> np.ndarray:
    """``returns`` divided by the task's maximum return (:data:`NORMALIZERS`); unchanged (as
    float) for envs without a known maximum.

    >>> normalize("dm_control/walker-walk-v0", np.array([500.0, 1000.0]))
    array([0.5, 1. ])
    """
    return np.asarray(returns, dtype=float) / (max_return(env_id) or 1.0)


def _trimmed_mean(values: np.ndarray) -> np.ndarray:
    """The 25 % trimmed mean along axis 0: ``int(0.25 * n)`` values cut from each end of the
    sorted values, as ``scipy.stats.trim_mean`` (so 3 runs keep all 3, 4 to 7 runs lose one
    at each end)."""
    ordered = np.sort(values, axis=0)
    cut = int(TRIM * len(ordered))
    return ordered[cut : len(ordered) - cut].mean(axis=0)


def iqm(scores: np.ndarray) -> float:
    """Interquartile mean of every value in ``scores`` (all runs, and all tasks if it is a
    runs x tasks matrix): rliable's ``aggregate_iqm``, a 25 % trimmed mean.

    >>> iqm(np.array([[1.0, 100.0], [2.0, 3.0]]))  # 4 values: 1 and 100 cut
    2.5
    """
    values = np.asarray(scores, dtype=float).ravel()
    if values.size == 0:
        raise ValueError("iqm of no scores: give at least one run")
    return float(_trimmed_mean(values))


def aggregate_iqm(scores: Scores) -> float:
    """IQM over all runs of all tasks (rliable's ``aggregate_iqm`` of its runs x tasks matrix;
    with unequal run counts a task with more runs weighs more)."""
    return iqm(np.concatenate([np.ravel(runs) for runs in scores.values()]))


def aggregate_mean(scores: Scores) -> float:
    """Mean over tasks of the mean over each task's runs (rliable's ``aggregate_mean``)."""
    return float(np.mean([np.mean(runs) for runs in scores.values()]))


def iqm_over_steps(scores: Scores) -> np.ndarray:
    """IQM over all runs of all tasks at each evaluation step: scores are ``(runs, steps)``
    per task, on one step grid; returns ``(steps,)`` (rliable's sample-efficiency curve)."""
    return _trimmed_mean(np.concatenate([np.atleast_2d(runs) for runs in scores.values()]))


def _draw_indices(
    rng: np.random.RandomState, counts: list[list[int]], reps: int
) -> list[np.ndarray]:
    """``reps`` stratified resamples of each of several score sets (``counts[k]``: the run count
    of each task of set k): for each set, ``(reps, max count, tasks)`` run indices, column
    ``j`` drawn from ``range(counts[k][j])`` (its first ``counts[k][j]`` rows are used).

    One resample of every set after the other, set by set, as rliable draws them (its
    ``np.random.choice(runs, (runs, tasks))`` for each set in turn); one ``randint`` call with
    a bound per element gives the same stream as those calls made one by one
    (tests/test_stats.py finds rliable's intervals).
    """
    bounds = [np.broadcast_to(np.asarray(c), (max(c), len(c))) for c in counts]
    sizes = [bound.size for bound in bounds]
    draws = rng.randint(0, np.concatenate([b.ravel() for b in bounds]), size=(reps, sum(sizes)))
    parts = np.split(draws, np.cumsum(sizes)[:-1], axis=1)
    return [part.reshape(reps, *bound.shape) for part, bound in zip(parts, bounds, strict=True)]


def _take(scores: Scores, indices: np.ndarray) -> dict[str, np.ndarray]:
    """The resample that ``indices`` (one of :func:`_draw_indices`) picks, as task -> runs."""
    return {
        task: np.asarray(runs)[indices[: len(runs), column]]
        for column, (task, runs) in enumerate(scores.items())
    }


def _check(scores: Scores, name: str) -> None:
    if not scores or any(len(runs) == 0 for runs in scores.values()):
        raise ValueError(f"{name}: every task needs at least one run (got {dict(scores)})")


def bootstrap_replicates(
    scores: Scores,
    statistic: Callable[[Scores], float | np.ndarray],
    reps: int = 2000,
    seed: int = 0,
) -> np.ndarray:
    """``statistic`` of ``reps`` stratified resamples of ``scores`` (runs drawn with replacement
    within each task, each task keeping its number of runs): ``(reps, *statistic's shape)``."""
    _check(scores, "bootstrap")
    rng = np.random.RandomState(seed)
    (draws,) = _draw_indices(rng, [[len(runs) for runs in scores.values()]], reps)
    return np.array([statistic(_take(scores, indices)) for indices in draws])


def percentile_interval(
    replicates: np.ndarray, confidence: float = 0.95
) -> tuple[np.ndarray, np.ndarray]:
    """The percentile bootstrap interval of ``replicates`` along axis 0: the (1 - c) / 2 and
    (1 + c) / 2 quantiles (linear interpolation, as rliable through ``arch``)."""
    if not 0 < confidence < 1:
        raise ValueError(f"confidence must lie in (0, 1), got {confidence}")
    alpha = (1.0 - confidence) / 2
    low, high = np.percentile(replicates, [100 * alpha, 100 * (1.0 - alpha)], axis=0)
    return low, high


def stratified_bootstrap_ci(
    scores: Scores,
    statistic: Callable[[Scores], float],
    reps: int = 2000,
    confidence: float = 0.95,
    seed: int = 0,
) -> tuple[float, float, float]:
    """(point estimate, low, high): ``statistic`` of ``scores`` and its percentile confidence
    interval over ``reps`` stratified bootstrap resamples (:func:`bootstrap_replicates`).

    >>> point, low, high = stratified_bootstrap_ci({"t": np.arange(1.0, 9.0)}, aggregate_iqm)
    >>> point, low <= point <= high
    (4.5, True)
    """
    low, high = percentile_interval(bootstrap_replicates(scores, statistic, reps, seed), confidence)
    return float(statistic(scores)), float(low), float(high)


def stratified_bootstrap_band(
    scores: Scores,
    statistic: Callable[[Scores], np.ndarray],
    reps: int = 2000,
    confidence: float = 0.95,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`stratified_bootstrap_ci` of a vector statistic (a curve over steps, a profile
    over thresholds): point, low and high arrays. Whole runs are resampled, so a resampled
    curve is the curve of one run (rliable resamples each step on its own)."""
    replicates = bootstrap_replicates(scores, statistic, reps, seed)
    low, high = percentile_interval(replicates, confidence)
    return np.asarray(statistic(scores), dtype=float), low, high


def _same_tasks(x: Scores, y: Scores) -> None:
    if set(x) != set(y):
        raise ValueError(
            "probability of improvement needs the same tasks for both: "
            f"{sorted(set(x) ^ set(y))} only in one; pass the tasks both have"
        )
    _check(x, "probability of improvement")
    _check(y, "probability of improvement")


def _improvement(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """P(X > Y) + P(X = Y) / 2 for runs on axis -1 of ``x`` (n) and ``y`` (m), i.e. the
    Mann-Whitney U statistic of x over y divided by n m."""
    greater = (x[..., :, None] > y[..., None, :]).mean(axis=(-2, -1))
    ties = (x[..., :, None] == y[..., None, :]).mean(axis=(-2, -1))
    return greater + ties / 2


def probability_of_improvement(x: Scores, y: Scores) -> float:
    """P(X > Y): the probability that a run of X scores above a run of Y on the same task, ties
    counting one half (Mann-Whitney U / (n m)), averaged over the tasks (rliable's
    ``probability_of_improvement``). ``x`` and ``y`` must have the same tasks; their run counts
    may differ."""
    _same_tasks(x, y)
    return float(np.mean([_improvement(np.ravel(x[task]), np.ravel(y[task])) for task in x]))


def probability_of_improvement_ci(
    x: Scores,
    y: Scores,
    reps: int = 2000,
    confidence: float = 0.95,
    seed: int = 0,
) -> tuple[float, float, float]:
    """(point, low, high): :func:`probability_of_improvement` and its percentile interval, the
    runs of X and of Y resampled independently within each task (rliable's
    ``StratifiedIndependentBootstrap``; each resample draws X's indices, then Y's)."""
    _same_tasks(x, y)
    y = {task: y[task] for task in x}
    rng = np.random.RandomState(seed)
    counts = [[len(runs) for runs in x.values()], [len(runs) for runs in y.values()]]
    draws_x, draws_y = _draw_indices(rng, counts, reps)
    per_task = []
    for column, task in enumerate(x):
        runs_x, runs_y = np.ravel(x[task]), np.ravel(y[task])
        resampled_x = runs_x[draws_x[:, : len(runs_x), column]]
        resampled_y = runs_y[draws_y[:, : len(runs_y), column]]
        per_task.append(_improvement(resampled_x, resampled_y))
    low, high = percentile_interval(np.mean(per_task, axis=0), confidence)
    return probability_of_improvement(x, y), float(low), float(high)


def difference_ci(
    x: Scores,
    y: Scores,
    statistic: Callable[[Scores], float] = aggregate_iqm,
    reps: int = 2000,
    confidence: float = 0.95,
    seed: int = 0,
) -> tuple[float, float, float]:
    """(point, low, high): ``statistic(x) - statistic(y)`` and its percentile interval, the runs
    of X and of Y resampled independently within each task, drawn as
    :func:`probability_of_improvement_ci` draws them (rliable's
    ``StratifiedIndependentBootstrap`` of the difference).

    >>> difference_ci({"t": np.array([3.0, 3.0])}, {"t": np.array([1.0, 1.0])})
    (2.0, 2.0, 2.0)
    """
    _same_tasks(x, y)
    y = {task: y[task] for task in x}
    rng = np.random.RandomState(seed)
    counts = [[len(runs) for runs in x.values()], [len(runs) for runs in y.values()]]
    draws_x, draws_y = _draw_indices(rng, counts, reps)
    replicates = np.array(
        [
            statistic(_take(x, indices_x)) - statistic(_take(y, indices_y))
            for indices_x, indices_y in zip(draws_x, draws_y, strict=True)
        ]
    )
    low, high = percentile_interval(replicates, confidence)
    return float(statistic(x) - statistic(y)), float(low), float(high)


def performance_profile(scores: Scores, taus: np.ndarray) -> np.ndarray:
    """For each threshold tau, the fraction of all runs (of all tasks) whose normalized score
    exceeds it (rliable's run-score distribution).

    >>> performance_profile({"a": np.array([0.2, 0.6]), "b": np.array([0.9])}, np.array([0.5]))
    array([0.66666667])
    """
    _check(scores, "performance profile")
    values = np.concatenate([np.ravel(runs) for runs in scores.values()])
    return (values[:, None] > np.asarray(taus, dtype=float)[None, :]).mean(axis=0)
