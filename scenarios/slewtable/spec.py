"""What a slew table computes: the scenario, the grid of eigen-axes and angles, the objective.

A table is asked for by a scenario file and options, given either as command-line flags or in a
small table file (its top-level key ``table``)::

    table:
      scenario: cubesat_12u_sun_keep_out.yaml   # relative to this file
      axes: 40                  # about 40 axes, or a list of [x, y, z] (body frame)
      grid: polytope            # how a number of axes is spread: polytope (default) or fibonacci
      angles_deg: [10, 30, 60, 90, 120, 150, 180]   # or a count: that many from 10 to 180
      objective: min_time       # or min_energy (then duration is required)
      duration: null            # [s], min_energy only
      held_out: 12              # axes of the held-out lattice (0: none), at the mid angles
      planner_options: {}       # more collocation options (intervals, ...)
      execution: {workers: null, scheduler: null, case_timeout_s: 600}
      refine: {tolerance: 0.01, check_angles_deg: all, max_axes: 2000, max_rounds: 8}   # optional

``refine`` (or ``--tolerance``) refines the axes where the fit misses
(:mod:`scenarios.slewtable.refine`).

Every case is the scenario's spacecraft, actuators (failed wheels included), environment and
pointing and rate requirements, slewing rest to rest from the identity attitude by the angle about
the axis, planned by ``collocation``; nothing is simulated beyond a token closed loop (controller
``none``). ``requirements.actuators`` is kept only when the scenario states it (absent, the limits
are the planner's bounds at the collocation points: see :doc:`/guide/slew_table`).
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ocp.simulation.simulator import MAX_SUBSTEPS
from scenarios.errors import ScenarioError
from scenarios.slewtable.fit import zonotope_facets
from scenarios.slewtable.grid import (
    fibonacci_axes,
    held_out_angles,
    offset_axes,
    polytope_grid,
)
from scenarios.slewtable.refine import RefineOptions

__all__ = ["DEFAULT_ANGLES", "DEFAULT_AXES", "GRIDS", "OBJECTIVES", "REFINE_KEYS", "TABLE_KEYS", "TableCase", "TableSpec", "angles_from_text",
           "case_scenario", "check_angles", "check_axes", "parse_table_spec", "table_cases", "torque_generators"]

OBJECTIVES = ("min_time", "min_energy")
"""The objectives a table computes."""
TABLE_KEYS = ("scenario", "axes", "grid", "angles_deg", "objective", "duration", "held_out", "planner_options", "execution",
              "refine")
"""The keys of a table file's ``table`` mapping."""
REFINE_KEYS = ("tolerance", "check_angles_deg", "max_axes", "max_rounds")
"""The keys of ``table.refine`` (:class:`scenarios.slewtable.refine.RefineOptions`)."""
_REFINE_FLAGS = {"tolerance": "tolerance", "check_angles_deg": "check-angles", "max_axes": "max-axes",
                 "max_rounds": "max-rounds"}
DEFAULT_AXES = 40
GRIDS = ("polytope", "fibonacci")
"""How a number of axes is spread: along the kinks of the slew time (the torque polytope's faces,
:func:`scenarios.slewtable.grid.polytope_grid`; needs bounded torques on three independent axes),
or a Fibonacci lattice (:func:`scenarios.slewtable.grid.fibonacci_axes`)."""
DEFAULT_ANGLES = (10.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0)
_EXECUTION_KEYS = ("workers", "scheduler", "case_timeout_s")


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
        Axes of the held-out lattice (at the midpoints of ``angles_deg``); 0: none.
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
    """

    name: str
    base: dict[str, Any]
    axes: np.ndarray
    angles_deg: list[float]
    objective: str = "min_time"
    duration: float | None = None
    held_out: int = 0
    planner_options: dict[str, Any] = field(default_factory=dict)
    workers: int | None = None
    scheduler: str | None = None
    case_timeout_s: float = 600.0
    source: Path | None = None
    grid: str = "fibonacci"
    triangles: np.ndarray | None = None
    refine: RefineOptions | None = None

    @property
    def held_out_axes(self) -> np.ndarray:
        """The held-out axes (:func:`scenarios.slewtable.grid.offset_axes`), shape (held_out, 3)."""
        return offset_axes(self.held_out) if self.held_out else np.zeros((0, 3))

    @property
    def held_out_angles_deg(self) -> list[float]:
        """The held-out angles [deg]: midpoints of :attr:`angles_deg`."""
        return held_out_angles(self.angles_deg) if self.held_out else []


def _number(value: Any, where: str, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ScenarioError(where, f"expected {what}, got {value!r}")
    return float(value)


def angles_from_text(text: str, where: str = "--angles") -> list[float]:
    """Read ``--angles``: a comma-separated list [deg], or a count (that many from 10 to 180 deg).

    Parameters
    ----------
    text : str
        ``"10,45,90,180"`` or ``"8"``.
    where : str, optional
        The option's name, for messages.

    Returns
    -------
    list of float
        The angles [deg], checked (:func:`check_angles`).

    Raises
    ------
    ScenarioError
        Not numbers, or angles out of range.
    """
    parts = [p.strip() for p in str(text).split(",") if p.strip()]
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise ScenarioError(where, f"expected a count or a comma-separated list of angles in degrees, got {text!r}") from None
    if len(parts) == 1 and parts[0].isdigit():
        count = int(parts[0])
        if count < 2:
            raise ScenarioError(where, f"expected a count of at least 2 angles, got {count}")
        return check_angles(list(np.linspace(10.0, 180.0, count)), where)
    return check_angles(values, where)


def check_angles(values: Any, where: str) -> list[float]:
    """Angles [deg]: at least 2 distinct values in (0, 180], returned sorted.

    Parameters
    ----------
    values : Any
        A list of numbers.
    where : str
        The option or YAML path, for messages.

    Returns
    -------
    list of float
        Sorted angles [deg].

    Raises
    ------
    ScenarioError
        Anything else.
    """
    if not isinstance(values, (list, tuple)) or len(values) < 2:
        raise ScenarioError(where, f"expected at least 2 angles in degrees, got {values!r}")
    angles = sorted(_number(v, where, "angles in degrees") for v in values)
    if angles[0] <= 0.0 or angles[-1] > 180.0:
        raise ScenarioError(where, f"angles must be in (0, 180] degrees, got {values!r}")
    if len(set(angles)) != len(angles):
        raise ScenarioError(where, f"angles must be distinct, got {values!r}")
    return angles


def check_axes(value: Any, where: str) -> np.ndarray:
    """Eigen-axes: a count (a Fibonacci lattice, 1 to 10000) or a list of body vectors.

    Parameters
    ----------
    value : Any
        An int or a list of 3-number lists.
    where : str
        The option or YAML path, for messages.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        Unit axes, body frame.

    Raises
    ------
    ScenarioError
        Anything else (a zero vector or a direction given twice included).
    """
    if isinstance(value, int) and not isinstance(value, bool):
        if not 1 <= value <= 10000:
            raise ScenarioError(where, f"expected a number of axes from 1 to 10000, got {value}")
        return fibonacci_axes(value)
    if not isinstance(value, (list, tuple)) or not value:
        raise ScenarioError(where, f"expected a number of axes or a list of [x, y, z] axes, got {value!r}")
    axes: list[np.ndarray] = []
    for i, item in enumerate(value):
        if not isinstance(item, (list, tuple)) or len(item) != 3:
            raise ScenarioError(f"{where}[{i}]", f"expected 3 numbers (a body axis), got {item!r}")
        vector = np.array([_number(v, f"{where}[{i}]", "3 numbers (a body axis)") for v in item])
        size = float(np.linalg.norm(vector))
        if size == 0.0:
            raise ScenarioError(f"{where}[{i}]", "a zero vector has no direction")
        unit = vector / size
        for j, other in enumerate(axes):
            if np.linalg.norm(unit - other) <= 1e-9:
                raise ScenarioError(f"{where}[{i}]", f"repeats the direction of {where}[{j}] ({value[j]!r}): "
                                                     "each axis once")
        axes.append(unit)
    return np.array(axes)


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


def _scenario(path: Path, where: str) -> dict[str, Any]:
    from scenarios.schema.loader import parse_scenario
    from scenarios.schema.read import read_yaml
    try:
        data = read_yaml(path)
    except ScenarioError as error:  # the path as resolved (relative to the table file), not as written
        raise ScenarioError(where, error.message.replace(str(path), str(path.resolve()))) from None
    if not isinstance(data, dict):
        raise ScenarioError(where, f"{path} is not a scenario (a mapping)")
    if "study" in data or "table" in data:
        raise ScenarioError(where, f"{path} is a study or table file, not a scenario")
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
        A scenario YAML file, or a table file (top-level key ``table``; module docstring).
    overrides : dict, optional
        Command-line flag without its dashes (``axes``, ``angles`` (text), ``objective``,
        ``duration``, ``held-out``, ``workers``, ``scheduler``) -> value (None: not given); they
        win over the table file's.

    Returns
    -------
    TableSpec
        The checked table.

    Raises
    ------
    ScenarioError
        A bad file or option, named by its YAML path or option (exit 2 on the command line).
    """
    from scenarios.schema.read import read_yaml
    path = Path(file)
    data = read_yaml(path)
    given: dict[str, Any] = {}
    if isinstance(data, dict) and "table" in data:
        extra = sorted(set(data) - {"table"})
        if extra:
            raise ScenarioError(extra[0], "unknown key in a table file (expected only 'table')")
        table = data["table"]
        if not isinstance(table, dict):
            raise ScenarioError("table", f"expected a mapping with keys {', '.join(TABLE_KEYS)}, got {table!r}")
        for key in table:
            if key not in TABLE_KEYS:
                raise ScenarioError(f"table.{key}", f"unknown key; expected one of {', '.join(TABLE_KEYS)}")
        if not isinstance(table.get("scenario"), str):
            raise ScenarioError("table.scenario", f"expected the scenario file's path, got {table.get('scenario')!r}")
        source = path.parent / table["scenario"]
        base = _scenario(source, "table.scenario")
        given = {f"table.{k}": v for k, v in table.items() if k != "scenario"}
    else:
        source = path
        base = _scenario(path, str(path))
    overrides = overrides or {}
    for flag, value in overrides.items():
        if value is not None:
            given[f"--{flag}"] = value

    def pick(key: str, flag: str) -> tuple[str, Any] | None:
        for where in (f"--{flag}", f"table.{key}"):
            if where in given:
                return where, given[where]
        return None

    count: int | None = DEFAULT_AXES
    axes = None
    if (found := pick("axes", "axes")) is not None:
        axes = check_axes(found[1], found[0])
        count = len(axes) if isinstance(found[1], int) and not isinstance(found[1], bool) else None
    grid = "polytope"
    if (found := pick("grid", "grid")) is not None:
        if found[1] not in GRIDS:
            raise ScenarioError(found[0], f"expected one of {', '.join(GRIDS)}, got {found[1]!r}")
        grid = found[1]
    triangles = None
    if count is None:
        grid = "list"
    elif grid == "polytope":
        inertia, generators = torque_generators(base)
        facets = zonotope_facets(generators) if len(generators) else np.zeros((0, 3))
        if len(facets):
            axes, triangles = polytope_grid(facets @ inertia, count)
        else:
            grid = "fibonacci"
    if grid == "fibonacci":
        axes = fibonacci_axes(count or DEFAULT_AXES)
    angles = list(DEFAULT_ANGLES)
    if (found := pick("angles_deg", "angles")) is not None:
        where, value = found
        angles = angles_from_text(value, where) if isinstance(value, str) else check_angles(value, where)
    objective = "min_time"
    if (found := pick("objective", "objective")) is not None:
        if found[1] not in OBJECTIVES:
            raise ScenarioError(found[0], f"expected one of {', '.join(OBJECTIVES)}, got {found[1]!r}")
        objective = found[1]
    duration = None
    if (found := pick("duration", "duration")) is not None and found[1] is not None:
        duration = _number(found[1], found[0], "a duration in seconds")
        if duration <= 0.0:
            raise ScenarioError(found[0], f"expected a positive duration in seconds, got {found[1]!r}")
        if objective != "min_energy":
            raise ScenarioError(found[0], "a duration is for objective min_energy (min_time finds it)")
    if objective == "min_energy" and duration is None:
        raise ScenarioError("--duration", "objective min_energy needs the slew duration (--duration T or table.duration)")
    held_out = 0
    if (found := pick("held_out", "held-out")) is not None:
        value = found[1]
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 10000:
            raise ScenarioError(found[0], f"expected a number of held-out axes from 0 to 10000, got {value!r}")
        held_out = value
        if held_out:
            _check_held_out(found[0], axes, objective)
    options: dict[str, Any] = {}
    if (found := pick("planner_options", "planner-options")) is not None:
        if not isinstance(found[1], dict):
            raise ScenarioError(found[0], f"expected a mapping of collocation options, got {found[1]!r}")
        if "objective" in found[1]:
            raise ScenarioError(f"{found[0]}.objective", "give the objective as table.objective")
        options = dict(found[1])
    execution: dict[str, Any] = {}
    if (found := pick("execution", "execution")) is not None:
        if not isinstance(found[1], dict):
            raise ScenarioError(found[0], f"expected a mapping with keys {', '.join(_EXECUTION_KEYS)}")
        for key in found[1]:
            if key not in _EXECUTION_KEYS:
                raise ScenarioError(f"{found[0]}.{key}", f"unknown key; expected one of {', '.join(_EXECUTION_KEYS)}")
        execution = {f"table.execution.{k}": v for k, v in found[1].items()}
    workers = overrides.get("workers")
    if workers is None and execution.get("table.execution.workers") is not None:
        workers = execution["table.execution.workers"]
        if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= 1024:
            raise ScenarioError("table.execution.workers", f"expected 1 to 1024, got {workers!r}")
    scheduler = overrides.get("scheduler") or execution.get("table.execution.scheduler")
    timeout = 600.0
    if execution.get("table.execution.case_timeout_s") is not None:
        timeout = _number(execution["table.execution.case_timeout_s"], "table.execution.case_timeout_s", "seconds")
        if timeout <= 0:
            raise ScenarioError("table.execution.case_timeout_s", f"expected a positive time, got {timeout!r}")
    assert axes is not None
    refine = _refine_options(given, angles, objective, len(axes))
    spec = TableSpec(str(base.get("name") or source.stem), base, axes, angles, objective, duration, held_out,
                     options, workers, scheduler, timeout, source, grid, triangles, refine)
    table_cases(spec)  # the collocation options and the case scenario are checked now
    return spec


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


def _refine_options(given: dict[str, Any], angles: list[float], objective: str, axes: int) -> RefineOptions | None:
    """``table.refine`` and its flags (flags win) -> the refinement's options, None when no tolerance."""
    section = given.get("table.refine")
    if section is not None and not isinstance(section, dict):
        raise ScenarioError("table.refine", f"expected a mapping with keys {', '.join(REFINE_KEYS)}, got {section!r}")
    values: dict[str, tuple[str, Any]] = {}
    for key, value in (section or {}).items():
        if key not in REFINE_KEYS:
            raise ScenarioError(f"table.refine.{key}", f"unknown key; expected one of {', '.join(REFINE_KEYS)}")
        values[key] = (f"table.refine.{key}", value)
    for key, flag in _REFINE_FLAGS.items():
        if given.get(f"--{flag}") is not None:
            values[key] = (f"--{flag}", given[f"--{flag}"])
    if "tolerance" not in values or values["tolerance"][1] is None:
        others = [where for key, (where, value) in values.items() if key != "tolerance" and value is not None]
        if others:
            raise ScenarioError(others[0], "refinement options need a tolerance (--tolerance or table.refine.tolerance)")
        return None
    where, value = values["tolerance"]
    tolerance = _number(value, where, "a tolerance (a fraction of the slew time, e.g. 0.01)")
    if not 0.0 < tolerance < 1.0:
        raise ScenarioError(where, f"expected a tolerance above 0 and below 1 (a fraction of the slew time), got {value!r}")
    if objective != "min_time":
        raise ScenarioError(where, "refinement is of the fit, which is of min_time tables")
    check: list[int] | None = None
    if (found := values.get("check_angles_deg")) is not None and found[1] not in (None, "all"):
        where, value = found
        if isinstance(value, str):
            try:
                value = [float(p) for p in value.split(",") if p.strip()]
            except ValueError:
                raise ScenarioError(where, f"expected 'all' or table angles in degrees, got {value!r}") from None
        if not isinstance(value, (list, tuple)) or not value:
            raise ScenarioError(where, f"expected 'all' or a list of the table's angles in degrees, got {value!r}")
        check = []
        for v in value:
            number = _number(v, where, "the table's angles in degrees")
            near = int(np.argmin([abs(number - a) for a in angles]))
            if abs(angles[near] - number) > 0.05:
                raise ScenarioError(where, f"{v!r} is not one of the table's angles "
                                           f"({', '.join(f'{a:.4g}' for a in angles)} deg)")
            check.append(near)
    limits = {}
    for key, low in (("max_axes", axes), ("max_rounds", 1)):
        if (found := values.get(key)) is not None and found[1] is not None:
            where, value = found
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= 100000:
                raise ScenarioError(where, f"expected a whole number from {low} to 100000, got {value!r}")
            limits[key] = value
    return RefineOptions(tolerance, check, **limits)


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
    # the table reads the plan; the closed loop (no law) only completes the row: two samples, with
    # RK4 sub-steps long enough for any window (the default 0.05 s allows a 100 s window at most)
    data["simulation"] = {"sample_time": window / 2.0, "duration": window,
                          "max_step": max(0.05, window / 2.0 / MAX_SUBSTEPS)}
    requirements = data.get("requirements")
    if isinstance(requirements, dict):
        kept = {k: requirements[k] for k in ("pointing", "rate", "actuators") if k in requirements}
        kept.setdefault("actuators", None)
        data["requirements"] = kept
    elif "requirements" not in data:
        data["requirements"] = {"actuators": None}
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
