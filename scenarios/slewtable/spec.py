"""What a slew table computes: the scenario, the grid of eigen-axes and angles, the objective.

A table is asked for by a scenario file and options, given either as command-line flags or in a
small table file (its top-level key ``table``)::

    table:
      scenario: cubesat_12u_sun_keep_out.yaml   # relative to this file
      axes: 40
      angles_deg: [10, 30, 60, 90, 120, 150, 180]
      held_out: 12
      refine: {tolerance: 0.01}

Its keys, with their types, units, defaults and ranges, and the flags that set them, are declared
once in :mod:`scenarios.schema.table` and read through those declarations here; the schema
reference lists the same (``slewbench schema table``). This module adds the checks across keys and
builds the grid. ``refine`` (or ``--tolerance``) refines the axes where the fit misses
(:mod:`scenarios.slewtable.refine`).

Every case is the scenario's spacecraft, actuators (failed wheels included), environment and
pointing and rate requirements, slewing rest to rest from the identity attitude by the angle about
the axis, planned by ``collocation``; nothing is simulated beyond a token closed loop (controller
``none``, two samples of the numeric integrator, whose build does not depend on the entry). The
actuator requirement applies as in ``slewbench run`` (stated, or margin 0 when unstated), so that an
entry is the time a run flies: see :doc:`/guide/slew_table`.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ocp.simulation.simulator import MAX_SUBSTEPS
from scenarios.errors import ScenarioError, in_file
from scenarios.schema.node import Node
from scenarios.schema.table import (
    MAX_REFINE,
    TABLE_FILE,
    TABLE_FLAGS,
    TableValue,
    bare_count,
    read_table,
)
from scenarios.slewtable.fit import zonotope_facets
from scenarios.slewtable.grid import (
    fibonacci_axes,
    held_out_angles,
    offset_axes,
    polytope_grid,
)
from scenarios.slewtable.refine import RefineOptions

__all__ = ["TableCase", "TableSpec", "case_scenario", "parse_table_spec", "rate_limits", "table_cases",
           "torque_generators"]


@dataclass
class TableSpec:
    """A slew table to compute.

    Parameters
    ----------
    name : str
        The table's name (the scenario's ``name``).
    base : dict
        The scenario mapping (plain YAML data) the cases are made from.
    axes : numpy.ndarray, shape (n, 3)
        Unit eigen-axes, body frame.
    angles_deg : list of float
        Slew angles [deg], increasing, in (0, 180].
    objective : str
        ``min_time`` or ``min_energy``.
    duration : float or None
        Slew duration [s] for ``min_energy``; None for ``min_time`` (the scenario's
        ``maneuver.duration`` is the upper bound).
    held_out : int
        Axes of the held-out lattice (at every angle of ``angles_deg`` and the midpoints between
        them, :func:`scenarios.slewtable.grid.held_out_angles`); 0: none.
    planner_options : dict
        More ``collocation`` options.
    workers : int or None
        Cases at once (None: one per core).
    scheduler : str or None
        A Dask scheduler address, or None for the local process pool.
    case_timeout_s : float
        A case's time limit [s].
    source : Path or None
        The scenario file.
    grid : str
        ``polytope``, ``fibonacci`` or ``list`` (axes given one by one).
    triangles : numpy.ndarray or None
        For a ``polytope`` grid, its triangles (vertex indices), kept by the fit; None otherwise.
    refine : RefineOptions or None
        Refine the axes to a tolerance (:mod:`scenarios.slewtable.refine`); None: the grid as it is.
    axes_asked : int or None
        The number of axes asked for (``axes`` / ``--axes``); a ``polytope`` grid may have more
        (at least its vertices and face centres), a ``fibonacci`` grid has exactly that many; None
        when the axes were listed.
    angles_count : int or None
        The count the angles were given as (``angles_deg: 8``, ``--angles 8``: 8 angles from 10 to
        180 deg, :func:`scenarios.schema.table.bare_count`); None when they were listed (or the default).
    angles_where : str
        Where the angles were given: ``table.angles_deg`` or ``--angles`` (for messages).
    """

    name: str
    base: dict[str, Any]
    axes: np.ndarray
    angles_deg: list[float]
    objective: str
    duration: float | None
    held_out: int
    planner_options: dict[str, Any]
    workers: int | None
    scheduler: str | None
    case_timeout_s: float
    source: Path | None
    grid: str
    triangles: np.ndarray | None
    refine: RefineOptions | None
    axes_asked: int | None = None
    angles_count: int | None = None
    angles_where: str = "table.angles_deg"

    @property
    def held_out_axes(self) -> np.ndarray:
        """The held-out axes (:func:`scenarios.slewtable.grid.offset_axes`), shape (held_out, 3)."""
        return offset_axes(self.held_out) if self.held_out else np.zeros((0, 3))

    @property
    def held_out_angles_deg(self) -> list[float]:
        """The held-out angles [deg]: every angle of :attr:`angles_deg` and the midpoints between them."""
        return held_out_angles(self.angles_deg) if self.held_out else []


def torque_generators(scenario: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """The spacecraft's inertia and its working actuators' torque generators.

    Parameters
    ----------
    scenario : dict
        A scenario mapping (plain YAML data).

    Returns
    -------
    inertia : numpy.ndarray, shape (3, 3)
        [kg m²], body frame.
    generators : numpy.ndarray, shape (m, 3)
        Each working wheel's axis times its torque bound, each torquer axis times its bound [N m],
        body frame; empty when an actuator is unbounded (no shape for the fit).
    """
    from scenarios.schema.loader import parse_scenario
    spacecraft = parse_scenario(scenario).problem.spacecraft
    generators = []
    wheels = spacecraft.wheels
    if wheels is not None:
        for i in range(wheels.count):
            if i not in wheels.failed:
                generators.append(wheels.axes[:, i] * wheels.max_torque[i])
    torquers = spacecraft.torquers
    if torquers is not None:
        for i in range(3):
            generators.append(np.eye(3)[i] * torquers.max_torque[i])
    g = np.array(generators).reshape(-1, 3)
    if not np.all(np.isfinite(g)):
        g = np.zeros((0, 3))
    return np.asarray(spacecraft.inertia, dtype=float), g


def rate_limits(scenario: dict[str, Any]) -> tuple[np.ndarray, float | None]:
    """What caps the body rate of the fit's baseline, the eigenaxis bang-coast-bang
    (:meth:`scenarios.slewtable.fit.SlewTimeFit.baseline`).

    Parameters
    ----------
    scenario : dict
        A scenario mapping (plain YAML data).

    Returns
    -------
    momentum_generators : numpy.ndarray, shape (m, 3)
        Each working wheel's axis times its ``max_momentum`` [N m s], body frame: the body's
        momentum ``J ω`` stays in their zonotope when the wheels alone act (total momentum zero
        from rest). Empty when another actuator kind acts (torquers, magnetorquers: they change the
        total momentum) or a wheel's momentum is unbounded.
    max_rate : float or None
        The problem's rate bound (``maneuver.max_rate``, else ``requirements.rate.max``:
        ``ManeuverProblem.rate_bound``) [rad/s]; None without one.
    """
    from scenarios.schema.loader import parse_scenario
    problem = parse_scenario(scenario).problem
    spacecraft = problem.spacecraft
    wheels = spacecraft.wheels
    generators = np.zeros((0, 3))
    if wheels is not None and all(a is wheels for a in spacecraft.actuators):
        working = [i for i in range(wheels.count) if i not in wheels.failed]
        if np.all(np.isfinite(wheels.max_momentum[working])):  # an unbounded wheel: no cap (0 x inf is NaN)
            generators = np.array([wheels.axes[:, i] * wheels.max_momentum[i] for i in working]).reshape(-1, 3)
    return generators, problem.rate_bound(None)


def _scenario(path: Path, where: str) -> dict[str, Any]:
    from scenarios.schema.loader import parse_scenario
    from scenarios.schema.read import read_yaml
    try:
        data = read_yaml(path)
    except ScenarioError as error:  # the path as resolved (relative to the table file), not as written
        message = error.message.replace(str(path), str(path.resolve()))
        if error.file is not None:  # an error in the file (a duplicate key): the file and the YAML path in it
            message = f"{path.resolve()}: {f'{error.path}: ' if error.path else ''}{message}"
        raise ScenarioError(where, message) from None
    if not isinstance(data, dict):
        raise ScenarioError(where, f"{path} is not a scenario (a mapping)")
    if "study" in data or "table" in data:  # which one: "a study or table file" read as if tables were refused
        kind, command = ("table", "table") if "table" in data else ("study", "sweep")
        raise ScenarioError(where, f"{path} is a {kind} file, not a scenario: "
                                   + (f"run it with `slewbench {command} {path}` (slewbench table expects a scenario "
                                      "file or a table file, top-level key 'table')" if where == str(path)
                                      else "table.scenario names the scenario file the table is made for"))
    try:
        parse_scenario(data)
    except ScenarioError as error:  # the scenario's YAML path, in the scenario's file
        raise ScenarioError(f"{path}: {error.path}" if error.path else str(path), error.message) from None
    return data


def parse_table_spec(file: str | Path, overrides: dict[str, Any] | None = None) -> TableSpec:
    """Read a scenario file or a table file, with command-line overrides.

    Parameters
    ----------
    file : str or Path
        A scenario YAML file, or a table file (top-level key ``table``; its keys are
        :data:`scenarios.schema.table.TABLE`).
    overrides : dict, optional
        Command-line flag without its dashes (``axes``, ``angles`` (text), ``held-out``, ...: the
        flags of :data:`scenarios.schema.table.TABLE_FLAGS`) -> value (None: not given); they win
        over the table file's.

    Returns
    -------
    TableSpec
        The checked table.

    Raises
    ------
    ScenarioError
        A bad file or option, named by its YAML path or option (exit 2 on the command line); its
        :attr:`~scenarios.errors.ScenarioError.file` is ``file``, named in its text.
    ValueError
        An override that is not a flag of ``TABLE_FLAGS``.
    """
    from scenarios.schema.read import read_yaml
    flags = {f"--{name}": value for name, value in (overrides or {}).items()}
    unknown = sorted(set(flags) - set(TABLE_FLAGS.values()))
    if unknown:
        raise ValueError(f"unknown table override(s) {', '.join(unknown)}; expected flags of TABLE_FLAGS without dashes: "
                         f"{', '.join(flag[2:] for flag in TABLE_FLAGS.values())}")
    path = Path(file)
    try:
        return _table_spec(path, read_yaml(path), flags)
    except ScenarioError as error:
        raise in_file(error, path, "table") from None


def _table_spec(path: Path, data: Any, flags: dict[str, Any]) -> TableSpec:
    """:func:`parse_table_spec` of the file at ``path`` read as ``data``, with the overrides ``flags``."""
    if isinstance(data, dict) and "table" in data:
        root = Node(data)
        table = TABLE_FILE["table"].node(root).mapping()
        root.finish()  # a table file holds only ``table``
        values = read_table(table, flags)
        source = path.parent / values["scenario"].value
        base = _scenario(source, values["scenario"].where)
    else:
        values = read_table(Node({}, "table"), flags, skip=("scenario",))
        source = path
        base = _scenario(path, str(path))

    def value(name: str) -> Any:
        return values[name].value

    axes, grid, triangles = _grid(values["axes"], value("grid"), base)
    angles = value("angles_deg")
    objective = value("objective")
    duration = values["duration"]
    if duration.value is not None and objective != "min_energy":
        raise ScenarioError(duration.where, "a duration is for objective min_energy (min_time finds it)")
    if objective == "min_energy" and duration.value is None:
        raise ScenarioError("--duration", "objective min_energy needs the slew duration (--duration T or table.duration)")
    held_out = value("held_out")
    if held_out:
        _check_held_out(values["held_out"].where, axes, objective)
    refine = _refine_options(values, angles, objective, len(axes))
    spec = TableSpec(str(base.get("name") or source.stem), base, axes, angles, objective, duration.value, held_out,
                     value("planner_options"), value("execution.workers"), value("execution.scheduler"),
                     value("execution.case_timeout_s"), source, grid, triangles, refine,
                     values["axes"].value if isinstance(values["axes"].value, int) else None,
                     bare_count(values["angles_deg"].written), values["angles_deg"].where)
    table_cases(spec)  # the collocation options and the case scenario are checked now
    return spec


def _grid(axes: TableValue, grid: str, base: dict[str, Any]) -> tuple[np.ndarray, str, np.ndarray | None]:
    """The table's axes, how they were made (``grid``, or ``list`` for axes given one by one) and,
    for a polytope grid, its triangles."""
    if not isinstance(axes.value, int):
        return axes.value, "list", None
    if grid == "polytope":
        inertia, generators = torque_generators(base)
        facets = zonotope_facets(generators) if len(generators) else np.zeros((0, 3))
        if len(facets):
            vertices, triangles = polytope_grid(facets @ inertia, axes.value)
            return vertices, grid, triangles
    return fibonacci_axes(axes.value), "fibonacci", None


def _check_held_out(where: str, axes: np.ndarray | None, objective: str) -> None:
    """A held-out grid measures the fit: refuse one when the table can have no fit (fewer than 4
    axes, axes that do not span the sphere, or a min_energy table)."""
    from scenarios.slewtable.fit import _hull
    if objective != "min_time":
        raise ScenarioError(where, "a held-out grid measures the fit, which is of min_time tables: "
                                   "use 0 for a min_energy table")
    assert axes is not None
    try:
        _hull(axes)
    except ValueError as error:
        count = "1 axis gives" if len(axes) == 1 else f"{len(axes)} axes give"
        raise ScenarioError(where, f"a held-out grid measures the fit, and {count} no fit over the sphere "
                                   f"({error}): use 0") from None


def _refine_options(values: dict[str, TableValue], angles: list[float], objective: str,
                    axes: int) -> RefineOptions | None:
    """``table.refine`` and its flags (read) -> the refinement's options, None when no tolerance."""
    tolerance = values["refine.tolerance"]
    if tolerance.value is None:
        others = [item.where for name, item in values.items()
                  if name.startswith("refine.") and name != "refine.tolerance" and item.given]
        if others:
            raise ScenarioError(others[0], "refinement options need a tolerance (--tolerance or table.refine.tolerance)")
        return None
    if objective != "min_time":
        raise ScenarioError(tolerance.where, "refinement is of the fit, which is of min_time tables")
    check: list[int] | None = None
    chosen = values["refine.check_angles_deg"]
    if chosen.value is not None:
        check = []
        for number in chosen.value:
            near = int(np.argmin([abs(number - a) for a in angles]))
            if abs(angles[near] - number) > 0.05:
                raise ScenarioError(chosen.where, f"{number:g} is not one of the table's angles "
                                                  f"({', '.join(f'{a:.4g}' for a in angles)} deg)")
            check.append(near)
    budget = values["refine.max_axes"]
    if budget.given and budget.value < axes:
        raise ScenarioError(budget.where, f"expected a whole number from {axes} to {MAX_REFINE}, got {budget.value!r}")
    return RefineOptions(tolerance.value, check, budget.value, values["refine.max_rounds"].value)


def case_scenario(spec: TableSpec, axis: np.ndarray, angle_deg: float) -> dict[str, Any]:
    """The scenario mapping of one table entry (module docstring).

    Parameters
    ----------
    spec : TableSpec
        The table.
    axis : numpy.ndarray, shape (3,)
        Unit eigen-axis, body frame.
    angle_deg : float
        Slew angle [deg].

    Returns
    -------
    dict
        Plain YAML data.
    """
    data = copy.deepcopy(spec.base)
    for key in ("controllers", "truth", "plots", "estimator"):
        data.pop(key, None)
    maneuver = data.setdefault("maneuver", {})
    half = math.radians(angle_deg) / 2.0
    q = [math.cos(half), *(float(a) * math.sin(half) for a in axis)]
    initial = dict(maneuver.get("initial") or {})
    initial.update({"q": [1.0, 0.0, 0.0, 0.0], "omega": [0.0, 0.0, 0.0]})
    maneuver["initial"] = initial
    maneuver["final"] = {"q": q, "omega": [0.0, 0.0, 0.0]}
    maneuver.pop("quaternion_order", None)
    if spec.duration is not None:
        maneuver["duration"] = spec.duration
    options = {**spec.planner_options, "objective": spec.objective}
    data["planners"] = [{"name": "collocation", "label": "collocation", "options": options}]
    data["controller"] = {"name": "none"}
    window = float(maneuver.get("duration") or 1.0)
    # the table reads the plan; the closed loop (no law) only completes the row: two samples of the
    # numeric (CVODES) step, built once per worker. The RK4 default runs the loop as one CasADi function
    # that bakes in the law's target, so each entry (a new target) built its own: about 5 s of an
    # entry's 6 s, for a loop nothing reads. The sub-step bound is checked for either integrator
    data["simulation"] = {"sample_time": window / 2.0, "duration": window, "integrator": "cvodes",
                          "max_step": max(0.05, window / 2.0 / MAX_SUBSTEPS)}
    requirements = data.get("requirements")
    if isinstance(requirements, dict):  # unstated ones as in `slewbench run` (the actuators' margin 0)
        data["requirements"] = {k: requirements[k] for k in ("pointing", "rate", "actuators") if k in requirements}
    return data


@dataclass
class TableCase:
    """One entry to compute: where it sits and its scenario.

    Parameters
    ----------
    part : str
        ``table`` or ``held_out``.
    axis_index, angle_index : int
        Its place in that part's grid.
    axis : numpy.ndarray, shape (3,)
        Unit eigen-axis, body frame.
    angle_deg : float
        Slew angle [deg].
    scenario : dict
        Its scenario mapping.
    """

    part: str
    axis_index: int
    angle_index: int
    axis: np.ndarray
    angle_deg: float
    scenario: dict[str, Any]


def table_cases(spec: TableSpec) -> list[TableCase]:
    """Every entry of the table, then of the held-out grid, with its scenario checked.

    Parameters
    ----------
    spec : TableSpec
        The table.

    Returns
    -------
    list of TableCase
        In order: table axes by angles, then held-out axes by angles.

    Raises
    ------
    ScenarioError
        A case's scenario is refused (a bad collocation option), named by its YAML path.
    """
    from scenarios.schema.loader import parse_scenario
    cases = []
    for part, axes, angles in (("table", spec.axes, spec.angles_deg),
                               ("held_out", spec.held_out_axes, spec.held_out_angles_deg)):
        for i, axis in enumerate(axes):
            for k, angle in enumerate(angles):
                cases.append(TableCase(part, i, k, axis, angle, case_scenario(spec, axis, angle)))
    if cases:
        try:
            parse_scenario(cases[0].scenario)
        except ScenarioError as error:
            where = error.path
            if where.startswith("planners[0].options"):
                where = where.replace("planners[0].options", "table.planner_options", 1)
            raise ScenarioError(where, error.message) from None
    return cases
