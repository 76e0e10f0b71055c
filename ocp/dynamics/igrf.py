"""IGRF geomagnetic field along a known circular orbit, tabulated and interpolated.

The International Geomagnetic Reference Field (IGRF-14, degree 13) is evaluated by ``ppigrf``
(IAGA's pure-Python implementation, which ships the coefficient file: nothing is downloaded at run
time) at nodes ``t_k = k·step`` along the orbit, rotated into the inertial frame and interpolated
by a CasADi cubic B-spline in time. The orbit is known in advance, so the field along it is a
function of time alone; the interpolant is a CasADi function, usable inside the model's symbolic
right-hand side like the tilted dipole. With the default 30 s step the spline agrees with the
package to far better than 1 nT at the nodes and to ~1e-5 (relative) between them at 600 km.

The secular variation over a run (tens of nT per year) is neglected: the coefficients are those of
the epoch. Frames: the Earth-fixed frame turns about the inertial z axis at ``EARTH_RATE`` from the
angle ``greenwich_angle`` at t = 0 (by default the Greenwich mean sidereal time of the epoch, so that
the inertial frame is the epoch's equatorial frame, precession and nutation neglected).
"""
from __future__ import annotations

import dataclasses
import datetime
from dataclasses import dataclass
from functools import cached_property
from typing import Annotated, Any, ClassVar

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.cache import RecentCache, Unkeyable, exact_key
from ocp.dynamics.environment import MAGNETIC_FIELDS, FieldModel
from ocp.dynamics.ephemeris import parse_utc
from ocp.dynamics.orbits import Orbit
from ocp.errors import ModelError
from ocp.options import Range
from ocp.quat_casadi import Expr

EARTH_RATE = 7.2921159e-5      # rad/s, as ocp.dynamics.environment
MAX_NODES = 200_000
"""Upper bound on the table's nodes (work size): span / step."""
EPOCH_RANGE = (datetime.date(1900, 1, 1), datetime.date(2030, 1, 1))
"""Dates the IGRF-14 coefficients cover (definitive to 2020, the 2025 model and its secular
variation to 2030)."""
_INTERPOLANTS = RecentCache(size=16)
"""Built interpolants (:attr:`IGRFField.interpolant`) keyed by the field's exact value: a scenario
parsed again, or a study's cases sharing one orbit and epoch, tabulate the field once per thread."""


def parse_epoch(epoch: str | datetime.date) -> datetime.datetime:
    """The epoch as a naive UTC ``datetime``, within the IGRF's dates.

    Parameters
    ----------
    epoch : str, datetime.date or datetime.datetime
        As :func:`~ocp.dynamics.ephemeris.parse_utc` reads it: ISO text (``"2025-01-01"``,
        ``"2025-01-01T06:00:00+02:00"``), a date (00:00 UTC) or a datetime (naive means UTC; an
        aware one is converted to UTC).

    Returns
    -------
    datetime.datetime
        The instant in UTC, without time zone.

    Raises
    ------
    ModelError
        (field ``"epoch"``) For text that is not an ISO date, or a date outside
        :data:`EPOCH_RANGE`.
    """
    value = parse_utc(epoch)
    if not EPOCH_RANGE[0] <= value.date() < EPOCH_RANGE[1]:
        raise ModelError("epoch", f"IGRF-14 covers {EPOCH_RANGE[0]} to {EPOCH_RANGE[1]}, got {value.date()}")
    return value


def greenwich_mean_sidereal_angle(epoch: datetime.datetime) -> float:
    """Greenwich mean sidereal angle at a UTC epoch, IAU 1982 linear form (UT1 = UTC; error well under 0.01°).

    Parameters
    ----------
    epoch : datetime.datetime
        UTC instant (naive).

    Returns
    -------
    float
        Angle of the Greenwich meridian from the vernal equinox [rad], in [0, 2π).
    """
    days = (epoch - datetime.datetime(2000, 1, 1, 12)).total_seconds() / 86400.0
    return float(np.deg2rad((280.46061837 + 360.98564736629 * days) % 360.0))


def igrf_earth_fixed(position_ecef: ArrayLike, epoch: datetime.datetime) -> NDArray:
    """IGRF field in Earth-fixed Cartesian axes at Earth-fixed positions, by ``ppigrf``.

    Parameters
    ----------
    position_ecef : (N, 3) or (3,) array_like
        Geocentric positions [m], Earth-fixed frame (spherical Earth-centred coordinates are
        derived from them; no geodetic conversion).
    epoch : datetime.datetime
        Date of the coefficients (UTC).

    Returns
    -------
    (N, 3) ndarray
        Field [T], Earth-fixed Cartesian axes.
    """
    import ppigrf  # the dependency is needed only by the IGRF model

    position = np.atleast_2d(np.asarray(position_ecef, dtype=float))
    radius = np.linalg.norm(position, axis=1)
    colatitude = np.arccos(np.clip(position[:, 2] / radius, -1.0, 1.0))
    # ppigrf divides B_phi by sin(colatitude): keep 1e-7 rad off the poles (the field is smooth there)
    colatitude = np.clip(colatitude, 1e-7, np.pi - 1e-7)
    longitude = np.arctan2(position[:, 1], position[:, 0])
    b_r, b_theta, b_phi = (component[0] * 1e-9 for component in ppigrf.igrf_gc(
        radius / 1e3, np.rad2deg(colatitude), np.rad2deg(longitude), epoch))
    ct, st, cp, sp = np.cos(colatitude), np.sin(colatitude), np.cos(longitude), np.sin(longitude)
    return np.stack([b_r * st * cp + b_theta * ct * cp - b_phi * sp,
                     b_r * st * sp + b_theta * ct * sp + b_phi * cp,
                     b_r * ct - b_theta * st], axis=-1)


@dataclass(frozen=True)
class IGRFField(FieldModel):
    """The IGRF-14 field tabulated along ``orbit`` over ``[0, span]`` s and interpolated in time.

    Parameters
    ----------
    orbit : Orbit
        The orbit along which the field is tabulated; it must be the environment's orbit.
    span : float
        Tabulated window [s], positive; the simulator refuses to run beyond it. At most
        :data:`MAX_NODES` nodes (``span / step``).
    epoch : str, optional
        Date of the IGRF coefficients and of t = 0, ISO text (default ``"2025-01-01"``), within
        :data:`EPOCH_RANGE`.
    step : float, optional
        Spacing of the nodes [s], positive (default 30; cubic B-spline between them).
    greenwich_angle : float or None, optional
        Angle of the Earth-fixed x axis from the inertial x axis at t = 0 [rad]; ``None``
        (default): the GMST of the epoch.
    earth_rate : float, optional
        Rotation rate of the Earth-fixed frame about the inertial z axis [rad/s] (default
        ``EARTH_RATE``).
    span_from_window : bool, optional
        ``span`` is provisional: :meth:`for_window` replaces it by the closed-loop window (a
        scenario that leaves ``span_s`` out). Not part of the field's value (default False).

    Raises
    ------
    ModelError
        For an epoch outside the IGRF range, a non-positive step or span, or too many nodes.
    """

    name: ClassVar[str] = "igrf"

    orbit: Orbit
    span: float
    epoch: str = "2025-01-01"
    step: float = 30.0
    greenwich_angle: float | None = None
    earth_rate: float = EARTH_RATE
    span_from_window: bool = dataclasses.field(default=False, compare=False, repr=False)

    @dataclass(frozen=True)
    class Options:
        """Options of ``igrf`` (YAML keys of ``environment.magnetic_field``).

        Attributes
        ----------
        epoch : str
            Date of the IGRF-14 coefficients and of t = 0, ISO text (``2025-01-01``), from 1900 to
            2029.
        step_s : float
            Spacing of the table's nodes [s] (cubic B-spline between them; at 1000 s the spline
            misses the field by 42 %).
        span_s : float or None
            Tabulated window [s]; ``null``: the closed-loop window or, when there are planners,
            twice the manoeuvre's duration if that is longer, plus 60 s. A run beyond it is a failed
            row naming this key.
        greenwich_angle_deg : float or None
            Angle of the Earth-fixed x axis from the inertial x axis at t = 0 [deg]; ``null``: the
            Greenwich mean sidereal time of the epoch.
        """

        epoch: str = "2025-01-01"
        step_s: Annotated[float, Range(gt=0.0, le=120.0)] = 30.0
        span_s: Annotated[float | None, Range(gt=0.0)] = None
        greenwich_angle_deg: Annotated[float | None, Range()] = None

    @classmethod
    def from_options(cls, options: Any, orbit: Orbit | None) -> IGRFField:
        """The table of ``options`` along ``orbit`` (without ``span_s``, a provisional one-second
        span that :meth:`for_window` replaces).

        Parameters
        ----------
        options : IGRFField.Options
            The YAML options.
        orbit : Orbit or None
            The orbit to tabulate the field along.

        Returns
        -------
        IGRFField
            The field.

        Raises
        ------
        ModelError
            Without an orbit (field ``""``: the whole entry), or for a bad epoch, step or span.
        """
        if orbit is None:
            raise ModelError("", "the IGRF field is tabulated along the orbit; give `orbit:`")
        greenwich = options.greenwich_angle_deg
        return cls(orbit, epoch=options.epoch, span=options.span_s or 1.0, step=options.step_s,
                   greenwich_angle=None if greenwich is None else float(np.deg2rad(greenwich)),
                   span_from_window=options.span_s is None)

    def for_window(self, window: float) -> IGRFField:
        """This table over a closed-loop window of ``window`` seconds, if its span is provisional.

        Parameters
        ----------
        window : float
            The window to tabulate [s].

        Returns
        -------
        IGRFField
            ``self`` when ``span`` was given; else a copy spanning ``window``.
        """
        if not self.span_from_window:
            return self
        return dataclasses.replace(self, span=window, span_from_window=False)

    def __post_init__(self) -> None:
        parse_epoch(self.epoch)
        if not (self.step > 0 and np.isfinite(self.step)):
            raise ModelError("step_s", f"expected a positive node spacing, got {self.step}")
        if not (self.span > 0 and np.isfinite(self.span)):
            raise ModelError("span_s", f"expected a positive window, got {self.span}")
        if self.span / self.step > MAX_NODES:
            raise ModelError("span_s", f"span / step = {self.span / self.step:.0f} nodes; at most {MAX_NODES}")

    @property
    def initial_greenwich_angle(self) -> float:
        """The Earth-fixed x axis's angle from the inertial x axis at t = 0 [rad]: ``greenwich_angle``
        or, when that is ``None``, the GMST of the epoch."""
        if self.greenwich_angle is not None:
            return float(self.greenwich_angle)
        return greenwich_mean_sidereal_angle(parse_epoch(self.epoch))

    @property
    def valid_until(self) -> float:
        """End of the tabulated window [s]: the last node, at or after ``span``."""
        return float(self.nodes[-1])

    @property
    def nodes(self) -> NDArray:
        """(N,) times of the table [s], ``k * step`` from 0 (at least four, for the cubic spline)."""
        count = max(4, int(np.ceil(self.span / self.step - 1e-9)) + 1)
        return np.arange(count) * self.step

    def exact(self, t: ArrayLike) -> NDArray:
        """The field evaluated by ``ppigrf`` (not interpolated) along the orbit.

        Parameters
        ----------
        t : float or (N,) array_like
            Times since t = 0 [s].

        Returns
        -------
        (N, 3) ndarray
            Field [T], inertial frame, at the orbit's positions at ``t``.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        position = np.asarray(self.orbit.function().map(t.size)(t[None, :])[0]).T
        angle = self.initial_greenwich_angle + self.earth_rate * t
        c, s = np.cos(angle), np.sin(angle)
        ecef = np.stack([c * position[:, 0] + s * position[:, 1], -s * position[:, 0] + c * position[:, 1],
                         position[:, 2]], axis=-1)
        b = igrf_earth_fixed(ecef, parse_epoch(self.epoch))
        return np.stack([c * b[:, 0] - s * b[:, 1], s * b[:, 0] + c * b[:, 1], b[:, 2]], axis=-1)

    @cached_property
    def interpolant(self) -> ca.Function:
        """``casadi.Function`` ``igrf_field(t) -> b``: cubic B-spline through the table, ``t`` [s],
        ``b`` (3,) [T], inertial axes (built on first use; fields of equal value share one,
        a bounded cache per thread)."""
        try:
            key = exact_key(self)  # every compared field: orbit, span, epoch, step, angle, rate
        except Unkeyable:  # an orbit of unknown kind: its own table
            return self._build_interpolant()
        return _INTERPOLANTS.get(("igrf_interpolant", key), self._build_interpolant)

    def _build_interpolant(self) -> ca.Function:
        """A new interpolant through the table (:attr:`interpolant`)."""
        nodes = self.nodes
        values = self.exact(nodes)
        return ca.interpolant("igrf_field", "bspline", [nodes], values.ravel())

    def field_inertial(self, position: Expr, t: Expr) -> Expr:
        """Interpolated field at time ``t`` (the table is along the orbit).

        Parameters
        ----------
        position : (3, 1) casadi.SX, MX, DM or array_like
            Ignored: it is the orbit's position at ``t``; accepted for the interface shared with
            :meth:`ocp.dynamics.environment.TiltedDipole.field_inertial`.
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s], within ``[0, valid_until]``.

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Field [T], inertial frame.
        """
        return self.interpolant(t)

    def function(self) -> ca.Function:
        """The field as a CasADi function, with the tilted dipole's signature.

        Returns
        -------
        casadi.Function
            ``igrf_field(position, t) -> b``: ``position`` (3,) [m] (ignored), ``t`` [s], ``b``
            (3, 1) [T], inertial frame.
        """
        position, t = ca.SX.sym("position", 3), ca.SX.sym("t")
        return ca.Function("igrf_field", [position, t], [self.field_inertial(position, t)], ["position", "t"], ["b"])


MAGNETIC_FIELDS[IGRFField.name] = IGRFField
