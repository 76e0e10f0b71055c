"""A problem built in Python without an actuator margin holds the actuator limits between the
collocation points, as a scenario does.

A fresh-eyes check (2026-12-02): full inertia, three body-axis wheels (0.1 N m, 1.0 N m s), 120°
minimum time. ``ManeuverProblem``'s default (then ``actuator_margin=None``) let collocation impose
the momentum bound at its points only: status ``ok`` at T = 33.3977 s while the wheels' momentum,
the integral of their torques, peaked at 1.0028 N m s between the points (0.245 s over the limit);
from YAML (margin 0, the requirement every scenario carries) 33.567 s within the limit.

Oracle: the momentum is the integral of the wheel torques (``ḣ = g`` per wheel, whatever the
attitude does): the reference's torque history integrated by the trapezoid rule on 40001 times,
not the reference's own momentum states.
"""
import numpy as np
import pytest

from ocp import Spacecraft
from ocp.dynamics.actuator_kinds import ReactionWheels
from planners import PLANNERS, ManeuverProblem

INERTIA = [[19.5, 0.4, -0.3], [0.4, 19.0, 0.5], [-0.3, 0.5, 12.6]]
MAX_MOMENTUM = 1.0


@pytest.fixture(scope="module")
def problem():
    wheels = ReactionWheels(axes=np.eye(3).tolist(), max_torque=0.1, max_momentum=MAX_MOMENTUM)
    return ManeuverProblem(spacecraft=Spacecraft(inertia=INERTIA, wheels=wheels), q0=[1, 0, 0, 0], omega0=[0, 0, 0],
                           qf=[0.5, 0.5, 0.5, 0.5], omegaf=[0, 0, 0], duration=150.0)


def test_the_default_problem_keeps_the_wheels_momentum_between_the_points(problem):
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.ok, reference.message
    t = np.linspace(0.0, reference.duration, 40001)
    torque = np.asarray(reference.control(t), dtype=float)
    momentum = np.vstack([np.zeros(3), np.cumsum(0.5 * (torque[1:] + torque[:-1]) * np.diff(t)[:, None], axis=0)])
    assert np.max(np.abs(momentum)) <= MAX_MOMENTUM * (1 + 1e-6)
    assert reference.duration > 33.5  # the time the overshoot bought (33.3977 s) is not claimed
