"""Any planner's reference as a table, and the one interpolation that reads it in Python and in C.

A table holds rows ``[q*, ω*, ω̇*, τ*]`` (13 numbers, :data:`~ocp.dynamics.layout.REFERENCE_FIELDS`)
at increasing times ``t_0 = 0 < … < t_{N-1} = t_end``. ``t_end`` is the reference's duration ``T``,
or later (``tabulate(..., end=)``: ``slewbench codegen`` tabulates through the closed-loop window
and one sample, all the times the loop reads): after ``T`` the table holds what the reference gives
there, its torque-free coast (:meth:`planners.reference.Reference.sample`: ``ω̇ = −I⁻¹ ω × I ω``,
torque zero). Past ``t_end`` the interpolation holds the last row (``t`` is clamped), in Python as
in C; :class:`TableReference` does the same.

The manoeuvre ``[0, T]`` and the coast ``[T, t_end]`` are tabulated apart, each on a uniform grid
refined by halving (from 32 intervals over the manoeuvre, from one over the coast) until the
interpolation meets the tolerances inside every interval (or the grid reaches its cap, which the
table then says). The manoeuvre's grid holds the reference's own points (``Reference.enforced_times``:
collocation's nodes) and its ``breakpoints``, each with a node one double before it (the left
limit) and one double after it (the right limit), so that a jump of ``ω`` or ``ω̇`` is not smeared;
at the breakpoint itself the node holds what the reference gives there (one side of the jump, by the
reference's own convention: ``natural_motion``'s step stop gives the arc's rate at the stop time),
so the table and the reference agree at that time too (a closed loop sampled on the breakpoint, or
one sample before it with the hold-averaged feed-forward, reads the same row in C as in Python).
The coast starts at the next double after ``T`` (``T`` itself is the manoeuvre's last node: at ``T``
the table gives what the reference gives at ``T``, the manoeuvre's torque, and from the next double
on the coast's).

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
that is not a declared breakpoint), and at every node (the breakpoints' included, where the side of
a jump the table gives is checked). The tolerances are checked on the same points.
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

QUANTITIES = ("attitude", "rate", "omega_dot", "torque")
"""The quantities a table's error is stated for, in :class:`TableError`'s order."""

__all__ = ["QUANTITIES", "ReferenceTable", "TableError", "TableReference", "TableTolerance", "interpolate", "segment_function", "tabulate"]


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
        Cap on each uniform grid's intervals (the manoeuvre's and the coast's; default 4096); a
        table that reaches it without meeting the tolerances says so (:attr:`TableError.met`).
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
    failed : tuple of str, optional
        The quantities over their tolerance, among :data:`QUANTITIES` (empty when ``met``).
    allowed : tuple of float, optional
        The largest error each quantity of :data:`QUANTITIES` may have (the relative tolerances
        times their scale): attitude [rad], rate [rad/s], ``ω̇`` [rad/s^2], torque [N m]; empty
        when not known.
    """

    attitude_rad: float
    rate: float
    acceleration: float
    torque: float
    points: int
    met: bool
    failed: tuple[str, ...] = ()
    allowed: tuple[float, ...] = ()

    def summary(self) -> str:
        """The four errors in one line, and which quantities miss their tolerance.

        Returns
        -------
        str
            ``attitude error 3.1e-08 rad, rate 2e-09 rad/s, omega_dot 1e-05 rad/s^2, torque 1e-05 N m``,
            then `` (tolerances NOT met: omega_dot over 3.4e-06 rad/s^2)`` when some are not met.
        """
        text = (f"attitude error {self.attitude_rad:.2g} rad, rate {self.rate:.2g} rad/s, "
                f"omega_dot {self.acceleration:.2g} rad/s^2, torque {self.torque:.2g} N m")
        if self.met:
            return text
        limits = dict(zip(QUANTITIES, self.allowed))
        units = dict(zip(QUANTITIES, ("rad", "rad/s", "rad/s^2", "N m")))
        failed = [name + (f" over {limits[name]:.2g} {units[name]}" if name in limits else "") for name in self.failed]
        return text + f" (tolerances NOT met: {', '.join(failed) or 'see README.md'})"


@dataclass(frozen=True)
class ReferenceTable:
    """A reference as rows at nodes (module docstring).

    Parameters
    ----------
    times : (N,) ndarray
        Node times [s], non-decreasing (``tabulate`` gives increasing ones), ``N ≥ 2``.
    rows : (N, 13) ndarray
        ``[q (4, scalar first, body to inertial; signs continuous), ω (3) rad/s, ω̇ (3) rad/s^2,
        τ (3) N m]`` at the nodes, body axes.
    duration : float or None, optional
        The tabulated reference's duration ``T`` [s]; after it the rows are the reference's
        torque-free coast. ``None`` (default): the last node's time.
    """

    times: Array
    rows: Array
    duration: float | None = None

    @property
    def end(self) -> float:
        """The last node's time [s]: past it the interpolation holds the last row."""
        return float(self.times[-1])

    @property
    def manoeuvre_duration(self) -> float:
        """The tabulated reference's duration ``T`` [s] (:attr:`duration`, else :attr:`end`)."""
        return self.end if self.duration is None else float(self.duration)

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


def _nodes(reference: Reference, intervals: int, start: float = 0.0, stop: float | None = None) -> tuple[Array, Array]:
    """Times and rows over ``[start, stop]``: a uniform grid, the reference's own points and its
    breakpoints, each flanked by the doubles next to it (those inside the span, a breakpoint at
    ``start`` or ``stop`` included); ``stop`` defaults to the reference's duration."""
    stop = reference.duration if stop is None else stop
    own = [] if reference.enforced_times is None else [t for t in reference.enforced_times if start <= t <= stop]
    breaks = [b for b in reference.breakpoints if start < b < stop]
    fixed = np.unique(np.clip(np.asarray([start, stop, *own, *breaks], dtype=float), start, stop))
    grid = np.linspace(start, stop, intervals + 1)
    gap = 1e-9 * max(stop - start, abs(stop), 1e-300)
    near = np.min(np.abs(grid[:, None] - fixed[None, :]), axis=1) <= gap
    times = np.unique(np.concatenate([fixed, grid[~near]]))
    # the left limit one double before each breakpoint and the right limit one double after it, those
    # inside the span: a step at ``stop`` (a stop at T) keeps its left limit, one at ``start`` its right
    at = np.asarray([b for b in reference.breakpoints if start <= b <= stop], dtype=float)
    if at.size:
        times = np.unique(np.concatenate([times, np.nextafter(at[at > start], -np.inf),
                                          np.nextafter(at[at < stop], np.inf)]))
    # at a breakpoint itself the node holds what the reference gives there (one side of the jump, the
    # reference's own convention), so that the table and the reference agree at that time too
    rows = _rows(reference, times)
    rows[:, 0:4] = quat.continuous(quat.normalize(rows[:, 0:4]))
    return times, rows


def _scales(rows: Array) -> list[float]:
    """The largest component of ``ω``, ``ω̇`` and ``τ`` in ``rows``."""
    return [float(np.max(np.abs(rows[:, a:b]))) for a, b in ((4, 7), (7, 10), (10, 13))]


def _refined(reference: Reference, tolerance: TableTolerance, start: float, stop: float, intervals: int,
             floor: list[float] | None = None) -> ReferenceTable:
    """The smallest uniform refinement of ``[start, stop]`` (from ``intervals``, halving) whose error
    meets ``tolerance``, relative to the larger of its own scales and ``floor``; the finest allowed
    if none does."""
    while True:
        times, rows = _nodes(reference, intervals, start, stop)
        table = ReferenceTable(times, rows)
        scales = _scales(rows) if floor is None else [max(a, b) for a, b in zip(_scales(rows), floor)]
        if _error(reference, table, tolerance, scales).met or 2 * intervals > tolerance.max_intervals:
            return table
        intervals *= 2


def _error(reference: Reference, table: ReferenceTable, tolerance: TableTolerance,
           scales: list[float]) -> TableError:
    """:func:`table_error` with the scales of the relative tolerances given."""
    times = table.times
    h = np.diff(times)
    inside = h > 0
    # the nodes too: at a breakpoint's node the reference gives one side of its jump, which the table must give
    mid = np.concatenate([(times[:-1][inside, None] + CHECK_POINTS[None, :] * h[inside, None]).ravel(), times])
    exact = _rows(reference, mid)
    got = table.evaluate(mid)
    angle = float(np.max(quat.error_angle(got[:, 0:4], exact[:, 0:4])))
    errors = [float(np.max(np.abs(got[:, a:b] - exact[:, a:b]))) for a, b in ((4, 7), (7, 10), (10, 13))]
    allowed = (tolerance.attitude_rad, tolerance.rate * scales[0] + 1e-15, tolerance.linear * scales[1] + 1e-15,
               tolerance.linear * scales[2] + 1e-15)
    failed = tuple(name for name, error, limit in zip(QUANTITIES, [angle, *errors], allowed) if error > limit)
    return TableError(angle, errors[0], errors[1], errors[2], int(mid.size), not failed, failed, allowed)


def table_error(reference: Reference, table: ReferenceTable, tolerance: TableTolerance) -> TableError:
    """A table's error against its reference at :data:`CHECK_POINTS` of every interval.

    Parameters
    ----------
    reference : Reference
        The continuous reference (after its duration: its torque-free coast).
    table : ReferenceTable
        Its table.
    tolerance : TableTolerance
        What the table must meet (the relative ones against the table's largest components).

    Returns
    -------
    TableError
        The largest errors, whether they meet ``tolerance`` and which do not.
    """
    return _error(reference, table, tolerance, _scales(table.rows))


def tabulate(reference: Reference, tolerance: TableTolerance | None = None,
             end: float | None = None) -> tuple[ReferenceTable, TableError]:
    """A reference as a table meeting ``tolerance`` inside every interval (module docstring).

    Parameters
    ----------
    reference : Reference
        A planned reference (``status == "ok"``).
    tolerance : TableTolerance or None, optional
        What the table must meet; ``None``: the defaults.
    end : float or None, optional
        The table's last time [s]; after the reference's duration ``T`` the rows are its
        torque-free coast (:meth:`~planners.reference.Reference.sample`). ``None`` or at most ``T``:
        the table ends at ``T``.

    Returns
    -------
    table : ReferenceTable
        The manoeuvre ``[0, T]`` as the smallest uniform refinement (from 32 intervals, halving)
        that meets ``tolerance``, with the reference's own points and breakpoints; then, when
        ``end > T``, the coast from the next double after ``T`` to ``end``, refined the same way
        from one interval; each the finest allowed if none meets ``tolerance``.
    error : TableError
        Its error against ``reference`` at :data:`CHECK_POINTS` of every interval.
    """
    tolerance = tolerance or TableTolerance()
    duration = reference.duration
    manoeuvre = _refined(reference, tolerance, 0.0, duration, 32)
    times, rows = manoeuvre.times, manoeuvre.rows
    if end is not None and end > duration:
        after = float(np.nextafter(duration, np.inf))
        coast = _refined(reference, tolerance, after, max(float(end), after), 1, _scales(rows))
        times = np.concatenate([times, coast.times])
        rows = np.concatenate([rows, coast.rows])
        rows[:, 0:4] = quat.continuous(rows[:, 0:4])
    table = ReferenceTable(times, rows, duration)
    return table, table_error(reference, table, tolerance)


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
    exactly what the C reads, at every time: the table's interpolation (:func:`interpolate`) on its
    whole span, the coast after ``T`` included, and its last row held past its end, as
    ``slewbench_reference_row`` in C (not the torque-free continuation other references give after
    their duration).

    Parameters
    ----------
    table : ReferenceTable
        The table.
    inertia : (3, 3) array_like
        Body inertia [kg m^2], body axes.
    planner : str, optional
        The planner that made the tabulated reference.

    Notes
    -----
    Its :attr:`duration` is the tabulated reference's ``T`` (:attr:`ReferenceTable.manoeuvre_duration`),
    so that the closed loop's window and metrics are those of the reference.
    """

    def __init__(self, table: ReferenceTable, inertia: ArrayLike, planner: str = "table") -> None:
        super().__init__(planner, table.manoeuvre_duration, inertia)
        self.table = table

    def _evaluate(self, t: Array) -> ReferenceSample:
        rows = self.table.evaluate(t)
        return ReferenceSample(rows[:, 0:4], rows[:, 4:7], rows[:, 7:10], rows[:, 10:13])

    def sample(self, t: ArrayLike) -> ReferenceSample:
        """The table's rows at ``t``, at any time (clamped to the table, as the C clamps it).

        Parameters
        ----------
        t : float or array_like
            Time [s] or array of times (flattened if not 1-D).

        Returns
        -------
        ReferenceSample
            ``q`` (4,), ``omega``, ``omega_dot``, ``torque`` (3,) for a scalar ``t``; ``(N, 4)`` and
            ``(N, 3)`` for ``N`` times.
        """
        times = np.atleast_1d(np.asarray(t, dtype=float)).ravel()
        sample = self._checked(times)
        if np.ndim(t) == 0:
            return ReferenceSample(*(a[0] for a in sample))
        return sample
