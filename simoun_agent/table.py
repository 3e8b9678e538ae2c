"""The one table writer of every report: column headers and rows in, Markdown and CSV out.

A report's table reads the same in its Markdown (for people) and its CSV (for spreadsheets
and scripts) because both come from one list of headers and rows. It lives in the product,
not the lab, because the product's own reports (generalization, driving references) use it
and the product imports nothing from the lab.

Example:
    >>> print(markdown_table(["run", "return"], [["a", "1.5"], ["b", "2.0"]], align="lr"))
    | run | return |
    |---|---:|
    | a | 1.5 |
    | b | 2.0 |
    >>> csv_text(["run", "return"], [{"run": "a", "return": 1.5}])
    'run,return\\r\\na,1.5\\r\\n'
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from simoun_agent.run.atomic import atomic_write

Row = Sequence[object] | Mapping[str, object]
"""A table row: its cells in the headers' order, or a mapping from header to cell."""


def markdown_table(headers: Sequence[str], rows: Iterable[Row], align: str = "") -> str:
    """A Markdown table, one line per row, without a final newline.

    ``align`` has one letter per column, ``l`` (left) or ``r`` (right, for numbers); columns
    past its end are left-aligned. Cells are written as ``str`` gives them, unescaped, so a
    cell holds no ``|`` of its own.
    """
    if len(align) > len(headers) or set(align) - {"l", "r"}:
        raise ValueError(f"align {align!r}: one letter l or r per column of {list(headers)}")
    rule = "".join(
        "|---:" if letter == "r" else "|---" for letter in align.ljust(len(headers), "l")
    )
    lines = [_markdown_line(headers), rule + "|"]
    lines += [_markdown_line(_cells(headers, row)) for row in rows]
    return "\n".join(lines)


def csv_text(headers: Sequence[str], rows: Iterable[Row]) -> str:
    """The table as CSV text: a header line, then one line per row (the csv module's dialect,
    ``\\r\\n`` line ends; a mapping row's missing cells are empty)."""
    buffer = io.StringIO()
    writer = csv.writer(buffer)
    writer.writerow(headers)
    writer.writerows(_cells(headers, row) for row in rows)
    return buffer.getvalue()


def write_csv(path: Path, headers: Sequence[str], rows: Iterable[Row]) -> None:
    """Write :func:`csv_text` to ``path`` atomically, byte for byte (no newline translation)."""
    text = csv_text(headers, rows)
    atomic_write(path, lambda tmp: tmp.write_bytes(text.encode("utf-8")))


def _cells(headers: Sequence[str], row: Row) -> Sequence[object]:
    if isinstance(row, Mapping):
        return [row.get(header, "") for header in headers]
    if len(row) != len(headers):
        raise ValueError(f"row {list(row)} has {len(row)} cells for {len(headers)} columns")
    return row


def _markdown_line(cells: Sequence[object]) -> str:
    return "| " + " | ".join(str(cell) for cell in cells) + " |"
