"""The sensor and estimator keys of a scenario: ``simulation.sensors`` and ``simulation.estimator``.

Units are in the key names (``arw_deg_per_sqrt_h``, ``noise_arcsec``, ``bias_T`` ...) and are
converted to SI here for :mod:`ocp.estimation`. A sensor declared here replaces that part of
``simulation.sensor_noise`` (giving both is refused); the MEKF needs a gyro and a star tracker.
Every error names the YAML path, the value and what was expected.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ocp.estimation import Exclusion, Gyro, Magnetometer, Mekf, SensorSuite, StarTracker
from ocp.estimation.sensors import STAR_TRACKER_RATE_LIMIT_HZ
from ocp.geometry.directions import DIRECTIONS, Geometry
from planners.problem import MAX_BODY_RATE
from scenarios.errors import ScenarioError
from scenarios.schema.keys import Section, choice, custom, mapping, number
from scenarios.schema.node import Node

DEG_PER_H = math.pi / 180.0 / 3600.0
"""One deg/h in rad/s."""
ARCSEC = math.pi / 180.0 / 3600.0
"""One arcsecond in rad."""
SQRT_HOUR = 60.0
"""√(1 h) in √s."""
STAR_TRACKER_NOISE_LIMIT_ARCSEC = 648_000.0
"""Largest star-tracker noise [arcsec, 1 sigma] per axis: 180 deg, half a turn. A rotation-vector
error whose standard deviation exceeds a half turn is no attitude measurement at all (the rotation
vector wraps at pi rad), and from about 1e83 arcsec the estimator's covariance overflows (its
knowledge error came out NaN). Plausible values, a thousand times below, warn from
:data:`~scenarios.schema.plausibility.MAX_STAR_TRACKER_NOISE_ARCSEC`."""
MAX_GYRO_ARW_DEG_PER_SQRT_H = math.degrees(MAX_BODY_RATE) * SQRT_HOUR
"""Largest gyro angle random walk [deg/√h] (3.4e6): a white rate noise whose one-second standard
deviation is ``MAX_BODY_RATE`` (1e3 rad/s, the largest body rate slewbench accepts) measures no rate;
from about 1e150 the estimator's process noise overflowed (a traceback)."""
MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H = MAX_BODY_RATE / DEG_PER_H * SQRT_HOUR
"""Largest gyro rate random walk [deg/h/√h] (1.2e13): a bias whose one-second drift has the standard
deviation ``MAX_BODY_RATE`` (1e3 rad/s); beyond it the estimator's process noise overflows likewise."""
MAX_GYRO_BIAS_DEG_PER_H = MAX_BODY_RATE / DEG_PER_H
"""Largest gyro bias per axis, and initial bias standard deviation of the estimator [deg/h] (2.1e8):
``MAX_BODY_RATE`` (1e3 rad/s), the largest body rate slewbench accepts (a bias of 1e300 deg/h made
the knowledge error NaN, an initial sigma of 1e300 a traceback)."""
MAX_MAGNETIC_NOISE_T = 1.0
"""Largest magnetometer noise and bias per axis [T] (``sensor_noise.magnetic_field``,
``sensors.magnetometer.noise_T`` and ``bias_T``): a tesla, 15,000 times the strongest field at the
Earth's surface (6.5e-5 T); 1e300 T was accepted (a B-dot run of 27 s on noise alone). A noise above
the field itself warns (:data:`~scenarios.schema.plausibility.MAX_MAGNETIC_NOISE_T`)."""
BORESIGHT_AGREEMENT_DEG = 0.01
"""``simulation.sensors.star_tracker.boresight`` given beside ``spacecraft.sensors.star_tracker`` must be
within this angle of it [deg] (the same direction, up to numbers written to four digits)."""


def _non_negative_vector(node: Node) -> np.ndarray:
    values = node.vector(3)
    if np.any(values < 0):
        raise node.error(f"expected 3 non-negative numbers, got {values.tolist()}")
    return values


def _vector3(node: Node) -> np.ndarray:
    return node.vector(3)


def _tesla_beyond(values: np.ndarray) -> str:
    """Why a magnetometer value beyond :data:`MAX_MAGNETIC_NOISE_T` is refused, and the value it
    would be in nT written as T, where that is a magnetometer's (at most 1e-4 T)."""
    shown = f"{float(values):g}" if values.ndim == 0 else str(values.tolist())
    meant = [float(f"{v * 1e-9:g}") for v in np.atleast_1d(values)]
    guess = (f"; if it is in nT, write {meant[0] if values.ndim == 0 else meant}"
             if np.max(np.abs(values)) * 1e-9 <= 1e-4 else "")
    return (f"{shown} T is beyond {MAX_MAGNETIC_NOISE_T:g} T, 15,000 times the Earth's field (at most 6.5e-5 T; "
            f"magnetometers' noise is nT){guess}")


def magnetic_noise(node: Node) -> float:
    """A magnetometer noise [T]: a non-negative number of at most :data:`MAX_MAGNETIC_NOISE_T`.

    Parameters
    ----------
    node : Node
        ``simulation.sensor_noise.magnetic_field`` or ``simulation.sensors.magnetometer.noise_T``.

    Returns
    -------
    float
        The noise [T].

    Raises
    ------
    ScenarioError
        Not a non-negative number, or beyond the bound (the message reads it in nT too).
    """
    value = node.number(non_negative=True)
    if value > MAX_MAGNETIC_NOISE_T:
        raise node.error(_tesla_beyond(np.asarray(value)))
    return value


def _magnetometer_bias(node: Node) -> np.ndarray:
    values = node.vector(3)
    if np.any(np.abs(values) > MAX_MAGNETIC_NOISE_T):
        raise node.error(_tesla_beyond(values))
    return values


def _gyro_bias(node: Node) -> np.ndarray:
    values = node.vector(3)
    if np.any(np.abs(values) > MAX_GYRO_BIAS_DEG_PER_H):
        raise node.error(f"expected 3 numbers of magnitude at most {MAX_GYRO_BIAS_DEG_PER_H:.4g} deg/h (1e3 rad/s, the "
                         f"largest body rate slewbench accepts; gyro biases are below 1,000 deg/h), got {values.tolist()}")
    return values


def _star_tracker_noise(node: Node) -> np.ndarray:
    values = _non_negative_vector(node)
    if np.any(values > STAR_TRACKER_NOISE_LIMIT_ARCSEC):
        raise node.error(f"expected 3 non-negative numbers of at most {STAR_TRACKER_NOISE_LIMIT_ARCSEC:,.0f} arcsec (180 deg: "
                         f"a noise beyond half a turn measures no attitude; star trackers give 0.1 to 100 arcsec), "
                         f"got {values.tolist()}")
    return values


def _boresight(node: Node) -> np.ndarray | None:
    if node.value is None:
        return None
    values = node.vector(3)
    if not np.linalg.norm(values) > 0:
        raise node.error(f"a boresight cannot be zero, got {values.tolist()}; give its direction in body axes")
    return values


def _outages(node: Node) -> tuple[tuple[float, float], ...]:
    windows = []
    for item in node.items():
        start, stop = item.vector(2)
        if not stop > start:
            raise item.error(f"expected [t0, t1] with t0 < t1 (s), got {[float(start), float(stop)]}")
        windows.append((float(start), float(stop)))
    return tuple(windows)


GYRO = Section((
    number("arw_deg_per_sqrt_h", "Angle random walk ``σ_v``: the white rate noise density (at most "
           f"{MAX_GYRO_ARW_DEG_PER_SQRT_H:.4g}: a one-second noise of 1e3 rad/s).", unit="deg/√h",
           default=0.0, non_negative=True, maximum=MAX_GYRO_ARW_DEG_PER_SQRT_H),
    number("rrw_deg_per_h_per_sqrt_h", "Rate random walk ``σ_u``: the density of the bias's white derivative "
           f"(at most {MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H:.4g}: a one-second drift of 1e3 rad/s).",
           unit="deg/h/√h", default=0.0, non_negative=True, maximum=MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H),
    custom("bias_deg_per_h", f"The bias at t = 0, body axes (each at most {MAX_GYRO_BIAS_DEG_PER_H:.4g}: 1e3 rad/s).",
           "list of 3 numbers", _gyro_bias, unit="deg/h", default=[0.0, 0.0, 0.0]),
), "A rate gyro (Farrenkopf's model: angle and rate random walk, bias); it replaces ``sensor_noise.rate``.")

BRIGHT_BODIES = ("sun", "moon", "earth_limb")
"""The directions a star tracker's exclusion may be about: the bright bodies. The Earth is
``earth_limb`` (its apparent radius added to the angle): a cone about nadir (``earth``) narrower
than that radius, 68° at 500 km, would leave the tracker updating on the Earth's disc; ``velocity``
is no body."""

EXCLUSION = Section(tuple(
    number(name, f"Half-angle about the ``{name}`` direction (as pointing requirements mean it"
           f"{'; needs the epoch' if DIRECTIONS[name].needs_epoch else ''}"
           f"{'; needs the orbit' if DIRECTIONS[name].needs_orbit else ''}); ``null``: none.",
           unit="deg", default=None, non_negative=True, maximum=180.0, nullable=True)
    for name in BRIGHT_BODIES
), "The star tracker's exclusion cones about the bright bodies (the Earth as ``earth_limb``: its apparent "
   "radius added, so that the whole disc blinds; a cone about nadir would leave the tracker updating on it).")


def _exclusions(node: Node) -> dict[str, Any]:
    """The half-angles in the order the mapping writes them (the exclusions', their bits', the
    messages' and the summary's order), the bodies not written after them."""
    if node.is_null():
        return EXCLUSION.read(Node({}, node.path))
    written = list(node.mapping().value)
    keys = sorted(EXCLUSION.keys, key=lambda key: written.index(key.name) if key.name in written else len(written))
    return Section(tuple(keys), EXCLUSION.meaning).read(node)


STAR_TRACKER = Section((
    custom("noise_arcsec", "Standard deviation of the attitude error about the sensor's x, y (cross-boresight) "
           "and z (boresight) axes; with an estimator, a zero needs some gyro noise (a filter certain of an axis "
           "divides by zero at its next update); each at most 648,000 (180 deg).", "list of 3 numbers",
           _star_tracker_noise, unit="arcsec"),
    number("rate_hz", f"Updates per second (at most {STAR_TRACKER_RATE_LIMIT_HZ:g}; one a sample at most); ``null``: every "
           "sample.", unit="Hz", default=None, positive=True, nullable=True, maximum=STAR_TRACKER_RATE_LIMIT_HZ),
    custom("outages_s", "Windows ``[t0, t1]`` without updates.", "list of [t0, t1]", _outages, unit="s", default=[]),
    custom("boresight", "The sensor's z axis in body axes (its x and y: the body's, turned by the shortest "
           "rotation taking body z there). Absent or ``null``: the boresight of ``spacecraft.sensors.star_tracker`` "
           "when the spacecraft declares that sensor (the one its pointing requirements read), else body z; "
           "given beside it, it must be the same direction.", "list of 3 numbers or null", _boresight, default=None),
    custom("exclusion_deg", "Exclusion half-angles about bright bodies: an update due at a sample is dropped "
           "when the true attitude puts the boresight within that angle of the body (of the Earth's limb for "
           "``earth_limb``); the MEKF then only propagates. The Sun's holds in eclipse too (no shadow test; "
           "conservative: a real tracker is not blinded by an eclipsed Sun). In the order written: the i-th is "
           "bit i of the ``blinded`` time-series column. The sensor's only source of blinding: a pointing "
           "requirement keeping the tracker off a body is scored, not applied to the sensor. Absent or "
           "``null``: none.", "mapping or null", _exclusions, unit="deg", default={}, section=EXCLUSION),
), "A star tracker; it replaces ``sensor_noise.attitude_deg``.")

MAGNETOMETER = Section((
    custom("noise_T", f"Standard deviation of the white noise per body axis (at most {MAX_MAGNETIC_NOISE_T:g}).",
           "number", magnetic_noise, unit="T", default=0.0, bounds=f">= 0 and <= {MAX_MAGNETIC_NOISE_T:g}"),
    custom("bias_T", f"Constant bias, body axes (each at most {MAX_MAGNETIC_NOISE_T:g}).", "list of 3 numbers",
           _magnetometer_bias, unit="T", default=[0.0, 0.0, 0.0]),
), "A magnetometer; it replaces ``sensor_noise.magnetic_field``.")

SENSORS = Section((
    mapping("gyro", "The rate gyro; absent: the rate of ``sensor_noise``.", GYRO, default=None, null="none"),
    mapping("star_tracker", "The star tracker; absent: the attitude of ``sensor_noise``.", STAR_TRACKER,
            default=None, null="none"),
    mapping("magnetometer", "The magnetometer; absent: the field of ``sensor_noise``.", MAGNETOMETER,
            default=None, null="none"),
), "The attitude sensors of the closed loop (seeded by ``sensor_noise.seed``, each on a stream of its own).")

ESTIMATOR = Section((
    choice("type", "The estimator: a multiplicative extended Kalman filter (gyro propagation, star tracker "
           "updates).", ("mekf",), default="mekf"),
    number("initial_attitude_sigma_deg", "Initial attitude standard deviation per axis (the estimate starts "
           "off by a draw from it).", unit="deg", positive=True, maximum=180.0),
    number("initial_bias_sigma_deg_per_h", "Initial gyro-bias standard deviation per axis (the estimate starts "
           f"at zero; at most {MAX_GYRO_BIAS_DEG_PER_H:.4g}: 1e3 rad/s).", unit="deg/h", positive=True,
           maximum=MAX_GYRO_BIAS_DEG_PER_H),
), "The attitude estimator in the loop: the controller gets its attitude and the gyro's rate less its bias "
   "estimate. It needs ``sensors.gyro`` and ``sensors.star_tracker``.")


def parse_sensor_suite(sensors: dict[str, Any] | None, estimator: dict[str, Any] | None,
                       noise: dict[str, Any], path: str, tracker_boresight: ArrayLike | None = None,
                       geometry: Geometry | None = None) -> SensorSuite | None:
    """The :class:`~ocp.estimation.SensorSuite` of ``simulation.sensors`` and ``simulation.estimator``.

    Parameters
    ----------
    sensors : dict or None
        :data:`SENSORS`'s values (``None``: absent).
    estimator : dict or None
        :data:`ESTIMATOR`'s values (``None``: absent).
    noise : dict
        ``simulation.sensor_noise``'s values (a sensor given there and here is refused).
    path : str
        YAML path of the simulation mapping.
    tracker_boresight : (3,) array_like or None, optional
        The boresight of ``spacecraft.sensors.star_tracker`` (body axes) when the spacecraft
        declares it: the star tracker's unless its own ``boresight`` is given, which must then be
        the same direction; ``None``: body z by default.
    geometry : Geometry or None, optional
        The scenario's epoch and orbit, for the star tracker's exclusions (``None``: none known,
        so an exclusion is refused).

    Returns
    -------
    SensorSuite or None
        ``None`` when neither key is given (the measurement is ``sensor_noise``'s, as before).

    Raises
    ------
    ScenarioError
        A sensor given twice, an estimator without a gyro or a star tracker, a star tracker
        boresight that is not the declared one, or an exclusion about a body whose direction needs
        an epoch or an orbit the scenario does not give.
    """
    sensors = sensors or {}
    gyro = tracker = magnetometer = None
    if sensors.get("gyro") is not None:
        values = sensors["gyro"]
        gyro = Gyro(arw=values["arw_deg_per_sqrt_h"] * math.pi / 180.0 / SQRT_HOUR,
                    rrw=values["rrw_deg_per_h_per_sqrt_h"] * DEG_PER_H / SQRT_HOUR,
                    bias=values["bias_deg_per_h"] * DEG_PER_H)
    if sensors.get("star_tracker") is not None:
        values = sensors["star_tracker"]
        boresight = values["boresight"]
        if boresight is None:
            boresight = (np.array([0.0, 0.0, 1.0]) if tracker_boresight is None
                         else np.asarray(tracker_boresight, dtype=float))
        elif tracker_boresight is not None:
            given, stated = boresight / np.linalg.norm(boresight), np.asarray(tracker_boresight, dtype=float)
            stated = stated / np.linalg.norm(stated)
            apart = math.degrees(math.atan2(float(np.linalg.norm(np.cross(given, stated))), float(given @ stated)))
            if apart > BORESIGHT_AGREEMENT_DEG:
                raise ScenarioError(f"{path}.sensors.star_tracker.boresight",
                                    f"{boresight.tolist()} is {apart:.3g} deg from spacecraft.sensors.star_tracker's "
                                    f"boresight {stated.tolist()}: one sensor has one boresight (remove this key, "
                                    f"which then takes the spacecraft's, or make them agree)")
            boresight = stated  # the declared direction, not its rounding here
        exclusions = tuple(_exclusion(name, angle, geometry, f"{path}.sensors.star_tracker.exclusion_deg.{name}")
                           for name, angle in values["exclusion_deg"].items() if angle is not None)
        tracker = StarTracker(noise=values["noise_arcsec"] * ARCSEC, rate=values["rate_hz"],
                              outages=values["outages_s"], boresight=boresight, exclusions=exclusions)
    if sensors.get("magnetometer") is not None:
        values = sensors["magnetometer"]
        magnetometer = Magnetometer(noise=values["noise_T"], bias=values["bias_T"])
    for declared, name, legacy in ((gyro, "gyro", "rate"), (tracker, "star_tracker", "attitude_deg"),
                                   (magnetometer, "magnetometer", "magnetic_field")):
        if declared is not None and noise[legacy] > 0:
            raise ScenarioError(f"{path}.sensor_noise.{legacy}",
                                f"{noise[legacy]:g} is given and {path}.sensors.{name} is declared: give that "
                                f"sensor's noise once (set sensor_noise.{legacy} to 0 or remove it)")
    mekf = None
    if estimator is not None:
        missing = [name for name, value in (("gyro", gyro), ("star_tracker", tracker)) if value is None]
        if missing:
            raise ScenarioError(f"{path}.estimator", f"the {estimator['type']} needs "
                                f"{' and '.join(f'{path}.sensors.{m}' for m in missing)}; declare "
                                f"{'it' if len(missing) == 1 else 'them'} or remove the estimator")
        silent = [] if tracker is None else [int(i) for i in np.flatnonzero(np.asarray(tracker.noise) == 0.0)]
        if silent and gyro is not None and tracker is not None and gyro.arw == 0.0 and gyro.rrw == 0.0:  # the filter's knowledge came out NaN, the row failed
            raise ScenarioError(f"{path}.sensors.star_tracker.noise_arcsec",
                                f"{[float(f'{v:g}') for v in np.asarray(tracker.noise) / ARCSEC]} is zero about the sensor's "
                                f"{', '.join('xyz'[i] for i in silent)} ax{'is' if len(silent) == 1 else 'es'} and the gyro is noise-free "
                                f"({path}.sensors.gyro.arw_deg_per_sqrt_h and rrw_deg_per_h_per_sqrt_h 0): the "
                                f"{estimator['type']} would be certain of that axis after its first update and divide "
                                "by zero at the next; expected a positive noise on every axis, or some gyro noise "
                                f"(remove {path}.estimator for a measurement taken as the state)")
        mekf = Mekf(attitude_sigma=math.radians(estimator["initial_attitude_sigma_deg"]),
                    bias_sigma=estimator["initial_bias_sigma_deg_per_h"] * DEG_PER_H)
    if gyro is None and tracker is None and magnetometer is None:
        return None
    return SensorSuite(gyro, tracker, magnetometer, mekf)


def _exclusion(name: str, angle_deg: float, geometry: Geometry | None, path: str) -> Exclusion:
    """The star tracker's exclusion about the direction ``name`` (a :data:`DIRECTIONS` kind),
    tabulated from ``geometry`` at the run's samples."""
    kind = DIRECTIONS[name]
    for needed, what, hint in ((kind.needs_epoch, "epoch", "the scenario's `epoch` (a UTC date-time)"),
                               (kind.needs_orbit, "orbit", "an orbit (`orbit` or `environment.orbit`)")):
        if needed and (geometry is None or getattr(geometry, what) is None):
            raise ScenarioError(path, f"an exclusion about {name} needs the {name} direction, which needs {hint}, "
                                      f"and none is given; give it or remove this exclusion")
    assert geometry is not None
    return Exclusion(name, math.radians(angle_deg), BodyDirection(name, geometry))


@dataclass(frozen=True)
class BodyDirection:
    """A direction kind's table with its geometry bound: the :data:`~ocp.estimation.sensors.DirectionTable`
    of a star tracker exclusion (compared by value: the kind and the geometry).

    Parameters
    ----------
    kind : str
        A name in :data:`~ocp.geometry.directions.DIRECTIONS`.
    geometry : Geometry
        The scenario's epoch and orbit.
    """

    kind: str
    geometry: Geometry

    def __call__(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The direction (N, 3) and its cone's growth (N,) [rad] at ``times`` [s]."""
        return DIRECTIONS[self.kind].table(self.geometry, np.asarray(times, dtype=float))
