"""The eigenaxis bang profiles' message names a triangle's rate a peak rate, a coast's a coast rate.

A user read "coast rate 0.2344 rad/s" for a ``min_time`` profile that is a pure triangle (accelerate
to T/2, decelerate: no coast). Oracles by hand, rest to rest about a principal axis of moment ``J``:
with torque ``u`` alone, ``α = u / J`` and the triangle peaks at ``sqrt(Θ α)``; with a wheel of
momentum ``h_max`` below ``J sqrt(Θ α)`` it coasts at ``h_max / J``; over a fixed T longer than the
minimum, the bang-coast-bang coasts at the ``w`` of ``w (T − w / α) = Θ``.
"""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

J, U, ANGLE = 4.0, 0.1, np.deg2rad(90.0)


def _problem(duration, max_momentum=None):
    if max_momentum is None:
        spacecraft = Spacecraft([J, 5.0, 6.0], torquers=Torquers(U))
    else:
        spacecraft = Spacecraft([J, 5.0, 6.0], wheels=ReactionWheels(np.eye(3), max_torque=U, max_momentum=max_momentum))
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([1, 0, 0], ANGLE), duration,
                           omegaf=np.zeros(3))


def _words(message):
    return "coast" if "coast rate" in message else "peak" if "peak rate" in message else None


def test_min_time_triangle_says_peak_rate():
    peak = np.sqrt(ANGLE * U / J)
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(_problem(200.0))
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(2 * peak / (U / J), rel=1e-9)  # a triangle: 2 w / α
    assert f"minimum time {reference.duration:.3f} s, peak rate {peak:.4g} rad/s" in reference.message
    assert _words(reference.message) == "peak", reference.message


def test_min_time_capped_by_the_wheels_says_coast_rate():
    h_max = 0.05
    w, alpha = h_max / J, U / J
    assert w < np.sqrt(ANGLE * alpha)  # not vacuous: the momentum caps the rate, the profile coasts
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(_problem(200.0, h_max))
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(ANGLE / w + w / alpha, rel=1e-9)
    assert f"coast rate {w:.4g} rad/s, capped by the wheels' momentum bound" in reference.message
    assert _words(reference.message) == "coast", reference.message


def test_trapezoid_longer_than_the_minimum_says_coast_rate():
    alpha, T = U / J, 30.0
    w = (alpha * T - np.sqrt((alpha * T) ** 2 - 4 * alpha * ANGLE)) / 2  # w (T − w / α) = Θ, the slower root
    assert T > 2 * np.sqrt(ANGLE / alpha)  # longer than the triangle: a coast
    reference = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(_problem(T))
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(T)
    assert f"bang-coast-bang, coast rate {w:.4g} rad/s" in reference.message, reference.message


def test_trapezoid_over_the_minimum_time_says_peak_rate():
    alpha = U / J
    T = 2 * np.sqrt(ANGLE / alpha)  # the triangle's time: no coast is left
    reference = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(_problem(T))
    assert reference.ok, reference.message
    assert f"bang-coast-bang, peak rate {np.sqrt(ANGLE * alpha):.4g} rad/s" in reference.message, reference.message
    assert _words(reference.message) == "peak", reference.message


# The user's 12U: full inertia, a 4-wheel pyramid at 30 deg elevation (4 mN m, 0.03 N m s), 120 deg about (0, 1, 1)
INERTIA_12U = np.array([[0.21, -0.004, 0.003], [-0.004, 0.24, 0.002], [0.003, 0.002, 0.11]])
PYRAMID = np.array([[np.cos(np.deg2rad(30)) * np.cos(a), np.cos(np.deg2rad(30)) * np.sin(a), np.sin(np.deg2rad(30))]
                    for a in np.deg2rad([45, 135, 225, 315])]).T


@pytest.mark.parametrize("fraction, margin, coasts", [(0.8, 0.1, False), (1.0, 0.0, True)])
def test_user_pyramid_says_peak_rate_for_its_triangle(fraction, margin, coasts):
    """torque_fraction 0.8 and margin 0.1: α = 0.72 × 4 mN m / max|(A⁺ I e)_i|, a triangle peaking at
    sqrt(Θ α) = 0.2344 rad/s; fraction 1, margin 0: the momentum cap 0.03 / max|(A⁺ I e)_i| is below
    the triangle's peak, and the profile coasts there (the user's two checks)."""
    axis, angle = np.array([0.0, 1.0, 1.0]) / np.sqrt(2.0), np.deg2rad(120.0)
    wheels = ReactionWheels(PYRAMID, max_torque=0.004, max_momentum=0.03)
    problem = ManeuverProblem(Spacecraft(INERTIA_12U, wheels=wheels), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle(axis, angle), 60.0, omegaf=np.zeros(3), actuator_margin=margin)
    per_rate = np.max(np.abs(np.linalg.pinv(PYRAMID) @ INERTIA_12U @ axis))  # wheel momentum per rad/s
    alpha, cap = fraction * (1 - margin) * 0.004 / per_rate, (1 - margin) * 0.03 / per_rate
    peak = np.sqrt(angle * alpha)
    assert (cap < peak) == coasts  # not vacuous: the momentum caps the rate in the second case only
    reference = PLANNERS["eigenaxis"]({"profile": "min_time", "torque_fraction": fraction}).plan(problem)
    assert reference.ok, reference.message
    if coasts:
        assert reference.duration == pytest.approx(angle / cap + cap / alpha, rel=1e-9)
        assert f"coast rate {cap:.4g} rad/s, capped by the wheels' momentum bound" in reference.message
    else:
        assert reference.duration == pytest.approx(2 * np.sqrt(angle / alpha), rel=1e-9)
        assert f"minimum time {reference.duration:.3f} s, peak rate {peak:.4g} rad/s" in reference.message
    assert _words(reference.message) == ("coast" if coasts else "peak"), reference.message
