"""Ties in :func:`ocp.nlp.solve.solve_multistart`: a secondary criterion among equal optima."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocp.nlp.solve import solve_multistart, solver_options


@pytest.fixture(scope="module")
def double_well():
    """min (x² − 1)² + a x: two minima at x ≈ ±1, equal (f = 0) for a = 0."""
    x, a = ca.SX.sym("x"), ca.SX.sym("a")
    return ca.nlpsol("double_well", "ipopt", {"x": x, "p": a, "f": (x ** 2 - 1) ** 2 + a * x},
                     solver_options("ipopt", 1e-12, 100))


@pytest.mark.parametrize("order", [(1.3, -1.3), (-1.3, 1.3)])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_equal_optima_are_ranked_by_the_tie_break(double_well, order, sign):
    result = solve_multistart(double_well, [np.array([g]) for g in order], p=0.0, agree=0,
                              tie_break=lambda x: sign * float(x[0]))
    assert result.success and len(result.starts) == 2
    assert result.x[0] == pytest.approx(-sign, abs=1e-8)  # whatever the order of the starts
    assert result.f == pytest.approx(0.0, abs=1e-12)


def test_the_tie_break_does_not_override_a_better_objective(double_well):
    # a = 0.1: the minimum near −1 is lower by about 0.2; a tie-break preferring +1 must not win
    result = solve_multistart(double_well, [np.array([-1.3]), np.array([1.3])], p=0.1, agree=0,
                              tie_break=lambda x: -float(x[0]))
    assert result.x[0] < 0 and result.f == pytest.approx(min(s.f for s in result.starts))


def test_without_a_tie_break_the_least_objective_wins(double_well):
    result = solve_multistart(double_well, [np.array([1.3]), np.array([-1.3])], p=-1e-9, agree=0)
    assert result.x[0] > 0  # f(+1) = −1e-9 < f(−1) = +1e-9: the least objective, however slight


@pytest.fixture(scope="module")
def triple_well():
    """min 100 (x (x² − 1))² + a x: three minima near −1, 0, +1 with f ≈ −a, −a²/400, +a."""
    x, a = ca.SX.sym("x"), ca.SX.sym("a")
    return ca.nlpsol("triple_well", "ipopt", {"x": x, "p": a, "f": 100 * (x * (x ** 2 - 1)) ** 2 + a * x},
                     solver_options("ipopt", 1e-12, 100))


@pytest.mark.parametrize("order", [(1.3, 0.1, -1.3), (-1.3, 0.1, 1.3), (0.1, 1.3, -1.3)])
def test_ties_are_judged_against_the_least_objective_whatever_the_order(triple_well, order):
    # a = 0.6, atol 0.8: f ≈ −0.600, −0.001, +0.600. The start near 0 agrees with both others, which
    # do not agree with each other (1.2 apart). The least objective is −0.600; the starts within
    # 0.8 of it are those near −1 and 0, and the tie-break (1 − x) prefers the one near 0. Judged
    # against the kept start instead, a chain −1 → 0 → +1 kept +0.600, 1.2 above a converged start.
    result = solve_multistart(triple_well, [np.array([g]) for g in order], p=0.6, agree=0, rtol=0.0, atol=0.8,
                              tie_break=lambda x: 1.0 - float(x[0]))
    assert sorted(round(s.f, 1) for s in result.starts) == [-0.6, -0.0, 0.6] and all(s.converged for s in result.starts)
    assert result.x[0] == pytest.approx(0.0, abs=0.01)
    assert result.f <= min(s.f for s in result.starts) + 0.8
    assert result.f == result.starts[result.best_start].f


@pytest.mark.parametrize("value", [np.inf, np.nan])
def test_a_start_whose_tie_break_is_not_finite_still_counts(double_well, value):
    # the only converged start must be the result, whatever its secondary criterion
    result = solve_multistart(double_well, [np.array([1.3])], p=0.0, agree=0, tie_break=lambda x: value)
    assert result.success and result.best_start == 0, result.message
    assert result.x[0] == pytest.approx(1.0, abs=1e-8)
