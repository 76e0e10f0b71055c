"""Natural motions: closed forms against integration, shooting, zero torque, closed loop."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from controllers import CONTROLLERS
from ocp import ReactionWheels, Simulator, Spacecraft, metrics_from_simulation, quat
from ocp.errors import OptionsError
from planners import PLANNERS, ManeuverProblem
from planners.natural_motion import NaturalMotionReference
from planners.torque_free import asymmetric_rates
from scenarios.requirements.scoring import rate_jumps

UKUBE1 = np.array([0.0109, 0.05, 0.05])  # nano-spacecraft paper, section III


def integrate_free_motion(q0, omega0, moments, t):
    """Euler's equations and q̇ = ½ q ⊗ [0, ω], written out here, by DOP853."""
    I1, I2, I3 = moments

    def rhs(_, y):
        w = y[4:]
        return np.r_[quat.kinematics(y[:4], w),
                     (I2 - I3) / I1 * w[1] * w[2], (I3 - I1) / I2 * w[2] * w[0], (I1 - I2) / I3 * w[0] * w[1]]

    solution = solve_ivp(rhs, (0, t[-1]), np.r_[q0, omega0], method="DOP853", rtol=1e-13, atol=1e-14, t_eval=t)
    return solution.y[:4].T, solution.y[4:].T


def test_symmetric_closed_form_matches_integration(rng):
    for case in range(20):
        axis = case % 3
        moments = np.full(3, rng.uniform(0.03, 0.08))
        moments[axis] = rng.uniform(0.01, 0.1)
        omega0 = rng.normal(0, 0.05, 3)
        omega0[axis] = abs(omega0[axis]) * (1 if case % 2 else -1)  # both signs of the spin
        q0 = quat.random_unit(rng)
        reference = NaturalMotionReference(q0, omega0, moments, 90.0, 100.0, "step", "", {})
        t = np.linspace(0, 90.0, 10)
        q_true, omega_true = integrate_free_motion(q0, omega0, moments, t)
        np.testing.assert_allclose(reference.omega(t), omega_true, atol=1e-9)
        np.testing.assert_allclose(reference.q(t), q_true, atol=1e-9)


@pytest.mark.parametrize("regime", ["major", "minor"])
def test_asymmetric_elliptic_rates_match_integration_and_conserve(regime, rng):
    found = 0
    while found < 6:
        moments = rng.uniform(1.0, 3.0, 3)
        omega0 = rng.normal(0, 0.3, 3)
        h2, e2 = np.sum((moments * omega0) ** 2), np.sum(moments * omega0**2)
        if (h2 >= e2 * np.sort(moments)[1]) != (regime == "major"):
            continue
        found += 1
        t = np.linspace(0, 60, 13)
        _, omega_true = integrate_free_motion(quat.IDENTITY, omega0, moments, t)
        omega = asymmetric_rates(t, omega0, moments)
        np.testing.assert_allclose(omega, omega_true, atol=1e-10)
        dense = asymmetric_rates(np.linspace(0, 60, 601), omega0, moments)
        np.testing.assert_allclose(np.sum(moments * dense**2, axis=1), e2, rtol=1e-12)
        np.testing.assert_allclose(np.sum((moments * dense) ** 2, axis=1), h2, rtol=1e-12)


def paper_problem(moments=UKUBE1):
    """Nano paper: [0,0,0,1] -> [0.5,0.5,0.5,0.5] scalar last, 110 s, the last 10 s at rest."""
    spacecraft = Spacecraft(moments, wheels=ReactionWheels.from_body_axes())
    return ManeuverProblem(spacecraft, quat.from_scalar_last([0, 0, 0, 1]), np.zeros(3),
                           quat.from_scalar_last([0.5, 0.5, 0.5, 0.5]), 110.0, omegaf=np.zeros(3))


@pytest.mark.parametrize("moments", [UKUBE1, np.array([0.02, 0.05, 0.04])], ids=["ukube1", "asymmetric"])
@pytest.mark.parametrize("stop", ["step", "smooth"])
def test_shooting_reaches_the_target_with_zero_torque_on_the_arc(moments, stop):
    problem = paper_problem(moments)
    reference = PLANNERS["natural_motion"]({"stop": stop}).plan(problem)
    assert reference.status == "ok", reference.message
    assert np.rad2deg(quat.error_angle(reference.q(110.0), problem.qf)) < 1e-3
    assert np.allclose(reference.omega(110.0), 0.0)
    arc = np.linspace(0, 100.0, 501)
    assert np.all(reference.torque(arc) == 0.0)
    # The arc is free motion of the body: the attitude integrates from the arc's own ω(0).
    q_true, _ = integrate_free_motion(problem.q0, reference.omega(0.0), moments, arc)
    assert np.max(quat.error_angle(reference.q(arc), q_true)) < 1e-8


def test_tracked_natural_motion_of_an_asymmetric_body_ends_at_the_target():
    problem = paper_problem(np.array([0.02, 0.05, 0.04]))
    reference = PLANNERS["natural_motion"]().plan(problem)
    simulation = Simulator(problem.model, 0.1).run(
        CONTROLLERS["augmented_quaternion_feedback"]({"kp": 0.5, "kd": 1.2}), problem.initial_state, 110.0,
        reference=reference, target=(problem.qf, problem.omegaf))
    metrics = metrics_from_simulation(simulation, problem.qf, problem.omegaf, reference=reference)
    assert metrics["final_error_deg"] < 0.5


def test_non_principal_inertia_is_planned_in_principal_axes(rng):
    moments = np.array([0.02, 0.05, 0.04])
    rotation = quat.rotation_matrix(quat.random_unit(rng))
    inertia = rotation @ np.diag(moments) @ rotation.T
    spacecraft = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes())
    problem = ManeuverProblem(spacecraft, quat.random_unit(rng), np.zeros(3), quat.random_unit(rng), 110.0,
                              omegaf=np.zeros(3))
    reference = PLANNERS["natural_motion"]().plan(problem)
    assert reference.status == "ok", reference.message
    assert np.rad2deg(quat.error_angle(reference.q(110.0), problem.qf)) < 1e-3
    # On the arc the body moves freely with its full inertia: integrate I ω̇ = −ω × I ω in body axes.
    arc = np.linspace(0, 100.0, 201)

    def rhs(_, y):
        w = y[4:]
        return np.r_[quat.kinematics(y[:4], w), np.linalg.solve(inertia, -np.cross(w, inertia @ w))]

    truth = solve_ivp(rhs, (0, 100.0), np.r_[problem.q0, reference.omega(0.0)], method="DOP853", rtol=1e-13,
                      atol=1e-14, t_eval=arc)
    assert np.max(quat.error_angle(reference.q(arc), truth.y[:4].T)) < 1e-8
    np.testing.assert_allclose(reference.omega(arc), truth.y[4:].T, atol=1e-10)


@pytest.mark.parametrize("stop", ["step", "smooth"])
def test_a_stop_of_zero_seconds_is_refused(stop):
    # Without a stop the arc ends at T still turning: ω(T) ≠ 0 although the reference claims to end at
    # rest, and the stop (a rate step at T itself) is no breakpoint inside (0, T) the scoring could see.
    with pytest.raises(OptionsError, match=r"planners\[0\]\.options\.stop_time.*> 0"):
        PLANNERS["natural_motion"]({"stop_time": 0.0, "stop": stop}, path="planners[0].options")


@pytest.mark.parametrize("stop", ["step", "smooth"])
def test_a_short_stop_ends_at_rest_and_is_scored(stop):
    problem = paper_problem()
    reference = PLANNERS["natural_motion"]({"stop_time": 1e-6, "stop": stop}).plan(problem)
    assert reference.status == "ok", reference.message
    assert np.all(reference.omega(np.array([110.0])) == 0.0)
    arc_end = reference.omega(np.array([110.0 - 2e-6]))[0]  # the arc's rate just before the stop
    assert np.linalg.norm(arc_end) > 1e-3
    t = np.linspace(0.0, 110.0, 1101)
    jumps = rate_jumps(t, reference.omega(t), problem.omega0, reference)
    if stop == "step":  # no finite torque stops the body at once: an impulse the scoring reports
        assert len(jumps) == 1 and jumps[0][0] == pytest.approx(110.0 - 1e-6)
        np.testing.assert_allclose(jumps[0][2], -arc_end, atol=1e-6)
    else:  # the cubic's peak deceleration 1.5 ω/stop_time at mid-stop, a torque the actuators are scored on
        assert jumps == []
        mid = reference.torque(np.array([110.0 - 0.5e-6]))[0]
        assert np.linalg.norm(mid) > 0.99 * np.linalg.norm(UKUBE1 * 1.5 * arc_end / 1e-6)


@pytest.mark.parametrize("stop_time", [1e-15, 1e-300])
def test_a_stop_too_short_for_T_to_resolve_is_refused(stop_time):
    """110 s − 1e-15 s is 110 s in doubles: the stop vanished and the row was ok while the reference
    ended turning (as with stop_time 0, refused by the option's range)."""
    reference = PLANNERS["natural_motion"]({"stop_time": stop_time}).plan(paper_problem())
    assert reference.status == "failed" and "below 1e-09 of T = 110 s" in reference.message
