"""Limits of the detumbling laws that the loader checks against the run."""
import copy
from pathlib import Path

import pytest

import scenarios
from scenarios.errors import ScenarioError
from scenarios.schema.read import read_yaml

SCENARIO = Path(__file__).parent.parent / "scenarios" / "nano_detumble.yaml"


def detumble(delay, maneuver_duration, simulation_duration=None):
    data = copy.deepcopy(read_yaml(SCENARIO))
    data["maneuver"]["duration"] = maneuver_duration
    data["controllers"][1]["options"]["delay"] = delay
    if simulation_duration is not None:
        data["simulation"]["duration"] = simulation_duration
    return data


@pytest.mark.parametrize("delay,maneuver,simulation,source", [
    (5000.0, 3000.0, None, "maneuver.duration is 3000 s"),     # the user's: tdfc never acted, row ok
    (3000.0, 3000.0, None, "maneuver.duration is 3000 s"),     # the first reading that old comes at the end
    (4000.0, 6000.0, 3000.0, "simulation.duration is 3000 s"),  # the window, not the manoeuvre, decides
])
def test_tdfc_delay_not_shorter_than_the_run_is_refused(delay, maneuver, simulation, source):
    with pytest.raises(ScenarioError, match="never acts") as error:
        scenarios.parse_scenario(detumble(delay, maneuver, simulation))
    assert error.value.path == "controllers[1].options.delay"
    assert source in str(error.value)


@pytest.mark.parametrize("delay,maneuver,simulation", [(2999.0, 3000.0, None), (4000.0, 3000.0, 5000.0)])
def test_tdfc_delay_shorter_than_the_run_is_accepted(delay, maneuver, simulation):
    scenario = scenarios.parse_scenario(detumble(delay, maneuver, simulation))
    assert scenario.controllers[1].options.delay == delay
