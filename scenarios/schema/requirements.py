"""The requirement keys of a scenario: ``epoch``, ``spacecraft.sensors`` and ``requirements``.

Each mapping's keys are declared here (:data:`SENSOR`, :data:`POINTING`, :data:`REQUIREMENTS` ...)
and read through them; the objects they build are :mod:`scenarios.requirements.spec`'s. Directions
are the names of :data:`~ocp.geometry.directions.DIRECTIONS` (listed from the registry) or
``{inertial: [x, y, z]}``. Every error is a :class:`~scenarios.errors.ScenarioError` naming the YAML
path, the value and what was expected: an unknown sensor or direction, a zero boresight, an angle
outside (0°, 180°), a direction that needs the epoch or the orbit the scenario lacks, an epoch the
ephemeris does not cover, a window outside the run or reversed.
"""
from __future__ import annotations

import dataclasses
import datetime
import re
from dataclasses import dataclass

import numpy as np

from ocp.dynamics.ephemeris import EPHEMERIS_RANGE, check_epoch, parse_utc
from ocp.errors import ModelError, excerpt
from ocp.geometry.directions import DIRECTIONS, Geometry
from ocp.geometry.pointing import PointingConstraint
from scenarios.errors import ScenarioError
from scenarios.requirements.spec import (
    RESERVED_NAMES,
    ActuatorRequirement,
    Direction,
    FinalRequirement,
    PointingRequirement,
    RateRequirement,
    Requirements,
    Sensor,
)
from scenarios.schema.keys import Described, Section, custom, mapping, number, vector
from scenarios.schema.node import Node

__all__ = [
    "INERTIAL_DIRECTION",
    "POINTING",
    "REQUIREMENTS",
    "REQUIREMENT_ACTUATORS",
    "REQUIREMENT_FINAL",
    "REQUIREMENT_RATE",
    "SENSOR",
    "RunSpan",
    "check_ephemeris",
    "parse_epoch",
    "parse_requirements",
    "parse_sensors",
]

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]{0,63}$")
"""A sensor's or requirement's name: it names result columns (``ref.req.<name>.<field>``)."""


def _name(node: Node, name: object, what: str) -> str:
    if not isinstance(name, str) or not _NAME.match(name):
        raise ScenarioError(f"{node.path}.{name}" if node.path else str(name),
                            f"a {what} name is a letter then letters, digits, '_' or '-' (at most 64 "
                            f"characters), got {excerpt(name)}")
    return name


def parse_epoch(node: Node) -> datetime.datetime | None:
    """The top-level ``epoch``: a UTC instant (ISO 8601), or ``None`` when absent or null.

    Parameters
    ----------
    node : Node
        The ``epoch`` value.

    Returns
    -------
    datetime.datetime or None
        Naive UTC.

    Raises
    ------
    ScenarioError
        At ``epoch`` for anything but an ISO 8601 date or date-time.
    """
    if node.is_null():
        return None
    value = node.value
    if not isinstance(value, (str, datetime.date)):
        raise node.error(f"expected a UTC date-time like 2027-03-20T12:00:00Z, got {excerpt(value)}")
    try:
        return parse_utc(value)
    except ModelError as error:
        raise node.error(error.message) from None


def _boresight(node: Node) -> np.ndarray:
    vector_ = node.vector(3)
    if not np.linalg.norm(vector_) > 1e-12:
        raise node.error(f"a boresight cannot be zero, got {vector_.tolist()}; give its direction in body axes")
    return vector_ / np.linalg.norm(vector_)


SENSOR = Section((
    custom("boresight", "The sensor's boresight (or a panel's normal), body axes; normalised, zero refused.",
           "list of 3 numbers", _boresight),
), "One sensor: its boresight in body axes.")

INERTIAL_DIRECTION = Section((
    vector("inertial", "A fixed direction, inertial frame (normalised; zero refused).", 3),
), "A fixed inertial direction, written ``{inertial: [x, y, z]}``.")


def _angle(node: Node) -> float:
    value = node.number()
    if not 0.0 < value < 180.0:
        raise node.error(f"expected an angle in (0, 180) deg, got {excerpt(node.value)}")
    return value


def _window(node: Node) -> tuple[float, float | None]:
    items = list(node.items())
    if len(items) != 2:
        raise node.error(f"expected [start_s, end_s or null], got {excerpt(node.value)}")
    start = items[0].number(non_negative=True)
    end = items[1].optional_number()
    if end is not None and not end > start:
        raise node.error(f"the window's end must come after its start, got [{start:g}, {end:g}]")
    return start, end


_DIRECTION_WORDS = ("a direction's name (listed below) or ``{inertial: [x, y, z]}``; give ``keep_out`` or "
                    "``keep_in``, not both")

POINTING = Section((
    custom("sensor", "The sensor whose boresight is constrained (a name under ``spacecraft.sensors``).", "text",
           None),
    custom("keep_out", "The boresight stays at least ``angle_deg`` from this direction: " + _DIRECTION_WORDS + ".",
           "text or mapping", None, default=None, choices=DIRECTIONS, section=INERTIAL_DIRECTION),
    custom("keep_in", "The boresight stays within ``angle_deg`` of this direction: " + _DIRECTION_WORDS + ".",
           "text or mapping", None, default=None, choices=DIRECTIONS, section=INERTIAL_DIRECTION),
    custom("angle_deg", "Half-angle of the cone (about ``earth_limb``: from the limb, the cone widened by the "
           "Earth's apparent radius).", "number", _angle, unit="deg", bounds="> 0 and < 180"),
    custom("window", "When it applies: ``[start, end]`` from t = 0, ``null`` end: to the end of the run; inside "
           "the run.", "list of 2 numbers (the end may be null)", _window, unit="s", default=[0.0, None]),
), "One pointing requirement: a sensor's boresight kept out of (or inside) a cone about a direction.")


def _margin(node: Node) -> float:
    value = node.number(non_negative=True)
    if not value < 1.0:
        raise node.error(f"expected a margin in [0, 1) (0.1: the reference asks at most 90 % of each limit), "
                         f"got {excerpt(node.value)}")
    return value


REQUIREMENT_ACTUATORS = Section((
    custom("margin", "The reference asks at most ``(1 - margin)`` of each actuator limit (wheel torque and "
           "momentum, dipole, torquer torque), its demand taken through the row's controller's allocation.",
           "number", _margin, default=0.0, bounds=">= 0 and < 1"),
), "The reference must be feasible for the actuators.")

def _actuators(node: Node) -> dict | None:
    """``requirements.actuators``: its values, ``None`` for null; absent, margin 0 (unstated)."""
    if isinstance(node.value, Described):
        return {"margin": 0.0}
    if node.is_null():
        return None
    return REQUIREMENT_ACTUATORS.read(node)


REQUIREMENT_RATE = Section((
    number("max", "Bound on the body-rate norm ‖ω‖, reference and closed loop; also the planners' rate bound "
           "unless ``maneuver.max_rate`` is given (which must then not exceed it).", unit="rad/s", positive=True),
), "A body-rate limit.")

REQUIREMENT_FINAL = Section((
    number("after_s", "From ``T + after_s`` (T: the reference's duration) to the end of the run; the run must "
           "reach it (``simulation.duration``).", unit="s", default=0.0, non_negative=True),
    number("error_deg", "Bound on the error angle to ``maneuver.final.q``, scored between the closed loop's "
           "samples too (the attitude interpolated as for pointing); ``null``: none.", unit="deg",
           default=None, positive=True, maximum=180.0, nullable=True),
    number("rate", "Bound on ‖ω − ω_f‖ (``maneuver.final.omega``), scored at the closed loop's samples only; "
           "``null``: none.", unit="rad/s", default=None,
           positive=True, nullable=True),
), "The closed loop's final error and rate.")

REQUIREMENTS = Section((
    custom("pointing", "Pointing requirements by name (the name heads the result columns "
           "``ref.req.<name>.*`` and ``cl.req.<name>.*``).", "mapping of names to mappings", None, default={},
           section=POINTING, named=True),
    custom("actuators", "The reference's demand on the actuators. Absent: required with margin 0 (the "
           "actuators' limits are the scenario's: a reference that asks more than they give is never ok), and "
           "named in a row's note only when broken (``{}`` states it: named wherever a planner does not honour "
           "it); ``null``: not required: no actuator demand is scored and no row is violated for it (the closed "
           "loop's saturation is reported as a metric, ``cl.saturation_fraction``, never scored).", "mapping or null",
           _actuators, default=Described("margin 0, unstated"), section=REQUIREMENT_ACTUATORS),
    mapping("rate", "A body-rate limit; absent or ``null``: none.", REQUIREMENT_RATE, default=None, null="none"),
    mapping("final", "The closed loop's final error and rate; absent or ``null``: none.", REQUIREMENT_FINAL,
            default=None, null="none"),
), "What every row is scored against, reference and closed loop; a row that breaks one is ``violated``.")


def parse_sensors(node: Node) -> dict[str, Sensor]:
    """``spacecraft.sensors``: named boresights.

    Parameters
    ----------
    node : Node
        The ``sensors`` mapping (null or absent: none).

    Returns
    -------
    dict of str to Sensor
        By name, in the order written.

    Raises
    ------
    ScenarioError
        At the sensor's path for a bad name or boresight.
    """
    if node.is_null():
        return {}
    node.mapping()
    sensors = {}
    for name in list(node.value):
        entry = node.get(_name(node, name, "sensor"))
        sensors[name] = Sensor(name, SENSOR.read(entry)["boresight"])
    node.finish()
    return sensors


@dataclass(frozen=True)
class RunSpan:
    """The lengths a scenario's requirements are checked and tabulated against.

    Parameters
    ----------
    manoeuvre : float
        ``maneuver.duration`` [s].
    run : float
        The closed-loop window as written [s]: ``simulation.duration``, else the manoeuvre's.
    run_given : bool
        Whether ``simulation.duration`` is given.
    table : float
        How far directions are tabulated [s] (the run, with room for a planner's longer
        reference; near the ephemeris' end, clipped to it: :func:`check_ephemeris`).
    """

    manoeuvre: float
    run: float
    run_given: bool
    table: float


def _direction(node: Node, geometry: Geometry) -> Direction:
    """A direction: a registered kind's name or ``{inertial: [x, y, z]}``, checked against what the
    scenario gives (epoch, orbit)."""
    if isinstance(node.value, dict):
        if len(node.value) == 1 and next(iter(node.value)) in ("lvlh", "rtn", "ground"):  # a target's frame
            raise node.error(f"a requirement's direction is a name of {sorted(DIRECTIONS)} or {{inertial: [x, y, z]}}, "
                             f"got {{{excerpt(next(iter(node.value)))}: ...}} (the lvlh, rtn and ground frames are "
                             "for the manoeuvre's attitude targets, not for requirements)")
        vector_ = INERTIAL_DIRECTION.read(node)["inertial"]
        if not np.linalg.norm(vector_) > 1e-12:
            raise ScenarioError(f"{node.path}.inertial", f"a direction cannot be zero, got {vector_.tolist()}")
        return Direction(None, vector_)
    if not isinstance(node.value, str) or node.value not in DIRECTIONS:
        raise node.error(f"unknown direction {excerpt(node.value)}; expected one of {sorted(DIRECTIONS)} or "
                         "{inertial: [x, y, z]}")
    kind = DIRECTIONS[node.value]
    if kind.needs_epoch and geometry.epoch is None:
        raise node.error(f"direction {node.value!r} ({kind.meaning}) needs the scenario's epoch: give the top-level "
                         "`epoch:` (UTC, e.g. 2027-03-20T12:00:00Z)")
    if kind.needs_orbit and geometry.orbit is None:
        raise node.error(f"direction {node.value!r} ({kind.meaning}) needs an orbit: give `orbit:`")
    return Direction(node.value)


def _pointing(node: Node, name: str, sensors: dict[str, Sensor], geometry: Geometry,
              span: RunSpan) -> tuple[PointingRequirement, PointingConstraint]:
    node.mapping()
    sensor_node = POINTING["sensor"].value(node)
    sensor_name = sensor_node.string()
    if sensor_name not in sensors:
        raise sensor_node.error(f"unknown sensor {sensor_name!r}; spacecraft.sensors has "
                                f"{sorted(sensors) if sensors else 'none (declare it there)'}")
    out_node, in_node = POINTING["keep_out"].value(node), POINTING["keep_in"].value(node)
    if out_node.is_null() == in_node.is_null():
        raise node.exactly_one(("keep_out", "keep_in"), [key for key in ("keep_out", "keep_in") if key in node])
    keep_out = not out_node.is_null()
    direction_node = out_node if keep_out else in_node
    direction = _direction(direction_node, geometry)
    angle = POINTING["angle_deg"].value(node)
    window_node = POINTING["window"].node(node)
    window = _window(window_node)
    if window[0] >= span.run:
        raise window_node.error(f"the window starts at {window[0]:g} s, after the run's end at {span.run:g} s "
                                "(simulation.duration, else maneuver.duration)")
    if window[1] is not None and window[1] > span.run + 1e-9:
        raise window_node.error(f"the window ends at {window[1]:g} s, after the run's end at {span.run:g} s "
                                "(simulation.duration, else maneuver.duration); write null for the end of the run")
    node.finish()
    requirement = PointingRequirement(name, sensors[sensor_name], keep_out, float(np.deg2rad(angle)), direction, window)
    try:
        constraint = requirement.constraint(geometry, span.table)
    except ModelError as error:
        raise direction_node.error(error.message) from None
    if keep_out:  # a cone widened by the Earth's disc may cover the sky
        end = span.run if window[1] is None else window[1]
        inside = constraint.times[(constraint.times > window[0]) & (constraint.times < end)]
        widest = float(np.max(constraint.limit(np.concatenate([[window[0], end], inside]))))
        if widest >= np.pi:
            raise ScenarioError(f"{node.path}.angle_deg",
                                f"{angle:g} deg from the limb, with the Earth's apparent radius up to "
                                f"{np.rad2deg(widest) - angle:.4g} deg, is a keep-out cone of "
                                f"{np.rad2deg(widest):.4g} deg half-angle: it covers the whole sky, so no attitude "
                                "meets it; lower it")
    return requirement, constraint


def _final(node: Node, values: dict, qf_free: bool, omegaf_free: bool, span: RunSpan) -> FinalRequirement:
    if values["error_deg"] is None and values["rate"] is None:
        raise node.error("give error_deg, rate or both")
    if values["error_deg"] is not None and qf_free:
        raise ScenarioError(f"{node.path}.error_deg", "the final attitude is free (maneuver.final.q is null): "
                                                      "there is no error angle to bound")
    if values["rate"] is not None and omegaf_free:
        raise ScenarioError(f"{node.path}.rate", "the final rate is free (maneuver.final.omega is null): there "
                                                 "is no rate error to bound")
    start = span.manoeuvre + values["after_s"]
    if start > span.run + 1e-9:
        raise ScenarioError(f"{node.path}.after_s",
                            f"T + after_s = {start:g} s is after the run's end at {span.run:g} s; "
                            + ("lengthen simulation.duration" if span.run_given
                               else "set simulation.duration (the run ends at T without it)"))
    return FinalRequirement(values["after_s"], values["error_deg"], values["rate"])


def parse_requirements(node: Node, sensors: dict[str, Sensor], geometry: Geometry, span: RunSpan,
                       qf_free: bool, omegaf_free: bool) -> tuple[Requirements, tuple[PointingConstraint, ...]]:
    """The ``requirements`` section (:data:`REQUIREMENTS`) and the pointing constraints of the run.

    Parameters
    ----------
    node : Node
        The ``requirements`` mapping (null or absent: none).
    sensors : dict of str to Sensor
        ``spacecraft.sensors``.
    geometry : Geometry
        The epoch and the orbit (a direction that needs one the scenario lacks is an error).
    span : RunSpan
        The manoeuvre's and the run's lengths.
    qf_free, omegaf_free : bool
        Whether the final attitude, the final rate is free (``requirements.final`` cannot bound it).

    Returns
    -------
    requirements : Requirements
        The requirement objects.
    constraints : tuple of PointingConstraint
        One per pointing requirement, its direction tabulated over ``span.table``.

    Raises
    ------
    ScenarioError
        Naming the YAML path, the value and what was expected.
    """
    if node.is_null():
        return Requirements(), ()
    node.mapping()
    pointing_node = REQUIREMENTS["pointing"].value(node)
    pointing, constraints = [], []
    if not pointing_node.is_null():
        pointing_node.mapping()
        for name in list(pointing_node.value):
            _name(pointing_node, name, "requirement")
            if name in RESERVED_NAMES:
                raise ScenarioError(f"{pointing_node.path}.{name}", f"{name!r} names the {name} requirement; "
                                    f"choose another name (not one of {list(RESERVED_NAMES)})")
            requirement, constraint = _pointing(pointing_node.get(name), name, sensors, geometry, span)
            pointing.append(requirement)
            constraints.append(constraint)
        pointing_node.finish()
    stated = isinstance(node.value, dict) and "actuators" in node.value
    actuators = REQUIREMENTS["actuators"].value(node)
    rate = REQUIREMENTS["rate"].value(node)
    final_node = REQUIREMENTS["final"].node(node)
    final_values = REQUIREMENTS["final"].value(node)
    node.finish()
    requirements = Requirements(
        tuple(pointing),
        None if actuators is None else ActuatorRequirement(actuators["margin"], stated),
        None if rate is None else RateRequirement(rate["max"]),
        None if final_values is None else _final(final_node, final_values, qf_free, omegaf_free, span),
    )
    return requirements, tuple(constraints)


def check_ephemeris(epoch: datetime.datetime | None, span: RunSpan) -> RunSpan:
    """Refuse an epoch whose run leaves the ephemeris; clip the tabulated window to it.

    Every consumer of the ephemeris (a pointing requirement's direction, an attitude target's, a
    sensor's exclusion cone) reads it inside ``span.table`` from the epoch, so this one check, made
    before any of them, covers them all. When the run itself fits but the tabulation window (the
    room left for a longer reference) would leave the ephemeris, the window is clipped to the
    ephemeris' end: a reference running past it sees the directions held at their last value.

    Parameters
    ----------
    epoch : datetime.datetime or None
        The scenario's epoch, UTC (``None``: nothing to check).
    span : RunSpan
        The run and its tabulated length.

    Returns
    -------
    RunSpan
        ``span``, its ``table`` clipped to the ephemeris' end when that is shorter (never below
        ``span.run``).

    Raises
    ------
    ScenarioError
        At ``epoch``, naming the epoch, the run (``simulation.duration``, else ``maneuver.duration``)
        and the limit it crosses: the epoch before the ephemeris' start or after its end, or the run
        ending after it.
    """
    if epoch is None:
        return span
    low, high = EPHEMERIS_RANGE
    covers = f"the ephemeris (JPL DE421) covers {low:%Y-%m-%d} to {high:%Y-%m-%d} UTC"
    run = ("simulation.duration" if span.run_given else "maneuver.duration") + f" = {span.run:g} s"
    if epoch < low or epoch >= high:
        side = f"before its start, {low:%Y-%m-%d}" if epoch < low else f"after its end, {high:%Y-%m-%d}"
        raise ScenarioError("epoch", f"{covers}; the epoch {epoch.isoformat()}Z is {side} (the run: {run})")
    room = (high - epoch).total_seconds()
    if span.run > room:
        end = epoch + datetime.timedelta(seconds=span.run)
        latest = high - datetime.timedelta(seconds=span.run)
        raise ScenarioError("epoch", f"{covers}; the run from {epoch.isoformat()}Z ({run}) ends at "
                            f"{end.isoformat()}Z, after its end: start it at {latest.isoformat()}Z or earlier, "
                            "or shorten it")
    if span.table > room:
        span = dataclasses.replace(span, table=room)
    check_epoch(epoch, span.table)  # the same limits, as the ephemeris module states them
    return span
