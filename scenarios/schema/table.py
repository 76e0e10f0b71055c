"""The keys of a slew-table file (top-level key ``table``), declared once.

``slewbench table`` and ``slewbench validate`` read a table file through these keys
(:func:`read_table`, called by :func:`scenarios.slewtable.spec.parse_table_spec`), and the schema
reference (:mod:`scenarios.schema.reference`, ``slewbench schema table``) lists the same keys, so
that neither can drift from the other. Each key's reader checks its value alone and raises at its
YAML path (``table.refine.tolerance``) or at the command-line flag that gave it
(:data:`TABLE_FLAGS`, ``--tolerance``); the checks across keys (a duration only for
``min_energy``, a held-out grid only where a fit can be measured, check angles among the table's
angles, refinement options only with a tolerance) are the table spec's.

The declarations live here, beside the study file's (:mod:`scenarios.schema.study`), because the
reference may not import :mod:`scenarios.slewtable`, which sits above the schema.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from scenarios.errors import ScenarioError
from scenarios.schema.keys import Key, Section, choice, custom, integer, number
from scenarios.schema.node import Node
from scenarios.schema.study import EXECUTION

__all__ = ["GRIDS", "MAX_ANGLES", "MAX_AXES", "MAX_REFINE", "OBJECTIVES", "TABLE", "TABLE_EXECUTION", "TABLE_FILE", "TABLE_FLAGS",
           "TABLE_REFINE", "TableValue", "angles_from_text", "bare_count", "check_angles", "read_table"]

OBJECTIVES = ("min_time", "min_energy")
"""The objectives a table computes."""
GRIDS = ("polytope", "fibonacci")
"""How a number of axes is spread: along the kinks of the slew time (the torque polytope's faces,
:func:`scenarios.slewtable.grid.polytope_grid`; needs bounded torques on three independent axes),
or a Fibonacci lattice (:func:`scenarios.slewtable.grid.fibonacci_axes`)."""
MAX_AXES = 10000
"""Most axes of a table's grid, and of its held-out grid."""
MAX_ANGLES = 10000
"""Most angles of a table, listed or counted (``--angles N``): as many as :data:`MAX_AXES` (a count of
1e11 asked NumPy for 745 GiB before the entries were counted against ``--max-entries``)."""
MAX_REFINE = 100000
"""Largest ``table.refine.max_axes`` and ``table.refine.max_rounds``."""


def _number(value: Any, where: str, what: str) -> float:
    """``value`` as a float, or an error at ``where`` saying it is no number, or not finite (NaN, an
    infinity, an integer beyond a float's range), and that ``what`` was expected."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(where, f"expected {what}, got {value!r:.80}")
    try:
        finite = math.isfinite(value)
    except OverflowError:  # an integer beyond a float's range
        finite = False
    if not finite:
        said = (f"{str(value)[:20]}... ({len(str(value))} digits) is beyond a float's range (about 1.8e308)"
                if isinstance(value, int) else f"{value!r} is not finite")
        raise ScenarioError(where, f"{said}; expected {what}")
    return float(value)


def _item_number(values: Any, index: int, where: str, what: str) -> float:
    """:func:`_number` of ``values[index]``, its error at ``where`` (the key or the flag, as every
    other error of it) saying which item (``item 1: nan is not finite; ...``)."""
    try:
        return _number(values[index], where, what)
    except ScenarioError as error:
        raise ScenarioError(where, f"item {index + 1}: {error.message}") from None


def bare_count(value: Any) -> int | None:
    """The count of angles a bare value of ``table.angles_deg`` or ``--angles`` gives: a whole
    number alone (an integer, or text of digits alone: ``"90,"`` is a list of one angle in degrees).
    A count ``n`` is ``n`` angles evenly from 10 to 180 deg, not an angle: whether it is one the
    user meant is ``slewbench table``'s check (:func:`scenarios.cli.table.check_table_work`).

    Parameters
    ----------
    value : Any
        The value as written: YAML data, or the flag's text.

    Returns
    -------
    int or None
        The count; None for anything else (a list, a number with a decimal point such as ``90.0``,
        text with a comma, a bool).
    """
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().isdigit():
        return int(value.strip())
    return None


def angles_from_text(text: str, where: str = "--angles") -> list[float]:
    """Read ``--angles``: a comma-separated list [deg], or a count (that many from 10 to 180 deg):
    a whole number without a comma (:func:`bare_count`; ``"90,"`` is a list, of one angle: refused,
    a table needs two).

    Parameters
    ----------
    text : str
        ``"10,45,90,180"`` or ``"8"``.
    where : str, optional
        The option's name or YAML path, for messages.

    Returns
    -------
    list of float
        The angles [deg], checked (:func:`check_angles`).

    Raises
    ------
    ScenarioError
        Not numbers, an empty item (``30,,90``; one trailing comma is allowed), a count below 2,
        or angles out of range.
    """
    count = bare_count(text)
    if count is not None:
        if not 2 <= count <= MAX_ANGLES:
            raise ScenarioError(where, f"expected a count of 2 to {MAX_ANGLES} angles, got "
                                       f"{count if count < 10**20 else f'{str(count)[:20]}... ({len(str(count))} digits)'}")
        return check_angles(list(np.linspace(10.0, 180.0, count)), where)
    parts = _comma_items(str(text), where)
    try:
        values = [float(p) for p in parts]
    except ValueError:
        raise ScenarioError(where, f"expected a count or a comma-separated list of angles in degrees, got {text!r}") from None
    return check_angles(values, where)


def _comma_items(text: str, where: str) -> list[str]:
    """The items of a comma-separated list of angles, stripped; one trailing comma is allowed
    (``"90,180,"`` is two items), an empty item elsewhere (``"30,,90"``) is refused at ``where``."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) > 1 and not parts[-1]:
        parts.pop()
    for i, part in enumerate(parts, start=1):
        if not part:
            raise ScenarioError(where, f"item {i} of {text!r} is empty: expected a comma-separated list of angles "
                                       "in degrees, one number between each pair of commas (e.g. 30,60,90)")
    return parts


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
        raise ScenarioError(where, f"expected at least 2 angles in degrees (the table interpolates between them; "
                                   f"for one slew, slewbench run), got {values!r}")
    if len(values) > MAX_ANGLES:
        raise ScenarioError(where, f"expected at most {MAX_ANGLES} angles, got {len(values)}")
    numbers = [_item_number(values, i, where, "an angle in degrees, in (0, 180]") for i in range(len(values))]
    for i, angle in enumerate(numbers):
        if not 0.0 < angle <= 180.0:
            raise ScenarioError(where, f"item {i + 1}: {angle:g} is outside (0, 180]: expected a slew angle in "
                                       "degrees above 0 and at most 180")
        if angle in numbers[:i]:
            raise ScenarioError(where, f"item {i + 1}: {angle:g} repeats item {numbers.index(angle) + 1}: "
                                       "expected distinct angles")
    return sorted(numbers)


# --- the readers: one value each, at its YAML path or flag -----------------------------------------

def _scenario(node: Node) -> str:
    if not isinstance(node.value, str):
        raise node.error(f"expected the scenario file's path, got {node.value!r}")
    return node.value


def _axes(node: Node) -> int | np.ndarray:
    """A count (the grid spreads that many, about) or unit axes, body frame."""
    value, where = node.value, node.path
    if isinstance(value, int) and not isinstance(value, bool):
        if not 1 <= value <= MAX_AXES:
            raise node.error(f"expected a number of axes from 1 to {MAX_AXES}, got {value}")
        return value
    if where.startswith("--") and isinstance(value, str):  # the flag's text takes a count only: the axes
        # themselves are for the table file (a Python override at "--axes" may still give them as a list)
        raise node.error(f"expected a whole number of axes from 1 to {MAX_AXES} (e.g. --axes 40; to give the "
                         f"axes themselves, list them at table.axes in a table file), got {value!r}")
    if not isinstance(value, (list, tuple)) or not value:
        raise node.error(f"expected a number of axes or a list of [x, y, z] axes, got {value!r}")
    axes: list[np.ndarray] = []
    for i, item in enumerate(value):
        if not isinstance(item, (list, tuple)) or len(item) != 3:
            raise ScenarioError(f"{where}[{i}]", f"expected 3 numbers (a body axis), got {item!r}")
        vector = np.array([_number(v, f"{where}[{i}]", "3 numbers (a body axis)") for v in item])
        largest = float(np.max(np.abs(vector)))
        if largest == 0.0:
            raise ScenarioError(f"{where}[{i}]", "a zero vector has no direction")
        direction = vector / largest  # its norm cannot overflow ([1e300, 1e300, 0]: inf, then a zero axis and
        unit = direction / float(np.linalg.norm(direction))  # an error about a quaternion no one wrote)
        for j, other in enumerate(axes):
            if np.linalg.norm(unit - other) <= 1e-9:
                raise ScenarioError(f"{where}[{i}]", f"repeats the direction of {where}[{j}] ({value[j]!r}): "
                                                     "each axis once")
        axes.append(unit)
    return np.array(axes)


def _angles(node: Node) -> list[float]:
    """A list of angles [deg], or a bare count (:func:`bare_count`, as on the command line); a lone
    number that is not whole (``90.0``) is neither: refused, naming both forms."""
    value = node.value
    if bare_count(value) is not None or isinstance(value, str):
        return angles_from_text(str(value), node.path)
    if isinstance(value, float):
        raise node.error(f"expected a list of at least 2 angles in degrees (e.g. [60, 90, 120]; for one slew, "
                         f"slewbench run) or a whole number, a count of angles (e.g. 8: 8 angles evenly from 10 to "
                         f"180 deg), got the lone number {value!r}")
    return check_angles(value, node.path)


def _planner_options(node: Node) -> dict[str, Any]:
    if not isinstance(node.value, dict):
        raise node.error(f"expected a mapping of collocation options, got {node.value!r}")
    if "objective" in node.value:
        raise ScenarioError(f"{node.path}.objective", "give the objective as table.objective")
    return dict(node.value)


def _tolerance(node: Node) -> float | None:
    if node.value is None:
        return None
    tolerance = _number(node.value, node.path, "a tolerance (a fraction of the slew time, e.g. 0.01)")
    if not 0.0 < tolerance < 1.0:
        raise node.error(f"expected a tolerance above 0 and below 1 (a fraction of the slew time), got {node.value!r}")
    return tolerance


def _check_angles(node: Node) -> list[float] | None:
    """``all`` (None) or angles [deg]; which of the table's angles they are is the table spec's check."""
    value = node.value
    if value is None or value == "all":
        return None
    if isinstance(value, str):
        items = _comma_items(value, node.path)
        try:
            value = [float(p) for p in items]
        except ValueError:
            raise node.error(f"expected 'all' or table angles in degrees, got {node.value!r}") from None
    if not isinstance(value, (list, tuple)) or not value:
        raise node.error(f"expected 'all' or a list of the table's angles in degrees, got {value!r}")
    return [_number(v, node.path, "the table's angles in degrees") for v in value]


def _whole(node: Node) -> int:
    value = node.value
    if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= MAX_REFINE:
        raise node.error(f"expected a whole number from 1 to {MAX_REFINE}, got {value!r}")
    return value


# --- the declarations -------------------------------------------------------------------------------

TABLE_EXECUTION = Section((
    dataclasses.replace(EXECUTION["workers"], meaning="Entries computed at once on the local process pool; ``auto`` "
                                                      "or ``null``: one per core."),
    dataclasses.replace(EXECUTION["scheduler"], meaning="Address of a Dask scheduler (``tcp://host:8786``) that "
                                                        "computes the entries; ``null``: the local process pool."),
    dataclasses.replace(EXECUTION["case_timeout_s"], meaning="Wall time after which an entry's planner is stopped: "
                                                             "its status is then ``timed_out`` (no result; the "
                                                             "table run again into the same ``--out`` computes it "
                                                             "again)."),
), "How the entries run (the trade-study engine's, as a study's ``execution`` without ``retries``).")

TABLE_REFINE = Section((
    custom("tolerance", "Refine the axes until the fit's misses at the check points (the triangles' edge midpoints) "
           "are at most this fraction of the slew time (``0.01``: 1 %); ``null``: no refinement, and no other key "
           "of ``refine`` may be given.", "number or null", _tolerance, default=None, bounds="> 0 and < 1"),
    custom("check_angles_deg", "The table angles a midpoint is checked at first, each one of ``angles_deg`` "
           "(within 0.05 deg); ``all``: every angle.", "all, or list of numbers", _check_angles, unit="deg",
           default="all"),
    custom("max_axes", "Budget: axes of the refined table at most (a round that would pass it splits only its "
           "worst triangles, then the refinement stops).", "integer", _whole, default=2000,
           bounds=f">= the initial grid's axes and <= {MAX_REFINE}"),
    custom("max_rounds", "Budget: refinement rounds at most.", "integer", _whole, default=8,
           bounds=f">= 1 and <= {MAX_REFINE}"),
), "Refine the axes where the fit misses, in rounds after the initial grid (the slew-table guide, "
   "\"Refinement to a tolerance\"); a ``min_time`` table only.")

TABLE = Section((
    custom("scenario", "The scenario file the entries are made from (its spacecraft, actuators, environment, "
           "pointing and rate requirements), relative to the table file.", "text", _scenario),
    custom("axes", "The eigen-axes (body frame): about this many, spread by ``grid``; or a list of ``[x, y, z]`` "
           "axes used as given (each direction once, not zero).", "integer or list of [x, y, z]", _axes, default=40,
           bounds=f"a number: 1 to {MAX_AXES}"),
    choice("grid", "How a number of axes is spread: ``polytope`` cuts the faces of the actuators' torque polytope "
           "into triangles, so that none crosses a kink of the slew time (without bounded torques on three "
           "independent axes: the Fibonacci lattice); ``fibonacci``: a Fibonacci lattice. Not used by a list of "
           "axes.", GRIDS, default="polytope"),
    custom("angles_deg", "The slew angles in degrees, a list; or a whole number ``n``, a count, not an angle: ``n`` "
           "angles evenly from 10 to 180 deg (``slewbench table`` refuses a count that reads like an angle in "
           "degrees unless ``--max-entries`` confirms the work: the slew-table guide). A lone number that is not whole (``90.0``) is "
           "refused. The fit has no time above the largest angle unless it is 180 deg.",
           "a whole number (a count of angles), or a list of angles", _angles, unit="deg",  # [deg]: the list's
           default=[10.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0],
           bounds=f"a list: 2 to {MAX_ANGLES}, distinct, > 0 and <= 180; a count: 2 to {MAX_ANGLES}"),
    choice("objective", "``min_time``: the shortest slew (the scenario's ``maneuver.duration`` bounds it); "
           "``min_energy``: the least integral of the squared control over ``duration``.", OBJECTIVES,
           default="min_time"),
    number("duration", "The slew duration of a ``min_energy`` table (required there; ``min_time`` finds it).",
           unit="s", default=None, positive=True, nullable=True),
    integer("held_out", "Axes of the held-out grid the fit's error is measured on (a Fibonacci lattice turned by "
            "1 rad, at every angle of ``angles_deg`` and the midpoints between them); 0: none. A ``min_time`` "
            "table of axes that span the "
            "sphere only.", default=0, minimum=0, maximum=MAX_AXES),
    custom("planner_options", "More options of the ``collocation`` planner (its options in this reference, under "
           "Planner options), checked as a scenario's; not ``objective``.", "mapping", _planner_options, default={}),
    custom("execution", "How the entries run.", "mapping or null", None, default={}, section=TABLE_EXECUTION),
    custom("refine", "Refine the axes to a tolerance; absent or ``null`` (and no ``--tolerance``): the grid as it "
           "is.", "mapping or null", None, default=None, section=TABLE_REFINE),
), "What a slew table computes: minimum slew time (or least energy) from the identity attitude over eigen-axes "
   "and angles, each entry planned by ``collocation`` (the slew-table guide).")

TABLE_FILE = Section((
    custom("table", "What the table computes.", "mapping", None, section=TABLE),
), "A slew-table file (``slewbench table FILE``, ``slewbench validate FILE``) has the one top-level key ``table``. "
   "``slewbench table`` also takes a scenario file: its table has the defaults below. A flag wins over the "
   "file's key.")

TABLE_FLAGS: dict[str, str] = {
    "axes": "--axes", "grid": "--grid", "angles_deg": "--angles", "objective": "--objective",
    "duration": "--duration", "held_out": "--held-out", "execution.workers": "--workers",
    "execution.scheduler": "--scheduler", "execution.case_timeout_s": "--case-timeout", "refine.tolerance": "--tolerance", "refine.check_angles_deg": "--check-angles",
    "refine.max_axes": "--max-axes", "refine.max_rounds": "--max-rounds"}
"""Key below ``table`` (dotted) -> the ``slewbench table`` flag that sets it (and wins over the file)."""


@dataclass(frozen=True)
class TableValue:
    """One key of a table, as read.

    Parameters
    ----------
    value : object
        What its reader returned (its default's reading when not given).
    where : str
        Its YAML path (``table.refine.tolerance``) or the flag that gave it (``--tolerance``).
    given : bool
        Whether the file or a flag gave it a value (not ``null``).
    written : object, optional
        The value as the file or the flag wrote it, before its reader (``90`` where ``value`` is the
        90 angles that count gives); None when not given.
    """

    value: Any
    where: str
    given: bool
    written: Any = None


def read_table(node: Node, flags: Mapping[str, Any] | None = None, *, skip: tuple[str, ...] = (),
               section: Section = TABLE, prefix: str = "") -> dict[str, TableValue]:
    """Every key of ``section`` in ``node``, or from its flag, each read by its key.

    Parameters
    ----------
    node : Node
        The ``table`` mapping (``Node({}, "table")`` for a scenario file: every key its default).
    flags : mapping, optional
        Flag of :data:`TABLE_FLAGS` (``--axes``) -> value; ``None`` values are not given. A given
        flag wins: the file's value for that key is not read.
    skip : tuple of str, optional
        Keys not read (``scenario`` for a scenario file).
    section, prefix : optional
        A nested section and its dotted prefix (``refine.``); for the recursion.

    Returns
    -------
    dict of str to TableValue
        Dotted key below ``table`` (``refine.max_axes``) -> its value; nested mappings (``execution``,
        ``refine``) by their keys only.

    Raises
    ------
    ScenarioError
        At the YAML path or flag: a value its key refuses, a nested value that is not a mapping,
        a missing ``scenario``, or an unknown key.
    """
    flags = flags or {}
    node.mapping()
    found: dict[str, TableValue] = {}
    for key in section.keys:
        name = prefix + key.name
        if name in skip:
            node.get(key.name, None)  # marked as read
            continue
        if key.section is not None:
            child = key.node(node)
            inner = Node({}, child.path) if child.is_null() else child.mapping()
            found |= read_table(inner, flags, skip=skip, section=key.section, prefix=name + ".")
            continue
        flag = TABLE_FLAGS.get(name)
        if flag is not None and flags.get(flag) is not None:
            key.node(node)  # the flag wins; the file's value is not read
            found[name] = TableValue(_value(key, Node(flags[flag], flag)), flag, True, flags[flag])
        else:
            child = key.node(node)
            given = isinstance(node.value, dict) and node.value.get(key.name) is not None
            found[name] = TableValue(_value(key, child), child.path, given, child.value if given else None)
    node.finish()
    return found


def _value(key: Key, node: Node) -> Any:
    if key.read is None:  # every leaf of the table is declared with its reader
        raise TypeError(f"table key {key.name} has no reader")
    return key.read(node)
