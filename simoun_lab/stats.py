"""Statistics for comparing RL methods over a few seeds, as Agarwal et al. (2021, "Deep RL at
the edge of the statistical precipice", the ``rliable`` package) define them, in numpy only.

Scores are given per task as ``{task: array of runs}`` (one score per seed), normalized by the
task's maximum return (:func:`normalize`). Tasks may have different numbers of runs. Every
function checks its arguments: a task with no runs, a NaN or infinite score, learning curves
``(runs, steps)`` where final scores go (or the reverse), runs of different lengths, replicates
that are no resamples and a non-integer ``reps`` or ``seed`` are refused with a ValueError or
TypeError that names the argument and a fix.

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

import re
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


def _kind(value: object) -> str:
    """How a refused value is shown: its type, and its shape when it is an array."""
    if isinstance(value, np.ndarray):
        return f"a numpy array of shape {value.shape}"
    return f"{type(value).__name__} {value!r}"[:120]


def _lengths(values: object) -> list[int] | None:
    """The lengths of the entries of a list or tuple of sequences, None for anything else."""
    if not isinstance(values, list | tuple) or not values:
        return None
    if not all(hasattr(entry, "__len__") and not isinstance(entry, str) for entry in values):
        return None
    return [len(entry) for entry in values]


def _numbers(values: object, where: str) -> np.ndarray:
    """``values`` as a float array; a TypeError naming ``where`` when they are not numbers, a
    ValueError when its rows (runs) are of different lengths."""
    if isinstance(values, Mapping | str | bytes):
        raise TypeError(f"{where} must be an array of numbers, got {_kind(values)}")
    lengths = _lengths(values)
    if lengths is not None and len(set(lengths)) > 1:
        raise ValueError(
            f"{where} has runs of different lengths ({lengths} values), so they make no array: "
            f"every run needs a value at every evaluation step; cut them to the shortest, e.g. "
            f"np.stack([np.asarray(run)[:{min(lengths)}] for run in runs]), or evaluate the runs "
            "at the same steps"
        )
    try:
        array = np.asarray(values, dtype=float)
    except (TypeError, ValueError) as error:
        raise TypeError(
            f"{where} must be an array of numbers, got {_kind(values)} ({error})"
        ) from None
    return array


def _first_where(mask: np.ndarray) -> tuple[tuple[int, ...], int | tuple[int, ...]]:
    """The first True position of ``mask``: as an index tuple, and as the index a message shows
    (a plain number for one dimension)."""
    first = tuple(int(i) for i in np.argwhere(mask)[0])
    return first, first[0] if len(first) == 1 else first


def _finite(
    array: np.ndarray,
    where: str,
    fix: str,
    why: str = "every run needs a finite score (a NaN is often a run that did not finish)",
) -> None:
    """Refuse NaN and infinite values: a NaN sorts last and compares as a loss, so it would
    pass for a real score; ``fix`` says how to leave such values out."""
    bad = ~np.isfinite(array)
    if bad.any():
        first, index = _first_where(bad)
        raise ValueError(
            f"{where} has {int(bad.sum())} NaN or infinite value(s) ({array[first]} at index "
            f"{index}): {why}; leave them out, e.g. {fix}"
        )


_SHAPES = {
    1: "a 1-D array of final scores, one per run",
    2: "a 2-D array of learning curves (runs, steps), on one step grid",
    None: "an array with one entry per run on axis 0",
}


def _shape_hint(ndim: int | None, shape: tuple[int, ...], function: str, argument: str) -> str:
    """The fix for a task whose array has the ``shape`` given where ``ndim`` dimensions go."""
    got = len(shape)
    if ndim == 1 and got == 2 and shape[1] == 1:
        return (
            "one score per run is a 1-D array, e.g. "
            f"{{task: np.ravel(r) for task, r in {argument}.items()}}"
        )
    if ndim == 1 and got == 2:
        runs, columns = shape
        return (
            f"if these are learning curves of {runs} runs over {columns} steps, pass each run's "
            f"final score, e.g. {{task: np.asarray(c)[:, -1] for task, c in "
            f"{argument}.items()}}, or use iqm_over_steps for the curves; if it is rliable's "
            f"matrix of {runs} runs x {columns} tasks, give each task its own key, e.g. "
            f"{{name: m[:, j] for j, name in enumerate(task_names)}}, or use iqm(m) for the IQM "
            "of the whole matrix"
        )
    if ndim == 2 and got == 1:
        return (
            f"this looks like final scores (one per run); {function} takes each run's curve "
            "over the evaluation steps, e.g. {task: np.stack(curves_of_its_runs)}; for final "
            "scores use aggregate_iqm(scores)"
        )
    if got == 0:
        return "e.g. {task: [score]} for a task with one run"
    if ndim == 1:
        return "e.g. {task: np.ravel(runs)} when every entry is one run's score"
    return f"{function} takes one curve per run, e.g. {{task: np.stack(curves_of_its_runs)}}"


def _task_runs(
    runs: object, task: str, ndim: int | None, function: str, argument: str
) -> np.ndarray:
    """One task's runs, checked: numbers, of the shape ``function`` takes, at least one run,
    all finite."""
    where = f"{function}: {argument}[{task!r}]"
    array = _numbers(runs, where)
    if (ndim is None and array.ndim == 0) or (ndim is not None and array.ndim != ndim):
        raise ValueError(
            f"{where} must be {_SHAPES[ndim]}, got shape {array.shape}; "
            f"{_shape_hint(ndim, array.shape, function, argument)}"
        )
    if array.size == 0:
        raise ValueError(
            f"{where} has no {'runs' if len(array) == 0 else 'steps'} (shape {array.shape}): "
            "every task needs at least one finished run; leave the task out, e.g. "
            f"{{task: r for task, r in {argument}.items() if np.size(r)}}"
        )
    keep = "np.isfinite(r)" if array.ndim == 1 else "np.isfinite(r).all(axis=1)"
    fix = f"{{task: np.asarray(r)[{keep}] for task, r in {argument}.items()}}"
    if array.ndim > 2:
        fix = f"runs without NaN only in {argument}[{task!r}]"
    _finite(array, where, fix)
    return array


def _scores(
    scores: object, function: str, argument: str = "scores", ndim: int | None = 1
) -> dict[str, np.ndarray]:
    """``scores`` checked and as float arrays: a non-empty mapping task -> runs, each task's
    runs of ``ndim`` dimensions (1: final scores, 2: curves, None: any, runs on axis 0)."""
    example = "{'cheetah-run': np.array([0.71, 0.65, 0.8])}"
    if ndim == 2:
        example = "{'cheetah-run': np.array([[0.1, 0.5, 0.7], [0.2, 0.4, 0.65]])}"
    if not isinstance(scores, Mapping):
        raise TypeError(
            f"{function}: {argument} must be a dict task -> {_SHAPES[ndim]}, got "
            f"{_kind(scores)}; e.g. {function}({example})"
        )
    if not scores:
        raise ValueError(
            f"{function}: {argument} has no tasks; give at least one task with its runs, e.g. "
            f"{function}({example})"
        )
    return {task: _task_runs(runs, task, ndim, function, argument) for task, runs in scores.items()}


def _count(value: object, name: str, low: int, high: int | None, example: str) -> int:
    """An integer argument in [low, high]; bool and float (even 2000.0) are refused."""
    span = f">= {low}" if high is None else f"in [{low}, {high}]"
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        raise TypeError(f"{name} must be an int {span}, got {_kind(value)}; e.g. {example}")
    if value < low or (high is not None and value > high):
        raise ValueError(f"{name} must be an int {span}, got {value}; e.g. {example}")
    return int(value)


def _resampling(reps: object, seed: object) -> tuple[int, int]:
    """The bootstrap's ``reps`` (resamples) and ``seed`` (numpy RandomState's range)."""
    return (
        _count(reps, "reps (the number of bootstrap resamples)", 1, None, "reps=2000"),
        _count(seed, "seed", 0, 2**32 - 1, "seed=0"),
    )


def _confidence(confidence: object) -> float:
    """The interval's confidence level, a fraction in (0, 1)."""
    if isinstance(confidence, bool) or not isinstance(confidence, int | float | np.number):
        raise TypeError(
            f"confidence must be a number in (0, 1), got {_kind(confidence)}; e.g. "
            "confidence=0.95 for a 95 % interval"
        )
    if not 0 < confidence < 1:
        percent = (
            f" ({confidence} looks like a percent: confidence={confidence / 100:g})"
            if 1 < confidence < 100
            else ""
        )
        raise ValueError(
            f"confidence must lie in (0, 1), got {confidence}{percent}; e.g. confidence=0.95 "
            "for a 95 % interval"
        )
    return float(confidence)


def _statistic(statistic: object, scores: dict[str, np.ndarray]) -> np.ndarray:
    """``statistic(scores)`` as an array, with a TypeError naming ``statistic`` when it is not
    a function of the scores mapping that returns numbers."""
    example = "e.g. statistic=stats.aggregate_iqm or lambda s: stats.performance_profile(s, taus)"
    if not callable(statistic):
        named = f" (for {statistic!r} pass the function stats.aggregate_{statistic})" * (
            statistic in ("iqm", "mean")
        )
        raise TypeError(
            f"statistic must be a function of the scores dict task -> runs, got "
            f"{_kind(statistic)}{named}; {example}"
        )
    try:
        return np.asarray(statistic(scores), dtype=float)
    except (TypeError, AttributeError, IndexError) as error:
        name = getattr(statistic, "__name__", type(statistic).__name__)
        raise TypeError(
            f"statistic must be a function of the scores dict task -> runs returning numbers, "
            f"but statistic(scores) ({name}) raised {type(error).__name__}: {error}; {example}"
        ) from None


def _one_number(point: np.ndarray, function: str) -> float:
    """A statistic's value where an interval of one number is asked for."""
    if point.size != 1:
        raise ValueError(
            f"{function} takes a statistic that returns one number, but statistic(scores) "
            f"returned shape {point.shape}; for a curve or a profile use "
            "stratified_bootstrap_band(scores, statistic)"
        )
    return float(point.item())


def max_return(env_id: str) -> float | None:
    """The maximum return that :data:`NORMALIZERS` knows for ``env_id``, or None.

    >>> max_return("dm_control/cartpole-swingup-v0"), max_return("Pendulum-v1")
    (1000.0, None)
    """
    if not isinstance(env_id, str):
        raise TypeError(
            f"env_id must be a Gymnasium env id (a str), got {_kind(env_id)}; e.g. "
            "'dm_control/cheetah-run-v0'"
        )
    for prefix, maximum in NORMALIZERS.items():
        if env_id.startswith(prefix):
            return maximum
    return None


def normalize(env_id: str, returns: np.ndarray) -> np.ndarray:
    """``returns`` divided by the task's maximum return (:data:`NORMALIZERS`); unchanged (as
    float) for envs without a known maximum. A task key in the env id's place
    (``'cheetah-run'``) and a return above the task's maximum (returns summed over episodes)
    are refused: either would pass for a normalized score.

    >>> normalize("dm_control/walker-walk-v0", np.array([500.0, 1000.0]))
    array([0.5, 1. ])
    """
    if isinstance(returns, str) and not isinstance(env_id, str):
        raise TypeError(
            f"normalize takes (env_id, returns), got the returns first: env_id={_kind(env_id)}, "
            f"returns={returns!r}; e.g. normalize({returns!r}, returns)"
        )
    maximum = max_return(env_id)
    values = _numbers(returns, "normalize: returns")
    if maximum is None:
        _refuse_unknown_id(env_id)
        return values
    above = values > maximum * (1 + 1e-9)
    if above.any():
        first, index = _first_where(above)
        raise ValueError(
            f"normalize: returns of {env_id} must be at most its maximum return {maximum:g} "
            f"(NORMALIZERS), got {values[first]:g} at index {index}; "
            "a return above it is not one episode's return (often returns summed over several "
            "episodes, or rewards scaled upstream); pass each episode's return, e.g. the mean "
            "return of a run's evaluation episodes"
        )
    return values / maximum


GYMNASIUM_ID = re.compile(r"^(?:[\w.-]+:)?(?:[\w.-]+/)?[\w.:-]+-v\d+$")
"""A Gymnasium env id: ``[module:][namespace/]name-vN``."""


def _refuse_unknown_id(env_id: str) -> None:
    """A ValueError for an ``env_id`` without a known maximum that is no env id (a task key
    such as ``'cheetah-run'``: no version, namespace or module, not registered) or that names
    the task of an id with one (``'cheetah-run-v0'`` for ``'dm_control/cheetah-run-v0'``):
    dividing its returns by 1 would pass raw returns for normalized scores. The ids of other
    envs (Pendulum-v1, highway-fast-v0, MODULE:ID) keep their raw returns."""
    import difflib

    import gymnasium as gym

    from simoun_agent.config.envs import PAPER_ACTION_REPEAT, env_label

    known = [f"dm_control/{task}-v0" for task in PAPER_ACTION_REPEAT]
    known += [name for name in gym.registry if max_return(name) is not None]
    label = env_label(env_id).rsplit("-v", 1)[0]
    same = [name for name in known if env_label(name).rsplit("-v", 1)[0] == label]
    named = GYMNASIUM_ID.match(env_id) or "/" in env_id or ":" in env_id
    if not same and (named or env_id in gym.registry):
        return
    close = same or difflib.get_close_matches(env_id, known, n=3, cutoff=0.5)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ValueError(
        f"normalize: {env_id!r} is not an env id it knows the maximum return of, and its returns "
        f"would be passed on unchanged as normalized scores; {hint}give the Gymnasium env id: "
        f"the maximum is known for ids starting with {', '.join(map(repr, NORMALIZERS))} (e.g. "
        "'dm_control/cheetah-run-v0'); ids of other envs (e.g. 'Pendulum-v1') keep their raw "
        "returns"
    )


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
    if isinstance(scores, Mapping):
        raise TypeError(
            "iqm takes an array of scores (runs, or a runs x tasks matrix), got a dict; for a "
            "dict task -> runs use aggregate_iqm(scores)"
        )
    values = _numbers(scores, "iqm: scores").ravel()
    if values.size == 0:
        raise ValueError("iqm of no scores: give at least one run")
    _finite(values, "iqm: scores", "np.asarray(scores)[np.isfinite(scores)]")
    return float(_trimmed_mean(values))


def aggregate_iqm(scores: Scores) -> float:
    """IQM over all runs of all tasks (rliable's ``aggregate_iqm`` of its runs x tasks matrix;
    with unequal run counts a task with more runs weighs more)."""
    runs = _scores(scores, "aggregate_iqm")
    return float(_trimmed_mean(np.concatenate(list(runs.values()))))


def aggregate_mean(scores: Scores) -> float:
    """Mean over tasks of the mean over each task's runs (rliable's ``aggregate_mean``)."""
    return float(np.mean([runs.mean() for runs in _scores(scores, "aggregate_mean").values()]))


def iqm_over_steps(scores: Scores) -> np.ndarray:
    """IQM over all runs of all tasks at each evaluation step: scores are ``(runs, steps)``
    per task, on one step grid; returns ``(steps,)`` (rliable's sample-efficiency curve)."""
    curves = _scores(scores, "iqm_over_steps", ndim=2)
    steps = {task: runs.shape[1] for task, runs in curves.items()}
    if len(set(steps.values())) > 1:
        shortest = min(steps.values())
        raise ValueError(
            f"iqm_over_steps needs every task's curves on one step grid, got steps per task "
            f"{steps}; evaluate the tasks at the same steps, or cut the curves to a common grid, "
            f"e.g. {{task: np.asarray(curves)[:, :{shortest}] for task, curves in "
            "scores.items()} when the tasks share their first steps"
        )
    return _trimmed_mean(np.concatenate(list(curves.values())))


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


def bootstrap_replicates(
    scores: Scores,
    statistic: Callable[[Scores], float | np.ndarray],
    reps: int = 2000,
    seed: int = 0,
) -> np.ndarray:
    """``statistic`` of ``reps`` stratified resamples of ``scores`` (runs drawn with replacement
    within each task, each task keeping its number of runs): ``(reps, *statistic's shape)``."""
    runs = _scores(scores, "bootstrap_replicates", ndim=None)
    reps, seed = _resampling(reps, seed)
    _statistic(statistic, runs)
    rng = np.random.RandomState(seed)
    (draws,) = _draw_indices(rng, [[len(task) for task in runs.values()]], reps)
    return np.array([statistic(_take(runs, indices)) for indices in draws])


def percentile_interval(
    replicates: np.ndarray, confidence: float = 0.95
) -> tuple[np.ndarray, np.ndarray]:
    """The percentile bootstrap interval of ``replicates`` along axis 0: the (1 - c) / 2 and
    (1 + c) / 2 quantiles (linear interpolation, as rliable through ``arch``)."""
    values = _replicates(replicates)
    confidence = _confidence(confidence)
    alpha = (1.0 - confidence) / 2
    low, high = np.percentile(values, [100 * alpha, 100 * (1.0 - alpha)], axis=0)
    return low, high


def _replicates(replicates: object) -> np.ndarray:
    """:func:`percentile_interval`'s replicates checked: numbers, one resample per row, at least
    one, all finite; an interval (point, low, high) given in their place is refused."""
    example = "percentile_interval(bootstrap_replicates(scores, aggregate_iqm))"
    if (
        isinstance(replicates, tuple)
        and len(replicates) == 3
        and all(np.ndim(part) == 0 for part in replicates)
    ):
        raise TypeError(
            "percentile_interval: replicates must be the statistic of each bootstrap resample "
            f"(an array, one row per resample), got the tuple {replicates!r:.120}, which is an "
            "interval (point, low, high) as stratified_bootstrap_ci returns it: its low and high "
            f"are the interval already; for the replicates use e.g. {example}"
        )
    values = _numbers(replicates, "percentile_interval: replicates")
    if values.ndim == 0 or len(values) == 0:
        raise ValueError(
            f"percentile_interval: replicates must hold at least one resample's statistic "
            f"(one row per resample), got shape {values.shape}; e.g. {example}"
        )
    _finite(
        values,
        "percentile_interval: replicates",
        "np.asarray(replicates)[np.isfinite(replicates)], after finding why the statistic gave "
        "them",
        "a NaN replicate would shift both bounds silently",
    )
    return values


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
    runs = _scores(scores, "stratified_bootstrap_ci", ndim=None)
    confidence = _confidence(confidence)
    point = _one_number(_statistic(statistic, runs), "stratified_bootstrap_ci")
    low, high = percentile_interval(bootstrap_replicates(runs, statistic, reps, seed), confidence)
    return point, float(np.ravel(low)[0]), float(np.ravel(high)[0])


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
    runs = _scores(scores, "stratified_bootstrap_band", ndim=None)
    confidence = _confidence(confidence)
    point = _statistic(statistic, runs)
    low, high = percentile_interval(bootstrap_replicates(runs, statistic, reps, seed), confidence)
    return point, low, high


def _same_tasks(
    x: Scores, y: Scores, function: str
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """``x`` and ``y`` checked as final scores of the same tasks, ``y`` in ``x``'s task order."""
    runs_x, runs_y = _scores(x, function, "x"), _scores(y, function, "y")
    if set(runs_x) != set(runs_y):
        raise ValueError(
            f"{function} needs the same tasks for both: "
            f"{sorted(set(runs_x) ^ set(runs_y))} only in one; pass the tasks both have"
        )
    return runs_x, {task: runs_y[task] for task in runs_x}


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
    runs_x, runs_y = _same_tasks(x, y, "probability_of_improvement")
    return float(np.mean([_improvement(runs_x[task], runs_y[task]) for task in runs_x]))


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
    x, y = _same_tasks(x, y, "probability_of_improvement_ci")
    reps, seed = _resampling(reps, seed)
    confidence = _confidence(confidence)
    rng = np.random.RandomState(seed)
    counts = [[len(runs) for runs in x.values()], [len(runs) for runs in y.values()]]
    draws_x, draws_y = _draw_indices(rng, counts, reps)
    per_task = []
    for column, task in enumerate(x):
        runs_x, runs_y = x[task], y[task]
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
    x, y = _same_tasks(x, y, "difference_ci")
    reps, seed = _resampling(reps, seed)
    confidence = _confidence(confidence)
    point_x = _one_number(_statistic(statistic, x), "difference_ci")
    point_y = _one_number(_statistic(statistic, y), "difference_ci")
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
    return point_x - point_y, float(np.ravel(low)[0]), float(np.ravel(high)[0])


def performance_profile(scores: Scores, taus: np.ndarray) -> np.ndarray:
    """For each threshold tau, the fraction of all runs (of all tasks) whose normalized score
    exceeds it (rliable's run-score distribution).

    >>> performance_profile({"a": np.array([0.2, 0.6]), "b": np.array([0.9])}, np.array([0.5]))
    array([0.66666667])
    """
    values = np.concatenate(list(_scores(scores, "performance_profile").values()))
    return (values[:, None] > _thresholds(taus)[None, :]).mean(axis=0)


def _thresholds(taus: object) -> np.ndarray:
    """The profile's thresholds: a non-empty 1-D array of finite numbers."""
    thresholds = _numbers(taus, "performance_profile: taus")
    if thresholds.ndim != 1 or thresholds.size == 0:
        one = f"np.array([{thresholds.item():g}])" if thresholds.size == 1 else "np.array([0.5])"
        raise ValueError(
            f"performance_profile: taus must be a 1-D array of thresholds, got shape "
            f"{thresholds.shape}; e.g. taus={one} for one threshold, or np.linspace(0, 1, 21)"
        )
    _finite(
        thresholds, "performance_profile: taus", "taus[np.isfinite(taus)]", "a threshold is a score"
    )
    return thresholds
