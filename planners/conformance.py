"""Checks every planner's reference must pass (the planner contract of :mod:`planners.base`),
and standard problems to plan for them.

``tests/test_planner_conformance.py`` runs every check on every entry of ``PLANNERS`` (each of its
``example_options``) for every standard problem the planner accepts (``problem_error`` is
``None``), the way scipy tests every ``METHODS`` entry. A check raises :class:`ConformanceError`
with a message that says what is wrong and what to do about it; a new planner can be checked by
hand with :func:`check_reference`.

Oracles: finite values and unit quaternions on a dense grid (first: a NaN would read as another
defect in the later checks), finite differences of the reference's own ``q`` and ``ω``
(kinematics, rate derivative, inverse dynamics), one-sided differences of ``ω`` at 0 and T against
the reference's own ``ω̇`` (a rate step at an end), point-wise evaluation (vectorisation) and an
independent numerical integration of the torque-free Euler and kinematic equations (continuation
after T), for a planner that declares ``closed_form``, the reference's own ``sample`` against
the symbolic evaluator that ``slewbench codegen`` exports as C, and, for a planner that declares
``deterministic`` (the default), a second plan of one problem by a fresh instance against the first,
bit for bit (what a trade study's reuse of references relies on).
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Protocol

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

from ocp import CircularOrbit, Environment, ReactionWheels, Spacecraft, Torquers, quat
from ocp.dynamics.layout import REFERENCE_FIELDS
from planners.base import Planner
from planners.errors import ConformanceError
from planners.problem import Array, ManeuverProblem
from planners.reference import (
    BREAKPOINT_INSTANT,
    JUMP_TOLERANCE,
    Reference,
    inverse_dynamics_torque,
)
from planners.registry import PLANNERS
from planners.torque_free import REST_RATE

__all__ = ["ATTITUDE_TOLERANCE", "CHECKS", "CLOSED_FORM_TOLERANCE", "DETERMINISM_PROBLEMS", "FINITE_SAMPLES",
           "NORM_TOLERANCE", "RATE_TOLERANCE", "RELATIVE_TOLERANCE", "Check", "check_after_end", "check_boundary",
           "check_closed_form", "check_deterministic", "check_dynamics", "check_ends", "check_finite",
           "check_kinematics", "check_least_duration", "check_reference", "check_times", "check_vectorised", "closed_form_check_times",
           "declares_closed_form", "declared_ends", "determinism_problem", "finite_check_times", "standard_problems"]

ATTITUDE_TOLERANCE = 2e-5
"""rad: boundary attitudes (about 1e-3 deg, what the shooting planners guarantee)."""
RATE_TOLERANCE = 1e-7
"""rad/s: boundary rates, plus ``RELATIVE_TOLERANCE`` times the problem's rate scale (the largest of
``‖ω0‖``, ``‖ωf‖`` and the slew angle over the reference's duration, :func:`check_boundary`), not
the reference's own peak rate: a reference whose rate runs away mid-slew does not widen its own
tolerance at the ends."""
RELATIVE_TOLERANCE = 1e-5
"""Finite-difference checks, relative to the scale of the compared quantity."""
NORM_TOLERANCE = 1e-6
"""``|‖q‖ − 1|`` allowed of the reference's quaternions: far above rounding and the drift of an
integration that does not renormalise, far below a scaled quaternion (``1.01 q``)."""
FINITE_SAMPLES = 2001
"""Times on ``[0, T]`` where :func:`check_finite` samples the reference (uniform, plus its
breakpoints and enforced times): a step of T/2000, so a defect lasting T/1000 shows."""
CLOSED_FORM_TOLERANCE = 1e-12
"""The symbolic evaluator against ``sample`` (:func:`check_closed_form`), relative to each field's
scale (its largest magnitude on the grid): a few hundred roundings, far below any slip of a term."""
DETERMINISM_PROBLEMS = ("rest_to_rest", "non_principal", "rate_to_rate", "gravity_gradient", "spinning")
"""The :func:`standard_problems` from the cheapest to plan to the dearest (measured on the built-in
planners: the spinning body and the gravity gradient cost the shooting and co-state methods the
most): :func:`check_deterministic` plans the first one a planner accepts."""


def standard_problems() -> dict[str, ManeuverProblem]:
    """Manoeuvres every planner is tried on (it may decline some through ``problem_error``).

    Returns
    -------
    dict of str to ManeuverProblem
        Name to problem: rest to rest on a principal-axis body with wheels, rest to rest on a
        non-principal body with ideal torquers, the spin paper's re-pointing of a spinning body
        (free final rate), a rate-to-rate slew, and a rest-to-rest slew under gravity gradient.
    """
    wheels = ReactionWheels.from_body_axes(max_torque=0.1)
    principal = Spacecraft(np.array([19.5, 19.0, 12.6]), wheels=wheels)
    rotation = quat.rotation_matrix(quat.from_axis_angle(np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0), 0.7))
    non_principal = Spacecraft(rotation @ np.diag([10.0, 14.0, 18.0]) @ rotation.T, torquers=Torquers(1.0))
    q0 = quat.from_axis_angle(np.array([0.3, -0.5, 0.8]) / np.sqrt(0.98), 0.4)
    qf = quat.from_axis_angle(np.array([-0.6, 0.2, 0.7]) / np.sqrt(0.89), 1.9)
    orbit = Environment(CircularOrbit(500e3, 0.9), gravity_gradient=True)
    return {
        "rest_to_rest": ManeuverProblem(principal, q0, np.zeros(3), qf, 150.0, omegaf=np.zeros(3), max_rate=0.05),
        "non_principal": ManeuverProblem(non_principal, quat.IDENTITY, np.zeros(3), qf, 90.0, omegaf=np.zeros(3),
                                         max_rate=0.08),
        # Biggs & Horri's micro-satellite spinning at 0.2 rad/s about roll, re-pointed by 90 deg in 200 s.
        "spinning": ManeuverProblem(principal, quat.IDENTITY, np.array([0.2, 0.0, 0.0]),
                                    quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), np.pi / 2), 200.0),
        "rate_to_rate": ManeuverProblem(Spacecraft(np.array([8.0, 6.0, 5.0]), torquers=Torquers(0.5)), q0,
                                        np.array([0.01, -0.02, 0.015]), qf, 80.0, omegaf=np.array([-0.01, 0.02, 0.0]),
                                        max_rate=0.08),
        "gravity_gradient": ManeuverProblem(non_principal, q0, np.zeros(3), qf, 120.0, omegaf=np.zeros(3),
                                            environment=orbit, max_rate=0.05),
    }


def _fix_free(condition: str) -> str:
    return (f"meet it, or, if the method cannot, declare it on the reference: "
            f"Reference(..., free_boundary={{'{condition}'}}) (metrics then report the mismatch)")


def finite_check_times(reference: Reference, points: int = FINITE_SAMPLES) -> Array:
    """Where :func:`check_finite` samples: ``points`` uniform times on ``[0, T]``, the declared
    breakpoints and enforced times (the reference's own grid) inside it, and a few after T.

    Parameters
    ----------
    reference : Reference
        The reference to sample.
    points : int, optional
        Uniform times on ``[0, T]`` (default :data:`FINITE_SAMPLES`).

    Returns
    -------
    (M,) ndarray
        Sorted times [s].
    """
    T = reference.duration
    own = [reference.breakpoints]
    if reference.enforced_times is not None:
        own.append(reference.enforced_times)
    inside = np.concatenate(own)
    inside = inside[(inside >= 0.0) & (inside <= T)]
    return np.unique(np.concatenate([np.linspace(0.0, T, points), inside, T * np.array([1.05, 1.3, 2.0])]))


def check_finite(reference: Reference, points: int = FINITE_SAMPLES, after_end: bool = True) -> None:
    """Every quantity is finite and every ``q`` a unit quaternion, on a dense grid of ``[0, T]``
    (:func:`finite_check_times`) and after T.

    Run first: the other checks difference, normalise and compare the same numbers, and a NaN
    there reads as another defect.

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.
    points : int, optional
        Uniform times on ``[0, T]`` (default :data:`FINITE_SAMPLES`; a caller that screens many
        references, such as collocation's seeds, takes fewer).
    after_end : bool, optional
        Also sample the continuation after T (default; a start for another method is read on
        ``[0, T]`` only, and its torque-free coast after T is integrated numerically).

    Raises
    ------
    ConformanceError
        At the first time where ``q``, ``ω``, ``ω̇`` or the torque is not finite, or where
        ``|‖q‖ − 1|`` exceeds :data:`NORM_TOLERANCE`.
    """
    T = reference.duration
    if not (np.isfinite(T) and T > 0.0):
        raise ConformanceError(f"{reference.planner}: the reference's duration is {T!r} s; it must be a finite "
                               f"positive number of seconds")
    times = finite_check_times(reference, points)
    # [0, T] first: the continuation after T starts from the state at T, which must be finite.
    for part in (times[times <= T], times[times > T]) if after_end else (times[times <= T],):
        try:
            sample = reference.sample(part)
        except (TypeError, ValueError) as error:  # the contract's shape checks (Reference.sample)
            raise ConformanceError(f"{reference.planner}: sampling at {part.size} times on [{part[0]:g}, {part[-1]:g}] "
                                   f"s: {error}") from error
        for name, values in zip(("q", "ω", "ω̇", "torque"), sample):
            bad = ~np.all(np.isfinite(values), axis=1)
            if np.any(bad):
                k = int(np.argmax(bad))
                raise ConformanceError(
                    f"{reference.planner}: non-finite {name} at t = {part[k]:.6g} s ({part[k] / T:.4g} T): "
                    f"{values[k].tolist()} ({int(np.sum(bad))} of {part.size} times sampled on "
                    f"[{part[0]:g}, {part[-1]:g}] s); every quantity of a reference must be finite at every time "
                    f"(a division by a vanishing norm, an arccos or sqrt outside its domain, an interpolant "
                    f"evaluated off its grid)")
        deviation = np.abs(np.linalg.norm(sample.q, axis=1) - 1.0)
        if np.max(deviation) > NORM_TOLERANCE:
            k = int(np.argmax(deviation))
            raise ConformanceError(
                f"{reference.planner}: q at t = {part[k]:.6g} s has norm {np.linalg.norm(sample.q[k]):.9g}, not 1 "
                f"(|‖q‖ − 1| = {deviation[k]:.3g} > {NORM_TOLERANCE:g}); a reference's q must be a unit "
                f"quaternion at every time: normalise it (ocp.quat.normalize)")


def declared_ends(reference: Reference) -> tuple[bool, bool]:
    """Whether the reference declares a rate step at 0 and at T (a breakpoint there).

    Parameters
    ----------
    reference : Reference
        The reference.

    Returns
    -------
    at_start, at_end : bool
        A breakpoint at 0; a breakpoint at T (within 1e-12 T).
    """
    T, points = reference.duration, reference.breakpoints
    slack = 1e-12 * max(abs(T), 1.0)
    return bool(np.any(np.abs(points) <= slack)), bool(np.any(np.abs(points - T) <= slack))


def check_boundary(problem: ManeuverProblem, reference: Reference) -> None:
    """``q(0) = q0``, ``ω(0) = ω0``, ``q(T) = qf``, ``ω(T) = ωf`` (when fixed), except those the
    reference declares in ``free_boundary``, and ``ω(0) = ω0`` when it declares a rate step at 0
    (a breakpoint at 0: its sample at 0 is then the right limit, the step an impulse the scoring
    counts).

    Tolerances: :data:`ATTITUDE_TOLERANCE` (2e-5 rad) on the attitudes; on the rates
    :data:`RATE_TOLERANCE` + :data:`RELATIVE_TOLERANCE` times the problem's rate scale, the largest
    of ``‖ω0‖``, ``‖ωf‖`` (when fixed) and ``θ / T`` (the slew angle from ``q0`` to ``qf`` over the
    reference's duration: the mean rate of any motion between them), never the reference's own
    rates (a reference peaking at 1e4 rad/s mid-slew would otherwise pass ends 0.1 rad/s off).

    Parameters
    ----------
    problem : ManeuverProblem
        The planned problem.
    reference : Reference
        The planner's reference for it (status ``"ok"``).

    Raises
    ------
    ConformanceError
        Naming the condition, both values and the fix.
    """
    T = reference.duration
    start, end = reference.sample(0.0), reference.sample(T)
    rate_tolerance = RATE_TOLERANCE + RELATIVE_TOLERANCE * _rate_scale(problem, T)
    checks = [("q0", "q(0)", start.q, problem.q0, True), ("omega0", "ω(0)", start.omega, problem.omega0, False),
              ("qf", f"q(T = {T:g} s)", end.q, problem.qf, True),
              ("omegaf", f"ω(T = {T:g} s)", end.omega, problem.omegaf, False)]
    stepped = {"omega0"} if declared_ends(reference)[0] else set()
    for condition, label, value, wanted, attitude in checks:
        if wanted is None or condition in reference.free_boundary or condition in stepped:
            continue
        if attitude:
            error = float(quat.error_angle(value, wanted))
            bad, unit, tolerance = error > ATTITUDE_TOLERANCE, "rad", ATTITUDE_TOLERANCE
        else:
            error = float(np.linalg.norm(value - wanted))
            bad, unit, tolerance = error > rate_tolerance, "rad/s", rate_tolerance
        if bad:
            raise ConformanceError(
                f"{reference.planner}: {label} = {np.round(value, 6).tolist()} but the problem asks "
                f"{condition} = {np.round(wanted, 6).tolist()} (error {error:.3g} {unit} > {tolerance:.2g}); "
                + _fix_free(condition))


def _rate_scale(problem: ManeuverProblem, duration: float) -> float:
    """The problem's rate scale [rad/s] for :func:`check_boundary`: the largest of ``‖ω0‖``,
    ``‖ωf‖`` (when fixed) and the slew angle over ``duration`` (0 without a target attitude)."""
    angle = 0.0 if problem.qf is None else float(quat.error_angle(problem.qf, problem.q0))
    rates = [float(np.linalg.norm(problem.omega0)), angle / duration]
    if problem.omegaf is not None:
        rates.append(float(np.linalg.norm(problem.omegaf)))
    return max(rates)


def check_ends(reference: Reference) -> None:
    """No undeclared rate step at 0 or T: ``ω`` at each end against ``ω`` an instant inside.

    The instant is the scoring's, ``h = 1e-9 max(T, 1 s)``
    (:func:`scenarios.requirements.scoring.rate_jumps`); a change of ``ω`` over it beyond
    ``2 h max|ω̇|`` (the reference's own ``ω̇`` at both times) and
    :data:`~planners.reference.JUMP_TOLERANCE` (the scoring's: what it counts as an impulse) is a
    step. The
    central differences of the other checks stay inside ``[0.02 T, 0.98 T]``, and
    :func:`check_boundary` compares the values at 0 and T alone: a reference whose rate is
    pinned to ``ω0`` at the instant 0 and is something else from ``0⁺`` passes both.

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.

    Raises
    ------
    ConformanceError
        At an end without a declared breakpoint where ``ω`` steps.
    """
    T = reference.duration
    h = 1e-9 * max(T, 1.0)
    tolerance = JUMP_TOLERANCE  # what the requirement scoring counts as an impulse
    declared = declared_ends(reference)
    for (end, inside), skip, label, index in zip(((0.0, h), (T, T - h)), declared, ("0", "T"), ("0.0", "T")):
        if skip:
            continue
        sample = reference.sample(np.array([end, inside]))
        change = float(np.linalg.norm(sample.omega[1] - sample.omega[0]))
        explained = 2.0 * h * float(np.max(np.abs(sample.omega_dot)))
        if change > tolerance + explained:
            raise ConformanceError(
                f"{reference.planner}: ω steps at t = {label}: ω({end:g} s) = {np.round(sample.omega[0], 9).tolist()} "
                f"but ω({inside:.9g} s) = {np.round(sample.omega[1], 9).tolist()} (a change of {change:.3g} rad/s in "
                f"{h:.3g} s, beyond {tolerance:.2g} rad/s and the {explained:.3g} rad/s its ω̇ explains); a step is "
                f"an impulse I Δω no actuator gives. Remove it, or declare it: Reference(..., breakpoints=[{index}, ...]) "
                f"(the sample at 0 is then the right limit, the one at T the rate after the step)")


def check_times(reference: Reference, points: int = 41) -> tuple[Array, float]:
    """Interior times for finite differences, away from 0, T and the declared breakpoints.

    Parameters
    ----------
    reference : Reference
        The reference to sample.
    points : int, optional
        Number of candidate times (default 41): uniform on ``[0.02 T, 0.98 T]``, or picked among
        ``enforced_times`` inside ``(0.01 T, 0.99 T)`` when the reference declares them.

    Returns
    -------
    times : (M,) ndarray
        Times [s], at least five steps away from every declared breakpoint (``M <= points``).
    step : float
        The central-difference step [s]: ``1e-5 T``, or ``1e-7 T`` at enforced times.
    """
    T = reference.duration
    step = 1e-5 * T
    times = np.linspace(0.02, 0.98, points) * T
    if reference.enforced_times is not None:
        times = reference.enforced_times[(reference.enforced_times > 0.01 * T) & (reference.enforced_times < 0.99 * T)]
        times = times[np.linspace(0, times.size - 1, min(points, times.size)).astype(int)]
        step = 1e-7 * T  # the interpolant is a polynomial there: differences of the piece itself
    if reference.breakpoints.size:
        distance = np.min(np.abs(times[:, None] - reference.breakpoints[None, :]), axis=1)
        times = times[distance > 5 * step]
    return times, step


def _aligned(q: Array, like: Array) -> Array:
    """``q`` with each row's sign chosen to agree with ``like`` (the double cover)."""
    return q * np.where(np.sum(q * like, axis=1) < 0, -1.0, 1.0)[:, None]


def _where(times: Array, error: Array, scale: float) -> str:
    k = int(np.argmax(error))
    return f"worst at t = {times[k]:.6g} s: error {error[k]:.3g} against a scale of {scale:.3g}"


def _half_q_times_omega(q: Array, w: Array) -> Array:
    """``½ q ⊗ [0, ω]`` written out component by component (Hamilton product, scalar first), so
    that the check does not rely on the library's own quaternion code."""
    q0, q1, q2, q3 = (q[..., i] for i in range(4))
    w1, w2, w3 = (w[..., i] for i in range(3))
    return 0.5 * np.stack([-(q1 * w1 + q2 * w2 + q3 * w3),
                           q0 * w1 + q2 * w3 - q3 * w2,
                           q0 * w2 + q3 * w1 - q1 * w3,
                           q0 * w3 + q1 * w2 - q2 * w1], axis=-1)


def check_kinematics(reference: Reference) -> None:
    """``q̇ = ½ q ⊗ [0, ω]``, with ``q̇`` by central differences of the reference's own ``q``.

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.

    Raises
    ------
    ConformanceError
        If the reference's ``omega`` is not the rate of its ``q`` (a sign, a frame, inertial
        instead of body axes, a missing factor ½).
    """
    times, h = check_times(reference)
    sample = reference.sample(times)
    q_dot = (_aligned(reference.q(times + h), sample.q) - _aligned(reference.q(times - h), sample.q)) / (2 * h)
    expected = _half_q_times_omega(sample.q, sample.omega)
    error = np.linalg.norm(q_dot - expected, axis=1)
    scale = max(float(np.max(np.linalg.norm(expected, axis=1))), 1e-9)
    if np.max(error) > RELATIVE_TOLERANCE * scale + 1e-12:
        raise ConformanceError(
            f"{reference.planner}: the reference's omega is not the body rate of its q: q̇ (finite differences) "
            f"differs from ½ q ⊗ [0, ω], {_where(times, error, scale)}. ω must be the body rate in body axes, "
            f"q scalar first rotating body to inertial; if ω jumps at some times, declare them in "
            f"Reference(..., breakpoints=[...])")


def check_dynamics(reference: Reference) -> None:
    """``omega_dot`` is the derivative of ``omega`` and ``torque`` the inverse dynamics
    ``I ω̇ + ω × I ω`` (both by central differences of the reference's own ``ω``).

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.

    Raises
    ------
    ConformanceError
        If ``omega_dot`` has the wrong sign or scale, or the torque is not the rigid-body ``u``
        (a missing gyroscopic term, wheel momentum or environment torque left out).
    """
    times, h = check_times(reference)
    sample = reference.sample(times)
    omega_dot = (reference.omega(times + h) - reference.omega(times - h)) / (2 * h)
    inertia = reference.inertia
    # A floor for references at constant rate: the rate change over the manoeuvre's time.
    floor = float(np.max(np.linalg.norm(sample.omega, axis=1))) / reference.duration + 1e-15
    scale_rate = max(float(np.max(np.linalg.norm(omega_dot, axis=1))), floor)
    error = np.linalg.norm(sample.omega_dot - omega_dot, axis=1)
    if np.max(error) > RELATIVE_TOLERANCE * scale_rate:
        raise ConformanceError(
            f"{reference.planner}: omega_dot is not the time derivative of omega (finite differences), "
            f"{_where(times, error, scale_rate)}; check its sign and units (rad/s²)")
    expected = inverse_dynamics_torque(inertia, sample.omega, omega_dot)
    gyroscopic = np.cross(sample.omega, sample.omega @ inertia.T)
    scale = max(float(np.max(np.linalg.norm(omega_dot @ inertia.T, axis=1))),
                float(np.max(np.linalg.norm(gyroscopic, axis=1))), float(np.linalg.norm(inertia, 2)) * floor)
    error = np.linalg.norm(sample.torque - expected, axis=1)
    if np.max(error) > RELATIVE_TOLERANCE * scale:
        raise ConformanceError(
            f"{reference.planner}: the feed-forward torque is not the inverse dynamics I ω̇ + ω × I ω of the "
            f"reference (ω̇ by finite differences), {_where(times, error, scale)}. The torque is the rigid-body u "
            f"of I ω̇ = −ω × I ω + u (wheel momentum and environment torques included); use "
            f"planners.inverse_dynamics_torque(inertia, omega, omega_dot)")


def check_vectorised(reference: Reference) -> None:
    """Evaluating an array of times equals evaluating each time alone (inside and after T).

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.

    Raises
    ------
    ConformanceError
        If a row of the vectorised evaluation differs from the scalar one.
    """
    T = reference.duration
    times = np.concatenate([np.linspace(0.0, T, 9), T * np.array([1.05, 1.3])])
    together = reference.sample(times)
    for k, t in enumerate(times):
        alone = reference.sample(float(t))
        for name, a, b in zip(together._fields, together, alone):
            if np.shape(b) == np.shape(a[k]) and np.all(np.isfinite(a[k])) and not np.all(np.isfinite(b)):
                raise ConformanceError(
                    f"{reference.planner}: non-finite {name} at t = {t:g} s when sampled alone: "
                    f"{np.asarray(b).tolist()} (finite, {np.asarray(a[k]).round(9).tolist()}, among {times.size} "
                    f"times); _evaluate must give finite values for an array of one time too, each time "
                    f"independently of the others")
            if np.shape(b) != np.shape(a[k]) or not np.allclose(a[k], b, rtol=1e-9, atol=1e-12 * (1 + np.max(np.abs(a)))):
                raise ConformanceError(
                    f"{reference.planner}: sample(t) for an array of times differs from sample(t) at t = {t:g} s "
                    f"alone in {name}: {np.asarray(a[k]).round(9).tolist()} vs {np.asarray(b).round(9).tolist()}; "
                    f"_evaluate must treat each time of its array independently")


def check_after_end(reference: Reference, horizon: float | None = None) -> None:
    """After T: the torque-free motion of the final state (integrated here with LSODA), zero torque.

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.
    horizon : float or None, optional
        How long after T to check [s]; ``None`` (default): ``min(T, 100 s)``.

    Raises
    ------
    ConformanceError
        If ``q``, ``ω``, ``ω̇`` after T are not torque-free motion or the torque is not zero.
    """
    T = reference.duration
    horizon = min(T, 100.0) if horizon is None else horizon
    end = reference.sample(T)
    inertia, inverse = reference.inertia, np.linalg.inv(reference.inertia)

    def rhs(_t: float, y: Array) -> Array:
        w = y[4:]
        return np.concatenate([_half_q_times_omega(y[:4], w), -inverse @ np.cross(w, inertia @ w)])

    offsets = horizon * np.array([1e-3, 0.1, 0.37, 0.8, 1.0])
    # The contract: a final state at rest (a rate of at most REST_RATE, rounding residue of a
    # rest-to-rest profile) holds its attitude.
    omega_end = np.zeros(3) if np.linalg.norm(end.omega) <= REST_RATE else end.omega
    solution = solve_ivp(rhs, (0.0, horizon), np.concatenate([end.q, omega_end]), method="LSODA", t_eval=offsets,
                         rtol=1e-11, atol=1e-13)
    later = reference.sample(T + offsets)
    q_expected, w_expected = quat.normalize(solution.y[:4].T), solution.y[4:].T
    w_dot_expected = -np.cross(w_expected, w_expected @ inertia.T) @ inverse.T
    rate_scale = 1e-9 + float(np.max(np.linalg.norm(w_expected, axis=1)))
    problems = []
    angle = quat.error_angle(later.q, q_expected)
    if np.max(angle) > 1e-6:
        problems.append(f"q differs by {np.max(angle):.3g} rad")
    if np.max(np.linalg.norm(later.omega - w_expected, axis=1)) > 1e-7 * rate_scale:
        problems.append(f"ω = {later.omega[-1].round(6).tolist()} instead of {w_expected[-1].round(6).tolist()} rad/s")
    if np.max(np.linalg.norm(later.omega_dot - w_dot_expected, axis=1)) > 1e-6 * rate_scale**2 / 1 + 1e-12:
        problems.append("ω̇ is not −I⁻¹ (ω × I ω)")
    if np.max(np.abs(later.torque)) > 0:
        problems.append(f"the torque is {np.max(np.abs(later.torque)):.3g} N m, not zero")
    if problems:
        raise ConformanceError(
            f"{reference.planner}: after T = {T:g} s the reference must continue as the torque-free motion of its "
            f"final state (Reference.sample does this when _evaluate only covers [0, T]): " + "; ".join(problems))


def declares_closed_form(reference: Reference, planner: Planner | type[Planner] | None = None) -> bool | None:
    """Whether the planner of ``reference`` declares ``closed_form`` (:attr:`Planner.closed_form`),
    the declaration ``slewbench codegen`` trusts to export its references' symbolic evaluator.

    Parameters
    ----------
    reference : Reference
        The reference.
    planner : Planner, Planner subclass or None, optional
        The planner that made it; ``None`` (default): the planner registered in
        ``planners.PLANNERS`` under the reference's ``planner`` name.

    Returns
    -------
    bool or None
        The declaration; ``None`` when ``planner`` is not given and no planner is registered under
        that name (a plugin checked before it is registered).
    """
    if planner is None:
        planner = PLANNERS.get(reference.planner)
        if planner is None:
            return None
    return bool(planner.closed_form)


def closed_form_check_times(reference: Reference) -> Array:
    """Where :func:`check_closed_form` compares: the grid of :func:`finite_check_times` (uniform on
    ``[0, T]``, the breakpoints and enforced times, after T), and the neighbourhood of each
    breakpoint and of both ends, before 0 included.

    Parameters
    ----------
    reference : Reference
        The reference to sample.

    Returns
    -------
    (M,) ndarray
        Sorted times [s]: around each breakpoint ``b`` and at 0 and T, ``b + k`` for ``k`` in
        ``0, ±δ, ±1e-6 T, ±1e-3 T``, ``δ`` = :data:`~planners.reference.BREAKPOINT_INSTANT` ``× max(T, 1 s)``
        (the instant the scoring samples either side of a switch), and ``−0.05 T``.
    """
    T = reference.duration
    instant = BREAKPOINT_INSTANT * max(T, 1.0)
    offsets = np.array([0.0, instant, 1e-6 * T, 1e-3 * T])
    offsets = np.concatenate([-offsets[1:], offsets])
    centres = np.concatenate([reference.breakpoints, [0.0, T]])
    near = (centres[:, None] + offsets[None, :]).ravel()
    return np.unique(np.concatenate([finite_check_times(reference), near, [-0.05 * T]]))


def _numbers(values: Array) -> str:
    return "[" + ", ".join(f"{value:.15g}" for value in np.asarray(values, dtype=float).ravel()) + "]"


def check_closed_form(reference: Reference, planner: Planner | type[Planner] | None = None) -> None:
    """For a planner that declares ``closed_form``: its reference's symbolic evaluator (what
    ``slewbench codegen`` exports as C) gives what :meth:`Reference.sample` gives.

    ``reference.symbolic_evaluator()`` must be a CasADi function of one scalar time [s] to one
    column of :data:`~ocp.dynamics.layout.REFERENCE_FIELDS` (13) numbers
    ``[q, ω, ω̇, torque]``; at every time of :func:`closed_form_check_times` it must agree with
    ``sample`` at that time clamped to ``[0, T]`` (the evaluator's contract: before 0 and after T
    it holds the row at the end, as the exported table does; ``q`` with ``sample``'s sign), to
    :data:`CLOSED_FORM_TOLERANCE` of each field's scale. A planner that does not declare
    ``closed_form`` is not asked: codegen exports no evaluator of its references. When the
    declaration is unknown (``planner`` not given and none registered under the reference's name)
    an evaluator the reference offers is checked.

    Parameters
    ----------
    reference : Reference
        A reference with status ``"ok"``.
    planner : Planner, Planner subclass or None, optional
        The planner that made it (:func:`declares_closed_form`); ``None`` (default): the one
        registered under the reference's name.

    Raises
    ------
    ConformanceError
        If a declaring planner's reference offers no evaluator, or one of another signature, or if
        the evaluator fails or differs from ``sample``, naming the time, the field and both values.
    """
    declared = declares_closed_form(reference, planner)
    if declared is False:
        return
    name = reference.planner
    evaluator = reference.symbolic_evaluator()
    if evaluator is None:
        if declared:
            raise ConformanceError(
                f"{name}: the planner declares closed_form but its reference's symbolic_evaluator() returns None; "
                f"implement Reference.symbolic_evaluator (a casadi.Function of t to the 13-row [q, ω, ω̇, torque]), "
                f"or do not declare closed_form (slewbench codegen then exports the reference as a table only)")
        return
    wanted = f"one input of shape (1, 1) (t [s]) and one output of shape ({REFERENCE_FIELDS}, 1)"
    if not isinstance(evaluator, ca.Function):
        raise ConformanceError(f"{name}: symbolic_evaluator() returned a {type(evaluator).__name__}; it must be a "
                               f"casadi.Function with {wanted}")
    shapes = ([evaluator.size_in(k) for k in range(evaluator.n_in())],
              [evaluator.size_out(k) for k in range(evaluator.n_out())])
    if shapes != ([(1, 1)], [(REFERENCE_FIELDS, 1)]):
        raise ConformanceError(f"{name}: symbolic_evaluator() takes inputs of shapes {shapes[0]} and gives outputs of "
                               f"shapes {shapes[1]}; slewbench codegen exports a function with {wanted} "
                               f"(the row [q (4), ω (3), ω̇ (3), torque (3)])")
    T = reference.duration
    times = closed_form_check_times(reference)
    try:
        rows = np.asarray(evaluator.map(times.size)(ca.DM(times).T)).T
    except RuntimeError as failure:
        raise ConformanceError(f"{name}: evaluating symbolic_evaluator() at {times.size} times on [{times[0]:g}, "
                               f"{times[-1]:g}] s failed: {failure}") from failure
    expected = reference.sample(np.clip(times, 0.0, T))
    start = 0
    for field, values in zip(("q", "ω", "ω̇", "torque"), expected):
        width = values.shape[1]
        symbolic = rows[:, start:start + width]
        start += width
        scale = max(float(np.max(np.abs(values))), np.finfo(float).tiny)
        tolerance = CLOSED_FORM_TOLERANCE * scale
        error = np.max(np.abs(symbolic - values), axis=1)
        bad = ~(error <= tolerance)  # NaN is bad
        if np.any(bad):
            k = int(np.argmax(np.where(bad, np.nan_to_num(error, nan=np.inf), -1.0)))
            t = times[k]
            where = "before 0, clamped to 0" if t < 0 else "after T, clamped to T" if t > T else f"{t / T:.6g} T"
            raise ConformanceError(
                f"{name}: the symbolic evaluator (exported as C by slewbench codegen, the planner declaring closed_form) "
                f"differs from sample() at t = {float(t)!r} s ({where}) in {field}: symbolic_evaluator gives "
                f"{_numbers(symbolic[k])} but sample gives {_numbers(values[k])} (error {error[k]:.3g} > "
                f"{tolerance:.3g}, {CLOSED_FORM_TOLERANCE:g} of the field's scale {scale:.3g}; {int(np.sum(bad))} of "
                f"{times.size} times); the symbolic evaluator must compute what _evaluate computes, with t clamped to "
                f"[0, T]")


def determinism_problem(planner: Planner) -> tuple[str, ManeuverProblem] | None:
    """The problem :func:`check_deterministic` plans: the first of :data:`DETERMINISM_PROBLEMS` (the
    cheapest standard problem) that ``planner`` accepts (``problem_error`` is ``None``).

    Parameters
    ----------
    planner : Planner
        The planner, its options given.

    Returns
    -------
    (str, ManeuverProblem) or None
        The standard problem's name and the problem; ``None`` when it accepts none.
    """
    problems = standard_problems()
    for name in DETERMINISM_PROBLEMS:
        if planner.problem_error(problems[name]) is None:
            return name, problems[name]
    return None


def _exact_numbers(values: Array) -> str:
    """Numbers as Python writes them back exactly (two that differ in the last bit read differently)."""
    return "[" + ", ".join(repr(float(value)) for value in np.asarray(values, dtype=float).ravel()) + "]"


def _fresh(planner: Planner | type[Planner]) -> Planner:
    """A new instance of ``planner``'s class with its options and solver cache (a class: the
    default options, the model's own cache)."""
    if isinstance(planner, type):
        return planner(None)
    return type(planner)(planner.options, cache=planner.cache)


def check_deterministic(planner: Planner | type[Planner], problem: ManeuverProblem | None = None,
                        reference: Reference | None = None) -> None:
    """For a planner that declares ``deterministic`` (:attr:`Planner.deterministic`, the default):
    two plans of one problem give the same reference, bit for bit.

    A trade study's worker reuses a reference for a case whose planner, options and problem are an
    earlier case's (:func:`scenarios.runner.planning_key`) on this declaration alone. The check plans
    one problem twice, each time with a fresh instance of the planner's class with its options,
    building into the planner's solver cache (its own, else the problem model's): the first plan
    builds what it needs and the second finds it built, as a worker's later case does. By default
    the problem is the cheapest standard problem the planner accepts (:func:`determinism_problem`);
    a reference the planner already made for ``problem`` may stand for the first plan (what
    :data:`CHECKS` does, so that only one more plan is made, into a cache already built). Both
    references' duration, breakpoints, declared free boundary conditions and ``sample`` at the times
    of :func:`finite_check_times` on ``[0, T]`` (after T the reference coasts from its state at T)
    must be identical, every bit. A planner that declares ``deterministic = False`` is not asked
    (its references are never reused), nor one whose plan fails (a failed reference is never
    reused).

    Parameters
    ----------
    planner : Planner or Planner subclass
        The planner (its options and cache used) or its class (the default options).
    problem : ManeuverProblem or None, optional
        The problem to plan; ``None`` (default): :func:`determinism_problem`.
    reference : Reference or None, optional
        The first plan: ``planner``'s reference for ``problem`` (with ``problem`` only); ``None``
        (default): planned here.

    Raises
    ------
    ConformanceError
        If the two references differ, naming the first difference and telling to declare
        ``deterministic = False``.
    ValueError
        A ``reference`` without its ``problem``.
    """
    if not planner.deterministic:
        return
    if problem is None:
        if reference is not None:
            raise ValueError("check_deterministic: a reference needs the problem it was planned for")
        chosen = determinism_problem(_fresh(planner))
        if chosen is None:
            return
        where, problem = chosen
        where = f"the standard problem {where!r}"
    else:
        where = f"a problem of T = {problem.duration:g} s"
    first = reference if reference is not None else _fresh(planner).plan(problem)
    if not first.ok:
        return
    second = _fresh(planner).plan(problem)
    if not second.ok:
        return
    name = planner.name
    fix = ("a planner whose plans of one problem may differ (an unseeded random start, a result that depends on "
           "the clock or on what its solver cache held) must declare deterministic = False (a class attribute), so "
           "that a trade study plans every case instead of reusing an earlier case's reference")
    for label, a, b in (("duration", np.float64(first.duration), np.float64(second.duration)),
                        ("breakpoints", first.breakpoints, second.breakpoints)):
        if np.shape(a) != np.shape(b) or np.asarray(a).tobytes() != np.asarray(b).tobytes():
            raise ConformanceError(f"{name}: planned twice on {where} by fresh instances, its references' {label} "
                                   f"differ: {np.asarray(a).tolist()!r} then {np.asarray(b).tolist()!r}; {fix}")
    if first.free_boundary != second.free_boundary:
        raise ConformanceError(f"{name}: planned twice on {where} by fresh instances, its references declare "
                               f"free {sorted(first.free_boundary)} then {sorted(second.free_boundary)}; {fix}")
    times = finite_check_times(first)
    times = times[times <= first.duration]  # after T: the torque-free coast of the state at T, compared there
    for field, a, b in zip(("q", "ω", "ω̇", "torque"), first.sample(times), second.sample(times)):
        a, b = (np.ascontiguousarray(values, dtype=np.float64) for values in (a, b))
        same = np.all(a.view(np.int64) == b.view(np.int64), axis=1)  # bit for bit: -0.0 is not 0.0, NaN is NaN
        if not np.all(same):
            k = int(np.argmin(same))
            raise ConformanceError(
                f"{name}: planned twice on {where} by fresh instances, its references differ in {field} at "
                f"t = {float(times[k])!r} s: {_exact_numbers(a[k])} then {_exact_numbers(b[k])} "
                f"({int(np.sum(~same))} of {times.size} times differ); {fix}")


class Check(Protocol):
    """A check of :data:`CHECKS`: ``check(problem, reference, planner=None)`` raises
    :class:`ConformanceError`; ``planner`` is the planner that made the reference (``None``: the one
    registered under its name), which only the checks of a planner's declarations read."""

    def __call__(self, problem: ManeuverProblem, reference: Reference,
                 planner: Planner | type[Planner] | None = None) -> None:
        """Raise :class:`ConformanceError` if ``reference`` breaks the check."""
        ...


def _reference_only(check: Callable[[Reference], None]) -> Check:
    """A check of the reference alone, in the signature of :data:`CHECKS`."""
    def run(problem: ManeuverProblem, reference: Reference, planner: Planner | type[Planner] | None = None) -> None:
        check(reference)
    return run


def _boundary(problem: ManeuverProblem, reference: Reference, planner: Planner | type[Planner] | None = None) -> None:
    check_boundary(problem, reference)


def _closed_form(problem: ManeuverProblem, reference: Reference,
                 planner: Planner | type[Planner] | None = None) -> None:
    check_closed_form(reference, planner)


_DETERMINISTIC: set[tuple[object, ...]] = set()
"""The planners (class, its plan methods, options) found deterministic in this process."""


def _deterministic(problem: ManeuverProblem, reference: Reference,
                   planner: Planner | type[Planner] | None = None) -> None:
    """:func:`check_deterministic` of the planner that made ``reference``, once per planner class
    and options in a process (determinism is the planner's, not one reference's). Given the planner
    (an instance: its options), ``reference`` is the first plan of ``problem`` and one more is
    made; else the class registered under the reference's name (none: nothing to check) is
    checked with its default options on its own problem (the reference's options are unknown)."""
    if planner is None:
        planner = PLANNERS.get(reference.planner)
        if planner is None:
            return
    kind = planner if isinstance(planner, type) else type(planner)
    options = None if isinstance(planner, type) else planner.options
    key = (kind, kind.plan, getattr(kind, "_plan", None), repr(options))
    if key in _DETERMINISTIC:
        return
    if isinstance(planner, type):
        check_deterministic(planner)
    else:
        check_deterministic(planner, problem, reference)
    _DETERMINISTIC.add(key)


def check_least_duration(problem: ManeuverProblem, reference: Reference,
                         planner: Planner | type[Planner] | None = None) -> None:
    """The planner's :meth:`~planners.base.Planner.least_duration` is a lower bound of what it plans:
    ``slewbench validate`` calls a row ``infeasible`` from it, before planning, so a least duration
    above the reference's would doom a row the run makes ``ok``.

    Parameters
    ----------
    problem : ManeuverProblem
        The planned problem.
    reference : Reference
        The planner's reference for it.
    planner : Planner, Planner subclass or None, optional
        The planner that made it (an instance: its options); a class, or ``None`` (the class
        registered under the reference's name, if any), with its default options.

    Raises
    ------
    ConformanceError
        The least duration exceeds the reference's duration (by more than 1e-9 of it: rounding).
    """
    if planner is None:
        planner = PLANNERS.get(reference.planner)
        if planner is None:
            return
    least = _fresh(planner).least_duration(problem) if isinstance(planner, type) else planner.least_duration(problem)
    if least is not None and least > reference.duration * (1.0 + 1e-9):  # rounding, no more
        raise ConformanceError(f"{reference.planner}: least_duration says {least:.9g} s, above the "
                               f"{reference.duration:.9g} s it plans: validate would call a plannable row "
                               "infeasible (least_duration must be a lower bound, or None)")


CHECKS: dict[str, Check] = {
    "finite": _reference_only(check_finite),
    "boundary": _boundary,
    "ends": _reference_only(check_ends),
    "kinematics": _reference_only(check_kinematics),
    "dynamics": _reference_only(check_dynamics),
    "vectorised": _reference_only(check_vectorised),
    "after_end": _reference_only(check_after_end),
    "closed_form": _closed_form,
    "deterministic": _deterministic,
    "least_duration": check_least_duration,
}
"""Every check, by name, in the order :func:`check_reference` runs them (``finite`` first: a NaN
would read as another defect in the others): ``check(problem, reference, planner=None)`` raises
:class:`ConformanceError` (:class:`Check`). ``deterministic`` plans the problem once more (given
the planner; else the registered class's own problem, :func:`check_deterministic`), once per planner
class and options in a process."""


def check_reference(problem: ManeuverProblem, reference: Reference,
                    planner: Planner | type[Planner] | None = None) -> None:
    """Run every check of :data:`CHECKS` on a reference planned for ``problem``.

    Parameters
    ----------
    problem : ManeuverProblem
        The planned problem.
    reference : Reference
        The planner's reference for it (a status other than ``"ok"`` fails at once).
    planner : Planner, Planner subclass or None, optional
        The planner that made it, whose declarations (``closed_form``, ``deterministic``) the checks
        verify; ``None`` (default): the planner registered under the reference's name, if any, with
        its default options (pass it for a planner not registered yet, or to check its options).

    Raises
    ------
    ConformanceError
        At the first failed check, with what to fix.
    """
    if not reference.ok:
        raise ConformanceError(f"{reference.planner}: status {reference.status!r}: {reference.message}")
    for check in CHECKS.values():
        check(problem, reference, planner)
