"""Torque-free motion integrated over many chunks (the coast of every reference after T) against
the invariants of Euler's equations, an integration written here with scipy, and the derivative
of its own rate by finite differences; the elliptic rates of a spin about a principal axis by hand."""
import numpy as np
from scipy.integrate import solve_ivp

from ocp import quat
from planners.torque_free import TorqueFreeMotion, asymmetric_rates

INERTIA = np.array([[0.08, 0.004, -0.006], [0.004, 0.05, 0.002], [-0.006, 0.002, 0.11]])
Q0 = quat.normalize(np.array([0.6, -0.3, 0.2, 0.7]))
OMEGA0 = np.array([0.25, -0.15, 0.3])
START = 12.0


def test_the_coast_keeps_energy_and_inertial_momentum_over_many_chunks():
    motion = TorqueFreeMotion(Q0, OMEGA0, INERTIA, START)
    t = START + np.linspace(0.0, 12 * motion.chunk, 97)  # twelve chunks, times inside each
    q, omega, _ = motion(t)
    energy = 0.5 * np.einsum("ni,ij,nj->n", omega, INERTIA, omega)
    momentum = np.array([quat.rotate(qk, INERTIA @ wk) for qk, wk in zip(q, omega)])
    np.testing.assert_allclose(energy, 0.5 * OMEGA0 @ INERTIA @ OMEGA0, rtol=1e-10)
    np.testing.assert_allclose(momentum, np.tile(quat.rotate(Q0, INERTIA @ OMEGA0), (t.size, 1)), atol=1e-12)


def test_the_coast_is_eulers_motion_integrated_here():
    motion = TorqueFreeMotion(Q0, OMEGA0, INERTIA, START)
    t = START + np.linspace(0.0, 6 * motion.chunk, 25)
    inverse = np.linalg.inv(INERTIA)

    def rhs(_, y):
        q, w = y[:4], y[4:]
        qw = np.r_[0.0, w]
        dq = 0.5 * np.array([q[0] * qw[0] - q[1:] @ qw[1:], *(q[0] * qw[1:] + qw[0] * q[1:] + np.cross(q[1:], qw[1:]))])
        return np.r_[dq, inverse @ np.cross(INERTIA @ w, w)]

    truth = solve_ivp(rhs, (START, t[-1]), np.r_[Q0, OMEGA0], method="DOP853", rtol=1e-12, atol=1e-14, t_eval=t)
    q, omega, _ = motion(t)
    np.testing.assert_allclose(omega, truth.y[4:].T, atol=1e-9)
    assert np.max(quat.error_angle(q, truth.y[:4].T)) < 1e-9


def test_the_coasts_acceleration_is_the_derivative_of_its_rate():
    motion = TorqueFreeMotion(Q0, OMEGA0, INERTIA, START)
    t = START + np.array([0.3, 2.5, 1.5 * motion.chunk + 0.1])
    h = 1e-4
    _, _, omega_dot = motion(t)
    slope = (motion(t + h)[1] - motion(t - h)[1]) / (2 * h)
    np.testing.assert_allclose(omega_dot, slope, atol=1e-8)


def test_a_spin_about_a_principal_axis_is_an_equilibrium():
    """Euler's equations leave a spin about any principal axis unchanged (about the intermediate one
    too: it is unstable, not moving)."""
    moments = np.array([0.02, 0.05, 0.04])
    t = np.linspace(0.0, 300.0, 7)
    for axis in range(3):
        omega0 = np.zeros(3)
        omega0[axis] = -0.2
        np.testing.assert_array_equal(asymmetric_rates(t, omega0, moments), np.tile(omega0, (t.size, 1)))
