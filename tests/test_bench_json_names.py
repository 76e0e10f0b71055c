"""``leaderboard.json`` names things as ``leaderboard.csv`` does (docs/guide/bench.rst): a row's
``objective`` is the objective's name, the name its problem's metadata gives, and ``value`` its
objective value.

Oracle: the eigenaxis slew's minimum time on Bilimoria & Wie's 45° slew, 2 √(θ J / u) with θ = π/4,
J = 1, u = 1: √π = 1.7724539 s, worked by hand.
"""
from __future__ import annotations

import csv
import json
import math

import pytest

from scenarios.bench.leaderboard import ROWS_SCHEMA, run_bench
from scenarios.bench.suite import load_suite


def test_json_rows_and_csv_lines_use_the_same_names(tmp_path):
    board = run_bench(load_suite(), problems=["bilimoria_wie_45"], planners=["eigenaxis"])
    board.write(tmp_path / "board", plots=False)
    data = json.loads((tmp_path / "board" / "leaderboard.json").read_text())
    row, problem = data["rows"][0], data["problems"][0]
    assert problem["objective"] == "min_time"
    assert row["objective"] == problem["objective"]  # the name, in rows as in problems
    assert row["value"] == pytest.approx(math.sqrt(math.pi), abs=1e-6)
    line = next(csv.DictReader((tmp_path / "board" / "leaderboard.csv").open()))
    assert line["objective"] == row["objective"] and float(line["value"]) == row["value"]
    assert data["rows_schema"] == ROWS_SCHEMA == 2
