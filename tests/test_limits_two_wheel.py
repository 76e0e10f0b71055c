"""Limits of the two-wheel laws (Horri & Palmer) that a scenario must respect to be meaningful."""
import copy
from pathlib import Path

import numpy as np
import pytest

import scenarios
from controllers import CONTROLLERS
from ocp import ReactionWheels, Simulator, Spacecraft, quat
from planners import ManeuverProblem
from scenarios.errors import ScenarioError
from scenarios.schema.read import read_yaml

SCENARIO = Path(__file__).parent.parent / "scenarios" / "horri_palmer_two_wheels.yaml"
LAWS = ("singular_zero_momentum", "singular_rate_tracking", "min_norm", "gain_scheduled_min_norm")
INERTIA = np.array([40.45, 42.09, 42.36])


def regulation(initial):
    data = copy.deepcopy(read_yaml(SCENARIO))
    data["planners"] = []
    data["maneuver"]["initial"].update(initial)
    return data


def test_momentum_in_the_failed_wheel_is_refused_at_its_yaml_path():
    # z wheel failed: I_z ω_z = 42.36 x 0.01 = 0.4236 N m s balanced by the failed wheel, total zero
    data = regulation({"omega": [0, 0, 0.01], "wheel_momentum": [0, 0, -0.4236]})
    with pytest.raises(ScenarioError, match="failed wheel") as error:
        scenarios.parse_scenario(data)
    assert error.value.path == "maneuver.initial.wheel_momentum"


@pytest.mark.parametrize("name", LAWS)
def test_every_law_refuses_failed_wheel_momentum_and_takes_a_balanced_working_one(name):
    law = CONTROLLERS[name]()
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.02, failed=[2]))
    refused = law.initial_state_error(spacecraft, np.array([0.0, 0.0, 0.01]), np.array([0.0, 0.0, -0.4236]), None)
    assert refused is not None and refused[0] == "initial.wheel_momentum" and "[2]" in refused[1]
    # the same spin stored in a working wheel is the laws' zero-momentum case: accepted
    assert law.initial_state_error(spacecraft, np.array([0.01, 0.0, 0.0]), np.array([-0.4045, 0.0, 0.0]), None) is None


def simulate(name, q0, duration=600.0):
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.02, failed=[2]))
    problem = ManeuverProblem(spacecraft, q0, np.zeros(3), quat.IDENTITY, duration, omegaf=np.zeros(3))
    return Simulator(problem.model, 1.0).run(CONTROLLERS[name](), problem.initial_state, duration,
                                             target=(problem.qf, problem.omegaf))


@pytest.mark.parametrize("name", LAWS)
def test_an_error_about_the_unactuated_axis_is_outside_the_laws_domain(name):
    # 90 deg about z (the failed wheel's axis): q1 = q2 = 0, the singular ratios 0/0; from rest each
    # law gives no torque at all, while 1e-6 rad off that axis it turns the body (the paper's Ω)
    about_z = quat.from_axis_angle(np.array([0.0, 0.0, 1.0]), np.pi / 2)
    stuck = simulate(name, about_z)
    assert np.all(stuck.omega == 0.0)
    assert np.rad2deg(quat.error_angle(stuck.q[-1], quat.IDENTITY)) == pytest.approx(90.0, abs=1e-9)
    nudged = simulate(name, quat.product(about_z, quat.from_rotation_vector(np.array([1e-6, 0.0, 0.0]))))
    assert np.max(np.abs(nudged.omega)) > 1e-4
    law = CONTROLLERS[name]()
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.02, failed=[2]))
    rest = np.zeros(3)
    refused = law.initial_attitude_error(spacecraft, about_z, rest, quat.IDENTITY)
    assert refused is not None and refused[0] == "initial.q" and "90 deg" in refused[1]
    assert law.initial_attitude_error(spacecraft, nudged.q[0], rest, quat.IDENTITY) is None
    assert law.initial_attitude_error(spacecraft, quat.IDENTITY, rest, quat.IDENTITY) is None  # at the target
    # turning about an actuated axis (x), the body leaves the set at once: accepted
    assert law.initial_attitude_error(spacecraft, about_z, np.array([0.005, 0.0, 0.0]), quat.IDENTITY) is None


def test_a_start_about_the_unactuated_axis_that_turns_about_an_actuated_one_runs():
    """90 deg about z with ω0 = 0.005 rad/s about x held by the x wheel (zero total momentum): the
    body leaves q1 = q2 = 0 at once and every law turns it (a reviewer's case, refused before)."""
    data = regulation({"q": [0.0, 0.0, 0.70710678, 0.70710678], "omega": [0.005, 0.0, 0.0],
                       "wheel_momentum": [-INERTIA[0] * 0.005, 0.0, 0.0]})
    scenarios.parse_scenario(data)  # accepted (it raised ScenarioError at maneuver.initial.q)


def test_the_loader_refuses_a_start_about_the_unactuated_axis_unless_perturbed():
    data = regulation({"q": [0, 0, 1, 0]})  # scalar last: 180 deg about z, the failed wheel's axis
    with pytest.raises(ScenarioError, match="q1² \\+ q2² ≠ 0") as error:
        scenarios.parse_scenario(data)
    assert error.value.path == "maneuver.initial.q"
    # the simulated start is what counts: perturbed off the axis, it is in the domain
    data["simulation"]["initial_attitude_error_deg"] = [1.0, -1.0, 0.5]
    scenarios.parse_scenario(data)
