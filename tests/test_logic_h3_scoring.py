"""Requirement scoring (``scenarios.requirements.scoring``): the free start's torque, the closed
loop's wheel limits, the rate requirement's least duration and the peak rate at breakpoint sides,
against oracles that are not the scoring's own code:

* the free start's torque is constant in the inertial frame and removes the momentum no wheel
  takes: ``∫₀ᵀ R(q(t)) τ(t) dt = R(q₀) J`` (the integrand is constant, so the trapezoidal sum over
  any grid is exact), ``J`` the component of ``I Δω`` along the axis two wheels (x, y) leave, by
  hand; below the documented rate tolerance (``‖I⁻¹ J‖``, a rate) there is none, whatever the
  inertia;
* the closed loop's wheel score on hand-made momenta: of two wheels reaching the limit at one
  sample, the documented one (the lowest) is named, not the one rounding puts higher;
* ``rate_violations`` refuses ``θ/ω_max > T`` only beyond the scoring's slack (the documented rule,
  with θ the principal angle, 1 rad here by construction);
* the peak rate reads the reference's breakpoint sides only within the scored samples (a stub
  reference whose sides are given by hand).

Mutations caught (a scratch mutation run on scoring.py with test_requirements_free_start,
test_closed_loop_wheel_momentum, test_between_samples_oracle, test_mutants_scoring,
test_requirements_scoring, test_needed_duration, test_endpoint_free_time, which let them through):
the start torque's impulse not rotated to the inertial frame, its tolerance on momentum instead
of rate, the first element at the limit chosen by ratio, the rate violation without the slack,
breakpoint sides outside the samples counted.
"""
from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, quat
from planners import ManeuverProblem
from planners.base import REQUIREMENT_TOLERANCE
from planners.reference import JUMP_TOLERANCE
from scenarios.requirements.scoring import (
    _rate,
    closed_loop_wheels,
    rate_violations,
    start_torque,
)
from scenarios.requirements.spec import RateRequirement

INERTIA = np.array([[19.5, 0.4, -0.3], [0.4, 19.0, 0.2], [-0.3, 0.2, 12.6]])


def _rotation(q: np.ndarray) -> np.ndarray:
    """Body-to-inertial matrix of a scalar-first quaternion (written out here)."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _two_wheels(inertia: np.ndarray = INERTIA) -> Spacecraft:
    return Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(2, max_torque=0.1, max_momentum=1.0))


def test_the_free_start_torque_removes_the_untaken_momentum_in_the_inertial_frame():
    T = 40.0
    t = np.linspace(0.0, 50.0, 101)
    axis = np.array([0.48, 0.6, 0.64])
    q = np.array([np.r_[np.cos(0.4 + 0.01 * tk), np.sin(0.4 + 0.01 * tk) * axis] for tk in t])  # tilted, turning
    step = np.array([0.01, -0.02, 0.015])
    torque, impulse = start_torque(_two_wheels(), t, q, step, T)
    expected = np.array([0.0, 0.0, (INERTIA @ step)[2]])  # wheels on x and y take the rest at once
    np.testing.assert_allclose(impulse, expected, rtol=1e-12, atol=1e-15)
    during = t <= T
    np.testing.assert_array_equal(torque[~during], 0.0)
    inertial = np.array([_rotation(qk) @ tk for qk, tk in zip(q[during], torque[during])])
    np.testing.assert_allclose(inertial, np.tile(_rotation(q[0]) @ expected / T, (int(during.sum()), 1)),
                               rtol=0, atol=1e-15)
    swept = np.sum(0.5 * (inertial[1:] + inertial[:-1]) * np.diff(t[during])[:, None], axis=0)
    np.testing.assert_allclose(swept, _rotation(q[0]) @ expected, rtol=1e-12)
    np.testing.assert_allclose(torque[0], expected / T, rtol=1e-12, atol=1e-16)


@pytest.mark.parametrize("moment, rate, asked", [(500.0, 0.9 * JUMP_TOLERANCE, False),
                                                 (0.05, 3.0 * JUMP_TOLERANCE, True)])
def test_the_free_start_tolerance_is_on_the_rate_not_the_momentum(moment, rate, asked):
    """z is no wheel's: J = moment * rate about z. 500 kg m² at 0.9e-6 rad/s: J = 4.5e-4 N m s, yet a
    rate within the tolerance; 0.05 kg m² at 3e-6 rad/s: J = 1.5e-7 N m s, a rate beyond it."""
    inertia = np.diag([moment, moment, moment])
    t = np.linspace(0.0, 10.0, 11)
    q = np.tile(quat.IDENTITY, (t.size, 1))
    torque, impulse = start_torque(_two_wheels(inertia), t, q, [0.0, 0.0, rate], 10.0)
    if asked:
        np.testing.assert_allclose(impulse, [0.0, 0.0, moment * rate], rtol=1e-12)
        np.testing.assert_allclose(torque[0], [0.0, 0.0, moment * rate / 10.0], rtol=1e-12)
    else:
        assert not np.any(impulse) and not np.any(torque)


def test_the_first_wheel_at_its_limit_is_the_lowest_there_whatever_the_rounding():
    """Wheels 0 and 1 reach the limit at the same sample, wheel 1 a rounding (1e-10) closer: the
    documented choice is the lowest element at the limit there, wheel 0."""
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=0.3))
    t = np.linspace(0.0, 4.0, 5)
    h = np.zeros((t.size, 3))
    h[2:, 0] = 0.3 * (1 - 1e-10)
    h[2:, 1] = 0.3
    score = closed_loop_wheels(spacecraft, t, np.zeros((t.size, 3)), h)
    assert score is not None and not score.met
    assert "wheel 0: 0.3 N m s, the first there" in score.detail, score.detail
    assert score.values["wheels_momentum_time_s"] == 2.0


def _problem(duration: float) -> ManeuverProblem:
    """A 1 rad slew about z under a 0.01 rad/s rate requirement: θ/ω_max = 100 s."""
    return ManeuverProblem(Spacecraft(INERTIA), quat.IDENTITY, np.zeros(3), np.array([np.cos(0.5), 0.0, 0.0, np.sin(0.5)]),
                           duration, rate_requirement=0.01)


def test_the_rate_violation_before_planning_allows_the_scorings_slack():
    assert rate_violations(_problem(100.0 / (1.0 + 0.5 * REQUIREMENT_TOLERANCE))) == []
    assert rate_violations(_problem(100.0)) == []
    words = rate_violations(_problem(100.0 / (1.0 + 5.0 * REQUIREMENT_TOLERANCE)))
    assert len(words) == 1 and "requirements.rate.max" in words[0]


def test_the_peak_rate_reads_breakpoint_sides_within_the_samples_only():
    t = np.linspace(0.0, 8.0, 9)
    omega = np.zeros((t.size, 3))
    omega[3] = [0.0, 0.06, 0.08]  # |ω| = 0.1 at 3 s
    requirement = RateRequirement(0.2)

    def stub(at: float) -> Any:  # the two members _rate reads of a Reference
        sides = np.array([at - 1e-6, at + 1e-6])
        return SimpleNamespace(breakpoints=np.array([at]),
                               breakpoint_sides=lambda: (sides, SimpleNamespace(omega=np.array([[0.0, 0.0, 0.5]] * 2))))

    outside = _rate(requirement, t, omega, stub(10.0))  # a switch after the last sample scored
    assert outside.met and outside.values["peak_rate"] == pytest.approx(0.1, rel=1e-12)
    assert outside.values["peak_time_s"] == 3.0
    inside = _rate(requirement, t, omega, stub(5.0))  # between two samples: its peak counts
    assert not inside.met and inside.values["peak_rate"] == 0.5
