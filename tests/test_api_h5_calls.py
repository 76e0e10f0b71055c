"""Bad library calls found by trying the public API: each is refused at the call with a message
naming the argument and the value. ``ReactionWheels.from_body_axes(4)`` built three wheels, ``"3"``
raised a slicing ``TypeError`` from inside and ``True`` built one wheel; a ``wheel_momentum0`` for
a spacecraft without wheels was "must be 0 finite numbers"."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from ocp import Spacecraft
from ocp.dynamics.actuator_kinds import ReactionWheels
from ocp.errors import ModelError
from planners import ManeuverProblem


@pytest.mark.parametrize("n_axes, shown", [(4, "4 (int)"), (0, "0 (int)"), ("3", "'3' (str)"), (True, "True (bool)"),
                                           (2.0, "2.0 (float)")])
def test_from_body_axes_takes_one_to_three_wheels(n_axes, shown):
    with pytest.raises(ModelError, match=r"n_axes: expected 1, 2 or 3 wheels along the body axes, got "
                                         + shown.replace("(", r"\(").replace(")", r"\)")):
        ReactionWheels.from_body_axes(n_axes)


@pytest.mark.parametrize("n_axes", [1, 2, 3, np.int64(2)])
def test_from_body_axes_builds_wheels_along_the_first_axes(n_axes):
    assert np.array_equal(ReactionWheels.from_body_axes(n_axes).axes, np.eye(3)[:, :int(n_axes)])


def test_wheel_momentum_for_a_spacecraft_without_wheels_says_so():
    with pytest.raises(ValueError, match=r"wheel_momentum0 must be None \(or empty\) for a spacecraft without wheels, "
                                         r"got \[1.0\]"):
        ManeuverProblem(Spacecraft([1, 1, 1]), [1, 0, 0, 0], [0, 0, 0], [0, 1, 0, 0], 10.0, wheel_momentum0=[1.0])
    problem = ManeuverProblem(Spacecraft([1, 1, 1]), [1, 0, 0, 0], [0, 0, 0], [0, 1, 0, 0], 10.0)
    assert replace(problem, duration=5.0).wheel_momentum0.shape == (0,)  # its own empty array still passes


@pytest.mark.parametrize("args, words", [
    (([np.nan, 0, 0, 1], [0.1, 0, 0], np.eye(3), 0.0), r"q_start must be finite numbers of shape \(4,\)"),
    (([1, 0, 0, 0], [0.1, 0], np.eye(3), 0.0), r"omega_start must be finite numbers of shape \(3,\), got shape \(2,\)"),
    (([1, 0, 0, 0], [True, 0, 0], np.eye(3), 0.0), r"omega_start must be real numbers, got \[True, 0, 0\]: True \(bool\)"),
    (([1, 0, 0, 0], [1e300, 0, 0], np.eye(3), 0.0), r"omega_start must be within ±1000 rad/s"),
    (([1, 0, 0, 0], [0.1, 0, 0], np.zeros((3, 3)), 0.0), r"inertia must be positive definite"),
    (([1, 0, 0, 0], [0.1, 0, 0], [1, 2, 3], 0.0), r"inertia must be finite numbers of shape \(3, 3\), got shape \(3,\)"),
    (([1, 0, 0, 0], [0.1, 0, 0], np.eye(3), np.nan), r"start must be a finite time \[s\], got nan"),
])
def test_torque_free_motion_refuses_bad_arguments_at_the_call(args, words):
    import warnings

    from planners.torque_free import TorqueFreeMotion
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # NaN start: "invalid value encountered in cast"; 1e300: overflow
        with pytest.raises(ValueError, match="TorqueFreeMotion: " + words):
            TorqueFreeMotion(*args)([1.0])


def test_torque_free_motion_refuses_a_time_beyond_its_span_instead_of_extrapolating():
    # Was: the chunk index capped at 1e6, so 1e12 s integrated 1e6 chunks (about 6 ms each: 1.7 h)
    # and then evaluated the last chunk's polynomial 1e12 s beyond its end.
    from planners.torque_free import MAX_COAST_CHUNKS, TorqueFreeMotion
    motion = TorqueFreeMotion([1, 0, 0, 0], [0.1, 0.2, 0.0], np.diag([1.0, 2.0, 3.0]), 5.0)
    with pytest.raises(ValueError, match=r"t = 1e\+12 s is 1e\+12 s after the start of the coast, beyond the "):
        motion([1.0, 1e12])
    assert MAX_COAST_CHUNKS * motion.chunk > 1e6  # a million seconds of coast remain reachable
    with pytest.raises(ValueError, match=r"times must be finite"):
        motion([np.inf])


def _plain_problem() -> ManeuverProblem:
    return ManeuverProblem(Spacecraft([1, 2, 2.5]), [1, 0, 0, 0], [0, 0, 0], [0, 1, 0, 0], 10.0, max_rate=0.5,
                           rate_requirement=1.0)


@pytest.mark.parametrize("option, margin, words", [
    ("0.1", 0.0, r"option must be a finite positive rate \[rad/s\] or None, got '0.1' \(str\)"),
    (-1.0, 0.0, r"option must be a finite positive rate .*got -1.0 \(float\)"),  # was -1.0, a negative bound
    (True, 0.0, r"option .*got True \(bool\)"),
    (None, 1.0, r"margin must be a fraction in \[0, 1\), got 1.0"),  # was a bound of 0 rad/s
    (None, "0.1", r"margin must be a fraction in \[0, 1\), got '0.1' \(str\)"),  # was a TypeError from inside
])
def test_rate_bound_refuses_bad_arguments(option, margin, words):
    with pytest.raises(ValueError, match="rate_bound: " + words):
        _plain_problem().rate_bound(option, margin)


def test_rate_bound_is_the_smallest_bound():
    problem = _plain_problem()  # max_rate 0.5, requirement 1.0
    assert problem.rate_bound(None) == 0.5 and problem.rate_bound(0.2) == 0.2
    assert problem.rate_bound(None, 0.6) == pytest.approx(0.4)


@pytest.mark.parametrize("duration", ["1", True, -1.0, np.nan])
def test_environment_torque_bound_refuses_a_bad_duration(duration):
    with pytest.raises(ValueError, match=r"environment_torque_bound: duration must be a finite time >= 0 \[s\], got"):
        _plain_problem().environment_torque_bound(duration)
