"""The second-order check (ocp.nlp.second_order) against closed forms, and its use by the multistart.

Oracles: the reduced Hessian of small NLPs worked by hand (a saddle, a maximum on a line, a vertex,
a weakly active bound); random sparse QPs built with a chosen number of negative curvatures on the
null space of their active constraints (bounds and rows strongly active, rows dependent); the
eigenvalues of the reduced Hessian computed densely here (SVD null space, as the check did before it
used the KKT inertia) on collocation optima and saddles; and the eigenaxis slew, a known saddle of
Bilimoria & Wie's minimum-time problem (2 √π = 3.5449 against the optimum 3.2431), found by IPOPT
from the unperturbed warm start.
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
    assert check.negative_curvatures == 1 and check.curvature_threshold == pytest.approx(2e-6)  # 1e-6 ‖∇²f‖∞


@pytest.mark.parametrize("sign, certified", [(-1.0, True), (1.0, False)])
def test_the_curvature_along_an_equality_constraint(sign, certified):
    # f = ±x y on x + y = 2 at (1, 1), multiplier ∓1 (∇f + λ ∇g = 0). Along d = (1, −1)/√2:
    # dᵀ ∇²f d = ±(2 d₁ d₂) = ∓1, so −x y has a minimum there (curvature 1) and x y a maximum (−1).
    solver = nlp(lambda x: sign * x[0] * x[1], lambda x: x[0] + x[1])
    check = second_order_check(solver, np.ones(2), np.zeros(2), np.array([-sign]), lbg=2.0, ubg=2.0)
    assert check.certified is certified
    assert check.negative_curvatures == (0 if certified else 1)


@pytest.mark.parametrize("solver", ["ipopt", "fatrop"])
@pytest.mark.parametrize("corner, certified", [(-1.0, True), (1.0, False)])
def test_the_curvature_of_a_nonlinear_constraint_comes_from_its_multiplier(solver, corner, certified):
    # min x + y on x² + y² = 2: ∇f + λ ∇g = (1, 1) + 2 λ (x, y) = 0 gives λ = 1/2 at (−1, −1) (the
    # minimum) and λ = −1/2 at (1, 1) (the maximum). ∇²f = 0, so ∇²L = 2 λ I: the curvature along the
    # circle, 2 λ = ∓1, is the multiplier's alone (its sign in CasADi's L = f + λᵀ g decides).
    solver = nlp(lambda x: x[0] + x[1], lambda x: x[0] ** 2 + x[1] ** 2, solver=solver)
    lam = np.array([-0.5 * corner])
    check = second_order_check(solver, corner * np.ones(2), np.zeros(2), lam, lbg=2.0, ubg=2.0)
    assert check.certified is certified and check.negative_curvatures == (0 if certified else 1)


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
    assert check.certified and check.negative_curvatures == 0


def test_a_weakly_active_bound_is_left_free():
    # min x² − y² near 0 with y in [0, 1]: at (0, 0) the bound y >= 0 is met with a zero multiplier,
    # so y stays free and its negative curvature −2 shows (y = 1 is the minimum).
    solver = nlp(lambda x: x[0] ** 2 - x[1] ** 2)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0), lbx=[-1, 0], ubx=[1, 1])
    assert not check.certified and check.negative_curvatures == 1
    # min x² − y² + y: ∇f = (0, 1) at (0, 0), balanced by the bound's multiplier −1 (strongly active,
    # y fixed): f = x² + y − y² >= 0 nearby, a strict minimum with curvature 2 along x.
    solver = nlp(lambda x: x[0] ** 2 - x[1] ** 2 + x[1])
    fixed = second_order_check(solver, np.zeros(2), np.array([0.0, -1.0]), np.zeros(0), lbx=[-1, 0], ubx=[1, 1])
    assert fixed.certified and fixed.negative_curvatures == 0


def test_strongly_active_inequality_rows_make_a_vertex():
    # The vertex of test_strongly_active_bounds_make_a_vertex with x, y >= 0 as constraint rows:
    # both active with multipliers −1 (∇f = (1, 1) at 0), so the indefinite −0.1 x y does not count.
    solver = nlp(lambda x: x[0] + x[1] - 0.1 * x[0] * x[1], lambda x: x)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), -np.ones(2), lbg=0.0, ubg=np.inf)
    assert check.certified and check.negative_curvatures == 0


def test_dependent_active_rows_leave_their_null_space():
    # f = x y with x + y = 0 written twice (2 x + 2 y = 0: dependent rows, λ = 0 satisfies KKT at 0).
    # Z is the line d = (1, −1)/√2 (rank 1, not 2), where dᵀ ∇²f d = 2 d₁ d₂ = −1: a saddle. Counting
    # both rows as independent would leave Z = {0} and certify it as a vertex; the KKT matrix of the
    # inertia theorem is singular here.
    solver = nlp(lambda x: x[0] * x[1], lambda x: ca.vertcat(x[0] + x[1], 2 * x[0] + 2 * x[1]))
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(2), lbg=0.0, ubg=0.0)
    assert not check.certified and check.negative_curvatures == 1


def test_zero_curvature_is_not_certified(capfd):
    # f = x² + y³ at 0: ∇²f = diag(2, 0), positive semidefinite only, and f(0, −t) = −t³ < 0.
    solver = nlp(lambda x: x[0] ** 2 + x[1] ** 3)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))
    # no curvature below −δ: degenerate (no saddle direction), not certified
    assert not check.certified and check.degenerate and check.negative_curvatures == 0
    # curvature 1e-6 along y, exactly the threshold 1e-6 × max(1, ‖∇²f‖∞): a zero pivot, not checked
    solver = nlp(lambda x: 0.5 * x[0] ** 2 + 0.5e-6 * x[1] ** 2)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))
    assert not check.certified and check.negative_curvatures == -1 and "zero pivot" in check.message
    # found from the factorisation's rank, without the solve that prints CasADi's warning to stderr
    assert "zeros in D" not in capfd.readouterr().err


def test_an_infinite_bound_is_never_near():
    # x >= 0 (row 1, multiplier −1000: strongly active) and y >= −1 (row 2, y = 0 is 1 away from it; a
    # stray multiplier −1e-4, within the complementarity tolerance relative to 1000). f = 1000 x +
    # 1e-4 y − y²: stationary, and y, being free, carries the curvature −2: a saddle. Taking row 2's
    # infinite upper bound as "near" would fix y and certify a vertex.
    solver = nlp(lambda x: 1000 * x[0] + 1e-4 * x[1] - x[1] ** 2, lambda x: x)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.array([-1000.0, -1e-4]),
                               lbg=[0.0, -1.0], ubg=np.inf)
    assert not check.certified and check.negative_curvatures == 1


def dense_reduced_curvatures(solver, x, lam_x, lam_g, *, p=None, lbx=-np.inf, ubx=np.inf, lbg=-np.inf, ubg=np.inf,
                             tolerance=1e-6, scale=1e-6):
    """The eigenvalues of ∇²L on Z (the module's subspace: strongly active rows and bounds, multiplier
    above ``tolerance``), densely: an SVD null space of the active rows on the free variables, and the
    threshold δ = ``scale`` × ‖H_FF‖∞ (× 1 when H_FF = 0). Independent of the module's linear algebra."""
    import scipy.linalg

    p = np.zeros(solver.nnz_in("p")) if p is None else p
    hessian, jacobian = solver.get_function("nlp_hess_l"), solver.get_function("nlp_jac_g")
    outputs = hessian(x=x, p=p, lam_f=1.0, lam_g=lam_g)
    H = np.triu(np.asarray(outputs.get("triu_hess_gamma_x_x", outputs.get("hess_gamma_x_x"))))
    H = H + np.triu(H, 1).T
    outputs = jacobian(x=x, p=p)
    g, J = np.asarray(outputs["g"]).ravel(), np.asarray(outputs["jac_g_x"])

    def strongly_active(values, low, high, multipliers):
        low, high = np.broadcast_to(low, values.shape), np.broadcast_to(high, values.shape)
        at = (np.abs(values - low) <= 1e-6 * (1 + np.abs(low))) | (np.abs(high - values) <= 1e-6 * (1 + np.abs(high)))
        return (low == high) | (at & (np.abs(multipliers) > tolerance))

    free = ~strongly_active(x, lbx, ubx, lam_x)
    A = J[np.ix_(strongly_active(g, lbg, ubg, lam_g), free)]
    H_free = H[np.ix_(free, free)]
    Z = scipy.linalg.null_space(A) if A.shape[0] else np.eye(int(free.sum()))
    norm = float(np.max(np.sum(np.abs(H_free), axis=1)))
    return np.linalg.eigvalsh(Z.T @ H_free @ Z), scale * (norm if norm > 0.0 else 1.0)


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
    curvatures, delta = dense_reduced_curvatures(built.solver, result.x, result.lam_x, result.lam_g, **bounds)
    assert check.curvature_threshold == pytest.approx(delta)
    assert certified == bool(np.sum(curvatures <= delta) == 0)
    assert check.negative_curvatures == np.sum(curvatures < -delta)
    if not certified:
        assert curvatures[0] < -1e-3


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


def test_an_inaccurate_factorisation_is_not_checked(monkeypatch):
    # The guard: the LDLᵀ's estimated backward error times ‖K‖ must stay below δ / GUARD. A guard
    # no factorisation passes leaves a positive definite point not checked (never certified).
    from ocp.nlp import second_order

    solver, x, lam_x, lam_g, bounds, _ = random_qp(0, 0)
    assert second_order_check(solver, x, lam_x, lam_g, **bounds).certified
    monkeypatch.setattr(second_order, "GUARD", 1e300)  # rounding alone fails it
    check = second_order_check(solver, x, lam_x, lam_g, **bounds)
    assert not check.certified and check.negative_curvatures == -1 and "not accurate enough" in check.message


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


def random_qp(seed, negative, n=60, fixed=8, equalities=20, active=6, inactive=5, duplicate=False, vertex=False,
              scale=1.0):
    """A sparse random QP and a KKT point of it whose Hessian has ``negative`` negative eigenvalues on
    the null space Z of its strongly active rows and bounds, by construction: ``fixed`` variables at
    a bound with a multiplier pushing against it (the Hessian there strongly negative: it must not
    count), ``equalities`` equality rows, ``active`` inequality rows at their upper bound with a
    positive multiplier, ``inactive`` rows inside their bounds (zero multiplier: not in Z's
    definition), one free variable at its bound with a zero multiplier (weakly active: free). The
    Hessian on the free variables is ``Z Λ Zᵀ + Y B Yᵀ + Z C Yᵀ + Y Cᵀ Zᵀ`` with ``Y`` the range of
    the active rows' transpose and ``Λ`` the chosen eigenvalues (magnitudes 0.1 to 10), ``B`` and
    ``C`` random (indefinite: only Z's block decides). ``duplicate``: an active row repeated (the rows
    dependent); ``vertex``: as many active rows as free variables (Z = {0}), the Hessian indefinite;
    ``scale``: the objective and so the multipliers times this (the same point, the same curvature signs)."""
    import scipy.linalg
    import scipy.sparse

    rng = np.random.default_rng(seed)
    rows = equalities + active
    if vertex:
        rows = n - fixed
        equalities = rows - active
    A = scipy.sparse.random(rows + inactive, n, density=0.08, random_state=rng, format="csr").toarray()
    A[np.arange(rows + inactive), rng.integers(0, n, rows + inactive)] += 1.0  # no empty row
    order = rng.permutation(n)
    fixed_vars, free_vars = np.sort(order[:fixed]), np.sort(order[fixed:])
    if vertex:  # the active rows on the free variables diagonally dominant: nonsingular
        A[np.arange(rows), free_vars] += 10.0
    if duplicate:
        A = np.vstack([A[:rows], 2.0 * A[rows - 1:rows], A[rows:]])
        rows += 1
    A_free = A[:rows][:, free_vars]
    Z = scipy.linalg.null_space(A_free)
    Y = scipy.linalg.orth(A_free.T)
    k = Z.shape[1]
    eigenvalues = rng.uniform(0.1, 10.0, k) * np.where(np.arange(k) < negative, -1.0, 1.0)
    B = rng.standard_normal((Y.shape[1], Y.shape[1]))
    C = rng.standard_normal((k, Y.shape[1]))
    H_free = Z @ np.diag(eigenvalues) @ Z.T + Y @ (B + B.T) @ Y.T + Z @ C @ Y.T + Y @ C.T @ Z.T
    H = rng.standard_normal((n, n))
    H = H + H.T
    H[np.ix_(free_vars, free_vars)] = H_free
    H[fixed_vars, fixed_vars] = -50.0
    # the point: fixed variables at a bound (lower or upper), the others inside [-5, 5], one at 5
    x = rng.uniform(-1.0, 1.0, n)
    low, high = np.full(n, -5.0), np.full(n, 5.0)
    side = rng.random(fixed) < 0.5
    x[fixed_vars] = np.where(side, low[fixed_vars], high[fixed_vars])
    x[free_vars[0]] = high[free_vars[0]]
    lam_x = np.zeros(n)
    lam_x[fixed_vars] = np.where(side, -1.0, 1.0) * rng.uniform(0.5, 2.0, fixed)
    lam_g = np.zeros(A.shape[0])
    lam_g[:equalities] = rng.standard_normal(equalities)
    lam_g[equalities:rows] = rng.uniform(0.5, 2.0, rows - equalities)  # at the upper bound
    g = A @ x
    lbg, ubg = g.copy(), g.copy()
    lbg[equalities:rows] = -np.inf
    lbg[rows:], ubg[rows:] = g[rows:] - 1.0, g[rows:] + 1.0
    c = -(H @ x + A.T @ lam_g + lam_x)  # stationarity: ∇f + Aᵀ λ_g + λ_x = 0
    variables = ca.SX.sym("x", n)
    f = scale * (0.5 * ca.dot(variables, ca.mtimes(ca.DM(H), variables)) + ca.dot(ca.DM(c), variables))
    solver = ca.nlpsol("qp", "ipopt", {"x": variables, "f": f, "g": ca.mtimes(ca.DM(A), variables)},
                       solver_options("ipopt", 1e-12, 200))
    bounds = {"lbx": low, "ubx": high, "lbg": lbg, "ubg": ubg}
    return solver, x, scale * lam_x, scale * lam_g, bounds, k


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("negative", [0, 1, 4])
@pytest.mark.parametrize("variant", ["independent", "duplicate"])
def test_random_qps_with_a_known_number_of_negative_curvatures(seed, negative, variant):
    solver, x, lam_x, lam_g, bounds, k = random_qp(seed, negative, duplicate=variant == "duplicate")
    assert k >= 20  # Z is 60 − 8 fixed − 26 rows (one row more, dependent: the same Z) = 26 dimensional
    check = second_order_check(solver, x, lam_x, lam_g, **bounds)
    assert check.certified is (negative == 0), check.message
    assert check.negative_curvatures == negative, check.message


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_random_vertex_is_certified_whatever_its_hessian(seed):
    # As many independent active rows as free variables: Z = {0}, and the indefinite Hessian (and
    # the −50 on the fixed variables) must not matter.
    solver, x, lam_x, lam_g, bounds, k = random_qp(seed, 0, vertex=True)
    assert k == 0
    check = second_order_check(solver, x, lam_x, lam_g, **bounds)
    assert check.certified and check.negative_curvatures == 0, check.message


@pytest.mark.slow  # about 20 s; the saddle's count against the dense one on 8 intervals: the coarse optima test
def test_the_full_mesh_saddle_is_not_certified_and_its_count_is_the_dense_one():
    # Bilimoria & Wie on 50 intervals (1908 variables) from the unperturbed eigenaxis seed stops at
    # the eigenaxis saddle 3.5449; its negative curvatures below −δ, counted densely, are the check's.
    from tests.test_certificate import bilimoria_wie_solution

    _, solved, params, lbx, ubx = bilimoria_wie_solution({"objective": "min_time", "multistart": 0})
    result = solved.result
    assert result.x.size == 1908
    assert float(solved.nlp.unpack(result.x, params)[0]) == pytest.approx(3.5449, abs=1e-3)
    bounds = {"p": params, "lbx": lbx, "ubx": ubx, "lbg": solved.nlp.lbg, "ubg": solved.nlp.ubg}
    check = second_order_check(solved.nlp.solver, result.x, result.lam_x, result.lam_g, **bounds)
    assert not check.certified and not check.degenerate, check.message
    curvatures, delta = dense_reduced_curvatures(solved.nlp.solver, result.x, result.lam_x, result.lam_g,
                                                 scale=1e-6, **bounds)
    assert curvatures[0] < -1e-3
    assert check.negative_curvatures == np.sum(curvatures < -delta)


def min_time_problem(name, seed=0):
    """Bilimoria & Wie, the full inertia and XTE cases of tests/benchmarks/test_bench_min_time.py and
    scenarios/bench/problems/xte_150.yaml, or a random inertia (diagonal 4-8 kg m², small
    products; moments 4-8 keep the triangle inequality) slewing a random angle about a random axis, |u_i| <= 1 N m."""
    from ocp import Spacecraft, Torquers, quat
    from planners import ManeuverProblem

    if name == "bilimoria_wie":
        return bilimoria_wie_problem()
    if name == "full_inertia":
        return ManeuverProblem(Spacecraft([[10, 0.5, 0.2], [0.5, 8, 0.3], [0.2, 0.3, 6]], torquers=Torquers(1.0)),
                               quat.IDENTITY, np.zeros(3), quat.from_axis_angle([1, 1, 1], np.deg2rad(150)), 30.0,
                               omegaf=np.zeros(3))
    if name == "xte":
        return ManeuverProblem(Spacecraft([5621.0, 4547.0, 2364.0], torquers=Torquers(50.0)), quat.IDENTITY,
                               np.zeros(3), quat.from_axis_angle([1, 0, 0], np.deg2rad(150)), 60.0, omegaf=np.zeros(3))
    rng = np.random.default_rng(seed)
    products = rng.uniform(-0.3, 0.3, 3)
    inertia = np.diag(rng.uniform(4.0, 8.0, 3)) + np.array([[0, products[0], products[1]],
                                                              [products[0], 0, products[2]],
                                                              [products[1], products[2], 0]])
    return ManeuverProblem(Spacecraft(inertia, torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle(rng.standard_normal(3), rng.uniform(np.pi / 4, np.pi)), 60.0,
                           omegaf=np.zeros(3))


@pytest.mark.parametrize("name, seed", [("bilimoria_wie", 0), ("full_inertia", 0), ("xte", 0), ("random", 1),
                                        ("random", 2), ("random", 3)])
@pytest.mark.parametrize("multistart", ["auto", 0])
def test_the_check_agrees_with_the_dense_reduced_hessian_on_coarse_optima(name, seed, multistart):
    # 8 intervals, no coarse mesh: the optimum of the default search, and the point the unperturbed
    # warm start stops at (a saddle or the optimum). Certified exactly where the dense curvature on Z
    # exceeds δ everywhere, and the count below −δ the dense one.
    problem = min_time_problem(name, seed)
    planner = PLANNERS["collocation"]({"objective": "min_time", "intervals": 8, "coarse_intervals": 0,
                                       "multistart": multistart})
    ocp = planner._ocp(problem)
    params = np.concatenate([problem.initial_state, problem.qf, problem.omegaf, [problem.duration],
                             problem.model.default_parameters])
    solved = planner._optimum(problem, ocp, planner._starts(problem), params, 8)
    lbx, ubx = solved.transcription.bounds(ocp, solved.nlp, *planner._variable_bounds(problem), problem.duration)
    result = solved.result
    assert result.success
    bounds = {"p": params, "lbx": lbx, "ubx": ubx, "lbg": solved.nlp.lbg, "ubg": solved.nlp.ubg}
    check = second_order_check(solved.nlp.solver, result.x, result.lam_x, result.lam_g, **bounds)
    assert check.negative_curvatures >= 0, check.message  # checked: the guard passed
    curvatures, delta = dense_reduced_curvatures(solved.nlp.solver, result.x, result.lam_x, result.lam_g, **bounds)
    assert check.curvature_threshold == pytest.approx(delta)
    assert check.certified == bool(np.sum(curvatures <= delta) == 0), (check.message, curvatures[:4])
    if not check.certified:
        assert check.negative_curvatures == np.sum(curvatures < -delta), (check.message, curvatures[:4])


@pytest.mark.parametrize("negative", [0, 1, 4])
def test_the_verdict_does_not_depend_on_the_objective_scale(negative):
    # Scaling f by c > 0 scales ∇²L and the multipliers by c and keeps the point, Z and the signs of
    # the curvatures on Z: a strict minimum stays one. The QP's curvatures on Z, 0.1 to 10 in
    # magnitude, become 1e-8 to 1e-6 at c = 1e-7, below an absolute threshold 1e-6 (the multipliers'
    # tolerance scaled alike, so that the same bounds and rows are strongly active).
    c = 1e-7
    solver, x, lam_x, lam_g, bounds, k = random_qp(0, negative, scale=c)
    check = second_order_check(solver, x, lam_x, lam_g, multiplier_tolerance=1e-6 * c, **bounds)
    assert check.certified is (negative == 0), check.message
    assert check.negative_curvatures == negative, check.message
    unit = second_order_check(*random_qp(0, negative)[:4], **bounds)
    assert check.curvature_threshold == pytest.approx(c * unit.curvature_threshold, rel=1e-9)


@pytest.mark.parametrize("c", [1.0, 1e-9])
def test_a_zero_curvature_direction_stays_degenerate_at_any_objective_scale(c):
    # min c ((x + y)² + z²) on x + y + z = 0 at 0: ∇²f = 2c [[1, 1, 0], [1, 1, 0], [0, 0, 1]], Z the
    # plane d₁ + d₂ + d₃ = 0, which holds d = (1, −1, 0) of curvature exactly 0 (and (1, 1, −2) of
    # curvature 12 c / 6 = 2c): positive semidefinite, no saddle, no strict minimum.
    solver = nlp(lambda x: c * ((x[0] + x[1]) ** 2 + x[2] ** 2), lambda x: x[0] + x[1] + x[2], n=3)
    check = second_order_check(solver, np.zeros(3), np.zeros(3), np.zeros(1), lbg=0.0, ubg=0.0)
    assert not check.certified and check.degenerate and check.negative_curvatures == 0, check.message
    assert check.curvature_threshold == pytest.approx(1e-6 * 4.0 * c)  # 1e-6 ‖∇²f‖∞, ‖∇²f‖∞ = 4c
    # ∇²L = 0 (f = c (x + y), on x + y = 0 with λ = −c): every curvature on Z is 0, none above any δ
    solver = nlp(lambda x: c * (x[0] + x[1]), lambda x: x[0] + x[1])
    zero = second_order_check(solver, np.zeros(2), np.zeros(2), np.array([-c]), lbg=0.0, ubg=0.0)
    assert not zero.certified and zero.degenerate, zero.message
    assert zero.curvature_threshold == pytest.approx(1e-6)  # ‖∇²L‖∞ = 0: the tolerance itself


@pytest.mark.slow  # about 15 s; the refinement below δ and its message: test_a_tiny_curvature_is_refined_to_its_sign
def test_the_natural_motion_minimum_energy_optimum_is_certified_below_the_first_threshold():
    # The bench's natural-motion minimum-energy problem (UKube-1, J = [0.0109, 0.05, 0.05] kg m²,
    # 110 s, objective 5.8e-8): ∇²L on the free variables is not small (‖H‖∞ = 2.25, the controls'
    # energy), but its curvature on Z spans 1.7e-9 to 0.044 (dense eigenvalues: a strict minimum).
    # At δ = 1e-6 ‖H‖∞ the point is degenerate (the dense count of curvatures below δ, none below
    # −δ); the refinement certifies it at a threshold below the least curvature, 7.7e-10 ‖H‖∞.
    from scenarios.bench import load_suite
    from scenarios.schema.loader import load

    problem = load(load_suite().problems["natural_motion_min_energy"].file).problem
    planner = PLANNERS["collocation"]({"objective": "min_energy"})
    ocp = planner._ocp(problem)
    params = np.concatenate([problem.initial_state, problem.qf, problem.omegaf, [problem.duration],
                             problem.model.default_parameters])
    solved = planner._optimum(problem, ocp, planner._starts(problem), params, planner.options.intervals)
    lbx, ubx = solved.transcription.bounds(ocp, solved.nlp, *planner._variable_bounds(problem), problem.duration)
    result = solved.result
    assert result.f == pytest.approx(5.85e-8, rel=1e-2)
    bounds = {"p": params, "lbx": lbx, "ubx": ubx, "lbg": solved.nlp.lbg, "ubg": solved.nlp.ubg}
    check = second_order_check(solved.nlp.solver, result.x, result.lam_x, result.lam_g, **bounds)
    curvatures, delta = dense_reduced_curvatures(solved.nlp.solver, result.x, result.lam_x, result.lam_g, **bounds)
    assert delta == pytest.approx(2.25e-6, rel=1e-2) and 1e-9 < curvatures[0] < 1e-3 * delta
    assert check.certified, check.message
    assert 1e-10 * delta < check.curvature_threshold < curvatures[0]
    assert f"{np.sum(curvatures <= delta)} directions between" in check.message


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_tiny_curvature_is_refined_to_its_sign(sign):
    # f = x² ± 1.5e-9 y² at 0: ∇²f = diag(2, ±3e-9), ‖∇²f‖∞ = 2, so δ = 2e-6 leaves y between ±δ
    # (degenerate). Refined (δ / √10, δ / 10, ...), +3e-9 is certified below 3e-9; −3e-9 stays
    # below every threshold: degenerate, never certified (and no saddle beyond −2e-6 either).
    solver = nlp(lambda x: x[0] ** 2 + sign * 1.5e-9 * x[1] ** 2)
    check = second_order_check(solver, np.zeros(2), np.zeros(2), np.zeros(0))
    if sign > 0:
        assert check.certified and 2e-10 <= check.curvature_threshold < 3e-9, check.message
        assert "1 directions between" in check.message  # y alone lies between ±δ
    else:
        assert not check.certified and check.degenerate and check.curvature_threshold == pytest.approx(2e-6)
