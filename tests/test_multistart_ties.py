"""Ties in :func:`ocp.nlp.solve_multistart`: a secondary criterion among equal optima."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocp.nlp import solve_multistart, solver_options


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
