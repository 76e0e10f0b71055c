r"""Pointing constraints: a body boresight kept out of (or inside) a cone about a direction.

:class:`PointingConstraint` is one requirement made concrete for one run: the sensor's body
boresight, the cone's half-angle, and the direction it is measured from, tabulated along the run
(a fixed inertial vector is a table of one row). The same object serves both sides of the
workbench:

* scoring (NumPy): :meth:`PointingConstraint.margins` and :meth:`PointingConstraint.score` on any
  sampled motion (a reference on its dense grid); :meth:`PointingConstraint.score_between_samples`
  on a motion known by its attitude and body rate at coarse samples (a closed loop), between which
  the attitude is interpolated (:func:`hermite_attitudes`); :func:`scores_between_samples` scores
  several constraints on one such motion together (each as alone);
* planning (CasADi): :meth:`PointingConstraint.expression` is the constraint ``g(q, t) <= 0`` a
  transcription imposes at its points (a moving direction is interpolated in time, as the IGRF
  field is).

Angles: the angle θ between the boresight in inertial axes ``R(q) b`` and the direction ``d(t)``;
the cone's limit is ``angle + growth(t)`` (``growth``: the Earth's apparent radius for a limb
constraint, else 0). The **margin** is ``θ − limit`` for a keep-out and ``limit − θ`` for a keep-in:
negative when the constraint is broken. A constraint applies only inside its window.
"""
from __future__ import annotations

import hashlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp import quat_casadi as qc

Array = NDArray[np.float64]

__all__ = [
    "COARSE_STEPS",
    "DEGENERATE_NORM",
    "FINE_STEP",
    "GROUP_REACH",
    "MAX_SUB_GRID",
    "MIN_SEARCHES",
    "REFINE_LEVELS",
    "REFINE_POINTS",
    "SAMPLE_GROUP",
    "HermiteMotion",
    "PointingConstraint",
    "PointingScore",
    "Searched",
    "hermite_attitudes",
    "scores_between_samples",
    "search_between_samples",
    "searches_between_samples",
    "violation_intervals",
]

FINE_STEP = np.deg2rad(0.05)
"""[rad]: the largest rotation of the attitude between two points of the sub-grid on which
:func:`search_between_samples` evaluates (each sample interval that may hide a crossing of the
threshold is cut into as many equal steps as its faster end's rate needs, at least 4)."""
COARSE_STEPS = 16
"""Steps of a sample interval that may hide a lower value but no crossing of the threshold (by the
bound of :func:`search_between_samples`): the smallest value there is searched further
(:data:`MIN_SEARCHES`), not the whole interval at :data:`FINE_STEP`."""
MIN_SEARCHES = 64
"""Brackets searched for a lower value at each zoom, the deepest by the bound first (every bracket
that may hide a crossing of the threshold is searched): the cost stays bounded when the bound
cannot exclude much (a boresight circling at a constant angle to the direction)."""
REFINE_POINTS = 65
"""Points of each zoom of :func:`search_between_samples` (the ends and 63 new ones: each zoom cuts a
bracket into 64 parts; one searched for a lower value goes on by the two about its least point,
one that may hide a crossing by every part the bound cannot clear)."""
REFINE_LEVELS = 3
"""Zooms of that search: a bracket ends ``32**3 ≈ 3.3e4`` (a lower value) or ``64**3 ≈ 2.6e5``
(a crossing) times narrower than a sub-grid step."""
SAMPLE_GROUP = 16
"""Samples of which :func:`search_between_samples` evaluates one first (fewer where the bound sums
to :data:`GROUP_REACH` over fewer): a group whose bound can neither cross the threshold nor go
below the least value found is not evaluated inside (a long run densely sampled far from the cone
costs a sixteenth of its samples)."""
GROUP_REACH = np.deg2rad(2.0)
"""[rad]: the most the bound may move the value over a group of samples evaluated first (a
group that may cross the threshold is cut into the fine sub-grid: at most this over
:data:`FINE_STEP`, or 4 steps a sample interval)."""
MAX_SUB_GRID = 2_000_000
"""The work limit of :func:`search_between_samples`: the points of its sub-grid, and of each zoom's
brackets that may hide a crossing. A search whose sub-grid at :data:`FINE_STEP` would exceed it (a
motion that turns more than about ``MAX_SUB_GRID * FINE_STEP`` = 1745 rad near the threshold: 40 s
at 44 rad/s) is cut coarser, every step in the same ratio, to at most this many points, and each of
its zooms goes on by its deepest such brackets only: a crossing shorter than the longest step of
that sub-grid (:attr:`Searched.missable_s`) may then be missed. A zoom of any search past it (a long
motion grazing the threshold: a 1 rad/s spin 0.01° from a cone's edge for 10 min) goes on by its
deepest brackets too, ``missable_s`` the longest left unsearched. Below it, the search is unchanged."""
DEGENERATE_NORM = 0.1
"""The interpolant's unnormalised norm below which an interval's rate is not bounded from its
polynomial (:attr:`HermiteMotion.rate_bound`): samples that disagree with their rates by about a
half turn, whose interpolant passes near zero; 1.5 times :attr:`HermiteMotion.turn_rate` is
used there."""


def hermite_attitudes(t: ArrayLike, q: ArrayLike, omega: ArrayLike, times: ArrayLike) -> Array:
    """The attitude between samples: a cubic Hermite in the quaternion through the samples, with the
    slopes ``q̇ = ½ q ⊗ [0, ω]`` of the body rates at both ends of each interval, normalised.

    Over an interval of length ``h`` its error is ``O(h⁴)`` where the motion is smooth inside the
    interval (a zero-order hold changes the torque only at the samples: the attitude and the rate
    are continuous across them). The samples are made sign-continuous first (``q`` and ``−q`` are one
    attitude). To evaluate one motion many times, build :class:`HermiteMotion` once.

    Parameters
    ----------
    t : (N,) array_like
        Increasing sample times [s], N >= 1.
    q : (N, 4) array_like
        Attitude at ``t`` (scalar first, body to inertial).
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s], body axes.
    times : (M,) array_like
        Where to evaluate [s], inside ``[t[0], t[-1]]`` (clipped to it).

    Returns
    -------
    (M, 4) ndarray
        Unit quaternions at ``times``; the samples themselves (normalised) at the sample times.
    """
    return HermiteMotion(t, q, omega).attitudes(times)


class HermiteMotion:
    """A motion known at samples by its attitude and body rate, interpolated as
    :func:`hermite_attitudes` does; the sign-continuous samples and their slopes are computed once.

    Parameters
    ----------
    t : (N,) array_like
        Increasing sample times [s], N >= 1.
    q : (N, 4) array_like
        Attitude at ``t`` (scalar first, body to inertial).
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s], body axes.
    """

    def __init__(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> None:
        self.t = np.atleast_1d(np.asarray(t, dtype=float))
        self.q = quat.continuous(np.atleast_2d(np.asarray(q, dtype=float)))
        self.omega = np.atleast_2d(np.asarray(omega, dtype=float))
        self.slope = quat.kinematics(self.q, self.omega)
        h = np.diff(self.t)
        self._inverse_h = np.divide(1.0, h, out=np.zeros_like(h), where=h > 0.0)  # a repeated time: its sample
        start, end = h[:, None] * self.slope[:-1], h[:, None] * self.slope[1:]
        q0, q1 = self.q[:-1], self.q[1:]
        # p(s) = c0 + c1 s + c2 s² + c3 s³ on each interval (K, power, component): the Hermite basis expanded
        self._cubic = np.stack([q0, start, -3.0 * q0 - 2.0 * start + 3.0 * q1 - end,
                                2.0 * q0 + start - 2.0 * q1 + end], axis=1)

    def attitudes(self, times: ArrayLike) -> Array:
        """The interpolated attitude.

        Parameters
        ----------
        times : (M,) array_like
            Where to evaluate [s], inside ``[t[0], t[-1]]`` (clipped to it).

        Returns
        -------
        (M, 4) ndarray
            Unit quaternions at ``times`` (scalar first, body to inertial).
        """
        t = self.t
        # np.minimum / np.maximum rather than np.clip: the same values, without np.clip's per-call overhead
        at = np.minimum(np.maximum(np.atleast_1d(np.asarray(times, dtype=float)), t[0]), t[-1])
        if len(t) == 1:
            return np.repeat(self.unit, len(at), axis=0)
        k = t.searchsorted(at, side="right")
        k -= 1
        np.minimum(np.maximum(k, 0, out=k), len(t) - 2, out=k)
        s = at - t[k]
        s *= self._inverse_h[k]
        s = s[:, None]
        c = self._cubic.take(k, axis=0)  # np.take: the rows of fancy indexing, faster
        # Horner in place: ((c3 s + c2) s + c1) s + c0, the same operations and values, fewer temporaries
        value = c[:, 3] * s
        value += c[:, 2]
        value *= s
        value += c[:, 1]
        value *= s
        value += c[:, 0]
        value /= np.sqrt(np.einsum("ij,ij->i", value, value))[:, None]
        return value

    def interval(self, times: ArrayLike) -> NDArray[np.intp]:
        """The sample interval holding each time (the later one at a sample; clipped to the span).

        Parameters
        ----------
        times : (M,) array_like
            Times [s].

        Returns
        -------
        (M,) ndarray of int
            Indices into :attr:`turn_rate` and :attr:`rate_bound`, in ``[0, N − 2]``.
        """
        at = np.atleast_1d(np.asarray(times, dtype=float))
        return np.minimum(np.maximum(np.searchsorted(self.t, at, side="right") - 1, 0), max(len(self.t) - 2, 0))

    @cached_property
    def turn_rate(self) -> Array:
        """Per sample interval [rad/s]: the larger of its faster end's ``‖ω‖`` and the mean rate of
        the turn between its samples (samples whose rates do not match their attitudes: the
        interpolant still turns); what sizes the sub-grid of :func:`search_between_samples`."""
        h = np.diff(self.t)
        norms = np.sqrt(np.add.reduce(self.omega * self.omega, axis=1))  # np.linalg.norm's own sum, without its overhead
        cosine = np.abs(np.einsum("ij,ij->i", self.q[:-1], self.q[1:]))
        chord = 2.0 * np.arccos(np.minimum(np.maximum(cosine, 0.0, out=cosine), 1.0, out=cosine), out=cosine)
        return np.maximum(np.maximum(norms[:-1], norms[1:]), np.divide(chord, h, out=np.zeros_like(h), where=h > 0.0))

    @cached_property
    def increasing(self) -> bool:
        """Whether the sample times increase strictly (no repeated time)."""
        return bool(np.all(self.t[1:] > self.t[:-1]))

    @cached_property
    def sample_steps(self) -> tuple[Array, Array, Array]:
        """The steps between the samples as :func:`search_between_samples` cuts them: their lengths,
        :attr:`rate_bound` and the sub-grid steps of at most :data:`FINE_STEP` (at least 4)."""
        if not self.increasing:  # a repeated time: the lookup of _knot_steps picks the later interval
            return _knot_steps(self, self.t)
        # strictly increasing samples: each step is its own sample interval, as _knot_steps finds it
        h = np.diff(self.t)
        return h, self.rate_bound, np.maximum(4, np.ceil(self.turn_rate * h / FINE_STEP)).astype(int)

    @cached_property
    def unit(self) -> Array:
        """(N, 4): the samples normalised (the interpolant at the sample times)."""
        return np.asarray(quat.normalize(self.q), dtype=float)

    @cached_property
    def rate_bound(self) -> Array:
        """Per sample interval [rad/s]: an upper bound on the interpolated attitude's angular rate.

        The interpolant is ``r = p / |p|`` with ``p(s) = c0 + c1 s + c2 s² + c3 s³`` the cubic of
        :meth:`attitudes` at ``s = (t − t_k) / h``; its rate is ``2 |ṙ| <= 2 max|p'| / (h min|p|)``
        over the interval, with ``max|p'|`` at most the largest norm of the control points
        ``c1, c1 + c2, c1 + 2 c2 + 3 c3`` of ``p'`` as a quadratic Bézier curve (it stays in their
        convex hull) and
        ``min|p| >= (|p(0)| + |p(1)| − max|p'|) / 2`` (each end less the way ``p`` can go): a bound,
        not an estimate, where that ``min|p|`` exceeds :data:`DEGENERATE_NORM`; elsewhere (samples
        a large part of a turn apart, or that disagree with their rates) 1.5 times
        :attr:`turn_rate`. 0 on an interval of zero length.
        """
        q, h = self.q, np.diff(self.t)
        if len(q) < 2:
            return np.zeros(0)
        c1, c2, c3 = self._cubic[:, 1], self._cubic[:, 2], self._cubic[:, 3]
        # p' as a quadratic Bézier curve: its control points c1, c1 + c2, c1 + 2 c2 + 3 c3, each norm
        # by its own sum of squares (not stacked: a (3, K, 4) sum costs some times more, same values)
        middle = c1 + c2
        last = c2 * 2.0
        last += c1
        last += 3.0 * c3
        slope_high = np.einsum("ij,ij->i", c1, c1)
        np.maximum(slope_high, np.einsum("ij,ij->i", middle, middle), out=slope_high)
        np.maximum(slope_high, np.einsum("ij,ij->i", last, last), out=slope_high)
        np.sqrt(slope_high, out=slope_high)
        ends = np.sqrt(np.einsum("ij,ij->i", q, q))
        low = 0.5 * (ends[:-1] + ends[1:] - slope_high)
        sound = low > DEGENERATE_NORM
        bound = np.divide(2.0 * slope_high, h * np.where(sound, low, 1.0), out=np.zeros_like(h), where=h > 0.0)
        return np.where(sound, bound, 1.5 * self.turn_rate)


def _may_cross(start: Array, end: Array, reach: Array, threshold: float | Array,
               smallest: float | Array) -> NDArray[np.bool_]:
    """Which brackets (values at their ends, ``reach``: their rate bound times their length) may go
    from one side of ``threshold`` to the other, or below ``smallest`` (NaN: no)."""
    mean, slack = 0.5 * (start + end), 0.5 * reach
    straddle = (np.fmin(start, end) < threshold) & (np.fmax(start, end) >= threshold)
    return straddle | ((mean - slack < threshold) & (mean + slack >= threshold)) | (mean - slack < smallest)


def search_between_samples(motion: HermiteMotion, value: Callable[[Array, Array], Array], threshold: float = -np.inf,
                           drift: float = 0.0, edges: Sequence[float] = ()) -> Searched:
    """The points where a function of the interpolated motion is evaluated to find its least value
    and every crossing of a threshold between the samples (a keep-out's margin below 0, the final
    error above its bound: one search for both).

    ``value(times, attitudes)`` must change no faster than ``motion.rate_bound + drift`` (per sample
    interval; NaN marks times where it does not apply). Between two points it then stays above the
    mean of their values less half the integral of that rate between them (the bound), and below
    the mean plus as much. All in array operations over every interval at once:

    1. the heads are evaluated: every :data:`SAMPLE_GROUP`-th sample, the ``edges`` inside the
       samples' span, and each sample where the bound's integral passes a multiple of
       :data:`GROUP_REACH`;
    2. a group between two heads whose bound lets it cross ``threshold`` (or has its heads on both
       sides) has each of its sample intervals cut into equal steps over which the attitude turns at
       most :data:`FINE_STEP` (by :attr:`HermiteMotion.turn_rate`, at least 4: its crossings are
       located on them); one that may only hide a value below the least found, into at most
       :data:`COARSE_STEPS`; the others stay one bracket, their samples not evaluated (a densely
       sampled reference far from the cone costs a sixteenth of its samples);
    3. :data:`REFINE_LEVELS` times, every bracket whose bound falls below ``threshold`` while
       neither end does, and the :data:`MIN_SEARCHES` whose bounds fall deepest below the least
       value found, are cut by :data:`REFINE_POINTS` points; the next brackets are all the parts of
       the former (a branch and bound: no part the bound cannot clear is dropped) and the two parts
       about the least point of the latter.

    A crossing of the threshold is never missed unless it goes less deep than the bound over the
    last brackets (``64**-3`` of a sub-grid step); a region between two points on the far side of
    the threshold may hide a return shorter than a sub-grid step (its time is counted on the far
    side). The least value is exact where the search reaches it, else within the bound over a step.

    Parameters
    ----------
    motion : HermiteMotion
        The motion (its samples' times span the search).
    value : callable
        ``value(times, attitudes) -> values``: (M,) times [s] and (M, 4) interpolated attitudes to
        (M,) values.
    threshold : float, optional
        The value below which a crossing must not be missed; ``-inf`` (default): the least value only.
    drift : float, optional
        What the value's rate may add to the attitude's [per s] (a moving direction's rate).
    edges : sequence of float, optional
        Times [s] that are points of the search when inside the samples' span (a window's edges).

    The work is limited (:data:`MAX_SUB_GRID`): beyond it the sub-grid is coarser or a zoom leaves
    its shallowest brackets, and the result says so (:attr:`Searched.missable_s`).

    Returns
    -------
    Searched
        ``(times, values)``: every point evaluated, in time order (the samples and edges first
        among them); with :attr:`~Searched.missable_s`.
    """
    return searches_between_samples(motion, [(value, threshold, drift, edges)])[0]


SearchSpec = tuple[Callable[[Array, Array], Array], float, float, Sequence[float]]
"""One search of :func:`searches_between_samples`: ``(value, threshold, drift, edges)`` as the
arguments of :func:`search_between_samples`."""


class Searched(tuple[Array, Array]):
    """``(times, values)``: the points a search between samples evaluated and their values, in time
    order; and :attr:`missable_s`.

    Attributes
    ----------
    missable_s : float
        [s]: 0 when the search ran in full; else (the work limit, :data:`MAX_SUB_GRID`, reached)
        the longest step of its sub-grid cut coarser or bracket a zoom left unsearched: a crossing
        of the threshold shorter than it may be missed.
    """

    missable_s: float

    def __new__(cls, times: Array, values: Array, missable_s: float = 0.0) -> Searched:
        found = super().__new__(cls, (times, values))
        found.missable_s = float(missable_s)
        return found


Together = Callable[[NDArray[np.intp], Array, Array], Array]
"""Every search's values in one call (:func:`searches_between_samples`): ``together(bounds, times,
attitudes)``, the points of search ``i`` being ``times[bounds[i]:bounds[i + 1]]`` (``bounds``: one more
than the searches), each point's value exactly what that search's own ``value`` gives."""


def searches_between_samples(motion: HermiteMotion, searches: Sequence[SearchSpec],
                             together: Together | None = None) -> list[Searched]:
    """Several searches of :func:`search_between_samples` on one motion (a row's pointing
    requirements), each exactly as alone: the same points, the same values.

    The searches' heads and sub-grids are found together, each on its own knots (one row of an
    array per search; the steps' sums per search, as alone) and evaluated together: the heads of
    every search in one call, then the new points of every sub-grid (their attitudes interpolated
    in one call) in one more; the refinement brackets then go through the zooms together (one
    array per zoom, each bracket tagged with its search; the least value, the threshold and the
    :data:`MIN_SEARCHES` deepest brackets counted per search), each zoom's points interpolated and
    evaluated in one call: the array operations are paid once for all the searches, not once for
    each.

    Parameters
    ----------
    motion : HermiteMotion
        The motion (its samples' times span the searches).
    searches : sequence of (value, threshold, drift, edges)
        Each as the arguments of :func:`search_between_samples`.
    together : callable or None, optional
        ``together(bounds, times, attitudes)``: every search's values in one call, the points of
        search ``i`` being ``times[bounds[i]:bounds[i + 1]]``, each value exactly that of the
        search's own ``value`` (:func:`scores_between_samples`: the margins of several constraints);
        ``None``: each search's ``value`` on its own points.

    Returns
    -------
    list of Searched
        Per search, as :func:`search_between_samples` returns.
    """
    count = len(searches)
    if not count:
        return []
    evaluate = _each(searches) if together is None else together
    t = motion.t
    if len(t) < 2:  # no step between knots: the samples alone
        values = evaluate(np.arange(count + 1, dtype=np.intp) * len(t), np.tile(t, count),
                          np.tile(motion.unit, (count, 1)))
        return [Searched(t, values[index * len(t):(index + 1) * len(t)]) for index in range(count)]
    results, opened = _sub_grids(motion, searches, evaluate)
    active = sorted(opened)
    if active:
        grids = [opened[index] for index in active]
        missable = [longest for _, _, _, longest in grids]
        found_t: list[list[Array]] = [[grid] for grid, _, _, _ in grids]
        found_v: list[list[Array]] = [[values] for _, values, _, _ in grids]
        # 3. the zooms, every search's brackets together
        _zoom(motion, evaluate, count, active, [float(searches[index][1]) for index in active],
              [(grid, values, rate) for grid, values, rate, _ in grids], found_t, found_v, missable)
        for slot, index in enumerate(active):
            if len(found_t[slot]) == 1:
                results[index] = Searched(found_t[slot][0], found_v[slot][0], missable[slot])
                continue
            times, values = np.concatenate(found_t[slot]), np.concatenate(found_v[slot])
            order = np.argsort(times, kind="stable")
            results[index] = Searched(times[order], values[order], missable[slot])
    return [result for result in results if result is not None]


def _each(searches: Sequence[SearchSpec]) -> Together:
    """``together`` of :func:`searches_between_samples` from each search's own ``value``."""
    def evaluate(bounds: NDArray[np.intp], times: Array, attitudes: Array) -> Array:
        values = np.empty(len(times))
        for index, (value, _, _, _) in enumerate(searches):
            span = slice(int(bounds[index]), int(bounds[index + 1]))
            if span.start < span.stop:
                values[span] = np.asarray(value(times[span], attitudes[span]), dtype=np.float64)
        return values
    return evaluate


def _sub_grids(motion: HermiteMotion, searches: Sequence[SearchSpec], evaluate: Together
               ) -> tuple[list[Searched | None], dict[int, tuple[Array, Array, Array, float]]]:
    """Steps 1 and 2 of :func:`search_between_samples` for every search at once (``motion`` of
    two samples or more): per search the final :class:`Searched` when nothing is left to zoom into
    (no head inside the value's domain), else ``None`` and (by search) its sub-grid, its values,
    the bound's rate on each of its steps and its longest step [s] when the work limit cut it
    coarser (:data:`MAX_SUB_GRID`; else 0).

    One row per search of arrays over the knots (the samples and the search's edges inside them,
    padded to the longest row), the column of the last knot a step of length 0: every sum runs
    over one search's own steps in its own order, so each value is that of the search alone."""
    t = motion.t
    count = len(searches)
    knots_of: list[Array] = []
    inner_of: list[list[float]] = []
    for _, _, _, edges in searches:
        inner = [float(edge) for edge in edges if t[0] < edge < t[-1]]
        inner_of.append(inner)
        # the samples increase (repeats allowed): np.unique only where an edge is inserted or a time repeats
        knots_of.append(t if not inner and motion.increasing else np.unique(np.concatenate([t, inner])))
    widths = np.array([len(knots) for knots in knots_of])
    width = int(widths.max())
    knots = np.empty((count, width))
    h = np.zeros((count, width))  # the steps between knots; 0 at the last knot and past it
    bound = np.zeros((count, width))
    fine_steps = np.ones((count, width), dtype=int)
    for index, row in enumerate(knots_of):
        size = len(row)
        knots[index, :size] = row
        knots[index, size:] = row[-1]
        # the knots' steps, their bound and their fine steps: the motion's own (built once for a row's
        # searches) when the knots are its samples
        own = row is t
        knot_steps = motion.sample_steps if own else _knot_steps(motion, row)
        h[index, :size - 1], bound[index, :size - 1], fine_steps[index, :size - 1] = knot_steps
    drift = np.array([float(search[2]) for search in searches])
    speed = bound + drift[:, None]  # per step between knots
    # the heads of groups of knot steps, evaluated first: every SAMPLE_GROUP-th knot, the edges, and
    # each knot where the bound's sum over the steps passes a multiple of GROUP_REACH
    moved = speed * h  # the bound's integral over each knot step
    turned = np.zeros((count, width))
    turned[:, 1:] = np.cumsum(moved, axis=1)[:, :-1]  # each row's own running sum (the later columns add 0)
    turned //= GROUP_REACH
    column = np.arange(width)
    head = np.zeros((count, width), dtype=bool)
    head[:, ::SAMPLE_GROUP] = True
    head[np.arange(count), widths - 1] = True
    head[:, 1:] |= turned[:, 1:] != turned[:, :-1]
    head &= column < widths[:, None]
    for index, inner in enumerate(inner_of):
        if inner:
            head[index, np.searchsorted(knots_of[index], inner)] = True
    flat_head = head.ravel()
    heads = np.flatnonzero(flat_head)  # into the rows end to end
    owner = heads // width
    flat_knots = knots.ravel()
    head_bounds = np.searchsorted(owner, np.arange(count + 1))
    # the heads' attitudes: the samples' (normalised) where a search's knots are the samples, else its
    # knots interpolated (an edge between samples); the samples normalised row by row, those of the heads alone
    if all(len(row) == len(t) for row in knots_of):
        head_attitudes = np.asarray(quat.normalize(motion.q.take(heads - owner * width, axis=0)), dtype=float)
    else:
        head_attitudes = np.empty((len(heads), 4))
        for index, row in enumerate(knots_of):
            span = slice(int(head_bounds[index]), int(head_bounds[index + 1]))
            head_attitudes[span] = (motion.unit if len(row) == len(t) else motion.attitudes(row)).take(
                heads[span] - index * width, axis=0)
    at_heads = evaluate(head_bounds, flat_knots[heads], head_attitudes)
    live = np.logical_or.reduceat(np.isfinite(at_heads), head_bounds[:-1])  # each search's heads: two or more
    # a search without a head inside its value's domain: nothing to zoom into
    results: list[Searched | None] = [
        None if alive else Searched(flat_knots[heads[start:stop]], at_heads[start:stop])
        for alive, start, stop in zip(live.tolist(), head_bounds[:-1].tolist(), head_bounds[1:].tolist())]
    # the groups between two heads of one search that goes on
    group = (owner[:-1] == owner[1:]) & live[owner[:-1]]
    first, after = heads[:-1][group], heads[1:][group]
    sizes = after - first
    reach = np.add.reduceat(moved.ravel(), heads[:-1])[group]  # the bound's integral over each group
    searched = owner[:-1][group]
    # each search's last knot: a step of its own in its last group (one point, known: a head; 0 long
    # and one step), so that the sub-grids of all searches are built end to end
    sizes_to_end = sizes + (after == searched * width + widths[searched] - 1)
    thresholds = np.array([float(search[1]) for search in searches])[searched]
    smallest = np.fmin.reduceat(at_heads, head_bounds[:-1])[searched]  # each search's least head (NaN: none)
    start, end = at_heads[:-1][group], at_heads[1:][group]
    with np.errstate(invalid="ignore"):
        crossing = _may_cross(start, end, reach, thresholds, -np.inf)
        deeper = _may_cross(start, end, reach, -np.inf, smallest)
    # a group that may cross the threshold: its knot steps cut into the fine sub-grid; one that may
    # hide a lower value: into at most COARSE_STEPS; the others keep their heads alone (one bracket)
    real = np.flatnonzero(((column < widths[:, None]) & live[:, None]).ravel())  # the live searches' steps
    fine = fine_steps.ravel()[real]
    cut = np.where(np.repeat(crossing, sizes_to_end), fine, np.minimum(COARSE_STEPS, fine))
    opened = np.repeat(crossing | deeper, sizes_to_end)
    steps = np.where(opened, cut, flat_head[real])
    rate = np.where(opened, speed.ravel()[real],
                    np.repeat(reach / (flat_knots[after] - flat_knots[first]), sizes_to_end))
    # each live search's steps: one run of those arrays (its last knot's the last of the run)
    step_bounds = np.concatenate([[0], np.cumsum(np.where(live, widths, 0))])
    flat_h = h.ravel()[real]
    longest = np.zeros(count)
    for index in np.flatnonzero(live).tolist():
        span = slice(int(step_bounds[index]), int(step_bounds[index + 1]) - 1)
        total = int(steps[span].sum())
        if total > MAX_SUB_GRID:  # the work limit: every opened step coarser in one ratio, at least one step each
            ratio = (MAX_SUB_GRID - len(steps[span])) / total
            cut[span] = np.maximum(1, np.floor(cut[span] * ratio)).astype(int)
            steps[span] = np.where(opened[span], cut[span], flat_head[real[span]])
            longest[index] = float(np.max(np.where(opened[span], flat_h[span] / cut[span], 0.0)))
    knot_of_step = real
    divided = flat_h / np.maximum(cut, 1)
    total = int(steps.sum())
    offset = np.arange(total) - np.repeat(np.cumsum(steps) - steps, steps)
    grid = np.repeat(flat_knots[knot_of_step], steps) + np.repeat(divided, steps) * offset
    rate = np.repeat(rate, steps)
    known = np.repeat(flat_head[knot_of_step], steps) & (offset == 0)
    values = np.empty(total)
    values[known] = at_heads[np.repeat(live, np.diff(head_bounds))]
    new = np.flatnonzero(~known)
    point_owner = np.repeat(knot_of_step // width, steps)
    if new.size:
        values[new] = evaluate(np.searchsorted(point_owner[new], np.arange(count + 1)), grid[new],
                               motion.attitudes(grid[new]))
    point_bounds = np.searchsorted(point_owner, np.arange(count + 1))
    grids: dict[int, tuple[Array, Array, Array, float]] = {}
    for index in np.flatnonzero(live).tolist():
        span = slice(int(point_bounds[index]), int(point_bounds[index + 1]))
        grids[index] = (grid[span], values[span], rate[span.start:span.stop - 1], float(longest[index]))
    return results, grids


def _knot_steps(motion: HermiteMotion, knots: Array) -> tuple[Array, Array, Array]:
    """Per step between increasing ``knots``: its length, the interpolant's rate bound
    (:attr:`HermiteMotion.rate_bound` of the sample interval holding it) and the sub-grid steps
    over which the attitude turns at most :data:`FINE_STEP` (by :attr:`HermiteMotion.turn_rate`,
    at least 4)."""
    interval = motion.interval(knots[:-1])
    h = np.diff(knots)
    return h, motion.rate_bound[interval], np.maximum(4, np.ceil(motion.turn_rate[interval] * h / FINE_STEP)).astype(int)


def _zoom(motion: HermiteMotion, evaluate: Together, searches: int, active: Sequence[int], thresholds: Sequence[float],
          grids: Sequence[tuple[Array, Array, Array]], found_t: list[list[Array]], found_v: list[list[Array]],
          missable: list[float]) -> None:
    """Step 3 of :func:`search_between_samples` for several searches at once: the brackets of every
    search in one array (``owner``: the search of each, in order), the least value, the threshold
    and the :data:`MIN_SEARCHES` deepest brackets per search; the points of each zoom evaluated in
    one call (``evaluate`` of ``searches`` searches, of which those zoomed are ``active``) and
    appended to that search's ``found_t`` and ``found_v``. Every search zooms into at most
    :data:`MAX_SUB_GRID` points a zoom: past that, into its deepest brackets that may hide a
    crossing only, its ``missable`` raised (in place) to the longest bracket left unsearched."""
    count = len(grids)
    owner = np.repeat(np.arange(count), [len(grid) - 1 for grid, _, _ in grids])
    low = np.concatenate([grid[:-1] for grid, _, _ in grids])
    high = np.concatenate([grid[1:] for grid, _, _ in grids])
    at_low = np.concatenate([values[:-1] for _, values, _ in grids])
    at_high = np.concatenate([values[1:] for _, values, _ in grids])
    rate = np.concatenate([rate for _, _, rate in grids])
    thresholds_of = np.asarray(thresholds, dtype=float)
    # each search's least value (min ignores NaN: np.nanmin's value, once for all)
    smallest = np.fmin.reduceat(np.concatenate([values for _, values, _ in grids]),
                                np.concatenate([[0], np.cumsum([len(values) for _, values, _ in grids])[:-1]])).tolist()
    near = np.ones(len(low), dtype=bool)  # a candidate for a lower value (else only for a crossing)
    fraction = _FRACTION
    part = np.arange(REFINE_POINTS - 1)
    inside_count = REFINE_POINTS - 2
    searched = np.asarray(active, dtype=np.intp)  # each slot's search
    for _ in range(REFINE_LEVELS):
        threshold = thresholds_of[owner]
        with np.errstate(invalid="ignore"):
            floor = 0.5 * (at_low + at_high) - 0.5 * rate * (high - low)
            hidden = (np.fmin(at_low, at_high) >= threshold) & (floor < threshold)
            lower = np.flatnonzero(near & (floor < np.asarray(smallest)[owner]))
        if lower.size > MIN_SEARCHES:  # per search, the MIN_SEARCHES deepest (ties: the earlier)
            ranked = lower[np.lexsort((floor[lower], owner[lower]))]
            first = np.searchsorted(owner[ranked], owner[ranked], side="left")
            lower = ranked[np.arange(ranked.size) - first < MIN_SEARCHES]
        allowed = max(MAX_SUB_GRID // inside_count - MIN_SEARCHES, 0)
        for slot in np.unique(owner[hidden]).tolist() if np.count_nonzero(hidden) > allowed else ():  # the work
            # limit, per search and zoom (none past it when all of them are within)
            may_hide = np.flatnonzero(hidden & (owner == slot))
            if may_hide.size > allowed:
                dropped = may_hide[np.argsort((floor - threshold)[may_hide], kind="stable")[allowed:]]
                hidden[dropped] = False
                # a bracket left unsearched may hide a violation as long as itself
                missable[slot] = max(missable[slot], float(np.max(high[dropped] - low[dropped])))
        pick = hidden.copy()
        pick[lower] = True
        if not pick.any():
            break
        whole = hidden[pick]
        low, high, at_low, at_high, rate = low[pick], high[pick], at_low[pick], at_high[pick], rate[pick]
        owner = owner[pick]
        points = low[:, None] + (high - low)[:, None] * fraction
        flat = points.ravel()
        # every search's points in one call (owner increases: each search's points are one run)
        bounds = np.searchsorted(searched[owner], np.arange(searches + 1)) * inside_count
        inside_values = evaluate(bounds, flat, motion.attitudes(flat))
        starts = bounds[searched]
        zoomed = np.flatnonzero(bounds[searched + 1] > starts)  # the slots with points at this zoom
        least = np.fmin.reduceat(inside_values, starts[zoomed]).tolist()  # each one's least (NaN: none)
        for slot, lowest in zip(zoomed.tolist(), least):
            span = slice(int(starts[slot]), int(bounds[searched[slot] + 1]))
            found_t[slot].append(flat[span])
            found_v[slot].append(inside_values[span])
            smallest[slot] = min(smallest[slot], lowest)
        inside_values = inside_values.reshape(points.shape)
        ends_t = np.column_stack([low, points, high])
        ends_v = np.column_stack([at_low, inside_values, at_high])
        # a bracket searched for a lower value goes on by the two parts about its least point; one
        # that may hide a crossing by all its parts (the next bound clears most)
        best = np.argmin(np.where(np.isnan(ends_v), np.inf, ends_v), axis=1)[:, None]
        near = ((part == best) | (part == best - 1)).ravel()
        keep = near | np.repeat(whole, REFINE_POINTS - 1)
        low, high = ends_t[:, :-1].ravel()[keep], ends_t[:, 1:].ravel()[keep]
        at_low, at_high = ends_v[:, :-1].ravel()[keep], ends_v[:, 1:].ravel()[keep]
        rate = np.repeat(rate, REFINE_POINTS - 1)[keep]
        owner = np.repeat(owner, REFINE_POINTS - 1)[keep]
        near = near[keep]


_FRACTION = np.linspace(0.0, 1.0, REFINE_POINTS)[1:-1]
"""Where a zoom's new points lie in each bracket (fractions of it)."""


class PointingScore(NamedTuple):
    """How a sampled motion meets one pointing constraint.

    Attributes
    ----------
    min_margin_deg : float or None
        Smallest margin over the points scored inside the window [deg] (the samples, or a
        sub-grid between them: :meth:`PointingConstraint.score_between_samples`), negative when
        violated; ``None`` when no point lies in the window.
    time_in_violation_s : float
        Time spent with a negative margin inside the window [s] (zero crossings interpolated
        linearly between the points scored).
    first_violation_s : float or None
        First time the margin goes negative inside the window [s] (interpolated); ``None`` if never.
    min_margin_time_s : float or None
        Time of the smallest margin [s].
    missable_s : float
        [s]: 0, or when the search between the samples reached its work limit
        (:data:`MAX_SUB_GRID`) its :attr:`Searched.missable_s`: a violation shorter than it may be
        missed.
    """

    min_margin_deg: float | None
    time_in_violation_s: float
    first_violation_s: float | None
    min_margin_time_s: float | None
    missable_s: float = 0.0

    @property
    def met(self) -> bool:
        """Whether no point scored inside the window has a negative margin."""
        return self.min_margin_deg is None or self.min_margin_deg >= 0.0


def _covers(window: tuple[float, float], t: Array) -> bool:
    """Whether every time of ``t`` lies in ``window`` (inclusive; a NaN time does not; ``t`` empty:
    no time is left out)."""
    if not t.size:
        return True
    start, end = window
    return bool(start <= t.min() and (end == np.inf or end >= t.max()))


def violation_intervals(t: Array, margin: Array) -> list[tuple[float, float]]:
    """Intervals where a sampled margin is negative, with linearly interpolated ends.

    Parameters
    ----------
    t : (N,) ndarray
        Increasing sample times [s].
    margin : (N,) ndarray
        Margin at ``t`` (any unit); NaN marks samples outside the window (never violated).

    Returns
    -------
    list of (start, end) tuples
        Times [s]; a violation at a single isolated sample gives an interval of zero length.
    """
    t, margin = np.asarray(t, dtype=float), np.asarray(margin, dtype=float)
    bad = margin < 0.0  # NaN compares False
    if not bad.any():
        return []
    edges = np.diff(np.concatenate([[0], bad.astype(np.int8), [0]]))
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1  # each run of bad samples
    start, end = t[first], t[last]
    with np.errstate(invalid="ignore", divide="ignore"):
        before = np.maximum(first - 1, 0)  # crossing into violation between first-1 and first
        into = (first > 0) & np.isfinite(margin[before])
        m0, m1 = margin[before], margin[first]
        start = np.where(into, t[before] + (t[first] - t[before]) * m0 / (m0 - m1), start)
        after = np.minimum(last + 1, len(t) - 1)  # crossing out between last and last+1
        out = (last + 1 < len(t)) & np.isfinite(margin[after])
        m0, m1 = margin[last], margin[after]
        end = np.where(out, t[last] + (t[after] - t[last]) * m0 / (m0 - m1), end)
    return [(float(a), float(b)) for a, b in zip(start, end)]


@dataclass(frozen=True, eq=False)
class PointingConstraint:
    """A body boresight kept out of, or inside, a cone about a (possibly moving) direction.

    Parameters
    ----------
    name : str
        The requirement's name (its key under ``requirements.pointing``, or an option path).
    boresight : (3,) array_like
        Sensor boresight, body axes (normalised here; zero refused).
    keep_out : bool
        ``True``: the boresight stays at least the limit from the direction; ``False``: at most.
    angle : float
        Cone half-angle [rad], in (0, π).
    times : (n,) array_like, optional
        Times of the direction table [s] since t = 0, increasing; one entry (default ``[0]``) for a
        fixed direction.
    directions : (n, 3) array_like, optional
        Direction at ``times`` (normalised here), inertial frame; default the inertial x axis
        (give it: a constraint without a direction is not useful).
    growth : (n,) array_like or None, optional
        Added to ``angle`` at ``times`` [rad] (the Earth's apparent radius for a limb); ``None``: 0.
    window : (float, float), optional
        Times [s] between which the constraint applies; default the whole run.
    description : str, optional
        What the direction is (``"sun"``, ``"inertial [0, 1, 0]"``), for messages and plots.

    Notes
    -----
    Between table rows the direction is interpolated linearly and normalised, the growth linearly;
    before the first row and after the last they are held. Tabulate at a step that makes the
    interpolation error negligible against the tolerance a user would state (the Sun moves 0.04°
    per hour, the Moon 0.5°, the nadir of a low orbit 3.8° per minute).
    """

    name: str
    boresight: Array
    keep_out: bool
    angle: float
    times: Array = field(default_factory=lambda: np.zeros(1))
    directions: Array = field(default_factory=lambda: np.array([[1.0, 0.0, 0.0]]))
    growth: Array | None = None
    window: tuple[float, float] = (0.0, np.inf)
    description: str = ""

    def __post_init__(self) -> None:
        b = np.asarray(self.boresight, dtype=float).reshape(-1)
        if b.shape != (3,) or not np.all(np.isfinite(b)) or not np.linalg.norm(b) > 1e-12:
            raise ValueError(f"{self.name}: the boresight must be a non-zero finite 3-vector, got {b.tolist()}")
        object.__setattr__(self, "boresight", b / np.linalg.norm(b))
        if not (np.isfinite(self.angle) and 0.0 < self.angle < np.pi):
            raise ValueError(f"{self.name}: the half-angle must lie in (0, pi) rad, got {self.angle!r}")
        times = np.atleast_1d(np.asarray(self.times, dtype=float))
        directions = np.asarray(self.directions, dtype=float).reshape(-1, 3)
        if len(times) != len(directions) or len(times) == 0:
            raise ValueError(f"{self.name}: {len(times)} times for {len(directions)} directions")
        if len(times) > 1 and not np.all(np.diff(times) > 0):
            raise ValueError(f"{self.name}: the direction table's times must increase")
        norms = np.linalg.norm(directions, axis=1)
        if not np.all(np.isfinite(directions)) or not np.all(norms > 1e-12):
            raise ValueError(f"{self.name}: every direction must be a non-zero finite 3-vector")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "directions", directions / norms[:, None])
        growth = np.zeros(len(times)) if self.growth is None else np.atleast_1d(np.asarray(self.growth, dtype=float))
        if growth.shape != times.shape or not np.all(np.isfinite(growth)):
            raise ValueError(f"{self.name}: growth needs one finite value per time")
        object.__setattr__(self, "growth", growth)
        start, end = (float(v) for v in self.window)
        if not (start < end) or np.isnan(start):
            raise ValueError(f"{self.name}: the window must be (start, end) with start < end, got {self.window!r}")
        object.__setattr__(self, "window", (start, end))

    # ------------------------------------------------------------------ identity
    @cached_property
    def key(self) -> tuple[Any, ...]:
        """A hashable identity of everything that shapes the constraint (for solver caches)."""
        digest = hashlib.sha1()
        for array in (self.boresight, self.times, self.directions, self.growth):
            digest.update(np.ascontiguousarray(array).tobytes())
        return (self.keep_out, float(self.angle), self.window, digest.hexdigest())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, PointingConstraint) and self.key == other.key

    def __hash__(self) -> int:
        return hash(self.key)

    @property
    def moving(self) -> bool:
        """Whether the direction or the limit changes along the run (a table of more than one row)."""
        return len(self.times) > 1

    def tightened(self, amount: float) -> PointingConstraint:
        """The same constraint made stricter by ``amount`` [rad] (a wider keep-out, a narrower keep-in).

        Parameters
        ----------
        amount : float
            Tightening [rad]; may be negative to loosen.

        Returns
        -------
        PointingConstraint
        """
        angle = self.angle + amount if self.keep_out else self.angle - amount
        return replace(self, angle=float(angle))

    # ------------------------------------------------------------------ numeric
    def direction(self, t: ArrayLike) -> Array:
        """The direction at times ``t`` (interpolated, normalised).

        Parameters
        ----------
        t : float or (N,) array_like
            Times [s].

        Returns
        -------
        (N, 3) ndarray
            Unit vectors, inertial frame.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if not self.moving:
            return np.repeat(self.directions, len(t), axis=0)
        d = self._table_at(t)[:, :3]
        return np.asarray(d / np.sqrt(np.einsum("ij,ij->i", d, d))[:, None], dtype=float)

    def _table_at(self, t: Array) -> Array:
        """(N, 4): the direction (not normalised) and the growth at ``t``, interpolated linearly
        between the table's rows (one lookup for both) and held beyond them."""
        times = self.times
        rows, inverse_steps, differences = self._table_slopes
        row = times.searchsorted(t, side="right")
        row -= 1
        np.minimum(np.maximum(row, 0, out=row), len(times) - 2, out=row)
        weight = t - times[row]
        weight *= inverse_steps[row]
        np.minimum(np.maximum(weight, 0.0, out=weight), 1.0, out=weight)
        table = differences[row]  # in place, fewer temporaries: the same operations, the same values
        table *= weight[:, None]
        table += rows[row]
        return table

    @cached_property
    def _table_slopes(self) -> tuple[Array, Array, Array]:
        """The moving table's rows (direction, growth), 1 / their steps, and their differences."""
        rows = np.column_stack([self.directions, np.asarray(self.growth)])
        return rows, 1.0 / np.diff(self.times), np.diff(rows, axis=0)

    def limit(self, t: ArrayLike) -> Array:
        """The cone's half-angle at times ``t``.

        Parameters
        ----------
        t : float or (N,) array_like
            Times [s].

        Returns
        -------
        (N,) ndarray
            ``angle + growth(t)`` [rad].
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        growth = self.growth if self.growth is not None else np.zeros(1)
        if not self.moving:
            return np.full(len(t), self.angle + float(growth[0]))
        return np.asarray(self.angle + self._table_at(t)[:, 3], dtype=float)

    def angles(self, t: ArrayLike, q: ArrayLike) -> Array:
        """Angle between the boresight and the direction [rad].

        Parameters
        ----------
        t : (N,) array_like
            Times [s].
        q : (N, 4) array_like
            Attitude quaternions (scalar first, body to inertial) at ``t``.

        Returns
        -------
        (N,) ndarray
            Angles in [0, π] [rad].
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return self._angles(t, np.atleast_2d(np.asarray(q, dtype=float)), self._table_at(t) if self.moving else None)

    def _angles(self, t: Array, q: Array, table: Array | None) -> Array:
        """:meth:`angles`, with the table looked up at ``t`` (``None``: a fixed direction)."""
        # R(q) b |q|² as a quadratic form of q (one array op), over |q|²: the attitude of q / |q|
        pointing = np.einsum("mij,mj->mi", (q @ self._rotation_form).reshape(len(q), 3, 4), q)
        if table is None:
            cosine = pointing @ self.directions[0]
            cosine /= np.einsum("ij,ij->i", q, q)
        else:
            direction = table[:, :3]
            scale = np.sqrt(np.einsum("ij,ij->i", direction, direction))
            scale *= np.einsum("ij,ij->i", q, q)
            cosine = np.einsum("ij,ij->i", pointing, direction)
            cosine /= scale
        # in place: the same operations, the same values, fewer temporaries
        return np.arccos(np.minimum(np.maximum(cosine, -1.0, out=cosine), 1.0, out=cosine), out=cosine)

    @cached_property
    def _rotation_form(self) -> Array:
        """(4, 12): ``A_i`` with ``(R(q) b)_i |q|² = qᵀ A_i q`` for the boresight ``b`` and any ``q``
        (``(q0² − |v|²) b + 2 (v·b) v + 2 q0 v × b``), as ``[A_0 | A_1 | A_2]`` (row: ``q``'s index)."""
        b = self.boresight
        form = np.zeros((3, 4, 4))
        for i in range(3):
            form[i, 0, 0] = b[i]
            for j in range(3):
                form[i, 1 + j, 1 + j] -= b[i]
                form[i, 1 + i, 1 + j] += b[j]
                form[i, 1 + j, 1 + i] += b[j]
                for k in range(3):
                    cross = float(np.cross(np.eye(3)[j], np.eye(3)[k])[i]) * b[k]  # ε_ijk b_k
                    form[i, 0, 1 + j] += cross
                    form[i, 1 + j, 0] += cross
        return np.ascontiguousarray(form.transpose(1, 0, 2).reshape(4, 12))

    def in_window(self, t: ArrayLike) -> NDArray[np.bool_]:
        """Whether each time lies in the window (inclusive).

        Parameters
        ----------
        t : float or (N,) array_like
            Times [s].

        Returns
        -------
        (N,) ndarray of bool
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        return (t >= self.window[0]) & (t <= self.window[1])

    def margins(self, t: ArrayLike, q: ArrayLike) -> Array:
        """Margin at each sample [rad]: negative when violated, NaN outside the window.

        Parameters
        ----------
        t : (N,) array_like
            Times [s].
        q : (N, 4) array_like
            Attitude quaternions at ``t``.

        Returns
        -------
        (N,) ndarray
            ``θ − limit`` (keep-out) or ``limit − θ`` (keep-in) [rad].
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        q = np.atleast_2d(np.asarray(q, dtype=float))
        if self.moving:
            table = self._table_at(t)  # one lookup for the direction and the limit
            limit = table[:, 3]
            limit += self.angle
        else:
            table, limit = None, self.limit(t[:1])[0]
        margin = self._angles(t, q, table)  # in place from here: the same operations, the same values
        margin -= limit
        if not self.keep_out:
            np.negative(margin, out=margin)
        if not _covers(self.window, t):
            start, end = self.window
            inside = t >= start
            inside &= t <= end
            margin[~inside] = np.nan
        return margin

    def score(self, t: ArrayLike, q: ArrayLike) -> PointingScore:
        """Score a sampled motion against the constraint.

        Parameters
        ----------
        t : (N,) array_like
            Increasing sample times [s].
        q : (N, 4) array_like
            Attitude quaternions at ``t``.

        Returns
        -------
        PointingScore
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        margin = self.margins(t, q)
        if not np.any(np.isfinite(margin)):
            return PointingScore(None, 0.0, None, None)
        worst = int(np.nanargmin(margin))
        intervals = violation_intervals(t, margin)
        return PointingScore(float(np.rad2deg(margin[worst])), float(sum(b - a for a, b in intervals)),
                             intervals[0][0] if intervals else None, float(t[worst]))

    def score_between_samples(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike,
                              motion: HermiteMotion | None = None) -> PointingScore:
        """Score a motion known at samples by its attitude and body rate, between the samples too.

        The attitude between samples is the cubic Hermite of :func:`hermite_attitudes`, searched by
        :func:`search_between_samples` for the least margin and every crossing of 0: the margin
        changes no faster than the interpolant turns (:attr:`HermiteMotion.rate_bound`) plus the
        direction's and the limit's rates (:attr:`drift`); the window's edges are points of it.
        The smallest margin and its time, and the violations (zero crossings interpolated linearly
        between the points), are then those of :meth:`score` on the points searched. A violation of
        the interpolated motion is never missed unless less deep than the bound over the search's
        last brackets (about ``1e-9`` rad at the 12U CubeSat's rates); the true motion differs from
        the interpolated one by the interpolation's O(h⁴) where the samples agree with their rates.
        A positive least margin is exact where the search reaches it, else within the bound over a
        step.

        Parameters
        ----------
        t : (N,) array_like
            Increasing sample times [s].
        q : (N, 4) array_like
            Attitude at ``t`` (scalar first, body to inertial).
        omega : (N, 3) array_like
            Body rate at ``t`` [rad/s], body axes.
        motion : HermiteMotion or None, optional
            ``HermiteMotion(t, q, omega)`` when already built (a row's requirements share one);
            ``None``: built here.

        Returns
        -------
        PointingScore
            As :meth:`score`, of the interpolated motion.
        """
        return scores_between_samples([self], t, q, omega, motion)[0]

    def _scored(self, times: Array, margin: Array, missable_s: float = 0.0) -> PointingScore:
        """The score of the margins at the points searched (:meth:`score_between_samples`)."""
        # np.nanargmin's index (the first least, NaN ignored) in one pass: NaN as +inf
        filled = np.fmin(margin, np.inf)
        worst = int(np.argmin(filled))
        if not np.isfinite(filled[worst]) and not np.any(np.isfinite(margin)):
            return PointingScore(None, 0.0, None, None, missable_s)
        intervals = violation_intervals(times, margin)
        return PointingScore(float(np.rad2deg(margin[worst])), float(sum(b - a for a, b in intervals)),
                             intervals[0][0] if intervals else None, float(times[worst]), missable_s)

    @cached_property
    def drift(self) -> float:
        """A bound on how fast the margin moves with the attitude held [rad/s]: the direction's
        largest angular rate between table rows (``2 tan(φ/2) / Δt`` for a turn ``φ`` over ``Δt``:
        the normalised linear interpolation turns fastest mid-row) plus the limit's."""
        if not self.moving:
            return 0.0
        dt = np.diff(self.times)
        turn = np.arccos(np.clip(np.einsum("ij,ij->i", self.directions[:-1], self.directions[1:]), -1.0, 1.0))
        growth = np.abs(np.diff(np.asarray(self.growth)))
        return float(np.max((2.0 * np.tan(0.5 * turn) + growth) / dt))

    # ------------------------------------------------------------------ symbolic
    @cached_property
    def _tables(self) -> tuple[ca.Function, ca.Function] | None:
        """Linear CasADi interpolants of the direction (3 outputs) and the growth; None when fixed."""
        if not self.moving:
            return None
        grid = [self.times.tolist()]
        direction = ca.interpolant(f"{self.name}_direction", "linear", grid, self.directions.ravel(order="C").tolist())
        growth = ca.interpolant(f"{self.name}_growth", "linear", grid, np.asarray(self.growth).tolist())
        return direction, growth

    def expression(self, q: Any, t: Any) -> Any:
        """The constraint as ``g(q, t) <= 0`` (cosines, smooth), for a transcription.

        Outside the window ``g`` is not switched off: a transcription imposes it only at points whose
        times it knows to lie inside (see :meth:`applies_between`).

        Parameters
        ----------
        q : (4,) CasADi expression
            Attitude quaternion (scalar first, body to inertial).
        t : CasADi scalar or float
            Time [s].

        Returns
        -------
        CasADi scalar expression
            ``cos θ − cos(limit)`` for a keep-out, ``cos(limit) − cos θ`` for a keep-in (the
            direction is normalised after interpolation).
        """
        pointing = ca.mtimes(qc.rotation_matrix(q), ca.DM(self.boresight))
        tables = self._tables
        if tables is None:
            direction: Any = ca.DM(self.directions[0])
            limit: Any = self.angle + float(np.asarray(self.growth)[0])
        else:
            held = ca.fmin(ca.fmax(t, float(self.times[0])), float(self.times[-1]))  # held beyond the table, as in NumPy
            raw = tables[0](held)
            direction = raw / ca.norm_2(raw)
            limit = self.angle + tables[1](held)
        cosine = ca.dot(pointing, direction) / ca.norm_2(pointing)
        return cosine - ca.cos(limit) if self.keep_out else ca.cos(limit) - cosine

    def applies_between(self, start: float, end: float) -> bool:
        """Whether the window overlaps an interval.

        Parameters
        ----------
        start, end : float
            The interval [s].

        Returns
        -------
        bool
        """
        return self.window[0] <= end and self.window[1] >= start


def scores_between_samples(constraints: Sequence[PointingConstraint], t: ArrayLike, q: ArrayLike, omega: ArrayLike,
                           motion: HermiteMotion | None = None) -> list[PointingScore]:
    """:meth:`PointingConstraint.score_between_samples` of several constraints on one motion (a
    row's pointing requirements): their searches go through :func:`searches_between_samples`
    together, each score exactly that of the constraint alone.

    Parameters
    ----------
    constraints : sequence of PointingConstraint
        The constraints.
    t : (N,) array_like
        Increasing sample times [s].
    q : (N, 4) array_like
        Attitude at ``t`` (scalar first, body to inertial).
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s], body axes.
    motion : HermiteMotion or None, optional
        ``HermiteMotion(t, q, omega)`` when already built; ``None``: built here.

    Returns
    -------
    list of PointingScore
        One per constraint, in order.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if len(t) < 2:
        return [constraint.score(t, np.atleast_2d(np.asarray(q, dtype=float))) for constraint in constraints]
    moving = HermiteMotion(t, q, omega) if motion is None else motion
    found = searches_between_samples(moving, [(constraint.margins, 0.0, constraint.drift, constraint.window)
                                              for constraint in constraints], _margins_together(constraints))
    return [constraint._scored(search[0], search[1], search.missable_s) for constraint, search in zip(constraints, found)]


def _margins_together(constraints: Sequence[PointingConstraint]) -> Together:
    """:func:`_margins_built` of these constraints."""
    return _margins_built(tuple(constraints))


@lru_cache(maxsize=16)
def _margins_built(constraints: tuple[PointingConstraint, ...]) -> Together:
    """``together`` of :func:`searches_between_samples` for the constraints' margins
    (:meth:`PointingConstraint.margins`), each constraint at its own points: the moving constraints'
    in one pass (their tables end to end, each point's lookup into its own; per point the same
    operations as :meth:`PointingConstraint.margins`, so the same values), a fixed one alone. Kept
    for the last few sets of constraints (equal constraints have equal margins: a run's rows and
    scopes share one)."""
    moving = [index for index, constraint in enumerate(constraints) if constraint.moving]
    if len(moving) < 2:
        return _each([(constraint.margins, 0.0, 0.0, ()) for constraint in constraints])
    fixed = [index for index in range(len(constraints)) if index not in moving]
    mine = [constraints[index] for index in moving]
    last = np.array([len(constraint.times) - 2 for constraint in mine])  # each table's last step
    offsets = np.concatenate([[0], np.cumsum(last + 2)[:-1]])
    table_times = np.concatenate([constraint.times for constraint in mine])
    slopes = [constraint._table_slopes for constraint in mine]
    rows = np.concatenate([slope[0] for slope in slopes])
    # the steps' arrays hold one fewer than the rows: padded by one, the rows' offsets serve them
    inverse_steps = np.concatenate([np.append(slope[1], 0.0) for slope in slopes])
    differences = np.concatenate([np.vstack([slope[2], np.zeros((1, 4))]) for slope in slopes])
    angles = np.array([constraint.angle for constraint in mine])
    keep_in = np.array([not constraint.keep_out for constraint in mine])
    any_keep_in = bool(keep_in.any())
    starts = np.array([constraint.window[0] for constraint in mine])
    ends = np.array([constraint.window[1] for constraint in mine])
    forms = [constraint._rotation_form for constraint in mine]
    alone = [constraints[index].margins for index in fixed]

    def evaluate(bounds: NDArray[np.intp], times: Array, attitudes: Array) -> Array:
        values = np.empty(len(times))
        for index, margins in zip(fixed, alone):
            span = slice(int(bounds[index]), int(bounds[index + 1]))
            if span.start < span.stop:
                values[span] = margins(times[span], attitudes[span])
        sizes = np.diff(bounds)[moving]
        if fixed:
            select: Any = np.concatenate([np.arange(bounds[index], bounds[index + 1]) for index in moving])
            t, q = times[select], attitudes[select]
        else:
            select, t, q = slice(None), times, attitudes
        count = len(t)
        row = np.empty(count, dtype=np.intp)
        product = np.empty((count, 12))
        start = 0
        for slot, constraint in enumerate(mine):  # each point's lookup into its own table
            span = slice(start, start + int(sizes[slot]))
            start = span.stop
            if span.start == span.stop:
                continue
            found = constraint.times.searchsorted(t[span], side="right")
            found -= 1
            np.minimum(np.maximum(found, 0, out=found), last[slot], out=found)
            found += offsets[slot]
            row[span] = found
            product[span] = q[span] @ forms[slot]
        owner = np.repeat(np.arange(len(mine)), sizes)
        # from here per point the operations of PointingConstraint._table_at, margins and _angles
        weight = t - table_times.take(row)
        weight *= inverse_steps.take(row)
        np.minimum(np.maximum(weight, 0.0, out=weight), 1.0, out=weight)
        table = differences.take(row, axis=0)
        table *= weight[:, None]
        table += rows.take(row, axis=0)
        limit = table[:, 3]
        limit += angles[owner]
        pointing = np.einsum("mij,mj->mi", product.reshape(count, 3, 4), q)
        direction = table[:, :3]
        scale = np.sqrt(np.einsum("ij,ij->i", direction, direction))
        scale *= np.einsum("ij,ij->i", q, q)
        cosine = np.einsum("ij,ij->i", pointing, direction)
        cosine /= scale
        margin = np.arccos(np.minimum(np.maximum(cosine, -1.0, out=cosine), 1.0, out=cosine), out=cosine)
        margin -= limit
        if any_keep_in:
            np.negative(margin, out=margin, where=keep_in[owner])
        if not _covers((float(starts.max()), float(ends.min())), t):  # some window may leave out a point
            within = t >= starts[owner]
            within &= t <= ends[owner]
            margin[~within] = np.nan
        values[select] = margin
        return values

    return evaluate
