"""Limits of the two-wheel laws (Horri & Palmer) that a scenario must respect to be meaningful."""
import copy
from pathlib import Path

import numpy as np
import pytest

import scenarios
from controllers import CONTROLLERS
from ocp import ReactionWheels, Spacecraft
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
