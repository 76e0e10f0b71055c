"""Collocation's seed bound chooses right: of two feasible slews faster than its optimum the bound is
the faster (hand-checked: the eigenaxis bang-coast-bang within the 5 % margin, 78.27 s, against the
one within a 7 % margin, 79.85 s, both feasible), and the answer it returns is never slower than
the optimum it had before the bound was looked at (the faster of that and the second solve)."""
from dataclasses import replace

import pytest

from planners import PLANNERS
from planners.collocation.planner import CollocationPlanner
from tests.test_collocation_seed_bound import feasible_eigenaxis, pyramid_problem


def test_the_bound_is_the_fastest_feasible_slew_and_the_faster_answer_is_kept(monkeypatch):
    problem = pyramid_problem()
    fastest = feasible_eigenaxis(problem)
    slower = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(replace(problem, actuator_margin=0.07))
    assert slower.ok and fastest.duration < slower.duration < 81.0  # both faster than the optimum (81.38 s)
    candidates, seed_bound = CollocationPlanner._bound_candidates, CollocationPlanner._seed_bound

    def with_a_slower_one(self, problem, starts):  # the slower first: a wrong comparison keeps it
        return [("eigenaxis at a 7 % margin", slower), *candidates(self, problem, starts)]

    before = []

    def recorded(self, problem, ocp, params, starts, reference):
        before.append(float(reference.duration))
        return seed_bound(self, problem, ocp, params, starts, reference)

    monkeypatch.setattr(CollocationPlanner, "_bound_candidates", with_a_slower_one)
    monkeypatch.setattr(CollocationPlanner, "_seed_bound", recorded)
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.ok, reference.message
    record = reference.stats["seed_bound"]
    checked = {entry["from"]: entry["checked"] for entry in record["candidates"]}
    assert checked["eigenaxis at a 7 % margin"] == "feasible" and checked["eigenaxis min_time"] == "feasible"
    assert record["bound_s"] == pytest.approx(fastest.duration, rel=1e-12)
    assert len(before) == 1 and reference.duration <= before[0]
    if record["resolve"]["duration_s"] is not None:
        assert reference.duration <= record["resolve"]["duration_s"]
