"""The second-order check (ocp.nlp.second_order) against closed forms, and its use by the multistart.

Oracles: the reduced Hessian of small NLPs worked by hand (a saddle, a maximum on a line, a vertex,
a weakly active bound), then the eigenaxis slew, a known saddle of Bilimoria & Wie's minimum-time
problem (2 √π = 3.5449 against the optimum 3.2431), found by IPOPT from the unperturbed warm start.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocp.nlp.second_order import second_order_check
from ocp.nlp.solve import solve_multistart, solver_options
from planners import PLANNERS
from planners.collocation.reference import seed_sampler
from planners.collocation.strategy import control_floor
from tests.test_collocation import bilimoria_wie_problem


def nlp(f, g=None, n=2, solver="ipopt"):
    x = ca.SX.sym("x", n)
    problem = {"x": x, "f": f(x)}
    if g is not None:
        problem["g"] = g(x)
    # FATROP without its structure detection: only its derivative functions are used here
    options = solver_options("ipopt", 1e-12, 200) if solver == "ipopt" else {"print_time": False}
    return ca.nlpsol("s", solver, problem, options)


@pytest.mark.parametrize("solver", ["ipopt", "fatrop"])
def test_an_unconstrained_saddle_has_its_negative_curvature(solver):
    # f = x² − y² at 0: ∇²f = diag(2, −2), no constraint, so Z is the plane and the least curvature −2.
    # (FATROP's nlp_hess_l returns the Lagrangian's gradient first, then its full Hessian.)
    solver = nlp(lambda x: x[0] ** 2 - x[1] ** 2, solver=solver)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))
    assert not check.certified
    assert check.null_dimension == 2
    assert check.min_curvature == pytest.approx(-2.0)


@pytest.mark.parametrize("sign, certified", [(-1.0, True), (1.0, False)])
def test_the_curvature_along_an_equality_constraint(sign, certified):
    # f = ±x y on x + y = 2 at (1, 1), multiplier ∓1 (∇f + λ ∇g = 0). Along d = (1, −1)/√2:
    # dᵀ ∇²f d = ±(2 d₁ d₂) = ∓1, so −x y has a minimum there (curvature 1) and x y a maximum (−1).
    solver = nlp(lambda x: sign * x[0] * x[1], lambda x: x[0] + x[1])
    check = second_order_check(solver, np.ones(2), np.zeros(2), np.array([-sign]), lbg=2.0, ubg=2.0)
    assert check.certified is certified
    assert check.null_dimension == 1
    assert check.min_curvature == pytest.approx(-sign)


@pytest.mark.parametrize("solver", ["ipopt", "fatrop"])
@pytest.mark.parametrize("corner, certified", [(-1.0, True), (1.0, False)])
def test_the_curvature_of_a_nonlinear_constraint_comes_from_its_multiplier(solver, corner, certified):
    # min x + y on x² + y² = 2: ∇f + λ ∇g = (1, 1) + 2 λ (x, y) = 0 gives λ = 1/2 at (−1, −1) (the
    # minimum) and λ = −1/2 at (1, 1) (the maximum). ∇²f = 0, so ∇²L = 2 λ I: the curvature along the
    # circle, 2 λ = ∓1, is the multiplier's alone (its sign in CasADi's L = f + λᵀ g decides).
    solver = nlp(lambda x: x[0] + x[1], lambda x: x[0] ** 2 + x[1] ** 2, solver=solver)
    lam = np.array([-0.5 * corner])
    check = second_order_check(solver, corner * np.ones(2), np.zeros(2), lam, lbg=2.0, ubg=2.0)
    assert check.certified is certified and check.null_dimension == 1
    assert check.min_curvature == pytest.approx(-corner)


@pytest.mark.parametrize("case", ["maximum with multipliers of the wrong sign", "not stationary",
                                  "multiplier of an inactive one-sided constraint"])
def test_a_point_that_is_not_first_order_is_not_certified(case):
    # Theorem 12.6 assumes a KKT point; a stalled solve (Search_Direction_Becomes_Too_Small is
    # accepted by the multistart) or multipliers of another convention are not one. Each point below
    # is a vertex or has a positive definite Hessian, yet is no minimum.
    if case == "maximum with multipliers of the wrong sign":
        # min −x − y on [0, 1]²: (0, 0) is the maximum; λ = (1, 1) makes ∇f + λ = 0 but belongs to
        # upper bounds (a lower bound's multiplier is negative in CasADi)
        solver = nlp(lambda x: -x[0] - x[1])
        check = second_order_check(solver, np.zeros(2), np.ones(2), np.zeros(0), lbx=0.0, ubx=1.0)
    elif case == "not stationary":
        # min (x − 1)² + y² at (0, 0): ∇²f = 2 I, but ∇f = (−2, 0)
        solver = nlp(lambda x: (x[0] - 1) ** 2 + x[1] ** 2)
        check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))
    else:
        # min x with x >= −1 as a constraint, at x = 0 with λ = −1: stationary, but the constraint
        # is 1 away from its bound (its upper bound is infinite, never "near")
        solver = nlp(lambda x: x[0], lambda x: x[0], n=1)
        check = second_order_check(solver, np.zeros(1), np.zeros(1), -np.ones(1), lbg=-1.0, ubg=np.inf)
    assert not check.certified and "not a first-order point" in check.message


def test_strongly_active_bounds_make_a_vertex():
    # min x + y on x, y >= 0: both bounds active with multipliers 1, nothing left to move.
    solver = nlp(lambda x: x[0] + x[1] - 0.1 * x[0] * x[1])
    check = second_order_check(solver, np.zeros(2), -np.ones(2), np.zeros(0), lbx=0.0)
    assert check.certified and check.null_dimension == 0 and check.min_curvature == np.inf


def test_a_weakly_active_bound_is_left_free():
    # min x² − y² near 0 with y in [0, 1]: at (0, 0) the bound y >= 0 is met with a zero multiplier,
    # so y stays free and its negative curvature −2 shows (y = 1 is the minimum).
    solver = nlp(lambda x: x[0] ** 2 - x[1] ** 2)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0), lbx=[-1, 0], ubx=[1, 1])
    assert not check.certified and check.min_curvature == pytest.approx(-2.0)
    # min x² − y² + y: ∇f = (0, 1) at (0, 0), balanced by the bound's multiplier −1 (strongly active,
    # y fixed): f = x² + y − y² >= 0 nearby, a strict minimum with curvature 2 along x.
    solver = nlp(lambda x: x[0] ** 2 - x[1] ** 2 + x[1])
    fixed = second_order_check(solver, np.zeros(2), np.array([0.0, -1.0]), np.zeros(0), lbx=[-1, 0], ubx=[1, 1])
    assert fixed.certified and fixed.null_dimension == 1 and fixed.min_curvature == pytest.approx(2.0)


def test_strongly_active_inequality_rows_make_a_vertex():
    # The vertex of test_strongly_active_bounds_make_a_vertex with x, y >= 0 as constraint rows:
    # both active with multipliers −1 (∇f = (1, 1) at 0), so the indefinite −0.1 x y does not count.
    solver = nlp(lambda x: x[0] + x[1] - 0.1 * x[0] * x[1], lambda x: x)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), -np.ones(2), lbg=0.0, ubg=np.inf)
    assert check.certified and check.null_dimension == 0


def test_dependent_active_rows_leave_their_null_space():
    # f = x y with x + y = 0 written twice (2 x + 2 y = 0: dependent rows, λ = 0 satisfies KKT at 0).
    # Z is the line d = (1, −1)/√2 (rank 1, not 2), where dᵀ ∇²f d = 2 d₁ d₂ = −1: a saddle. Counting
    # both rows as independent would leave Z = {0} and certify it as a vertex.
    solver = nlp(lambda x: x[0] * x[1], lambda x: ca.vertcat(x[0] + x[1], 2 * x[0] + 2 * x[1]))
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(2), lbg=0.0, ubg=0.0)
    assert not check.certified and check.null_dimension == 1
    assert check.min_curvature == pytest.approx(-1.0)


def test_zero_curvature_is_not_certified():
    # f = x² + y³ at 0: ∇²f = diag(2, 0), positive semidefinite only, and f(0, −t) = −t³ < 0.
    solver = nlp(lambda x: x[0] ** 2 + x[1] ** 3)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))
    assert not check.certified and check.min_curvature == pytest.approx(0.0, abs=1e-12)


def test_an_infinite_bound_is_never_near():
    # x >= 0 (row 1, multiplier −1000: strongly active) and y >= −1 (row 2, y = 0 is 1 away from it; a
    # stray multiplier −1e-4, within the complementarity tolerance relative to 1000). f = 1000 x +
    # 1e-4 y − y²: stationary, and y, being free, carries the curvature −2: a saddle. Taking row 2's
    # infinite upper bound as "near" would fix y and certify a vertex.
    solver = nlp(lambda x: 1000 * x[0] + 1e-4 * x[1] - x[1] ** 2, lambda x: x)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.array([-1000.0, -1e-4]),
                               lbg=[0.0, -1.0], ubg=np.inf)
    assert not check.certified and check.null_dimension == 1 and check.min_curvature == pytest.approx(-2.0)


def bilimoria_wie_coarse(perturbation):
    problem = bilimoria_wie_problem()
    planner = PLANNERS["collocation"]({"objective": "min_time"})
    ocp = planner._ocp(problem)
    transcription, built = planner._nlp(problem, ocp, "cold", 8)
    reference = planner._starts(problem)[0]
    seed = transcription.seed(ocp, built, seed_sampler(problem, reference), reference.duration)
    if perturbation:
        seed = planner._guesses(problem, ocp, transcription, built, [seed])[0][0]
    lbx, ubx = transcription.bounds(ocp, built, *planner._variable_bounds(problem), problem.duration)
    params = np.concatenate([problem.initial_state, problem.qf, np.zeros(3), [problem.duration],
                             problem.model.default_parameters])
    return built, {"p": params, "lbx": lbx, "ubx": ubx, "lbg": built.lbg, "ubg": built.ubg}, seed


@pytest.mark.parametrize("perturbation, T, certified", [(False, 3.5449, False), (True, 3.2435, True)])
def test_bilimoria_wie_saddle_and_minimum(perturbation, T, certified):
    # 8 intervals: the eigenaxis point 3.5449 (2 √π) is a saddle (a pair of negative curvatures, one
    # per symmetric way off the axis); the optimum (3.2435 on this mesh) is bang-bang, a vertex.
    built, bounds, seed = bilimoria_wie_coarse(perturbation)
    result = solve_multistart(built.solver, [seed], agree=1, **bounds)
    assert result.success
    x = built.unpack(result.x, bounds["p"])[0]
    assert float(x) == pytest.approx(T, abs=1e-4)
    check = second_order_check(built.solver, result.x, result.lam_x, result.lam_g, **bounds)
    assert check.certified is certified, check.message
    if not certified:
        assert check.min_curvature < -1e-3


def test_restarts_only_where_the_second_order_conditions_fail():
    # From the saddle the check fails and a restart leaves it; at the optimum it holds, no restart.
    built, bounds, seed = bilimoria_wie_coarse(False)
    escape = solve_multistart(built.solver, [seed], restart=0.05, second_order=True, **bounds)
    assert escape.f == pytest.approx(3.2435, abs=1e-4)
    assert len(escape.starts) == 2 and escape.starts[0].f == pytest.approx(3.5449, abs=1e-4)
    assert escape.second_order is not None and escape.second_order.certified
    _, _, perturbed = bilimoria_wie_coarse(True)
    direct = solve_multistart(built.solver, [perturbed], restart=0.05, second_order=True, **bounds)
    assert len(direct.starts) == 1 and direct.stats()["second_order"]["certified"]
    # without the check, the restarts confirm the optimum by coming back to it
    confirmed = solve_multistart(built.solver, [perturbed], restart=0.05, **bounds)
    assert len(confirmed.starts) == 2 and confirmed.f == pytest.approx(direct.f, rel=1e-6)
    # the certificate counts as one agreeing start: agree=3 still asks for one restart coming back,
    # agree=0 (try everything) for every restart
    three = solve_multistart(built.solver, [perturbed], restart=0.05, second_order=True, agree=3, **bounds)
    assert len(three.starts) == 2 and three.starts[1].f == pytest.approx(direct.f, rel=1e-6)
    every = solve_multistart(built.solver, [perturbed], restart=0.05, second_order=True, agree=0, max_restarts=2,
                             **bounds)
    assert len(every.starts) == 3


def test_the_default_minimum_time_plan_certifies_its_coarse_optimum():
    # The warm start alone (the default seeds add spin_extremal's start, which agrees with it and
    # so ends the search without the check: tests/test_collocation_seeds.py).
    reference = PLANNERS["collocation"]({"objective": "min_time", "seed_planners": []}).plan(bilimoria_wie_problem())
    coarse = reference.stats["coarse"]
    assert coarse["second_order"]["certified"] and len(coarse["starts"]) == 1
    assert reference.duration == pytest.approx(3.2431, abs=2e-4)


def test_the_unchecked_size_is_reported(monkeypatch):
    from ocp.nlp import second_order

    solver = nlp(lambda x: ca.sumsqr(x), n=3)
    monkeypatch.setattr(second_order, "MAX_VARIABLES", 2)
    check = second_order_check(solver, np.zeros(3), np.zeros(3), np.zeros(0))
    assert not check.certified and check.null_dimension == -1 and "not checked" in check.message


def test_perturbation_floor_reaches_zero_components():
    from ocp.nlp.solve import perturbed

    center = np.zeros(20000)
    floor = np.where(np.arange(center.size) % 2 == 0, 1.0, 1e-3)
    noise = perturbed(center, 1, scales=(0.03, 0.03), floor=floor)[0]
    assert np.std(noise[0::2]) == pytest.approx(0.03, rel=0.05)
    assert np.std(noise[1::2]) == pytest.approx(3e-5, rel=0.05)


def test_the_control_floor_is_half_the_actuator_range_and_nothing_else():
    problem = bilimoria_wie_problem()
    for transcription_name in ("collocation", "multiple_shooting"):
        planner = PLANNERS["collocation"]({"objective": "min_time", "transcription": transcription_name})
        ocp = planner._ocp(problem)
        transcription, built = planner._nlp(problem, ocp, "cold", 8)
        floor = control_floor(transcription, ocp, built, *planner._variable_bounds(problem)[2:])
        T, states, controls = (np.asarray(v) for v in built.unpack(floor, np.zeros(built.solver.nnz_in("p"))))
        assert np.all(controls == 1.0)  # |u_i| <= 1 N m: half the range
        assert np.all(states == 1e-3) and np.all(T == 1e-3)


def test_a_problem_without_the_solver_derivatives_is_not_checked():
    class NoDerivatives:
        def get_function(self, name):
            raise RuntimeError(f"no {name}\nmore")

    check = second_order_check(NoDerivatives(), np.zeros(2), np.zeros(2), np.zeros(0))  # type: ignore[arg-type]
    assert not check.certified and "no derivatives" in check.message and "more" not in check.message


def test_the_dense_factorisations_run_on_one_blas_thread(monkeypatch):
    # A threaded BLAS waits for cores that other processes hold (a trade study's workers): the
    # check's QR and eigenvalues must run on BLAS_THREADS threads whatever the machine's default.
    import threadpoolctl

    import ocp.nlp.second_order as second_order

    seen = []
    null_space = second_order._null_space

    def recording(A, n):
        seen.append({info["internal_api"]: info["num_threads"] for info in threadpoolctl.threadpool_info()
                     if info["user_api"] == "blas"})
        return null_space(A, n)

    monkeypatch.setattr(second_order, "_null_space", recording)
    solver = nlp(lambda x: sum(x[i] ** 2 for i in range(6)) - x[0] * x[1], lambda x: x[0] + x[1] + x[2], n=6)
    check = second_order_check(solver, np.full(6, 0.0), np.zeros(6), np.zeros(1), lbg=0.0, ubg=0.0)
    assert check.certified  # x² terms with a -x0 x1 coupling: positive definite on the plane
    assert seen and all(seen[0].values()) and set(seen[0].values()) == {second_order.BLAS_THREADS}
    assert second_order.BLAS_THREADS == 1
