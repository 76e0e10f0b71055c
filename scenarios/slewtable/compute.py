"""Compute a slew table through the trade-study engine, and fit it.

Every entry is a case of a :class:`scenarios.study.Study` built here (one per axis and angle, the
table's then the held-out grid's) and run by :func:`scenarios.study.sweep`: on the local process
pool or a Dask cluster, each finished case committed to the crash-safe store when a directory is
given (so a table run again into the same directory computes only the entries it lacks). An entry
whose solve fails, or that breaks a requirement, is kept with its status and message; only the
``ok`` entries are interpolated: the fit keeps every axis with its entries' statuses and has no value
(NaN) in the cells around an entry that is not ``ok`` (``inf`` at an ``infeasible`` one), rather than
a time the table did not find. An entry proven impossible before planning (its start or target
attitude already breaks a pointing requirement, or its angle needs longer than
``maneuver.duration`` at the rate bound; both say "no reference can meet it") is ``infeasible``, as
the run's row is (an entry stored ``failed`` for it by an earlier version is recorded
``infeasible`` too). A ``min_time`` entry whose slew meets every requirement, but whose
target, held after the slew until ``maneuver.duration``, enters a moving cone, is ``ok`` (an entry
is the slew: its time and feasibility) and its message says when the cone reaches the target. A ``min_time`` entry that the planner found slower than a
feasible slew of the same problem it knows (its certificate's ``seed_bound`` note: "not the best
known") stays ``ok`` and is fitted (its time is achieved by its own reference), and is marked
(:attr:`TablePart.best_known` false; the fit's note counts them).

With a tolerance (``TableSpec.refine``) the table's axes are then refined where the fit misses
(:func:`scenarios.slewtable.refine.refine`): each round's entries are one more study through the
same engine and store, so an interrupted refinement also resumes where it stopped.
"""
from __future__ import annotations

import json
import math
import statistics
import time
import timeit
from concurrent.futures import Executor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from scenarios.slewtable.fit import SlewTimeFit
from scenarios.slewtable.spec import (
    TableCase,
    TableSpec,
    case_scenario,
    rate_limits,
    table_cases,
    torque_generators,
)

__all__ = ["FIT_TARGET", "PART_NAMES", "TIMED_OUT", "UNDERACTUATED_NOTE", "SlewTable", "TablePart", "compute_table",
           "end_cones", "eval_time_us", "fit_entries", "held_out_errors", "quality_lines", "slower_than_known",
           "timed_out_message"]

PART_NAMES = ("table", "held_out", "check")
"""The grids of a table: the fitted one, the held-out one, and the refinement's check points that
were not split (so not in the fit; empty without refinement)."""


@dataclass
class TablePart:
    """One grid's entries (axes by angles).

    Parameters
    ----------
    axes : numpy.ndarray, shape (n, 3)
        Unit eigen-axes, body frame.
    angles_deg : list of float
        Slew angles [deg].
    slew_time_s : numpy.ndarray, shape (n, k)
        Slew time [s] (NaN where the entry has none).
    objective_value : numpy.ndarray, shape (n, k)
        The objective's value: the slew time [s] for ``min_time``, ``∫‖u‖² dt`` [N² m² s] for
        ``min_energy`` (NaN where none).
    plan_time_s : numpy.ndarray, shape (n, k)
        The planner's wall time [s] (NaN where none).
    status : list of list of str
        Each entry's status (``ok``, ``violated``, ``infeasible``, ``failed``, ``timed_out``: the
        planner ran out of ``case_timeout_s`` without an error, ``crashed``, ``missing``).
    message : list of list of str
        Each entry's message.
    best_known : list of list of (bool or None), optional
        For a ``min_time`` entry with a slew time: False where the planner knows a faster
        feasible slew of the same problem (:func:`slower_than_known`; the message names it), True
        where it knows none; None where the question does not apply (no slew time, or a
        ``min_energy`` table). Default: None everywhere.
    """

    axes: np.ndarray
    angles_deg: list[float]
    slew_time_s: np.ndarray
    objective_value: np.ndarray
    plan_time_s: np.ndarray
    status: list[list[str]]
    message: list[list[str]]
    best_known: list[list[bool | None]] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.best_known:
            self.best_known = [[None] * len(row) for row in self.status]

    @classmethod
    def empty(cls, axes: np.ndarray, angles_deg: list[float]) -> TablePart:
        """A part with every entry ``missing``.

        Parameters
        ----------
        axes : numpy.ndarray, shape (n, 3)
            Unit eigen-axes, body frame.
        angles_deg : list of float
            Slew angles [deg].

        Returns
        -------
        TablePart
        """
        shape = (len(axes), len(angles_deg))
        return cls(np.asarray(axes, dtype=float).reshape(-1, 3), list(angles_deg), np.full(shape, np.nan),
                   np.full(shape, np.nan), np.full(shape, np.nan),
                   [["missing"] * shape[1] for _ in range(shape[0])], [[""] * shape[1] for _ in range(shape[0])])

    @property
    def not_best_known(self) -> np.ndarray:
        """Where an entry is ``ok`` and the planner knows a faster feasible slew, shape (n, k): it is
        fitted, its time an achievable one, not the best known."""
        return self.ok & np.array([[flag is False for flag in row] for row in self.best_known],
                                  dtype=bool).reshape(self.slew_time_s.shape)

    @property
    def ok(self) -> np.ndarray:
        """Where an entry is ``ok`` with a finite slew time, shape (n, k)."""
        return np.array([[s == "ok" for s in row] for row in self.status], dtype=bool).reshape(
            self.slew_time_s.shape) & np.isfinite(self.slew_time_s)


@dataclass
class SlewTable:
    """A computed slew table, its held-out grid and its fit.

    Parameters
    ----------
    spec : TableSpec
        What was computed.
    parts : dict
        ``table`` and ``held_out`` -> :class:`TablePart`.
    wall_time_s : float
        Wall time of the computation [s] (entries found in the store cost nothing).
    stored : int
        Entries found already computed in the store (not ``crashed``: those run again).
    rerun : int
        Entries found ``crashed`` in the store (raised or killed their worker), run again.
    rerun_timed_out : int
        Entries found ``timed_out`` in the store (the engine's ``crashed`` of a case that ran out of
        ``case_timeout_s``), run again.
    fit : SlewTimeFit or None
        The fit (None when it could not be made: :attr:`fit_note` says why).
    fit_note : str
        Why there is no fit, or which axes were left out of it.
    fit_quality : dict
        The fit's errors on the held-out grid (:func:`held_out_errors`) and its evaluation time
        ``eval_time_us`` [µs per call]; empty without a fit.
    refinement : dict
        The refinement's figures (:meth:`scenarios.slewtable.refine.RefineResult.summary`, with
        ``tolerance``; a round's ``max_miss`` None where it is unbounded: a check whose entry or
        fit has no time); empty without one.
    """

    spec: TableSpec
    parts: dict[str, TablePart]
    wall_time_s: float = 0.0
    stored: int = 0
    rerun: int = 0
    rerun_timed_out: int = 0
    fit: SlewTimeFit | None = None
    fit_note: str = ""
    fit_quality: dict[str, Any] = field(default_factory=dict)
    refinement: dict[str, Any] = field(default_factory=dict)


def _study(spec: TableSpec, cases: list[TableCase]) -> Any:
    from scenarios.output.provenance import package_version
    from scenarios.study.types import Case, Execution, Study, case_key
    version = package_version()
    study_cases = [Case(index, 0, index, {"maneuver.final.q": json.dumps(case.scenario["maneuver"]["final"]["q"])},
                        case.scenario, case_key(case.scenario, version)) for index, case in enumerate(cases)]
    execution = Execution(spec.workers, spec.scheduler, spec.case_timeout_s, 1)
    return Study(f"table {spec.name}", spec.source, spec.base, ["maneuver.final.q"], [], 1, None, 0, [], execution,
                 study_cases, {"table": spec.name}, units=("entry", "entries"))


def end_cones(scenario: dict[str, Any]) -> np.ndarray:
    """The pointing requirements' cones that an entry's target is checked against, for the fit.

    The same check as an entry's own (:func:`scenarios.requirements.scoring.endpoint_violations`):
    the target at the scenario's duration, or at a window's start when it opens later; a cone whose
    window has closed by then is left out. For a ``min_time`` table (T only bounds the slew) a
    moving cone is narrowed (a keep-out) or widened (a keep-in) by how far it may move back over
    ``[0, T]`` (:func:`~scenarios.requirements.scoring.target_slack`): inside it the target breaks the
    cone whenever the slew ends; one whose window does not cover ``[0, T]``, or that nothing
    breaks at every such time, is left out.

    Parameters
    ----------
    scenario : dict
        One entry's scenario (plain YAML data; its target does not matter).

    Returns
    -------
    numpy.ndarray, shape (c, 8)
        A row per cone: the body boresight, the inertial direction at that time (unit vectors), the
        cosine of the half-angle there (its growth included) and 1 for a keep-out, 0 for a keep-in
        (:class:`~scenarios.slewtable.fit.SlewTimeFit`'s ``end_cones``); no rows without pointing
        requirements.
    """
    from scenarios.requirements.scoring import target_slack
    from scenarios.schema.loader import parse_scenario
    parsed = parse_scenario(scenario)
    problem = parsed.problem
    free_time = _free_time(parsed)
    rows = []
    for constraint in problem.pointing:
        time = max(float(problem.duration), constraint.window[0])
        slack = target_slack(constraint, float(problem.duration), free_time)
        if not bool(constraint.in_window([time])[0]) or slack is None:
            continue
        # a minimum-time slew may end before T: a moving cone narrowed by how far it can move back
        limit = float(constraint.limit([time])[0]) + (-slack if constraint.keep_out else slack)
        if not 0.0 < limit < math.pi:
            continue  # no attitude breaks it at every time the slew may end
        direction = constraint.direction([time])[0]
        rows.append([*constraint.boresight, *direction, math.cos(limit), 1.0 if constraint.keep_out else 0.0])
    return np.array(rows, dtype=float).reshape(-1, 8)


def _proven_infeasible(scenario: dict[str, Any]) -> bool:
    """Whether the entry is proven impossible before planning (:func:`~scenarios.requirements.scoring.endpoint_violations`:
    its start or target attitude already breaks a pointing requirement, or its angle needs longer
    than ``maneuver.duration`` at the rate bound; the run's row ``infeasible``), as the run checks
    it for the entry's planner (a ``min_time`` one: ``maneuver.duration`` bounds the slew's end).
    A stored entry that an earlier version ran ``failed`` for a pointing end point is recorded
    ``infeasible`` by the table (a store keeps its records across versions)."""
    from scenarios.errors import ScenarioError
    from scenarios.requirements.scoring import endpoint_violations
    from scenarios.schema.loader import parse_scenario
    if not scenario:
        return False
    try:
        parsed = parse_scenario(scenario)
    except ScenarioError:
        return False
    return bool(endpoint_violations(parsed.problem, _free_time(parsed)))


def _free_time(parsed: Any) -> bool:
    """Whether the entry's planner minimises time (:func:`planners.capabilities.minimises_time`)."""
    from planners.capabilities import minimises_time
    return any(minimises_time(type(spec.planner), spec.planner.options) for spec in parsed.planners)


def _broken_after_slew(row: dict[str, Any]) -> bool:
    """Whether a ``violated`` row breaks only pointing requirements, each first after its slew ends
    (the target held into a moving cone before ``maneuver.duration``): its reference's scores, and
    the token closed loop's for those requirements only."""
    from scenarios.requirements.fields import VERDICT
    requirements = row.get("requirements") or {}
    duration = (row.get("reference") or {}).get("duration_s")
    reference = requirements.get("reference") or {}
    broken = {name: values for name, values in reference.items() if not values.get(VERDICT, True)}
    if duration is None or not broken:
        return False
    late = all(values.get("first_violation_s") is not None and values["first_violation_s"] > float(duration)
               for values in broken.values())
    loop = {name for name, values in (requirements.get("closed_loop") or {}).items() if not values.get(VERDICT, True)}
    return late and loop <= set(broken)


def slower_than_known(row: dict[str, Any]) -> str:
    """What says that a planned row's minimum time is slower than a feasible slew its planner knows.

    Parameters
    ----------
    row : dict
        A run's row as the engine stores it (:meth:`scenarios.output.results.Row.to_dict`).

    Returns
    -------
    str
        The certificate's ``seed_bound`` note (``collocation``'s "slower than a feasible slew of
        this problem, ...: not the best known", :mod:`planners.collocation.planner`), which the
        row's message also ends with; empty when the row has none.
    """
    certificate = row.get("certificate")
    note = certificate.get("seed_bound") if isinstance(certificate, dict) else None
    return note if isinstance(note, str) else ""


TIMED_OUT = "timed out after "
"""How the engine's message of a case that ran out of ``case_timeout_s`` begins
(:func:`scenarios.study.worker.timed_out_message`): the table's entry is then ``timed_out``."""


def timed_out_message(engine_message: str) -> str:
    """What a ``timed_out`` entry says: the engine's message, and what it means.

    Parameters
    ----------
    engine_message : str
        The engine's ``timed out after <limit> s (case_timeout_s)`` (with ``; worker stopped`` when
        the driver stopped the worker).

    Returns
    -------
    str
        The message, saying that the planner was still solving (no error, not a crash), that the
        slew time is unknown and the slew may be possible, and which flag or key gives it more time.
    """
    return (f"{engine_message}: the planner was still solving (no error, not a crash); the slew time is unknown "
            "and the slew may be possible: give it more time (slewbench table --case-timeout, or "
            "table.execution.case_timeout_s in a table file) and run the table again into the same --out")


UNDERACTUATED_NOTE = ("; the spacecraft has torque about fewer than three independent axes (underactuated): its "
                      "minimum-time solves take many times longer than a fully actuated one's, and may run to ipopt's "
                      "iteration limit (failed) given the time; table.planner_options {time_regularization: 0.02} "
                      "converges more often (the slew-table guide)")
"""What a ``timed_out`` entry of an underactuated spacecraft adds (:func:`compute_table`)."""


def _timed_out(record: dict[str, Any]) -> bool:
    """Whether an engine's ``crashed`` record ran out of ``case_timeout_s`` (the table's ``timed_out``)."""
    rows = record.get("rows") or [{}]
    return str(rows[0].get("message") or "").startswith(TIMED_OUT)


def _fill(part: TablePart, case: TableCase, record: dict[str, Any] | None, objective: str) -> None:
    i, k = case.axis_index, case.angle_index
    if record is None or not record.get("rows"):
        return
    row = record["rows"][0]
    part.status[i][k] = str(row.get("status"))
    if part.status[i][k] == "failed" and _proven_infeasible(case.scenario):
        part.status[i][k] = "infeasible"
    part.message[i][k] = str(row.get("message") or "")
    if part.status[i][k] == "violated" and objective == "min_time" and _broken_after_slew(row):
        part.status[i][k] = "ok"  # the slew meets them: only its target, held after it, does not (message)
    if part.status[i][k] == "crashed" and _timed_out(record):
        part.status[i][k] = "timed_out"  # ran out of case_timeout_s: no error, the time unknown
        part.message[i][k] = timed_out_message(part.message[i][k])
    if row.get("plan_time_s") is not None:
        part.plan_time_s[i, k] = float(row["plan_time_s"])
    reference = row.get("reference") or {}
    duration = reference.get("duration_s")
    if duration is not None and row.get("status") in ("ok", "violated"):
        part.slew_time_s[i, k] = float(duration)
        value = duration if objective == "min_time" else reference.get("int_u2")
        if value is not None:
            part.objective_value[i, k] = float(value)
        if objective == "min_time" and np.isfinite(part.slew_time_s[i, k]):
            part.best_known[i][k] = not slower_than_known(row)


def _plural(count: int, word: str, words: str | None = None) -> str:
    """``1 axis``, ``2 axes``."""
    return f"{count} {word if count == 1 else (words or word + 's')}"


def fit_entries(part: TablePart, inertia: np.ndarray | None = None, generators: np.ndarray | None = None,
                meta: dict[str, Any] | None = None, triangles: np.ndarray | None = None,
                rates: tuple[np.ndarray, float | None] | None = None,
                cones: np.ndarray | None = None) -> tuple[SlewTimeFit | None, str]:
    """Fit a grid's ``ok`` entries; the others are kept as gaps (module docstring).

    Parameters
    ----------
    part : TablePart
        The table's grid.
    inertia : numpy.ndarray, shape (3, 3), optional
        [kg m²], body frame.
    generators : numpy.ndarray, shape (m, 3), optional
        Torque generators [N m], body frame (:func:`torque_generators`).
    meta : dict, optional
        Kept with the fit.
    triangles : numpy.ndarray, shape (t, 3), optional
        The grid's triangles (:func:`scenarios.slewtable.grid.polytope_grid`); None: the convex hull
        of the axes.
    rates : tuple of (numpy.ndarray, float or None), optional
        The momentum generators [N m s] and rate bound [rad/s] of the fit's baseline
        (:func:`rate_limits`); None: no rate cap.
    cones : numpy.ndarray, shape (c, 8), optional
        The pointing requirements' cones at the end of a slew (:func:`end_cones`); None: none.

    Returns
    -------
    fit : SlewTimeFit or None
        None when no fit can be made (fewer than 4 axes, axes that do not span the sphere, or no
        ``ok`` entry).
    note : str
        Why not, or how many entries are not ok and where the fit has no value, and how many
        fitted entries are not the best known (:attr:`TablePart.not_best_known`: fitted, their
        time an achievable one) ("" when every entry is ok and none is flagged).
    """
    angles = np.deg2rad(part.angles_deg)
    ok = part.ok
    status = [[s if good else ("missing" if s == "ok" else s) for s, good in zip(row, flags)]
              for row, flags in zip(part.status, ok.tolist())]  # "ok" without a finite time is not ok
    notes = []  # without a fit, what is not ok is said alone: there is no fit to give NaN around it
    bad = int((~ok).sum())
    if bad:
        infeasible = sum(s == "infeasible" for row in status for s in row)
        notes.append(f"{_plural(bad, 'entry', 'entries')} not ok ({infeasible} infeasible)")
    if len(part.axes) < 4:
        return None, "; ".join([*notes, (f"no fit over the sphere: {_plural(len(part.axes), 'axis', 'axes')} "
                                         "(4 or more spanning the sphere needed)")])
    if not ok.any():
        return None, "; ".join([*notes, "no fit: no entry is ok"])
    try:
        momentum, max_rate = rates if rates is not None else (None, None)
        fit = SlewTimeFit(angles, part.axes, np.where(ok, part.slew_time_s, np.nan), meta, inertia, generators,
                          triangles, status, momentum, max_rate, cones)
    except ValueError as error:
        return None, "; ".join([*notes, f"no fit: {error}"])
    if bad:
        notes[0] += (f": the fit gives NaN in the cells around {'it' if bad == 1 else 'them'} (inf at an infeasible "
                     "one), not a time")
    slower = int(part.not_best_known.sum())
    if slower:
        notes.append(f"{_plural(slower, 'fitted entry', 'fitted entries')} slower than a feasible slew the planner "
                     "knows (best_known false: the fit's time there is achievable, not the best known)")
    return fit, "; ".join(notes)


def eval_time_us(fit: SlewTimeFit, repeats: int = 7, number: int = 2000) -> float:
    """Median over ``repeats`` of the mean CPU time of one ``fit(q0, qf)`` call on tuples [µs]
    (64 random attitude pairs; ``q0`` the identity for a fit of slews from the identity only).

    CPU time of this process (``time.process_time``), not wall time: on a shared machine the wall
    clock counts the time other processes hold the core.

    Parameters
    ----------
    fit : SlewTimeFit
        The fit.
    repeats, number : int, optional
        ``timeit.repeat`` arguments.

    Returns
    -------
    float
        [µs] per call.
    """
    rng = np.random.default_rng(0)
    q = rng.normal(size=(64, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    identity = bool(fit.meta.get("from_identity_only"))  # then every slew starts at the identity
    pairs = [((1.0, 0.0, 0.0, 0.0) if identity else tuple(q[i].tolist()), tuple(q[(i + 1) % 64].tolist()))
             for i in range(64)]
    loops = max(1, number // 64)

    def run() -> None:
        for a, b in pairs:
            fit(a, b)

    times = timeit.repeat(run, timer=time.process_time, number=loops, repeat=repeats)
    return statistics.median(times) / (loops * len(pairs)) * 1e6


FIT_TARGET = 0.01
"""The fit's target: its error on held-out points at most this fraction of the slew time (issue 30)."""


def held_out_errors(fit: SlewTimeFit, part: TablePart, table_angles_deg: list[float] | None = None) -> dict[str, Any]:
    """The fit's signed relative error ``fit / truth - 1`` on a held-out grid's ``ok`` entries.

    Parameters
    ----------
    fit : SlewTimeFit
        The fit.
    part : TablePart
        The held-out grid (axes not in the table, at the table's angles and their midpoints:
        :func:`scenarios.slewtable.grid.held_out_angles`).
    table_angles_deg : list of float, optional
        The table's angles [deg]: each held-out angle is reported as ``table`` (the fit interpolates
        over axes only) or ``midpoint`` (over axes and angles). None: every one is ``midpoint``
        unless it is the fit's own angle.

    Returns
    -------
    dict
        ``points`` (ok entries compared); ``max_over_error`` (the largest over-estimate, ``fit``
        above the solve, a fraction of the solved slew time, >= 0), ``max_under_error`` (the
        largest under-estimate, >= 0), ``max_rel_error`` (the larger of the two) and
        ``rms_rel_error`` (None without points); ``target`` (:data:`FIT_TARGET`) and ``target_met``
        (``max_rel_error <= target``; None without points); ``worst`` (axis, angle [deg], solved
        and fitted times [s], signed error) and ``worst_under`` (the same at the largest
        under-estimate, None without one); ``by_angle`` (per held-out angle [deg]: ``kind``,
        ``points``, ``max_over_error``, ``max_under_error``, and ``min_error`` and ``max_error``, the
        range of the signed errors there); ``held_out`` (what the set is:
        ``axes``, ``angles_deg``, ``table_angles_deg``, ``midpoint_angles_deg``); ``no_value`` (ok
        entries where the fit has no time, in a cell around an entry that is not ok: not compared);
        ``timed_infeasible`` (``infeasible`` held-out entries where the fit gives a finite time: a
        time for a slew that cannot be made; any makes ``target_met`` false) and
        ``timed_infeasible_example`` (one of them: axis, angle [deg], fitted time [s]; None without).
    """
    fitted = np.rad2deg(fit.angles).tolist()
    table_angles = [float(a) for a in (fitted if table_angles_deg is None else table_angles_deg)]

    def on_table(angle: float) -> bool:
        return any(abs(angle - a) <= 1e-9 * max(1.0, abs(a)) for a in table_angles)

    kinds = ["table" if on_table(float(a)) else "midpoint" for a in part.angles_deg]
    described = {"axes": len(part.axes), "angles_deg": [float(a) for a in part.angles_deg],
                 "table_angles_deg": [float(a) for a, kind in zip(part.angles_deg, kinds) if kind == "table"],
                 "midpoint_angles_deg": [float(a) for a, kind in zip(part.angles_deg, kinds) if kind == "midpoint"]}
    none: dict[str, Any] = {"points": 0, "max_rel_error": None, "max_over_error": None, "max_under_error": None,
                            "rms_rel_error": None, "target": FIT_TARGET, "target_met": None, "worst": None,
                            "worst_under": None, "by_angle": [], "held_out": described, "no_value": 0,
                            "timed_infeasible": 0, "timed_infeasible_example": None}
    impossible = np.array([[status == "infeasible" for status in row] for row in part.status], dtype=bool)
    if impossible.size and impossible.any():
        a, b = np.nonzero(impossible)
        guessed = fit.many_axis_angle(part.axes[a], np.deg2rad(np.asarray(part.angles_deg, dtype=float))[b])
        timed = np.isfinite(guessed)
        none["timed_infeasible"] = int(timed.sum())
        if timed.any():
            w = int(np.argmax(timed))
            none["timed_infeasible_example"] = {"axis": part.axes[a[w]].tolist(), "angle_deg": float(part.angles_deg[b[w]]),
                                              "fit_s": float(guessed[w])}
    ok = part.ok
    if not ok.any():
        return none
    i, k = np.nonzero(ok)
    truth = part.slew_time_s[i, k]
    angles = np.deg2rad(np.asarray(part.angles_deg, dtype=float))[k]
    estimate = fit.many_axis_angle(part.axes[i], angles)
    finite = np.isfinite(estimate)
    if not finite.all():
        i, k, truth, estimate = i[finite], k[finite], truth[finite], estimate[finite]
    none["no_value"] = int((~finite).sum())
    if not finite.any():
        return none
    signed = estimate / truth - 1.0
    over, under = max(float(signed.max()), 0.0), max(float(-signed.min()), 0.0)

    def point(w: int) -> dict[str, Any]:
        return {"axis": part.axes[i[w]].tolist(), "angle_deg": float(part.angles_deg[k[w]]), "table_s": float(truth[w]),
                "fit_s": float(estimate[w]), "error": float(signed[w])}

    by_angle = []
    for column, angle in enumerate(part.angles_deg):
        here = signed[k == column]
        if len(here):
            by_angle.append({"angle_deg": float(angle), "kind": kinds[column], "points": len(here),
                             "max_over_error": max(float(here.max()), 0.0),
                             "max_under_error": max(float(-here.min()), 0.0),
                             "min_error": float(here.min()), "max_error": float(here.max())})
    largest = max(over, under)
    return {"points": len(signed), "max_rel_error": largest, "max_over_error": over, "max_under_error": under,
            "rms_rel_error": float(np.sqrt(np.mean(signed ** 2))), "target": FIT_TARGET,
            "target_met": bool(largest <= FIT_TARGET and not none["timed_infeasible"]),
            "worst": point(int(np.argmax(np.abs(signed)))),
            "worst_under": point(int(np.argmin(signed))) if under > 0.0 else None, "by_angle": by_angle,
            "held_out": described, "no_value": none["no_value"], "timed_infeasible": none["timed_infeasible"],
            "timed_infeasible_example": none["timed_infeasible_example"]}


def quality_lines(quality: dict[str, Any]) -> list[str]:
    """What the command says of a fit's held-out errors (:func:`held_out_errors`), naming the set.

    Parameters
    ----------
    quality : dict
        :func:`held_out_errors`'s result, with ``eval_time_us``.

    Returns
    -------
    list of str
        The lines: the signed errors and the target's verdict, then what the held-out set is and
        the errors at each held-out angle.
    """
    evaluation = f"evaluation {quality['eval_time_us']:.2f} us CPU per call"
    timed = quality.get("timed_infeasible") or 0
    impossible = []
    if timed:
        example = quality["timed_infeasible_example"]
        impossible.append(f"fit: gives a time for {_plural(timed, 'infeasible held-out entry', 'infeasible held-out entries')}"
                          f" (a slew that cannot be made; target NOT met), e.g. {example['fit_s']:.4g} s at "
                          f"{example['angle_deg']:g} deg about [{', '.join(f'{v:.3f}' for v in example['axis'])}]")
    unknown = quality.get("no_value") or 0
    if unknown:  # NaN: the fit does not know (cells beside entries that are not ok), not compared
        compared = quality.get("points") or 0
        impossible.append(f"fit: no time at {unknown} of {unknown + compared} ok held-out entries "
                          f"({100 * unknown / (unknown + compared):.3g} %: cells beside entries that are not ok; NaN, "
                          "not compared)")
    if not quality.get("points"):
        return [f"fit: no held-out points; {evaluation}", *impossible]
    held = quality["held_out"]
    verdict = "met" if quality["target_met"] else "NOT met"
    degrees = ", ".join(f"{a:g}" for a in held["table_angles_deg"])
    mids = ", ".join(f"{a:g}" for a in held["midpoint_angles_deg"])
    angles = f"at the table's angles ({degrees} deg)" + (f" and their midpoints ({mids} deg)" if mids else "")
    worst = quality["worst"]
    lines = [f"fit: held-out error from {_signed(-quality['max_under_error'])} % (largest under-estimate) to "
             f"{_signed(quality['max_over_error'])} % (largest over-estimate), RMS {100 * quality['rms_rel_error']:.3g} "
             f"% of the slew time ({quality['points']} points); target {100 * quality['target']:g} %: {verdict} "
             f"(worst {100 * worst['error']:+.3g} % at {worst['angle_deg']:g} deg about "
             f"[{', '.join(f'{v:.3f}' for v in worst['axis'])}]); {evaluation}",
             f"fit: held-out points: {held['axes']} axes not in the table, {angles}"]
    lines.append("fit: held-out error by angle: " + "; ".join(
        f"{item['angle_deg']:g} deg ({item['kind']}) {_signed(item['min_error'])} to "
        f"{_signed(item['max_error'])} %" for item in quality["by_angle"]))
    return lines + impossible


def _signed(fraction: float) -> str:
    """A signed fraction in percent (``0`` without a sign: none)."""
    return "0" if fraction == 0.0 else f"{100 * fraction:+.3g}"


def compute_table(spec: TableSpec, directory: str | Path | None = None, *, workers: int | None = None,
                  cluster: Any = None, executor: Executor | None = None, progress: bool = False) -> SlewTable:
    """Compute every entry of a table (and its held-out grid) and fit it.

    Parameters
    ----------
    spec : TableSpec
        The table (:func:`scenarios.slewtable.spec.parse_table_spec`).
    directory : str or Path or None, optional
        A claimed directory to keep the engine's store in (entries already there are not
        computed again); None: memory only.
    workers : int or None, optional
        Cases at once (None: ``spec.workers``, else one per core).
    cluster : DaskCluster or None, optional
        A connected Dask cluster (:func:`scenarios.study.connect_scheduler`); None: the local pool
        (or ``spec.scheduler``, connected here).
    executor : concurrent.futures.Executor or None, optional
        Any executor instead (:func:`scenarios.study.sweep`'s); None: the local pool or ``cluster``.
    progress : bool, optional
        Show the engine's progress bar.

    Returns
    -------
    SlewTable
        The entries, the fit and its quality (held-out errors, evaluation time).

    Raises
    ------
    SweepInterrupted
        Interrupted (committed entries stay in the store).
    """
    from scenarios.study.store import SweepStore
    cases = table_cases(spec)
    start = time.perf_counter()
    store = SweepStore(directory) if directory is not None else None
    parts = {"table": TablePart.empty(spec.axes, spec.angles_deg),
             "held_out": TablePart.empty(spec.held_out_axes, spec.held_out_angles_deg),
             "check": TablePart.empty(np.zeros((0, 3)), spec.angles_deg)}
    table = SlewTable(spec, parts)
    run = _Runner(spec, store, workers or spec.workers, cluster, executor, progress)
    try:
        for case, record in zip(cases, run(cases)):
            _fill(parts[case.part], case, record, spec.objective)
        inertia, generators = torque_generators(spec.base)
        rates = rate_limits(spec.base)
        cones = end_cones(cases[0].scenario) if cases else None
        triangles = spec.triangles
        if spec.refine is not None:
            triangles = _refine(table, run, inertia, generators, rates, cones, _fit_meta(spec))
    finally:
        if store is not None:
            store.close()
    table.wall_time_s = time.perf_counter() - start
    table.stored, table.rerun, table.rerun_timed_out = run.stored, run.rerun, run.rerun_timed_out
    if len(generators) and np.linalg.matrix_rank(generators, tol=1e-9 * float(np.max(np.abs(generators)))) < 3:
        for part in table.parts.values():
            for statuses, messages in zip(part.status, part.message):
                for k, status in enumerate(statuses):
                    if status == "timed_out":
                        messages[k] += UNDERACTUATED_NOTE
    if spec.objective != "min_time":
        table.fit_note = "the fit is of minimum-time tables (this table is min_energy at a fixed duration)"
        return table
    meta = _fit_meta(spec)
    meta["grid"] = spec.grid
    if table.refinement:
        meta["refinement"] = table.refinement
    table.fit, table.fit_note = fit_entries(parts["table"], inertia, generators, meta, triangles, rates, cones)
    if table.fit is not None:
        quality = held_out_errors(table.fit, parts["held_out"], spec.angles_deg)
        if quality["no_value"]:
            missed = (f"{_plural(quality['no_value'], 'ok held-out entry', 'ok held-out entries')} where the fit "
                      "has no time (not compared)")
            table.fit_note = "; ".join([*filter(None, [table.fit_note]), missed])
        quality["eval_time_us"] = eval_time_us(table.fit)
        table.fit.meta["held_out"] = quality
        table.fit.meta["note"] = table.fit_note
        table.fit_quality = quality
    return table


def _fit_meta(spec: TableSpec) -> dict[str, Any]:
    """What a table's fit keeps of its scenario (the final fit's and the refinement's working fits'):
    its name and objective, and whether its times hold for slews from the identity only (pointing
    requirements or environment torques; then with the epoch, requirements and environment they
    hold for). A fit with end cones needs ``from_identity_only`` (:class:`SlewTimeFit`)."""
    meta = {"scenario": spec.name, "objective": spec.objective,
            "from_identity_only": _inertially_dependent(spec.base)}
    if meta["from_identity_only"]:  # what the times hold for: slews from the identity at the epoch
        written = {key: spec.base.get(key) for key in ("epoch", "requirements", "environment")}
        meta.update(json.loads(json.dumps(written, default=str)))  # YAML's dates as text
    return meta


class _Runner:
    """Runs table entries through the trade-study engine (one study per call), counting those found
    in the store (``stored``) and those found ``crashed`` there, run again: ``rerun_timed_out`` those
    that ran out of ``case_timeout_s`` (the table's ``timed_out``), ``rerun`` the others."""

    def __init__(self, spec: TableSpec, store: Any, workers: int | None, cluster: Any, executor: Executor | None,
                 progress: bool):
        self.spec, self.store, self.workers = spec, store, workers
        self.cluster, self.executor, self.progress = cluster, executor, progress
        self.stored = 0
        self.rerun = 0
        self.rerun_timed_out = 0
        self.entries = 0

    def __call__(self, cases: list[TableCase]) -> list[dict[str, Any] | None]:
        from scenarios.study.engine import sweep
        from scenarios.study.store import resume_counts
        if not cases:
            return []
        study = _study(self.spec, cases)
        if self.store is not None:  # a crashed entry is not kept: the engine runs it again
            counts = resume_counts(self.store, {case.key for case in study.cases})
            self.stored += counts.kept
            if counts.crashed:  # the engine's crashed: the table tells those that timed out apart
                keys = {case.key for case in study.cases}
                timed = sum(1 for key, record in self.store.records().items()
                            if key in keys and record["status"] == "crashed" and _timed_out(record))
                self.rerun += counts.crashed - timed
                self.rerun_timed_out += timed
        results = sweep(study, self.executor, workers=self.workers, store=self.store, progress=self.progress,
                        cluster=self.cluster, timeouts_apart=True)  # the table's timed_out entries
        self.entries += len(cases)
        return [results.records.get(study_case.key) for study_case in study.cases]


def _refine(table: SlewTable, run: _Runner, inertia: np.ndarray, generators: np.ndarray,
            rates: tuple[np.ndarray, float | None], cones: np.ndarray | None, meta: dict[str, Any]) -> np.ndarray:
    """Refine the table's axes (module docstring); the table part becomes the refined grid, the
    check points not split become the ``check`` part; its working fits carry ``meta``, the final
    fit's (:func:`_fit_meta`: with end cones they must hold for slews from the identity only).
    Returns the refined triangles."""
    from scenarios.slewtable.fit import _hull
    from scenarios.slewtable.grid import held_out_angles
    from scenarios.slewtable.refine import check_positions, refine
    spec = table.spec
    assert spec.refine is not None
    initial = table.parts["table"]
    entries: dict[tuple[tuple[float, ...], float], tuple[TableCase, dict[str, Any] | None]] = {}
    between = held_out_angles(spec.angles_deg)  # the table's angles and their midpoints: position p at 2 p

    def solve(axes: np.ndarray, positions: list[float]) -> np.ndarray:
        # a table angle is the table's entry (its angle index), a midpoint a check entry (its index in `between`)
        places = [(i, c, TableCase("table", i, int(p), axis, between[round(2 * p)],
                                   case_scenario(spec, axis, between[round(2 * p)])) if p == int(p) else
                   TableCase("check", i, round(2 * p), axis, between[round(2 * p)],
                             case_scenario(spec, axis, between[round(2 * p)])))
                  for i, axis in enumerate(axes) for c, p in enumerate(positions)]
        times = np.full((len(axes), len(positions)), np.nan)
        for (i, c, case), record in zip(places, run([case for *_, case in places])):
            entries[tuple(case.axis.tolist()), positions[c]] = (case, record)
            one = TablePart.empty(np.zeros((1, 3)), [case.angle_deg])
            _fill(one, TableCase(case.part, 0, 0, case.axis, case.angle_deg, case.scenario), record, spec.objective)
            if one.ok[0, 0]:
                times[i, c] = one.slew_time_s[0, 0]
            elif one.status[0][0] == "infeasible":
                times[i, c] = np.inf
        return times

    def predict(axes: np.ndarray, times: np.ndarray, triangles: np.ndarray) -> Any:
        part = TablePart.empty(axes, spec.angles_deg)
        part.slew_time_s[:] = np.where(np.isfinite(times), times, np.nan)
        part.status = [["ok" if np.isfinite(v) else ("infeasible" if v == np.inf else "failed") for v in row]
                       for row in times]
        fit, _ = fit_entries(part, inertia, generators, meta, triangles, rates, cones)
        if fit is None:
            return None
        at = np.deg2rad(between)
        return lambda e, p: fit.many_axis_angle(np.repeat(e, len(p), axis=0),
                                                np.tile(at[np.round(2 * np.asarray(p)).astype(int)], len(e))
                                                ).reshape(len(e), len(p))

    triangles = spec.triangles if spec.triangles is not None else _hull(initial.axes)
    infeasible = np.array([[status == "infeasible" for status in row] for row in initial.status], dtype=bool)
    times = np.where(initial.ok, initial.slew_time_s, np.where(infeasible.reshape(initial.ok.shape), np.inf, np.nan))
    result = refine(initial.axes, triangles, times, solve, predict, spec.refine)
    refined = TablePart.empty(result.axes, spec.angles_deg)
    n0 = len(initial.axes)
    for i, axis in enumerate(result.axes):
        for k in range(len(spec.angles_deg)):
            if i < n0:  # the initial axes keep their order and entries
                _copy_entry(initial, i, refined, i, k)
            elif (found := entries.get((tuple(axis.tolist()), float(k)))) is not None:
                _fill(refined, TableCase("table", i, k, axis, spec.angles_deg[k], found[0].scenario), found[1],
                      spec.objective)
    checks = TablePart.empty(np.array([c["axis"] for c in result.checks]).reshape(-1, 3), between)
    for i, axis in enumerate(checks.axes):
        for c, angle in enumerate(between):
            if (found := entries.get((tuple(axis.tolist()), c / 2))) is not None:
                _fill(checks, TableCase("check", i, c, axis, angle, found[0].scenario), found[1], spec.objective)
    table.parts["table"], table.parts["check"] = refined, checks
    table.refinement = {"tolerance": spec.refine.tolerance,
                        "check_angles_deg": [spec.angles_deg[k] for k in (spec.refine.check_angles
                                                                          or range(len(spec.angles_deg)))],
                        "check_midpoint_angles_deg": [between[round(2 * p)] for p in check_positions(
                            spec.refine.check_angles or list(range(len(spec.angles_deg))), len(spec.angles_deg))
                                                      if p != int(p)],
                        "max_axes": spec.refine.max_axes, "max_rounds": spec.refine.max_rounds,
                        "initial_axes": n0, **result.summary()}
    for item in table.refinement["rounds"]:  # fit.json is strict JSON: an unbounded miss is null
        if not math.isfinite(item["max_miss"]):
            item["max_miss"] = None
    return result.triangles


def _copy_entry(source: TablePart, i: int, target: TablePart, j: int, k: int) -> None:
    for name in ("slew_time_s", "objective_value", "plan_time_s"):
        getattr(target, name)[j, k] = getattr(source, name)[i, k]
    target.status[j][k] = source.status[i][k]
    target.message[j][k] = source.message[i][k]
    target.best_known[j][k] = source.best_known[i][k]


def _inertially_dependent(scenario: dict[str, Any]) -> bool:
    """Whether the slew time depends on the start attitude, not only on the relative rotation:
    pointing requirements fixed in inertial space, or environment torques."""
    requirements = scenario.get("requirements") or {}
    environment = scenario.get("environment") or {}
    return bool(requirements.get("pointing")) or any(bool(v) for k, v in environment.items()
                                                     if k in ("gravity_gradient", "magnetic_field", "disturbance_torque"))
