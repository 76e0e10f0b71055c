"""Public constructors and functions check their arguments (issue 11, section 3): each call below
used to return garbage (a NaN quaternion, a non-unit quaternion, a negative time grid) or fail deep
inside NumPy; now it raises ValueError/TypeError naming the argument and what was expected."""
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
    arguments = dict(spacecraft=SPACECRAFT, q0=quat.IDENTITY, omega0=np.zeros(3),
                     qf=quat.from_axis_angle([0, 0, 1], 0.5), duration=30.0)
    arguments.update(changes)
    return ManeuverProblem(**arguments)


@pytest.mark.parametrize("changes, words", [
    ({"q0": [0, 0, 0, 0]}, "q0 must be a non-zero quaternion"),
    ({"qf": [0, 0, 0, 0]}, "qf must be a non-zero quaternion"),
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
