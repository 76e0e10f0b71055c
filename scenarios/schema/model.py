"""The model sections of a scenario YAML: ``spacecraft``, ``orbit`` and ``environment``.

Each section's keys are declared here (:data:`SPACECRAFT`, :data:`ORBIT`, :data:`ENVIRONMENT`) and
read through them; the orbit kinds and their options come from the registry
:data:`~ocp.dynamics.orbits.ORBITS`, the magnetic field models and their options from
:data:`~ocp.dynamics.environment.MAGNETIC_FIELDS`. Errors are
:class:`~scenarios.errors.ScenarioError` at the YAML path; a model constructor's
:class:`~ocp.ModelError` is reported at the field it names. Kilometres and degrees become SI here.
"""
from __future__ import annotations

import dataclasses
import datetime
from collections.abc import Callable
from typing import Any

import numpy as np

from ocp import (
    Environment,
    Magnetorquers,
    ModelError,
    ReactionWheels,
    Spacecraft,
    Torquers,
)
from ocp.dynamics.environment import MAGNETIC_FIELDS, MAX_DISTURBANCE, MagneticField
from ocp.dynamics.ephemeris import parse_utc
from ocp.dynamics.orbits import ORBITS, TLE_EPOCH_WARN_DAYS, Orbit
from ocp.dynamics.spacecraft import MAX_INERTIA, MIN_INERTIA
from ocp.errors import InvalidOption, excerpt
from ocp.simulation.compiled import notice
from scenarios.errors import ScenarioError
from scenarios.requirements.spec import Sensor
from scenarios.schema.keys import (
    Section,
    boolean,
    choice,
    custom,
    mapping,
    option_keys,
    read_mapping,
    vector,
)
from scenarios.schema.node import Node
from scenarios.schema.requirements import SENSOR, parse_sensors

__all__ = ["ENVIRONMENT", "MAGNETIC_FIELD", "MAGNETORQUERS", "ORBIT", "SPACECRAFT", "TORQUERS",
           "WHEELS",
           "parse_environment", "parse_magnetic_field", "parse_orbit", "parse_spacecraft"]


def _model_part(node: Node, build: Callable[..., Any], **kwargs: Any) -> Any:
    """Call a model constructor, turning its ModelError into a ScenarioError at ``node.path``
    (at ``<node.path>.<field>`` when the error names a field)."""
    try:
        return build(**kwargs)
    except ModelError as error:
        where = (f"{node.path}.{error.field}" if node.path else error.field) if error.field else node.path
        raise ScenarioError(where, error.message) from None


def _limits(node: Node) -> Any:
    return None if node.is_null() else node.vector(allow_scalar=True)


def _inertia(node: Node) -> np.ndarray:
    inertia = node.value
    if isinstance(inertia, list) and inertia and all(isinstance(row, list) for row in inertia):
        if len(inertia) != 3:
            raise node.error(f"expected a 3x3 matrix (3 rows of 3 numbers), got {len(inertia)} rows")
        values = np.array([Node(row, f"{node.path}[{i}]").vector(3) for i, row in enumerate(inertia)])
    elif not isinstance(inertia, list):
        raise node.error(f"expected a list of 3 numbers or a 3x3 matrix (3 rows of 3 numbers), got {excerpt(inertia)}")
    else:
        values = node.vector(3)
    if np.any(np.abs(values) > MAX_INERTIA):
        raise node.error(f"expected entries within ±{MAX_INERTIA:g} kg m² (ten thousand times the International Space "
                         f"Station's), got {values.tolist()}")
    matrix = np.diag(values) if values.ndim == 1 else values
    least = float(np.linalg.eigvalsh((matrix + matrix.T) / 2.0)[0])
    if 0.0 < least < MIN_INERTIA:
        raise node.error(f"expected a least principal moment of at least {MIN_INERTIA:g} kg m² (a gram at a millimetre; "
                         f"the smallest spacecraft have about 1e-7), got {least:.4g} kg m² for {values.tolist()}")
    return values


def _axes(node: Node) -> np.ndarray:
    return np.eye(3) if node.is_null() else np.array([row.vector(3) for row in node.items()]).T


def _limit(name: str, meaning: str, unit: str, each: str = "wheel") -> Any:
    return custom(name, meaning, f"number, list of numbers (one per {each}) or null", _limits, unit=unit, default=None)


WHEELS = Section((
    custom("axes", "Spin axes of the wheels, one row (3 numbers, body axes) per wheel; ``null``: the body axes.",
           "list of lists of 3 numbers or null", _axes, default=None),
    _limit("max_torque", "Torque bound of each wheel (one number for all); ``null``: none.", "N m"),
    _limit("max_momentum", "Momentum bound of each wheel; ``null``: none.", "N m s"),
    _limit("spin_inertia", "Spin inertia of each wheel (wheel speeds are reported with it); ``null``: none.",
           "kg m²"),
    custom("failed", "Indices (from 0) of failed wheels, which give no torque.", "list of integers",
           lambda node: tuple(item.integer() for item in node.items()), default=[]),
), "Reaction wheels; ``null`` (or ``none``): no wheels.")

MAGNETORQUERS = Section((
    _limit("max_dipole", "Dipole bound per axis (one number for all three); ``null``: none.", "A m²", "axis"),
    choice("saturation", "``per_axis``: each axis clipped to ``max_dipole``; ``scale``: the dipole vector "
           "scaled down as a whole, keeping its direction.", ("per_axis", "scale"), default="per_axis"),
), "Magnetorquers on the body axes; absent or ``null``: none.")

TORQUERS = Section((
    _limit("max_torque", "Torque bound per body axis (one number for all three); ``null``: none.", "N m", "axis"),
), "Ideal body-axis torquers (thrusters) that store no momentum; absent or ``null``: none.")

SPACECRAFT = Section((
    custom("inertia", "Principal moments (3 numbers) or the 3x3 inertia matrix about the centre of mass, body "
           "frame; positive definite, the moments meeting the triangle inequality.",
           "list of 3 numbers or 3x3 matrix", _inertia, unit="kg m²",
           bounds=f"each entry within ±{MAX_INERTIA:g}; the least principal moment at least {MIN_INERTIA:g}"),
    mapping("wheels", "Reaction wheels (default: three wheels on the body axes without bounds).", WHEELS,
            default={}, null="none"),
    mapping("magnetorquers", "Magnetorquers.", MAGNETORQUERS, default=None, null="none"),
    mapping("torquers", "Ideal body-axis torquers.", TORQUERS, default=None, null="none"),
    custom("sensors", "Named sensors (star trackers, cameras, antennas, panels) that ``requirements.pointing`` "
           "constrains; the name is the key.", "mapping of names to mappings", parse_sensors, default={},
           section=SENSOR, named=True),
), "The rigid body, its actuators and its sensors.")

ORBIT = Section((
    choice("type", "The orbit kind (a name registered in ``ORBITS``); the other keys of the mapping are its options.",
           ORBITS, default="circular"),
), "The orbit (absent or ``null``: none): ``type`` and that kind's keys; the gravity gradient and magnetic fields "
   "need one, and so do the directions of the Earth and of the velocity.")

MAGNETIC_FIELD = Section((
    choice("model", "The field model (a name registered in ``MAGNETIC_FIELDS``); the other keys of the mapping "
           "are its options.", MAGNETIC_FIELDS, default="tilted_dipole"),
), "A field model's name, ``none``, or a mapping of ``model`` and the model's options.")


ENVIRONMENT = Section((
    boolean("gravity_gradient", "Include the gravity-gradient torque (needs ``orbit``).", default=False),
    custom("magnetic_field", "The geomagnetic field: a model name (its default options), ``none``, or "
           "``{model: <name>, <option>: <value>, ...}``; needs ``orbit``.", "text, mapping or null", None,
           default=None, section=MAGNETIC_FIELD, choices=MAGNETIC_FIELDS),
    vector("disturbance_torque", f"Constant disturbance torque, body frame (each entry within ±{MAX_DISTURBANCE:g}).", 3,
           unit="N m", default=[0.0, 0.0, 0.0], magnitude=MAX_DISTURBANCE),
), "What acts on the spacecraft besides its actuators (absent or ``null``: nothing).")


def parse_spacecraft(node: Node) -> tuple[Spacecraft, dict[str, Sensor]]:
    """The ``spacecraft`` section (:data:`SPACECRAFT`): inertia, wheels, magnetorquers, torquers
    and sensors.

    Parameters
    ----------
    node : Node
        The ``spacecraft`` mapping.

    Returns
    -------
    spacecraft : Spacecraft
        The spacecraft model.
    sensors : dict of str to Sensor
        The named sensors (``spacecraft.sensors``), in the order written.

    Raises
    ------
    ScenarioError
        At the offending key's YAML path.
    """
    node.mapping()
    inertia = SPACECRAFT["inertia"].value(node)
    wheels_node = SPACECRAFT["wheels"].node(node)
    wheels = None
    if not wheels_node.is_null():
        values = WHEELS.read(wheels_node)
        wheels = _model_part(wheels_node, ReactionWheels, **values)
    magnetorquers = torquers = None
    mtq = SPACECRAFT["magnetorquers"].node(node)
    if not mtq.is_null():
        magnetorquers = _model_part(mtq, Magnetorquers, **MAGNETORQUERS.read(mtq))
    trq = SPACECRAFT["torquers"].node(node)
    if not trq.is_null():
        torquers = _model_part(trq, Torquers, **TORQUERS.read(trq))
    sensors = SPACECRAFT["sensors"].value(node)
    spacecraft = _model_part(node, Spacecraft, inertia=inertia, wheels=wheels, magnetorquers=magnetorquers,
                             torquers=torquers)
    node.finish()
    return spacecraft, sensors


def parse_orbit(node: Node, epoch: datetime.datetime | None = None) -> Orbit | None:
    """The ``orbit`` section (:data:`ORBIT`): ``type`` (default ``circular``) and that kind's options,
    kilometres and degrees converted to SI.

    A kind that needs a calendar epoch (``tle``) takes the scenario's; a TLE whose own epoch lies
    more than :data:`~ocp.dynamics.orbits.TLE_EPOCH_WARN_DAYS` from it is used with a warning.

    Parameters
    ----------
    node : Node
        The ``orbit`` mapping, or null for none.
    epoch : datetime.datetime or None, optional
        The scenario's epoch (top-level ``epoch``), UTC.

    Returns
    -------
    Orbit or None
        The orbit.

    Raises
    ------
    ScenarioError
        At the offending key's YAML path (``epoch`` for a missing epoch or one too far from a TLE's).
    """
    if node.is_null():
        return None
    node.mapping()
    kind = ORBITS[ORBIT["type"].value(node)]
    values = read_mapping(node, option_keys(kind.Options))
    try:
        options = kind.Options(**values)
    except InvalidOption as error:  # a relation between options (Options.__post_init__)
        raise ScenarioError(f"{node.path}.{error.option}", error.message) from None
    if kind.needs_epoch and epoch is None:
        raise ScenarioError("epoch", f"orbit type {kind.name!r} is dated: it needs the scenario's epoch (t = 0), a UTC "
                                     "date-time like 2025-01-01T06:00:00Z; none is given")
    try:
        orbit = kind.from_options(options, epoch)
    except ModelError as error:
        if error.field == "epoch":
            raise ScenarioError("epoch", f"{error.message} (orbit type {kind.name!r})") from None
        where = (f"{node.path}.{error.field}" if node.path else error.field) if error.field else node.path
        raise ScenarioError(where, error.message) from None
    offset = getattr(orbit, "epoch_offset_days", None)
    if offset is not None and abs(offset) > TLE_EPOCH_WARN_DAYS:
        notice(f"warning: {node.path}: the TLE's epoch lies {abs(offset):.1f} days from the scenario's epoch "
               f"(more than {TLE_EPOCH_WARN_DAYS:g}); SGP4's error grows by kilometres a day")
    return orbit


def parse_magnetic_field(node: Node, orbit: Orbit | None,
                         epoch: datetime.datetime | None = None) -> MagneticField | None:
    """``environment.magnetic_field``: a registered model's name, ``none``, or a mapping of ``model``
    and the model's options (read by the keys of its ``Options``).

    A model whose options have an ``epoch`` (IGRF) takes the scenario's epoch when its own is not
    given; given both, they must be the same instant.

    Parameters
    ----------
    node : Node
        The ``magnetic_field`` value.
    orbit : Orbit or None
        The scenario's orbit.
    epoch : datetime.datetime or None, optional
        The scenario's epoch (top-level ``epoch``), UTC.

    Returns
    -------
    MagneticField or None
        The field (``None`` for null or ``none``).

    Raises
    ------
    ScenarioError
        At the offending key's YAML path.
    """
    if node.is_null():
        return None
    given_epoch = False
    if isinstance(node.value, str):
        model = MAGNETIC_FIELDS[node.string((*MAGNETIC_FIELDS, "none"))]
        options = model.Options()
    else:
        node.mapping()
        model = MAGNETIC_FIELDS[MAGNETIC_FIELD["model"].value(node)]
        given_epoch = "epoch" in node
        values = read_mapping(node, option_keys(model.Options))
        try:
            options = model.Options(**values)
        except InvalidOption as error:  # a relation between options (Options.__post_init__)
            raise ScenarioError(f"{node.path}.{error.option}", error.message) from None
    inherited = epoch is not None and "epoch" in {spec.name for spec in dataclasses.fields(options)}
    if epoch is not None and inherited and given_epoch:
        try:
            own: datetime.datetime | None = parse_utc(getattr(options, "epoch"))  # noqa: B009 - any model's
        except ModelError:  # the model reports its own epoch's error below
            own = None
        if own is not None and own != epoch:
            raise ScenarioError(f"{node.path}.epoch", f"{own.isoformat()} differs from the scenario's epoch "
                                f"(epoch: {epoch.isoformat()}Z); give one of them, or the same instant")
    elif epoch is not None and inherited:
        options = dataclasses.replace(options, epoch=epoch.isoformat())  # type: ignore[call-arg]  # a model's Options
    try:
        return model.from_options(options=options, orbit=orbit)
    except ModelError as error:
        if inherited and not given_epoch and error.field == "epoch":
            raise ScenarioError("epoch", f"{error.message} ({node.path} takes the scenario's epoch)") from None
        where = (f"{node.path}.{error.field}" if node.path else error.field) if error.field else node.path
        raise ScenarioError(where, error.message) from None


def parse_environment(orbit_node: Node, node: Node, epoch: datetime.datetime | None = None) -> Environment:
    """The ``orbit`` and ``environment`` sections (``*_km`` and ``*_deg`` converted to SI).

    Parameters
    ----------
    orbit_node : Node
        The ``orbit`` mapping (:data:`ORBIT`), or null for none.
    node : Node
        The ``environment`` mapping (:data:`ENVIRONMENT`), or null for the defaults.
    epoch : datetime.datetime or None, optional
        The scenario's epoch, UTC, for a field model that has one (:func:`parse_magnetic_field`).

    Returns
    -------
    Environment
        The environment model (a field whose extent follows the closed-loop window, such as an
        IGRF table without ``span_s``, spans a provisional second until the loader fits it).

    Raises
    ------
    ScenarioError
        At the offending key's YAML path.
    """
    orbit = parse_orbit(orbit_node, epoch)
    node = node if not node.is_null() else Node({}, node.path)
    node.mapping()
    magnetic_field = parse_magnetic_field(ENVIRONMENT["magnetic_field"].value(node), orbit, epoch)
    environment = _model_part(
        node, Environment, orbit=orbit, gravity_gradient=ENVIRONMENT["gravity_gradient"].value(node),
        magnetic_field=magnetic_field, disturbance_torque=ENVIRONMENT["disturbance_torque"].value(node),
    )
    node.finish()
    return environment
