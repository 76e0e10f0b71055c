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


# --- slewbench table: the work it is asked for (report D5) ---

def _table_scenario(tmp_path):
    import yaml
    path = tmp_path / "tiny.yaml"
    path.write_text(yaml.safe_dump(copy.deepcopy(BASE)))
    return path


def test_a_bare_angle_count_over_the_entry_limit_is_refused_before_anything_is_written(tmp_path, capsys):
    """``--angles 90`` is 90 angles: 30 axes x 90 = 2700 solves, over the default 2000."""
    from scenarios.cli.commands import main
    out = tmp_path / "out"
    status = main(["table", str(_table_scenario(tmp_path)), "--grid", "fibonacci", "--axes", "30", "--angles", "90",
                   "--out", str(out), "--no-plots"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "30 axes x 90 angles = 2700 entries, more than 2000" in err
    assert "not 90 deg" in err and "--max-entries 2700" in err
    assert not out.exists()


def test_max_entries_sets_the_limit_and_a_list_of_angles_gets_no_count_hint(tmp_path, capsys):
    from scenarios.cli.commands import main
    out = tmp_path / "out"
    status = main(["table", str(_table_scenario(tmp_path)), "--grid", "fibonacci", "--axes", "10", "--angles", "30,90",
                   "--max-entries", "19", "--out", str(out), "--no-plots"])
    err = capsys.readouterr().err
    assert status == 2 and "10 axes x 2 angles = 20 entries, more than 19" in err, err
    assert "means" not in err and not out.exists()
    assert main(["table", str(_table_scenario(tmp_path)), "--max-entries", "0", "--out", str(out)]) == 2
    assert "--max-entries: expected a positive number" in capsys.readouterr().err


def test_a_polytope_grid_says_how_many_axes_it_has_when_not_the_count_asked(tmp_path, capsys):
    """Three body-axis wheels of one torque: the torque polytope is a cube, whose 8 vertices and 6
    face centres are the fewest axes its grid has."""
    from scenarios.cli.commands import main
    status = main(["table", str(_table_scenario(tmp_path)), "--axes", "4", "--angles", "30,90", "--max-entries", "1",
                   "--out", str(tmp_path / "out"), "--no-plots"])
    captured = capsys.readouterr()
    assert status == 2
    assert "4 axes asked for, the polytope grid has 14" in captured.out, captured.out
    assert "--grid fibonacci gives exactly 4" in captured.out
    assert "14 axes x 2 angles = 28 entries" in captured.err
