"""Dispersions that provably arrive (issue 28, part 4).

A Monte Carlo study that disperses a scenario path must change what the path names in the loaded
scenario, and nothing else: the spacecraft (and the plant the simulator integrates), the orbit, the
environment, the manoeuvre, the planners' bounds, one planner's or controller's options, the
simulation settings or the requirements. Basilisk's users were bitten by dispersions that silently
did not reach the simulation (its issue 1164); here every dispersible path has a case.

How it works: each entry of :data:`ARRIVALS` (scenario keys, written by hand) and of the generated
planner, controller and field-model option entries names a scenario path, a base scenario, a new
value and the parts of the loaded :class:`~scenarios.schema.loader.Scenario` that the value must
change (:data:`PARTS`). The value is set by a one-case study, a Monte Carlo dispersion
(``uniform: [v, v]`` draws exactly ``v``; a matrix is scaled) or a one-value grid for integers, so it
travels the study's own path machinery; the case's scenario is loaded and each part compared with
the base's. :func:`test_every_dispersible_key_has_an_arrival_case` makes the table complete: every
numeric key of the generated schema reference (scenario keys, planner and controller options,
magnetic field options) must have an entry, or a reason in :data:`NOT_DISPERSIBLE`.

Adding a key (for example the truth model's ``truth.*`` keys): give its reference key (as
``slewbench schema`` lists it) an :class:`Arrival` in :data:`ARRIVALS` with the parts it must change
(a truth key changes ``plant`` and nothing else: not ``spacecraft``, which is the design model the
planners and controllers see), and, if the loaded scenario gains a part of its own, add a function
for it to :data:`PARTS` (every other entry then checks that it does *not* change that part).
"""
from __future__ import annotations

import copy
import dataclasses
import math
import typing
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import pytest

from controllers import CONTROLLERS
from ocp.options import numeric_leaves, option_fields
from planners import PLANNERS
from scenarios.schema.loader import Scenario, parse_scenario
from scenarios.schema.read import read_yaml
from scenarios.schema.reference import reference_parts
from scenarios.study.paths import get_path, parse_path
from scenarios.study.spec import parse_study

# --- the parts of a loaded scenario ---------------------------------------------------------------


def plain(value: Any) -> Any:
    """A value as nested tuples of plain numbers and text, for comparison (dataclasses by their
    fields, arrays by their numbers, other objects by their public attributes)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return (type(value).__name__,) + tuple((f.name, plain(getattr(value, f.name)))
                                               for f in dataclasses.fields(value))
    if isinstance(value, np.ndarray):
        return ("array", value.shape, tuple(value.ravel().tolist()))
    if isinstance(value, dict):
        return tuple(sorted((str(k), plain(v)) for k, v in value.items()))
    if isinstance(value, (list, tuple)):
        return tuple(plain(v) for v in value)
    if value is None or isinstance(value, (bool, int, float, str, np.floating, np.integer)):
        return value.item() if isinstance(value, (np.floating, np.integer)) else value
    if callable(value) and not hasattr(value, "__dict__"):
        return type(value).__name__
    public = {k: v for k, v in vars(value).items() if not k.startswith("_")} if hasattr(value, "__dict__") else {}
    return (type(value).__name__, plain(public))


def _environment(scenario: Scenario) -> Any:
    environment = scenario.problem.environment
    return plain((environment.gravity_gradient, environment.magnetic_field, environment.disturbance_torque))


def _maneuver(scenario: Scenario) -> Any:
    p = scenario.problem
    return plain((p.q0, p.omega0, p.qf, p.omegaf, p.duration, p.wheel_momentum0))


def _bounds(scenario: Scenario) -> Any:
    p = scenario.problem
    return plain((p.max_rate, p.actuator_margin, p.pointing))


PARTS: dict[str, Callable[[Scenario], Any]] = {
    "spacecraft": lambda s: plain(s.problem.spacecraft),  # the design model planners and controllers see
    "plant": lambda s: s.problem.model.fingerprint,  # every number of the model the simulator integrates
    "orbit": lambda s: plain(s.problem.environment.orbit),
    "environment": _environment,
    "maneuver": _maneuver,
    "planning bounds": _bounds,  # what the planners must honour: rate bound, actuator margin, pointing
    "simulation": lambda s: plain(s.simulation),
    "requirements": lambda s: plain(s.requirements),
    "truth": lambda s: None if s.truth is None else s.truth.fingerprint,  # the plant alone (truth:)
}
"""The parts a value may change: name -> the part of a loaded scenario, comparable. Each planner row
(``planner:<label>``) and controller (``controller:<label>``) is a part of its own, its options."""


def parts(scenario: Scenario) -> dict[str, Any]:
    found = {name: part(scenario) for name, part in PARTS.items()}
    found.update({f"planner:{p.label}": plain(p.options) for p in scenario.planners})
    found.update({f"controller:{c.label}": plain(c.options) for c in scenario.controllers})
    return found


# --- base scenarios --------------------------------------------------------------------------------

FULL = {
    "name": "arrival",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0],
                   "wheels": {"max_torque": 0.05, "max_momentum": 0.5, "spin_inertia": 1.0e-4},
                   "magnetorquers": {"max_dipole": 0.2}, "torquers": {"max_torque": 0.01},
                   "sensors": {"tracker": {"boresight": [0, 0, 1]}}},
    "orbit": {"altitude_km": 500.0, "inclination_deg": 51.6},
    "environment": {"magnetic_field": {"model": "tilted_dipole"}, "disturbance_torque": [1e-6, 0, 0]},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}, "max_rate": 0.2},
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "eigenaxis", "label": "fast", "options": {"profile": "min_time", "torque_fraction": 0.8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0, "fine_settling_tolerance_deg": 0.1},
    "requirements": {"pointing": {"sun": {"sensor": "tracker", "keep_out": {"inertial": [0, 1, 0]},
                                          "angle_deg": 10.0, "window": [0.0, 30.0]}},
                     "actuators": {"margin": 0.1}, "rate": {"max": 0.3},
                     "final": {"after_s": 2.0, "error_deg": 1.0, "rate": 0.01}},
}
"""A scenario with every section a scenario key lives in."""

KEEP_IN = copy.deepcopy(FULL)
KEEP_IN["requirements"]["pointing"] = {"antenna": {"sensor": "tracker", "keep_in": {"inertial": [0, 0, 1]},
                                                   "angle_deg": 80.0}}
KEEP_IN["requirements"].pop("rate")
KEEP_IN["maneuver"]["max_rate"] = None
IGRF = copy.deepcopy(FULL)
IGRF["epoch"] = "2025-03-20T12:00:00Z"
IGRF["environment"]["magnetic_field"] = {"model": "igrf", "step_s": 10.0}
IGRF["requirements"] = None

KEPLER = copy.deepcopy(FULL)
KEPLER["orbit"] = {"type": "keplerian", "semi_major_axis_km": 7000.0, "eccentricity": 0.01, "inclination_deg": 60.0,
                   "raan_deg": 20.0, "arg_perigee_deg": 30.0, "mean_anomaly_deg": 40.0, "j2": True}
KEPLER_BY_ALTITUDE = copy.deepcopy(KEPLER)
KEPLER_BY_ALTITUDE["orbit"] = {"type": "keplerian", "altitude_km": 600.0, "eccentricity": 0.01,
                               "inclination_deg": 60.0, "true_anomaly_deg": 40.0}
TLE = copy.deepcopy(FULL)
TLE["epoch"] = "2019-12-10T00:00:00Z"
TLE["orbit"] = {"type": "tle", "line1": "1 25544U 98067A   19343.69339541  .00001764  00000-0  38792-4 0  9991",
                "line2": "2 25544  51.6439 211.2001 0007417  17.6667  85.6398 15.50103472202482"}
TARGETS = copy.deepcopy(FULL)  # attitudes in mission terms: every form of maneuver.initial.q and .final.q
TARGETS["epoch"] = "2027-06-21T10:30:00Z"  # the orbit of cubesat_12u_ground_target.yaml: Toulouse and Paris in view
TARGETS["orbit"] = {"altitude_km": 500, "inclination_deg": 97.4, "raan_deg": 78.5, "arg_latitude_deg": 38.13}
TARGETS["spacecraft"]["sensors"]["panel"] = {"boresight": [0, 1, 0]}
TARGETS["requirements"] = None
TARGETS["maneuver"]["max_rate"] = None
TARGET_FORMS = {
    "quaternion": {"quaternion": [1, 0, 0, 0], "frame": "lvlh", "at_time_s": 1.0},
    "axis_angle": {"axis_angle": {"axis": [0, 0, 1], "angle_deg": 20.0}},
    "euler": {"euler": {"angles_deg": [10.0, 5.0, 0.0], "sequence": "321"}},
    "point": {"point": {"boresight": [0, 0, 1], "at": {"inertial": [1, 0, 0]},
                        "secondary": {"axis": [0, 1, 0], "toward": {"inertial": [0, 0, 1]}}}},
    "point.at.lvlh": {"point": {"sensor": "tracker", "at": {"lvlh": [0, 0, 1]},
                                "secondary": {"sensor": "panel", "toward": {"lvlh": [1, 0, 0]}}}},
    "point.at.rtn": {"point": {"sensor": "tracker", "at": {"rtn": [0, 0, 1]},
                               "secondary": {"sensor": "panel", "toward": {"rtn": [1, 0, 0]}}}},
    "point.at.ground": {"point": {"sensor": "tracker", "at": {"ground": {"lat_deg": 43.6, "lon_deg": 1.44, "alt_m": 150.0}},
                                  "secondary": {"sensor": "panel",
                                                "toward": {"ground": {"lat_deg": 48.85, "lon_deg": 2.35,
                                                                      "alt_m": 35.0}}}}},
}
"""One attitude of each form (:mod:`scenarios.schema.targets`), written as maneuver.initial.q and as
maneuver.final.q of a base of its own."""
SENSORS = copy.deepcopy(FULL)
SENSORS["simulation"]["sensors"] = {
    "gyro": {"arw_deg_per_sqrt_h": 0.01, "rrw_deg_per_h_per_sqrt_h": 0.1, "bias_deg_per_h": [1.0, -0.5, 0.3]},
    "star_tracker": {"noise_arcsec": [5, 5, 40], "rate_hz": 1.0, "outages_s": [[5, 6]], "boresight": [0, 0, 1]},
    "magnetometer": {"noise_T": 1e-8, "bias_T": [1e-7, 0, 0]}}
SENSORS["simulation"]["estimator"] = {"type": "mekf", "initial_attitude_sigma_deg": 0.1,
                                      "initial_bias_sigma_deg_per_h": 5.0}
SENSORS["epoch"] = "2025-03-20T12:00:00Z"  # the Sun's and the Moon's exclusions need it
SENSORS["simulation"]["sensors"]["star_tracker"]["exclusion_deg"] = {"sun": 30.0, "moon": 10.0, "earth_limb": 20.0}

TRUTH = copy.deepcopy(FULL)  # every truth key set, so that each can change (tests/test_truth_study.py has its own)
TRUTH["spacecraft"]["wheels"]["spin_inertia"] = 2e-4
TRUTH["truth"] = {
    "spacecraft": {"inertia": [2.0, 3.0, 4.0]},
    "wheels": {"misalignment_deg": [[0, 1, 0], [0, 0, 1], [1, 0, 0]], "max_torque": 0.04, "max_momentum": 0.4,
               "friction": {"coulomb": 1e-5, "viscous": 1e-6}, "max_speed_rpm": 3000.0, "torque_noise": 1e-5},
    "magnetorquers": {"scale_error": 0.05},
    "residual_dipole": [0.01, 0.0, 0.0],
    "disturbance": {"constant": [0.0, 1e-7, 0.0],
                    "orbit_periodic": [{"harmonic": 1, "amplitude": [1e-7, 0, 0], "phase_deg": [0, 0, 0]}]},
}

BASES: dict[str, dict[str, Any]] = {"truth": TRUTH, "full": FULL, "keep_in": KEEP_IN, "igrf": IGRF, "kepler": KEPLER,
                                    "kepler_altitude": KEPLER_BY_ALTITUDE, "tle": TLE, "sensors": SENSORS}
for _form, _attitude in TARGET_FORMS.items():
    for _end in ("initial", "final"):
        BASES[f"{_end}:{_form}"] = copy.deepcopy(TARGETS)
        BASES[f"{_end}:{_form}"]["maneuver"][_end]["q"] = copy.deepcopy(_attitude)


@dataclass(frozen=True)
class Arrival:
    """One dispersible key: the scenario path set, the base it is set in, the value and the parts it
    must change (and no other)."""

    path: str
    value: Any
    changes: frozenset[str]
    base: str = "full"


def arrival(path: str, value: Any, *changes: str, base: str = "full") -> Arrival:
    return Arrival(path, value, frozenset(changes), base)


MODEL = ("spacecraft", "plant")
ORBIT = ("orbit", "plant")
ENVIRONMENT = ("environment", "plant")
POINTING = ("requirements", "planning bounds")

ARRIVALS: dict[str, Arrival] = {
    "spacecraft.inertia": arrival("spacecraft.inertia", [2.2, 3.0, 4.1], *MODEL),
    "spacecraft.wheels.axes": arrival("spacecraft.wheels.axes", [[1, 0, 0], [0, 1, 0], [0, 0.1, 1]], *MODEL),
    "spacecraft.wheels.max_torque": arrival("spacecraft.wheels.max_torque", 0.06, *MODEL),
    "spacecraft.wheels.max_momentum": arrival("spacecraft.wheels.max_momentum", [0.5, 0.6, 0.5], *MODEL),
    "spacecraft.wheels.spin_inertia": arrival("spacecraft.wheels.spin_inertia", 2.0e-4, *MODEL),
    "spacecraft.wheels.failed": arrival("spacecraft.wheels.failed", [2], *MODEL),
    "spacecraft.magnetorquers.max_dipole": arrival("spacecraft.magnetorquers.max_dipole", 0.3, *MODEL),
    "spacecraft.torquers.max_torque": arrival("spacecraft.torquers.max_torque", [0.01, 0.02, 0.01], *MODEL),
    "spacecraft.sensors.boresight": arrival("spacecraft.sensors.tracker.boresight", [0, 0.1, 1], *POINTING),
    "orbit.circular.altitude_km": arrival("orbit.altitude_km", 550.0, *ORBIT),
    "orbit.circular.inclination_deg": arrival("orbit.inclination_deg", 97.4, *ORBIT),
    "orbit.circular.raan_deg": arrival("orbit.raan_deg", 30.0, *ORBIT),
    "orbit.circular.arg_latitude_deg": arrival("orbit.arg_latitude_deg", 45.0, *ORBIT),
    "environment.disturbance_torque": arrival("environment.disturbance_torque", [1e-6, 2e-6, 0], *ENVIRONMENT),
    "environment.magnetic_field.tilted_dipole.strength": arrival("environment.magnetic_field.strength", 7.0e15,
                                                                 *ENVIRONMENT),
    "environment.magnetic_field.tilted_dipole.tilt_deg": arrival("environment.magnetic_field.tilt_deg", 9.0,
                                                                 *ENVIRONMENT),
    "environment.magnetic_field.tilted_dipole.pole_longitude_deg": arrival(
        "environment.magnetic_field.pole_longitude_deg", 100.0, *ENVIRONMENT),
    "environment.magnetic_field.tilted_dipole.greenwich_angle_deg": arrival(
        "environment.magnetic_field.greenwich_angle_deg", 20.0, *ENVIRONMENT),
    "environment.magnetic_field.igrf.step_s": arrival("environment.magnetic_field.step_s", 5.0, *ENVIRONMENT,
                                                      base="igrf"),
    "environment.magnetic_field.igrf.span_s": arrival("environment.magnetic_field.span_s", 400.0, *ENVIRONMENT,
                                                      base="igrf"),
    "environment.magnetic_field.igrf.greenwich_angle_deg": arrival("environment.magnetic_field.greenwich_angle_deg",
                                                                   20.0, *ENVIRONMENT, base="igrf"),
    "maneuver.initial.q": arrival("maneuver.initial.q", [0.9998477, 0.0174524, 0, 0], "maneuver"),
    "maneuver.initial.omega": arrival("maneuver.initial.omega", [0.001, 0, 0], "maneuver"),
    "maneuver.initial.wheel_momentum": arrival("maneuver.initial.wheel_momentum", [0.01, 0, 0], "maneuver"),
    "maneuver.final.q": arrival("maneuver.final.q", [0.9063078, 0.4226183, 0, 0], "maneuver"),
    "maneuver.final.omega": arrival("maneuver.final.omega", [0, 0, 0.001], "maneuver"),
    "maneuver.duration": arrival("maneuver.duration", 32.0, "maneuver"),
    "maneuver.max_rate": arrival("maneuver.max_rate", 0.25, "planning bounds"),
    "simulation.sample_time": arrival("simulation.sample_time", 0.5, "simulation"),
    "simulation.duration": arrival("simulation.duration", 40.0, "simulation"),
    "simulation.initial_attitude_error_deg": arrival("simulation.initial_attitude_error_deg", [1.0, -0.5, 0.2],
                                                     "simulation"),
    "simulation.initial_rate_error": arrival("simulation.initial_rate_error", [1e-3, 0, -1e-3], "simulation"),
    "simulation.sensor_noise.attitude_deg": arrival("simulation.sensor_noise.attitude_deg", 0.01, "simulation"),
    "simulation.sensor_noise.rate": arrival("simulation.sensor_noise.rate", 1e-5, "simulation"),
    "simulation.sensor_noise.seed": arrival("simulation.sensor_noise.seed", 7, "simulation"),
    "simulation.sensor_noise.magnetic_field": arrival("simulation.sensor_noise.magnetic_field", 1e-8, "simulation"),
    "simulation.max_step": arrival("simulation.max_step", 0.04, "simulation"),
    "simulation.settling_tolerance_deg": arrival("simulation.settling_tolerance_deg", 0.4, "simulation"),
    "simulation.fine_settling_tolerance_deg": arrival("simulation.fine_settling_tolerance_deg", 0.05, "simulation"),
    "simulation.detumble_tolerance": arrival("simulation.detumble_tolerance", 0.02, "simulation"),
    "simulation.max_samples": arrival("simulation.max_samples", 50_000, "simulation"),
    "requirements.pointing.angle_deg": arrival("requirements.pointing.sun.angle_deg", 12.0, *POINTING),
    "requirements.pointing.window": arrival("requirements.pointing.sun.window", [1.0, 25.0], *POINTING),
    "requirements.pointing.keep_out.inertial": arrival("requirements.pointing.sun.keep_out.inertial", [0, 1, 0.1],
                                                       *POINTING),
    "requirements.pointing.keep_in.inertial": arrival("requirements.pointing.antenna.keep_in.inertial",
                                                      [0, 0.1, 1], *POINTING, base="keep_in"),
    "requirements.actuators.margin": arrival("requirements.actuators.margin", 0.2, *POINTING),
    "requirements.rate.max": arrival("requirements.rate.max", 0.35, "requirements"),  # maneuver.max_rate binds
    "requirements.final.after_s": arrival("requirements.final.after_s", 3.0, "requirements"),
    # the base sets no simulation.settling_tolerance_deg: settling_time_s's band is the requirement's
    "requirements.final.error_deg": arrival("requirements.final.error_deg", 0.8, "requirements", "simulation"),
    "requirements.final.rate": arrival("requirements.final.rate", 0.02, "requirements"),
    "orbit.keplerian.semi_major_axis_km": arrival("orbit.semi_major_axis_km", 7100.0, *ORBIT, base="kepler"),
    "orbit.keplerian.altitude_km": arrival("orbit.altitude_km", 650.0, *ORBIT, base="kepler_altitude"),
    "orbit.keplerian.eccentricity": arrival("orbit.eccentricity", 0.02, *ORBIT, base="kepler"),
    "orbit.keplerian.inclination_deg": arrival("orbit.inclination_deg", 70.0, *ORBIT, base="kepler"),
    "orbit.keplerian.raan_deg": arrival("orbit.raan_deg", 25.0, *ORBIT, base="kepler"),
    "orbit.keplerian.arg_perigee_deg": arrival("orbit.arg_perigee_deg", 35.0, *ORBIT, base="kepler"),
    "orbit.keplerian.mean_anomaly_deg": arrival("orbit.mean_anomaly_deg", 45.0, *ORBIT, base="kepler"),
    "orbit.keplerian.true_anomaly_deg": arrival("orbit.true_anomaly_deg", 45.0, *ORBIT, base="kepler_altitude"),
    "orbit.tle.span_s": arrival("orbit.span_s", 7200.0, *ORBIT, base="tle"),
    "orbit.tle.step_s": arrival("orbit.step_s", 5.0, *ORBIT, base="tle"),
    "simulation.sensors.gyro.arw_deg_per_sqrt_h": arrival("simulation.sensors.gyro.arw_deg_per_sqrt_h", 0.02,
                                                          "simulation", base="sensors"),
    "simulation.sensors.gyro.rrw_deg_per_h_per_sqrt_h": arrival(
        "simulation.sensors.gyro.rrw_deg_per_h_per_sqrt_h", 0.2, "simulation", base="sensors"),
    "simulation.sensors.gyro.bias_deg_per_h": arrival("simulation.sensors.gyro.bias_deg_per_h", [1.5, -0.5, 0.3],
                                                      "simulation", base="sensors"),
    "simulation.sensors.star_tracker.noise_arcsec": arrival("simulation.sensors.star_tracker.noise_arcsec",
                                                            [6.0, 5.0, 40.0], "simulation", base="sensors"),
    "simulation.sensors.star_tracker.rate_hz": arrival("simulation.sensors.star_tracker.rate_hz", 2.0, "simulation",
                                                       base="sensors"),
    "simulation.sensors.star_tracker.boresight": arrival("simulation.sensors.star_tracker.boresight", [0, 0.1, 1.0],
                                                         "simulation", base="sensors"),
    **{f"simulation.sensors.star_tracker.exclusion_deg.{_body}": arrival(
        f"simulation.sensors.star_tracker.exclusion_deg.{_body}", 12.5, "simulation", base="sensors")
       for _body in ("sun", "moon", "earth_limb")},
    "simulation.sensors.magnetometer.noise_T": arrival("simulation.sensors.magnetometer.noise_T", 2e-8, "simulation",
                                                       base="sensors"),
    "simulation.sensors.magnetometer.bias_T": arrival("simulation.sensors.magnetometer.bias_T", [2e-7, 0.0, 0.0],
                                                      "simulation", base="sensors"),
    "simulation.estimator.initial_attitude_sigma_deg": arrival("simulation.estimator.initial_attitude_sigma_deg",
                                                               0.2, "simulation", base="sensors"),
    "simulation.estimator.initial_bias_sigma_deg_per_h": arrival(
        "simulation.estimator.initial_bias_sigma_deg_per_h", 6.0, "simulation", base="sensors"),
}
"""Scenario keys (by their key in the schema reference) and what setting them must change."""

TRUTH_VALUES = {  # truth keys change the plant alone: not the design spacecraft the planners and laws see
    "truth.spacecraft.inertia": ("truth.spacecraft.inertia", [2.2, 3.0, 3.9]),
    "truth.wheels.misalignment_deg": ("truth.wheels.misalignment_deg", [[0, 2, 0], [0, 0, 1], [1, 0, 0]]),
    "truth.wheels.max_torque": ("truth.wheels.max_torque", 0.03),
    "truth.wheels.max_momentum": ("truth.wheels.max_momentum", [0.4, 0.3, 0.4]),
    "truth.wheels.friction.coulomb": ("truth.wheels.friction.coulomb", 2e-5),
    "truth.wheels.friction.viscous": ("truth.wheels.friction.viscous", 3e-6),
    "truth.wheels.max_speed_rpm": ("truth.wheels.max_speed_rpm", 2000.0),
    "truth.wheels.torque_noise": ("truth.wheels.torque_noise", 2e-5),
    "truth.magnetorquers.scale_error": ("truth.magnetorquers.scale_error", -0.05),
    "truth.residual_dipole": ("truth.residual_dipole", [0.0, 0.02, 0.0]),
    "truth.disturbance.constant": ("truth.disturbance.constant", [0.0, 0.0, 2e-7]),
    "truth.disturbance.orbit_periodic.harmonic": ("truth.disturbance.orbit_periodic[0].harmonic", 2),
    "truth.disturbance.orbit_periodic.amplitude": ("truth.disturbance.orbit_periodic[0].amplitude", [0, 2e-7, 0]),
    "truth.disturbance.orbit_periodic.phase_deg": ("truth.disturbance.orbit_periodic[0].phase_deg", [10, 0, 0]),
}
for _key, (_path, _value) in TRUTH_VALUES.items():
    ARRIVALS[_key] = arrival(_path, _value, "truth", base="truth")

TARGET_VALUES = {  # reference key below maneuver.<end>.q -> (form, path below it, new value)
    "quaternion": ("quaternion", "quaternion", [0.9998477, 0.0174524, 0.0, 0.0]),
    "at_time_s": ("quaternion", "at_time_s", 2.0),
    "axis_angle.axis": ("axis_angle", "axis_angle.axis", [0.0, 0.1, 1.0]),
    "axis_angle.angle_deg": ("axis_angle", "axis_angle.angle_deg", 25.0),
    "euler.angles_deg": ("euler", "euler.angles_deg", [12.0, 5.0, 0.0]),
    "point.boresight": ("point", "point.boresight", [0.0, 0.1, 1.0]),
    "point.at.inertial": ("point", "point.at.inertial", [1.0, 0.1, 0.0]),
    "point.secondary.axis": ("point", "point.secondary.axis", [0.1, 1.0, 0.0]),
    "point.secondary.toward.inertial": ("point", "point.secondary.toward.inertial", [0.0, 0.1, 1.0]),
    "point.at.lvlh": ("point.at.lvlh", "point.at.lvlh", [0.0, 0.1, 1.0]),
    "point.secondary.toward.lvlh": ("point.at.lvlh", "point.secondary.toward.lvlh", [1.0, 0.1, 0.0]),
    "point.at.rtn": ("point.at.rtn", "point.at.rtn", [0.0, 0.1, 1.0]),
    "point.secondary.toward.rtn": ("point.at.rtn", "point.secondary.toward.rtn", [1.0, 0.1, 0.0]),
    **{f"point.{where}.ground.{leaf}": ("point.at.ground", f"point.{where}.ground.{leaf}", value)
       for where in ("at", "secondary.toward") for leaf, value in (("lat_deg", 45.0), ("lon_deg", 3.0),
                                                                   ("alt_m", 500.0))},
}
for _end in ("initial", "final"):
    for _key, (_form, _below, _value) in TARGET_VALUES.items():
        ARRIVALS[f"maneuver.{_end}.q.{_key}"] = arrival(f"maneuver.{_end}.q.{_below}", _value, "maneuver",
                                                        base=f"{_end}:{_form}")

NOT_DISPERSIBLE: dict[str, str] = {
    "maneuver.quaternion_order": "a word, not a number",
}
"""Keys of the reference that hold numbers but are not dispersed, with the reason."""

REQUIREMENT_RATE_ALONE = arrival("requirements.rate.max", 0.35, *POINTING, base="keep_in")


# --- planner, controller and field model options: generated ---------------------------------------

def _shipped(kind: str) -> dict[str, list[tuple[dict[str, Any], str]]]:
    """Registry name -> every (shipped scenario, YAML path of its row or controller) that uses it."""
    from pathlib import Path

    found: dict[str, list[tuple[dict[str, Any], str]]] = {}
    for path in sorted(Path(__file__).parent.parent.joinpath("scenarios").glob("*.yaml")):
        data = read_yaml(path)
        if "study" in data:
            continue
        head = kind if kind == "planners" or "controllers" in data else "controller"
        entries = data.get(head) if head != "controller" else [data.get("controller")]
        for index, entry in enumerate(entries or []):
            if isinstance(entry, dict):
                where = head if head == "controller" else f"{head}[{index}]"
                found.setdefault(entry["name"], []).append((data, where))
    return found


def _candidates(annotation: Any, default: Any) -> list[Any]:
    """New values to try for a numeric option: its default moved within range, or typical values."""
    args = [a for a in typing.get_args(annotation) if a is not type(None)] or [annotation]
    if isinstance(default, bool):
        return []
    if isinstance(default, int):  # never the default itself (0 * 2): a value that changes nothing proves nothing
        return [v for v in (default + 1, default * 2, default - 1, default + 2) if v != default]
    if isinstance(default, float) and math.isfinite(default):
        return [default * 1.25, default * 0.8, default * 2.0, default + 1.0] if default else [0.1, 1.0]
    if isinstance(default, (list, tuple)) and default and all(isinstance(v, (int, float)) for v in default):
        return [[float(v) * 1.25 or 0.1 for v in default]]
    values: list[Any] = []
    if int in args:
        values += [3, 2, 10]
    if float in args:
        values += [0.05, 0.5, 1.0, 2.0]
    if any(typing.get_origin(a) is list for a in args):
        values += [[0.05, 0.05, 0.05], [1.0, 1.0, 1.0]]
    return values


def _in_full(kind: str, name: str) -> list[tuple[dict[str, Any], str]]:
    """:data:`FULL` with the planner or controller ``name`` as its only one: the base of a
    component no shipped scenario uses."""
    base = copy.deepcopy(FULL)
    if kind == "planners":
        base["planners"] = [{"name": name}]
        return [(base, "planners[0]")]
    base["controller"] = {"name": name}
    return [(base, "controller")]


def _option_arrivals() -> list[tuple[str, dict[str, Any], str, Any, str]]:
    """(reference key, base scenario, option path, new value, changed part) for every numeric option
    of every registered planner and controller, set in a shipped scenario that uses it (else in
    :data:`FULL`, :func:`_in_full`): the first (scenario, candidate value) the scenario loader
    accepts (value None when none is)."""
    found = []
    for kind, registry, shipped in (("planners", PLANNERS, _shipped("planners")),
                                    ("controller", CONTROLLERS, _shipped("controllers"))):
        for name, component in registry.items():
            defaults = component.Options()
            for option, (annotation, _) in option_fields(component.Options).items():
                if not numeric_leaves(annotation):
                    continue
                accepted = None
                for base, where in shipped.get(name) or _in_full(kind, name):
                    for candidate in _candidates(annotation, getattr(defaults, option)):
                        try:
                            parse_scenario(_with(base, f"{where}.options.{option}", candidate))
                        except Exception:  # noqa: BLE001 - the loader refuses this one; try the next
                            continue
                        accepted = (base, where, candidate)
                        break
                    if accepted:
                        break
                base, where, value = accepted or ((shipped.get(name) or _in_full(kind, name))[0] + (None,))
                entry = get_path(base, parse_path(where, where), where) if base else {}
                part = f"{'planner' if kind == 'planners' else 'controller'}:{entry.get('label', name)}"
                found.append((f"{kind}.{name}.{option}", base, f"{where}.options.{option}", value, part))
    return found


def _with(base: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    from scenarios.study.paths import set_path

    data = copy.deepcopy(base)
    set_path(data, parse_path(path, path), value, path)
    return data


OPTION_ARRIVALS = _option_arrivals()


# --- the check -------------------------------------------------------------------------------------

def _study(base: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    """A one-case study setting ``value`` at ``path``: a Monte Carlo dispersion for numbers (a draw
    of ``uniform: [v, v]`` is ``v``; a matrix is scaled), a one-value grid for integers and lists of
    lists."""
    study: dict[str, Any] = {"study": "arrival", "scenario": copy.deepcopy(base)}
    numbers = np.asarray(value, dtype=float) if not isinstance(value, bool) else None
    integral = isinstance(value, int) or (isinstance(value, list) and all(isinstance(v, int) for v in value))
    if numbers is not None and numbers.ndim <= 1 and not integral:
        low = value if numbers.ndim == 0 else [float(v) for v in value]
        study["monte_carlo"] = {"samples": 1, "seed": 1, "dispersions": {path: {"uniform": {"low": low, "high": low}}}}
    else:
        study["grid"] = {path: [value]}
    return study


def check_arrival(base: dict[str, Any], path: str, value: Any, changes: frozenset[str]) -> None:
    study = parse_study(_study(base, path, value))
    (case,) = study.cases
    steps = parse_path(path, path)
    assert np.allclose(np.asarray(get_path(case.scenario, steps, path), dtype=float),
                       np.asarray(value, dtype=float), rtol=1e-15, atol=0.0), "the case does not hold the value"
    before, after = parts(parse_scenario(copy.deepcopy(base))), parts(parse_scenario(case.scenario))
    assert before.keys() == after.keys()
    changed = {name for name in before if before[name] != after[name]}
    assert changed == set(changes), f"{path} = {value!r} changed {sorted(changed)}, expected {sorted(changes)}"


@pytest.mark.parametrize("key", sorted(ARRIVALS))
def test_a_dispersed_scenario_key_changes_what_it_names_and_nothing_else(key):
    entry = ARRIVALS[key]
    check_arrival(BASES[entry.base], entry.path, entry.value, entry.changes)


def test_a_rate_requirement_alone_bounds_the_planners():
    """Without ``maneuver.max_rate`` the rate requirement is also the planners' bound."""
    check_arrival(BASES[REQUIREMENT_RATE_ALONE.base], REQUIREMENT_RATE_ALONE.path, REQUIREMENT_RATE_ALONE.value,
                  REQUIREMENT_RATE_ALONE.changes)


@pytest.mark.parametrize("key, base, path, value, part", OPTION_ARRIVALS, ids=[a[0] for a in OPTION_ARRIVALS])
def test_a_dispersed_option_changes_its_planner_or_controller_and_nothing_else(key, base, path, value, part):
    assert value is not None, f"no new value of {key} is accepted in the shipped scenario that uses it"
    check_arrival(base, path, value, frozenset({part}))


def test_every_dispersible_key_has_an_arrival_case():
    """Every key of the schema reference that takes numbers has an arrival case (or a reason): the
    scenario's keys (a study disperses those, not its own keys nor a slew-table file's)."""
    covered = set(ARRIVALS) | set(NOT_DISPERSIBLE) | {key for key, *_ in OPTION_ARRIVALS}
    numeric = []
    for part in reference_parts():
        if part.group in ("Study file", "Slew-table file"):
            continue
        for entry in part.entries:
            if any(word in entry.type for word in ("number", "integer", "matrix")):
                numeric.append(entry.key)
    missing = [key for key in numeric if key not in covered]
    assert not missing, f"dispersible keys without an arrival case (add them to ARRIVALS): {missing}"
    assert {"planner:smooth", "controller:augmented_quaternion_feedback"} <= set(parts(parse_scenario(FULL)))


def test_the_parts_compare_equal_for_the_same_scenario_and_see_a_change():
    """The comparison itself: two loads of one scenario are equal part by part, and a part that
    differs is seen (so an empty difference is not a blind one)."""
    first, second = parts(parse_scenario(copy.deepcopy(FULL))), parts(parse_scenario(copy.deepcopy(FULL)))
    assert first == second
    changed = copy.deepcopy(FULL)
    changed["controller"]["options"]["kd"] = 0.61
    changed["spacecraft"]["inertia"] = [2.0, 3.0, 4.0000001]
    after = parts(parse_scenario(changed))
    assert {name for name in first if first[name] != after[name]} == {"controller:augmented_quaternion_feedback",
                                                                      "spacecraft", "plant"}
