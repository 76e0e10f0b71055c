"""The eigenaxis bang profiles with torquers unlimited on some axes (``max_torque`` ``inf`` there).

An unlimited axis caps no rate: its rate cap was ``2 inf / (c + sqrt(c² + 4 g inf))``, NaN, and
Python's ``min`` kept or dropped it by position, losing the bounded axes' cap (275.270 s "minimum
time" for torquers ``[inf, .01, .01]`` against 94.571 s). Oracles: a finite stand-in bound of
1e12 N m on the same axes, and the rigid-body torque ``I ω̇ + ω × I ω`` of the planned reference
on a dense grid (within the bounded axes' limits, and at one of them: the budget is exact).
"""
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from planners.eigenaxis import _positive_root

LIMIT = 0.01


def plan(inertia, limits, axis, angle, profile, duration=100.0):
    problem = ManeuverProblem(Spacecraft(inertia, torquers=Torquers(limits)), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle(axis, angle), duration)
    return PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)


def peak_demand(reference, inertia):
    """max |I ω̇ + ω × I ω| per body axis on a dense grid with both sides of each switch."""
    switches = np.asarray(reference.breakpoints)
    t = np.unique(np.clip(np.concatenate([np.linspace(0.0, reference.duration, 20001), switches - 1e-9,
                                          switches + 1e-9]), 0.0, reference.duration))
    sample = reference.sample(t)
    torque = sample.omega_dot @ inertia.T + np.cross(sample.omega, sample.omega @ inertia.T)
    return np.max(np.abs(torque), axis=0)


def test_an_unlimited_bound_caps_no_rate():
    assert _positive_root(1.0, 0.0, np.inf) == np.inf
    assert _positive_root(1.0, 2.0, np.inf) == np.inf
    assert _positive_root(0.0, 2.0, np.inf) == np.inf


def test_the_reviewers_case_is_the_finite_proxys_minimum_time():
    """nan4.py: torquers [inf, .01, .01] gave 275.270 s and refused a trapezoidal at 100 s."""
    inertia = np.array([[15.80889063819217, 0.2907468370971603, 0.3193120697012907],
                        [0.2907468370971603, 11.375757670219649, 0.504198890363309],
                        [0.3193120697012907, 0.504198890363309, 9.980242260315185]])
    axis = np.array([0.7619038633830855, 0.38485341627970887, 0.5209513901889177])
    unlimited = plan(inertia, [np.inf, LIMIT, LIMIT], axis, 2.606034974285076, "min_time")
    proxy = plan(inertia, [1e12, LIMIT, LIMIT], axis, 2.606034974285076, "min_time")
    assert unlimited.status == proxy.status == "ok", (unlimited.message, proxy.message)
    assert unlimited.duration == pytest.approx(proxy.duration, rel=1e-6)
    assert unlimited.duration < 95.0  # not 275.270 s
    assert plan(inertia, [np.inf, LIMIT, LIMIT], axis, 2.606034974285076, "trapezoidal").status == "ok"


def test_partly_unlimited_torquers_agree_with_a_finite_proxy_and_the_dense_demand(rng):
    """Random inertias, axes, angles and one or two unlimited axes: min_time and trapezoidal equal
    the 1e12 N m proxy's to 1e-6; the minimum-time reference's rigid-body torque stays within the
    bounded axes' limit on a dense grid and reaches it (the budget is exact without wheels)."""
    for _ in range(40):
        m = rng.normal(size=(3, 3))
        inertia = 0.5 * (m + m.T) + np.diag(rng.uniform(10.0, 20.0, 3))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(0.5, 3.1)
        free = rng.choice(3, size=int(rng.integers(1, 3)), replace=False)
        limits, proxy_limits = np.full(3, LIMIT), np.full(3, LIMIT)
        limits[free], proxy_limits[free] = np.inf, 1e12
        fastest = plan(inertia, limits, axis, angle, "min_time")
        proxy = plan(inertia, proxy_limits, axis, angle, "min_time")
        assert fastest.status == proxy.status == "ok", (fastest.message, proxy.message)
        assert fastest.duration == pytest.approx(proxy.duration, rel=1e-6)
        bounded = np.isfinite(limits)
        ratio = peak_demand(fastest, inertia)[bounded] / LIMIT
        assert np.max(ratio) <= 1 + 1e-6 and np.max(ratio) >= 1 - 1e-6, ratio
        duration = 1.3 * proxy.duration
        fixed = plan(inertia, limits, axis, angle, "trapezoidal", duration)
        fixed_proxy = plan(inertia, proxy_limits, axis, angle, "trapezoidal", duration)
        assert fixed.status == fixed_proxy.status == "ok", (fixed.message, fixed_proxy.message)
        assert fixed.profile.rate_max == pytest.approx(fixed_proxy.profile.rate_max, rel=1e-6)
        assert np.max(peak_demand(fixed, inertia)[bounded]) <= LIMIT * (1 + 1e-6)
