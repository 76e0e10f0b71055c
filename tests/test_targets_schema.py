"""``maneuver.initial.q`` / ``maneuver.final.q`` in mission terms, read from YAML.

Each form's quaternion is checked against an independent construction (SciPy's ``Rotation``, the
orbit's position and velocity, the Sun's direction from the ephemeris, the ground point's direction
from ERFA's geodetic conversion); bad input is exit 2 naming the YAML path (through the command
line for the issue's cases, through the parser for the rest).
"""
from __future__ import annotations

import contextlib
import copy
import io
from pathlib import Path

import erfa
import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from ocp import quat
from ocp.geometry.directions import Geometry
from ocp.geometry.targets import itrs_to_gcrf
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.schema.loader import parse_scenario
from scenarios.schema.node import Node
from scenarios.schema.study import grid_values

EPOCH = "2027-03-20T12:00:00Z"
BASE = {
    "name": "targets",
    "epoch": EPOCH,
    "spacecraft": {"inertia": [0.25, 0.28, 0.12], "wheels": {"max_torque": 0.003, "max_momentum": 0.02},
                   "sensors": {"camera": {"boresight": [0, 0, 1]}, "panel": {"boresight": [0, 1, 0]}}},
    "orbit": {"altitude_km": 500, "inclination_deg": 97.4, "raan_deg": 20.0, "arg_latitude_deg": 10.0},
    "maneuver": {"duration": 120.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5},
}


def scenario(final=None, initial=None, **top):
    data = copy.deepcopy(BASE)
    if final is not None:
        data["maneuver"]["final"]["q"] = final
    if initial is not None:
        data["maneuver"]["initial"]["q"] = initial
    for key, value in top.items():
        if value is None:
            data.pop(key, None)
        else:
            data[key] = value
    return data


def parsed(final=None, initial=None, **top):
    return parse_scenario(scenario(final, initial, **top))


def refused(data) -> ScenarioError:
    with pytest.raises(ScenarioError) as error:
        parse_scenario(data)
    return error.value


def angle(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b))


def geometry(data=None):
    loaded = parse_scenario(data or scenario())
    return Geometry(loaded.epoch, loaded.problem.environment.orbit)


# --- the rotation forms ------------------------------------------------------------------------------

def test_plain_quaternion_is_unchanged():
    assert np.allclose(parsed(final=[0.5, 0, 0, 0.8660254]).problem.qf, [0.5, 0, 0, 0.8660254], atol=1e-7)


def test_axis_angle_and_euler_forms_match_scipy():
    axis, angle_deg = [1.0, -2.0, 0.5], 140.0
    expected = Rotation.from_rotvec(np.array(axis) / np.linalg.norm(axis) * np.deg2rad(angle_deg))
    qf = parsed(final={"axis_angle": {"axis": axis, "angle_deg": angle_deg}}).problem.qf
    assert quat.error_angle(qf, expected.as_quat(scalar_first=True)) < 1e-12
    for sequence, letters in (("321", "ZYX"), ("313", "ZXZ"), ("xyz", "XYZ")):
        angles = [30.0, -50.0, 100.0]
        qf = parsed(final={"euler": {"angles_deg": angles, "sequence": sequence}}).problem.qf
        oracle = Rotation.from_euler(letters, angles, degrees=True).as_quat(scalar_first=True)
        assert quat.error_angle(qf, oracle) < 1e-12, sequence
    default = parsed(final={"euler": {"angles_deg": [10, 20, 30]}}).problem.qf
    assert quat.error_angle(default, Rotation.from_euler("ZYX", [10, 20, 30], degrees=True)
                            .as_quat(scalar_first=True)) < 1e-12
    numeric = parsed(final={"euler": {"angles_deg": [10, 20, 30], "sequence": 321}}).problem.qf
    assert quat.error_angle(numeric, default) < 1e-15


def test_quaternion_form_follows_the_quaternion_order():
    data = scenario(final={"quaternion": [0, 0, 0.8660254, 0.5]})
    data["maneuver"]["quaternion_order"] = "scalar_last"
    data["maneuver"]["initial"]["q"] = [0, 0, 0, 1]
    assert np.allclose(parse_scenario(data).problem.qf, [0.5, 0, 0, 0.8660254], atol=1e-7)


def test_study_axis_angle_generator_gives_the_scenario_form_quaternions():
    values, recorded = grid_values(Node({"axis_angle": {"axis": [0, 1, 1], "angle_deg": [30.0, 200.0]}},
                                        "grid.maneuver.final.q"), BASE)
    assert recorded == [30.0, 200.0]
    for value, angle_deg in zip(values, recorded):
        form = parsed(final={"axis_angle": {"axis": [0, 1, 1], "angle_deg": angle_deg}}).problem.qf
        assert quat.error_angle(np.array(value), form) < 1e-15


# --- frames ------------------------------------------------------------------------------------------

def lvlh_by_hand(geo, t):
    r, v = geo.position(t)[0], geo.velocity(t)[0]
    z = -r / np.linalg.norm(r)
    y = -np.cross(r, v) / np.linalg.norm(np.cross(r, v))
    return np.column_stack([np.cross(y, z), y, z])


def test_lvlh_and_rtn_frames_at_t0_for_the_initial_and_the_duration_for_the_final():
    loaded = parsed(initial={"quaternion": [1, 0, 0, 0], "frame": "lvlh"},
                    final={"euler": {"angles_deg": [0, 0, 90], "sequence": "321"}, "frame": "lvlh"})
    geo = geometry()
    np.testing.assert_allclose(quat.rotation_matrix(loaded.problem.q0), lvlh_by_hand(geo, 0.0), atol=1e-12)
    roll = Rotation.from_euler("X", 90, degrees=True).as_matrix()
    np.testing.assert_allclose(quat.rotation_matrix(loaded.problem.qf), lvlh_by_hand(geo, 120.0) @ roll, atol=1e-12)
    timed = parsed(final={"quaternion": [1, 0, 0, 0], "frame": "lvlh", "at_time_s": 30.0})
    np.testing.assert_allclose(quat.rotation_matrix(timed.problem.qf), lvlh_by_hand(geo, 30.0), atol=1e-12)
    rtn = parsed(final={"axis_angle": {"axis": [0, 0, 1], "angle_deg": 0.0}, "frame": "rtn"})
    r, v = geo.position(120.0)[0], geo.velocity(120.0)[0]
    matrix = quat.rotation_matrix(rtn.problem.qf)
    assert angle(matrix[:, 0], r) < 1e-12 and angle(matrix[:, 2], np.cross(r, v)) < 1e-12


def test_final_relative_to_the_initial_attitude():
    loaded = parsed(initial={"euler": {"angles_deg": [40, 10, -20]}},
                    final={"axis_angle": {"axis": [0, 0, 1], "angle_deg": 90.0}, "frame": "initial"})
    q0 = Rotation.from_euler("ZYX", [40, 10, -20], degrees=True)
    expected = (q0 * Rotation.from_rotvec([0, 0, np.pi / 2])).as_quat(scalar_first=True)  # body axis z of q0
    assert quat.error_angle(loaded.problem.qf, expected) < 1e-12


# --- pointing targets ---------------------------------------------------------------------------------

def check_pointing(q, boresight, target, axis, toward):
    b_inertial = quat.rotate(q, boresight)
    assert angle(b_inertial, target) < 1e-9
    s_inertial = quat.rotate(q, np.asarray(axis) / np.linalg.norm(axis))
    normal = np.cross(target, toward)
    assert abs(s_inertial @ normal) / np.linalg.norm(normal) < 1e-9
    across = toward - (toward @ target) * target / (target @ target)
    assert s_inertial @ across > 0.0


def test_point_a_sensor_at_the_sun_with_the_panel_toward_nadir():
    loaded = parsed(final={"point": {"sensor": "camera", "at": "sun", "secondary": {"sensor": "panel",
                                                                                   "toward": "earth"}}})
    geo = geometry()
    sun, nadir = geo.sun(120.0)[0], -geo.position(120.0)[0]
    check_pointing(loaded.problem.qf, [0, 0, 1], sun, [0, 1, 0], nadir / np.linalg.norm(nadir))
    # at_time_s moves the instant of the directions
    early = parsed(final={"point": {"sensor": "camera", "at": "earth", "secondary": {"axis": [1, 0, 0],
                                                                                    "toward": "velocity"}},
                          "at_time_s": 0.0})
    r, v = geo.position(0.0)[0], geo.velocity(0.0)[0]
    check_pointing(early.problem.qf, [0, 0, 1], -r / np.linalg.norm(r), [1, 0, 0], v / np.linalg.norm(v))
    # nadir pointing with x along the velocity is the LVLH frame itself (circular orbit)
    np.testing.assert_allclose(quat.rotation_matrix(early.problem.qf), lvlh_by_hand(geo, 0.0), atol=1e-12)


def test_point_at_a_ground_point_with_the_orbit_normal_as_secondary():
    geo = geometry()
    t = 120.0
    rotation = itrs_to_gcrf(geo.epoch, t)[0]
    # a point 3 deg of latitude from the sub-satellite point (ERFA's inverse geodetic conversion)
    longitude, latitude, _ = erfa.gc2gd(1, rotation.T @ geo.position(t)[0])
    ground = {"lat_deg": float(np.rad2deg(latitude)) + 3.0, "lon_deg": float(np.rad2deg(longitude)), "alt_m": 250.0}
    loaded = parsed(final={"point": {"boresight": [0, 0, 1], "at": {"ground": ground},
                                     "secondary": {"axis": [0, 1, 0], "toward": {"lvlh": [0, -1, 0]}}}})
    point = rotation @ erfa.gd2gc(1, np.deg2rad(ground["lon_deg"]), np.deg2rad(ground["lat_deg"]), 250.0)
    target = point - geo.position(t)[0]
    r, v = geo.position(t)[0], geo.velocity(t)[0]
    check_pointing(loaded.problem.qf, [0, 0, 1], target / np.linalg.norm(target), [0, 1, 0],
                   np.cross(r, v) / np.linalg.norm(np.cross(r, v)))
    rtn = parsed(final={"point": {"boresight": [0, 0, 1], "at": {"ground": ground},
                                  "secondary": {"axis": [0, 1, 0], "toward": {"rtn": [0, 0, 1]}}}})
    assert quat.error_angle(rtn.problem.qf, loaded.problem.qf) < 1e-12
    inertial = parsed(final={"point": {"boresight": [0, 0, 1], "at": {"inertial": [0, 0, 2]},
                                       "secondary": {"axis": [1, 0, 0], "toward": {"inertial": [0, 3, 0]}}}})
    np.testing.assert_allclose(quat.rotate(inertial.problem.qf, [1, 0, 0]), [0, 1, 0], atol=1e-15)


# --- bad input: exit 2 naming the YAML path ------------------------------------------------------------

def run_validate(tmp_path: Path, data: dict) -> tuple[int, str]:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main(["validate", str(path)])
    return status, stderr.getvalue()


@pytest.mark.parametrize("point, path, words", [
    ({"sensor": "camera", "at": "sun", "secondary": {"axis": [0, 0, -3], "toward": "earth"}},
     "maneuver.final.q.point.secondary.axis", "parallel"),
    ({"sensor": "camera", "at": "sun", "secondary": {"sensor": "camera", "toward": "earth"}},
     "maneuver.final.q.point.secondary.sensor", "parallel"),
    ({"sensor": "camera", "at": {"inertial": [1, 0, 0]}, "secondary": {"axis": [1, 0, 0], "toward": {"inertial":
                                                                                                    [-2, 0, 0]}}},
     "maneuver.final.q.point.secondary.toward", "parallel"),
])
def test_an_undetermined_roll_is_exit_2_naming_the_path(tmp_path, point, path, words):
    status, stderr = run_validate(tmp_path, scenario(final={"point": point}))
    assert status == 2 and "Traceback" not in stderr
    assert path + ":" in stderr and words in stderr


@pytest.mark.parametrize("final, top, path, words", [
    ({"quaternion": [1, 0, 0, 0], "frame": "lvlh"}, {"orbit": None}, "maneuver.final.q.frame", "needs an orbit"),
    ({"point": {"boresight": [0, 0, 1], "at": {"ground": {"lat_deg": 10, "lon_deg": 0}},
                "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}, {"epoch": None},
     "maneuver.final.q.point.at.ground", "epoch"),
    ({"point": {"boresight": [0, 0, 1], "at": "sun", "secondary": {"axis": [1, 0, 0], "toward": {"inertial":
                                                                                                [0, 0, 1]}}}},
     {"epoch": None}, "maneuver.final.q.point.at", "epoch"),
    ({"point": {"boresight": [0, 0, 1], "at": "earth", "secondary": {"axis": [1, 0, 0], "toward": {"rtn": [0, 0, 1]}}}},
     {"orbit": None}, "maneuver.final.q.point.at", "needs an orbit"),
    ({"point": {"boresight": [0, 0, 1], "at": "earth_limb", "secondary": {"axis": [1, 0, 0], "toward": "sun"}}},
     {}, "maneuver.final.q.point.at", "earth"),
    ({"point": {"sensor": "star_tracker", "at": "sun", "secondary": {"axis": [1, 0, 0], "toward": "earth"}}}, {},
     "maneuver.final.q.point.sensor", "unknown sensor"),
    ({"point": {"sensor": "camera", "boresight": [0, 0, 1], "at": "sun", "secondary": {"axis": [1, 0, 0],
                                                                                      "toward": "earth"}}}, {},
     "maneuver.final.q.point", "exactly one of sensor"),
    ({"point": {"sensor": "camera", "at": "sunn", "secondary": {"axis": [1, 0, 0], "toward": "earth"}}}, {},
     "maneuver.final.q.point.at", "unknown direction"),
    ({"point": {"sensor": "camera", "at": "sun", "secondary": {"axis": [1, 0, 0], "toward": "earth"}},
      "frame": "lvlh"}, {}, "maneuver.final.q.frame", "own directions"),
    ({"euler": {"angles_deg": [1, 2, 3]}, "axis_angle": {"axis": [1, 0, 0], "angle_deg": 3}}, {}, "maneuver.final.q",
     "exactly one of"),
    ({"frame": "lvlh"}, {}, "maneuver.final.q", "exactly one of"),
    ({"euler": {"angles_deg": [1, 2, 3]}, "at_time_s": 10.0}, {}, "maneuver.final.q.at_time_s",
     "does not depend on time"),
    ({"euler": {"angles_deg": [1, 2, 3], "sequence": "112"}}, {}, "maneuver.final.q.euler.sequence", "sequence"),
    ({"axis_angle": {"axis": [0, 0, 0], "angle_deg": 3}}, {}, "maneuver.final.q.axis_angle.axis", "cannot be zero"),
    ({"axis_angle": {"axis": [0, 0, 1], "angle": 3}}, {}, "maneuver.final.q.axis_angle.angle_deg", "missing"),
    ({"quaternion": [1, 0, 0, 0], "frame": "body"}, {}, "maneuver.final.q.frame", "expected one of"),
    ({"quaternion": [1, 0, 0, 0], "frame": "lvlh", "at_time_s": -1}, {}, "maneuver.final.q.at_time_s",
     "non-negative"),
    ({"quaternion": [1, 0, 0, 0], "extra": 1}, {}, "maneuver.final.q.extra", "unknown key"),
    ("up", {}, "maneuver.final.q", "expected a quaternion"),
    ({"point": {"boresight": [0, 0, 1], "at": {"ground": {"lat_deg": 95, "lon_deg": 0}},
                "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}, {}, "maneuver.final.q.point.at.ground.lat_deg",
     "expected a number <= 90, got 95"),
    ({"point": {"boresight": [0, 0, 1], "at": {"ground": {"lat_deg": 45, "lon_deg": 361.44}},
                "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}, {}, "maneuver.final.q.point.at.ground.lon_deg",
     "expected a number <= 360, got 361.44"),
    ({"point": {"boresight": [0, 0, 1], "at": {"ground": {"lat_deg": 45, "lon_deg": 1, "alt_m": -2e5}},
                "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}, {}, "maneuver.final.q.point.at.ground.alt_m",
     "expected a number >= -100000"),
    ({"point": {"boresight": [0, 0, 1], "at": {"inertial": [1, 0, 0], "lvlh": [1, 0, 0]},
                "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}, {}, "maneuver.final.q.point.at",
     "expected a direction"),
    ({"point": {"boresight": [0, 0, 1], "at": {"inertial": [0, 0, 0]},
                "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}, {}, "maneuver.final.q.point.at.inertial",
     "cannot be zero"),
])
def test_bad_attitudes_name_the_path(final, top, path, words):
    error = refused(scenario(final, **top))
    assert error.path == path, str(error)
    assert words in error.message, error.message


def test_a_ground_point_below_the_horizon_is_refused():
    geo = geometry()
    rotation = itrs_to_gcrf(geo.epoch, 120.0)[0]
    longitude, latitude, _ = erfa.gc2gd(1, rotation.T @ geo.position(120.0)[0])
    antipode = {"lat_deg": -float(np.rad2deg(latitude)), "lon_deg": float(np.rad2deg(longitude)) + 180.0}
    error = refused(scenario({"point": {"boresight": [0, 0, 1], "at": {"ground": antipode},
                                        "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}))
    assert error.path == "maneuver.final.q.point.at.ground" and "horizon" in error.message


def test_initial_attitude_frames_and_null():
    error = refused(scenario(initial={"quaternion": [1, 0, 0, 0], "frame": "initial"}))
    assert error.path == "maneuver.initial.q.frame" and "final attitude" in error.message
    error = refused(scenario(initial=[0, 0, 0, 0]))
    assert error.path == "maneuver.initial.q"
    data = scenario()
    data["maneuver"]["initial"]["q"] = None
    assert refused(data).path == "maneuver.initial.q"


def test_an_initial_pointing_target_is_taken_at_t0():
    nadir = {"point": {"sensor": "camera", "at": "earth", "secondary": {"axis": [1, 0, 0], "toward": "velocity"}}}
    loaded = parsed(initial=nadir)
    np.testing.assert_allclose(quat.rotation_matrix(loaded.problem.q0), lvlh_by_hand(geometry(), 0.0), atol=1e-12)
    later = parsed(initial={**nadir, "at_time_s": 60.0})
    np.testing.assert_allclose(quat.rotation_matrix(later.problem.q0), lvlh_by_hand(geometry(), 60.0), atol=1e-12)
