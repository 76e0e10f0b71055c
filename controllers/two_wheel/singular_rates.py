"""Desired-rate math of the two-wheel laws of Horri & Palmer (paper 004): the singular desired
rates (eq. 7-8) and their time derivative, the rate-tracking torque (eq. 14/24) and the min-norm
projection (eq. 25, sign corrected), on floats and on CasADi expressions.

Desired rates (eq. 7, 8; ``q = [q0, q1, q2, q3]`` the error quaternion in the control frame, the
paper's scalar-last ``[q1, q2, q3, q4]`` with ``q4 = q0``, no sign change)::

    ωd1 = −k q1 + g sat(q2 q3 / D, a1),   ωd2 = −k q2 − g sat(q1 q3 / D, a2),   D = q1² + q2² + ε_D

``a = None`` is the unsaturated eq. 7; ``ε_D`` the regularisation the paper used in orbit (end of
section IV.B). With ``ε_D = 0`` and no saturation, ``ω = ωd`` gives ``q̇3 = −g/2 q3`` (eq. 9) and
``q̇0 = k/2 (q1² + q2²)`` (eq. 10), both checked against integration.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

import casadi as ca

Scalar = TypeVar("Scalar", float, ca.SX)
"""A number or a CasADi expression: the laws' arithmetic runs on both (Python loop, symbolic form)."""


@dataclass(frozen=True)
class SingularGains:
    """Gains of one desired-rate law (eq. 7/8, or eq. 27 for the Lyapunov function's rates).

    Parameters
    ----------
    k : float
        Gain on the actuated components ``q1``, ``q2`` of the error quaternion [rad/s].
    g : float
        Gain of the singular term ``q2 q3 / D``, ``q1 q3 / D`` [rad/s]; the laws need ``g > 2 k``.
    a1, a2 : float or None
        Saturation limits of the singular ratios ``q2 q3 / D`` and ``q1 q3 / D`` (dimensionless,
        eq. 8); ``None``: unsaturated (eq. 7).
    epsilon_d : float, optional
        Regularisation ``ε_D`` added to ``D = q1² + q2²`` (dimensionless); 0: the paper's eq. 7/8.
    """

    k: float
    g: float
    a1: float | None
    a2: float | None
    epsilon_d: float = 0.0


def _sat(value: float, limit: float | None) -> tuple[float, float]:
    """``(sat(value, limit), d sat / d value)``."""
    if limit is None or -limit < value < limit:
        return value, 1.0
    return (limit if value > 0 else -limit), 0.0


def _ratio(numerator: float, denominator: float) -> float:
    """``numerator / denominator`` with the singular point ``0/0`` taken as 0 (the limit along the
    closed loop, where the numerator vanishes faster) and ``x/0`` as ±inf (saturated, or a
    non-finite command that the simulator reports)."""
    if denominator > 0.0:
        return numerator / denominator
    if numerator == 0.0:
        return 0.0
    return math.copysign(math.inf, numerator)


def desired_rates(q0: float, q1: float, q2: float, q3: float, w1: float, w2: float, w3: float,
                  gains: SingularGains) -> tuple[float, float, float, float]:
    """Desired rates of eq. 7/8 and their time derivative along ``q̇ = ½ q ⊗ [0, ω]``.

    Parameters
    ----------
    q0, q1, q2, q3 : float
        Error quaternion in the control frame (scalar first, dimensionless).
    w1, w2, w3 : float
        Body rate in the control frame [rad/s]; it enters the derivative only.
    gains : SingularGains
        The law's gains.

    Returns
    -------
    tuple of 4 float
        ``(ωd1, ωd2, ω̇d1, ω̇d2)`` [rad/s, rad/s²]; the derivative is zero where a ratio saturates.
    """
    k, g = gains.k, gains.g
    dq1 = 0.5 * (q0 * w1 - q3 * w2 + q2 * w3)
    dq2 = 0.5 * (q0 * w2 - q1 * w3 + q3 * w1)
    dq3 = 0.5 * (q0 * w3 - q2 * w1 + q1 * w2)
    d = q1 * q1 + q2 * q2 + gains.epsilon_d
    dd = 2.0 * (q1 * dq1 + q2 * dq2)
    r1, slope1 = _sat(_ratio(q2 * q3, d), gains.a1)
    r2, slope2 = _sat(_ratio(q1 * q3, d), gains.a2)
    wd1 = -k * q1 + g * r1
    wd2 = -k * q2 - g * r2
    if d > 0.0:
        dr1 = ((dq2 * q3 + q2 * dq3) - q2 * q3 * dd / d) / d if slope1 else 0.0
        dr2 = ((dq1 * q3 + q1 * dq3) - q1 * q3 * dd / d) / d if slope2 else 0.0
    else:
        dr1 = dr2 = 0.0
    return wd1, wd2, -k * dq1 + g * dr1, -k * dq2 - g * dr2


def rate_tracking_torque(w1: Scalar, w2: Scalar, rates: tuple[Scalar, Scalar, Scalar, Scalar], gain: float,
                         inertia: tuple[float, float]) -> tuple[Scalar, Scalar]:
    """snlc law (eq. 14/24 with eq. 31's units): ``u_i = −K (ω_i − ωd_i) + I_i ω̇d_i``.

    Works on floats and on CasADi expressions alike.

    Parameters
    ----------
    w1, w2 : float or casadi.SX
        Body rate on the actuated axes [rad/s], control frame.
    rates : tuple of 4 float or casadi.SX
        ``(ωd1, ωd2, ω̇d1, ω̇d2)`` [rad/s, rad/s²] as :func:`desired_rates` returns them.
    gain : float
        K [N m s/rad] (eq. 31's units; not 1/s times the inertia as eq. 14's ``I_i K_i`` reads).
    inertia : tuple of 2 float
        Principal moments ``I1``, ``I2`` of the actuated axes [kg m²].

    Returns
    -------
    tuple of 2 float or casadi.SX
        Torque ``(u1, u2)`` on the actuated axes [N m], control frame.
    """
    wd1, wd2, dwd1, dwd2 = rates
    return -gain * (w1 - wd1) + inertia[0] * dwd1, -gain * (w2 - wd2) + inertia[1] * dwd2


def min_norm(benchmark: tuple[float, float], lgv: tuple[float, float]) -> tuple[float, float]:
    """Minimum-norm ``u`` with ``L_gV u <= L_gV k`` (eq. 22), sign corrected.

    ``u = (L_gV k) L_gVᵀ / (L_gV L_gVᵀ)`` when ``L_gV k < 0``, else 0. Eq. 25 prints a leading
    minus, which gives ``L_gV u = −L_gV k > 0``: V̇ increases wherever the law acts. ``‖u‖ =
    |L_gV k| / ‖L_gV‖ <= ‖k‖`` (Cauchy-Schwarz), not ``= ‖k‖`` as the text after eq. 24 says.

    Parameters
    ----------
    benchmark : tuple of 2 float
        The benchmark torque ``k(x)`` on the actuated axes [N m], control frame.
    lgv : tuple of 2 float
        ``L_gV``, the gradient of the Lyapunov function along the control [s/(kg m²)].

    Returns
    -------
    tuple of 2 float
        The min-norm torque ``(u1, u2)`` [N m], control frame; zeros where the benchmark does not
        decrease V or ``L_gV = 0``.
    """
    s = lgv[0] * benchmark[0] + lgv[1] * benchmark[1]
    norm2 = lgv[0] * lgv[0] + lgv[1] * lgv[1]
    if s >= 0.0 or norm2 == 0.0:
        return 0.0, 0.0
    scale = s / norm2
    return scale * lgv[0], scale * lgv[1]


def _sat_symbolic(value: ca.SX, limit: float | None) -> tuple[ca.SX, ca.SX]:
    """:func:`_sat` on expressions."""
    if limit is None:
        return value, ca.SX(1.0)
    return ca.fmin(ca.fmax(value, -limit), limit), ca.if_else(ca.fabs(value) < limit, 1.0, 0.0)


def _ratio_symbolic(numerator: ca.SX, denominator: ca.SX) -> ca.SX:
    """:func:`_ratio` on expressions."""
    safe = ca.if_else(denominator > 0, denominator, 1.0)
    singular = ca.if_else(numerator == 0, 0.0, ca.sign(numerator) * ca.inf)
    return ca.if_else(denominator > 0, numerator / safe, singular)


def desired_rates_symbolic(q: Sequence[ca.SX], w: Sequence[ca.SX | float],
                           gains: SingularGains) -> tuple[ca.SX, ca.SX, ca.SX, ca.SX]:
    """:func:`desired_rates` on expressions: the same arithmetic, branches as ``if_else``.

    Parameters
    ----------
    q : sequence of 4 casadi.SX
        Error quaternion ``[q0, q1, q2, q3]`` in the control frame (scalar first).
    w : sequence of 3 casadi.SX or float
        Body rate ``[ω1, ω2, ω3]`` in the control frame [rad/s]; it enters the derivative only.
    gains : SingularGains
        The law's gains.

    Returns
    -------
    tuple of 4 casadi.SX
        ``(ωd1, ωd2, ω̇d1, ω̇d2)`` [rad/s, rad/s²].
    """
    q0, q1, q2, q3 = q
    w1, w2, w3 = w
    k, g = gains.k, gains.g
    dq1 = 0.5 * (q0 * w1 - q3 * w2 + q2 * w3)
    dq2 = 0.5 * (q0 * w2 - q1 * w3 + q3 * w1)
    dq3 = 0.5 * (q0 * w3 - q2 * w1 + q1 * w2)
    d = q1 * q1 + q2 * q2 + gains.epsilon_d
    dd = 2.0 * (q1 * dq1 + q2 * dq2)
    r1, slope1 = _sat_symbolic(_ratio_symbolic(q2 * q3, d), gains.a1)
    r2, slope2 = _sat_symbolic(_ratio_symbolic(q1 * q3, d), gains.a2)
    safe = ca.if_else(d > 0, d, 1.0)
    dr1 = ca.if_else(ca.logic_and(d > 0, slope1 != 0), ((dq2 * q3 + q2 * dq3) - q2 * q3 * dd / safe) / safe, 0.0)
    dr2 = ca.if_else(ca.logic_and(d > 0, slope2 != 0), ((dq1 * q3 + q1 * dq3) - q1 * q3 * dd / safe) / safe, 0.0)
    return -k * q1 + g * r1, -k * q2 - g * r2, -k * dq1 + g * dr1, -k * dq2 - g * dr2


def min_norm_symbolic(benchmark: tuple[ca.SX, ca.SX], lgv: tuple[ca.SX, ca.SX]) -> tuple[ca.SX, ca.SX]:
    """:func:`min_norm` on expressions (the branch as ``if_else``).

    Parameters
    ----------
    benchmark : tuple of 2 casadi.SX
        The benchmark torque ``k(x)`` on the actuated axes [N m], control frame.
    lgv : tuple of 2 casadi.SX
        ``L_gV`` [s/(kg m²)].

    Returns
    -------
    tuple of 2 casadi.SX
        The min-norm torque ``(u1, u2)`` [N m], control frame.
    """
    s = lgv[0] * benchmark[0] + lgv[1] * benchmark[1]
    norm2 = lgv[0] * lgv[0] + lgv[1] * lgv[1]
    acting = ca.logic_and(s < 0, norm2 != 0)
    scale = ca.if_else(acting, s / ca.if_else(norm2 != 0, norm2, 1.0), 0.0)
    return scale * lgv[0], scale * lgv[1]
