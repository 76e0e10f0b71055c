"""Quaternion algebra in NumPy, vectorised over leading axes.

Conventions (ARCHITECTURE.md): ``q = [q0, q1, q2, q3]`` scalar first, Hamilton product, unit
norm; ``q`` rotates body vectors into the inertial frame, ``v_I = R(q) v_B``. Every function
accepts arrays of shape ``(..., 4)`` (and ``(..., 3)`` for vectors) and broadcasts.
The CasADi twins live in :mod:`ocp.quat_casadi`; tests check that both agree.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Array = NDArray[np.float64]

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


def product(p: ArrayLike, q: ArrayLike) -> Array:
    """Hamilton product ``p ⊗ q``."""
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    p0, pv = p[..., :1], p[..., 1:]
    q0, qv = q[..., :1], q[..., 1:]
    scalar = p0 * q0 - np.sum(pv * qv, axis=-1, keepdims=True)
    vector = p0 * qv + q0 * pv + np.cross(pv, qv)
    return np.concatenate([scalar, vector], axis=-1)


def conjugate(q: ArrayLike) -> Array:
    """Conjugate ``q*`` (the inverse of a unit quaternion)."""
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def normalize(q: ArrayLike) -> Array:
    """Unit quaternion along ``q`` (shape ``(..., 4)``; any vector length is normalised alike).

    Raises
    ------
    ValueError
        If a quaternion is zero or not finite.
    """
    q = np.asarray(q, dtype=float)
    norm = np.linalg.norm(q, axis=-1, keepdims=True)
    if not np.all(np.isfinite(norm)) or np.any(norm == 0.0):
        raise ValueError("cannot normalise a zero or non-finite quaternion")
    return q / norm


def rotation_matrix(q: ArrayLike) -> Array:
    """Rotation matrix ``R(q)`` with ``v_I = R v_B``; shape ``(..., 3, 3)``."""
    q = np.asarray(q, dtype=float)
    q0, q1, q2, q3 = (q[..., i] for i in range(4))
    rows = [
        [1 - 2 * (q2**2 + q3**2), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1**2 + q3**2), 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1**2 + q2**2)],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def rotate(q: ArrayLike, v_body: ArrayLike) -> Array:
    """Body vector(s) expressed in the inertial frame, ``R(q) v``."""
    return np.einsum("...ij,...j->...i", rotation_matrix(q), np.asarray(v_body, dtype=float))


def rotate_inverse(q: ArrayLike, v_inertial: ArrayLike) -> Array:
    """Inertial vector(s) expressed in the body frame, ``R(q)ᵀ v``."""
    return np.einsum("...ji,...j->...i", rotation_matrix(q), np.asarray(v_inertial, dtype=float))


def from_rotation_matrix(matrix: ArrayLike) -> Array:
    """Unit quaternion of a rotation matrix ``R`` (inverse of :func:`rotation_matrix`),
    by Shepperd's method: the largest of the four squared components sets the branch."""
    m = np.asarray(matrix, dtype=float)
    trace = np.trace(m, axis1=-2, axis2=-1)
    squares = np.stack(
        [1 + trace, 1 + 2 * m[..., 0, 0] - trace, 1 + 2 * m[..., 1, 1] - trace, 1 + 2 * m[..., 2, 2] - trace],
        axis=-1,
    )
    branch = np.argmax(squares, axis=-1)[..., None]
    big = 0.5 * np.sqrt(np.take_along_axis(squares, branch, axis=-1))
    r21, r12 = m[..., 2, 1], m[..., 1, 2]
    r02, r20 = m[..., 0, 2], m[..., 2, 0]
    r10, r01 = m[..., 1, 0], m[..., 0, 1]
    candidates = np.stack(
        [
            np.stack([4 * big[..., 0] ** 2, r21 - r12, r02 - r20, r10 - r01], axis=-1),
            np.stack([r21 - r12, 4 * big[..., 0] ** 2, r01 + r10, r02 + r20], axis=-1),
            np.stack([r02 - r20, r01 + r10, 4 * big[..., 0] ** 2, r12 + r21], axis=-1),
            np.stack([r10 - r01, r02 + r20, r12 + r21, 4 * big[..., 0] ** 2], axis=-1),
        ],
        axis=-2,
    )
    q = np.take_along_axis(candidates, branch[..., None], axis=-2)[..., 0, :] / (4 * big)
    return np.where(q[..., :1] < 0, -q, q)


def error(q: ArrayLike, q_ref: ArrayLike, shortest: bool = True) -> Array:
    """Attitude error ``q_e = q_ref* ⊗ q``; with ``shortest`` the sign gives ``q_e0 >= 0``."""
    q_e = product(conjugate(q_ref), q)
    if shortest:
        q_e = np.where(q_e[..., :1] < 0.0, -q_e, q_e)
    return q_e


def error_angle(q: ArrayLike, q_ref: ArrayLike) -> Array:
    """Rotation angle between two attitudes, ``2 acos|q_e0|`` in rad, computed with atan2."""
    q_e = product(conjugate(q_ref), q)
    return 2.0 * np.arctan2(np.linalg.norm(q_e[..., 1:], axis=-1), np.abs(q_e[..., 0]))


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> Array:
    """Quaternion of a rotation by ``angle`` (rad) about ``axis`` (normalised here).

    Raises
    ------
    ValueError
        If ``axis`` is not a (..., 3) array of finite, non-zero vectors.
    """
    axis = np.asarray(axis, dtype=float)
    if axis.ndim == 0 or axis.shape[-1] != 3:
        raise ValueError(f"axis must have 3 components, got shape {axis.shape}")
    length = np.linalg.norm(axis, axis=-1, keepdims=True)
    if not np.all(np.isfinite(length)) or np.any(length == 0.0):
        raise ValueError(f"axis must be a finite non-zero vector, got {axis.tolist()}")
    axis = axis / length
    half = 0.5 * np.asarray(angle, dtype=float)[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)


def from_rotation_vector(rotvec: ArrayLike) -> Array:
    """Quaternion of the rotation vector ``θ e`` (rad); exact at and near zero."""
    rotvec = np.asarray(rotvec, dtype=float)
    angle = np.linalg.norm(rotvec, axis=-1, keepdims=True)
    # sin(θ/2)/θ = 0.5 sinc(θ/2π): numpy's sinc is exact at zero.
    return np.concatenate([np.cos(0.5 * angle), 0.5 * np.sinc(angle / (2 * np.pi)) * rotvec], axis=-1)


def to_rotation_vector(q: ArrayLike) -> Array:
    """Rotation vector (rad) of the shortest rotation represented by ``q``."""
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0.0, -q, q)
    vec_norm = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(vec_norm, q[..., :1])
    scale = np.where(vec_norm > 1e-12, angle / np.where(vec_norm > 1e-12, vec_norm, 1.0), 2.0)
    return scale * q[..., 1:]


def from_scalar_last(q_xyzw: ArrayLike) -> Array:
    """Convert ``[q1, q2, q3, q4]`` with the scalar last (the nano and Vepa papers) to ours."""
    q = np.asarray(q_xyzw, dtype=float)
    return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def to_scalar_last(q: ArrayLike) -> Array:
    """Convert a scalar-first quaternion to scalar-last order."""
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def slerp(q_start: ArrayLike, q_end: ArrayLike, s: ArrayLike) -> Array:
    """Spherical linear interpolation along the shortest arc, ``s`` in [0, 1]."""
    q_start = np.asarray(q_start, dtype=float)
    q_e = error(q_end, q_start)  # q_start* ⊗ q_end with q_e0 >= 0
    rotvec = to_rotation_vector(q_e)
    s = np.asarray(s, dtype=float)[..., None]
    return product(q_start, from_rotation_vector(s * rotvec))


def kinematics(q: ArrayLike, omega: ArrayLike) -> Array:
    """Quaternion rate ``q̇ = ½ q ⊗ [0, ω]`` with ω in body axes (rad/s)."""
    omega = np.asarray(omega, dtype=float)
    return 0.5 * product(q, np.concatenate([np.zeros(omega.shape[:-1] + (1,)), omega], axis=-1))


def random_unit(rng: np.random.Generator, size: int | None = None) -> Array:
    """Uniformly distributed random unit quaternion(s)."""
    shape = (4,) if size is None else (size, 4)
    return normalize(rng.standard_normal(shape))
