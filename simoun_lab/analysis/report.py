"""The information-bias results of several runs: a grouped bar chart, JSON and Markdown."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from simoun_agent import table
from simoun_agent.run.atomic import atomic_write
from simoun_lab.analysis import pairs
from simoun_lab.analysis.bias import CATEGORIES, THRESHOLD, BiasEstimate

CATEGORY_COLOURS = {
    "static": "#E69F00",
    "dynamic": "#0072B2",
    "joint": "#009E73",
    "residual": "#999999",
}
"""Okabe-Ito colours, distinguishable with the common colour-vision deficiencies."""


@dataclass
class RunBias:
    """The estimates of every layer of one run."""

    run_dir: str
    """the run directory"""
    encoder: str
    """the run's ``agent.encoder``"""
    env: str
    """the run's environment id"""
    env_step: int
    """environment steps of the checkpoint"""
    pairs: int
    """pairs per factor"""
    recolour: str
    """how the dynamic pairs were recoloured: ``conv`` or ``model``"""
    layers: dict[str, BiasEstimate]
    """layer name -> estimate"""


def to_json(results: list[RunBias], seed: int) -> dict[str, Any]:
    """Everything the chart and table show, and the per-factor scores behind them."""
    return {
        "method": "Kowal et al., CVPR 2022 (simoun_lab.analysis.bias.information_bias)",
        "threshold": THRESHOLD,
        "seed": seed,
        "pairs_doc": " ".join((pairs.__doc__ or "").split()),
        "runs": [
            {
                "run_dir": result.run_dir,
                "encoder": result.encoder,
                "env": result.env,
                "env_step": result.env_step,
                "pairs": result.pairs,
                "recolour": result.recolour,
                "layers": {
                    name: {
                        "units": estimate.units,
                        "categories_percent": estimate.category_percent(),
                        "categories": estimate.categories,
                        "factor_percent": estimate.factor_percent(),
                        "layer_scores": estimate.layer_scores,
                        "mean_unit_score": {
                            factor: float(scores.mean())
                            for factor, scores in estimate.unit_scores.items()
                        },
                    }
                    for name, estimate in result.layers.items()
                },
            }
            for result in results
        ],
    }


def to_markdown(results: list[RunBias]) -> str:
    """A table: one row per run and layer, percent of units per category and per factor."""
    headers = ["encoder", "layer", "units", *CATEGORIES, "factors s / d / r", "pairs"]
    headers += ["env step", "run"]
    rows = []
    for result in results:
        for name, estimate in result.layers.items():
            cats = estimate.category_percent()
            factors = estimate.factor_percent()
            shares = " / ".join(f"{factors[f]:.0f}" for f in ("static", "dynamic", "residual"))
            rows.append(
                [result.encoder, name, estimate.units]
                + [f"{cats[c]:.1f}" for c in CATEGORIES]
                + [shares, f"{result.pairs} ({result.recolour})", result.env_step]
                + [Path(result.run_dir).name]
            )
    intro = (
        f"Percent of units per category (threshold {THRESHOLD} on the per-unit scores) and per "
        "factor (softmax of the layer scores), Kowal et al. (CVPR 2022)."
    )
    align = "llr" + "r" * len(CATEGORIES) + "llrl"
    return intro + "\n\n" + table.markdown_table(headers, rows, align) + "\n"


def draw_chart(path: Path, results: list[RunBias]) -> Path:
    """One group per encoder and layer, one bar per category (percent of units)."""
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    groups = [
        (f"{result.encoder}\n{name}", estimate)
        for result in results
        for name, estimate in result.layers.items()
    ]
    figure = Figure(figsize=(max(6.0, 1.3 * len(groups) + 2), 4.2), layout="constrained")
    FigureCanvasAgg(figure)
    ax = figure.subplots()
    width = 0.8 / len(CATEGORIES)
    x = np.arange(len(groups))
    for i, category in enumerate(CATEGORIES):
        values = [estimate.category_percent()[category] for _, estimate in groups]
        ax.bar(
            x + (i - 1.5) * width, values, width, label=category, color=CATEGORY_COLOURS[category]
        )
    ax.set_xticks(x, [label for label, _ in groups], fontsize=8)
    ax.set_ylabel("units (%)")
    ax.set_ylim(0, 115)  # headroom for the legend above bars of 100 %
    ax.set_yticks(range(0, 101, 20))
    ax.set_title(
        f"Static / dynamic units per encoder and layer (Kowal et al., threshold {THRESHOLD})"
    )
    ax.legend(ncols=4, loc="upper right", fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    atomic_write(path, lambda tmp: figure.savefig(tmp, format="png", dpi=110))
    return path


def write_report(out: Path, results: list[RunBias], seed: int) -> list[Path]:
    """Write ``bias.json``, ``bias.md`` and ``bias.png`` into ``out``; return their paths."""
    text = json.dumps(to_json(results, seed), indent=2) + "\n"
    atomic_write(out / "bias.json", lambda tmp: tmp.write_text(text))
    table = to_markdown(results)
    atomic_write(out / "bias.md", lambda tmp: tmp.write_text(table))
    return [out / "bias.json", out / "bias.md", draw_chart(out / "bias.png", results)]
