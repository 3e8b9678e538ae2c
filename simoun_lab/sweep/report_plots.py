"""The figures of ``simoun-report``: learning curves (mean ± std), IQM over env steps with its
95 % bootstrap band, and performance profiles (Agarwal et al. 2021, Fig. 5 and 8 of rliable's
paper). Each is written atomically as a PNG; matplotlib is imported only here."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from simoun_agent.run.atomic import atomic_write

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

Band = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
"""x, center, low, high of one curve with its band"""


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(fig: Figure, axes: Sequence[Axes], path: Path) -> None:
    """One legend under the panels (ten recipes' labels inside a panel would hide its curves),
    then the PNG, atomically."""
    fig.tight_layout()
    labelled = {line.get_label(): line for ax in axes for line in ax.lines}
    if labelled:
        fig.legend(
            labelled.values(),
            labelled.keys(),
            loc="upper center",
            bbox_to_anchor=(0.5, 0.0),
            ncol=min(3, len(labelled)),
            fontsize="small",
        )
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png", bbox_inches="tight"))
    _pyplot().close(fig)


def plot_panels(
    panels: dict[str, dict[str, Band]], xlabel: str, ylabel: str, path: Path, steps: bool = False
) -> None:
    """One panel per key of ``panels`` (an env, or all tasks), one line with its shaded band
    per label (a variant): ``{panel: {label: (x, center, low, high)}}``; ``steps`` draws step
    functions (a profile jumps at each run's score)."""
    plt = _pyplot()
    names = list(panels) or ["no runs"]
    fig, axes = plt.subplots(1, len(names), figsize=(5.5 * len(names), 4), dpi=110, squeeze=False)
    for ax, name in zip(axes[0], names, strict=True):
        for label, (x, center, low, high) in panels.get(name, {}).items():
            if steps:
                (line,) = ax.step(x, center, where="post", label=label)
            else:
                (line,) = ax.plot(x, center, label=label)
            where = "post" if steps else None
            ax.fill_between(x, low, high, alpha=0.2, color=line.get_color(), step=where)
        ax.set_title(name)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        if not ax.lines:
            ax.text(0.5, 0.5, "no counted run", ha="center", transform=ax.transAxes)
    _save(fig, axes[0], path)
