"""Any planner's reference as a table, and the one interpolation that reads it in Python and in C.

A table holds rows ``[q*, ω*, ω̇*, τ*]`` (13 numbers, :data:`~ocp.dynamics.layout.REFERENCE_FIELDS`)
at increasing times ``t_0 = 0 < … < t_{N-1} = T``. Its nodes are a uniform grid, refined by halving
until the interpolation meets the tolerances inside every interval (or the node count
reaches its cap, which the table then says), together with the reference's own points
(``Reference.enforced_times``: collocation's nodes) and its ``breakpoints``, where the node is
doubled (the left and the right limits at the same time) so that a jump of ``ω̇`` is not smeared.

Interpolation (:func:`interpolate` in NumPy, :func:`segment_function` in CasADi, generated as C):
with ``k`` the last node such that ``t_k ≤ t`` (``t`` clamped to ``[t_0, t_{N-1}]``, ``k`` at most
``N - 2``), ``h = t_{k+1} − t_k`` and ``s = (t − t_k)/h``,

* ``q``: cubic Hermite between the nodes' quaternions with the kinematic derivatives
  ``q̇ = ½ q ⊗ [0, ω]``, then renormalised;
* ``ω``: cubic Hermite with the nodes' ``ω̇`` as derivatives;
* ``ω̇`` and ``τ``: linear.

The table states its error against the continuous reference (:class:`TableError`), the largest over
seven points of every interval (:data:`CHECK_POINTS`): the midpoint, where the Hermite and the linear
interpolation errors of a smooth function peak, and six more for a kink inside an interval (a switch
that is not a declared breakpoint). The tolerances are checked on the same points.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.dynamics.layout import REFERENCE_FIELDS
from planners.reference import Reference, ReferenceSample

Array = NDArray[np.float64]
CHECK_POINTS = np.arange(1, 8) / 8.0
"""Where in each interval (fractions ``s`` of its length) a table's error is measured: the midpoint,
where a smooth function's interpolation error peaks, and six more points, for the intervals that
hold a kink of the reference that is no declared breakpoint (a switch inside an interval)."""

__all__ = ["ReferenceTable", "TableError", "TableReference", "TableTolerance", "interpolate", "segment_function", "tabulate"]


@dataclass(frozen=True)
class TableTolerance:
    """What a table must meet at :data:`CHECK_POINTS` of every interval.

    Parameters
    ----------
    attitude_rad : float, optional
        Largest attitude error angle [rad] (default 1e-6 rad, 0.2″).
    rate : float, optional
        Largest body-rate error, relative to the largest ``|ω*|`` component of the reference
        (default 1e-6).
    linear : float, optional
        Largest error of ``ω̇*`` and ``τ*`` (linearly interpolated), each relative to its own
        largest component (default 1e-3).
    max_intervals : int, optional
        Cap on the uniform grid's intervals (default 4096); a table that reaches it without meeting
        the tolerances says so (:attr:`TableError.met`).
    """

    attitude_rad: float = 1e-6
    rate: float = 1e-6
    linear: float = 1e-3
    max_intervals: int = 4096


@dataclass(frozen=True)
class TableError:
    """A table's error against the continuous reference, largest over :data:`CHECK_POINTS` of every interval.

    Parameters
    ----------
    attitude_rad : float
        Largest attitude error angle [rad].
    rate : float
        Largest body-rate error [rad/s], any component.
    acceleration : float
        Largest ``ω̇`` error [rad/s^2], any component.
    torque : float
        Largest feed-forward torque error [N m], any component.
    points : int
        Times checked.
    met : bool
        Whether the tolerances were met.
    """

    attitude_rad: float
    rate: float
    acceleration: float
    torque: float
    points: int
    met: bool


@dataclass(frozen=True)
class ReferenceTable:
    """A reference as rows at nodes (module docstring).

    Parameters
    ----------
    times : (N,) ndarray
        Node times [s], non-decreasing (a time appears twice at a breakpoint), ``N ≥ 2``.
    rows : (N, 13) ndarray
        ``[q (4, scalar first, body to inertial; signs continuous), ω (3) rad/s, ω̇ (3) rad/s^2,
        τ (3) N m]`` at the nodes, body axes.
    """

    times: Array
    rows: Array

    def evaluate(self, t: ArrayLike) -> Array:
        """The interpolated rows (:func:`interpolate`).

        Parameters
        ----------
        t : float or (M,) array_like
            Times [s] (clamped to the table's span).

        Returns
        -------
        (M, 13) ndarray
            Interpolated rows, layout as :attr:`rows`.
        """
        return interpolate(self.times, self.rows, t)


def _kinematics(q: Array, omega: Array) -> Array:
    """``½ q ⊗ [0, ω]`` row by row, written out as the CasADi form writes it."""
    q0, q1, q2, q3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    w0, w1, w2 = omega[..., 0], omega[..., 1], omega[..., 2]
    return 0.5 * np.stack([-q1 * w0 - q2 * w1 - q3 * w2,
                           q0 * w0 + q2 * w2 - q3 * w1,
                           q0 * w1 + q3 * w0 - q1 * w2,
                           q0 * w2 + q1 * w1 - q2 * w0], axis=-1)


def interval_index(times: Array, t: Array) -> Array:
    """The interval of each time: the last ``k`` with ``t_k ≤ t``, within ``[0, N - 2]``.

    Parameters
    ----------
    times : (N,) ndarray
        Node times [s], non-decreasing.
    t : (M,) ndarray
        Times [s], already clamped to ``[t_0, t_{N-1}]``.

    Returns
    -------
    (M,) ndarray of int
    """
    return np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)


def interpolate(times: ArrayLike, rows: ArrayLike, t: ArrayLike) -> Array:
    """The table interpolation in NumPy (module docstring), the twin of the generated C.

    Parameters
    ----------
    times : (N,) array_like
        Node times [s], non-decreasing, ``N ≥ 2``.
    rows : (N, 13) array_like
        Rows ``[q, ω, ω̇, τ]`` at the nodes.
    t : float or (M,) array_like
        Times [s]; clamped to ``[t_0, t_{N-1}]``.

    Returns
    -------
    (M, 13) ndarray
        Interpolated rows: unit ``q`` (scalar first, body to inertial), ``ω`` [rad/s], ``ω̇``
        [rad/s^2], ``τ`` [N m], body axes.
    """
    times = np.asarray(times, dtype=float)
    rows = np.asarray(rows, dtype=float)
    at: Array = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), times[0], times[-1])
    k = interval_index(times, at)
    t0, t1 = times[k], times[k + 1]
    a, b = rows[k], rows[k + 1]
    h = t1 - t0
    s = np.where(h > 0, (at - t0) / np.where(h > 0, h, 1.0), 0.0)
    s2, s3 = s * s, s * s * s
    h00 = (2 * s3 - 3 * s2 + 1)[:, None]
    h10 = ((s3 - 2 * s2 + s) * h)[:, None]
    h01 = (-2 * s3 + 3 * s2)[:, None]
    h11 = ((s3 - s2) * h)[:, None]
    q = h00 * a[:, 0:4] + h10 * _kinematics(a[:, 0:4], a[:, 4:7]) + h01 * b[:, 0:4] \
        + h11 * _kinematics(b[:, 0:4], b[:, 4:7])
    q = q / np.sqrt(np.sum(q * q, axis=1))[:, None]
    omega = h00 * a[:, 4:7] + h10 * a[:, 7:10] + h01 * b[:, 4:7] + h11 * b[:, 7:10]
    linear = (1 - s)[:, None] * a[:, 7:13] + s[:, None] * b[:, 7:13]
    return np.concatenate([q, omega, linear], axis=1)


def segment_function(name: str = "slewbench_segment") -> ca.Function:
    """The interpolation inside one interval as a CasADi function (generated as C).

    Parameters
    ----------
    name : str, optional
        The function's (and the C symbol's) name.

    Returns
    -------
    casadi.Function
        ``segment(t, t0, t1, row0, row1) -> row``: times [s], the rows (13) at ``t0`` and ``t1``,
        the interpolated row at ``t`` (module docstring; ``s = 0`` when ``t1 = t0``).
    """
    t, t0, t1 = ca.SX.sym("t"), ca.SX.sym("t0"), ca.SX.sym("t1")
    a, b = ca.SX.sym("row0", REFERENCE_FIELDS), ca.SX.sym("row1", REFERENCE_FIELDS)
    h = t1 - t0
    s = ca.if_else(h > 0, (t - t0) / ca.if_else(h > 0, h, 1.0), 0.0)
    s2, s3 = s * s, s * s * s
    h00, h10, h01, h11 = 2 * s3 - 3 * s2 + 1, (s3 - 2 * s2 + s) * h, -2 * s3 + 3 * s2, (s3 - s2) * h

    def kinematics(q: ca.SX, w: ca.SX) -> ca.SX:
        return 0.5 * ca.vertcat(-q[1] * w[0] - q[2] * w[1] - q[3] * w[2],
                                q[0] * w[0] + q[2] * w[2] - q[3] * w[1],
                                q[0] * w[1] + q[3] * w[0] - q[1] * w[2],
                                q[0] * w[2] + q[1] * w[1] - q[2] * w[0])

    q = h00 * a[0:4] + h10 * kinematics(a[0:4], a[4:7]) + h01 * b[0:4] + h11 * kinematics(b[0:4], b[4:7])
    q = q / ca.sqrt(ca.sumsqr(q))
    omega = h00 * a[4:7] + h10 * a[7:10] + h01 * b[4:7] + h11 * b[7:10]
    linear = (1 - s) * a[7:13] + s * b[7:13]
    return ca.Function(name, [t, t0, t1, a, b], [ca.vertcat(q, omega, linear)],
                       ["t", "t0", "t1", "row0", "row1"], ["row"])


def _rows(reference: Reference, times: Array) -> Array:
    sample = reference.sample(times)
    return np.concatenate([sample.q, sample.omega, sample.omega_dot, sample.torque], axis=1)


def _nodes(reference: Reference, intervals: int) -> tuple[Array, Array]:
    """Times and rows: a uniform grid, the reference's own points, breakpoints doubled."""
    duration = reference.duration
    own = [] if reference.enforced_times is None else list(reference.enforced_times)
    breaks = [b for b in reference.breakpoints if 0.0 < b < duration]
    fixed = np.unique(np.clip(np.asarray([0.0, duration, *own, *breaks], dtype=float), 0.0, duration))
    grid = np.linspace(0.0, duration, intervals + 1)
    gap = 1e-9 * max(duration, 1e-300)
    near = np.min(np.abs(grid[:, None] - fixed[None, :]), axis=1) <= gap
    times = np.unique(np.concatenate([fixed, grid[~near]]))
    rows = _rows(reference, times)
    if breaks:  # the left limit at each breakpoint, then the right limit
        at = np.searchsorted(times, breaks)
        left = _rows(reference, np.nextafter(np.asarray(breaks), -np.inf))
        right = _rows(reference, np.nextafter(np.asarray(breaks), np.inf))
        rows[at] = right
        times = np.insert(times, at, breaks)
        rows = np.insert(rows, at, left, axis=0)
    rows[:, 0:4] = quat.continuous(quat.normalize(rows[:, 0:4]))
    return times, rows


def table_error(reference: Reference, table: ReferenceTable, tolerance: TableTolerance) -> TableError:
    """A table's error against its reference at :data:`CHECK_POINTS` of every interval.

    Parameters
    ----------
    reference : Reference
        The continuous reference.
    table : ReferenceTable
        Its table.
    tolerance : TableTolerance
        What the table must meet.

    Returns
    -------
    TableError
        The largest errors and whether they meet ``tolerance``.
    """
    times = table.times
    h = np.diff(times)
    inside = h > 0
    mid = (times[:-1][inside, None] + CHECK_POINTS[None, :] * h[inside, None]).ravel()
    exact = _rows(reference, mid)
    got = table.evaluate(mid)
    angle = float(np.max(quat.error_angle(got[:, 0:4], exact[:, 0:4])))
    errors = [float(np.max(np.abs(got[:, a:b] - exact[:, a:b]))) for a, b in ((4, 7), (7, 10), (10, 13))]
    all_rows = table.rows
    scale = [float(np.max(np.abs(all_rows[:, a:b]))) for a, b in ((4, 7), (7, 10), (10, 13))]
    met = (angle <= tolerance.attitude_rad and errors[0] <= tolerance.rate * scale[0] + 1e-15
           and all(e <= tolerance.linear * s + 1e-15 for e, s in zip(errors[1:], scale[1:])))
    return TableError(angle, errors[0], errors[1], errors[2], int(mid.size), bool(met))


def tabulate(reference: Reference, tolerance: TableTolerance | None = None) -> tuple[ReferenceTable, TableError]:
    """A reference as a table meeting ``tolerance`` inside every interval (module docstring).

    Parameters
    ----------
    reference : Reference
        A planned reference (``status == "ok"``).
    tolerance : TableTolerance or None, optional
        What the table must meet; ``None``: the defaults.

    Returns
    -------
    table : ReferenceTable
        The smallest uniform refinement (from 32 intervals, halving) that meets ``tolerance``, with
        the reference's own points and breakpoints; the finest allowed if none does.
    error : TableError
        Its error against ``reference`` at :data:`CHECK_POINTS` of every interval.
    """
    tolerance = tolerance or TableTolerance()
    intervals = 32
    while True:
        table = ReferenceTable(*_nodes(reference, intervals))
        error = table_error(reference, table, tolerance)
        if error.met or 2 * intervals > tolerance.max_intervals:
            return table, error
        intervals *= 2


def angle_text(radians: float) -> str:
    """An angle in degrees and arcseconds, for the README.

    Parameters
    ----------
    radians : float

    Returns
    -------
    str
    """
    return f"{math.degrees(radians):.3g} deg ({math.degrees(radians) * 3600:.3g} arcsec)"


class TableReference(Reference):
    """A table read as a :class:`~planners.reference.Reference`, to run the Python closed loop on
    exactly what the C reads.

    Parameters
    ----------
    table : ReferenceTable
        The table.
    inertia : (3, 3) array_like
        Body inertia [kg m^2], body axes (for the torque-free continuation after the table's end).
    planner : str, optional
        The planner that made the tabulated reference.
    """

    def __init__(self, table: ReferenceTable, inertia: ArrayLike, planner: str = "table") -> None:
        super().__init__(planner, float(table.times[-1]), inertia)
        self.table = table

    def _evaluate(self, t: Array) -> ReferenceSample:
        rows = self.table.evaluate(t)
        return ReferenceSample(rows[:, 0:4], rows[:, 4:7], rows[:, 7:10], rows[:, 10:13])
