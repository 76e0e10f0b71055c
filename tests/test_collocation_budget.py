"""``collocation``'s minimum time under a time budget (``maneuver.duration``, the bound on its free
final time) shorter than its minimum time: an ``infeasible`` row with ``needed_duration_s``, as
``eigenaxis`` and a minimum-time ``costate_tpbvp`` give, not a ``failed`` one; a solve that does not
converge is still ``failed``.

Oracle: Bilimoria & Wie (1993), the rest-to-rest 180° slew about x of a unit-inertia body with
|u_i| <= 1 N m per body axis: minimum time 3.2431 s (published, not computed here). A budget of 3.0 s
is below it, 3.3 s above it.
"""
from __future__ import annotations

import pytest
import yaml

from scenarios.runner import run
from scenarios.schema.loader import parse_scenario

PUBLISHED = 3.2431  # s, Bilimoria & Wie's minimum time, to its published digits

SCENARIO = """
name: bw-budget
spacecraft: {inertia: [1.0, 1.0, 1.0], wheels: none, torquers: {max_torque: 1.0}}
maneuver:
  duration: 3.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0, 1, 0, 0], omega: [0, 0, 0]}
planners: [{name: collocation, options: {objective: min_time}}]
controller: {name: augmented_quaternion_feedback, options: {kp: 2.0, kd: 3.0}}
simulation: {sample_time: 0.05, duration: 5.0}
"""


def scenario(duration: float, **options: object):
    data = yaml.safe_load(SCENARIO)
    data["maneuver"]["duration"] = duration
    data["planners"][0]["options"].update(options)
    return parse_scenario(data)


@pytest.fixture(scope="module")
def short_budget_row():
    """The row of a 3.0 s budget (about 14 s of solves: planned once for the tests that read it)."""
    return run(scenario(3.0)).rows[0]


def test_a_budget_below_the_minimum_time_is_infeasible_with_the_duration_needed(short_budget_row) -> None:
    """3.0 s < 3.2431 s: the row is infeasible (not failed), and its needed_duration_s is the
    planner's minimum time with the bound released, at least the published optimum (to its four
    decimals) and within 1e-4 s of it; the message says it is a local optimum, not a proof."""
    row = short_budget_row
    assert row.status == "infeasible", row.message
    assert row.needed_duration_s is not None and row.needed_duration_s >= PUBLISHED - 5e-5
    assert row.needed_duration_s == pytest.approx(PUBLISHED, abs=1e-4)
    assert "local optimum" in row.message and "not a proof" in row.message
    assert "maneuver.duration = 3 s" in row.message
    assert row.simulation is None  # refused: nothing tracked


def test_the_planner_itself_says_infeasible_with_its_least_time(short_budget_row) -> None:
    """The planner's own reference (the row's, as the planner returned it): infeasible, its duration
    the released optimum, its stats recording the bound, what it was released to and the statuses
    under the bound."""
    reference = short_budget_row.reference
    assert reference.status == "infeasible", reference.message
    assert reference.duration == pytest.approx(PUBLISHED, abs=1e-4)
    record = reference.stats["time_bound"]
    assert record["bound_s"] == 3.0 and record["feasible_s"] > PUBLISHED and record["released_ok"]
    assert record["released_T_s"] == reference.duration
    assert record["bounded_status"]  # what the solver said under the bound


def test_a_budget_above_the_minimum_time_is_ok() -> None:
    """3.3 s > 3.2431 s: ok, at the published optimum."""
    row = run(scenario(3.3)).rows[0]
    assert row.status == "ok", row.message
    assert row.reference.duration == pytest.approx(PUBLISHED, abs=1e-4)
    assert row.needed_duration_s is None


@pytest.mark.parametrize("duration", [3.0, 10.0])
def test_a_solve_that_does_not_converge_is_still_failed(duration: float) -> None:
    """Three iterations per start converge nowhere, under a short budget or a long one: failed (a
    numerical failure), never infeasible, and no needed duration is claimed."""
    row = run(scenario(duration, max_iterations=3)).rows[0]
    assert row.status == "failed", row.message
    assert row.needed_duration_s is None
    assert "did not converge" in row.message
