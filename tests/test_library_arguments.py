"""Public constructors and functions check their arguments (issue 11, section 3): each call below
used to return garbage (a NaN quaternion, a non-unit quaternion, a negative time grid) or fail deep
inside NumPy; now it raises ValueError/TypeError naming the argument and what was expected."""
import re

import numpy as np
import pytest

from controllers import CONTROLLERS
from ocp import (
    AttitudeModel,
    ModelError,
    ReactionWheels,
    SensorNoise,
    Simulator,
    Spacecraft,
    quat,
)
from ocp.errors import OptionsError
from planners import PLANNERS, ManeuverProblem

SPACECRAFT = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.1))


def problem(**changes):
    arguments = {"spacecraft": SPACECRAFT, "q0": quat.IDENTITY, "omega0": np.zeros(3),
                 "qf": quat.from_axis_angle([0, 0, 1], 0.5), "duration": 30.0}
    arguments.update(changes)
    return ManeuverProblem(**arguments)


@pytest.mark.parametrize("changes, words", [
    ({"q0": [0, 0, 0, 0]}, r"q0 must be a unit quaternion .*: a quaternion cannot be zero"),
    ({"qf": [0, 0, 0, 0]}, r"qf must be a unit quaternion .*: a quaternion cannot be zero"),
    # Was normalised silently, while the YAML loader refuses it with the same words.
    ({"q0": [2, 0, 0, 0]}, r"q0 must be a unit quaternion .*unit norm \(got norm 2; tolerance 1e-3\)"),
    ({"qf": [1.01241, 0, 0, 0]}, r"qf must be a unit quaternion .*unit norm \(got norm 1.01241; tolerance 1e-3\)"),
    ({"q0": [1, 0, 0]}, "q0 must be 4 finite numbers"),
    ({"q0": [np.nan, 0, 0, 1]}, "q0 must be 4 finite numbers"),
    ({"omega0": [0, 0]}, "omega0 must be 3 finite numbers"),
    ({"omegaf": [0, 0, np.inf]}, "omegaf must be 3 finite numbers"),
    ({"wheel_momentum0": [0.0]}, "wheel_momentum0 must be 3 finite numbers"),
    ({"duration": -10.0}, "duration must be a finite positive"),
    ({"duration": np.nan}, "duration must be a finite positive"),
    ({"max_rate": 0.0}, "max_rate must be a finite positive"),
])
def test_maneuver_problem_checks_its_arguments(changes, words):
    with pytest.raises(ValueError, match=words):
        problem(**changes)


@pytest.mark.parametrize("changes, named", [
    ({"omega0": [1e23, 0, 0]}, r"omega0 .*within ±1000 rad/s .*got \[1e\+23, 0\.0, 0\.0\] \(entry 0\)"),
    ({"omega0": [0, 0, -1000.5]}, r"omega0 .*within ±1000 rad/s .*got \[0\.0, 0\.0, -1000\.5\] \(entry 2\)"),
    ({"omegaf": [0, 1001, 0]}, r"omegaf .*within ±1000 rad/s .*got \[0\.0, 1001\.0, 0\.0\] \(entry 1\)"),
])
def test_maneuver_problem_bounds_its_rates_as_the_yaml_path_does(changes, named):
    """From [1e23, 0, 0] eigenaxis returned an ok reference ending at -2e8 rad/s: the library now
    refuses what maneuver.initial.omega / maneuver.final.omega refuse, with the same bound."""
    from planners.problem import MAX_BODY_RATE
    from scenarios.schema.loader import MAX_BODY_RATE as YAML_BOUND
    assert MAX_BODY_RATE == YAML_BOUND == 1e3
    with pytest.raises(ValueError, match=named):
        problem(**changes)
    at_bound = problem(omega0=[-1e3, 0, 1e3], omegaf=[0, 1e3, 0])  # the bound itself is accepted
    assert at_bound.omega0.tolist() == [-1e3, 0.0, 1e3] and at_bound.omegaf.tolist() == [0.0, 1e3, 0.0]


def test_maneuver_problem_checks_types():
    with pytest.raises(TypeError, match="spacecraft must be an ocp.Spacecraft"):
        problem(spacecraft=[2.0, 3.0, 4.0])


def test_axis_angle_needs_a_non_zero_axis_and_normalises_it():
    with pytest.raises(ValueError, match="axis must be a finite non-zero vector"):
        quat.from_axis_angle([0, 0, 0], 1.0)
    with pytest.raises(ValueError, match="axis must have 3 components"):
        quat.from_axis_angle([0, 1], 1.0)
    q = quat.from_axis_angle([0, 0, 2.0], 1.0)  # a non-unit axis is a direction
    assert np.isclose(np.linalg.norm(q), 1.0, atol=1e-15) and np.allclose(q, [np.cos(0.5), 0, 0, np.sin(0.5)])


def test_normalize_refuses_a_zero_quaternion():
    with pytest.raises(ValueError, match="zero or non-finite"):
        quat.normalize([0.0, 0.0, 0.0, 0.0])


@pytest.mark.parametrize("call, error, words", [
    (lambda s, x: s.run(CONTROLLERS["none"](), x, -10.0), ValueError, "duration must be a finite positive"),
    (lambda s, x: s.run(CONTROLLERS["none"](), x, np.inf), ValueError, "duration must be a finite positive"),
    (lambda s, x: s.run(CONTROLLERS["none"](), x[:5], 10.0), ValueError, "x0 must be 10 finite numbers"),
    (lambda s, x: s.run(CONTROLLERS["none"](), np.zeros(10), 10.0), ValueError, "non-zero quaternion"),
    (lambda s, x: s.run(CONTROLLERS["none"](), x, 10.0, parameters=[1.0]), ValueError, "parameters must be a finite 3-vector"),
])
def test_simulator_run_checks_its_arguments(call, error, words):
    simulator = Simulator(AttitudeModel(SPACECRAFT), sample_time=1.0)
    x0 = np.concatenate([quat.IDENTITY, np.zeros(6)])
    with pytest.raises(error, match=words):
        call(simulator, x0)


@pytest.mark.parametrize("arguments, words", [
    ({"sample_time": 0.0}, "sample_time must be a finite positive"),
    ({"sample_time": np.nan}, "sample_time must be a finite positive"),
    ({"sample_time": 1.0, "max_step": 1e-9}, "sub-steps per"),
    ({"sample_time": 1.0, "integrator": "euler"}, "integrator must be one of"),
    ({"sample_time": 1.0, "max_samples": 0}, "max_samples must be a positive integer"),
])
def test_simulator_checks_its_settings(arguments, words):
    with pytest.raises(ValueError, match=words):
        Simulator(AttitudeModel(SPACECRAFT), **arguments)


def test_simulator_refuses_more_samples_than_its_limit():
    from ocp import SimulationError
    simulator = Simulator(AttitudeModel(SPACECRAFT), sample_time=1.0, max_samples=100)
    with pytest.raises(SimulationError, match="over the limit of 100"):
        simulator.run(CONTROLLERS["none"](), np.concatenate([quat.IDENTITY, np.zeros(6)]), 1000.0)


def test_spacecraft_checks_actuator_types():
    with pytest.raises(ModelError, match="wheels: expected an ocp.ReactionWheels"):
        Spacecraft([2.0, 3.0, 4.0], wheels=[[1, 0, 0]])
    with pytest.raises(ModelError, match="inertia: expected 3 principal moments"):
        Spacecraft("heavy")


@pytest.mark.parametrize("arguments, words", [
    ({"attitude_std": -1.0}, "attitude_std must be a finite non-negative"),
    ({"rate_std": np.nan}, "rate_std must be a finite non-negative"),
    ({"seed": -1}, "seed must be a non-negative integer"),
])
def test_sensor_noise_checks_its_arguments(arguments, words):
    with pytest.raises(ValueError, match=words):
        SensorNoise(**arguments)


@pytest.mark.parametrize("registry", [PLANNERS, CONTROLLERS], ids=["planners", "controllers"])
def test_every_numeric_option_declares_its_range(registry):
    """Each option of every registered planner and controller that can hold a number has a Range
    next to its type, and its default lies in that range."""
    from ocp.options import _check_range, numeric_leaves, option_fields
    for name, cls in registry.items():
        for option, (annotation, bounds) in option_fields(cls.Options).items():
            if numeric_leaves(annotation):
                assert bounds is not None, f"{name}.{option} declares no Range"
                default = getattr(cls.Options(), option)
                if default is not None:
                    _check_range(list(default) if isinstance(default, tuple) else default, bounds, f"{name}.{option}")


def test_library_options_are_validated_like_yaml():
    with pytest.raises(OptionsError, match=r"options.torque_fraction: expected a finite number > 0 and <= 1, got 2.0"):
        PLANNERS["eigenaxis"]({"torque_fraction": 2.0})
    options = PLANNERS["eigenaxis"].Options(torque_fraction=-1.0)  # built by hand, bypassing YAML
    with pytest.raises(OptionsError, match="torque_fraction"):
        PLANNERS["eigenaxis"](options)


# --- a fresh-eyes user's calls (2026-12-02): raw errors from deep inside, now named at the entry ---

@pytest.mark.parametrize("registry, name, words", [
    (PLANNERS, "eigenaxiz", (r"unknown planner 'eigenaxiz'; registered: \['collocation', .*'eigenaxis'.*\] "
                             r"\(did you mean 'eigenaxis'\?\)")),
    (CONTROLLERS, "pd", r"unknown controller 'pd'; registered: \['augmented_quaternion_feedback', .*\]"),
], ids=["planners", "controllers"])
def test_an_unknown_registry_name_lists_the_registered_ones(registry, name, words):
    from planners.errors import UnknownNameError
    with pytest.raises(KeyError) as caught:  # a KeyError still, as a dictionary's
        registry[name]
    assert isinstance(caught.value, UnknownNameError)
    assert re.fullmatch(words, str(caught.value))  # plain text, not the quoted repr of a bare KeyError
    assert name not in registry and registry.get(name) is None


@pytest.mark.parametrize("argument", ["abc", None, SPACECRAFT])
def test_plan_refuses_what_is_not_a_problem(argument):
    with pytest.raises(TypeError, match=r"EigenaxisPlanner.plan\(problem\): problem must be a planners.ManeuverProblem"):
        PLANNERS["eigenaxis"]().plan(argument)


@pytest.mark.parametrize("call, error, words", [
    (lambda s, x: s.run(CONTROLLERS["none"](), x, 10.0, reference="eigenaxis"), TypeError,
     r"reference must be a planners.Reference .*got str \(a planner's name\? plan it first"),
    (lambda s, x: s.run(CONTROLLERS["none"](), x, 10.0, target=([1, 0, 0], None)), ValueError,
     r"target\[0\] \(q_f\) must be 4 finite numbers .*got shape \(3,\)"),
    (lambda s, x: s.run(CONTROLLERS["none"](), x, 10.0, target=(quat.IDENTITY, [0, 0])), ValueError,
     r"target\[1\] \(omega_f\) must be 3 finite numbers"),
    (lambda s, x: s.run(CONTROLLERS["none"](), x, 10.0, target=quat.IDENTITY), ValueError,
     r"target must be a pair \(q_f, omega_f\)"),
    # a scaled target changes a law's gains (the error quaternion scales): refused as ManeuverProblem does
    (lambda s, x: s.run(CONTROLLERS["none"](), x, 10.0, target=(2 * quat.IDENTITY, None)), ValueError,
     r"target\[0\] \(q_f\): a quaternion must have unit norm \(got norm 2; tolerance 1e-3\)"),
    (lambda s, x: s.run(CONTROLLERS["none"], x, 10.0), TypeError,
     r"controller must be a controller instance, got the class NoControl; instantiate it"),
])
def test_simulator_run_names_a_wrong_reference_or_target(call, error, words):
    simulator = Simulator(AttitudeModel(SPACECRAFT), sample_time=1.0)
    x0 = np.concatenate([quat.IDENTITY, np.zeros(6)])
    with pytest.raises(error, match=words):
        call(simulator, x0)


def test_metric_functions_name_a_wrong_target():
    from ocp import metrics_from_reference, metrics_from_simulation
    slew = problem(omegaf=np.zeros(3))
    reference = PLANNERS["eigenaxis"]().plan(slew)
    result = Simulator(slew.model, sample_time=1.0).run(CONTROLLERS["none"](), slew.initial_state, 3.0)
    with pytest.raises(TypeError, match=r"metrics_from_reference: target_q must be 4 numbers .*got ManeuverProblem "
                                        r"\(pass problem.qf and problem.omegaf\)"):
        metrics_from_reference(reference, slew)
    with pytest.raises(ValueError, match=r"metrics_from_simulation: target_q must be 4 finite numbers .*shape \(3,\)"):
        metrics_from_simulation(result, [1, 0, 0])
    with pytest.raises(ValueError, match=r"metrics_from_reference: target_omega must be 3 finite numbers"):
        metrics_from_reference(reference, slew.qf, [0.0, 0.0])
    with pytest.raises(TypeError, match=r"metrics_from_reference: reference must be a planners.Reference, got str"):
        metrics_from_reference("eigenaxis", slew.qf)
    with pytest.raises(TypeError, match=r"metrics_from_simulation: result must be an ocp.SimulationResult"):
        metrics_from_simulation(reference, slew.qf)
    # What they take still works.
    assert metrics_from_reference(reference, slew.qf, slew.omegaf)["final_error_deg"] == pytest.approx(0.0, abs=1e-9)


def test_compute_metrics_names_a_torque_of_the_wrong_length():
    """A torque with neither N nor N+1 rows for N+1 sample times ended in a NumPy broadcasting error."""
    from ocp import compute_metrics
    t = np.linspace(0.0, 10.0, 11)
    q = np.tile(quat.IDENTITY, (11, 1))
    omega = np.zeros((11, 3))
    with pytest.raises(ValueError, match=re.escape("compute_metrics: torque must have shape (10, 3) or (11, 3) for "
                                                   "the 11 sample times t (held over each interval, or sampled at "
                                                   "t), got shape (7, 3)")):
        compute_metrics(t, q, omega, np.zeros((7, 3)), quat.IDENTITY)
    with pytest.raises(ValueError, match=re.escape("torque must have shape (10, 3) or (11, 3) for the 11 sample "
                                                   "times t (held over each interval, or sampled at t), got shape "
                                                   "(10, 2)")):
        compute_metrics(t, q, omega, np.zeros((10, 2)), quat.IDENTITY)  # silently two axes before
    with pytest.raises(ValueError, match=re.escape("compute_metrics: omega must have shape (11, 3) for the 11 "
                                                   "sample times t, got shape (10, 3)")):
        compute_metrics(t, q, omega[:-1], np.zeros((10, 3)), quat.IDENTITY)
    # What it takes still works: 1 N m about x held for 10 s.
    torque = np.tile([1.0, 0.0, 0.0], (10, 1))
    assert compute_metrics(t, q, omega, torque, quat.IDENTITY)["int_u2"] == pytest.approx(10.0, rel=1e-12)


def test_a_non_finite_inertia_is_called_non_finite():
    with pytest.raises(ModelError, match=r"inertia: the inertia must be finite, got \[\[nan, 0.0, 0.0\]"):
        Spacecraft([np.nan, 1.0, 1.0])
    with pytest.raises(ModelError, match=r"inertia: expected 3 principal moments or a 3x3 matrix, got shape \(2,\)"):
        Spacecraft([1.0, 2.0])


def test_the_yaml_and_the_library_refuse_one_non_unit_quaternion_alike():
    from scenarios.errors import ScenarioError
    from scenarios.schema import parse_yaml_text
    text = ("name: q\nspacecraft: {inertia: [2, 3, 4], wheels: {max_torque: 0.1}}\n"
            "maneuver: {duration: 30, initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}, final: {q: [1.01241, 0, 0, 0]}}\n"
            "planners: [{name: eigenaxis}]\ncontroller: {name: none}\n")
    import scenarios
    with pytest.raises(ScenarioError) as yaml_error:
        scenarios.parse_scenario(parse_yaml_text(text))
    with pytest.raises(ValueError) as library_error:
        problem(qf=[1.01241, 0, 0, 0])
    reason = quat.unit_norm_error([1.01241, 0, 0, 0])
    assert reason == "a quaternion must have unit norm (got norm 1.01241; tolerance 1e-3)"
    assert reason in str(yaml_error.value) and reason in str(library_error.value)
    assert quat.unit_norm_error([1.0 + 0.9 * quat.UNIT_NORM_TOLERANCE, 0, 0, 0]) is None
    q = problem(q0=[1.0005, 0, 0, 0]).q0  # within the tolerance: normalised, as documented
    assert np.linalg.norm(q) == pytest.approx(1.0, abs=1e-15)


def test_shape_polynomial_says_how_to_plan_without_a_rate_bound():
    # Its default, duration: rate_limit (the paper's minimum time), needs a rate bound; it cannot
    # fall back to the problem's duration by itself, because whether it minimises time and honours
    # the rate bound are read from its options alone (planners.capabilities). The refusal says both ways out.
    slew = problem(omegaf=np.zeros(3))
    reason = PLANNERS["shape_polynomial"]().problem_error(slew)
    assert "needs a rate bound" in reason and "ManeuverProblem(..., max_rate=...)" in reason
    assert "options {'duration': 'scenario'}" in reason
    assert PLANNERS["shape_polynomial"]({"duration": "scenario", "terms": 1}).plan(slew).ok
    assert PLANNERS["shape_polynomial"]({"terms": 1}).plan(problem(omegaf=np.zeros(3), max_rate=0.05)).ok


@pytest.mark.parametrize("argument, words", [
    (None, "path must be a str or os.PathLike, got NoneType$"),
    ({"name": "x"}, r"got dict; a scenario mapping already read: scenarios.parse_scenario\(data\)"),
    (b"scenario.yaml", "got bytes"),
])
def test_load_names_a_path_that_is_not_one(argument, words):
    """``scenarios.load`` raised pathlib's 'expected str, bytes or os.PathLike object, not dict'
    (and, for bytes, 'argument should be a str object ...'); ``load_study`` names the argument."""
    import scenarios
    with pytest.raises(TypeError, match=words):
        scenarios.load(argument)
