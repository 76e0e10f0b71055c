"""Collocation's reading of another planner's reference as model states and controls.

Oracles: the problem's initial state (the wheel momenta at t = 0), the conservation of the total
angular momentum in inertial axes (no external torque: wheels only), a failed wheel's momentum held
(it is given no torque), and the allocation's zero torque on a failed wheel.
"""
import numpy as np

from ocp import ReactionWheels, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem
from planners.collocation.reference import states_controls


def test_a_failed_wheel_keeps_its_stored_momentum_and_the_total_is_conserved():
    # four wheels, the skewed fourth failed holding 0.2 N m s: the three working ones span the body,
    # so the total momentum can be conserved exactly along any motion
    inertia = np.diag([3.0, 4.0, 5.0])
    axes = np.column_stack([np.eye(3), np.ones(3) / np.sqrt(3.0)])
    wheels = ReactionWheels(axes, max_torque=0.1, max_momentum=1.0, failed=[3])
    h0 = np.array([0.1, 0.0, 0.05, 0.2])
    problem = ManeuverProblem(Spacecraft(inertia, wheels=wheels), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 2, 0], np.deg2rad(30.0)), 100.0, omegaf=np.zeros(3),
                              wheel_momentum0=h0)
    reference = PLANNERS["eigenaxis"]({"profile": "smooth"}).plan(problem)
    assert reference.ok, reference.message
    t = np.linspace(0.0, reference.duration, 201)
    x, u, sample = states_controls(problem, reference, t)
    np.testing.assert_allclose(x[0, 7:], h0, atol=1e-15)  # before: the failed wheel's 0.2 went to the others
    np.testing.assert_allclose(x[:, 10], 0.2, atol=1e-15)  # held
    total = quat.rotate(sample.q, sample.omega @ inertia.T + x[:, 7:] @ axes.T)
    np.testing.assert_allclose(total, np.broadcast_to(axes @ h0, total.shape), atol=1e-12)
    np.testing.assert_array_equal(u[:, 3], 0.0)  # no torque asked of the failed wheel
