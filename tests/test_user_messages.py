"""Messages a first user found unclear (report D6): each names the value as written, the key the
user set, and how to fix it."""
from __future__ import annotations

import copy
import re

import pytest

from scenarios import parse_scenario
from scenarios.errors import ScenarioError
from scenarios.study.spec import parse_study
from tests.test_sweep import BASE


def _error(call, *args) -> ScenarioError:
    with pytest.raises(ScenarioError) as caught:
        call(*args)
    return caught.value


def test_a_nan_quaternion_names_the_value():
    data = copy.deepcopy(BASE)
    data["maneuver"]["final"]["q"] = [float("nan"), 0, 0, 1]
    error = _error(parse_scenario, data)
    assert error.path == "maneuver.final.q"
    assert "finite" in error.message and "nan" in error.message.lower(), error.message


def test_an_infinite_entry_is_shown_where_it_is():
    data = copy.deepcopy(BASE)
    data["spacecraft"]["inertia"] = [2.0, float("inf"), 4.0]
    error = _error(parse_scenario, data)
    assert error.path == "spacecraft.inertia"
    assert "inf" in error.message and "[1]" in error.message, error.message


def test_a_scale_of_a_value_the_base_scenario_lacks_says_to_add_it_there():
    study = {"study": "s", "scenario": copy.deepcopy(BASE), "monte_carlo": {"samples": 2, "seed": 1, "dispersions": {
        "truth.spacecraft.inertia": {"scale": {"uniform": {"low": [0.9, 0.9, 0.9], "high": [1.1, 1.1, 1.1]}}}}}}
    error = _error(parse_study, study)
    assert "truth" in str(error) and "base scenario" in str(error)
    assert "scale" in error.message and "add truth.spacecraft.inertia to the base scenario" in error.message, \
        error.message


def test_a_linspace_count_of_zero_is_shown_as_written():
    study = {"study": "s", "scenario": copy.deepcopy(BASE), "grid": {"maneuver.duration": {"linspace": [20, 30, 0]}}}
    error = _error(parse_study, study)
    assert error.path.endswith("linspace[2]")
    assert re.search(r"got 0\b(?!\.)", error.message), error.message


def test_a_linspace_count_that_is_not_whole_is_shown_as_written():
    study = {"study": "s", "scenario": copy.deepcopy(BASE), "grid": {"maneuver.duration": {"linspace": [20, 30, 2.5]}}}
    assert "got 2.5" in _error(parse_study, study).message


def test_a_long_sample_time_names_sample_time_and_the_default_max_step():
    data = copy.deepcopy(BASE)
    data["simulation"]["sample_time"] = 100.0
    error = _error(parse_scenario, data)
    assert error.path == "simulation.sample_time", str(error)
    assert "100" in error.message and "max_step" in error.message and "0.05" in error.message, error.message
    assert "default" in error.message, error.message


def test_a_max_step_the_user_set_is_still_blamed_on_max_step():
    data = copy.deepcopy(BASE)
    data["simulation"]["max_step"] = 0.001
    data["simulation"]["sample_time"] = 5.0
    error = _error(parse_scenario, data)
    assert error.path == "simulation.max_step", str(error)
    assert "0.001" in error.message and "5" in error.message
