"""The sensors and the estimator as one step of the closed loop, in NumPy and in CasADi.

A :class:`SensorSuite` declares the sensors (and the MEKF, if any). Per sample ``k`` of length
``Δt_k`` the loop carries the sensor state

    s = [β (3): the gyro's true bias [rad/s], q̂ (4): the attitude the controller was given
         (the MEKF's estimate, or the last star tracker reading), b̂ (3): the bias estimate
         [rad/s], P (21): the MEKF covariance's upper triangle, ω (3): the true rate at the
         previous sample [rad/s], Δt (1): the previous sample's length [s] (0 before the first),
         e (1): which exclusions held the star tracker's boresight at this sample (bit i for the
         tracker's exclusion i; 0 without)]

and takes a row of :attr:`SensorSuite.noise_size` numbers drawn in advance by :func:`draw_sensor_noise`
(bias increment, gyro white noise, star tracker rotation vector in body axes, all scaled, the star
tracker's availability by its rate and outages, then per exclusion the body's direction and its
cone's cosine at the sample: they do not depend on the state, so they are tabulated before the run
like the noise). One step (:func:`sensor_step`, :func:`sensor_step_symbolic`):

1. the gyro reads the rate ``ω̃_k = ω_k + ½(β + β⁺) + n_v`` (Farrenkopf), ``β⁺ = β + n_u``,
   and, as a rate-integrating gyro, the mean rate since the previous sample
   ``ω̄_k = ½(ω_{k−1} + ω_k) + ½(β + β⁺) + n_v`` (its angle increment over the sample's length;
   the rate changes over a sample in a slew or a spin, the trapezoid follows it to second order);
2. with the MEKF: it propagates from the previous sample with ``ω̄_k − b̂`` over the previous
   sample's length;
3. the star tracker reads ``q̃ = q ⊗ exp(v/2)`` when an update is due and its boresight, turned to
   inertial by the true attitude ``q``, lies outside every exclusion cone (``b · d_i ≤ cos α_i``);
   the MEKF updates with it (else it only propagates: its covariance grows);
4. the controller gets ``q̂`` and ``ω̃_k − b̂`` (without a MEKF: the last reading ``q̃`` and ``ω̃_k``);
5. the magnetometer's bias is added to the field reading.

A sensor not declared leaves that part of the measurement as :class:`ocp.simulation.SensorNoise`
makes it. Noise streams: the gyro's from ``numpy.random.default_rng([seed, 3])``, the star
tracker's from ``[seed, 4]``, the MEKF's initial error from ``[seed, 5]`` (the attitude and rate
noise use ``seed``, the magnetometer ``[seed, 1]``), so that adding a sensor leaves the others'
noise unchanged.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
from numpy.typing import NDArray

from ocp.estimation.mekf import (
    COVARIANCE_SIZE,
    Mekf,
    pack,
    pack_symbolic,
    propagate,
    propagate_symbolic,
    unpack,
    update,
    update_symbolic,
)
from ocp.estimation.sensors import Gyro, Magnetometer, StarTracker

Array = NDArray[np.float64]
SENSOR_NOISE_SIZE = 10
"""Numbers per sample of :func:`draw_sensor_noise` without exclusions: bias increment (3, rad/s), gyro
white noise (3, rad/s), star tracker rotation vector (3, rad, body axes), availability (1: 0 or 1);
each star tracker exclusion adds 4 (:attr:`SensorSuite.noise_size`)."""
SENSOR_STATE_SIZE = 3 + 4 + 3 + COVARIANCE_SIZE + 3 + 1 + 1
"""Numbers of the carried sensor state ``s = [β, q̂, b̂, P, ω, Δt, e]``."""
BLINDED = SENSOR_STATE_SIZE - 1
"""Index in ``s`` of the exclusion bits at the sample (bit i: inside the star tracker's exclusion i)."""
STREAMS = {"gyro": 3, "star_tracker": 4, "estimator": 5}
"""Second entry of each sensor's generator seed ``[seed, n]``."""


@dataclass(frozen=True)
class SensorSuite:
    """The sensors of a run and its estimator.

    Parameters
    ----------
    gyro : Gyro or None, optional
        The rate gyro; ``None``: the rate as :class:`~ocp.simulation.SensorNoise` makes it.
    star_tracker : StarTracker or None, optional
        The star tracker; ``None``: the attitude as :class:`~ocp.simulation.SensorNoise` makes it.
    magnetometer : Magnetometer or None, optional
        The magnetometer's bias (its white noise is ``SensorNoise.field_std``'s stream).
    estimator : Mekf or None, optional
        The MEKF in the loop; it needs a gyro and a star tracker.
    """

    gyro: Gyro | None = None
    star_tracker: StarTracker | None = None
    magnetometer: Magnetometer | None = None
    estimator: Mekf | None = None

    def __post_init__(self) -> None:
        if self.estimator is not None and (self.gyro is None or self.star_tracker is None):
            raise ValueError("the MEKF needs a gyro and a star tracker")

    @property
    def exclusions(self) -> int:
        """Number of the star tracker's exclusions (0 without a star tracker)."""
        return 0 if self.star_tracker is None else len(self.star_tracker.exclusions)

    @property
    def noise_size(self) -> int:
        """Numbers per sample of :func:`draw_sensor_noise`: :data:`SENSOR_NOISE_SIZE`, 4 more per exclusion."""
        return SENSOR_NOISE_SIZE + 4 * self.exclusions

    @property
    def key(self) -> tuple:
        """What a closed-loop build bakes in (the numbers of the models, not the noise draws)."""
        tracker = self.star_tracker
        return (None if self.gyro is None else (self.gyro.arw, self.gyro.rrw),
                None if tracker is None else tuple(tracker.covariance.ravel()),
                None if tracker is None or not tracker.exclusions else (tuple(tracker.boresight), self.exclusions),
                None if self.magnetometer is None else tuple(self.magnetometer.bias),
                None if self.estimator is None else (self.estimator.attitude_sigma, self.estimator.bias_sigma))


def _rotate_by(q: Array, v: Array) -> Array:
    """``q ⊗ exp(v/2)`` (NumPy; the operations of ``ocp.simulation.simulator.measure``)."""
    angle = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    s = math.sin(0.5 * angle) / angle if angle > 0 else 0.5
    p0, p1, p2, p3 = math.cos(0.5 * angle), s * v[0], s * v[1], s * v[2]
    q0, q1, q2, q3 = q
    return np.array([q0 * p0 - q1 * p1 - q2 * p2 - q3 * p3,
                     q0 * p1 + p0 * q1 + q2 * p3 - q3 * p2,
                     q0 * p2 + p0 * q2 + q3 * p1 - q1 * p3,
                     q0 * p3 + p0 * q3 + q1 * p2 - q2 * p1])


def _rotate_by_symbolic(q: Any, v: Any) -> Any:
    angle = ca.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    s = ca.if_else(angle > 0, ca.sin(0.5 * angle) / ca.if_else(angle > 0, angle, 1.0), 0.5)
    p0, p1, p2, p3 = ca.cos(0.5 * angle), s * v[0], s * v[1], s * v[2]
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    return ca.vertcat(q0 * p0 - q1 * p1 - q2 * p2 - q3 * p3,
                      q0 * p1 + p0 * q1 + q2 * p3 - q3 * p2,
                      q0 * p2 + p0 * q2 + q3 * p1 - q1 * p3,
                      q0 * p3 + p0 * q3 + q1 * p2 - q2 * p1)


def _boresight_inertial(q: Any, b: Array) -> tuple[Any, Any, Any]:
    """``R(q) b``: the body vector ``b`` in inertial axes (``q`` scalar first, body to inertial);
    the same operations on floats and on CasADi symbols."""
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    t0, t1, t2 = 2.0 * (q2 * b2 - q3 * b1), 2.0 * (q3 * b0 - q1 * b2), 2.0 * (q1 * b1 - q2 * b0)
    return (b0 + q0 * t0 + (q2 * t2 - q3 * t1), b1 + q0 * t1 + (q3 * t0 - q1 * t2),
            b2 + q0 * t2 + (q1 * t1 - q2 * t0))


def _excluded(tracker: StarTracker, q: Array, row: Array) -> float:
    """The exclusion bits at a sample: bit i when the boresight is inside exclusion i's cone."""
    if not tracker.exclusions:
        return 0.0
    v0, v1, v2 = _boresight_inertial(q, tracker.boresight)
    bits = 0.0
    for i in range(len(tracker.exclusions)):
        d = row[SENSOR_NOISE_SIZE + 4 * i:SENSOR_NOISE_SIZE + 4 * i + 4]
        if v0 * d[0] + v1 * d[1] + v2 * d[2] > d[3]:
            bits += 2.0 ** i
    return bits


def _excluded_symbolic(tracker: StarTracker, q: Any, row: Any) -> Any:
    if not tracker.exclusions:
        return ca.SX(0.0)
    v0, v1, v2 = _boresight_inertial(q, tracker.boresight)
    bits = ca.SX(0.0)
    for i in range(len(tracker.exclusions)):
        d = row[SENSOR_NOISE_SIZE + 4 * i:SENSOR_NOISE_SIZE + 4 * i + 4]
        bits = bits + ca.if_else(v0 * d[0] + v1 * d[1] + v2 * d[2] > d[3], 2.0 ** i, 0.0)
    return bits


def draw_sensor_noise(suite: SensorSuite, seed: int, times: Array) -> Array:
    """The sensors' noise of a whole run, scaled, with the star tracker's availability and its
    exclusions' directions.

    Parameters
    ----------
    suite : SensorSuite
        The sensors.
    seed : int
        The run's seed (the gyro draws from ``[seed, 3]``, the star tracker from ``[seed, 4]``).
    times : (N + 1,) ndarray
        Sample instants and the final time [s].

    Returns
    -------
    (N, suite.noise_size) ndarray
        Rows of :attr:`SensorSuite.noise_size` numbers; absent sensors' parts are zero (availability 0
        without a star tracker); the star tracker's :meth:`~ocp.estimation.StarTracker.exclusion_rows`
        at the sample instants after the first :data:`SENSOR_NOISE_SIZE`.
    """
    times = np.asarray(times, dtype=float)
    n = times.size - 1
    dt = np.diff(times)
    rows = np.zeros((n, suite.noise_size))
    gyro = suite.gyro
    if gyro is not None:
        normals = np.random.default_rng([seed, STREAMS["gyro"]]).standard_normal((n, 6))
        walk = gyro.rrw * np.sqrt(dt)
        white = np.sqrt(gyro.arw ** 2 / dt + gyro.rrw ** 2 * dt / 12.0)
        rows[:, 0:3] = walk[:, None] * normals[:, 0:3]
        rows[:, 3:6] = white[:, None] * normals[:, 3:6]
    tracker = suite.star_tracker
    if tracker is not None:
        normals = np.random.default_rng([seed, STREAMS["star_tracker"]]).standard_normal((n, 3))
        rows[:, 6:9] = (normals * tracker.noise) @ tracker.sensor_to_body.T
        rows[:, 9] = tracker.available(times[:-1])
        rows[:, SENSOR_NOISE_SIZE:] = tracker.exclusion_rows(times[:-1])
    return rows


def initial_sensor_state(suite: SensorSuite, q0: Array, seed: int) -> Array:
    """The sensor state ``s`` at ``t = 0``.

    Parameters
    ----------
    suite : SensorSuite
        The sensors.
    q0 : (4,) ndarray
        True initial attitude, scalar first, body to inertial.
    seed : int
        The run's seed (the MEKF's initial error is drawn from ``[seed, 5]``).

    Returns
    -------
    (36,) ndarray
        ``[β (the gyro's bias), q̂, b̂ = 0, P, ω̃ = 0, Δt = 0, e = 0]``: ``q̂`` is ``q0`` turned by a draw from the MEKF's
        initial attitude covariance (without a MEKF: ``q0``, the reading held until the first
        update), ``P`` the MEKF's initial covariance (zero without).
    """
    s = np.zeros(SENSOR_STATE_SIZE)
    if suite.gyro is not None:
        s[0:3] = suite.gyro.bias
    q = np.asarray(q0, dtype=float)
    if suite.estimator is not None:
        error = np.random.default_rng([seed, STREAMS["estimator"]]).normal(0.0, suite.estimator.attitude_sigma, 3)
        q = _rotate_by(q, error)
        s[10:31] = pack(suite.estimator.initial_covariance)
    s[3:7] = q / np.linalg.norm(q)
    return s


def sensor_step(suite: SensorSuite, s: Array, q: Array, omega: Array, field: Array | None, noise: Array,
                dt: float) -> tuple[Array, Array, Array | None, Array]:
    """One sample of the sensors and the estimator (NumPy; the Python loop).

    Parameters
    ----------
    suite : SensorSuite
        The sensors.
    s : (36,) ndarray
        Sensor state after the previous sample (module docstring).
    q : (4,) ndarray
        True attitude at ``t_k`` (scalar first, body to inertial), or the attitude
        :class:`~ocp.simulation.SensorNoise` measured when there is no star tracker.
    omega : (3,) ndarray
        True body rate [rad/s], or the one ``SensorNoise`` measured when there is no gyro.
    field : (3,) ndarray or None
        The magnetometer's reading before its bias [T], body axes.
    noise : (suite.noise_size,) ndarray
        This sample's row of :func:`draw_sensor_noise`.
    dt : float
        Sample length [s].

    Returns
    -------
    q : (4,) ndarray
        Attitude given to the controller.
    omega : (3,) ndarray
        Body rate given to the controller [rad/s].
    field : (3,) ndarray or None
        Magnetometer reading [T].
    s : (36,) ndarray
        Sensor state after this sample (``s[BLINDED]``: the exclusion bits at this sample).
    """
    s_next = s.copy()
    beta = s[0:3]
    true_rate = omega
    if suite.gyro is not None:
        beta_next = beta + noise[0:3]
        omega = omega + 0.5 * (beta + beta_next) + noise[3:6]
        s_next[0:3] = beta_next
    if suite.magnetometer is not None and field is not None:
        field = field + suite.magnetometer.bias
    if suite.star_tracker is None:
        return q, omega, field, s_next
    blinded = _excluded(suite.star_tracker, q, noise)
    s_next[BLINDED] = blinded
    available = noise[9] > 0.5 and blinded == 0.0
    if suite.estimator is None:
        held = _rotate_by(q, noise[6:9]) if available else s[3:7].copy()
        s_next[3:7] = held
        return held, omega, field, s_next
    gyro = suite.gyro
    assert gyro is not None
    bias = s[7:10]
    mean_rate = omega + 0.5 * (s[31:34] - true_rate)  # ω̄_k: the reading's bias and noise, the rates' mean
    q_hat, P = propagate(s[3:7], unpack(s[10:31]), mean_rate - bias, s[34], gyro.arw, gyro.rrw)
    if available:
        q_hat, bias, P = update(q_hat, bias, P, _rotate_by(q, noise[6:9]), suite.star_tracker.covariance)
    s_next[3:7], s_next[7:10], s_next[10:31], s_next[31:34], s_next[34] = q_hat, bias, pack(P), true_rate, dt
    return q_hat, omega - bias, field, s_next


def sensor_step_symbolic(suite: SensorSuite, s: Any, q: Any, omega: Any, field: Any, noise: Any,
                         dt: Any) -> tuple[Any, Any, Any, Any]:
    """:func:`sensor_step` in CasADi (the closed loop as one function; same operations).

    Parameters
    ----------
    suite : SensorSuite
        The sensors.
    s : (36, 1) casadi.SX
        Sensor state.
    q, omega : casadi.SX
        As :func:`sensor_step`.
    field : casadi.SX or None
        The magnetometer's reading before its bias [T]; ``None`` without a field model.
    noise : (suite.noise_size, 1) casadi.SX
        This sample's noise row.
    dt : casadi.SX
        Sample length [s].

    Returns
    -------
    q, omega, field, s : casadi.SX
        As :func:`sensor_step`.
    """
    beta = s[0:3]
    beta_next = beta
    true_rate = omega
    if suite.gyro is not None:
        beta_next = beta + noise[0:3]
        omega = omega + 0.5 * (beta + beta_next) + noise[3:6]
    if suite.magnetometer is not None and field is not None:
        field = field + ca.DM(suite.magnetometer.bias)
    if suite.star_tracker is None:
        return q, omega, field, ca.vertcat(beta_next, s[3:])
    tracker = suite.star_tracker
    if tracker.exclusions:
        blinded = _excluded_symbolic(tracker, q, noise)
        available = ca.logic_and(noise[9] > 0.5, blinded == 0)
    else:  # the loop's operations as before the exclusions
        blinded, available = s[BLINDED], noise[9] > 0.5
    if suite.estimator is None:
        held = ca.if_else(available, _rotate_by_symbolic(q, noise[6:9]), s[3:7])
        return held, omega, field, ca.vertcat(beta_next, held, s[7:BLINDED], blinded)
    gyro = suite.gyro
    assert gyro is not None
    bias = s[7:10]
    mean_rate = omega + 0.5 * (s[31:34] - true_rate)
    q_hat, P = propagate_symbolic(s[3:7], unpack(s[10:31]), mean_rate - bias, s[34], gyro.arw, gyro.rrw)
    q_up, bias_up, P_up = update_symbolic(q_hat, bias, P, _rotate_by_symbolic(q, noise[6:9]),
                                          tracker.covariance)
    q_hat = ca.if_else(available, q_up, q_hat)
    bias = ca.if_else(available, bias_up, bias)
    P = ca.if_else(available, P_up, P)
    return q_hat, omega - bias, field, ca.vertcat(beta_next, q_hat, bias, pack_symbolic(P), true_rate, dt, blinded)
