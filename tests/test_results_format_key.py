"""A stored case is found again only under the same results' format (scenarios.study.types.RESULTS_FORMAT):
a study resumed across a change of what a case stores (2026-12-03: the settling band's default, the
unrealised torque's bound) recomputes its cases instead of mixing two meanings in one table (found by
a review: cases stored before the change were reused as they were, the package version unchanged)."""
from __future__ import annotations

import scenarios.study.types as types


def test_the_store_key_changes_with_the_results_format(monkeypatch) -> None:
    scenario = {"name": "x", "maneuver": {"duration": 10.0}}
    now = types.case_key(scenario, "0.1.0")
    assert types.case_key(scenario, "0.1.0") == now  # stable
    monkeypatch.setattr(types, "RESULTS_FORMAT", types.RESULTS_FORMAT - 1)
    assert types.case_key(scenario, "0.1.0") != now
