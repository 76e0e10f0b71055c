r"""Pointing constraints: a body boresight kept out of (or inside) a cone about a direction.

:class:`PointingConstraint` is one requirement made concrete for one run: the sensor's body
boresight, the cone's half-angle, and the direction it is measured from, tabulated along the run
(a fixed inertial vector is a table of one row). The same object serves both sides of the
workbench:

* scoring (NumPy): :meth:`PointingConstraint.margins` and :meth:`PointingConstraint.score` on any
  sampled motion (a reference on its dense grid); :meth:`PointingConstraint.score_between_samples`
  on a motion known by its attitude and body rate at coarse samples (a closed loop), between which
  the attitude is interpolated (:func:`hermite_attitudes`);
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
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any, NamedTuple

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp import quat_casadi as qc

Array = NDArray[np.float64]

__all__ = [
    "COARSE_STEPS",
    "FINE_STEP",
    "MIN_SEARCHES",
    "REFINE_LEVELS",
    "REFINE_POINTS",
    "HermiteMotion",
    "PointingConstraint",
    "PointingScore",
    "hermite_attitudes",
    "violation_intervals",
]

FINE_STEP = np.deg2rad(0.05)
"""[rad]: the largest rotation of the attitude between two points of the sub-grid on which
:meth:`PointingConstraint.score_between_samples` evaluates the margin (each sample interval is cut
into as many equal steps as its faster end's rate needs, at least 4)."""
COARSE_STEPS = 16
"""Steps of a sample interval that may hide a lower margin but no violation (by the bound of
:meth:`PointingConstraint.score_between_samples`): the smallest margin there is searched further
(:data:`MIN_SEARCHES`), not the whole interval at :data:`FINE_STEP`."""
MIN_SEARCHES = 64
"""Sub-grid steps searched for a lower margin, the deepest by the bound first (every step that may
hide a violation is searched): the cost stays bounded when the bound cannot exclude much (a
boresight circling at a constant angle to the direction)."""
REFINE_POINTS = 17
"""Points of each zoom of :meth:`PointingConstraint.score_between_samples`'s search for a minimum
inside a sub-grid step (each zoom narrows the bracket to two of its steps: 8 times)."""
REFINE_LEVELS = 6
"""Zooms of that search: the bracket ends ``8**6 ≈ 2.6e5`` times narrower than a sub-grid step."""


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
        t, q, slope = self.t, self.q, self.slope
        at = np.clip(np.atleast_1d(np.asarray(times, dtype=float)), t[0], t[-1])
        if len(t) == 1:
            return np.repeat(quat.normalize(q), len(at), axis=0)
        k = np.clip(np.searchsorted(t, at, side="right") - 1, 0, len(t) - 2)
        h = t[k + 1] - t[k]
        s = (np.divide(at - t[k], h, out=np.zeros_like(h), where=h > 0.0))[:, None]  # a repeated time: its sample
        s2, s3 = s * s, s * s * s
        value = ((2 * s3 - 3 * s2 + 1) * q[k] + (s3 - 2 * s2 + s) * h[:, None] * slope[k]
                 + (3 * s2 - 2 * s3) * q[k + 1] + (s3 - s2) * h[:, None] * slope[k + 1])
        return np.asarray(value / np.linalg.norm(value, axis=1, keepdims=True), dtype=float)


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
    """

    min_margin_deg: float | None
    time_in_violation_s: float
    first_violation_s: float | None
    min_margin_time_s: float | None

    @property
    def met(self) -> bool:
        """Whether no point scored inside the window has a negative margin."""
        return self.min_margin_deg is None or self.min_margin_deg >= 0.0


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
        d = np.stack([np.interp(t, self.times, self.directions[:, i]) for i in range(3)], axis=-1)
        return d / np.linalg.norm(d, axis=1, keepdims=True)

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
        return self.angle + np.interp(t, self.times, growth)

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
        q = np.atleast_2d(np.asarray(q, dtype=float))
        pointing = quat.rotate(q, self.boresight)
        pointing = pointing / np.linalg.norm(pointing, axis=-1, keepdims=True)
        cosine = np.einsum("ij,ij->i", np.atleast_2d(pointing), self.direction(t))
        return np.arccos(np.clip(cosine, -1.0, 1.0))

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
        excess = self.angles(t, q) - self.limit(t)
        margin = excess if self.keep_out else -excess
        return np.where(self.in_window(t), margin, np.nan)

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

    def score_between_samples(self, t: ArrayLike, q: ArrayLike, omega: ArrayLike) -> PointingScore:
        """Score a motion known at samples by its attitude and body rate, between the samples too.

        The attitude between samples is the cubic Hermite of :func:`hermite_attitudes`. A bound says
        where to look: over a stretch of length ``Δ`` the margin stays above the mean of its ends
        less ``½ Δ`` times a bound on its rate (1.5 times the larger of the faster sample's ``‖ω‖``
        and the mean rate of the turn between the samples, plus the direction's and the limit's
        rates). A sample interval that may hide a violation by it, or has one at an end, is cut into
        equal steps over which the attitude turns at most :data:`FINE_STEP` (at least 4); one that
        may only hide a lower margin into at most :data:`COARSE_STEPS`; the others keep their
        samples alone. Every step that may hide a violation between two clear points, and the
        :data:`MIN_SEARCHES` steps that may hide the lowest margins, are searched for their minimum
        (up to :data:`REFINE_LEVELS` zooms of :data:`REFINE_POINTS` points, each while the bound
        still allows something lower); the minima found join the points. The smallest margin and
        its time, and the violations (zero crossings interpolated linearly between the points), are
        then those of :meth:`score` on the points. A violation is never missed where the samples
        agree with their rates; a positive least margin is exact where the search reaches it, else
        within the bound over a step.

        Parameters
        ----------
        t : (N,) array_like
            Increasing sample times [s].
        q : (N, 4) array_like
            Attitude at ``t`` (scalar first, body to inertial).
        omega : (N, 3) array_like
            Body rate at ``t`` [rad/s], body axes.

        Returns
        -------
        PointingScore
            As :meth:`score`, of the interpolated motion.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        q = np.atleast_2d(np.asarray(q, dtype=float))
        omega = np.atleast_2d(np.asarray(omega, dtype=float))
        if len(t) < 2:
            return self.score(t, q)
        h = np.diff(t)
        norms = np.linalg.norm(omega, axis=1)
        # per sample interval: the faster end's rate, or the mean rate of the turn between the samples
        # when that is more (samples whose rates do not match their attitudes: the Hermite still turns)
        quat_ = quat.continuous(q)
        chord = 2.0 * np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", quat_[:-1], quat_[1:])), 0.0, 1.0))
        rate = np.maximum(np.maximum(norms[:-1], norms[1:]),
                          np.divide(chord, h, out=np.zeros_like(h), where=h > 0.0))
        # by the same bound over each sample interval: those that may hide a violation, or have one at
        # an end (its crossings are located on the sub-grid), are cut into the fine sub-grid; those
        # that may only hide a lower margin into at most COARSE_STEPS steps; the others keep their
        # samples alone (a long fast run far from the cone costs its samples)
        at_samples = self.margins(t, q)
        if not np.any(np.isfinite(at_samples)):
            return PointingScore(None, 0.0, None, None)
        lowest = np.fmin(at_samples[:-1], at_samples[1:])
        with np.errstate(invalid="ignore"):
            reach = 0.5 * (at_samples[:-1] + at_samples[1:]) - 0.5 * (1.5 * rate + self._drift) * h
            violation = ((lowest >= 0.0) & (reach < 0.0)) | (lowest < 0.0)
            deeper = reach < float(np.nanmin(at_samples))
        fine_steps = np.maximum(4, np.ceil(rate * h / FINE_STEP))
        steps = np.where(violation, fine_steps, np.where(deeper, np.minimum(COARSE_STEPS, fine_steps), 1)).astype(int)
        offset = np.arange(int(steps.sum())) - np.repeat(np.cumsum(steps) - steps, steps)
        fine = np.repeat(t[:-1], steps) + np.repeat(h, steps) * offset / np.repeat(steps, steps)
        ends = [edge for edge in self.window if t[0] < edge < t[-1]]
        fine = np.unique(np.concatenate([fine, [t[-1]], ends]))
        motion = HermiteMotion(t, quat_, omega)
        margin = self.margins(fine, motion.attitudes(fine))
        # the sub-grid steps that may hide, between their ends, a margin below the smallest found or
        # below zero where neither end is: a Lipschitz bound of the margin over the step
        interval = np.clip(np.searchsorted(t, fine[:-1], side="right") - 1, 0, len(t) - 2)
        speed = 1.5 * rate[interval] + self._drift
        floor = 0.5 * (margin[:-1] + margin[1:]) - 0.5 * speed * np.diff(fine)
        with np.errstate(invalid="ignore"):
            ends_low = np.fmin(margin[:-1], margin[1:])
            hidden = np.flatnonzero((ends_low >= 0.0) & (floor < 0.0))  # a violation between two clear points
            lower = np.flatnonzero(floor < float(np.nanmin(margin)))  # a lower margin: the deepest few only
            lower = lower[np.argsort(floor[lower], kind="stable")[:MIN_SEARCHES]]
            suspect = np.union1d(hidden, lower)
        if suspect.size:
            found_t, found_m = self._zoom(motion, fine[suspect], fine[suspect + 1], speed[suspect],
                                          float(np.nanmin(margin)))
            order = np.argsort(np.concatenate([fine, found_t]), kind="stable")
            fine = np.concatenate([fine, found_t])[order]
            margin = np.concatenate([margin, found_m])[order]
        worst = int(np.nanargmin(margin))
        intervals = violation_intervals(fine, margin)
        return PointingScore(float(np.rad2deg(margin[worst])), float(sum(b - a for a, b in intervals)),
                             intervals[0][0] if intervals else None, float(fine[worst]))

    @staticmethod
    def _suspect(floor: Array, lowest_end: Array, smallest: float) -> NDArray[np.bool_]:
        """Which brackets may hold a margin below ``smallest`` (the smallest found), or below zero
        where none of their points found is, given the bound ``floor`` on their margin (NaN: no)."""
        return (floor < smallest) | ((lowest_end >= 0.0) & (floor < 0.0))

    def _zoom(self, motion: HermiteMotion, start: Array, end: Array, speed: Array,
              smallest: float) -> tuple[Array, Array]:
        """The smallest margin of the interpolated motion in each ``[start, end]`` and its time (all the
        brackets at once, each narrowed :data:`REFINE_LEVELS` times to two of its
        :data:`REFINE_POINTS` points about its smallest; a bracket whose bound (its best margin less
        ``speed`` [rad/s] times its new step) leaves nothing to find stops narrowing)."""
        fraction = np.linspace(0.0, 1.0, REFINE_POINTS)
        found_t, found_m = np.empty(len(start)), np.empty(len(start))
        alive = np.arange(len(start))
        for _ in range(REFINE_LEVELS):
            points = start[:, None] + (end - start)[:, None] * fraction
            margin = self.margins(points.ravel(), motion.attitudes(points.ravel())).reshape(points.shape)
            rows = np.arange(len(alive))
            best = np.argmin(margin, axis=1)
            found_t[alive], found_m[alive] = points[rows, best], margin[rows, best]
            smallest = min(smallest, float(np.min(margin)))
            step = (end - start) / (REFINE_POINTS - 1)
            keep = self._suspect(margin[rows, best] - speed * step, margin[rows, best], smallest)
            start = points[rows, np.maximum(best - 1, 0)][keep]
            end = points[rows, np.minimum(best + 1, REFINE_POINTS - 1)][keep]
            alive, speed = alive[keep], speed[keep]
            if not alive.size:
                break
        return found_t, found_m

    @cached_property
    def _drift(self) -> float:
        """A bound on how fast the margin moves with the attitude held [rad/s]: the direction's
        largest angular rate between table rows plus the limit's."""
        if not self.moving:
            return 0.0
        dt = np.diff(self.times)
        turn = np.arccos(np.clip(np.einsum("ij,ij->i", self.directions[:-1], self.directions[1:]), -1.0, 1.0))
        growth = np.abs(np.diff(np.asarray(self.growth)))
        return float(np.max((turn + growth) / dt))

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
