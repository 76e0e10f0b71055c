"""``multiple_shooting`` plans what the controllers' allocation realises on a skewed wheel array
(``planners.collocation.allocation``), checked with NumPy's pseudo-inverse and SciPy's integrator.

Multiple shooting's controls are ``u_0`` (in the first stage state) and one per interval (its end,
``c_k = u_{k+1}``), linear in between: the allocation's rows ``E u = 0`` go on ``c_k`` in every
interval and on ``u_0`` after the initial condition. Without the ``u_0`` rows the fresh-eyes user's
pyramid slew (the case of ``tests/test_collocation_allocation.py``) planned a first control 0.005 N m
out of the row space of the axes, whose min-norm allocation reached 1.50 times the wheel limit at
t = 0; before, the transcription was refused on any skewed array.
"""
from __future__ import annotations

import pickle

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ocp import Magnetorquers, ReactionWheels, Spacecraft, quat
from ocp.transcription import MultipleShooting
from planners import PLANNERS, ManeuverProblem
from planners.collocation.allocation import allocation_error

PYRAMID = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / np.sqrt(3)
INERTIA = np.array([[20.0, 0.5, -0.3], [0.5, 17.0, 0.4], [-0.3, 0.4, 14.0]])
TARGET = quat.normalize([0.5, 0.1796, -0.4490, 0.7184])  # 120 deg
G_MAX, H_MAX, DURATION = 0.01, 0.5, 90.0
SHOOTING = {"transcription": "multiple_shooting"}


def _pyramid() -> Spacecraft:
    return Spacecraft(INERTIA, wheels=ReactionWheels(PYRAMID, max_torque=G_MAX, max_momentum=H_MAX))


def _problem(spacecraft: Spacecraft) -> ManeuverProblem:
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), TARGET, DURATION, omegaf=np.zeros(3))


def _rigid_body(controls: np.ndarray, duration: float):
    """``y = [q, ω, h]`` of the body with the wheel torques ``g`` linear between the nodes:
    ``q̇ = ½ q ⊗ (0, ω)``, ``I ω̇ = −ω × (I ω + A h) − A g``, ``ḣ = g`` (wheel momenta along their axes)."""
    intervals = controls.shape[1] - 1
    step = duration / intervals

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        s = min(max(t / step, 0.0), float(intervals))
        k = min(int(s), intervals - 1)
        g = (1 - (s - k)) * controls[:, k] + (s - k) * controls[:, k + 1]
        q, omega, h = y[:4], y[4:7], y[7:]
        q_dot = 0.5 * quat.product(q, np.concatenate([[0.0], omega]))
        omega_dot = np.linalg.solve(INERTIA, -np.cross(omega, INERTIA @ omega + PYRAMID @ h) - PYRAMID @ g)
        return np.concatenate([q_dot, omega_dot, g])

    return rhs


@pytest.fixture(scope="module")
def plans():
    shooting = PLANNERS["collocation"](SHOOTING).plan(_problem(_pyramid()))
    radau = PLANNERS["collocation"]({}).plan(_problem(_pyramid()))
    return shooting, radau


def test_the_pyramid_is_no_longer_refused_with_multiple_shooting():
    assert allocation_error(_pyramid(), "multiple_shooting") is None
    assert PLANNERS["collocation"](SHOOTING).problem_error(_problem(_pyramid())) is None
    # a transcription that does not say where its controls are is still refused on the pyramid
    message = allocation_error(_pyramid(), "unregistered_transcription")
    assert message is not None and "allocation" in message


def test_every_shooting_control_is_the_min_norm_allocation_of_its_body_torque(plans):
    shooting, _ = plans
    assert shooting.status == "ok", shooting.message
    assert isinstance(shooting.transcription, MultipleShooting)
    g = shooting.controls  # (4, N + 1): u_0 … u_N, the nodes the linear controls join
    assert g.shape == (4, shooting.intervals + 1)
    torque = -PYRAMID @ g
    allocated = -np.linalg.pinv(PYRAMID) @ torque  # g = −A⁺ τ, what every controller commands
    # 3.5e-18 measured (1.7e-18 at t = 0; 0.005 at t = 0 without the rows on u_0)
    assert np.abs(g - allocated).max() <= 1e-12
    assert np.abs(g[:, 0] - allocated[:, 0]).max() <= 1e-12
    assert np.abs(g).max() <= G_MAX * (1 + 1e-6)  # 0.0100000096: IPOPT's relaxed bounds
    assert np.abs(g).max() >= G_MAX * (1 - 1e-6)  # the plan uses the wheels' limit: the bound binds
    # between the nodes the controls are linear: the allocation holds at every RK4 stage
    middle = 0.5 * (g[:, :-1] + g[:, 1:])
    assert np.abs(middle + np.linalg.pinv(PYRAMID) @ (-PYRAMID @ middle)).max() <= 1e-12
    # its transcription (a class made for these rows) pickles and interpolates the same, and the
    # whole plan pickles small: its model's solver cache pickles empty (0.7 GB of built solvers before)
    assert len(pickle.dumps(shooting)) < 1_000_000
    back = pickle.loads(pickle.dumps(shooting.transcription))
    assert type(back).__name__ == "MultipleShootingWithAllocation" and np.array_equal(back.allocation_rows,
                                                                                     shooting.transcription.allocation_rows)
    times = np.linspace(0.0, DURATION, 37)
    for a, b in zip(back.interpolate(shooting.model, shooting.states, g, DURATION, times),
                    shooting.transcription.interpolate(shooting.model, shooting.states, g, DURATION, times)):
        assert np.array_equal(a, b)


def test_the_open_loop_plan_reaches_the_target_with_the_wheels_within_their_bounds(plans):
    shooting, _ = plans
    duration, intervals = shooting.duration, shooting.intervals
    nodes = np.linspace(0.0, duration, intervals + 1)
    y0 = np.concatenate([quat.IDENTITY, np.zeros(3), np.zeros(4)])
    solution = solve_ivp(_rigid_body(shooting.controls, duration), (0.0, duration), y0, method="DOP853",
                         rtol=1e-12, atol=1e-14, max_step=duration / intervals / 4, dense_output=True)
    assert solution.success
    # the transcription's accuracy: its 200 RK4 steps of 0.45 s against DOP853 at 1e-12, node by node
    # (1.7e-10 measured), and the target at T (1.2e-10 rad, 7.6e-13 rad/s measured)
    assert np.abs(solution.sol(nodes) - shooting.states).max() <= 1e-8
    end = solution.y[:, -1]
    assert float(quat.error_angle(end[:4], TARGET)) <= 1e-8
    assert np.abs(end[4:7]).max() <= 1e-10
    momentum = solution.sol(np.linspace(0.0, duration, 9001))[7:]
    assert np.abs(momentum).max() <= H_MAX * (1 + 1e-6)
    # the objective is ∫ ‖τ‖² dt of these controls (exact for linear controls: h/3 (a² + a·b + b²))
    tau = -PYRAMID @ shooting.controls
    a, b = tau[:, :-1], tau[:, 1:]
    energy = duration / intervals / 3 * float(np.sum(a * a + a * b + b * b))
    assert shooting.stats["objective"] == pytest.approx(energy, rel=1e-9)


def test_shooting_and_radau_collocation_reach_the_same_optimum(plans):
    """Both transcribe the same problem with the same allocation and converge to the same
    continuous optimum; they differ by their controls: continuous piecewise-linear on the mesh
    (shooting) against Radau's piecewise quadratics (degree 3). Measured (2026-12-02): shooting
    0.01793936, 0.01793870, 0.01793840 on 25, 50, 100 intervals, Radau 0.01793834, 0.01793837,
    0.01793835; shooting's excess, 1.0e-6, 3.3e-7, 5e-8, shrinks with the mesh as a control
    parametrisation error does, and is not its integration's (8 RK4 substeps instead of 4 change
    the 50-interval value by 4e-13). At 50 intervals: 1.8e-5 relative; the bound, 1e-4, is the
    25-interval excess (5.6e-5) with room."""
    shooting, radau = plans
    assert radau.status == "ok", radau.message
    assert shooting.stats["objective"] == pytest.approx(radau.stats["objective"], rel=1e-4)
    # the same motion: attitudes within 1e-3 rad of each other over the slew
    times = np.linspace(0.0, DURATION, 181)
    angle = quat.error_angle(shooting.sample(times).q, radau.sample(times).q)
    assert np.max(angle) <= 1e-3


def test_magnetorquers_beside_two_wheels_stay_refused_with_multiple_shooting():
    two = np.array([[1.0, 1.0, 0.0], [0.0, 1.0, 1.0]]).T / np.sqrt(2)
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(two, max_torque=0.05, max_momentum=1.0),
                            magnetorquers=Magnetorquers(50.0))
    message = allocation_error(spacecraft, "multiple_shooting")
    assert message is not None and "magnetorquers" in message and "across the field" in message
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), np.array([np.cos(0.2), np.sin(0.2), 0.0, 0.0]),
                              60.0, omegaf=np.zeros(3))
    refused = PLANNERS["collocation"]({"intervals": 4, **SHOOTING}).problem_error(problem)
    assert refused is not None and refused.startswith("options.transcription:") and "across the field" in refused


def test_the_rows_on_u0_sit_after_the_initial_condition_with_their_derivatives():
    """The NLP's own rows at a point: ``E u_0`` right after ``x_0 − x0`` (the null direction of the
    axes, by NumPy, gives ±1 there, a torque in their row space 0), and the derivatives IPOPT is
    given (the stage-wise blocks with the rows spliced in) equal CasADi's of the whole ``g`` and
    Lagrangian."""
    import casadi as ca

    planner = PLANNERS["collocation"]({**SHOOTING, "intervals": 6})
    problem = _problem(_pyramid())
    _, nlp = planner._nlp(problem, planner._ocp(problem))
    nx, ns, nb = 11, nlp.n_stage_state, nlp.n_stage_state + nlp.layout["n_path"]
    assert nb == ns + 1  # one row per interval, on c_k
    assert len(nlp.lbg) == 6 * nb + nx + 1 + nlp.layout["n_terminal"]
    assert nlp.lbg[nb + nx] == nlp.ubg[nb + nx] == 0.0
    null = np.linalg.svd(PYRAMID)[2][-1]  # A n = 0
    g_of = nlp.solver.get_function("nlp_g")
    rng = np.random.default_rng(20261202)
    p = rng.normal(size=g_of.size1_in(1))
    for u0, expected in ((null, 1.0), (PYRAMID.T @ [0.3, -0.2, 0.5], 0.0)):
        w = rng.normal(size=nlp.n_w)
        w[nx:ns] = u0
        g = np.asarray(g_of(w, p)).ravel()
        assert abs(g[nb + nx]) == pytest.approx(expected, abs=1e-12)
        np.testing.assert_allclose(g[nb:nb + nx], w[:nx] - p[:nx], atol=1e-12)
    x, ps = ca.SX.sym("x", nlp.n_w), ca.SX.sym("p", g_of.size1_in(1))
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", len(nlp.lbg))
    g_sym = g_of(x, ps)
    lagrangian = lam_f * nlp.solver.get_function("nlp_f")(x, ps) + ca.dot(lam_g, g_sym)
    reference = ca.Function("reference", [x, ps, lam_f, lam_g],
                            [ca.jacobian(g_sym, x), ca.triu(ca.hessian(lagrangian, x)[0])])
    w, lam = rng.normal(size=nlp.n_w), rng.normal(size=len(nlp.lbg))
    jacobian, hessian = (np.asarray(ca.DM(m)) for m in reference(w, p, 0.7, lam))
    given_jacobian = np.asarray(ca.DM(nlp.solver.get_function("nlp_jac_g")(w, p)[1]))
    given_hessian = np.asarray(ca.DM(nlp.solver.get_function("nlp_hess_l")(w, p, 0.7, lam)))
    np.testing.assert_allclose(given_jacobian, jacobian, atol=1e-9, rtol=1e-9)
    np.testing.assert_allclose(given_hessian, hessian, atol=1e-9, rtol=1e-9)
