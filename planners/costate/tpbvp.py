"""Indirect optimal control: the states and co-states of Pontryagin's principle as a two-point
boundary-value problem (Vepa, sections 3 and 6), solved with ``scipy.integrate.solve_bvp``.

Problem forms (``objective``; the Hamiltonian systems are in :mod:`planners.costate.systems`):

* ``min_energy``: ``min ½∫‖M_c‖² dt`` for any rest-to-rest or rate-to-rate slew in the scenario's
  time, ``M_c = −I⁻¹λ_ω``. Cross-checked against the collocation planner.
* ``rate_acquisition``: reach the target rate ``ω_f`` steering a torque of fixed size,
  ``M_c = diag(τ) W u``, ``u = −Gᵀλ_ω/‖Gᵀλ_ω‖`` (eq. 21, 34); the attitude is free.
* ``attitude_acquisition``: reach ``q_f`` with the rate as the control, ``ω = ω_max u`` (eq. 44, 50).

The steering forms solve for the minimum time (``final_time: minimum``, default) or, with
``final_time: fixed``, minimise the paper's terminal cost at ``t_f = T`` with its transversality
conditions (eq. 36-38, 51). Gravity gradient enters whenever the scenario has it (eq. 5-8, orbit
frame from the scenario's orbit). A cold start (eigenaxis slew, the torque-free coast of a spinning
start, or straight-line rates) is walked to the target by continuation, each solve seeding the next, and the target's solution is refined once
to the final tolerance, in co-states scaled to order one for ``solve_bvp`` (:func:`solve`). Torque
bounds are not imposed.
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from ocp.errors import InvalidOption
from ocp.nlp.certificate import necessary_conditions_certificate
from ocp.options import Range
from planners.base import Planner
from planners.costate.hamiltonian import HamiltonianSystem, RigidBodySystem
from planners.costate.systems import (
    AttitudeAcquisitionSystem,
    ColdStartError,
    MinimumEnergySystem,
    RateAcquisitionSystem,
)
from planners.problem import Array, ManeuverProblem
from planners.reference import FailedReference, Reference, ReferenceSample


def _min_energy(problem: ManeuverProblem, o, build: bool = True) -> HamiltonianSystem | str | None:
    if problem.qf is None:
        return "objective min_energy needs a target attitude (maneuver.final.q)"
    if o.final_time == "minimum":
        return "objective min_energy has a fixed final time (final_time: fixed)"
    return MinimumEnergySystem(problem, problem.duration) if build else None


def _rate_acquisition(problem: ManeuverProblem, o, build: bool = True) -> HamiltonianSystem | str | None:
    if problem.omegaf is None:
        return "objective rate_acquisition needs a target rate (maneuver.final.omega)"
    torque = np.asarray(o.steering_torque if o.steering_torque is not None else problem.torque_limit, dtype=float)
    if torque.shape != (3,) or not np.all(np.isfinite(torque) & (torque > 0)):
        return (f"objective rate_acquisition needs a finite positive torque on every axis, got {torque}; "
                "give the actuators limits or set options.steering_torque (N m per axis)")
    if o.final_time != "fixed" and np.allclose(problem.omega0, problem.omegaf, rtol=0.0, atol=1e-12):
        return ("objective rate_acquisition: the initial and target rates are equal, there is no rate to acquire "
                "in minimum time; use objective min_energy for a slew")
    if not build:
        return None
    return RateAcquisitionSystem(problem, problem.duration, torque, np.diag(o.weighting), o.terminal_weight,
                                 o.final_time != "fixed")


def _attitude_acquisition(problem: ManeuverProblem, o, build: bool = True) -> HamiltonianSystem | str | None:
    max_rate = problem.rate_bound(o.max_rate, o.rate_margin)
    if max_rate is None:
        return ("objective attitude_acquisition needs a rate bound (options.max_rate, maneuver.max_rate or "
                "requirements.rate.max)")
    if problem.qf is None:
        return "objective attitude_acquisition needs a target attitude (maneuver.final.q)"
    if not build:
        return None
    return AttitudeAcquisitionSystem(problem, problem.duration, max_rate, o.terminal_weight, o.final_time != "fixed")


# objective -> builder(problem, options, build=True): the system, or the reason it cannot be built
# (with build=False only the reason, or None: a cheap check for scenario loading).
TORQUE_FORMS = ("min_energy", "rate_acquisition")
"""Objectives whose control is a body torque (the attitude-acquisition form steers the rate)."""

FORMS: dict[str, Callable[..., HamiltonianSystem | str | None]] = {
    "min_energy": _min_energy,
    "rate_acquisition": _rate_acquisition,
    "attitude_acquisition": _attitude_acquisition,
}


class CostateReference(Reference):
    """States and co-states from ``solve_bvp``'s C¹ interpolant on ``[0, t_f]``.

    Declares the boundary conditions its form leaves free (``HamiltonianSystem.free_boundary``)
    and the times where its rate jumps (``HamiltonianSystem.breakpoints``: the ends of attitude
    acquisition, whose rate is the control).

    Parameters
    ----------
    system : HamiltonianSystem
        The problem form that was solved.
    solution : object
        The result of ``scipy.integrate.solve_bvp``; ``solution.sol(s)`` gives ``y`` (2n, m) at
        scaled times ``s = t / t_f``.
    duration : float
        t_f [s].
    message : str
        Outcome description.
    stats : dict
        Solver statistics.
    """

    def __init__(self, system: HamiltonianSystem, solution: Any, duration: float, message: str,
                 stats: dict[str, Any]) -> None:
        super().__init__("costate_tpbvp", duration, system.inertia, message=message, stats=stats,
                         free_boundary=system.free_boundary(), breakpoints=system.breakpoints(duration))
        self.system, self.solution = system, solution

    def state_and_costate(self, t: ArrayLike) -> tuple[Array, Array]:
        """The optimal states and co-states (``planners.capabilities.CostateCarrier``).

        Parameters
        ----------
        t : float or array_like
            Time [s] or ``m`` times, clipped to ``[0, t_f]``.

        Returns
        -------
        x : (m, n) ndarray
            States, one row per time: ``[q, ω]`` (scalar first, body to inertial; rad/s, body axes)
            for the torque forms, ``q`` for attitude acquisition.
        lam : (m, n) ndarray
            Co-states ``[λ_q, λ_ω]`` (or ``λ_q``), one row per time.
        """
        y = self.solution.sol(np.clip(np.atleast_1d(np.asarray(t, dtype=float)), 0.0, self.duration) / self.duration)
        n = self.system.n_state
        return y[:n].T, y[n:].T

    def feedback_torque(self, lam_omega: Array, lam_omega_reference: Array) -> Array:
        """The optimal control at an estimated rate co-state (``planners.capabilities.CostateCarrier``).

        Parameters
        ----------
        lam_omega : (3,) ndarray
            The estimated rate co-state ``λ̂_ω``.
        lam_omega_reference : (3,) ndarray
            The reference's ``λ_ω`` at the same time (fixes the normalisation of eq. 42).

        Returns
        -------
        (3,) ndarray
            Control torque [N m], body axes, without the environment torque.

        Raises
        ------
        AttributeError
            For the attitude-acquisition form, whose control is a rate, not a torque.
        """
        if not isinstance(self.system, RigidBodySystem):
            raise AttributeError(f"{type(self.system).__name__} has no feedback_torque: its control is not a torque")
        return self.system.feedback_torque(lam_omega, lam_omega_reference)

    def _evaluate(self, t: Array) -> ReferenceSample:
        return self.system.sample(t, self.solution.sol(t / self.duration), self.duration)


LOOSE_TOLERANCE = 1e-5
"""``solve_bvp`` tolerance of the continuation stages (a stage only seeds the next)."""


def _costate_scale(system: HamiltonianSystem, y: Array) -> float:
    """The size of the co-states in a start: the largest ``|λ|`` (1 if they are all zero)."""
    size = float(np.max(np.abs(y[system.n_state:]), initial=0.0))
    return size if np.isfinite(size) and size > 0.0 else 1.0


def _solve_stage(system: HamiltonianSystem, fraction: float, start: tuple[float, Array, Array], tolerance: float,
                 max_nodes: int) -> Any:
    """One ``solve_bvp`` call on the problem at ``fraction``, in co-states scaled to order one.

    ``solve_bvp`` measures a residual relative to ``1 + |f|``: a co-state of size 1e5 whose rate is
    small is held to an absolute tolerance, far below its round-off once the mesh is fine (XTE's
    minimum energy at ``tol = 1e-8`` added nodes until ``max_nodes``). The co-state equations and the
    optimal controls are written in ``λ = c λ̃`` with ``c`` the size of the start's co-states; the
    result is returned in ``λ`` (its ``rms_residuals`` are those of the scaled problem; ``sol`` is
    ``None`` unless it converged).
    """
    from scipy.integrate import (
        solve_bvp,  # lazily: scipy.integrate pulls in scipy.optimize
    )
    from scipy.interpolate import CubicHermiteSpline

    free, n = system.free_final_time, system.n_state
    t_f, s, y = start
    scale = np.r_[np.ones(n), np.full(n, _costate_scale(system, y))]
    column, bc = scale[:, None], system.boundary(fraction)

    def fun(mesh, z, p=None):
        time = system.final_time(p) if free else t_f
        return time * system.evaluate(mesh * time, column * z, derivatives=False)[0] / column

    def fun_jac(mesh, z, p=None):
        time = system.final_time(p) if free else t_f
        f, jac, f_t = system.evaluate(mesh * time, column * z)
        assert jac is not None and f_t is not None  # evaluate gives them with derivatives=True
        jac = time * jac * (scale[None, :, None] / scale[:, None, None])
        if not free:
            return jac
        return jac, ((f + time * mesh * f_t) / column)[:, None, :]

    def boundary(za, zb, p=None):
        return bc(scale * za, scale * zb, p) if free else bc(scale * za, scale * zb)

    trial = solve_bvp(fun, boundary, s, y / column, p=[t_f] if free else None, fun_jac=fun_jac, tol=tolerance,
                      max_nodes=max_nodes)
    trial.y, trial.yp = column * trial.y, column * trial.yp
    # solve_bvp's own interpolant, in λ (a failed solve may hold non-finite values: no interpolant)
    trial.sol = CubicHermiteSpline(trial.x, trial.y, trial.yp, axis=1) if trial.status == 0 else None
    return trial


def _solved(trial: Any, free: bool) -> bool:
    """Whether a ``solve_bvp`` result converged (with a positive ``t_f`` for a free-time form)."""
    return bool(trial.status == 0 and (not free or trial.p[0] > 0))


def _failure(trial: Any) -> str:
    """Why a ``solve_bvp`` result is not a solution, with its size and residual."""
    detail = trial.message if trial.status != 0 else f"non-positive t_f = {trial.p[0]:.4g} s"
    return f"{detail} ({trial.x.size} nodes, max rms residual {float(np.max(trial.rms_residuals)):.2g})"


OUT_OF_TIME = "time limit reached"
"""How the message of a solve stopped by its ``deadline`` begins."""


def _out_of_time(deadline: float | None) -> bool:
    """Whether ``time.monotonic()`` has passed ``deadline`` (never when it is ``None``)."""
    return deadline is not None and time.monotonic() >= deadline


def _stopped(stages: int, done: float, trial: Any) -> str:
    """The message of a continuation stopped by its deadline: the calls made, the fraction solved
    and the last failure, if the last call failed."""
    last = f"; the last stage failed: {_failure(trial)}" if trial is not None and trial.status != 0 else ""
    return (f"{OUT_OF_TIME} after {stages} solve_bvp call(s), the continuation solved up to fraction "
            f"{done:.3f}{last}")


def solve(system: HamiltonianSystem, nodes: int, steps: int, tolerance: float, max_nodes: int,
          guess: tuple[float, Array, Array] | None = None,
          min_step: float = 1e-3, deadline: float | None = None) -> tuple[Any, float | None, int, str | None]:
    """Solve the TPBVP of ``system`` by adaptive continuation, starting with steps of ``1/steps``,
    then refine the solution of the target to ``tolerance``.

    The continuation stages use the tolerance ``max(tolerance, LOOSE_TOLERANCE)``. A failed stage
    is retried with half the step; a successful one lengthens the next by half. Each solution is
    resampled on ``m`` points before it seeds the next stage (``solve_bvp`` only ever adds nodes),
    ``m = nodes`` unless the cold start (``guess`` or the system's) has more points, whose number
    it then is (a spinning start's mesh, :meth:`~planners.costate.systems.MinimumEnergySystem.guess`); stages short of the
    target have at most ``min(max_nodes, max(10 nodes, 3 m))`` nodes. Once the
    target is solved, one ``solve_bvp`` call refines that solution, on its mesh, to ``tolerance``
    with at most ``max_nodes`` nodes. A failed refinement ends the solve: the continuation has
    done its work, and a smaller step would only reach the same target and refine it again. Every
    stage solves in co-states scaled to order one (``_solve_stage``).

    Parameters
    ----------
    system : HamiltonianSystem
        The problem form.
    nodes : int
        Mesh points each stage starts from (at least; see above).
    steps : int
        The first continuation step is ``1/steps`` (a form that is not ``continued`` solves the
        target at once).
    tolerance : float
        ``solve_bvp`` residual tolerance of the solution returned.
    max_nodes : int
        ``solve_bvp`` node limit of the stages that solve the target.
    guess : (t_f, s, y) or None, optional
        Replaces the system's own cold start (tests use it to start far away): final time [s],
        scaled mesh (m,) on [0, 1], ``y`` (2n, m).
    min_step : float, optional
        Smallest continuation step before giving up (default 1e-3).
    deadline : float or None, optional
        ``time.monotonic()`` [s] after which no further ``solve_bvp`` call starts (a call under
        way is not interrupted); the solve then fails with a message beginning with
        :data:`OUT_OF_TIME` and saying how far the continuation got. ``None`` (default): no limit.

    Returns
    -------
    solution : object or None
        The result of the last ``scipy.integrate.solve_bvp`` call, ``None`` on failure.
    t_f : float or None
        The final time [s], ``None`` on failure.
    stages : int
        ``solve_bvp`` calls made.
    message : str or None
        Why it failed, ``None`` on success.
    """
    free = system.free_final_time
    loose = max(tolerance, LOOSE_TOLERANCE)
    done, step, stages, start, solution, t_f = 0.0, 1.0 / steps if system.continued else 1.0, 0, guess, None, 0.0
    mesh_size = nodes if guess is None else max(nodes, guess[1].size)
    trial: Any = None
    while done < 1.0:
        fraction = min(1.0, done + step)
        if _out_of_time(deadline):
            return None, None, stages, _stopped(stages, done, trial)
        stage_start = start if start is not None else system.guess(nodes, fraction)
        if solution is None:  # a cold start finer than nodes (a spinning start) sets the mesh
            mesh_size = max(nodes, stage_start[1].size)
        limit = max_nodes if fraction == 1.0 else min(max_nodes, max(10 * nodes, 3 * mesh_size))
        trial = _solve_stage(system, fraction, stage_start, loose, limit)
        stages += 1
        if _solved(trial, free):
            solution, done, step = trial, fraction, 1.5 * step
            t_f = float(trial.p[0]) if free else stage_start[0]
            mesh = np.linspace(0.0, 1.0, mesh_size)
            start = (t_f, mesh, trial.sol(mesh))
            continue
        step /= 2
        if step < min_step:
            return None, None, stages, f"solve_bvp failed at continuation fraction {fraction:.3f}: {_failure(trial)}"
    assert solution is not None  # the loop ends on a solved target
    if tolerance >= loose:
        return solution, t_f, stages, None
    if _out_of_time(deadline):
        return None, None, stages, (f"{OUT_OF_TIME} before refining the target's solution to tolerance {tolerance:g} "
                                    f"({stages} solve_bvp call(s), {solution.x.size} nodes at tolerance {loose:g})")
    refined = _solve_stage(system, 1.0, (t_f, solution.x, solution.y), tolerance, max_nodes)
    stages += 1
    if not _solved(refined, free):
        return None, None, stages, (
            f"solve_bvp solved the target at tolerance {loose:g} ({stages - 1} continuation stage(s), "
            f"{solution.x.size} nodes) but refining it to tolerance {tolerance:g} failed: {_failure(refined)}; "
            "not retried (a smaller continuation step reaches the same target); a larger tolerance or "
            "max_nodes may pass")
    return refined, float(refined.p[0]) if free else t_f, stages, None


RATE_CHECK_POINTS = 2001
"""Samples over ``[0, t_f]`` (with the breakpoints' sides) on which :func:`rate_excess` checks the rate."""


def rate_excess(reference: Reference, bound: float) -> str:
    """Where a reference's body rate exceeds a bound, in words; empty when it keeps it.

    Sampled on :data:`RATE_CHECK_POINTS` times over ``[0, duration]`` and either side of its
    breakpoints within it (:meth:`~planners.Reference.breakpoint_sides`: where the rate may jump),
    within a relative ``1e-9`` (rounding).

    Parameters
    ----------
    reference : Reference
        The planned reference.
    bound : float
        The rate bound [rad/s], on ``‖ω‖``.

    Returns
    -------
    str
        ``"its rate reaches ... rad/s at ... s, above the rate bound ... rad/s"``, or ``""``.
    """
    t = np.linspace(0.0, reference.duration, RATE_CHECK_POINTS)
    sides, at_sides = reference.breakpoint_sides()
    inside = (sides >= 0.0) & (sides <= reference.duration)
    times = np.concatenate([t, sides[inside]])
    norms = np.linalg.norm(np.vstack([reference.sample(t).omega, at_sides.omega[inside]]), axis=1)
    worst = int(np.argmax(norms))
    if norms[worst] <= bound * (1 + 1e-9):
        return ""
    return f"its rate reaches {norms[worst]:.6g} rad/s at {times[worst]:.6g} s, above the rate bound {bound:g} rad/s"


COAST_NODE_FACTOR = 25
"""Nodes the torque-free-coast fallback of a spinning start may use, per node of its coarsest mesh
(one per :data:`~planners.costate.systems.SPIN_MESH_ANGLE` turned), when that exceeds
``max_nodes``: the spin re-pointing benchmark's refinement to 1e-8 ends on 7651 nodes from 401 (its
fast rotation needs a fine mesh everywhere), above the default ``max_nodes`` 5000, which keeps the
cost of a failing refinement elsewhere (XTE at tolerance 1e-13: 3-4 s against 15 s with 20000)."""


class CostateTPBVPPlanner(Planner):
    """Indirect (co-state) planner; see the module docstring."""

    name = "costate_tpbvp"
    example_options = ({}, {"objective": "rate_acquisition"}, {"objective": "attitude_acquisition"})

    @dataclass(frozen=True)
    class Options:
        """Options of ``costate_tpbvp`` (YAML ``planner.options``).

        Attributes
        ----------
        objective : {"min_energy", "rate_acquisition", "attitude_acquisition"}
            The problem form: ``min_energy`` (default; ``min ½∫‖M_c‖² dt`` over the scenario's T,
            needs a target attitude), ``rate_acquisition`` (steer a torque ``diag(τ) W u``,
            ``‖u‖ = 1``, to ``maneuver.final.omega``; the attitude is free) or
            ``attitude_acquisition`` (the rate ``ω = max_rate u``, ``‖u‖ = 1``, is the control).
        final_time : {"minimum", "fixed"} or None
            Steering forms: ``minimum`` (the default for them, ``None``) solves for the minimum
            time; ``fixed`` uses the scenario's T with the terminal cost ``terminal_weight`` and the
            paper's transversality conditions (rate acquisition: for a T shorter than the minimum
            time; a target rate reachable within T makes the problem singular and the solve fails). ``min_energy`` has a fixed time (``minimum`` is
            refused).
        weighting : tuple of 3 float
            Diagonal of ``W`` (eq. 34), positive (default ``[1, 1, 1]``; rate acquisition).
        steering_torque : list of 3 float or None
            ``τ``, the steering torque per body axis [N m], positive; ``None`` (default): the
            largest per-axis box the controllers' allocation realises at every corner
            (``Spacecraft.body_torque_limit``: ``diag(τ) W u`` with ``‖u‖ = 1`` and ``W <= 1``
            stays within it, whatever the direction ``u`` turns to; conservative for a skewed
            wheel array, which gives more along a single axis; torquers beside wheels that span
            three axes add nothing, the allocation never asks them) (rate acquisition).
        terminal_weight : float
            ``Q_f = terminal_weight · I`` of the terminal cost with ``final_time: fixed`` (on the
            rate for rate acquisition, on the quaternion for attitude acquisition), positive
            (default 100). The optimum does not depend on it: the control has unit norm and there
            is no running cost, so the co-state equations and boundary conditions are homogeneous
            in λ and the weight only scales the co-states.
        max_rate : float or None
            ``ω_max`` of attitude acquisition [rad/s]: it tightens the problem's bound
            (``maneuver.max_rate``, else ``requirements.rate.max``), never loosens it; ``None``
            (default): the problem's (:meth:`~planners.problem.ManeuverProblem.rate_bound`).
        rate_margin : float
            Attitude acquisition plans the rate requirement (``requirements.rate.max``,
            ``ManeuverProblem.rate_requirement``) this fraction lower, in [0, 1) (default 0.01), as
            ``eigenaxis``'s: its rate is ``ω_max`` on all of ``(0, t_f)``, and a closed loop tracking a
            rate at the bound overshoots it; ``maneuver.max_rate`` (the paper's bound) and the
            option ``max_rate`` are imposed as given.
        continuation_steps : int
            The first continuation step is ``1/continuation_steps`` of the way from the cold start
            to the target, then adaptive; 1 to 100 (default 3).
        nodes : int
            Mesh points each continuation stage starts from, 5 to 5000 (default 60).
        tolerance : float
            ``solve_bvp`` residual tolerance of the final stage, in (0, 1) (default 1e-8).
        max_nodes : int
            ``solve_bvp`` node limit of the final stage, 10 to 100000 and at least ``nodes``
            (default 5000). A spinning start's torque-free-coast fallback may use up to
            :data:`COAST_NODE_FACTOR` times its coarsest mesh, if that is more.
        time_limit : float or None
            Wall-clock budget of one plan [s], above 0 and at most 86400, or ``None`` for none (default 120): no
            further ``solve_bvp`` call starts once it is spent (one under way is not interrupted, so
            a plan can overrun it by one call), and the plan fails with a message naming this
            option, the calls made and the continuation fraction reached; the torque-free-coast
            fallback of a spinning start is not tried when the eigenaxis start has spent it. A fast
            spin's continuation can crawl for minutes before failing (1 rad/s for 200 s: 101-192 s,
            2 rad/s: 534 s, measured 2026-12-03); the spin re-pointing benchmark succeeds in 19-43 s.
        """

        objective: Literal["min_energy", "rate_acquisition", "attitude_acquisition"] = "min_energy"
        final_time: Literal["minimum", "fixed"] | None = None   # steering forms: default minimum
        weighting: Annotated[tuple[float, float, float], Range(gt=0.0, size=3)] = (1.0, 1.0, 1.0)                # diagonal of W (eq. 34)
        steering_torque: Annotated[list[float] | None, Range(gt=0.0, size=3)] = None              # N m per axis; default the actuator limits
        terminal_weight: Annotated[float, Range(gt=0.0)] = 100.0                           # Q_f = terminal_weight · I (final_time: fixed)
        max_rate: Annotated[float | None, Range(gt=0.0)] = None                            # rad/s; default the problem's bound
        rate_margin: Annotated[float, Range(ge=0.0, lt=1.0)] = 0.01                         # the rate requirement is planned this fraction lower
        continuation_steps: Annotated[int, Range(ge=1, le=100)] = 3                              # first step 1/continuation_steps, then adaptive
        nodes: Annotated[int, Range(ge=5, le=5000)] = 60                                          # mesh each stage starts from
        tolerance: Annotated[float, Range(gt=0.0, lt=1.0)] = 1e-8                                  # solve_bvp residual tolerance
        max_nodes: Annotated[int, Range(ge=10, le=100000)] = 5000
        time_limit: Annotated[float | None, Range(gt=0.0, le=86400.0)] = 120.0                                # s of wall clock per plan; None: none

        def __post_init__(self) -> None:
            if self.max_nodes < self.nodes:
                raise InvalidOption("max_nodes", f"must be at least nodes ({self.nodes}), got {self.max_nodes}")

    @classmethod
    def minimises_time(cls, options: Any) -> bool:
        """Whether the final time is free and minimised (:func:`planners.capabilities.minimises_time`).

        Parameters
        ----------
        options : Options or any
            The planner's options.

        Returns
        -------
        bool
            True for the steering forms with ``final_time`` ``minimum`` (their default).
        """
        objective = getattr(options, "objective", None)
        return objective in ("rate_acquisition", "attitude_acquisition") and getattr(options, "final_time", None) != "fixed"

    @classmethod
    def honoured(cls, options: Any) -> frozenset[str]:
        """The rate requirement with ``attitude_acquisition``: its rate, the control, has the norm
        ``ω_max`` (the rate bound, :meth:`~planners.problem.ManeuverProblem.rate_bound`) on all of
        ``(0, t_f)`` and the target rate at ``t_f``; a reference above the bound is ``infeasible``
        (:func:`rate_excess`). The torque forms impose no rate bound.

        Parameters
        ----------
        options : Options
            The planner's options.

        Returns
        -------
        frozenset of str
        """
        return frozenset({"rate"}) if getattr(options, "objective", None) == "attitude_acquisition" else frozenset()

    @classmethod
    def offers_costates(cls, options: Any) -> bool:
        """Whether references carry co-states with a torque control (``planners.capabilities``).

        Parameters
        ----------
        options : Options or any
            The planner's options.

        Returns
        -------
        bool
            True for the torque forms (``min_energy``, ``rate_acquisition``).
        """
        return getattr(options, "objective", None) in TORQUE_FORMS

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        error = FORMS[self.options.objective](problem, self.options, build=False)
        return error if isinstance(error, str) else None

    def _plan(self, problem: ManeuverProblem) -> Reference:
        o = self.options
        system = FORMS[o.objective](problem, o)
        if not isinstance(system, HamiltonianSystem):
            return FailedReference(self.name, str(system))
        deadline = None if o.time_limit is None else time.monotonic() + o.time_limit
        try:
            solution, t_f, stages, failure = solve(system, o.nodes, o.continuation_steps, o.tolerance, o.max_nodes,
                                                   deadline=deadline)
        except ColdStartError as error:
            return FailedReference(self.name, f"{o.objective}: {error}")
        fallback, first = (system.fallback() if failure else None), system.cold_start
        if fallback is not None and _out_of_time(deadline):  # no time left for the other cold start
            failure = f"from the {first}: {failure}; the {fallback.cold_start} was not tried ({OUT_OF_TIME})"
            fallback = None
        elif fallback is not None:  # the same problem from another cold start, on its own (finer) mesh
            limit = max(o.max_nodes, COAST_NODE_FACTOR * fallback.guess(o.nodes, 1.0)[1].size)
            solution, t_f, more, second = solve(fallback, o.nodes, o.continuation_steps, o.tolerance, limit,
                                                deadline=deadline)
            failure = None if second is None else f"from the {first}: {failure}; from the {fallback.cold_start}: {second}"
            stages, system = stages + more, fallback
        if failure or solution is None or t_f is None:
            if failure and OUT_OF_TIME in failure:
                failure += (f" (options.time_limit = {o.time_limit:g} s: a larger time_limit, or null for none, "
                            "lets the solver go on)")
            return FailedReference(self.name, f"{o.objective}: {failure}")
        stats = {"objective_form": o.objective, "t_f": t_f, "nodes": int(solution.x.size),
                 "max_rms_residual": float(np.max(solution.rms_residuals)), "continuation_stages": stages}
        if fallback is not None:
            stats["cold_start"] = fallback.cold_start
        if system.torque_control and isinstance(system, RigidBodySystem):
            fine = np.linspace(0.0, t_f, 4001)
            reference = CostateReference(system, solution, t_f, "", {})
            control = reference.sample(fine).torque - system.environment_torque(fine, reference.state_and_costate(fine)[0].T).T
            stats["int_u2"] = float(np.trapezoid(np.sum(control**2, axis=1), fine))
            if o.objective == "min_energy":  # ½∫‖M_c‖² is minimised with ∫‖M_c‖², the actuators' torque
                stats["functional"] = {"name": "int_actuator_torque_squared", "value": stats["int_u2"]}
        ends = (solution.y[:, 0], solution.y[:, -1]) + ((solution.p,) if system.free_final_time else ())
        boundary = float(np.max(np.abs(system.boundary(1.0)(*ends)), initial=0.0))
        stats["certificate"] = necessary_conditions_certificate(max(stats["max_rms_residual"], boundary), "solve_bvp")
        reference = CostateReference(system, solution, t_f, "", stats)
        if isinstance(system, AttitudeAcquisitionSystem):
            excess = rate_excess(reference, system.max_rate)
            if excess:
                return FailedReference(self.name, f"{o.objective}: {excess}", "infeasible")
        timing = "minimum time" if system.free_final_time else "fixed time"
        reference.message = (f"{o.objective} ({timing}) t_f = {t_f:.6g} s"
                             + (f", ∫‖M_c‖² = {stats['int_u2']:.6g}" if "int_u2" in stats else "")
                             + f" on {solution.x.size} nodes (solve_bvp"
                             + (f", from the {system.cold_start}: the {first} failed)" if fallback else ")"))
        return reference

