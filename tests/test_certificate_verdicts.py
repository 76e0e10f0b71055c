"""What a certificate's verdict requires (docs/metrics.rst, "Certificates"): ``certified`` only with
the second-order sufficient conditions; a degenerate second order with Pontryagin's switching
evidence reads ``first-order, bang-bang``, never ``certified``.

Oracle: the verdicts' definitions in the docs' table, applied to Bilimoria & Wie's 90° minimum time
on the bench's 50-interval mesh (``switch_refinement: 0``: by default the switch-time shooting's
bang-bang optimum and its own certificate replace that solve, ``tests/test_collocation_bang_bang.py``),
whose second-order check finds one direction of near-zero curvature (degenerate) and whose torques
agree with their switching functions.
"""
from __future__ import annotations

from pathlib import Path

import yaml

import scenarios
from scenarios.bench.leaderboard import certificate_text
from scenarios.schema.loader import parse_scenario


def fifty_intervals(path: str) -> scenarios.Scenario:
    """The bench problem with its collocation row on the plain 50-interval solve."""
    data = yaml.safe_load(Path(path).read_text())
    for planner in data["planners"]:
        if planner["name"] == "collocation":
            planner["options"]["switch_refinement"] = 0
    return parse_scenario(data, Path(path))


def test_a_degenerate_second_order_is_not_read_as_certified():
    scenario = fifty_intervals("scenarios/bench/problems/bilimoria_wie_90.yaml")
    reference = scenarios.run(scenario).rows[0].reference
    record = reference.stats["certificate"]
    assert record["second_order"].startswith("degenerate: "), record  # the case the verdict must not hide
    assert record["kkt_scaled"] <= 1e-6 and record["switching"] >= 0.9
    assert record["verdict"] == "first-order, bang-bang", record
    assert not record["summary"].startswith("certified"), record["summary"]
    assert certificate_text(reference.stats).startswith("first-order, bang-bang: KKT ")


def test_certified_requires_a_strict_local_minimum():
    scenario = fifty_intervals("scenarios/bench/problems/bilimoria_wie_180.yaml")
    record = scenarios.run(scenario).rows[0].reference.stats["certificate"]
    assert record["second_order"] == "strict local minimum", record
    assert record["verdict"] == "certified" and record["summary"].startswith("certified: KKT ")
