"""The common score of a motion: one function, :func:`compute_metrics`, used for references
sampled on a grid and for closed-loop simulations alike. Keys are part of the contract; each is
defined, with its unit, in :data:`METRIC_INFO` (the documentation's metrics page is that table).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat

METRIC_KEYS: tuple[str, ...] = (
    "int_u2", "int_u", "int_abs_u", "int_actuator_torque", "peak_body_torque", "peak_actuator_torque",
    "peak_wheel_torque",
    "final_error_deg", "final_rate_error",
    "rms_error_deg", "max_error_deg", "settling_time_s", "saturation_fraction",
    "peak_wheel_momentum", "plan_time_s", "duration_s",
    "detumble_time_s", "int_dipole", "final_rate", "energy_ratio",
    "fine_settling_time_s", "initial_rate_error",
    "final_knowledge_error_deg", "max_knowledge_error_deg",
    "star_tracker_blinded_s", "star_tracker_blinded_updates",
)
"""Every key :func:`compute_metrics` returns; definitions and units in :data:`METRIC_INFO`."""


class MetricInfo(NamedTuple):
    """Unit and definition of one metric key.

    Attributes
    ----------
    unit : str
        SI unit of the value (``–`` for a ratio).
    meaning : str
        Its definition as :func:`compute_metrics` computes it (reStructuredText inline markup).
    null_worst_when : str or None
        For a metric whose null can mean +inf, the worst outcome: a time never reached (the motion
        is still outside the band at the last sample) or an effort without a finite value (a
        reference's impulse, written null in the files): the key of the metric whose value shows
        that this one applies to the motion (``final_error_deg`` for ``settling_time_s``: a final
        attitude is set; ``int_u`` for ``int_u2`` and ``peak_body_torque``: a torque was
        integrated). When that key has a value and this one is null, the trade-study tables count
        it as never reached, +inf (:mod:`scenarios.study.report`). None (the default): a null only
        means that the metric does not apply.
    """

    unit: str
    meaning: str
    null_worst_when: str | None = None


METRIC_INFO: dict[str, MetricInfo] = {
    "int_u2": MetricInfo(
        "N² m² s", "∫ ‖u‖₂² dt over the window: the control effort, u the control torque on the rigid body "
        "(as ``peak_body_torque``: a reference's feed-forward torque; in closed loop the applied actuator "
        "torque less the wheels' gyroscopic torque, so that a tracked reference's closed loop approaches the "
        "reference's value); +inf for a reference whose body rate "
        "jumps (an impulse, whose square has no finite integral: shown as missing in the tables).",
        null_worst_when="int_u"),
    "int_u": MetricInfo(
        "N m s", "∫ ‖u‖₂ dt, the integrated torque (Euclidean norm, not the sum of the axes); a reference's "
        "rate jumps Δω add their angular impulses ‖I Δω‖ (the torque of a jump is I Δω δ(t − t_j))."),
    "int_abs_u": MetricInfo(
        "N m s", "[∫ |u_x| dt, ∫ |u_y| dt, ∫ |u_z| dt], one integral per body axis (a list of three; "
        "the CSV tables split it into ``_x``, ``_y``, ``_z`` columns); a reference's rate jumps add "
        "|(I Δω)_i| (as ``int_u``)."),
    "int_actuator_torque": MetricInfo(
        "N m s", "Closed loop: ∫ ‖τ_act‖₂ dt, τ_act the actuators' applied torque on the body (wheels "
        "−A g, magnetorquers m × B, torquers; as ``peak_actuator_torque``), zero-order hold: what the "
        "actuators did. Without wheels it equals ``int_u``; with wheels τ_act = u + ω × A h_w differs from ``int_u``'s "
        "u by the wheels' gyroscopic torque (with the total momentum zero, −ω × A h_w = ω × I ω: the "
        "body's own gyroscopic torque, which a reference's feed-forward and ``int_u`` contain and the "
        "wheels' motor torques do not supply); null for a reference."),
    "peak_body_torque": MetricInfo(
        "N m", "max over the samples and the body axes of |u_i|, u the control torque on the rigid body of "
        "I ω̇ = −ω × I ω + u: a reference's feed-forward torque (I ω̇ + ω × I ω); in closed loop the applied "
        "actuator torque less the wheels' gyroscopic torque, τ_act − ω × A h_w at each sample (the u the "
        "allocation realised, so that reference and closed loop compare); 0 without any torque sample; +inf "
        "for a reference whose body rate jumps (an impulse; shown as missing in the tables).",
        null_worst_when="int_u"),
    "peak_actuator_torque": MetricInfo(
        "N m", "Closed loop: max over the samples and the body axes of |τ_act,i|, τ_act the actuators' "
        "applied torque on the body (wheels −A g, magnetorquers m × B, torquers); null for a reference "
        "(its demand on the actuators is scored by the requirement ``actuators``)."),
    "peak_wheel_torque": MetricInfo(
        "N m", "Closed loop: max over the samples and the wheels of the applied motor torque |g_i| (compare "
        "with ``spacecraft.wheels.max_torque``); null without wheels and for a reference."),
    "final_error_deg": MetricInfo(
        "deg", "Error angle 2 acos|q_e0| (``q_e = q_f* ⊗ q``) between the attitude at the last sample and "
        "the target ``q_f``; in closed loop, where the manoeuvre ends turning (``ω_f ≠ 0``, or free "
        "and the reference's ``ω(T)`` not zero), the "
        "target after T is the reference's own motion from ``(q_f, ω_f)`` (``ocp.metrics.target_motion``); "
        "null when the final attitude is free."),
    "final_rate_error": MetricInfo(
        "rad/s", "‖ω(t_N) − ω_f‖ at the last sample (``ω_f`` the target's rate there, as for "
        "``final_error_deg``, in the body's axes); null when the final rate is free."),
    "rms_error_deg": MetricInfo(
        "deg", "Closed loop with a reference: √(mean over the samples of e_k²), e_k the error angle between "
        "the attitude and the reference attitude at t_k; null for a reference and in regulation."),
    "max_error_deg": MetricInfo(
        "deg", "Closed loop with a reference: max over the samples of e_k (as for ``rms_error_deg``); null for a "
        "reference and in regulation."),
    "settling_time_s": MetricInfo(
        "s", "t_(j+1) for the last sample j whose error angle to ``q_f`` (the target, as for "
        "``final_error_deg``) exceeds the band "
        "(``simulation.settling_tolerance_deg``; unset, ``requirements.final.error_deg`` when stated, else "
        "0.5°); 0 if no sample does; null if the last "
        "sample does, or when the final attitude is free.", null_worst_when="final_error_deg"),
    "saturation_fraction": MetricInfo(
        "–", "Closed loop: fraction of the held intervals in which any actuator was at its limit (a wheel "
        "torque clipped by its torque or momentum limit or at its torque limit, a dipole or torquer axis "
        "at or beyond its limit); null for a reference."),
    "peak_wheel_momentum": MetricInfo(
        "N m s", "Closed loop: max over the samples and the wheels of |h_w|; null without wheels and for a "
        "reference."),
    "plan_time_s": MetricInfo(
        "s", "Wall time of the planner's ``plan``; null in regulation (no planner)."),
    "duration_s": MetricInfo(
        "s", "The reference's manoeuvre time T (chosen by the planner when the time is free), in closed loop "
        "too: ``cl.duration_s`` is the T the closed loop tracked, not the simulated horizon (the run's last "
        "sample: ``simulation.duration``, else the longer of ``maneuver.duration`` and T; the row's message says "
        "when the run stops before T); null in regulation."),
    "detumble_time_s": MetricInfo(
        "s", "t_(j+1) for the last sample j where max_i |ω_i| ≥ ``simulation.detumble_tolerance`` "
        "(default 0.01 rad/s), i.e. the first sample time after which the rate stays below it to the end; "
        "0 if it holds throughout; null if it does not hold at the last sample."),
    "int_dipole": MetricInfo(
        "A m² s", "∫ ‖m‖ dt of the applied (saturated) magnetorquer dipole, zero-order hold; null without "
        "magnetorquers and for a reference."),
    "final_rate": MetricInfo(
        "rad/s", "‖ω(t_N)‖, the body rate at the last sample."),
    "energy_ratio": MetricInfo(
        "–", "½ ω(t_N)ᵀ I ω(t_N) / ½ ω(t_0)ᵀ I ω(t_0), the body's rotational kinetic energy at the end over "
        "that at the start (wheels excluded); null when the motion starts at rest (an initial energy at most "
        "1e-12 of the largest along the motion: a rest-to-rest reference's rounding residue, 1e-17 rad/s, is "
        "rest)."),
    "fine_settling_time_s": MetricInfo(
        "s", "As ``settling_time_s`` with the band ``simulation.fine_settling_tolerance_deg``; null when it "
        "is not set."),
    "initial_rate_error": MetricInfo(
        "rad/s", "Reference: ‖ω(t_0) − ω_0‖, the initial rate a planner that declares ``omega0`` free leaves "
        "to the closed loop; null in closed loop."),
    "final_knowledge_error_deg": MetricInfo(
        "deg", "Closed loop with a star tracker (``simulation.sensors``): the angle between the attitude given "
        "to the controller (the estimator's, else the tracker's last reading) and the true attitude at the "
        "last sample t_(N−1); null otherwise."),
    "max_knowledge_error_deg": MetricInfo(
        "deg", "As ``final_knowledge_error_deg``, its maximum over the samples t_0 … t_(N−1); null without a "
        "star tracker."),
    "star_tracker_blinded_s": MetricInfo(
        "s", "Closed loop with a star tracker that has exclusions (``simulation.sensors.star_tracker."
        "exclusion_deg``): the time its boresight spent inside an exclusion cone, Σ (t_(k+1) − t_k) over the "
        "samples t_k where the true attitude put it there; null otherwise."),
    "star_tracker_blinded_updates": MetricInfo(
        "count", "As ``star_tracker_blinded_s``: the updates due by the tracker's rate and outages that an "
        "exclusion dropped (the estimator only propagated); null without exclusions."),
}
"""Unit and definition of every key of :data:`METRIC_KEYS`, in the same order. ``u`` in the integrals
``int_u2``, ``int_u`` and ``int_abs_u`` is the torque given to :func:`compute_metrics` (body axes),
the control torque on the rigid body in both scopes, as for ``peak_body_torque``: a reference's
feed-forward torque, or in closed loop the applied actuator torque less the wheels' gyroscopic
torque, held over each sample; ``int_actuator_torque`` and the other peaks name what they
measure. t_0 … t_N are the sample times of the scored window. A metric that does not apply is
null (``None``). A reference whose body rate jumps (natural motion's
step stop, a start away from the manoeuvre's initial rate it does not declare free) asks an
impulse ``I Δω δ(t − t_j)`` at each jump, which no sampling sees: :func:`compute_metrics` adds it
(``impulses``), so ``int_u2`` and ``peak_body_torque`` are +inf (:data:`IMPULSE_INFINITE`) and
``int_u``, ``int_abs_u`` include ``‖I Δω‖``, ``|(I Δω)_i|``."""
IMPULSE_INFINITE: tuple[str, ...] = ("int_u2", "peak_body_torque")
"""The metrics that are +inf for a motion with an impulse (:func:`compute_metrics`'s ``impulses``):
∫ ‖u‖² dt and the peak of a Dirac torque. :func:`metric_violations` takes +inf there as physical when
``int_u`` is finite and both are +inf (an impulse's; a torque sample that is not finite makes ``int_u``
so too)."""
DEFAULT_SETTLING_TOLERANCE_DEG = 0.5
"""deg, error band about the target attitude for ``settling_time_s``."""
DEFAULT_DETUMBLE_TOLERANCE = 0.01
"""rad/s, bound on every body-rate component for ``detumble_time_s``."""
REST_ENERGY_RTOL = 1e-12
"""``energy_ratio`` is null when the initial kinetic energy is at most this fraction of the largest
along the motion (a rate 1e-6 of the peak rate): a start at rest, whose rounding residue (a
rest-to-rest reference's 1e-17 rad/s) would otherwise give a ratio of two rounding errors."""


def detumble_time(t: NDArray, omega: NDArray, tolerance: float = DEFAULT_DETUMBLE_TOLERANCE) -> float | None:
    """First sample time after which ``max_i |ω_i| < tolerance`` holds at every sample to the end.

    Parameters
    ----------
    t : (N+1,) ndarray
        Sample times [s], increasing.
    omega : (N+1, 3) ndarray
        Body rate at ``t`` [rad/s], body axes.
    tolerance : float, optional
        Bound on every rate component [rad/s] (default :data:`DEFAULT_DETUMBLE_TOLERANCE`).

    Returns
    -------
    float or None
        ``t[j + 1]`` [s] for the last sample ``j`` at or above the bound; 0 if the bound holds
        throughout, ``None`` if it does not hold at the final sample.
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


def _peak(values: ArrayLike | None, empty: float | None) -> float | None:
    """max |v| over every entry; ``empty`` for ``None`` or no entries (``None`` stays null)."""
    if values is None:
        return None
    array = np.asarray(values, dtype=float)
    return float(np.max(np.abs(array))) if array.size else empty


def settling_time(t: NDArray, error_deg: NDArray | None, tolerance_deg: float) -> float | None:
    """First sample time after which the error stays at or below the tolerance to the end.

    Parameters
    ----------
    t : (N+1,) ndarray
        Sample times [s], increasing.
    error_deg : (N+1,) ndarray or None
        Error angle to the target attitude at ``t`` [deg]; ``None`` for a free final attitude.
    tolerance_deg : float
        Settling band [deg].

    Returns
    -------
    float or None
        ``t[j + 1]`` [s] for the last sample ``j`` whose error exceeds the band; 0 if none does;
        ``None`` for a free attitude or when the last sample is outside the band.
    """
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
    body_torque: ArrayLike | None = None,
    actuator_torque: ArrayLike | None = None,
    wheel_torque: ArrayLike | None = None,
    known_q: ArrayLike | None = None,
    impulses: ArrayLike | None = None,
    blinded: ArrayLike | None = None,
    due: ArrayLike | None = None,
) -> dict[str, Any]:
    """Metrics of a motion sampled at times ``t`` (definitions: :data:`METRIC_INFO`).

    Integrals of a quantity given once per interval (N values) use the zero-order hold
    ``Σ_k (t_k+1 − t_k) f_k``; given at the N+1 sample times, trapezoids. ``impulses`` (a
    reference's rate jumps) add Dirac torques no sample sees: ``int_u2`` and ``peak_body_torque``
    become +inf, ``int_u`` and ``int_abs_u`` gain ``Σ_j ‖p_j‖`` and ``Σ_j |p_j,i|``.

    Parameters
    ----------
    t : (N+1,) array_like
        Sample times [s], increasing.
    q : (N+1, 4) array_like
        Attitude at ``t``, scalar-first quaternion, body to inertial.
    omega : (N+1, 3) array_like
        Body rate with respect to the inertial frame at ``t`` [rad/s], body axes.
    torque : (N, 3) or (N+1, 3) array_like
        Torque of the integrals ``int_u2``, ``int_u``, ``int_abs_u`` [N m], body axes, the control
        torque on the rigid body: held over each interval (closed loop: the applied actuator
        torque less the wheels' gyroscopic torque, zero-order hold), or sampled at ``t`` (a
        reference's feed-forward, trapezoids).
    target_q : (4,) or (N+1, 4) array_like or None
        The manoeuvre's final attitude, or the target's attitude at each of ``t`` (a target that
        moves: :func:`target_motion`); ``None``: free (attitude metrics null).
    target_omega : (3,) or (N+1, 3) array_like or None, optional
        The manoeuvre's final body rate [rad/s], or the target's at each of ``t``; ``None``: free
        (``final_rate_error`` null).
    reference_q : (N+1, 4) array_like or None, optional
        Reference attitude at ``t`` for ``rms_error_deg`` and ``max_error_deg`` (closed loop).
    wheel_momentum : (N+1, n_w) array_like or None, optional
        Wheel spin momenta [N m s] for ``peak_wheel_momentum``; ``None`` or empty: null.
    saturated : (N,) array_like of bool or None, optional
        Whether any actuator was at its limit over each interval, for ``saturation_fraction``.
    plan_time_s : float or None, optional
        Wall time of the planner [s], copied to ``plan_time_s``.
    duration_s : float or None, optional
        The manoeuvre time T [s], the reference's, copied to ``duration_s``.
    settling_tolerance_deg : float, optional
        Band about ``target_q`` for ``settling_time_s`` [deg] (default
        :data:`DEFAULT_SETTLING_TOLERANCE_DEG`).
    initial_omega : (3,) array_like or None, optional
        The manoeuvre's initial body rate ω0 [rad/s]: gives ``initial_rate_error``
        ``‖ω(t_0) − ω0‖`` (a reference that leaves ω(0) free starts away from it).
    fine_settling_tolerance_deg : float or None, optional
        Band for ``fine_settling_time_s`` [deg]; ``None``: that metric is null.
    dipole : (N, 3) array_like or None, optional
        Magnetorquer dipole held over each interval [A m^2], body axes, for ``int_dipole``;
        ``None``: no magnetorquers (null).
    inertia : (3, 3) array_like or None, optional
        Body inertia [kg m^2] for ``energy_ratio``; ``None``: null.
    detumble_tolerance : float, optional
        Bound on ``max_i |ω_i|`` for ``detumble_time_s`` [rad/s] (default
        :data:`DEFAULT_DETUMBLE_TOLERANCE`).
    body_torque : (N, 3) or (N+1, 3) array_like or None, optional
        The control torque on the rigid body ``u`` of ``I ω̇ = −ω × I ω + u`` [N m], body axes,
        for ``peak_body_torque``; ``None`` (default): ``torque``, which is that torque.
    actuator_torque : (N, 3) array_like or None, optional
        The actuators' applied torque on the body [N m], body axes, held over each interval, for
        ``int_actuator_torque`` and ``peak_actuator_torque``; ``None``: null (a reference).
    wheel_torque : (N, n_w) array_like or None, optional
        Applied wheel motor torques [N m] for ``peak_wheel_torque``; ``None`` or empty: null.
    known_q : (N, 4) array_like or None, optional
        The attitude the controller was given at ``t_0 … t_(N−1)`` (scalar first, body to
        inertial), for ``final_knowledge_error_deg`` and ``max_knowledge_error_deg``; ``None``: null.
    impulses : (K, 3) array_like or None, optional
        Angular impulses ``p_j = I Δω_j`` [N m s], body axes, of Dirac torques ``p_j δ(t − t_j)``
        (a reference's rate jumps); a zero impulse is none; ``None`` (default) or empty: none.
    blinded : (N,) array_like of bool or None, optional
        Whether the star tracker's boresight was inside an exclusion at ``t_0 … t_(N−1)``, for
        ``star_tracker_blinded_s``; ``None`` (default): null.
    due : (N,) array_like of bool or None, optional
        Whether an update was due then (rate and outages), for ``star_tracker_blinded_updates``
        with ``blinded``; ``None``: every sample.

    Returns
    -------
    dict of str to float, list of float or None
        Every key of :data:`METRIC_KEYS` (``int_abs_u`` is a list of three per-axis integrals);
        metrics that do not apply are ``None``.
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    torque = np.asarray(torque, dtype=float)
    _check_samples(t, q, omega, torque)
    norms = np.linalg.norm(torque, axis=1)
    error_to_target = None if target_q is None else np.rad2deg(quat.error_angle(q, target_q))
    settling = settling_time(t, error_to_target, settling_tolerance_deg)
    metrics: dict[str, Any] = {
        "int_u2": float(_integrate(t, norms**2)),
        "int_u": float(_integrate(t, norms)),
        "int_abs_u": [float(v) for v in _integrate(t, np.abs(torque))],
        "int_actuator_torque": None if actuator_torque is None
        else float(_integrate(t, np.linalg.norm(np.asarray(actuator_torque, dtype=float), axis=1))),
        "peak_body_torque": _peak(torque if body_torque is None else body_torque, 0.0),
        "peak_actuator_torque": _peak(actuator_torque, None),
        "peak_wheel_torque": _peak(wheel_torque, None),
        "final_error_deg": None if error_to_target is None else float(error_to_target[-1]),
        "final_rate_error": None if target_omega is None
        else float(rate_error(np.asarray(q)[-1:], np.asarray(omega)[-1:],
                              None if target_q is None or np.ndim(target_q) == 1 else np.asarray(target_q)[-1:],
                              np.asarray(target_omega, dtype=float).reshape(-1, 3)[-1:]
                              if np.ndim(target_omega) == 2 else target_omega)[0]),
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
        "final_knowledge_error_deg": None,
        "max_knowledge_error_deg": None,
        "star_tracker_blinded_s": None,
        "star_tracker_blinded_updates": None,
    }
    if blinded is not None:
        inside = np.asarray(blinded, dtype=bool)
        metrics["star_tracker_blinded_s"] = float(np.sum(np.diff(t)[:inside.size][inside]))
        scheduled = np.ones(inside.size, dtype=bool) if due is None else np.asarray(due, dtype=bool)
        metrics["star_tracker_blinded_updates"] = int(np.count_nonzero(inside & scheduled))
    if known_q is not None:
        known = np.asarray(known_q, dtype=float)
        knowledge = np.rad2deg(quat.error_angle(known, q[:known.shape[0]]))
        metrics["final_knowledge_error_deg"] = float(knowledge[-1])
        metrics["max_knowledge_error_deg"] = float(np.max(knowledge))
    if inertia is not None:
        rates = np.asarray(omega, dtype=float)
        energy = 0.5 * np.einsum("ni,ij,nj->n", rates, np.asarray(inertia, dtype=float), rates)
        at_rest = energy[0] <= REST_ENERGY_RTOL * float(np.max(energy))  # rounding residue is rest
        metrics["energy_ratio"] = None if at_rest else float(energy[-1] / energy[0])
    if reference_q is not None:
        tracking = np.rad2deg(quat.error_angle(q, reference_q))
        metrics["rms_error_deg"] = float(np.sqrt(np.mean(tracking**2)))
        metrics["max_error_deg"] = float(np.max(tracking))
    if wheel_momentum is not None and np.size(wheel_momentum):
        metrics["peak_wheel_momentum"] = float(np.max(np.abs(wheel_momentum)))
    if impulses is not None and np.size(impulses):
        kicks = np.asarray(impulses, dtype=float).reshape(-1, 3)
        kicks = kicks[np.linalg.norm(kicks, axis=1) > 0.0]
        if kicks.size:  # a Dirac torque: its square has no finite integral, its peak no bound
            metrics["int_u"] += float(np.sum(np.linalg.norm(kicks, axis=1)))
            metrics["int_abs_u"] = [value + float(extra) for value, extra in
                                    zip(metrics["int_abs_u"], np.sum(np.abs(kicks), axis=0))]
            metrics.update(dict.fromkeys(IMPULSE_INFINITE, float("inf")))
    return metrics


def target_motion(target_q: ArrayLike | None, target_omega: ArrayLike | None, reference: Any,
                  t: ArrayLike) -> tuple[NDArray | None, NDArray | None]:
    """Where the manoeuvre's target is at each time: the attitude and body rate the final-state
    metrics and the ``final`` requirement measure a motion against.

    A manoeuvre that ends at rest has a fixed target: ``q_f`` (and ``ω_f``) at every time. One that
    ends turning (``ω_f ≠ 0``, or a free ``ω_f`` where the reference's own ``ω(T)`` is not zero)
    cannot be held at ``q_f``: after its end ``T`` the target is where its final state goes, the
    reference's own motion after ``T`` (its torque-free coast from ``(q_f, ω(T))``, which the
    closed loop tracks; the runner fails a reference that misses ``q_f`` or a given ``ω_f`` at
    ``T``); until ``T`` it is ``(q_f, ω_f)``. Without a reference (regulation) the target is fixed.

    Parameters
    ----------
    target_q : (4,) array_like or None
        ``q_f`` (scalar first, body to inertial); ``None``: free.
    target_omega : (3,) array_like or None
        ``ω_f`` [rad/s], body axes; ``None``: free.
    reference : planners.Reference or None
        The row's reference (``sample(t)`` and ``duration``); ``None``: regulation.
    t : (N,) array_like
        Times [s].

    Returns
    -------
    q : (N, 4) ndarray or None
        The target attitude at ``t`` (``None`` when ``q_f`` is free).
    omega : (N, 3) ndarray or None
        The target body rate at ``t`` [rad/s], body axes of the target attitude (``None`` when
        ``ω_f`` is free).
    """
    t = np.asarray(t, dtype=float)
    q = None if target_q is None else np.tile(np.asarray(target_q, dtype=float), (t.size, 1))
    omega = None if target_omega is None else np.tile(np.asarray(target_omega, dtype=float), (t.size, 1))
    if not turning(target_omega, reference):
        return q, omega
    after = t > reference.duration
    if np.any(after):
        coast = reference.sample(t[after])
        if q is not None:
            q[after] = coast.q
        if omega is not None:
            omega[after] = coast.omega
    return q, omega


def turning(target_omega: ArrayLike | None, reference: Any) -> bool:
    """Whether a manoeuvre ends turning, so that its target moves after ``T``
    (:func:`target_motion`): ``ω_f`` given and not zero, or free and the reference's ``ω(T)`` not
    zero; never without a reference.

    Parameters
    ----------
    target_omega : (3,) array_like or None
        ``ω_f`` [rad/s]; ``None``: free.
    reference : planners.Reference or None
        The row's reference; ``None``: regulation.

    Returns
    -------
    bool
    """
    if reference is None:
        return False
    if target_omega is not None:
        return bool(np.any(np.asarray(target_omega, dtype=float) != 0.0))
    return bool(np.any(reference.sample(np.array([reference.duration])).omega != 0.0))


def rate_error(q: ArrayLike, omega: ArrayLike, target_q: ArrayLike | None, target_omega: ArrayLike) -> NDArray:
    """``‖ω − ω_t‖`` with the target's rate in the body's axes, ``ω_t`` turned by ``R(q_e)ᵀ``
    (``q_e = q_t* ⊗ q``) when the target's attitude is given per sample (a target that turns,
    :func:`target_motion`); as it is otherwise (a fixed target: at rest, or a rate alone).

    Parameters
    ----------
    q : (N, 4) array_like
        The attitude (scalar first, body to inertial).
    omega : (N, 3) array_like
        The body rate [rad/s], body axes.
    target_q : (4,) or (N, 4) array_like or None
        The target's attitude, fixed or per sample; ``None``: free.
    target_omega : (3,) or (N, 3) array_like
        The target's body rate [rad/s], in its own body axes.

    Returns
    -------
    (N,) ndarray
        The rate error [rad/s].
    """
    omega = np.atleast_2d(np.asarray(omega, dtype=float))
    target = np.asarray(target_omega, dtype=float)
    if target_q is not None and np.ndim(target_q) == 2 and np.ndim(target) == 2:
        target = quat.rotate_inverse(quat.error(np.atleast_2d(np.asarray(q, dtype=float)), target_q,
                                                shortest=False), target)
    return np.asarray(np.linalg.norm(omega - target, axis=-1))


def _check_samples(t: NDArray, q: NDArray, omega: ArrayLike, torque: NDArray) -> None:
    """ValueError naming the argument of :func:`compute_metrics` whose shape does not fit the
    times ``t`` (N+1 samples), instead of a NumPy broadcasting error deep in an integral."""
    if t.ndim != 1 or t.size < 1:
        raise ValueError(f"compute_metrics: t must be (N+1,) sample times, got shape {t.shape}")
    n = t.size - 1
    rates = np.shape(omega)
    for name, shape, expected in (("q", q.shape, [(n + 1, 4)]), ("omega", rates, [(n + 1, 3)]),
                                  ("torque", torque.shape, [(n, 3), (n + 1, 3)])):
        if shape not in expected:
            said = " or ".join(str(s) for s in expected)
            raise ValueError(f"compute_metrics: {name} must have shape {said} for the {n + 1} sample times t"
                             f"{' (held over each interval, or sampled at t)' if name == 'torque' else ''}, "
                             f"got shape {shape}")


def _check_targets(function: str, target_q: Any, target_omega: Any) -> None:
    """TypeError/ValueError naming ``target_q`` or ``target_omega`` when it is not what the metric
    functions take (a problem instead of its ``qf``, a 3-vector instead of a quaternion)."""
    for name, value, size, what in (("target_q", target_q, 4, "the final attitude, a quaternion scalar first"),
                                    ("target_omega", target_omega, 3, "the final body rate [rad/s]")):
        if value is None:
            continue
        if not isinstance(value, (list, tuple, np.ndarray)):
            raise TypeError(f"{function}: {name} must be {size} numbers ({what}) or None, got {type(value).__name__}"
                            + (" (pass problem.qf and problem.omegaf)" if hasattr(value, "qf") else ""))
        try:
            if np.asarray(value).dtype.kind in "US":  # text, though NumPy reads "1" as a number
                raise TypeError(name)
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"{function}: {name} must be {size} numbers ({what}) or None, got {value!r:.80}") from None
        if array.shape != (size,) or not np.all(np.isfinite(array)):
            raise ValueError(f"{function}: {name} must be {size} finite numbers ({what}) or None, got shape "
                             f"{array.shape}: {array.tolist()}")
        if size == 4 and (reason := quat.unit_norm_error(array)) is not None:  # [0, 0, 0, 0] scored 0 deg
            raise ValueError(f"{function}: {name} must be a unit quaternion ({what}): {reason}; got {array.tolist()}")


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
    """Closed-loop metrics of a simulation, by :func:`compute_metrics`.

    The torque of ``int_u2``, ``int_u``, ``int_abs_u`` and ``peak_body_torque`` is the control
    torque on the rigid body, the ``u`` of ``I ω̇ = −ω × I ω + u`` the allocation realised, as a
    reference's feed-forward is (so that a tracked reference's closed-loop integrals approach its
    own): the applied actuator torque held over each sample less the wheels' gyroscopic torque
    ``ω × A h_w`` at the start of the sample (without wheels, the applied torque itself).
    ``int_actuator_torque`` and ``peak_actuator_torque`` take the applied actuator torque,
    ``peak_wheel_torque`` the applied wheel motor torques; the dipole (with magnetorquers) is the
    applied one; ``inertia`` is the spacecraft's; with a star tracker among the run's sensors,
    the attitude the controller was given is ``result.sensor_state``'s (``known_q``), and with its
    exclusions the samples they blinded are ``result.blinded``'s (``star_tracker_blinded_s``,
    ``star_tracker_blinded_updates``).

    Parameters
    ----------
    result : ocp.simulation.simulator.SimulationResult
        The simulated run (states at the sample times, applied controls and torques).
    target_q : (4,) array_like or None
        The manoeuvre's final attitude (scalar first, body to inertial); ``None``: free.
    target_omega : (3,) array_like or None, optional
        The manoeuvre's final body rate [rad/s]; ``None``: free.
    reference : object or None, optional
        A planner's reference (vectorised ``q(t)``, ``sample(t)``, ``duration``): gives
        ``rms_error_deg`` and ``max_error_deg``, and the target's motion after ``T`` when the
        manoeuvre ends turning (:func:`target_motion`); ``None`` (regulation): those are null and
        the target is fixed.
    plan_time_s : float or None, optional
        Wall time of the planner [s].
    duration_s : float or None, optional
        The manoeuvre time T [s]: the tracked reference's ``duration`` (not the simulated horizon,
        ``result.t[-1]``); ``None`` in regulation.
    settling_tolerance_deg : float, optional
        Band for ``settling_time_s`` [deg].
    fine_settling_tolerance_deg : float or None, optional
        Band for ``fine_settling_time_s`` [deg]; ``None``: null.
    detumble_tolerance : float, optional
        Bound on ``max_i |ω_i|`` for ``detumble_time_s`` [rad/s].

    Returns
    -------
    dict of str to float, list of float or None
        Every key of :data:`METRIC_KEYS` (``initial_rate_error`` is null in closed loop).

    Raises
    ------
    TypeError, ValueError
        Naming the argument: a ``result`` that is not a simulation result, a ``target_q`` that is
        not 4 numbers (a problem, a 3-vector), a ``target_omega`` that is not 3.
    """
    if not all(hasattr(result, name) for name in ("t", "q", "omega", "applied_u", "model")):
        raise TypeError(f"metrics_from_simulation: result must be an ocp.SimulationResult (Simulator.run), got "
                        f"{type(result).__name__}")
    _check_targets("metrics_from_simulation", target_q, target_omega)
    target_q, target_omega = target_motion(target_q, target_omega, reference, result.t)
    slices = result.model.control_slices
    dipole = result.applied_u[:, slices["dipole"]] if "dipole" in slices else None
    wheel_torque = result.applied_u[:, slices["wheels"]] if "wheels" in slices else None
    return compute_metrics(
        result.t, result.q, result.omega, _rigid_body_torque(result), target_q, target_omega,
        reference_q=None if reference is None else reference.q(result.t),
        wheel_momentum=result.wheel_momentum if result.wheel_momentum.shape[1] else None,
        saturated=result.saturated, plan_time_s=plan_time_s, duration_s=duration_s,
        settling_tolerance_deg=settling_tolerance_deg,
        fine_settling_tolerance_deg=fine_settling_tolerance_deg, dipole=dipole,
        inertia=result.model.spacecraft.inertia, detumble_tolerance=detumble_tolerance,
        actuator_torque=result.applied_torque, wheel_torque=wheel_torque,
        known_q=_known_attitude(result), **_blinding(result),
    )


def _rigid_body_torque(result: Any) -> NDArray:
    """The control torque on the rigid body that a closed loop realised, held over each sample:
    the ``u`` of ``I ω̇ = −ω × I ω + u``, comparable with a reference's feed-forward torque.

    With wheels the actuators' torque on the body ``τ_act`` (``−A g``, plus magnetorquers and
    torquers) is not that ``u``: the body with its wheels obeys
    ``I ω̇ = −ω × (I ω + A h_w) + τ_act``, so ``u = τ_act − ω × A h_w``, taken at the start of each
    sample (the hold's ``ω_k`` and ``h_w,k``). Without wheels ``u`` is ``τ_act`` itself (the same
    array, no arithmetic).

    Parameters
    ----------
    result : ocp.simulation.simulator.SimulationResult
        The simulated run: ``omega`` (N+1, 3) [rad/s] and ``wheel_momentum`` (N+1, n_w) [N m s] at
        the sample times, ``applied_torque`` (N, 3) [N m] held over each sample, body axes, and
        its ``model``'s wheel axes ``A`` (3, n_w).

    Returns
    -------
    (N, 3) ndarray
        ``u`` [N m], body axes, one row per held sample.
    """
    if not result.wheel_momentum.shape[1]:
        return np.asarray(result.applied_torque)
    stored = result.wheel_momentum[:-1] @ result.model.spacecraft.wheel_axes.T  # A h_w, body axes
    return np.asarray(result.applied_torque - np.cross(result.omega[:-1], stored))


def _blinding(result: Any) -> dict[str, Any]:
    """``blinded`` and ``due`` of :func:`compute_metrics` when the run's star tracker has exclusions."""
    sensors = getattr(result, "sensors", None)
    tracker = getattr(sensors, "star_tracker", None)
    if tracker is None or not getattr(tracker, "exclusions", ()) or getattr(result, "blinded", None) is None:
        return {}
    return {"blinded": result.blinded != 0, "due": tracker.available(np.asarray(result.t)[:-1])}


def _known_attitude(result: Any) -> NDArray | None:
    """The attitude the controller was given at each sample, when a star tracker gave it."""
    sensors = getattr(result, "sensors", None)
    if sensors is None or getattr(sensors, "star_tracker", None) is None or result.sensor_state is None:
        return None
    return result.sensor_state[1:, 3:7]  # the state after sample k holds what the controller saw at t_k


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
    sample: Any = None,
    rate_jumps: ArrayLike | None = None,
) -> dict[str, Any]:
    """Metrics of a reference's own motion and feed-forward torque over ``[0, duration]``,
    sampled on ``points`` uniform times (trapezoidal integrals), by :func:`compute_metrics`; the
    jumps of its body rate (``rate_jumps``) are impulses ``I Δω`` no sample sees
    (``int_u2`` and ``peak_body_torque`` +inf, ``int_u`` and ``int_abs_u`` include them).

    Parameters
    ----------
    reference : planners.base.Reference
        A planner's reference: vectorised ``q(t)``, ``omega(t)``, ``torque(t)`` (the rigid-body
        feed-forward torque [N m], body axes), ``duration`` [s] and ``plan_time_s`` [s].
    target_q : (4,) array_like or None
        The manoeuvre's final attitude (scalar first, body to inertial); ``None``: free.
    target_omega : (3,) array_like or None, optional
        The manoeuvre's final body rate [rad/s]; ``None``: free.
    points : int, optional
        Number of uniform sample times, including both ends (default 2001).
    settling_tolerance_deg : float, optional
        Band about ``target_q`` for ``settling_time_s`` [deg].
    initial_omega : (3,) array_like or None, optional
        The manoeuvre's ω0 [rad/s], for ``initial_rate_error``; ``None``: null.
    fine_settling_tolerance_deg : float or None, optional
        Band for ``fine_settling_time_s`` [deg]; ``None``: null.
    inertia : (3, 3) array_like or None, optional
        Body inertia [kg m^2] for ``energy_ratio``; ``None``: null.
    detumble_tolerance : float, optional
        Bound on ``max_i |ω_i|`` for ``detumble_time_s`` [rad/s].
    sample : planners.reference.ReferenceSample or None, optional
        The reference already sampled at those ``points`` uniform times (its ``q``, ``omega`` and
        ``torque`` rows), by a caller that needs them too; ``None`` (default): sampled here.
    rate_jumps : (K, 3) array_like or None, optional
        The jumps ``Δω = ω⁺ − ω⁻`` [rad/s], body axes, of the reference's body rate
        (:func:`scenarios.requirements.scoring.rate_jumps` finds them, as the runner does);
        needs ``inertia``. ``None`` (default): the reference's rate does not jump.

    Returns
    -------
    dict of str to float, list of float or None
        Every key of :data:`METRIC_KEYS`; the closed-loop-only ones (tracking errors,
        saturation, wheel momentum, peak actuator and wheel torques, dipole) are null.

    Raises
    ------
    TypeError, ValueError
        Naming the argument: a ``reference`` without ``sample(t)`` and ``duration``, a
        ``target_q`` that is not 4 numbers (a problem, a 3-vector), a ``target_omega`` that is not 3.
    """
    if not (callable(getattr(reference, "sample", None)) and hasattr(reference, "duration")):
        raise TypeError(f"metrics_from_reference: reference must be a planners.Reference, got {type(reference).__name__}")
    _check_targets("metrics_from_reference", target_q, target_omega)
    t = np.linspace(0.0, reference.duration, points)
    if sample is None:
        sample = reference.sample(t)
    impulses = None
    if rate_jumps is not None and np.size(rate_jumps):
        if inertia is None:
            raise ValueError("metrics_from_reference: rate_jumps needs the inertia (an impulse is I Δω)")
        impulses = np.asarray(rate_jumps, dtype=float).reshape(-1, 3) @ np.asarray(inertia, dtype=float).T
    return compute_metrics(
        t, sample.q, sample.omega, sample.torque, target_q, target_omega,
        plan_time_s=reference.plan_time_s, duration_s=reference.duration,
        settling_tolerance_deg=settling_tolerance_deg, initial_omega=initial_omega,
        fine_settling_tolerance_deg=fine_settling_tolerance_deg, inertia=inertia, detumble_tolerance=detumble_tolerance,
        impulses=impulses,
    )


def metric_violations(metrics: dict[str, Any] | None) -> list[str]:
    """The metrics whose values physics forbids: every metric is a norm, an integral of a norm,
    an angle, a time or a fraction, so a value must be finite and non-negative (fractions at most
    1, a manoeuvre's duration positive). A row with a violation is not "ok". The one exception is
    an impulse's: +inf in every key of :data:`IMPULSE_INFINITE` beside a finite ``int_u``
    (:func:`compute_metrics`).

    Parameters
    ----------
    metrics : dict or None
        Metric keys to values (numbers, lists of numbers, or ``None`` for metrics that do not
        apply); ``None``: no metrics, no violation.

    Returns
    -------
    list of str
        ``"key = value"`` for each offending metric; empty when all are physical.
    """
    problems = []
    given = metrics or {}
    int_u = given.get("int_u")
    impulsive = (isinstance(int_u, (int, float)) and bool(np.isfinite(int_u))
                 and all(given.get(key) == float("inf") for key in IMPULSE_INFINITE))
    for key, value in (metrics or {}).items():
        values = value if isinstance(value, (list, tuple)) else [value]
        for item in values:
            if item is None:
                continue
            number = float(item)
            if impulsive and key in IMPULSE_INFINITE and number == float("inf"):
                continue
            bad = (not np.isfinite(number) or number < 0.0
                   or (key.endswith("fraction") and number > 1.0) or (key == "duration_s" and number == 0.0))
            if bad:
                problems.append(f"{key} = {value}")
                break
    return problems
