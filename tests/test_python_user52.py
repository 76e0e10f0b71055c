"""A GNC engineer's findings from Python (user 52), each failing before its fix.

* Plausibility warnings (a wheel torque in mN m written as N m, coplanar wheels, an inertia in
  g cm² written as kg m²) reached only ``slewbench validate`` and ``run``: ``parse_scenario`` and
  ``load`` were silent. They are now :class:`scenarios.PlausibilityWarning` warnings, one per finding.
* ``parse_scenario`` refused numpy arrays, numpy integers and tuples, describing them wrongly.
* ``aem_text`` normalised ``[2, 0, 0, 0]`` quietly, and a zero quaternion gave a numpy warning.
* Library errors said "choose another --out"; ``validate`` of a study file with a duplicate key,
  or of a file that is no mapping, did not name the file.
* ``Simulator.run`` over its work limit raised a ``RuntimeError``, not the documented ``ValueError``.
"""
from __future__ import annotations

import contextlib
import copy
import io
import warnings

import numpy as np
import pytest
import yaml

import scenarios
from controllers import CONTROLLERS
from ocp import AttitudeModel, SimulationError, Simulator, Spacecraft, quat
from scenarios.cli.commands import main
from scenarios.errors import OutputError, PlausibilityWarning, ScenarioError
from scenarios.output.aem import aem_text
from scenarios.schema.loader import parse_scenario
from scenarios.schema.plausibility import plausibility_warnings

PYRAMID = [[0.612372, 0.612372, 0.5], [-0.612372, 0.612372, 0.5], [-0.612372, -0.612372, 0.5],
           [0.612372, -0.612372, 0.5]]
INERTIA = [[0.21, -0.004, 0.003], [-0.004, 0.24, 0.002], [0.003, 0.002, 0.11]]


def base() -> dict:
    """The report's 12U: full inertia tensor, four pyramid wheels (4 mN m, 0.03 N m s), 120 deg in 60 s."""
    return {"name": "u52", "spacecraft": {"inertia": copy.deepcopy(INERTIA),
                                          "wheels": {"axes": copy.deepcopy(PYRAMID), "max_torque": 0.004,
                                                     "max_momentum": 0.03}},
            "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                         "final": {"q": [0.5, 0, 0.6123724, 0.6123724], "omega": [0, 0, 0]}},
            "planners": [{"name": "eigenaxis"}],
            "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.06, "kd": 0.48}},
            "simulation": {"sample_time": 0.5}}


def caught(call) -> list[warnings.WarningMessage]:
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        call()
    return [w for w in seen if issubclass(w.category, PlausibilityWarning)]


SLIPS = {
    "mN m as N m": (lambda d: d["spacecraft"]["wheels"].__setitem__("max_torque", 4.0),
                    "spacecraft.wheels.max_torque", "mN m written as N m"),
    "coplanar wheels": (lambda d: d["spacecraft"]["wheels"].__setitem__(
        "axes", [[1, 0, 0], [0, 1, 0], [0.7071, 0.7071, 0]]), "spacecraft.wheels.axes", "span only a plane"),
    "g cm2 as kg m2": (lambda d: d["spacecraft"].__setitem__("inertia", [2.1e6, 2.4e6, 1.1e6]),
                       "spacecraft.inertia", "g cm² 1e7"),
}


@pytest.mark.parametrize("slip", sorted(SLIPS))
def test_parse_scenario_warns_once_per_slip_naming_the_yaml_path(slip):
    change, path, words = SLIPS[slip]
    data = base()
    change(data)
    seen = caught(lambda: parse_scenario(data))
    assert len(seen) == 1, [str(w.message) for w in seen]
    message = seen[0].message
    assert isinstance(message, PlausibilityWarning) and message.path == path and words in str(message), str(message)
    assert seen[0].filename == __file__  # points at the caller's line, not inside slewbench
    assert str(message) == str(plausibility_warnings(parse_scenario(data, inapplicable_rows=True))[0])


def test_a_plausible_scenario_gives_no_warning_and_the_face_exports_the_class():
    assert caught(lambda: parse_scenario(base())) == []
    assert scenarios.PlausibilityWarning is PlausibilityWarning and issubclass(PlausibilityWarning, UserWarning)


def test_load_warns_at_the_callers_line_and_a_study_case_does_not(tmp_path):
    data = base()
    data["spacecraft"]["wheels"]["max_torque"] = 4.0
    path = tmp_path / "mnm.yaml"
    path.write_text(yaml.safe_dump(data))
    seen = caught(lambda: scenarios.load(path))
    assert [w.message.path for w in seen] == ["spacecraft.wheels.max_torque"]
    assert seen[0].filename == __file__
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        with pytest.raises(PlausibilityWarning, match="did you mean 0.004 N m"):
            scenarios.load(path)


def test_the_command_line_prints_each_finding_once_not_as_a_python_warning(tmp_path):
    data = base()
    data["spacecraft"]["wheels"]["max_torque"] = 4.0
    path = tmp_path / "mnm.yaml"
    path.write_text(yaml.safe_dump(data))
    out, err = io.StringIO(), io.StringIO()
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            assert main(["validate", str(path)]) == 0
    assert out.getvalue().count("mN m written as N m") == 1 and "PlausibilityWarning" not in err.getvalue()


def test_numpy_values_and_tuples_read_as_the_lists_and_numbers_they_stand_for():
    lists = parse_scenario(base())
    data = base()
    data["spacecraft"]["inertia"] = np.array(INERTIA)
    data["spacecraft"]["wheels"]["axes"] = tuple(tuple(row) for row in PYRAMID)
    data["maneuver"]["duration"] = np.int64(60)
    data["maneuver"]["final"]["q"] = (0.5, 0, 0.6123724, 0.6123724)
    data["maneuver"]["initial"]["q"] = np.array([1, 0, 0, 0], dtype=np.float32)
    data["controller"]["options"]["kp"] = np.float64(0.06)
    built = parse_scenario(data)
    assert np.array_equal(built.problem.spacecraft.inertia, lists.problem.spacecraft.inertia)
    assert np.array_equal(built.problem.qf, lists.problem.qf) and built.problem.duration == 60.0
    assert np.array_equal(built.problem.spacecraft.wheels.axes, lists.problem.spacecraft.wheels.axes)
    assert built.data == lists.data and yaml.safe_dump(built.data)  # recorded as plain YAML values


def test_a_numpy_bool_is_still_no_number_and_a_bad_inertia_is_described_as_accepted():
    data = base()
    data["maneuver"]["duration"] = np.bool_(True)
    with pytest.raises(ScenarioError, match=r"maneuver.duration: expected a number, got True"):
        parse_scenario(data)
    data = base()
    data["spacecraft"]["inertia"] = "heavy"
    with pytest.raises(ScenarioError, match=r"expected a list of 3 numbers or a 3x3 matrix \(3 rows of 3 numbers\), "
                                            r"got 'heavy'"):
        parse_scenario(data)
    data["spacecraft"]["inertia"] = np.eye(2).tolist()
    with pytest.raises(ScenarioError, match="expected a 3x3 matrix .* got 2 rows"):
        parse_scenario(data)


@pytest.mark.parametrize("bad, words", [([2, 0, 0, 0], r"q\[1\] = \[2.0, 0.0, 0.0, 0.0\]: a quaternion must have unit "
                                                       r"norm \(got norm 2; tolerance 1e-3\)"),
                                        ([0, 0, 0, 0], r"q\[1\] = \[0.0, 0.0, 0.0, 0.0\]: a quaternion cannot be zero"),
                                        ([1.002, 0, 0, 0], "unit norm")])
def test_aem_text_refuses_a_quaternion_the_library_refuses(bad, words):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy RuntimeWarning on the way
        with pytest.raises(ValueError, match=words):
            aem_text("2027-03-20T12:00:00Z", [0, 10], [[1, 0, 0, 0], bad], object_name="x")


def test_aem_text_takes_a_quaternion_within_the_tolerance():
    text = aem_text("2027-03-20T12:00:00Z", [0, 10], [[1, 0, 0, 0], [1.0009, 0, 0, 0]], object_name="x")
    assert [float(v) for v in text.splitlines()[-2].split()[1:]] == [0.0, 0.0, 0.0, 1.0]  # normalised, scalar last


def test_a_run_over_the_work_limit_is_a_value_error_and_still_a_simulation_error():
    model = AttitudeModel(Spacecraft([1.0, 1.0, 1.0]))
    simulator = Simulator(model, sample_time=1.0, max_samples=100)
    state = np.concatenate([quat.IDENTITY, np.zeros(model.nx - 4)])
    for kind in (ValueError, SimulationError):
        with pytest.raises(kind, match="over the limit of 100"):
            simulator.run(CONTROLLERS["none"](), state, 1000.0)


def test_run_results_write_speaks_of_the_directory_argument(tmp_path):
    data = base()
    results = scenarios.run(parse_scenario(data))
    out = tmp_path / "run1"
    results.write(out, plots=False)
    (out / "results.md").write_text("edited by hand")
    with pytest.raises(OutputError) as error:
        results.write(out, plots=False)
    assert "`directory` argument" in str(error.value) and "choose another --out" not in str(error.value)


@pytest.mark.parametrize("text, words", [
    ("study: s\nscenario: base.yaml\ngrid:\n  controller.options.kp: [0.1]\n  controller.options.kp: [0.2]\n",
     "error in {file}: grid.controller.options.kp: duplicate key (lines 4 and 5); each key may appear once"),
    ("- a\n- b\n", "error in {file}: (top level): expected a mapping, got ['a', 'b']")])
def test_validate_names_the_file_before_its_kind_is_known(text, words, tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text(text)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert main(["validate", str(path)]) == 2
    assert words.format(file=path) in err.getvalue() and "error in scenario" not in err.getvalue(), err.getvalue()
    assert err.getvalue().count(str(path)) == 1, err.getvalue()  # the file named once


@pytest.mark.parametrize("text, words", [
    ("name: a\nname: b\n", "error in study.yaml: name: duplicate key (lines 1 and 2); each key may appear once"),
    ("- a\n", "error in study.yaml: (top level): expected a mapping, got ['a']")])
def test_a_file_given_as_dot_slash_is_named_once(text, words, tmp_path, monkeypatch):
    """``validate ./FILE``: the error names the file once (Python writes ./FILE as FILE)."""
    (tmp_path / "study.yaml").write_text(text)
    monkeypatch.chdir(tmp_path)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert main(["validate", "./study.yaml"]) == 2
    assert words in err.getvalue() and err.getvalue().count("study.yaml") == 1, err.getvalue()


def test_a_scenario_files_error_still_says_scenario(tmp_path):
    path = tmp_path / "s.yaml"
    data = base()
    data["maneuver"]["duration"] = -1
    path.write_text(yaml.safe_dump(data))
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert main(["validate", str(path)]) == 2
    assert f"error in scenario: {path}: maneuver.duration:" in err.getvalue(), err.getvalue()


def test_a_mapping_that_holds_itself_is_refused_not_a_recursion_error():
    data: dict = base()
    data["spacecraft"]["self"] = data
    with pytest.raises(ScenarioError, match="spacecraft.self: unknown key"):
        parse_scenario(data)
