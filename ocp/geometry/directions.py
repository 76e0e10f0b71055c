r"""The directions a pointing requirement is measured from, seen from the spacecraft and tabulated along a run.

:class:`Geometry` holds what places the spacecraft in space and time: the epoch (UTC) and the orbit,
in the inertial frame (the GCRF: geocentric, ICRF axes). The direction kinds a scenario names are
registered in :data:`DIRECTIONS` (with :func:`direction_kind`): each says whether it needs the epoch
or the orbit, what it means, and tabulates its unit vector (and the growth of a cone about it)
along the run at a step that keeps linear interpolation within :data:`INTERPOLATION_TOLERANCE`.
:func:`direction_table` makes the table a :class:`~ocp.geometry.pointing.PointingConstraint` takes.

Directions are geometric: no light time and no aberration, neither the Earth's (see
:mod:`ocp.dynamics.ephemeris`) nor that of the spacecraft's orbital velocity (v/c ≈ 5″ in low orbit). The Sun and the Moon are
seen from the spacecraft when there is an orbit (the Moon's parallax from a low orbit reaches 1°),
from the Earth's centre otherwise. The Earth is a sphere of the equatorial radius ``R_EARTH`` (its
limb from 500 km lies up to 0.5° beyond the true one over the poles: a keep-out errs on the safe
side) with no atmosphere.

A fixed inertial direction is not a kind: it is a table of one row.
"""
from __future__ import annotations

import datetime
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar, TypeVar

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.ephemeris import check_epoch, moon_position, parse_utc, sun_position
from ocp.dynamics.orbits import R_EARTH, Orbit
from ocp.errors import ModelError

__all__ = ["DIRECTIONS", "FRAMES", "INTERPOLATION_TOLERANCE", "DirectionKind", "Geometry", "direction_kind",
           "direction_table"]

Array = NDArray[np.float64]

FRAMES = ("GCRF",)
"""Inertial frames a :class:`Geometry` can be expressed in: the GCRF (geocentric, ICRF axes)."""

INTERPOLATION_TOLERANCE = np.deg2rad(1e-4)
"""Largest angle [rad] between a tabulated direction, interpolated linearly and normalised, and the
exact one (1e-4°): :meth:`DirectionKind.step_s` chooses the step for half of it."""

_SUN_RATE = 2.0 * np.pi / (365.25 * 86400.0) * 1.04   # rad/s, the Sun's geocentric rate at perihelion
_MOON_RATE = 2.0 * np.pi / (27.32 * 86400.0) * 1.25   # rad/s, the Moon's geocentric rate at perigee, with margin
_SUN_DISTANCE_MIN = 1.47e11                           # m, perihelion
_MOON_DISTANCE_MIN = 3.56e8                           # m, the closest perigee
_CUBIC = np.sqrt(3.0) / 108.0
"""A direction turning uniformly by φ over a step and interpolated linearly then normalised is off
by at most ``_CUBIC φ³`` (at the fraction (3 − √3)/6 of the step)."""


def _unit(vectors: Array) -> Array:
    """Rows normalised."""
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


@dataclass(frozen=True)
class Geometry:
    """Where the spacecraft is and when: the epoch and the orbit, in an Earth-centred inertial frame.

    Parameters
    ----------
    epoch : datetime.datetime or None
        Instant of t = 0, UTC (naive, or aware and converted to UTC); ``None``: no epoch (no Sun
        or Moon).
    orbit : Orbit or None
        The spacecraft's orbit, inertial frame; ``None``: no orbit (no Earth or velocity direction;
        the Sun and the Moon are then seen from the Earth's centre).
    frame : str, optional
        The inertial frame, one of :data:`FRAMES` (default ``"GCRF"``), named in the outputs.

    Raises
    ------
    ModelError
        For an unknown frame (field ``"frame"``) or an epoch :func:`~ocp.dynamics.ephemeris.parse_utc`
        refuses (field ``"epoch"``).
    """

    epoch: datetime.datetime | None
    orbit: Orbit | None
    frame: str = "GCRF"

    def __post_init__(self) -> None:
        if self.frame not in FRAMES:
            raise ModelError("frame", f"expected one of {list(FRAMES)}, got {self.frame!r}")
        if self.epoch is not None:
            object.__setattr__(self, "epoch", parse_utc(self.epoch))

    def _need_orbit(self, what: str) -> Orbit:
        if self.orbit is None:
            raise ModelError("orbit", f"{what} needs an orbit (environment.orbit), and none is given")
        return self.orbit

    def _need_epoch(self, what: str) -> datetime.datetime:
        if self.epoch is None:
            raise ModelError("epoch", f"{what} needs an epoch (a UTC date-time like 2025-01-01T06:00:00Z), "
                                      "and none is given")
        return self.epoch

    def position(self, t: ArrayLike) -> Array:
        """The spacecraft's position from the Earth's centre.

        Parameters
        ----------
        t : float or (N,) array_like
            Time since the epoch [s].

        Returns
        -------
        (N, 3) ndarray
            Position [m], inertial frame.

        Raises
        ------
        ModelError
            (field ``"orbit"``) Without an orbit.
        """
        orbit = self._need_orbit("the spacecraft's position")
        row = ca.DM(np.atleast_1d(np.asarray(t, dtype=float)).reshape(1, -1))
        return np.asarray(orbit.position(row), dtype=float).T.reshape(-1, 3)

    def velocity(self, t: ArrayLike) -> Array:
        """The spacecraft's velocity with respect to the inertial frame.

        Parameters
        ----------
        t : float or (N,) array_like
            Time since the epoch [s].

        Returns
        -------
        (N, 3) ndarray
            Velocity [m/s], inertial frame.

        Raises
        ------
        ModelError
            (field ``"orbit"``) Without an orbit.
        """
        orbit = self._need_orbit("the orbital velocity")
        row = ca.DM(np.atleast_1d(np.asarray(t, dtype=float)).reshape(1, -1))
        return np.asarray(orbit.velocity(row), dtype=float).T.reshape(-1, 3)

    def _from_spacecraft(self, body: Array, t: ArrayLike) -> Array:
        """Unit vectors from the spacecraft (the Earth's centre without an orbit) to a body at ``body``."""
        return _unit(body - self.position(t) if self.orbit is not None else body)

    def sun(self, t: ArrayLike) -> Array:
        """Direction from the spacecraft to the Sun (JPL DE421, geometric).

        Parameters
        ----------
        t : float or (N,) array_like
            Time since the epoch [s].

        Returns
        -------
        (N, 3) ndarray
            Unit vectors, inertial frame; from the Earth's centre when there is no orbit.

        Raises
        ------
        ModelError
            (field ``"epoch"``) Without an epoch, or outside the ephemeris' range.
        """
        return self._from_spacecraft(sun_position(self._need_epoch("the Sun's direction"), t), t)

    def moon(self, t: ArrayLike) -> Array:
        """Direction from the spacecraft to the Moon (JPL DE421, geometric; with the parallax).

        Parameters
        ----------
        t : float or (N,) array_like
            Time since the epoch [s].

        Returns
        -------
        (N, 3) ndarray
            Unit vectors, inertial frame; from the Earth's centre when there is no orbit.

        Raises
        ------
        ModelError
            (field ``"epoch"``) Without an epoch, or outside the ephemeris' range.
        """
        return self._from_spacecraft(moon_position(self._need_epoch("the Moon's direction"), t), t)


class DirectionKind(ABC):
    """A kind of direction a pointing requirement may name (``sun``, ``earth_limb``, ...).

    Subclass it, set the class attributes, implement :meth:`table` and :meth:`step_s`, and register
    the class with :func:`direction_kind`.

    Attributes
    ----------
    name : str
        Registry name, as written in a scenario.
    needs_epoch : bool
        Whether the direction needs the epoch (the Sun, the Moon).
    needs_orbit : bool
        Whether the direction needs the orbit (the Earth, the velocity).
    meaning : str
        One line for the docs and the schema reference.
    """

    name: ClassVar[str]
    needs_epoch: ClassVar[bool]
    needs_orbit: ClassVar[bool]
    meaning: ClassVar[str]

    @abstractmethod
    def step_s(self, geometry: Geometry) -> float | None:
        """Tabulation step that keeps linear interpolation within :data:`INTERPOLATION_TOLERANCE`.

        Parameters
        ----------
        geometry : Geometry
            The epoch and the orbit.

        Returns
        -------
        float or None
            Step [s]; ``None`` for a direction that does not move.
        """

    @abstractmethod
    def table(self, geometry: Geometry, times: Array) -> tuple[Array, Array]:
        """The direction and the cone's growth at given times.

        Parameters
        ----------
        geometry : Geometry
            The epoch and the orbit.
        times : (N,) ndarray
            Times since the epoch [s].

        Returns
        -------
        directions : (N, 3) ndarray
            Unit vectors, inertial frame.
        growth : (N,) ndarray
            Added to a cone's half-angle about the direction [rad] (0 but for an extended body).

        Raises
        ------
        ModelError
            Without the epoch or orbit the kind needs.
        """


DIRECTIONS: dict[str, DirectionKind] = {}
"""The direction kinds a scenario names: registry name -> kind (:class:`DirectionKind`); add one with
:func:`direction_kind`."""

_K = TypeVar("_K", bound=type[DirectionKind])


def direction_kind(cls: _K) -> _K:
    """Register a direction kind (a class decorator): an instance goes into :data:`DIRECTIONS`.

    Parameters
    ----------
    cls : type
        A concrete :class:`DirectionKind` subclass with its ``name``, ``needs_epoch``,
        ``needs_orbit`` and ``meaning``.

    Returns
    -------
    type
        ``cls``, its instance now in :data:`DIRECTIONS`.

    Raises
    ------
    TypeError
        If ``cls`` is no DirectionKind subclass.
    ValueError
        If its name is already taken by another kind.
    """
    if not (isinstance(cls, type) and issubclass(cls, DirectionKind)):
        raise TypeError(f"a direction kind subclasses ocp.geometry.directions.DirectionKind, got {cls!r}")
    taken = DIRECTIONS.get(cls.name)
    if taken is not None and type(taken) is not cls:
        raise ValueError(f"direction kind {cls.__name__}: name {cls.name!r} is taken by {type(taken).__name__}")
    DIRECTIONS[cls.name] = cls()
    return cls


def _step(rate: float, acceleration: float) -> float:
    """Step [s] for a direction turning at most at ``rate`` [rad/s] whose unit vector's acceleration
    across its path is at most ``acceleration`` [rad/s²]: the cubic error of a uniform turn
    (``_CUBIC (rate h)³``) and the quadratic one of the rest (``acceleration h² / 8``) each within a
    quarter of :data:`INTERPOLATION_TOLERANCE`."""
    budget = INTERPOLATION_TOLERANCE / 4.0
    cubic = (budget / _CUBIC) ** (1.0 / 3.0) / rate if rate > 0 else np.inf
    quadratic = np.sqrt(8.0 * budget / acceleration) if acceleration > 0 else np.inf
    return float(min(cubic, quadratic))


def _body_step(geometry: Geometry, rate: float, distance_min: float) -> float:
    """Step for a body at least ``distance_min`` [m] from the Earth, turning at ``rate`` [rad/s]
    about it, seen from the orbit (the parallax swings at the orbit rate)."""
    if geometry.orbit is None:
        return _step(rate, rate**2)
    n, r = geometry.orbit.max_rate, geometry.orbit.max_radius
    parallax = r / (distance_min - r)
    return _step(rate + n * parallax, rate**2 + (n**2 + geometry.orbit.max_rate_change) * parallax)


@direction_kind
class Sun(DirectionKind):
    """The Sun (JPL DE421), from the spacecraft."""

    name = "sun"
    needs_epoch = True
    needs_orbit = False
    meaning = "the Sun's centre seen from the spacecraft (JPL DE421; needs the epoch)"

    def step_s(self, geometry: Geometry) -> float | None:
        return _body_step(geometry, _SUN_RATE, _SUN_DISTANCE_MIN)

    def table(self, geometry: Geometry, times: Array) -> tuple[Array, Array]:
        return geometry.sun(times), np.zeros(len(np.atleast_1d(times)))


@direction_kind
class Moon(DirectionKind):
    """The Moon (JPL DE421), from the spacecraft, parallax included."""

    name = "moon"
    needs_epoch = True
    needs_orbit = False
    meaning = "the Moon's centre seen from the spacecraft, parallax included (JPL DE421; needs the epoch)"

    def step_s(self, geometry: Geometry) -> float | None:
        return _body_step(geometry, _MOON_RATE, _MOON_DISTANCE_MIN)

    def table(self, geometry: Geometry, times: Array) -> tuple[Array, Array]:
        return geometry.moon(times), np.zeros(len(np.atleast_1d(times)))


def _orbit_step(geometry: Geometry) -> float:
    """Step for a direction that turns with the orbit (uniformly for a circular one): its bounds
    :attr:`~ocp.dynamics.orbits.Orbit.max_rate` and :attr:`~ocp.dynamics.orbits.Orbit.max_rate_change`."""
    orbit = geometry._need_orbit("this direction")
    return _step(orbit.max_rate, orbit.max_rate_change)


@direction_kind
class Earth(DirectionKind):
    """The Earth's centre: nadir."""

    name = "earth"
    needs_epoch = False
    needs_orbit = True
    meaning = "the Earth's centre (nadir) seen from the spacecraft (needs the orbit)"

    def step_s(self, geometry: Geometry) -> float | None:
        return _orbit_step(geometry)

    def table(self, geometry: Geometry, times: Array) -> tuple[Array, Array]:
        position = geometry.position(times)
        return _unit(-position), np.zeros(len(position))


@direction_kind
class EarthLimb(DirectionKind):
    """Nadir with the Earth's apparent radius as growth: a cone of α keeps α from the limb."""

    name = "earth_limb"
    needs_epoch = False
    needs_orbit = True
    meaning = ("the Earth's disc: nadir, the cone widened by the Earth's apparent radius asin(R/|r|), so that "
               "a keep-out of α stays α above the limb (needs the orbit)")

    def step_s(self, geometry: Geometry) -> float | None:
        return _orbit_step(geometry)

    def table(self, geometry: Geometry, times: Array) -> tuple[Array, Array]:
        position = geometry.position(times)
        radius = np.linalg.norm(position, axis=1)
        if np.any(radius <= R_EARTH):
            raise ModelError("orbit", f"the Earth's limb needs an orbit above the Earth's surface (radius > {R_EARTH:g} m), "
                                      f"got radius {float(np.min(radius)):g} m")
        return _unit(-position), np.arcsin(R_EARTH / radius)


@direction_kind
class Velocity(DirectionKind):
    """The direction of the orbital velocity (ram)."""

    name = "velocity"
    needs_epoch = False
    needs_orbit = True
    meaning = "the orbital velocity's direction (ram), inertial (needs the orbit)"

    def step_s(self, geometry: Geometry) -> float | None:
        return _orbit_step(geometry)

    def table(self, geometry: Geometry, times: Array) -> tuple[Array, Array]:
        velocity = geometry.velocity(times)
        return _unit(velocity), np.zeros(len(velocity))


def direction_table(kind: str, geometry: Geometry, duration: float) -> tuple[Array, Array, Array]:
    """Tabulate a direction kind over a run, for :class:`~ocp.geometry.pointing.PointingConstraint`.

    Parameters
    ----------
    kind : str
        A name in :data:`DIRECTIONS`.
    geometry : Geometry
        The epoch and the orbit.
    duration : float
        Length of the run [s], non-negative; the table spans ``[0, duration]``.

    Returns
    -------
    times : (n,) ndarray
        Equally spaced times [s] from 0 to ``duration`` at most the kind's step apart (one row,
        at 0, for a direction that does not move).
    directions : (n, 3) ndarray
        Unit vectors, inertial frame.
    growth : (n,) ndarray
        Growth of a cone about the direction [rad].

    Raises
    ------
    KeyError
        For an unknown kind (the message lists the known ones).
    ModelError
        Without the epoch or orbit the kind needs, for an epoch whose run leaves the ephemeris
        (field ``"epoch"``), or a negative or non-finite duration (field ``"duration"``).
    """
    if kind not in DIRECTIONS:
        raise KeyError(f"unknown direction {kind!r}; expected one of {sorted(DIRECTIONS)}")
    if not (np.isfinite(duration) and duration >= 0.0):
        raise ModelError("duration", f"expected a finite non-negative run length [s], got {duration!r}")
    direction = DIRECTIONS[kind]
    if direction.needs_epoch:
        check_epoch(geometry._need_epoch(f"the {kind} direction"), duration)
    if direction.needs_orbit:
        geometry._need_orbit(f"the {kind} direction")
    step = direction.step_s(geometry)
    if step is None or duration == 0.0:
        times = np.zeros(1)
    else:
        times = np.linspace(0.0, float(duration), int(np.ceil(duration / step)) + 1)
    directions, growth = direction.table(geometry, times)
    return times, directions, growth
