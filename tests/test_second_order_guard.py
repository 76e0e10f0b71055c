"""The second-order check's accuracy guard at the finer thresholds of a degenerate point's refinement.

A degenerate point (no curvature below ``−δ``, some between ``±δ``) is checked again at ``δ / √10``,
``δ / 10``, ... and each factorisation must pass the guard at its own threshold: backward error times
``‖K̃‖∞`` below ``threshold / (‖H‖∞ GUARD)``. Here a factorisation with a fixed backward error, set
between the guard's bound at ``δ`` and at ``δ / √10``, stands for one accurate enough for ``δ`` and
not finer; the bounds are worked by hand from the module's constants.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

from ocp.nlp import second_order
from ocp.nlp.second_order import second_order_check
from ocp.nlp.solve import solver_options

BACKWARD_ERROR = 5e-8
"""The factorisation's backward error times ‖K̃‖∞ (the check estimates it from one solve)."""


class InaccurateSolve:
    """A CasADi ``ldl`` whose solve comes back off by a residual of ``BACKWARD_ERROR`` ‖x‖∞ in its
    first row (the rest of the factorisation, its rank and inertia, as it is)."""

    def __init__(self, linsol):
        self.linsol = linsol

    def __getattr__(self, name):
        return getattr(self.linsol, name)

    def solve(self, values, rhs):
        solution = np.asarray(self.linsol.solve(values, rhs)).ravel()
        # K (x + t) − b = K t = BACKWARD_ERROR ‖x‖∞ e_0 for t = e_0 BACKWARD_ERROR ‖x‖∞ / K_00 (K_00 alone in its row)
        solution[0] += BACKWARD_ERROR * np.max(np.abs(solution)) / float(values[0, 0])
        return ca.DM(solution)


def tiny_curvature_check():
    # f = x² + 1.5e-9 y² at 0: ∇²f = diag(2, 3e-9), ‖H‖∞ = 2, δ = 2e-6: y between ±δ (degenerate);
    # refined, it is certified below 3e-9 (at δ / 10³ = 2e-9) when every factorisation is accurate
    x = ca.SX.sym("x", 2)
    solver = ca.nlpsol("s", "ipopt", {"x": x, "f": x[0] ** 2 + 1.5e-9 * x[1] ** 2}, solver_options("ipopt", 1e-12, 50))
    return second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))


def test_the_guard_bounds_are_on_either_side_of_the_error_by_hand():
    # ‖H‖∞ = 2 and K̃ = H / 2 + shift / 2: ‖K̃‖∞ = 1 to 1e-6. The bound at δ = 2e-6 is 2e-6 / (2 × 10) =
    # 1e-7, at δ / √10 it is 3.16e-8: the error 5e-8 passes the first and fails the second
    assert second_order.GUARD == 10.0 and second_order.REFINEMENT == np.sqrt(10.0)
    scale = 2.0
    delta = second_order.CURVATURE_TOLERANCE * scale
    assert delta / scale / second_order.GUARD > BACKWARD_ERROR * (1 + 1e-6)
    assert delta / second_order.REFINEMENT / scale / second_order.GUARD < BACKWARD_ERROR


def test_accurate_factorisations_certify_the_tiny_curvature_below_the_first_threshold():
    check = tiny_curvature_check()
    assert check.certified and 2e-10 <= check.curvature_threshold < 3e-9, check.message


def test_a_factorisation_accurate_at_delta_only_does_not_certify_finer(monkeypatch):
    linsol = second_order._linsol
    monkeypatch.setattr(second_order, "_linsol",
                        lambda *args: (lambda found: (found[0], InaccurateSolve(found[1]), found[2]))(linsol(*args)))
    check = tiny_curvature_check()
    # at δ the guard passes (a degenerate count, not "not accurate enough"); at δ / √10 it fails, so the
    # refinement stops there: degenerate, not certified (a guard applied at δ alone would certify at 2e-9)
    assert not check.certified and check.degenerate and check.negative_curvatures == 0, check.message
    assert check.curvature_threshold == 2e-6 and "1 directions of curvature between" in check.message
