"""The certificate's scaled KKT error and the Radau points' times, against IPOPT's published rules
and the published Radau IIA nodes.

Oracles: Wächter & Biegler (2006), eq. (5) and section 3.8, with IPOPT's defaults: the overall error
``max(‖∇f + Jᵀλ + z‖∞ / s_d, ‖c‖∞, ‖complementarity‖∞ / s_c)`` with
``s_d = max(s_max, (‖λ‖₁ + ‖z‖₁) / (m + n_b)) / s_max``, ``s_max = 100``, ``m`` the constraint rows
and ``n_b`` the finite bounds of the variables that are not fixed, a variable's lower and upper
bound counted apart (``ocp.nlp.certificate.kkt_residuals``; the paper's ``n`` bounds every variable
once; IPOPT's own computation adds the multipliers of the inequality rows' slack bounds and their
count, ``‖v‖₁`` and ``n_v``, to both sums, ``s_c = max(s_max, (‖z‖₁ + ‖v‖₁) / (n_b + n_v)) / s_max``);
the gradient-based scaling
``s = min(1, 100 / ‖∇‖∞)`` of the objective and of each constraint row (``nlp_scaling_max_gradient``),
worked by hand on small NLPs; IPOPT's own reported dual infeasibility (``inf_du``, scaled) where the
objective scaling is 1; the Radau IIA nodes of degree 3, ``(4 ∓ √6) / 10`` and 1."""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from ocp.nlp.certificate import kkt_residuals
from ocp.nlp.solve import solver_options


def small_nlp(f, g=None, n=2, max_iterations=200):
    x = ca.SX.sym("x", n)
    problem = {"x": x, "f": f(x)}
    if g is not None:
        problem["g"] = g(x)
    return ca.nlpsol("s", "ipopt", problem, solver_options("ipopt", 1e-12, max_iterations))


def test_large_multipliers_divide_the_stationarity_by_s_d_by_hand():
    # min x² + y² on x + y = 1, at (0.6, 0.5) with λ = −500: ∇f + λ ∇g = (1.2 − 500, 1 − 500), so the
    # stationarity is 499; ∇f and ∇g are below 100 (no scaling); s_d = max(100, 500 / 1) / 100 = 5
    solver = small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: x[0] + x[1])
    kkt = kkt_residuals(solver, [0.6, 0.5], [0.0, 0.0], [-500.0], lbg=1.0, ubg=1.0)
    assert kkt.stationarity == pytest.approx(499.0) and kkt.feasibility == pytest.approx(0.1)
    assert kkt.objective_scaling == 1.0
    assert kkt.scaled == pytest.approx(499.0 / 5.0, rel=1e-12)
    # small multipliers: s_d = 1, the scaled error is the stationarity itself
    small = kkt_residuals(solver, [0.6, 0.5], [0.0, 0.0], [-1.0], lbg=1.0, ubg=1.0)
    assert small.scaled == pytest.approx(0.2, rel=1e-12)


def test_s_d_counts_the_rows_and_the_finite_bounds_of_the_moving_variables_by_hand():
    # The NLP above with a third variable w fixed at 0 (lbx = ubx: no multiplier of its own in IPOPT,
    # which removes it), x in [−10, 10] and y unbounded: m = 1 row, n_b = 2 finite bounds (x's two),
    # so s_d = max(100, 500 / 3) / 100 = 5 / 3 and the scaled error 499 × 3 / 5 = 299.4 (with m + n =
    # 4 it would be 499 / 1.25; counting w's bounds too, m + 4 = 5, 499 / 1).
    solver = small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: x[0] + x[1], n=3)
    kkt = kkt_residuals(solver, [0.6, 0.5, 0.0], [0.0, 0.0, 0.0], [-500.0], lbg=1.0, ubg=1.0,
                        lbx=[-10.0, -np.inf, 0.0], ubx=[10.0, np.inf, 0.0])
    assert kkt.stationarity == pytest.approx(499.0) and kkt.objective_scaling == 1.0
    assert kkt.scaled == pytest.approx(499.0 * 3.0 / 5.0, rel=1e-12)


def test_an_inequality_rows_slack_bounds_count_in_s_d_by_hand():
    # min x² + y² on 1 <= x + y <= 3, at (0.5, 0.5) with λ = −500 (the lower bound's): the
    # stationarity is |1 − 500| = 499, no scaling (gradients 1). IPOPT writes the row as
    # x + y − s = 0 with 1 <= s <= 3: its slack-bound multipliers v_L = 500, v_U = 0 (v_U − v_L = λ)
    # count in s_d beside λ, and its two finite bounds beside the row: s_d = max(100, (500 + 500) /
    # (1 + 2)) / 100 = 10 / 3, the scaled error 499 × 0.3 = 149.7 (without them 500 / 1: 499 / 5)
    solver = small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: x[0] + x[1])
    kkt = kkt_residuals(solver, [0.5, 0.5], [0.0, 0.0], [-500.0], lbg=1.0, ubg=3.0)
    assert kkt.stationarity == pytest.approx(499.0) and kkt.objective_scaling == 1.0
    assert kkt.complementarity == 0.0 and kkt.feasibility == 0.0
    assert kkt.scaled == pytest.approx(499.0 * 0.3, rel=1e-12)
    # an equality row has no slack: s_d = max(100, 500 / 1) / 100 = 5, as before
    equality = kkt_residuals(solver, [0.5, 0.5], [0.0, 0.0], [-500.0], lbg=1.0, ubg=1.0)
    assert equality.scaled == pytest.approx(499.0 / 5.0, rel=1e-12)


def test_an_inequality_rows_slack_bound_multipliers_divide_the_complementarity_by_hand():
    # min 500 (x² + y²) on 1 <= x + y <= 3 at (0.5005, 0.5005), λ = −500.5: stationary
    # (∇f = 500.5 each), the row 0.001 inside its lower bound, so the complementarity is
    # 500.5 × 0.001 = 0.5005. Scaled at x0 = 0 (∇f = 0: s_f = 1). No variable bounds: s_c comes from
    # the slack's alone, max(100, (500.5 + 0) / 2) / 100 = 2.5025, and the error is 0.5005 / 2.5025 =
    # 0.2 (without them s_c = 1: 0.5005); s_d = max(100, 1001 / 3) / 100 leaves the stationarity ~0
    solver = small_nlp(lambda x: 500 * (x[0] ** 2 + x[1] ** 2), lambda x: x[0] + x[1])
    kkt = kkt_residuals(solver, [0.5005, 0.5005], [0.0, 0.0], [-500.5], lbg=1.0, ubg=3.0, scaling_point=[0.0, 0.0])
    assert kkt.objective_scaling == 1.0 and kkt.stationarity < 1e-9
    assert kkt.complementarity == pytest.approx(0.5005, rel=1e-9)
    assert kkt.scaled == pytest.approx(0.2, rel=1e-9)


def test_a_steep_constraint_row_is_scaled_once_by_hand():
    # g = 300 (x + y) = 300: its gradient 300 gives the row the scale 100 / 300; at (0.5, 0.6) it is
    # 330, 30 over, so the scaled violation is 10; the objective x² + y² (gradient 1.2) is not scaled
    solver = small_nlp(lambda x: x[0] ** 2 + x[1] ** 2, lambda x: 300 * (x[0] + x[1]))
    kkt = kkt_residuals(solver, [0.5, 0.6], [0.0, 0.0], [0.0], lbg=300.0, ubg=300.0)
    assert kkt.feasibility == pytest.approx(30.0)
    assert kkt.feasibility_scaled == pytest.approx(10.0, rel=1e-12)


@pytest.mark.parametrize("iterations", [1, 2])
def test_small_gradients_leave_the_objective_unscaled_as_ipopt_reports(iterations):
    # ∇f = (0.2, 0.3) at the start, far below 100: IPOPT's s_f is 1 (it never scales up), and its
    # reported inf_du is the unscaled stationarity at the point and multipliers it returns
    def f(x):
        return 0.05 * (x[0] ** 2 + x[1] ** 2) + 0.001 * x[0] ** 4

    solver = small_nlp(f, lambda x: ca.vertcat(x[0] + x[1], x[0] - x[1] ** 2), max_iterations=iterations)
    x0 = np.array([2.0, 3.0])
    bounds = {"lbx": [-5.0, -5.0], "ubx": [5.0, 0.9], "lbg": [1.0, -0.2], "ubg": [1.0, -0.2]}
    solution = solver(x0=x0, **bounds)
    reported = solver.stats()["iterations"]["inf_du"][-1]
    kkt = kkt_residuals(solver, solution["x"].full(), solution["lam_x"].full(), solution["lam_g"].full(),
                        scaling_point=x0, **bounds)
    assert kkt.objective_scaling == 1.0
    assert reported > 1e-6  # far from converged: the comparison is not between two roundings
    assert kkt.stationarity_scaled == pytest.approx(reported, rel=1e-6)


def test_the_radau_points_times_are_the_published_nodes():
    from planners.collocation.certificate import radau_points
    from tests.test_certificate import bilimoria_wie_solution

    problem, solved, params, _, _ = bilimoria_wie_solution({"objective": "min_time", "intervals": 4})
    transcription = solved.transcription
    assert transcription.degree == 3
    _, _, _, t = radau_points(transcription, problem.model, solved.nlp, solved.result.x, solved.result.lam_g)
    T = float(solved.nlp.unpack(solved.result.x, params)[0])
    nodes = np.array([(4.0 - math.sqrt(6.0)) / 10.0, (4.0 + math.sqrt(6.0)) / 10.0, 1.0])
    expected = ((np.arange(4)[:, None] + nodes[None, :]) / 4 * T).ravel()
    np.testing.assert_allclose(t, expected, rtol=1e-12)


def test_the_derivatives_are_read_again_at_another_point_parameter_or_multiplier():
    # min (x − p)² + (y − p)² on x y = 1 (a parameter p; the second-order check also reads the
    # Hessian of the Lagrangian, which the multiplier of x y = 1 enters): a certificate's KKT
    # residuals and second-order check may reuse one evaluation of the derivatives only at the same
    # point, parameter and multipliers. Each case by hand: ∇f = 2 (x − p, y − p), ∇g = (y, x).
    from ocp.nlp.certificate import certify
    from ocp.nlp.second_order import second_order_check

    x, p = ca.SX.sym("x", 2), ca.SX.sym("p")
    solver = ca.nlpsol("s", "ipopt", {"x": x, "p": p, "f": (x[0] - p) ** 2 + (x[1] - p) ** 2, "g": x[0] * x[1]},
                       solver_options("ipopt", 1e-12, 100))
    at_one = {"lbg": 1.0, "ubg": 1.0}
    assert kkt_residuals(solver, [1.0, 1.0], [0.0, 0.0], [0.0], p=1.0, **at_one).stationarity == 0.0
    assert kkt_residuals(solver, [1.0, 1.0], [0.0, 0.0], [0.0], p=0.0, **at_one).stationarity == 2.0
    assert kkt_residuals(solver, [2.0, 0.5], [0.0, 0.0], [0.0], p=0.0, **at_one).stationarity == 4.0
    # at (1, 1) the multiplier λ = 2 (p − 1) makes it stationary; along the tangent (1, −1) the
    # Hessian 2 I + λ [[0, 1], [1, 0]] curves 4 − 2 λ: 2 > 0 at p = 1.5 (λ = 1), a strict minimum;
    # 0 at p = 2 (λ = 2), degenerate
    record = certify(solver, [1.0, 1.0], [0.0, 0.0], [1.0], p=1.5, **at_one)
    assert record["kkt_unscaled"] == 0.0 and record["second_order"] == "strict local minimum"
    degenerate = second_order_check(solver, [1.0, 1.0], [0.0, 0.0], [2.0], p=2.0, **at_one)
    assert not degenerate.certified and degenerate.degenerate
    record = certify(solver, [1.0, 1.0], [0.0, 0.0], [1.0], p=1.5, **at_one)
    assert record["second_order"] == "strict local minimum"
