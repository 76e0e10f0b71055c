"""Planner references against oracles on non-default options (issue 33): the eigenaxis attitude
against integration of its own rate through a coast arc, and the eigenaxis bang-bang time with a
torque fraction below one (closed form)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem


@pytest.mark.parametrize("profile", ["trapezoidal", "min_time"])
def test_eigenaxis_attitude_is_the_integral_of_its_rate_through_the_coast(profile):
    """The profile accelerates, coasts and decelerates: q(t) must be the
    integral of q̇ = ½ q ⊗ [0, ω(t)] from q0 in every phase (solve_ivp, tight tolerances)."""
    spacecraft = Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(max_torque=0.05))
    target = quat.from_axis_angle([0.3, -0.5, 0.8], 2.0)
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), target, 400.0, max_rate=0.02)
    reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)
    assert reference.ok, reference.message
    t = np.linspace(0.0, reference.duration, 201)
    rates = np.linalg.norm(reference.omega(t), axis=1)
    assert np.sum(np.isclose(rates, rates.max(), rtol=1e-9)) > 20  # a coast arc at constant rate
    solution = solve_ivp(lambda s, q: quat.kinematics(q, reference.omega(s)), (0.0, reference.duration),
                         quat.IDENTITY, t_eval=t, method="DOP853", rtol=1e-11, atol=1e-12, max_step=1.0)
    assert np.max(quat.error_angle(solution.y.T, reference.q(t))) < 1e-7


def test_eigenaxis_minimum_time_with_a_torque_fraction():
    """Rest to rest about a principal axis with a fraction f of the bound: T = 2 sqrt(θ I / (f u_max)),
    peak torque f u_max."""
    inertia, u_max, fraction, angle = np.array([19.5, 19.0, 12.6]), 0.1, 0.6, 1.3
    spacecraft = Spacecraft(inertia, torquers=Torquers(max_torque=u_max))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 1, 0], angle), 100.0)
    reference = PLANNERS["eigenaxis"]({"profile": "min_time", "torque_fraction": fraction}).plan(problem)
    assert reference.duration == pytest.approx(2 * np.sqrt(angle * inertia[1] / (fraction * u_max)), rel=1e-9)
    t = np.linspace(0, reference.duration, 1001)
    assert np.max(np.abs(reference.torque(t))) == pytest.approx(fraction * u_max, rel=1e-9)
