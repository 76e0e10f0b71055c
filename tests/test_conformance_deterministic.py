"""The ``deterministic`` conformance check: a planner declaring ``deterministic`` (the default, on
which a trade study reuses its references) gives the same reference, bit for bit, when one problem
is planned twice by fresh instances; a planner whose plans differ fails with a message that says to
declare ``deterministic = False``; one that declares it is not asked. Every built-in planner passes
(``tests/test_planner_conformance.py`` runs the check on each option set)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from planners import PLANNERS
from planners.conformance import (
    CHECKS,
    check_deterministic,
    check_reference,
    determinism_problem,
    standard_problems,
)
from planners.eigenaxis import EigenaxisPlanner
from planners.errors import ConformanceError
from tests.test_plan_reuse import Jittery, JitteryDeclared


class Remembers(EigenaxisPlanner):
    """Deterministic from a cold start, but its plan depends on what its solver cache holds (a
    count it keeps there, as a planner warm-starting from its last solution would)."""

    name = "remembers"

    def _plan(self, problem):
        count = self.solver_cache(problem).get(("remembers", "count"), lambda: [0])
        count[0] += 1
        return super()._plan(dataclasses.replace(problem, duration=problem.duration + 1e-9 * (count[0] - 1)))


class OneUlp(EigenaxisPlanner):
    """Equal to rounding, not bit for bit: every other plan's rates are one unit in the last place
    above the first's (what a sum taken in another order gives)."""

    name = "one_ulp"
    calls = 0

    def _plan(self, problem):
        type(self).calls += 1
        reference = super()._plan(problem)
        if type(self).calls % 2 == 0:
            evaluate = reference._evaluate

            def nudged(t, evaluate=evaluate):
                sample = evaluate(t)
                return sample._replace(omega=np.nextafter(sample.omega, np.inf))
            reference._evaluate = nudged
        return reference


def test_a_planner_declaring_deterministic_whose_plans_differ_fails_saying_what_to_declare():
    with pytest.raises(ConformanceError, match=r"jittery_declared: planned twice on the standard problem "
                                               r"'rest_to_rest' by fresh instances, its references' duration differ.*"
                                               r"must declare deterministic = False"):
        check_deterministic(JitteryDeclared())


def test_through_check_reference_the_given_reference_is_the_first_plan():
    planner = JitteryDeclared({"profile": "trapezoidal"})
    problem = standard_problems()["non_principal"]
    reference = planner.plan(problem)
    for name, check in CHECKS.items():
        if name != "deterministic":
            check(problem, reference, planner)  # a consistent, conforming motion ...
    with pytest.raises(ConformanceError, match="deterministic = False"):
        check_reference(problem, reference, planner)  # ... that a second plan does not repeat


def test_a_planner_declaring_it_is_not_asked():
    assert Jittery.deterministic is False
    Jittery.plans = 0
    check_deterministic(Jittery())
    CHECKS["deterministic"](standard_problems()["rest_to_rest"], Jittery().plan(standard_problems()["rest_to_rest"]),
                            Jittery())
    assert Jittery.plans == 1  # only the plan the test made


def test_a_plan_that_depends_on_the_solver_cache_fails():
    with pytest.raises(ConformanceError, match="remembers: .*duration differ: 150.0 then 150.000000001"):
        check_deterministic(Remembers())


def test_a_difference_of_one_unit_in_the_last_place_fails():
    OneUlp.calls = 0
    with pytest.raises(ConformanceError, match=r"one_ulp: .* differ in ω at t = 0.0 s: .* \(2001 of 2001 times differ\)"):
        check_deterministic(OneUlp())


@pytest.mark.parametrize("name, problem", [("eigenaxis", "rest_to_rest"), ("spin_extremal", "spinning")])
def test_the_problem_is_the_cheapest_the_planner_accepts(name, problem):
    assert determinism_problem(PLANNERS[name]())[0] == problem
    check_deterministic(PLANNERS[name])  # the class: its default options


def test_a_reference_needs_its_problem():
    with pytest.raises(ValueError, match="needs the problem"):
        check_deterministic(EigenaxisPlanner(), reference=EigenaxisPlanner().plan(standard_problems()["rest_to_rest"]))
