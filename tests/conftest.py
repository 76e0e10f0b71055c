"""Shared test helpers."""
import numpy as np
import pytest

from ocp import Command, quat


class WheelPD:
    """Minimal quaternion PD law on three body-axis wheels, written here independently of
    ``controllers`` so that the foundation tests do not depend on the code they support."""

    def __init__(self, q_target, kp=1.0, kd=2.0):
        self.q_target = np.asarray(q_target, dtype=float)
        self.kp, self.kd = kp, kd

    def reset(self, spacecraft, sample_time, target=None):
        self.inertia = spacecraft.inertia

    def __call__(self, t, measurement, reference):
        q_e = quat.error(measurement.q, self.q_target)
        u = self.inertia @ (-self.kp * q_e[1:] - self.kd * measurement.omega)
        return Command(wheel_torque=-u)


def finite_difference_torque(reference, inertia, t, h=1e-3):
    """Inverse dynamics from the attitude alone: ω = 2 vec(q* ⊗ q̇), ω̇ by central differences."""
    def omega(times):
        q_dot = (reference.q(times + h) - reference.q(times - h)) / (2 * h)
        return 2 * quat.product(quat.conjugate(reference.q(times)), q_dot)[:, 1:]

    w = omega(t)
    w_dot = (omega(t + h) - omega(t - h)) / (2 * h)
    return w, w_dot @ inertia.T + np.cross(w, w @ inertia.T)


@pytest.fixture
def rng():
    return np.random.default_rng(20261123)
