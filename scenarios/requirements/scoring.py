"""Scoring a row against every requirement: the reference on its own dense sampling, the closed loop
on its samples (between the samples too: the pointing of both, the closed loop's final error), and
the end points of the manoeuvre before anything is planned.

One :class:`Score` per requirement and scope (``reference``, ``closed_loop``): the numbers that go
into the result columns ``ref.req.<name>.<field>`` and ``cl.req.<name>.<field>``, whether it is met,
and what breaks it in words. The fields (their units, words and definitions are declared once in
:mod:`scenarios.requirements.fields`, which the tables, the report, the plots and the docs read):

* a pointing requirement: ``min_margin_deg`` (negative when violated), ``time_in_violation_s``,
  ``first_violation_s`` (null if never), ``min_margin_time_s``, in both scopes by one machinery:
  :meth:`~ocp.geometry.pointing.PointingConstraint.score_between_samples` on the attitude
  interpolated between the samples with the body rates (the reference's own rates; the window's
  edges are points of it, the reference sampled there exactly, the closed loop interpolated);
* ``actuators``: in the closed loop, its wheels' momentum (and speed, under a truth speed limit)
  against the same limits, reaching one a violation (:func:`closed_loop_wheels`); in the
  reference, for each actuator quantity with a limit
  (:func:`controllers.allocation.reference_demand`, through the row's controller's allocation, at
  the samples and either side of each of the reference's breakpoints: the integrated demand never
  interpolates across a switch, and a bang's peak at its end is read there; a declared free start's
  momentum the wheels cannot take asked on top, :func:`start_torque`),
  ``<quantity>`` the peak demand over the limit and ``<quantity>_time_s`` when it peaks, then
  ``rate_jump`` [rad/s] and ``rate_jump_time_s``, the largest jump of the reference's body rate
  (:func:`rate_jumps`: an impulse no finite torque gives; its momentum goes to the wheels), then
  ``unrealised_torque`` [N m] and ``unrealised_torque_time_s``, the largest torque the reference asks
  that the allocation's commands do not give (:func:`controllers.allocation.unrealised_torque`:
  about an axis no working actuator spans), and ``unrealised_torque_allowed`` [N m], its bound; met when every ratio is at most ``1 − margin``, the
  rate never jumps and the unrealised torque stays within :data:`UNREALISED_TOLERANCE` of the
  reference's peak torque; a demand or unrealised torque that is not finite (nan, inf) is no
  number met: its field is null, its time the first sample where it is not finite, and the
  requirement broken;
* ``rate``: ``peak_rate`` [rad/s] (of ``‖ω‖``), ``peak_time_s``, ``ratio`` (over the bound); the
  reference's either side of its breakpoints too (a bang-bang's peak at a switch between samples);
* ``final`` (closed loop only): ``worst_error_deg`` from ``T + after_s`` to the end, between the
  samples too (:func:`worst_error_between_samples`, on the attitude interpolated as for pointing),
  ``worst_rate_error`` [rad/s] over the samples from then on, and ``from_s``; to ``(q_f, ω_f)``,
  or, where the manoeuvre ends turning (``ω_f ≠ 0``), to where its final state goes after ``T``
  (:func:`ocp.metrics.target_motion`: the reference's own coast, which the closed loop tracks).

The runner (:mod:`scenarios.runner`) glues this to the rows and turns the scores into statuses and
messages (:func:`violations`, :func:`unhonoured`).
"""
from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from controllers.allocation import (
    MAX_SUBSTEPS,
    Allocation,
    demand_limits,
    model_rows,
    reference_demand,
    unrealised_torque,
)
from ocp import Spacecraft, quat, target_motion
from ocp.dynamics.layout import actuator_blocks
from ocp.dynamics.truth import TruthPlant
from ocp.geometry.pointing import (
    MAX_SUB_GRID,
    HermiteMotion,
    PointingConstraint,
    PointingScore,
    scores_between_samples,
    search_between_samples,
)
from ocp.metrics import rate_error, turning
from ocp.simulation.simulator import RPM_PER_RAD_S
from planners import ManeuverProblem, Planner, Reference
from planners.base import REQUIREMENT_KINDS, REQUIREMENT_TOLERANCE
from planners.reference import BREAKPOINT_INSTANT, JUMP_TOLERANCE
from scenarios.requirements.fields import VERDICT
from scenarios.requirements.spec import FinalRequirement, RateRequirement, Requirements

__all__ = ["AT_LIMIT", "FINAL_FIELDS", "JUMP_FIELDS", "LATE_SLACK", "POINTING_FIELDS", "RATE_FIELDS",
           "REFERENCE_POINTS", "SCOPE_WORDS", "TURN_PER_SAMPLE_RAD", "UNREALISED_FIELDS", "UNREALISED_FLOOR",
           "UNREALISED_TOLERANCE", "Score", "closed_loop_wheels", "coarse_samples", "endpoint_violations",
           "late_slew", "plant_limits", "rate_jumps", "reference_times", "score_closed_loop", "score_fields",
           "rate_least_duration", "rate_violations", "score_reference", "start_torque", "target_slack",
           "tracking_loss", "unhonoured", "violations", "worst_error_between_samples"]

Array = NDArray[np.float64]

REFERENCE_POINTS = 2001
"""Uniform sample times of a reference over ``[0, T]`` for its scores (as its metrics,
:func:`ocp.metrics.metrics_from_reference`)."""

SCOPE_WORDS = {"reference": "reference", "closed_loop": "closed loop"}
"""A scope's key (of ``Row.requirements`` and ``results.json``) and its words in messages."""

POINTING_FIELDS = ("min_margin_deg", "time_in_violation_s", "first_violation_s", "min_margin_time_s")
"""The fields of a pointing requirement's score, in column order (both scopes)."""
RATE_FIELDS = ("peak_rate", "peak_time_s", "ratio")
"""The fields of the rate requirement's score (both scopes)."""
FINAL_FIELDS = ("worst_error_deg", "worst_rate_error", "from_s")
"""The fields of the final requirement's score (closed loop only)."""
JUMP_FIELDS = ("rate_jump", "rate_jump_time_s")
"""The actuator score's fields after its quantities': the largest jump of the reference's body rate
[rad/s] (0 without one) and when it happens [s] (``None`` without one)."""
UNREALISED_FIELDS = ("unrealised_torque", "unrealised_torque_time_s", "unrealised_torque_allowed")
"""The actuator score's last fields: the largest torque the reference asks that its commands do not
give (:func:`controllers.allocation.unrealised_torque`) [N m], when [s], and the most it may be
[N m] (:data:`UNREALISED_TOLERANCE` of the reference's peak torque)."""
UNREALISED_FLOOR = 1e-12
"""[N m]: the torque scale of :data:`UNREALISED_TOLERANCE` for a reference that asks no torque (a
torque-free motion): rounding, not a demand."""
UNREALISED_TOLERANCE = 1e-2
"""The unrealised torque breaks the actuator requirement above this fraction of the reference's
peak torque. A reference that needs torque about an axis no working actuator gives leaves 0.59-1.0
of it unrealised (eigenaxis and spin-extremal references on one wheel or on two wheels); rounding
leaves about 1e-16 on a fully actuated spacecraft, and the optimal two-wheel manoeuvre
(``collocation`` on two wheels, whose z torque is the wheels' gyroscopic term) 2.5e-3: its wheel
momenta integrated from its saturated torques part from its state polynomial's by that much
(``scenarios/REPRODUCTION.md``, the saturated controls)."""

_TOLERANCE = REQUIREMENT_TOLERANCE
"""Relative slack on the ratio and bound checks (rounding, not a margin):
:data:`planners.base.REQUIREMENT_TOLERANCE`, the one that ``collocation``'s dense check allows a
bound too, so that a reference it calls within a bound is not scored breaking it for the slack."""
LATE_SLACK = 1e-6
"""Relative slack of :func:`late_slew` on ``maneuver.duration``: a solver's relaxation of the bound
on a free final time (IPOPT's ``bound_relax_factor``, 1e-8) and rounding, not a margin (60 µs of a
60 s budget)."""

AT_LIMIT = 1.0 - 1e-9
"""A closed-loop actuator state (a wheel's momentum or speed) at this fraction of its limit or more
is at the limit (:func:`closed_loop_wheels`): the simulator's momentum saturation puts it there to
rounding (``h + g dt = h_max``), and it is the violation."""


def _over(value: float, bound: float) -> tuple[str, str]:
    """``value`` (above ``bound``) and ``bound``, with 3 significant digits or as many more as it
    takes for the value to read above the bound (``1.00001`` over 1, not ``1``), 12 at most."""
    for digits in range(3, 13):
        shown, limit = f"{value:.{digits}g}", f"{bound:.{digits}g}"
        if float(shown) > float(limit):
            return shown, limit
    return f"{value:.12g}", f"{bound:.12g}"


@dataclass(frozen=True)
class Score:
    """How one scope of a row meets one requirement.

    Attributes
    ----------
    name : str
        The requirement's name (a pointing requirement's key, ``actuators``, ``rate``, ``final``).
    values : dict of str to float or None
        The fields (the module docstring), in column order.
    met : bool
        Whether the requirement holds.
    detail : str
        What breaks it, in words: ``min margin -0.19 deg at 31.2 s, 3.2 s inside``; when met, empty
        or a caveat of the scoring (the row's message shows it): ``the search between samples
        reached its work limit ...``.
    """

    name: str
    values: dict[str, float | None]
    met: bool
    detail: str = ""


def reference_times(duration: float, run_end: float, sample_time: float, points: int = REFERENCE_POINTS) -> Array:
    """Where a reference is scored: ``points`` uniform times over ``[0, T]`` (those of its metrics,
    :func:`ocp.metrics.metrics_from_reference`, so that one sampling serves both), then the closed
    loop's sample spacing to the end of the run (the reference coasts there, and the closed loop
    tracks it).

    Parameters
    ----------
    duration : float
        The reference's duration T [s].
    run_end : float
        End of the closed-loop window [s].
    sample_time : float
        The closed loop's sample time [s].
    points : int, optional
        Uniform times over ``[0, T]`` (default :data:`REFERENCE_POINTS`).

    Returns
    -------
    (N,) ndarray
        Increasing times [s].
    """
    times = np.linspace(0.0, duration, points)
    if run_end > duration:
        tail = np.linspace(duration, run_end, int(np.ceil((run_end - duration) / sample_time - 1e-9)) + 1)
        times = np.concatenate([times, tail[1:]])
    return times


def _pointing_scores(constraints: Sequence[PointingConstraint], t: Array, q: Array, omega: Array,
                     motion: HermiteMotion) -> dict[str, Score]:
    """The pointing requirements' scores on one motion, their searches between the samples together
    (:func:`ocp.geometry.pointing.scores_between_samples`: each as the constraint's alone)."""
    return {constraint.name: _pointing(constraint, score)
            for constraint, score in zip(constraints, scores_between_samples(constraints, t, q, omega, motion))}


def _pointing(constraint: PointingConstraint, score: PointingScore) -> Score:
    values: dict[str, float | None] = dict(zip(POINTING_FIELDS, (score.min_margin_deg, score.time_in_violation_s,
                                                                 score.first_violation_s, score.min_margin_time_s)))
    caveat = _limited("the search between samples", "a violation", score.missable_s)
    if score.met:
        return Score(constraint.name, values, True, caveat)
    assert score.min_margin_deg is not None and score.min_margin_time_s is not None
    where = "inside" if constraint.keep_out else "outside"
    broken = (f"min margin {score.min_margin_deg:.3g} deg at {_seconds(score.min_margin_time_s)} s, "
              f"{_seconds(score.time_in_violation_s)} s {where}")
    return Score(constraint.name, values, False, "; ".join(filter(None, (broken, caveat))))


def _after_slew(score: Score, reference: Reference | None) -> Score:
    """A pointing score of a reference broken only after its slew ends (T = its duration), when
    the end state is held (or coasts) to the end of the run: said so, with when the cone reaches
    it, since the slew itself clears the cone (a minimum-time slew ending before
    ``maneuver.duration``, its target held into a moving cone)."""
    first = score.values.get("first_violation_s")
    if score.met or reference is None or first is None or not first > reference.duration * (1 + _TOLERANCE):
        return score
    return dataclasses.replace(score, detail=(
        f"the slew clears it (it ends at T = {reference.duration:.4g} s), but the cone reaches its end state, "
        f"held after it, at {_seconds(first)} s: {score.detail}"))


def _limited(search: str, breach: str, missable_s: float) -> str:
    """The caveat of a search between samples that reached its work limit (``missable_s`` > 0: a
    breach shorter than that may be missed, :data:`~ocp.geometry.pointing.MAX_SUB_GRID`); empty
    for a full search."""
    return (f"{search} reached its work limit ({MAX_SUB_GRID:,} points): {breach} shorter than "
            f"{missable_s:.2g} s may be missed") if missable_s > 0 else ""


def _seconds(value: float) -> str:
    """A time in a message: one decimal, or two significant digits below 0.1 s (a 9 ms violation
    reads ``0.0093 s``, never ``0.0 s``)."""
    return f"{value:.1f}" if value == 0.0 or abs(value) >= 0.1 else f"{value:.2g}"


def _on_samples(times: Array, t: Array) -> NDArray[np.bool_]:
    """Whether each of ``times`` is one of the increasing samples ``t`` (``np.isin``, by a binary search)."""
    found = np.minimum(t.searchsorted(times), t.size - 1)
    return t[found] == times


def _inserted(t: Array, columns: Sequence[Array], times: Array, values: Sequence[Array]) -> tuple[Array, list[Array]]:
    """``t`` and its columns (rows per time) with the rows of ``values`` at ``times`` inserted, in
    time order: those strictly inside ``t``'s span, on no sample and on no earlier one of ``times``."""
    times = np.asarray(times, dtype=float)
    _, first = np.unique(times, return_index=True)
    keep = np.zeros(times.size, bool)
    keep[first] = True
    keep &= (times > t[0]) & (times < t[-1]) & ~_on_samples(times, t)
    if not np.any(keep):
        return t, [np.asarray(column, dtype=float) for column in columns]
    merged = np.concatenate([t, times[keep]])
    order = np.argsort(merged, kind="stable")
    return merged[order], [np.concatenate([np.asarray(column, dtype=float), np.atleast_2d(value)[keep]])[order]
                           for column, value in zip(columns, values)]


def _sides(reference: Reference) -> tuple[Array, tuple[Array, Array, Array]]:
    """The times either side of a reference's breakpoints and its attitude, rate and torque there
    (:meth:`planners.Reference.breakpoint_sides`, sampled once per reference)."""
    times, sample = reference.breakpoint_sides()
    return times, (sample.q, sample.omega, sample.torque)


def _with_edges(problem: ManeuverProblem, t: Array, sample: Any,
                reference: Reference | None) -> tuple[Array, Array, Array]:
    """The reference's times, attitudes and rates for its pointing scores: its samples, and the
    reference sampled exactly where the interpolation between them cannot stand for it: the edges
    of every pointing window inside the samples' span, and either side of each breakpoint (where its
    rate may jump: the Hermite between samples across a jump would use the wrong slopes;
    :meth:`planners.Reference.breakpoint_sides`, sampled once per reference)."""
    q, omega = np.asarray(sample.q, dtype=float), np.asarray(sample.omega, dtype=float)
    if reference is None or not problem.pointing or t.size < 2:
        return t, q, omega
    edges = np.unique(np.asarray([edge for constraint in problem.pointing for edge in constraint.window], dtype=float))
    edges = edges[(edges > t[0]) & (edges < t[-1]) & ~_on_samples(edges, t)]
    sides, at_sides = reference.breakpoint_sides()
    times = np.concatenate([edges, sides])
    if not times.size:
        return t, q, omega
    more = reference.sample(edges) if edges.size else None
    quaternions = np.concatenate([np.zeros((0, 4)) if more is None else more.q, at_sides.q])
    rates = np.concatenate([np.zeros((0, 3)) if more is None else more.omega, at_sides.omega])
    merged, (q, omega) = _inserted(t, (q, omega), times, (quaternions, rates))
    return merged, q, omega


def _rate(requirement: RateRequirement, t: Array, omega: Array, reference: Reference | None = None) -> Score:
    """The rate requirement's score on the samples, and on a reference's sides of its breakpoints
    (:meth:`planners.Reference.breakpoint_sides`, those within the samples' span): a rate that
    peaks at a switch between two samples (a bang-bang's, a step stop's) peaks there only."""
    norms = np.linalg.norm(omega, axis=1)
    worst = int(np.argmax(norms))
    peak, when = float(norms[worst]), float(t[worst])
    if reference is not None and reference.breakpoints.size:
        sides, at_sides = reference.breakpoint_sides()
        side_norms = np.where((sides >= t[0]) & (sides <= t[-1]), np.linalg.norm(at_sides.omega, axis=1), -np.inf)
        side = int(np.argmax(side_norms))
        if side_norms[side] > peak:  # a side above every sample (on a tie, the sample's time)
            peak, when = float(side_norms[side]), float(sides[side])
    ratio = peak / requirement.max_rate
    values: dict[str, float | None] = dict(zip(RATE_FIELDS, (peak, when, ratio)))
    met = ratio <= 1.0 + _TOLERANCE
    return Score("rate", values, met, "" if met else f"peak rate {peak:.4g} rad/s at {when:.1f} s, "
                                                     f"{_over(ratio, 1.0)[0]} x the {requirement.max_rate:g} rad/s bound")


def worst_error_between_samples(t: ArrayLike, q: ArrayLike, omega: ArrayLike, target: ArrayLike,
                                start: float, limit: float | None = None,
                                motion: HermiteMotion | None = None) -> tuple[float, float]:
    """The largest error angle to a fixed attitude from ``start`` on, between the samples too.

    The attitude between samples is that of the pointing scores
    (:func:`ocp.geometry.pointing.hermite_attitudes`: a cubic Hermite in the quaternion with the
    slopes of the body rates), searched by the pointing scores' search
    (:func:`ocp.geometry.pointing.search_between_samples`) for the least of minus the error angle,
    whose threshold is ``−limit``: the error angle moves no faster than the interpolant turns
    (:attr:`~ocp.geometry.pointing.HermiteMotion.rate_bound`), and ``start`` is a point of it when
    it falls between samples. An error of the interpolated motion above ``limit`` is never missed
    unless it rises less above than the bound over the search's last brackets (the true motion
    differs from the interpolated one by the interpolation's O(h⁴): with samples far apart next to
    the motion's own time scale, sample more finely), or shorter than the search's ``missable_s``
    where it reached its work limit (:data:`~ocp.geometry.pointing.MAX_SUB_GRID`; the final
    requirement's score says so); the largest error is exact where the search reaches it, else
    within the bound over a step.

    Parameters
    ----------
    t : (N,) array_like
        Increasing sample times [s].
    q : (N, 4) array_like
        Attitude at ``t`` (scalar first, body to inertial).
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s], body axes.
    target : (4,) array_like
        The attitude the error is measured to.
    start : float
        From when [s] (at most ``t[-1]``).
    limit : float or None, optional
        The bound on the error [rad] whose breaking must not be missed; ``None``: the largest
        error only.
    motion : HermiteMotion or None, optional
        ``HermiteMotion(t, q, omega)`` when already built (a row's pointing scores share it);
        ``None``: built here.

    Returns
    -------
    (float, float)
        The largest error angle [rad] and its time [s].
    """
    worst, when, _ = _worst_error(t, q, omega, target, start, limit, motion)
    return worst, when


def _worst_error(t: ArrayLike, q: ArrayLike, omega: ArrayLike, target: ArrayLike, start: float,
                 limit: float | None, motion: HermiteMotion | None) -> tuple[float, float, float]:
    """:func:`worst_error_between_samples` and its search's ``missable_s`` [s]."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    if not t[-1] >= start - 1e-9:
        raise ValueError(f"no sample from {start:g} s on (the samples end at {t[-1]:g} s)")
    target = np.asarray(target, dtype=float)
    moving = HermiteMotion(t, q, omega) if motion is None else motion

    def less_error(times: Array, attitudes: Array) -> Array:
        return np.where(times >= start - 1e-9, -quat.error_angle(attitudes, target), np.nan)

    found = search_between_samples(moving, less_error, -np.inf if limit is None else -float(limit),
                                   edges=(float(start),))
    times, values = found
    worst = int(np.nanargmin(values))
    return float(-values[worst]), float(times[worst]), found.missable_s


def _final(requirement: FinalRequirement, t: Array, q: Array, omega: Array, problem: ManeuverProblem,
           end_of_manoeuvre: float, motion: HermiteMotion | None = None, reference: Reference | None = None) -> Score:
    start = end_of_manoeuvre + requirement.after_s
    inside = t >= start - 1e-9
    values: dict[str, float | None] = dict(zip(FINAL_FIELDS, (None, None, start)))
    if not np.any(inside):
        return Score("final", values, False, f"no closed-loop sample from {start:g} s (T + after_s) on; lengthen "
                                             "simulation.duration")
    problems = []
    missable_s = 0.0  # the error search's (a breach shorter than it may be missed)
    moving = turning(problem.omegaf, reference)
    if moving:  # the target is the reference's own motion: the plan until T, its coast after (target_motion)
        assert reference is not None  # turning() needs one
        own = reference.sample(t)  # at every sample: an interval across T interpolates it consistently
        target_q: Array | None = own.q
        target_omega: Array | None = own.omega
    else:
        target_q, target_omega = target_motion(problem.qf, problem.omegaf, reference, t)
    if problem.qf is not None:
        bound = None if requirement.error_deg is None else float(np.deg2rad(requirement.error_deg))
        if moving:
            # the error's own motion, q_e = q_target* ⊗ q with body rate ω − R(q_e)ᵀ ω_target, to the identity
            relative = quat.error(q, own.q, shortest=False)
            relative_rate = omega - quat.rotate_inverse(relative, own.omega)
            worst_error, when, missable_s = _worst_error(t, relative, relative_rate, quat.IDENTITY, start, bound, None)
        else:
            worst_error, when, missable_s = _worst_error(t, q, omega, problem.qf, start, bound, motion)
        worst_deg = float(np.rad2deg(worst_error))
        values["worst_error_deg"] = worst_deg
        if requirement.error_deg is not None and worst_deg > requirement.error_deg * (1 + _TOLERANCE):
            shown, limit = _over(worst_deg, requirement.error_deg)
            problems.append(f"error {shown} deg at {when:.1f} s over {limit} deg")
    if problem.omegaf is not None:
        assert target_omega is not None  # omega_f given
        rates = rate_error(q[inside], omega[inside], target_q[inside] if moving and target_q is not None else None,
                           target_omega[inside])
        worst = int(np.argmax(rates))
        values["worst_rate_error"] = float(rates[worst])
        if requirement.rate is not None and rates[worst] > requirement.rate * (1 + _TOLERANCE):
            shown, limit = _over(rates[worst], requirement.rate)
            problems.append(f"rate error {shown} rad/s at {t[inside][worst]:.1f} s over {limit} rad/s")
    broken = (", ".join(problems) + f" (from {start:g} s)") if problems else ""
    caveat = _limited("the error's search between samples", "an error over the bound", missable_s)
    return Score("final", values, not problems, "; ".join(filter(None, (broken, caveat))))


def rate_jumps(t: Array, omega: Array, omega0: ArrayLike, reference: Reference | None = None) -> list[tuple[float, int, Array]]:
    """Where a reference's body rate jumps: no finite torque gives a jump, so no actuator can follow it.

    At t = 0 the reference's rate against the manoeuvre's initial rate, unless the reference declares
    ``omega0`` free (:attr:`planners.Reference.free_boundary`: natural motion's spin-up, the spin
    extremals' transverse rates, an eigenaxis slew from a spinning state): that start is an initial
    tracking error the closed loop absorbs, reported as ``ref.initial_rate_error`` and scored in the
    closed loop, not an impulse the reference asks for (the momentum it carries still counts in the
    wheels': :func:`score_reference`); and across each of the reference's
    breakpoints (:attr:`planners.Reference.breakpoints`, where ``ω`` may jump: natural motion's step
    stop). A change of more than :data:`~planners.reference.JUMP_TOLERANCE` across a breakpoint, beyond what ``ω̇``
    explains over the instant either side sampled, is a jump.

    Parameters
    ----------
    t : (N,) ndarray
        The sample times [s], from 0.
    omega : (N, 3) ndarray
        The reference's rate at ``t`` [rad/s], body axes.
    omega0 : (3,) array_like
        The manoeuvre's initial rate [rad/s], body axes.
    reference : planners.Reference or None, optional
        The reference, for its breakpoints; ``None``: the start only.

    Returns
    -------
    list of (time, index, jump)
        The time [s] of each jump, the first sample after it (0 for the start), and the jump
        ``ω⁺ − ω⁻`` [rad/s], body axes; in time order.
    """
    found = []
    start = np.asarray(omega[0], dtype=float) - np.asarray(omega0, dtype=float)
    declared = reference is not None and "omega0" in reference.free_boundary
    if np.linalg.norm(start) > JUMP_TOLERANCE and not declared:
        found.append((float(t[0]), 0, start))
    breakpoints = np.array([] if reference is None else reference.breakpoints, dtype=float)
    # a breakpoint at the last sample too (a stop at T sampled up to T: the reference's metrics); the
    # sample after it is then the torque-free coast from the final state
    inside = (breakpoints > t[0]) & (breakpoints <= t[-1])
    if np.any(inside):
        assert reference is not None
        _, around = reference.breakpoint_sides()  # sampled once per reference
        instant = BREAKPOINT_INSTANT * max(reference.duration, 1.0)
        before, after = (side[inside] for side in np.split(around.omega, 2))
        slopes = np.max(np.abs(np.stack([side[inside] for side in np.split(around.omega_dot, 2)])), axis=(0, 2))
        for time, jump, slope in zip(breakpoints[inside], after - before, slopes):
            if np.linalg.norm(jump) > JUMP_TOLERANCE + 2.0 * instant * slope:  # beyond what ω̇ explains
                # the first sample after the jump; a step at T is in the sample at T already (its
                # contract: the rate after the step, Reference's breakpoints)
                index = np.searchsorted(t, time, side="left") if time >= reference.duration else \
                    np.searchsorted(t, time, side="right")
                found.append((float(time), int(index), jump))
    return found


def start_torque(spacecraft: Spacecraft, t: Array, q: Array, step: ArrayLike,
                 duration: float) -> tuple[Array, Array]:
    """The torque that removes, over the manoeuvre, the momentum of a declared free start that the
    working wheels cannot take.

    A reference that starts at ``ω_ref(0)`` while the spacecraft turns at ``ω₀`` (a declared free
    start, :func:`rate_jumps`) leaves the body ``I (ω_ref(0) − ω₀)`` of momentum to gain. The
    working wheels take its part within their span at once (:func:`controllers.allocation.reference_demand`'s
    jumps); the rest, ``J = (1 − S Sᵀ) I (ω_ref(0) − ω₀)`` (``S`` the wheels' span,
    :meth:`ocp.Spacecraft.wheel_span`; all of it without wheels), only an external torque gives: a
    torque impulse. It is asked as the least constant torque that gives it by the end of the
    manoeuvre, ``j / T`` in the inertial frame (``j = R(q(0)) J``), in body axes ``R(q(t))ᵀ j / T``
    from 0 to T and nothing after, on top of the reference's torque: through the allocation,
    torquers asked nothing else are asked ``|J_i| / (T τ_max,i)`` of their limit on body axis ``i``
    at t = 0 (the time they need at their limit to remove it, over T), wheels take what turns into
    their span, and what no working actuator
    spans is unrealised torque (:func:`controllers.allocation.unrealised_torque`), which breaks the
    actuator requirement.

    Parameters
    ----------
    spacecraft : ocp.Spacecraft
        The spacecraft (its inertia [kg m^2] and working wheels).
    t : (N,) ndarray
        Sample times [s], from 0.
    q : (N, 4) ndarray
        The reference's attitude at ``t`` (scalar first, body to inertial).
    step : (3,) array_like
        ``ω_ref(0) − ω₀`` [rad/s], body axes.
    duration : float
        The manoeuvre's T [s] (positive).

    Returns
    -------
    torque : (N, 3) ndarray
        The torque [N m], body axes, at ``t`` (its value up to T at a sample at T; zero after).
    impulse : (3,) ndarray
        ``J`` [N m s], body axes at t = 0; zeros (and no torque) when the working wheels span three
        axes or its rate ``‖I⁻¹ J‖`` is within :data:`~planners.reference.JUMP_TOLERANCE`.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    torque = np.zeros((t.size, 3))
    span = spacecraft.wheel_span()
    if span.shape[1] == 3 or not t.size:
        return torque, np.zeros(3)
    inertia = np.asarray(spacecraft.inertia, dtype=float)
    impulse = (np.eye(3) - span @ span.T) @ inertia @ np.asarray(step, dtype=float).reshape(3)
    if np.linalg.norm(np.linalg.solve(inertia, impulse)) <= JUMP_TOLERANCE:
        return torque, np.zeros(3)
    inertial = quat.rotate(np.asarray(q, dtype=float)[0], impulse) / duration
    during = t <= duration
    torque[during] = quat.rotate_inverse(np.asarray(q, dtype=float).reshape(-1, 4)[during],
                                         np.tile(inertial, (int(np.sum(during)), 1)))
    return torque, impulse


def _actuators(margin_allowed: float, demand: Mapping[str, Any], t: Array,
               jumps: list[tuple[float, int, Array]] | None = None, unrealised: Array | None = None,
               torque: Array | None = None, plant_limited: Mapping[str, Array] | None = None,
               impulse: Array | None = None, duration: float | None = None,
               unstarted: Callable[[], Mapping[str, Array]] | None = None, start_momentum: float = 0.0) -> Score:
    """The actuator requirement's score of a reference's demand (:func:`score_reference`).

    A quantity whose element at the peak (a wheel) is broken only with a declared free start (its
    peak ratio in ``unstarted()``, the demand as if the spacecraft started at the reference's rate,
    within the allowed; asked only for a quantity broken, where the message needs it) is said to be
    the free start's:
    ``(the free start's momentum, J N m s, takes it there: r x without it)``, ``J``
    the momentum ``‖I (ω_ref(0) − ω₀)‖`` the actuators take up (the wheels, at once where they
    span it and as the body turns where the other actuators remove it, :func:`start_torque`).
    """
    values: dict[str, float | None] = {}
    broken = []
    unscored = []
    allowed = f"{margin_allowed:.3g}"  # with the digits the most precise ratio shown needs
    free = ""  # what a part the free start's momentum asks for says of it
    if impulse is not None and duration is not None and np.any(impulse):
        size = float(np.linalg.norm(impulse))
        free = (f" (with the free start's momentum the wheels cannot take, {size:.3g} N m s, removed at "
                f"{size / duration:.3g} N m over the {duration:g} s manoeuvre)")
    # that momentum is asked, up to the duration, of the actuators that store none (Demand.name)
    stores = {name.removesuffix("_momentum") for name in demand if name.endswith("_momentum")}
    for name, quantity in demand.items():
        if not quantity.limited:
            continue
        ratios = quantity.ratios()
        finite = np.isfinite(quantity.values)
        if not finite.all():  # a demand that cannot be computed is no demand met
            first = int(np.argmax(~np.all(finite, axis=1)))
            values[name] = None
            values[f"{name}_time_s"] = float(t[first])
            unscored.append(f"{name} is not finite (nan or inf) from {t[first]:.1f} s: the demand cannot be scored "
                            f"(a reference rate that is not finite, or past the {MAX_SUBSTEPS:,} integration sub-steps "
                            f"the demand may take)")
            continue
        if ratios.size:  # the peak over every sample and element: the first sample that holds it
            highest = int(np.argmax(ratios))
            worst, ratio = highest // ratios.shape[1], float(ratios.flat[highest])
        else:
            worst, ratio = 0, 0.0
        values[name] = ratio
        values[f"{name}_time_s"] = float(t[worst]) if ratios.size or t.size else None
        if ratio > margin_allowed * (1 + _TOLERANCE):
            shown, limit = _over(ratio, margin_allowed)
            allowed = max(allowed, limit, key=len)
            element = int(np.argmax(ratios[worst])) if ratios.size else 0  # the element at the peak
            lowered = (plant_limited or {}).get(name)
            whose = (" (the truth model's; the planners plan to the design's, above it)"
                     if lowered is not None and lowered[element] else "")
            removes = free and name.rsplit("_", 1)[0] not in stores and duration is not None and t[worst] <= duration
            cause = free if removes else ""
            alone = unstarted().get(name) if not cause and unstarted is not None else None
            before = None if alone is None or element >= alone.size else float(alone[element])
            if before is not None and before <= margin_allowed * (1 + _TOLERANCE):
                cause = (f" (the free start's momentum, {start_momentum:.3g} N m s, takes it there: "
                         f"{before:.3g} x without it)")
            broken.append(f"{name} {shown} x its limit{whose} at {t[worst]:.1f} s{cause}")
    detail = ", ".join(unscored + ([", ".join(broken) + f" (allowed {allowed} x)"] if broken else []))
    if jumps is not None:
        largest = max(jumps, key=lambda jump: float(np.linalg.norm(jump[2])), default=None)
        values.update(zip(JUMP_FIELDS, (0.0, None) if largest is None
                          else (float(np.linalg.norm(largest[2])), largest[0])))
        if largest is not None:
            count = f", {len(jumps)} jumps" if len(jumps) > 1 else ""
            jumped = (f"the body rate jumps by {np.linalg.norm(largest[2]):.3g} rad/s at {largest[0]:g} s "
                      f"(an impulse: no finite torque gives it{count})")
            detail = jumped + (f", {detail}" if detail else "")
    if unrealised is not None and torque is not None:
        norms = np.linalg.norm(unrealised, axis=1)
        worst = int(np.argmax(norms)) if norms.size else 0
        peak = float(norms[worst]) if norms.size else 0.0
        scale = float(np.max(np.linalg.norm(torque, axis=1), initial=0.0))
        allowed_torque = UNREALISED_TOLERANCE * max(scale, UNREALISED_FLOOR)
        values.update(zip(UNREALISED_FIELDS, (peak, float(t[worst]) if norms.size and peak > 0.0 else None,
                                              allowed_torque if np.isfinite(allowed_torque) else None)))
        unknown = ~np.isfinite(norms)
        if np.any(unknown):
            first = int(np.argmax(unknown))
            values.update(zip(UNREALISED_FIELDS[:2], (None, float(t[first]))))
            missing = f"the unrealised torque is not finite (nan or inf) from {t[first]:g} s: it cannot be scored"
            detail = missing + (f", {detail}" if detail else "")
        # a reference asking no torque is measured against the rounding of its own terms
        elif peak > allowed_torque:
            share = f" ({peak / scale:.0%} of the reference's peak)" if scale > 0.0 else ""
            missing = f"{peak:.3g} N m of the torque asked at {t[worst]:g} s{share} is given by no working actuator"
            during = duration is not None and t[worst] <= duration
            detail = missing + (free if during else "") + (f", {detail}" if detail else "")
    return Score("actuators", values, not detail, detail)


def plant_limits(plant: TruthPlant | None) -> dict[str, Array] | None:
    """The actuator limits of the plant the closed loop flies, for :func:`score_reference`'s
    ``plant_limits``: :func:`controllers.allocation.demand_limits` of a truth model's spacecraft (its
    wheels' ``max_torque`` and ``max_momentum``), the wheels' momentum limit lowered to
    ``J_s Ω_max`` where the truth has a speed limit (``truth.wheels.max_speed_rpm``: the wheel's
    speed relative to the body is ``h / J_s − aᵀω``; the body rate's share ``J_s aᵀω`` is left out,
    small beside ``J_s Ω_max`` for a wheel that can store the slew's momentum at all), and the
    magnetorquers' dipole scaled by ``1 + e`` per body axis where the truth has a scale error
    (``truth.magnetorquers.scale_error``: the delivered dipole is ``(1 + e)`` times the saturated
    command, so a negative error lowers what the plant can deliver).

    Parameters
    ----------
    plant : ocp.dynamics.truth.TruthPlant or None
        The scenario's truth model (``Scenario.truth``); ``None``: the design model is flown.

    Returns
    -------
    dict of str to ndarray or None
        :attr:`controllers.allocation.Demand.limit` by quantity name; ``None`` without a truth model.
    """
    if plant is None:
        return None
    limits = demand_limits(plant.model.spacecraft)
    wheels = plant.model.spacecraft.wheels
    speed = plant.wheel_max_speed
    if speed is not None and wheels is not None and wheels.spin_inertia is not None and "wheels_momentum" in limits:
        limits["wheels_momentum"] = np.minimum(limits["wheels_momentum"], np.asarray(wheels.spin_inertia) * speed)
    scale = plant.truth.dipole_scale_error
    if scale is not None and "magnetorquers_dipole" in limits:
        # the plant delivers (1 + e) times the saturated command: at most (1 + e) times the design's dipole
        limits["magnetorquers_dipole"] = limits["magnetorquers_dipole"] * (1.0 + np.asarray(scale, dtype=float))
    return limits


def score_reference(requirements: Requirements, problem: ManeuverProblem, times: ArrayLike, sample: Any,
                    allocation: Allocation | None, reference: Reference | None = None,
                    plant_limits: Mapping[str, Array] | None = None, *, shared: bool = True) -> dict[str, Score]:
    """Score a reference, sampled densely, against every requirement that applies to it.

    The pointing requirements are scored between the samples too, as the closed loop's are
    (:meth:`~ocp.geometry.pointing.PointingConstraint.score_between_samples` with the reference's
    rates), the reference sampled exactly at the edges of their windows and either side of its
    breakpoints; the actuator requirement at the samples and either side of the breakpoints (where
    the torque or the rate may jump: the demand, integrated with its inputs linear between samples,
    would smear a switch over the interval across it; :meth:`planners.Reference.breakpoint_sides`,
    sampled once per reference), the rate requirement at the samples and either side of the breakpoints.

    Parameters
    ----------
    requirements : Requirements
        The scenario's requirements.
    problem : ManeuverProblem
        The problem planned (its ``pointing`` constraints, spacecraft, environment and initial
        wheel momenta).
    times : (N,) array_like
        The sample times [s] (:func:`reference_times`).
    sample : planners.ReferenceSample
        The reference at ``times`` (``reference.sample(times)``: ``q``, ``omega``, ``torque``).
    allocation : controllers.allocation.Allocation or None
        The row's controller, whose allocation the actuator demand goes through; ``None``: the
        actuator requirement is not scored.
    reference : planners.Reference or None, optional
        The reference sampled, for the jumps of its rate at its breakpoints (:func:`rate_jumps`) and
        its attitude at the windows' edges; ``None``: only a jump at the start (against the
        manoeuvre's initial rate) is found, and the edges are interpolated between the samples.
    plant_limits : mapping of str to ndarray or None, optional
        The limits of the plant the closed loop flies where it is not the design
        (:func:`plant_limits` of the scenario's truth model): each
        quantity is scored against the lesser of the design's limit and the plant's, element by
        element, and the message says where the plant's is the lesser; ``None``: the design's.
    shared : bool, optional
        ``True`` (default): every requirement; ``False``: the actuator requirement alone, the one
        that depends on ``allocation`` (a reference tracked by several controllers: the pointing and
        rate scores of one call serve them all).

    Returns
    -------
    dict of str to Score
        By requirement name: the pointing requirements, then ``actuators`` and ``rate`` (``final``
        is scored in closed loop only).
    """
    t = np.asarray(times, dtype=float)
    scores: dict[str, Score] = {}
    if shared and problem.pointing:
        edged = _with_edges(problem, t, sample, reference)
        motion = HermiteMotion(*edged)  # one interpolant for the row's pointing requirements
        pointing = _pointing_scores(problem.pointing, *edged, motion)
        scores.update({name: _after_slew(score, reference) for name, score in pointing.items()})
    if requirements.actuators is not None and allocation is not None:
        # The demand on the samples and either side of each breakpoint: where the torque (or the
        # rate) may jump, the demand's integration interpolates its inputs linearly between samples
        # and would smear a switch over the interval across it (the wheels' momentum read past its
        # true peak, or short of it), and the peaks of a bang profile sit at its switches.
        columns = (sample.q, sample.omega, sample.torque)
        demand_t, (q, omega, reference_torque) = (
            (t, [np.asarray(column, dtype=float) for column in columns]) if reference is None or t.size < 2
            else _inserted(t, columns, *_sides(reference)))
        jumps = rate_jumps(demand_t, omega, problem.omega0, reference)
        steps = np.zeros((demand_t.size, 3))
        for _, index, jump in jumps:
            if index < demand_t.size:
                steps[index] += jump
        start = np.zeros((demand_t.size, 3))
        impulse = np.zeros(3)
        if demand_t.size and not any(index == 0 for _, index, _ in jumps):
            # A declared free start (rate_jumps) is no torque demand, but the momentum it carries is:
            # the total angular momentum is the spacecraft's own at t = 0, I ω₀ + A h₀, whatever rate
            # the reference starts from, so the wheels take up I (ω₀ − ω_ref(0)) however the closed
            # loop absorbs the difference (a body spinning with more momentum than the wheels hold
            # cannot be brought to rest by them); what they cannot take the other actuators remove
            # over the manoeuvre (start_torque).
            steps[0] += omega[0] - np.asarray(problem.omega0, dtype=float)
            if reference is not None:
                start, impulse = start_torque(problem.model.spacecraft, demand_t, q, steps[0], reference.duration)
        # The actuators' share: the reference's torque u (of I ω̇ = −ω × I ω + u, the environment
        # it models inside) less the environment's torque along it (a planner that models none, such
        # as eigenaxis, leaves the actuators a disturbance to cancel; one that does, its own model),
        # and the torque that removes a free start's momentum the wheels cannot take.
        environment = _environment_torque(problem, demand_t, q, omega)
        torque = reference_torque - environment
        after = None
        if reference is not None:
            # the sample at T holds the torque's value there; the reference coasts torque-free after it
            coasting = (demand_t >= reference.duration)[:, None]
            after = np.where(coasting, 0.0, reference_torque) - environment
            if np.any(impulse):
                torque = torque + start
                after = after + np.where(coasting, 0.0, start)
        demand = reference_demand(allocation, problem.model, demand_t, q, omega, torque,
                                  problem.wheel_momentum0, jumps=steps, torque_after=after, environment=environment)
        # with a free start, each element's peak ratio as if it started at ω_ref(0): a second demand, asked
        # only where a broken quantity's message needs it
        unstarted: Callable[[], dict[str, Array]] | None = None
        if demand_t.size and np.any(steps[0]) and not any(index == 0 for _, index, _ in jumps):
            unstarted = functools.cache(functools.partial(_unstarted, allocation, problem, demand_t, q, omega,
                                                          reference_torque, environment, steps, reference))
        unrealised = unrealised_torque(problem.model, demand_t, q, omega, torque, demand)
        lower: dict[str, Array] = {}  # per quantity, the elements whose plant limit is below the design's
        if plant_limits is not None:
            for name, quantity in list(demand.items()):
                limit = np.minimum(quantity.limit, np.asarray(plant_limits.get(name, quantity.limit), dtype=float))
                if np.any(limit < quantity.limit):
                    lower[name] = limit < quantity.limit
                    demand[name] = dataclasses.replace(quantity, limit=limit)
        scores["actuators"] = _actuators(requirements.actuators.allowed, demand, demand_t, jumps, unrealised, torque,
                                         lower, impulse, None if reference is None else reference.duration,
                                         unstarted, float(np.linalg.norm(problem.spacecraft.inertia @ steps[0]))
                                         if unstarted is not None else 0.0)
    if shared and requirements.rate is not None:
        scores["rate"] = _rate(requirements.rate, t, sample.omega, reference)
    return scores


def _unstarted(allocation: Allocation, problem: ManeuverProblem, t: Array, q: Array, omega: Array,
               reference_torque: Array, environment: Array, steps: Array,
               reference: Reference | None) -> dict[str, Array]:
    """Each limited quantity's peak ratio per element as if the spacecraft started at the
    reference's rate (:func:`score_reference`'s demand without the free start's jump at ``t[0]``)."""
    free_steps = steps.copy()
    free_steps[0] -= omega[0] - np.asarray(problem.omega0, dtype=float)
    alone = reference_demand(allocation, problem.model, t, q, omega, reference_torque - environment,
                             problem.wheel_momentum0, jumps=free_steps,
                             torque_after=None if reference is None else
                             np.where((t >= reference.duration)[:, None], 0.0, reference_torque) - environment,
                             environment=environment)
    return {name: np.max(quantity.ratios(), axis=0) for name, quantity in alone.items()
            if quantity.limited and quantity.ratios().size and np.all(np.isfinite(quantity.values))}


def _environment_torque(problem: ManeuverProblem, t: Array, q: Array, omega: Array) -> Array:
    """The environment's torque [N m], body axes, along a sampled motion (gravity gradient and the
    constant disturbance of ``problem.model``; zeros without them)."""
    environment = problem.environment
    if environment is None or not (environment.gravity_gradient or np.any(environment.disturbance_torque)):
        return np.zeros((t.size, 3))
    model = problem.model
    x = np.hstack([q, omega, np.zeros((t.size, model.nx - 7))])
    return model_rows(model, "environment_torque", x, t[:, None], np.asarray(model.default_parameters, dtype=float).ravel())


def score_closed_loop(requirements: Requirements, problem: ManeuverProblem, t: ArrayLike, q: ArrayLike,
                      omega: ArrayLike, end_of_manoeuvre: float, reference: Reference | None = None,
                      wheel_momentum: ArrayLike | None = None, plant: TruthPlant | None = None) -> dict[str, Score]:
    """Score a closed-loop run against every requirement that applies to it: the rate requirement
    and the final rate error on its samples, the pointing requirements and the final error angle
    between them too (the attitude interpolated with the body rates,
    :meth:`ocp.geometry.pointing.PointingConstraint.score_between_samples`,
    :func:`worst_error_between_samples`; a window's edges and ``T + after_s`` are points of it).

    Parameters
    ----------
    requirements : Requirements
        The scenario's requirements.
    problem : ManeuverProblem
        The problem (its ``pointing`` constraints and targets).
    t : (N,) array_like
        Sample times [s].
    q : (N, 4) array_like
        Attitude at ``t`` (scalar first, body to inertial).
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s], body axes.
    end_of_manoeuvre : float
        T [s]: the reference's duration, the manoeuvre's in regulation (``final`` starts
        ``after_s`` later).
    reference : planners.Reference or None, optional
        The row's reference: where the manoeuvre ends turning (``ω_f ≠ 0``), ``final`` measures
        the error and the rate error to the target's motion after ``T``
        (:func:`ocp.metrics.target_motion`: the reference's own coast from ``(q_f, ω_f)``);
        ``None`` (regulation): to ``(q_f, ω_f)``.
    wheel_momentum : (N, n_w) array_like or None, optional
        The closed loop's wheel momenta at ``t`` [N m s] (``SimulationResult.wheel_momentum``):
        with the actuator requirement, scored against the wheels' momentum limits
        (:func:`closed_loop_wheels`); ``None``: not scored.
    plant : ocp.dynamics.truth.TruthPlant or None, optional
        The truth model the closed loop flew (``Scenario.truth``): its limits where lower than the
        design's (:func:`plant_limits`), and its wheels' speed limit; ``None``: the design's.

    Returns
    -------
    dict of str to Score
        By requirement name: the pointing requirements, then ``actuators`` (the wheels' momentum,
        with ``wheel_momentum`` and the actuator requirement, on a spacecraft whose wheels have a
        limit), ``rate`` and ``final``.
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    omega = np.asarray(omega, dtype=float)
    motion = HermiteMotion(t, q, omega)  # one interpolant for the row's requirements
    scores = _pointing_scores(problem.pointing, t, q, omega, motion)
    coarse = coarse_samples(t, omega)
    if coarse:  # a pointing requirement met between such samples is met by the interpolant: said so
        scores = {name: dataclasses.replace(score, detail="; ".join(filter(None, (score.detail, coarse))))
                  if score.met else score for name, score in scores.items()}
    if requirements.actuators is not None and wheel_momentum is not None:
        wheels = closed_loop_wheels(problem.spacecraft, t, omega, wheel_momentum, plant)
        if wheels is not None:
            scores["actuators"] = wheels
    if requirements.rate is not None:
        scores["rate"] = _rate(requirements.rate, t, omega)
    if requirements.final is not None:
        scores["final"] = _final(requirements.final, t, q, omega, problem, end_of_manoeuvre, motion, reference)
    return scores


TURN_PER_SAMPLE_RAD = 0.5
"""The turn between two closed-loop samples above which a pointing requirement scored met between
them carries a caveat (:func:`coarse_samples`). Between samples the scorer interpolates the attitude
by a cubic Hermite with the body rates at the samples; the closed loop flies the held torque there.
Against that motion (integrated from each written sample, SciPy), a nutating 3-4-5 kg m² body's
interpolant was off by 2.6e-5 deg at 0.2 rad a sample, 0.0015 deg at 0.5 rad, 0.026 deg at 1 rad and
0.40 deg at 2 rad (the error grows as about the fourth power of the turn), where a 0.218 deg cone the
motion entered by 0.2 deg was scored met (``tests/test_check_h6_held_torque_between_samples.py``)."""


def coarse_samples(t: ArrayLike, omega: ArrayLike, limit: float = TURN_PER_SAMPLE_RAD) -> str:
    """The caveat of a closed loop sampled too coarsely for its pointing margins between samples.

    Parameters
    ----------
    t : (N,) array_like
        Sample times [s].
    omega : (N, 3) array_like
        Body rate at ``t`` [rad/s].
    limit : float, optional
        The turn between two samples [rad] above which the caveat is given
        (:data:`TURN_PER_SAMPLE_RAD`).

    Returns
    -------
    str
        Empty where every interval turns at most ``limit`` (its larger end rate times its length);
        else the largest turn, where, and what to do.
    """
    t = np.asarray(t, dtype=float)
    speed = np.linalg.norm(np.asarray(omega, dtype=float), axis=1)
    if t.size < 2:
        return ""
    turn = np.diff(t) * np.maximum(speed[:-1], speed[1:])
    worst = int(np.argmax(turn))
    if not turn[worst] > limit:
        return ""
    return (f"the closed loop turns up to {turn[worst]:.2g} rad between two samples ({_seconds(t[worst])} to "
            f"{_seconds(t[worst + 1])} s), where its attitude is interpolated from the samples (a cubic Hermite, "
            f"not the held torque's motion), which at such turns can be off by a fraction of a degree: a margin "
            f"that small is not assured; sample faster (simulation.sample_time)")


def closed_loop_wheels(spacecraft: Spacecraft, t: ArrayLike, omega: ArrayLike, wheel_momentum: ArrayLike,
                       plant: TruthPlant | None = None) -> Score | None:
    """The actuator requirement's score of a closed loop: its momentum-storing actuators (the
    wheels) against their momentum limits, and against their speed limit under a truth model's.

    The simulator keeps each wheel within its momentum limit by cutting its motor torque
    (:meth:`~ocp.dynamics.actuator_kinds.ReactionWheels.saturate`), and a truth's speed limit by
    cutting it at ``|Ω| = Ω_max`` (:meth:`~ocp.dynamics.truth.TruthPlant.effective_control`): a
    wheel at its limit is a wheel the loop could not use as the law asked, so reaching the limit is
    the violation, not only passing it (a torque saturation is the law's own design, a metric:
    ``cl.saturation_fraction``). The limits are those :func:`score_reference` holds the reference's
    demand to: the lesser of the design's and the truth's momentum limit, element by element, and
    the truth's speed limit, which :func:`plant_limits` turns into the momentum ``J_s Ω_max`` for
    the reference (its body-rate share ``J_s aᵀω`` left out), scored here on the closed loop's
    speed itself. The closed loop is held to the limit itself, not to ``1 − margin`` (the margin is
    the reference's, room left for the closed loop).

    Parameters
    ----------
    spacecraft : ocp.Spacecraft
        The design's spacecraft (its actuators' limits and state layout).
    t : (N,) array_like
        Sample times [s].
    omega : (N, 3) array_like
        The closed loop's body rate at ``t`` [rad/s], body axes.
    wheel_momentum : (N, n_s) array_like
        The actuators' states at ``t`` (``SimulationResult.wheel_momentum``: the wheel momenta
        [N m s]).
    plant : ocp.dynamics.truth.TruthPlant or None, optional
        The truth model flown; ``None``: the design's.

    Returns
    -------
    Score or None
        ``actuators``: per momentum-storing kind with a limit, ``<kind>_momentum``, the peak of
        ``|h_i| / limit_i`` over the samples and elements, and ``<kind>_momentum_time_s`` when;
        under a truth speed limit, ``wheels_speed``, the peak of ``|Ω_i| / Ω_max,i`` (``Ω = h / J_s −
        aᵀω``, truth axes and spin inertia), and ``wheels_speed_time_s``: ratios to the limit, as the
        reference's. Met when every ratio is below 1 (:data:`AT_LIMIT`, a relative tolerance);
        else the time is the first sample at the limit (the peak's otherwise), and the detail
        says, in ratios (``x its limit``), which element reached it first (the lowest at that
        sample) and its limit, when, and for how long an element stays there: ``wheels_momentum at
        its limit, 1 x (wheel 0: 0.3 N m s, the first there) from 61.5 s to 140.0 s, 78.5 s at the
        limit in all`` (the time between consecutive samples both at it), ``at 6.5 s, on that
        sample only`` or ``on 2 separate samples from 4.0 s to 6.0 s``. ``None`` when no such quantity is limited.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    states = np.asarray(wheel_momentum, dtype=float).reshape(t.size, -1)
    values: dict[str, float | None] = {}
    broken: list[str] = []
    for name, (block, limit, lowered) in _momentum_limits(spacecraft, plant).items():
        element = block.actuator.name.removesuffix("s")
        whose = [" (the truth model's; the design's is above it)" if low else "" for low in lowered]

        def words(i: int, kind: str = element, bound: Array = limit, truth: list[str] = whose) -> str:
            return f"{kind} {i}: {bound[i]:.4g} N m s{truth[i]}"

        broken += _peak(name, np.abs(states[:, block.state]), limit, t, values, words)
    speed = _speed_limit(plant)
    if speed is not None:
        assert plant is not None
        flying = plant.model.spacecraft
        wheels = flying.wheels
        assert wheels is not None and wheels.spin_inertia is not None  # the truth's speed limit needs them
        where = next(block.state for block in actuator_blocks(flying) if block.actuator is wheels)
        relative = (states[:, where] / np.asarray(wheels.spin_inertia, dtype=float)
                    - np.asarray(omega, dtype=float).reshape(t.size, 3) @ np.asarray(wheels.axes, dtype=float))
        limits = np.asarray(speed, dtype=float)
        broken += _peak("wheels_speed", np.abs(relative), limits, t, values,
                        lambda i: f"wheel {i}: {limits[i] * RPM_PER_RAD_S:.4g} rpm, truth.wheels.max_speed_rpm")
    if not values:
        return None
    detail = ", ".join(broken)
    if detail:
        detail += " (the simulator holds a wheel at its limit by cutting the motor torque the law asks)"
    return Score("actuators", values, not broken, detail)


def _momentum_limits(spacecraft: Spacecraft, plant: TruthPlant | None) -> dict[str, tuple[Any, Array, Array]]:
    """The closed loop's momentum limits (:func:`closed_loop_wheels`): per actuator that stores
    momentum (its states' ``momentum_matrix`` is not zero: the wheels) with a finite limit, by the
    name of its states' quantity (``wheels_momentum``, :func:`controllers.allocation.demand_limits`),
    its block (:func:`ocp.dynamics.layout.actuator_blocks`), the lesser of the design's and the
    truth's limit per element, and where the truth's is the lesser. The truth's speed limit is not
    in it (:func:`_speed_limit`: the closed loop's speed is scored itself)."""
    limits = demand_limits(spacecraft)
    flown = {} if plant is None else demand_limits(plant.model.spacecraft)
    found = {}
    for block in actuator_blocks(spacecraft):
        name = f"{block.actuator.name}_momentum"
        if not (block.actuator.state_size and np.any(block.actuator.momentum_matrix()) and name in limits):
            continue
        design = np.asarray(limits[name], dtype=float)
        limit = np.minimum(design, np.asarray(flown.get(name, design), dtype=float))
        if np.any(np.isfinite(limit)):
            found[name] = (block, limit, limit < design)
    return found


def _speed_limit(plant: TruthPlant | None) -> Array | None:
    """The truth's wheel speed limit [rad/s] (``truth.wheels.max_speed_rpm``, which needs the wheels'
    spin inertia); ``None`` without one."""
    return None if plant is None else plant.wheel_max_speed


def _peak(name: str, magnitude: Array, limit: Array, t: Array, values: dict[str, float | None],
          words: Callable[[int], str]) -> list[str]:
    """One closed-loop quantity's peak ratio (``|value| / limit`` per sample and element, 0 where
    unlimited) and its time into ``values`` as ``name`` and ``<name>_time_s``, and its sentence when
    it reaches the limit (:data:`AT_LIMIT`: a relative tolerance, so that rounding does not pick
    the sample nor the element): the element that reached it first (the earliest sample at the
    limit, the lowest element there, ``words(element)`` its limit in words), when, and for how long
    any element is at or over the limit. ``<name>_time_s`` is then that first time, else the peak's."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = np.where(np.isinf(limit), 0.0, magnitude / limit)
    ratios = np.where(limit == 0.0, np.where(magnitude > 0.0, np.inf, 0.0), ratios)
    if not np.all(np.isfinite(magnitude)):  # a state that is not finite is no state within its limit
        first = int(np.argmax(~np.all(np.isfinite(magnitude), axis=1)))
        values[name], values[f"{name}_time_s"] = None, float(t[first])
        return [f"{name} is not finite (nan or inf) from {t[first]:.1f} s"]
    if not ratios.size:
        values[name], values[f"{name}_time_s"] = 0.0, None
        return []
    highest = int(np.argmax(ratios))
    worst, _ = divmod(highest, ratios.shape[1])
    ratio = float(ratios.flat[highest])
    values[name], values[f"{name}_time_s"] = ratio, float(t[worst])
    reached = ratios >= AT_LIMIT
    if not reached.any():
        return []
    at: NDArray[np.bool_] = np.any(reached, axis=1)  # the samples where an element is at (or over) its limit
    first = int(np.argmax(at))
    element = int(np.argmax(reached[first]))
    values[f"{name}_time_s"] = float(t[first])
    last = int(at.size - 1 - np.argmax(at[::-1]))
    held = float(np.sum(np.diff(t)[at[:-1] & at[1:]]))  # between consecutive samples both at it
    size = ("at its limit, 1 x" if ratio <= 1 + _TOLERANCE
            else f"at or over its limit, up to {_over(ratio, 1.0)[0]} x at {t[worst]:.1f} s")
    when = (f"at {t[first]:.1f} s, on that sample only" if first == last
            else f"on {int(np.sum(at))} separate samples from {t[first]:.1f} s to {t[last]:.1f} s" if held == 0.0
            else f"from {t[first]:.1f} s to {t[last]:.1f} s, {held:.3g} s at the limit in all")
    return [f"{name} {size} ({words(element)}, the first there) {when}"]


def score_fields(requirements: Requirements, spacecraft: Spacecraft,
                 plant: TruthPlant | None = None) -> dict[str, dict[str, tuple[str, ...]]]:
    """The fields a row's scores may hold, by scope and requirement: the result columns
    ``ref.req.<name>.<field>`` and ``cl.req.<name>.<field>`` a scenario can give.

    Parameters
    ----------
    requirements : Requirements
        The scenario's requirements.
    spacecraft : ocp.Spacecraft
        Its spacecraft (the actuator requirement has a field per limited actuator quantity,
        :func:`controllers.allocation.demand_limits`, and its time).
    plant : ocp.dynamics.truth.TruthPlant or None, optional
        Its truth model: a quantity limited there only has its fields too (:func:`plant_limits`).

    Returns
    -------
    dict
        Scope (``reference``, ``closed_loop``) -> requirement name -> fields, in column order,
        each requirement's verdict first (:data:`~scenarios.requirements.fields.VERDICT`, as the
        runner stores the scores): pointing and rate in both scopes, ``actuators`` in the
        reference, and in the closed loop where a momentum-storing actuator (the wheels) has a
        limit (:func:`closed_loop_wheels`), ``final`` in the closed loop only.
    """
    pointing = {requirement.name: POINTING_FIELDS for requirement in requirements.pointing}
    reference: dict[str, tuple[str, ...]] = dict(pointing)
    closed_loop: dict[str, tuple[str, ...]] = dict(pointing)
    if requirements.actuators is not None:
        flown = plant_limits(plant) or {}
        limited = [name for name, limit in demand_limits(spacecraft).items()
                   if np.any(np.isfinite(np.minimum(limit, flown.get(name, limit))))]
        reference["actuators"] = (tuple(field for name in limited for field in (name, f"{name}_time_s"))
                                  + JUMP_FIELDS + UNREALISED_FIELDS)
        stored = list(_momentum_limits(spacecraft, plant))
        if _speed_limit(plant) is not None:
            stored.append("wheels_speed")
        if stored:
            closed_loop["actuators"] = tuple(field for name in stored for field in (name, f"{name}_time_s"))
    if requirements.rate is not None:
        reference["rate"] = closed_loop["rate"] = RATE_FIELDS
    if requirements.final is not None:
        closed_loop["final"] = FINAL_FIELDS
    return {scope: {name: (VERDICT, *names) for name, names in fields.items()}
            for scope, fields in (("reference", reference), ("closed_loop", closed_loop))}


def endpoint_violations(problem: ManeuverProblem, free_time: bool = False) -> list[str]:
    """Requirements that the manoeuvre's end points already break, before anything is planned.

    The initial attitude is checked at t = 0 and the target at T, the manoeuvre's duration
    (``maneuver.duration``, the time the target attitude is given for), or at the window's start
    when it opens after T (the target is held), each when the window covers that time. The sentence
    names that time as what it is.

    With a free final time (a planner that minimises time,
    :func:`planners.capabilities.minimises_time`) T only bounds the slew's time: the slew may end
    at any time up to T. A fixed cone is checked as above (its margin is the same at every time);
    a moving one (:attr:`~ocp.geometry.pointing.PointingConstraint.moving`) at the target only
    where that is proven for every time the slew may end: its window covers ``[0, T]`` and the
    margin at T plus the most it can grow back over T (the constraint's ``drift``, a bound on the
    margin's rate with the attitude held, times T, :func:`target_slack`) is still negative.
    Otherwise the slew is planned, and a target held after it into the cone is scored as the row's
    violation, after planning.

    The rate requirement (``requirements.rate.max``, ω_max) is checked too: the principal angle θ
    between the initial and the target attitude takes at least ``θ / ω_max`` (the angle changes no
    faster than ``‖ω‖``), whatever the boundary rates; more than T is refused.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre with its pointing constraints.
    free_time : bool, optional
        The row's planner chooses the final time, T its upper bound (default False: the slew ends
        at T).

    Returns
    -------
    list of str
        One sentence per broken requirement and end, then the rate requirement's (empty when
        none is broken).
    """
    found = []
    ends: list[tuple[str, Any, float]] = [("initial attitude", problem.q0, 0.0)]
    if problem.qf is not None:
        ends.append(("target attitude", problem.qf, problem.duration))
    for constraint in problem.pointing:
        for words, q, time in ends:
            target = words == "target attitude"
            time = max(time, constraint.window[0]) if target else time
            slack = target_slack(constraint, problem.duration, free_time) if target else 0.0
            margin = constraint.margins(np.array([time]), np.asarray(q).reshape(1, 4))[0]
            if slack is None or not (np.isfinite(margin) and margin + slack < 0.0):
                continue
            kind = "keep-out" if constraint.keep_out else "keep-in"
            # the cone at that time: the angle and its growth (the Earth's apparent radius about the limb)
            limit = float(np.rad2deg(constraint.limit([time])[0]))
            grown = f": {constraint.description}" if abs(limit - np.rad2deg(constraint.angle)) > 1e-9 else ""
            cone = f"margin {np.rad2deg(margin):.3g} deg to the {limit:.4g} deg {kind} cone{grown}"
            if slack > 0.0:
                found.append(f"{constraint.name}: the target attitude breaks it at every time a minimum-time slew "
                             f"may end, up to maneuver.duration = {problem.duration:g} s ({cone} at "
                             f"{problem.duration:g} s; the cone moves back by at most {np.rad2deg(slack):.3g} deg "
                             "before it); no reference can meet it")
            else:
                found.append(f"{constraint.name}: the {words} already breaks it {_end_time(words, time, problem)} "
                             f"({cone}); no reference can meet it")
    found += rate_violations(problem)
    return found


def target_slack(constraint: PointingConstraint, duration: float, free_time: bool) -> float | None:
    """How much a pointing constraint's margin at the target, checked at T, may grow back at the
    earlier times a slew may end (:func:`endpoint_violations`).

    Parameters
    ----------
    constraint : PointingConstraint
        One pointing constraint of the manoeuvre.
    duration : float
        The manoeuvre's duration T [s] (``maneuver.duration``).
    free_time : bool
        The slew may end at any time up to T (a planner that minimises time).

    Returns
    -------
    float or None
        [rad]: 0 with a fixed final time or a fixed cone (its margin at T is the slew's end's, or
        the same at every time); for a moving cone with a free final time the most its margin can
        grow over ``[0, T]`` with the attitude held, ``drift · T``
        (:attr:`~ocp.geometry.pointing.PointingConstraint.drift`): the target breaks it at every
        time the slew may end only where its margin at T is below minus that. None: a moving cone
        whose window does not cover ``[0, T]`` (the slew may end outside it): the target is not
        checked before planning.
    """
    if not (free_time and constraint.moving):
        return 0.0
    if constraint.window[0] > 0.0 or constraint.window[1] < duration:
        return None
    return float(constraint.drift * duration)


def rate_least_duration(problem: ManeuverProblem) -> float | None:
    """The least time the rate requirement lets a slew from ``q0`` to ``qf`` take, ``θ / ω_max``
    (:func:`rate_violations` refuses a ``maneuver.duration`` below it).

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its end attitudes and ``rate_requirement``).

    Returns
    -------
    float or None
        ``θ / ω_max`` [s], ``θ`` the principal angle between the end attitudes [rad] and ``ω_max``
        the rate requirement [rad/s]; None without a rate requirement or a target attitude.
    """
    bound = problem.rate_requirement
    if bound is None or problem.qf is None:
        return None
    theta = 2.0 * float(np.arccos(min(1.0, abs(float(np.dot(problem.q0, problem.qf))))))
    return theta / bound


def rate_violations(problem: ManeuverProblem) -> list[str]:
    """The rate requirement that no motion from ``q0`` to ``qf`` within T can meet, before planning
    (part of :func:`endpoint_violations`; the runner makes such rows ``infeasible``, as every proof
    of it does).

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its end attitudes, duration T and ``rate_requirement``).

    Returns
    -------
    list of str
        One sentence (θ, ω_max, θ/ω_max and T, with their YAML paths) when ``θ / ω_max > T``,
        else empty (also without a rate requirement or a target).

    Notes
    -----
    The principal angle
    ``θ`` between them (the shorter way, ±qf) changes no faster than the body turns, ``|dθ/dt| ≤ ‖ω‖``,
    so a motion with ``‖ω‖ ≤ ω_max`` throughout needs at least ``θ / ω_max``; T bounds the slew
    (fixed, or the upper bound of a minimum-time slew: ``maneuver.duration`` is the manoeuvre's time
    budget for every planner, :func:`late_slew`, which holds a planned reference to it by the same
    rule). Whatever the boundary rates (the bound holds at every time, the ends included). Refused
    only beyond the scoring's own slack (``_TOLERANCE``).
    """
    least, bound = rate_least_duration(problem), problem.rate_requirement
    if least is None or bound is None or least <= problem.duration * (1.0 + _TOLERANCE):
        return []
    theta = least * bound
    return [f"rate: the slew turns {np.rad2deg(theta):.4g} deg (the principal angle from maneuver.initial.q to "
            f"maneuver.final.q); at ‖ω‖ at most {bound:g} rad/s (requirements.rate.max) it takes at least "
            f"θ/ω_max = {least:.4g} s, more than the {problem.duration:g} s bound (maneuver.duration); no "
            "reference within it can meet it"]


def late_slew(problem: ManeuverProblem, duration: float) -> str:
    """Why a planned slew that ends after ``maneuver.duration`` is not the manoeuvre asked for.

    ``maneuver.duration`` (T) is the manoeuvre's time budget for every planner: a fixed-time planner
    plans over it, a minimum-time one ends its slew at or before it (T its upper bound, as
    :func:`endpoint_violations` and :func:`rate_violations` take it). A planner that chooses a
    longer duration of its own (``eigenaxis``'s ``min_time``, ``shape_polynomial``'s
    ``rate_limit``, a minimum-time ``costate_tpbvp``) has found no slew within the budget under its
    bounds: its row is ``infeasible``, as a bang-coast-bang longer than T is, and as the rate proof
    makes it before planning.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its duration T [s]).
    duration : float
        The planned reference's duration [s].

    Returns
    -------
    str
        The sentence (the slew's duration and T, with its YAML path, and what to change) when the
        slew ends after T by more than :data:`LATE_SLACK` of T, else empty.
    """
    if duration <= problem.duration * (1.0 + LATE_SLACK):
        return ""
    digits = next(k for k in range(7, 18) if f"{duration:.{k}g}" != f"{problem.duration:.{k}g}")
    return (f"its slew takes {duration:.{digits}g} s, longer than the {problem.duration:g} s bound "
            "(maneuver.duration, the manoeuvre's time budget for every planner): the planner found no slew "
            f"within it under its bounds; a maneuver.duration of at least {_rounded_up(duration)} s admits this one")


def _rounded_up(value: float) -> str:
    """``value`` (> 0) rounded up to the fewest significant digits (3 at least) that stay within
    1e-3 of it: a duration to suggest, never below the one needed (100.00045 -> ``100.1``)."""
    for k in range(3, 17):
        step = 10.0 ** (math.floor(math.log10(value)) - k + 1)
        up = math.ceil(value / step) * step
        if up >= value and up - value <= 1e-3 * value:
            return f"{up:.{max(0, k - 1 - math.floor(math.log10(value)))}f}"
    return repr(value)


def _end_time(words: str, time: float, problem: ManeuverProblem) -> str:
    """When :func:`endpoint_violations` checked an end, in words: ``at 0 s`` for the initial
    attitude; for the target, the manoeuvre's duration T named as such (``maneuver.duration``, not
    the end of a slew, which a minimum-time planner chooses itself), or the window's start after it."""
    if words != "target attitude":
        return f"at {time:g} s"
    if time <= problem.duration:
        return f"at {time:g} s, maneuver.duration"
    return f"at {time:g} s, when the window opens after maneuver.duration = {problem.duration:g} s"


def violations(scores: Mapping[str, Mapping[str, Score]]) -> list[str]:
    """The broken requirements of a row, in words.

    Parameters
    ----------
    scores : mapping
        Scope (``reference``, ``closed_loop``) -> requirement name -> :class:`Score`.

    Returns
    -------
    list of str
        ``"<name> (<scope>): <detail>"`` per broken requirement, reference first; a pointing
        requirement the reference meets and the closed loop breaks says how much of the
        reference's margin the tracking took (:func:`tracking_loss`).
    """
    return [f"{name} ({SCOPE_WORDS[scope]}): {score.detail}"
            + (tracking_loss(scores["reference"][name], score) if scope == "closed_loop" and name in scores.get(
                "reference", {}) else "")
            for scope in SCOPE_WORDS for name, score in scores.get(scope, {}).items() if not score.met]


def tracking_loss(reference: Score, closed_loop: Score) -> str:
    """Why a closed loop breaks a pointing requirement its reference meets, in words.

    The reference clears the cone by its minimum margin ``m_r``; the closed loop ends at ``m_c < 0``:
    the tracking took ``m_r − m_c`` of the reference's margin. A reference planned that much
    further from the cone (collocation's ``cone_margin_deg``, 0.01° by default) or tighter tracking
    leaves room; the hint is the measured loss, not a guarantee (another reference is tracked
    differently).

    Parameters
    ----------
    reference, closed_loop : Score
        One pointing requirement's scores on the reference and on the closed loop.

    Returns
    -------
    str
        ``" (the reference clears it by 0.01 deg; the tracking took 0.2 deg: ...)"``, or ``""``
        unless the reference meets it, the closed loop breaks it and both have a margin [deg].
    """
    kept, lost = reference.values.get("min_margin_deg"), closed_loop.values.get("min_margin_deg")
    if not reference.met or closed_loop.met or kept is None or lost is None:
        return ""
    return (f" (the reference clears it by {kept:.3g} deg; the tracking took {kept - lost:.3g} deg: plan with at "
            "least that margin to the cone's edge, collocation's cone_margin_deg, or track tighter)")


def unhonoured(requirements: Requirements, planner: Planner | None) -> str:
    """What a planner does not impose of the scenario's requirements, in words.

    Parameters
    ----------
    requirements : Requirements
        The scenario's requirements.
    planner : planners.Planner or None
        The row's planner; ``None`` in regulation mode.

    Returns
    -------
    str
        ``"<planner> does not honour the pointing and actuators requirements (scored only)"``, or
        empty when it honours them all (or there is no planner). The actuator requirement every
        scenario carries unstated (margin 0) is left out: a broken one is named by its violation.
    """
    if planner is None:
        return ""
    implicit = requirements.actuators is not None and not requirements.actuators.stated
    honoured = type(planner).honoured(planner.options)
    missing: Sequence[str] = [kind for kind in REQUIREMENT_KINDS if kind in requirements.kinds
                              and kind not in honoured and not (kind == "actuators" and implicit)]
    if not missing:
        return ""
    words = missing[0] if len(missing) == 1 else ", ".join(missing[:-1]) + " and " + missing[-1]
    return f"{planner.name} does not honour the {words} requirement{'s' if len(missing) > 1 else ''} (scored only)"
