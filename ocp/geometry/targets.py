r"""Attitudes given in mission terms: a boresight on a target with a second axis fixing the roll,
attitudes relative to the orbit's frames, and points on the ground.

* :func:`two_vector_attitude`: the attitude that puts a body axis (a sensor's boresight) exactly on
  an inertial direction and a second body axis in the half-plane of the boresight's direction and
  a second inertial direction (the TRIAD construction with the primary pair exact).
* :data:`ATTITUDE_FRAMES`: the frames an attitude may be written in (``inertial``; ``lvlh`` and
  ``rtn`` of the orbit at an instant), each a rotation matrix from the frame to the inertial frame.
* :func:`geodetic_to_ecef`, :func:`itrs_to_gcrf` and :func:`ground_point`: a point given by
  WGS-84 geodetic latitude, longitude and height, in the Earth-fixed frame (ITRS), then in the
  inertial frame (GCRF) at ``epoch + t``.

The Earth's orientation is ERFA's IAU 2006/2000A precession-nutation with the Earth rotation angle
(``c2t06a``) and two approximations: UT1 is taken as UTC (``|UT1 − UTC| < 0.9 s``, a rotation of at
most 13.5″: 420 m on the equator) and the polar motion as zero (under 0.5″, 15 m). A ground point's
inertial position is so within about 0.5 km, its direction from a low orbit within about 0.05°;
the orbit model itself is usually the larger error. Frames and conventions: :doc:`/architecture`
(quaternions scalar first, body to inertial; SI units, radians).
"""
from __future__ import annotations

import datetime
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.dynamics.ephemeris import parse_utc
from ocp.errors import ModelError
from ocp.geometry.directions import Geometry

__all__ = ["ATTITUDE_FRAMES", "MIN_SEPARATION", "WGS84_A", "WGS84_F", "AttitudeFrame", "geodetic_to_ecef",
           "ground_point", "itrs_to_gcrf", "two_vector_attitude"]

Array = NDArray[np.float64]

WGS84_A = 6378137.0
"""WGS-84 semi-major axis [m]."""
WGS84_F = 1.0 / 298.257223563
"""WGS-84 flattening."""
MIN_SEPARATION = np.deg2rad(0.1)
"""Smallest angle [rad] between the two body axes, and between the two inertial directions, of
:func:`two_vector_attitude` (0.1°): nearer parallel, the roll they fix turns by more than 0.5° for
a 1e-3 rad error in either vector, and at parallel it is undetermined."""
_SECONDS_PER_DAY = 86400.0


def _unit(vector: ArrayLike, field: str) -> Array:
    array = np.asarray(vector, dtype=float).reshape(-1)
    norm = float(np.linalg.norm(array)) if array.shape == (3,) else 0.0
    if array.shape != (3,) or not np.all(np.isfinite(array)) or not norm > 1e-12:
        raise ModelError(field, f"expected a finite non-zero 3-vector, got {array.tolist()}")
    return array / norm


def _separation(a: Array, b: Array) -> float:
    """Angle [rad] between two unit vectors, or between one and the other's opposite (the smaller)."""
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), abs(float(a @ b))))


def two_vector_attitude(primary_body: ArrayLike, primary_target: ArrayLike, secondary_body: ArrayLike,
                        secondary_direction: ArrayLike) -> Array:
    """The attitude that points a body axis at a target and fixes the roll with a second axis.

    The primary body axis ``b`` is turned exactly onto the target direction ``t``; the secondary
    body axis ``s`` then lies in the plane of ``t`` and the secondary direction ``d``, on ``d``'s
    side of ``t`` (its component across ``t`` is along ``d − (d·t) t``): the axis "as close to
    ``d`` as the primary allows". With ``b ⊥ s`` and ``t ⊥ d``, ``s`` lands on ``d`` itself.
    Built as two orthonormal triads, ``(b, b × s, b × (b × s))`` in body axes and
    ``(t, t × d, t × (t × d))`` in inertial axes, ``R = T Bᵀ``.

    Parameters
    ----------
    primary_body : (3,) array_like
        The axis to point (a sensor's boresight), body axes; any non-zero length.
    primary_target : (3,) array_like
        Where it must point, inertial frame; any non-zero length.
    secondary_body : (3,) array_like
        The axis that fixes the roll, body axes; not within :data:`MIN_SEPARATION` of
        ``±primary_body``.
    secondary_direction : (3,) array_like
        The direction it is turned toward, inertial frame; not within :data:`MIN_SEPARATION` of
        ``±primary_target``.

    Returns
    -------
    (4,) ndarray
        Unit quaternion, scalar first, body to inertial, ``q0 >= 0``.

    Raises
    ------
    ModelError
        A zero or non-finite vector (its field: ``primary_body`` ...), the secondary axis
        (nearly) parallel to the primary (field ``secondary_body``), or the secondary direction
        (nearly) parallel to the target (field ``secondary_direction``); the roll is then
        undetermined.
    """
    b, t = _unit(primary_body, "primary_body"), _unit(primary_target, "primary_target")
    s, d = _unit(secondary_body, "secondary_body"), _unit(secondary_direction, "secondary_direction")
    for first, second, field, words in ((b, s, "secondary_body", "the secondary axis and the primary axis (body)"),
                                        (t, d, "secondary_direction", "the secondary direction and the target")):
        angle = _separation(first, second)
        if angle < MIN_SEPARATION:
            raise ModelError(field, f"{words} are {np.rad2deg(angle):.3g} deg from parallel (at least "
                                    f"{np.rad2deg(MIN_SEPARATION):g} deg needed): the roll about the target is "
                                    "undetermined; choose a secondary axis or direction across the primary one")

    def triad(first: Array, second: Array) -> Array:
        across = np.cross(first, second)
        across /= np.linalg.norm(across)
        return np.column_stack([first, across, np.cross(first, across)])

    return quat.from_rotation_matrix(triad(t, d) @ triad(b, s).T)


# --- the frames an attitude may be written in ----------------------------------------------------

@dataclass(frozen=True)
class AttitudeFrame:
    """A frame an attitude may be written in: ``q_inertial = q_frame ⊗ q_in_frame``.

    Parameters
    ----------
    name : str
        Its name as a scenario writes it (``frame: lvlh``).
    meaning : str
        One line for the docs and the schema reference.
    needs_orbit : bool
        Whether it is defined by the orbit.
    matrix : callable
        ``matrix(geometry, t) -> (3, 3) ndarray``: the frame's axes in inertial components (columns),
        so that ``v_I = M v_frame``, at ``t`` [s] from the epoch.
    """

    name: str
    meaning: str
    needs_orbit: bool
    matrix: Callable[[Geometry, float], Array]


def _orbit_lvlh(geometry: Geometry, t: float) -> Array:
    orbit = geometry._need_orbit("the LVLH frame")
    return np.array(ca.DM(orbit.lvlh_matrix(float(t))), dtype=float).reshape(3, 3)


def _rtn(geometry: Geometry, t: float) -> Array:
    # from the orbit's LVLH axes (x along-track, y = -orbit normal, z nadir): R = -z, T = x, N = -y
    lvlh = _orbit_lvlh(geometry, t)
    return np.column_stack([-lvlh[:, 2], lvlh[:, 0], -lvlh[:, 1]])


ATTITUDE_FRAMES: dict[str, AttitudeFrame] = {frame.name: frame for frame in (
    AttitudeFrame("inertial", "the inertial frame (GCRF with an epoch)", False, lambda geometry, t: np.eye(3)),
    AttitudeFrame("lvlh", "local vertical, local horizontal at the instant: z nadir, y the negative orbit normal, "
                          "x completing the triad (along-track; along the velocity on a circular orbit); needs the "
                          "orbit", True, _orbit_lvlh),
    AttitudeFrame("rtn", "radial, transverse, normal at the instant: x radial (outward), z the orbit normal "
                         "(r × v), y completing the triad (along-track); needs the orbit", True, _rtn),
)}
"""The frames an attitude may be written in: name -> :class:`AttitudeFrame`."""


# --- points on the ground --------------------------------------------------------------------------

def geodetic_to_ecef(latitude: float, longitude: float, altitude: float) -> Array:
    """A WGS-84 geodetic position in the Earth-fixed frame.

    Parameters
    ----------
    latitude : float
        Geodetic latitude [rad], in [-π/2, π/2].
    longitude : float
        Longitude [rad], east positive.
    altitude : float
        Height above the ellipsoid [m].

    Returns
    -------
    (3,) ndarray
        Position [m], Earth-fixed (ITRS) axes: x at latitude and longitude 0, z the pole.
    """
    e2 = WGS84_F * (2.0 - WGS84_F)
    sin_lat, cos_lat = np.sin(latitude), np.cos(latitude)
    radius = WGS84_A / np.sqrt(1.0 - e2 * sin_lat**2)  # prime vertical radius of curvature
    return np.array([(radius + altitude) * cos_lat * np.cos(longitude),
                     (radius + altitude) * cos_lat * np.sin(longitude),
                     (radius * (1.0 - e2) + altitude) * sin_lat])


def itrs_to_gcrf(epoch: datetime.datetime | str, t: ArrayLike) -> Array:
    """The rotation from the Earth-fixed frame (ITRS) to the inertial frame (GCRF) at ``epoch + t``.

    ERFA's ``c2t06a`` (IAU 2006/2000A, CIO based) transposed, with UT1 = UTC and no polar motion
    (module docstring: about 13.5″ at most, from UT1 − UTC).

    Parameters
    ----------
    epoch : datetime.datetime or str
        Instant of ``t = 0``, UTC (see :func:`~ocp.dynamics.ephemeris.parse_utc`).
    t : float or (N,) array_like
        SI seconds since the epoch [s].

    Returns
    -------
    (N, 3, 3) ndarray
        ``M`` with ``v_GCRF = M v_ITRS``.
    """
    import erfa  # imported on use, like the ephemeris' time scales

    epoch = parse_utc(epoch)
    t = np.atleast_1d(np.asarray(t, dtype=float)).reshape(-1)
    second = epoch.second + epoch.microsecond * 1e-6
    with warnings.catch_warnings():
        # "dubious year": after ERFA's last leap second TAI - UTC is held (ocp.dynamics.ephemeris)
        warnings.simplefilter("ignore", erfa.ErfaWarning)
        utc1, utc2 = erfa.dtf2d("UTC", epoch.year, epoch.month, epoch.day, epoch.hour, epoch.minute, second)
        tt1, tt2 = erfa.taitt(*erfa.utctai(utc1, utc2))
    days = t / _SECONDS_PER_DAY
    celestial_to_terrestrial = erfa.c2t06a(np.full(t.shape, float(tt1)), float(tt2) + days,
                                           np.full(t.shape, float(utc1)), float(utc2) + days, 0.0, 0.0)
    return np.swapaxes(np.asarray(celestial_to_terrestrial, dtype=float).reshape(-1, 3, 3), -1, -2)


def ground_point(geometry: Geometry, latitude: float, longitude: float, altitude: float,
                 t: float) -> tuple[Array, float]:
    """A ground point seen from the spacecraft at ``t``: its direction and its elevation.

    Parameters
    ----------
    geometry : Geometry
        The epoch (the Earth's orientation) and the orbit (the spacecraft's position).
    latitude, longitude : float
        WGS-84 geodetic latitude and longitude [rad].
    altitude : float
        Height above the WGS-84 ellipsoid [m].
    t : float
        Time since the epoch [s].

    Returns
    -------
    direction : (3,) ndarray
        Unit vector from the spacecraft to the point, inertial frame (GCRF).
    elevation : float
        The spacecraft's elevation above the point's horizon (the plane normal to the ellipsoid's
        normal) [rad]; negative: the point does not see the spacecraft.

    Raises
    ------
    ModelError
        Without the epoch (field ``"epoch"``) or the orbit (field ``"orbit"``).
    """
    epoch = geometry._need_epoch("a ground point")
    position = geometry.position(t)[0]
    rotation = itrs_to_gcrf(epoch, t)[0]
    point = rotation @ geodetic_to_ecef(latitude, longitude, altitude)
    up = rotation @ np.array([np.cos(latitude) * np.cos(longitude), np.cos(latitude) * np.sin(longitude),
                              np.sin(latitude)])
    line = position - point
    distance = float(np.linalg.norm(line))
    if not distance > 0.0:
        raise ModelError("orbit", "the spacecraft is at the ground point")
    return -line / distance, float(np.arcsin(np.clip(line @ up / distance, -1.0, 1.0)))
