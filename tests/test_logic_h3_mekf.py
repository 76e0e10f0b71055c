"""The MEKF (``ocp.estimation.mekf``) where tests/test_mutants_mekf.py's tolerances do not reach:
the small-turn series, the settings' variances, and the CasADi update's hemisphere.

Oracles, none from the code under test:

* the Taylor series of ``sin θ / θ``, ``(1 − cos θ) / θ²`` and ``(θ − sin θ) / θ³`` summed to
  eight terms here (exact to rounding below a turn of 1e-3 rad), so the filter's two-term
  series must agree with them to its own truncation error (< 1e-14), not merely to 1e-9;
* the rotation of the estimate over a step, ``q̂ ⊗ exp(ω Δt / 2)`` with cos and sin of the half
  turn (written out here), and the covariance ``Φ P Φᵀ`` with ``Φ`` SciPy's matrix exponential of
  the error dynamics ``F = [[−[ω×], −I], [0, 0]]``, at turns just below the series' threshold;
* the definition of a variance (σ²) and of the settings' domain (documented: positive);
* the dense Kalman update ``K = P Hᵀ (H P Hᵀ + R)⁻¹``, ``z = 2 vec(q̂⁻¹ ⊗ q̃)`` with ``q̃`` taken in
  the hemisphere of ``q̂`` (``q̃`` and ``−q̃`` are one attitude), for the CasADi form.

Mutations caught (a scratch mutation run on mekf.py with tests/test_mutants_mekf.py and
tests/test_estimation_filter.py, which let them through): the series of ``sin θ/θ`` with θ²/2 for
θ²/6, the sign of the θ²/120 term of ``(θ − sin θ)/θ³``, the propagation's half-turn sine without
its series term, the bias variance not squared, a zero standard deviation accepted, the CasADi
update's hemisphere guard removed.
"""
from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.linalg import expm

from ocp.estimation.mekf import (
    SMALL_ANGLE,
    Mekf,
    _series,
    propagate,
    unpack,
    update_symbolic,
)

TURNS = [1e-4, 5e-4, 0.99 * SMALL_ANGLE]


def _exact_series(theta: float, start: int) -> float:
    """Σₖ (−1)ᵏ θ²ᵏ / (2k + start)!, eight terms."""
    return sum((-1) ** k * theta ** (2 * k) / math.factorial(2 * k + start) for k in range(8))


def _product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    p0, pv, q0, qv = p[0], p[1:], q[0], q[1:]
    return np.r_[p0 * q0 - pv @ qv, p0 * qv + q0 * pv + np.cross(pv, qv)]


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


@pytest.mark.parametrize("theta", TURNS)
def test_the_small_turn_series_are_the_functions_to_rounding(theta):
    dt = 0.4
    w = theta / dt
    a, b, c = _series(theta, dt, w, True, lambda s, x, y: x if s else y, math.sin(theta / 2), math.cos(theta / 2))
    np.testing.assert_allclose([a / dt, b / dt**2, c / dt**3],
                               [_exact_series(theta, 1), _exact_series(theta, 2), _exact_series(theta, 3)],
                               rtol=1e-14, atol=0)  # the two-term series: θ⁴/120 < 1e-14


@pytest.mark.parametrize("theta", TURNS)
def test_a_small_turn_propagates_attitude_and_covariance_exactly(theta):
    rng = np.random.default_rng(4)
    dt = 0.4
    omega = rng.normal(size=3)
    omega *= theta / (np.linalg.norm(omega) * dt)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    root = rng.normal(size=(6, 6)) * np.r_[[1e-2] * 3, [1e-3] * 3][:, None]
    P = root @ root.T
    q_next, P_next = propagate(q, P, omega, dt, 0.0, 0.0)
    half = 0.5 * theta
    turn = np.r_[math.cos(half), math.sin(half) * omega / np.linalg.norm(omega)]
    np.testing.assert_allclose(q_next, _product(q, turn), rtol=0, atol=2e-16)
    F = np.zeros((6, 6))
    F[0:3, 0:3], F[0:3, 3:6] = -_skew(omega), -np.eye(3)
    phi = expm(F * dt)
    np.testing.assert_allclose(P_next, phi @ P @ phi.T, rtol=0, atol=1e-14 * np.abs(P).max())


def test_the_initial_covariance_holds_the_variances():
    settings = Mekf(attitude_sigma=2e-3, bias_sigma=3e-5)
    np.testing.assert_allclose(settings.initial_covariance, np.diag([4e-6] * 3 + [9e-10] * 3), rtol=1e-15, atol=0)


@pytest.mark.parametrize("name", ["attitude_sigma", "bias_sigma"])
@pytest.mark.parametrize("value", [0.0, -1e-3])
def test_a_standard_deviation_that_is_not_positive_is_refused(name, value):
    """A zero variance would make the gain K = A (A + R)⁻¹ zero for that state: the filter would
    never correct it (the docs ask for a positive standard deviation)."""
    given = {"attitude_sigma": 1e-3, "bias_sigma": 1e-5, name: value}
    with pytest.raises(ValueError, match=name):
        Mekf(**given)


def test_the_casadi_update_does_not_see_the_measured_quaternions_sign():
    rng = np.random.default_rng(9)
    q_sym, b_sym, p_sym, m_sym = ca.SX.sym("q", 4), ca.SX.sym("b", 3), ca.SX.sym("p", 21), ca.SX.sym("m", 4)
    R = np.diag([4e-6, 9e-6, 2.5e-5])
    outputs = update_symbolic(q_sym, b_sym, unpack(p_sym), m_sym, R)
    step = ca.Function("update", [q_sym, b_sym, p_sym, m_sym], list(outputs))
    root = rng.normal(size=(6, 6)) * np.r_[[1e-2] * 3, [1e-4] * 3][:, None]
    P = root @ root.T + np.diag([1e-6] * 3 + [1e-10] * 3)
    q_hat = rng.normal(size=4)
    q_hat /= np.linalg.norm(q_hat)
    error = np.array([2e-3, -1e-3, 3e-3])
    measured = _product(q_hat, np.r_[math.cos(np.linalg.norm(error) / 2),
                                     math.sin(np.linalg.norm(error) / 2) * error / np.linalg.norm(error)])
    bias = np.array([1e-4, 0.0, -2e-4])
    H = np.hstack([np.eye(3), np.zeros((3, 3))])
    K = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
    z = 2 * _product(q_hat * np.array([1, -1, -1, -1]), measured)[1:]  # scalar part > 0: this hemisphere
    correction = K @ z
    for sign in (1.0, -1.0):
        q_new, b_new, P_new = (np.asarray(v).ravel() for v in step(q_hat, bias, P[np.triu_indices(6)], sign * measured))
        np.testing.assert_allclose(b_new, bias + correction[3:], rtol=1e-9, atol=1e-15)
        expected_q = _product(q_hat, np.r_[1.0, correction[:3] / 2])
        np.testing.assert_allclose(q_new, expected_q / np.linalg.norm(expected_q), rtol=0, atol=1e-14)
        np.testing.assert_allclose(P_new.reshape(6, 6), (np.eye(6) - K @ H) @ P, rtol=1e-9, atol=1e-9 * np.abs(P).max())
