"""The benchmark convention every benchmark script of the project follows.

A benchmark compares this project's figure with a reference measured in the same run on the
same input (a well-kept library, a bare loop): these machines are shared and noisy, so an
absolute time measured on another day says little, a ratio measured side by side says more.
Each script prints a table and, with ``--json PATH``, writes a list of rows
``{figure, value, unit, reference, reference_value, ratio, goal, met}``; ``make bench`` collects
every script's rows into one table (docs/benchmarks.md).

Typical use::

    parser = argparse.ArgumentParser(...)
    add_json_option(parser)
    args = parser.parse_args()
    rows = [BenchRow("A* warehouse, median", 12.1, "ms", "pyastar2d", 9.0,
                     goal="<= 1.5x pyastar2d and <= 50 ms", met=12.1 <= 13.5 and 12.1 <= 50)]
    report(rows, args.json)
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Iterable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np


@dataclass
class BenchRow:
    """One figure beside its reference. ``ratio`` is value / reference_value (NaN without one).

    ``met`` is whether the issue's goal (``goal``, in words) is met, or None when the figure has
    no goal of its own (a reference row, a figure shown for context).
    """

    figure: str
    value: float
    unit: str
    reference: str = ""
    reference_value: float = math.nan
    goal: str = ""
    met: bool | None = None

    @property
    def ratio(self) -> float:
        if not self.reference_value or math.isnan(self.reference_value):
            return math.nan
        return self.value / self.reference_value

    def as_dict(self) -> dict:
        """The JSON row (NaN written as null)."""
        row = asdict(self)
        row["ratio"] = self.ratio
        return {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in row.items()}


def add_json_option(parser: argparse.ArgumentParser) -> None:
    """``--json PATH``: also write the rows as JSON."""
    parser.add_argument("--json", metavar="PATH", help="write the rows as JSON to PATH")


def percentiles(samples: Sequence[float] | np.ndarray, *qs: float) -> tuple[float, ...]:
    """The ``qs`` percentiles of ``samples`` (e.g. ``percentiles(s, 50, 99)``)."""
    values = np.asarray(samples, dtype=float)
    return tuple(float(np.percentile(values, q)) for q in qs)


def _cell(value: float) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
    return str(value)


def format_table(rows: Iterable[BenchRow]) -> str:
    """The rows as an aligned text table."""
    header = ("figure", "value", "unit", "reference", "ref. value", "ratio", "goal", "met")
    lines = [header]
    for r in rows:
        met = "—" if r.met is None else ("yes" if r.met else "NO")
        lines.append(
            (r.figure, _cell(r.value), r.unit, r.reference or "—", _cell(r.reference_value),
             _cell(r.ratio), r.goal or "—", met)
        )
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    out = []
    for n, line in enumerate(lines):
        out.append("  ".join(cell.ljust(w) for cell, w in zip(line, widths, strict=True)))
        if n == 0:
            out.append("  ".join("-" * w for w in widths))
    return "\n".join(out)


def report(rows: Sequence[BenchRow], json_path: str | Path | None = None) -> None:
    """Print the table; write the JSON rows when ``json_path`` is given."""
    print(format_table(rows), flush=True)
    if json_path:
        Path(json_path).write_text(json.dumps([r.as_dict() for r in rows], indent=2) + "\n")
