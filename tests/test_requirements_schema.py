"""Bad requirement input is exit 2 naming the YAML path, the value and what was expected (through the
command line, as a user meets it); good input builds the objects and the problem the planners get."""
from __future__ import annotations

import contextlib
import copy
import datetime
import io
from pathlib import Path

import numpy as np
import pytest
import yaml

import scenarios
from scenarios.cli.commands import main

BASE = {
    "name": "requirements",
    "spacecraft": {"inertia": [0.25, 0.28, 0.12], "wheels": {"max_torque": 0.003, "max_momentum": 0.02},
                   "sensors": {"star_tracker": {"boresight": [0.5, -0.8660254, 0.0]}}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0, 0, 0.8660254], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5},
    "requirements": {"pointing": {"st": {"sensor": "star_tracker", "keep_out": {"inertial": [1, 0, 0]},
                                         "angle_deg": 30}}},
}
ORBIT = {"altitude_km": 500, "inclination_deg": 97.4}
EPOCH = "2027-03-20T12:00:00Z"


def changed(**paths) -> dict:
    """BASE with ``a__b__c=value`` set (``None`` deletes the key)."""
    data = copy.deepcopy(BASE)
    for path, value in paths.items():
        keys = path.split("__")
        node = data
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        if value is None:
            node.pop(keys[-1], None)
        else:
            node[keys[-1]] = value
    return data


def pointing(**entry) -> dict:
    base = {"sensor": "star_tracker", "keep_out": {"inertial": [1, 0, 0]}, "angle_deg": 30}
    base.update(entry)
    return {k: v for k, v in base.items() if v is not None}


def run_cli(tmp_path: Path, data: dict, command: str = "validate") -> tuple[int, str]:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main([command, str(path)] + (["--out", str(tmp_path / "out"), "--no-plots"] if command == "run" else []))
    return status, stderr.getvalue()


BAD = {
    "unknown sensor": (changed(requirements__pointing__st=pointing(sensor="camera")),
                       "requirements.pointing.st.sensor", ["'camera'", "star_tracker"]),
    "zero boresight": (changed(spacecraft__sensors__star_tracker={"boresight": [0, 0, 0]}),
                       "spacecraft.sensors.star_tracker.boresight", ["cannot be zero"]),
    "angle 0": (changed(requirements__pointing__st=pointing(angle_deg=0)), "requirements.pointing.st.angle_deg",
                ["(0, 180)", "0"]),
    "angle 180": (changed(requirements__pointing__st=pointing(angle_deg=180)), "requirements.pointing.st.angle_deg",
                  ["(0, 180)", "180"]),
    "negative angle": (changed(requirements__pointing__st=pointing(angle_deg=-5)),
                       "requirements.pointing.st.angle_deg", ["(0, 180)"]),
    "sun without epoch": (changed(requirements__pointing__st=pointing(keep_out="sun")),
                          "requirements.pointing.st.keep_out", ["'sun'", "epoch"]),
    "moon without epoch": (changed(requirements__pointing__st=pointing(keep_out=None, keep_in="moon")),
                           "requirements.pointing.st.keep_in", ["'moon'", "epoch"]),
    "earth without orbit": (changed(requirements__pointing__st=pointing(keep_out="earth")),
                            "requirements.pointing.st.keep_out", ["'earth'", "orbit"]),
    "limb without orbit": (changed(requirements__pointing__st=pointing(keep_out="earth_limb")),
                           "requirements.pointing.st.keep_out", ["'earth_limb'", "orbit"]),
    "velocity without orbit": (changed(requirements__pointing__st=pointing(keep_out="velocity")),
                               "requirements.pointing.st.keep_out", ["'velocity'", "orbit"]),
    "unknown direction": (changed(requirements__pointing__st=pointing(keep_out="sunn")),
                          "requirements.pointing.st.keep_out", ["'sunn'", "'earth_limb'", "inertial"]),
    # 170 deg from the limb seen from 500 km (the Earth's apparent radius 68.0 deg): a 238 deg cone
    "a limb keep-out covering the sky": (changed(orbit={"altitude_km": 500.0},
                                                 requirements__pointing__st=pointing(keep_out="earth_limb", angle_deg=170)),
                                         "requirements.pointing.st.angle_deg", ["238 deg half-angle", "whole sky"]),
    "a target's frame": (changed(requirements__pointing__st=pointing(keep_out={"lvlh": [0, 0, 1]})),
                         "requirements.pointing.st.keep_out", ["{inertial: [x, y, z]}", "'lvlh'", "attitude targets"]),
    "zero inertial direction": (changed(requirements__pointing__st=pointing(keep_out={"inertial": [0, 0, 0]})),
                                "requirements.pointing.st.keep_out.inertial", ["cannot be zero"]),
    "both keep_out and keep_in": (changed(requirements__pointing__st=pointing(keep_in="sun")),
                                  "requirements.pointing.st", ["exactly one of keep_out and keep_in"]),
    "neither": (changed(requirements__pointing__st=pointing(keep_out=None)), "requirements.pointing.st",
                ["exactly one"]),
    "epoch before the ephemeris": (changed(epoch="1950-01-01T00:00:00Z"), "epoch", ["1960-01-01", "1950-01-01"]),
    "epoch after the ephemeris": (changed(epoch="2199-12-31T23:59:30Z"), "epoch", ["2200-01-01"]),
    "epoch not a date": (changed(epoch="next tuesday"), "epoch", ["'next tuesday'", "2025-01-01"]),
    "window after the run": (changed(requirements__pointing__st=pointing(window=[70, None])),
                             "requirements.pointing.st.window", ["70", "60"]),
    "window ends after the run": (changed(requirements__pointing__st=pointing(window=[0, 90])),
                                  "requirements.pointing.st.window", ["90", "null"]),
    "window reversed": (changed(requirements__pointing__st=pointing(window=[30, 10])),
                        "requirements.pointing.st.window", ["[30, 10]"]),
    "window negative start": (changed(requirements__pointing__st=pointing(window=[-1, None])),
                              "requirements.pointing.st.window[0]", ["non-negative"]),
    # a window of no length: the run is [0, 60] s (maneuver.duration), so none of it is left at 60 s
    "window starting at the run's end": (changed(requirements__pointing__st=pointing(window=[60, None])),
                                         "requirements.pointing.st.window", ["starts at 60 s", "end at 60 s"]),
    "window of no length": (changed(requirements__pointing__st=pointing(window=[10, 10])),
                            "requirements.pointing.st.window", ["[10, 10]", "after its start"]),
    "window of one number": (changed(requirements__pointing__st=pointing(window=[10])),
                             "requirements.pointing.st.window", ["[start_s, end_s or null]"]),
    "reserved name": (changed(requirements__pointing={"rate": pointing()}), "requirements.pointing.rate",
                      ["another name"]),
    "name with a dot": (changed(requirements__pointing={"st.sun": pointing()}), "requirements.pointing.st.sun",
                        ["letter"]),
    "unknown requirement key": (changed(requirements__pointing__st=pointing(angle=30)),
                                "requirements.pointing.st.angle", ["unknown key"]),
    "margin of 1": (changed(requirements__actuators={"margin": 1.0}), "requirements.actuators.margin", ["[0, 1)"]),
    "negative margin": (changed(requirements__actuators={"margin": -0.1}), "requirements.actuators.margin",
                        ["non-negative"]),
    "zero rate": (changed(requirements__rate={"max": 0}), "requirements.rate.max", ["positive"]),
    "planning rate above the requirement": (changed(requirements__rate={"max": 0.05}, maneuver__max_rate=0.1),
                                            "maneuver.max_rate", ["0.1", "0.05"]),
    "final after the run": (changed(requirements__final={"after_s": 5, "error_deg": 1}),
                            "requirements.final.after_s", ["65", "simulation.duration"]),
    "final past a given run": (changed(requirements__final={"after_s": 15, "error_deg": 1}, simulation__duration=70),
                               "requirements.final.after_s", ["75", "70"]),
    "final with nothing to bound": (changed(requirements__final={"after_s": 0}), "requirements.final",
                                    ["error_deg, rate or both"]),
    "final rate with a free final rate": (changed(requirements__final={"rate": 0.001},
                                                  maneuver__final__omega=None),
                                          "requirements.final.rate", ["free"]),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_requirement_input_is_exit_2_naming_the_path(case, tmp_path):
    data, path, words = BAD[case]
    status, error = run_cli(tmp_path, data)
    assert status == 2, error
    assert f"error in scenario: {tmp_path / 'case.yaml'}: {path}:" in error, error
    for word in words:
        assert word in error, (word, error)
    assert "Traceback" not in error


def test_a_field_model_takes_the_scenarios_epoch_or_must_agree_with_it(tmp_path):
    igrf = {"model": "igrf"}
    data = changed(epoch=EPOCH, orbit=ORBIT, environment={"magnetic_field": igrf})
    scenario = scenarios.parse_scenario(copy.deepcopy(data))
    assert scenario.problem.environment.magnetic_field.epoch == "2027-03-20T12:00:00"
    assert scenario.epoch == datetime.datetime(2027, 3, 20, 12) and scenario.frame == "GCRF (epoch 2027-03-20T12:00:00Z)"
    same = changed(epoch=EPOCH, orbit=ORBIT, environment={"magnetic_field": {"model": "igrf",
                                                                             "epoch": "2027-03-20T13:00:00+01:00"}})
    assert scenarios.parse_scenario(same).problem.environment.magnetic_field.epoch == "2027-03-20T13:00:00+01:00"
    differ = changed(epoch=EPOCH, orbit=ORBIT, environment={"magnetic_field": {"model": "igrf", "epoch": "2025-01-01"}})
    status, error = run_cli(tmp_path, differ)
    assert status == 2 and f"error in scenario: {tmp_path / 'case.yaml'}: environment.magnetic_field.epoch: 2025-01-01T00:00:00 differs" in error
    assert "epoch: 2027-03-20T12:00:00Z" in error
    outside = changed(epoch="2035-01-01T00:00:00Z", orbit=ORBIT, environment={"magnetic_field": igrf})
    status, error = run_cli(tmp_path, outside)
    assert status == 2 and f"error in scenario: {tmp_path / 'case.yaml'}: epoch: IGRF-14 covers" in error, error
    assert "takes the scenario's epoch" in error


def test_good_requirements_build_the_problem_the_planners_get():
    data = changed(epoch=EPOCH, orbit=ORBIT, requirements={
        "pointing": {"st_sun": pointing(keep_out="sun", window=[5, None]),
                     "st_limb": pointing(keep_out="earth_limb", angle_deg=10)},
        "actuators": {"margin": 0.2}, "rate": {"max": 0.05},
        "final": {"error_deg": 0.5}})
    scenario = scenarios.parse_scenario(data)
    problem = scenario.problem
    assert [c.name for c in problem.pointing] == ["st_sun", "st_limb"]
    sun, limb = problem.pointing
    assert sun.keep_out and sun.window == (5.0, np.inf) and sun.angle == pytest.approx(np.deg2rad(30))
    np.testing.assert_allclose(sun.boresight, [0.5, -0.8660254, 0.0], atol=1e-7)
    assert sun.times[-1] >= 60.0 and limb.moving and np.all(limb.growth > np.deg2rad(60))  # Earth's radius from 500 km
    assert problem.actuator_margin == 0.2 and problem.max_rate == 0.05
    assert scenario.requirements.names == ("st_sun", "st_limb", "actuators", "rate", "final")
    assert scenario.requirements.final.error_deg == 0.5 and scenario.requirements.final.after_s == 0.0
    tighter = changed(requirements__rate={"max": 0.05}, maneuver__max_rate=0.04)
    assert scenarios.parse_scenario(tighter).problem.max_rate == 0.04  # the planning bound, no looser
    assert scenarios.parse_scenario(changed(requirements=None)).problem.pointing == ()


@pytest.mark.parametrize("name", ["actuators", "rate", "final"])
def test_a_pointing_requirement_may_not_take_a_reserved_name(name):
    """The names ``actuators``, ``rate`` and ``final`` name the other requirements' result columns
    (``ref.req.<name>.<field>``): a pointing requirement called so is refused, naming it."""
    from scenarios.requirements.spec import (
        Direction,
        PointingRequirement,
        Requirements,
        Sensor,
    )
    cone = PointingRequirement(name, Sensor("st", [0, 0, 1]), True, 0.5, Direction(None, [1, 0, 0]))
    with pytest.raises(ValueError, match=name):
        Requirements(pointing=(cone,))
    assert Requirements(pointing=(PointingRequirement("sun", cone.sensor, True, 0.5, cone.direction),)).names == ("sun",)


def test_a_sensors_boresight_and_a_fixed_direction_are_made_unit():
    """[0, 6, 8] becomes [0, 0.6, 0.8] (norm 10, by hand); the cone's angle at the identity attitude from
    inertial z is then acos(0.8)."""
    from ocp.geometry.directions import Geometry
    from scenarios.requirements.spec import Direction, PointingRequirement, Sensor
    sensor = Sensor("st", [0.0, 6.0, 8.0])
    np.testing.assert_allclose(sensor.boresight, [0.0, 0.6, 0.8], rtol=1e-15)
    direction = Direction(None, [0.0, 0.0, 5.0])
    np.testing.assert_allclose(direction.vector, [0.0, 0.0, 1.0], rtol=1e-15)
    constraint = PointingRequirement("sun", sensor, True, 0.3, direction).constraint(Geometry(None, None), 10.0)
    assert float(constraint.angles([0.0], [[1.0, 0.0, 0.0, 0.0]])[0]) == pytest.approx(np.arccos(0.8), abs=1e-12)
