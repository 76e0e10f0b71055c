"""The ``truth`` section of a scenario: the simulated plant's own values, beside the design model.

The keys are declared here (:data:`TRUTH` and its subsections) and read through them;
:func:`parse_truth` builds the :class:`~ocp.dynamics.truth.TruthPlant` on the scenario's design
model. Only the closed loop integrates the truth: planners, the requirements' scoring of the
references and the controllers keep the design values (``spacecraft``, ``environment``). Degrees
and revolutions per minute become SI here; every error is a :class:`~scenarios.errors.ScenarioError`
at the ``truth.`` path.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ocp.dynamics.model import AttitudeModel
from ocp.dynamics.truth import MAX_MISALIGNMENT_DEG, PeriodicTorque, Truth, TruthPlant
from ocp.errors import ModelError, excerpt
from scenarios.errors import ScenarioError
from scenarios.schema.keys import Section, custom, integer, mapping, vector
from scenarios.schema.model import SPACECRAFT
from scenarios.schema.node import Node

__all__ = ["TRUTH", "TRUTH_DISTURBANCE", "TRUTH_FRICTION", "TRUTH_MAGNETORQUERS", "TRUTH_PERIODIC",
           "TRUTH_SPACECRAFT", "TRUTH_WHEELS", "parse_truth"]

RAD_S_PER_RPM = 2.0 * math.pi / 60.0
"""rad/s in one revolution per minute."""


def _per_wheel(positive: bool = False, non_negative: bool = False) -> Callable[[Node], Any]:
    """Reader of a number or a list of numbers (one per wheel), or null."""
    def read(node: Node) -> Any:
        if node.is_null():
            return None
        value = node.vector(allow_scalar=True)
        if positive and np.any(~(value > 0)):
            raise node.error(f"expected numbers > 0, got {excerpt(node.value)}")
        if non_negative and np.any(value < 0):
            raise node.error(f"expected numbers >= 0 (a standard deviation or a friction), got {excerpt(node.value)}")
        return value
    return read


def _misalignment(node: Node) -> np.ndarray | None:
    """Per wheel a rotation vector [deg], each at most :data:`MAX_MISALIGNMENT_DEG`; returned in rad."""
    if node.is_null():
        return None
    rows = []
    for item in node.items():
        row = item.vector(3)
        angle = float(np.linalg.norm(row))
        if angle > MAX_MISALIGNMENT_DEG:
            raise item.error(f"a misalignment of {angle:.4g} deg exceeds {MAX_MISALIGNMENT_DEG:g} deg; expected a "
                             "small rotation (give a different axis in spacecraft.wheels.axes)")
        rows.append(row)
    if not rows:
        raise node.error("expected one rotation vector (3 numbers, deg) per wheel")
    return np.radians(np.array(rows))


def _scale_error(node: Node) -> np.ndarray | None:
    if node.is_null():
        return None
    value = node.vector(3, allow_scalar=True) if isinstance(node.value, list) else node.vector(allow_scalar=True)
    if np.any(~(value > -1.0)):
        raise node.error(f"expected scale errors > -1 (the dipole keeps its sign), got {excerpt(node.value)}")
    return np.broadcast_to(value, (3,)).copy()


def _inertia(node: Node) -> np.ndarray | None:
    if node.is_null():
        return None
    reader = SPACECRAFT["inertia"].read
    assert reader is not None
    return reader(node)


TRUTH_SPACECRAFT = Section((
    custom("inertia", "The true inertia about the centre of mass: principal moments (3 numbers) or the full 3x3 "
           "tensor with its products of inertia, body frame (positive definite, the moments meeting the triangle "
           "inequality); ``null``: the design's ``spacecraft.inertia``.", "list of 3 numbers, 3x3 matrix or null",
           _inertia, unit="kg m²", default=None, bounds=SPACECRAFT["inertia"].bounds),
), "The true rigid body.")

TRUTH_FRICTION = Section((
    custom("coulomb", "Coulomb friction torque of each wheel's bearing, ``c sign(Ω)`` with ``Ω`` the wheel's "
           "speed relative to the body (needs ``spacecraft.wheels.spin_inertia``).",
           "number, list of numbers (one per wheel) or null", _per_wheel(non_negative=True), unit="N m",
           default=None, bounds=">= 0"),
    custom("viscous", "Viscous friction coefficient of each wheel's bearing, torque ``b Ω`` (needs "
           "``spacecraft.wheels.spin_inertia``).", "number, list of numbers (one per wheel) or null",
           _per_wheel(non_negative=True), unit="N m s", default=None, bounds=">= 0"),
), "Bearing friction, internal to the spacecraft: it slows each wheel and turns the body the other way.")

TRUTH_WHEELS = Section((
    custom("misalignment_deg", "Per wheel, the small rotation (a rotation vector, body frame) from its design axis "
           "to its true axis; the controllers allocate with the design axes.",
           "list of lists of 3 numbers (one per wheel) or null", _misalignment, unit="deg", default=None,
           bounds=f"norm <= {MAX_MISALIGNMENT_DEG:g}"),
    custom("max_torque", "The wheels' physical torque limit, applied in the loop (the controllers and planners keep "
           "``spacecraft.wheels.max_torque``); ``null``: the design's.",
           "number, list of numbers (one per wheel) or null", _per_wheel(positive=True), unit="N m", default=None,
           bounds="> 0"),
    custom("max_momentum", "The wheels' physical momentum limit, applied in the loop; ``null``: the design's.",
           "number, list of numbers (one per wheel) or null", _per_wheel(positive=True), unit="N m s", default=None,
           bounds="> 0"),
    mapping("friction", "Bearing friction.", TRUTH_FRICTION, default={}, null="defaults"),
    custom("max_speed_rpm", "Speed limit of each wheel relative to the body: the motor torque is cut while the wheel "
           "is at it and the motor would drive it further (needs ``spacecraft.wheels.spin_inertia``); "
           "``null``: none.", "number, list of numbers (one per wheel) or null", _per_wheel(positive=True),
           unit="rpm", default=None, bounds="> 0"),
    custom("torque_noise", "Standard deviation of each wheel's motor torque noise, white per sample, drawn from "
           "a stream of its own (seeded by ``[simulation.sensor_noise.seed, 2]``).",
           "number, list of numbers (one per wheel) or null", _per_wheel(non_negative=True), unit="N m",
           default=None, bounds=">= 0"),
), "The true reaction wheels.")

TRUTH_MAGNETORQUERS = Section((
    custom("scale_error", "Dipole scale error ``e`` per body axis (one number for all three): the delivered dipole "
           "is ``(1 + e)`` times the saturated command.", "number, list of 3 numbers or null", _scale_error,
           default=None, bounds="> -1"),
), "The true magnetorquers.")

TRUTH_PERIODIC = Section((
    integer("harmonic", "1: at the orbit rate ``n``; 2: at twice it.", minimum=1, maximum=2),
    vector("amplitude", "Amplitude ``A`` per body axis of ``A sin(k n t + φ)``.", 3, unit="N m"),
    vector("phase_deg", "Phase ``φ`` per body axis.", 3, unit="deg", default=[0.0, 0.0, 0.0]),
), "A disturbance torque periodic at a harmonic of the orbit rate, body frame (needs ``orbit``).")

TRUTH_DISTURBANCE = Section((
    vector("constant", "The plant's constant disturbance torque, body frame, in place of "
           "``environment.disturbance_torque`` (which the planners see); ``null``: that one.", 3, unit="N m",
           default=None, nullable=True),
    custom("orbit_periodic", "Disturbance torques periodic at the orbit rate or twice it, added to the constant one.",
           "list of mappings", None, default=[], section=TRUTH_PERIODIC, entries=True),
), "Disturbance torques on the plant.")

TRUTH = Section((
    mapping("spacecraft", "The true rigid body.", TRUTH_SPACECRAFT, default={}, null="defaults"),
    mapping("wheels", "The true reaction wheels (needs ``spacecraft.wheels``).", TRUTH_WHEELS, default={},
            null="defaults"),
    mapping("magnetorquers", "The true magnetorquers (needs ``spacecraft.magnetorquers``).", TRUTH_MAGNETORQUERS,
            default={}, null="defaults"),
    vector("residual_dipole", "Residual magnetic dipole of the spacecraft, body frame: torque "
           "``m_res × B`` (needs ``environment.magnetic_field``); ``null``: none.", 3, unit="A m²", default=None,
           nullable=True),
    mapping("disturbance", "Disturbance torques.", TRUTH_DISTURBANCE, default={}, null="defaults"),
), "The simulated plant where it differs from the design model (absent or ``null``: the design model is the plant).")


def parse_truth(node: Node, design: AttitudeModel) -> TruthPlant | None:
    """The ``truth`` section (:data:`TRUTH`) as a plant built on the design model.

    Parameters
    ----------
    node : Node
        The ``truth`` mapping, or null for none.
    design : AttitudeModel
        The scenario's design model (its spacecraft and environment).

    Returns
    -------
    TruthPlant or None
        The plant; ``None`` when the section is absent or null.

    Raises
    ------
    ScenarioError
        At the offending key's YAML path (``truth.…``).
    """
    if node.is_null():
        return None
    values = TRUTH.read(node)
    wheels, friction = values["wheels"], values["wheels"]["friction"]
    disturbance = values["disturbance"]
    periodic = []
    for item in disturbance["orbit_periodic"].items():
        entry = TRUTH_PERIODIC.read(item)
        periodic.append(PeriodicTorque(entry["harmonic"], entry["amplitude"], np.radians(entry["phase_deg"])))
    max_speed = wheels["max_speed_rpm"]
    try:
        truth = Truth(
            inertia=values["spacecraft"]["inertia"], wheel_misalignment=wheels["misalignment_deg"],
            wheel_max_torque=wheels["max_torque"], wheel_max_momentum=wheels["max_momentum"],
            wheel_coulomb=friction["coulomb"], wheel_viscous=friction["viscous"],
            wheel_max_speed=None if max_speed is None else max_speed * RAD_S_PER_RPM,
            wheel_torque_noise=wheels["torque_noise"], dipole_scale_error=values["magnetorquers"]["scale_error"],
            residual_dipole=values["residual_dipole"], constant_disturbance=disturbance["constant"],
            periodic_disturbance=tuple(periodic))
        return TruthPlant(design, truth)
    except ModelError as error:
        raise ScenarioError(f"{node.path}.{error.field}", error.message) from None
