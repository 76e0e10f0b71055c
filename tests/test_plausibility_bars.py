"""The plausibility bars of rates: a rate bound of exactly 1 rad/s (1 deg/s written in a rad/s
field) warns, as one above it does (the bar is inclusive); the tolerances on a rate left over
(``requirements.final.rate``, ``simulation.detumble_tolerance``) have their own bar, 0.1 rad/s
(5.7 deg/s, faster than any spacecraft slews), so that 0.5 deg/s written as 0.5 warns. Each
warning names the YAML path, the value and what was expected.

Oracles: the unit conversions by hand (1 rad/s = 57.3 deg/s; 1 deg/s = 0.01745 rad/s; 0.5 deg/s =
0.008727 rad/s) and the bars as the module states them.
"""
from __future__ import annotations

import pytest

from scenarios.schema.plausibility import MAX_RATE, MAX_RATE_TOLERANCE
from tests.test_plausibility import warnings_of


def set_path(path: str, value: float):
    def change(data):
        node = data
        *sections, key = path.split(".")
        for name in sections:
            if not isinstance(node.get(name), dict):
                node[name] = {}
            node = node[name]
        node[key] = value
    return change


@pytest.mark.parametrize("path", ["maneuver.max_rate", "requirements.rate.max"])
def test_a_rate_bound_of_exactly_one_rad_per_second_warns(path):
    assert MAX_RATE == 1.0
    said = warnings_of(set_path(path, 1.0))
    assert len(said) == 1, said
    assert said[0].startswith(f"{path}: 1 rad/s is 57 deg/s, at or above 1 rad/s (57 deg/s)"), said
    assert "did you mean 0.01745 rad/s (1 deg/s)?" in said[0], said
    assert warnings_of(set_path(path, 0.99)) == []  # just under the bar: a fast slew, not a slip


def test_a_boundary_rate_of_exactly_one_rad_per_second_the_wheels_cannot_take_warns():
    said = warnings_of(lambda d: d["maneuver"]["initial"].update(omega=[1.0, 0.0, 0.0]))
    assert len(said) == 1 and said[0].startswith("maneuver.initial.omega: [1.0, 0.0, 0.0] rad/s"), said
    assert "at or above 1 rad/s" in said[0] and "did you mean [0.017453, 0.0, 0.0]" in said[0], said


@pytest.mark.parametrize("path", ["requirements.final.rate", "simulation.detumble_tolerance"])
def test_a_rate_tolerance_in_degrees_per_second_warns_under_the_bounds_bar(path):
    assert MAX_RATE_TOLERANCE == 0.1 < MAX_RATE
    said = warnings_of(set_path(path, 0.5))  # 0.5 deg/s meant: under 1 rad/s, the rate bounds' bar
    assert len(said) == 1, said
    assert said[0].startswith(f"{path}: 0.5 rad/s is 28.6 deg/s, at or above 0.1 rad/s (5.7 deg/s)"), said
    assert "a tolerance that a spacecraft still slewing as fast as any does would meet" in said[0], said
    assert "did you mean 0.008727 rad/s (0.5 deg/s)?" in said[0], said
    assert len(warnings_of(set_path(path, 0.1))) == 1  # the bar itself warns
    assert warnings_of(set_path(path, 0.05)) == []  # 2.9 deg/s: loose, not implausible


def test_a_plausible_tolerance_does_not_warn():
    def change(data):
        data.setdefault("requirements", {})["final"] = {"error_deg": 1.0, "rate": 0.001}
        data.setdefault("simulation", {})["detumble_tolerance"] = 0.01
    assert warnings_of(change) == []
