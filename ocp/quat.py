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

__all__ = ["EULER_SEQUENCES", "IDENTITY", "UNIT_NORM_TOLERANCE", "conjugate", "continuous", "error", "error_angle",
           "from_axis_angle", "from_euler", "from_rotation_matrix", "from_rotation_vector", "from_scalar_last",
           "kinematics", "normalize", "product", "random_unit", "rotate", "rotate_inverse", "rotation_matrix",
           "sequence_axes", "slerp", "to_euler", "to_rotation_vector", "to_scalar_last", "unit_norm_error"]

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
"""(4,) ndarray: the identity rotation, scalar first (body axes aligned with the inertial ones);
read-only (a module constant)."""
IDENTITY.setflags(write=False)

UNIT_NORM_TOLERANCE = 1e-3
"""How far from 1 the norm of a quaternion given as input may be (:func:`unit_norm_error`; the
scenario loader and ``planners.ManeuverProblem``): any unit quaternion rounded to 3 decimals passes
(each entry off by at most 5e-4, so the norm by at most ``sqrt(4) * 5e-4 = 1e-3``), such as
``[0.707, 0.707, 0, 0]``; a typo such as ``[0.7, 0, 0.5, 0.5]`` (norm 0.995) is refused, and so is a
quaternion that is not a rotation (``[2, 0, 0, 0]``)."""


def unit_norm_error(q: ArrayLike, tolerance: float = UNIT_NORM_TOLERANCE) -> str | None:
    """Why ``q`` is not a unit quaternion given as input (the check of the YAML loader and of
    ``planners.ManeuverProblem``), or ``None``.

    Parameters
    ----------
    q : (4,) array_like
        Quaternion, scalar first.
    tolerance : float, optional
        Largest ``|‖q‖ − 1|`` accepted (default :data:`UNIT_NORM_TOLERANCE`).

    Returns
    -------
    str or None
        ``"a quaternion cannot be zero"``, ``"a quaternion must be finite"`` or ``"a quaternion
        must have unit norm (got norm 2; tolerance 1e-3)"``; ``None`` when its norm is within
        ``tolerance`` of 1 (the caller then normalises it).
    """
    norm = float(np.linalg.norm(np.asarray(q, dtype=float)))
    if not np.isfinite(norm):
        return "a quaternion must be finite"
    if norm == 0.0:
        return "a quaternion cannot be zero"
    if abs(norm - 1.0) > tolerance:
        mantissa, exponent = f"{tolerance:.0e}".split("e")
        return f"a quaternion must have unit norm (got norm {norm:.6g}; tolerance {mantissa}e{int(exponent)})"
    return None


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
    p, q = np.broadcast_arrays(np.asarray(p, dtype=float), np.asarray(q, dtype=float))
    p0, p1, p2, p3 = (p[..., i] for i in range(4))
    q0, q1, q2, q3 = (q[..., i] for i in range(4))
    out = np.empty(p.shape)
    # written out (np.cross costs more than the product): p0 q0 - pv·qv, p0 qv + q0 pv + pv × qv
    out[..., 0] = p0 * q0 - (p1 * q1 + p2 * q2 + p3 * q3)
    out[..., 1] = p0 * q1 + q0 * p1 + (p2 * q3 - p3 * q2)
    out[..., 2] = p0 * q2 + q0 * p2 + (p3 * q1 - p1 * q3)
    out[..., 3] = p0 * q3 + q0 * p3 + (p1 * q2 - p2 * q1)
    return out


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
    try:
        axis = np.asarray(axis, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"axis must be 3 numbers (a (..., 3) array), got {axis!r}") from None
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


_AXES = {"1": 0, "2": 1, "3": 2, "x": 0, "y": 1, "z": 2}
"""Body axis index of each letter of an Euler sequence."""
_GIMBAL_LOCK = 1e-7
"""rad: a middle Euler angle this close to its singular value is treated as gimbal lock."""


EULER_SEQUENCES = ("321", "123", "312", "213", "231", "132", "121", "131", "212", "232", "313", "323")
"""The twelve Euler sequences: six Tait-Bryan, then six proper (body axes, ``1`` = x)."""


def sequence_axes(sequence: str) -> tuple[int, int, int]:
    """Axis indices of an Euler sequence.

    Parameters
    ----------
    sequence : str
        Three body axes in the order the rotations are applied: ``1``, ``2``, ``3`` (or ``x``,
        ``y``, ``z``), no two consecutive ones equal, such as ``"321"``, ``"313"`` or ``"zyx"``.

    Returns
    -------
    (int, int, int)
        The axes (0 = x), in the order of the rotations.

    Raises
    ------
    ValueError
        Another sequence.
    """
    axes = tuple(_AXES.get(letter) for letter in sequence.lower()) if isinstance(sequence, str) else ()
    if len(axes) != 3 or None in axes or axes[0] == axes[1] or axes[1] == axes[2]:
        raise ValueError(f"an Euler sequence must name three body axes (1, 2, 3 or x, y, z), no two consecutive ones "
                         f"equal, such as '321' or '313', got {sequence!r}")
    return axes  # type: ignore[return-value]  # None excluded above


def to_euler(q: ArrayLike, sequence: str = "321") -> Array:
    """Euler angles of an attitude: rotations about body axes in the order of ``sequence``.

    For ``sequence = "321"`` (the default, yaw-pitch-roll) the angles ``(ψ, θ, φ)`` satisfy
    ``q = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)`` up to sign (``R(q) = R_z(ψ) R_y(θ) R_x(φ)``): from the
    inertial frame, yaw about z, then pitch about the new y, then roll about the newest x, reach
    the body axes. Any sequence of three body axes with no two consecutive ones equal works: the six
    Tait-Bryan (``"321"``, ``"123"`` ...) and the six proper Euler sequences (``"313"`` ...). The
    angles are computed from the quaternion directly (Bernardes and Viollet, 2022), so ``q`` and
    ``-q`` give the same angles; at gimbal lock (middle angle ±90° for Tait-Bryan, 0 or 180° for
    proper sequences) the third angle is set to zero and the first carries the rotation.

    Parameters
    ----------
    q : (..., 4) array_like
        Unit quaternion(s), scalar first, body to inertial.
    sequence : str, optional
        The body axes in the order the rotations are applied from the inertial frame: three of
        ``1``, ``2``, ``3`` (or ``x``, ``y``, ``z``); default ``"321"``.

    Returns
    -------
    (..., 3) ndarray
        The three angles [rad], in the order of ``sequence``: the first and last in (-π, π], the
        middle one in [-π/2, π/2] for a Tait-Bryan sequence and [0, π] for a proper one.

    Raises
    ------
    ValueError
        A sequence that is not three body axes with no two consecutive ones equal, or ``q`` that
        is not a (..., 4) array of numbers.
    """
    first, middle, last = sequence_axes(sequence)
    q = _quaternions("q", q)
    # Written for the extrinsic sequence (i, j, k): the intrinsic (first, middle, last) is the
    # extrinsic (last, middle, first), its angles in reverse order.
    i, j, k = last, middle, first
    proper = i == k
    if proper:
        k = 3 - i - j
    sign = (i - j) * (j - k) * (k - i) // 2  # Levi-Civita symbol of (i, j, k): +1 or -1
    w, v = q[..., 0], q[..., 1:]
    if proper:
        a, b, c, d = w, v[..., i], v[..., j], sign * v[..., k]
    else:
        a, b, c, d = w - v[..., j], v[..., i] + sign * v[..., k], v[..., j] + w, sign * v[..., k] - v[..., i]
    middle_angle = 2.0 * np.arctan2(np.hypot(c, d), np.hypot(a, b))
    half_sum, half_difference = np.arctan2(b, a), np.arctan2(d, c)
    at_zero = np.abs(middle_angle) <= _GIMBAL_LOCK
    at_pi = np.abs(middle_angle - np.pi) <= _GIMBAL_LOCK
    # extrinsic first angle (the intrinsic last): zero at gimbal lock, where only a sum or a
    # difference of the outer angles is defined
    outer_first = np.where(at_zero | at_pi, 0.0, half_sum - half_difference)
    outer_last = np.where(at_zero, 2.0 * half_sum, np.where(at_pi, 2.0 * half_difference,
                                                            half_sum + half_difference))
    if not proper:
        outer_last = sign * outer_last
        middle_angle = middle_angle - np.pi / 2
    return _wrap(np.stack([outer_last, middle_angle, outer_first], axis=-1))


def from_euler(angles: ArrayLike, sequence: str = "321") -> Array:
    """Attitude of Euler angles: rotations about body axes in the order of ``sequence`` (inverse of
    :func:`to_euler`).

    For ``sequence = "321"`` (the default) the angles ``(ψ, θ, φ)`` give
    ``q = q_z(ψ) ⊗ q_y(θ) ⊗ q_x(φ)``, ``R(q) = R_z(ψ) R_y(θ) R_x(φ)``: from the reference frame,
    yaw about z, then pitch about the new y, then roll about the newest x, reach the body axes.
    Any sequence :func:`to_euler` takes (Tait-Bryan or proper) is accepted; the angles may lie
    anywhere (no range is imposed).

    Parameters
    ----------
    angles : (..., 3) array_like
        The three angles [rad], in the order of ``sequence``.
    sequence : str, optional
        The body axes in the order the rotations are applied: three of ``1``, ``2``, ``3`` (or
        ``x``, ``y``, ``z``), no two consecutive ones equal; default ``"321"``.

    Returns
    -------
    (..., 4) ndarray
        Unit quaternion(s), scalar first, rotating body vectors into the reference frame
        (``v_ref = R(q) v_B``, as everywhere in this module), with the sign chosen so that
        ``q0 >= 0``.

    Raises
    ------
    ValueError
        A sequence that is not three body axes with no two consecutive ones equal, or angles whose
        last axis is not 3 long.
    """
    axes = sequence_axes(sequence)
    angles = np.asarray(angles, dtype=float)
    if angles.ndim == 0 or angles.shape[-1] != 3:
        raise ValueError(f"angles must have 3 components, got shape {angles.shape}")
    q = np.broadcast_to(IDENTITY, angles.shape[:-1] + (4,))
    for index, axis in enumerate(axes):
        q = product(q, from_axis_angle(np.eye(3)[axis], angles[..., index]))
    return np.where(q[..., :1] < 0.0, -q, q)


def _quaternions(name: str, q: ArrayLike) -> Array:
    """``q`` as a float (..., 4) array, or a ``ValueError`` naming ``name`` (text is no number)."""
    try:
        array = np.asarray(q, dtype=float) if np.asarray(q).dtype.kind not in "US" else None
    except (TypeError, ValueError):
        array = None
    if array is None or array.ndim == 0 or array.shape[-1] != 4:
        raise ValueError(f"{name} must be quaternions of 4 numbers (a (..., 4) array, scalar first), got {q!r}")
    return array


def _wrap(angles: Array) -> Array:
    """Angles in (-π, π]."""
    return np.pi - (np.pi - angles) % (2.0 * np.pi)


def continuous(q: ArrayLike) -> Array:
    """A quaternion time series with each sample's sign chosen so that no sample jumps to ``-q``.

    ``q`` and ``-q`` are the same attitude; a series that switches between them (a solver, a
    canonical form ``q0 >= 0``) looks like a jump in a plot or a table. Each sample after the first
    takes the sign that makes its dot product with the previous (sign-corrected) sample
    non-negative; the first sample keeps its sign.

    Parameters
    ----------
    q : (N, 4) array_like
        Quaternions, scalar first, in time order.

    Returns
    -------
    (N, 4) ndarray
        The same attitudes, each ``+q_k`` or ``-q_k``.

    Raises
    ------
    ValueError
        ``q`` is not an (N, 4) array.
    """
    q = np.array(q, dtype=float)
    if q.ndim != 2 or q.shape[1] != 4:
        raise ValueError(f"q must be an (N, 4) series of quaternions, got shape {q.shape}")
    if len(q) < 2:
        return q
    flips = np.where(np.sum(q[1:] * q[:-1], axis=1) < 0.0, -1.0, 1.0)
    signs = np.concatenate([[1.0], np.cumprod(flips)])
    return q * signs[:, None]
