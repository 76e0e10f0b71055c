"""Direct optimal control on the full model: the workbench's numerical reference.

Objectives: ``min_energy`` ∫‖τ‖² dt (default), ``min_l1`` ∫Σ|τ_i| dt (slack variables),
``min_time`` (free T, the scenario's T is the upper bound), and ``weighted``
(``energy_weight``, ``l1_weight``, ``time_weight``). τ is the actuators' body torque.
A ``min_time`` (or a ``weighted`` objective with a ``time_weight``) that fails under its bound, where
the starts say the bound may be below the minimum time and a feasible slew longer than it is known,
is solved again as a minimum time with the bound released (:meth:`CollocationPlanner._released`):
an optimum above the bound makes the reference ``infeasible``, its duration that optimum's T (the
least time this planner finds, a local optimum, not a proof that no faster slew exists), as a
minimum-time slew of another planner longer than the budget is; ``failed`` stays for a solve that
does not converge. Where the coarse starts (``coarse_intervals``) fail so, the released solve
comes before the full mesh, which is solved under the bound only where the released optimum does not
settle the verdict.
Constraints: actuator bounds (wheel torques, dipoles, torquers), wheel momentum bounds, a body-rate
bound ``max_rate`` (option, per axis), fixed or free final rate, keep-out / keep-in cones (options),
and the controllers' allocation on the controls (:mod:`planners.collocation.allocation`): the wheel
torques are the min-norm allocation ``g = −A⁺ τ`` of their own body torque (no component in the null
space of the working wheels' axes, so their bounds bound ``A⁺ τ`` as the closed loop and the
actuator requirement read it), and the torquers give only what the wheels cannot. Nothing is added
where the allocation is the identity (wheels along three independent axes, torquers alone): those
NLPs are unchanged.
It honours every requirement of the problem (:attr:`CollocationPlanner.honours`): the pointing
constraints ``problem.pointing`` (moving directions and windows included), the actuator limits
tightened by ``problem.actuator_margin`` (the environment's torque is in its model: they bound the
actuators' own torque, what the scenario's actuator requirement measures) and the body-rate norm
``‖ω‖ <= problem.rate_bound(None)`` (the rate requirement ``rate_margin`` lower at first); each
converged reference is checked against them between its points and solved again tighter where it
breaks one (:mod:`planners.collocation.requirements`; see :meth:`CollocationPlanner.plan`).
The transcription (``collocation``: Legendre-Gauss-Radau, or ``multiple_shooting``) comes from
:data:`ocp.transcription.TRANSCRIPTIONS` and owns its layout (bounds, seeding, interpolation); the
NLP (IPOPT or FATROP) is built once per problem structure into the planner's ``SolverCache``.
Starts: the reference of the ``warm_start`` planner (perturbed copies of it per ``multistart``)
and the ``seed_planners``, solved by :func:`ocp.nlp.solve.solve_multistart` (its status policy and early
stopping); the best converged optimum is kept. With ``multistart: auto`` they are solved on
``coarse_intervals`` first and the full mesh once from that optimum and its multipliers (see the
option). For plain bang-bang minimum time (``switch_refinement: auto``) the full mesh is not solved
where the switch-time shooting from the coarse optimum reaches the bang-bang optimum (to its RK4 steps) and
its certificate (:func:`~planners.collocation.certificate.bang_bang_certificate`) is
``certified``: that trajectory is the reference (:meth:`CollocationPlanner._bang_bang`).
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, replace
from typing import Annotated, Any, Literal

import numpy as np

from ocp.dynamics.layout import actuator_blocks
from ocp.errors import InvalidOption, OptionsError
from ocp.fast_call import matrices
from ocp.nlp.certificate import seed_counts
from ocp.nlp.interior_point import for_nlpsol
from ocp.nlp.solve import (
    INFEASIBLE,
    NLPResult,
    perturbed,
    solve_multistart,
    solver_options,
    warm_start_options,
)
from ocp.options import Range
from ocp.transcription import (
    NLP,
    TRANSCRIPTIONS,
    OptimalControlProblem,
    RadauCollocation,
    Transcription,
)
from ocp.transcription.mesh_transfer import transfer_multipliers
from planners.base import REQUIREMENT_TOLERANCE, Planner
from planners.collocation.allocation import (
    allocation_constraints,
    allocation_error,
    with_allocation,
)
from planners.collocation.certificate import (
    SHOOTING_STEPS,
    bang_bang_certificate,
    bound_excess,
    collocation_certificate,
    final_conditions,
    start_violations,
    switch_intervals,
    switching_functions,
    time_error,
)
from planners.collocation.problem import (
    endpoint_cone_error,
    parse_cone,
    variable_bounds,
)
from planners.collocation.reference import (
    CollocationReference,
    bang_bang_solution,
    cone_avoiding_sampler,
    cone_sides,
    seed_sampler,
    solution_sampler,
    switch_mesh,
)
from planners.collocation.requirements import (
    DENSE_POINTS,
    START_TOLERANCE,
    DenseCheck,
    Requirements,
    Tightening,
    dense_check,
    imposed_pointing,
    imposed_state_bounds,
)
from planners.collocation.strategy import (
    AGREE_ATOL,
    AGREE_RTOL,
    AUTO_FIRST,
    AUTO_PIECES,
    AUTO_RESTART,
    COARSE_INTERIOR_POINT,
    COARSE_MIN_TIME_OPTIONS,
    DENSE_ROUNDS,
    POLISH_MU_INIT,
    SEED_BOUND_ATOL,
    SEED_BOUND_RTOL,
    SEED_CONE_PAD,
    SEED_FATROP,
    SEED_TOLERANCE,
    TRANSFER_L1_BARRIER,
    TRANSFER_MAX_INTERVALS,
    TRANSFER_MIN_TIME_BARRIER,
    TRANSFER_WARM_START,
    control_floor,
    merged,
    seed_record,
)
from planners.conformance import check_finite
from planners.errors import ConformanceError
from planners.problem import Array, ManeuverProblem, bound_keys
from planners.reference import FailedReference, Reference
from planners.registry import PLANNERS

SEED_CHECK_POINTS = 129
"""Uniform times on ``[0, T]`` (with the reference's own breakpoints and enforced times) on which a
start reference must be finite before it seeds a solve (:meth:`CollocationPlanner._starts`): a
seed planner registered by a plugin whose reference turns NaN mid-slew was handed to the solver,
which then never returned."""
MAX_RK4_STEPS = 1000
"""Largest ``intervals × substeps`` of ``multiple_shooting``: the NLP build expands every RK4 step
(10 × 100 and 50 × 20 steps built in 20 s on a shared machine, 200 × 100 ran over 120 s; the
default 50 × 4 is 200)."""


@dataclass(frozen=True)
class CollocationOptions:
    """Options of ``collocation`` (YAML keys; see :doc:`/guide/planners` and :doc:`/reference/schema`).

    Attributes
    ----------
    objective : str
        ``min_energy`` ∫‖τ‖² dt (default), ``min_l1`` ∫Σ|τ_i| dt, ``min_time`` (free T, the
        scenario's duration its upper bound: where none is found within it, ``infeasible`` with
        the least T found with the bound released, see the module docstring) or ``weighted`` (with
        a ``time_weight``, free T so bounded and decided so, by that least time); τ the actuators'
        body torque [N m].
    intervals : int
        Mesh intervals.
    degree : int
        Radau points per interval (``collocation``).
    transcription : str
        A registered transcription (:data:`ocp.transcription.TRANSCRIPTIONS`): ``collocation``
        (Legendre-Gauss-Radau, default) or ``multiple_shooting``, or one a user registered.
    substeps : int
        RK4 steps per interval (``multiple_shooting``; ``intervals × substeps`` at most
        :data:`MAX_RK4_STEPS`).
    solver : str
        ``ipopt`` (default) or ``fatrop``.
    warm_start : str
        Registered planner whose reference seeds the NLP (default ``eigenaxis``; ``collocation``
        itself with its own ``warm_start_options``).
    warm_start_options : dict
        The warm-start planner's options.
    seed_planners : "auto" or list of str
        Further planners whose references are starts, each solved after the warm start; the best
        converged optimum is kept. ``auto`` (default): every registered planner that plans in
        milliseconds (:attr:`~planners.base.Planner.cheap`: ``eigenaxis``, ``spin_extremal``)
        and can start it (:meth:`~planners.base.Planner.start_error`), besides the warm
        start, in name order, with its default options; only where the starts are solved on the
        coarse mesh (``coarse_intervals``: ``multistart: auto``, and no cones at a fixed final
        time), none elsewhere. On the spin paper's minimum energy ``spin_extremal``'s start
        reaches 0.018548 where the eigenaxis warm start alone stops at 0.0932. A list: those
        planners (each at most once); ``[]``: the warm start alone. A seed planner that fails or
        raises is skipped and named in ``stats["seeds"]["skipped"]``; ``stats["seeds"]`` records
        the starts tried, how many agreed on the best optimum and where it came from.
    multistart : int or "auto"
        ``auto`` (default): for a free final time a perturbed copy of the warm start
        (:data:`AUTO_FIRST`), then, unless its optimum satisfies the second-order sufficient
        conditions (:mod:`ocp.nlp.second_order`), restarts from the best point perturbed by 5 %
        until one agrees with it (the warm start itself if the copy does not converge); for a
        fixed final time the warm start. n > 0: n perturbed copies; 0: the warm start itself.
    agree : int
        Stop once this many starts agree on the best objective (0: try all); with ``multistart:
        auto``, a best point that satisfies the second-order sufficient conditions counts as one
        of them.
    time_regularization : float
        ``min_time`` only: ε > 0 first solves min T + ε ∫‖τ‖² dt / Σ τ_max² (τ_max the wheels'
        and torquers' torque bounds [N m]) from the starts, then polishes plain minimum time
        from that optimum and its multipliers; 0 (default): off.
    coarse_intervals : int
        With ``multistart: auto``, the starts are first solved on this many intervals (for a
        free final time the whole multistart; for a fixed one only without cones and with at
        least twice as many ``intervals``, and to the looser tolerance
        :data:`~planners.collocation.strategy.SEED_TOLERANCE`: that optimum is only a seed) and the
        full mesh is solved once from that optimum and its multipliers carried over (IPOPT, its
        barrier adaptive for an L1 term without an energy term and, with Mehrotra's probing oracle,
        for minimum time without cones; with ``time_regularization`` the
        regularised optimum, then polished on the full mesh; falling back to that optimum alone
        with the barrier starting at 1e-4, then to the full-mesh solve from the starts); 0 or >=
        ``intervals``: off. Default 8.
    energy_weight, l1_weight, time_weight : float
        Weights of ``weighted`` [1/(N² m² s), 1/(N m s), 1/s].
    max_rate : float or None
        Body-rate bound per axis [rad/s] (a box on ω at the points, not checked between them);
        ``None``: none. The problem's ``max_rate`` (``maneuver.max_rate``, ``requirements.rate``)
        is a bound on the norm ‖ω‖, honoured besides it.
    keep_out, keep_in : list of dict
        Cones ``{boresight (body), direction (inertial), angle_deg}`` over the whole run: constraints
        of this planner's problem, imposed and checked densely as the problem's pointing constraints
        are (named ``keep_out[i]``, ``keep_in[i]`` in ``stats["dense_check"]``), but no requirement
        of a scenario: no row is scored against them (a mission's cone belongs in the scenario's
        ``requirements.pointing``, which every row is scored by and this planner imposes too).
    cone_margin_deg : float
        Every cone (these and the problem's) is imposed this much tighter [deg] at first, so that
        it holds between the points; the dense check tightens further where needed.
    rate_margin : float
        The rate requirement (``requirements.rate.max``, ``ManeuverProblem.rate_requirement``) is
        imposed this fraction lower, in [0, 1) (default 0.01), so that the closed loop tracking the
        reference stays within it (a zero-order-hold loop overshoots a coast at the bound by
        0.03-0.04 %, with a perfect plant); ``maneuver.max_rate`` is imposed as given
        (:meth:`~planners.problem.ManeuverProblem.rate_bound`).
    tolerance : float
        Solver tolerance (scaled KKT error); the coarse seed of a fixed final time
        (``coarse_intervals``) is solved to 1e-5 at the tightest
        (:data:`~planners.collocation.strategy.SEED_TOLERANCE`).
    max_iterations : int
        Solver iterations per start.
    switch_refinement : int or "auto"
        Plain minimum time (no energy or L1 term, no cones or rate bound; Radau collocation,
        IPOPT) only: after the solve on ``intervals``, each mesh interval
        where a control switches (a control between its bounds at a Radau point, or at different
        bounds at two) is split into this many equal intervals and the problem solved once more on
        that non-uniform mesh, from the optimum and its multipliers; its optimum is kept if it
        converges. A switch inside an interval is a jump the control polynomial cannot follow: the
        final time's error is of the order of those intervals' length (XTE: +8.6e-4 s on 50
        intervals, +3.7e-5 s refined by 4). Skipped when no interval or more than a quarter of them
        hold a switch (a singular arc, not bang-bang), or for a problem with cones, a rate bound or
        an energy term (``time_regularization``); ``stats["switch_refinement"]`` records it.
        ``auto`` (default): split in 4 (:data:`~planners.collocation.strategy.AUTO_PIECES`) only where
        the estimated discretisation error of T (``stats["time_error"]``, see ``mesh_tolerance``)
        exceeds ``mesh_tolerance``, else nothing is done and nothing recorded (under every other
        objective too). The error of T falls as the square of the switching intervals' length (XTE:
        8.6e-4 s, 1.6e-4 s split in 2, 3.7e-5 s in 4), so 4 pieces bring an estimate of up to about
        16 times the tolerance within it. Where the refined optimum's estimate is still above
        ``mesh_tolerance``, where no estimate could be made (the shooting's reason) or the refinement
        was skipped or did not converge, the record's ``note`` says so and the reference's message
        repeats it (``within_tolerance`` records the refined estimate's verdict): no tolerance is
        missed silently. Before all this, ``auto`` takes the bang-bang optimum where it can: where the
        estimate applies (see ``mesh_tolerance``) and the coarse mesh was solved first
        (``coarse_intervals``), the switch-time shooting runs from the coarse optimum; where it
        converges, its bang-bang certificate
        (:func:`~planners.collocation.certificate.bang_bang_certificate`) is ``certified`` and the
        trajectory meets the requirements between its points, the reference is that
        bang-bang trajectory (on ``intervals`` intervals with a node at every switch, its states
        integrated) and nothing is solved on ``intervals`` (Bilimoria & Wie 180°: 3.2430833 s, the
        50-interval solve's 3.2431108 s; XTE 28.6304068 s against Betts's 28.6304077 s). Its T is
        that of the same switches flown exactly: the shooting's RK4 error (12 steps per arc, more
        where needed) is estimated by step doubling and taken off the switch times and T (within
        2e-9 s of the optimum found by DOP853 on B&W, the full inertia and XTE).
        ``stats["shooting"]`` records the shooting from the coarse optimum (``time_error``'s record,
        its ``estimate_s`` the coarse T's error, ``from_intervals``, ``used`` and, where not,
        ``why``), ``stats["certificate"]`` is then the bang-bang certificate and
        ``stats["iterations"]`` the coarse solve's. 0: off (the plain ``intervals`` solve, no
        shooting); n >= 2: always (never the shot trajectory); another objective, transcription
        or solver, or 1, is refused.
    mesh_tolerance : float
        With ``switch_refinement: auto``, the estimated discretisation error of a bang-bang minimum
        time [s] above which the intervals holding a switch are split (default 1e-4 s, the agreement
        the benchmark suite asks of a published minimum time; a slew's duration is commanded to
        the controller's sample, milliseconds, far coarser). The estimate
        (:func:`~planners.collocation.certificate.time_error`, ``stats["time_error"]`` and the
        reference's message, reported whatever the option) is ``T_N`` minus the final time of the
        exact bang-bang trajectory with the solution's switches, found by Newton's method on the
        switch times, iterated until the final miss and the stationarity at the point returned are
        below 1e-10, the RK4 steps' error then taken off by step doubling (``stats["time_error"]``
        records them, the switch times, ``steps_per_arc`` and ``rk4_correction_s``): it is ``T_N``
        minus the exact minimum time for those switches (within 2e-9 s of DOP853's on Bilimoria &
        Wie, the full inertia and XTE; before the correction the RK4 optimum was 1.6e-6 s off on
        XTE), whatever the mesh (full inertia on 10 to 36 intervals: its shooting T the same to
        1e-9 s). Where it cannot be had (a switch or T moved by more than a
        mesh interval, no convergence, varying control bounds, wheels, cones, a rate bound) nothing
        is refined, and under ``auto`` the reason is recorded and in the message.
    """

    objective: Literal["min_energy", "min_l1", "min_time", "weighted"] = "min_energy"
    intervals: Annotated[int, Range(ge=1, le=2000)] = 50
    degree: Annotated[int, Range(ge=1, le=9)] = 3
    transcription: str = "collocation"       # a key of ocp.transcription.TRANSCRIPTIONS
    substeps: Annotated[int, Range(ge=1, le=100)] = 4       # RK4 steps per interval (multiple_shooting)
    solver: Literal["ipopt", "fatrop"] = "ipopt"
    warm_start: str = "eigenaxis"            # registered planner whose reference seeds the NLP
    warm_start_options: dict = field(default_factory=dict)  # its options, e.g. {profile: min_time}
    seed_planners: list[str] | Literal["auto"] = "auto"
    multistart: Annotated[int | Literal["auto"], Range(ge=0, le=50)] = "auto"
    agree: Annotated[int, Range(ge=0, le=50)] = 2  # stop once this many starts agree on the best optimum (0: try all)
    time_regularization: Annotated[float, Range(ge=0.0, le=1.0)] = 0.0
    coarse_intervals: Annotated[int, Range(ge=0, le=2000)] = 8
    energy_weight: Annotated[float, Range(ge=0.0)] = 1.0               # for objective "weighted"
    l1_weight: Annotated[float, Range(ge=0.0)] = 0.0
    time_weight: Annotated[float, Range(ge=0.0)] = 0.0
    max_rate: Annotated[float | None, Range(gt=0.0)] = None  # rad/s, per body axis (the problem's: the norm)
    keep_out: list[dict] = field(default_factory=list)  # {boresight, direction, angle_deg}
    keep_in: list[dict] = field(default_factory=list)
    cone_margin_deg: Annotated[float, Range(ge=0.0, lt=90.0)] = 0.01            # cones are imposed this much tighter, so that they
                                             # hold between the points where they are imposed
    rate_margin: Annotated[float, Range(ge=0.0, lt=1.0)] = 0.01  # the rate requirement is imposed this fraction lower
    tolerance: Annotated[float, Range(gt=0.0, lt=1.0)] = 1e-10
    max_iterations: Annotated[int, Range(ge=1, le=100000)] = 500
    switch_refinement: Annotated[int | Literal["auto"], Range(ge=0, le=16)] = "auto"
    mesh_tolerance: Annotated[float, Range(gt=0.0)] = 1e-4  # s: the estimated error of T that auto refines

    def __post_init__(self) -> None:

        # A collocation warm start is planned with its own options (say min_energy, itself warm
        # started from eigenaxis): the way into min_time where a kinematic seed is too far
        # (two wheels). Only its own warm start may nest further; the depth is the YAML's.
        listed = [] if self.seed_planners == "auto" else list(self.seed_planners)
        for index, name in enumerate([self.warm_start, *listed]):
            if name not in PLANNERS or (name == "collocation" and index > 0):
                where = "warm_start" if index == 0 else f"seed_planners[{index - 1}]"
                raise InvalidOption(where, f"{name!r} is not another registered planner; expected one of "
                                           f"{sorted(set(PLANNERS) - {'collocation'})} (or collocation as warm_start)")
        for index, name in enumerate(listed):
            if name in listed[:index]:  # the same reference again: the same start solved twice
                raise InvalidOption(f"seed_planners[{index}]", f"{name!r} is listed twice; expected each planner once")
        if self.transcription not in TRANSCRIPTIONS:
            raise InvalidOption("transcription", f"{self.transcription!r} is not a registered transcription; "
                                                 f"expected one of {sorted(TRANSCRIPTIONS)}")
        if self.transcription == "multiple_shooting" and self.intervals * self.substeps > MAX_RK4_STEPS:
            raise InvalidOption("substeps", f"{self.intervals} intervals x {self.substeps} substeps = "
                                            f"{self.intervals * self.substeps} RK4 steps; expected at most "
                                            f"{MAX_RK4_STEPS} (every step is expanded into the NLP)")
        try:
            PLANNERS[self.warm_start](self.warm_start_options, path="warm_start_options")
        except OptionsError as error:
            raise InvalidOption(error.path, error.message) from None
        if self.time_regularization and self.objective != "min_time":
            raise InvalidOption("time_regularization", f"applies to objective min_time only, not {self.objective!r}")
        if self.switch_refinement != "auto" and self.switch_refinement:
            refusal = (f"objective {self.objective!r}" if self.objective != "min_time" else
                       f"transcription {self.transcription!r}" if not TRANSCRIPTIONS[self.transcription].non_uniform
                       else f"solver {self.solver!r}" if self.solver != "ipopt" else
                       "1 piece per interval" if self.switch_refinement == 1 else None)
            if refusal is not None:
                raise InvalidOption("switch_refinement", f"{self.switch_refinement} applies to objective min_time "
                                                         f"on radau collocation with IPOPT, split in 2 to 16; not "
                                                         f"to {refusal} (0: off; auto: where the estimated error "
                                                         f"of T exceeds mesh_tolerance)")
        if self.objective == "weighted" and not (self.energy_weight or self.l1_weight or self.time_weight):
            raise InvalidOption("objective", "weighted needs a positive energy_weight, l1_weight or time_weight")
        l1 = self.objective == "min_l1" or (self.objective == "weighted" and self.l1_weight > 0)
        refused = TRANSCRIPTIONS[self.transcription].problem_error(l1, bool(self.keep_out or self.keep_in))
        if refused:
            raise ValueError(refused)
        for index, spec in enumerate(self.keep_out):
            parse_cone(spec, True, np.deg2rad(self.cone_margin_deg), f"keep_out[{index}]")
        for index, spec in enumerate(self.keep_in):
            parse_cone(spec, False, np.deg2rad(self.cone_margin_deg), f"keep_in[{index}]")


_Mode = Literal["cold", "warm", "near_optimum", "transfer"]


@dataclass
class _Optimum:
    """What :meth:`CollocationPlanner._optimum` found: the solve, its extra stats, the transcription
    and NLP it was solved on, their number of intervals and, with ``time_regularization``, the
    regularised solve it was polished from."""

    result: NLPResult
    extra: dict
    transcription: Transcription
    nlp: NLP
    intervals: int
    regularized: NLPResult | None = None
    solver: str | None = None  # None: the option's
    switching: tuple | None = None  # switching_functions() of the result, where computed (shared by the certificate)
    exact: CollocationReference | None = None  # the exact bang-bang optimum shot from this coarse one (_bang_bang)
    deferred: Reference | None = None  # the coarse mesh's failure at the time bound, the full mesh not tried (_optimum)


class CollocationPlanner(Planner):
    """Direct optimal control planner (see the module docstring).

    How it honours the problem's requirements (:attr:`honours`): before any solve, a pointing
    constraint that the initial attitude (at t = 0) or the final one (at t = T) breaks inside its
    window is a failed reference naming it. After each successful solve the reference is checked
    on :data:`~planners.collocation.requirements.DENSE_POINTS` points per mesh interval against the
    requirements as stated (:func:`~planners.collocation.requirements.dense_check`: pointing
    margins, the body-rate norm, the actuator limits less ``actuator_margin``; the controls read
    saturated at the bounds imposed, as the reference gives them); what it breaks is
    imposed tighter (:meth:`~planners.collocation.requirements.Tightening.after`) and solved again
    from the solution and its multipliers, at most :data:`~planners.collocation.strategy.DENSE_ROUNDS`
    times. A reference that still breaks one keeps its status (it is a solution, only not within
    the requirement everywhere); its message states the residual violation, and
    ``stats["dense_check"]`` records the rounds, the least margins [deg] and the violations (a
    scenario scores such a row violated). A start whose boresight enters a keep-out cone is bent
    round it first (:meth:`_seeds`).
    """

    name = "collocation"
    example_options = ({"intervals": 20}, {"intervals": 20, "transcription": "multiple_shooting"})
    honours = frozenset({"pointing", "actuators", "rate"})

    class Options(CollocationOptions):
        __doc__ = CollocationOptions.__doc__

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
            True for ``min_time`` and for ``weighted`` with a positive ``time_weight``.
        """
        objective = getattr(options, "objective", None)
        return objective == "min_time" or (objective == "weighted" and getattr(options, "time_weight", 0.0) > 0)

    def problem_error(self, problem: ManeuverProblem) -> str | None:
        """Why collocation cannot take ``problem``.

        Parameters
        ----------
        problem : ManeuverProblem
            The problem to plan.

        Returns
        -------
        str or None
            The reason (no target attitude; an objective without an energy term (time or L1
            alone) on an actuator whose control has no bound: the optimum is then impulses, a
            rest-to-rest slew in no time; a transcription that cannot impose the pointing or rate
            requirements, or the controllers' allocation on the controls,
            :func:`~planners.collocation.allocation.allocation_error`), or ``None``.
        """
        error = super().problem_error(problem)
        o = self.options
        energy = o.objective == "min_energy" or (o.objective == "weighted" and o.energy_weight > 0)
        if error is None and not energy:  # time or an L1 term alone: the optimum rides the control bounds
            unbounded = [actuator for actuator in problem.spacecraft.actuators
                         if not all(np.all(np.isfinite(bound)) for bound in actuator.control_bounds())]
            if unbounded:
                names = bound_keys(unbounded)
                what = f"objective {o.objective}" + (" without energy_weight" if o.objective == "weighted" else "")
                return (f"{what} needs a bound on every actuator's control ({names}): without an energy term the "
                        f"optimal torque is unbounded, impulses (min_time: a slew in no time; min_l1: the torque "
                        f"grows with the mesh)")
        if error is None:
            error = allocation_error(problem.spacecraft, o.transcription)
            if error is not None:
                return f"options.transcription: {error}"
        if error is None and (problem.pointing or problem.rate_bound(None) is not None):
            l1 = o.objective == "min_l1" or (o.objective == "weighted" and o.l1_weight > 0)
            refused = TRANSCRIPTIONS[o.transcription].problem_error(l1, True)
            if refused:
                return f"options.transcription: {refused} (the pointing or rate requirements are path constraints)"
        return error

    def _requirements(self, problem: ManeuverProblem) -> Requirements:
        """The problem's requirements and the options' cones, as stated."""
        o = self.options
        cones = tuple(parse_cone(c, True, where=f"keep_out[{i}]") for i, c in enumerate(o.keep_out))
        cones += tuple(parse_cone(c, False, where=f"keep_in[{i}]") for i, c in enumerate(o.keep_in))
        return Requirements(tuple(problem.pointing) + cones, problem.rate_bound(None), problem.actuator_margin)

    def _ocp(self, problem: ManeuverProblem, tightening: Tightening | None = None) -> OptimalControlProblem:
        """The optimal-control problem, its requirements imposed with ``tightening`` (default the
        first solve's: the cones by ``cone_margin_deg``); a ``ValueError`` names a cone that the
        tightening leaves empty."""
        o = self.options
        weights = {"min_energy": (1.0, 0.0, 0.0), "min_l1": (0.0, 1.0, 0.0), "min_time": (0.0, 0.0, 1.0),
                   "weighted": (o.energy_weight, o.l1_weight, o.time_weight)}[o.objective]
        free_time = weights[2] > 0
        requirements = self._requirements(problem)
        if tightening is None:
            tightening = Tightening.initial(requirements, float(np.deg2rad(o.cone_margin_deg)),
                                            problem.rate_bound(None, o.rate_margin))
        cones = imposed_pointing(requirements, tightening, None if free_time else problem.duration / o.intervals,
                                 problem.duration)
        max_rate = None if requirements.max_rate is None else requirements.max_rate * (1.0 - tightening.rate)
        return OptimalControlProblem(problem.model, *weights, free_time=free_time,
                                     fixed_final_rate=problem.omegaf is not None, cones=cones, max_rate=max_rate)

    def _nlp(self, problem: ManeuverProblem, ocp: OptimalControlProblem, mode: _Mode = "cold",
             intervals: int | None = None, solver: str | None = None,
             mesh: Array | None = None) -> tuple[Transcription, NLP]:
        """The transcription on ``intervals`` (default the option) and its built NLP for ``ocp``
        (from the cache when built before). ``mode``: the solver options of a start from a point
        alone (``cold``), with its multipliers (``warm``, :func:`ocp.nlp.solve.warm_start_options`), near
        the optimum (``near_optimum``: IPOPT's barrier starts at :data:`POLISH_MU_INIT`) or with the
        multipliers of a coarse-mesh optimum (``transfer``: :data:`TRANSFER_WARM_START`, with
        :data:`TRANSFER_L1_BARRIER` for an L1 objective without an energy term and
        :data:`TRANSFER_MIN_TIME_BARRIER` for minimum time without cones; the cold starts of minimum time
        without cones on ``coarse_intervals`` with :data:`COARSE_MIN_TIME_OPTIONS`). A fixed final
        time on other than the option's ``intervals`` is the coarse seed: solved to
        :data:`SEED_TOLERANCE` at the least (by FATROP with :data:`SEED_FATROP` where
        :meth:`_seed_solver` chooses it for the ``solver`` option IPOPT; a ``solver: fatrop`` seed
        keeps FATROP's defaults). ``solver``: ``None`` for the option's. ``mesh``: the nodes of a
        non-uniform mesh as fractions of T (then ``intervals`` is its number of intervals)."""
        o = self.options
        intervals = (o.intervals if intervals is None else intervals) if mesh is None else len(mesh) - 1
        solver = o.solver if solver is None else solver
        if solver != "ipopt" and mode in ("near_optimum", "transfer"):
            mode = "cold"
        seed_only = intervals != o.intervals and not ocp.free_time
        tolerance = max(o.tolerance, SEED_TOLERANCE) if seed_only else o.tolerance
        extra = {"cold": None, "warm": warm_start_options(solver), "near_optimum": {"ipopt.mu_init": POLISH_MU_INIT},
                 "transfer": warm_start_options(solver, **TRANSFER_WARM_START)}[mode]
        if mode == "transfer" and ocp.l1_weight > 0 and ocp.energy_weight == 0:
            extra = {**(extra or {}), **TRANSFER_L1_BARRIER}
        elif mode == "transfer" and ocp.free_time and not (ocp.energy_weight or ocp.l1_weight or ocp.cones):
            extra = {**(extra or {}), **TRANSFER_MIN_TIME_BARRIER}
        if mode == "cold" and mesh is None and self._coarse_min_time(ocp, intervals, solver):
            extra = {**(extra or {}), **COARSE_MIN_TIME_OPTIONS}
        if seed_only and solver == "fatrop" and o.solver == "ipopt":  # the IPOPT option's FATROP seed only
            extra = {**(extra or {}), **SEED_FATROP}
        # The extra options in the key: a shared cache also serves planners whose options differ
        # (a FATROP seed with SEED_FATROP and a FATROP mesh without it can share all else).
        key = (ocp.energy_weight, ocp.l1_weight, ocp.time_weight, ocp.free_time, ocp.fixed_final_rate, ocp.cones,
               ocp.max_rate, o.transcription, intervals, o.degree, o.substeps, solver, tolerance, o.max_iterations, mode,
               tuple(sorted((extra or {}).items())), None if mesh is None else tuple(mesh))

        def build() -> tuple[Transcription, NLP]:
            # the transcription is built here, once per entry (its constructor is not free)
            same = intervals == o.intervals
            transcription = TRANSCRIPTIONS[o.transcription].from_options(o if same else replace(o, intervals=intervals))
            if mesh is not None:
                transcription = transcription.with_mesh(mesh)
            rows = allocation_constraints(problem.spacecraft)  # the controls as the allocation gives them
            if rows is not None:
                transcription = with_allocation(transcription, rows)
            return transcription, transcription.build(ocp, solver, solver_options(solver, tolerance, o.max_iterations, extra))

        # The model's numbers are baked into the graph: a shared cache needs them in the key.
        return self.solver_cache(problem).get(("collocation", problem.model.fingerprint, key), build)

    def _coarse_min_time(self, ocp: OptimalControlProblem, intervals: int, solver: str) -> bool:
        """Whether a solve on ``intervals`` by ``solver`` is a cold start of minimum time on the coarse
        mesh that :data:`COARSE_MIN_TIME_OPTIONS` tune (a free final time, no energy or L1 term, no
        cones; IPOPT)."""
        return (solver == "ipopt" and intervals == self.options.coarse_intervals and ocp.free_time
                and not (ocp.energy_weight or ocp.l1_weight or ocp.cones))

    def _variable_bounds(self, problem: ManeuverProblem,
                         tightening: Tightening | None = None) -> tuple[Array, Array, Array, Array]:
        """Per-point bounds of the model state and the actuator controls: the actuators' limits
        scaled by ``1 − actuator_margin`` and by ``1 − tightening.actuators``, their states'
        imposed inside the solver's relaxation (:func:`~planners.collocation.requirements.imposed_state_bounds`)."""
        scale = 1.0 - (problem.actuator_margin or 0.0)
        if tightening is not None:
            scale *= 1.0 - tightening.actuators
        x_low, x_high, u_low, u_high = variable_bounds(problem, self.options.max_rate, scale)
        return (*imposed_state_bounds(x_low, x_high, problem.initial_state), u_low, u_high)

    def _seed_names(self, problem: ManeuverProblem) -> list[str]:
        """The seed planners: the option's list, or with ``seed_planners: auto`` every registered
        planner but this one and the warm start that is :attr:`~planners.base.Planner.cheap` and
        accepts ``problem`` (with its default options), in name order, where the starts are solved
        on the coarse mesh (:meth:`_coarse`), none elsewhere: there a seed would cost a full-mesh
        solve (the 12U CubeSat's fixed-time keep-out, solved on the full mesh: the same optimum
        from one more start, at 1.8 times the plan time)."""
        o = self.options
        if o.seed_planners != "auto":
            return list(o.seed_planners)
        try:
            coarse = self._coarse(self._ocp(problem))
        except ValueError:  # a cone left empty: no plan (_plan says why)
            coarse = False
        if not coarse:
            return []
        names = []
        for name in sorted(PLANNERS):
            cls = PLANNERS[name]
            if name in (self.name, o.warm_start) or not cls.cheap:
                continue
            try:
                refused = cls(None, cache=self.cache).start_error(problem)
            except Exception as error:  # noqa: BLE001 (a planner that cannot judge the problem is no seed)
                refused = str(error)
            if refused is None:
                names.append(name)
        return names

    def _starts(self, problem: ManeuverProblem, failures: list[str] | None = None) -> list[Reference]:
        """The references of the warm start and the seed planners (:meth:`_seed_names`) that
        planned; a planner that fails or raises, or whose reference is not finite on
        :data:`SEED_CHECK_POINTS` times or raises when sampled
        (:func:`planners.conformance.check_finite`), is skipped, its ``planner: message`` appended
        to ``failures`` when given."""
        starts = []
        requested = [(self.options.warm_start, self.options.warm_start_options)]
        requested += [(name, None) for name in self._seed_names(problem)]
        for name, options in requested:
            try:
                reference = PLANNERS[name](options, cache=self.cache).plan_start(problem)
            except Exception as error:  # noqa: BLE001 (a seed is optional: its crash is recorded, not raised)
                if failures is not None:
                    failures.append(f"{name}: raised {type(error).__name__}: {error}")
                continue
            if not reference.ok:
                if failures is not None:
                    failures.append(f"{name}: {reference.message}")
                continue
            try:  # a seed with a NaN would reach the solver (a plugin's reference, say), where it can hang
                check_finite(reference, SEED_CHECK_POINTS, after_end=False)
            except ConformanceError as error:
                if failures is not None:
                    failures.append(f"{name}: {error}")
                continue
            except Exception as error:  # noqa: BLE001 (its sampling raised: recorded, as a planner's crash above)
                if failures is not None:
                    failures.append(f"{name}: sampling its reference raised {type(error).__name__}: {error}")
                continue
            starts.append(reference)
        return starts

    def _guesses(self, problem: ManeuverProblem, ocp: OptimalControlProblem, transcription: Transcription, nlp: NLP,
                 seeds: list[Array], alternates: list[Array] | None = None,
                 labels: list[str] | None = None) -> tuple[list[Array], list[Array], float, list[str]]:
        """The starts (the warm start or its perturbed copies, then the seed planners' starts), the
        fallback starts (tried only if none of those converged: ``alternates`` last), the
        relative size of the restarts from the best point (0: none) and where each start and
        fallback comes from (from ``labels``, one per seed then per alternate; default
        ``start i``)."""
        alternates = list(alternates or [])
        if labels is None:
            labels = [f"start {i}" for i in range(len(seeds) + len(alternates))]
        starts, fallback, restart, names = self._policy(problem, ocp, transcription, nlp, seeds, labels[:len(seeds)])
        return starts, fallback + alternates, restart, names + labels[len(seeds):]

    def first_start(self, problem: ManeuverProblem) -> tuple[Array, NLP, str]:
        """The first start of the multistart on the ``intervals`` mesh, for tools that start where
        this planner starts (the benchmark's peers): the ``warm_start`` planner's reference as a
        decision vector, as :meth:`plan` seeds it, then as the ``multistart`` policy makes its first
        start (with ``auto`` and a free final time a copy perturbed by
        :data:`~planners.collocation.strategy.AUTO_FIRST`; the noise of
        :func:`ocp.nlp.solve.perturbed` has seed 0, so every call gives the same vector).

        Parameters
        ----------
        problem : ManeuverProblem
            The problem.

        Returns
        -------
        tuple
            The decision vector (the stage-wise layout of :mod:`ocp.transcription.base`), the NLP it
            belongs to (its ``n_stage_state``, ``n_interval`` and ``free_time`` read the layout) and
            where the start comes from (e.g. ``"eigenaxis perturbed 1"``).

        Raises
        ------
        ValueError
            The warm-start planner does not plan the problem, or a pointing constraint leaves no
            cone.
        """
        o = self.options
        ocp = self._ocp(problem)
        transcription, nlp = self._nlp(problem, ocp)
        reference = PLANNERS[o.warm_start](o.warm_start_options, cache=self.cache).plan_start(problem)
        if not reference.ok:
            raise ValueError(f"no first start: the warm-start planner {o.warm_start!r} failed ({reference.message})")
        seeds, _, labels = self._seeds(problem, ocp, transcription, nlp, [reference])
        starts, _, _, names = self._guesses(problem, ocp, transcription, nlp, seeds, labels=labels[:len(seeds)])
        return starts[0], nlp, names[0]

    def _policy(self, problem: ManeuverProblem, ocp: OptimalControlProblem, transcription: Transcription, nlp: NLP,
                seeds: list[Array], labels: list[str]) -> tuple[list[Array], list[Array], float, list[str]]:
        """The ``multistart`` policy of :meth:`_guesses` (the labels of its starts, then of its
        fallbacks, last)."""
        count = self.options.multistart
        if count == "auto":
            # A warm start can sit exactly on a stationary point (the eigenaxis slew is one for minimum
            # time with per-axis torque bounds: IPOPT stays there, 3.5449 in 191 iterations against
            # 3.2431 for Bilimoria & Wie's slew). A perturbed copy of it (AUTO_FIRST), then 5 %
            # restarts from the best point unless it satisfies the second-order conditions (a saddle
            # does not), escape such points; the warm start itself is the fallback when its
            # perturbed copy does not converge.
            if ocp.free_time:
                floor = control_floor(transcription, ocp, nlp, *self._variable_bounds(problem)[2:])
                first = perturbed(seeds[0], 1, scales=(AUTO_FIRST, AUTO_FIRST), floor=floor)
                return (first + seeds[1:], seeds[:1], AUTO_RESTART,
                        [f"{labels[0]} perturbed 1", *labels[1:], labels[0]])
            return seeds, [], 0.0, list(labels)
        if not count:
            return seeds, [], 0.0, list(labels)
        copies = [f"{labels[0]} perturbed {k + 1}" for k in range(count)]
        return perturbed(seeds[0], count) + seeds[1:], [], 0.0, copies + labels[1:]

    def _regularized(self, problem: ManeuverProblem, ocp: OptimalControlProblem) -> OptimalControlProblem:
        """``ocp`` (minimum time) with the energy term of ``time_regularization``: weight ε over the
        sum of the squared torque bounds of the wheels and torquers (1 (N m)² without them)."""
        _, _, _, u_high = self._variable_bounds(problem)
        slices = problem.model.control_slices
        bounds = [u_high[slices[name]] for name in ("wheels", "torquers") if name in slices]
        scale = float(np.sum(np.square(np.concatenate(bounds)))) if bounds else 0.0
        scale = scale if 0.0 < scale < np.inf else 1.0
        return replace(ocp, energy_weight=self.options.time_regularization / scale)

    def _solve(self, problem: ManeuverProblem, ocp: OptimalControlProblem, seeds: list[Array], params: Array,
               bounds: tuple[Array, Array], intervals: int, near_optimum: bool = False,
               solver: str | None = None, alternates: list[Array] | None = None,
               labels: list[str] | None = None) -> tuple[NLPResult, dict, NLPResult | None]:
        """Solve ``ocp`` on ``intervals`` from ``seeds`` by the multistart policy (``near_optimum``:
        from the one seed given, near the optimum, see :meth:`_nlp`); with ``time_regularization``,
        solve the regularised problem so and polish plain minimum time from its optimum and
        multipliers (the regularised solve is returned third, ``None`` without one); ``solver`` as
        in :meth:`_nlp`; ``alternates``: further fallback starts and ``labels`` where the seeds and
        alternates come from (:meth:`_seeds`). The extra stats of a multistart hold ``seeds``
        (:func:`~planners.collocation.strategy.seed_record`)."""
        o = self.options
        transcription, nlp = self._nlp(problem, ocp, "near_optimum" if near_optimum else "cold", intervals, solver)
        guesses, fallback, restart, names = ((seeds, [], 0.0, []) if near_optimum
                                             else self._guesses(problem, ocp, transcription, nlp, seeds, alternates,
                                                                labels))
        agree = 1 if near_optimum else o.agree
        lbx, ubx = bounds
        if not o.time_regularization:
            solving: Any = nlp.solver  # the nlpsol, or its stand-in (solve_multistart takes either)
            if (not near_optimum and self._coarse_min_time(ocp, intervals, o.solver if solver is None else solver)
                    and np.array_equal(nlp.lbg, nlp.ubg)):
                # IPOPT's iterates on a compiled factorisation (COARSE_INTERIOR_POINT), IPOPT where unavailable
                solving = for_nlpsol(nlp.solver, o.tolerance, COARSE_INTERIOR_POINT, o.max_iterations) or nlp.solver
            result = solve_multistart(solving, guesses, p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg,
                                      agree=agree, restart=restart, fallback=fallback, second_order=restart > 0,
                                      rtol=AGREE_RTOL, atol=AGREE_ATOL)
            return result, {} if near_optimum else {"seeds": seed_record(result, len(guesses), names)}, None
        _, regular = self._nlp(problem, self._regularized(problem, ocp), intervals=intervals)
        first = solve_multistart(regular.solver, guesses, p=params, lbx=lbx, ubx=ubx, lbg=regular.lbg, ubg=regular.ubg,
                                 agree=agree, restart=restart, fallback=fallback, second_order=restart > 0,
                                 rtol=AGREE_RTOL, atol=AGREE_ATOL)
        extra = {"regularized": first.stats()}
        if not near_optimum:
            extra["seeds"] = seed_record(first, len(guesses), names)
        return self._polished(problem, ocp, first, params, bounds, intervals), extra, first

    def _polished(self, problem: ManeuverProblem, ocp: OptimalControlProblem, regularized: NLPResult, params: Array,
                  bounds: tuple[Array, Array], intervals: int) -> NLPResult:
        """Plain minimum time from the optimum of the regularised problem and its multipliers
        (``regularized`` itself when it failed)."""
        if regularized.x is None:
            return regularized
        _, polish = self._nlp(problem, ocp, "warm", intervals)
        return solve_multistart(polish.solver, [regularized.x], p=params, lbx=bounds[0], ubx=bounds[1],
                                lbg=polish.lbg, ubg=polish.ubg, agree=1, lam_x0=regularized.lam_x,
                                lam_g0=regularized.lam_g)

    def _coarse(self, ocp: OptimalControlProblem) -> bool:
        """Whether to solve on ``coarse_intervals`` first: with ``multistart: auto``, for a free final
        time (the escape from stationary points) and for a fixed one without cones with at least
        twice as many intervals (a cheap seed near the optimum; cones are imposed at fewer points on
        a coarse mesh, so its optimum may cut through one)."""
        o = self.options
        if ocp.free_time:
            return o.multistart == "auto" and 0 < o.coarse_intervals < o.intervals
        # A fixed final time gains only when the full mesh is several times the coarse one.
        return o.multistart == "auto" and 0 < 2 * o.coarse_intervals <= o.intervals and not ocp.cones

    def _seed_solver(self, ocp: OptimalControlProblem) -> str:
        """The solver of the coarse seed: FATROP (with :data:`SEED_FATROP`) for a fixed final time
        without an L1 term when the option's solver is IPOPT and the transcription's
        ``fatrop_seed`` says so, else the option's."""
        o = self.options
        if (o.solver == "ipopt" and not ocp.free_time and ocp.l1_weight == 0
                and TRANSCRIPTIONS[o.transcription].fatrop_seed):
            return "fatrop"
        return o.solver

    def _plan(self, problem: ManeuverProblem) -> Reference:
        unreachable = problem.unreachable()  # proven by momentum conservation: no solve can reach it
        if unreachable:
            return FailedReference(self.name, unreachable, "infeasible")
        try:
            ocp = self._ocp(problem)
        except ValueError as error:
            return FailedReference(self.name, f"a pointing constraint leaves no cone once tightened by "
                                              f"cone_margin_deg: {error}")
        broken = endpoint_cone_error(ocp.cones, problem.q0, problem.qf, problem.duration, ocp.free_time)
        if broken:
            return FailedReference(self.name, f"no trajectory meets the pointing constraints: {broken}")
        failures: list[str] = []
        starts = self._starts(problem, failures)
        if not starts:
            return FailedReference(self.name, f"no start: the warm-start planner {self.options.warm_start!r} failed ("
                                              + "; ".join(failures) + ")")
        timed = self.minimises_time(self.options)
        reference = self._plan_from(problem, starts, defer=timed)
        if not (reference.ok or not timed):
            reference = self._released(problem, reference, starts, failures)
        else:
            _skipped(reference, failures)
        warm = self.options.warm_start
        unused = [failure[len(warm) + 2:] for failure in failures if failure.startswith(f"{warm}: ")]
        if unused:  # the start the user named did not plan: the row says so, not only the stats
            reference.message += f"; the warm start {warm!r} was not used ({unused[0]})"
        return reference

    def _released(self, problem: ManeuverProblem, failed: Reference, starts: list[Reference],
                  failures: list[str]) -> Reference:
        """A minimum time (or a ``weighted`` objective with a time term) that failed at its bound,
        decided by the minimum time with the bound released.

        Where no start converged under ``maneuver.duration`` (the bound on the free final time), some
        ended locally infeasible or at the bound, and a feasible slew of the problem longer than the
        bound is known (:meth:`_time_bound`: ``eigenaxis``'s ``min_time``, checked against the
        problem's constraints), the same problem is planned again as a minimum time (``weighted``
        too: its problem under the bound admits a slew exactly where the least feasible time is
        within the bound, whatever its weights) with its bound at that slew's duration ``D`` (a
        bound that admits a slew; nothing else of the problem changes: with a free final time the
        pointing windows are imposed over the whole run). Where that converges to
        ``T* > maneuver.duration``, the reference is ``infeasible``, its ``duration`` ``T*`` and its
        stats the released optimum's (its certificate, and ``time_bound``: the bound, ``D``, where
        ``D`` came from, the mesh the bound was tried on, ``T*`` and the statuses at the bound):
        this planner's least time is longer than the budget, as a minimum-time ``costate_tpbvp`` or
        ``eigenaxis`` slew longer than it is (:func:`scenarios.requirements.scoring.late_slew`), and
        the row's ``needed_duration_s`` is ``T*`` (:func:`scenarios.runner.needed_duration`). ``T*``
        is a local optimum, whatever its certificate says of it: the least time this planner finds,
        not a proof that no faster slew exists, and the message says so. Where a minimum time's
        released solve converges within the bound, its optimum is the bounded problem's too (the
        starts under the bound failed on a mesh whose optimum lies above the exact one): it is the
        reference, ``ok``, its stats' ``time_bound`` saying so. Where the released solve does not
        converge, or a ``weighted`` objective's minimum time lies within the bound (not its
        optimum) and its own solves under the bound fail, the reference stays ``failed`` (a
        numerical failure, not a verdict on the budget), its message saying what the released solve
        did.

        The starts under the bound are the coarse multistart's where it failed so
        (:meth:`_optimum`'s ``defer``): the full-mesh attempts under the bound (from the starts
        again, costlier per iteration; Bilimoria & Wie 180° under 3 s: 906 iterations) are made
        only where the released solve does not settle the verdict (it fails, or its ``T*`` is
        within the bound: the full mesh may then converge under it, as the coarse one did not), and
        the reference is theirs as without the deferral."""
        record = failed.stats.get("time_bound")
        if failed.status != "failed" or not isinstance(record, dict) or "feasible_s" not in record:
            _skipped(failed, failures)
            return failed
        bound, (released, label) = float(problem.duration), (float(record["feasible_s"]), str(record["feasible_from"]))
        o = self.options
        timer = self
        if o.objective != "min_time":  # weighted: the least feasible time is the minimum time's
            timer = copy.copy(self)
            timer.options = replace(o, objective="min_time")
        wider = replace(problem, duration=released)
        refused = None if timer is self else timer.problem_error(wider)  # min_time refuses unbounded controls
        found_starts = [] if refused else timer._starts(wider)
        found = (timer._plan_from(wider, found_starts) if found_starts
                 else FailedReference(self.name, refused or "no start"))
        if found.ok and timer is self and not float(found.duration) > bound:
            # the released minimum time lies within the bound: it is the bounded problem's optimum too
            # (the same problem, its final time admitted by both bounds); the discretised optima above it
            # (coarse mesh, full mesh) are what failed under the bound
            _skipped(found, failures)
            found.stats["time_bound"] = {**record, "released_ok": True, "released_T_s": float(found.duration),
                                         "bounded_status": failed.stats.get("solver_status")}
            found.message += (f"; the starts under maneuver.duration = {bound:.10g} s failed on the "
                              f"N={record.get('intervals')} mesh (a mesh's optimum may lie above the exact one): "
                              f"this optimum, found with the bound released to {released:.6g} s ({label}'s "
                              f"feasible slew), is within the bound")
            return found
        if record.get("intervals") != o.intervals and not (found.ok and float(found.duration) > bound):
            # deferred on the coarse mesh: the full mesh under the bound, as it would have been solved
            failed = self._plan_from(problem, starts, resumed=failed)
            _skipped(failed, failures)
            record = failed.stats.get("time_bound")
            if failed.status != "failed" or not isinstance(record, dict) or "feasible_s" not in record:
                return failed
        else:
            _skipped(failed, failures)
        minimum = "minimum time" if timer is self else "minimum time (objective min_time)"
        it = "it" if timer is self else f"its {minimum}"
        record = {**record, "released_ok": found.ok, "bounded_status": failed.stats.get("solver_status")}
        if timer is not self:
            record["released_objective"] = "min_time"
        failed.stats["time_bound"] = record
        if not found.ok:
            failed.message += (f"; with the bound released to {released:.6g} s ({label}'s feasible slew) {it} "
                               f"did not converge either: {found.message}")
            return failed
        T = float(found.duration)
        record["released_T_s"] = T
        if not T > bound:
            failed.message += (f"; with the bound released to {released:.6g} s ({label}'s feasible slew) {it} "
                               f"converged to T = {T:.8g} s, within the bound: the starts under the "
                               f"bound failed for another reason (try more starts)")
            return failed
        certificate = found.stats.get("certificate")
        verdict = f", its certificate {certificate.get('verdict')}" if isinstance(certificate, dict) else ""
        least = ("" if timer is self else " (the least time of a slew, which the weighted objective's final time "
                                          "cannot undercut)")
        mesh = ("" if record.get("intervals") == o.intervals else
                f" (on the N={record.get('intervals')} coarse mesh; the full mesh is not tried under a bound below "
                f"the released minimum time)")
        message = (f"{o.objective}: no slew found within maneuver.duration = {bound:g} s (the bound on the "
                   f"free final time): with the bound released to {released:.6g} s ({label}'s feasible slew) this "
                   f"planner's {minimum} is T = {T:.8g} s{verdict}, longer than the bound{least}; a local optimum, "
                   f"the least time this planner finds, not a proof that no faster slew exists; a maneuver.duration "
                   f"of {_rounded_up(T)} s admits this slew. Under the bound{mesh}: {failed.message}")
        return FailedReference(self.name, message, "infeasible", duration=T, stats={**found.stats, "time_bound": record})

    def _plan_from(self, problem: ManeuverProblem, starts: list[Reference], defer: bool = False,
                   resumed: Reference | None = None) -> Reference:
        """Plan from the given start references (see the module docstring), then honour the
        requirements between the points (:meth:`_honoured`). ``defer`` and ``resumed``: as in
        :meth:`_optimum` (a deferred failure is returned as it is)."""
        ocp = self._ocp(problem)
        omegaf = np.zeros(3) if problem.omegaf is None else problem.omegaf
        params = np.concatenate([problem.initial_state, problem.qf, omegaf, [problem.duration],
                                 problem.model.default_parameters])
        solved = self._optimum(problem, ocp, starts, params, self.options.intervals, defer=defer, resumed=resumed)
        if solved.deferred is not None:  # the coarse mesh failed at the time bound: _released decides
            return solved.deferred
        if solved.exact is not None:  # the exact bang-bang optimum, its requirements checked (_bang_bang)
            reference: Reference = solved.exact
        else:
            solved = self._switch_refined(problem, ocp, params, solved)
            reference = self._honoured(problem, params, solved, self._reference(problem, ocp, params, solved))
        if ocp.free_time and not (ocp.energy_weight or ocp.l1_weight) and isinstance(reference, CollocationReference):
            reference = self._seed_bound(problem, ocp, params, starts, reference)
        return reference

    def _time_error(self, problem: ManeuverProblem, ocp: OptimalControlProblem, params: Array,
                    solved: _Optimum) -> dict[str, Any] | None:
        """The estimated discretisation error of a bang-bang minimum time
        (:func:`~planners.collocation.certificate.time_error`) of a converged ``solved``, kept in its
        extra stats as ``time_error`` (its switching functions in ``solved.switching``); ``None``
        where it does not apply (not plain minimum time on Radau collocation, cones, a rate bound,
        the allocation's equalities, or actuator states other than reaction wheels' momenta, which are
        states of the shooting, free at the end)."""
        result, transcription = solved.result, solved.transcription
        if (not ocp.free_time or ocp.energy_weight or ocp.l1_weight or ocp.cones or ocp.max_rate is not None
                or not isinstance(transcription, RadauCollocation) or ocp.model.nx != 7 + ocp.model.n_wheels
                or result.x is None
                or result.lam_g is None or getattr(transcription, "allocation_rows", None) is not None):
            return None
        lbx, ubx = transcription.bounds(ocp, solved.nlp, *self._variable_bounds(problem), problem.duration)
        solved.switching = switching_functions(transcription, ocp.model, solved.nlp, result.x, result.lam_g, params)
        record = time_error(transcription, ocp.model, solved.nlp, result.x, lbx, ubx, params, ocp.fixed_final_rate,
                            solved.switching)
        solved.extra["time_error"] = record
        return record

    def _bang_bang(self, problem: ManeuverProblem, ocp: OptimalControlProblem, params: Array, coarse: _Optimum,
                   found: CollocationReference, extra: dict[str, Any]) -> CollocationReference | None:
        """The bang-bang minimum time (switch-time shooting) from the coarse optimum (``switch_refinement: auto``).

        Where the discretisation error of T can be estimated (:meth:`_time_error`: plain minimum
        time on Radau collocation, torquers or reaction wheels without cones, rate bound or
        allocation), the
        switch-time shooting of :func:`~planners.collocation.certificate.time_error` from the
        coarse optimum ``coarse`` (``found``, its reference) is the exact bang-bang trajectory with
        its switching structure. Where it converged and
        :func:`~planners.collocation.certificate.bang_bang_certificate` certifies it (Pontryagin's
        conditions along the integrated co-state, a strictly bang-bang control, the second-order
        conditions in the switch times), and it meets the requirements between its points
        (:func:`~planners.collocation.requirements.dense_check`), it is the reference: a
        :class:`~planners.collocation.reference.CollocationReference` on ``intervals`` intervals
        with a node at every switch (:func:`~planners.collocation.reference.switch_mesh`), its
        states integrated (:func:`~planners.collocation.reference.bang_bang_solution`). Else
        ``None`` (the full-mesh solve follows); ``extra["shooting"]`` records the shooting
        (``used``, and ``why`` not) wherever it was tried."""
        o = self.options
        if o.switch_refinement != "auto" or not coarse.result.success:
            return None
        record = self._time_error(problem, ocp, params, coarse)
        if record is None:  # it does not apply
            return None
        shooting: dict[str, Any] = {**record, "from_intervals": coarse.intervals, "used": False}
        extra["shooting"] = shooting
        if "shooting_T_s" not in record:
            shooting["why"] = f"no exact optimum: {record.get('skipped')}"
            return None
        model, nx = ocp.model, ocp.model.nx
        T, switches = float(record["shooting_T_s"]), np.asarray(record["switch_times_s"], dtype=float)
        arcs = np.asarray(record["controls"], dtype=float)
        bounds = self._variable_bounds(problem)
        tried, agreed = seed_counts(found.stats)
        transcription = coarse.transcription.with_mesh(switch_mesh(switches, T, o.intervals))
        states, controls = bang_bang_solution(model, transcription, params[:nx], switches, arcs, T, params[-3:])
        # The actuators' states within the bounds the NLP imposes (wheel momenta: linear in time on
        # each arc, ḣ = g, so at their largest at the nodes, which hold every switch): the shooting
        # knows no state bound, and where one is active the optimum is not the bang-bang one.
        excess = bound_excess(states[7:].T, bounds[0][7:], bounds[1][7:])
        if excess > REQUIREMENT_TOLERANCE:
            shooting["why"] = (f"its actuator states leave their bounds (by {excess:.2g} of the largest; a wheel's "
                               f"momentum bound is active at the optimum)")
            return None
        certificate = bang_bang_certificate(model, params[:nx], final_conditions(params, nx), params[-3:], switches,
                                            arcs, T, bounds[2], bounds[3], ocp.fixed_final_rate, seeds=tried,
                                            seeds_agreed=agreed)
        if certificate.get("verdict") != "certified":
            shooting.update(why=f"its certificate: {certificate.get('verdict')}", certificate=certificate)
            return None
        stats: dict[str, Any] = {key: found.stats[key] for key in ("iterations", "solver_status", "solve_time_s")
                                 if key in found.stats}
        stats.update(extra, objective=T, transcription=transcription.name, intervals=transcription.intervals,
                     solver=coarse.solver or o.solver, duration=T, certificate=certificate, cones=[],
                     max_quaternion_norm_error=float(np.max(np.abs(np.linalg.norm(states[0:4], axis=0) - 1))))
        reference = CollocationReference(problem, transcription, T, states, controls, stats,
                                         control_bounds=(bounds[2], bounds[3]))
        requirements = self._requirements(problem)
        if requirements.any:
            check = dense_check(problem, reference, requirements)
            if not check.met:
                shooting["why"] = f"it breaks {check.summary()} between its points"
                return None
            tightening = Tightening.initial(requirements, float(np.deg2rad(o.cone_margin_deg)),
                                            problem.rate_bound(None, o.rate_margin))
            reference.stats["dense_check"] = self._dense_stats(requirements, tightening, check, [])
        shooting["used"] = True
        seeds = found.stats.get("seeds") or {}
        agreement = _agreement(seeds)
        reference.message = (f"{o.objective}: the bang-bang optimum, T = {T:.8g} s, by switch-time shooting "
                             f"from the N={coarse.intervals} optimum (T = {found.duration:.7g} s{agreement}): "
                             f"{record['switches']} switches, RK4 with {record.get('steps_per_arc', SHOOTING_STEPS)} "
                             f"steps per arc, its T moved by {record.get('rk4_correction_s', 0.0):+.1e} s by step "
                             f"doubling to that of the same switches flown exactly; "
                             f"{certificate.get('summary', certificate.get('verdict'))}")
        return reference

    def _switch_refined(self, problem: ManeuverProblem, ocp: OptimalControlProblem, params: Array,
                        solved: _Optimum) -> _Optimum:
        """``solved`` solved again on its mesh with the intervals that hold a switch split
        (``switch_refinement``, see the option), from its optimum and multipliers; ``solved`` itself
        where that does not apply or the refined solve does not converge (recorded in its extra
        stats as ``switch_refinement``, except where ``auto`` leaves it). Either carries the
        estimated error of its T (:meth:`_time_error`)."""
        o = self.options
        result, transcription = solved.result, solved.transcription
        if not result.success or result.x is None:
            return solved
        estimate = self._time_error(problem, ocp, params, solved)
        auto = o.switch_refinement == "auto"
        pieces = AUTO_PIECES if auto else int(o.switch_refinement)
        if auto and estimate is not None and "estimate_s" not in estimate:  # no tolerance missed silently
            solved.extra["switch_refinement"] = {
                "pieces": pieces, "auto": True, "mesh_tolerance_s": o.mesh_tolerance,
                "skipped": f"no estimate of the discretisation error of T: {estimate.get('skipped')}",
                "note": f"mesh_tolerance not checked (no estimate of the error of T: {estimate.get('skipped')})"}
            return solved
        if auto and (estimate is None or abs(estimate.get("estimate_s", 0.0)) <= o.mesh_tolerance):
            return solved
        if pieces < 2:
            return solved
        above = (f"the estimated discretisation error of T ({estimate['estimate_s']:.1e} s) is above mesh_tolerance "
                 f"({o.mesh_tolerance:.1e} s)" if auto and estimate is not None else "")
        why = ("an energy or L1 term" if ocp.energy_weight or ocp.l1_weight else "cones" if ocp.cones else
               "a rate bound" if ocp.max_rate is not None else "not a free final time" if not ocp.free_time else
               "another solver" if solved.solver not in (None, "ipopt") or o.solver != "ipopt" else None)
        if not isinstance(transcription, RadauCollocation):
            why = "another transcription"
        if why is not None or not isinstance(transcription, RadauCollocation):
            solved.extra["switch_refinement"] = ({"pieces": pieces, "skipped": why} if not auto else
                                                 {"pieces": pieces, "auto": True, "skipped": why,
                                                  "note": f"{above}: not refined ({why})"})
            return solved
        lbx, ubx = transcription.bounds(ocp, solved.nlp, *self._variable_bounds(problem), problem.duration)
        held = switch_intervals(transcription, ocp.model, solved.nlp, result.x, lbx, ubx)
        record: dict[str, Any] = {"pieces": pieces, "intervals_split": int(held.sum()),
                                  "from_s": float(result.x[solved.nlp.n_stage_state - 1])}
        if auto:
            assert estimate is not None
            record.update(auto=True, estimate_s=estimate["estimate_s"], mesh_tolerance_s=o.mesh_tolerance)
        solved.extra["switch_refinement"] = record
        if not held.any() or held.sum() > transcription.intervals / 4:
            record["skipped"] = "no switch inside an interval" if not held.any() else "not bang-bang"
            if auto:
                record["note"] = f"{above}: not refined ({record['skipped']})"
            return solved
        nodes = transcription.nodes
        pieces_per = np.where(held, pieces, 1)
        mesh = np.concatenate([[0.0], *(nodes[k] + (nodes[k + 1] - nodes[k]) * np.arange(1, n + 1) / n
                                        for k, n in enumerate(pieces_per))])
        mesh[-1] = 1.0
        refined, nlp = self._nlp(problem, ocp, "transfer", mesh=mesh)
        multipliers = transfer_multipliers(solved.nlp, nlp, result.lam_x, result.lam_g, nodes, mesh) if (
            result.lam_x is not None and result.lam_g is not None) else None
        T, states, controls = matrices(solved.nlp.unpack, result.x, params)
        found = CollocationReference(problem, transcription, T.item(), states, controls, {})
        seed = refined.seed(ocp, nlp, solution_sampler(found), found.duration)
        lower, upper = refined.bounds(ocp, nlp, *self._variable_bounds(problem), problem.duration)
        again = solve_multistart(nlp.solver, [seed], p=params, lbx=lower, ubx=upper, lbg=nlp.lbg, ubg=nlp.ubg,
                                 agree=1, lam_x0=None if multipliers is None else multipliers[0],
                                 lam_g0=None if multipliers is None else multipliers[1])
        record.update(intervals=len(mesh) - 1, status=again.status, iterations=again.iterations, time_s=again.time_s)
        if not again.success or again.x is None:
            if auto:
                record["note"] = f"{above}: the refined solve did not converge ({again.status})"
            return solved
        record["to_s"] = float(again.x[nlp.n_stage_state - 1])
        extra = {key: value for key, value in solved.extra.items() if key != "time_error"}
        optimum = _Optimum(merged(result, again), extra, refined, nlp, len(mesh) - 1, None, solved.solver)
        after = self._time_error(problem, ocp, params, optimum)
        if auto and after is not None:  # the refined optimum's own estimate, against the tolerance
            if "estimate_s" not in after:
                record["note"] = f"mesh_tolerance not checked after refinement (no estimate: {after.get('skipped')})"
            elif abs(after["estimate_s"]) > o.mesh_tolerance:
                record["note"] = f"still above mesh_tolerance {o.mesh_tolerance:.1e} s after refinement"
            record["within_tolerance"] = "estimate_s" in after and abs(after["estimate_s"]) <= o.mesh_tolerance
        return optimum

    def _bound_candidates(self, problem: ManeuverProblem, starts: list[Reference]) -> list[tuple[str, Reference]]:
        """The motions whose durations may bound the minimum time (:meth:`_seed_bound`): the starts
        at their own durations and ``eigenaxis``'s ``min_time`` profile (within the bounds the NLP
        imposes: it keeps the problem's ``actuator_margin`` of every torque and momentum limit),
        each labelled."""
        candidates = [(f"start {reference.planner}", reference) for reference in starts]
        try:
            eigenaxis = PLANNERS["eigenaxis"]({"profile": "min_time"}, cache=self.cache).plan_start(problem)
        except Exception:  # noqa: BLE001 (a candidate is optional: none from a planner that cannot plan it)
            return candidates
        if eigenaxis.ok:
            candidates.append(("eigenaxis min_time", eigenaxis))
        return candidates

    def _seed_bound(self, problem: ManeuverProblem, ocp: OptimalControlProblem, params: Array,
                    starts: list[Reference], reference: CollocationReference) -> CollocationReference:
        """A minimum time no slower than a feasible candidate's (:meth:`_bound_candidates`).

        A candidate faster than ``reference`` (by more than :data:`SEED_BOUND_RTOL`) is checked
        against the problem's constraints as the NLP imposes them before any dense tightening
        (:func:`~planners.collocation.certificate.start_violations`: the variable bounds, the
        rate norm, the pointing requirements as stated, the boundary conditions); a feasible one is
        a slew of the problem and its duration an upper bound of the minimum time. Then the
        problem is solved once more from the fastest feasible candidate at its own duration (and
        checked densely, :meth:`_honoured`), and the faster converged reference kept. If the one
        kept is still slower than that candidate, its message and certificate say so. Without a
        faster candidate nothing is solved: ``stats["seed_bound"]`` records the check."""
        o = self.options
        T = float(reference.duration)
        record: dict[str, Any] = {"rtol": SEED_BOUND_RTOL, "candidates": [], "resolved": False, "bound_s": None}
        best: tuple[str, Reference] | None = None
        requirements = self._requirements(problem)
        bounds = self._variable_bounds(problem)
        for label, candidate in self._bound_candidates(problem, starts):
            entry: dict[str, Any] = {"from": label, "duration_s": float(candidate.duration)}
            record["candidates"].append(entry)
            if not candidate.duration < T * (1.0 - SEED_BOUND_RTOL):
                entry["checked"] = "not faster"
                continue
            broken = start_violations(problem, candidate, bounds, ocp.max_rate, requirements.pointing,
                                      DENSE_POINTS * o.intervals + 1, START_TOLERANCE, SEED_BOUND_ATOL)
            entry["checked"] = broken if isinstance(broken, str) else ("feasible" if not broken else "infeasible")
            if isinstance(broken, dict) and broken:
                entry["violations"] = broken
            if broken == {} and (best is None or candidate.duration < best[1].duration):
                best = (label, candidate)
        reference.stats["seed_bound"] = record
        if best is None:
            return reference
        label, candidate = best
        record["bound_s"], record["bound_from"], record["resolved"] = float(candidate.duration), label, True
        transcription, nlp = self._nlp(problem, ocp)
        lbx, ubx = transcription.bounds(ocp, nlp, *bounds, problem.duration)
        seed = transcription.seed(ocp, nlp, seed_sampler(problem, candidate), candidate.duration)
        result = solve_multistart(nlp.solver, [seed], p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg, agree=1)
        again = _Optimum(result, {}, transcription, nlp, o.intervals)
        other = self._honoured(problem, params, again, self._reference(problem, ocp, params, again))
        record["resolve"] = {"status": result.status, "iterations": result.iterations, "time_s": result.time_s,
                             "duration_s": float(other.duration) if other.ok else None}
        if isinstance(other, CollocationReference) and other.duration < T:
            other.stats["seeds"] = reference.stats.get("seeds")
            other.stats["seed_bound"] = record
            other.message += f" (solved again from {label}'s feasible {candidate.duration:.6g} s: {T:.6g} s before)"
            reference, T = other, float(other.duration)
        record["kept_s"] = T
        record["met"] = T <= candidate.duration * (1.0 + SEED_BOUND_RTOL)
        if not record["met"]:
            dense = reference.stats.get("dense_check") or {}
            tightened = {name: float(dense[key]) for name, key in (("actuators", "actuator_tightening"),
                                                                   ("rate", "rate_tightening")) if dense.get(key)}
            why = ("; the dense check tightened the bounds at the points: " + ", ".join(
                f"{name} {100.0 * value:.3g} %" for name, value in tightened.items())) if tightened else ""
            note = (f"slower than a feasible slew of this problem, {label} in {candidate.duration:.6g} s "
                    f"(+{100.0 * (T / candidate.duration - 1.0):.3g} %{why}): not the best known")
            reference.message += f"; {note}"
            certificate = reference.stats.get("certificate")
            if isinstance(certificate, dict):
                certificate["seed_bound"] = note
                certificate["summary"] = f"{certificate.get('summary', '')}; {note}"
        return reference

    def _honoured(self, problem: ManeuverProblem, params: Array, solved: _Optimum, reference: Reference) -> Reference:
        """``reference`` checked densely against the requirements, and solved again tighter while it
        breaks one (see :meth:`plan`)."""
        requirements = self._requirements(problem)
        if not requirements.any or not isinstance(reference, CollocationReference):
            return reference
        tightening = Tightening.initial(requirements, float(np.deg2rad(self.options.cone_margin_deg)),
                                        problem.rate_bound(None, self.options.rate_margin))
        check = dense_check(problem, reference, requirements)
        first_seeds = reference.stats.get("seeds")
        first, first_f = reference, float(solved.result.f)
        rounds: list[dict] = []
        stopped = ""
        while not check.met and len(rounds) < DENSE_ROUNDS:
            tightening = tightening.after(check, requirements)
            try:
                ocp = self._ocp(problem, tightening)
            except ValueError as error:
                stopped = f"; cannot tighten further: {error}"
                break
            again = self._resolved(problem, ocp, params, solved, tightening)
            candidate = self._reference(problem, ocp, params, again, tightening)
            rounds.append({"violations": dict(check.violations), "iterations": again.result.iterations,
                           "time_s": again.result.time_s, "status": again.result.status})
            if not isinstance(candidate, CollocationReference):
                stopped = f"; the tightened solve failed ({candidate.message})"
                break
            solved, reference = again, candidate
            check = dense_check(problem, reference, requirements)
        if first_seeds is not None:  # the tightened solves start from the first one's optimum
            reference.stats["seeds"] = first_seeds
        if rounds and reference is not first:  # the message names the last solve: say where it started
            origin = f"T = {first.duration:.6g} s" if self._ocp(problem).free_time else f"objective {first_f:.6g}"
            starts = (f"; its multistart: {first_seeds.get('tried')} starts, {first_seeds.get('agreed')} agreed, "
                      f"best from {first_seeds.get('best_from')}") if isinstance(first_seeds, dict) else ""
            reference.message += (f" (the dense check's tightened solve from the optimum at {origin}{starts})")
        reference.stats["dense_check"] = self._dense_stats(requirements, tightening, check, rounds)
        if not check.met:
            reference.message += (f"; still breaks {check.summary()} between the mesh points after "
                                   f"{len(rounds)} tightening rounds{stopped} (try more intervals, a larger "
                                   f"cone_margin_deg or a longer duration)")
        return reference

    def _time_bound_note(self, problem: ManeuverProblem, ocp: OptimalControlProblem, result: NLPResult) -> str:
        """When no start converged on a free final time and some ended locally infeasible or at the
        final time's bound: that ``maneuver.duration`` bounds the final time and may be below the
        minimum time (local infeasibility is no proof), and the duration of a feasible slew of the
        problem when one is known (``eigenaxis``'s ``min_time``, checked against the problem's
        constraints as :meth:`_seed_bound` checks it, the final time's bound aside: an upper bound
        of the minimum time, so a ``maneuver.duration`` at least that admits a slew). When such a
        slew fits within the bound, that instead: the bound is then not below the minimum time.
        Else empty. (:meth:`_time_bound` says it, and which slew's duration the bound may be
        released to.)"""
        return self._time_bound(problem, ocp, result)[0]

    def _time_bound(self, problem: ManeuverProblem, ocp: OptimalControlProblem,
                    result: NLPResult) -> tuple[str, tuple[float, str] | None]:
        """:meth:`_time_bound_note`'s note, and where it says the bound may be below the minimum
        time and names a feasible slew longer than the bound, that slew's duration [s] and label
        (what :meth:`_released` releases the bound to); else ``None``."""
        if not ocp.free_time:
            return "", None
        bound = float(problem.duration)
        infeasible = sum(start.status in INFEASIBLE for start in result.starts)
        plain = not (ocp.energy_weight or ocp.l1_weight)  # the objective is the final time
        weight = float(ocp.time_weight) if ocp.time_weight else 1.0  # f = time_weight T
        at_bound = sum(plain and start.status not in INFEASIBLE and np.isfinite(start.f)
                       and start.f >= weight * bound * (1.0 - 1e-6) for start in result.starts)
        if not infeasible and not at_bound:
            return "", None
        ended = " and ".join(part for part in (f"{infeasible} ended locally infeasible" if infeasible else "",
                                               f"{at_bound} stopped at T = {bound:g} s" if at_bound else "") if part)
        note = (f"the final time is free and maneuver.duration = {bound:g} s bounds it; of {len(result.starts)} "
                f"starts {ended}: the bound may be below the minimum time, which local infeasibility does not prove")
        bounds = self._variable_bounds(problem)
        pointing = self._requirements(problem).pointing
        known: list[tuple[float, str]] = []
        within: list[tuple[float, str]] = []
        for label, candidate in self._bound_candidates(problem, []):
            broken = start_violations(problem, candidate, bounds, ocp.max_rate, pointing,
                                      DENSE_POINTS * self.options.intervals + 1, START_TOLERANCE, SEED_BOUND_ATOL)
            if broken == {}:
                (within if candidate.duration <= bound else known).append((float(candidate.duration), label))
        if within:  # a feasible slew fits: the bound is not below the minimum time
            duration, label = min(within)
            return (f"the final time is free and maneuver.duration = {bound:g} s bounds it; of {len(result.starts)} "
                    f"starts {ended}, but {label} is a feasible slew of this problem in {duration:.6g} s, within "
                    f"the bound: the starts failed for another reason"), None
        if known:
            duration, label = min(known)
            note += (f"; {label} is a feasible slew of this problem in {duration:.6g} s, so a maneuver.duration "
                     f"of at least that admits one")
            return note, (duration, label)
        return note, None

    @staticmethod
    def _failure_hint(problem: ManeuverProblem, ocp: OptimalControlProblem, statuses: list[str]) -> str:
        """What to try when no start converged, by what the problem asks: the cones (more starts or
        intervals), the rate bound and the actuator margin (looser, or a longer duration); more
        iterations when the solver ran out of them; the allocation imposed on the controls said."""
        allocated = "" if allocation_constraints(problem.spacecraft) is None else (
            "; the controls follow the controllers' allocation (wheel torques g = −A⁺ τ; torquers and "
            "magnetorquers only for what the wheels cannot give: nothing beside wheels spanning three axes)")
        tries = []
        if "Maximum_Iterations_Exceeded" in statuses:
            tries.append("a larger max_iterations")
        if statuses and all(status in INFEASIBLE for status in statuses) and not ocp.cones:
            tries.append("more starts, a larger multistart (IPOPT's infeasibility is local)")
        if ocp.cones:
            tries.append("multistart: 4 or more intervals (pointing constraints)")
        if problem.rate_bound(None) is not None:
            tries.append(f"a larger rate bound than {problem.rate_bound(None):g} rad/s (requirements.rate.max, "
                         "maneuver.max_rate)")
        if problem.actuator_margin:
            tries.append(f"a smaller requirements.actuators.margin than {problem.actuator_margin:g} (the reference "
                         f"may use {100.0 * (1.0 - problem.actuator_margin):.3g} % of each actuator limit)")
        if not tries:
            return f" (try a longer duration{allocated})" if allocated else ""
        return " (try " + "; ".join(tries) + f"; or a longer duration{allocated})"

    @staticmethod
    def _dense_stats(requirements: Requirements, tightening: Tightening, check: DenseCheck,
                     rounds: list[dict]) -> dict:
        """The ``dense_check`` entry of a reference's stats (see :meth:`plan`)."""
        return {"points_per_interval": DENSE_POINTS, "points": check.points, "rounds": len(rounds),
                "met": check.met, "margins_deg": dict(check.margins_deg), "violations": dict(check.violations),
                "tightening_deg": {c.name: float(np.rad2deg(extra))
                                   for c, extra in zip(requirements.pointing, tightening.pointing)},
                "rate_tightening": tightening.rate, "actuator_tightening": tightening.actuators,
                "round_solves": rounds}

    def _resolved(self, problem: ManeuverProblem, ocp: OptimalControlProblem, params: Array, solved: _Optimum,
                  tightening: Tightening) -> _Optimum:
        """``ocp`` (tightened) solved on the mesh of ``solved`` from its optimum and multipliers
        (IPOPT's warm start of :data:`TRANSFER_WARM_START`: near, not at, the new optimum), else from
        its optimum alone."""
        o, x = self.options, solved.result.x
        assert x is not None  # a converged solve
        mesh = solved.transcription.mesh  # a switch-refined mesh (_switch_refined) is kept
        transcription, nlp = self._nlp(problem, ocp, "transfer", solved.intervals, solved.solver, mesh)
        lbx, ubx = transcription.bounds(ocp, nlp, *self._variable_bounds(problem, tightening), problem.duration)
        result = solve_multistart(nlp.solver, [x], p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg, agree=1,
                                  lam_x0=solved.result.lam_x, lam_g0=solved.result.lam_g)
        if not result.success and (o.solver if solved.solver is None else solved.solver) == "ipopt":
            _, cold = self._nlp(problem, ocp, "near_optimum", solved.intervals, solved.solver, mesh)
            result = merged(result, solve_multistart(cold.solver, [x], p=params, lbx=lbx, ubx=ubx, lbg=cold.lbg,
                                                     ubg=cold.ubg, agree=1))
        return _Optimum(result, {}, transcription, nlp, solved.intervals, None, solved.solver)

    def _seeds(self, problem: ManeuverProblem, ocp: OptimalControlProblem, transcription: Transcription, nlp: NLP,
               starts: list[Reference], dropped: list[str] | None = None) -> tuple[list[Array], list[Array], list[str]]:
        """The decision vectors of the start references, alternates tried only if none converges,
        and where each comes from (the planner's name, one per start then per alternate).

        A vector that is not finite (a start reference NaN at a point of this mesh that
        :meth:`_starts`'s screening did not sample) is left out, ``"label: why"`` appended to
        ``dropped`` (a ``ValueError`` when none is left, or without ``dropped``): the solver would
        not return from it.

        A start whose boresight enters a keep-out cone is bent round it
        (:func:`~planners.collocation.reference.cone_avoiding_sampler`, :data:`SEED_CONE_PAD`
        outside the cone) on the side where it passes nearest the rim. The first start bent round
        the other side is a start too when it passes within half the cone's angle of the centre
        (neither side is clearly better: the solve keeps the better optimum), else an alternate;
        the first start as it was is the last alternate."""
        seeds: list[Array] = []
        alternates: list[Array] = []
        labels: list[str] = []
        alternate_labels: list[str] = []
        for index, reference in enumerate(starts):
            duration = reference.duration if ocp.free_time else problem.duration
            sample = seed_sampler(problem, reference)
            sides, central = cone_sides(sample, ocp.cones, duration) if ocp.cones else ([], False)
            labels.append(reference.planner)
            if not any(side is not None for side in sides):
                seeds.append(transcription.seed(ocp, nlp, sample, duration))
                continue
            seeds.append(transcription.seed(ocp, nlp, cone_avoiding_sampler(sample, ocp.cones, sides, SEED_CONE_PAD),
                                            duration))
            if index == 0:
                opposite = [None if side is None else -side for side in sides]
                other = transcription.seed(ocp, nlp, cone_avoiding_sampler(sample, ocp.cones, opposite, SEED_CONE_PAD),
                                           duration)
                (seeds if central else alternates).append(other)
                (labels if central else alternate_labels).append(f"{reference.planner} other side")
                alternates.append(transcription.seed(ocp, nlp, sample, duration))
                alternate_labels.append(f"{reference.planner} unbent")
        def finite(vectors: list[Array], names: list[str]) -> tuple[list[Array], list[str]]:
            kept = [(vector, name) for vector, name in zip(vectors, names) if np.all(np.isfinite(vector))]
            for vector, name in zip(vectors, names):
                if not np.all(np.isfinite(vector)):
                    why = (f"{name}: its start on {transcription.intervals} intervals is not finite at "
                           f"{int(np.sum(~np.isfinite(vector)))} of {vector.size} entries")
                    if dropped is None:
                        raise ValueError(f"collocation: {why}")
                    dropped.append(why)
            return [vector for vector, _ in kept], [name for _, name in kept]

        seeds, labels = finite(seeds, labels)
        alternates, alternate_labels = finite(alternates, alternate_labels)
        if not seeds:
            raise ValueError("collocation: no start is finite (" + "; ".join(dropped or []) + ")")
        return seeds, alternates, labels + alternate_labels

    def _optimum(self, problem: ManeuverProblem, ocp: OptimalControlProblem, starts: list[Reference], params: Array,
                 intervals: int, solver: str | None = None, defer: bool = False,
                 resumed: Reference | None = None) -> _Optimum:
        """The best optimum on ``intervals`` from the starts (through the coarse mesh first, see
        :meth:`_coarse`, when ``intervals`` is the option's); ``solver`` as in :meth:`_nlp`.

        ``defer``: where the coarse multistart fails and :meth:`_time_bound` names a feasible slew
        longer than the bound on the free final time (the bound may be below the minimum time), that
        failure is returned (``deferred``) without the full-mesh attempts under the bound, for
        :meth:`_released` to decide; ``resumed``: such a deferred failure, whose full-mesh attempts
        are made now (the coarse multistart not solved again), as without ``defer``."""
        o = self.options
        coarse_first = intervals == o.intervals and self._coarse(ocp)
        # The layout (bounds, seeds, unpack) is the same in every build: use the one solved first.
        mode: _Mode = "warm" if o.time_regularization else "transfer" if coarse_first else "cold"
        transcription, nlp = self._nlp(problem, ocp, mode, intervals, solver)
        bounds = transcription.bounds(ocp, nlp, *self._variable_bounds(problem), problem.duration)
        result, regularized = None, None
        extra: dict[str, Any] = {}
        if coarse_first and resumed is not None:  # the coarse multistart failed (deferred): its stats as then
            extra["coarse"] = resumed.stats
            if "seeds" in resumed.stats:
                extra["seeds"] = resumed.stats["seeds"]
        elif coarse_first:
            # On a coarse mesh, where an iteration costs a fraction: the escape from stationary
            # points and its confirmation (free T), or the long way from a far seed (fixed T); its
            # optimum (and its multipliers, carried to the full mesh) seeds one solve on the full mesh.
            seed_solver = self._seed_solver(ocp)
            coarse = self._optimum(problem, ocp, starts, params, o.coarse_intervals, seed_solver)
            found = self._reference(problem, ocp, params, coarse)
            if not found.ok and seed_solver != o.solver:  # the option's solver takes the seed over
                extra["coarse_" + seed_solver] = found.stats
                coarse = self._optimum(problem, ocp, starts, params, o.coarse_intervals)
                found = self._reference(problem, ocp, params, coarse)
            extra["coarse"] = found.stats
            if "seeds" in found.stats:  # the multistart was the coarse one
                extra["seeds"] = found.stats["seeds"]
            record = found.stats.get("time_bound")
            if defer and not found.ok and isinstance(record, dict) and "feasible_s" in record:
                # The bound may be below the minimum time (:meth:`_time_bound`): the released solve
                # first; the full mesh is tried under the bound only where that does not settle it.
                return replace(coarse, extra=extra, deferred=found)
            if found.ok:
                assert isinstance(found, CollocationReference)  # found.ok
                exact = self._bang_bang(problem, ocp, params, coarse, found, extra)
                if exact is not None:  # certified: no full-mesh solve
                    return replace(coarse, extra=extra, exact=exact)
                transferred = self._transferred(problem, ocp, coarse, found, params, bounds)
                if transferred is not None:
                    result, more = transferred
                    extra.update(more)
                if result is None or not result.success:
                    # Without multipliers, the seed POLISH_MU_INIT was tuned on: the coarse optimum
                    # through the inverse dynamics. Its own controls (a bang-bang arc's polynomial
                    # overshoots the bounds between the Radau points, up to 55 % on two wheels) took
                    # the two-wheel regularised solve 61 iterations instead of 31.
                    seed = transcription.seed(ocp, nlp, seed_sampler(problem, found), found.duration)
                    polish, more, _ = self._solve(problem, ocp, [seed], params, bounds, intervals, near_optimum=True)
                    result = polish if result is None else merged(result, polish)
                    extra.update(more)
        if result is None or not result.success:
            dropped: list[str] = []
            seeds, alternates, labels = self._seeds(problem, ocp, transcription, nlp, starts, dropped)
            if dropped:
                extra["seeds_dropped"] = dropped
            fine, more, regularized = self._solve(problem, ocp, seeds, params, bounds, intervals, solver=solver,
                                                  alternates=alternates, labels=labels)
            result = fine if result is None else merged(result, fine)
            extra.update(more)
        return _Optimum(result, extra, transcription, nlp, intervals, regularized, solver)

    def _transferred(self, problem: ManeuverProblem, ocp: OptimalControlProblem, coarse: _Optimum,
                     found: CollocationReference, params: Array,
                     bounds: tuple[Array, Array]) -> tuple[NLPResult, dict] | None:
        """The full-mesh solve from the coarse optimum ``found`` with its multipliers carried over
        (:meth:`_transfer`), and its extra stats; with ``time_regularization``, the coarse
        regularised optimum is carried to the full mesh's regularised problem, which is then
        polished (:meth:`_polished`). ``None`` where that does not apply (``solver: fatrop``, more than
        :data:`TRANSFER_MAX_INTERVALS` intervals, layouts that differ)."""
        if self.options.solver != "ipopt" or self.options.intervals > TRANSFER_MAX_INTERVALS:
            return None
        if not self.options.time_regularization:
            result = self._transfer(problem, ocp, coarse.result, coarse.nlp, found, params, bounds)
            return None if result is None else (result, {})
        if coarse.regularized is None or not coarse.regularized.success:
            return None
        regular = self._regularized(problem, ocp)
        _, coarse_nlp = self._nlp(problem, regular, intervals=coarse.intervals)
        origin = self._reference(problem, regular, params,
                                 _Optimum(coarse.regularized, {}, coarse.transcription, coarse_nlp, coarse.intervals))
        assert isinstance(origin, CollocationReference)  # a converged solve
        first = self._transfer(problem, regular, coarse.regularized, coarse_nlp, origin, params, bounds)
        if first is None:
            return None
        return self._polished(problem, ocp, first, params, bounds, self.options.intervals), {"regularized": first.stats()}

    def _transfer(self, problem: ManeuverProblem, ocp: OptimalControlProblem, coarse: NLPResult, coarse_nlp: NLP,
                  found: CollocationReference, params: Array, bounds: tuple[Array, Array]) -> NLPResult | None:
        """The full-mesh solve of ``ocp`` from ``found``, the coarse optimum ``coarse`` of
        ``coarse_nlp`` (its own states and controls, read by
        :func:`~planners.collocation.reference.solution_sampler`), with its multipliers carried over
        (:func:`ocp.transcription.mesh_transfer.transfer_multipliers`); ``None`` when the layouts differ."""
        if coarse.lam_x is None or coarse.lam_g is None:
            return None
        transcription, nlp = self._nlp(problem, ocp, "transfer")
        multipliers = transfer_multipliers(coarse_nlp, nlp, coarse.lam_x, coarse.lam_g)
        if multipliers is None:
            return None
        lbx, ubx = bounds
        seed = transcription.seed(ocp, nlp, solution_sampler(found), found.duration)
        return solve_multistart(nlp.solver, [seed], p=params, lbx=lbx, ubx=ubx, lbg=nlp.lbg, ubg=nlp.ubg, agree=1,
                                lam_x0=multipliers[0], lam_g0=multipliers[1])

    def _reference(self, problem: ManeuverProblem, ocp: OptimalControlProblem, params: Array,
                   solved: _Optimum, tightening: Tightening | None = None) -> Reference:
        """The reference (or the failure) of an optimum found by :meth:`_optimum` (with the variable
        bounds of ``tightening``, :meth:`_variable_bounds`); its controls saturated at those bounds."""
        o, result, transcription = self.options, solved.result, solved.transcription
        solver = solved.solver or o.solver
        stats = result.stats()
        stats.update(solved.extra, transcription=transcription.name, intervals=solved.intervals, solver=solver)
        if not result.success:
            hint, (note, release) = self._failure_hint(problem, ocp, result.statuses), self._time_bound(problem, ocp,
                                                                                                        result)
            if note:  # first: what the starts' ends say, then what to try
                hint = f" ({note}; {hint[2:-1]})" if hint else f" ({note})"
            if release is not None:  # a feasible slew longer than the bound: what _released releases it to
                stats["time_bound"] = {"bound_s": float(problem.duration), "feasible_s": release[0],
                                       "feasible_from": release[1], "intervals": solved.intervals}
            return FailedReference(self.name, f"{solver} did not converge from any start: "
                                   f"{sorted(set(result.statuses))}{hint}", result.status, stats=stats)
        assert result.x is not None  # success implies a point
        T_matrix, states, controls = matrices(solved.nlp.unpack, result.x, params)
        T = T_matrix.item()
        rows = allocation_constraints(problem.spacecraft)
        scaled = () if rows is None else tuple(block.control for block in actuator_blocks(problem.spacecraft)
                                               if np.any(rows[:, block.control]))
        reference = CollocationReference(problem, transcription, T, states, controls, stats,
                                         control_bounds=self._variable_bounds(problem, tightening)[2:],
                                         scaled_blocks=scaled)
        norm_error = float(np.max(np.abs(np.linalg.norm(states[0:4], axis=0) - 1)))
        # the fixed-direction cones as stated (their angles not tightened), for the cone plots
        fixed = [c for c in self._requirements(problem).pointing if not c.moving]
        reference.stats.update(duration=T, max_quaternion_norm_error=norm_error,
                               cones=[(c.boresight, c.directions[0], c.angle, c.keep_out) for c in fixed])
        if o.objective == "min_energy" and problem.model.nx == 7:
            # ∫‖τ‖² of the actuators' torque on a rigid body without actuator states (what the
            # co-state planner's rigid body minimises; wheels add their momentum to the dynamics)
            reference.stats["functional"] = {"name": "int_actuator_torque_squared", "value": float(result.f)}
        coarse = solved.extra.get("coarse")
        seeded = ""
        if isinstance(coarse, dict) and "intervals" in coarse:  # the full mesh solved from the coarse optimum
            seeds = coarse.get("seeds") or {}
            agreed = _agreement(seeds)
            seeded = f" (seeded by the N={coarse['intervals']} optimum{agreed})"
        refined = solved.extra.get("switch_refinement")
        if isinstance(refined, dict) and "to_s" in refined:  # the result is the refined mesh's
            seeded += (f"; refined: {refined['intervals_split']} intervals holding a switch split in "
                       f"{refined['pieces']}, T {refined['from_s']:.7g} -> {refined['to_s']:.7g} s")
        estimate = solved.extra.get("time_error")
        if isinstance(estimate, dict) and "estimate_s" in estimate:
            seeded += f"; estimated discretisation error of T {estimate['estimate_s']:.1e} s"
        if isinstance(refined, dict) and "note" in refined:  # a mesh_tolerance missed or not checked
            seeded += f"; {refined['note']}"
        shot = solved.extra.get("shooting")
        if isinstance(shot, dict) and not shot.get("used") and shot.get("why"):  # why the full mesh was solved
            seeded += f"; the shooting from the N={shot.get('from_intervals')} optimum not used ({shot['why']})"
        reference.message = (f"{o.objective} by {transcription.name} (N={solved.intervals}, {solver}): "
                             f"objective {result.f:.6g}, T = {T:.4g} s, {result.message}{seeded}")
        if solved.intervals == o.intervals or transcription.mesh is not None:  # the final mesh: its certificate
            # (planners.collocation.certificate)
            lbx, ubx = transcription.bounds(ocp, solved.nlp, *self._variable_bounds(problem, tightening), problem.duration)
            reference.stats["certificate"] = collocation_certificate(result, transcription, ocp, solved.nlp, params,
                                                                     lbx, ubx, solver, reference.stats,
                                                                     solved.switching)
        return reference


def _skipped(reference: Reference, failures: list[str]) -> None:
    """Name in ``reference``'s seed record the seed planners that failed or raised (``failures``)
    and the starts left out as not finite (``seeds_dropped``, its own or its coarse mesh's)."""
    if isinstance(reference.stats.get("seeds"), dict):
        coarse = reference.stats.get("coarse")
        dropped = [*(coarse.get("seeds_dropped", []) if isinstance(coarse, dict) else []),
                   *reference.stats.get("seeds_dropped", [])]
        reference.stats["seeds"]["skipped"] = failures + dropped


def _rounded_up(value: float, digits: int = 7) -> str:
    """``value`` (> 0) rounded up at ``digits`` significant digits: a duration to suggest, never below
    the one needed (3.24308328 -> ``3.243084``)."""
    step = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return f"{math.ceil(value / step) * step:.{max(0, digits - 1 - math.floor(math.log10(value)))}f}"


def _agreement(seeds: dict[str, Any]) -> str:
    """The coarse multistart's seeds in a reference's message: ``", 2 of 2 seeds agreed there"``,
    ``", from 1 seed"`` where one was tried (no agreement to speak of), empty without a record."""
    if "agreed" not in seeds or "tried" not in seeds:
        return ""
    if seeds["tried"] == 1:
        return ", from 1 seed"
    return f", {seeds['agreed']} of {seeds['tried']} seeds agreed there"
