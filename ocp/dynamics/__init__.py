"""The spacecraft and its environment as equations: rigid body, actuators, orbit, fields, the model.

What lives here: the actuator kinds, with the :class:`~ocp.dynamics.actuator_kinds.Actuator` base
class a new kind extends and registers with :func:`~ocp.dynamics.actuator_kinds.actuator_kind`
(:mod:`~ocp.dynamics.actuator_kinds`), the spacecraft that holds them
(:mod:`~ocp.dynamics.spacecraft`), what a command becomes once applied
(:mod:`~ocp.dynamics.actuators`), the orbits (the :class:`~ocp.dynamics.orbits.Orbit` contract,
circular, Keplerian with J2 drift, SGP4 TLE, and the ``ORBITS`` registry, :mod:`~ocp.dynamics.orbits`),
gravity gradient and the magnetic field models with
the :class:`~ocp.dynamics.environment.MagneticField` protocol and their registry
(:mod:`~ocp.dynamics.environment`, :mod:`~ocp.dynamics.igrf`), the epoch (UTC) and the Sun's and
the Moon's geocentric positions in the GCRF from JPL DE421 (:mod:`~ocp.dynamics.ephemeris`), the assembled symbolic model
``ẋ = f(x, u, t, p)`` (:mod:`~ocp.dynamics.model`), the vector layouts shared with the laws and the
generated C (:mod:`~ocp.dynamics.layout`), the RK4 step (:mod:`~ocp.dynamics.integration`), the
closed-form spinning attitude (:mod:`~ocp.dynamics.spin_closed_form`) and the truth model the closed
loop integrates beside the design model (:mod:`~ocp.dynamics.truth`).

May import: NumPy, CasADi, ppigrf, pyerfa, sgp4, jplephem with de421 and the top-level modules of :mod:`ocp` (``quat``,
``quat_casadi``, ``cache``, ``fast_call``, ``errors``); never the other subpackages of ``ocp``.
"""
from ocp.dynamics.actuator_kinds import (
    ACTUATOR_KINDS,
    Actuator,
    Magnetorquers,
    ReactionWheels,
    Torquers,
    actuator_kind,
)
from ocp.dynamics.actuators import ActuatorModel, Command, Measurement
from ocp.dynamics.environment import (
    MAGNETIC_FIELDS,
    Environment,
    FieldModel,
    MagneticField,
    TiltedDipole,
    gravity_gradient_torque,
)
from ocp.dynamics.ephemeris import (
    EPHEMERIS_RANGE,
    check_epoch,
    moon_position,
    parse_utc,
    sun_position,
    tdb_julian_date,
)
from ocp.dynamics.igrf import IGRFField
from ocp.dynamics.integration import rk4_step
from ocp.dynamics.model import AttitudeModel
from ocp.dynamics.orbits import (
    ORBITS,
    CircularOrbit,
    KeplerianOrbit,
    Orbit,
    OrbitKind,
    TLEOrbit,
)
from ocp.dynamics.spacecraft import Spacecraft
from ocp.dynamics.truth import PeriodicTorque, Truth, TruthPlant

__all__ = ["ACTUATOR_KINDS", "EPHEMERIS_RANGE", "MAGNETIC_FIELDS", "ORBITS", "Actuator", "ActuatorModel",
           "AttitudeModel", "CircularOrbit", "Command", "Environment", "FieldModel", "IGRFField", "KeplerianOrbit",
           "MagneticField", "Magnetorquers", "Measurement", "Orbit", "OrbitKind", "PeriodicTorque", "ReactionWheels",
           "Spacecraft", "TLEOrbit", "TiltedDipole", "Torquers", "Truth", "TruthPlant", "actuator_kind", "check_epoch",
           "gravity_gradient_torque", "moon_position", "parse_utc", "rk4_step", "sun_position", "tdb_julian_date"]


def __dir__() -> list[str]:
    """What ``dir()`` lists: the public names (``__all__``) and the module's dunder attributes."""
    return sorted({*__all__, *(name for name in globals() if name.startswith("__") and name.endswith("__"))})
