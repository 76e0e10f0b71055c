"""Targets no motion reaches, by conservation of angular momentum (ManeuverProblem.unreachable).

Oracle: the rigid body with one working wheel, integrated by SciPy from zero total momentum under an
arbitrary wheel torque, turns about the fixed body axis I⁻¹a only; collocation refuses other slews
at once (a slew table with two failed wheels spent 235 s per such entry) and plans the reachable one
in the closed-form time 2√(θ J / u).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

INERTIA = np.array([[10.0, 0.5, 0.2], [0.5, 8.0, 0.3], [0.2, 0.3, 6.0]])
WHEEL = np.array([0.6, 0.0, 0.8])  # the one working wheel's axis, body frame


def one_wheel(inertia=INERTIA) -> Spacecraft:
    axes = np.column_stack([WHEEL, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    return Spacecraft(inertia, wheels=ReactionWheels(axes, max_torque=0.1, max_momentum=2.0, failed=[1, 2]))


def test_one_wheel_turns_the_body_about_the_inverse_inertia_axis_only():
    inertia_inverse = np.linalg.inv(INERTIA)

    def rhs(t, y):  # q, ω, h (wheel momentum along WHEEL); torque g(t) on the wheel, −g a on the body
        q, omega, h = y[:4], y[4:7], y[7]
        g = 0.05 * np.sin(0.7 * t) + 0.02
        omega_dot = inertia_inverse @ (-g * WHEEL - np.cross(omega, INERTIA @ omega + h * WHEEL))
        return np.concatenate([0.5 * quat.product(q, np.r_[0.0, omega]), omega_dot, [g]])

    solution = solve_ivp(rhs, (0.0, 20.0), np.r_[quat.IDENTITY, np.zeros(3), 0.0], rtol=1e-11, atol=1e-13)
    turn = quat.to_rotation_vector(solution.y[:4, -1])
    axis = inertia_inverse @ WHEEL / np.linalg.norm(inertia_inverse @ WHEEL)
    assert np.linalg.norm(turn) > 0.5 and np.linalg.norm(np.cross(turn, axis)) < 1e-8 * np.linalg.norm(turn)


def test_a_slew_off_that_axis_is_refused_and_one_about_it_is_not():
    spacecraft = one_wheel()
    axis = np.linalg.solve(INERTIA, WHEEL)
    about = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(axis, 1.0), 60.0,
                            omegaf=np.zeros(3))
    assert about.unreachable() is None
    off = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(WHEEL, 1.0), 60.0,
                          omegaf=np.zeros(3))
    reason = off.unreachable()
    assert reason is not None and "can only turn about the body axis" in reason
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(off)
    assert reference.status == "infeasible" and reference.message == reason and reference.plan_time_s < 0.5


def test_the_reachable_slew_takes_the_closed_form_time():
    # a sphere, J = 2: the wheel about x turns the body about x, bang-bang 2 sqrt(θ J / u)
    spacecraft = one_wheel(np.diag([2.0, 2.0, 2.0]))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(WHEEL, 1.0), 30.0,
                              omegaf=np.zeros(3))
    assert problem.unreachable() is None
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(2.0 * np.sqrt(1.0 * 2.0 / 0.1), rel=1e-6)


@pytest.mark.parametrize("change", ["torquers", "momentum", "two wheels", "failed wheel momentum"])
def test_what_it_does_not_decide(change):
    spacecraft = one_wheel()
    omega0, h0 = np.zeros(3), np.zeros(3)
    if change == "torquers":
        spacecraft = Spacecraft(INERTIA, wheels=spacecraft.wheels, torquers=Torquers(0.01))
    elif change == "momentum":
        omega0 = np.array([0.0, 0.01, 0.0])  # the body's momentum with nothing to balance it: it drifts
    elif change == "failed wheel momentum":
        # failed wheel 1 (body y) keeps 0.5 N m s, the body the opposite: zero in total, yet the body
        # coasts about another axis than I⁻¹a (a reviewer's SciPy coast: 72 deg about ~y in 20 s)
        h0 = np.array([0.0, 0.5, 0.0])
        omega0 = -np.linalg.solve(INERTIA, np.array([0.0, 0.5, 0.0]))
    else:
        axes = np.column_stack([WHEEL, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
        spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes, max_torque=0.1, max_momentum=2.0, failed=[2]))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, omega0, quat.from_axis_angle(WHEEL, 1.0), 60.0,
                              wheel_momentum0=h0)
    assert problem.unreachable() is None


def test_a_final_rate_off_the_axis_is_named():
    """About the reachable axis, but ending with a rate off it: the reason is the final rate."""
    spacecraft = one_wheel(np.diag([2.0, 2.0, 2.0]))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(WHEEL, 1.0), 30.0,
                              omegaf=np.array([0.0, 1e-3, 0.0]))
    reason = problem.unreachable()
    assert reason is not None and reason.endswith("the final rate [0.0, 0.001, 0.0] rad/s is not about it "
                                                  "(maneuver.final.omega)")
