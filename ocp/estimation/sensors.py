"""Attitude sensors of the closed loop: a rate-integrating gyro, a star tracker, a magnetometer.

All values are SI. The gyro follows Farrenkopf's discrete model (Markley & Crassidis,
*Fundamentals of Spacecraft Attitude Determination and Control*, 2014, sec. 6.4; Crassidis &
Junkins, *Optimal Estimation of Dynamic Systems*, eq. 7.56): over a sample of length ``Δt`` the
bias walks ``β_{k+1} = β_k + σ_u √Δt N_u`` (rate random walk, RRW) and the reading is

    ω̃_k = ω_k + ½ (β_{k+1} + β_k) + √(σ_v² / Δt + σ_u² Δt / 12) N_v

(``σ_v`` the angle random walk, ARW: the gyro's white rate noise; ``N_u``, ``N_v`` standard
normal 3-vectors). Its Allan variance is ``σ_v² / τ + σ_u² τ / 3``. The star tracker measures
``q ⊗ exp(v / 2)``, ``v`` a rotation vector with independent per-axis noise in the sensor frame,
at its own rate and outside its outage windows, and gives nothing while its boresight lies within an
exclusion half-angle of a bright body (:class:`Exclusion`: the Sun, the Earth's limb, the Moon),
tested at each sample from the true attitude. The magnetometer adds a constant bias to the
field reading and white noise (``ocp.simulation.SensorNoise.field_std``'s stream).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ocp.options import is_real, real_array

Array = NDArray[np.float64]

STAR_TRACKER_RATE_LIMIT_HZ = 1.0e7
"""Largest star-tracker update rate [Hz] (:class:`StarTracker`'s and ``rate_hz``'s bound). The
updates fall where the count ``floor(t rate)`` advances, and over the longest run slewbench allows
(``MAX_DURATION_S``, 1e8 s) ``t rate`` then stays below 2**53, where a float counts every integer;
far beyond it the count overflows (from 1.8e308 / t Hz) and the tracker silently stops updating.
Real trackers update at 1 to 30 Hz; rates above the controller's sample rate or a kHz warn
(:mod:`scenarios.schema.plausibility`)."""


def _vector(name: str, value: Any, non_negative: bool = False) -> Array:
    """``value`` as 3 finite real numbers (:func:`~ocp.options.real_array`), or a ``ValueError``
    naming ``name``, the value and what is wrong."""
    try:
        array = real_array(value)
    except ValueError as reason:
        raise ValueError(f"{name} must be 3 finite numbers, got {value!r:.200}: {reason}") from None
    if array.shape != (3,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be 3 finite numbers, got {value!r:.200}")
    if non_negative and np.any(array < 0):
        raise ValueError(f"{name} must be non-negative, got {array.tolist()}")
    return array


def _non_negative(name: str, value: Any) -> float:
    if not is_real(value) or not math.isfinite(value) or value < 0:
        raise ValueError(f"{name} must be a finite non-negative number, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class Gyro:
    """A three-axis rate gyro with angle random walk, rate random walk and bias (Farrenkopf).

    Parameters
    ----------
    arw : float, optional
        Angle random walk ``σ_v`` [rad/s^(1/2)], the white rate noise density; 0: none.
    rrw : float, optional
        Rate random walk ``σ_u`` [rad/s^(3/2)], the density of the bias's white derivative; 0: none.
    bias : (3,) array_like, optional
        The bias at ``t = 0`` [rad/s], body axes (default zero).
    """

    arw: float = 0.0
    rrw: float = 0.0
    bias: Array = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "arw", _non_negative("arw", self.arw))
        object.__setattr__(self, "rrw", _non_negative("rrw", self.rrw))
        object.__setattr__(self, "bias", _vector("bias", self.bias))

    def scales(self, dt: float) -> tuple[float, float]:
        """The deviations of one sample's draws.

        Parameters
        ----------
        dt : float
            Sample length [s].

        Returns
        -------
        walk : float
            Deviation of the bias increment ``σ_u √Δt`` [rad/s].
        white : float
            Deviation of the reading's white part ``√(σ_v²/Δt + σ_u² Δt/12)`` [rad/s].
        """
        return (self.rrw * math.sqrt(dt), math.sqrt(self.arw ** 2 / dt + self.rrw ** 2 * dt / 12.0))


def _sensor_to_body(boresight: Array) -> Array:
    """The rotation taking the sensor's z axis to ``boresight`` (body axes) by the shortest way."""
    z = np.array([0.0, 0.0, 1.0])
    b = boresight / np.linalg.norm(boresight)
    c = float(z @ b)
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])  # half turn about x
    k = np.cross(z, b)
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + kx + kx @ kx / (1.0 + c)


DirectionTable = Callable[[Any], tuple[Any, Any]]
"""``times (N,) -> (directions (N, 3), growth (N,))``: a body's unit vectors (inertial) and the
widening of a cone about it [rad] (its apparent radius; zeros for a point), as
``ocp.geometry.directions.DirectionKind.table`` gives with its geometry bound."""


@dataclass(frozen=True)
class Exclusion:
    """A bright body the star tracker cannot look near: no attitude while the angle between its
    boresight (inertial, from the true attitude) and the body's direction is below the half-angle
    (plus the body's apparent radius, the table's growth).

    Parameters
    ----------
    name : str
        The body, for messages and metrics (``"sun"``, ``"earth_limb"``, ``"moon"`` ...).
    half_angle : float
        Exclusion half-angle [rad], in [0, π].
    directions : callable or (3,) array_like
        The body's direction at given times (:data:`DirectionTable`), or one fixed inertial
        direction (a 3-vector, not necessarily unit).
    """

    name: str
    half_angle: float
    directions: DirectionTable | Array

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"an exclusion's name must be a non-empty string, got {self.name!r}")
        angle = self.half_angle
        if not is_real(angle):
            raise ValueError(f"the {self.name} exclusion half-angle must be a number of rad in [0, pi], "
                             f"got {angle!r} ({type(angle).__name__})")
        if not (math.isfinite(angle) and 0.0 <= angle <= math.pi):
            raise ValueError(f"the {self.name} exclusion half-angle must be in [0, pi] rad, got {angle!r}")
        object.__setattr__(self, "half_angle", float(angle))
        if not callable(self.directions):
            direction = _vector(f"the {self.name} exclusion direction", self.directions)
            if not np.linalg.norm(direction) > 0:
                raise ValueError(f"the {self.name} exclusion direction cannot be zero")
            object.__setattr__(self, "directions", direction / np.linalg.norm(direction))

    def table(self, times: Array) -> tuple[Array, Array]:
        """The body's direction and the cosine of the exclusion cone's half-angle at given times.

        Parameters
        ----------
        times : (N,) ndarray
            Sample instants [s].

        Returns
        -------
        directions : (N, 3) ndarray
            Unit vectors, inertial frame.
        cosines : (N,) ndarray
            ``cos(min(half_angle + growth, π))``: the boresight is excluded where its dot product
            with the direction exceeds it.
        """
        times = np.asarray(times, dtype=float)
        if callable(self.directions):
            directions, growth = self.directions(times)
            directions = np.asarray(directions, dtype=float).reshape(times.size, 3)
            growth = np.broadcast_to(np.asarray(growth, dtype=float), (times.size,))
        else:
            directions = np.tile(self.directions, (times.size, 1))
            growth = np.zeros(times.size)
        directions = directions / np.linalg.norm(directions, axis=1, keepdims=True)
        return directions, np.cos(np.minimum(self.half_angle + growth, math.pi))


def _windows(outages: Any) -> tuple[tuple[float, float], ...]:
    """The outage windows as float pairs, or a ValueError saying what was expected (a single
    window, ``(10, 20)``, is refused in words, as a single :class:`Exclusion` is)."""
    try:
        windows = tuple(outages)
    except TypeError:
        raise ValueError(f"outages must be a tuple of (t0, t1) windows in s, got {outages!r:.80}") from None
    if len(windows) == 2 and all(is_real(t) for t in windows):
        raise ValueError(f"outages must be a tuple of (t0, t1) windows, got a single window {windows!r}; "
                         f"write outages=(({windows[0]!r}, {windows[1]!r}),)")
    pairs = []
    for window in windows:
        try:
            pair = tuple(window)
        except TypeError:
            pair = ()
        if len(pair) != 2 or not all(is_real(t) for t in pair):
            raise ValueError(f"an outage must be a window (t0, t1) of two numbers of s, got {window!r:.80} "
                             f"in outages={outages!r:.80}")
        pairs.append((float(pair[0]), float(pair[1])))
    return tuple(pairs)


@dataclass(frozen=True)
class StarTracker:
    """A star tracker: attitude with per-axis noise in its own frame, at a rate, with outages.

    Parameters
    ----------
    noise : (3,) array_like
        Standard deviation of the measured rotation vector per sensor axis [rad]: about the
        sensor's x and y axes (cross-boresight) and about its z axis, the boresight.
    rate : float or None, optional
        Updates per second [Hz], at most :data:`STAR_TRACKER_RATE_LIMIT_HZ` (1e7); ``None``: every
        sample. An update falls on a sample when the count ``floor(t rate)`` has advanced since the
        previous sample (and on the first sample).
    outages : tuple of (float, float), optional
        Windows ``[t0, t1)`` [s] without updates, whatever the attitude (for blinding by a body at a
        known attitude, ``exclusions`` follows the attitude).
    boresight : (3,) array_like, optional
        The sensor's z axis in body axes (default ``[0, 0, 1]``); its x and y axes are the body's
        turned by the shortest rotation taking body z to the boresight.
    exclusions : tuple of Exclusion, optional
        Bright bodies that blind it: an update due at a sample is dropped when the true attitude
        puts the boresight inside one's cone (tested in the closed loop, both paths).
    """

    noise: Array
    rate: float | None = None
    outages: tuple[tuple[float, float], ...] = ()
    boresight: Array = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    exclusions: tuple[Exclusion, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "noise", _vector("noise", self.noise, non_negative=True))
        if isinstance(self.exclusions, Exclusion):
            raise ValueError(f"exclusions must be a tuple of Exclusion, got a single one ({self.exclusions.name!r}); "
                             f"write exclusions=(Exclusion(...),)")
        try:
            exclusions = tuple(self.exclusions)
        except TypeError:
            raise ValueError(f"exclusions must be a tuple of Exclusion, got {self.exclusions!r:.80}") from None
        if not all(isinstance(item, Exclusion) for item in exclusions):
            raise ValueError(f"exclusions must be Exclusion instances, got {self.exclusions!r:.80}")
        names = [item.name for item in exclusions]
        if len(set(names)) != len(names):
            raise ValueError(f"exclusion names must be distinct, got {names}")
        object.__setattr__(self, "exclusions", exclusions)
        if self.rate is not None:
            if not is_real(self.rate) or not math.isfinite(self.rate) or not self.rate > 0:
                raise ValueError(f"rate must be a finite positive number of Hz or None, got {self.rate!r:.80} "
                                 f"({type(self.rate).__name__})")
            if self.rate > STAR_TRACKER_RATE_LIMIT_HZ:
                raise ValueError(f"rate must be at most {STAR_TRACKER_RATE_LIMIT_HZ:g} Hz (STAR_TRACKER_RATE_LIMIT_HZ; "
                                 f"beyond it the update count overflows and the tracker stops updating; None: every "
                                 f"sample), got {self.rate:g}")
            object.__setattr__(self, "rate", float(self.rate))
        windows = _windows(self.outages)
        for a, b in windows:
            if not (math.isfinite(a) and math.isfinite(b) and b > a):
                raise ValueError(f"an outage must be [t0, t1] with t0 < t1 (s), got {[a, b]}")
        object.__setattr__(self, "outages", windows)
        boresight = _vector("boresight", self.boresight)
        if not np.linalg.norm(boresight) > 0:
            raise ValueError("the boresight cannot be zero")
        object.__setattr__(self, "boresight", boresight / np.linalg.norm(boresight))

    @property
    def sensor_to_body(self) -> Array:
        """(3, 3) rotation matrix taking sensor-frame vectors to body axes."""
        return _sensor_to_body(self.boresight)

    @property
    def covariance(self) -> Array:
        """(3, 3) covariance of the measured rotation vector in body axes [rad²]."""
        rotation = self.sensor_to_body
        return rotation @ np.diag(self.noise ** 2) @ rotation.T

    def available(self, times: Array) -> NDArray[np.bool_]:
        """Which samples carry an update.

        Parameters
        ----------
        times : (N,) ndarray
            Sample instants [s], increasing.

        Returns
        -------
        (N,) bool ndarray
            True where an update is due (rate and outages; the exclusions, which depend on the
            attitude, are tested in the closed loop).
        """
        times = np.asarray(times, dtype=float)
        if self.rate is None:
            due = np.ones(times.size, dtype=bool)
        else:
            count = np.floor(times * self.rate + 1e-9)
            due = np.concatenate([[True], count[1:] > count[:-1]]) if times.size else np.zeros(0, dtype=bool)
        for a, b in self.outages:
            due &= ~((times >= a) & (times < b))
        return due

    def exclusion_rows(self, times: Array) -> Array:
        """The exclusions' directions and cone cosines at the samples, for the closed loop.

        Parameters
        ----------
        times : (N,) ndarray
            Sample instants [s].

        Returns
        -------
        (N, 4 E) ndarray
            Per exclusion (in order) its unit direction (3, inertial) and the cosine of its cone's
            half-angle (1) (:meth:`Exclusion.table`); no columns without exclusions.
        """
        times = np.asarray(times, dtype=float)
        rows = np.zeros((times.size, 4 * len(self.exclusions)))
        for i, exclusion in enumerate(self.exclusions):
            directions, cosines = exclusion.table(times)
            rows[:, 4 * i:4 * i + 3], rows[:, 4 * i + 3] = directions, cosines
        return rows


@dataclass(frozen=True)
class Magnetometer:
    """A three-axis magnetometer: the field plus a constant bias and white noise.

    Parameters
    ----------
    noise : float, optional
        Standard deviation of the white noise per body axis [T].
    bias : (3,) array_like, optional
        Constant bias [T], body axes (default zero).
    """

    noise: float = 0.0
    bias: Array = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        object.__setattr__(self, "noise", _non_negative("noise", self.noise))
        object.__setattr__(self, "bias", _vector("bias", self.bias))
