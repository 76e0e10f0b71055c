"""The manoeuvre a planner is given: :class:`ManeuverProblem` (spacecraft, environment, boundary
conditions, duration), part of the planner contract of :mod:`planners.base`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import casadi as ca
import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import AttitudeModel, Environment, Spacecraft, quat
from ocp.geometry import PointingConstraint
from ocp.options import is_real, real_array

Array = NDArray[np.float64]

RADIUS_STEP = 5.0
"""Largest spacing [s] of the orbit's samples in :meth:`ManeuverProblem.environment_torque_bound`."""
MAX_BODY_RATE = 1.0e3
"""Largest entry [rad/s] of a boundary body rate (``omega0``, ``omegaf``; ``maneuver.initial.omega``
and ``maneuver.final.omega`` of a scenario): about 9,500 rpm, beyond any spacecraft body (fast
spinners turn at a few rad/s; rates from 1 rad/s already warn in a scenario,
:mod:`scenarios.schema.plausibility`). Above it the planners' arithmetic breaks down: from 1e23 rad/s
``eigenaxis``'s quintic returned ``ok`` ending at -2e8 rad/s and the torque-free coast after it
never ended."""


@dataclass(frozen=True)
class ManeuverProblem:
    """A slew to plan: the spacecraft, its environment and the boundary conditions.

    Inputs are checked on construction (a ``ValueError`` or ``TypeError`` names the field):
    quaternions must have unit norm within ``ocp.quat.UNIT_NORM_TOLERANCE`` (1e-3, the YAML
    loader's tolerance; ``[2, 0, 0, 0]`` is refused, not normalised) and are then normalised to
    unit float arrays; vectors become float arrays of the right size. Every array is stored as a
    read-only copy: a later change to the caller's arrays does not reach the problem (build a new
    problem for other values).

    Parameters
    ----------
    spacecraft : ocp.Spacecraft
        The body (inertia, actuators: wheels, torquers, magnetorquers).
    q0 : (4,) array_like
        Initial attitude quaternion, scalar first, body to inertial: unit norm within 1e-3
        (``ocp.quat.unit_norm_error``), normalised here.
    omega0 : (3,) array_like
        Initial body rate [rad/s], body axes: finite, each entry within ±:data:`MAX_BODY_RATE`
        (1000 rad/s).
    qf : (4,) array_like or None
        Target attitude, scalar first, body to inertial: unit norm within 1e-3, normalised here. ``None`` leaves the final
        attitude free, which only suits planners that accept it in :meth:`Planner.problem_error`
        (the default refuses it).
    duration : float
        Manoeuvre time T [s], finite and positive (a Python or numpy integer or float, not a bool;
        stored as a float): the manoeuvre's time budget. Minimum-time planners return their own
        duration; ``slewbench``'s runner makes a reference that ends after T ``infeasible``
        (:func:`scenarios.requirements.scoring.late_slew`).
    omegaf : (3,) array_like or None, optional
        Target body rate [rad/s], body axes, each entry within ±:data:`MAX_BODY_RATE`. ``None``
        (default) leaves the final rate free.
    environment : ocp.Environment, optional
        Orbit and environment torques (gravity gradient, constant disturbance, magnetic field); the
        default has none.
    wheel_momentum0 : (n_w,) array_like or None, optional
        Initial wheel momenta [N m s], one per wheel of ``spacecraft``; ``None`` (default): zero.
        Stored as an array after construction.
    max_rate : float or None, optional
        Bound on the body rate norm [rad/s] for planners that honour it (``maneuver.max_rate``,
        ``requirements.rate``); ``None`` (default): no bound. Imposed as given (a planning bound).
    pointing : tuple of ocp.geometry.PointingConstraint, optional
        Pointing requirements (keep-out and keep-in cones, their directions tabulated along the
        run) for planners that honour them (:attr:`planners.base.Planner.honours`); default none.
    actuator_margin : float or None, optional
        The actuator requirement: a reference may ask at most ``(1 - actuator_margin)`` of each
        actuator limit (torque, momentum, dipole), in [0, 1). ``0`` (default, as a scenario without
        ``requirements.actuators``): the limits themselves, held between a planner's points too by
        the planners that check densely (``collocation``). ``None``: no actuator requirement: the
        limits are imposed where a planner imposes them (its mesh points) and not checked between
        them, where a reference can exceed them (a wheel's momentum by 0.5 % on a minimum-time slew).
    rate_requirement : float or None, optional
        The rate requirement the closed loop is scored against (``requirements.rate.max``) [rad/s],
        at least ``max_rate`` when both are given; ``None`` (default): none. Planners that honour
        the rate plan at most ``1 − rate_margin`` of it (their option, :meth:`rate_bound`): a
        zero-order-hold closed loop tracking a coast at the bound overshoots it (by 0.03-0.04 %
        with a perfect plant).
    """

    spacecraft: Spacecraft
    q0: Array
    omega0: Array
    qf: Array | None
    duration: float
    omegaf: Array | None = None
    environment: Environment = field(default_factory=Environment)
    wheel_momentum0: Array | None = None
    max_rate: float | None = None
    pointing: tuple[PointingConstraint, ...] = ()
    actuator_margin: float | None = 0.0
    rate_requirement: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.spacecraft, Spacecraft):
            raise TypeError(f"spacecraft must be an ocp.Spacecraft, got {type(self.spacecraft).__name__}")
        if not isinstance(self.environment, Environment):
            raise TypeError(f"environment must be an ocp.Environment, got {type(self.environment).__name__}")
        object.__setattr__(self, "q0", _quaternion("q0", self.q0))
        if self.qf is not None:
            object.__setattr__(self, "qf", _quaternion("qf", self.qf))
        object.__setattr__(self, "omega0", _rate("omega0", self.omega0))
        if self.omegaf is not None:
            object.__setattr__(self, "omegaf", _rate("omegaf", self.omegaf))
        if self.spacecraft.n_wheels == 0 and self.wheel_momentum0 is not None and np.size(self.wheel_momentum0) != 0:
            raise ValueError(f"wheel_momentum0 must be None (or empty) for a spacecraft without wheels, got "
                             f"{self.wheel_momentum0!r:.80}")
        momentum = np.zeros(self.spacecraft.n_wheels) if self.wheel_momentum0 is None else self.wheel_momentum0
        object.__setattr__(self, "wheel_momentum0", _vector("wheel_momentum0", momentum, self.spacecraft.n_wheels))
        if not is_real(self.duration) or not np.isfinite(self.duration) or not self.duration > 0:
            raise ValueError(f"duration must be a finite positive number of seconds, got {self.duration!r}")
        object.__setattr__(self, "duration", float(self.duration))
        if self.max_rate is not None:
            if not is_real(self.max_rate) or not np.isfinite(self.max_rate) or not self.max_rate > 0:
                raise ValueError(f"max_rate must be a finite positive rate (rad/s) or None, got {self.max_rate!r}")
            object.__setattr__(self, "max_rate", float(self.max_rate))
        if self.rate_requirement is not None:
            if not (is_real(self.rate_requirement) and np.isfinite(self.rate_requirement) and self.rate_requirement > 0):
                raise ValueError(f"rate_requirement must be a finite positive rate (rad/s) or None, got "
                                 f"{self.rate_requirement!r}")
            object.__setattr__(self, "rate_requirement", float(self.rate_requirement))
        object.__setattr__(self, "pointing", tuple(self.pointing))
        if not all(isinstance(c, PointingConstraint) for c in self.pointing):
            raise TypeError("pointing must hold ocp.geometry.PointingConstraint objects")
        if self.actuator_margin is not None:
            if not (is_real(self.actuator_margin) and 0.0 <= self.actuator_margin < 1.0):
                raise ValueError(f"actuator_margin must lie in [0, 1) or be None, got {self.actuator_margin!r}")
            object.__setattr__(self, "actuator_margin", float(self.actuator_margin))

    def unreachable(self) -> str | None:
        """Why no motion reaches the target, by conservation of angular momentum alone: with wheels
        as the only actuators, no external torque (no other actuator kind, gravity gradient or
        disturbance), zero total momentum ``I ω0 + A h_w0`` and none in the failed wheels, the
        body's rate is ``ω = −I⁻¹ a h``: with one working wheel axis ``a`` it turns about the fixed
        body axis ``I⁻¹ a`` only, with none it stays at rest. (Two or more working wheel axes reach
        every attitude; a drift, or momentum kept in a failed wheel, is not decided here.)

        Returns
        -------
        str or None
            The reason, or ``None`` when the target may be reachable (or is free).
        """
        sc = self.spacecraft
        environment = self.environment
        if self.qf is None or any(actuator.block != "wheels" for actuator in sc.actuators) or (
                environment is not None and (environment.gravity_gradient or np.any(environment.disturbance_torque))):
            return None  # another actuator kind (any registered one) or an external torque: not decided here
        failed = set(sc.wheels.failed) if sc.wheels is not None else set()
        working = sc.wheel_axes[:, [i for i in range(sc.n_wheels) if i not in failed]]
        if working.shape[1] and np.linalg.matrix_rank(working, tol=1e-9) >= 2:
            return None
        scale = 1e-12 * max(1.0, float(np.max(np.abs(sc.inertia))))
        held = sc.wheel_axes[:, sorted(failed)] @ self.initial_state[7:][sorted(failed)]  # momentum failed wheels keep
        momentum = sc.inertia @ self.omega0 + sc.wheel_axes @ self.initial_state[7:]  # I ω0 + A h_w0
        if float(np.linalg.norm(momentum)) > scale or float(np.linalg.norm(held)) > scale:
            return None  # a drift (or a failed wheel's momentum, which turns the body too): not decided here
        turn = quat.to_rotation_vector(quat.error(self.qf, self.q0))  # body axes, q0 to qf
        if not working.shape[1]:
            return None if float(np.linalg.norm(turn)) <= 1e-9 else (
                "no working actuator and no momentum: the body stays at rest and cannot reach the target")
        axis = np.linalg.solve(sc.inertia, working[:, 0])
        axis /= np.linalg.norm(axis)
        off = float(np.linalg.norm(np.cross(turn, axis)))
        final = self.omegaf if self.omegaf is not None else np.zeros(3)
        along = off <= 1e-6 * max(1.0, float(np.linalg.norm(turn)))
        if along and np.linalg.norm(np.cross(final, axis)) <= 1e-12:
            return None
        what = (f"the slew is {np.rad2deg(np.linalg.norm(turn)):.4g} deg about "
                f"{np.round(turn / np.linalg.norm(turn), 4).tolist()}" if not along else
                f"the final rate {np.round(final, 6).tolist()} rad/s is not about it (maneuver.final.omega)")
        return (f"one working wheel axis {np.round(working[:, 0], 4).tolist()} and zero total momentum: the body "
                f"can only turn about the body axis I⁻¹a = {np.round(axis, 4).tolist()}, and {what}")

    def rate_bound(self, option: float | None, margin: float = 0.0) -> float | None:
        """The rate bound a planner imposes: its own ``max_rate`` option tightens the problem's
        (``maneuver.max_rate``, else ``requirements.rate.max``), never loosens it, and the rate
        requirement (:attr:`rate_requirement`) is kept ``margin`` below: a closed loop tracking
        a reference that coasts exactly at the requirement overshoots it.

        Parameters
        ----------
        option : float or None
            The planner's option [rad/s]; ``None``: the problem's bound.
        margin : float, optional
            The planner's ``rate_margin``, a fraction in [0, 1) of :attr:`rate_requirement`
            (default 0: the requirement itself).

        Returns
        -------
        float or None
            The smallest of the option, ``max_rate`` and ``(1 − margin)`` times the requirement
            [rad/s]; ``None`` without any.

        Raises
        ------
        ValueError
            For an option that is not a finite positive number or ``None``, or a margin outside
            [0, 1) (booleans and text are refused).
        """
        if option is not None and not (is_real(option) and np.isfinite(option) and option > 0):
            raise ValueError(f"rate_bound: option must be a finite positive rate [rad/s] or None, got {option!r:.60} "
                             f"({type(option).__name__})")
        if not (is_real(margin) and 0.0 <= margin < 1.0):
            raise ValueError(f"rate_bound: margin must be a fraction in [0, 1), got {margin!r:.60} "
                             f"({type(margin).__name__})")
        required = None if self.rate_requirement is None else self.rate_requirement * (1.0 - margin)
        bounds = [bound for bound in (option, self.max_rate, required) if bound is not None]
        return min(bounds) if bounds else None

    def environment_torque_bound(self, duration: float) -> tuple[Array, float]:
        """A bound on the environment's torque from t = 0 over ``duration``, for planners that do
        not model it (what the actuators must give is the motion's torque less it).

        The constant disturbance (``environment.disturbance_torque``) is returned as it is, in body
        axes. The gravity gradient, ``3 μ / r³ r̂ × I r̂`` in body axes, is bounded in norm by
        ``3 μ / r³ (I_max − I_min) / 2`` whatever the attitude (``I_max``, ``I_min`` the extreme
        principal moments; the bound is reached with ``r̂`` halfway between their axes), ``3 n²
        (I_max − I_min) / 2`` on a circular orbit of mean motion ``n``. ``r`` is the least radius
        over ``[0, max(duration, P)]``, ``P = 2π √(r_max³ / μ)`` at least one orbital period (so
        that any slew shorter than either is covered, its duration not yet known): the orbit
        sampled at most every :data:`RADIUS_STEP` seconds, less what the radius can lose between
        two samples, ``(|ṙ| + r̈ Δ/2) Δ/2`` with ``|r̈| <= μ / r² + v² / r`` (two-body gravity and
        the turning velocity) taken 10 % larger.

        Parameters
        ----------
        duration : float
            The time from t = 0 the bound must cover [s].

        Returns
        -------
        disturbance : (3,) ndarray
            The constant disturbance torque [N m], body axes (zeros without one).
        gravity_gradient : float
            Bound on the gravity gradient's norm [N m] (0 without it).

        Raises
        ------
        ValueError
            For a ``duration`` that is not a finite number >= 0 (a boolean or text).
        """
        if not (is_real(duration) and np.isfinite(duration) and duration >= 0):
            raise ValueError(f"environment_torque_bound: duration must be a finite time >= 0 [s], got "
                             f"{duration!r:.60} ({type(duration).__name__})")
        environment = self.environment
        disturbance = np.array(environment.disturbance_torque, dtype=float)
        orbit = environment.orbit
        if not environment.gravity_gradient or orbit is None:
            return disturbance, 0.0
        mu = float(orbit.mu)
        window = max(float(duration), 2.0 * np.pi * np.sqrt(float(orbit.max_radius) ** 3 / mu))
        samples = int(np.ceil(window / RADIUS_STEP)) + 1
        step = window / (samples - 1)
        times = ca.DM(np.linspace(0.0, window, samples)).T
        position = np.asarray(orbit.position(times), dtype=float).reshape(3, samples)
        velocity = np.asarray(orbit.velocity(times), dtype=float).reshape(3, samples)
        radius = np.linalg.norm(position, axis=0)
        speed = np.linalg.norm(velocity, axis=0)
        radial = np.abs(np.sum(position * velocity, axis=0)) / radius
        least = float(np.min(radius))
        curvature = 1.1 * (mu / least**2 + float(np.max(speed)) ** 2 / least)
        least -= (float(np.max(radial)) + 0.5 * curvature * step) * 0.5 * step
        moments = np.linalg.eigvalsh(np.asarray(self.spacecraft.inertia, dtype=float))
        return disturbance, float(3.0 * mu / least**3 * (moments[-1] - moments[0]) / 2.0)

    @property
    def torque_limit(self) -> Array:
        """(3,) ndarray: per-body-axis torque bound [N m] of the actuators (``Spacecraft.body_torque_limit``)."""
        return self.spacecraft.body_torque_limit()

    @cached_property
    def model(self) -> AttitudeModel:
        """ocp.AttitudeModel: the symbolic model of this spacecraft in this environment (built once)."""
        return AttitudeModel(self.spacecraft, self.environment)

    @property
    def initial_state(self) -> Array:
        """(7 + n_w,) ndarray: the model state ``[q0, ω0, h_w0]`` at t = 0 (rad/s, N m s)."""
        return np.concatenate([self.q0, self.omega0, self.wheel_momentum0])


def bound_keys(actuators: list) -> str:
    """The scenario keys that would bound these actuators, for a message
    (``spacecraft.wheels.max_torque, spacecraft.magnetorquers.max_dipole``).

    Parameters
    ----------
    actuators : list of ocp actuators
        Wheels, torquers, magnetorquers (their ``name``).

    Returns
    -------
    str
        The keys, comma-separated.
    """
    return ", ".join(f"spacecraft.{actuator.name}" + next((f".{key}" for key in ("max_torque", "max_dipole")
                                                           if hasattr(actuator, key)), "") for actuator in actuators)


def _vector(name: str, value: ArrayLike, size: int) -> Array:
    """``value`` as a finite float vector of ``size`` entries, or a ``ValueError`` naming ``name``
    (:func:`~ocp.options.real_array`: ``None``, text, booleans and complex numbers are refused)."""
    try:
        array = real_array(value)  # a private copy: the caller's array is not kept
    except ValueError as reason:
        raise ValueError(f"{name} must be {size} numbers, got {value!r:.200}: {reason}") from None
    if array.shape != (size,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be {size} finite numbers, got shape {array.shape}: {array.tolist()}")
    array.setflags(write=False)
    return array


def _rate(name: str, value: ArrayLike) -> Array:
    """A body rate from ``value`` (3 finite numbers, each within ±:data:`MAX_BODY_RATE`), or a
    ``ValueError`` naming ``name``, the value and the bound."""
    rate = _vector(name, value, 3)
    beyond = np.abs(rate) > MAX_BODY_RATE
    if np.any(beyond):
        raise ValueError(f"{name} must be a body rate [rad/s] with each entry within ±{MAX_BODY_RATE:g} rad/s "
                         f"(MAX_BODY_RATE, about 9,500 rpm, beyond any spacecraft body), got {rate.tolist()} "
                         f"(entry {int(np.argmax(beyond))})")
    return rate


def _quaternion(name: str, value: ArrayLike) -> Array:
    """A unit quaternion from ``value`` (normalised), or a ``ValueError`` naming ``name`` for one
    whose norm is not within ``ocp.quat.UNIT_NORM_TOLERANCE`` of 1 (the YAML loader's check)."""
    q = _vector(name, value, 4)
    reason = quat.unit_norm_error(q)
    if reason is not None:
        raise ValueError(f"{name} must be a unit quaternion [q0, q1, q2, q3] (scalar first): {reason}; "
                         f"got {q.tolist()}")
    unit = q / np.linalg.norm(q)
    unit.setflags(write=False)
    return unit
