"""Compute a slew table through the trade-study engine, and fit it.

Every entry is a case of a :class:`scenarios.study.Study` built here (one per axis and angle, the
table's then the held-out grid's) and run by :func:`scenarios.study.sweep`: on the local process
pool or a Dask cluster, each finished case committed to the crash-safe store when a directory is
given (so a table run again into the same directory computes only the entries it lacks). An entry
whose solve fails, or that breaks a requirement, is kept with its status and message; only the
``ok`` entries enter the fit (an axis is filled between its ok angles by its own cubic, and an axis
with fewer than two ok angles is left out of the fit).
"""
from __future__ import annotations

import json
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
    table_cases,
    torque_generators,
)

__all__ = ["PART_NAMES", "SlewTable", "TablePart", "compute_table", "eval_time_us", "fit_entries", "held_out_errors"]

PART_NAMES = ("table", "held_out")
"""The two grids of a table: the fitted one and the held-out one."""


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
        Each entry's status (``ok``, ``violated``, ``failed``, ``crashed``, ``missing``).
    message : list of list of str
        Each entry's message.
    """

    axes: np.ndarray
    angles_deg: list[float]
    slew_time_s: np.ndarray
    objective_value: np.ndarray
    plan_time_s: np.ndarray
    status: list[list[str]]
    message: list[list[str]]

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
        Entries found already computed in the store.
    fit : SlewTimeFit or None
        The fit (None when it could not be made: :attr:`fit_note` says why).
    fit_note : str
        Why there is no fit, or which axes were left out of it.
    fit_quality : dict
        The fit's errors on the held-out grid (:func:`held_out_errors`) and its evaluation time
        ``eval_time_us`` [µs per call]; empty without a fit.
    """

    spec: TableSpec
    parts: dict[str, TablePart]
    wall_time_s: float = 0.0
    stored: int = 0
    fit: SlewTimeFit | None = None
    fit_note: str = ""
    fit_quality: dict[str, Any] = field(default_factory=dict)


def _study(spec: TableSpec, cases: list[TableCase]) -> Any:
    from scenarios.output.provenance import package_version
    from scenarios.study.types import Case, Execution, Study, case_key
    version = package_version()
    study_cases = [Case(index, 0, index, {"maneuver.final.q": json.dumps(case.scenario["maneuver"]["final"]["q"])},
                        case.scenario, case_key(case.scenario, version)) for index, case in enumerate(cases)]
    execution = Execution(spec.workers, spec.scheduler, spec.case_timeout_s, 1)
    return Study(f"table {spec.name}", spec.source, spec.base, ["maneuver.final.q"], [], 1, None, 0, [], execution,
                 study_cases, {"table": spec.name})


def _fill(part: TablePart, case: TableCase, record: dict[str, Any] | None, objective: str) -> None:
    i, k = case.axis_index, case.angle_index
    if record is None or not record.get("rows"):
        return
    row = record["rows"][0]
    part.status[i][k] = str(row.get("status"))
    part.message[i][k] = str(row.get("message") or "")
    if row.get("plan_time_s") is not None:
        part.plan_time_s[i, k] = float(row["plan_time_s"])
    reference = row.get("reference") or {}
    duration = reference.get("duration_s")
    if duration is not None and row.get("status") in ("ok", "violated"):
        part.slew_time_s[i, k] = float(duration)
        value = duration if objective == "min_time" else reference.get("int_u2")
        if value is not None:
            part.objective_value[i, k] = float(value)


def fit_entries(part: TablePart, inertia: np.ndarray | None = None, generators: np.ndarray | None = None,
                meta: dict[str, Any] | None = None, triangles: np.ndarray | None = None
                ) -> tuple[SlewTimeFit | None, str]:
    """Fit a grid's ``ok`` entries (module docstring).

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
        The grid's triangles (:func:`scenarios.slewtable.grid.polytope_grid`), used when every axis
        enters the fit; otherwise (or None) the convex hull of the axes that do.

    Returns
    -------
    fit : SlewTimeFit or None
        None when no fit can be made.
    note : str
        Why not, or which axes were left out or filled ("" when every entry is ok).
    """
    from scipy.interpolate import PchipInterpolator
    angles = np.deg2rad(part.angles_deg)
    ok = part.ok
    keep, rows, filled = [], [], 0
    for i in range(len(part.axes)):
        good = ok[i]
        if good.sum() < 2:
            continue
        times = part.slew_time_s[i].copy()
        if not good.all():
            g = times[good] / np.sqrt(angles[good])
            times[~good] = PchipInterpolator(angles[good], g, extrapolate=True)(angles[~good]) * np.sqrt(angles[~good])
            filled += int((~good).sum())
        keep.append(i)
        rows.append(times)
    notes = []
    if len(keep) < len(part.axes):
        notes.append(f"{len(part.axes) - len(keep)} of {len(part.axes)} axes left out (fewer than 2 ok angles)")
    if filled:
        notes.append(f"{filled} entries not ok filled along their axis")
    if len(keep) < 4:
        return None, "; ".join([*notes, f"no fit over the sphere: {len(keep)} axes with ok entries (4 or more needed)"])
    try:
        use = triangles if triangles is not None and len(keep) == len(part.axes) else None
        fit = SlewTimeFit(angles, part.axes[keep], np.array(rows), meta, inertia, generators, use)
    except ValueError as error:
        return None, "; ".join([*notes, f"no fit: {error}"])
    return fit, "; ".join(notes)


def eval_time_us(fit: SlewTimeFit, repeats: int = 7, number: int = 2000) -> float:
    """Median over ``repeats`` of the mean CPU time of one ``fit(q0, qf)`` call on tuples [µs].

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
    pairs = [(tuple(q[i].tolist()), tuple(q[(i + 1) % 64].tolist())) for i in range(64)]
    loops = max(1, number // 64)

    def run() -> None:
        for a, b in pairs:
            fit(a, b)

    times = timeit.repeat(run, timer=time.process_time, number=loops, repeat=repeats)
    return statistics.median(times) / (loops * len(pairs)) * 1e6


def held_out_errors(fit: SlewTimeFit, part: TablePart) -> dict[str, Any]:
    """The fit's relative error on a held-out grid's ``ok`` entries.

    Parameters
    ----------
    fit : SlewTimeFit
        The fit.
    part : TablePart
        The held-out grid.

    Returns
    -------
    dict
        ``points`` (ok entries compared), ``max_rel_error`` and ``rms_rel_error`` (fractions of the
        slew time; None without points), ``worst`` (axis, angle [deg], table and fitted times [s]).
    """
    ok = part.ok
    if not ok.any():
        return {"points": 0, "max_rel_error": None, "rms_rel_error": None, "worst": None}
    i, k = np.nonzero(ok)
    truth = part.slew_time_s[i, k]
    angles = np.deg2rad(np.asarray(part.angles_deg))[k]
    estimate = fit.many_axis_angle(part.axes[i], angles)
    rel = np.abs(estimate / truth - 1.0)
    w = int(np.argmax(rel))
    return {"points": len(rel), "max_rel_error": float(rel.max()), "rms_rel_error": float(np.sqrt(np.mean(rel ** 2))),
            "worst": {"axis": part.axes[i[w]].tolist(), "angle_deg": float(part.angles_deg[k[w]]),
                      "table_s": float(truth[w]), "fit_s": float(estimate[w])}}


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
    from scenarios.study.engine import sweep
    from scenarios.study.store import SweepStore
    cases = table_cases(spec)
    study = _study(spec, cases)
    start = time.perf_counter()
    store = SweepStore(directory) if directory is not None else None
    try:
        stored = len(store.keys() & {case.key for case in study.cases}) if store is not None else 0
        results = sweep(study, executor, workers=workers or spec.workers, store=store, progress=progress,
                        cluster=cluster)
    finally:
        if store is not None:
            store.close()
    wall = time.perf_counter() - start
    parts = {"table": TablePart.empty(spec.axes, spec.angles_deg),
             "held_out": TablePart.empty(spec.held_out_axes, spec.held_out_angles_deg)}
    for case, study_case in zip(cases, study.cases):
        _fill(parts[case.part], case, results.records.get(study_case.key), spec.objective)
    table = SlewTable(spec, parts, wall, stored)
    if spec.objective != "min_time":
        table.fit_note = "the fit is of minimum-time tables (this table is min_energy at a fixed duration)"
        return table
    inertia, generators = torque_generators(spec.base)
    meta = {"scenario": spec.name, "objective": spec.objective,
            "from_identity_only": _inertially_dependent(spec.base)}
    meta["grid"] = spec.grid
    table.fit, table.fit_note = fit_entries(parts["table"], inertia, generators, meta, spec.triangles)
    if table.fit is not None:
        quality = held_out_errors(table.fit, parts["held_out"])
        quality["eval_time_us"] = eval_time_us(table.fit)
        table.fit.meta["held_out"] = quality
        table.fit.meta["note"] = table.fit_note
        table.fit_quality = quality
    return table


def _inertially_dependent(scenario: dict[str, Any]) -> bool:
    """Whether the slew time depends on the start attitude, not only on the relative rotation:
    pointing requirements fixed in inertial space, or environment torques."""
    requirements = scenario.get("requirements") or {}
    environment = scenario.get("environment") or {}
    return bool(requirements.get("pointing")) or any(bool(v) for k, v in environment.items()
                                                     if k in ("gravity_gradient", "magnetic_field", "disturbance_torque"))
