"""Quaternion algebra on CasADi symbols, and the same operations as named ``casadi.Function``s.

The expression builders (``product``, ``rotation_matrix``, …) take and return 4- or 3-vectors of
``SX``/``MX``/``DM`` and are what the model uses to build its right-hand side. :data:`FUNCTIONS`
wraps each in a ``casadi.Function`` with named inputs and outputs that evaluates on NumPy arrays.
Conventions are those of :mod:`ocp.quat` (scalar first, Hamilton product, body to inertial).
"""
from __future__ import annotations

import casadi as ca


def product(p, q):
    """Hamilton product ``p ⊗ q``."""
    p0, pv = p[0], p[1:4]
    q0, qv = q[0], q[1:4]
    return ca.vertcat(p0 * q0 - ca.dot(pv, qv), p0 * qv + q0 * pv + ca.cross(pv, qv))


def conjugate(q):
    """Conjugate ``q*``."""
    return ca.vertcat(q[0], -q[1:4])


def rotation_matrix(q):
    """``R(q)`` with ``v_I = R v_B``."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(
        ca.horzcat(1 - 2 * (q2**2 + q3**2), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)),
        ca.horzcat(2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1**2 + q3**2), 2 * (q2 * q3 - q0 * q1)),
        ca.horzcat(2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1**2 + q2**2)),
    )


def error(q, q_ref, shortest: bool = True):
    """``q_e = q_ref* ⊗ q``; with ``shortest`` its sign is chosen so that ``q_e0 >= 0``."""
    q_e = product(conjugate(q_ref), q)
    if shortest:
        q_e = ca.if_else(q_e[0] < 0, -q_e, q_e)
    return q_e


def error_angle(q, q_ref):
    """Angle between two attitudes, ``2 acos|q_e0|`` (rad), evaluated with atan2."""
    q_e = product(conjugate(q_ref), q)
    return 2 * ca.atan2(ca.norm_2(q_e[1:4]), ca.fabs(q_e[0]))


def from_axis_angle(axis, angle):
    """Quaternion of a rotation by ``angle`` about the unit ``axis``."""
    return ca.vertcat(ca.cos(angle / 2), ca.sin(angle / 2) * axis)


def from_rotation_vector(rotvec):
    """Quaternion of the rotation vector ``θ e``; a series branch keeps it exact near zero."""
    angle_sq = ca.dot(rotvec, rotvec)
    angle = ca.sqrt(angle_sq + 1e-300)
    half_sinc = ca.if_else(angle_sq < 1e-8, 0.5 - angle_sq / 48, ca.sin(angle / 2) / angle)
    half_cos = ca.if_else(angle_sq < 1e-8, 1 - angle_sq / 8 + angle_sq**2 / 384, ca.cos(angle / 2))
    return ca.vertcat(half_cos, half_sinc * rotvec)


def from_scalar_last(q_xyzw):
    """``[q1, q2, q3, q4]`` scalar last to scalar first."""
    return ca.vertcat(q_xyzw[3], q_xyzw[0:3])


def to_scalar_last(q):
    """Scalar first to scalar last."""
    return ca.vertcat(q[1:4], q[0])


def slerp(q_start, q_end, s):
    """Spherical linear interpolation along the shortest arc, ``s`` in [0, 1]."""
    q_e = error(q_end, q_start)
    vec_norm = ca.norm_2(q_e[1:4])
    angle = 2 * ca.atan2(vec_norm, q_e[0])
    axis = q_e[1:4] / ca.fmax(vec_norm, 1e-300)
    return product(q_start, from_axis_angle(axis, s * angle))


def kinematics(q, omega):
    """``q̇ = ½ q ⊗ [0, ω]`` with ω in body axes."""
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
