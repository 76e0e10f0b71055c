"""A study worker reuses a reference when the planning inputs are identical (the planner, its
options, the design problem), and plans again when any of them changes.

A Monte Carlo that disperses only the truth plant (``truth.*``) plans once per worker; its rows are
those of cases each planned afresh, bit for bit (the wall-clock ``plan_time_s`` aside).
"""
from __future__ import annotations

import copy
import math
from concurrent.futures import Executor, Future

import numpy as np
import pytest

import scenarios
from ocp import SolverCache
from planners import FailedReference
from planners.collocation.planner import CollocationPlanner
from planners.eigenaxis import EigenaxisPlanner
from scenarios.study.engine import sweep
from scenarios.study.spec import parse_study

BASE = {
    "name": "plan-reuse",
    "spacecraft": {"inertia": [3.0, 3.5, 4.0], "wheels": {"max_torque": 0.05, "spin_inertia": 2.0e-5}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "collocation", "label": "min energy", "options": {"intervals": 8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
    "truth": {"spacecraft": {"inertia": [3.1, 3.4, 4.1]}, "wheels": {"friction": {"coulomb": 1e-5}}},
}


class InlineExecutor(Executor):
    """Runs each task at submission, in this thread: one worker, the test's monkeypatching applied."""

    def submit(self, fn, *args, **kwargs):
        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as error:  # noqa: BLE001 - handed to the caller like any executor
            future.set_exception(error)
        return future


@pytest.fixture
def calls(monkeypatch):
    """Counts the plans of each planner class (the class's plan replaced by a counting one; a
    collocation's seed planned by eigenaxis counts too)."""
    counts = {"eigenaxis": 0, "collocation": 0}
    for name, kind in (("eigenaxis", EigenaxisPlanner), ("collocation", CollocationPlanner)):
        def counting(self, problem, original=kind.plan, name=name):
            counts[name] += 1
            return original(self, problem)

        monkeypatch.setattr(kind, "plan", counting)
    return counts


def _bits(value):
    """A row as nested plain values with every float as its exact bits (NaN equal to NaN)."""
    if isinstance(value, dict):
        return {key: _bits(item) for key, item in value.items() if key != "plan_time_s"}
    if isinstance(value, (list, tuple)):
        return [_bits(item) for item in value]
    if isinstance(value, (float, np.floating)):
        return "nan" if math.isnan(value) else float(value).hex()
    return value


def _study(dispersions, samples=3):
    return parse_study({"study": "plan-reuse", "scenario": copy.deepcopy(BASE),
                        "monte_carlo": {"samples": samples, "seed": 3, "dispersions": dispersions}})


def _fresh_rows(cases):
    """Each case run alone, its references planned afresh (no reuse), as rows."""
    return [[row.to_dict() for row in scenarios.run(scenarios.parse_scenario(copy.deepcopy(case.scenario)),
                                                    cache=SolverCache()).rows]
            for case in cases]


def test_a_plant_only_monte_carlo_plans_once_and_gives_the_rows_of_fresh_plans(calls):
    study = _study({"truth.spacecraft.inertia": {"principal": {"moments_scale": {"uniform": [[0.9] * 3, [1.1] * 3]}}},
                    "truth.wheels.friction.coulomb": {"uniform": [0.0, 4e-5]}})
    fresh = _fresh_rows(study.cases[:1])
    one = dict(calls)  # the plans of one case
    assert one["eigenaxis"] >= 1 and one["collocation"] == 1
    results = sweep(study, InlineExecutor())
    assert calls == {name: 2 * count for name, count in one.items()}  # one worker: planned in the first case only
    stored = [results.records[case.key]["rows"] for case in study.cases]
    assert all(row["status"] == "ok" for rows in stored for row in rows)
    # the closed loops differ (the plants do), the references do not
    assert len({rows[0]["closed_loop"]["final_error_deg"] for rows in stored}) == len(study.cases)
    # a reused row carries the time of the plan that made its reference
    assert len({rows[1]["plan_time_s"] for rows in stored}) == 1
    fresh += _fresh_rows(study.cases[1:])
    assert calls == {name: (1 + len(study.cases)) * count for name, count in one.items()}
    assert [_bits(rows) for rows in stored] == [_bits(rows) for rows in fresh]


def test_a_design_dispersion_plans_every_case(calls):
    study = _study({"spacecraft.inertia": {"principal": {"moments_scale": {"uniform": [[0.9] * 3, [1.1] * 3]}}}})
    sweep(study, InlineExecutor())
    assert calls["collocation"] == len(study.cases) and calls["eigenaxis"] >= len(study.cases)


def test_a_changed_planner_option_or_boundary_condition_plans_again(calls):
    references = SolverCache()

    def run(change=None):
        data = copy.deepcopy(BASE)
        data["planners"] = data["planners"][:1]
        if change:
            change(data)
        scenarios.run(scenarios.parse_scenario(data), cache=SolverCache(), references=references)

    run()
    run()
    assert calls["eigenaxis"] == 1
    run(lambda data: data["planners"][0].update(options={"torque_fraction": 0.8}))
    assert calls["eigenaxis"] == 2
    run(lambda data: data["maneuver"].update(duration=30.0 + 1e-12))  # compared exactly
    assert calls["eigenaxis"] == 3
    run(lambda data: data["maneuver"]["final"].update(omega=[0, 0, 1e-6]))
    assert calls["eigenaxis"] == 4
    run(lambda data: data.update(truth={"spacecraft": {"inertia": [3.2, 3.5, 4.0]}}))  # the plant only
    run(lambda data: data["simulation"].update(duration=40.0))  # the closed loop only
    assert calls["eigenaxis"] == 4


def test_a_failed_plan_is_never_reused(monkeypatch):
    planned = []

    def out_of_time(self, problem):
        planned.append(problem)
        return FailedReference(self.name, "time limit reached after 3 calls")

    monkeypatch.setattr(EigenaxisPlanner, "plan", out_of_time)
    references = SolverCache()
    data = copy.deepcopy(BASE)
    data["planners"] = data["planners"][:1]
    for _ in range(3):
        row = scenarios.run(scenarios.parse_scenario(data), references=references).rows[0]
        assert row.status == "failed" and "time limit" in row.message
    assert len(planned) == 3 and len(references) == 0


def test_a_reused_reference_is_a_copy_that_a_run_cannot_change(calls):
    references = SolverCache()
    data = copy.deepcopy(BASE)
    data["planners"] = data["planners"][:1]
    first = scenarios.run(scenarios.parse_scenario(data), references=references).rows[0].reference
    first.stats["certificate"] = {"verdict": "changed by the first run"}
    second = scenarios.run(scenarios.parse_scenario(data), references=references).rows[0].reference
    assert calls["eigenaxis"] == 1 and second is not first and "certificate" not in second.stats
