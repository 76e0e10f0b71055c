"""A GNC user's schema findings, each failing before its fix.

* A misspelt ``keep_out`` (or an attitude form, or a ``point`` axis) was reported as "give exactly
  one of ...", not as the unknown key it is.
* A quaternion refused for its norm did not show the value nor how to fix it.
* ``simulation.initial_rate_error`` in deg/s (typed as rad/s) passed ``validate`` silently, while the
  same slip in ``maneuver.initial.omega`` is noted.
* A spacecraft whose every wheel is failed, without other actuators, was accepted with a tracking
  controller (rows then "infeasible" or 90 deg off the target).

Bad input is exit 2 on the command line, the message naming the YAML path, the value and what was
expected, never a traceback.
"""
from __future__ import annotations

import contextlib
import copy
import io
from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.schema.checks import rate_bound_notes
from scenarios.schema.loader import parse_scenario
from scenarios.schema.read import read_yaml

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
KEEP_OUT = read_yaml(SCENARIOS / "cubesat_12u_sun_keep_out.yaml")
KEEP_OUT["epoch"] = "2027-03-20T12:00:00Z"  # as a user writes it (a date-time object does not dump as such)

PYRAMID = [[0.5773503, 0.5773503, 0.5773503], [-0.5773503, 0.5773503, 0.5773503],
           [-0.5773503, -0.5773503, 0.5773503], [0.5773503, -0.5773503, 0.5773503]]


def small(**changes) -> dict:
    """A 12U CubeSat on four pyramid wheels, 90 deg about z in 60 s, no orbit nor epoch (fast to load)."""
    data = {"name": "user-a", "spacecraft": {"inertia": [0.25, 0.28, 0.12],
                                             "wheels": {"axes": PYRAMID, "max_torque": 0.002, "max_momentum": 0.018}},
            "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                         "final": {"q": [0.7071068, 0, 0, 0.7071068], "omega": [0, 0, 0]}},
            "planners": [{"name": "eigenaxis"}], "controller": {"name": "augmented_quaternion_feedback"},
            "simulation": {"sample_time": 0.5}, "requirements": {"rate": {"max": 0.05}}}
    for path, value in changes.items():
        node = data
        keys = path.split("__")
        for key in keys[:-1]:
            node = node.setdefault(key, {})
        node[keys[-1]] = value
    return data


def refused(data: dict) -> ScenarioError:
    with pytest.raises(ScenarioError) as error:
        parse_scenario(copy.deepcopy(data))
    return error.value


def validate(tmp_path: Path, data: dict) -> tuple[int, str, str]:
    """``slewbench validate`` on ``data``; (exit status, stdout, stderr)."""
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(["validate", str(path)])
    return status, out.getvalue(), err.getvalue()


# -- 1. a misspelt key where exactly one of two is wanted ---------------------------------------------


def test_a_misspelt_keep_out_is_named_as_the_unknown_key_on_the_command_line(tmp_path):
    data = copy.deepcopy(KEEP_OUT)
    data["requirements"]["pointing"]["st_sun"] = {"sensor": "star_tracker", "keepout": "sun", "angle_deg": 30}
    status, _, error = validate(tmp_path, data)
    assert status == 2, error
    assert f"error in scenario: {tmp_path / 'case.yaml'}: requirements.pointing.st_sun.keepout: unknown key 'keepout'" \
        in error, error
    assert "a misspelling of 'keep_out'?" in error and "exactly one of keep_out and keep_in" in error, error
    assert "Traceback" not in error


@pytest.mark.parametrize(("final_q", "path", "meant"), [
    ({"quaternon": [1, 0, 0, 0]}, "maneuver.final.q.quaternon", "'quaternion'"),
    ({"axisangle": {"axis": [0, 0, 1], "angle_deg": 90}}, "maneuver.final.q.axisangle", "'axis_angle'"),
    ({"point": {"bore_sight": [0, 0, 1], "at": {"inertial": [1, 0, 0]},
                "secondary": {"axis": [1, 0, 0], "toward": {"inertial": [0, 0, 1]}}}},
     "maneuver.final.q.point.bore_sight", "'boresight'"),
    ({"point": {"boresight": [0, 0, 1], "at": {"inertial": [1, 0, 0]},
                "secondary": {"axes": [1, 0, 0], "toward": {"inertial": [0, 0, 1]}}}},
     "maneuver.final.q.point.secondary.axes", "'axis'"),
])
def test_every_exactly_one_of_names_a_misspelt_key(final_q, path, meant):
    error = refused(small(maneuver__final__q=final_q))
    assert error.path == path, error
    assert f"unknown key {path.rsplit('.', 1)[1]!r}: a misspelling of {meant}?" in error.message, error


def test_a_keep_out_misspelt_beyond_recognition_still_says_which_keys_are_wanted():
    data = copy.deepcopy(KEEP_OUT)
    data["requirements"]["pointing"]["st_sun"] = {"sensor": "star_tracker", "avoid": "sun", "angle_deg": 30}
    error = refused(data)
    assert error.path == "requirements.pointing.st_sun", error
    assert error.message == "give exactly one of keep_out and keep_in; got none of them", error


# -- 2. a quaternion refused for its norm says what to write --------------------------------------------


def test_a_quaternion_refused_for_its_norm_shows_the_value_and_the_normalised_one():
    error = refused(small(maneuver__final__q=[1.4142, 0, 0, 1.4142]))
    assert error.path == "maneuver.final.q", error
    norm = np.hypot(1.4142, 1.4142)  # 1.99999, by hand
    assert f"got norm {norm:.6g}" in error.message and "[1.4142, 0, 0, 1.4142]" in error.message, error
    assert "normalise it (q / ‖q‖ = [0.7071068, 0.0, 0.0, 0.7071068])" in error.message, error


# -- 3. the true initial rate against the rate requirement ------------------------------------------------


def test_an_initial_rate_error_in_deg_per_s_is_noted_like_an_initial_rate():
    scenario = parse_scenario(small(simulation__initial_rate_error=[1, 0, 0]))
    notes = rate_bound_notes(scenario.problem, scenario.simulation, 0.05)
    assert notes == ["every row's closed loop breaks the rate requirement: simulation.initial_rate_error "
                     "[1.0, 0.0, 0.0] starts it at ‖ω‖ = 1 rad/s (maneuver.initial.omega plus the error), above "
                     "0.05 rad/s (the key is in rad/s)"]


def test_a_plausible_rate_error_is_not_noted_and_a_large_initial_rate_is_noted_once():
    scenario = parse_scenario(small(simulation__initial_rate_error=[0.0, 0.002, -0.002]))
    assert rate_bound_notes(scenario.problem, scenario.simulation, 0.05) == []
    # 0.049 + 0.002 = 0.051 rad/s > 0.05: the error alone takes it over the bound
    scenario = parse_scenario(small(maneuver__initial__omega=[0.049, 0, 0], simulation__initial_rate_error=[0.002, 0, 0]))
    assert len(rate_bound_notes(scenario.problem, scenario.simulation, 0.05)) == 1
    scenario = parse_scenario(small(maneuver__initial__omega=[0, 0, 5], simulation__initial_rate_error=[0, 0, 0.01]))
    assert rate_bound_notes(scenario.problem, scenario.simulation, 0.05) == [
        "every row breaks the rate requirement: maneuver.initial.omega has ‖ω‖ = 5 rad/s, above 0.05 rad/s"]


# -- 4. no working actuator -------------------------------------------------------------------------------


def test_every_wheel_failed_without_other_actuators_is_refused_at_the_failed_list(tmp_path):
    data = small(spacecraft__wheels__failed=[0, 1, 2, 3])
    status, _, error = validate(tmp_path, data)
    assert status == 2, error
    assert f"error in scenario: {tmp_path / 'case.yaml'}: spacecraft.wheels.failed: [0, 1, 2, 3]: every one of the 4 " \
        "wheels is failed" in error
    assert "controller.name 'augmented_quaternion_feedback' has nothing to steer with" in error, error
    assert "Traceback" not in error


def test_no_wheels_and_no_other_actuator_is_refused_at_the_wheels():
    error = refused(small(spacecraft__wheels=None))
    assert error.path == "spacecraft.wheels" and "no working actuator" in error.message, error


@pytest.mark.parametrize("changes", [
    {"spacecraft__wheels__failed": [0, 1, 2]},                                      # one wheel left
    {"spacecraft__wheels__failed": [0, 1, 2, 3], "spacecraft__torquers": {"max_torque": 0.001}},
    {"spacecraft__wheels__failed": [0, 1, 2, 3], "controller": {"name": "none"}},   # a torque-free run
], ids=["one wheel", "torquers", "torque-free"])
def test_a_spacecraft_with_an_actuator_or_a_law_that_steers_nothing_is_accepted(changes):
    parse_scenario(small(**changes))


def test_a_detumbling_study_with_failed_wheels_and_magnetorquers_is_accepted():
    data = read_yaml(SCENARIOS / "nano_detumble.yaml")
    data["spacecraft"]["wheels"] = {"failed": [0, 1, 2]}
    parse_scenario(data)


# -- with ocp.quat.UNIT_NORM_TOLERANCE 1e-3 and validate printing rate_bound_notes ---------------------


@pytest.mark.parametrize("q", [[0.7071, 0.7071, 0, 0], [0.707, 0.707, 0, 0], [0.707, 0, 0.5, 0.5],
                               [0.5, 0.5, 0.5, 0.5], [0.7071068, 0, 0.5, 0.5]])
def test_a_quaternion_typed_with_3_or_more_decimals_is_accepted(q):
    parse_scenario(small(maneuver__final__q=q))


def test_a_quaternion_of_norm_0995_is_refused_with_its_norm_and_a_hint():
    error = refused(small(maneuver__final__q=[0.7, 0, 0.5, 0.5]))
    assert error.path == "maneuver.final.q", error
    assert "got norm 0.994987" in error.message and "tolerance 1e-3" in error.message, error  # sqrt(0.99)
    assert "[0.7, 0, 0.5, 0.5]" in error.message and "normalise it" in error.message, error


def test_validate_notes_an_initial_rate_error_in_deg_per_s(tmp_path):
    status, out, error = validate(tmp_path, small(simulation__initial_rate_error=[1, 0, 0]))
    assert status == 0, error
    assert "  every row's closed loop breaks the rate requirement: simulation.initial_rate_error [1.0, 0.0, 0.0]" in out


# --- an unknown key beside a missing required one ---------------------------------------------------

@pytest.mark.parametrize(("edit", "unknown", "missing"), [
    # a TLE or apsides given to the circular orbit: said only that altitude_km is missing
    (lambda d: d.__setitem__("orbit", {"tle": "1 25544U 98067A"}), "orbit.tle", "orbit.altitude_km"),
    (lambda d: d.__setitem__("orbit", {"perigee_km": 800, "apogee_km": 500}), "orbit.perigee_km", "orbit.altitude_km"),
    # a keep-out direction under a key its mapping form does not have (a Section's read)
    (lambda d: d["requirements"]["pointing"]["st_sun"].__setitem__("keep_out", {"body": [1, 0, 0]}),
     "requirements.pointing.st_sun.keep_out.body", "requirements.pointing.st_sun.keep_out.inertial"),
])
def test_an_unknown_key_beside_a_missing_required_one_is_named_first(tmp_path, capsys, edit, unknown, missing):
    """The key the user wrote is the mistake to see: the error is at it, and says the missing one."""
    data = read_yaml(Path(__file__).resolve().parents[1] / "scenarios" / "cubesat_12u_sun_keep_out.yaml")
    edit(data)
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))  # the first unknown key as written
    assert main(["validate", str(path)]) == 2
    err = " ".join(capsys.readouterr().err.split())
    assert f": {unknown}: unknown key; expected one of [" in err, err
    assert f"({missing}: required key is missing)" in err, err
