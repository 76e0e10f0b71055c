"""Shape polynomials against the kinematics integrated here (the attitude is the integral of the
rate, q̇ = ½ q ⊗ [0, ω], scipy's DOP853), the rate's derivative by finite differences at the ends
and inside, the angle turned (the short way round, whatever the sign of the given target), and with
a rate limit the shortest duration over the shapes tried."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp, trapezoid

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

SPACECRAFT = Spacecraft([2.27293, 3.27331, 1.5], torquers=Torquers(1.0))
Q0 = quat.normalize(np.array([0.9, 0.2, -0.3, 0.1]))
QF = quat.product(Q0, quat.from_rotation_vector([0.6, -0.4, 0.9]))


def planned(qf, omega0=(0.0, 0.0, 0.0), omegaf=(0.0, 0.0, 0.0), terms=3):
    problem = ManeuverProblem(SPACECRAFT, Q0, np.array(omega0), qf, 600.0, omegaf=np.array(omegaf))
    reference = PLANNERS["shape_polynomial"]({"terms": terms, "duration": "scenario"}).plan(problem)
    assert reference.status == "ok", reference.message
    return reference


@pytest.mark.parametrize("terms", [1, 3])
def test_the_attitude_is_the_integral_of_the_rate(terms):
    reference = planned(QF, omega0=(1e-3, -2e-3, 5e-4), omegaf=(-1e-3, 0.0, 2e-3), terms=terms)
    t = np.linspace(0.0, reference.duration, 31)

    def rhs(time, q):
        w = reference.omega(time)
        return 0.5 * np.r_[-q[1:] @ w, q[0] * w + np.cross(q[1:], w)]

    truth = solve_ivp(rhs, (0.0, reference.duration), Q0, method="DOP853", rtol=1e-12, atol=1e-13, t_eval=t)
    assert np.max(quat.error_angle(reference.q(t), truth.y.T)) < 1e-7


def test_the_acceleration_is_the_derivative_of_the_rate_at_the_ends_too():
    reference = planned(QF, omega0=(1e-3, -2e-3, 5e-4), omegaf=(-1e-3, 0.0, 2e-3))
    T, h = reference.duration, 1e-3
    inside = np.array([0.25 * T, 0.5 * T])
    central = (reference.omega(inside + h) - reference.omega(inside - h)) / (2 * h)
    ends = np.array([(reference.omega(h) - reference.omega(0.0)) / h, (reference.omega(T) - reference.omega(T - h)) / h])
    scale = np.max(np.abs(central))
    np.testing.assert_allclose(reference.omega_dot(inside), central, atol=1e-6 * scale)
    np.testing.assert_allclose(reference.omega_dot(np.array([0.0, T])), ends, atol=1e-3 * scale)


def test_a_target_given_as_minus_q_is_reached_the_short_way_round():
    angle = quat.error_angle(QF, Q0)
    for target in (QF, -QF):
        reference = planned(target, terms=1)
        t = np.linspace(0.0, reference.duration, 4001)
        turned = trapezoid(np.linalg.norm(reference.omega(t), axis=1), t)
        assert turned < 1.05 * angle, (target, turned, angle)


def test_with_a_rate_limit_the_shortest_of_the_shapes_tried_is_kept():
    """The option's promise: t_f is the shortest over N = 1 … max_terms (each planned on its own
    here), not the N of the lowest path cost (N = 6 on this slew, 0.6 % slower than N = 5)."""
    problem = ManeuverProblem(SPACECRAFT, quat.IDENTITY, np.zeros(3),
                              quat.from_scalar_last([0.2068, 0.2518, 0.1682, 0.9303]), 1000.0,
                              omegaf=np.zeros(3), max_rate=0.001)
    alone = [PLANNERS["shape_polynomial"]({"terms": n}).plan(problem) for n in range(1, 7)]
    assert all(reference.ok for reference in alone)
    chosen = PLANNERS["shape_polynomial"]({"max_terms": 6}).plan(problem)
    assert chosen.ok, chosen.message
    assert chosen.duration <= min(reference.duration for reference in alone) * (1 + 1e-4)
