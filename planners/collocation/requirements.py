"""The requirements ``collocation`` honours, how much tighter it imposes them, and the dense check.

A problem's requirements (:class:`Requirements`: its pointing constraints and the planner's own
``keep_out`` / ``keep_in`` cones, the bound on the body-rate norm, the actuator margin) are imposed
by the NLP at the transcription's points only, and tighter than stated (:class:`Tightening`):
the cones by ``cone_margin_deg``, a window widened by one mesh interval (:func:`imposed_pointing`),
the actuators' states inside the solver's relaxation of their bounds (:func:`imposed_state_bounds`).
Between the points the interpolated solution may still cut a cone or overshoot a bound, so every
converged reference is checked on a dense grid (:func:`dense_check`, :data:`DENSE_POINTS` points per
interval) against the requirements **as stated**; the planner tightens what is broken
(:meth:`Tightening.after`) and solves again from the solution (see
:class:`~planners.collocation.planner.CollocationPlanner`). The controls are read as the reference
gives them: the interpolant saturated at the bounds the NLP imposed
(:class:`~planners.collocation.reference.CollocationReference`), so a bang-bang arc's polynomial,
which overshoots its bound between the points (by about a third across a switch inside an interval),
is not taken for a demand of the solution; the states (attitude, rate, wheel momenta) are read as
interpolated.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import cast

import numpy as np

from ocp import quat
from ocp.dynamics.layout import actuator_blocks
from ocp.geometry import PointingConstraint
from planners.base import REQUIREMENT_TOLERANCE
from planners.collocation.problem import variable_bounds
from planners.collocation.reference import CollocationReference
from planners.problem import Array, ManeuverProblem

__all__ = ["BOUND_TOLERANCE", "DENSE_POINTS", "DenseCheck", "Requirements", "START_TOLERANCE", "Tightening", "dense_check",
           "dense_times", "imposed_pointing", "imposed_state_bounds"]

DENSE_POINTS = 20
"""Points per mesh interval of the dense check (equally spaced, the nodes included)."""


@dataclass(frozen=True)
class Requirements:
    """What a ``collocation`` reference must meet, as stated (not tightened).

    Parameters
    ----------
    pointing : tuple of PointingConstraint
        The problem's pointing requirements, then the planner's own ``keep_out`` and ``keep_in``
        cones (named ``keep_out[i]``, ``keep_in[i]``): the planner holds its reference to them all;
        a scenario scores its rows against the former only.
    max_rate : float or None
        Bound on the body-rate norm ``‖ω‖`` [rad/s] (``ManeuverProblem.rate_bound(None)``: the
        lesser of ``max_rate`` and ``rate_requirement``), as stated; ``None``: none. The planner
        imposes it ``rate_margin`` lower where it is the rate requirement
        (:meth:`Tightening.initial`).
    actuator_margin : float or None
        The reference may ask at most ``1 − actuator_margin`` of every actuator limit (torques,
        dipoles, wheel momenta); ``None``: no actuator requirement (the limits are still imposed at
        the points, not checked between them).
    """

    pointing: tuple[PointingConstraint, ...] = ()
    max_rate: float | None = None
    actuator_margin: float | None = None

    @property
    def any(self) -> bool:
        """Whether there is anything to check densely."""
        return bool(self.pointing) or self.max_rate is not None or self.actuator_margin is not None

    @property
    def actuator_scale(self) -> float:
        """``1 − actuator_margin`` (1 without an actuator requirement)."""
        return 1.0 - (self.actuator_margin or 0.0)


@dataclass(frozen=True)
class Tightening:
    """How much tighter than the :class:`Requirements` the NLP imposes them.

    Parameters
    ----------
    pointing : tuple of float
        Per pointing requirement, in their order: how much tighter its cone is imposed [rad]
        (``cone_margin_deg`` at first).
    rate : float
        Fraction of ``max_rate`` taken off the imposed rate-norm bound, in [0, 1).
    actuators : float
        Fraction of the required actuator limits (``1 − actuator_margin`` of the limits) taken off
        the imposed bounds, in [0, 1).
    """

    pointing: tuple[float, ...] = ()
    rate: float = 0.0
    actuators: float = 0.0

    @classmethod
    def initial(cls, requirements: Requirements, cone_margin: float, rate_bound: float | None = None) -> Tightening:
        """The first solve's tightening: the cones by ``cone_margin``, the rate-norm bound down to
        ``rate_bound``, the actuators not.

        Parameters
        ----------
        requirements : Requirements
            What is required.
        cone_margin : float
            ``cone_margin_deg`` [rad].
        rate_bound : float or None, optional
            The rate-norm bound to impose first [rad/s], at most :attr:`Requirements.max_rate`
            (``ManeuverProblem.rate_bound`` with the planner's ``rate_margin``); ``None``
            (default): the requirement's own.

        Returns
        -------
        Tightening
        """
        rate = 0.0
        if rate_bound is not None and requirements.max_rate is not None:
            rate = max(0.0, 1.0 - rate_bound / requirements.max_rate)
        return cls((cone_margin,) * len(requirements.pointing), rate=rate)

    def after(self, check: DenseCheck, requirements: Requirements) -> Tightening:
        """The tightening for the next solve, after a dense check found violations.

        Every broken requirement is tightened further: a cone by 1.5 times its violation plus
        :data:`POINTING_STEP` [rad]; a bound's imposed value is divided by ``1 + 1.5 v +``
        :data:`BOUND_STEP`, ``v`` its violation as a fraction of it (an overshoot between the points
        scales with the bound, so this takes it below the bound in one round when the solution keeps
        its shape). The others are left as they are.

        Parameters
        ----------
        check : DenseCheck
            The dense check of the last solution.
        requirements : Requirements
            What is required (the order of :attr:`pointing`).

        Returns
        -------
        Tightening
        """
        pointing = tuple(
            extra + (1.5 * np.deg2rad(check.violations[c.name]) + POINTING_STEP if check.violations.get(c.name) else 0.0)
            for c, extra in zip(requirements.pointing, self.pointing))
        rate = check.violations.get("rate", 0.0)
        actuators = max((v for name, v in check.violations.items() if name.startswith("actuators.")), default=0.0)

        def further(taken: float, violation: float) -> float:
            return 1.0 - (1.0 - taken) / (1.0 + 1.5 * violation + BOUND_STEP) if violation else taken

        return replace(self, pointing=pointing, rate=further(self.rate, rate),
                       actuators=further(self.actuators, actuators))


POINTING_STEP = float(np.deg2rad(1e-3))
"""Floor of a cone's further tightening after a dense check [rad] (1e-3 deg)."""
BOUND_STEP = 1e-6
"""Floor of a bound's further tightening after a dense check (fraction of the limit)."""
BOUND_TOLERANCE = REQUIREMENT_TOLERANCE
"""A bound (rate norm, actuator limit) counts as broken by the dense check when exceeded by more
than this fraction of it: the scorer's slack (:data:`planners.base.REQUIREMENT_TOLERANCE`, 1e-9),
so that the planner never calls within a bound what a scenario then scores as breaking it. The
solver meets an inequality only to about 1e-8 of its scale: a bound it rides (a rate requirement
imposed with ``rate_margin: 0``) can exceed it by that and is then tightened and solved again, as
any violation is; the actuators' state bounds are imposed :data:`STATE_BACKOFF` inside
(:func:`imposed_state_bounds`) and the controls saturate at the bounds imposed, so neither needs
it. (Until 2026-12-04 this was 1e-6: a reference up to 1e-6 above a bound passed the dense check and
was scored ``violated``.) Not the slack of a start's feasibility (:data:`START_TOLERANCE`)."""
START_TOLERANCE = 1e-6
"""How far above a bound a start or candidate slew may go and still count as feasible for the NLP
(:func:`~planners.collocation.certificate.start_violations`: the minimum time's seed bound and the
note on a bound below the minimum time): the solver's own scale, about 1e-8, with room for a
start's rounding. A start is no row: no scenario scores it."""
SOLVER_BOUND_RELAXATION = 1e-8
"""How far the solver may leave a variable's bound ``b``, as a fraction of ``max(1, |b|)``: IPOPT's
``bound_relax_factor`` (its default, which :func:`~ocp.nlp.solve.solver_options` keeps) relaxes
every bound by that before it solves, and returns a point within the relaxed bounds. On a wheel
momentum limit of 0.03 N m s that is 1e-8 N m s, 3.3e-7 of the limit: a minimum-time optimum rides
the limit that far above it, and is scored against the limit itself."""
STATE_BACKOFF = 2.0 * SOLVER_BOUND_RELAXATION
"""How far inside an actuator state's bound ``b`` (a wheel momentum limit, ``1 − actuator_margin`` of
it) the NLP imposes it, as a fraction of ``max(1, |b|)``: twice the solver's relaxation
(:data:`SOLVER_BOUND_RELAXATION`), so that the solution's states stay within ``b`` with the
relaxation and rounding (2e-8 N m s below 1 N m s: 6.7e-7 of a 0.03 N m s limit, which moves a
minimum time by less than that fraction). The controls need none: the reference saturates them at
the bounds as imposed (:class:`~planners.collocation.reference.CollocationReference`)."""


def imposed_state_bounds(low: Array, high: Array, start: Array) -> tuple[Array, Array]:
    """The model state's per-point bounds as the NLP imposes them: the actuators' states (entries 7
    on: wheel momenta) :data:`STATE_BACKOFF` inside each finite bound, not past the start's value
    (a start at its bound keeps the bound); the attitude and rate entries as given.

    Parameters
    ----------
    low, high : (nx,) ndarray
        The state's bounds (:func:`~planners.collocation.problem.variable_bounds`, scaled by the
        actuator margin and the tightening); ``±inf``: none.
    start : (nx,) ndarray
        The state at t = 0 (``ManeuverProblem.initial_state``; only its actuator states are read).

    Returns
    -------
    tuple of (nx,) ndarray
        ``(low, high)``, new arrays.
    """
    low, high = np.array(low, dtype=float), np.array(high, dtype=float)
    if low.size <= 7:  # no actuator state: nothing to back off
        return low, high
    states = np.asarray(start, dtype=float)[7:]
    with np.errstate(invalid="ignore"):  # an infinite bound stays infinite
        high[7:] = np.where(np.isfinite(high[7:]), np.maximum(high[7:] - STATE_BACKOFF * np.maximum(1.0, np.abs(high[7:])),
                                                              np.minimum(states, high[7:])), high[7:])
        low[7:] = np.where(np.isfinite(low[7:]), np.minimum(low[7:] + STATE_BACKOFF * np.maximum(1.0, np.abs(low[7:])),
                                                            np.maximum(states, low[7:])), low[7:])
    return low, high


def imposed_pointing(requirements: Requirements, tightening: Tightening, interval: float | None,
                     duration: float) -> tuple[PointingConstraint, ...]:
    """The pointing constraints as the NLP imposes them.

    Each is tightened by its :attr:`Tightening.pointing`; with a fixed final time a window that
    starts after 0 or ends before ``duration`` is widened by one mesh interval on that side (by half
    the distance to 0 or to ``duration`` when nearer, so that an end the window leaves out stays
    out), so that the constraint holds at the window's edge between the points where it is imposed.

    Parameters
    ----------
    requirements : Requirements
        What is required.
    tightening : Tightening
        How much tighter.
    interval : float or None
        The mesh interval [s] (``T / intervals``) with a fixed final time; ``None`` with a free one
        (windows are then imposed over the whole run, see
        :class:`~ocp.transcription.OptimalControlProblem`).
    duration : float
        The final time [s].

    Returns
    -------
    tuple of PointingConstraint

    Raises
    ------
    ValueError
        When a tightened cone is no cone (half-angle outside (0, π)), naming it.
    """
    imposed = []
    for constraint, extra in zip(requirements.pointing, tightening.pointing):
        cone = constraint.tightened(extra)
        start, end = cone.window
        if interval is not None:
            if start > 0.0:
                start -= min(interval, 0.5 * start)
            if end < duration:
                end += min(interval, 0.5 * (duration - end))
            cone = replace(cone, window=(start, end))
        imposed.append(cone)
    return tuple(imposed)


@dataclass(frozen=True)
class DenseCheck:
    """A reference checked on a dense grid against the :class:`Requirements` as stated.

    Parameters
    ----------
    margins_deg : dict
        Per pointing requirement (by name): its least margin on the grid inside its window [deg]
        (negative when broken; ``None`` when no grid point lies in the window).
    violations : dict
        Per broken requirement: by how much, in degrees for a pointing requirement (minus its
        least margin), as a fraction of the required bound for ``"rate"`` (the body-rate norm)
        and ``"actuators.<block>"`` / ``"actuators.<block>.state"`` (an actuator's controls and
        states: wheel torques, wheel momenta, dipoles, torquer torques). A requirement met is
        not listed.
    points : int
        Points of the grid.
    """

    margins_deg: dict[str, float | None]
    violations: dict[str, float]
    points: int

    @property
    def met(self) -> bool:
        """Whether nothing is broken."""
        return not self.violations

    def summary(self) -> str:
        """The violations in words (empty when met).

        Returns
        -------
        str
        """
        words = []
        for name, value in self.violations.items():
            words.append(f"{name} by {value:.3g} deg" if name in self.margins_deg
                         else f"{name} by {100 * value:.3g} % of its bound")
        return ", ".join(words)


def _saturated_within(reference: CollocationReference, columns: slice, limits: Array) -> bool:
    """Whether the bounds at which ``reference`` saturates its controls ``columns`` keep them within
    ``limits`` wherever a limit is bounded (finite, positive), by at most :data:`BOUND_TOLERANCE`:
    every control it gives lies between its lower and upper saturation bound, so its magnitude is at
    most the larger of theirs, and the dense check cannot find it above the limit by more."""
    if reference.control_bounds is None:  # read as interpolated: unbounded between the points
        return False
    low, high = reference.control_bounds
    bounded = np.isfinite(limits) & (limits > 0)
    reach = np.maximum(np.abs(low[columns]), np.abs(high[columns]))[bounded]
    with np.errstate(invalid="ignore"):  # a NaN bound: not within
        return bool(float(np.max(reach / limits[bounded])) - 1.0 <= BOUND_TOLERANCE)


def dense_times(reference: CollocationReference, points_per_interval: int = DENSE_POINTS) -> Array:
    """The dense check's grid: ``points_per_interval`` equally spaced points per mesh interval, the
    nodes among them, and T.

    Parameters
    ----------
    reference : CollocationReference
        The solution (its duration [s] and its transcription's mesh, uniform or not).
    points_per_interval : int, optional
        Points per mesh interval (default :data:`DENSE_POINTS`).

    Returns
    -------
    (points_per_interval * intervals + 1,) ndarray
        Times [s] from 0 to T.
    """
    mesh = reference.transcription.mesh
    if mesh is None:
        return np.linspace(0.0, reference.duration, points_per_interval * reference.intervals + 1)
    steps = np.arange(points_per_interval) / points_per_interval  # a non-uniform mesh (switch_refinement)
    fractions = np.append((mesh[:-1, None] + np.diff(mesh)[:, None] * steps[None, :]).ravel(), 1.0)
    return np.asarray(fractions * reference.duration, dtype=float)


def dense_check(problem: ManeuverProblem, reference: CollocationReference, requirements: Requirements,
                points_per_interval: int = DENSE_POINTS) -> DenseCheck:
    """Check a reference between its points against the requirements as stated.

    The grid has ``points_per_interval`` equally spaced points per mesh interval, the nodes
    included (at a node the controls are read from both intervals that meet there, saturated at the
    bounds imposed as the reference gives them,
    :class:`~planners.collocation.reference.CollocationReference`; the states as interpolated). A pointing
    requirement is broken where its margin (:meth:`~ocp.geometry.PointingConstraint.margins` on the
    reference's normalised attitude) is negative; a bound where it is exceeded by more than
    :data:`BOUND_TOLERANCE` of it. The grid reads only what a check needs: the states for the
    pointing and rate requirements and the actuators' states, the controls only for a block whose
    saturation bounds do not already keep them within their limits (the reference gives no control
    beyond its saturation bounds, so there the check is met without a sample); a problem with
    nothing else to check is not sampled at all.

    Parameters
    ----------
    problem : ManeuverProblem
        The manoeuvre (its actuators' limits).
    reference : CollocationReference
        The solution to check.
    requirements : Requirements
        What is required.
    points_per_interval : int, optional
        Grid points per mesh interval (default :data:`DENSE_POINTS`).

    Returns
    -------
    DenseCheck
    """
    t = dense_times(reference, points_per_interval)
    # what each check reads: the actuator checks with a bounded entry (controls, then states, per block)
    actuators: list[tuple[str, str, slice, Array]] = []
    if requirements.actuator_margin is not None:
        _, x_high, _, u_high = variable_bounds(problem, None, requirements.actuator_scale)
        for block in actuator_blocks(problem.spacecraft):
            name = f"actuators.{block.actuator.block}"
            actuators += [(name, "controls", block.control, u_high[block.control]),
                          (name + ".state", "states", block.state, x_high[7:][block.state])]
        actuators = [entry for entry in actuators if np.any(np.isfinite(entry[3]) & (entry[3] > 0))]
        # a control saturated within its limit cannot break it: not sampled (the same verdict)
        actuators = [entry for entry in actuators
                     if entry[1] == "states" or not _saturated_within(reference, entry[2], entry[3])]
    needs_states = bool(requirements.pointing) or requirements.max_rate is not None \
        or any(kind == "states" for _, kind, _, _ in actuators)
    needs_controls = any(kind == "controls" for _, kind, _, _ in actuators)
    margins: dict[str, float | None] = {}
    violations: dict[str, float] = {}
    if not (needs_states or needs_controls):
        return DenseCheck(margins, violations, t.size)
    # the states as the reference samples them (its q normalised, its ω; the controls shifted and
    # saturated only when read), without the torques and rates of change that sample() would compute
    x_right, u_right = reference._state_control(t) if needs_controls else reference._interpolated(t)
    q, omega = quat.normalize(x_right[:, 0:4]), x_right[:, 4:7]
    for constraint in requirements.pointing:
        margin = constraint.margins(t, q)
        least = float(np.rad2deg(np.nanmin(margin))) if np.any(np.isfinite(margin)) else None
        margins[constraint.name] = least
        if least is not None and least < 0.0:
            violations[constraint.name] = -least
    if requirements.max_rate is not None:
        excess = float(np.max(np.linalg.norm(omega, axis=1))) / requirements.max_rate - 1.0
        if excess > BOUND_TOLERANCE:
            violations["rate"] = excess
    if actuators:
        x_left, u_left = reference._state_control(t, left=True) if needs_controls \
            else reference._interpolated(t, left=True)
        values = {"controls": np.maximum(np.abs(u_right), np.abs(u_left)) if needs_controls else None,
                  "states": np.maximum(np.abs(x_right), np.abs(x_left))[:, 7:]}
        for label, kind, columns, limits in actuators:
            bounded = np.isfinite(limits) & (limits > 0)
            read = cast(Array, values[kind])[:, columns]
            excess = float(np.max(read[:, bounded] / limits[bounded])) - 1.0
            if excess > BOUND_TOLERANCE:
                violations[label] = excess
    return DenseCheck(margins, violations, t.size)
