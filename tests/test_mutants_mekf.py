"""The MEKF's propagation and update against oracles other than its own code: the transition matrix
against scipy's matrix exponential of the error-state dynamics (at small and large turns per
sample), Farrenkopf's discrete process noise against Van Loan's integral at rest, and the update
against a dense textbook Kalman update with a covariance whose attitude-bias block is not symmetric."""
import numpy as np
import pytest
from scipy.linalg import expm

from ocp import quat
from ocp.estimation.mekf import propagate, update


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def error_dynamics(omega):
    """F of δẋ = F δx + G w for [δθ, δb]: δθ̇ = −[ω×] δθ − δb − n_v, δḃ = n_u."""
    F = np.zeros((6, 6))
    F[0:3, 0:3] = -skew(omega)
    F[0:3, 3:6] = -np.eye(3)
    return F


def random_covariance(rng):
    """A covariance whose attitude-bias block B is far from symmetric (B ≠ Bᵀ)."""
    root = rng.normal(size=(6, 6)) * np.r_[[1e-2] * 3, [1e-4] * 3][:, None]
    P = root @ root.T + np.diag([1e-6] * 3 + [1e-10] * 3)
    assert np.linalg.norm(P[0:3, 3:6] - P[0:3, 3:6].T) > 0.1 * np.linalg.norm(P[0:3, 3:6])
    return P


@pytest.mark.parametrize("turn", [1e-4, 0.02, 0.5, 1.5], ids=["tiny", "small", "half_rad", "large"])
def test_the_transition_matrix_is_the_exponential_of_the_error_dynamics(turn):
    rng = np.random.default_rng(11)
    P = random_covariance(rng)
    dt = 0.7
    omega = rng.normal(size=3)
    omega *= turn / (np.linalg.norm(omega) * dt)  # |ω| Δt = turn [rad]
    q = quat.random_unit(rng)
    q_next, P_next = propagate(q, P, omega, dt, 0.0, 0.0)  # no process noise: Φ P Φᵀ alone
    phi = expm(error_dynamics(omega) * dt)
    np.testing.assert_allclose(P_next, phi @ P @ phi.T, rtol=1e-9, atol=1e-9 * np.abs(P).max())
    # the estimate turns by ω Δt in body axes
    assert quat.error_angle(q_next, quat.product(q, quat.from_rotation_vector(omega * dt))) < 1e-12


def test_farrenkopf_noise_is_van_loans_integral_at_rest():
    """At ω = 0 the discrete noise ∫ Φ(s) G Q_c Gᵀ Φ(s)ᵀ ds is exact (Van Loan's method)."""
    arw, rrw, dt = 3e-4, 2e-5, 2.5
    F = error_dynamics(np.zeros(3))
    G = np.diag([-1.0] * 3 + [1.0] * 3)
    Qc = np.diag([arw**2] * 3 + [rrw**2] * 3)
    A = np.zeros((12, 12))
    A[0:6, 0:6], A[0:6, 6:12], A[6:12, 6:12] = -F, G @ Qc @ G.T, F.T
    B = expm(A * dt)
    phi = B[6:12, 6:12].T
    Qd = phi @ B[0:6, 6:12]
    _, P_next = propagate(np.array([1.0, 0, 0, 0]), np.zeros((6, 6)), np.zeros(3), dt, arw, rrw)
    np.testing.assert_allclose(P_next, Qd, rtol=1e-10, atol=1e-22)


def test_the_update_is_the_dense_kalman_update():
    rng = np.random.default_rng(5)
    P = random_covariance(rng)
    R = np.diag([4e-6, 9e-6, 2.5e-5])
    q_hat = quat.random_unit(rng)
    error = np.array([2e-3, -1e-3, 3e-3])
    measured = quat.product(q_hat, quat.from_rotation_vector(error))
    q_new, bias, P_new = update(q_hat, np.array([1e-4, 0.0, -2e-4]), P, measured, R)
    H = np.hstack([np.eye(3), np.zeros((3, 3))])
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    z = 2 * quat.product(quat.conjugate(q_hat), measured)[1:]
    correction = K @ z
    np.testing.assert_allclose(P_new, (np.eye(6) - K @ H) @ P, rtol=1e-9, atol=1e-9 * np.abs(P).max())
    np.testing.assert_allclose(bias, np.array([1e-4, 0.0, -2e-4]) + correction[3:], rtol=1e-9, atol=1e-15)
    # the reset turns the estimate by the attitude correction (a rotation vector, to second order)
    turned = quat.to_rotation_vector(quat.product(quat.conjugate(q_hat), q_new))
    np.testing.assert_allclose(turned, correction[0:3], atol=1e-8)


def test_the_update_does_not_see_the_sign_of_the_measured_quaternion():
    """q̃ and −q̃ are one attitude: the update is the same."""
    rng = np.random.default_rng(8)
    P = random_covariance(rng)
    q_hat = quat.random_unit(rng)
    measured = quat.product(q_hat, quat.from_rotation_vector([1e-3, 2e-3, -1e-3]))
    plus = update(q_hat, np.zeros(3), P, measured, 1e-5 * np.eye(3))
    minus = update(q_hat, np.zeros(3), P, -measured, 1e-5 * np.eye(3))
    assert quat.error_angle(plus[0], minus[0]) < 1e-12
    np.testing.assert_allclose(plus[1], minus[1], atol=1e-15)
    np.testing.assert_allclose(plus[2], minus[2], rtol=1e-12)
