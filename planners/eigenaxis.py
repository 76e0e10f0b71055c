"""Eigenaxis slew: rotation about the fixed Euler axis of ``q0* ⊗ qf``, with three angle profiles.

* ``smooth``: quintic θ(t) over the scenario's T with zero angular acceleration at both ends and
  the boundary rates projected on the axis (rest-to-rest when they are zero); ``infeasible`` if its
  peak rate (15 Θ / (8 T) from rest to rest) exceeds the rate bound.
* ``trapezoidal``: bang-coast-bang over the scenario's T, rest to rest, with the largest
  acceleration the torque bounds allow; ``infeasible`` if T is shorter than the minimum time.
* ``min_time``: the fastest bang-coast-bang under the torque and optional rate bounds.

Every profile honours the rate bound (option ``max_rate``, else ``maneuver.max_rate``): the body
rate is ``‖ω‖ = |θ̇|``.

The body rate is ``ω = e θ̇`` and the feed-forward torque the inverse dynamics
``I ω̇ + ω × I ω = I e θ̈ + θ̇² e × I e``; the second term is not zero off a principal axis, so the
acceleration ``α`` is chosen with the coast rate ``w`` such that every actuator respects its bound
through the controllers' allocation (``Spacecraft.allocation_rows``: ``|M τ| <= L`` row by row, a
row per working wheel ``(A⁺)_i`` with its ``max_torque``, and the torquers' rows for what the wheels
cannot give): ``|(M I e)_j| α + w² |(M (e × I e))_j| <= f L_j`` (``f`` the ``torque_fraction``).
With wheels along the body axes ``M`` is the identity: the per-axis bound ``|(I e)_i| α + w² |(e ×
I e)_i| <= u_i``.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import casadi as ca
import numpy as np

from ocp import quat, quat_casadi
from ocp.options import Range
from planners.base import Planner
from planners.problem import Array, ManeuverProblem, bound_keys
from planners.reference import (
    FailedReference,
    Reference,
    ReferenceSample,
    inverse_dynamics_torque,
)


def golden_section_minimum(function: Callable[[float], float], low: float, high: float, tolerance: float) -> float:
    """Minimiser of a unimodal function by golden-section search (at most 300 iterations).

    1-D searches here are too small to pay for importing scipy.optimize, which costs more than a run.

    Parameters
    ----------
    function : callable
        ``f(x) -> float``, unimodal on ``[low, high]``.
    low, high : float
        The bracket, ``low < high``.
    tolerance : float
        Absolute width of the final bracket (units of ``x``).

    Returns
    -------
    float
        The middle of the final bracket.
    """
    ratio = 0.5 * (np.sqrt(5.0) - 1.0)
    a, b = low, high
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = function(c), function(d)
    for _ in range(300):
        if b - a <= tolerance:
            break
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = function(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = function(d)
    return 0.5 * (a + b)


def bisection_root(function: Callable[[float], float], low: float, high: float, tolerance: float) -> float:
    """Root of an increasing-through-zero function by bisection (at most 400 iterations).

    Parameters
    ----------
    function : callable
        ``f(x) -> float`` with ``f(low) < 0 < f(high)``.
    low, high : float
        The bracket.
    tolerance : float
        Absolute width of the final bracket (units of ``x``), plus four ulps of ``high``.

    Returns
    -------
    float
        The middle of the final bracket.
    """
    for _ in range(400):
        middle = 0.5 * (low + high)
        if high - low <= tolerance + 4 * np.finfo(float).eps * abs(high):
            break
        if function(middle) > 0:
            high = middle
        else:
            low = middle
    return 0.5 * (low + high)


class AngleProfile:
    """θ(t), θ̇(t), θ̈(t) of a rotation about a fixed axis, from θ(0) = 0."""

    def __call__(self, t: Array) -> tuple[Array, Array, Array]:
        """Angle [rad], rate [rad/s] and acceleration [rad/s^2] at times ``t`` [s] (arrays like ``t``)."""
        raise NotImplementedError

    def symbolic(self, t: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
        """The profile as CasADi expressions.

        Parameters
        ----------
        t : casadi.SX
            Scalar time [s].

        Returns
        -------
        angle, rate, acceleration : casadi.SX
            θ [rad], θ̇ [rad/s], θ̈ [rad/s^2] at ``t``.
        """
        raise NotImplementedError


class QuinticProfile(AngleProfile):
    """Quintic θ(t) with θ(0) = 0, θ(T) = Θ, θ̇(0) = w0, θ̇(T) = wT, θ̈(0) = θ̈(T) = 0.

    Parameters
    ----------
    angle : float
        Θ, the rotation angle [rad].
    duration : float
        T [s].
    rate0, rate_end : float
        w0 and wT, the boundary rates about the axis [rad/s].
    """

    def __init__(self, angle: float, duration: float, rate0: float, rate_end: float) -> None:
        T = duration
        rows = [[1, 0, 0, 0, 0, 0], [0, 1, 0, 0, 0, 0], [0, 0, 2, 0, 0, 0],
                [1, T, T**2, T**3, T**4, T**5], [0, 1, 2 * T, 3 * T**2, 4 * T**3, 5 * T**4],
                [0, 0, 2, 6 * T, 12 * T**2, 20 * T**3]]
        coefficients = np.linalg.solve(np.array(rows, float), [0, rate0, 0, angle, rate_end, 0])
        self.duration = float(duration)
        self.position = np.polynomial.Polynomial(coefficients)
        self.rate = self.position.deriv()
        self.acceleration = self.rate.deriv()

    def __call__(self, t: Array) -> tuple[Array, Array, Array]:
        return self.position(t), self.rate(t), self.acceleration(t)

    def peak_rate(self) -> float:
        """The peak rate of the profile.

        Returns
        -------
        float
            ``max |θ̇|`` over ``[0, T]`` [rad/s]: at an end or where ``θ̈ = 0`` (the quartic's
            stationary points, roots of the cubic ``θ̈``).
        """
        candidates = [0.0, self.duration]
        candidates += [float(r.real) for r in self.acceleration.roots()
                       if abs(r.imag) <= 1e-9 * max(1.0, abs(r)) and 0.0 <= r.real <= self.duration]
        return float(np.max(np.abs(self.rate(np.array(candidates)))))

    def symbolic(self, t: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
        def horner(polynomial: np.polynomial.Polynomial) -> ca.SX:
            value = ca.SX(0.0)
            for coefficient in polynomial.coef[::-1]:
                value = value * t + float(coefficient)
            return value

        return horner(self.position), horner(self.rate), horner(self.acceleration)


class BangCoastBangProfile(AngleProfile):
    """From rest, accelerate at α to the coast rate w, coast, decelerate at α to rest.

    Parameters
    ----------
    angle : float
        Θ, the rotation angle [rad], non-negative.
    acceleration : float
        α [rad/s^2], positive.
    coast_rate : float
        w [rad/s]; a triangle (no coast) when ``w^2/α >= Θ``.

    Attributes
    ----------
    ramp : float
        Duration of each acceleration phase, ``w/α`` [s].
    coast : float
        Duration of the coast [s].
    duration : float
        Total time ``2 ramp + coast`` [s].
    """

    def __init__(self, angle: float, acceleration: float, coast_rate: float) -> None:
        self.alpha = acceleration
        self.rate_max = coast_rate
        self.ramp = coast_rate / acceleration
        self.coast = max(angle / coast_rate - self.ramp, 0.0) if coast_rate > 0 else 0.0
        self.angle = angle
        self.duration = 2 * self.ramp + self.coast

    def __call__(self, t: Array) -> tuple[Array, Array, Array]:
        a, w, ramp = self.alpha, self.rate_max, self.ramp
        late = np.maximum(self.duration - t, 0.0)
        accelerating, decelerating = t < ramp, t > ramp + self.coast
        position = np.where(accelerating, 0.5 * a * t**2,
                            np.where(decelerating, self.angle - 0.5 * a * late**2, 0.5 * a * ramp**2 + w * (t - ramp)))
        rate = np.where(accelerating, a * t, np.where(decelerating, a * late, w))
        acceleration = np.where(accelerating, a, np.where(decelerating, -a, 0.0))
        return position, rate, acceleration

    def symbolic(self, t: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
        a, w, ramp = self.alpha, self.rate_max, self.ramp
        late = ca.fmax(self.duration - t, 0.0)
        accelerating, decelerating = t < ramp, t > ramp + self.coast
        position = ca.if_else(accelerating, 0.5 * a * t**2, ca.if_else(
            decelerating, self.angle - 0.5 * a * late**2, 0.5 * a * ramp**2 + w * (t - ramp)))
        rate = ca.if_else(accelerating, a * t, ca.if_else(decelerating, a * late, w))
        acceleration = ca.if_else(accelerating, a, ca.if_else(decelerating, -a, 0.0))
        return position, rate, acceleration


def unmet_rates(problem: ManeuverProblem, axis: Array, profile: AngleProfile) -> set[str]:
    """The boundary rates an eigenaxis profile cannot meet: it rotates about ``axis`` only (the
    quintic keeps the boundary rates' components along it), and the bang-coast-bang profiles
    start and end at rest.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre.
    axis : (3,) ndarray
        Unit Euler axis, body axes.
    profile : AngleProfile
        The angle profile.

    Returns
    -------
    set of str
        Among ``"omega0"`` and ``"omegaf"`` (names of ``planners.base.BOUNDARY_CONDITIONS``).
    """
    along = isinstance(profile, QuinticProfile)
    unmet: set[str] = set()
    for name, rate in (("omega0", problem.omega0), ("omegaf", problem.omegaf)):
        if rate is None:
            continue
        kept = axis * (axis @ rate) if along else np.zeros(3)
        if np.linalg.norm(rate - kept) > 1e-12 * max(1.0, float(np.linalg.norm(rate))):
            unmet.add(name)
    return unmet


def _unbounded_about_the_axis(problem: ManeuverProblem) -> list[Any]:
    """The actuators without a torque bound that alone bound the torque ``I e α`` about the slew
    axis ``e`` through the controllers' allocation (``Spacecraft.allocation_rows``): every row that
    torque loads has an infinite limit. Empty when a bounded row limits it, or there is no rotation."""
    assert problem.qf is not None
    rotvec = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
    angle = float(np.linalg.norm(rotvec))
    if angle < 1e-12:
        return []
    spacecraft = problem.spacecraft
    rows, limits = spacecraft.allocation_rows()
    torque = spacecraft.inertia @ (rotvec / angle)
    loaded = np.abs(rows @ torque) > 1e-12 * np.linalg.norm(rows, axis=1) * np.linalg.norm(torque)
    if not np.any(loaded) or np.any(np.isfinite(limits[loaded])):
        return []
    wheels = spacecraft.wheels
    n_wheel_rows = 0 if wheels is None else int(np.count_nonzero(wheels.working))
    owners = [wheels] * n_wheel_rows + [spacecraft.residual_actuator] * (len(limits) - n_wheel_rows)
    named: list[Any] = []
    for owner, on in zip(owners, loaded):
        if on and not any(owner is other for other in named):
            named.append(owner)
    return named


class EigenaxisReference(Reference):
    """``q(t) = q0 ⊗ [cos θ/2, e sin θ/2]``, ``ω = e θ̇`` (body axes), torque ``I e θ̈ + θ̇² e × I e``.

    Parameters
    ----------
    q0 : (4,) ndarray
        Initial attitude, scalar first, body to inertial.
    axis : (3,) ndarray
        Unit Euler axis ``e``, body axes (fixed in the body and in inertial space).
    profile : AngleProfile
        θ(t) about ``axis``.
    duration : float
        T [s].
    inertia : (3, 3) ndarray
        Body inertia [kg m^2].
    message : str
        Outcome description.
    problem : ManeuverProblem or None, optional
        The planned problem: its boundary rates that the profile does not meet are declared in
        ``free_boundary`` (:func:`unmet_rates`); ``None``: none declared.
    """

    def __init__(self, q0: Array, axis: Array, profile: AngleProfile, duration: float, inertia: Array, message: str,
                 problem: ManeuverProblem | None = None) -> None:
        switches = []
        if isinstance(profile, BangCoastBangProfile):  # a coast of rounding length is a triangle: one switch
            switches = [profile.ramp] + ([profile.ramp + profile.coast] if profile.coast > 1e-12 * duration else [])
        super().__init__("eigenaxis", duration, inertia, message=message,
                         free_boundary=() if problem is None else unmet_rates(problem, axis, profile),
                         breakpoints=[t for t in switches if 0.0 < t < duration])
        self.q0, self.axis, self.profile = q0, axis, profile

    def _evaluate(self, t: Array) -> ReferenceSample:
        angle, rate, acceleration = self.profile(t)
        q = quat.product(self.q0, quat.from_axis_angle(self.axis, angle))
        omega = rate[:, None] * self.axis
        omega_dot = acceleration[:, None] * self.axis
        return ReferenceSample(q, omega, omega_dot, inverse_dynamics_torque(self.inertia, omega, omega_dot))

    def symbolic_evaluator(self) -> ca.Function:
        t = ca.SX.sym("t")
        angle, rate, acceleration = self.profile.symbolic(ca.fmin(ca.fmax(t, 0.0), self.duration))
        axis, inertia = ca.DM(self.axis), ca.DM(self.inertia)
        q = quat_casadi.product(ca.DM(self.q0), quat_casadi.from_axis_angle(axis, angle))
        omega, omega_dot = rate * axis, acceleration * axis
        torque = ca.mtimes(inertia, omega_dot) + ca.cross(omega, ca.mtimes(inertia, omega))
        return ca.Function("reference", [t], [ca.vertcat(q, omega, omega_dot, torque)], ["t"], ["row"])


class EigenaxisPlanner(Planner):
    """Eigenaxis slew planner; see the module docstring for the profiles."""

    name = "eigenaxis"
    example_options = ({"profile": "smooth"}, {"profile": "trapezoidal"}, {"profile": "min_time"})
    closed_form = True
    cheap = True
    honours = frozenset({"rate"})  # every profile: ‖ω‖ = |θ̇|, at most the rate bound or infeasible

    @classmethod
    def minimises_time(cls, options: Any) -> bool:
        """Whether the duration is minimised (:func:`planners.capabilities.minimises_time`).

        Parameters
        ----------
        options : Options or any
            The planner's options.

        Returns
        -------
        bool
            True for the ``min_time`` profile (the fastest bang-coast-bang about the eigenaxis).
        """
        return getattr(options, "profile", None) == "min_time"

    @dataclass(frozen=True)
    class Options:
        """Options of ``eigenaxis`` (YAML ``planner.options``).

        Attributes
        ----------
        profile : {"smooth", "trapezoidal", "min_time"}
            Angle profile: ``smooth`` (default) a quintic over the scenario's T with the boundary
            rates projected on the axis; ``trapezoidal`` a rest-to-rest bang-coast-bang over T with
            the largest acceleration the torque bounds allow (``infeasible`` if T is below the
            minimum time); ``min_time`` the fastest bang-coast-bang (its own duration).
        max_rate : float or None
            Bound on the body rate [rad/s] (``‖ω‖ = |θ̇|`` about the axis): the bang profiles coast
            at most at it; the quintic, whose peak rate is fixed by T, is ``infeasible`` above it.
            It tightens the problem's bound (``maneuver.max_rate``, or ``requirements.rate.max``),
            never loosens it; ``None`` (default): the problem's (if any).
        torque_fraction : float
            Share of each actuator's torque bound (each wheel's ``max_torque`` through ``g = −A⁺ τ``,
            the torquers' per axis) the bang profiles may use, in (0, 1]; default 1.
        """

        profile: Literal["smooth", "trapezoidal", "min_time"] = "smooth"
        max_rate: Annotated[float | None, Range(gt=0.0)] = None       # rad/s about the axis; default: the problem's max_rate
        torque_fraction: Annotated[float, Range(gt=0.0, le=1.0)] = 1.0        # share of the actuator bound the bang profiles may use

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why an eigenaxis slew cannot take ``problem``.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan.

        Returns
        -------
        str or None
            The reason (no target attitude; for the bang profiles, ``trapezoidal`` and ``min_time``,
            a torque about the slew axis that the controllers' allocation gives to actuators
            without a torque bound alone: their acceleration is the largest the bounds allow,
            unbounded there, and ``min_time``'s duration would be zero), or ``None``. Unbounded
            torquers beside wheels that span three axes are no reason (the allocation never asks
            them), nor beside fewer where the wheels' bound also limits the torque about the axis.
        """
        if self.options.profile != "smooth" and problem.qf is not None:
            unbounded = _unbounded_about_the_axis(problem)
            if unbounded:
                names = bound_keys(unbounded)
                return (f"profile {self.options.profile} needs a torque bound on the actuators the controllers' "
                        f"allocation gives the torque about the slew axis ({names}): it accelerates at the largest "
                        f"rate the bounds allow, unbounded without them")
        return super().problem_error(problem)

    def _rate_source(self, problem: ManeuverProblem) -> str:
        """Where the rate bound comes from, in a message."""
        option = self.options.max_rate
        return "option max_rate" if option is not None and (problem.max_rate is None or option < problem.max_rate) \
            else "the problem's: maneuver.max_rate, else requirements.rate.max"

    def _plan(self, problem: ManeuverProblem) -> Reference:
        assert problem.qf is not None  # problem_error (the default) refuses a free attitude
        rotvec = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        angle = float(np.linalg.norm(rotvec))
        axis = rotvec / angle if angle > 1e-12 else np.array([1.0, 0.0, 0.0])
        inertia = problem.spacecraft.inertia
        max_rate = problem.rate_bound(self.options.max_rate)
        if self.options.profile == "smooth":
            rate_end = 0.0 if problem.omegaf is None else float(axis @ problem.omegaf)
            quintic = QuinticProfile(angle, problem.duration, float(axis @ problem.omega0), rate_end)
            peak = quintic.peak_rate()
            if max_rate is not None and peak > max_rate * (1 + 1e-12):
                # |θ̇| of a rest-to-rest quintic peaks at 15 Θ / (8 T), mid-slew
                at_rest = float(axis @ problem.omega0) == 0.0 and rate_end == 0.0
                longer = f"; T >= {15 * angle / (8 * max_rate):.8g} s keeps it within" if at_rest else ""
                return FailedReference(self.name, f"the quintic over T = {problem.duration:g} s peaks at {peak:.4g} "
                                       f"rad/s, above the rate bound {max_rate:g} rad/s ({self._rate_source(problem)}){longer}",
                                       "infeasible")
            return EigenaxisReference(problem.q0, axis, quintic, problem.duration, inertia,
                                      f"quintic, {np.rad2deg(angle):.2f} deg about {np.round(axis, 4).tolist()}", problem)
        # The torque I e θ̈ + θ̇² e × I e through the controllers' allocation: |M τ| <= L row by row
        # (Spacecraft.allocation_rows; with wheels along the body axes, M = 1 and L their limits).
        rows, limits = problem.spacecraft.allocation_rows()
        bounds = self.options.torque_fraction * limits
        accel_axis = rows @ (inertia @ axis)
        gyro = np.abs(rows @ np.cross(axis, inertia @ axis))
        # A row no actuator gives (limit 0, a projector's): its rounding is no demand on it.
        given = limits > 0
        scale = np.linalg.norm(rows, axis=1)
        gyro[~given & (gyro <= 1e-12 * scale * np.linalg.norm(np.cross(axis, inertia @ axis)))] = 0.0
        accel_axis[~given & (np.abs(accel_axis) <= 1e-12 * scale * np.linalg.norm(inertia @ axis))] = 0.0

        def acceleration(coast_rate: float) -> float:
            """Largest α with every row within its bound while coasting at ``coast_rate``."""
            margin = bounds - coast_rate**2 * gyro
            active = np.abs(accel_axis) > 1e-12 * np.max(np.abs(accel_axis))
            if np.any(margin < 0) or np.any(margin[active] <= 0):
                return 0.0
            return float(np.min(margin[active] / np.abs(accel_axis[active])))

        if angle < 1e-12:
            profile = BangCoastBangProfile(0.0, 1.0, 0.0)
            return EigenaxisReference(problem.q0, axis, profile, problem.duration if self.options.profile
                                      == "trapezoidal" else 0.0, inertia, "no rotation needed", problem)
        if acceleration(0.0) <= 0:
            return FailedReference(self.name, f"the actuators give no torque about the axis {axis.round(4).tolist()}",
                                   "infeasible")
        rate_cap = max_rate if max_rate is not None else np.inf
        if np.any(gyro > 0):
            rate_cap = min(rate_cap, float(np.sqrt(np.min(bounds[gyro > 0] / gyro[gyro > 0]))))

        def slew_time(coast_rate: float) -> float:
            alpha = acceleration(coast_rate)
            if alpha <= 0:
                return np.inf
            return angle / coast_rate + coast_rate / alpha if coast_rate**2 / alpha <= angle else 2 * np.sqrt(angle / alpha)

        # With no gyroscopic term the optimum is the triangle w = sqrt(Θ α); else a bounded 1-D search.
        peak = np.sqrt(angle * acceleration(0.0))
        if np.all(gyro == 0) or not np.isfinite(rate_cap):
            best_rate = min(peak, rate_cap)
        else:
            best_rate = golden_section_minimum(slew_time, 1e-9 * peak, min(peak, rate_cap), 1e-12 * peak)
        best_rate = min(best_rate, np.sqrt(angle * acceleration(best_rate)))  # a triangle never coasts faster
        minimum_time = slew_time(best_rate)
        if self.options.profile == "min_time":
            profile = BangCoastBangProfile(angle, acceleration(best_rate), best_rate)
            return EigenaxisReference(problem.q0, axis, profile, profile.duration, inertia,
                                      f"minimum time {profile.duration:.3f} s, coast rate {best_rate:.4g} rad/s", problem)
        if problem.duration < minimum_time * (1 - 1e-12):
            bounds_words = "the torque bounds"
            if max_rate is not None and best_rate >= max_rate * (1 - 1e-9):  # the rate bound caps the coast
                bounds_words += f" and the rate bound {max_rate:g} rad/s ({self._rate_source(problem)})"
            return FailedReference(self.name, f"T = {problem.duration:g} s is shorter than the minimum "
                                   f"bang-coast-bang time {minimum_time:.4g} s under {bounds_words}", "infeasible")
        # Fixed T: the slowest coast rate w with w (T − w/α(w)) = Θ.
        def covered(w: float) -> float:
            alpha = acceleration(w)
            return w * (problem.duration - w / alpha) - angle if alpha > 0 else -angle

        coast_rate = bisection_root(covered, 1e-15, best_rate, 1e-15) if covered(best_rate) > 0 else best_rate
        profile = BangCoastBangProfile(angle, acceleration(coast_rate), coast_rate)
        profile.coast = problem.duration - 2 * profile.ramp  # exact T despite root tolerance
        profile.duration = problem.duration
        return EigenaxisReference(problem.q0, axis, profile, problem.duration, inertia,
                                  f"bang-coast-bang, coast rate {coast_rate:.4g} rad/s", problem)
