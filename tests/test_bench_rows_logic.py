"""The leaderboard's rows (scenarios/bench/leaderboard.py, rows_schema 2): a peer's row names its
problem's objective in ``objective`` and carries the number in ``value``; a row reaches the optimum
when ``|value − optimum| <= tolerance`` (docs/guide/bench.rst), at the tolerance included and on
either side of the optimum, not below it by more.

Oracles: the suite index's own objective name and tolerance (scenarios/bench/suite.yaml), gaps
built by hand from them.
"""
from __future__ import annotations

import json

from scenarios.bench.leaderboard import Leaderboard, _peer_row, _reached
from scenarios.bench.peers.base import PeerResult
from scenarios.bench.suite import load_suite


def test_a_peers_row_names_the_objective_and_carries_the_value():
    suite = load_suite()
    problem = suite.problems["xte_150"]
    row = _peer_row(problem, "fatrop", PeerResult(28.7, 0.5, "ok", 40, ""))
    assert row.objective == "min_time" == problem.objective and row.value == 28.7
    data = json.loads(json.dumps(Leaderboard(suite, [problem], [row]).to_json()))
    assert data["rows"][0]["objective"] == "min_time" and data["rows"][0]["value"] == 28.7


def test_a_gap_of_the_tolerance_reaches_on_either_side_and_no_more():
    problem = load_suite().problems["xte_150"]
    tolerance = problem.tolerance
    assert tolerance == 1e-4
    assert _reached("ok", tolerance, problem) is True
    assert _reached("ok", -tolerance, problem) is True
    assert _reached("ok", -2 * tolerance, problem) is False  # below the optimum by more than the tolerance
    assert _reached("ok", -1.0, problem) is False
    assert _reached("ok", 2 * tolerance, problem) is False
