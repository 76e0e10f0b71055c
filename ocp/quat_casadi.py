"""Quaternion algebra on CasADi symbols, and the same operations as named ``casadi.Function`` objects.

The expression builders (``product``, ``rotation_matrix``, …) take and return 4- or 3-vectors of
``SX``/``MX``/``DM`` and are what the model uses to build its right-hand side. :data:`FUNCTIONS`
wraps each in a ``casadi.Function`` with named inputs and outputs that evaluates on NumPy arrays.
Conventions are those of :mod:`ocp.quat` (scalar first, Hamilton product, body to inertial).
"""
from __future__ import annotations

from typing import Any

import casadi as ca

Expr = Any
"""A CasADi column: ``casadi.SX``, ``casadi.MX`` or ``casadi.DM`` (numbers and NumPy arrays are
converted by CasADi). Typed ``Any`` because CasADi mixes these freely (``DM`` with ``SX`` gives
``SX``) and its stubs type each operator for one class only."""


def product(p: Expr, q: Expr) -> Expr:
    """Hamilton product ``p ⊗ q`` (``R(p ⊗ q) = R(p) R(q)``).

    Parameters
    ----------
    p, q : (4, 1) casadi.SX, MX or DM
        Quaternions, scalar first.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        The product, scalar first.
    """
    p0, pv = p[0], p[1:4]
    q0, qv = q[0], q[1:4]
    return ca.vertcat(p0 * q0 - ca.dot(pv, qv), p0 * qv + q0 * pv + ca.cross(pv, qv))


def conjugate(q: Expr) -> Expr:
    """Conjugate ``q* = [q0, -q1, -q2, -q3]``, the inverse of a unit quaternion.

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Quaternion, scalar first.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        The conjugate.
    """
    return ca.vertcat(q[0], -q[1:4])


def rotation_matrix(q: Expr) -> Expr:
    """Rotation matrix ``R(q)`` with ``v_I = R v_B`` (body to inertial).

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Unit attitude quaternion, scalar first, body to inertial (not normalised here).

    Returns
    -------
    (3, 3) casadi.SX, MX or DM
        ``R(q)``; its columns are the body axes in inertial components.
    """
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(
        ca.horzcat(1 - 2 * (q2**2 + q3**2), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)),
        ca.horzcat(2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1**2 + q3**2), 2 * (q2 * q3 - q0 * q1)),
        ca.horzcat(2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1**2 + q2**2)),
    )


def error(q: Expr, q_ref: Expr, shortest: bool = True) -> Expr:
    """Attitude error ``q_e = q_ref* ⊗ q``, the rotation from the reference to the actual body frame.

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Actual attitude, scalar first, body to inertial.
    q_ref : (4, 1) casadi.SX, MX or DM
        Reference attitude, same convention.
    shortest : bool, optional
        If True (default), the sign is chosen (``if_else``) so that ``q_e0 >= 0``.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        Error quaternion, scalar first; its vector part is in body axes.
    """
    q_e = product(conjugate(q_ref), q)
    if shortest:
        q_e = ca.if_else(q_e[0] < 0, -q_e, q_e)
    return q_e


def error_angle(q: Expr, q_ref: Expr) -> Expr:
    """Rotation angle between two attitudes, ``2 acos|q_e0|`` with ``q_e = q_ref* ⊗ q``, evaluated as
    ``2 atan2(‖q_e,v‖, |q_e0|)``.

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Actual attitude, scalar first, body to inertial (unit).
    q_ref : (4, 1) casadi.SX, MX or DM
        Reference attitude, same convention.

    Returns
    -------
    (1, 1) casadi.SX, MX or DM
        Angle [rad], in [0, π].
    """
    q_e = product(conjugate(q_ref), q)
    return 2 * ca.atan2(ca.norm_2(q_e[1:4]), ca.fabs(q_e[0]))


def from_axis_angle(axis: Expr, angle: Expr) -> Expr:
    """Quaternion of a rotation by ``angle`` about ``axis``: ``[cos(angle/2), sin(angle/2) axis]``.

    Parameters
    ----------
    axis : (3, 1) casadi.SX, MX or DM
        Unit rotation axis (not normalised here, unlike :func:`ocp.quat.from_axis_angle`).
    angle : scalar casadi.SX, MX, DM or float
        Rotation angle [rad], right-handed about ``axis``.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        Quaternion, scalar first (unit when ``axis`` is).
    """
    return ca.vertcat(ca.cos(angle / 2), ca.sin(angle / 2) * axis)


def from_rotation_vector(rotvec: Expr) -> Expr:
    """Quaternion of the rotation vector ``θ e`` (the exponential map); a series branch for
    ``θ² < 1e-8`` keeps it exact, and differentiable, near zero.

    Parameters
    ----------
    rotvec : (3, 1) casadi.SX, MX or DM
        Rotation vector [rad]: unit axis ``e`` times angle ``θ``.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        Unit quaternion ``[cos(θ/2), sin(θ/2) e]``, scalar first.
    """
    angle_sq = ca.dot(rotvec, rotvec)
    angle = ca.sqrt(angle_sq + 1e-300)
    half_sinc = ca.if_else(angle_sq < 1e-8, 0.5 - angle_sq / 48, ca.sin(angle / 2) / angle)
    half_cos = ca.if_else(angle_sq < 1e-8, 1 - angle_sq / 8 + angle_sq**2 / 384, ca.cos(angle / 2))
    return ca.vertcat(half_cos, half_sinc * rotvec)


def from_scalar_last(q_xyzw: Expr) -> Expr:
    """Reorder a scalar-last quaternion ``[q1, q2, q3, q4]`` (``q4`` the scalar) to scalar first.

    Parameters
    ----------
    q_xyzw : (4, 1) casadi.SX, MX or DM
        Quaternion, vector part first, scalar last.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        ``[q4, q1, q2, q3]``.
    """
    return ca.vertcat(q_xyzw[3], q_xyzw[0:3])


def to_scalar_last(q: Expr) -> Expr:
    """Reorder a scalar-first quaternion to scalar-last order.

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Quaternion, scalar first.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        ``[q1, q2, q3, q0]``.
    """
    return ca.vertcat(q[1:4], q[0])


def slerp(q_start: Expr, q_end: Expr, s: Expr) -> Expr:
    """Spherical linear interpolation from ``q_start`` to ``q_end`` along the shortest arc:
    ``q_start ⊗ exp(s θ e / 2)``, a constant-rate rotation about a fixed axis.

    Parameters
    ----------
    q_start, q_end : (4, 1) casadi.SX, MX or DM
        Unit attitudes, scalar first, body to inertial.
    s : scalar casadi.SX, MX, DM or float
        Interpolation fraction; 0 gives ``q_start``, 1 gives ``±q_end``.

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        Unit quaternion, scalar first.
    """
    q_e = error(q_end, q_start)
    vec_norm = ca.norm_2(q_e[1:4])
    angle = 2 * ca.atan2(vec_norm, q_e[0])
    axis = q_e[1:4] / ca.fmax(vec_norm, 1e-300)
    return product(q_start, from_axis_angle(axis, s * angle))


def kinematics(q: Expr, omega: Expr) -> Expr:
    """Quaternion rate ``q̇ = ½ q ⊗ [0, ω]``.

    Parameters
    ----------
    q : (4, 1) casadi.SX, MX or DM
        Attitude quaternion, scalar first, body to inertial.
    omega : (3, 1) casadi.SX, MX or DM
        Body angular rate with respect to the inertial frame, body axes [rad/s].

    Returns
    -------
    (4, 1) casadi.SX, MX or DM
        ``q̇`` [1/s], scalar first.
    """
    return 0.5 * product(q, ca.vertcat(0, omega))


def _build_functions() -> dict[str, ca.Function]:
    q, p = ca.SX.sym("q", 4), ca.SX.sym("p", 4)
    v, s = ca.SX.sym("v", 3), ca.SX.sym("s")
    specs = {
        "product": ([p, q], ["p", "q"], product(p, q), "p_q"),
        "conjugate": ([q], ["q"], conjugate(q), "q_conj"),
        "rotation_matrix": ([q], ["q"], rotation_matrix(q), "R"),
        "error": ([q, p], ["q", "q_ref"], error(q, p), "q_e"),
        "error_angle": ([q, p], ["q", "q_ref"], error_angle(q, p), "angle"),
        "from_axis_angle": ([v, s], ["axis", "angle"], from_axis_angle(v, s), "q"),
        "from_rotation_vector": ([v], ["rotvec"], from_rotation_vector(v), "q"),
        "from_scalar_last": ([q], ["q_xyzw"], from_scalar_last(q), "q"),
        "to_scalar_last": ([q], ["q"], to_scalar_last(q), "q_xyzw"),
        "slerp": ([q, p, s], ["q_start", "q_end", "s"], slerp(q, p, s), "q"),
        "kinematics": ([q, v], ["q", "omega"], kinematics(q, v), "q_dot"),
    }
    return {
        name: ca.Function(f"quat_{name}", inputs, [output], names, [out_name])
        for name, (inputs, names, output, out_name) in specs.items()
    }


FUNCTIONS: dict[str, ca.Function] = _build_functions()
"""Named ``casadi.Function`` versions of the builders above (evaluate on NumPy arrays)."""
