"""The unrealised torque's bound is stored with its score (``unrealised_torque_allowed``, 1 % of the
reference's peak torque), so the sign-off record says whether that quantity is within it: it said
``within bound: -`` beside a bound in words. And a requirement broken by another quantity reads
``yes`` under "this quantity within its bound" beside the requirement's ``broken``."""
from __future__ import annotations

import copy
import math

import pytest

import scenarios
from scenarios.output.report.record import requirement_lines
from tests.test_requirement_fields import ONE_WHEEL


@pytest.fixture(scope="module")
def one_wheel():
    return scenarios.run(scenarios.parse_scenario(copy.deepcopy(ONE_WHEEL)))


def _lines(results) -> dict[str, list]:
    """The reference's actuator lines by quantity (the closed loop's, with the same names, are
    scored since its wheel momentum is a requirement too)."""
    return {line[3]: line for line in requirement_lines(results) if line[1:3] == ["reference", "actuators"]}


def test_the_bound_is_one_percent_of_the_peak_torque_asked_and_the_record_compares_with_it(one_wheel):
    """90 deg about y on a sphere (I = 2 kg m²) with one wheel on x: the quintic asks
    2 x 5.7735 θ / T² N m about y at its peak, all of it unrealised."""
    peak = 2.0 * 5.7735 * (math.pi / 2.0) / 60.0**2
    score = one_wheel.rows[0].requirements["reference"]["actuators"]
    assert score["unrealised_torque_allowed"] == pytest.approx(0.01 * peak, rel=1e-3)
    line = _lines(one_wheel)["unrealised_torque"]
    assert line[4] == "N m" and line[5].startswith("≤ ") and float(line[5][2:]) == pytest.approx(0.01 * peak, rel=1e-3)
    assert (line[8], line[9]) == ("no", "broken")


def test_a_quantity_within_its_bound_beside_a_requirement_broken_by_another(one_wheel):
    """The tester's natural-motion row: a rate jump breaks the actuator requirement while the
    unrealised torque is rounding (1.65e-20 N m against 1e-4 N m)."""
    row = one_wheel.rows[0]
    saved = row.requirements["reference"]["actuators"]
    try:
        row.requirements["reference"]["actuators"] = {
            "met": False, "wheels_torque": 0.0105, "wheels_torque_time_s": 67.7, "rate_jump": 0.0285,
            "rate_jump_time_s": 80.0, "unrealised_torque": 1.65e-20, "unrealised_torque_time_s": 19.8,
            "unrealised_torque_allowed": 1e-4}
        lines = _lines(one_wheel)
        assert (lines["unrealised_torque"][5], lines["unrealised_torque"][8]) == ("≤ 0.0001", "yes")
        assert lines["rate_jump"][8] == "no"
        assert {line[9] for line in lines.values()} == {"broken"}
        del row.requirements["reference"]["actuators"]["unrealised_torque_allowed"]  # a run scored before
        assert _lines(one_wheel)["unrealised_torque"][8] == "-"
    finally:
        row.requirements["reference"]["actuators"] = saved
