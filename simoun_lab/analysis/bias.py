"""The static / dynamic information estimator of Kowal et al. (CVPR 2022), used by Sec. 4, Fig. 5.

M. Kowal, M. Siam, M. A. Islam, N. D. B. Bruce, R. P. Wildes, K. G. Derpanis, "A Deeper Dive Into
What Deep Spatiotemporal Networks Encode: Quantifying Static vs. Dynamic Information", CVPR 2022
(after Esser et al., CVPR 2020, and Islam et al., ICLR 2021). The estimator only needs a layer's
per-unit activations on pairs of inputs that share one factor; how simoun builds the pairs from a
run's own environment is in :mod:`simoun_lab.analysis.pairs`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

FACTORS = ("dynamic", "static")
"""The two factors that pairs can share, in the order of the estimator's outputs."""

CATEGORIES = ("static", "dynamic", "joint", "residual")
"""Per-unit categories: encodes the static factor only, the dynamic factor only, both, neither."""

THRESHOLD = 0.5
"""A unit encodes a factor when its per-unit score exceeds this (Kowal et al.'s joint-encoding
threshold, the one behind the unit counts of the paper's Fig. 5)."""


@dataclass
class BiasEstimate:
    """What :func:`information_bias` finds for one layer of ``units`` units."""

    unit_scores: dict[str, np.ndarray]
    """factor -> (units,) per-unit mutual-information proxy rho_{f,i}"""
    layer_scores: dict[str, float]
    """factor -> layer score s_f; ``residual`` is fixed at 1"""
    factor_units: dict[str, int]
    """factor (dynamic, static, residual) -> units of the layer assigned to it by the softmax"""
    categories: dict[str, int]
    """category (static, dynamic, joint, residual) -> units in it (threshold on rho)"""
    units: int
    """units of the layer (channels)"""

    def category_percent(self) -> dict[str, float]:
        """Percent of units per category (the bars of Fig. 5)."""
        return {name: 100.0 * count / self.units for name, count in self.categories.items()}

    def factor_percent(self) -> dict[str, float]:
        """Percent of units per factor from the softmax of the layer scores."""
        return {name: 100.0 * count / self.units for name, count in self.factor_units.items()}


def information_bias(
    pairs: dict[str, tuple[np.ndarray, np.ndarray]], threshold: float = THRESHOLD
) -> BiasEstimate:
    """Estimate how many units of a layer encode the static and the dynamic factor.

    ``pairs[f] = (z_a, z_b)``, each ``(N, D)``: the layer's D units on N input pairs that share
    factor ``f`` (``"dynamic"``: same motion, different appearance; ``"static"``: same
    appearance, different motion). For each factor f, over its N pairs:

    - mean of the pair: ``mu_f = (mean_n z_a + mean_n z_b) / 2`` (per unit)
    - per-unit score (the mutual-information proxy, a correlation coefficient):
      ``rho_{f,i} = mean_n[(z_a[n,i] - mu_{f,i}) (z_b[n,i] - mu_{f,i})] / var_{f,i}``, with
      ``var_{f,i}`` the variance of unit i over the 2N inputs of factor f. A unit whose value is
      the same for both inputs of every pair scores 1; one unrelated across the pair scores 0. A
      unit that never varies (a dead ReLU channel) scores 0 (it carries no information).
    - layer score: ``s_f = sum_i mean_n[(z_a - mu_f)(z_b - mu_f)]_i / sum_i var_i``, where
      ``var_i`` is unit i's variance over all inputs of all factors; the residual factor has
      ``s_residual = 1``.
    - units per factor: ``D * softmax(s_dynamic, s_static, s_residual)``, rounded down, the
      residual taking what rounding leaves.
    - per-unit category with threshold ``t`` (0.5 in the paper): ``joint`` when
      ``rho_dynamic > t`` and ``rho_static > t``, ``dynamic`` / ``static`` when only that score
      exceeds t, ``residual`` when neither does.

    Example:
        >>> rng = np.random.default_rng(0)
        >>> shared = rng.normal(size=(500, 1))
        >>> copy = (shared, shared + 0.1 * rng.normal(size=(500, 1)))
        >>> noise = (rng.normal(size=(500, 1)), rng.normal(size=(500, 1)))
        >>> information_bias({"dynamic": copy, "static": noise}).categories
        {'static': 0, 'dynamic': 1, 'joint': 0, 'residual': 0}
    """
    _check_factors(pairs)
    _check_threshold(threshold)
    shapes = {
        factor: (np.shape(pairs[factor][0]), np.shape(pairs[factor][1])) for factor in FACTORS
    }
    units = shapes[FACTORS[0]][0][-1] if len(shapes[FACTORS[0]][0]) == 2 else -1
    for factor, (shape_a, shape_b) in shapes.items():
        if len(shape_a) != 2 or shape_a != shape_b or shape_a[1] != units or shape_a[0] < 2:
            raise ValueError(
                f"pairs[{factor!r}] must be two arrays of the same shape (N, D) with N >= 2 and "
                f"one D for every factor, got {shape_a} and {shape_b}"
            )
    z = {factor: _activations(factor, pairs[factor]) for factor in FACTORS}
    everything = np.concatenate([side for factor in FACTORS for side in z[factor]])
    total_var = float(everything.var(axis=0).sum())
    unit_scores, layer_scores = {}, {}
    for factor in FACTORS:
        z_a, z_b = z[factor]
        mu = 0.5 * (z_a.mean(axis=0) + z_b.mean(axis=0))
        covariance = ((z_a - mu) * (z_b - mu)).mean(axis=0)
        variance = np.concatenate([z_a, z_b]).var(axis=0)
        alive = variance > 1e-12 * max(1.0, float(variance.max()))
        unit_scores[factor] = np.where(alive, covariance / np.where(alive, variance, 1.0), 0.0)
        layer_scores[factor] = float(covariance.sum() / total_var) if total_var > 0 else 0.0
    layer_scores["residual"] = 1.0
    names = (*FACTORS, "residual")
    logits = np.array([layer_scores[name] for name in names])
    share = np.exp(logits - logits.max())
    share /= share.sum()
    counts = [int(s * units) for s in share[:-1]]
    factor_units = dict(zip(names, [*counts, units - sum(counts)], strict=True))
    dynamic = unit_scores["dynamic"] > threshold
    static = unit_scores["static"] > threshold
    categories = {
        "static": int(np.sum(static & ~dynamic)),
        "dynamic": int(np.sum(dynamic & ~static)),
        "joint": int(np.sum(static & dynamic)),
        "residual": int(np.sum(~static & ~dynamic)),
    }
    return BiasEstimate(unit_scores, layer_scores, factor_units, categories, units)


EXAMPLE = "information_bias({'dynamic': (z_a, z_b), 'static': (z_c, z_d)}), each z an (N, D) array"
"""The form of ``pairs``, shown when it is refused."""


def _check_factors(pairs: object) -> None:
    """``pairs`` is a mapping with exactly the factors of :data:`FACTORS`, each a pair."""
    if not isinstance(pairs, Mapping):
        raise TypeError(
            f"information_bias takes pairs as a dict factor -> (z_a, z_b), keyed by {FACTORS}, "
            f"got {type(pairs).__name__}; e.g. {EXAMPLE}"
        )
    missing = [factor for factor in FACTORS if factor not in pairs]
    unknown = [factor for factor in pairs if factor not in FACTORS]
    if missing or unknown:
        found = [f"missing {missing}"] * bool(missing) + [f"unknown {unknown}"] * bool(unknown)
        raise ValueError(
            f"information_bias needs pairs for exactly {FACTORS}, got {', '.join(found)}: the "
            f"estimator knows these two factors only (lowercase); e.g. {EXAMPLE}"
        )
    for factor in FACTORS:
        _check_pair(factor, pairs[factor])


def _check_pair(factor: str, pair: Any) -> None:
    """``pairs[factor]`` holds two sides, each the activations on one input of every pair."""
    try:
        size = None if isinstance(pair, str | bytes | Mapping) else len(pair)
    except TypeError:
        size = None
    if size != 2:
        length = "" if size is None else f" of length {size}"
        raise ValueError(
            f"pairs[{factor!r}] must be two arrays (z_a, z_b), the layer's activations on the "
            f"first and the second input of each pair, got {type(pair).__name__}{length}; "
            f"e.g. {EXAMPLE}"
        )


def _check_threshold(threshold: object) -> None:
    """The category threshold is a fraction in (0, 1), as the per-unit scores are."""
    if isinstance(threshold, bool) or not isinstance(threshold, int | float | np.number):
        raise TypeError(
            f"threshold must be a number in (0, 1), got {type(threshold).__name__} "
            f"{threshold!r}; e.g. threshold={THRESHOLD} (the paper's)"
        )
    if not 0 < threshold < 1:
        percent = (
            f" ({threshold} looks like a percent: threshold={threshold / 100:g})"
            if 1 < threshold <= 100
            else ""
        )
        raise ValueError(
            f"threshold must lie in (0, 1): the per-unit scores are correlations, at most 1, "
            f"got {threshold}{percent}; e.g. threshold={THRESHOLD} (the paper's)"
        )


def _activations(factor: str, pair: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, ...]:
    """The two sides of ``pair`` as float arrays of finite numbers."""
    sides = []
    for side, values in enumerate(pair):
        where = f"pairs[{factor!r}][{side}]"
        if callable(getattr(values, "detach", None)):
            # torch activations taken with gradient (outside torch.no_grad()): only their values
            # count here
            values = values.detach().cpu()
        try:
            array = np.asarray(values, np.float64)
        except (TypeError, ValueError) as error:
            raise TypeError(
                f"{where} must be an (N, D) array of activations, got "
                f"{type(values).__name__} ({error})"
            ) from None
        bad = ~np.isfinite(array)
        if bad.any():
            row, unit = (int(i) for i in np.argwhere(bad)[0][:2])
            raise ValueError(
                f"{where} has {int(bad.sum())} NaN or infinite activation(s) "
                f"({array[row, unit]} at row {row}, unit {unit}): every score needs finite "
                "activations; check the layer, or leave out the pairs with one, e.g. "
                "keep = np.isfinite(z_a).all(1) & np.isfinite(z_b).all(1), then "
                "(z_a[keep], z_b[keep])"
            )
        sides.append(array)
    return tuple(sides)
