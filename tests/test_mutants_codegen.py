"""Gaps the mutation check found in the codegen tables' breakpoints (scenarios.codegen.tables).

A reference whose rate steps at a declared breakpoint ``b``: the table holds the left limit one
double before ``b``, the right limit one double after it, and at ``b`` the side the reference
itself gives there (its own convention, either side). The references are written here with the
step known by construction (the oracle); the rate is constant on each side, so the table's Hermite
interpolation is exact there and any smearing of the step shows.
"""
import numpy as np
import pytest

from ocp import quat
from planners import Reference, ReferenceSample, inverse_dynamics_torque
from scenarios.codegen.tables import tabulate

INERTIA = np.diag([2.0, 2.5, 3.0])
BEFORE, AFTER = np.array([0.01, -0.02, 0.005]), np.array([0.0, 0.0, 0.0])


class StepAt(Reference):
    """``ω = BEFORE`` before ``b`` and ``AFTER`` after; at ``b`` the left side (``left``) or the right."""

    def __init__(self, duration, b, left):
        super().__init__("step_at", duration, INERTIA, breakpoints=(b,))
        self.b, self.left = b, left

    def _evaluate(self, t):
        first = t <= self.b if self.left else t < self.b
        angle = np.where(first[:, None], np.outer(t, BEFORE), np.outer(np.minimum(t, self.b), BEFORE))
        q = quat.from_rotation_vector(angle)  # turning at BEFORE, then at rest (AFTER = 0)
        omega = np.where(first[:, None], BEFORE, AFTER)
        omega_dot = np.zeros_like(omega)
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))


@pytest.mark.parametrize("left", [True, False])
def test_a_rate_step_is_kept_on_both_sides_and_the_breakpoint_holds_the_references_side(left):
    T, b = 60.0, 37.3  # b on no grid node of the 32-interval start
    reference = StepAt(T, b, left)
    table, error = tabulate(reference)
    assert error.met, error
    times = np.array([b - 1.0, np.nextafter(b, -np.inf), b, np.nextafter(b, np.inf), b + 1e-6, b + 1.0])
    expected = [BEFORE, BEFORE, BEFORE if left else AFTER, AFTER, AFTER, AFTER]
    got = table.evaluate(times)[:, 4:7]
    for t, value, want in zip(times, got, expected):
        np.testing.assert_allclose(value, want, rtol=0, atol=1e-15, err_msg=f"ω at {t!r} s")
    assert error.rate <= 1e-15


def test_a_stop_at_t_keeps_its_left_limit():
    # A declared step to rest at T itself (a co-state minimum-time stop, Vepa's acquisition): the
    # table held no node one double before T, so its last interval blended the turning rate into
    # rest, ran to the 4096-interval cap and missed its tolerances (rate error 7.7e-4 rad/s).
    T = 100.0
    reference = StepAt(T, T, left=False)  # at T the right side: at rest
    table, error = tabulate(reference)
    assert error.met, error
    times = np.array([T - 1.0, np.nextafter(T, -np.inf), T])
    np.testing.assert_allclose(table.evaluate(times)[:, 4:7], [BEFORE, BEFORE, AFTER], rtol=0, atol=1e-15)
    assert table.times.size < 100  # no refinement forced by a smeared step


def test_the_coast_after_t_starts_with_the_coasts_own_torque():
    """A reference ending while it turns, torque non-zero at T (a constant ω̇ about a principal
    axis: τ = I ω̇): after T the reference coasts torque-free (τ = 0, ω constant about the principal
    axis), so just after T the table's torque is 0, and at T itself the manoeuvre's."""

    class SpinningUp(Reference):
        ALPHA = 1e-3

        def __init__(self):
            super().__init__("spinning_up", 20.0, INERTIA)

        def _evaluate(self, t):
            axis = np.array([0.0, 0.0, 1.0])
            q = quat.from_axis_angle(axis, 0.5 * self.ALPHA * t**2)
            omega = np.outer(self.ALPHA * t, axis)
            omega_dot = np.tile(self.ALPHA * axis, (t.size, 1))
            return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))

    reference = SpinningUp()
    table, error = tabulate(reference, end=30.0)
    assert error.met, error
    rows = table.evaluate(np.array([20.0, 20.0 + 1e-6, 25.0]))
    np.testing.assert_allclose(rows[0, 10:13], [0.0, 0.0, 3.0 * 1e-3], rtol=1e-12, atol=0)  # I_z α at T
    np.testing.assert_allclose(rows[1:, 10:13], 0.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rows[1:, 4:7], [[0.0, 0.0, 0.02]] * 2, rtol=0, atol=1e-12)  # the coast: α T
