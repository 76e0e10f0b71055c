"""Hostile numbers in a scenario: each a one-line error naming the YAML path, the value and what is
expected, with nothing printed before it (NumPy's overflow warnings) and no hang.

- a quaternion with entries of 1e300: its norm overflowed (NumPy's RuntimeWarning, then "must be
  finite" said of finite entries);
- ``simulation.initial_rate_error`` of 1e300 rad/s: accepted (its norm inf in a warning);
- an inertia of 1e300 kg m²: accepted with NumPy's overflow warning and a 150-digit bound; one of
  1e-250 kg m²: ``slewbench run`` hung in the torque-free coast of a bang-coast-bang row.
"""
from __future__ import annotations

import copy
import warnings
from pathlib import Path

import pytest

from scenarios.errors import ScenarioError
from scenarios.schema.loader import parse_scenario
from scenarios.schema.read import read_yaml

ROOT = Path(__file__).resolve().parents[1]
DEMO = read_yaml(ROOT / "scenarios" / "eigenaxis_demo.yaml")
TRUTH = read_yaml(ROOT / "scenarios" / "eigenaxis_truth.yaml")


def refused(base: dict, path: str, value) -> str:
    data = copy.deepcopy(base)
    node = data
    *parents, key = path.split(".")
    for name in parents:
        node = node.setdefault(name, {})
    node[key] = value
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing may warn on the way to the error
        with pytest.raises(ScenarioError) as raised:
            parse_scenario(data)
    assert raised.value.path == path, raised.value
    return raised.value.message


@pytest.mark.parametrize("q, norm", [([1e300, 1e300, 0, 0], "1.41421e+300"), ([1e200, 0, 0, 0], "1e+200"),
                                     ([1.7e308] * 4, "beyond a float's range")])
def test_a_quaternion_whose_norm_overflows_says_its_norm_and_the_unit_one(q, norm):
    message = refused(DEMO, "maneuver.initial.q", q)
    assert message.startswith(f"a quaternion must have unit norm (got norm {norm}) for "), message
    assert "q / ‖q‖ = [" in message, message


def test_an_initial_rate_error_beyond_any_body_rate_is_refused():
    message = refused(DEMO, "simulation.initial_rate_error", [1e300, 0, 0])
    assert message == "expected entries within ±1000, got [1e+300, 0.0, 0.0]", message


@pytest.mark.parametrize("inertia, said", [
    ([1e300, 1e300, 1e300], "expected entries within ±1e+12 kg m²"),
    ([[1e13, 0, 0], [0, 1e13, 0], [0, 0, 1e13]], "expected entries within ±1e+12 kg m²"),
    ([1e-250, 1e-250, 1e-250], "expected a least principal moment of at least 1e-09 kg m²"),
    ([[1.0, 0, 0], [0, 1.0, 0.999999999999], [0, 0.999999999999, 1.0]], "got 1e-12 kg m²"),  # 1 - 0.999999999999
])
def test_an_inertia_beyond_any_spacecraft_is_refused_at_its_path(inertia, said):
    assert said in refused(DEMO, "spacecraft.inertia", inertia)


def test_the_truths_inertia_has_the_same_bounds():
    assert "at least 1e-09 kg m²" in refused(TRUTH, "truth.spacecraft.inertia", [1e-250, 1e-250, 1e-250])


def test_the_bounds_leave_real_spacecraft_alone():
    for inertia in ([1e8, 1e8, 1.2e8], [2e-7, 3e-7, 4e-7]):  # the ISS's order; a chip-sat's
        data = copy.deepcopy(DEMO)
        data["spacecraft"]["inertia"] = inertia
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the torque bound warns on these; only acceptance is judged
            parse_scenario(data)


def test_an_integer_beyond_pythons_digit_limit_names_its_path(tmp_path):
    """5,000 digits: Python's int() refuses text beyond 4,300 digits, and the message said only 'a
    value cannot be read: Exceeds the limit ... use sys.set_int_max_str_digits()'."""
    from scenarios.schema.read import read_yaml as read
    path = tmp_path / "big.yaml"
    path.write_text("name: big\nmaneuver:\n  duration: " + "9" * 5000 + "\n")
    with pytest.raises(ScenarioError) as raised:
        read(path)
    assert raised.value.path == "maneuver.duration" and raised.value.file == path, raised.value
    assert "(5000 characters, line 3) is an integer beyond any number" in raised.value.message, raised.value
    assert "set_int_max_str_digits" not in str(raised.value)


def test_a_long_written_out_list_is_not_called_an_alias_bomb(tmp_path, monkeypatch):
    from scenarios.schema import read as reader
    from scenarios.schema.read import read_yaml as read
    monkeypatch.setattr(reader, "MAX_NODES", 1000)  # the limit's logic at a size that parses fast
    path = tmp_path / "long.yaml"
    path.write_text("grid:\n  maneuver.duration: [" + ", ".join(["1"] * 1010) + "]\n")
    with pytest.raises(ScenarioError) as raised:
        read(path)
    assert raised.value.file == path and raised.value.path.startswith("grid.maneuver.duration["), raised.value
    assert "holds more than 1000 values" in raised.value.message and "alias" not in raised.value.message
    bomb = tmp_path / "bomb.yaml"  # nine aliases of nine, three levels deep: 9**4 values from a few lines
    bomb.write_text("a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{b}: &{b} [{', '.join([f'*{a}'] * 9)}]\n" for a, b in zip("abc", "bcd")))
    with pytest.raises(ScenarioError) as raised:
        read(bomb)
    assert "alias bomb" in raised.value.message and raised.value.file == bomb, raised.value


@pytest.mark.parametrize("form, path", [
    ({"axis_angle": {"axis": [0, 0, 1], "angle_deg": 1e300}}, "maneuver.final.q.axis_angle.angle_deg"),
    ({"euler": {"angles_deg": [1e300, 0, 0], "sequence": "321"}}, "maneuver.final.q.euler.angles_deg"),
])
def test_an_attitude_angle_beyond_a_turn_is_refused(form, path):
    """1e300 deg was accepted: cos and sin of it are rounding noise, an attitude no one wrote (the
    plausibility checks say the schema bounds every angle)."""
    data = copy.deepcopy(DEMO)
    data["maneuver"]["final"]["q"] = form
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(data)
    assert raised.value.path == path and "360" in raised.value.message and "1e+300" in raised.value.message


def test_an_attitude_angle_of_a_turn_or_less_is_kept():
    for angle in (-360.0, 270.0):
        data = copy.deepcopy(DEMO)
        data["maneuver"]["final"]["q"] = {"axis_angle": {"axis": [0, 0, 1], "angle_deg": angle}}
        parse_scenario(data)


def test_a_disturbance_torque_beyond_any_spacecrafts_is_refused():
    """1e300 N m was valid without a warning (its norm inf, read as unlimited) and NumPy's overflow
    warnings were printed."""
    assert refused(DEMO, "environment.disturbance_torque", [1e300, 0, 0]) == \
        "expected entries within ±1e+06, got [1e+300, 0.0, 0.0]"


def test_a_yaml_boolean_where_a_number_is_expected_says_where_it_came_from():
    """``duration: yes`` read as True: the message said 'got True' of a file that says yes."""
    data = copy.deepcopy(DEMO)
    data["maneuver"]["duration"] = yaml_boolean = True  # what YAML makes of an unquoted yes
    with pytest.raises(ScenarioError) as raised:
        parse_scenario(data)
    assert raised.value.path == "maneuver.duration" and yaml_boolean
    assert raised.value.message == ("expected a number, got True (a YAML boolean: unquoted yes, no, on, off, true and "
                                    "false are read as one)"), raised.value
