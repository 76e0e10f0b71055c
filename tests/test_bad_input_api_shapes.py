"""Public functions given arguments of the wrong kind: text for numbers, ``None``, arrays of the
wrong shape. Each is refused with an error naming the argument and what was expected, as the
scalar form of the same call already does, never a NumPy error or an answer computed from text."""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, quat
from ocp.errors import ModelError
from planners import ManeuverProblem
from scenarios.slewtable.fit import SlewTimeFit

IDENTITY = [1.0, 0.0, 0.0, 0.0]
QUARTER_X = [np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0]


@pytest.fixture(scope="module")
def fit():
    """A fit on the six body axes at 90 and 180 deg: unit inertia, unit torque bounds, the
    eigenaxis bang-bang times 2 sqrt(theta) (closed form)."""
    axes = np.vstack([np.eye(3), -np.eye(3)])
    angles = np.array([np.pi / 2, np.pi])
    return SlewTimeFit(angles, axes, np.tile(2.0 * np.sqrt(angles), (6, 1)), inertia=np.eye(3),
                       generators=np.eye(3))


def test_the_fit_answers_the_well_formed_calls(fit):
    assert fit(IDENTITY, QUARTER_X) == pytest.approx(2.0 * np.sqrt(np.pi / 2), rel=1e-9)
    assert fit.slew_time_many([IDENTITY] * 2, [QUARTER_X] * 2) == pytest.approx([2.0 * np.sqrt(np.pi / 2)] * 2, rel=1e-9)


def test_slew_time_many_refuses_text_as_the_scalar_call_does(fit):
    # the scalar call refused ["1", "0", "0", "0"]; the vectorised one answered 2.5066 s for it
    with pytest.raises(TypeError, match="q0 and qf must be 4 numbers"):
        fit(["1", "0", "0", "0"], QUARTER_X)
    with pytest.raises(TypeError, match=r"q0 must be quaternions of 4 numbers \(scalar first\), got array\(\[\['1'"):
        fit.slew_time_many(np.array([["1", "0", "0", "0"]]), [QUARTER_X])
    with pytest.raises(TypeError, match="qf must be quaternions of 4 numbers"):
        fit.slew_time_many([IDENTITY], "0.7071,0.7071,0,0")


def test_slew_time_many_names_none(fit):
    # was "got shape (1, 1)": None read as a NaN
    with pytest.raises(TypeError, match="q0 must be quaternions of 4 numbers .*, got None"):
        fit.slew_time_many(None, [QUARTER_X])


def test_slew_time_many_names_q0_and_qf_of_different_lengths(fit):
    # was NumPy's "shape mismatch: objects cannot be broadcast to a single shape. Mismatch is between arg 0 ..."
    with pytest.raises(ValueError, match=r"q0 and qf must hold as many quaternions .*got shapes \(3, 4\) and \(2, 4\)"):
        fit.slew_time_many([IDENTITY] * 3, [QUARTER_X] * 2)
    # one against many still broadcasts
    assert fit.slew_time_many(IDENTITY, [QUARTER_X] * 3).shape == (3,)


@pytest.mark.parametrize("q", [[1.0, 0.0, 0.0], np.eye(3), None, 1.0, "1000"])
def test_to_euler_refuses_what_is_not_quaternions_naming_q(q):
    # [1, 0, 0] raised IndexError from inside the formula; "1000" and None a NumPy error
    with pytest.raises(ValueError, match=r"q must be quaternions of 4 numbers"):
        quat.to_euler(q)


def test_to_euler_still_takes_stacks_of_quaternions():
    # 90 deg about z: yaw pi/2, pitch and roll 0 (3-2-1, closed form)
    angles = quat.to_euler(np.array([[np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]] * 2))
    assert angles == pytest.approx(np.array([[np.pi / 2, 0.0, 0.0]] * 2), abs=1e-12)


def test_from_axis_angle_names_the_axis_for_text():
    # was NumPy's "could not convert string to float: 'xyz'"
    with pytest.raises(ValueError, match="axis must be 3 numbers"):
        quat.from_axis_angle("xyz", 1.0)


@pytest.mark.parametrize("build, fragment", [
    # each was accepted: NumPy reads "2" as the number 2
    (lambda: Spacecraft(["1", "2", "2"]), "inertia: expected 3 principal moments or a 3x3 matrix of numbers, got ['1'"),
    (lambda: ReactionWheels(np.array([["1", "0", "0"], ["0", "1", "0"], ["0", "0", "1"]])),
     "axes: expected a 3 x n matrix of wheel axes (numbers), got"),
    (lambda: ReactionWheels.from_body_axes(max_torque="0.1"), "max_torque: expected a number or 3 numbers, got '0.1'"),
])
def test_the_model_refuses_text_for_numbers(build, fragment):
    with pytest.raises(ModelError) as caught:
        build()
    assert fragment in str(caught.value)


@pytest.mark.parametrize("argument, value, fragment", [
    ("q0", ["1", "0", "0", "0"], "q0 must be 4 numbers, got ['1', '0', '0', '0']"),  # was accepted
    ("omega0", "000", "omega0 must be 3 numbers, got '000'"),  # was "got shape (): 0.0"
    ("q0", None, "q0 must be 4 numbers, got None"),  # was "got shape (): nan"
])
def test_a_problem_refuses_text_and_none_for_its_vectors(argument, value, fragment):
    arguments = {"q0": IDENTITY, "omega0": np.zeros(3), "qf": QUARTER_X, "duration": 10.0, argument: value}
    with pytest.raises(ValueError) as caught:
        ManeuverProblem(Spacecraft([1.0, 1.0, 1.0]), **arguments)
    assert fragment in str(caught.value)


@pytest.mark.parametrize("t, fragment", [
    ("1.0", "got '1.0'"),  # was sampled at 1 s
    (None, "got None"),  # was "reference times must be finite [s]; got [nan]"
])
def test_a_reference_refuses_times_that_are_not_numbers(t, fragment):
    from planners import PLANNERS
    problem = ManeuverProblem(Spacecraft([1.0, 1.0, 1.0]), q0=IDENTITY, omega0=np.zeros(3), qf=QUARTER_X,
                              duration=10.0, omegaf=np.zeros(3))
    reference = PLANNERS["eigenaxis"]({"profile": "smooth"}).plan(problem)
    assert reference.sample(10.0).q == pytest.approx(QUARTER_X, abs=1e-9)  # ends at qf
    with pytest.raises(TypeError, match="reference times must be numbers") as caught:
        reference.sample(t)
    assert fragment in str(caught.value)


@pytest.mark.parametrize("target_q, fragment", [
    ([0.0, 0.0, 0.0, 0.0], "target_q must be a unit quaternion"),  # scored final_error_deg 0.0
    ([1.4142, 0.0, 1.4142, 0.0], "target_q must be a unit quaternion"),  # 2 qf: as qf, a slip unseen
    (["0.7071", "0", "0.7071", "0"], "target_q must be 4 numbers"),  # read as numbers
])
def test_the_metrics_refuse_a_target_that_is_no_attitude(target_q, fragment):
    from ocp import metrics_from_reference
    from planners import PLANNERS
    qf = [np.cos(np.pi / 4), 0.0, np.sin(np.pi / 4), 0.0]  # 90 deg about y
    problem = ManeuverProblem(Spacecraft([1.0, 1.0, 1.0]), q0=IDENTITY, omega0=np.zeros(3), qf=qf,
                              duration=10.0, omegaf=np.zeros(3))
    reference = PLANNERS["eigenaxis"]({"profile": "smooth"}).plan(problem)
    # the reference ends at qf: 0 deg from it, 90 deg from the identity (closed form)
    assert metrics_from_reference(reference, qf)["final_error_deg"] == pytest.approx(0.0, abs=1e-9)
    assert metrics_from_reference(reference, IDENTITY)["final_error_deg"] == pytest.approx(90.0, abs=1e-9)
    with pytest.raises((TypeError, ValueError)) as caught:
        metrics_from_reference(reference, target_q)
    assert fragment in str(caught.value)


def _fit_file(tmp_path, fit, edit):
    import json
    data = fit.to_dict()
    edit(data)
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(data) if isinstance(data, dict) else data)
    return path


@pytest.mark.parametrize("edit, fragment", [
    (lambda data: data.pop("axes"), "is not a complete slew-time fit: no 'axes'"),  # was KeyError: 'axes'
    (lambda data: data.update(angles_rad=["a", "b"]), "whose parameters cannot be read (could not convert"),
])
def test_load_fit_names_the_file_of_an_edited_fit(tmp_path, fit, edit, fragment):
    from scenarios.slewtable import load_fit
    path = _fit_file(tmp_path, fit, edit)
    with pytest.raises(ValueError) as caught:
        load_fit(path)
    assert str(caught.value).startswith(str(path)) and fragment in str(caught.value)


def test_load_fit_names_a_file_that_is_not_json(tmp_path, fit):
    from scenarios.slewtable import load_fit
    path = tmp_path / "fit.json"
    path.write_text('{"format": "slewbench-slew-')  # cut short: was a bare JSONDecodeError
    with pytest.raises(ValueError, match="fit.json is not a slewbench slew-time fit: not JSON"):
        load_fit(path)
    good = _fit_file(tmp_path, fit, lambda data: None)  # the same fit written whole loads and answers
    assert load_fit(good)(IDENTITY, QUARTER_X) == pytest.approx(2.0 * np.sqrt(np.pi / 2), rel=1e-9)


@pytest.fixture(scope="module")
def run_results():
    import scenarios
    data = {"name": "write check", "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None,
                                                  "torquers": {"max_torque": 1.0}},
            "maneuver": {"duration": 5.0, "initial": {"q": IDENTITY, "omega": [0, 0, 0]},
                         "final": {"q": QUARTER_X, "omega": [0, 0, 0]}},
            "planners": [{"name": "eigenaxis"}], "controller": {"name": "augmented_quaternion_feedback"},
            "simulation": {"sample_time": 0.1, "duration": 6.0}}
    return scenarios.run(scenarios.parse_scenario(data))


@pytest.mark.parametrize("arguments, fragment", [
    ({"directory": None}, "directory must be a str or os.PathLike, got NoneType"),  # was pathlib's TypeError
    ({"directory": 3}, "directory must be a str or os.PathLike, got int"),
])
def test_run_results_write_names_a_directory_that_is_no_path(run_results, arguments, fragment):
    with pytest.raises(TypeError) as caught:
        run_results.write(**arguments)
    assert fragment in str(caught.value)


def test_run_results_write_refuses_plots_that_is_not_a_bool(run_results, tmp_path):
    # plots="no" drew the figures ("no" is truthy), as a sweep's write already refuses
    with pytest.raises(TypeError, match="plots must be True or False, got 'no'"):
        run_results.write(tmp_path / "out", plots="no")
    assert not (tmp_path / "out").exists()
