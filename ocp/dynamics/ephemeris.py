"""The Sun and the Moon seen from the Earth's centre: an offline ephemeris and the epoch it is read at.

Positions come from JPL's planetary ephemeris DE421 (Folkner et al. 2008), read through
``jplephem``'s Chebyshev evaluator from the ``de421`` package, which ships the coefficients: nothing
is downloaded at run time. DE421 covers 1899-07-29 to 2200-02-02; :data:`EPHEMERIS_RANGE` is the
part this module accepts (UTC is defined from 1960).

Frames and time:

* Positions are **geocentric, in the GCRF** (ICRF axes, origin the Earth's centre), in metres: the
  differences of DE421's barycentric positions (the Earth from the Earth-Moon barycentre,
  ``earth = earthmoon − moon / (1 + EMRAT)``; DE421's Moon is already geocentric). The relativistic
  difference between those differences and true GCRS coordinates is of order 1e-8 and neglected.
* They are **geometric**: the body where it is at the instant, with no light-time correction and no
  aberration (the apparent Sun lies 20″ from the geometric one, the apparent Moon under 1″ from it).
* The epoch is **UTC**. ``epoch + t`` means ``t`` SI seconds elapsed after the epoch, so that a
  leap second inside a run is counted: UTC → TAI (leap seconds from ERFA's table) → TT (+32.184 s)
  → TDB (ERFA's ``dtdb`` series, at the geocentre), the time argument of DE421. After the last leap
  second ERFA knows, TAI − UTC is held at its last value (37 s since 2017-01-01); a leap second
  announced later would shift the bodies by the motion of a second (the Moon 1.5e-4°).
"""
from __future__ import annotations

import datetime
import warnings
from functools import cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp.errors import ModelError

__all__ = ["EPHEMERIS_RANGE", "check_epoch", "moon_position", "parse_utc", "sun_position", "tdb_julian_date"]

Array = NDArray[np.float64]

EPHEMERIS_RANGE = (datetime.datetime(1960, 1, 1), datetime.datetime(2200, 1, 1))
"""UTC instants between which :func:`sun_position` and :func:`moon_position` answer (DE421's span,
from the start of UTC in 1960)."""

_KM = 1e3
_SECONDS_PER_DAY = 86400.0


def parse_utc(value: str | datetime.date | datetime.datetime) -> datetime.datetime:
    """An instant as a naive UTC ``datetime``.

    Parameters
    ----------
    value : str, datetime.date or datetime.datetime
        ISO 8601 text: a date (``"2025-01-01"``, 00:00 UTC) or a date-time
        (``"2025-01-01T06:00:00"``), with ``Z`` or an explicit offset (``+02:00``, converted to UTC)
        or none (UTC); a date (00:00 UTC); a datetime (naive means UTC, an aware one is converted).

    Returns
    -------
    datetime.datetime
        The instant in UTC, without time zone.

    Raises
    ------
    ModelError
        (field ``"epoch"``) For anything else: text that is no ISO 8601 date or date-time (a leap
        second ``:60`` included: write the second before it and count on from there), a number.
    """
    if isinstance(value, datetime.datetime):
        instant = value
    elif isinstance(value, datetime.date):
        instant = datetime.datetime(value.year, value.month, value.day)
    elif isinstance(value, str):
        text = value.strip()
        if text[-1:] in ("Z", "z"):
            text = text[:-1] + "+00:00"
        try:
            instant = datetime.datetime.fromisoformat(text)
        except ValueError:
            hint = (" (a leap second cannot be an epoch: give the second before it; t counts SI seconds "
                    "across it)") if ":60" in text else ""
            raise ModelError("epoch", "expected a date like 2025-01-01 or a UTC date-time like "
                                      f"2025-01-01T06:00:00Z, got {value[:40]!r}{hint}") from None
    else:
        raise ModelError("epoch", "expected a date like 2025-01-01 or a UTC date-time like "
                                  f"2025-01-01T06:00:00Z, got {type(value).__name__} {str(value)[:40]!r}")
    if instant.tzinfo is not None:
        instant = instant.astimezone(datetime.timezone.utc).replace(tzinfo=None)
    return instant


def check_epoch(epoch: str | datetime.date | datetime.datetime, duration_s: float = 0.0) -> datetime.datetime:
    """Refuse an epoch whose run leaves the ephemeris.

    Parameters
    ----------
    epoch : str, datetime.date or datetime.datetime
        Start of the run, UTC (see :func:`parse_utc`).
    duration_s : float, optional
        Length of the run [s], non-negative (default 0).

    Returns
    -------
    datetime.datetime
        The epoch, naive UTC.

    Raises
    ------
    ModelError
        (field ``"epoch"``) When the epoch or ``epoch + duration_s`` lies outside
        :data:`EPHEMERIS_RANGE`, or for an epoch :func:`parse_utc` refuses.
    """
    start = parse_utc(epoch)
    if not (np.isfinite(duration_s) and duration_s >= 0.0):
        raise ModelError("epoch", f"the run's duration must be a finite non-negative number of seconds, got {duration_s!r}")
    end = start + datetime.timedelta(seconds=float(duration_s))
    low, high = EPHEMERIS_RANGE
    if not (low <= start and end <= high):
        raise ModelError("epoch", f"the ephemeris (JPL DE421) covers {low:%Y-%m-%d} to {high:%Y-%m-%d} UTC; "
                                  f"the run from {start.isoformat()} for {duration_s:g} s leaves it")
    return start


def tdb_julian_date(epoch: datetime.datetime, t: ArrayLike) -> tuple[Array, Array]:
    """Barycentric dynamical time of ``epoch + t`` as a two-part Julian date.

    Parameters
    ----------
    epoch : datetime.datetime
        Instant of ``t = 0``, UTC (naive; see :func:`parse_utc`).
    t : float or (N,) array_like
        SI seconds elapsed since the epoch [s] (leap seconds between are counted).

    Returns
    -------
    jd1, jd2 : (N,) ndarray
        TDB Julian date ``jd1 + jd2`` [d] (``jd1`` a whole or half day, ``jd2`` the rest).
    """
    import erfa  # the ephemeris' time scales; imported on use like the ephemeris itself

    t = np.atleast_1d(np.asarray(t, dtype=float)).reshape(-1)
    epoch = parse_utc(epoch)
    second = epoch.second + epoch.microsecond * 1e-6
    with warnings.catch_warnings():
        # "dubious year": ERFA's leap-second table ends; TAI - UTC is held at its last value (see module)
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        utc1, utc2 = erfa.dtf2d("UTC", epoch.year, epoch.month, epoch.day, epoch.hour, epoch.minute, second)
        tai1, tai2 = erfa.utctai(utc1, utc2)
    tt1, tt2 = erfa.taitt(tai1, tai2)
    tt1 = np.full(t.shape, float(tt1))
    tt2 = float(tt2) + t / _SECONDS_PER_DAY
    day_fraction = np.mod(tt2 + 0.5, 1.0)  # only the topocentric terms use it; zero at the geocentre
    tdb_minus_tt = erfa.dtdb(tt1, tt2, day_fraction, 0.0, 0.0, 0.0)
    tdb1, tdb2 = erfa.tttdb(tt1, tt2, tdb_minus_tt)
    return np.asarray(tdb1, dtype=float), np.asarray(tdb2, dtype=float)


@cache
def _de421() -> Any:
    """DE421 through jplephem's package interface (loaded once)."""
    import de421
    from jplephem import Ephemeris

    return Ephemeris(de421)


def _geocentric(body: str, epoch: datetime.datetime, t: ArrayLike) -> Array:
    """Geocentric GCRF position [m] of ``"sun"`` or ``"moon"`` at ``epoch + t``, (N, 3)."""
    tt = np.atleast_1d(np.asarray(t, dtype=float)).reshape(-1)
    epoch = check_epoch(epoch, float(np.max(tt, initial=0.0)))
    if np.min(tt, initial=0.0) < 0.0:
        check_epoch(epoch - datetime.timedelta(seconds=-float(np.min(tt))), 0.0)
    tdb1, tdb2 = tdb_julian_date(epoch, tt)
    ephemeris = _de421()
    moon = ephemeris.position("moon", tdb1, tdb2)  # km, Earth to Moon
    if body == "moon":
        return np.ascontiguousarray(moon.T) * _KM
    earth = ephemeris.position("earthmoon", tdb1, tdb2) - moon * ephemeris.earth_share
    return np.ascontiguousarray((ephemeris.position("sun", tdb1, tdb2) - earth).T) * _KM


def sun_position(epoch: datetime.datetime, t: ArrayLike) -> Array:
    """Position of the Sun from the Earth's centre (JPL DE421; geometric).

    Parameters
    ----------
    epoch : datetime.datetime
        Instant of ``t = 0``, UTC (see :func:`parse_utc`).
    t : float or (N,) array_like
        SI seconds since the epoch [s]; one call evaluates them all.

    Returns
    -------
    (N, 3) ndarray
        Geocentric positions [m], GCRF (ICRF axes); no light time, no aberration.

    Raises
    ------
    ModelError
        (field ``"epoch"``) When a time lies outside :data:`EPHEMERIS_RANGE`.
    """
    return _geocentric("sun", epoch, t)


def moon_position(epoch: datetime.datetime, t: ArrayLike) -> Array:
    """Position of the Moon from the Earth's centre (JPL DE421; geometric).

    Parameters
    ----------
    epoch : datetime.datetime
        Instant of ``t = 0``, UTC (see :func:`parse_utc`).
    t : float or (N,) array_like
        SI seconds since the epoch [s]; one call evaluates them all.

    Returns
    -------
    (N, 3) ndarray
        Geocentric positions [m], GCRF (ICRF axes); no light time, no aberration.

    Raises
    ------
    ModelError
        (field ``"epoch"``) When a time lies outside :data:`EPHEMERIS_RANGE`.
    """
    return _geocentric("moon", epoch, t)
