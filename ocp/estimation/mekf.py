"""The multiplicative extended Kalman filter (MEKF): gyro propagation, star tracker updates.

Markley & Crassidis, *Fundamentals of Spacecraft Attitude Determination and Control* (2014),
sec. 6.2.4 (and Crassidis & Junkins, *Optimal Estimation of Dynamic Systems*, table 7.1), in this
project's conventions: the quaternion ``q̂`` is scalar first and rotates body vectors to inertial,
and the error state ``[δθ, δb]`` is a body-frame rotation vector with ``q = q̂ ⊗ exp(δθ/2)`` and
the gyro bias error ``δb = b − b̂`` [rad/s]. With ``ω̂ = ω̃ − b̂`` held over ``Δt``:

* propagation: ``q̂ ← q̂ ⊗ exp(ω̂ Δt / 2)``, ``P ← Φ P Φᵀ + Q`` with the closed-form ``Φ`` of
  ``F = [[−[ω̂×], −I], [0, 0]]`` and Farrenkopf's discrete ``Q`` (``σ_v`` the ARW, ``σ_u`` the RRW);
* update by a star tracker quaternion ``q̃ = q ⊗ exp(v/2)``, ``v ~ N(0, R)``: residual
  ``z = 2 vec(q̂⁻¹ ⊗ q̃)`` (the sign with a non-negative scalar part), ``H = [I, 0]``, the
  covariance update ``P − K H P`` (by blocks, symmetrised), reset ``q̂ ← normalise(q̂ ⊗ [1, δθ/2])``, ``b̂ ← b̂ + δb``.

Each step exists twice, in NumPy (:func:`propagate`, :func:`update`: the Python loop) and in CasADi
(:func:`propagate_symbolic`, :func:`update_symbolic`: the closed loop as one function), operation
for operation, so that both loops agree to rounding.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
SMALL_ANGLE = 1e-3
"""Below this rotation per sample [rad] the transition matrix uses its Taylor series."""
_UPPER = np.triu_indices(6)
COVARIANCE_SIZE = 21
"""Numbers of the covariance's upper triangle (row by row)."""


@dataclass(frozen=True)
class Mekf:
    """Settings of the MEKF in the loop.

    Parameters
    ----------
    attitude_sigma : float
        Initial attitude standard deviation per axis [rad]: the filter starts this far off (a
        draw from its own covariance) with this covariance.
    bias_sigma : float
        Initial gyro bias standard deviation per axis [rad/s] (the estimate starts at zero).
    """

    attitude_sigma: float
    bias_sigma: float

    def __post_init__(self) -> None:
        for name in ("attitude_sigma", "bias_sigma"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value) or not value > 0:
                raise ValueError(f"{name} must be a finite positive standard deviation, got {value!r}")

    @property
    def initial_covariance(self) -> Array:
        """(6, 6) initial covariance of ``[δθ (rad), δb (rad/s)]``."""
        return np.diag([self.attitude_sigma ** 2] * 3 + [self.bias_sigma ** 2] * 3)


def pack(P: Array) -> Array:
    """The upper triangle of a 6×6 covariance, row by row (21 numbers).

    Parameters
    ----------
    P : (6, 6) ndarray
        Symmetric covariance.

    Returns
    -------
    (21,) ndarray
    """
    return np.asarray(P, dtype=float)[_UPPER]


def unpack(values: Any) -> Any:
    """The symmetric 6×6 covariance of its packed upper triangle (NumPy or CasADi).

    Parameters
    ----------
    values : (21,) ndarray or casadi.SX
        :func:`pack`'s layout.

    Returns
    -------
    (6, 6) ndarray or casadi.SX
    """
    if isinstance(values, (ca.SX, ca.MX)):
        entries: list[list[Any]] = [[None] * 6 for _ in range(6)]
        for n, (i, j) in enumerate(zip(*_UPPER)):
            entries[i][j] = entries[j][i] = values[n]
        return ca.vertcat(*[ca.horzcat(*row) for row in entries])
    P = np.empty((6, 6))
    P[_UPPER] = values
    P.T[_UPPER] = values
    return P


def pack_symbolic(P: Any) -> Any:
    """:func:`pack` of a CasADi 6×6 (symmetrised: the mean of ``P[i, j]`` and ``P[j, i]``).

    Parameters
    ----------
    P : (6, 6) casadi.SX

    Returns
    -------
    (21, 1) casadi.SX
    """
    return ca.vertcat(*[P[i, j] if i == j else 0.5 * (P[i, j] + P[j, i]) for i, j in zip(*_UPPER)])


def _series(theta: Any, dt: Any, w: Any, small: Any, if_else: Any, sh: Any, ch: Any) -> tuple[Any, Any, Any]:
    """``sin θ / w``, ``(1 − cos θ) / w²``, ``(θ − sin θ) / w³`` (θ = w Δt) from ``sh = sin(θ/2)``,
    ``ch = cos(θ/2)`` (two trigonometric calls per step, not four), their series below SMALL_ANGLE."""
    w_safe = if_else(small, 1.0, w)
    th2 = theta * theta
    sin_theta = 2.0 * sh * ch
    a = if_else(small, dt * (1.0 - th2 / 6.0), sin_theta / w_safe)
    b = if_else(small, dt * dt * (0.5 - th2 / 24.0), 2.0 * sh * sh / (w_safe * w_safe))
    c = if_else(small, dt * dt * dt * (1.0 / 6.0 - th2 / 120.0), (theta - sin_theta) / (w_safe * w_safe * w_safe))
    return a, b, c


def _propagated(P: Any, phi11: Any, phi12: Any, dt: Any, arw: float, rrw: float, mm: Any, block: Any,
                 eye: Any) -> Any:
    """``Φ P Φᵀ + Q`` by blocks (``Φ = [[Φ11, Φ12], [0, I]]``, ``P = [[A, B], [Bᵀ, C]]``), the same
    operations for NumPy and CasADi (``mm`` the matrix product, ``block`` the block matrix)."""
    A, B, C = P[0:3, 0:3], P[0:3, 3:6], P[3:6, 3:6]
    M = mm(phi11, A) + mm(phi12, B.T)
    N = mm(phi11, B) + mm(phi12, C)
    top = mm(M, phi11.T) + mm(N, phi12.T)
    qa = (arw ** 2) * dt + (rrw ** 2) * dt * dt * dt / 3.0  # Farrenkopf's discrete Q
    qc = -(rrw ** 2) * dt * dt / 2.0
    qb = (rrw ** 2) * dt
    top = 0.5 * (top + top.T) + qa * eye
    N = N + qc * eye
    return block([[top, N], [N.T, C + qb * eye]])


def _updated(P: Any, R: Any, z: Any, mm: Any, block: Any) -> tuple[Any, Any]:
    """The star tracker update by blocks (``H = [I, 0]``): the correction ``δx = K z`` and
    ``P − K H P`` (``K = P Hᵀ S⁻¹``, ``S = A + R``), the same operations for NumPy and CasADi."""
    A, B, C = P[0:3, 0:3], P[0:3, 3:6], P[3:6, 3:6]
    S_inv = _inverse3(A + R, block)
    K1, K2 = mm(A, S_inv), mm(B.T, S_inv)
    top, right, bottom = A - mm(K1, A), B - mm(K1, B), C - mm(K2, B)
    top, bottom = 0.5 * (top + top.T), 0.5 * (bottom + bottom.T)
    return (mm(K1, z), mm(K2, z)), block([[top, right], [right.T, bottom]])


def propagate(q: Array, P: Array, omega: Array, dt: float, arw: float, rrw: float) -> tuple[Array, Array]:
    """One propagation of the MEKF over ``dt`` with the bias-corrected rate ``omega`` (NumPy).

    Parameters
    ----------
    q : (4,) ndarray
        Attitude estimate, scalar first, body to inertial.
    P : (6, 6) ndarray
        Covariance of ``[δθ (rad), δb (rad/s)]``.
    omega : (3,) ndarray
        ``ω̃ − b̂`` [rad/s], body axes, held over the step.
    dt : float
        Step [s].
    arw, rrw : float
        Gyro angle random walk [rad/s^(1/2)] and rate random walk [rad/s^(3/2)].

    Returns
    -------
    q : (4,) ndarray
        Propagated estimate (unit).
    P : (6, 6) ndarray
        Propagated covariance.
    """
    w = math.sqrt(omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2])
    theta = w * dt
    small = theta < SMALL_ANGLE
    half = 0.5 * theta
    sh, ch = math.sin(half), math.cos(half)
    a, b, c = _series(theta, dt, w, small, lambda s, x, y: x if s else y, sh, ch)
    s = 0.5 * dt * (1.0 - theta * theta / 24.0) if small else sh / w
    p0, p1, p2, p3 = ch, s * omega[0], s * omega[1], s * omega[2]
    q0, q1, q2, q3 = q
    q_next = np.array([q0 * p0 - q1 * p1 - q2 * p2 - q3 * p3,
                       q0 * p1 + p0 * q1 + q2 * p3 - q3 * p2,
                       q0 * p2 + p0 * q2 + q3 * p1 - q1 * p3,
                       q0 * p3 + p0 * q3 + q1 * p2 - q2 * p1])
    q_next = q_next / math.sqrt(float(q_next @ q_next))
    wx = np.array([[0.0, -omega[2], omega[1]], [omega[2], 0.0, -omega[0]], [-omega[1], omega[0], 0.0]])
    wx2 = wx @ wx
    eye = np.eye(3)
    return q_next, _propagated(P, eye - wx * a + wx2 * b, -eye * dt + wx * b - wx2 * c, dt, arw, rrw, np.matmul,
                               np.block, eye)


def update(q: Array, bias: Array, P: Array, measured: Array, R: Array) -> tuple[Array, Array, Array]:
    """One star tracker update of the MEKF (NumPy).

    Parameters
    ----------
    q : (4,) ndarray
        Attitude estimate, scalar first, body to inertial.
    bias : (3,) ndarray
        Gyro bias estimate [rad/s].
    P : (6, 6) ndarray
        Covariance of ``[δθ (rad), δb (rad/s)]``.
    measured : (4,) ndarray
        The star tracker's attitude ``q ⊗ exp(v/2)``.
    R : (3, 3) ndarray
        Covariance of ``v`` [rad²], body axes.

    Returns
    -------
    q : (4,) ndarray
        Updated, reset estimate (unit).
    bias : (3,) ndarray
        Updated bias estimate [rad/s].
    P : (6, 6) ndarray
        Updated covariance ``P − K H P``.
    """
    q0, q1, q2, q3 = q
    m0, m1, m2, m3 = measured
    # q̂⁻¹ ⊗ q̃
    d0 = q0 * m0 + q1 * m1 + q2 * m2 + q3 * m3
    d = np.array([q0 * m1 - m0 * q1 - q2 * m3 + q3 * m2,
                  q0 * m2 - m0 * q2 - q3 * m1 + q1 * m3,
                  q0 * m3 - m0 * q3 - q1 * m2 + q2 * m1])
    z = (2.0 if d0 >= 0 else -2.0) * d
    (d_theta, d_bias), P_next = _updated(P, R, z, np.matmul, np.block)
    e = 0.5 * d_theta
    q_next = np.array([q0 - q1 * e[0] - q2 * e[1] - q3 * e[2],
                       q1 + q0 * e[0] + q2 * e[2] - q3 * e[1],
                       q2 + q0 * e[1] + q3 * e[0] - q1 * e[2],
                       q3 + q0 * e[2] + q1 * e[1] - q2 * e[0]])
    q_next = q_next / math.sqrt(float(q_next @ q_next))
    return q_next, bias + d_bias, P_next


def _inverse3(S: Any, build: Any) -> Any:
    """Inverse of a 3×3 matrix by its adjugate (the same operations for NumPy and CasADi)."""
    a, b, c = S[0, 0], S[0, 1], S[0, 2]
    d, e, f = S[1, 0], S[1, 1], S[1, 2]
    g, h, i = S[2, 0], S[2, 1], S[2, 2]
    A, B, C = e * i - f * h, -(d * i - f * g), d * h - e * g
    det = a * A + b * B + c * C
    rows = [[A, -(b * i - c * h), b * f - c * e],
            [B, a * i - c * g, -(a * f - c * d)],
            [C, -(a * h - b * g), a * e - b * d]]
    if build is np.block:
        return np.array(rows) / det
    return ca.vertcat(*[ca.horzcat(*row) for row in rows]) / det


def propagate_symbolic(q: Any, P: Any, omega: Any, dt: Any, arw: float, rrw: float) -> tuple[Any, Any]:
    """:func:`propagate` in CasADi (same operations).

    Parameters
    ----------
    q : (4, 1) casadi.SX
        Attitude estimate, scalar first, body to inertial.
    P : (6, 6) casadi.SX
        Covariance of ``[δθ (rad), δb (rad/s)]``.
    omega : (3, 1) casadi.SX
        ``ω̃ − b̂`` [rad/s], body axes.
    dt : casadi.SX
        Step [s].
    arw, rrw : float
        Gyro angle random walk [rad/s^(1/2)] and rate random walk [rad/s^(3/2)].

    Returns
    -------
    q : (4, 1) casadi.SX
        Propagated estimate.
    P : (6, 6) casadi.SX
        Propagated covariance.
    """
    w = ca.sqrt(omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2])
    theta = w * dt
    small = theta < SMALL_ANGLE
    half = 0.5 * theta
    sh, ch = ca.sin(half), ca.cos(half)
    a, b, c = _series(theta, dt, w, small, ca.if_else, sh, ch)
    s = ca.if_else(small, 0.5 * dt * (1.0 - theta * theta / 24.0), sh / ca.if_else(small, 1.0, w))
    p0, p1, p2, p3 = ch, s * omega[0], s * omega[1], s * omega[2]
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    q_next = ca.vertcat(q0 * p0 - q1 * p1 - q2 * p2 - q3 * p3,
                        q0 * p1 + p0 * q1 + q2 * p3 - q3 * p2,
                        q0 * p2 + p0 * q2 + q3 * p1 - q1 * p3,
                        q0 * p3 + p0 * q3 + q1 * p2 - q2 * p1)
    q_next = q_next / ca.sqrt(ca.dot(q_next, q_next))
    wx = ca.skew(omega)
    wx2 = ca.mtimes(wx, wx)
    eye = ca.SX.eye(3)
    return q_next, _propagated(P, eye - wx * a + wx2 * b, -eye * dt + wx * b - wx2 * c, dt, arw, rrw, ca.mtimes,
                               ca.blockcat, eye)


def update_symbolic(q: Any, bias: Any, P: Any, measured: Any, R: Array) -> tuple[Any, Any, Any]:
    """:func:`update` in CasADi (same operations).

    Parameters
    ----------
    q : (4, 1) casadi.SX
        Attitude estimate, scalar first, body to inertial.
    bias : (3, 1) casadi.SX
        Gyro bias estimate [rad/s].
    P : (6, 6) casadi.SX
        Covariance of ``[δθ (rad), δb (rad/s)]``.
    measured : (4, 1) casadi.SX
        The star tracker's attitude.
    R : (3, 3) ndarray
        Covariance of its rotation vector [rad²], body axes.

    Returns
    -------
    q : (4, 1) casadi.SX
    bias : (3, 1) casadi.SX
    P : (6, 6) casadi.SX
    """
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    m0, m1, m2, m3 = measured[0], measured[1], measured[2], measured[3]
    d0 = q0 * m0 + q1 * m1 + q2 * m2 + q3 * m3
    d = ca.vertcat(q0 * m1 - m0 * q1 - q2 * m3 + q3 * m2,
                   q0 * m2 - m0 * q2 - q3 * m1 + q1 * m3,
                   q0 * m3 - m0 * q3 - q1 * m2 + q2 * m1)
    z = ca.if_else(d0 >= 0, 2.0, -2.0) * d
    (d_theta, d_bias), P_next = _updated(P, ca.SX(R), z, ca.mtimes, ca.blockcat)
    e = 0.5 * d_theta
    q_next = ca.vertcat(q0 - q1 * e[0] - q2 * e[1] - q3 * e[2],
                        q1 + q0 * e[0] + q2 * e[2] - q3 * e[1],
                        q2 + q0 * e[1] + q3 * e[0] - q1 * e[2],
                        q3 + q0 * e[2] + q1 * e[1] - q2 * e[0])
    q_next = q_next / ca.sqrt(ca.dot(q_next, q_next))
    return q_next, bias + d_bias, P_next
