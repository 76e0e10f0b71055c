"""Quaternion algebra in NumPy, vectorised over leading axes.

Conventions (:doc:`/architecture`): ``q = [q0, q1, q2, q3]`` scalar first, Hamilton product, unit
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
    """Hamilton product ``p ⊗ q``.

    With the body-to-inertial convention, ``R(p ⊗ q) = R(p) R(q)``: ``q`` is applied first.

    Parameters
    ----------
    p, q : (..., 4) array_like
        Quaternions, scalar first; broadcast against each other. Not required to be unit.

    Returns
    -------
    (..., 4) ndarray
        The product, scalar first.
    """
    p = np.asarray(p, dtype=float)
    q = np.asarray(q, dtype=float)
    p0, pv = p[..., :1], p[..., 1:]
    q0, qv = q[..., :1], q[..., 1:]
    scalar = p0 * q0 - np.sum(pv * qv, axis=-1, keepdims=True)
    vector = p0 * qv + q0 * pv + np.cross(pv, qv)
    return np.concatenate([scalar, vector], axis=-1)


def conjugate(q: ArrayLike) -> Array:
    """Conjugate ``q* = [q0, -q1, -q2, -q3]``, the inverse of a unit quaternion.

    Parameters
    ----------
    q : (..., 4) array_like
        Quaternion(s), scalar first.

    Returns
    -------
    (..., 4) ndarray
        The conjugate; for a unit ``q`` it rotates inertial vectors to body axes.
    """
    q = np.asarray(q, dtype=float)
    return q * np.array([1.0, -1.0, -1.0, -1.0])


def normalize(q: ArrayLike) -> Array:
    """Unit quaternion along ``q``.

    Parameters
    ----------
    q : (..., 4) array_like
        Quaternion(s) of any non-zero norm (any last-axis length is normalised alike).

    Returns
    -------
    (..., 4) ndarray
        ``q / ‖q‖`` along the last axis; the sign is kept.

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
    """Rotation matrix ``R(q)`` that takes body components to inertial ones, ``v_I = R v_B``.

    Parameters
    ----------
    q : (..., 4) array_like
        Unit attitude quaternion(s), scalar first, body to inertial. Not normalised here.

    Returns
    -------
    (..., 3, 3) ndarray
        ``R(q)``; its columns are the body axes in inertial components.
    """
    q = np.asarray(q, dtype=float)
    q0, q1, q2, q3 = (q[..., i] for i in range(4))
    rows = [
        [1 - 2 * (q2**2 + q3**2), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
        [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1**2 + q3**2), 2 * (q2 * q3 - q0 * q1)],
        [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1**2 + q2**2)],
    ]
    return np.stack([np.stack(row, axis=-1) for row in rows], axis=-2)


def rotate(q: ArrayLike, v_body: ArrayLike) -> Array:
    """Body vector(s) expressed in the inertial frame, ``v_I = R(q) v_B``.

    Parameters
    ----------
    q : (..., 4) array_like
        Unit attitude quaternion(s), scalar first, body to inertial.
    v_body : (..., 3) array_like
        Vector(s) in body components (any unit); broadcast against ``q``.

    Returns
    -------
    (..., 3) ndarray
        The same vector(s) in inertial components (same unit).
    """
    return np.einsum("...ij,...j->...i", rotation_matrix(q), np.asarray(v_body, dtype=float))


def rotate_inverse(q: ArrayLike, v_inertial: ArrayLike) -> Array:
    """Inertial vector(s) expressed in the body frame, ``v_B = R(q)ᵀ v_I``.

    Parameters
    ----------
    q : (..., 4) array_like
        Unit attitude quaternion(s), scalar first, body to inertial.
    v_inertial : (..., 3) array_like
        Vector(s) in inertial components (any unit); broadcast against ``q``.

    Returns
    -------
    (..., 3) ndarray
        The same vector(s) in body components (same unit).
    """
    return np.einsum("...ji,...j->...i", rotation_matrix(q), np.asarray(v_inertial, dtype=float))


def from_rotation_matrix(matrix: ArrayLike) -> Array:
    """Unit quaternion of a rotation matrix (inverse of :func:`rotation_matrix`).

    Shepperd's method: the largest of the four squared components selects the branch, so the
    result is accurate for every rotation, 180° included.

    Parameters
    ----------
    matrix : (..., 3, 3) array_like
        Proper orthogonal matrix ``R`` with ``v_I = R v_B`` (body to inertial).

    Returns
    -------
    (..., 4) ndarray
        Unit quaternion, scalar first, with the sign chosen so that ``q0 >= 0``.
    """
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
    """Attitude error ``q_e = q_ref* ⊗ q``: the rotation from the reference to the actual body frame.

    ``R(q_e) = R(q_ref)ᵀ R(q)`` takes actual-body components to reference-body components; its
    vector part is in body axes (the same in both frames).

    Parameters
    ----------
    q : (..., 4) array_like
        Actual attitude(s), scalar first, body to inertial.
    q_ref : (..., 4) array_like
        Reference (desired) attitude(s), same convention; broadcast against ``q``.
    shortest : bool, optional
        If True (default), flip the sign where needed so that ``q_e0 >= 0`` (the rotation of at
        most 180°); if False, return the raw product.

    Returns
    -------
    (..., 4) ndarray
        Error quaternion, scalar first; the identity when ``q == ±q_ref``.
    """
    q_e = product(conjugate(q_ref), q)
    if shortest:
        q_e = np.where(q_e[..., :1] < 0.0, -q_e, q_e)
    return q_e


def error_angle(q: ArrayLike, q_ref: ArrayLike) -> Array:
    """Rotation angle between two attitudes, ``2 acos|q_e0|`` with ``q_e = q_ref* ⊗ q``.

    Computed as ``2 atan2(‖q_e,v‖, |q_e0|)``, accurate near 0 and 180°; insensitive to the sign
    of either quaternion.

    Parameters
    ----------
    q : (..., 4) array_like
        Actual attitude(s), scalar first, body to inertial (unit).
    q_ref : (..., 4) array_like
        Reference attitude(s), same convention; broadcast against ``q``.

    Returns
    -------
    (...) ndarray
        Angle [rad], in [0, π].
    """
    q_e = product(conjugate(q_ref), q)
    return 2.0 * np.arctan2(np.linalg.norm(q_e[..., 1:], axis=-1), np.abs(q_e[..., 0]))


def from_axis_angle(axis: ArrayLike, angle: ArrayLike) -> Array:
    """Quaternion of a rotation by ``angle`` about ``axis``.

    Parameters
    ----------
    axis : (..., 3) array_like
        Rotation axis, any non-zero length (normalised here). For an attitude the axis has the
        same components in body and inertial axes.
    angle : (...) array_like
        Rotation angle [rad], right-handed about ``axis``; broadcast against ``axis``.

    Returns
    -------
    (..., 4) ndarray
        Unit quaternion ``[cos(angle/2), sin(angle/2) axis/‖axis‖]``, scalar first.

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
    """Quaternion of the rotation vector ``θ e`` (the exponential map), exact at and near zero.

    Parameters
    ----------
    rotvec : (..., 3) array_like
        Rotation vector [rad]: unit axis ``e`` times angle ``θ``.

    Returns
    -------
    (..., 4) ndarray
        Unit quaternion ``[cos(θ/2), sin(θ/2) e]``, scalar first.
    """
    rotvec = np.asarray(rotvec, dtype=float)
    angle = np.linalg.norm(rotvec, axis=-1, keepdims=True)
    # sin(θ/2)/θ = 0.5 sinc(θ/2π): numpy's sinc is exact at zero.
    return np.concatenate([np.cos(0.5 * angle), 0.5 * np.sinc(angle / (2 * np.pi)) * rotvec], axis=-1)


def to_rotation_vector(q: ArrayLike) -> Array:
    """Rotation vector of the shortest rotation represented by ``q`` (inverse of
    :func:`from_rotation_vector`).

    Parameters
    ----------
    q : (..., 4) array_like
        Unit quaternion(s), scalar first; ``q`` and ``-q`` give the same result.

    Returns
    -------
    (..., 3) ndarray
        Rotation vector ``θ e`` [rad] with ``θ`` in [0, π].
    """
    q = np.asarray(q, dtype=float)
    q = np.where(q[..., :1] < 0.0, -q, q)
    vec_norm = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    angle = 2.0 * np.arctan2(vec_norm, q[..., :1])
    scale = np.where(vec_norm > 1e-12, angle / np.where(vec_norm > 1e-12, vec_norm, 1.0), 2.0)
    return scale * q[..., 1:]


def from_scalar_last(q_xyzw: ArrayLike) -> Array:
    """Reorder a scalar-last quaternion ``[q1, q2, q3, q4]`` (``q4`` the scalar, as in the
    nano-spacecraft and Vepa papers) to our scalar-first order.

    Parameters
    ----------
    q_xyzw : (..., 4) array_like
        Quaternion(s), vector part first, scalar last.

    Returns
    -------
    (..., 4) ndarray
        The same quaternion(s), scalar first. Only the order changes: the papers' quaternion
        must follow the same Hamilton, body-to-inertial convention for the result to mean the
        same attitude.
    """
    q = np.asarray(q_xyzw, dtype=float)
    return np.concatenate([q[..., 3:], q[..., :3]], axis=-1)


def to_scalar_last(q: ArrayLike) -> Array:
    """Reorder a scalar-first quaternion to scalar-last order (inverse of :func:`from_scalar_last`).

    Parameters
    ----------
    q : (..., 4) array_like
        Quaternion(s), scalar first.

    Returns
    -------
    (..., 4) ndarray
        ``[q1, q2, q3, q0]``.
    """
    q = np.asarray(q, dtype=float)
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def slerp(q_start: ArrayLike, q_end: ArrayLike, s: ArrayLike) -> Array:
    """Spherical linear interpolation from ``q_start`` to ``q_end`` along the shortest arc.

    The result rotates at constant rate about a fixed body axis (the axis of
    ``q_start* ⊗ q_end``): ``q_start ⊗ exp(s θ e / 2)``.

    Parameters
    ----------
    q_start, q_end : (4,) or (..., 4) array_like
        Unit attitudes, scalar first, body to inertial.
    s : (...) array_like
        Interpolation fraction; 0 gives ``q_start``, 1 gives ``±q_end`` (the sign that makes the
        arc shortest). Values outside [0, 1] extrapolate.

    Returns
    -------
    (..., 4) ndarray
        Unit quaternion(s), scalar first.
    """
    q_start = np.asarray(q_start, dtype=float)
    q_e = error(q_end, q_start)  # q_start* ⊗ q_end with q_e0 >= 0
    rotvec = to_rotation_vector(q_e)
    s = np.asarray(s, dtype=float)[..., None]
    return product(q_start, from_rotation_vector(s * rotvec))


def kinematics(q: ArrayLike, omega: ArrayLike) -> Array:
    """Quaternion rate ``q̇ = ½ q ⊗ [0, ω]``.

    Parameters
    ----------
    q : (..., 4) array_like
        Attitude quaternion(s), scalar first, body to inertial.
    omega : (..., 3) array_like
        Body angular rate with respect to the inertial frame, body axes [rad/s].

    Returns
    -------
    (..., 4) ndarray
        ``q̇`` [1/s], scalar first.
    """
    omega = np.asarray(omega, dtype=float)
    return 0.5 * product(q, np.concatenate([np.zeros(omega.shape[:-1] + (1,)), omega], axis=-1))


def random_unit(rng: np.random.Generator, size: int | None = None) -> Array:
    """Random unit quaternion(s), uniformly distributed over rotations (normalised Gaussian 4-vectors).

    Parameters
    ----------
    rng : numpy.random.Generator
        Source of the random numbers.
    size : int or None, optional
        Number of quaternions; ``None`` returns a single one.

    Returns
    -------
    (4,) or (size, 4) ndarray
        Unit quaternion(s), scalar first (either sign).
    """
    shape = (4,) if size is None else (size, 4)
    return normalize(rng.standard_normal(shape))
