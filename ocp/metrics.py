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
    "peak_wheel_momentum", "plan_time_s", "duration_s", "initial_rate_error",
)
DEFAULT_SETTLING_TOLERANCE_DEG = 0.5


def _integrate(t: NDArray, values: NDArray) -> NDArray:
    """∫ values dt: a zero-order hold when there is one value per interval, else trapezoids."""
    dt = np.diff(t)
    if values.shape[0] == t.shape[0] - 1:
        return np.tensordot(dt, values, axes=(0, 0))
    return np.tensordot(dt, 0.5 * (values[1:] + values[:-1]), axes=(0, 0))


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

    Returns
    -------
    dict with every key of :data:`METRIC_KEYS`; metrics that do not apply are ``None``.
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    torque = np.asarray(torque, dtype=float)
    norms = np.linalg.norm(torque, axis=1)
    error_to_target = None if target_q is None else np.rad2deg(quat.error_angle(q, target_q))
    above = None if target_q is None else np.nonzero(error_to_target > settling_tolerance_deg)[0]
    if above is None:
        settling = None  # free final attitude
    elif above.size == 0:
        settling = 0.0
    elif above[-1] == t.size - 1:
        settling = None  # not settled by the end of the window
    else:
        settling = float(t[above[-1] + 1])
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
    }
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
) -> dict[str, Any]:
    """Closed-loop metrics of an :class:`~ocp.simulator.SimulationResult`; ``reference`` (anything
    with a vectorised ``q(t)``) gives the tracking errors."""
    return compute_metrics(
        result.t, result.q, result.omega, result.applied_torque, target_q, target_omega,
        reference_q=None if reference is None else reference.q(result.t),
        wheel_momentum=result.wheel_momentum if result.wheel_momentum.shape[1] else None,
        saturated=result.saturated, plan_time_s=plan_time_s, duration_s=duration_s,
        settling_tolerance_deg=settling_tolerance_deg,
    )


def metrics_from_reference(
    reference: Any,
    target_q: ArrayLike | None,
    target_omega: ArrayLike | None = None,
    points: int = 2001,
    settling_tolerance_deg: float = DEFAULT_SETTLING_TOLERANCE_DEG,
    initial_omega: ArrayLike | None = None,
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
