"""The eigenaxis bang profiles and ``Spacecraft.torque_along`` against the controllers' allocation
``g = −A⁺ τ``, with the pseudo-inverse and the closed forms recomputed here with NumPy.

A four-wheel pyramid gives along a body direction far more torque than the per-axis box every
corner of which it realises (``body_torque_limit``); the bang profiles use the former, so that a
wheel reaches its limit, and no more, through the allocation every controller uses.
"""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

PYRAMID = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / np.sqrt(3)
G_MAX = 0.01
SKEWED_INERTIA = np.array([[20.0, 0.5, -0.3], [0.5, 17.0, 0.4], [-0.3, 0.4, 14.0]])
USER_TARGET = quat.normalize([0.5, 0.1796, -0.4490, 0.7184])  # 120 deg, the fresh-eyes user's case


def _plan(spacecraft, qf, profile, duration=90.0):
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), qf, duration, omegaf=np.zeros(3))
    return PLANNERS["eigenaxis"]({"profile": profile, "torque_fraction": 1.0}).plan(problem)


def _axis_angle(qf):
    rotation = quat.to_rotation_vector(qf)
    angle = float(np.linalg.norm(rotation))
    return rotation / angle, angle


def _peak_wheel_torque(reference, axes, inertia):
    """max |g_i| of the wheels' motor torque g = −A⁺ (I ω̇ + ω × H) over a dense grid of the
    reference (A⁺ by NumPy), from rest with the wheels at zero momentum: the total momentum H is
    conserved at zero, g = −A⁺ I ω̇ (the body's ω × I ω is the wheels' −ω × A h_w)."""
    t = np.linspace(0.0, reference.duration, 20001)
    switches = np.asarray(reference.breakpoints)
    t = np.unique(np.concatenate([t, switches - 1e-9, switches + 1e-9]).clip(0.0, reference.duration))
    torque = reference.sample(t).omega_dot @ np.asarray(inertia).T
    return float(np.max(np.abs(torque @ np.linalg.pinv(axes).T)))


def test_torque_along_pyramid_and_body_axes():
    pyramid = Spacecraft(np.diag([10.0, 10.0, 8.0]), wheels=ReactionWheels(PYRAMID, max_torque=G_MAX))
    # along z every wheel takes (A⁺ e_z)_i = (3/4)/sqrt(3): 4 g_max / sqrt(3), three times the box's
    assert pyramid.torque_along([0, 0, 2.0]) == pytest.approx(4 * G_MAX / np.sqrt(3), rel=1e-12)
    assert pyramid.body_torque_limit()[2] < 0.34 * pyramid.torque_along([0, 0, 1])
    direction = np.array([0.3, -0.5, 0.8])
    d = direction / np.linalg.norm(direction)
    assert pyramid.torque_along(direction) == pytest.approx(G_MAX / np.max(np.abs(np.linalg.pinv(PYRAMID) @ d)),
                                                            rel=1e-12)
    # wheels along the body axes: the box is the realised set, exact along every direction
    body = Spacecraft(np.diag([10.0, 10.0, 8.0]), wheels=ReactionWheels.from_body_axes(max_torque=G_MAX))
    assert body.torque_along([1, 1, 1]) == pytest.approx(G_MAX * np.sqrt(3), rel=1e-12)
    assert body.torque_along(direction) == pytest.approx(float(np.min(body.body_torque_limit() / np.abs(d))),
                                                         rel=1e-12)
    # a failed wheel: A⁺ of the three working ones
    failed = Spacecraft(np.diag([10.0, 10.0, 8.0]), wheels=ReactionWheels(PYRAMID, max_torque=G_MAX, failed=[1]))
    working = PYRAMID[:, [0, 2, 3]]
    assert failed.torque_along([0, 0, 1]) == pytest.approx(
        G_MAX / np.max(np.abs(np.linalg.inv(working) @ [0, 0, 1])), rel=1e-12)


def test_torque_along_combined_actuators_as_the_allocation():
    inertia = np.diag([10.0, 10.0, 8.0])
    # wheels spanning three axes take every torque: torquers beside them are never asked
    both = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(max_torque=G_MAX), torquers=Torquers(0.003))
    assert both.torque_along([1, 0, 0]) == pytest.approx(G_MAX, rel=1e-12)
    # two wheels: the third axis is the torquers' alone, and nobody's without them
    two = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(2, max_torque=G_MAX), torquers=Torquers(0.003))
    assert two.torque_along([0, 0, 1]) == pytest.approx(0.003, rel=1e-12)
    assert two.torque_along([1, 0, 1]) == pytest.approx(0.003 * np.sqrt(2), rel=1e-12)
    alone = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(2, max_torque=G_MAX))
    assert alone.torque_along([0, 0, 1]) == 0.0
    assert alone.torque_along([0, 1, 0]) == pytest.approx(G_MAX, rel=1e-12)


def test_min_time_about_a_principal_axis_is_the_closed_form_triangle():
    """No gyroscopic term about a principal axis: T = 2 sqrt(Θ / α), α = g_max / max|A⁺ I e|."""
    inertia = np.diag([12.0, 11.0, 8.0])
    spacecraft = Spacecraft(inertia, wheels=ReactionWheels(PYRAMID, max_torque=G_MAX))
    qf = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.deg2rad(90.0))
    axis, angle = _axis_angle(qf)
    alpha = G_MAX / np.max(np.abs(np.linalg.pinv(PYRAMID) @ (inertia @ axis)))
    reference = _plan(spacecraft, qf, "min_time")
    assert reference.status == "ok"
    assert reference.duration == pytest.approx(2 * np.sqrt(angle / alpha), rel=1e-9)
    assert _peak_wheel_torque(reference, PYRAMID, inertia) == pytest.approx(G_MAX, rel=1e-9)
    # the box would have taken sqrt(3) longer: the wheels give 3 x its torque about z
    box = spacecraft.body_torque_limit()[2]
    assert reference.duration < 2 * np.sqrt(angle * inertia[2, 2] / box) / 1.7


def test_pyramid_min_time_within_the_allocation_and_at_its_acceleration():
    """The user's case: 120 deg, non-principal inertia. From rest with the wheels at zero momentum
    the total momentum stays zero and the wheels' torque is A⁺ I e θ̈: no gyroscopic reserve (the
    rigid body's ω × I ω is the wheels' own momentum turning), so T is the bang-bang time at the
    allocation's acceleration (9.885e-4 rad/s^2), 92.06 s (94.2 s with the rigid-body budget, 112.6 s
    with the box), and the wheels reach their limit through A⁺ without exceeding it."""
    spacecraft = Spacecraft(SKEWED_INERTIA, wheels=ReactionWheels(PYRAMID, max_torque=G_MAX, max_momentum=0.5))
    axis, angle = _axis_angle(USER_TARGET)
    alpha = G_MAX / np.max(np.abs(np.linalg.pinv(PYRAMID) @ (SKEWED_INERTIA @ axis)))
    assert alpha == pytest.approx(9.885e-4, rel=1e-3)
    bang_bang = 2 * np.sqrt(angle / alpha)  # 92.06 s
    reference = _plan(spacecraft, USER_TARGET, "min_time")
    assert reference.status == "ok"
    assert reference.duration == pytest.approx(bang_bang, rel=1e-9)
    peak = _peak_wheel_torque(reference, PYRAMID, SKEWED_INERTIA)
    assert peak == pytest.approx(G_MAX, rel=1e-9)
    # trapezoidal over 100 s (infeasible under the box): within the limits through A⁺
    fixed = _plan(spacecraft, USER_TARGET, "trapezoidal", duration=100.0)
    assert fixed.status == "ok", fixed.message
    assert fixed.duration == 100.0
    assert _peak_wheel_torque(fixed, PYRAMID, SKEWED_INERTIA) <= G_MAX * (1 + 1e-9)
    below = _plan(spacecraft, USER_TARGET, "trapezoidal", duration=0.99 * bang_bang)
    assert below.status == "infeasible"


def test_wheels_and_torquers_min_time_uses_the_wheels_alone():
    """Wheels along the body axes take every torque, so the torquers add nothing in the closed
    loop: the principal-axis min time is 2 sqrt(Θ I_z / g_max), not with g_max + the torquers'."""
    inertia = np.diag([12.0, 11.0, 8.0])
    spacecraft = Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(max_torque=G_MAX), torquers=Torquers(0.02))
    qf = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.deg2rad(60.0))
    _, angle = _axis_angle(qf)
    reference = _plan(spacecraft, qf, "min_time")
    assert reference.duration == pytest.approx(2 * np.sqrt(angle * 8.0 / G_MAX), rel=1e-9)
