"""scenarios.runner.planning_key, input by input: a reference is reused only when the planner's class,
its options and the design problem are all equal; the solver cache a planner builds into is no
input; a planner declaring itself not deterministic has no key. And what ``run`` keeps under a key:
successful references only, each row given its own copy.

Oracles: planners that plan differently by construction (a subclass that changes one method,
another option), counted calls of ``plan`` and the references' own fields.
"""
from __future__ import annotations

import copy

import scenarios
from ocp import SolverCache
from planners import FailedReference
from planners.eigenaxis import EigenaxisPlanner
from scenarios.runner import planning_key
from tests.test_exact_key import BASE


class _Refusing(EigenaxisPlanner):
    """Another planner that shares the eigenaxis planner's ``plan`` and ``_plan`` and its options,
    and refuses every bang profile."""

    def _plan_bang(self, problem, axis, angle, max_rate, horizon, environment=None):
        return FailedReference(self.name, "refused", "infeasible")


def _scenario():
    return scenarios.parse_scenario(copy.deepcopy(BASE))


def test_another_planner_class_with_the_same_methods_and_options_has_another_key():
    scenario = _scenario()
    options = {"profile": "min_time"}
    own, other = EigenaxisPlanner(options), _Refusing(options)
    assert own.plan(scenario.problem).ok and not other.plan(scenario.problem).ok  # they plan differently
    assert vars(own).keys() == vars(other).keys() and _Refusing.plan is EigenaxisPlanner.plan
    assert _Refusing._plan is EigenaxisPlanner._plan
    assert planning_key(own, scenario.problem) != planning_key(other, scenario.problem)


def test_another_option_gives_another_key():
    problem = _scenario().problem
    keys = {planning_key(EigenaxisPlanner({"profile": profile}), problem) for profile in ("smooth", "trapezoidal")}
    keys.add(planning_key(EigenaxisPlanner({"profile": "trapezoidal", "torque_fraction": 0.5}), problem))
    assert None not in keys and len(keys) == 3


def test_the_solver_cache_is_no_input():
    problem = _scenario().problem
    planner = EigenaxisPlanner({"profile": "trapezoidal"})
    first, second = planner.with_cache(SolverCache()), planner.with_cache(SolverCache())
    assert first.cache is not second.cache
    key = planning_key(first, problem)
    assert key is not None and key == planning_key(second, problem) == planning_key(planner, problem)


def test_a_planner_declaring_itself_not_deterministic_has_no_key():
    class Random(EigenaxisPlanner):
        deterministic = False

    problem = _scenario().problem
    assert planning_key(EigenaxisPlanner({}), problem) is not None
    assert planning_key(Random({}), problem) is None


def _run(references):
    data = copy.deepcopy(BASE)
    return scenarios.run(scenarios.parse_scenario(data), cache=SolverCache(), references=references).rows[0]


def test_a_failure_is_not_kept_and_the_next_success_is(monkeypatch):
    outcomes = iter(["failed", "ok", "ok"])
    planned = []
    original = EigenaxisPlanner.plan

    def sometimes(self, problem):
        planned.append(None)
        if next(outcomes) == "failed":
            return FailedReference(self.name, "time limit reached")
        return original(self, problem)

    monkeypatch.setattr(EigenaxisPlanner, "plan", sometimes)
    references = SolverCache()
    assert _run(references).status == "failed" and len(references) == 0
    assert _run(references).reference.ok and len(references) == 1
    assert _run(references).reference.ok
    assert len(planned) == 2  # failed, planned and kept, reused


def test_each_reuse_has_stats_of_its_own():
    references = SolverCache()
    first = _run(references).reference
    second = _run(references).reference
    assert first is not second and first.stats is not second.stats
    second.stats["certificate"] = {"verdict": "written by the second row"}
    third = _run(references).reference
    assert "certificate" not in third.stats and "certificate" not in first.stats
    assert third.duration == first.duration
