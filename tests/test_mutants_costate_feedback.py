"""Co-state feedback on a hand-made co-state reference: its fit window by hand (the paper's
``t − nΔt``), the double cover (q and −q are one attitude) and no torque from T on."""
import numpy as np

from controllers import CONTROLLERS
from ocp import Measurement, Spacecraft, Torquers, quat

W = np.array([0.01, -0.02, 0.015])
Q0 = quat.normalize(np.array([0.8, 0.1, -0.3, 0.5]))
P_TRUE = np.diag([0.0, 0.0, 0.0, 0.0, 2.0, 3.0, 4.0])  # λ = P x: only a rate co-state


class LinearCostates:
    """A constant-rate spin whose co-state is ``P x`` and whose control is ``−λ_ω``."""

    duration = 10.0

    def state_and_costate(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        q = np.array([quat.product(Q0, quat.from_rotation_vector(W * tk)) for tk in t])
        x = np.hstack([q, np.tile(W, (t.size, 1))])
        return x, x @ P_TRUE.T

    def feedback_torque(self, lam_omega, lam_omega_reference):
        return -np.asarray(lam_omega)


def controller(**options):
    law = CONTROLLERS["costate_feedback"](options)
    law.reset(Spacecraft([1.0, 1.2, 0.9], torquers=Torquers(10.0)), 0.1)
    return law


def measurement(t, q, omega):
    return Measurement(t=t, q=np.asarray(q, dtype=float), omega=np.asarray(omega, dtype=float),
                       wheel_momentum=np.zeros(0))


def test_the_window_reaches_back_from_the_sample():
    law = controller(window_samples=5, window_step=0.5)
    np.testing.assert_allclose(law.window(4.0, 10.0), [2.0, 2.5, 3.0, 3.5, 4.0])
    np.testing.assert_allclose(law.window(1.0, 10.0), [0.0, 0.5, 1.0, 1.5, 2.0])  # kept inside [0, T]


def test_the_control_is_blind_to_the_sign_of_the_measured_quaternion():
    """q and −q are one attitude: the same command (the fit reads the states' quaternions, so the
    fitted P couples them to the rate co-state)."""
    reference = LinearCostates()
    t = 3.0
    x, _ = reference.state_and_costate(t)
    omega = W + np.array([0.01, 0.02, -0.01])
    q = quat.product(x[0, :4], quat.from_rotation_vector([0.01, 0.0, 0.0]))
    plus = controller()(t, measurement(t, q, omega), reference).torque
    minus = controller()(t, measurement(t, -q, omega), reference).torque
    assert np.linalg.norm(plus) > 1e-3
    np.testing.assert_allclose(minus, plus, rtol=1e-9, atol=1e-15)


def test_no_torque_from_the_end_of_the_reference():
    law, reference = controller(), LinearCostates()
    x, _ = reference.state_and_costate(reference.duration)
    command = law(reference.duration, measurement(reference.duration, x[0, :4], W + 0.01), reference)
    np.testing.assert_array_equal(command.torque, np.zeros(3))
