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


@pytest.fixture
def rng():
    return np.random.default_rng(20261123)
