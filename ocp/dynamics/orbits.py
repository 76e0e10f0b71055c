"""Orbits: where the spacecraft is, as CasADi expressions of time, in the GCRF.

Every orbit is an :class:`Orbit`: :meth:`~Orbit.position` and :meth:`~Orbit.velocity` are CasADi
expressions of ``t`` (a number, a row of numbers, or a symbol used inside the NLPs and the closed
loop), and the base class derives :meth:`~Orbit.nadir`, :meth:`~Orbit.lvlh_matrix` and
:meth:`~Orbit.function` from them. The kinds a scenario names (``orbit.type``) are registered in
:data:`ORBITS`, each an :class:`OrbitKind` with its ``Options`` (the YAML keys):

* :class:`CircularOrbit` (``circular``): a circular Keplerian orbit fixed in the inertial frame.
* :class:`KeplerianOrbit` (``keplerian``): an elliptic two-body orbit of classical elements,
  Kepler's equation solved symbolically, with the optional secular drift of the node, the
  perigee and the mean anomaly by the Earth's oblateness (J2, first order).
* :class:`TLEOrbit` (``tle``): a two-line element set propagated by SGP4 (the ``sgp4`` package,
  Vallado's reference implementation), converted from TEME to the GCRF and interpolated in time.

Frames and time: positions are geocentric, inertial frame the GCRF (ICRF axes); ``t`` is in SI
seconds from the epoch (t = 0). A circular or Keplerian orbit's elements are given in that frame
at t = 0 and need no calendar epoch; a TLE needs the scenario's UTC epoch to place its own.
"""
from __future__ import annotations

import datetime
import warnings
from abc import ABC, abstractmethod
from dataclasses import dataclass
from functools import cached_property
from typing import Annotated, Any, ClassVar

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.dynamics.ephemeris import parse_utc
from ocp.errors import InvalidOption, ModelError
from ocp.options import Range, is_real
from ocp.quat_casadi import Expr

__all__ = ["J2_EARTH", "MAX_ORBIT_KM", "MU_EARTH", "ORBITS", "R_EARTH", "TLE_EPOCH_REFUSE_DAYS", "TLE_EPOCH_WARN_DAYS",
           "CircularOrbit", "KeplerianOrbit", "Orbit", "OrbitKind", "TLEOrbit", "kepler_newton_iterations",
           "teme_to_gcrf_matrices"]

MU_EARTH = 3.986004418e14      # m³/s², EGM96 / WGS-84
R_EARTH = 6378.137e3           # m, WGS-84 equatorial radius
J2_EARTH = 1.08262668e-3       # EGM96 second zonal harmonic (unnormalised), with R_EARTH
MAX_ORBIT_KM = 1e9
"""The largest altitude or semi-major axis an orbit may have [km]: 650 times the radius of the Earth's Hill
sphere (1.5 million km), far beyond any orbit about the Earth alone; above it the orbit's rate and
the geometry built on it overflow (a radius³ beyond the largest float from 5.6e99 km)."""
TLE_EPOCH_WARN_DAYS = 30.0
"""A TLE whose epoch lies more than this many days from the scenario's epoch is used with a warning."""
TLE_EPOCH_REFUSE_DAYS = 365.0
"""A TLE whose epoch lies more than this many days from the scenario's epoch is refused."""
KEPLER_ITERATIONS = 7
"""Newton steps on Kepler's equation from Danby's start: round-off (a few 1e-16 rad) for e ≤ 0.95;
six leave 5e-15 rad near perigee at e = 0.95."""
MAX_TLE_NODES = 200_000
"""Upper bound on a TLE table's nodes (``span / step``)."""


def _row(t: Expr) -> Expr:
    """``t`` as CasADi: numbers (one or a row of them) become a (1, N) ``DM``; symbols pass through."""
    if isinstance(t, (ca.SX, ca.MX, ca.DM)):
        return t
    return ca.DM(np.atleast_1d(np.asarray(t, dtype=float)).reshape(1, -1)) if np.ndim(t) else ca.DM(float(t))


class Orbit(ABC):
    """The contract of an orbit: the spacecraft's position and velocity as CasADi expressions of time.

    A subclass implements :meth:`position` and :meth:`velocity` (and the bounds :attr:`mu`,
    :attr:`max_radius`, :attr:`max_rate`, :attr:`max_rate_change`); the rest follows. Both
    methods take ``t`` [s since the epoch] as a float, a (1, N) row of times (``DM``, one column
    per time) or a scalar ``SX``/``MX`` symbol, and return (3, 1) (or (3, N)) expressions in the
    GCRF (geocentric, ICRF axes) built of CasADi operations, so that they can sit inside the
    model's right-hand side, the NLPs and the closed loop. ``velocity`` is the time derivative of
    ``position`` (to the accuracy the subclass states). An orbit is a frozen dataclass of plain
    numbers and text: the model's fingerprint reads it field by field, and two equal orbits are
    the same orbit.
    """

    mu: float
    """Gravitational parameter [m^3/s^2] of the gravity gradient."""

    @abstractmethod
    def position(self, t: Expr) -> Expr:
        """Position of the spacecraft from the Earth's centre.

        Parameters
        ----------
        t : float, (1, N) casadi.DM or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) or (3, N) casadi.DM, SX or MX
            Position [m], GCRF.
        """

    @abstractmethod
    def velocity(self, t: Expr) -> Expr:
        """Velocity of the spacecraft with respect to the inertial frame.

        Parameters
        ----------
        t : float, (1, N) casadi.DM or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) or (3, N) casadi.DM, SX or MX
            Velocity [m/s], GCRF.
        """

    @property
    @abstractmethod
    def max_radius(self) -> float:
        """Largest distance from the Earth's centre along the orbit [m]."""

    @property
    @abstractmethod
    def max_rate(self) -> float:
        """Upper bound on the angular rate of the position's direction (and of the velocity's) [rad/s]."""

    @property
    def max_rate_change(self) -> float:
        """Upper bound on the angular acceleration of the position's direction along its path [rad/s²]
        (zero: it turns uniformly)."""
        return 0.0

    def nadir(self, t: Expr) -> Expr:
        """Unit vector from the spacecraft to the Earth's centre.

        Parameters
        ----------
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Unit vector, inertial frame.
        """
        r = self.position(t)
        return -r / ca.norm_2(r)

    def function(self) -> ca.Function:
        """The orbit as a CasADi function of time.

        Returns
        -------
        casadi.Function
            ``orbit(t) -> (position, velocity, nadir)``: ``t`` [s]; position [m], velocity [m/s]
            and unit nadir vector, each (3, 1) in the inertial frame.
        """
        t = ca.SX.sym("t")
        return ca.Function("orbit", [t], [self.position(t), self.velocity(t), self.nadir(t)], ["t"],
                           ["position", "velocity", "nadir"])

    def lvlh_matrix(self, t: Expr) -> Expr:
        """Local-vertical local-horizontal (orbit) frame at time ``t``.

        Parameters
        ----------
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 3) casadi.DM, SX or MX
            Columns: the LVLH axes in inertial components, x along-track (along the velocity for
            a circular orbit; the local horizontal in the orbit plane otherwise), y = −orbit
            normal, z nadir; it maps LVLH components to inertial ones, ``v_I = M v_LVLH``.
        """
        z = self.nadir(t)
        v = self.velocity(t)
        y = ca.cross(z, v)
        y = y / ca.norm_2(y)
        return ca.horzcat(ca.cross(y, z), y, z)


class OrbitKind(Orbit):
    """Base of the orbit kinds a scenario names: an :class:`Orbit` registered in :data:`ORBITS` under :attr:`name`.

    ``Options`` is a frozen dataclass of the YAML keys next to ``type:`` in ``orbit``, in the
    units written there (``_km``, ``_deg``, ``_s``), each typed with its
    :class:`~ocp.options.Range` and a default, and documented in an ``Attributes`` section: the
    scenario schema reads them and the schema reference lists them.

    Attributes
    ----------
    name : str
        The registry name (``orbit.type``).
    needs_epoch : bool
        The orbit is placed by a calendar date and needs the scenario's ``epoch``.
    """

    name: ClassVar[str]
    needs_epoch: ClassVar[bool] = False

    @dataclass(frozen=True)
    class Options:
        """The kind's options: subclasses replace this empty dataclass by their own."""

    @classmethod
    @abstractmethod
    def from_options(cls, options: Any, epoch: datetime.datetime | None) -> OrbitKind:
        """The orbit of validated options.

        Parameters
        ----------
        options : Options
            The options (an instance of the class's ``Options``).
        epoch : datetime.datetime or None
            The scenario's epoch (t = 0), UTC; ``None``: none given.

        Returns
        -------
        OrbitKind
            The orbit.

        Raises
        ------
        ModelError
            Naming the option (its ``field``; ``"epoch"`` for the scenario's epoch) and what was
            expected.
        """

    def frame(self) -> str:
        """How the orbit reaches the inertial frame, for the outputs' frame name (empty: given in it).

        Returns
        -------
        str
            A short phrase, e.g. ``"TEME -> GCRF"``; empty for elements given in the GCRF.
        """
        return ""


def _real_fields(orbit: Any, names: tuple[str, ...]) -> None:
    """Refuse an orbit element that is no finite real number (``True`` read as 1 m or 1 rad, a
    text, NaN): a :class:`~ocp.errors.ModelError` naming the element, its value and its type."""
    for name in names:
        value = getattr(orbit, name)
        if not (is_real(value) and np.isfinite(value)):
            raise ModelError(name, f"expected a finite real number, got {value!r:.100} ({type(value).__name__})")


@dataclass(frozen=True)
class CircularOrbit(OrbitKind):
    """Circular Keplerian orbit, fixed in the inertial (ECI) frame.

    Parameters
    ----------
    altitude : float
        Height above the equatorial radius ``R_EARTH`` [m]; must exceed ``−0.99 R_EARTH``.
    inclination : float, optional
        Inclination of the orbit plane to the equator [rad] (default 0).
    raan : float, optional
        Right ascension of the ascending node [rad] (default 0).
    arg_latitude : float, optional
        Argument of latitude at t = 0 [rad], measured from the ascending node in the direction
        of motion (default 0).
    mu : float, optional
        Gravitational parameter [m^3/s^2] (default ``MU_EARTH``).

    Raises
    ------
    ModelError
        If the orbit radius is not positive.
    """

    name: ClassVar[str] = "circular"

    altitude: float
    inclination: float = 0.0
    raan: float = 0.0
    arg_latitude: float = 0.0
    mu: float = MU_EARTH

    @dataclass(frozen=True)
    class Options:
        """Options of ``circular`` (YAML keys of ``orbit``).

        Attributes
        ----------
        altitude_km : float
            Height of the circular orbit above the equatorial radius (6378.137 km) [km], positive
            (an orbit under the surface is an error, as a Keplerian orbit's perigee there is).
        inclination_deg : float
            Inclination of the orbit plane to the equator [deg], in [0, 180] (above 90: retrograde).
        raan_deg : float
            Right ascension of the ascending node [deg].
        arg_latitude_deg : float
            Argument of latitude at t = 0, from the ascending node [deg].
        """

        altitude_km: Annotated[float, Range(gt=0.0, le=MAX_ORBIT_KM)]
        inclination_deg: Annotated[float, Range(ge=0.0, le=180.0)] = 0.0
        raan_deg: Annotated[float, Range()] = 0.0
        arg_latitude_deg: Annotated[float, Range()] = 0.0

    @classmethod
    def from_options(cls, options: Any, epoch: datetime.datetime | None) -> CircularOrbit:
        """The circular orbit of ``options`` (kilometres and degrees converted to SI).

        Parameters
        ----------
        options : CircularOrbit.Options
            The YAML options.
        epoch : datetime.datetime or None
            Not used: the elements are given in the inertial frame at t = 0.

        Returns
        -------
        CircularOrbit
            The orbit.
        """
        return cls(altitude=options.altitude_km * 1e3, inclination=np.deg2rad(options.inclination_deg),
                   raan=np.deg2rad(options.raan_deg), arg_latitude=np.deg2rad(options.arg_latitude_deg))

    def __post_init__(self) -> None:
        _real_fields(self, ("altitude", "inclination", "raan", "arg_latitude", "mu"))
        if not self.altitude > -R_EARTH * 0.99:
            raise ModelError("altitude", f"the orbit radius must be positive, got altitude {self.altitude} m")

    @property
    def radius(self) -> float:
        """Orbit radius ``R_EARTH + altitude`` [m]."""
        return R_EARTH + self.altitude

    @property
    def mean_motion(self) -> float:
        """Mean motion ``n = sqrt(mu / radius³)`` [rad/s]: the orbit rate."""
        return float(np.sqrt(self.mu / self.radius**3))

    @property
    def max_radius(self) -> float:
        """The radius [m]."""
        return self.radius

    @property
    def max_rate(self) -> float:
        """The mean motion [rad/s]."""
        return self.mean_motion

    def position(self, t: Expr) -> Expr:
        """Position of the spacecraft from the Earth's centre.

        Parameters
        ----------
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Position [m], inertial frame (``DM`` for a numeric ``t``).
        """
        u = self.arg_latitude + self.mean_motion * t
        ci, si = np.cos(self.inclination), np.sin(self.inclination)
        cO, sO = np.cos(self.raan), np.sin(self.raan)
        return self.radius * ca.vertcat(
            ca.cos(u) * cO - ca.sin(u) * ci * sO,
            ca.cos(u) * sO + ca.sin(u) * ci * cO,
            ca.sin(u) * si,
        )

    def velocity(self, t: Expr) -> Expr:
        """Velocity of the spacecraft with respect to the inertial frame.

        Parameters
        ----------
        t : float or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) casadi.DM, SX or MX
            Velocity [m/s], inertial frame; magnitude ``radius * mean_motion``.
        """
        u = self.arg_latitude + self.mean_motion * t
        ci, si = np.cos(self.inclination), np.sin(self.inclination)
        cO, sO = np.cos(self.raan), np.sin(self.raan)
        return self.radius * self.mean_motion * ca.vertcat(
            -ca.sin(u) * cO - ca.cos(u) * ci * sO,
            -ca.sin(u) * sO + ca.cos(u) * ci * cO,
            ca.cos(u) * si,
        )


# --- Keplerian elements -----------------------------------------------------------------------


def _kepler_start(mean_anomaly: Expr, e: float) -> Expr:
    """Danby's start ``E0 = M + 0.85 e sign(sin M)`` for ``M`` wrapped to [−π, π)."""
    return mean_anomaly + 0.85 * e * ca.sign(ca.sin(mean_anomaly))


def kepler_newton_iterations(mean_anomaly: Expr, e: float, iterations: int = KEPLER_ITERATIONS) -> Expr:
    """Eccentric anomaly solving Kepler's equation ``E − e sin E = M`` by a fixed number of Newton steps.

    ``M`` is first wrapped to [−π, π); from Danby's start each Newton step at least squares the
    error once it is small: seven steps reach round-off (under 1e-15 rad) for ``e ≤ 0.95`` (tested against
    a bracketing root finder). A fixed count keeps the expression one CasADi graph, symbolic in ``M``.

    Parameters
    ----------
    mean_anomaly : float, (1, N) casadi.DM or casadi.SX / MX
        Mean anomaly ``M`` [rad], any value.
    e : float
        Eccentricity, in [0, 1).
    iterations : int, optional
        Newton steps (default :data:`KEPLER_ITERATIONS`).

    Returns
    -------
    casadi.DM, SX or MX
        Eccentric anomaly ``E`` [rad], in the turn of the wrapped ``M`` (``E − M`` ∈ [−e, e]).
    """
    m = mean_anomaly - 2 * np.pi * ca.floor((mean_anomaly + np.pi) / (2 * np.pi))
    big_e = _kepler_start(m, e)
    for _ in range(iterations):
        big_e = big_e - (big_e - e * ca.sin(big_e) - m) / (1 - e * ca.cos(big_e))
    return big_e + (mean_anomaly - m)


@dataclass(frozen=True)
class KeplerianOrbit(OrbitKind):
    """An elliptic two-body orbit of classical elements in the GCRF, optionally with J2's secular drift.

    Two-body motion: ``M(t) = M0 + n t`` with ``n = sqrt(mu / a³)``, Kepler's equation solved by
    :func:`kepler_newton_iterations`. With ``j2`` the node, the argument of perigee and the mean
    anomaly drift at the first-order secular rates of the Earth's oblateness (Vallado,
    *Fundamentals of Astrodynamics*, eq. 9-41; ``p = a (1 − e²)``)::

        dΩ/dt = −3/2 n J2 (R/p)² cos i
        dω/dt =  3/4 n J2 (R/p)² (4 − 5 sin² i)
        dM/dt =  n + 3/4 n J2 (R/p)² sqrt(1 − e²) (3 cos² i − 1)

    the elements being mean elements; the short-period terms (up to ~10 km in low orbit) are not
    modelled. :meth:`velocity` is the exact time derivative of :meth:`position`.

    Parameters
    ----------
    semi_major_axis : float
        Semi-major axis ``a`` [m].
    eccentricity : float, optional
        In [0, 1) (default 0).
    inclination : float, optional
        [rad] (default 0).
    raan : float, optional
        Right ascension of the ascending node at t = 0 [rad] (default 0).
    arg_perigee : float, optional
        Argument of perigee at t = 0 [rad] (default 0).
    mean_anomaly : float, optional
        Mean anomaly at t = 0 [rad] (default 0).
    j2 : bool, optional
        Apply J2's secular drift (default False).
    mu : float, optional
        Gravitational parameter [m^3/s^2] (default ``MU_EARTH``).

    Raises
    ------
    ModelError
        For an eccentricity outside [0, 1) (field ``"eccentricity"``), or a perigee under the
        Earth's equatorial radius (field ``"semi_major_axis"``).
    """

    name: ClassVar[str] = "keplerian"

    semi_major_axis: float
    eccentricity: float = 0.0
    inclination: float = 0.0
    raan: float = 0.0
    arg_perigee: float = 0.0
    mean_anomaly: float = 0.0
    j2: bool = False
    mu: float = MU_EARTH

    @dataclass(frozen=True)
    class Options:
        """Options of ``keplerian`` (YAML keys of ``orbit``): give ``semi_major_axis_km`` or
        ``altitude_km``, and at most one of ``mean_anomaly_deg`` and ``true_anomaly_deg``.

        Attributes
        ----------
        semi_major_axis_km : float or None
            Semi-major axis a [km].
        altitude_km : float or None
            The semi-major axis less the equatorial radius, a − 6378.137 km [km] (the circular
            orbit's ``altitude_km`` when the eccentricity is 0).
        eccentricity : float
            Eccentricity, in [0, 1); the perigee a (1 − e) must clear the equatorial radius.
        inclination_deg : float
            Inclination to the GCRF equator [deg], in [0, 180] (above 90: retrograde).
        raan_deg : float
            Right ascension of the ascending node at t = 0 [deg].
        arg_perigee_deg : float
            Argument of perigee at t = 0 [deg].
        mean_anomaly_deg : float or None
            Mean anomaly at t = 0 [deg] (``null``: 0, unless ``true_anomaly_deg`` is given).
        true_anomaly_deg : float or None
            True anomaly at t = 0 [deg] (instead of ``mean_anomaly_deg``).
        j2 : bool
            Let the node, the perigee and the mean anomaly drift at J2's first-order secular rates.
        """

        semi_major_axis_km: Annotated[float | None, Range(gt=0.0, le=MAX_ORBIT_KM)] = None
        altitude_km: Annotated[float | None, Range(le=MAX_ORBIT_KM)] = None
        eccentricity: Annotated[float, Range(ge=0.0, lt=1.0)] = 0.0
        inclination_deg: Annotated[float, Range(ge=0.0, le=180.0)] = 0.0
        raan_deg: Annotated[float, Range()] = 0.0
        arg_perigee_deg: Annotated[float, Range()] = 0.0
        mean_anomaly_deg: Annotated[float | None, Range()] = None
        true_anomaly_deg: Annotated[float | None, Range()] = None
        j2: bool = False

        def __post_init__(self) -> None:
            if (self.semi_major_axis_km is None) == (self.altitude_km is None):
                raise InvalidOption("semi_major_axis_km", "give exactly one of semi_major_axis_km and altitude_km")
            if self.mean_anomaly_deg is not None and self.true_anomaly_deg is not None:
                raise InvalidOption("true_anomaly_deg", "give at most one of mean_anomaly_deg and true_anomaly_deg")

    @classmethod
    def from_options(cls, options: Any, epoch: datetime.datetime | None) -> KeplerianOrbit:
        """The orbit of ``options`` (kilometres and degrees converted; a true anomaly to a mean one).

        Parameters
        ----------
        options : KeplerianOrbit.Options
            The YAML options.
        epoch : datetime.datetime or None
            Not used: the elements are given in the GCRF at t = 0.

        Returns
        -------
        KeplerianOrbit
            The orbit.

        Raises
        ------
        ModelError
            A perigee under the surface (field: the key that gave the semi-major axis).
        """
        a_key = "semi_major_axis_km" if options.semi_major_axis_km is not None else "altitude_km"
        a = (options.semi_major_axis_km if options.semi_major_axis_km is not None
             else options.altitude_km + R_EARTH / 1e3) * 1e3
        e = options.eccentricity
        if options.true_anomaly_deg is not None:
            nu = np.deg2rad(options.true_anomaly_deg)
            big_e = 2 * np.arctan2(np.sqrt(1 - e) * np.sin(nu / 2), np.sqrt(1 + e) * np.cos(nu / 2))
            mean = float(big_e - e * np.sin(big_e))
        else:
            mean = float(np.deg2rad(options.mean_anomaly_deg or 0.0))
        try:
            return cls(a, e, float(np.deg2rad(options.inclination_deg)), float(np.deg2rad(options.raan_deg)),
                       float(np.deg2rad(options.arg_perigee_deg)), mean, bool(options.j2))
        except ModelError as error:
            raise ModelError(a_key if error.field == "semi_major_axis" else error.field, error.message) from None

    def __post_init__(self) -> None:
        _real_fields(self, ("semi_major_axis", "eccentricity", "inclination", "raan", "arg_perigee", "mean_anomaly",
                            "mu"))
        if not (0.0 <= self.eccentricity < 1.0):
            raise ModelError("eccentricity", f"expected an elliptic orbit, 0 <= e < 1, got {self.eccentricity!r}")
        if not (np.isfinite(self.semi_major_axis) and self.semi_major_axis > 0):
            raise ModelError("semi_major_axis", f"expected a positive semi-major axis, got {self.semi_major_axis!r} m")
        if self.perigee_radius < R_EARTH:
            raise ModelError("semi_major_axis", f"the perigee a (1 - e) = {self.perigee_radius / 1e3:.3f} km lies "
                                                f"{(R_EARTH - self.perigee_radius) / 1e3:.3f} km under the Earth's "
                                                f"surface (equatorial radius {R_EARTH / 1e3:.3f} km); raise the "
                                                "semi-major axis or lower the eccentricity")

    @property
    def perigee_radius(self) -> float:
        """``a (1 − e)`` [m]."""
        return self.semi_major_axis * (1.0 - self.eccentricity)

    @property
    def max_radius(self) -> float:
        """The apogee radius ``a (1 + e)`` [m]."""
        return self.semi_major_axis * (1.0 + self.eccentricity)

    @property
    def mean_motion(self) -> float:
        """Two-body mean motion ``n = sqrt(mu / a³)`` [rad/s]."""
        return float(np.sqrt(self.mu / self.semi_major_axis**3))

    @property
    def secular_rates(self) -> tuple[float, float, float]:
        """``(dΩ/dt, dω/dt, dM/dt)`` [rad/s]: J2's secular rates with ``j2``, else ``(0, 0, n)``."""
        n = self.mean_motion
        if not self.j2:
            return 0.0, 0.0, n
        e, i = self.eccentricity, self.inclination
        k = n * J2_EARTH * (R_EARTH / (self.semi_major_axis * (1 - e**2))) ** 2
        return (-1.5 * k * np.cos(i), 0.75 * k * (4 - 5 * np.sin(i) ** 2),
                n + 0.75 * k * np.sqrt(1 - e**2) * (3 * np.cos(i) ** 2 - 1))

    @property
    def max_rate(self) -> float:
        """The angular rate at perigee, ``dM/dt (1 + e)² / (1 − e²)^{3/2}``, plus the drift of the plane [rad/s]."""
        raan_rate, argp_rate, mean_rate = self.secular_rates
        e = self.eccentricity
        return abs(mean_rate) * (1 + e) ** 2 / (1 - e**2) ** 1.5 + abs(raan_rate) + abs(argp_rate)

    @property
    def max_rate_change(self) -> float:
        """``2 max|ṙ/r| max_rate`` with ``|ṙ/r| ≤ e (1 + e) n / (1 − e²)^{3/2}`` [rad/s²]."""
        e = self.eccentricity
        return 2.0 * self.max_rate * e * (1 + e) * self.secular_rates[2] / (1 - e**2) ** 1.5

    def _plane(self, t: Expr) -> tuple[Expr, Expr, Expr, Expr, Expr, Expr]:
        """In-plane position (x, y) and velocity (vx, vy) in the node frame, and the node angle Ω, at ``t``."""
        raan_rate, argp_rate, mean_rate = self.secular_rates
        a, e = self.semi_major_axis, self.eccentricity
        b = a * np.sqrt(1 - e**2)
        t = _row(t)
        big_e = kepler_newton_iterations(self.mean_anomaly + mean_rate * t, e)
        ce, se = ca.cos(big_e), ca.sin(big_e)
        xp, yp = a * (ce - e), b * se                   # perifocal position
        e_dot = mean_rate / (1 - e * ce)
        vxp, vyp = -a * se * e_dot, b * ce * e_dot      # perifocal velocity
        w = self.arg_perigee + argp_rate * t
        cw, sw = ca.cos(w), ca.sin(w)
        x, y = xp * cw - yp * sw, xp * sw + yp * cw     # node frame (x to the ascending node)
        vx = vxp * cw - vyp * sw - argp_rate * y
        vy = vxp * sw + vyp * cw + argp_rate * x
        return x, y, vx, vy, self.raan + raan_rate * t, ca.DM(raan_rate)

    def position(self, t: Expr) -> Expr:
        """Position of the spacecraft from the Earth's centre.

        Parameters
        ----------
        t : float, (1, N) casadi.DM or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) or (3, N) casadi.DM, SX or MX
            Position [m], GCRF.
        """
        x, y, _, _, node, _ = self._plane(t)
        ci, si = np.cos(self.inclination), np.sin(self.inclination)
        cO, sO = ca.cos(node), ca.sin(node)
        return ca.vertcat(x * cO - y * ci * sO, x * sO + y * ci * cO, y * si)

    def velocity(self, t: Expr) -> Expr:
        """Velocity of the spacecraft, the time derivative of :meth:`position`.

        Parameters
        ----------
        t : float, (1, N) casadi.DM or scalar casadi.SX / MX
            Time since t = 0 [s].

        Returns
        -------
        (3, 1) or (3, N) casadi.DM, SX or MX
            Velocity [m/s], GCRF.
        """
        x, y, vx, vy, node, raan_rate = self._plane(t)
        ci, si = np.cos(self.inclination), np.sin(self.inclination)
        cO, sO = ca.cos(node), ca.sin(node)
        px, py = x * cO - y * ci * sO, x * sO + y * ci * cO
        return ca.vertcat(vx * cO - vy * ci * sO - raan_rate * py, vx * sO + vy * ci * cO + raan_rate * px, vy * si)


# --- two-line elements ------------------------------------------------------------------------


def _tai(epoch: datetime.datetime, t: NDArray) -> tuple[NDArray, NDArray]:
    """TAI two-part Julian date of ``epoch + t`` (``t`` SI seconds, leap seconds counted)."""
    import erfa

    second = epoch.second + epoch.microsecond * 1e-6
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)  # after ERFA's last leap second: held (see ephemeris)
        utc1, utc2 = erfa.dtf2d("UTC", epoch.year, epoch.month, epoch.day, epoch.hour, epoch.minute, second)
        tai1, tai2 = erfa.utctai(utc1, utc2)
    return np.full(t.shape, float(tai1)), float(tai2) + t / 86400.0


def teme_to_gcrf_matrices(epoch: datetime.datetime, t: ArrayLike) -> NDArray:
    """Rotation matrices from SGP4's TEME frame to the GCRF at ``epoch + t``.

    TEME's x axis lies at the Greenwich mean sidereal angle of the IAU 1982 model (GMST82, which
    SGP4 uses) from the Greenwich meridian, about the true pole of date (Vallado et al. 2006,
    "Revisiting Spacetrack Report #3"). A TEME vector's components in the true equator and
    equinox of date (TOD) follow by turning it about that pole by ``GAST − GMST82`` (an equation
    of the equinoxes), and the GCRF from TOD by the transpose of the IAU 2006/2000A
    bias-precession-nutation matrix (ERFA's ``gmst82``, ``gst06a``, ``pnm06a``; TT from UTC by
    ERFA's leap-second table)::

        r_GCRF = NPB(t)ᵀ Rz(GAST(t) − GMST82(t)) r_TEME    (Rz(a): a vector turned by a about z)

    The two sidereal angles are taken with UT1 = UTC: their difference changes by 1e-11 rad over
    the 0.9 s UT1 − UTC may reach, so no Earth orientation data are needed; polar motion does not
    enter. The result agrees with ERFA's CIO-based route (``c2t06a`` with GMST82, tested) to under
    a millimetre in low orbit, and with the older IAU 1976/1980 route to the few milliarcseconds
    between the nutation models (centimetres), far below SGP4's own error (about a kilometre at
    the TLE epoch, growing by kilometres a day). The matrices' rate (precession, 50″ a year) is
    neglected in the velocity (under 1e-4 m/s).

    Parameters
    ----------
    epoch : datetime.datetime
        Instant of t = 0, UTC.
    t : float or (N,) array_like
        SI seconds since the epoch [s].

    Returns
    -------
    (N, 3, 3) ndarray
        ``M`` with ``r_GCRF = M r_TEME``.
    """
    import erfa

    t = np.atleast_1d(np.asarray(t, dtype=float)).reshape(-1)
    tai1, tai2 = _tai(parse_utc(epoch), t)
    tt1, tt2 = erfa.taitt(tai1, tai2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        ut1, ut2 = erfa.taiutc(tai1, tai2)                     # UT1 = UTC (see above)
    npb = erfa.pnm06a(tt1, tt2)                                # GCRS -> true of date
    angle = erfa.gst06a(ut1, ut2, tt1, tt2) - erfa.gmst82(ut1, ut2)  # the equation of the equinoxes
    c, s = np.cos(angle), np.sin(angle)
    zeros, ones = np.zeros_like(angle), np.ones_like(angle)
    r3 = np.stack([np.stack([c, -s, zeros], -1), np.stack([s, c, zeros], -1),
                   np.stack([zeros, zeros, ones], -1)], -2)    # TEME -> TOD (vectors turned by the angle)
    return np.einsum("nji,njk->nik", npb, r3)


@dataclass(frozen=True)
class TLEOrbit(OrbitKind):
    """A two-line element set propagated by SGP4, in the GCRF, tabulated and interpolated in time.

    SGP4 (the ``sgp4`` package, Vallado's reference code with the WGS-72 constants the TLEs are
    fitted with) gives TEME positions and velocities at nodes ``k·step`` over ``[0, span]``; they
    are rotated to the GCRF (:func:`teme_to_gcrf_matrices`) and interpolated by CasADi cubic
    B-splines in time (position and velocity separately). At the nodes the spline reproduces the
    table to under 1e-9 km (the spline's fit, 6e-7 m for the ISS); between them, at the default
    10 s step in low orbit, it is within 3 mm of SGP4 in position (2.2 mm for the ISS, the error
    growing as the fourth power of the step: 0.17 m at 30 s) and 1e-5 m/s in velocity (tested at
    the mid-points of six hours of nodes). SGP4 itself is good to about a kilometre near the TLE
    epoch: the interpolation adds nothing that matters. ``t = 0`` is ``epoch`` (the scenario's),
    which need not be the TLE's epoch; SGP4 is given the UTC instant of ``epoch + t`` (``t``
    counts SI seconds, leap seconds included).

    Parameters
    ----------
    line1, line2 : str
        The two lines (69 characters each, checksums verified).
    epoch : str
        Instant of t = 0, ISO 8601 UTC (see :func:`~ocp.dynamics.ephemeris.parse_utc`).
    span : float, optional
        Tabulated window [s] (default one day); times beyond it extrapolate the last cubic and are
        wrong: the scenario loader refuses a run that leaves it.
    step : float, optional
        Spacing of the nodes [s] (default 10).
    mu : float, optional
        Gravitational parameter of the gravity gradient [m^3/s^2] (default ``MU_EARTH``).

    Raises
    ------
    ModelError
        A malformed line or a bad checksum (field ``"line1"``/``"line2"``), an element set SGP4
        refuses, an epoch more than :data:`TLE_EPOCH_REFUSE_DAYS` from the TLE's (field
        ``"epoch"``), a bad span or step.
    """

    name: ClassVar[str] = "tle"
    needs_epoch: ClassVar[bool] = True

    line1: str
    line2: str
    epoch: str
    span: float = 86400.0
    step: float = 10.0
    mu: float = MU_EARTH

    @dataclass(frozen=True)
    class Options:
        """Options of ``tle`` (YAML keys of ``orbit``); the scenario's ``epoch`` is t = 0 and must be given.

        Attributes
        ----------
        line1 : str
            First line of the element set (69 characters; its checksum is verified).
        line2 : str
            Second line (69 characters; its checksum is verified).
        span_s : float
            Tabulated window from t = 0 [s]; the run (with the loader's margin) must fit in it.
        step_s : float
            Spacing of the table's nodes [s] (cubic B-spline between them).
        """

        line1: str
        line2: str
        span_s: Annotated[float, Range(gt=0.0)] = 86400.0
        step_s: Annotated[float, Range(gt=0.0, le=60.0)] = 10.0

    @classmethod
    def from_options(cls, options: Any, epoch: datetime.datetime | None) -> TLEOrbit:
        """The TLE orbit of ``options`` with t = 0 at ``epoch``.

        Parameters
        ----------
        options : TLEOrbit.Options
            The YAML options.
        epoch : datetime.datetime or None
            The scenario's epoch, UTC; required.

        Returns
        -------
        TLEOrbit
            The orbit.

        Raises
        ------
        ModelError
            Without an epoch (field ``"epoch"``) and as :class:`TLEOrbit`.
        """
        if epoch is None:
            raise ModelError("epoch", "a TLE orbit needs the scenario's epoch (t = 0), a UTC date-time like "
                                      "2025-01-01T06:00:00Z; none is given")
        return cls(options.line1, options.line2, epoch.isoformat(), span=options.span_s, step=options.step_s)

    def __post_init__(self) -> None:
        for field_name, line, number in (("line1", self.line1, "1"), ("line2", self.line2, "2")):
            _check_line(field_name, line, number)
        if self.line1[2:7] != self.line2[2:7]:
            raise ModelError("line2", f"the satellite number {self.line2[2:7]!r} differs from line 1's "
                                      f"{self.line1[2:7]!r}")
        if not (np.isfinite(self.step) and self.step > 0):
            raise ModelError("step_s", f"expected a positive node spacing, got {self.step}")
        if not (np.isfinite(self.span) and self.span > 0):
            raise ModelError("span_s", f"expected a positive window, got {self.span}")
        if self.span / self.step > MAX_TLE_NODES:
            raise ModelError("span_s", f"span / step = {self.span / self.step:.0f} nodes; at most {MAX_TLE_NODES}")
        satellite = self.satellite
        if satellite.error:
            raise ModelError("line2", f"SGP4 refuses the element set (error {satellite.error})")
        days = self.epoch_offset_days
        if abs(days) > TLE_EPOCH_REFUSE_DAYS:
            raise ModelError("epoch", f"the TLE's epoch {self.tle_epoch.isoformat()}Z lies {abs(days):.1f} days "
                                      f"from t = 0 ({parse_utc(self.epoch).isoformat()}Z); SGP4 is not meant to "
                                      f"propagate beyond {TLE_EPOCH_REFUSE_DAYS:g} days: use a recent element set")

    @property
    def satellite(self) -> Any:
        """The ``sgp4.api.Satrec`` of the two lines."""
        from sgp4.api import Satrec

        return Satrec.twoline2rv(self.line1, self.line2)

    @property
    def tle_epoch(self) -> datetime.datetime:
        """The element set's own epoch, naive UTC."""
        satellite = self.satellite
        days = (satellite.jdsatepoch - 2451544.5) + satellite.jdsatepochF
        return datetime.datetime(2000, 1, 1) + datetime.timedelta(days=float(days))

    @property
    def epoch_offset_days(self) -> float:
        """Days from the TLE's epoch to t = 0 (positive: t = 0 after it)."""
        return (parse_utc(self.epoch) - self.tle_epoch).total_seconds() / 86400.0

    @property
    def nodes(self) -> NDArray:
        """(N,) times of the table [s], ``k * step`` from 0 to at least ``span`` (at least four nodes)."""
        count = max(4, int(np.ceil(self.span / self.step - 1e-9)) + 1)
        return np.arange(count) * self.step

    @property
    def valid_until(self) -> float:
        """End of the tabulated window [s]: the last node."""
        return float(self.nodes[-1])

    def teme(self, t: ArrayLike) -> tuple[NDArray, NDArray]:
        """SGP4's own state at ``epoch + t`` (not interpolated), TEME frame.

        Parameters
        ----------
        t : float or (N,) array_like
            SI seconds since the epoch [s] (leap seconds counted; SGP4 is given the UTC instant).

        Returns
        -------
        position : (N, 3) ndarray
            [km], TEME (SGP4's units).
        velocity : (N, 3) ndarray
            [km/s], TEME.

        Raises
        ------
        ModelError
            (field ``"line2"``) When SGP4 fails at a time (decay, eccentricity out of range).
        """
        import erfa

        t = np.atleast_1d(np.asarray(t, dtype=float)).reshape(-1)
        tai1, tai2 = _tai(parse_utc(self.epoch), t)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", erfa.ErfaWarning)
            utc1, utc2 = erfa.taiutc(tai1, tai2)
        errors, position, velocity = self.satellite.sgp4_array(np.asarray(utc1, float), np.asarray(utc2, float))
        if np.any(errors):
            first = int(np.flatnonzero(errors)[0])
            raise ModelError("line2", f"SGP4 fails at t = {t[first]:g} s (error {int(errors[first])}: decayed or "
                                      "elements out of range)")
        return position, velocity

    def exact(self, t: ArrayLike) -> tuple[NDArray, NDArray]:
        """SGP4's state at ``epoch + t`` rotated to the GCRF (not interpolated).

        Parameters
        ----------
        t : float or (N,) array_like
            SI seconds since the epoch [s].

        Returns
        -------
        position : (N, 3) ndarray
            [m], GCRF.
        velocity : (N, 3) ndarray
            [m/s], GCRF.
        """
        position, velocity = self.teme(t)
        rotation = teme_to_gcrf_matrices(parse_utc(self.epoch), t)
        return (np.einsum("nij,nj->ni", rotation, position) * 1e3,
                np.einsum("nij,nj->ni", rotation, velocity) * 1e3)

    @cached_property
    def _tables(self) -> tuple[ca.Function, ca.Function, float, float, float]:
        """The position and velocity splines and the bounds, built on first use."""
        nodes = self.nodes
        position, velocity = self.exact(nodes)
        radius = np.linalg.norm(position, axis=1)
        rate = np.linalg.norm(np.cross(position, velocity), axis=1) / radius**2
        change = np.abs(np.gradient(rate, nodes)) if nodes.size > 1 else np.zeros(1)
        return (ca.interpolant("tle_position", "bspline", [nodes], position.ravel()),
                ca.interpolant("tle_velocity", "bspline", [nodes], velocity.ravel()),
                float(radius.max()), float(rate.max()), float(change.max()))

    @property
    def max_radius(self) -> float:
        """Largest radius at the table's nodes, plus 1 % [m]."""
        return 1.01 * self._tables[2]

    @property
    def max_rate(self) -> float:
        """Largest angular rate at the nodes, plus 5 % [rad/s]."""
        return 1.05 * self._tables[3]

    @property
    def max_rate_change(self) -> float:
        """Largest change of the angular rate between nodes, doubled [rad/s²]."""
        return 2.0 * self._tables[4]

    def _interpolate(self, spline: ca.Function, t: Expr) -> Expr:
        t = _row(t)
        if isinstance(t, ca.DM) and t.numel() > 1:
            return spline.map(t.numel())(ca.reshape(t, 1, -1))
        return spline(t)

    def position(self, t: Expr) -> Expr:
        """Position of the spacecraft, interpolated from the SGP4 table.

        Parameters
        ----------
        t : float, (1, N) casadi.DM or scalar casadi.SX / MX
            Time since t = 0 [s], within ``[0, valid_until]``.

        Returns
        -------
        (3, 1) or (3, N) casadi.DM, SX or MX
            Position [m], GCRF.
        """
        return self._interpolate(self._tables[0], t)

    def velocity(self, t: Expr) -> Expr:
        """Velocity of the spacecraft, interpolated from the SGP4 table.

        Parameters
        ----------
        t : float, (1, N) casadi.DM or scalar casadi.SX / MX
            Time since t = 0 [s], within ``[0, valid_until]``.

        Returns
        -------
        (3, 1) or (3, N) casadi.DM, SX or MX
            Velocity [m/s], GCRF.
        """
        return self._interpolate(self._tables[1], t)

    def frame(self) -> str:
        """``"SGP4 TEME -> GCRF"``: the conversion the positions went through.

        Returns
        -------
        str
            The phrase.
        """
        return "SGP4 TEME -> GCRF"


def _check_line(field_name: str, line: str, number: str) -> None:
    """A TLE line's length, line number and modulo-10 checksum (digits count, ``-`` counts 1)."""
    text = line.rstrip()
    if len(text) != 69 or text[0] != number:
        raise ModelError(field_name, f"expected TLE line {number}: 69 characters starting with {number!r}, got "
                                     f"{len(text)} characters starting {text[:10]!r}")
    checksum = sum(int(c) if c.isdigit() else 1 if c == "-" else 0 for c in text[:68]) % 10
    if not text[68].isdigit() or int(text[68]) != checksum:
        raise ModelError(field_name, f"bad checksum: the last digit is {text[68]!r}, the line's digits (a '-' "
                                     f"counting 1) sum to {checksum} modulo 10; the line is corrupt")


ORBITS: dict[str, type[OrbitKind]] = {kind.name: kind for kind in (CircularOrbit, KeplerianOrbit, TLEOrbit)}
"""The orbit kinds a scenario names (``orbit.type``): registry name -> class (:class:`OrbitKind`).
Register a kind of your own by adding its class under its ``name``."""
