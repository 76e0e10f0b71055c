r"""Pointing constraints: a body boresight kept out of (or inside) a cone about a direction.

:class:`PointingConstraint` is one requirement made concrete for one run: the sensor's body
boresight, the cone's half-angle, and the direction it is measured from, tabulated along the run
(a fixed inertial vector is a table of one row). The same object serves both sides of the
workbench:

* scoring (NumPy): :meth:`PointingConstraint.margins` and :meth:`PointingConstraint.score` on any
  sampled motion (a reference on its grid, a closed loop on its samples);
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

__all__ = ["PointingConstraint", "PointingScore", "violation_intervals"]


class PointingScore(NamedTuple):
    """How a sampled motion meets one pointing constraint.

    Attributes
    ----------
    min_margin_deg : float or None
        Smallest margin over the samples inside the window [deg], negative when violated;
        ``None`` when no sample lies in the window.
    time_in_violation_s : float
        Time spent with a negative margin inside the window [s] (zero crossings interpolated
        linearly between samples).
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
        """Whether no sample inside the window has a negative margin."""
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
    intervals: list[tuple[float, float]] = []
    k, n = 0, len(t)
    while k < n:
        if not bad[k]:
            k += 1
            continue
        j = k
        while j + 1 < n and bad[j + 1]:
            j += 1
        start, end = t[k], t[j]
        if k > 0 and np.isfinite(margin[k - 1]):  # crossing into violation between k-1 and k
            m0, m1 = margin[k - 1], margin[k]
            start = t[k - 1] + (t[k] - t[k - 1]) * m0 / (m0 - m1)
        if j + 1 < n and np.isfinite(margin[j + 1]):  # crossing out between j and j+1
            m0, m1 = margin[j], margin[j + 1]
            end = t[j] + (t[j + 1] - t[j]) * m0 / (m0 - m1)
        intervals.append((float(start), float(end)))
        k = j + 1
    return intervals


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
