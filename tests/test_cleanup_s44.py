"""A planner that cannot take a problem refuses the scenario at load, before anything runs, at its
``planners[i]`` entry (docs/guide/scenarios.rst, "When a planner or a controller cannot take a
scenario"; the contract of ``Planner.problem_error``): the spin extremals on a fixed final rate as
natural_motion on a non-zero one, through ``slewbench run``."""
from __future__ import annotations

import pytest
import yaml

from scenarios.cli.commands import main

REST_TO_REST = {
    "name": "rest-to-rest-four-planners",
    "spacecraft": {"inertia": [0.0109, 0.05, 0.05], "wheels": {}},
    "maneuver": {"duration": 110.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0.5, 0.5, 0.5], "omega": [0, 0, 0]}},
    "planners": [{"name": "natural_motion", "options": {"stop_time": 10.0}},
                 {"name": "eigenaxis", "options": {"profile": "smooth"}},
                 {"name": "shape_polynomial", "options": {"duration": "scenario"}},
                 {"name": "spin_extremal"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 1.0, "kd": 1.6}},
    "simulation": {"sample_time": 0.5},
}


def _run(tmp_path, data, capsys):
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out), "--no-plots"])
    return code, capsys.readouterr(), out


def test_spin_extremal_on_a_fixed_final_rate_refuses_the_scenario_at_its_entry(tmp_path, capsys):
    code, captured, out = _run(tmp_path, REST_TO_REST, capsys)
    assert code == 2, captured
    assert captured.err.startswith(f"slewbench: error in scenario: {tmp_path / 'scenario.yaml'}: planners[3]: "), captured.err
    for words in ("the spin extremals cannot meet a fixed final rate", "maneuver.final.omega = [0. 0. 0.]",
                  "set maneuver.final.omega: null"):
        assert words in captured.err, captured.err
    assert not out.exists()  # refused before anything ran: no row of the other planners either


@pytest.mark.parametrize("final_omega", [None, [0, 0, 0]])
def test_without_spin_extremal_the_other_planners_run(tmp_path, capsys, final_omega):
    # the control: the same scenario runs once spin_extremal is left out (a free final rate too)
    data = yaml.safe_load(yaml.safe_dump(REST_TO_REST))
    data["planners"] = data["planners"][:3]
    data["maneuver"]["final"]["omega"] = final_omega
    code, captured, out = _run(tmp_path, data, capsys)
    assert code == 0, captured.err
    assert [line.split(":")[0] for line in captured.out.splitlines() if line.startswith("[")] == [
        "[1/3] natural_motion", "[2/3] eigenaxis", "[3/3] shape_polynomial"], captured.out
    assert (out / "results.json").exists()


def test_natural_motion_on_a_non_zero_final_rate_is_refused_the_same_way(tmp_path, capsys):
    # the established rule the spin extremals follow: another planner's refusal, at load, at its entry
    data = yaml.safe_load(yaml.safe_dump(REST_TO_REST))
    data["planners"] = data["planners"][:3]
    data["maneuver"]["final"]["omega"] = [0.01, 0, 0]
    code, captured, out = _run(tmp_path, data, capsys)
    assert code == 2, captured
    assert captured.err.startswith(f"slewbench: error in scenario: {tmp_path / 'scenario.yaml'}: planners[0]: "
                                   "natural_motion ends at rest: maneuver.final.omega must be zero or null"), captured.err
    assert not out.exists()


def test_a_free_final_rate_lets_spin_extremal_run_as_a_row(tmp_path, capsys):
    data = yaml.safe_load(yaml.safe_dump(REST_TO_REST))
    data["maneuver"]["final"]["omega"] = None
    data["planners"] = [{"name": "spin_extremal"}]
    code, captured, out = _run(tmp_path, data, capsys)
    assert code == 0, captured.err
    assert "[1/1] spin_extremal: " in captured.out, captured.out
    assert (out / "results.json").exists()
