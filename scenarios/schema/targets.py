"""The attitudes of ``maneuver.initial.q`` and ``maneuver.final.q`` in mission terms.

An attitude is a list of four numbers (a quaternion, inertial frame: the plain form), or a mapping
of exactly one *form* of :data:`ATTITUDE_FORMS`:

* ``quaternion: [q0, q1, q2, q3]`` (in the order of ``maneuver.quaternion_order``);
* ``axis_angle: {axis: [x, y, z], angle_deg: a}``: the rotation by ``a`` about ``axis``;
* ``euler: {angles_deg: [a, b, c], sequence: "321"}``: rotations about body axes in that order
  (:func:`ocp.quat.from_euler`);
* ``point: {sensor: <name> | boresight: [..], at: <direction>, secondary: {sensor | axis, toward}}``:
  a boresight on a target, a second body axis toward a second direction fixing the roll
  (:func:`ocp.geometry.targets.two_vector_attitude`);

with ``frame`` (the first three forms; :data:`~ocp.geometry.targets.ATTITUDE_FRAMES`, or
``initial`` for a final attitude relative to the initial one) and ``at_time_s`` (the instant of an
``lvlh`` or ``rtn`` frame and of a ``point`` target's directions; default 0 for the initial
attitude, ``maneuver.duration`` for the final). The three rotation forms give the body's attitude
*relative to the frame*: ``q = q_frame ⊗ q_form``. A target direction is a name of
:data:`~ocp.geometry.directions.DIRECTIONS` (``earth`` is nadir), ``{inertial: [..]}``,
``{lvlh: [..]}``, ``{rtn: [..]}`` (a direction fixed in the orbit's frame at the instant) or
``{ground: {lat_deg, lon_deg, alt_m}}`` (a WGS-84 point, which needs the epoch and the orbit; the
spacecraft must be above its horizon).

Every error is a :class:`~scenarios.errors.ScenarioError` naming the YAML path: two forms or none,
a frame or direction that needs the orbit or epoch the scenario lacks, a secondary axis parallel to
the boresight, a secondary direction parallel to the target, a ground point below the horizon.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ocp import quat
from ocp.errors import ModelError, excerpt
from ocp.geometry.directions import DIRECTIONS, Geometry
from ocp.geometry.targets import ATTITUDE_FRAMES, ground_point, two_vector_attitude
from scenarios.errors import ScenarioError
from scenarios.requirements.spec import Sensor
from scenarios.schema.keys import (
    QUATERNION_BOUNDS,
    Described,
    Key,
    Section,
    custom,
    mapping,
    number,
    vector,
)
from scenarios.schema.node import Node

__all__ = ["ATTITUDE", "ATTITUDE_FORMS", "AXIS_ANGLE", "EULER", "GROUND", "POINT", "SECONDARY", "TARGET_DIRECTION",
           "AttitudeContext", "AttitudeForm", "attitude_key", "axis_angle_quaternion", "parse_attitude", "rotation_axis"]

Array = NDArray[np.float64]

INITIAL_FRAME = "initial"
"""The frame of a final attitude written relative to the initial one (its body axes)."""


@dataclass(frozen=True)
class AttitudeContext:
    """What an attitude form is read against.

    Parameters
    ----------
    geometry : Geometry
        The epoch and the orbit.
    sensors : dict of str to Sensor
        ``spacecraft.sensors``.
    scalar_last : bool
        Whether quaternions are written scalar last (``maneuver.quaternion_order``).
    time : float
        The default instant [s] of the time-dependent parts (0 for the initial attitude,
        ``maneuver.duration`` for the final).
    initial : (4,) ndarray or None, optional
        The initial attitude, for ``frame: initial`` (``None``: reading the initial attitude
        itself).
    """

    geometry: Geometry
    sensors: dict[str, Sensor]
    scalar_last: bool
    time: float
    initial: Array | None = None


# --- shared readers and conversions (the study's axis_angle generator uses them too) -------------

def rotation_axis(node: Node) -> Array:
    """A rotation axis: three numbers, not all zero.

    Parameters
    ----------
    node : Node
        The ``axis`` value.

    Returns
    -------
    (3,) ndarray
        The axis, scaled so that its largest component is ±1 (its norm cannot overflow).

    Raises
    ------
    ScenarioError
        At the node: not three finite numbers, or zero.
    """
    axis = node.vector(3)
    largest = float(np.max(np.abs(axis)))
    if not largest > 0:
        raise node.error("the rotation axis cannot be zero")
    return axis / largest


def axis_angle_quaternion(axis: ArrayLike, angle_deg: float) -> Array:
    """The quaternion of a rotation by ``angle_deg`` about ``axis``: the one conversion of the
    ``axis_angle`` attitude form and of the study's ``axis_angle`` generator.

    Parameters
    ----------
    axis : (3,) array_like
        Rotation axis, any non-zero length.
    angle_deg : float
        Rotation angle [deg], right-handed about ``axis``.

    Returns
    -------
    (4,) ndarray
        Unit quaternion, scalar first.
    """
    return quat.from_axis_angle(axis, np.deg2rad(float(angle_deg)))


# --- directions a target or a secondary axis is turned to ----------------------------------------

GROUND = Section((
    number("lat_deg", "Geodetic latitude (WGS-84).", unit="deg", minimum=-90.0, maximum=90.0),
    number("lon_deg", "Longitude, east positive.", unit="deg", minimum=-180.0, maximum=360.0),
    number("alt_m", "Height above the WGS-84 ellipsoid (under 100 km below it: the deepest point of the "
           "Earth is 11 km down).", unit="m", default=0.0, minimum=-1e5, maximum=1e8),
), "A point on the ground; needs the epoch (the Earth's orientation) and the orbit.")

_ONE_DIRECTION = Described("absent (the mapping has one of inertial, lvlh, rtn, ground)")

TARGET_DIRECTION = Section((
    vector("inertial", "A fixed direction, inertial frame (normalised; zero refused).", 3, default=_ONE_DIRECTION),
    vector("lvlh", "A direction fixed in the LVLH frame at the instant (``[0, -1, 0]``: the orbit normal); needs "
           "the orbit.", 3, default=_ONE_DIRECTION),
    vector("rtn", "A direction fixed in the RTN frame at the instant (``[0, 0, 1]``: the orbit normal); needs the "
           "orbit.", 3, default=_ONE_DIRECTION),
    mapping("ground", "A ground point, seen from the spacecraft at the instant; the spacecraft must be above the "
            "point's horizon.", GROUND, default=_ONE_DIRECTION),
), "A direction written as a mapping of one key.")

_DIRECTION_WORDS = ("a direction: a name of ``DIRECTIONS`` (``sun``, ``moon``, ``earth``: nadir, ``velocity``; not the "
                    "disc ``earth_limb``), "
                    "``{inertial: [x, y, z]}``, ``{lvlh: [x, y, z]}``, ``{rtn: [x, y, z]}`` or "
                    "``{ground: {lat_deg, lon_deg, alt_m}}``, evaluated at ``at_time_s``")


def _fixed(node: Node, frame: str, context: AttitudeContext, t: float) -> Array:
    value = TARGET_DIRECTION[frame].value(node)
    if not np.linalg.norm(value) > 1e-12:
        raise ScenarioError(f"{node.path}.{frame}", f"a direction cannot be zero, got {value.tolist()}")
    kind = ATTITUDE_FRAMES[frame]
    if kind.needs_orbit and context.geometry.orbit is None:
        raise ScenarioError(f"{node.path}.{frame}", f"a direction in the {frame} frame needs an orbit: give `orbit:`")
    return kind.matrix(context.geometry, t) @ (value / np.linalg.norm(value))


def _ground(node: Node, context: AttitudeContext, t: float) -> Array:
    values = TARGET_DIRECTION["ground"].value(node)
    path = f"{node.path}.ground"
    if context.geometry.epoch is None:
        raise ScenarioError(path, "a ground point needs the scenario's epoch (the Earth's orientation): give the "
                                  "top-level `epoch:` (UTC, e.g. 2027-03-20T12:00:00Z)")
    if context.geometry.orbit is None:
        raise ScenarioError(path, "a ground point needs an orbit (the spacecraft's position): give `orbit:`")
    direction, elevation = ground_point(context.geometry, np.deg2rad(values["lat_deg"]),
                                        np.deg2rad(values["lon_deg"]), values["alt_m"], t)
    if elevation < 0.0:
        raise ScenarioError(path, f"the spacecraft is below the point's horizon at t = {t:g} s (elevation "
                                  f"{np.rad2deg(elevation):.3g} deg): the boresight would look through the Earth; "
                                  "choose another at_time_s or point")
    return direction


def _direction(node: Node, context: AttitudeContext, t: float) -> Array:
    """A unit vector, inertial frame, at ``t``: a registered direction's name or a mapping of
    :data:`TARGET_DIRECTION`."""
    if isinstance(node.value, dict):
        node.mapping()
        given = [key.name for key in TARGET_DIRECTION.keys if key.name in node.value]
        if len(given) != 1 or len(node.value) != 1:
            raise node.error(f"expected {_DIRECTION_WORDS}; got {excerpt(node.value)}")
        (name,) = given
        return _ground(node, context, t) if name == "ground" else _fixed(node, name, context, t)
    if not isinstance(node.value, str) or node.value not in DIRECTIONS:
        raise node.error(f"unknown direction {excerpt(node.value)}; expected one of {sorted(DIRECTIONS)} (earth: "
                         "nadir) or a mapping {inertial | lvlh | rtn: [x, y, z]} or {ground: {lat_deg, lon_deg, "
                         "alt_m}}")
    kind = DIRECTIONS[node.value]
    if kind.needs_epoch and context.geometry.epoch is None:
        raise node.error(f"direction {node.value!r} ({kind.meaning}) needs the scenario's epoch: give the top-level "
                         "`epoch:` (UTC, e.g. 2027-03-20T12:00:00Z)")
    if kind.needs_orbit and context.geometry.orbit is None:
        raise node.error(f"direction {node.value!r} ({kind.meaning}) needs an orbit: give `orbit:`")
    try:
        directions, growth = kind.table(context.geometry, np.array([float(t)]))
    except ModelError as error:
        raise node.error(error.message) from None
    if growth[0] != 0.0:
        raise node.error(f"{node.value!r} is a disc (a cone widened by its apparent radius), not a direction to "
                         "point at; use `earth` for nadir")
    return np.asarray(directions[0], dtype=float)


# --- the attitude forms -----------------------------------------------------------------------------

def _sequence(node: Node) -> str:
    sequence = str(node.value) if isinstance(node.value, int) and not isinstance(node.value, bool) else node.string()
    try:
        quat.from_euler(np.zeros(3), sequence)
    except ValueError as error:
        raise node.error(str(error)) from None
    return sequence


AXIS_ANGLE = Section((
    custom("axis", "Rotation axis (any length but zero), in the axes of ``frame``.", "list of 3 numbers",
           rotation_axis),
    number("angle_deg", "Rotation angle, right-handed about ``axis`` (within ±360: a turn; 1e300 gave an "
           "attitude of rounding noise).", unit="deg", minimum=-360.0, maximum=360.0),
), "The rotation by ``angle_deg`` about ``axis``, from ``frame`` to the body.")

EULER = Section((
    vector("angles_deg", "The three angles, in the order of ``sequence`` (each within ±360: a turn).", 3, unit="deg",
           magnitude=360.0),
    custom("sequence", "The body axes rotated about, in order, from ``frame`` to the body: ``\"321\"`` (yaw, "
           "pitch, roll), ``\"313\"`` ... (1, 2, 3 or x, y, z; no two consecutive ones equal).", "text", _sequence,
           default="321"),
), "Euler angles: rotations about body axes in the order of ``sequence`` (``q = q_a(α) ⊗ q_b(β) ⊗ q_c(γ)``).")


def _body_axis(node: Node, keys: tuple[str, str], sensors: dict[str, Sensor]) -> tuple[Array, str]:
    """A body axis given as a sensor's name or a vector (``keys``: the two names); ``(unit axis, path)``."""
    sensor_key, vector_key = keys
    if (sensor_key in node) == (vector_key in node):
        raise node.exactly_one(keys, [key for key in keys if key in node],
                               f" ({sensor_key}: a name under spacecraft.sensors, {vector_key}: 3 numbers, body axes)")
    if sensor_key in node:
        name_node = node.get(sensor_key)
        name = name_node.string()
        if name not in sensors:
            raise name_node.error(f"unknown sensor {name!r}; spacecraft.sensors has "
                                  f"{sorted(sensors) if sensors else 'none (declare it there)'}")
        node.get(vector_key, None)
        return sensors[name].boresight, name_node.path
    axis_node = node.get(vector_key)
    axis = axis_node.vector(3)
    if not np.linalg.norm(axis) > 1e-12:
        raise axis_node.error(f"a body axis cannot be zero, got {axis.tolist()}")
    node.get(sensor_key, None)
    return axis / np.linalg.norm(axis), axis_node.path


SECONDARY = Section((
    custom("sensor", "The body axis that fixes the roll: a sensor's boresight (a name under "
           "``spacecraft.sensors``); or give ``axis``.", "text", None, default=Described("absent when axis is given")),
    vector("axis", "The body axis that fixes the roll, body axes; or give ``sensor``.", 3,
           default=Described("absent when sensor is given")),
    custom("toward", "Where it is turned (as near as the primary allows: into the half-plane of the target and "
           "this direction): " + _DIRECTION_WORDS + ".", "text or mapping", None, choices=DIRECTIONS,
           section=TARGET_DIRECTION),
), "The second axis: it lies in the plane of the target and ``toward``, on the side of ``toward``.")

POINT = Section((
    custom("sensor", "The body axis to point: a sensor's boresight (a name under ``spacecraft.sensors``); or give "
           "``boresight``.", "text", None, default=Described("absent when boresight is given")),
    vector("boresight", "The body axis to point, body axes; or give ``sensor``.", 3,
           default=Described("absent when sensor is given")),
    custom("at", "The target the boresight points at exactly: " + _DIRECTION_WORDS + ".", "text or mapping", None,
           choices=DIRECTIONS, section=TARGET_DIRECTION),
    mapping("secondary", "The second body axis and its direction, which fix the roll about the target.", SECONDARY),
), "A boresight pointed at a target, the roll fixed by a second axis.")


def _point(node: Node, context: AttitudeContext, t: float) -> Array:
    node.mapping()
    boresight, _ = _body_axis(node, ("sensor", "boresight"), context.sensors)
    target = _direction(POINT["at"].value(node), context, t)
    secondary_node = POINT["secondary"].node(node).mapping()
    axis, axis_path = _body_axis(secondary_node, ("sensor", "axis"), context.sensors)
    toward_node = SECONDARY["toward"].value(secondary_node)
    toward = _direction(toward_node, context, t)
    secondary_node.finish()
    node.finish()
    try:
        return two_vector_attitude(boresight, target, axis, toward)
    except ModelError as error:
        where = {"secondary_body": axis_path, "secondary_direction": toward_node.path}.get(error.field, node.path)
        raise ScenarioError(where, error.message) from None


@dataclass(frozen=True)
class AttitudeForm:
    """One way of writing an attitude, a key of the attitude mapping (:data:`ATTITUDE_FORMS`).

    Parameters
    ----------
    key : Key
        The form's key: how the reference describes it (its value is read by ``build``).
    framed : bool
        Whether it is written in a ``frame`` (``False``: it fixes the inertial attitude itself).
    build : callable
        ``build(node, context, t) -> q``: the form's value node, the context and the instant
        [s]; the quaternion (scalar first) in the form's frame.
    """

    key: Key
    framed: bool
    build: Callable[[Node, AttitudeContext, float], Array]

    @property
    def name(self) -> str:
        """The form's key name."""
        return self.key.name


def _quaternion(node: Node, context: AttitudeContext, t: float) -> Array:
    q = node.quaternion()
    return quat.from_scalar_last(q) if context.scalar_last else q


def _axis_angle(node: Node, context: AttitudeContext, t: float) -> Array:
    values = AXIS_ANGLE.read(node)
    return axis_angle_quaternion(values["axis"], values["angle_deg"])


def _euler(node: Node, context: AttitudeContext, t: float) -> Array:
    values = EULER.read(node)
    return quat.from_euler(np.deg2rad(values["angles_deg"]), values["sequence"])


_ONE_FORM = Described("absent (the mapping has exactly one form)")

ATTITUDE_FORMS: dict[str, AttitudeForm] = {form.name: form for form in (
    AttitudeForm(custom("quaternion", "A quaternion, body to ``frame`` (``v_frame = R(q) v_body``; scalar first unless "
                        "``maneuver.quaternion_order: scalar_last``).", "list of 4 numbers", None,
                        default=_ONE_FORM, bounds=QUATERNION_BOUNDS), True, _quaternion),
    AttitudeForm(custom("axis_angle", "A rotation about an axis, from ``frame`` to the body.", "mapping", None,
                        default=_ONE_FORM, section=AXIS_ANGLE), True, _axis_angle),
    AttitudeForm(custom("euler", "Euler angles from ``frame`` to the body.", "mapping", None, default=_ONE_FORM,
                        section=EULER), True, _euler),
    AttitudeForm(custom("point", "A boresight on a target with a second axis fixing the roll (its own "
                        "directions: no ``frame``).", "mapping", None, default=_ONE_FORM, section=POINT), False, _point),
)}
"""The forms of an attitude mapping: name -> :class:`AttitudeForm` (exactly one per mapping)."""

_FRAME_CHOICES = (*ATTITUDE_FRAMES, INITIAL_FRAME)

ATTITUDE = Section((
    *(form.key for form in ATTITUDE_FORMS.values()),
    custom("frame", "The frame the ``quaternion``, ``axis_angle`` or ``euler`` form is written in: ``inertial``; "
           "``lvlh`` or ``rtn`` of the orbit at ``at_time_s`` (needs the orbit); ``initial`` (the final attitude "
           "only): the initial attitude's body axes.", "text", None, default="inertial", choices=_FRAME_CHOICES),
    custom("at_time_s", "The instant of an ``lvlh`` or ``rtn`` frame and of a ``point`` target's directions.",
           "number", None, unit="s", default=Described("0 for the initial attitude, maneuver.duration for the final"),
           bounds=">= 0"),
), "An attitude written as a mapping: exactly one of ``quaternion``, ``axis_angle``, ``euler`` and ``point``, "
   "with ``frame`` and ``at_time_s``.")

_TIMED_FRAMES = tuple(name for name, frame in ATTITUDE_FRAMES.items() if frame.needs_orbit)


def parse_attitude(node: Node, context: AttitudeContext) -> Array:
    """An attitude of ``maneuver.initial.q`` or ``maneuver.final.q``: four numbers (an inertial
    quaternion) or a mapping of one form of :data:`ATTITUDE_FORMS` (:data:`ATTITUDE`).

    Parameters
    ----------
    node : Node
        The value (not null: the caller handles a free final attitude).
    context : AttitudeContext
        The epoch, orbit, sensors, quaternion order, default instant and initial attitude.

    Returns
    -------
    (4,) ndarray
        Unit quaternion, scalar first, body to inertial.

    Raises
    ------
    ScenarioError
        Naming the YAML path, the value and what was expected.
    """
    if not isinstance(node.value, dict):
        if not isinstance(node.value, list):
            raise node.error(f"expected a quaternion (4 numbers) or a mapping of one of {list(ATTITUDE_FORMS)}, "
                             f"got {excerpt(node.value)}")
        return _quaternion(node, context, context.time)
    given = [name for name in ATTITUDE_FORMS if name in node]
    if len(given) != 1:
        raise node.exactly_one(tuple(ATTITUDE_FORMS), given)
    form = ATTITUDE_FORMS[given[0]]
    frame_node = ATTITUDE["frame"].node(node)
    frame = frame_node.string(_FRAME_CHOICES)
    time_node = ATTITUDE["at_time_s"].node(node)
    timed = not form.framed or frame in _TIMED_FRAMES
    t = context.time if isinstance(time_node.value, Described) else time_node.number(non_negative=True)
    if not isinstance(time_node.value, Described) and not timed:
        raise time_node.error(f"an attitude given as {form.name} in the {frame} frame does not depend on time; "
                              f"at_time_s applies to the frames {list(_TIMED_FRAMES)} and to point")
    if not form.framed and "frame" in node:
        raise frame_node.error(f"an attitude given as {form.name} is fixed by its own directions; frame applies to "
                               f"{[name for name, other in ATTITUDE_FORMS.items() if other.framed]}")
    if frame == INITIAL_FRAME and context.initial is None:
        raise frame_node.error("frame 'initial' is for the final attitude (relative to the initial one); the initial "
                               f"attitude takes one of {list(ATTITUDE_FRAMES)}")
    if frame in ATTITUDE_FRAMES and ATTITUDE_FRAMES[frame].needs_orbit and context.geometry.orbit is None:
        raise frame_node.error(f"frame {frame!r} ({ATTITUDE_FRAMES[frame].meaning}) needs an orbit: give `orbit:`")
    for other in ATTITUDE_FORMS:
        node.get(other, None)
    q_form = form.build(node.get(form.name), context, t)
    node.finish()
    if frame == INITIAL_FRAME:
        assert context.initial is not None
        return quat.normalize(quat.product(context.initial, q_form))
    q_frame = quat.from_rotation_matrix(ATTITUDE_FRAMES[frame].matrix(context.geometry, t))
    return quat.normalize(quat.product(q_frame, q_form))


def attitude_key(name: str, meaning: str, nullable: bool = False) -> Key:
    """The key of an attitude (``maneuver.initial.q``, ``maneuver.final.q``), read by
    :func:`parse_attitude` (its node is returned: the loader knows the context).

    Parameters
    ----------
    name, meaning : str
        The YAML key and what it does.
    nullable : bool, optional
        Whether ``null`` is accepted (a free final attitude).

    Returns
    -------
    Key
        The key, its forms described by :data:`ATTITUDE`.
    """
    return custom(name, meaning, "list of 4 numbers, mapping" + (" or null" if nullable else ""), None,
                  section=ATTITUDE)
