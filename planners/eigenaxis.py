"""Eigenaxis slew: rotation about the fixed Euler axis of ``q0* ⊗ qf``, with three angle profiles.

* ``smooth``: quintic θ(t) over the scenario's T with zero angular acceleration at both ends and
  the boundary rates projected on the axis (rest-to-rest when they are zero); ``infeasible`` if its
  peak rate (15 Θ / (8 T) from rest to rest) exceeds the rate bound.
* ``trapezoidal``: bang-coast-bang over the scenario's T, rest to rest, with the largest
  acceleration the torque bounds allow; ``infeasible`` if T is shorter than the minimum time.
* ``min_time``: the fastest bang-coast-bang under the torque, wheel-momentum and optional rate
  bounds.

Every profile honours the rate bound (option ``max_rate``, else ``maneuver.max_rate``, the rate
requirement ``rate_margin`` lower: :meth:`~planners.problem.ManeuverProblem.rate_bound`): the
body rate is ``‖ω‖ = |θ̇|``.

The body rate is ``ω = e θ̇`` and the feed-forward torque the rigid body's inverse dynamics
``I ω̇ + ω × I ω = I e θ̈ + θ̇² e × I e`` (:class:`planners.Reference`'s contract). What the
actuators must give is ``I ω̇ + ω × H``, ``H = I ω + A h_w`` the total angular momentum in body
axes: the bang profiles choose the acceleration ``α`` and the coast rate ``w`` so that every row
of the controllers' allocation (``Spacecraft.allocation_rows``: ``|M τ| <= L``, a row per working
wheel ``(A⁺)_i`` with its ``max_torque``, and the torquers' rows for what the wheels cannot give)
stays within ``f L`` (``f`` the ``torque_fraction`` times ``1 − actuator_margin``, the scenario's
actuator requirement), and the working wheels' momenta within ``1 − actuator_margin`` of their
``max_momentum``, along the whole profile (:class:`WheelBudget`). With wheels spanning three
axes ``H`` is conserved and turns about ``e`` in the body (closed form; no gyroscopic term at all
from rest with no stored momentum); without working wheels it is the rigid body's; with wheels
spanning fewer axes beside torquers the demand is integrated and the profile stretched until it
holds.
The environment's torque (gravity gradient, a constant disturbance) is not in this planner's
model, but the actuators must cancel it: a bound of it along the slew
(:meth:`~planners.problem.ManeuverProblem.environment_torque_bound`) is kept from every row's bound
(:attr:`WheelBudget.reserve`), and the momentum it adds to the wheels over the slew, at most
``‖(A⁺)_i‖ (‖d‖ + g) T`` per working wheel (``d`` the constant disturbance, ``g`` the
gravity gradient's bound: the impulse turns with the body into any wheel), from every working wheel's momentum bound
(:attr:`WheelBudget.momentum_reserve`): ``T`` the scenario's for ``trapezoidal``, the slew's own
for ``min_time`` (iterated from no reserve up to the least duration that covers its own slew).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
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

    def rate_words(self) -> str:
        """The profile's rate for a message: ``coast rate w rad/s`` when it coasts for more than
        1e-6 of its duration, else ``peak rate w rad/s`` (a triangle, at ``w`` only at its switch; a
        fixed T's root finding leaves a coast of about 1e-8 of T at the minimum time).

        Returns
        -------
        str
        """
        return f"{'coast' if self.coast > 1e-6 * self.duration else 'peak'} rate {self.rate_max:.4g} rad/s"

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
    torque = torque / np.max(np.abs(torque))  # its direction only: the norm of 1e300 kg m^2's overflows
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


def sinusoid_peak(const: Array, cos: Array, sin: Array, span: float) -> Array:
    """``max |k + c cos θ + s sin θ|`` over ``θ ∈ [0, span]``, row by row: the magnitude's peak.

    The larger of the signed maxima of the sinusoid and of its negative (:func:`sinusoid_max` on
    ``(k, c, s)`` and on ``(−k, −c, −s)``); the budget bounds a torque or a momentum of either sign
    by it.

    Parameters
    ----------
    const, cos, sin : (m,) ndarray
        The sinusoid's ``k``, ``c`` and ``s`` per row, as :func:`sinusoid_max` takes them.
    span : float
        The interval's length [rad], in ``[0, π]``.

    Returns
    -------
    (m,) ndarray
        The peak magnitude per row, ``>= 0``.
    """
    return np.maximum(sinusoid_max(const, cos, sin, span), sinusoid_max(-const, -cos, -sin, span))


def sinusoid_max(const: Array, cos: Array, sin: Array, span: float) -> Array:
    """``max (k + c cos θ + s sin θ)`` over ``θ ∈ [0, span]``, row by row: the signed maximum.

    Exact, not sampled: a smooth function's maximum on a closed interval is at an end or where its
    derivative ``s cos θ − c sin θ`` vanishes, ``θ = atan2(s, c)`` and ``atan2(s, c) + π`` (mod
    ``2π``), the two counted where they fall within the span. The budget reads it for a wheel's
    momentum pushed to one side (:class:`WheelBudget`).

    Parameters
    ----------
    const, cos, sin : (m,) ndarray
        ``k`` (constant), ``c`` (of ``cos θ``) and ``s`` (of ``sin θ``) per row.
    span : float
        The interval's length [rad], in ``[0, π]`` (θ from 0).

    Returns
    -------
    (m,) ndarray
        The maximum per row, of its sign (negative when the sinusoid stays below zero).
    """
    stationary = np.arctan2(sin, cos) % (2 * np.pi)
    candidates = [np.zeros_like(cos), np.full_like(cos, span)]
    for theta in (stationary, (stationary + np.pi) % (2 * np.pi)):
        candidates.append(np.where(theta <= span, theta, 0.0))
    return np.max([const + cos * np.cos(t) + sin * np.sin(t) for t in candidates], axis=0)


class WheelBudget:
    """What a rest-to-rest bang-coast-bang about a fixed axis asks of each allocation row.

    The body torque the actuators must give is ``τ = I ω̇ + ω × H`` with ``H = I ω + A h_w`` the
    total angular momentum, body axes (body and wheels, failed wheels' momentum included); the
    allocation (:meth:`ocp.Spacecraft.allocation_rows`) gives the working wheels ``g = −A⁺ τ`` and
    the rest, ``(1 − A A⁺) τ``, to the torquers. With ``ω = e θ̇`` each row ``j`` is bounded, for
    ``|θ̈| <= α`` and ``|θ̇| <= w``, by ``|a_j| α + c_j w + g_j w² <= f L_j``:

    * working wheels spanning three axes (torquers beside them are never asked): nothing torques
      the spacecraft from outside, ``H`` is constant in inertial axes and turns about ``e`` in the
      body, ``H(θ) = R_e(−θ) H_0``, so ``τ = I e θ̈ + θ̇ e × H(θ)`` (the body's ``ω × I ω`` is part of
      ``ω × H``): ``a = M I e``, ``g = 0`` and ``c_j`` the peak of ``|M_j e × H(θ)|`` over the
      rotation ``θ ∈ [0, Θ]`` (a sinusoid in θ: :func:`sinusoid_peak`). Exact when ``H_0 = 0``
      (``|a_j| α <= f L_j``: the wheels' torque is ``A⁺ I e θ̈``); with stored momentum, sound
      (``θ̇ <= w`` and the peak over the rotation taken together). The working wheels' momenta,
      ``h_w = s(θ) − p θ̇`` with ``s(θ) = h_w0 + A⁺ (H(θ) − H_0)`` and ``p = A⁺ I e``, bound the
      coast rate: ``θ̇`` runs over ``[0, w]`` (rest to rest), so each wheel needs
      ``|s_i(θ)| <= h_max,i`` and ``s_i(θ) − p_i w`` within ``±h_max,i`` on the side ``p_i``
      pushes it, ``w <= (h_max,i − max_θ (−sign(p_i) s_i(θ))) / |p_i|``. Exact with ``H_0 = 0``
      (``s_i = h_w0,i``, a null-space bias included: ``w <= (h_max,i + sign(p_i) h_w0,i) / |p_i|``);
      with stored momentum, sound and conservative where it takes every θ with every
      ``θ̇ ∈ [0, w]`` (the coast rate is reached only mid-slew, rest only at the ends).
    * no working wheel (torquers only, or every wheel failed): ``A h_w`` is the failed wheels'
      constant ``W_0`` and ``τ = I e θ̈ + θ̇² e × I e + θ̇ e × W_0``: ``a = M I e``,
      ``g = |M (e × I e)|``, ``c = |M (e × W_0)|``; exact when ``W_0 = 0`` (one of the two bangs
      adds the gyroscopic term at the coast rate).
    * wheels spanning fewer than three axes (beside torquers, which change ``H``): the rows of the
      first case are an estimate, not a bound (:attr:`exact` is False): :meth:`integrated_ratios`
      measures the profile's demand, and the planner stretches the profile until it holds (a
      momentum cap of 0 from the estimate refuses nothing: the measurement decides).

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre: the spacecraft and the initial wheel momenta (a non-zero initial rate, which
        the bang profiles do not meet, is taken up by the wheels as the allocation does,
        ``Δ(A h_w) = A A⁺ I ω_0``).
    axis : (3,) ndarray
        Unit Euler axis ``e``, body axes.
    angle : float
        Θ [rad], in ``[0, π]``.
    fraction : float
        ``f``, the share of each torque bound the profile may use.
    scale : float, optional
        A further factor on the torque bounds (the planner's shrinking; default 1).
    momentum_fraction : float, optional
        The share of each working wheel's ``max_momentum`` the profile may use (default 1).
    horizon : float or None, optional
        The slew's duration [s] over which the momentum the environment's torque adds to the
        wheels is reserved (:attr:`momentum_reserve`); ``None`` (default): the problem's T.
    environment : tuple of ((3,) ndarray, float) or None, optional
        ``problem.environment_torque_bound(problem.duration)`` when already computed (a planner
        sizing several budgets of one problem); ``None`` (default): computed here.

    Attributes
    ----------
    bounds : (m,) ndarray
        ``f L`` (times ``scale``) less :attr:`reserve` [N m].
    reserve : (m,) ndarray
        Per bounded row, a bound of ``|M_i τ_env|`` over the slew [N m]: the environment's torque
        (:meth:`~planners.problem.ManeuverProblem.environment_torque_bound`, ``|M_i d| + ‖M_i‖ g``
        for the constant disturbance ``d`` and the gravity gradient's bound ``g``), which the
        actuators must cancel besides the motion's own torque; 0 without one.
    momentum_reserve : (n,) ndarray
        Per working wheel, a bound of the momentum the environment's torque adds to it over the
        slew, ``‖(A⁺)_i‖ (‖d‖ + g) T`` [N m s] (``T`` the ``horizon``; the impulse of a body-fixed
        ``d`` turns with the body into any wheel): the wheels absorb
        the torque the actuators cancel, so the profile's own momentum keeps within ``h_max`` less
        it; 0 without an environment torque.
    accel, quadratic, linear : (m,) ndarray
        ``M I e`` (signed), ``g`` and ``c`` per row.
    exact : bool
        Whether the rows bound the demand (False: wheels spanning fewer than three axes).
    torque_rate_cap : float
        The largest coast rate at which the rate terms alone stay within the bounds [rad/s].
    momentum_rate_cap : float
        The largest coast rate the wheels' momentum bounds allow [rad/s] (``inf`` without one; 0
        when the rotation itself breaks it; an estimate when :attr:`exact` is False).
    uncounted : str
        For messages: what gives no torque off the working wheels' span (empty when every row has
        a bound).
    """

    def __init__(self, problem: ManeuverProblem, axis: Array, angle: float, fraction: float,
                 scale: float = 1.0, momentum_fraction: float = 1.0, horizon: float | None = None,
                 environment: tuple[Array, float] | None = None) -> None:
        spacecraft = problem.spacecraft
        inertia = spacecraft.inertia
        rows, limits = spacecraft.allocation_rows()
        self.problem, self.axis, self.angle, self.rows = problem, axis, angle, rows
        self.limits = limits
        # The actuators give the motion's torque less the environment's, which this planner does not
        # model: each bounded row keeps a bound of |M_i τ_env| in reserve (ManeuverProblem.environment_torque_bound).
        disturbance, gravity_gradient = (problem.environment_torque_bound(problem.duration) if environment is None
                                          else environment)
        self.reserve = np.where(limits > 0, np.abs(rows @ disturbance) + gravity_gradient * np.linalg.norm(rows, axis=1),
                                0.0)
        self.bounds = fraction * scale * limits - self.reserve
        wheels = spacecraft.wheels
        axes = spacecraft.wheel_axes
        h0 = np.asarray(problem.initial_state[7:], dtype=float)
        self.working = np.zeros(0, bool) if wheels is None else wheels.working
        working_axes = axes * self.working
        self.pinv = np.zeros((0, 3)) if wheels is None else wheels.pseudo_inverse[self.working]
        self.projector = working_axes @ np.linalg.pinv(working_axes) if np.any(self.working) else np.zeros((3, 3))
        momentum0 = axes @ h0 + self.projector @ inertia @ problem.omega0  # A h_w at the start of the profile
        self.wheel_momentum0 = momentum0
        self.h0 = h0[self.working] + self.pinv @ inertia @ problem.omega0
        # The environment's torque, cancelled by the actuators, goes into the wheels' momentum: at most
        # ‖(A⁺)_i‖ (‖d‖ + g) T over the slew, kept from each working wheel's bound. Not |(A⁺)_i d| T:
        # the impulse of a body-fixed d is fixed in inertial space while the body turns, so the body
        # sees it turn into other wheels (a slew about an axis across d loads a wheel d never acts on).
        self.horizon = problem.duration if horizon is None else float(horizon)
        self.momentum_reserve = (np.linalg.norm(self.pinv, axis=1)
                                 * (np.linalg.norm(disturbance) + gravity_gradient) * self.horizon)
        self.h_max = np.zeros(0) if wheels is None else (momentum_fraction * wheels.max_momentum[self.working]
                                                         - self.momentum_reserve)
        inertia_axis = inertia @ axis
        self.exact = bool(np.allclose(self.projector, np.eye(3), atol=1e-9)) or not np.any(self.working)
        self.accel = rows @ inertia_axis
        if np.any(self.working):  # H conserved, turning about e (an estimate when not exact)
            parallel = axis * (axis @ momentum0)
            self.quadratic = np.zeros(len(rows))
            self.linear = sinusoid_peak(np.zeros(len(rows)), rows @ np.cross(axis, momentum0),
                                        rows @ (momentum0 - parallel), angle)
            # h_w(θ, θ̇) = s(θ) − p θ̇, s(θ) = h0 + A⁺((cos θ − 1) H⊥ − sin θ e × H0), p = A⁺ I e, and
            # θ̇ in [0, w] (rest to rest): |s_i| <= h_max and s_i − p_i w on the side p_i pushes to.
            across = momentum0 - parallel
            const, cos = self.h0 - self.pinv @ across, self.pinv @ across
            sin = -self.pinv @ np.cross(axis, momentum0).astype(float)
            peak = sinusoid_peak(const, cos, sin, angle)
            per_rate = self.pinv @ inertia_axis
            side = np.sign(per_rate)
            toward = sinusoid_max(-side * const, -side * cos, -side * sin, angle)  # max over θ of −sign(p_i) s_i(θ)
            with np.errstate(divide="ignore", invalid="ignore"):
                caps = np.where(peak > self.h_max, 0.0,
                                np.where(np.abs(per_rate) > 1e-12 * np.linalg.norm(inertia_axis),
                                         (self.h_max - toward) / np.abs(per_rate), np.inf))
            self.momentum_rate_cap = float(max(np.min(caps, initial=np.inf), 0.0))
        else:
            self.quadratic = np.abs(rows @ np.cross(axis, inertia_axis))
            self.linear = np.abs(rows @ np.cross(axis, momentum0))
            self.momentum_rate_cap = np.inf
        # A row no actuator gives (limit 0, a projector's): its rounding is no demand on it.
        given = limits > 0
        scale_rows = np.linalg.norm(rows, axis=1)
        for values, size in ((self.accel, np.linalg.norm(inertia_axis)),
                             (self.quadratic, np.linalg.norm(np.cross(axis, inertia_axis))),
                             (self.linear, np.linalg.norm(momentum0))):
            values[~given & (np.abs(values) <= 1e-12 * scale_rows * size)] = 0.0
        self.accel[np.abs(self.accel) <= 1e-12 * np.max(np.abs(self.accel), initial=0.0)] = 0.0
        self.torque_rate_cap = _smallest_cap(*(_positive_root(g, c, b) for g, c, b in
                                               zip(self.quadratic, self.linear, self.bounds)))
        sink = [a.name for a in spacecraft.actuators if a.residual_rank is not None]
        self.uncounted = "" if np.all(limits > 0) else (
            " (off the working wheels' span only magnetorquers act, whose torque depends on the field and "
            "is never along it: the eigenaxis budget counts them as none)" if "magnetorquers" in sink
            and "torquers" not in sink else " (off the working wheels' span no actuator gives torque)")
        if np.any((self.bounds <= 0) & (limits > 0)):
            self.uncounted += (f" (the environment's torque, up to {np.max(self.reserve):.3g} N m on an allocation "
                               f"row, takes all of an actuator's share of its bound)")

    def margin(self, coast_rate: float) -> Array:
        """What is left of each row's bound for the acceleration.

        Parameters
        ----------
        coast_rate : float
            ``w`` [rad/s].

        Returns
        -------
        (m,) ndarray
            ``f L − c w − g w²`` per row, what is left for ``|a| α`` [N m].
        """
        return self.bounds - coast_rate * self.linear - coast_rate**2 * self.quadratic

    def integrated_ratios(self, profile: BangCoastBangProfile, step_angle: float = 0.002) -> tuple[float, float]:
        """The profile's peak demand on the allocation rows and the working wheels' momenta, by
        integration of ``d(A h_w)/dt = −A A⁺ τ``, ``τ = I e θ̈ + θ̇² e × I e + θ̇ e × A h_w``.

        Classical Runge-Kutta on each phase, in steps over which the body turns at most
        ``step_angle``; the demand is read at the steps' ends.

        Parameters
        ----------
        profile : BangCoastBangProfile
            The rest-to-rest profile about :attr:`axis`.
        step_angle : float, optional
            The most the body turns in a step [rad].

        Returns
        -------
        torque_ratio, momentum_ratio : float
            ``max |M τ| / (f L)`` (scaled bounds: :attr:`bounds`; ``inf`` where a row of bound 0 is
            asked more than rounding) and ``max |h_w| / h_max`` over the working wheels (0 without
            a bound).
        """
        axis, inertia = self.axis, self.problem.spacecraft.inertia
        inertia_axis = inertia @ axis
        spin = np.cross(axis, inertia_axis)
        cross = _cross_matrix(axis)  # cross @ w = axis × w
        phases = [(profile.ramp, profile.alpha), (profile.coast, 0.0), (profile.ramp, -profile.alpha)]
        momentum = self.wheel_momentum0.astype(float)
        rate0 = 0.0
        pieces: list[Array] = []
        stored: list[Array] = []
        for length, accel in phases:
            if length <= 0:
                continue
            peak_rate = max(abs(rate0), abs(rate0 + accel * length))
            steps = max(8, int(np.ceil(peak_rate * length / step_angle)))
            dt = length / steps
            # The momentum's equation is affine in it, so each step of the classical Runge-Kutta is
            # an affine map h -> Φ_k h + γ_k: built for every step at once, then composed.
            rates = rate0 + accel * dt * np.arange(steps, dtype=float)
            phi, gamma = _runge_kutta_maps(self.projector, cross, inertia_axis * accel, spin, rates, accel, dt)
            states = _affine_orbit(phi, gamma, momentum)  # (steps + 1, 3): the momentum at each step's ends
            ends = np.concatenate([[rate0], rates + accel * dt])
            pieces.append(inertia_axis * accel + np.outer(ends**2, spin) + ends[:, None] * (states @ cross.T))
            stored.append(states[1:])
            momentum = states[-1]
            rate0 = rate0 + accel * length
        torques = np.concatenate(pieces) if pieces else np.zeros((0, 3))
        momenta = np.concatenate(stored) if stored else np.zeros((0, 3))
        demand = np.abs(torques @ self.rows.T)
        size = np.linalg.norm(self.rows, axis=1) * np.max(np.linalg.norm(torques, axis=1), initial=0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(self.bounds > 0, demand / self.bounds, np.where(demand > 1e-9 * size, np.inf, 0.0))
        h = self.h0 + (momenta - self.wheel_momentum0) @ self.pinv.T if len(momenta) else np.zeros((1, 0))
        with np.errstate(divide="ignore", invalid="ignore"):  # a bound the reserve takes whole: no momentum fits
            h_ratio = np.where(~np.isfinite(self.h_max), 0.0, np.where(self.h_max > 0, np.abs(h) / self.h_max, np.inf))
        return float(np.max(ratio, initial=0.0)), float(np.max(h_ratio, initial=0.0))


def _cross_matrix(vector: Array) -> Array:
    """The matrix ``S`` with ``S @ w = vector × w``."""
    x, y, z = (float(value) for value in vector)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def _runge_kutta_maps(projector: Array, cross: Array, push: Array, spin: Array, rates: Array, accel: float,
                      dt: float) -> tuple[Array, Array]:
    """The classical Runge-Kutta steps of ``dh/dt = −P (p + r² s + r S h)``, ``r = r_k + accel t``
    over ``[0, dt]``, as affine maps ``h -> Φ_k h + γ_k``, one per start rate ``r_k``.

    Parameters
    ----------
    projector, cross : (3, 3) ndarray
        ``P`` and ``S``.
    push, spin : (3,) ndarray
        ``p`` and ``s``.
    rates : (n,) ndarray
        ``r_k``, the rate at each step's start.
    accel : float
        The rate's derivative over the steps.
    dt : float
        The step.

    Returns
    -------
    phi : (n, 3, 3) ndarray
    gamma : (n, 3) ndarray
    """
    coupling = projector @ cross
    eye = np.eye(3)

    def slope(rate: Array) -> tuple[Array, Array]:  # f(h) = K h + κ at the rate, per step
        return -rate[:, None, None] * coupling, -(push + np.outer(rate**2, spin)) @ projector.T

    half, end = rates + 0.5 * accel * dt, rates + accel * dt
    (a1, c1), (a2, c2), (a4, c4) = slope(rates), slope(half), slope(end)
    k1, q1 = a1, c1
    k2, q2 = a2 @ (eye + 0.5 * dt * k1), c2 + 0.5 * dt * np.einsum("nij,nj->ni", a2, q1)
    k3, q3 = a2 @ (eye + 0.5 * dt * k2), c2 + 0.5 * dt * np.einsum("nij,nj->ni", a2, q2)
    k4, q4 = a4 @ (eye + dt * k3), c4 + dt * np.einsum("nij,nj->ni", a4, q3)
    return eye + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4), dt / 6 * (q1 + 2 * q2 + 2 * q3 + q4)


def _affine_orbit(phi: Array, gamma: Array, start: Array) -> Array:
    """``h_0 = start``, ``h_{k+1} = Φ_k h_k + γ_k``: every ``h_k`` (``n + 1`` of them), by composing the
    maps in ``log2 n`` rounds of batched products (an inclusive scan) instead of ``n`` small ones.

    Parameters
    ----------
    phi : (n, 3, 3) ndarray
    gamma : (n, 3) ndarray
    start : (3,) ndarray

    Returns
    -------
    (n + 1, 3) ndarray
    """
    total, offset = phi.copy(), gamma.copy()  # after the scan: the composition of maps 0..k
    shift = 1
    while shift < len(total):
        later_total, later_offset = total[shift:], offset[shift:]
        offset[shift:] = np.einsum("nij,nj->ni", later_total, offset[:-shift]) + later_offset
        total[shift:] = later_total @ total[:-shift]
        shift *= 2
    return np.concatenate([[start], np.einsum("nij,j->ni", total, start) + offset])


def _positive_root(quadratic: float, linear: float, bound: float) -> float:
    """The largest ``w >= 0`` with ``g w² + c w <= b`` (``inf`` when neither term grows or the
    bound is infinite: an unlimited actuator caps no rate)."""
    if (quadratic <= 0 and linear <= 0) or bound == np.inf:
        return np.inf
    if bound <= 0:
        return 0.0
    if quadratic <= 0:
        return bound / linear
    return float(2 * bound / (linear + np.sqrt(linear**2 + 4 * quadratic * bound)))


def _smallest_cap(*caps: float) -> float:
    """The smallest of rate caps, each ``>= 0`` or ``inf`` (``inf`` for none).

    Python's ``min`` keeps or drops a NaN by its position, losing the real cap; a NaN here is a
    bug upstream, so it is refused rather than compared.
    """
    values = np.asarray(caps, dtype=float)
    if np.any(np.isnan(values)):
        raise AssertionError(f"a rate cap is NaN: {values.tolist()}")
    return float(np.min(values, initial=np.inf))


def _rounded_up(value: float, digits: int = 4) -> str:
    """``value`` (> 0) rounded up to ``digits`` significant digits: a duration to suggest, never
    below the one needed (42.0534 -> ``42.06``); from a billion up or below 1e-4, in powers of ten
    (``1.122e+151``, not 152 digits)."""
    if not (np.isfinite(value) and value > 0):
        return f"{value:.{digits}g}"
    exponent = int(np.floor(np.log10(value)))
    step = 10.0 ** (exponent - digits + 1)
    up = np.ceil(value / step * (1 - 1e-15)) * step
    if up < value:
        up += step
    if not -4 <= exponent < 9:
        return f"{up:.{digits - 1}e}"
    return f"{up:.{max(0, digits - 1 - exponent)}f}"


def _seconds(value: float) -> str:
    """A duration [s] for a message: to the millisecond from 1 ms to a billion seconds, else in powers
    of ten (``1.121e-09``, ``3.545e+156``; not ``0.000`` or 157 digits)."""
    return f"{value:.3f}" if 1e-3 <= value < 1e9 else f"{value:.4g}"


def _environment_loads_the_wheels(problem: ManeuverProblem, environment: tuple[Array, float]) -> bool:
    """Whether the environment has a torque (``environment``: the constant disturbance and the
    gravity gradient's bound) and a working wheel a momentum bound: then the momentum the
    environment adds over the slew is reserved from it."""
    wheels = problem.spacecraft.wheels
    if wheels is None or not np.any(np.isfinite(wheels.max_momentum[wheels.working])):
        return False
    disturbance, gravity_gradient = environment
    return gravity_gradient > 0 or bool(np.any(disturbance != 0))


class EigenaxisPlanner(Planner):
    """Eigenaxis slew planner; see the module docstring for the profiles."""

    name = "eigenaxis"
    example_options = ({"profile": "smooth"}, {"profile": "trapezoidal"}, {"profile": "min_time"})
    closed_form = True
    cheap = True
    honours = frozenset({"rate"})  # every profile: ‖ω‖ = |θ̇|, at most the rate bound or infeasible

    @classmethod
    def honoured(cls, options: Any) -> frozenset[str]:
        """The rate bound with every profile; the actuator requirement with the bang profiles
        (``trapezoidal`` and ``min_time`` plan within ``1 − actuator_margin`` of every torque and
        momentum limit, :class:`WheelBudget`); the quintic's torque is fixed by T.

        Parameters
        ----------
        options : Options
            The planner's options.

        Returns
        -------
        frozenset of str
        """
        return cls.honours | ({"actuators"} if getattr(options, "profile", "smooth") != "smooth" else frozenset())

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

    def least_duration(self, problem: ManeuverProblem) -> float | None:
        """The least duration of the bang profiles, in closed form (a search of milliseconds with
        wheels spanning fewer than three axes): ``min_time``'s slew, and the fastest
        bang-coast-bang under ``trapezoidal``'s bounds (its momentum reserve over T), below which
        it is ``infeasible`` (:meth:`planners.base.Planner.least_duration`).

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan.

        Returns
        -------
        float or None
            The duration [s]; ``None`` for ``smooth`` (planned over T), for a problem the planner
            refuses and where the fastest profile itself is infeasible (its own reason, said
            when it is planned).
        """
        if self.options.profile == "smooth" or self.problem_error(problem) is not None:
            return None
        fastest = type(self)(replace(self.options, profile="min_time"))
        if self.options.profile == "min_time":
            reference = fastest.plan(problem)
        else:  # trapezoidal: the fastest profile under its own budget (the environment's momentum over T)
            axis, angle = self._axis_angle(problem)
            if angle < 1e-12:
                return None
            max_rate = problem.rate_bound(self.options.max_rate, self.options.rate_margin)
            reference = fastest._plan_bang(problem, axis, angle, max_rate, problem.duration,
                                           problem.environment_torque_bound(problem.duration))
        return float(reference.duration) if reference.ok else None

    @staticmethod
    def _axis_angle(problem: ManeuverProblem) -> tuple[Array, float]:
        """The eigenaxis (unit, body axes) and the angle [rad] of the rotation from ``q0`` to ``qf``."""
        assert problem.qf is not None  # problem_error (the default) refuses a free attitude
        rotvec = quat.to_rotation_vector(quat.error(problem.qf, problem.q0))
        angle = float(np.linalg.norm(rotvec))
        return (rotvec / angle if angle > 1e-12 else np.array([1.0, 0.0, 0.0])), angle

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
        rate_margin : float
            The rate requirement (``requirements.rate.max``, ``ManeuverProblem.rate_requirement``)
            is planned this fraction lower, in [0, 1) (default 0.01), with every profile: a
            zero-order-hold closed loop tracking a coast at the bound overshoots it (by 0.03-0.04 %
            with a perfect plant), and one tracking the quintic's smooth peak at the bound too, less
            (2.4e-5 of it at 0.5 s samples);
            ``maneuver.max_rate`` and the option ``max_rate`` are imposed as given
            (:meth:`~planners.problem.ManeuverProblem.rate_bound`).
        torque_fraction : float
            Share of each actuator's torque bound (each wheel's ``max_torque`` through ``g = −A⁺ τ``,
            the torquers' per axis) the bang profiles may use, in (0, 1]; default 1. The wheels'
            ``max_momentum`` caps the coast rate whole. With an actuator requirement
            (``requirements.actuators.margin``) the bang profiles keep ``1 − margin`` of every
            torque and momentum limit, and this share applies within it. With an environment
            torque (gravity gradient, a constant disturbance), which this planner does not model, a
            bound of it is kept from each torque bound besides, and of the momentum it adds over
            the slew from each wheel's momentum bound (:class:`WheelBudget`).
        """

        profile: Literal["smooth", "trapezoidal", "min_time"] = "smooth"
        max_rate: Annotated[float | None, Range(gt=0.0)] = None       # rad/s about the axis; default: the problem's max_rate
        rate_margin: Annotated[float, Range(ge=0.0, lt=1.0)] = 0.01   # the rate requirement is planned this fraction lower
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
        bound, stated = problem.rate_bound(option, self.options.rate_margin), problem.rate_bound(option)
        if bound is not None and stated is not None and bound < stated:  # the rate requirement, less the margin
            return f"requirements.rate.max less rate_margin {self.options.rate_margin:g}"
        return "option max_rate" if option is not None and (problem.max_rate is None or option < problem.max_rate) \
            else "the problem's: maneuver.max_rate, else requirements.rate.max"

    def _plan(self, problem: ManeuverProblem) -> Reference:
        # An overflow (a torque bound of 1e300 N m over a moment of 1e-9 kg m^2, T = 1e300 s) is a
        # failed reference that says so, not NumPy's warning and an "ok" reference of NaN duration.
        try:
            with np.errstate(over="raise", invalid="raise"):
                return self._plan_profile(problem)
        except (OverflowError, FloatingPointError) as failure:
            moments = np.linalg.eigvalsh(problem.spacecraft.inertia)
            return FailedReference(self.name, f"numerical failure: {type(failure).__name__}: {failure} in the "
                                   f"{self.options.profile} profile (duration {problem.duration:g} s, principal moments "
                                   f"{[float(f'{m:.6g}') for m in moments]} kg m^2, actuator limits "
                                   f"{bound_keys(list(problem.spacecraft.actuators))}): values far beyond any "
                                   "spacecraft's overflow its arithmetic")

    def _plan_profile(self, problem: ManeuverProblem) -> Reference:
        axis, angle = self._axis_angle(problem)
        inertia = problem.spacecraft.inertia
        max_rate = problem.rate_bound(self.options.max_rate, self.options.rate_margin)
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
        if angle < 1e-12:
            return EigenaxisReference(problem.q0, axis, BangCoastBangProfile(0.0, 1.0, 0.0), problem.duration if self.options.profile
                                      == "trapezoidal" else 0.0, inertia, "no rotation needed", problem)
        environment = problem.environment_torque_bound(problem.duration)  # one bound for every budget
        if self.options.profile != "min_time" or not _environment_loads_the_wheels(problem, environment):
            return self._plan_bang(problem, axis, angle, max_rate, problem.duration, environment)
        # min_time with an environment torque on wheels with a momentum bound: the momentum it adds
        # over the slew is reserved over the slew's own duration, which grows with the reserve. From
        # no reserve the durations increase to the least horizon that covers its own slew.
        horizon = 0.0
        for _ in range(100):
            reference = self._plan_bang(problem, axis, angle, max_rate, horizon, environment)
            if not reference.ok or reference.duration <= horizon:
                return reference
            horizon = reference.duration * (1 + 1e-6)
        return FailedReference(self.name, f"the minimum time grows with the wheels' momentum reserved for the "
                               f"environment's torque over it, past {horizon:.4g} s after 100 passes", "infeasible")

    def _plan_bang(self, problem: ManeuverProblem, axis: Array, angle: float, max_rate: float | None,
                   horizon: float, environment: tuple[Array, float] | None = None) -> Reference:
        """The bang profiles (``trapezoidal``, ``min_time``) of a rotation ``angle`` > 0 about
        ``axis``, the environment's momentum reserved over ``horizon`` [s] (:class:`WheelBudget`, with
        ``environment`` its torque bound when already computed)."""
        inertia = problem.spacecraft.inertia
        keep = 1.0 - (problem.actuator_margin or 0.0)  # the actuator requirement's share of each limit
        budget = WheelBudget(problem, axis, angle, self.options.torque_fraction * keep, momentum_fraction=keep,
                             horizon=horizon, environment=environment)
        if budget.exact:
            return self._bang(problem, axis, angle, max_rate, budget, self.options.profile)
        # Wheels spanning fewer than three axes (beside torquers): the wheels' momentum moves with
        # what the torquers give, not as a conserved total, and the budget is an estimate. Plan the
        # fastest profile under it, measure its demand through the allocation by integration, and
        # stretch it in time by k (α/k², w/k): from zero initial wheel momentum every torque then
        # scales by 1/k² and every momentum by 1/k exactly, so one stretch meets the worst bound.
        fastest = self._bang(problem, axis, angle, max_rate, budget, "min_time")
        if not isinstance(fastest, EigenaxisReference):
            return fastest
        base = fastest.profile
        assert isinstance(base, BangCoastBangProfile)

        def stretched_by(k: float) -> BangCoastBangProfile:
            return BangCoastBangProfile(angle, base.alpha / k**2, base.rate_max / k)

        def excess(k: float, step_angle: float = 0.002) -> float:
            """``max(sqrt(torque ratio), momentum ratio)`` of the profile stretched ``k`` x (inf off the span)."""
            torque_ratio, momentum_ratio = budget.integrated_ratios(stretched_by(k), step_angle)
            return max(np.sqrt(torque_ratio), momentum_ratio)

        off_span = FailedReference(self.name, f"the profile about {axis.round(4).tolist()} asks a torque off the "
                                   f"working wheels' span{budget.uncounted}", "infeasible")
        stretched = 1.0
        for _ in range(8):
            stretch = excess(stretched)
            if not np.isfinite(stretch):
                return off_span
            if stretch <= 1 + 1e-9:
                break
            stretched *= stretch * (1 + 1e-9)
        else:
            # Stored momentum: the wheels' momenta have a part the rotation itself moves, which no
            # stretch scales down, and the stretches above converge slowly. Bracket and bisect (on
            # coarser steps), then verify on the fine ones.
            low, high = stretched, 2 * stretched
            while (stretch := excess(high, 0.01)) > 1:
                if not np.isfinite(stretch):
                    return off_span
                if high > 1e6 * stretched:
                    return FailedReference(self.name, f"the bang-coast-bang profile's demand, measured by integration, "
                                           f"stays {stretch:.4g} x a bound even {high:.3g} x slower than the fastest "
                                           f"under the estimate (the stored momentum, moved by the rotation itself, "
                                           f"takes a working wheel beyond its max_momentum)", "infeasible")
                low, high = high, 4 * high
            while high > low * (1 + 1e-4):
                middle = 0.5 * (low + high)
                low, high = (low, middle) if excess(middle, 0.01) <= 1 else (middle, high)
            for _ in range(8):
                stretch = excess(high)
                if stretch <= 1 + 1e-9:
                    break
                high *= max(stretch, 1 + 1e-6)
            else:
                return FailedReference(self.name, "the bang-coast-bang profile's demand, measured by integration, "
                                       "stayed above the bounds after the stretches", "infeasible")
            stretched = high
        profile = stretched_by(stretched)
        # Without torquers nothing torques the spacecraft from outside (H conserved: the budget was
        # exact); with them an unstretched profile is feasible but not proven the fastest.
        torquers = bool(np.any(budget.limits[len(budget.h0):] > 0))
        words = "verified by integration through the allocation: the working wheels span fewer than three axes"
        if stretched > 1 + 1e-6:  # not the rounding margin of the verification
            words += f"; stretched {stretched:.4g} x in time to meet the bounds, feasible, not the minimum time"
        elif torquers:
            words += "; feasible, not proven the minimum time (the torquers change the total momentum)"
        if self.options.profile == "min_time":
            return EigenaxisReference(problem.q0, axis, profile, profile.duration, inertia,
                                      f"minimum time {_seconds(profile.duration)} s, {profile.rate_words()} ({words})", problem)
        if problem.duration < profile.duration * (1 - 1e-12):
            return FailedReference(self.name, self._too_short(problem, profile.duration, f"the fastest bang-coast-bang "
                                   f"this planner verifies, {profile.duration:.6g} s ({words})"), "infeasible")
        stretch = problem.duration / profile.duration
        slower = BangCoastBangProfile(angle, profile.alpha / stretch**2, profile.rate_max / stretch)
        if max(budget.integrated_ratios(slower)) > 1 + 1e-9:
            return FailedReference(self.name, f"the bang-coast-bang over T = {problem.duration:g} s, stretched from "
                                   f"the fastest verified one ({profile.duration:.4g} s), exceeds a bound", "infeasible")
        slower.coast = problem.duration - 2 * slower.ramp
        slower.duration = problem.duration
        return EigenaxisReference(problem.q0, axis, slower, problem.duration, inertia,
                                  f"bang-coast-bang, {slower.rate_words()} (the fastest verified "
                                  f"profile stretched to T; {words})", problem)

    def _too_short(self, problem: ManeuverProblem, least: float, shortest: str) -> str:
        """Why ``trapezoidal`` cannot plan over ``maneuver.duration`` (T), shorter than ``least`` [s]
        (``shortest`` says which profile takes it, and under what), and what to change."""
        fraction = self.options.torque_fraction
        levers = (f"a torque_fraction above {fraction:g} (planners[].options), " if fraction < 1 else "") + \
            "larger actuator limits (spacecraft.wheels or spacecraft.torquers: max_torque, max_momentum)"
        if problem.actuator_margin:
            levers += " or a smaller requirements.actuators.margin"
        return (f"maneuver.duration, the manoeuvre's time budget (T = {problem.duration:g} s), is shorter than "
                f"{shortest}; a maneuver.duration of at least {_rounded_up(least)} s admits it, or {levers}")

    def _bang(self, problem: ManeuverProblem, axis: Array, angle: float, max_rate: float | None,
              budget: WheelBudget, profile_name: str) -> Reference:
        """The bang-coast-bang profile ``profile_name`` (``trapezoidal`` or ``min_time``) under ``budget``."""
        inertia = problem.spacecraft.inertia
        accel_axis, quadratic, linear = budget.accel, budget.quadratic, budget.linear
        active = np.abs(accel_axis) > 0

        def acceleration(coast_rate: float) -> float:
            """Largest α with every row within its bound while coasting at ``coast_rate``."""
            margin = budget.margin(coast_rate)
            if np.any(margin < 0) or np.any(margin[active] <= 0):
                return 0.0
            return float(np.min(margin[active] / np.abs(accel_axis[active])))

        if not np.any(active) or acceleration(0.0) <= 0:
            return FailedReference(self.name, f"the actuators give no torque about the axis {axis.round(4).tolist()}"
                                   f"{budget.uncounted}", "infeasible")
        momentum_cap = budget.momentum_rate_cap
        if not budget.exact and momentum_cap <= 0:  # an estimate (H not conserved): the integration decides
            momentum_cap = np.inf
        rate_cap = _smallest_cap(max_rate if max_rate is not None else np.inf, budget.torque_rate_cap, momentum_cap)
        if rate_cap <= 0:
            why = ("the stored momentum, turning in the body with the rotation, takes a working wheel beyond "
                   "its max_momentum" + (f" less the {np.max(budget.momentum_reserve):.3g} N m s the environment's "
                                         f"torque may add over {budget.horizon:.4g} s"
                                         if np.any(budget.momentum_reserve > 0) else "")
                   if momentum_cap <= 0 else
                   f"the gyroscopic torque of any rate asks what the actuators cannot give{budget.uncounted}")
            return FailedReference(self.name, f"no rotation about the axis {axis.round(4).tolist()} is feasible: "
                                   f"{why}", "infeasible")

        def slew_time(coast_rate: float) -> float:
            alpha = acceleration(coast_rate)
            if alpha <= 0 or coast_rate <= 0:
                return np.inf
            return angle / coast_rate + coast_rate / alpha if coast_rate**2 / alpha <= angle else 2 * np.sqrt(angle / alpha)

        # With no rate-dependent term the optimum is the triangle w = sqrt(Θ α); else a bounded 1-D search.
        peak = np.sqrt(angle * acceleration(0.0))
        if (np.all(quadratic == 0) and np.all(linear == 0)) or not np.isfinite(rate_cap):
            best_rate = _smallest_cap(peak, rate_cap)
        else:
            best_rate = golden_section_minimum(slew_time, 1e-9 * peak, min(peak, rate_cap), 1e-12 * peak)
        best_rate = min(best_rate, np.sqrt(angle * acceleration(best_rate)))  # a triangle never coasts faster
        minimum_time = slew_time(best_rate)
        momentum_words = (", capped by the wheels' momentum bound" if np.isfinite(momentum_cap)
                          and best_rate >= momentum_cap * (1 - 1e-9) else "")
        reserve_words = "" if not np.any(budget.reserve > 0) else (
            f", up to {np.max(budget.reserve):.3g} N m of the torque bounds kept for the environment's torque")
        if np.any(budget.momentum_reserve > 0) and np.any(np.isfinite(budget.h_max)):
            reserve_words += (f", up to {np.max(budget.momentum_reserve):.3g} N m s of the wheels' momentum bounds "
                              f"for what it adds over {budget.horizon:.4g} s")
        if profile_name == "min_time":
            profile = BangCoastBangProfile(angle, acceleration(best_rate), best_rate)
            return EigenaxisReference(problem.q0, axis, profile, profile.duration, inertia,
                                      f"minimum time {_seconds(profile.duration)} s, {profile.rate_words()}"
                                      f"{momentum_words}{reserve_words}", problem)
        if problem.duration < minimum_time * (1 - 1e-12):
            bounds_words = "the torque bounds"
            if max_rate is not None and best_rate >= max_rate * (1 - 1e-9):  # the rate bound caps the coast
                bounds_words += f" and the rate bound {max_rate:g} rad/s ({self._rate_source(problem)})"
            if momentum_words:
                bounds_words += " and the wheels' momentum bound"
            return FailedReference(self.name, self._too_short(problem, minimum_time, f"the minimum bang-coast-bang "
                                   f"time {minimum_time:.6g} s under {bounds_words}, for its slew of "
                                   f"{np.rad2deg(angle):.4g} deg to the final attitude"), "infeasible")
        # Fixed T: the slowest coast rate w with w (T − w/α(w)) = Θ.
        def covered(w: float) -> float:
            alpha = acceleration(w)
            return w * (problem.duration - w / alpha) - angle if alpha > 0 else -angle

        coast_rate = bisection_root(covered, 1e-15, best_rate, 1e-15) if covered(best_rate) > 0 else best_rate
        profile = BangCoastBangProfile(angle, acceleration(coast_rate), coast_rate)
        profile.coast = problem.duration - 2 * profile.ramp  # exact T despite root tolerance
        profile.duration = problem.duration
        return EigenaxisReference(problem.q0, axis, profile, problem.duration, inertia,
                                  f"bang-coast-bang, {profile.rate_words()}{reserve_words}", problem)
