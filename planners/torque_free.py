"""Torque-free motion of a rigid body, ``I ω̇ = −ω × I ω``, ``q̇ = ½ q ⊗ [0, ω]``.

* :class:`TorqueFreeMotion`: numerical integration from any state. After ``T`` a
  :class:`~planners.base.Reference` continues as the torque-free motion of its final state (the
  contract of :mod:`planners.base`); this class integrates it.
* Closed forms in principal axes, used by :mod:`planners.natural_motion`: :func:`symmetric_motion`
  for an axisymmetric body (nano-spacecraft paper eq. 17-37), :func:`asymmetric_rates` with Jacobi
  elliptic functions for any other (Landau & Lifshitz §37), :func:`euler_rhs` for both backends.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.dynamics.spin_closed_form import extremal_quaternion
from ocp.options import is_real, real_array
from planners.problem import MAX_BODY_RATE

Array = NDArray[np.float64]
REST_RATE = 1e-15
"""rad/s: a final rate at or below this is rounding residue; the torque-free coast is then rest."""
MAX_COAST_CHUNKS = 10**6
"""Chunks of integration (each about a quarter turn at the initial rate, 1 s to 1e4 s) a
:class:`TorqueFreeMotion` evaluates at most; a later time is refused (about 6 ms a chunk: a
million is 1.5 h of integration)."""


def _finite(name: str, value: ArrayLike, shape: tuple[int, ...]) -> Array:
    """``value`` as a finite float array of ``shape`` (:func:`~ocp.options.real_array`), or a
    ``ValueError`` naming ``name``."""
    try:
        array = real_array(value)
    except ValueError as reason:
        raise ValueError(f"TorqueFreeMotion: {name} must be real numbers, got {value!r:.120}: {reason}") from None
    if array.shape != shape or not np.all(np.isfinite(array)):
        raise ValueError(f"TorqueFreeMotion: {name} must be finite numbers of shape {shape}, got shape {array.shape}: "
                         f"{array.tolist()!r:.120}")
    return array


class TorqueFreeMotion:
    """Torque-free motion of a rigid body from ``(q_start, omega_start)`` at time ``start``.

    Integrated with DOP853 (rtol 1e-12, atol 1e-14) in chunks of fixed length, so that a value does
    not depend on which times were asked for before. A state at rest (rate at most
    :data:`REST_RATE`, rounding residue) holds its attitude.

    Parameters
    ----------
    q_start : (4,) array_like
        Attitude quaternion at ``start``, scalar first, body to inertial (normalised here).
    omega_start : (3,) array_like
        Body rate at ``start`` [rad/s], body axes, each entry within
        ±:data:`~planners.problem.MAX_BODY_RATE`.
    inertia : (3, 3) array_like
        Body inertia [kg m^2], body axes.
    start : float
        Time of the initial state [s].

    Raises
    ------
    ValueError
        For values that are not finite real numbers of the shapes above, a zero quaternion or an
        inertia that is not positive definite.
    """

    def __init__(self, q_start: ArrayLike, omega_start: ArrayLike, inertia: ArrayLike, start: float) -> None:
        self.q_start = quat.normalize(_finite("q_start", q_start, (4,)))
        self.omega_start = _finite("omega_start", omega_start, (3,))
        self.inertia = _finite("inertia", inertia, (3, 3))
        moments = np.linalg.eigvalsh((self.inertia + self.inertia.T) / 2)
        if not moments[0] > 0:
            raise ValueError(f"TorqueFreeMotion: inertia must be positive definite [kg m^2], got principal moments "
                             f"{moments.tolist()}")
        self.inverse = np.linalg.inv(self.inertia)
        if not (is_real(start) and np.isfinite(start)):
            raise ValueError(f"TorqueFreeMotion: start must be a finite time [s], got {start!r:.60} "
                             f"({type(start).__name__})")
        self.start = float(start)
        if np.any(np.abs(self.omega_start) > MAX_BODY_RATE):
            raise ValueError(f"TorqueFreeMotion: omega_start must be within ±{MAX_BODY_RATE:g} rad/s (MAX_BODY_RATE) "
                             f"per axis, got {self.omega_start.tolist()}")
        rate = float(np.linalg.norm(self.omega_start))
        # A rest-to-rest profile ends at rest up to rounding (~1e-17 rad/s: a degree in 10⁸
        # years); at or below REST_RATE the coast is rest, and scipy.integrate (0.5 s) is not imported.
        self.at_rest = rate <= REST_RATE
        # About a quarter turn per chunk at the initial rate (the rate norm is bounded by energy).
        self.chunk = 1.0 if self.at_rest else float(np.clip(1.5 / rate, 1.0, 1e4))
        self._chunks: list[Any] = []
        self._ends = [np.concatenate([self.q_start, self.omega_start])]

    def _rhs(self, _t: float, y: Array) -> Array:
        q, w = y[:4], y[4:]
        return np.concatenate([quat.kinematics(q, w), -self.inverse @ np.cross(w, self.inertia @ w)])

    def _solution(self, index: int) -> Any:
        while len(self._chunks) <= index:
            k = len(self._chunks)
            from scipy.integrate import (
                solve_ivp,  # lazily: 0.5 s to import, needed only after T
            )

            solution = solve_ivp(self._rhs, (0.0, self.chunk), self._ends[k], method="DOP853", rtol=1e-12,
                                 atol=1e-14, dense_output=True)
            self._chunks.append(solution.sol)
            end = solution.y[:, -1].copy()
            end[:4] /= np.linalg.norm(end[:4])
            self._ends.append(end)
        return self._chunks[index]

    def __call__(self, t: ArrayLike) -> tuple[Array, Array, Array]:
        """The motion at times ``t``.

        Parameters
        ----------
        t : (N,) array_like
            Times [s], at or after ``start`` (earlier times give the state at ``start``), finite and
            within :data:`MAX_COAST_CHUNKS` chunks of it.

        Returns
        -------
        q : (N, 4) ndarray
            Attitude quaternions, scalar first, body to inertial.
        omega : (N, 3) ndarray
            Body rates [rad/s], body axes.
        omega_dot : (N, 3) ndarray
            Body accelerations ``−I⁻¹ (ω × I ω)`` [rad/s^2], body axes.
        """
        t = np.asarray(t, dtype=float)
        if self.at_rest:
            return np.tile(self.q_start, (t.size, 1)), np.zeros((t.size, 3)), np.zeros((t.size, 3))
        if not np.all(np.isfinite(t)):
            raise ValueError(f"TorqueFreeMotion: times must be finite [s], got {t.ravel()[~np.isfinite(t.ravel())][:3].tolist()}")
        elapsed = np.maximum(t - self.start, 0.0)
        span = MAX_COAST_CHUNKS * self.chunk
        if np.any(elapsed >= span):  # was extrapolated from the last chunk's polynomial: no motion at all
            raise ValueError(f"TorqueFreeMotion: t = {float(np.max(t)):.6g} s is {float(np.max(elapsed)):.6g} s after the "
                             f"start of the coast, beyond the {span:.6g} s it integrates (MAX_COAST_CHUNKS = "
                             f"{MAX_COAST_CHUNKS:g} steps of {self.chunk:.4g} s)")
        index = (elapsed / self.chunk).astype(int)
        y = np.empty((t.size, 7))
        for k in np.unique(index):
            mask = index == k
            y[mask] = self._solution(int(k))(elapsed[mask] - k * self.chunk).T
        q = quat.normalize(y[:, :4])
        omega = y[:, 4:]
        omega_dot = -np.cross(omega, omega @ self.inertia.T) @ self.inverse.T
        return q, omega, omega_dot


def symmetry_axis(moments: Array, rtol: float = 1e-9) -> int | None:
    """The symmetry axis of a body, if it has one.

    Parameters
    ----------
    moments : (3,) ndarray
        Principal moments of inertia [kg m^2].
    rtol : float, optional
        Two moments are equal when they differ by at most ``rtol`` times the largest.

    Returns
    -------
    int or None
        Index of the distinct moment of an axisymmetric body (0 for a sphere), else ``None``.
    """
    for axis in range(3):
        others = np.delete(moments, axis)
        if abs(others[0] - others[1]) <= rtol * np.max(moments):
            return axis
    return None


def _cyclic(axis: int) -> Array:
    """Cyclic axis order putting ``axis`` first (a proper rotation of the axes)."""
    return np.roll(np.arange(3), -axis)


def symmetric_motion(t: Any, omega0: Any, moments: Any, axis: int, math: Any = np) -> tuple[list[Any], list[Any]]:
    """Torque-free motion of an axisymmetric body in closed form (eq. 17-37).

    Parameters
    ----------
    t : (N,) ndarray or casadi.SX
        Times since the start of the arc [s].
    omega0 : (3,) sequence
        Body rate at t = 0 [rad/s], principal axes (numbers or CasADi scalars).
    moments : (3,) sequence
        Principal moments of inertia [kg m^2].
    axis : int
        Index of the symmetry axis (:func:`symmetry_axis`).
    math : module, optional
        ``numpy`` (default) or ``casadi``.

    Returns
    -------
    rates : list of 3
        Body rate components [rad/s], principal axes, each like ``t``.
    q_rel : list of 4
        Attitude relative to t = 0 (scalar first, body at t to body at 0), components like ``t``.
    """
    order = _cyclic(axis)
    w = [omega0[i] for i in order]
    spin, J_s, J = w[0], moments[axis], moments[order[1]]
    lam = spin * (J - J_s) / J  # eq. 17 prints (J1 − J)/J: a sign typo (its eq. 34 has J − J1)
    r = math.sqrt(w[1] ** 2 + w[2] ** 2)
    delta = math.arctan2(w[1], w[2]) if math is np else ca.atan2(w[1], w[2])
    q_rel = extremal_quaternion(t, spin, r, lam - spin, delta, math=math)
    theta = lam * t + delta
    permuted = [spin + 0 * t, r * math.sin(theta), r * math.cos(theta)]
    rates: list[Any] = [None] * 3
    vector: list[Any] = [None] * 3
    for k, i in enumerate(order):
        rates[i], vector[i] = permuted[k], q_rel[1 + k]
    return rates, [q_rel[0]] + vector


def asymmetric_rates(t: Array, omega0: Array, moments: Array) -> Array:
    """Torque-free rates of an asymmetric body with Jacobi elliptic functions (both polhode regimes).

    Parameters
    ----------
    t : float or (N,) ndarray
        Times since the rate was ``omega0`` [s].
    omega0 : (3,) array_like
        Body rate at t = 0 [rad/s], principal axes.
    moments : (3,) ndarray
        Distinct principal moments of inertia [kg m^2].

    Returns
    -------
    (3,) or (N, 3) ndarray
        Body rates [rad/s], principal axes.
    """
    omega0 = np.asarray(omega0, dtype=float)
    if np.count_nonzero(np.abs(omega0) > 1e-15 * np.max(np.abs(omega0), initial=0.0)) <= 1:
        # A spin about one principal axis is an equilibrium of Euler's equations; about the
        # intermediate axis it sits on the separatrix, where the elliptic phase below is infinite.
        return np.broadcast_to(omega0, np.shape(t) + (3,)).copy()
    order = np.argsort(moments)
    I, w0 = moments[order], omega0[order]
    h2, e2 = np.sum((I * w0) ** 2), np.sum(I * w0**2)
    a, b, c = (0, 1, 2) if h2 >= e2 * I[1] else (2, 1, 0)  # polhode about the major / minor axis
    Ia, Ib, Ic = I[a], I[b], I[c]
    amp_a = np.sqrt(max((e2 * Ic - h2) / (Ia * (Ic - Ia)), 0.0))
    amp_b = np.sqrt(max((e2 * Ic - h2) / (Ib * (Ic - Ib)), 0.0))
    amp_c = np.sqrt(max((h2 - e2 * Ia) / (Ic * (Ic - Ia)), 0.0))
    rate = np.sqrt((Ic - Ib) * (h2 - e2 * Ia) / (Ia * Ib * Ic))
    m = min((Ib - Ia) * (e2 * Ic - h2) / ((Ic - Ib) * (h2 - e2 * Ia)), 1.0)
    sign_c = 1.0 if w0[c] >= 0 else -1.0
    parity = np.linalg.det(np.eye(3)[order])  # an odd sort reverses the Euler equations
    from scipy.special import (  # lazily: scipy.special is slow to import
        ellipj,
        ellipkinc,
    )
    phase = ellipkinc(np.arctan2(w0[b] / amp_b if amp_b > 0 else 0.0, w0[a] / amp_a if amp_a > 0 else 1.0), m)
    sn, cn, dn, _ = ellipj(sign_c * parity * rate * np.asarray(t, dtype=float) + phase, m)
    sorted_rates = np.empty(np.shape(t) + (3,))
    sorted_rates[..., a], sorted_rates[..., b], sorted_rates[..., c] = amp_a * cn, amp_b * sn, sign_c * amp_c * dn
    rates = np.empty_like(sorted_rates)
    rates[..., order] = sorted_rates
    return rates


def euler_rhs(moments: Any) -> Callable[[Any], list[Any]]:
    """Torque-free Euler equations ``ω̇ = I⁻¹ (I ω × ω)`` in principal axes.

    Parameters
    ----------
    moments : (3,) sequence
        Principal moments of inertia [kg m^2] (numbers or CasADi scalars).

    Returns
    -------
    callable
        ``f(ω) -> [ω̇1, ω̇2, ω̇3]`` [rad/s^2] for rates ``ω`` [rad/s] (NumPy arrays or CasADi).
    """
    I1, I2, I3 = moments
    return lambda w: [(I2 - I3) / I1 * w[1] * w[2], (I3 - I1) / I2 * w[2] * w[0], (I1 - I2) / I3 * w[0] * w[1]]
