"""Gaps the mutation check found in where a reference's body rate jumps
(:func:`scenarios.requirements.scoring.rate_jumps`, :func:`planners.conformance.check_ends`,
:data:`planners.reference.JUMP_TOLERANCE`).

The references are written here with their jumps known by construction (the oracle): a constant
rate ``c`` about a fixed axis on ``(0, T)`` whose samples at the declared breakpoints follow the
contract (at 0 the right limit, at ``T`` the rate after the step), and a spin-up whose ``ω̇``
steps at a breakpoint while ``ω`` is continuous.
"""
import numpy as np
import pytest

from ocp import quat
from planners import Reference, ReferenceSample, inverse_dynamics_torque
from planners.conformance import ConformanceError, check_ends
from scenarios.requirements.scoring import rate_jumps

INERTIA = np.diag([2.0, 2.5, 3.0])


class ConstantRate(Reference):
    """``ω = c`` on ``[0, T)``; at ``T`` the rate is ``c + end_step`` (the rate after a step at T)."""

    def __init__(self, duration, rate, end_step, breakpoints=(), middle_step=None):
        super().__init__("constant_rate", duration, INERTIA, breakpoints=breakpoints)
        self.rate, self.end_step, self.middle_step = np.asarray(rate, float), np.asarray(end_step, float), middle_step

    def _evaluate(self, t):
        omega = np.tile(self.rate, (t.size, 1))
        if self.middle_step is not None:  # (time, step): the rate steps there (its sample: the right limit)
            omega[t >= self.middle_step[0]] += self.middle_step[1]
        omega[t >= self.duration] = self.rate + self.end_step
        q = quat.from_rotation_vector(np.outer(t, self.rate))  # turning at c (the rate in between)
        omega_dot = np.zeros_like(omega)
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))


RATE = np.array([6e-4, -8e-4, 5e-4])


@pytest.mark.parametrize("past_the_end", [False, True])
def test_a_stop_at_t_is_in_the_sample_at_t(past_the_end):
    """Breakpoints at 0 and T, rate c between: jumps +c at 0 (from ω0 = 0) and −c at T, the latter
    in the sample at T (index N − 1), whether or not samples follow T (the closed loop's tail)."""
    T, n = 100.0, 401
    reference = ConstantRate(T, RATE, -RATE, breakpoints=(0.0, T))
    t = np.linspace(0.0, T, n)
    if past_the_end:
        t = np.concatenate([t, [T + 0.5, T + 1.0]])
    jumps = rate_jumps(t, reference.sample(t).omega, np.zeros(3), reference)
    assert [(time, index) for time, index, _ in jumps] == [(0.0, 0), (T, n - 1)]
    np.testing.assert_allclose(jumps[0][2], RATE, rtol=0, atol=1e-15)
    np.testing.assert_allclose(jumps[1][2], -RATE, rtol=0, atol=1e-15)


@pytest.mark.parametrize("size, is_jump", [(5e-6, True), (5e-7, False)])
def test_a_step_over_a_micro_radian_per_second_is_a_jump(size, is_jump):
    """A declared step inside: 5e-6 rad/s is a jump (over JUMP_TOLERANCE, 1e-6 rad/s), 5e-7 rad/s
    is rounding; the sample at the breakpoint (50 s, a sample time) is the first after it."""
    T = 100.0
    step = size * np.array([0.6, 0.0, 0.8])
    reference = ConstantRate(T, RATE, np.zeros(3), breakpoints=(50.0,), middle_step=(50.0, step))
    t = np.linspace(0.0, T, 201)
    jumps = rate_jumps(t, reference.sample(t).omega, RATE, reference)
    if is_jump:
        assert [(time, index) for time, index, _ in jumps] == [(50.0, 101)]
        np.testing.assert_allclose(jumps[0][2], step, rtol=1e-6, atol=0)
    else:
        assert jumps == []


def test_a_fast_spin_up_across_a_breakpoint_is_no_jump():
    """ω = α t x̂ up to 0.5 s, then constant, α = 5000 rad/s² (T = 1 s): ω is continuous, so no jump,
    though it changes by α h = 5e-6 rad/s over the instant h = 1e-9 s either side of the breakpoint
    (more than the 1e-6 rad/s of rounding: what ω̇ explains is allowed for)."""

    class SpinUp(Reference):
        ALPHA = 5000.0

        def __init__(self):
            super().__init__("spin_up", 1.0, INERTIA, breakpoints=(0.5,))

        def _evaluate(self, t):
            ramp = t <= 0.5
            rate = np.where(ramp, self.ALPHA * t, self.ALPHA * 0.5)
            angle = np.where(ramp, 0.5 * self.ALPHA * t**2, self.ALPHA * 0.125 + self.ALPHA * 0.5 * (t - 0.5))
            q = np.stack([np.cos(0.5 * angle), np.sin(0.5 * angle), 0 * t, 0 * t], axis=1)
            omega = np.stack([rate, 0 * t, 0 * t], axis=1)
            omega_dot = np.stack([np.where(ramp, self.ALPHA, 0.0), 0 * t, 0 * t], axis=1)
            return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))

    reference = SpinUp()
    t = np.linspace(0.0, 1.0, 101)
    change = np.linalg.norm(reference.sample(0.5 + 1e-9).omega - reference.sample(0.5 - 1e-9).omega)
    assert change == pytest.approx(5e-6, rel=1e-3)  # the instant sees ω move by more than the rounding
    assert rate_jumps(t, reference.sample(t).omega, np.zeros(3), reference) == []


def test_an_undeclared_step_of_five_micro_radians_per_second_at_t_fails_the_ends_check():
    """At 0.5 rad/s, a 5e-6 rad/s step at T hidden in the last sample: over JUMP_TOLERANCE (absolute,
    not relative to the rate), an impulse the scoring would count, so the conformance check refuses it."""
    rate = np.array([0.3, 0.0, 0.4])  # 0.5 rad/s
    check_ends(ConstantRate(10.0, rate, np.zeros(3)))  # no step: passes
    with pytest.raises(ConformanceError, match="ω steps at t = T"):
        check_ends(ConstantRate(10.0, rate, 5e-6 * np.array([0.0, 1.0, 0.0])))
