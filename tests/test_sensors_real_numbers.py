"""One "real number" check (``ocp.options.is_real``) for the sensors, the simulator and the problem:
a Python or NumPy integer or float, never a bool (Python's or NumPy's) nor a string; each caller
keeps its own message."""
from __future__ import annotations

import fractions

import numpy as np
import pytest

from ocp import AttitudeModel, SensorNoise, Simulator, Spacecraft, quat
from ocp.estimation import Gyro, StarTracker
from ocp.options import is_real
from planners import ManeuverProblem


@pytest.mark.parametrize("value", [1, 2.5, np.float32(0.5), np.float64(-1.0), np.int8(3), np.uint64(7),
                                   float("nan"), float("inf"), fractions.Fraction(1, 3)])
def test_numbers_are_real(value):
    assert is_real(value)


@pytest.mark.parametrize("value", [True, False, np.bool_(True), "1.0", None, [1.0], np.array([1.0]), 1j])
def test_bools_strings_and_containers_are_not(value):
    assert not is_real(value)


def test_the_callers_refuse_a_bool_with_their_own_messages():
    with pytest.raises(ValueError, match="arw must be a finite non-negative number, got True"):
        Gyro(arw=True)
    with pytest.raises(ValueError, match="rate must be a finite positive number of Hz or None, got True"):
        StarTracker(noise=[1e-5] * 3, rate=True)
    with pytest.raises(ValueError, match="sample_time must be a finite positive number of seconds, got True"):
        Simulator(AttitudeModel(Spacecraft([1.0, 2.0, 3.0])), True)
    with pytest.raises(ValueError, match="attitude_std must be a finite non-negative standard deviation, got"):
        SensorNoise(np.bool_(True), 0.0)
    with pytest.raises(ValueError, match="duration must be a finite positive number of seconds, got True"):
        ManeuverProblem(Spacecraft([1.0, 2.0, 3.0]), quat.IDENTITY, np.zeros(3), quat.IDENTITY, True)


def test_the_callers_take_numpy_numbers():
    assert Gyro(arw=np.float32(1e-4)).arw == pytest.approx(1e-4)
    assert Simulator(AttitudeModel(Spacecraft([1.0, 2.0, 3.0])), np.int64(1)).sample_time == 1.0
    problem = ManeuverProblem(Spacecraft([1.0, 2.0, 3.0]), quat.IDENTITY, np.zeros(3), quat.IDENTITY, np.float32(30.0))
    assert problem.duration == 30.0
