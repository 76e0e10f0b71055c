"""The NLP status policy (module docstring of :mod:`ocp.nlp.solve`) on scripted solver outcomes,
one case per branch (issue 33): a stalled point counts only when feasible, one infeasible start
does not make a multistart infeasible, the least converged objective wins, early stopping counts
agreeing starts, and a start stopped at IPOPT's acceptable level is continued from where it
stopped."""
import casadi as ca
import numpy as np
import pytest

from ocp.nlp import solve_multistart

STALLED = "Search_Direction_Becomes_Too_Small"


class ScriptedSolver:
    """Stands for a ``casadi.nlpsol`` function: each call returns the next scripted outcome
    ``(status, success, f, g)``; the decision vector returned is ``[f]``. Records its calls."""

    def __init__(self, outcomes):
        self.outcomes, self.calls, self._stats = list(outcomes), [], {}

    def __call__(self, **arguments):
        self.calls.append(arguments)
        status, success, f, g = self.outcomes.pop(0)
        self._stats = {"return_status": status, "success": success, "iter_count": 10}
        return {"x": ca.DM([f]), "f": ca.DM(f), "g": ca.DM(g), "lam_x": ca.DM([0.5]), "lam_g": ca.DM([0.0] * len(g))}

    def stats(self):
        return self._stats


def solve(outcomes, **options):
    solver = ScriptedSolver(outcomes)
    guesses = [np.array([float(i)]) for i in range(len(outcomes))]
    result = solve_multistart(solver, guesses, lbg=[0.0], ubg=[0.0], agree=options.pop("agree", 0), **options)
    return result, solver


@pytest.mark.parametrize("violation, accepted", [(1e-3, False), (-1e-3, False), (1e-7, False), (1e-9, True), (0.0, True)])
def test_a_stalled_point_counts_only_when_feasible(violation, accepted):
    result, _ = solve([(STALLED, False, 1.0, [violation])], feasibility_tolerance=1e-8)
    assert result.success is accepted
    assert result.status == ("ok" if accepted else "failed")
    assert result.starts[0].converged is accepted


def test_stalled_infeasible_does_not_beat_a_worse_converged_start():
    result, _ = solve([(STALLED, False, 1.0, [1e-2]), ("Solve_Succeeded", True, 5.0, [0.0])])
    assert result.success and result.f == 5.0 and result.best_start == 1


@pytest.mark.parametrize("statuses, local", [
    (["Infeasible_Problem_Detected", "Maximum_Iterations_Exceeded"], False),
    (["Maximum_Iterations_Exceeded", "Restoration_Failed"], False),
    (["Infeasible_Problem_Detected", "Restoration_Failed"], True),
    (["Infeasible_Problem_Detected"], True),
])
def test_locally_infeasible_starts_fail_and_say_so_but_prove_nothing(statuses, local):
    # IPOPT's infeasibility is local: collocation's minimum energy over XTE at 1.001 T* ended so from
    # both starts (a fresh-eyes check, 2026-12-02) where the stretched minimum-time optimum is feasible
    result, _ = solve([(s, False, 1.0, [1.0]) for s in statuses])
    assert not result.success and result.status == "failed"
    assert ("every start locally infeasible: not a proof" in result.message) is local, result.message


def test_one_infeasible_start_beside_a_converged_one_is_ok():
    result, _ = solve([("Infeasible_Problem_Detected", False, 0.5, [1.0]), ("Solve_Succeeded", True, 2.0, [0.0])])
    assert result.success and result.status == "ok" and result.f == 2.0 and result.best_start == 1


def test_the_least_converged_objective_wins_and_failed_starts_never_do():
    result, _ = solve([("Solve_Succeeded", True, 3.0, [0.0]), ("Maximum_Iterations_Exceeded", False, 0.1, [0.0]),
                       ("Solve_Succeeded", True, 2.0, [0.0]), ("Solve_Succeeded", True, 2.5, [0.0])])
    assert result.f == 2.0 and result.best_start == 2 and list(result.x) == [2.0]
    assert [s.converged for s in result.starts] == [True, False, True, True]


def test_early_stop_once_enough_starts_agree():
    outcomes = [("Solve_Succeeded", True, 3.0, [0.0]), ("Solve_Succeeded", True, 2.0, [0.0]),
                ("Solve_Succeeded", True, 2.0 * (1 + 1e-9), [0.0]), ("Solve_Succeeded", True, 1.0, [0.0])]
    result, solver = solve(outcomes, agree=2)
    assert len(solver.calls) == 3 and result.f == 2.0  # the fourth start is never tried
    result, solver = solve(outcomes, agree=0)
    assert len(solver.calls) == 4 and result.f == 1.0


def test_a_start_at_the_acceptable_level_is_continued_from_where_it_stopped():
    """IPOPT's acceptable stop (150 here) is not the requested tolerance: the same solver, started
    again from that point with its multipliers, goes on (to 139); the start's outcome is the
    continuation's."""
    result, solver = solve([("Solved_To_Acceptable_Level", True, 150.0, [0.0]), ("Solve_Succeeded", True, 139.0, [0.0])],
                           agree=1)
    assert len(solver.calls) == 2
    np.testing.assert_array_equal(np.asarray(solver.calls[1]["x0"]).ravel(), [150.0])  # where it stopped
    assert "lam_x0" in solver.calls[1] and "lam_g0" in solver.calls[1]
    assert len(result.starts) == 1 and result.starts[0].f == 139.0 and result.starts[0].status == "Solve_Succeeded"
    assert result.f == 139.0 and result.starts[0].iterations == 20


def test_a_continuation_that_fails_leaves_the_acceptable_point():
    result, solver = solve([("Solved_To_Acceptable_Level", True, 150.0, [0.0]),
                            ("Maximum_Iterations_Exceeded", False, 120.0, [0.3])], agree=1)
    assert len(solver.calls) == 2 and result.success and result.f == 150.0
    assert result.starts[0].status == "Solved_To_Acceptable_Level"


@pytest.mark.parametrize("statuses, tried", [
    (["Maximum_Iterations_Exceeded"], True),  # a stall: the fallback may escape it
    (["Infeasible_Problem_Detected", "Restoration_Failed"], True),
    (["Infeasible_Problem_Detected", "Maximum_Iterations_Exceeded"], True),
    (["Infeasible_Problem_Detected"], False),  # locally infeasible from every start: nothing to escape
    (["Infeasible_Problem_Detected", "Infeasible_Problem_Detected"], False),
    (["Solve_Succeeded"], False),  # converged: fallbacks are for when nothing did
])
def test_a_fallback_is_tried_only_after_starts_that_stalled(statuses, tried):
    outcomes = [(s, s == "Solve_Succeeded", 1.0, [0.0 if s == "Solve_Succeeded" else 1.0]) for s in statuses]
    solver = ScriptedSolver(outcomes + [("Solve_Succeeded", True, 2.0, [0.0])])
    guesses = [np.array([float(i)]) for i in range(len(statuses))]
    result = solve_multistart(solver, guesses, lbg=[0.0], ubg=[0.0], agree=0, fallback=[np.array([9.0])])
    assert len(solver.calls) == len(statuses) + tried
    assert result.success is (tried or "Solve_Succeeded" in statuses)
