"""The slew table's fit: slew time as a smooth function of the eigen-axis and the angle.

Model. Let ``g(e, θ) = T(e, θ) / b(e, θ)`` (``T`` the table's slew time [s], ``θ`` the slew
angle [rad], ``e`` the unit eigen-axis in the body frame), ``2 b`` the eigenaxis bang-coast-bang
time: ``b = √(θ s(e))`` while ``θ m(e)² <= s(e)``, else ``b = (θ m + s / m) / 2``. ``s(e) = ‖J e‖_Z``
is the gauge of ``J e`` in the zonotope ``Z`` of body torques the working actuators can give
(wheels' and torquers' torque bounds; magnetorquers left out): ``1 / s(e)`` is the largest angular
acceleration about ``e``, and the eigenaxis bang-bang takes ``T = 2 √(θ s(e))``. ``1 / m(e)`` is the
largest rate about ``e``: the smaller of the rate bound and, with wheels alone (total momentum zero
from rest), the rate whose body momentum ``J e ω`` is on the boundary of the working wheels' momentum
zonotope, ``m(e) = max(‖J e‖_H, 1 / max_rate)`` (no coast without either, or without torque
bounds). Divided by it the times are nearly constant in ``θ``, so ``g`` is what is interpolated
(without torque bounds, or with fewer than three independent torque directions, ``s = 1``); a
table of exactly the eigenaxis bang-coast-bang times has ``g = 2`` everywhere and is reproduced to
round-off. Over the sphere the times (and ``g``)
have kinks where the bounding facet of ``Z`` changes, on great circles; the default grid
(:func:`scenarios.slewtable.grid.polytope_grid`) puts triangle edges on them. Per axis of the
table, ``g`` is a monotone-preserving piecewise cubic (PCHIP) in ``θ`` through the table's angles;
over the sphere the three axes of the triangle that holds ``e`` (the grid's triangles, else the
axes' convex hull) are blended linearly (barycentric weights of the gnomonic projection,
continuous across edges). Below the smallest angle ``g`` is held at its value there (``T → 0`` as ``√θ``);
above the largest there is no value (NaN), unless the largest is 180°, which covers every slew.

Entries that are not ``ok`` (``status``) are not interpolated: the fit is NaN in every cell (a
triangle of axes between two table angles) that has one with a non-zero weight, and ``inf`` where
every entry it uses is ``infeasible`` (at such an entry itself). That holds where the slew's end
clears every pointing requirement too: a keep-out cone is a path constraint, and a slew ending just
outside it may go around it slower than any ``ok`` corner of the cell, so no value of the corners
bounds it; the refinement (:mod:`scenarios.slewtable.refine`) splits the triangles across the
boundary to shrink that region. A table of slews from the identity only
(``meta.from_identity_only``) refuses any other start attitude.

A slew whose end attitude breaks a pointing requirement of the table's scenario is ``inf`` whatever
the interpolation gives (``end_cones``: each cone's body boresight, its inertial direction and
half-angle at the time the table checks its own entries' targets, the scenario's duration): the
table's entries there are ``infeasible``, but an end attitude inside a cone between the table's
axes is no entry of the table, and the blend of its neighbours' times would be a time for a slew
that cannot be made. Between the end points the fit relies on the entries alone.

Evaluation (:meth:`SlewTimeFit.__call__`) is pure Python on precomputed lists (a cube-map lookup
finds the candidate triangles), since every NumPy call costs about a microsecond;
:meth:`SlewTimeFit.slew_time_many` is the vectorised form.

Quaternions are scalar first, ``[w, x, y, z]``, body to inertial, unless the fit is made or loaded
with ``quaternion_order="scalar_last"`` (``[x, y, z, w]``, as ``maneuver.quaternion_order`` of a
scenario; ``fit.json`` keeps the order as ``quaternion_order``): the slew from ``q0`` to ``qf`` is
the rotation ``dq = q0⁻¹ ⊗ qf`` (Hamilton product), whose axis is in the body frame and whose angle
(the short way, in [0, π]) is the table's angle. A unit quaternion in the other order is a unit
quaternion too, of another rotation: the fit cannot tell, and answers for that rotation. Only a
table of slews from the identity only can tell: the identity written scalar last, ``[0, 0, 0, 1]``,
is 180° from it read scalar first, and the refusal says so.
"""
from __future__ import annotations

import bisect
import json
import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["FIT_FORMAT", "IDENTITY_TOLERANCE", "QUATERNION_ORDERS", "UNIT_TOLERANCE", "SlewTimeFit", "fit_table",
           "load_fit"]

FIT_FORMAT = "slewbench-slew-time-fit/1"
"""The ``format`` key of ``fit.json``."""
_CELLS = 12  # cube-map cells per face side
_SAMPLES = 7  # directions sampled per cell side to list its candidate triangles
_INSIDE = -1e-9
_UNUSED = 1e-9  # a barycentric weight at most this fraction of their sum: the vertex is not used
_ANGLE_SLACK = 1e-12  # rad: an angle this far past the table's largest is that angle (quaternion rounding)
_OK, _INFEASIBLE, _UNKNOWN = 0, 1, 2  # entry codes: ok, proven infeasible, anything else not ok


def _hull(axes: np.ndarray) -> np.ndarray:
    """Triangles (vertex indices) of the axes' convex hull, each facing outward; ValueError when the
    hull does not hold the origin inside (every direction must meet one triangle)."""
    from scipy.spatial import ConvexHull, QhullError
    if len(axes) < 4:
        raise ValueError(f"a fit over the sphere needs at least 4 axes spanning it, got {len(axes)}")
    try:
        hull = ConvexHull(axes)
    except QhullError as error:
        raise ValueError(f"the axes do not span the sphere: {str(error).splitlines()[0]}") from None
    if np.any(hull.equations[:, 3] >= -1e-9):
        raise ValueError("the axes do not surround the origin (a hemisphere or less): no fit over the sphere")
    if len(hull.vertices) != len(axes):
        raise ValueError("some axes are not on the convex hull (not unit vectors, or repeated)")
    return np.asarray(hull.simplices, dtype=int)


def _inverses(axes: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Per triangle, the inverse of the 3x3 matrix whose columns are its vertices."""
    return np.linalg.inv(np.stack([axes[t].T for t in triangles]))


def _locate(inverses: np.ndarray, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each direction, the triangle holding it and its normalised barycentric weights (in chunks
    of directions, so that memory stays bounded on refined meshes)."""
    found = np.empty(len(directions), dtype=int)
    chosen = np.empty((len(directions), 3))
    step = max(1, 2_000_000 // max(len(inverses), 1))
    for start in range(0, len(directions), step):
        block = directions[start:start + step]
        weights = np.einsum("tij,nj->nti", inverses, block)
        inside = np.all(weights >= _INSIDE, axis=2)
        first = np.argmax(inside, axis=1)
        found[start:start + step] = first
        chosen[start:start + step] = weights[np.arange(len(block)), first]
    return found, chosen / chosen.sum(axis=1, keepdims=True)


def _cube_cells(inverses: np.ndarray) -> list[list[int]]:
    """Cube-map cell -> the triangles that directions in the cell can fall into (sampled densely
    on each cell, edges included, among the triangles whose bounding cone meets the cell's; the
    evaluation falls back to every triangle if none holds)."""
    vertices = np.linalg.inv(inverses)  # (t, 3, 3): columns are the vertices
    centres = vertices.sum(axis=2)
    centres /= np.linalg.norm(centres, axis=1, keepdims=True)
    radii = np.max(np.arccos(np.clip(np.einsum("ti,tij->tj", centres, vertices)
                                     / np.linalg.norm(vertices, axis=1), -1.0, 1.0)), axis=1)
    s = np.linspace(-1.0, 1.0, _CELLS * (_SAMPLES - 1) + 1)
    cells: list[list[int]] = []
    for face in range(6):
        major, sign = face // 2, 1.0 if face % 2 == 0 else -1.0
        others = [i for i in range(3) if i != major]
        u, v = np.meshgrid(s, s, indexing="ij")
        directions = np.empty((u.size, 3))
        directions[:, major] = sign
        directions[:, others[0]] = u.ravel()
        directions[:, others[1]] = v.ravel()
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        cube = directions.reshape(*u.shape, 3)
        for i in range(_CELLS):
            for j in range(_CELLS):
                block = cube[i * (_SAMPLES - 1):(i + 1) * (_SAMPLES - 1) + 1,
                                   j * (_SAMPLES - 1):(j + 1) * (_SAMPLES - 1) + 1].reshape(-1, 3)
                centre = block.mean(axis=0)
                centre /= np.linalg.norm(centre)
                spread = float(np.max(np.arccos(np.clip(block @ centre, -1.0, 1.0))))
                near = np.nonzero(np.arccos(np.clip(centres @ centre, -1.0, 1.0)) <= radii + spread + 1e-9)[0]
                if not len(near):
                    near = np.arange(len(inverses))
                found, _ = _locate(inverses[near], block)
                cells.append(sorted({int(t) for t in near[found]}))
    return cells


def _cell(x: float, y: float, z: float) -> int:
    """The cube-map cell of a direction (the same layout as :func:`_cube_cells`)."""
    ax, ay, az = abs(x), abs(y), abs(z)
    if ax >= ay and ax >= az:
        face, m, u, v = (0 if x >= 0.0 else 1), ax, y, z
    elif ay >= az:
        face, m, u, v = (2 if y >= 0.0 else 3), ay, x, z
    else:
        face, m, u, v = (4 if z >= 0.0 else 5), az, x, y
    i = int((u / m + 1.0) * 0.5 * _CELLS)
    j = int((v / m + 1.0) * 0.5 * _CELLS)
    return (face * _CELLS + (i if i < _CELLS else _CELLS - 1)) * _CELLS + (j if j < _CELLS else _CELLS - 1)


def zonotope_facets(generators: ArrayLike) -> np.ndarray:
    """Facet normals of the torque zonotope ``{Σ u_k G_k : |u_k| <= 1}``, each divided by its support.

    Parameters
    ----------
    generators : array_like, shape (m, 3)
        Each actuator's torque direction times its bound [N m], body frame.

    Returns
    -------
    numpy.ndarray, shape (f, 3)
        Normals ``n / h`` [1/(N m)]: the gauge of a torque ``τ`` is ``max |n/h · τ|``; empty when the
        generators span fewer than three directions (no finite gauge).
    """
    g = np.asarray(generators, dtype=float).reshape(-1, 3)
    if len(g) < 3 or np.linalg.matrix_rank(g, tol=1e-9 * max(np.max(np.abs(g)), 1e-300)) < 3:
        return np.zeros((0, 3))
    facets = []
    for i in range(len(g)):
        for j in range(i + 1, len(g)):
            n = np.cross(g[i], g[j])
            size = np.linalg.norm(n)
            if size <= 1e-12 * np.linalg.norm(g[i]) * np.linalg.norm(g[j]):
                continue
            n = n / size
            facets.append(n / np.sum(np.abs(g @ n)))
    return np.array(facets)


def relative_axis_angle(q0: ArrayLike, qf: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Eigen-axes (body frame of ``q0``) and angles of the slews ``q0 -> qf`` (vectorised).

    Parameters
    ----------
    q0, qf : array_like, shape (4,) or (n, 4)
        Attitude quaternions, scalar first, body to inertial (normalised here).

    Returns
    -------
    axes : numpy.ndarray, shape (n, 3)
        Unit eigen-axes, body frame (``[1, 0, 0]`` where the angle is zero).
    angles : numpy.ndarray, shape (n,)
        Slew angles the short way [rad], in [0, π].
    """
    a = np.atleast_2d(np.asarray(q0, dtype=float))
    b = np.atleast_2d(np.asarray(qf, dtype=float))
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    w0, v0 = a[:, :1], -a[:, 1:]
    w1, v1 = b[:, :1], b[:, 1:]
    w = w0 * w1 - np.sum(v0 * v1, axis=1, keepdims=True)
    v = w0 * v1 + w1 * v0 + np.cross(v0, v1)
    flip = np.where(w < 0.0, -1.0, 1.0)
    w, v = w * flip, v * flip
    s = np.linalg.norm(v, axis=1)
    angles = 2.0 * np.arctan2(s, w[:, 0])
    axes = np.where(s[:, None] > 0.0, v / np.where(s > 0.0, s, 1.0)[:, None], np.array([1.0, 0.0, 0.0]))
    return axes, angles


UNIT_TOLERANCE = 1e-2
"""How far from 1 a quaternion's norm may be (as a scenario's, ``scenarios.schema``); the fit reads
the relative rotation's axis and angle, which scaling leaves alone."""
_UNIT_SQUARED = 2 * UNIT_TOLERANCE + UNIT_TOLERANCE ** 2  # |q|² within it: |q| in [1 − tol, 1 + tol]


IDENTITY_TOLERANCE = 1e-6
"""How far a start attitude ``q0`` may turn from the identity [rad] for a fit of slews from the
identity only (``meta.from_identity_only``: with pointing requirements or environment torques the
slew time depends on the start attitude, and the table holds slews from the identity)."""


QUATERNION_ORDERS = ("scalar_first", "scalar_last")
"""The orders a fit takes quaternions in: ``[w, x, y, z]`` (the default) or ``[x, y, z, w]``."""


def _identity_error(name: str, q: Any, angle: float, order: str = "scalar_first") -> ValueError:
    values = [float(v) for v in q]
    other = values[0] if order == "scalar_last" else values[-1]  # where the other order keeps the scalar
    hint = ""
    if abs(other) >= math.sqrt(sum(v * v for v in values)) * math.cos(IDENTITY_TOLERANCE / 2.0):
        written = "[w, x, y, z]" if order == "scalar_last" else "[x, y, z, w]"
        hint = (f"; it is the identity written {written}: this fit reads quaternions {order.replace('_', ' ')}, "
                f"load it with quaternion_order={QUATERNION_ORDERS[order == 'scalar_first']!r} to call it so")
    return ValueError(f"{name} must be the identity attitude (within {IDENTITY_TOLERANCE:g} rad): this fit's "
                      "table holds slews from the identity only (meta.from_identity_only: pointing requirements "
                      "or environment torques make the slew time depend on the start attitude, not only on the "
                      f"rotation), got {list(q)} ({angle:.6g} rad from the identity, quaternions read "
                      f"{order.replace('_', ' ')}){hint}")


def _as_list(name: str, value: Any, order: str) -> list[float]:
    """A quaternion argument as a list (NumPy arrays and other sequences), or a ``TypeError`` naming
    the fit's quaternion ``order``."""
    try:
        listed = np.asarray(value, dtype=float).tolist()
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be 4 numbers ({order.replace('_', ' ')}), got {value!r}") from None
    if not isinstance(listed, list) or len(listed) != 4:
        raise TypeError(f"{name} must be 4 numbers ({order.replace('_', ' ')}), got {value!r}")
    return listed


def _floats(name: str, q: Sequence[Any], order: str) -> list[float]:
    """A quaternion's 4 numbers (NumPy scalars, ints) as Python floats, or a ``TypeError`` naming the
    fit's quaternion ``order`` (text is not a number, though ``float`` reads it)."""
    a, b, c, d = q
    if isinstance(a, _TEXT) or isinstance(b, _TEXT) or isinstance(c, _TEXT) or isinstance(d, _TEXT):
        raise TypeError(f"{name} must be 4 numbers ({order.replace('_', ' ')}), got {q!r}")
    return [float(a), float(b), float(c), float(d)]


_TEXT = (str, bytes)


def _check_unit(q0: Sequence[float], qf: Sequence[float]) -> None:
    """The ``ValueError`` for the quaternion of ``q0``, ``qf`` whose norm is off."""
    for name, q in (("q0", q0), ("qf", qf)):
        norm = math.sqrt(sum(x * x for x in q))
        if not abs(norm - 1.0) <= UNIT_TOLERANCE:
            raise ValueError(f"{name} must be a unit quaternion (norm within {UNIT_TOLERANCE:g} of 1), "
                             f"got {list(q)} (norm {norm:.6g})")


class SlewTimeFit:
    """Slew time [s] between two attitudes from a slew table's fit (module docstring).

    Call it as ``fit(q0, qf)`` (pure Python, a few microseconds), or :meth:`slew_time_many` for arrays;
    quaternions scalar first, ``[w, x, y, z]``, body to inertial (or ``[x, y, z, w]`` with
    ``quaternion_order="scalar_last"``: :attr:`quaternion_order` says which).

    Parameters
    ----------
    angles : array_like, shape (k,)
        The table's slew angles [rad], increasing, k >= 2, in (0, π].
    axes : array_like, shape (n, 3)
        The table's eigen-axes, body frame (unit vectors spanning the sphere, n >= 4).
    times : array_like, shape (n, k)
        Slew time at each axis and angle [s], positive and finite where the entry is ``ok`` (NaN
        elsewhere).
    meta : dict, optional
        What the fit came from (scenario, objective, errors on held-out points); kept in ``fit.json``.
        ``meta["from_identity_only"]`` true: the start attitude must be the identity.
    inertia : array_like, shape (3, 3), optional
        The spacecraft's inertia [kg m²], body frame (for the shape ``s(e)``; with ``generators``).
    generators : array_like, shape (m, 3), optional
        The working actuators' torque directions times their bounds [N m], body frame; None or
        fewer than three independent ones: ``s = 1``.
    triangles : array_like of int, shape (t, 3), optional
        Triangles over the axes (vertex indices) that cover the sphere once by central projection
        (:func:`scenarios.slewtable.grid.polytope_grid`); None: the axes' convex hull.
    status : array_like of str, shape (n, k), optional
        Each entry's status in the table (``ok``, ``infeasible``, ``failed``, ...); None: all
        ``ok``. The fit is NaN in the cells that use an entry that is not ``ok``, ``inf`` where
        every entry used is ``infeasible`` (module docstring).
    momentum_generators : array_like, shape (m, 3), optional
        The working wheels' axes times their momentum bounds [N m s], body frame, when nothing else
        changes the total momentum (for the coast rate of the baseline, module docstring); None or
        fewer than three independent ones: no momentum cap.
    max_rate : float, optional
        The body-rate bound the table's slews keep [rad/s]; None: none.
    end_cones : array_like, shape (c, 8), optional
        The pointing requirements' cones at the end of a slew from the identity, a row each: the
        body boresight (3, unit), the inertial direction (3, unit), the cosine of the half-angle
        and 1 for a keep-out (0 for a keep-in) (:func:`scenarios.slewtable.compute.end_cones`).
        A slew whose end attitude breaks one is ``inf``. None: none (the table has no pointing
        requirement; a table with them holds slews from the identity only).
    quaternion_order : {"scalar_first", "scalar_last"}, optional
        The order :meth:`__call__` and :meth:`slew_time_many` read quaternions in: ``[w, x, y, z]``
        (default) or ``[x, y, z, w]``. A unit quaternion in the other order is another rotation:
        the fit cannot tell (module docstring).

    Raises
    ------
    ValueError
        Shapes that disagree, angles not increasing in (0, π], times of ``ok`` entries not positive
        and finite, no ``ok`` entry, axes that do not span the sphere, a ``max_rate`` that is
        not positive and finite, or another ``quaternion_order``.
    """

    def __init__(self, angles: ArrayLike, axes: ArrayLike, times: ArrayLike, meta: dict[str, Any] | None = None,
                 inertia: ArrayLike | None = None, generators: ArrayLike | None = None,
                 triangles: ArrayLike | None = None, status: ArrayLike | None = None,
                 momentum_generators: ArrayLike | None = None, max_rate: float | None = None,
                 end_cones: ArrayLike | None = None, quaternion_order: str = "scalar_first"):
        from scipy.interpolate import PchipInterpolator
        if quaternion_order not in QUATERNION_ORDERS:
            raise ValueError(f"quaternion_order must be one of {', '.join(QUATERNION_ORDERS)}, got {quaternion_order!r}")
        self.quaternion_order = quaternion_order
        self._scalar_last = quaternion_order == "scalar_last"
        theta = np.asarray(angles, dtype=float)
        e = np.asarray(axes, dtype=float)
        t = np.asarray(times, dtype=float)
        if theta.ndim != 1 or theta.size < 2 or np.any(np.diff(theta) <= 0) or theta[0] <= 0 or theta[-1] > np.pi + 1e-12:
            raise ValueError("angles must be at least 2 increasing values in (0, pi] [rad]")
        if e.ndim != 2 or e.shape[1] != 3 or t.shape != (e.shape[0], theta.size):
            raise ValueError(f"axes must be (n, 3) and times (n, {theta.size}), got {e.shape} and {t.shape}")
        states = np.full(t.shape, "ok", dtype=object) if status is None else np.asarray(status, dtype=object)
        if states.shape != t.shape:
            raise ValueError(f"status must be (n, k) like times, got {states.shape} and {t.shape}")
        ok = states == "ok"
        if not np.all(np.isfinite(t[ok])) or np.any(t[ok] <= 0):
            raise ValueError("times of ok entries must be positive and finite")
        if not ok.any():
            raise ValueError("no ok entry to fit")
        e = e / np.linalg.norm(e, axis=1, keepdims=True)
        t = np.where(ok, t, np.nan)
        self.angles, self.axes, self.times, self.status = theta, e, t, states
        codes = np.where(ok, _OK, np.where(states == "infeasible", _INFEASIBLE, _UNKNOWN))
        self._codes = codes.tolist()
        self.meta: dict[str, Any] = dict(meta or {})
        self._identity_only = bool(self.meta.get("from_identity_only"))
        self._identity_vsq = math.sin(IDENTITY_TOLERANCE / 2.0) ** 2  # |vector part|² / |q|² at the tolerance
        self._top = math.pi if theta[-1] >= math.pi - 1e-9 else float(theta[-1])  # beyond it: NaN
        self.triangles = _hull(e) if triangles is None else np.asarray(triangles, dtype=int).reshape(-1, 3)
        if self.triangles.size and (self.triangles.min() < 0 or self.triangles.max() >= len(e)):
            raise ValueError("triangles must index the axes")
        self.inverses = _inverses(e, self.triangles)
        self.inertia = np.eye(3) if inertia is None else np.asarray(inertia, dtype=float).reshape(3, 3)
        self.generators = np.zeros((0, 3)) if generators is None else np.asarray(generators, dtype=float).reshape(-1, 3)
        facets = zonotope_facets(self.generators) if len(self.generators) else np.zeros((0, 3))
        self.facets = facets @ self.inertia if len(facets) else facets  # n/h · (J e) = (n/h J) · e
        self._facets = [tuple(f) for f in self.facets.tolist()]
        self.momentum_generators = (np.zeros((0, 3)) if momentum_generators is None
                                    else np.asarray(momentum_generators, dtype=float).reshape(-1, 3))
        if max_rate is not None and not (math.isfinite(max_rate) and max_rate > 0):
            raise ValueError(f"max_rate must be positive and finite [rad/s], got {max_rate!r}")
        self.max_rate = None if max_rate is None else float(max_rate)
        momentum = zonotope_facets(self.momentum_generators) if len(self.momentum_generators) else np.zeros((0, 3))
        # n/h · (J e): the largest rate about e is 1 / max_f |rate_facets_f · e| (no coast without torque facets)
        self.rate_facets = momentum @ self.inertia if len(momentum) and len(self.facets) else np.zeros((0, 3))
        self._rate_facets = [tuple(f) for f in self.rate_facets.tolist()]
        self._inverse_rate = 1.0 / self.max_rate if self.max_rate is not None and len(self.facets) else 0.0
        self._coasts = bool(self._rate_facets) or self._inverse_rate > 0.0
        cones = np.zeros((0, 8)) if end_cones is None else np.asarray(end_cones, dtype=float).reshape(-1, 8)
        if not np.all(np.isfinite(cones)) or not np.allclose(np.linalg.norm(cones[:, :6].reshape(-1, 3), axis=1), 1.0):
            raise ValueError("end_cones must be finite rows of a unit boresight, a unit direction, the cosine of "
                             "the half-angle and 1 (keep-out) or 0 (keep-in)")
        if len(cones) and not self._identity_only:
            raise ValueError("end_cones need meta['from_identity_only'] true: the end check takes the slew's "
                             "rotation for the end attitude, which it is only from the identity")
        self.end_cones = cones
        self._cones = [tuple(row) for row in cones.tolist()]
        g = t / self.baseline(e[:, None, :], theta[None, :])
        slopes = np.full(g.shape, np.nan)
        for row, good in zip(range(len(g)), ok):  # PCHIP over each run of ok angles, alone
            start = 0
            while start < len(theta):
                if not good[start]:
                    start += 1
                    continue
                stop = start
                while stop + 1 < len(theta) and good[stop + 1]:
                    stop += 1
                run = slice(start, stop + 1)
                slopes[row, run] = (PchipInterpolator(theta[run], g[row, run]).derivative()(theta[run])
                                    if stop > start else 0.0)
                start = stop + 1
        self._g, self._dg = g, slopes
        # pure-Python tables for __call__
        self._theta = theta.tolist()
        self._rows = [list(zip(gr.tolist(), sr.tolist())) for gr, sr in zip(g, slopes)]
        self._tri = [(tuple(int(i) for i in tri), tuple(inv.ravel().tolist()))
                     for tri, inv in zip(self.triangles, self.inverses)]
        cells = _cube_cells(self.inverses)
        self._cells = [[self._tri[i] for i in cell] for cell in cells]
        widest = max(len(cell) for cell in cells)
        self._candidates = np.array([cell + [cell[-1]] * (widest - len(cell)) for cell in cells], dtype=int)

    # --- evaluation ------------------------------------------------------------------------

    def shape(self, axes: ArrayLike) -> np.ndarray:
        """The shape ``s(e) = ‖J e‖_Z`` of unit axes (module docstring; 1 without torque bounds).

        Parameters
        ----------
        axes : array_like, shape (n, 3)
            Unit eigen-axes, body frame.

        Returns
        -------
        numpy.ndarray, shape (n,)
            ``s(e)`` [s² / rad]: ``2 √(θ s)`` is the eigenaxis bang-bang time.
        """
        e = np.atleast_2d(np.asarray(axes, dtype=float))
        if not len(self.facets):
            return np.ones(len(e))
        return np.max(np.abs(e @ self.facets.T), axis=1)

    def baseline(self, axes: ArrayLike, angles: ArrayLike) -> np.ndarray:
        """Half the eigenaxis bang-coast-bang time about unit axes by angles (module docstring).

        Parameters
        ----------
        axes : array_like, shape (..., 3)
            Unit eigen-axes, body frame.
        angles : array_like
            Slew angles [rad], >= 0, broadcast against ``axes[..., 0]``.

        Returns
        -------
        numpy.ndarray
            ``√(θ s)`` while ``θ m² <= s``, else ``(θ m + s / m) / 2`` [s] (``s = 1``, no coast,
            without torque bounds): the fit is this times ``g``.
        """
        e = np.asarray(axes, dtype=float)
        theta = np.maximum(np.asarray(angles, dtype=float), 0.0)
        s = np.max(np.abs(e @ self.facets.T), axis=-1) if len(self.facets) else np.ones(e.shape[:-1])
        bang = np.sqrt(theta * s)
        if not self._coasts:
            return bang
        m = np.max(np.abs(e @ self.rate_facets.T), axis=-1) if len(self.rate_facets) else np.zeros(e.shape[:-1])
        m = np.maximum(m, self._inverse_rate)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(theta * m * m > s, 0.5 * (theta * m + s / m), bang)

    def axis_angle(self, x: float, y: float, z: float, angle: float) -> float:
        """Slew time about a body axis by an angle (pure Python).

        Parameters
        ----------
        x, y, z : float
            The eigen-axis, body frame (any length > 0).
        angle : float
            The slew angle [rad], >= 0.

        Returns
        -------
        float
            The fitted slew time [s] (0 for a zero angle; NaN and ``inf`` as :meth:`__call__`).
            The start attitude is the identity.
        """
        if angle <= 0.0:
            return 0.0
        if self._cones and self._end_breaks(x, y, z, angle):
            return math.inf
        found = None
        for tri in self._cells[_cell(x, y, z)]:
            m = tri[1]
            w0 = m[0] * x + m[1] * y + m[2] * z
            w1 = m[3] * x + m[4] * y + m[5] * z
            w2 = m[6] * x + m[7] * y + m[8] * z
            if w0 >= _INSIDE and w1 >= _INSIDE and w2 >= _INSIDE:
                found = tri
                break
        if found is None:  # never seen in tests: the sampled cell lists missed a sliver
            return float(self.many_axis_angle(np.array([[x, y, z]]), np.array([angle]))[0])
        s = w0 + w1 + w2
        i, j, k = found[0]
        theta = self._theta
        last = len(theta) - 1
        if angle <= theta[0]:
            r0, r1, r2 = self._rows[i][0][0], self._rows[j][0][0], self._rows[k][0][0]
        elif angle >= theta[last]:
            if angle > self._top + _ANGLE_SLACK:  # no extrapolation past the table's largest angle
                return math.nan
            r0, r1, r2 = self._rows[i][last][0], self._rows[j][last][0], self._rows[k][last][0]
        else:
            n = bisect.bisect_right(theta, angle) - 1
            h = theta[n + 1] - theta[n]
            t = (angle - theta[n]) / h
            t2 = t * t
            t3 = t2 * t
            h00, h01 = 2.0 * t3 - 3.0 * t2 + 1.0, 3.0 * t2 - 2.0 * t3
            h10, h11 = (t3 - 2.0 * t2 + t) * h, (t3 - t2) * h
            rows = self._rows
            (a0, b0), (a1, b1) = rows[i][n], rows[i][n + 1]
            r0 = h00 * a0 + h10 * b0 + h01 * a1 + h11 * b1
            (a0, b0), (a1, b1) = rows[j][n], rows[j][n + 1]
            r1 = h00 * a0 + h10 * b0 + h01 * a1 + h11 * b1
            (a0, b0), (a1, b1) = rows[k][n], rows[k][n + 1]
            r2 = h00 * a0 + h10 * b0 + h01 * a1 + h11 * b1
        scale = 1.0
        if self._facets:
            norm = math.sqrt(x * x + y * y + z * z)
            scale = 0.0
            for a, b, c in self._facets:
                v = a * x + b * y + c * z
                if v < 0.0:
                    v = -v
                if v > scale:  # noqa: PLR1730  (max() costs a call in the hot loop)
                    scale = v
            scale /= norm
        blend = (w0 * r0 + w1 * r1 + w2 * r2) / s
        if blend != blend:  # noqa: PLR0124  (NaN: an entry that is not ok in the cell; isnan costs a call)
            blend = self._gap(found[0], w0 / s, w1 / s, w2 / s, angle)
        if self._coasts:  # the eigenaxis slew coasts at 1/m past θ m² = s (baseline)
            slow = 0.0  # m(e) [s/rad]: 1 / the largest rate about e
            for a, b, c in self._rate_facets:
                v = a * x + b * y + c * z
                if v < 0.0:
                    v = -v
                if v > slow:  # noqa: PLR1730
                    slow = v
            slow /= math.sqrt(x * x + y * y + z * z)
            if slow < self._inverse_rate:
                slow = self._inverse_rate
            if angle * slow * slow > scale:
                return blend * 0.5 * (angle * slow + scale / slow)
        return blend * math.sqrt(angle * scale)

    def _end_breaks(self, x: float, y: float, z: float, angle: float) -> bool:
        """Whether the end attitude of the slew from the identity about ``(x, y, z)`` by ``angle``
        breaks a cone of :attr:`end_cones` (pure Python)."""
        half = 0.5 * angle
        k = math.sin(half) / math.sqrt(x * x + y * y + z * z)
        w, vx, vy, vz = math.cos(half), x * k, y * k, z * k
        for bx, by, bz, dx, dy, dz, cosine, keep_out in self._cones:
            # b rotated body to inertial: b + 2 w (v x b) + 2 v x (v x b)
            cx, cy, cz = vy * bz - vz * by, vz * bx - vx * bz, vx * by - vy * bx
            ix = bx + 2.0 * (w * cx + vy * cz - vz * cy)
            iy = by + 2.0 * (w * cy + vz * cx - vx * cz)
            iz = bz + 2.0 * (w * cz + vx * cy - vy * cx)
            dot = ix * dx + iy * dy + iz * dz
            if (dot > cosine) if keep_out else (dot < cosine):
                return True
        return False

    def end_breaks_many(self, axes: ArrayLike, angles: ArrayLike) -> np.ndarray:
        """Whether the end attitudes of slews from the identity break a cone of :attr:`end_cones`.

        Parameters
        ----------
        axes : array_like, shape (n, 3)
            Eigen-axes, body frame (any length > 0).
        angles : array_like, shape (n,)
            Slew angles [rad].

        Returns
        -------
        numpy.ndarray of bool, shape (n,)
            True where the end attitude's boresight is inside a keep-out cone or outside a keep-in
            cone (all False without cones).
        """
        e = np.atleast_2d(np.asarray(axes, dtype=float))
        theta = np.atleast_1d(np.asarray(angles, dtype=float))
        broken = np.zeros(len(e), dtype=bool)
        if not len(self.end_cones):
            return broken
        v = e / np.linalg.norm(e, axis=1, keepdims=True) * np.sin(0.5 * theta)[:, None]
        w = np.cos(0.5 * theta)[:, None]
        for row in self.end_cones:
            b, d, cosine, keep_out = row[:3], row[3:6], row[6], row[7] > 0.5
            c = np.cross(v, b)
            inertial = b + 2.0 * (w * c + np.cross(v, c))
            dot = inertial @ d
            broken |= (dot > cosine) if keep_out else (dot < cosine)
        return broken & (theta > 0.0)

    def _gap(self, vertices: tuple[int, ...], w0: float, w1: float, w2: float, angle: float) -> float:
        """The blended ``g`` of a cell holding an entry that is not ok (normalised weights): NaN if
        an entry used (non-zero weight) is not ok, inf if every one used is infeasible, else the
        blend of the entries used alone (a point on a table angle or a triangle's edge)."""
        theta = self._theta
        last = len(theta) - 1
        if angle <= theta[0]:
            nodes, t = [0], 0.0
        elif angle >= theta[last]:
            nodes, t = [last], 0.0
        else:
            n = bisect.bisect_right(theta, angle) - 1
            t = (angle - theta[n]) / (theta[n + 1] - theta[n])
            # a table angle recovered from quaternions lands a few ulps off it: a node whose Hermite
            # weight is rounding is not used (its entry may be a gap while the angle's own is not)
            if t <= _UNUSED:
                nodes, t = [n], 0.0
            elif t >= 1.0 - _UNUSED:
                nodes, t = [n + 1], 0.0
            else:
                nodes = [n, n + 1]
        used = [(v, w) for v, w in zip(vertices, (w0, w1, w2)) if w > _UNUSED]
        codes = [self._codes[v][n] for v, _ in used for n in nodes]
        if any(codes):
            return math.inf if all(c == _INFEASIBLE for c in codes) else math.nan
        total = 0.0
        for v, w in used:
            row = self._rows[v]
            if len(nodes) == 1:
                r = row[nodes[0]][0]
            else:
                n = nodes[0]
                h = theta[n + 1] - theta[n]
                t2, t3 = t * t, t * t * t
                (a0, b0), (a1, b1) = row[n], row[n + 1]
                r = ((2.0 * t3 - 3.0 * t2 + 1.0) * a0 + (t3 - 2.0 * t2 + t) * h * b0
                     + (3.0 * t2 - 2.0 * t3) * a1 + (t3 - t2) * h * b1)
            total += w * r
        return total / sum(w for _, w in used)

    def __call__(self, q0: Any, qf: Any) -> float:
        """Slew time from attitude ``q0`` to ``qf`` (pure Python).

        Parameters
        ----------
        q0, qf : sequence of 4 floats
            Attitude quaternions, body to inertial, in :attr:`quaternion_order`: scalar first,
            ``[w, x, y, z]``, unless the fit was made or loaded with ``quaternion_order="scalar_last"``
            (``[x, y, z, w]``). A quaternion in the other order is read as another rotation: it
            cannot be told apart (a unit quaternion either way), except a start that must be the
            identity (``meta.from_identity_only``), whose refusal names the order. Unit; tuples or
            lists of Python floats are fastest; NumPy arrays, and sequences of NumPy scalars or
            ints, are converted first.

        Returns
        -------
        float
            The fitted slew time [s] of the rest-to-rest slew ``q0 -> qf``; NaN where the fit has no
            value (a cell with an entry that is not ``ok``, or an angle past the table's largest),
            ``inf`` at an ``infeasible`` entry and where the end attitude breaks a pointing
            requirement (module docstring).

        Raises
        ------
        TypeError
            ``q0`` or ``qf`` is not 4 numbers.
        ValueError
            A norm farther than :data:`UNIT_TOLERANCE` from 1 (a zero or non-finite quaternion), or
            ``q0`` farther than :data:`IDENTITY_TOLERANCE` from the identity for a table of slews
            from the identity only (``meta.from_identity_only``).
        """
        if type(q0) is not tuple and type(q0) is not list:
            q0 = _as_list("q0", q0, self.quaternion_order)
        if type(qf) is not tuple and type(qf) is not list:
            qf = _as_list("qf", qf, self.quaternion_order)
        try:
            if self._scalar_last:  # [x, y, z, w]
                b, c, d, a = q0
                f, g, h, e = qf
            else:
                a, b, c, d = q0
                e, f, g, h = qf
            if type(a) is not float or type(e) is not float:  # e.g. NumPy scalars: ~10x a float per operation
                a, b, c, d = _floats("q0", q0, self.quaternion_order)
                e, f, g, h = _floats("qf", qf, self.quaternion_order)
                if self._scalar_last:
                    a, b, c, d = d, a, b, c
                    e, f, g, h = h, e, f, g
            n0 = a * a + b * b + c * c + d * d
            n1 = e * e + f * f + g * g + h * h
        except (TypeError, ValueError):
            raise TypeError(f"q0 and qf must be 4 numbers each ({self.quaternion_order.replace('_', ' ')}), "
                            f"got {q0!r} and {qf!r}") from None
        if not (abs(n0 - 1.0) <= _UNIT_SQUARED and abs(n1 - 1.0) <= _UNIT_SQUARED):  # NaN fails too
            _check_unit(q0, qf)
        if self._identity_only and b * b + c * c + d * d > self._identity_vsq * n0:
            raise _identity_error("q0", q0, 2.0 * math.atan2(math.sqrt(b * b + c * c + d * d), abs(a)),
                                  self.quaternion_order)
        # dq = conj(q0) ⊗ qf
        w = a * e + b * f + c * g + d * h
        x = a * f - b * e - c * h + d * g
        y = a * g - c * e - d * f + b * h
        z = a * h - d * e - b * g + c * f
        if w < 0.0:
            w, x, y, z = -w, -x, -y, -z
        s = math.sqrt(x * x + y * y + z * z)
        if s == 0.0:
            return 0.0
        return self.axis_angle(x, y, z, 2.0 * math.atan2(s, w))

    def _locate_many(self, e: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Triangle and normalised weights of unit directions (the cube-map candidates, vectorised;
        every triangle for a direction none of its candidates holds)."""
        a = np.abs(e)
        major = np.where((a[:, 0] >= a[:, 1]) & (a[:, 0] >= a[:, 2]), 0, np.where(a[:, 1] >= a[:, 2], 1, 2))
        rows = np.arange(len(e))
        m = a[rows, major]
        sign = e[rows, major] < 0.0
        others = np.array([[1, 2], [0, 2], [0, 1]])[major]
        u, v = e[rows, others[:, 0]] / m, e[rows, others[:, 1]] / m
        i = np.minimum(((u + 1.0) * 0.5 * _CELLS).astype(int), _CELLS - 1)
        j = np.minimum(((v + 1.0) * 0.5 * _CELLS).astype(int), _CELLS - 1)
        cell = ((2 * major + sign) * _CELLS + i) * _CELLS + j
        candidates = self._candidates[cell]  # (n, c)
        weights = np.einsum("ncij,nj->nci", self.inverses[candidates], e)
        inside = np.all(weights >= _INSIDE, axis=2)
        first = np.argmax(inside, axis=1)
        found = candidates[rows, first]
        chosen = weights[rows, first]
        missed = ~inside[rows, first]
        if np.any(missed):
            found[missed], chosen[missed] = _locate(self.inverses, e[missed])
            return found, chosen / chosen.sum(axis=1, keepdims=True)
        return found, chosen / chosen.sum(axis=1, keepdims=True)

    def many_axis_angle(self, axes: ArrayLike, angles: ArrayLike) -> np.ndarray:
        """Slew times about many axes by many angles (vectorised).

        Parameters
        ----------
        axes : array_like, shape (n, 3)
            Eigen-axes, body frame (any length > 0).
        angles : array_like, shape (n,)
            Slew angles [rad], >= 0.

        Returns
        -------
        numpy.ndarray, shape (n,)
            Fitted slew times [s] (NaN and ``inf`` as :meth:`__call__`).
        """
        e = np.atleast_2d(np.asarray(axes, dtype=float))
        theta = np.atleast_1d(np.asarray(angles, dtype=float))
        e = e / np.linalg.norm(e, axis=1, keepdims=True)
        found, weights = self._locate_many(e)
        vertices = self.triangles[found]  # (n, 3)
        nodes = self.angles
        clipped = np.clip(theta, nodes[0], nodes[-1])
        n = np.clip(np.searchsorted(nodes, clipped, side="right") - 1, 0, len(nodes) - 2)
        h = nodes[n + 1] - nodes[n]
        t = (clipped - nodes[n]) / h
        t2, t3 = t * t, t * t * t
        h00, h01 = 2 * t3 - 3 * t2 + 1, 3 * t2 - 2 * t3
        h10, h11 = (t3 - 2 * t2 + t) * h, (t3 - t2) * h
        g, dg = self._g[vertices], self._dg[vertices]  # (n, 3, k)
        nn = n[:, None]
        inner = (h00[:, None] * np.take_along_axis(g, nn[..., None], 2)[..., 0]
                 + h10[:, None] * np.take_along_axis(dg, nn[..., None], 2)[..., 0]
                 + h01[:, None] * np.take_along_axis(g, nn[..., None] + 1, 2)[..., 0]
                 + h11[:, None] * np.take_along_axis(dg, nn[..., None] + 1, 2)[..., 0])
        inner = np.where((theta >= nodes[-1])[:, None], g[..., -1], inner)
        with np.errstate(invalid="ignore"):
            blended = np.sum(weights * inner, axis=1)
        gaps = np.nonzero(np.isnan(blended) & (theta <= self._top + _ANGLE_SLACK) & (theta > 0.0))[0]
        for row in gaps.tolist():  # an entry that is not ok in the cell: as the scalar call
            w = weights[row].tolist()
            blended[row] = self._gap(tuple(vertices[row].tolist()), w[0], w[1], w[2], float(theta[row]))
        blended[theta > self._top + _ANGLE_SLACK] = np.nan  # no extrapolation past the table's largest angle
        with np.errstate(invalid="ignore"):
            times = np.where(theta > 0.0, blended * self.baseline(e, theta), 0.0)
        if len(self.end_cones):
            times[self.end_breaks_many(e, theta)] = np.inf
        return times

    def slew_time_many(self, q0: ArrayLike, qf: ArrayLike) -> np.ndarray:
        """Slew times of many slews (vectorised :meth:`__call__`).

        Parameters
        ----------
        q0, qf : array_like, shape (n, 4) or (4,)
            Attitude quaternions, body to inertial, in :attr:`quaternion_order` (scalar first,
            ``[w, x, y, z]``, by default), broadcast against each other.

        Returns
        -------
        numpy.ndarray, shape (n,)
            Fitted slew times [s] (NaN and ``inf`` as :meth:`__call__`).

        Raises
        ------
        TypeError, ValueError
            As :meth:`__call__`, naming the first bad quaternion; a ``ValueError`` for ``q0`` and
            ``qf`` whose numbers of quaternions differ (neither being one).
        """
        arrays = []
        order = self.quaternion_order.replace("_", " ")
        for name, value in (("q0", q0), ("qf", qf)):
            # text is not a number, though NumPy reads it as one (``__call__`` refuses it too)
            if value is None or np.asarray(value).dtype.kind in "US":
                raise TypeError(f"{name} must be quaternions of 4 numbers ({order}), got {value!r}")
            try:
                array = np.atleast_2d(np.asarray(value, dtype=float))
            except (TypeError, ValueError):
                raise TypeError(f"{name} must be quaternions of 4 numbers ({order}), got {value!r}") from None
            if array.shape[-1] != 4:
                raise TypeError(f"{name} must be quaternions of 4 numbers ({order}), got shape {array.shape}")
            arrays.append(array)
        try:
            a, b = np.broadcast_arrays(*arrays)
        except ValueError:
            raise ValueError(f"q0 and qf must hold as many quaternions (or one of them one), got shapes "
                             f"{arrays[0].shape} and {arrays[1].shape}") from None
        given, given_f = a, b  # as the caller wrote them (messages)
        if self._scalar_last:  # [x, y, z, w] -> [w, x, y, z]
            a, b = a[..., [3, 0, 1, 2]], b[..., [3, 0, 1, 2]]
        for name, quaternions in (("q0", given), ("qf", given_f)):
            norms = np.linalg.norm(quaternions, axis=-1)
            bad = ~(np.abs(norms - 1.0) <= UNIT_TOLERANCE)
            if np.any(bad):
                row = int(np.argmax(bad))
                raise ValueError(f"{name}[{row}] must be a unit quaternion (norm within {UNIT_TOLERANCE:g} of 1), "
                                 f"got {quaternions.reshape(-1, 4)[row].tolist()} (norm {norms.ravel()[row]:.6g})")
        if self._identity_only:
            vector = np.sum(a[..., 1:] ** 2, axis=-1)
            bad = vector > self._identity_vsq * np.sum(a ** 2, axis=-1)
            if np.any(bad):
                row = int(np.argmax(bad.ravel()))
                q = a.reshape(-1, 4)[row]
                raise _identity_error(f"q0[{row}]", given.reshape(-1, 4)[row].tolist(),
                                      2.0 * math.atan2(math.sqrt(float(vector.ravel()[row])), abs(float(q[0]))),
                                      self.quaternion_order)
        axes, angles = relative_axis_angle(a, b)
        return self.many_axis_angle(axes, angles)

    # --- storage ---------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """The fit's parameters as plain data (``fit.json``).

        Returns
        -------
        dict
            ``format``, ``model``, ``angles_rad``, ``axes`` (body frame), ``times_s`` (null where
            the entry is not ok), ``status`` (each entry's), ``g`` (T/√(θ s)) and ``dg_dangle``
            (its PCHIP slopes [1/rad], over each run of ok angles), ``triangles``,
            ``facets`` (the rows ``a_f`` of ``s(e)`` [s²/rad]), ``rate_facets`` (the rows ``b_f``
            of ``m(e)`` [s/rad]), ``inertia`` [kg m²], ``torque_generators`` [N m],
            ``momentum_generators`` [N m s], ``max_rate`` [rad/s] (null: none), ``end_cones``
            (boresight, direction, cosine of the half-angle, 1 keep-out / 0 keep-in, a row each),
            ``quaternion_order`` (the order the fit's call reads quaternions in) and ``meta``.
        """
        return {"format": FIT_FORMAT,
                "model": "T(e, θ) = b(e, θ) · g(e, θ), b = √(θ s) if θ m² <= s else (θ m + s/m)/2 (half the "
                         "eigenaxis bang-coast-bang time), s(e) = max_f |facets_f · e|, m(e) = max(max_f "
                         "|rate_facets_f · e|, 1/max_rate); g: PCHIP in θ per axis, linear (barycentric, gnomonic) "
                         "over the triangles",
                "angles_rad": self.angles.tolist(), "axes": self.axes.tolist(), "times_s": _plain(self.times),
                "status": self.status.tolist(),
                "g": _plain(self._g), "dg_dangle": _plain(self._dg), "triangles": self.triangles.tolist(),
                "facets": self.facets.tolist(), "rate_facets": self.rate_facets.tolist(),
                "inertia": self.inertia.tolist(), "torque_generators": self.generators.tolist(),
                "momentum_generators": self.momentum_generators.tolist(), "max_rate": self.max_rate,
                "end_cones": self.end_cones.tolist(), "quaternion_order": self.quaternion_order, "meta": self.meta}

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write :meth:`to_dict` as JSON.

        Parameters
        ----------
        path : str or os.PathLike
            The file to write.
        """
        Path(path).write_text(json.dumps(self.to_dict(), indent=1, allow_nan=False) + "\n")

    def __repr__(self) -> str:
        return (f"<SlewTimeFit: {len(self.axes)} axes x {len(self.angles)} angles "
                f"({np.rad2deg(self.angles[0]):g}..{np.rad2deg(self.angles[-1]):g} deg), quaternions "
                f"{self.quaternion_order.replace('_', ' ')}>")


def _plain(values: np.ndarray) -> list[Any]:
    """An array as nested lists with None for NaN (JSON has no NaN)."""
    return [[v if math.isfinite(v) else None for v in row] for row in values.tolist()]


def fit_table(angles: ArrayLike, axes: ArrayLike, times: ArrayLike, meta: dict[str, Any] | None = None,
              inertia: ArrayLike | None = None, generators: ArrayLike | None = None,
              triangles: ArrayLike | None = None, status: ArrayLike | None = None,
              momentum_generators: ArrayLike | None = None, max_rate: float | None = None,
              end_cones: ArrayLike | None = None, quaternion_order: str = "scalar_first") -> SlewTimeFit:
    """Fit a slew table (module docstring).

    Parameters
    ----------
    angles : array_like, shape (k,)
        Slew angles [rad], increasing, in (0, π].
    axes : array_like, shape (n, 3)
        Eigen-axes, body frame, spanning the sphere.
    times : array_like, shape (n, k)
        Slew times [s].
    meta : dict, optional
        Kept with the fit.
    inertia : array_like, shape (3, 3), optional
        Inertia [kg m²], body frame.
    generators : array_like, shape (m, 3), optional
        Working actuators' torque directions times bounds [N m], body frame.
    triangles : array_like of int, shape (t, 3), optional
        Triangles over the axes; None: their convex hull.
    status : array_like of str, shape (n, k), optional
        Each entry's status; None: all ``ok``.
    momentum_generators : array_like, shape (m, 3), optional
        Working wheels' axes times momentum bounds [N m s], body frame (no other momentum sink).
    max_rate : float, optional
        Body-rate bound [rad/s].
    end_cones : array_like, shape (c, 8), optional
        The pointing requirements' cones at the end of a slew (:class:`SlewTimeFit`).
    quaternion_order : {"scalar_first", "scalar_last"}, optional
        The order the fit's call reads quaternions in (:class:`SlewTimeFit`).

    Returns
    -------
    SlewTimeFit
        The fit.
    """
    return SlewTimeFit(angles, axes, times, meta, inertia, generators, triangles, status, momentum_generators,
                       max_rate, end_cones, quaternion_order)


def load_fit(path: str | os.PathLike[str], quaternion_order: str | None = None) -> SlewTimeFit:
    """Read a ``fit.json`` written by ``slewbench table``.

    Parameters
    ----------
    path : str or os.PathLike
        The ``fit.json`` file, or the table's output directory holding it.
    quaternion_order : {"scalar_first", "scalar_last"} or None, optional
        The order the fit's call reads quaternions in: ``[w, x, y, z]`` or ``[x, y, z, w]``; None:
        the file's ``quaternion_order`` (``scalar_first`` in a file written without one).

    Returns
    -------
    SlewTimeFit
        The fit; call it as ``fit(q0, qf)`` (quaternions body to inertial, in
        :attr:`SlewTimeFit.quaternion_order`) [s].

    Raises
    ------
    ValueError
        The file is not a slew-time fit of this format, or one that filled entries that were not
        ``ok`` (written before the fit kept them as gaps), or one of slews from the identity only
        without ``end_cones`` (written before the fit checked end attitudes); a quaternion order
        (given, or the file's) other than ``scalar_first`` or ``scalar_last``; a file that is not
        JSON, or whose parameters are missing or unreadable (an edited file); each names the file.
    """
    file = Path(path)
    if file.is_dir():
        file = file / "fit.json"
    try:
        data = json.loads(file.read_text())
    except json.JSONDecodeError as error:  # a file cut short, or another file given
        raise ValueError(f"{file} is not a slewbench slew-time fit: not JSON ({error})") from None
    if not isinstance(data, dict) or data.get("format") != FIT_FORMAT:
        raise ValueError(f"{file} is not a slewbench slew-time fit ({FIT_FORMAT!r} expected)")
    note = str((data.get("meta") or {}).get("note", ""))
    if "status" not in data and ("not ok filled" in note or "axes left out" in note):
        raise ValueError(f"{file} was written by an earlier slewbench that filled the entries that are not ok "
                         "(or covered axes it left out) with times the table did not find; run `slewbench table` "
                         "again into the same --out (the entries are stored: nothing is solved again) to write "
                         "the fit with its gaps")
    if "end_cones" not in data and (data.get("meta") or {}).get("from_identity_only"):
        raise ValueError(f"{file} was written by an earlier slewbench whose fit did not check a slew's end attitude "
                         "against the pointing requirements (it gave times for slews ending inside a keep-out "
                         "cone); run `slewbench table` again to write the fit with the check")
    order = quaternion_order if quaternion_order is not None else data.get("quaternion_order", "scalar_first")
    if order not in QUATERNION_ORDERS:
        where = "quaternion_order" if quaternion_order is not None else f"{file}'s quaternion_order"
        raise ValueError(f"{where} must be one of {', '.join(QUATERNION_ORDERS)}, got {order!r}")
    try:
        times = np.array(data["times_s"], dtype=float)  # null (an entry not ok) -> NaN
        return SlewTimeFit(data["angles_rad"], data["axes"], times, data.get("meta"), data.get("inertia"),
                           data.get("torque_generators"), data.get("triangles"), data.get("status"),
                           data.get("momentum_generators"), data.get("max_rate"), data.get("end_cones"), order)
    except KeyError as error:  # an edited file: its parameters are not the fit's
        raise ValueError(f"{file} is not a complete slew-time fit: no {error.args[0]!r}; run `slewbench table` "
                         "again into the table's --out to write it") from None
    except (TypeError, ValueError) as error:
        raise ValueError(f"{file} holds a slew-time fit whose parameters cannot be read ({error}); run `slewbench "
                         "table` again into the table's --out to write it") from None
