"""The model sections of a scenario YAML: ``spacecraft``, ``orbit`` and ``environment``.

Errors are :class:`~scenarios.schema.node.ScenarioError` at the YAML path; a model constructor's
:class:`~ocp.ModelError` is reported at the field it names. Kilometres and degrees become SI here.
"""
from __future__ import annotations

import datetime
from collections.abc import Callable
from typing import Any

import numpy as np

from ocp import (
    CircularOrbit,
    Environment,
    IGRFField,
    Magnetorquers,
    ModelError,
    ReactionWheels,
    Spacecraft,
    TiltedDipole,
    Torquers,
)
from scenarios.errors import ScenarioError
from scenarios.schema.node import Node


def _model_part(node: Node, build: Callable[..., Any], **kwargs: Any) -> Any:
    """Call a model constructor, turning its ModelError into a ScenarioError at ``node.path``."""
    try:
        return build(**kwargs)
    except ModelError as error:
        raise ScenarioError(f"{node.path}.{error.field}" if node.path else error.field, error.message) from None


def _limits(node: Node, key: str) -> Any:
    child = node.get(key, None)
    return None if child.is_null() else child.vector(allow_scalar=True)


def parse_spacecraft(node: Node) -> Spacecraft:
    """The ``spacecraft`` section: inertia, wheels, magnetorquers and torquers.

    Parameters
    ----------
    node : Node
        The ``spacecraft`` mapping: ``inertia`` (3 principal moments or a 3x3 matrix [kg m²],
        body frame), ``wheels`` (``axes`` as rows in body axes, ``max_torque`` [N m],
        ``max_momentum`` [N m s], ``spin_inertia`` [kg m²], ``failed`` indices),
        ``magnetorquers`` (``max_dipole`` [A m²], ``saturation``) and ``torquers``
        (``max_torque`` [N m]).

    Returns
    -------
    Spacecraft
        The spacecraft model.

    Raises
    ------
    ScenarioError
        At the offending key's YAML path.
    """
    node.mapping()
    inertia_node = node.get("inertia", required=True)
    inertia = inertia_node.value
    if isinstance(inertia, list) and inertia and all(isinstance(row, list) for row in inertia):
        inertia = np.array([Node(row, f"{inertia_node.path}[{i}]").vector(3) for i, row in enumerate(inertia)])
    else:
        inertia = inertia_node.vector(3)
    wheels_node = node.get("wheels", {})
    wheels = None
    if not wheels_node.is_null():
        wheels_node.mapping()
        axes_node = wheels_node.get("axes", None)
        axes = np.eye(3) if axes_node.is_null() else np.array([row.vector(3) for row in axes_node.items()]).T
        failed = [item.integer() for item in wheels_node.get("failed", []).items()]
        wheels = _model_part(
            wheels_node, ReactionWheels, axes=axes, max_torque=_limits(wheels_node, "max_torque"),
            max_momentum=_limits(wheels_node, "max_momentum"), spin_inertia=_limits(wheels_node, "spin_inertia"),
            failed=tuple(failed),
        )
        wheels_node.finish()
    magnetorquers = torquers = None
    mtq = node.get("magnetorquers", None)
    if not mtq.is_null():
        magnetorquers = _model_part(mtq.mapping(), Magnetorquers, max_dipole=_limits(mtq, "max_dipole"),
                                    saturation=mtq.get("saturation", "per_axis").string(("per_axis", "scale")))
        mtq.finish()
    trq = node.get("torquers", None)
    if not trq.is_null():
        torquers = _model_part(trq.mapping(), Torquers, max_torque=_limits(trq, "max_torque"))
        trq.finish()
    spacecraft = _model_part(node, Spacecraft, inertia=inertia, wheels=wheels, magnetorquers=magnetorquers,
                             torquers=torquers)
    node.finish()
    return spacecraft


def parse_environment(orbit_node: Node, node: Node) -> Environment:
    """The ``orbit`` and ``environment`` sections (``*_km`` and ``*_deg`` converted to SI).

    Parameters
    ----------
    orbit_node : Node
        The ``orbit`` mapping (``altitude_km``, ``inclination_deg``, ``raan_deg``,
        ``arg_latitude_deg``), or null for none.
    node : Node
        The ``environment`` mapping (``gravity_gradient``, ``magnetic_field``,
        ``disturbance_torque`` [N m, body frame]), or null for the defaults.

    Returns
    -------
    Environment
        The environment model (an IGRF table spans a provisional second until the loader fits it
        to the closed-loop window).

    Raises
    ------
    ScenarioError
        At the offending key's YAML path.
    """
    orbit = None
    if not orbit_node.is_null():
        orbit_node.mapping()
        orbit = _model_part(
            orbit_node, CircularOrbit,
            altitude=orbit_node.get("altitude_km", required=True).number() * 1e3,
            inclination=np.deg2rad(orbit_node.get("inclination_deg", 0.0).number()),
            raan=np.deg2rad(orbit_node.get("raan_deg", 0.0).number()),
            arg_latitude=np.deg2rad(orbit_node.get("arg_latitude_deg", 0.0).number()),
        )
        orbit_node.finish()
    node = node if not node.is_null() else Node({}, node.path)
    node.mapping()
    field_node = node.get("magnetic_field", None)
    magnetic_field: TiltedDipole | IGRFField | None = None
    if not field_node.is_null():
        if isinstance(field_node.value, str):
            field_node.string(("tilted_dipole", "none"))
            magnetic_field = TiltedDipole()
        else:
            field_node.mapping()
            model = field_node.get("model", "tilted_dipole").string(("tilted_dipole", "igrf"))
            magnetic_field = (_igrf_field(field_node, orbit) if model == "igrf"
                              else _tilted_dipole(field_node))
            field_node.finish()
    environment = _model_part(
        node, Environment, orbit=orbit,
        gravity_gradient=node.get("gravity_gradient", False).boolean(),
        magnetic_field=magnetic_field,
        disturbance_torque=node.get("disturbance_torque", [0.0, 0.0, 0.0]).vector(3),
    )
    node.finish()
    return environment


def _tilted_dipole(node: Node) -> TiltedDipole:
    defaults = TiltedDipole()
    return TiltedDipole(
        strength=node.get("strength", defaults.strength).number(positive=True),
        tilt=np.deg2rad(node.get("tilt_deg", np.rad2deg(defaults.tilt)).number()),
        pole_longitude=np.deg2rad(node.get("pole_longitude_deg", np.rad2deg(defaults.pole_longitude)).number()),
        greenwich_angle=np.deg2rad(node.get("greenwich_angle_deg", 0.0).number()),
    )


def _igrf_field(node: Node, orbit: CircularOrbit | None) -> IGRFField:
    """``{model: igrf, epoch, step_s, span_s, greenwich_angle_deg}``; without ``span_s`` the table
    spans a provisional second, fitted to the closed-loop window by :func:`_fit_field_span`."""
    if orbit is None:
        raise ScenarioError(node.path, "the IGRF field is tabulated along the orbit; give `orbit:`")
    epoch_node = node.get("epoch", "2025-01-01")
    epoch = epoch_node.value
    if not isinstance(epoch, (str, datetime.date)):
        raise epoch_node.error(f"expected a date like 2025-01-01, got {str(epoch)[:40]!r}")
    greenwich = node.get("greenwich_angle_deg", None).optional_number()
    return _model_part(
        node, IGRFField, orbit=orbit, epoch=str(epoch),
        span=node.get("span_s", None).optional_number(positive=True) or 1.0,
        step=node.get("step_s", 30.0).number(positive=True, maximum=120.0),  # cubic spline error ~3e-4 at 120 s
        greenwich_angle=None if greenwich is None else float(np.deg2rad(greenwich)),
    )
