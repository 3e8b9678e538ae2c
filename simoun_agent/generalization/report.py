"""The generalization table (Markdown and CSV, mean ± std) and grouped bar chart (Fig. 8)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import asdict, fields
from pathlib import Path

from simoun_agent import table
from simoun_agent.generalization.evaluation import ModeResult
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.rundir import make_output_dir
from simoun_wrappers._checks import check_path

TABLE_MD = "generalization.md"
TABLE_CSV = "generalization.csv"
CHART_PNG = "generalization.png"
REPORT_FILES = (TABLE_MD, TABLE_CSV, CHART_PNG)
"""The files :func:`write_report` writes."""


def default_out(run_dirs: list[Path]) -> Path:
    """``<run dir>/generalization`` for one run, ``<their common folder>/generalization`` for
    several (a run given by its checkpoint.pt counts as its folder)."""
    folders = [path if path.is_dir() else path.parent for path in run_dirs]
    return Path(os.path.commonpath([folder.resolve() for folder in folders])) / "generalization"


def _order(results: Sequence[ModeResult]) -> tuple[list[str], list[str]]:
    runs = list(dict.fromkeys(result.run for result in results))
    modes = list(dict.fromkeys(result.mode for result in results))
    return runs, modes


def markdown_table(results: Sequence[ModeResult]) -> str:
    """One row per run, one column per mode, cells ``mean ± std`` of the episode return."""
    runs, modes = _order(results)
    cell = {(r.run, r.mode): f"{r.return_mean:.1f} ± {r.return_std:.1f}" for r in results}
    rows = [[run] + [cell.get((run, m), "") for m in modes] for run in runs]
    text = table.markdown_table(["run", *modes], rows, align="l" + "r" * len(modes))
    first = results[0]
    note = (
        f"\nEpisode return, mean ± std over {first.episodes} deterministic episodes per mode "
        f"(reset seeds from {first.first_seed} for the first run; every mode plays the same ones)."
    )
    return text + "\n" + note + "\n"


def write_csv(results: Sequence[ModeResult], path: Path) -> None:
    """One row per run and mode, with every ``ModeResult`` field."""

    table.write_csv(path, [field.name for field in fields(ModeResult)], map(asdict, results))


def plot_bars(results: Sequence[ModeResult], path: Path, title: str) -> None:
    """Grouped bars as in the paper's Fig. 8: one group per mode, one bar per run, ± std."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    runs, modes = _order(results)
    by_key = {(r.run, r.mode): r for r in results}
    width = 0.8 / len(runs)
    fig, ax = plt.subplots(figsize=(max(6.0, 1.3 * len(modes) * max(1, len(runs) / 2)), 4), dpi=110)
    x = np.arange(len(modes))
    for index, run in enumerate(runs):
        means = [by_key[run, m].return_mean if (run, m) in by_key else np.nan for m in modes]
        stds = [by_key[run, m].return_std if (run, m) in by_key else np.nan for m in modes]
        offset = (index - (len(runs) - 1) / 2) * width
        ax.bar(x + offset, means, width, yerr=stds, capsize=3, label=run)
    ax.set_xticks(x, [mode.replace("_", " ") for mode in modes])
    ax.set_ylabel("episode return (mean ± std)")
    ax.set_title(title)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(loc="best", fontsize="small")
    fig.tight_layout()
    atomic_write(path, lambda tmp: fig.savefig(tmp, format="png"))
    plt.close(fig)


def write_report(results: Sequence[ModeResult], out: Path, title: str) -> dict[str, Path]:
    """Write the Markdown table, the CSV and the bar chart into the folder ``out`` (a str or
    os.PathLike, made when missing); returns their paths."""
    check_report_arguments(results, out, title)
    out = Path(out)
    make_output_dir(out, "write_report(out=...)", REPORT_FILES)
    paths = {"table": out / TABLE_MD, "csv": out / TABLE_CSV, "chart": out / CHART_PNG}
    text = f"# {title}\n\n" + markdown_table(results)
    atomic_write(paths["table"], lambda tmp: tmp.write_text(text))
    write_csv(results, paths["csv"])
    plot_bars(results, paths["chart"], title)
    return paths


def check_report_arguments(results: object, out: object, title: object) -> None:
    """A TypeError naming :func:`write_report`'s argument that is not what it takes."""
    if not (
        isinstance(results, (list, tuple))
        and results
        and all(isinstance(result, ModeResult) for result in results)
    ):
        raise TypeError(
            f"write_report(results=...) must be a non-empty list of ModeResult, got "
            f"{type(results).__name__} {results!r:.60}; pass what evaluate_runs returns"
        )
    check_path(out, "write_report(out=...)", "write_report(results, 'runs/generalization', title)")
    if not isinstance(title, str):
        raise TypeError(
            f"write_report(title=...) must be a str, got {type(title).__name__} {title!r:.60}; "
            "e.g. title='walker-walk under distraction'"
        )
