"""Run a scenario: plan with every planner, track each reference in closed loop, score both.

:func:`run` returns :class:`RunResults`, whose rows carry the metrics, the requirement scores, the
reference and the simulation, and which render to JSON, CSV and Markdown (see
:mod:`scenarios.output.tables`).

Requirements (:mod:`scenarios.requirements`): before anything is planned, a pointing requirement
that the initial or target attitude already breaks (:func:`~scenarios.requirements.scoring.endpoint_violations`),
or a rate requirement that the angle between them cannot be turned within T at
(:func:`~scenarios.requirements.scoring.rate_violations`), makes the planner's row ``infeasible``,
naming it, and nothing is planned: both are proofs that no motion meets the requirements, not a
numerical failure (``failed``). ``maneuver.duration`` (T) is the manoeuvre's time budget for every
planner: a planner that minimises time (:func:`planners.capabilities.minimises_time`) is checked
with T as the bound on its slew's time, and a reference that ends after T (a planner that chose a
longer duration of its own) is ``infeasible`` too (:func:`plan_row`), as a bang-coast-bang longer
than T is.
Then each row's reference and closed loop are scored against every requirement; a row that breaks
one is ``violated`` (never ``ok``), its message naming the requirement, the scope, the margin and
the time, and a planner that does not honour a kind of requirement present says so in its message.
Statuses rank ``failed`` over ``infeasible`` over ``violated`` over ``ok``. A planner that cannot take a study's case
(:attr:`~scenarios.schema.loader.Scenario.inapplicable`) gets ``failed`` rows, unplanned, whose
message is ``not applicable: ...`` with its reason.

References reused (a trade study's worker, which passes ``references``): a row whose planning
inputs are identical to an earlier case's (:func:`planning_key`: the planner's class, registry name
and validated options, and every field of the :class:`~planners.ManeuverProblem`) gets that case's
reference instead of planning again: a Monte Carlo that disperses only the truth plant
(``truth.*``) plans once per worker thread: the store, a :class:`~ocp.SolverCache`, keeps each
thread's entries apart, so a Dask worker with two threads plans twice. Only a successful reference
is kept (a failed plan, e.g. one stopped by a time limit, is planned again in every case), and each
row gets its own copy (its statistics are written on by the cross-check below). The reused row's
``plan_reused`` is True and its ``plan_time_s`` the wall time of the plan that made the reference
(the planner's cost), not the nothing the case spent on it; the case's own ``elapsed_s``
(:func:`scenarios.study.worker.run_case`) shows the saving. A planner that declares
``deterministic = False`` has no key: its rows are always planned.

Optima cross-checked: when a run holds a direct optimum (a reference whose certificate has no
``method``, e.g. ``collocation``) and an indirect one (a co-state solution, e.g. ``costate_tpbvp``)
of the same functional (the ``name`` of both references' ``stats["functional"]``), each
certificate gets the relative difference of their values of it, ``costate_gap``
(:func:`ocp.nlp.with_costate_gap`), once every row is planned.
"""
from __future__ import annotations

import copy
import hashlib
import time
import traceback
from collections.abc import Callable
from typing import Any

import numpy as np

from ocp import (
    SimulationError,
    Simulator,
    SolverCache,
    metric_violations,
    metrics_from_reference,
    metrics_from_simulation,
)
from ocp.cache import Unkeyable, exact_key
from ocp.nlp import with_costate_gap
from ocp.simulation.simulator import law_raised
from planners import FailedReference, Reference, ReferenceSample
from planners.capabilities import minimises_time
from planners.conformance import check_boundary
from planners.errors import ConformanceError
from planners.reference import JUMP_TOLERANCE
from scenarios.errors import CaseTimeout
from scenarios.output.results import Row, RunResults
from scenarios.requirements.fields import VERDICT
from scenarios.requirements.scoring import (
    REFERENCE_POINTS,
    SCOPE_WORDS,
    Score,
    endpoint_violations,
    late_slew,
    plant_limits,
    rate_jumps,
    rate_least_duration,
    rate_violations,
    reference_times,
    score_closed_loop,
    score_reference,
    unhonoured,
    violations,
)
from scenarios.schema.labels import row_labels
from scenarios.schema.loader import ControllerSpec, PlannerSpec, Scenario

_SCORE_REQUIREMENTS = True
"""Score the rows against the scenario's requirements (off only to measure what scoring costs:
``tests/benchmarks/test_bench_requirements.py``)."""


def final_accuracy_note(ends: list[tuple[float | None, float]], rows: int) -> str | None:
    """The note a run or a sweep prints when its scenario states no ``requirements.final``.

    A row's status reflects the requirements: without a final one, a closed loop that never
    performs the slew is ``ok``. This note says so and counts the rows that end outside their
    settling band.

    Parameters
    ----------
    ends : list of (float or None, float)
        For each row of a scenario without ``requirements.final``: its closed loop's
        ``final_error_deg`` (None without a closed loop or a final attitude) and the scenario's
        ``simulation.settling_tolerance_deg`` [deg].
    rows : int
        All the rows of the run or the sweep.

    Returns
    -------
    str or None
        ``note: no requirements.final: rows are ok whatever their final error; 22 of 24 rows end
        more than 0.1 deg off the target (up to 90 deg)``; None when no such row ends outside its
        band.
    """
    off = [(error, band) for error, band in ends if error is not None and error > band]
    if not off:
        return None
    bands = {band for _, band in off}
    band = f"{bands.pop():g} deg" if len(bands) == 1 else "their settling band"
    return (f"note: no requirements.final: rows are ok whatever their final error; {len(off)} of {rows} "
            f"row{'s' if rows != 1 else ''} end{'s' if len(off) == 1 else ''} more than {band} (simulation.settling_tolerance_deg) off the target "
            f"(up to {max(error for error, _ in off):.3g} deg)")


def closed_loop_window(scenario: Scenario, reference: Reference | None) -> float:
    """The length of a row's closed loop (and of its flight tables, ``slewbench codegen``).

    Parameters
    ----------
    scenario : Scenario
        The scenario (its ``simulation.duration`` and ``maneuver.duration``).
    reference : planners.Reference or None
        The row's reference; ``None`` in regulation.

    Returns
    -------
    float
        [s]: ``simulation.duration``, else the manoeuvre's duration or the reference's if longer.
    """
    return scenario.simulation.duration or max(scenario.problem.duration, reference.duration if reference else 0.0)


def _simulate(scenario: Scenario, simulator: Simulator, reference: Reference | None, row: Row,
              controller_spec: ControllerSpec | None = None) -> None:
    problem = scenario.problem
    spec = controller_spec or scenario.controller
    duration = closed_loop_window(scenario, reference)
    controller = spec.controller
    start = time.perf_counter()
    try:
        result = simulator.run(controller, scenario.true_initial_state, duration, reference=reference,
                               target=(problem.qf, problem.omegaf), noise=scenario.simulation.noise,
                               sensors=scenario.simulation.sensors)
    except SimulationError as error:
        row.status, row.message = "failed", f"simulation: {error}"
        return
    except Exception as error:
        interruption = _interruption(error)
        if interruption is not None:
            raise interruption from None
        where = law_raised(error)
        if where is None:  # the simulator's own code: an internal error
            raise
        traceback.print_exc()  # the law's bug fails its row, not the others
        when = "in reset" if where[1] is None else f"at t = {where[1]:g} s"
        row.status, row.message = "failed", f"simulation: {where[0]} raised {type(error).__name__} {when}: {error}"
        return
    finally:
        row.simulate_time_s = time.perf_counter() - start
    row.simulation = result
    if reference is not None and duration < reference.duration * (1 - 1e-9):
        cut = (f"the closed loop stops at {duration:g} s (simulation.duration), before the reference ends at "
               f"T = {reference.duration:.4g} s: its closed-loop metrics cover {100 * duration / reference.duration:.3g} "
               f"% of the manoeuvre")
        row.message = f"{row.message}; {cut}" if row.message else cut
    row.closed_loop_metrics = metrics_from_simulation(
        result, problem.qf, problem.omegaf, reference=reference, plan_time_s=row.plan_time_s,
        duration_s=reference.duration if reference else None,
        settling_tolerance_deg=scenario.simulation.settling_tolerance_deg,
        fine_settling_tolerance_deg=scenario.simulation.fine_settling_tolerance_deg,
        detumble_tolerance=scenario.simulation.detumble_tolerance)
    _check_physical(row, "closed loop", row.closed_loop_metrics)


def _judge(row: Row, scores: dict[str, dict[str, Score]], note: str) -> None:
    """Put a row's requirement scores on it, each with its verdict first (the field ``met``, a bool:
    :data:`~scenarios.requirements.fields.VERDICT`): a row that breaks one is ``violated`` unless it
    already failed; the message names what breaks (first), then the row's own message, the caveats of
    requirements met (a score's detail where it is met) and ``note``."""
    row.requirements = {scope: {name: {VERDICT: bool(score.met), **score.values} for name, score in scores[scope].items()}
                        for scope in SCOPE_WORDS if scope in scores} or None
    broken = violations(scores)
    if broken and row.status == "ok":
        row.status = "violated"
    own = [row.message] if row.message else []
    # a requirement met with a caveat of its scoring (a search between samples at its work limit)
    caveats = [f"{name} ({SCOPE_WORDS[scope]}) met, but {score.detail}" for scope in SCOPE_WORDS
               for name, score in scores.get(scope, {}).items() if score.met and score.detail]
    parts = (own + broken if row.status != "violated" else broken + own) + caveats + ([note] if note else [])
    row.message = "; ".join(parts)


def _check_physical(row: Row, scope: str, metrics: dict[str, Any] | None) -> None:
    """A row whose metrics physics forbids (negative, non-finite) is failed, not "ok"."""
    problems = metric_violations(metrics)
    if problems and row.status == "ok":
        row.status = "failed"
        row.message = f"{scope} metrics are not physical ({'; '.join(problems)}): the result cannot be trusted"


def run(scenario: Scenario, progress: Callable[[str], None] | None = None,
        cache: SolverCache | None = None, simulators: SolverCache | None = None,
        on_row: Callable[[Row], None] | None = None, references: SolverCache | None = None) -> RunResults:
    """Plan, simulate and score every planner of ``scenario``.

    The scenario's validated planner and controller instances serve every row (their options are
    checked once, when the scenario is loaded). The simulator resets a controller before each run,
    which the controller contract requires to clear its state (``controllers.conformance`` checks
    it), so the rows do not share state; one scenario is not meant to run in two threads at once.

    Parameters
    ----------
    scenario : a loaded scenario.
    progress : receives a line of text per finished row.
    cache : solvers built by planners, shared across runs (a trade-study worker passes one).
    simulators : simulators (and their closed-loop functions) shared across runs, keyed by the
        model's fingerprint and the simulation settings; anything with SolverCache's ``get``
        (a trade-study worker passes a bounded one). None: a new simulator per run.
    on_row : receives each row as soon as it is done (scored and judged), before its progress
        line: ``slewbench run`` sends its figure to the plot process
        (:func:`scenarios.output.writer.plot_streamer`).
    references : SolverCache or None
        Successful references kept across runs, keyed by :func:`planning_key`: a row whose planner
        and problem have the key of a kept reference reuses it (a copy) instead of planning, and
        its ``plan_reused`` is True; anything with SolverCache's ``get`` (a trade-study worker
        passes a bounded one). None (default): every row is planned.

    Returns
    -------
    RunResults
        One row per planner and controller pair (in regulation mode, one per controller).

    Raises
    ------
    ScenarioError
        Two rows would have the same label (a scenario built without :func:`scenarios.load`).
    TypeError
        An argument of the wrong type, named in the message.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario must be a Scenario (scenarios.load or scenarios.parse_scenario), got "
                        f"{type(scenario).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable or None, got {type(progress).__name__}")
    if on_row is not None and not callable(on_row):
        raise TypeError(f"on_row must be callable or None, got {type(on_row).__name__}")
    if cache is not None and not isinstance(cache, SolverCache):
        raise TypeError(f"cache must be an ocp.SolverCache or None, got {type(cache).__name__}")
    for name, given in (("simulators", simulators), ("references", references)):
        if given is not None and not callable(getattr(given, "get", None)):
            raise TypeError(f"{name} must have SolverCache's get (an ocp.SolverCache) or be None, got "
                            f"{type(given).__name__}")
    say = progress or (lambda line: None)
    spec = scenario.simulation
    model = scenario.problem.model

    plant = scenario.truth  # the truth model the closed loop integrates (None: the design model)
    # the actuator requirement holds for the wheels flown: the lesser of the design's and the plant's limits
    flown_limits = plant_limits(plant)

    def build() -> Simulator:
        return Simulator(model, spec.sample_time, spec.integrator, max_step=spec.max_step,
                         max_samples=spec.max_samples, compile=spec.compile, plant=plant)

    simulator = build() if simulators is None else simulators.get(
        ("simulator", model.fingerprint, None if plant is None else plant.fingerprint, spec.sample_time,
         spec.integrator, spec.max_step, spec.max_samples, spec.compile), build)
    controllers = scenario.controllers
    labels = row_labels([planner.label for planner in scenario.planners], [c.label for c in controllers])
    planned: dict[int, tuple[Reference, dict[str, Any] | None, tuple[Any, Any] | None]] = {}
    kept = None if references is None else _Watched(references)
    reused: dict[int, bool] = {}
    # per planner: its reference's pointing and rate scores, which no controller changes (scored once)
    shared_scores: dict[int, dict[str, Score]] = {}
    scoring = _SCORE_REQUIREMENTS and bool(scenario.requirements)
    # proven before planning, per planner: a minimum-time planner's slew may end before T (its bound)
    broken_ends = {i: endpoint_violations(scenario.problem, minimises_time(type(spec.planner), spec.planner.options))
                   if scoring else [] for i, spec in enumerate(scenario.planners)}
    rows: list[Row] = []
    for label, i, j in labels:
        scores: dict[str, dict[str, Score]] = {}
        if i is None:  # regulation mode: the controller alone, to the target
            row = Row(label, None, "ok", "regulation to the target", None, None, None, controller=controllers[j].name)
            _simulate(scenario, simulator, None, row, controllers[j])
            timing = f"simulated in {row.simulate_time_s:.2f} s"
            note = ""
        else:
            planner_spec = scenario.planners[i]
            if i in scenario.inapplicable:  # a study's case this planner cannot take: its rows fail, unplanned
                planned.setdefault(i, (FailedReference(planner_spec.name, f"not applicable: {planner_spec.name} cannot "
                                                       f"take this case: {scenario.inapplicable[i]}"), None, None))
            if broken_ends[i]:  # proven: no motion can meet them (infeasible, not a failure), nothing is planned
                planned.setdefault(i, (FailedReference(planner_spec.name, "; ".join(broken_ends[i]), "infeasible"),
                                       None, None))
            if i not in planned:  # planned once, tracked by every controller
                if kept is not None:
                    kept.reused = False
                planned[i] = plan_row(scenario, planner_spec, cache, scoring, kept=kept)
                reused[i] = kept is not None and kept.reused
            reference, reference_metrics, sampled = planned[i]
            row = Row(label, planner_spec.name, reference.status, reference.message,
                      reference.plan_time_s, None if reference_metrics is None else dict(reference_metrics), None,
                      reference, controller=controllers[j].name, plan_reused=reused.get(i, False),
                      needed_duration_s=needed_duration(scenario, planner_spec, reference, broken_ends[i]))
            if reference.ok:
                _check_physical(row, "reference", row.reference_metrics)
                if sampled is not None:
                    if i not in shared_scores:
                        shared_scores[i] = score_reference(scenario.requirements, scenario.problem, *sampled, None,
                                                           reference, flown_limits)
                    shared = shared_scores[i]
                    own = score_reference(scenario.requirements, scenario.problem, *sampled,
                                          controllers[j].controller, reference, flown_limits, shared=False)
                    # in score_reference's order: the pointing requirements, the actuators, the rate
                    scores["reference"] = {**{name: score for name, score in shared.items() if name != "rate"}, **own,
                                           **{name: score for name, score in shared.items() if name == "rate"}}
                _simulate(scenario, simulator, reference, row, controllers[j])
            timing = (f"planned in {(row.plan_time_s or 0.0) * 1e3:.1f} ms, "
                      f"simulated in {row.simulate_time_s:.2f} s")
            note = unhonoured(scenario.requirements, planner_spec.planner) if scoring and not broken_ends[i] else ""
        if scoring and row.simulation is not None:
            end = row.reference.duration if row.reference is not None else scenario.problem.duration
            result = row.simulation
            scores["closed_loop"] = score_closed_loop(scenario.requirements, scenario.problem, result.t, result.q,
                                                      result.omega, end, row.reference, result.wheel_momentum, plant)
        if scoring:
            _judge(row, scores, note)
        rows.append(row)
        if on_row is not None:
            on_row(row)
        say(f"[{len(rows)}/{len(labels)}] {row.label}: {row.status} ({timing})"
            + (f" - {row.message}" if row.status != "ok" else ""))
    _cross_check_optima(rows)
    return RunResults(scenario, rows)


def _cross_check_optima(rows: list[Row]) -> None:
    """Set ``costate_gap`` on the certificates of the direct and indirect optima of one functional.

    Each reference counts once (a reference tracked by several controllers is one optimum). A
    direct optimum's gap is to the best (least) indirect value; an indirect optimum's gap is to the
    best direct value; both relative to the indirect value: ``|J_direct − J_costate| / |J_costate|``.
    """
    found: dict[str, list[tuple[Reference, dict[str, Any], float]]] = {}
    seen: set[int] = set()
    for row in rows:
        reference = row.reference
        if reference is None or not reference.ok or id(reference) in seen:
            continue
        seen.add(id(reference))
        functional, record = reference.stats.get("functional"), reference.stats.get("certificate")
        if not isinstance(functional, dict) or not isinstance(record, dict):
            continue
        name, value = functional.get("name"), functional.get("value")
        if isinstance(name, str) and isinstance(value, (int, float)) and np.isfinite(value):
            found.setdefault(name, []).append((reference, record, float(value)))
    for entries in found.values():
        indirect = [entry for entry in entries if entry[1].get("method") is not None]
        direct = [entry for entry in entries if entry[1].get("method") is None]
        if not indirect or not direct:
            continue
        costate = min(value for _, _, value in indirect)
        best_direct = min(value for _, _, value in direct)
        if costate == 0.0:
            continue  # no relative gap to a zero functional
        for reference, record, value in direct:
            reference.stats["certificate"] = with_costate_gap(record, abs(value - costate) / abs(costate))
        for reference, record, value in indirect:
            reference.stats["certificate"] = with_costate_gap(record, abs(best_direct - value) / abs(value))


def needed_duration(scenario: Scenario, planner_spec: PlannerSpec, reference: Reference,
                    proven: list[str]) -> float | None:
    """The least ``maneuver.duration`` known to be needed by an ``infeasible`` row whose slew does
    not fit its time budget (the row's ``needed_duration_s``).

    The largest of: the refused reference's own duration, when it ends after ``maneuver.duration``
    (:func:`~scenarios.requirements.scoring.late_slew`; a budget that long admits that slew); the
    planner's :meth:`~planners.base.Planner.least_duration` when it exceeds the budget (a planner
    that refuses the slew itself, or is refused before planning); the rate requirement's
    ``θ / ω_max`` when it exceeds the budget (the proof before planning,
    :func:`~scenarios.requirements.scoring.rate_violations`). None for any other row, and for a row
    that an end point already breaking a pointing requirement makes infeasible (no budget admits it).

    Parameters
    ----------
    scenario : Scenario
        The scenario.
    planner_spec : PlannerSpec
        The row's planner.
    reference : planners.Reference
        The row's reference (a refused or failed one for an infeasible row).
    proven : list of str
        What was proven before planning (:func:`~scenarios.requirements.scoring.endpoint_violations`
        of the row's planner), empty when nothing was.

    Returns
    -------
    float or None
        [s], above ``maneuver.duration``; None when the row is not infeasible or no needed duration
        is known.
    """
    problem = scenario.problem
    if reference.status != "infeasible" or any(line not in rate_violations(problem) for line in proven):
        return None
    known = [reference.duration] if late_slew(problem, reference.duration) else []
    least = planner_spec.planner.least_duration(problem)
    if least is not None and late_slew(problem, least):
        known.append(least)
    rate = rate_least_duration(problem) if proven else None
    if rate is not None:
        known.append(rate)
    return max(known) if known else None


def plan_row(scenario: Scenario, planner_spec: PlannerSpec, cache: SolverCache | None,
             scoring: bool = False, kept: Any = None
             ) -> tuple[Reference, dict[str, Any] | None, tuple[Any, Any] | None]:
    """Plan one row's reference as :func:`run` does (``slewbench codegen`` plans its rows so too).

    Parameters
    ----------
    scenario : Scenario
        The scenario.
    planner_spec : PlannerSpec
        The row's planner.
    cache : ocp.SolverCache or None
        Where the planner keeps what it builds; ``None``: the model's own cache.
    scoring : bool, optional
        Also sample the reference for the requirements.
    kept : SolverCache or None, optional
        Successful references by :func:`planning_key` (:func:`run`'s ``references``, anything with
        SolverCache's ``get``): a copy of the one kept for this planner and problem is used
        instead of planning, and a new successful one is kept. None (default): planned.

    Returns
    -------
    tuple
        The reference (a failed one, naming the planner, when the planner raises, its reference
        raises or is not finite where it is sampled, or it misses a boundary condition of the
        manoeuvre that it does not declare free, :func:`planners.conformance.check_boundary`; an
        ``infeasible`` one, with the planned duration, when it ends after ``maneuver.duration``,
        the manoeuvre's time budget, :func:`~scenarios.requirements.scoring.late_slew`), its
        metrics (``None`` when failed)
        and, with ``scoring``, its times and sample for the requirements (one sampling serves both:
        the metrics' uniform times come first), else ``None``.
    """
    spec = scenario.simulation
    planner = planner_spec.planner.with_cache(cache)
    key = None if kept is None else planning_key(planner, scenario.problem)
    if kept is None or key is None:
        reference = _plan(planner, planner_spec.name, scenario.problem)
    else:
        reference = _kept_or_planned(kept, key, planner, planner_spec.name, scenario.problem)
    if not reference.ok:
        return reference, None, None
    late = late_slew(scenario.problem, reference.duration)
    if late:  # maneuver.duration is every planner's time budget: a longer slew is not the manoeuvre asked for
        failed = FailedReference(planner_spec.name, late, "infeasible", duration=reference.duration, stats=reference.stats)
        failed.plan_time_s = reference.plan_time_s
        return failed, None, None
    times = (reference_times(reference.duration, closed_loop_window(scenario, reference), spec.sample_time, REFERENCE_POINTS)
             if scoring else np.linspace(0.0, reference.duration, REFERENCE_POINTS))
    sample = _sampled(reference, times)
    if isinstance(sample, str):  # the planner's reference cannot be sampled: its row fails, the others run
        failed = FailedReference(planner_spec.name, f"{planner_spec.name}: {sample}", duration=reference.duration,
                                 stats=reference.stats)
        failed.plan_time_s = reference.plan_time_s
        return failed, None, None
    try:  # a reference that misses its manoeuvre's ends is a planner defect, not a motion to score
        check_boundary(scenario.problem, reference)
    except ConformanceError as error:
        failed = FailedReference(planner_spec.name, f"{error} (its reference does not perform the manoeuvre)",
                                 duration=reference.duration, stats=reference.stats)
        failed.plan_time_s = reference.plan_time_s
        return failed, None, None
    uniform = ReferenceSample(*(values[:REFERENCE_POINTS] for values in sample))
    # the rate's jumps are impulses no sample sees: the metrics add them (int_u2 and the peak torque +inf),
    # a start the reference declares free included (the actuator requirement exempts it: initial_rate_error
    # reports it; but the manoeuvre from its ω0 needs that impulse all the same)
    jumps = [jump for _, _, jump in rate_jumps(times[:REFERENCE_POINTS], uniform.omega, scenario.problem.omega0,
                                                reference)]
    start = uniform.omega[0] - np.asarray(scenario.problem.omega0, dtype=float)
    if "omega0" in reference.free_boundary and np.linalg.norm(start) > JUMP_TOLERANCE:
        jumps.insert(0, start)
    metrics = metrics_from_reference(
        reference, scenario.problem.qf, scenario.problem.omegaf, points=REFERENCE_POINTS,
        settling_tolerance_deg=spec.settling_tolerance_deg,
        fine_settling_tolerance_deg=spec.fine_settling_tolerance_deg,
        inertia=scenario.problem.spacecraft.inertia, detumble_tolerance=spec.detumble_tolerance,
        initial_omega=scenario.problem.omega0,
        sample=uniform, rate_jumps=jumps or None)
    return reference, metrics, (times, sample) if scoring else None


class _Watched:
    """:func:`run`'s ``references`` noting whether a ``get`` found its entry (``reused``: nothing
    was built), for the row's ``plan_reused``."""

    def __init__(self, kept: Any) -> None:
        self.kept, self.reused = kept, False

    def get(self, key: Any, build: Callable[[], Any]) -> Any:
        """``kept.get(key, build)``, setting ``reused`` when ``build`` was not called."""
        built = False

        def building() -> Any:
            nonlocal built
            built = True
            return build()

        value = self.kept.get(key, building)
        self.reused = not built
        return value


class _NotKept(Exception):
    """Carries a failed reference out of a cache's ``build``, so that the cache does not keep it."""

    def __init__(self, reference: Reference) -> None:
        super().__init__(reference.message)
        self.reference = reference


def _interruption(error: BaseException) -> BaseException | None:
    """The signal's exception (a study's :class:`~scenarios.errors.CaseTimeout`, Ctrl-C's
    ``KeyboardInterrupt``) that ``error`` carries as its direct cause, if any: a signal handler's
    exception raised inside a C call (CasADi's) comes back wrapped, as a ``SystemError`` whose
    cause it is. Nothing else: an error raised while handling another exception (its context), or
    one a planner raises ``from`` a ``GeneratorExit`` or ``SystemExit``, stays the planner's error."""
    cause = error.__cause__
    return cause if isinstance(cause, (CaseTimeout, KeyboardInterrupt)) else None


def _plan(planner: Any, name: str, problem: Any) -> Reference:
    """``planner.plan(problem)``; a planner that raises gives a failed reference naming it; an
    interruption wrapped by a C call is raised as itself (:func:`_interruption`)."""
    try:
        return planner.plan(problem)
    except Exception as error:  # noqa: BLE001 (a planner bug must not lose the other rows)
        interruption = _interruption(error)
        if interruption is not None:
            raise interruption from None
        traceback.print_exc()
        return FailedReference(name, f"planner raised {type(error).__name__}: {error}")


def _kept_or_planned(kept: Any, key: tuple[Any, ...], planner: Any, name: str, problem: Any) -> Reference:
    """A copy of the reference ``kept`` holds under ``key``, else one planned now (kept if it
    succeeded). The copy has its own ``stats`` (:func:`_cross_check_optima` writes there)."""
    def build() -> Reference:
        reference = _plan(planner, name, problem)
        if not reference.ok:  # a failure may be the machine's (a time limit): planned again next time
            raise _NotKept(reference)
        return reference

    try:
        original = kept.get(key, build)
    except _NotKept as failure:
        return failure.reference
    reference = copy.copy(original)
    reference.stats = dict(original.stats)  # the run replaces entries (the certificate), never edits one
    return reference


def planning_key(planner: Any, problem: Any) -> tuple[Any, ...] | None:
    """What a plan depends on, hashed: two plans with the same key give the same reference.

    A planner that declares ``deterministic`` (:attr:`planners.Planner.deterministic`, the default;
    the built-in planners do: their multistarts' random starts are seeded, a time limit can only
    make them fail, and a failed reference is never reused; the conformance check
    :func:`planners.conformance.check_deterministic` verifies it) has its reference fixed by its class,
    its instance's state (its registry name and validated options; not the solver cache it builds
    into, which changes how fast it plans, not what) and the problem it is given: every field of
    the :class:`~planners.ManeuverProblem` (spacecraft, environment, boundary conditions,
    duration, rate bound, pointing constraints with their direction tables, actuator margin),
    whether or not the planner reads it, stated by :func:`ocp.cache.exact_key`: numbers are compared
    exactly (bit for bit), however deep they sit. The class's
    ``plan`` and ``_plan`` are in the key as objects: a method replaced at run time (a test's
    monkeypatch) makes another key.

    Parameters
    ----------
    planner : planners.Planner
        The row's planner (its options validated).
    problem : planners.ManeuverProblem
        The manoeuvre it plans.

    Returns
    -------
    tuple or None
        The SHA-256 hex digest of the inputs, then the class's ``plan`` and ``_plan``; ``None``
        when the planner declares ``deterministic = False`` or an input cannot be stated exactly
        (an option or a field holding a callable or an object of unknown kind): the row is then
        always planned.
    """
    kind = type(planner)
    if not getattr(kind, "deterministic", True):
        return None
    state = {name: value for name, value in vars(planner).items() if name != "cache"}
    try:
        text = repr((f"{kind.__module__}.{kind.__qualname__}", exact_key(state), exact_key(problem)))
    except Unkeyable:
        return None
    return hashlib.sha256(text.encode()).hexdigest(), kind.plan, getattr(kind, "_plan", None)


def _first_non_finite(times: np.ndarray, sample: ReferenceSample) -> str | None:
    """Where a sample first holds a value that is not finite (nan, inf), naming the quantity."""
    if all(np.isfinite(values.sum()) for values in sample):  # the usual case, fast (an overflow looks below)
        return None
    bad = np.zeros(times.size, dtype=bool)
    for values in sample:
        bad |= ~np.all(np.isfinite(values), axis=1)
    if not np.any(bad):
        return None
    k = int(np.argmax(bad))
    fields = [name for name, values in zip(("q", "omega", "omega_dot", "torque"), sample)
              if not np.all(np.isfinite(values[k]))]
    return (f"its reference is not finite at t = {times[k]:.4g} s ({', '.join(fields)}; {int(np.sum(bad))} of "
            f"{times.size} times sampled on [{times[0]:g}, {times[-1]:g}] s)")


def _sampled(reference: Reference, times: np.ndarray) -> ReferenceSample | str:
    """A planner's reference sampled at ``times`` once it is planned, or why it cannot be used.

    The reference's ``_evaluate`` is the planner's code: an exception it raises, or a value that is
    not finite, fails the planner's row (the traceback on stderr), not the run; the closed loop,
    the metrics and the scores would otherwise meet the NaN (or the exception) far from its cause.
    """
    try:
        sample = reference.sample(times)
    except Exception as error:  # noqa: BLE001 (a planner bug must not lose the other rows)
        interruption = _interruption(error)
        if interruption is not None:
            raise interruption from None
        # the coast after T starts from the state at T, and raises on a NaN there: find the first within [0, T]
        within = times[times <= reference.duration]
        try:
            located = _first_non_finite(within, reference.sample(within))
        except Exception:  # noqa: BLE001 (the same defect: reported below)
            located = None
        if located is not None:
            return located
        traceback.print_exc()
        return f"sampling its reference raised {type(error).__name__}: {error}"
    return _first_non_finite(times, sample) or sample
