"""A collocation reference's wheel torques scaled as a whole keep each interval's impulse.

On a wheel array where ``collocation`` imposes the controllers' allocation (a four-wheel pyramid:
the torques stay in the row space of the axes, ``g = A⁺ A g``), the reference saturates the
interpolated wheel torques by scaling the block as a whole (a clip per wheel would leave the row
space). A bang-bang switch inside an interval overshoots the bounds between the points, and the
scaling alone loses that part of the impulse that the state polynomial integrates: flown open loop,
the user's pyramid minimum-time slew ended 0.155 deg from its target and a 30-deg pyramid's
0.603 deg. Each such interval's block is now shifted by a vector ``c`` in the allowed directions
(``E c = 0``) that restores the impulse (:func:`planners.collocation.reference._block_offsets`).

Oracles, independent of the planner: the rigid body with its wheels integrated by scipy under the
reference's wheel torques (``I ω̇ = −ω × (I ω + A h) − A g``, ``ḣ = g``, written here), the Radau
quadrature of the solution's values at its points (exact for the control polynomial), the pyramid's
null space and pseudo-inverse by NumPy, and, on synthetic intervals, the radial scaling written
here.
"""
from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import planners.collocation.reference as collocation_reference
from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from planners.conformance import check_reference

PYRAMID = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / np.sqrt(3)
NULL = np.array([1.0, -1.0, 1.0, -1.0]) / 2.0  # PYRAMID @ NULL = 0
SKEWED_INERTIA = np.array([[20.0, 0.5, -0.3], [0.5, 17.0, 0.4], [-0.3, 0.4, 14.0]])
USER_TARGET = quat.normalize([0.5, 0.1796, -0.4490, 0.7184])  # 120 deg, the fresh-eyes user's case
G_MAX = 0.01
ELEVATION, AZIMUTH = np.deg2rad(30.0), np.deg2rad([45.0, 135.0, 225.0, 315.0])
PYRAMID_30 = np.vstack([np.cos(ELEVATION) * np.cos(AZIMUTH), np.cos(ELEVATION) * np.sin(AZIMUTH),
                        np.sin(ELEVATION) * np.ones(4)])


def _user_pyramid() -> ManeuverProblem:
    spacecraft = Spacecraft(SKEWED_INERTIA, wheels=ReactionWheels(PYRAMID, max_torque=G_MAX, max_momentum=0.5))
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), USER_TARGET, 90.0, omegaf=np.zeros(3))


def _pyramid_30() -> ManeuverProblem:
    spacecraft = Spacecraft(np.diag([12.0, 10.0, 8.0]), wheels=ReactionWheels(PYRAMID_30, max_torque=2 * G_MAX))
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(axis, np.deg2rad(100.0)),
                           60.0, omegaf=np.zeros(3))


@pytest.fixture(scope="module", params=["user_pyramid", "pyramid_30"])
def pyramid(request):
    problem = {"user_pyramid": _user_pyramid, "pyramid_30": _pyramid_30}[request.param]()
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.status == "ok", reference.message
    assert reference.scaled_blocks == (slice(0, 4),)  # not vacuous: the wheels are scaled as a whole
    return problem, reference


def fly_open_loop(problem, reference):
    """The final attitude error [deg] and rate [rad/s] of the rigid body with its wheels (and
    torquers) under the reference's controls, scipy interval by interval (the control jumps at the
    nodes)."""
    spacecraft = problem.spacecraft
    axes, inertia = spacecraft.wheels.axes, spacecraft.inertia
    inverse = np.linalg.inv(inertia)

    wheels, torquers = problem.model.control_slices["wheels"], problem.model.control_slices.get("torquers")

    def rhs(t, y):
        q, omega, h = y[0:4], y[4:7], y[7:]
        u = reference.control(t)
        g = u[wheels]
        torque = -axes @ g + (u[torquers] if torquers is not None else 0.0)
        omega_dot = inverse @ (-np.cross(omega, inertia @ omega + axes @ h) + torque)
        return np.concatenate([0.5 * quat.product(q, np.concatenate([[0.0], omega])), omega_dot, g])

    y = np.concatenate([problem.q0, problem.omega0, np.zeros(axes.shape[1])])
    for a, b in pairwise(np.linspace(0.0, reference.duration, reference.intervals + 1)):
        y = solve_ivp(rhs, (a, b), y, rtol=1e-10, atol=1e-13, method="DOP853").y[:, -1]
    return float(np.rad2deg(quat.error_angle(quat.normalize(y[0:4]), problem.qf))), float(np.linalg.norm(y[4:7]))


def test_the_pyramid_slews_flown_open_loop_reach_their_targets(pyramid):
    # Scaled alone (before the block offsets) the slews ended 0.155 deg (1.2e-4 rad/s) and 0.603 deg
    # from their targets; with each interval's impulse kept, 0.0176 deg (2e-8 rad/s) and 0.0104 deg
    # (the unsaturated polynomial, which breaks the bounds: 2e-6 deg). What remains is the impulse's
    # first moment inside the switching intervals, as in the per-entry case (Bilimoria & Wie 0.0099 deg).
    problem, reference = pyramid
    error, rate = fly_open_loop(problem, reference)
    assert error < 0.03, error
    assert rate < 1e-6, rate


def test_each_interval_keeps_the_impulse_of_the_solution(pyramid):
    # The d-point Radau rule is exact for the control polynomial, so the solution's impulse over
    # interval k is h Σ_j w_j u_kj from its values at the points; the flown control's by a fine
    # midpoint rule. The offsets match on the reference's 64 midpoints, whose rule errs on these
    # switches' polynomials by about 1e-4 of the bound (the flown control: 1.7e-4 and 8e-5 of the
    # bound times h at the worst interval; scaled alone it lost 0.078 and 0.123).
    _, reference = pyramid
    transcription = reference.transcription
    N, d, h = transcription.intervals, transcription.degree, reference.duration / transcription.intervals
    bound = float(reference.control_bounds[1].max())
    U = reference.controls[:4 * d, :].reshape(d, 4, N)  # (point, wheel, interval)
    impulse = h * np.einsum("j,jik->ki", transcription.quadrature, U)
    m = 4000
    t = ((np.arange(N)[:, None] + ((np.arange(m) + 0.5) / m)[None, :]) * h).ravel()
    flown = reference.control(t).reshape(N, m, 4).mean(axis=1) * h
    scaled = collocation_reference._scaled(reference._interpolated(t)[1], *reference.control_bounds)
    scaled_alone = scaled.reshape(N, m, 4).mean(axis=1) * h
    assert np.max(np.abs(scaled_alone - impulse)) > 0.05 * bound * h  # not vacuous: scaling loses impulse
    assert np.max(np.abs(flown - impulse)) < 5e-4 * bound * h


def test_the_shifted_torques_stay_within_the_bounds_and_the_allocation(pyramid):
    problem, reference = pyramid
    axes = problem.spacecraft.wheels.axes
    null = np.linalg.svd(axes)[2][3]  # NumPy's null space of the four axes
    offsets = reference.impulse_offsets
    shifted = np.any(offsets != 0.0, axis=1)
    assert 0 < np.count_nonzero(shifted) < 10  # not vacuous: a few switching intervals, no more
    assert np.max(np.abs(offsets @ null)) <= 1e-15 * np.max(np.abs(offsets))  # E c = 0
    t = np.linspace(0.0, reference.duration, 200 * reference.intervals + 1)
    k = reference.transcription.interval_index(reference.duration, t)
    assert np.any(shifted[k])
    u, raw = reference.control(t), reference._interpolated(t)[1]
    low, high = reference.control_bounds
    assert np.all(u <= high) and np.all(u >= low)
    # the allocation's equality: u in the row space of the axes (u = A⁺ A u), no worse than the
    # solution's own polynomial (its points meet E u = 0 to the solver's tolerance) by 1e-12 of the bound
    pinv = np.linalg.pinv(axes)
    assert np.max(np.abs(u @ null)) <= np.max(np.abs(raw @ null)) + 1e-12 * high.max()
    assert np.max(np.abs(u - u @ (pinv @ axes).T)) <= np.max(np.abs(raw @ null)) + 1e-12 * high.max()
    # direction kept: the flown torque is a positive multiple of the polynomial plus its offset
    moved = raw + offsets[k]
    factor = np.einsum("ij,ij->i", u, moved) / np.einsum("ij,ij->i", moved, moved)
    assert np.all(factor > 0.0) and np.all(factor <= 1.0 + 1e-15)
    assert np.max(np.abs(u - factor[:, None] * moved)) <= 1e-15 * high.max()
    # the points of the shifted intervals are no enforced times, and the planner contract holds
    assert reference.enforced_times.size < reference.transcription.smoothness(reference.duration)[1].size
    check_reference(problem, reference)


def test_a_failed_wheel_is_not_shifted():
    # a fifth wheel, failed (held at 0 by its bounds): the equalities leave its direction free, the
    # offsets must not take it (the final clip would zero it and break the others' direction)
    spacecraft = Spacecraft(SKEWED_INERTIA, wheels=ReactionWheels(np.hstack([PYRAMID, [[0], [0], [1]]]),
                                                                  max_torque=G_MAX, max_momentum=0.5, failed=[4]))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), USER_TARGET, 90.0, omegaf=np.zeros(3))
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.status == "ok", reference.message
    offsets = reference.impulse_offsets
    assert np.any(offsets[:, :4] != 0.0) and np.all(offsets[:, 4] == 0.0)
    assert np.max(np.abs(offsets[:, :4] @ NULL)) <= 1e-15 * np.max(np.abs(offsets))
    u = reference.control(np.linspace(0.0, reference.duration, 5001))
    assert np.all(u[:, 4] == 0.0) and np.max(np.abs(u[:, :4])) <= G_MAX


def test_torquers_beside_two_wheels_are_shifted_about_the_third_axis_alone():
    # wheels on x and y, torquers beside them: the allocation sends the torquers z alone (E: their x
    # and y rows), so their block is scaled as a whole and its offsets lie along z. Flown open loop
    # the minimum time (115.21 s) ended 0.024 deg (1.3e-5 rad/s) from its target scaled alone,
    # 0.0087 deg (2.4e-6 rad/s) shifted.
    spacecraft = Spacecraft(SKEWED_INERTIA, wheels=ReactionWheels.from_body_axes(2, max_torque=G_MAX, max_momentum=0.5),
                            torquers=Torquers(0.5 * G_MAX))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), USER_TARGET, 120.0, omegaf=np.zeros(3))
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.status == "ok", reference.message
    torquers = problem.model.control_slices["torquers"]
    assert reference.scaled_blocks == (torquers,)
    offsets = reference.impulse_offsets[:, torquers]
    assert np.any(offsets[:, 2] != 0.0) and np.all(offsets[:, :2] == 0.0)
    t = np.linspace(0.0, reference.duration, 10001)
    u, raw = reference.control(t)[:, torquers], reference._interpolated(t)[1][:, torquers]
    # x and y no more than the solution's own (its equalities met to 1e-26 N m), z within its bound
    assert np.max(np.abs(u[:, :2])) <= np.max(np.abs(raw[:, :2])) and np.max(np.abs(u[:, 2])) <= 0.5 * G_MAX
    error, rate = fly_open_loop(problem, reference)
    assert error < 0.015, error
    assert rate < 5e-6, rate


def _radau_polynomials(points: np.ndarray) -> np.ndarray:
    """Degree-2 polynomials through values at the three Radau points, on 64 midpoints."""
    nodes = np.array([(4 - np.sqrt(6)) / 10, (4 + np.sqrt(6)) / 10, 1.0])
    tau = (np.arange(collocation_reference.IMPULSE_POINTS) + 0.5) / collocation_reference.IMPULSE_POINTS
    lagrange = np.array([[np.prod([(s - nodes[m]) / (nodes[j] - nodes[m]) for m in range(3) if m != j])
                          for j in range(3)] for s in tau])
    return np.einsum("mj,kjn->kmn", lagrange, points)


def _radial(x: np.ndarray, bound: float) -> np.ndarray:
    """Symmetric bounds: x scaled down until its largest entry is at the bound."""
    return x / np.maximum(np.abs(x).max(axis=-1, keepdims=True) / bound, 1.0)


def test_synthetic_switches_reach_their_impulse_and_never_lose_more():
    # 600 intervals of a pyramid's torques: three values at the Radau points within the bounds and
    # the row space (most on the boundary, bang-bang), their polynomial overshooting in between
    rng = np.random.default_rng(7)
    low, high = -G_MAX * np.ones(4), G_MAX * np.ones(4)
    basis = collocation_reference._allowed_directions(NULL[None, :], low, high)
    assert basis.shape == (4, 3) and np.max(np.abs(NULL @ basis)) < 1e-15
    directions = rng.normal(size=(600, 3, 3)) @ basis.T
    points = _radial(1e3 * directions, G_MAX) * np.where(rng.random((600, 3, 1)) < 0.3, rng.random((600, 3, 1)), 1.0)
    values = _radau_polynomials(points)
    offsets, residuals = collocation_reference._block_offsets(values, low, high, basis)
    flown = _radial(values + offsets[:, None, :], G_MAX).mean(axis=1) - values.mean(axis=1)
    before = _radial(values, G_MAX).mean(axis=1) - values.mean(axis=1)
    np.testing.assert_allclose(residuals, flown, rtol=0, atol=1e-15 * G_MAX)
    lost = np.linalg.norm(before, axis=1) > 1e-12 * G_MAX
    assert np.count_nonzero(lost) > 500  # not vacuous
    assert np.max(np.linalg.norm(flown, axis=1)[lost]) < 1e-13 * G_MAX
    assert np.max(np.abs(offsets @ NULL)) < 1e-15 * G_MAX


def test_an_unreachable_impulse_keeps_the_block_unshifted():
    # an arc at a vertex of the box (all four wheels at their limits, the direction (1, 1, 1, 1) in
    # the row space) whose points pass the bounds by 1e-6: its mean lies outside what the scaled
    # block reaches whatever the offset, so it is read as scaled, with the residual recorded
    low, high = -G_MAX * np.ones(4), G_MAX * np.ones(4)
    basis = collocation_reference._allowed_directions(NULL[None, :], low, high)
    vertex = G_MAX * np.ones(4) * (1 + 1e-6 * np.array([1.0, 0.5, 0.8]))[:, None]
    values = _radau_polynomials(vertex[None])
    offsets, residuals = collocation_reference._block_offsets(values, low, high, basis)
    assert np.all(offsets == 0.0)
    np.testing.assert_allclose(residuals[0], G_MAX - values[0].mean(axis=0), rtol=0, atol=1e-16)
