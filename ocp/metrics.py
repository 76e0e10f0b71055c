"""The common score of a motion: one function, :func:`compute_metrics`, used for references
sampled on a grid and for closed-loop simulations alike. Keys are part of the contract
(ARCHITECTURE.md, "Metrics").
"""
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat

METRIC_KEYS: tuple[str, ...] = (
    "int_u2", "int_u", "int_abs_u", "peak_u", "final_error_deg", "final_rate_error",
    "rms_error_deg", "max_error_deg", "settling_time_s", "saturation_fraction",
    "peak_wheel_momentum", "plan_time_s", "duration_s",
    "detumble_time_s", "int_dipole", "final_rate", "energy_ratio",
    "fine_settling_time_s", "initial_rate_error",
)
DEFAULT_SETTLING_TOLERANCE_DEG = 0.5
DEFAULT_DETUMBLE_TOLERANCE = 0.01
"""rad/s, bound on every body-rate component for ``detumble_time_s``."""


def detumble_time(t: NDArray, omega: NDArray, tolerance: float = DEFAULT_DETUMBLE_TOLERANCE) -> float | None:
    """First sample time after which ``max_i |ω_i| < tolerance`` holds to the end of the window.

    Parameters
    ----------
    t : (N+1,) s; omega : (N+1, 3) rad/s, body rate; tolerance : rad/s.

    Returns
    -------
    float or None
        s; 0 if the bound holds throughout, ``None`` if it does not hold at the final sample.
    """
    above = np.nonzero(np.max(np.abs(omega), axis=1) >= tolerance)[0]
    if above.size == 0:
        return 0.0
    if above[-1] == t.size - 1:
        return None
    return float(t[above[-1] + 1])


def _integrate(t: NDArray, values: NDArray) -> NDArray:
    """∫ values dt: a zero-order hold when there is one value per interval, else trapezoids."""
    dt = np.diff(t)
    if values.shape[0] == t.shape[0] - 1:
        return np.tensordot(dt, values, axes=(0, 0))
    return np.tensordot(dt, 0.5 * (values[1:] + values[:-1]), axes=(0, 0))


def settling_time(t: NDArray, error_deg: NDArray | None, tolerance_deg: float) -> float | None:
    """First time (s) after which ``error_deg`` stays at or below ``tolerance_deg`` to the end;
    ``None`` for a free attitude (``error_deg`` None) or when not settled by the last sample."""
    if error_deg is None:
        return None
    above = np.nonzero(error_deg > tolerance_deg)[0]
    if above.size == 0:
        return 0.0
    if above[-1] == t.size - 1:
        return None
    return float(t[above[-1] + 1])


def compute_metrics(
    t: ArrayLike,
    q: ArrayLike,
    omega: ArrayLike,
    torque: ArrayLike,
    target_q: ArrayLike | None,
    target_omega: ArrayLike | None = None,
    reference_q: ArrayLike | None = None,
    wheel_momentum: ArrayLike | None = None,
    saturated: ArrayLike | None = None,
    plan_time_s: float | None = None,
    duration_s: float | None = None,
    settling_tolerance_deg: float = DEFAULT_SETTLING_TOLERANCE_DEG,
    initial_omega: ArrayLike | None = None,
    fine_settling_tolerance_deg: float | None = None,
    dipole: ArrayLike | None = None,
    inertia: ArrayLike | None = None,
    detumble_tolerance: float = DEFAULT_DETUMBLE_TOLERANCE,
) -> dict[str, Any]:
    """Metrics of a motion sampled at times ``t`` (s).

    Parameters
    ----------
    q, omega : (N+1, 4), (N+1, 3) attitude and body rate (rad/s) at ``t``.
    torque : (N, 3) body torque held over each interval (zero-order hold, closed loop), or
        (N+1, 3) torque samples at ``t`` (a reference; integrated with trapezoids). N m.
    target_q, target_omega : the manoeuvre's final attitude and rate (``None``: free).
    reference_q : (N+1, 4) reference attitude at ``t`` for the tracking errors (closed loop).
    wheel_momentum : (N+1, n_w) N m s; saturated : (N,) bool per sample.
    initial_omega : (3,) rad/s, the manoeuvre's initial body rate ω0: gives ``initial_rate_error``
        ``‖ω(t_0) − ω0‖`` (a reference that leaves ω(0) free starts away from it).
    settling_tolerance_deg, fine_settling_tolerance_deg : error angles (deg) of ``settling_time_s``
        and of ``fine_settling_time_s`` (``None``: that metric is null).
    dipole : (N, 3) A m², magnetorquer dipole held over each interval (``None``: no magnetorquers).
    inertia : (3, 3) kg m², body inertia for ``energy_ratio`` (``None``: not computed).
    detumble_tolerance : rad/s, bound on ``max_i |ω_i|`` for ``detumble_time_s``.

    Returns
    -------
    dict with every key of :data:`METRIC_KEYS`; metrics that do not apply are ``None``.
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    torque = np.asarray(torque, dtype=float)
    norms = np.linalg.norm(torque, axis=1)
    error_to_target = None if target_q is None else np.rad2deg(quat.error_angle(q, target_q))
    settling = settling_time(t, error_to_target, settling_tolerance_deg)
    metrics: dict[str, Any] = {
        "int_u2": float(_integrate(t, norms**2)),
        "int_u": float(_integrate(t, norms)),
        "int_abs_u": [float(v) for v in _integrate(t, np.abs(torque))],
        "peak_u": float(np.max(np.abs(torque))) if torque.size else 0.0,
        "final_error_deg": None if error_to_target is None else float(error_to_target[-1]),
        "final_rate_error": None if target_omega is None
        else float(np.linalg.norm(np.asarray(omega)[-1] - np.asarray(target_omega, dtype=float))),
        "rms_error_deg": None,
        "max_error_deg": None,
        "settling_time_s": settling,
        "saturation_fraction": None if saturated is None else float(np.mean(np.asarray(saturated))),
        "peak_wheel_momentum": None,
        "plan_time_s": plan_time_s,
        "duration_s": duration_s,
        "initial_rate_error": None if initial_omega is None
        else float(np.linalg.norm(np.asarray(omega)[0] - np.asarray(initial_omega, dtype=float))),
        "fine_settling_time_s": None if fine_settling_tolerance_deg is None
        else settling_time(t, error_to_target, fine_settling_tolerance_deg),
        "detumble_time_s": detumble_time(t, np.asarray(omega, dtype=float), detumble_tolerance),
        "int_dipole": None if dipole is None
        else float(_integrate(t, np.linalg.norm(np.asarray(dipole, dtype=float), axis=1))),
        "final_rate": float(np.linalg.norm(np.asarray(omega, dtype=float)[-1])),
        "energy_ratio": None,
    }
    if inertia is not None:
        omega_ends = np.asarray(omega, dtype=float)[[0, -1]]
        energy = 0.5 * np.einsum("ni,ij,nj->n", omega_ends, np.asarray(inertia, dtype=float), omega_ends)
        metrics["energy_ratio"] = float(energy[1] / energy[0]) if energy[0] > 0 else None
    if reference_q is not None:
        tracking = np.rad2deg(quat.error_angle(q, reference_q))
        metrics["rms_error_deg"] = float(np.sqrt(np.mean(tracking**2)))
        metrics["max_error_deg"] = float(np.max(tracking))
    if wheel_momentum is not None and np.size(wheel_momentum):
        metrics["peak_wheel_momentum"] = float(np.max(np.abs(wheel_momentum)))
    return metrics


def metrics_from_simulation(
    result: Any,
    target_q: ArrayLike | None,
    target_omega: ArrayLike | None = None,
    reference: Any = None,
    plan_time_s: float | None = None,
    duration_s: float | None = None,
    settling_tolerance_deg: float = DEFAULT_SETTLING_TOLERANCE_DEG,
    fine_settling_tolerance_deg: float | None = None,
    detumble_tolerance: float = DEFAULT_DETUMBLE_TOLERANCE,
) -> dict[str, Any]:
    """Closed-loop metrics of an :class:`~ocp.simulator.SimulationResult`; ``reference`` (anything
    with a vectorised ``q(t)``) gives the tracking errors."""
    slices = result.model.control_slices
    dipole = result.applied_u[:, slices["dipole"]] if "dipole" in slices else None
    return compute_metrics(
        result.t, result.q, result.omega, result.applied_torque, target_q, target_omega,
        reference_q=None if reference is None else reference.q(result.t),
        wheel_momentum=result.wheel_momentum if result.wheel_momentum.shape[1] else None,
        saturated=result.saturated, plan_time_s=plan_time_s, duration_s=duration_s,
        settling_tolerance_deg=settling_tolerance_deg,
        fine_settling_tolerance_deg=fine_settling_tolerance_deg, dipole=dipole,
        inertia=result.model.spacecraft.inertia, detumble_tolerance=detumble_tolerance,
    )


def metrics_from_reference(
    reference: Any,
    target_q: ArrayLike | None,
    target_omega: ArrayLike | None = None,
    points: int = 2001,
    settling_tolerance_deg: float = DEFAULT_SETTLING_TOLERANCE_DEG,
    initial_omega: ArrayLike | None = None,
    fine_settling_tolerance_deg: float | None = None,
    inertia: ArrayLike | None = None,
    detumble_tolerance: float = DEFAULT_DETUMBLE_TOLERANCE,
) -> dict[str, Any]:
    """Metrics of a reference's own motion and feed-forward torque over ``[0, duration]``,
    sampled on ``points`` uniform times (trapezoidal integrals).

    Parameters
    ----------
    reference : a planner's reference (vectorised ``q``, ``omega``, ``torque``, ``duration``).
    target_q, target_omega : the manoeuvre's final attitude and rate (``None``: free).
    points : number of uniform sample times.
    settling_tolerance_deg : deg, the settling band about ``target_q``.
    initial_omega : (3,) rad/s, the manoeuvre's ω0, for ``initial_rate_error``.

    Returns
    -------
    dict with every key of :data:`METRIC_KEYS`.
    """
    t = np.linspace(0.0, reference.duration, points)
    return compute_metrics(
        t, reference.q(t), reference.omega(t), reference.torque(t), target_q, target_omega,
        plan_time_s=reference.plan_time_s, duration_s=reference.duration,
        settling_tolerance_deg=settling_tolerance_deg, initial_omega=initial_omega,
        fine_settling_tolerance_deg=fine_settling_tolerance_deg, inertia=inertia, detumble_tolerance=detumble_tolerance,
    )


def metric_violations(metrics: dict[str, Any] | None) -> list[str]:
    """The metrics whose values physics forbids: every metric is a norm, an integral of a norm,
    an angle, a time or a fraction, so a value must be finite and non-negative (fractions at most
    1, a manoeuvre's duration positive). A row with a violation is not "ok".

    Parameters
    ----------
    metrics : a mapping of metric keys to values (``None`` for metrics that do not apply).

    Returns
    -------
    list of str
        ``"key = value"`` for each offending metric; empty when all are physical.
    """
    problems = []
    for key, value in (metrics or {}).items():
        values = value if isinstance(value, (list, tuple)) else [value]
        for item in values:
            if item is None:
                continue
            number = float(item)
            bad = (not np.isfinite(number) or number < 0.0
                   or (key.endswith("fraction") and number > 1.0) or (key == "duration_s" and number == 0.0))
            if bad:
                problems.append(f"{key} = {value}")
                break
    return problems
