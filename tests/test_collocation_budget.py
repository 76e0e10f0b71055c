"""``collocation``'s minimum time under a time budget (``maneuver.duration``, the bound on its free
final time) shorter than its minimum time: an ``infeasible`` row with ``needed_duration_s``, as
``eigenaxis`` and a minimum-time ``costate_tpbvp`` give, not a ``failed`` one; a solve that does not
converge is still ``failed``.

Oracle: Bilimoria & Wie (1993), the rest-to-rest 180° slew about x of a unit-inertia body with
|u_i| <= 1 N m per body axis: minimum time 3.2431 s (published, not computed here). A budget of 3.0 s
is below it, 3.3 s above it.
"""
from __future__ import annotations

import numpy as np
import pytest
import yaml

import planners.collocation.planner as collocation_planner
from ocp.nlp.solve import solve_multistart
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


class Solves:
    """Every NLP solve of collocation while planning: its time bound (the ``maneuver.duration``
    parameter of the NLP) [s], its number of decision variables and its solver iterations."""

    def __init__(self) -> None:
        self.records: list[tuple[float, int, int]] = []

    def __call__(self, solver, guesses, **arguments):
        result = solve_multistart(solver, guesses, **arguments)
        bound = float(np.asarray(arguments["p"], dtype=float)[DURATION_PARAMETER])
        self.records.append((bound, int(np.size(arguments["lbx"])), result.iterations))
        return result


DURATION_PARAMETER = 14  # the NLP's parameters: state (7), final attitude (4), final rate (3), duration


def counted(duration: float, **options: object):
    """The row of ``duration`` and the solves that planned it."""
    solves = Solves()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(collocation_planner, "solve_multistart", solves)
        row = run(scenario(duration, **options)).rows[0]
    return row, solves.records


@pytest.fixture(scope="module")
def short_budget_row():
    """The row of a 3.0 s budget and its solves (planned once for the tests that read it)."""
    return counted(3.0)


def test_a_budget_below_the_minimum_time_is_infeasible_with_the_duration_needed(short_budget_row) -> None:
    """3.0 s < 3.2431 s: the row is infeasible (not failed), and its needed_duration_s is the
    planner's minimum time with the bound released, at least the published optimum (to its four
    decimals) and within 1e-4 s of it; the message says it is a local optimum, not a proof."""
    row, _ = short_budget_row
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
    reference = short_budget_row[0].reference
    assert reference.status == "infeasible", reference.message
    assert reference.duration == pytest.approx(PUBLISHED, abs=1e-4)
    record = reference.stats["time_bound"]
    assert record["bound_s"] == 3.0 and record["feasible_s"] > PUBLISHED and record["released_ok"]
    assert record["released_T_s"] == reference.duration
    assert record["bounded_status"]  # what the solver said under the bound
    assert record["intervals"] == 8  # the coarse mesh: the released optimum settled it


def test_the_verdict_costs_the_coarse_starts_and_the_released_solve_only(short_budget_row) -> None:
    """Under the 3 s bound only the coarse multistart is solved (its starts end locally infeasible,
    and the released optimum is longer than the bound): no full-mesh attempt under the bound (a
    planner that made one: 3 starts and 906 iterations on 50 intervals after 677 on 8, 1633 in all),
    and no fallback start after starts that all found the bound locally infeasible (the unperturbed
    eigenaxis start ran to the iteration limit: 500 of 727 iterations; 227 now)."""
    row, solves = short_budget_row
    bounded = [(size, iterations) for bound, size, iterations in solves if bound == 3.0]
    coarse = min(size for _, size, _ in solves)
    assert bounded and all(size == coarse for size, _ in bounded), bounded
    assert sum(iterations for _, iterations in bounded) <= 300, bounded
    assert sum(iterations for _, _, iterations in solves) <= 400, solves


def test_a_budget_between_the_coarse_and_the_exact_minimum_is_met_by_the_released_optimum() -> None:
    """3.2432 s: above the minimum time but below the coarse mesh's (3.243488 s on 8 intervals), whose
    starts all fail under it: the released minimum time (the exact bang-bang optimum, 3.2430833 s)
    lies within the bound, so it is the bounded problem's optimum too; no solve on the full mesh
    under the bound is needed (before: 1908-variable solves under the bound, ok at the 50-interval
    optimum 3.2431108 s)."""
    row, solves = counted(3.2432)
    assert row.status == "ok", row.message
    assert row.reference.duration == pytest.approx(PUBLISHED, abs=1e-4)
    assert row.reference.duration <= 3.2432
    coarse = min(s for _, s, _ in solves)
    assert not any(bound == 3.2432 and size > coarse for bound, size, _ in solves), solves
    record = row.reference.stats["time_bound"]
    assert record["bound_s"] == 3.2432 and record["released_T_s"] == row.reference.duration
    assert "is within the bound" in row.message


def test_the_suggested_duration_of_an_infeasible_row_admits_a_certified_slew(short_budget_row) -> None:
    """The duration a too-short budget's row suggests ("a maneuver.duration of 3.243084 s admits this
    slew": the least time rounded up) is met: the row at that budget is ok, its slew no longer than
    the budget and certified. Before, the full mesh under the bound (its optimum 3.2431108 s, above
    the suggestion) stopped at IPOPT's acceptable level at T = 3.243084032 s, over the budget."""
    suggested = collocation_planner._rounded_up(short_budget_row[0].needed_duration_s)
    assert f"a maneuver.duration of {suggested} s admits this slew" in short_budget_row[0].message
    row = run(scenario(float(suggested))).rows[0]
    assert row.status == "ok", row.message
    assert row.reference.duration <= float(suggested)
    assert row.reference.stats["certificate"]["verdict"] == "certified", row.reference.stats["certificate"]


def test_a_weighted_objective_with_a_time_term_is_infeasible_below_the_minimum_time() -> None:
    """objective weighted (energy and time) under 3.0 s: its problem admits a slew exactly where a
    slew of at most 3.0 s exists, so the row is infeasible with the minimum time (objective
    min_time, the bound released) as its needed duration, a local optimum, not a proof."""
    row, _ = counted(3.0, objective="weighted", energy_weight=1.0, time_weight=1.0)
    assert row.status == "infeasible", row.message
    assert row.needed_duration_s == pytest.approx(PUBLISHED, abs=1e-4)
    assert row.needed_duration_s >= PUBLISHED - 5e-5
    assert "local optimum" in row.message and "not a proof" in row.message
    assert "objective min_time" in row.message and row.message.startswith("weighted")
    assert row.reference.stats["time_bound"]["released_objective"] == "min_time"


def test_a_budget_above_the_minimum_time_is_ok() -> None:
    """3.3 s > 3.2431 s: ok, at the published optimum."""
    row = run(scenario(3.3)).rows[0]
    assert row.status == "ok", row.message
    assert row.reference.duration == pytest.approx(PUBLISHED, abs=1e-4)
    assert row.needed_duration_s is None


@pytest.mark.parametrize("duration, objective", [(3.0, "min_time"), (10.0, "min_time"), (3.0, "weighted")])
def test_a_solve_that_does_not_converge_is_still_failed(duration: float, objective: str) -> None:
    """Three iterations per start converge nowhere, under a short budget or a long one, for minimum
    time or a weighted cost with a time term: failed (a numerical failure), never infeasible, and no
    needed duration is claimed."""
    weights = {"time_weight": 1.0} if objective == "weighted" else {}
    row = run(scenario(duration, max_iterations=3, objective=objective, **weights)).rows[0]
    assert row.status == "failed", row.message
    assert row.needed_duration_s is None
    assert "did not converge" in row.message



FULL_INERTIA_7S = """
name: full-inertia-budget
spacecraft: {inertia: [[10, 0.5, 0.2], [0.5, 8, 0.3], [0.2, 0.3, 6]], wheels: none, torquers: {max_torque: 1.0}}
maneuver:
  duration: 7.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.25881904510252074, 0.5576775358252053, 0.5576775358252053, 0.5576775358252053], omega: [0, 0, 0]}
planners: [{name: collocation, options: {objective: min_time}}]
controller: {name: augmented_quaternion_feedback, options: {kp: 2.0, kd: 3.0}}
simulation: {sample_time: 0.05, duration: 9.0}
"""
"""150° about [1, 1, 1] of a full inertia under a 7.0 s budget, below its minimum time (7.68249 s,
``scenarios/bench/suite.yaml``): its full mesh under the bound costs a fifth of B&W's."""


def _counted_with(change, **options: object) -> tuple:
    """The row of :data:`FULL_INERTIA_7S` and its solves, ``change(planner, problem, reference)``
    replacing the released solve's reference (the plan of a problem whose bound is not the 7.0 s
    budget: the bound released to a feasible slew)."""
    plan_from = collocation_planner.CollocationPlanner._plan_from

    def patched(self, problem, starts, defer=False, resumed=None):
        reference = plan_from(self, problem, starts, defer=defer, resumed=resumed)
        return reference if float(problem.duration) == 7.0 else change(self, problem, reference)

    solves = Solves()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(collocation_planner, "solve_multistart", solves)
        patch.setattr(collocation_planner.CollocationPlanner, "_plan_from", patched)
        data = yaml.safe_load(FULL_INERTIA_7S)
        data["planners"][0]["options"].update(options)
        row = run(parse_scenario(data)).rows[0]
    return row, solves.records


def test_a_released_solve_that_fails_leaves_the_row_failed_after_the_full_mesh_under_the_bound() -> None:
    """Where the minimum time with the bound released does not converge (here: replaced by a failure),
    nothing is known of the least time: the row stays failed (a numerical failure, no needed
    duration), its message says what the released solve did, and the full mesh was tried under the
    bound after the coarse one, as without the deferral."""
    from planners.reference import FailedReference

    row, solves = _counted_with(lambda planner, problem, reference: FailedReference(planner.name, "stopped (test)"))
    assert row.status == "failed", row.message
    assert row.needed_duration_s is None
    assert "did not converge either: stopped (test)" in row.message, row.message
    coarse = min(size for _, size, _ in solves)
    assert any(bound == 7.0 and size > coarse for bound, size, _ in solves), solves  # the full mesh, under the bound
    assert row.reference.stats["time_bound"]["released_ok"] is False


def test_a_released_optimum_within_the_bound_leaves_a_weighted_row_failed_and_says_to_try_more_starts() -> None:
    """A weighted objective with a time term, whose released minimum time converges within the budget
    (here: its duration replaced by 6.9 s < 7.0 s): the weighted starts under the bound failed for
    another reason than the budget, and the minimum time is not the weighted optimum, so the full
    mesh is tried under the bound, and where it fails too the row is failed (not infeasible, no
    needed duration), its message naming the released time and suggesting more starts."""
    def shortened(planner, problem, reference):
        reference.duration = 6.9
        return reference

    row, solves = _counted_with(shortened, objective="weighted", energy_weight=1.0, time_weight=1.0)
    assert row.status == "failed", row.message
    assert row.needed_duration_s is None
    assert "converged to T = 6.9 s, within the bound" in row.message and "try more starts" in row.message, row.message
    coarse = min(size for _, size, _ in solves)
    assert any(bound == 7.0 and size > coarse for bound, size, _ in solves), solves
    assert row.reference.stats["time_bound"]["released_T_s"] == 6.9
