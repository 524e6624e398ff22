"""The benchmark convention: rows with a reference, ratio, goal and verdict; table and JSON."""

from __future__ import annotations

import argparse
import json
import math

from easynav.core.benchmarking import BenchRow, add_json_option, format_table, percentiles, report


def test_ratio_is_value_over_reference_and_nan_without_one():
    assert BenchRow("a", 3.0, "ms", "ref", 2.0).ratio == 1.5
    assert math.isnan(BenchRow("a", 3.0, "ms").ratio)


def test_json_rows_have_every_field_and_null_for_missing_numbers(tmp_path, capsys):
    path = tmp_path / "rows.json"
    report([BenchRow("A*", 12.0, "ms", "pyastar2d", 10.0, "<= 1.5x", True),
            BenchRow("context", 1.0, "ms")], path)
    rows = json.loads(path.read_text())
    assert rows[0] == {"figure": "A*", "value": 12.0, "unit": "ms", "reference": "pyastar2d",
                       "reference_value": 10.0, "ratio": 1.2, "goal": "<= 1.5x", "met": True}
    assert rows[1]["reference_value"] is None and rows[1]["ratio"] is None
    assert rows[1]["met"] is None
    printed = capsys.readouterr().out
    assert "A*" in printed and "pyastar2d" in printed and "yes" in printed


def test_table_marks_a_missed_goal():
    table = format_table([BenchRow("x", 2.0, "ms", "y", 1.0, "<= 1 ms", False)])
    assert table.splitlines()[2].rstrip().endswith("NO")


def test_json_option_and_percentiles():
    parser = argparse.ArgumentParser()
    add_json_option(parser)
    assert parser.parse_args(["--json", "out.json"]).json == "out.json"
    assert percentiles(range(101), 50, 99) == (50.0, 99.0)
