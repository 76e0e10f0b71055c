"""Bad numbers at the library API get a clear error at the call, naming the field, the value and
its type: actuator limits and wheel axes of booleans, complex numbers or text (NumPy read ``True``
as 1 and ``1+0j`` as 1), a star tracker faster than the schema's bound (its update count overflowed
and it stopped updating after 2 s at 1e308 Hz), a principal moment far below any spacecraft's
(1e-250 kg m^2 hung the torque-free coast after the slew) or an inertia far above (1e300 kg m^2
leaked NumPy's overflow warnings); and the eigenaxis planner's messages write huge or tiny durations
in powers of ten, not 157 digits, and an overflow of its arithmetic is a failed reference.

The bounds are the schema's own constants (one value for both faces)."""
from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from ocp import Spacecraft
from ocp.dynamics.actuator_kinds import Magnetorquers, ReactionWheels, Torquers
from ocp.dynamics.spacecraft import MAX_INERTIA, MIN_INERTIA
from ocp.errors import ModelError
from ocp.estimation import Gyro, StarTracker
from ocp.estimation.sensors import STAR_TRACKER_RATE_LIMIT_HZ
from ocp.options import real_array
from planners import PLANNERS, ManeuverProblem
from scenarios.schema import estimation as schema_estimation
from scenarios.schema import model as schema_model


@pytest.mark.parametrize("build, field, named", [
    (lambda: Torquers(max_torque=True), "max_torque", "True (bool) is no real number"),
    (lambda: Magnetorquers(max_dipole=[1, True, 1]), "max_dipole", "True (bool) is no real number"),
    (lambda: Torquers(max_torque=np.array([1.0, 1.0, 1.0], dtype=complex)), "max_torque",
     "an array of complex numbers (dtype complex128)"),
    (lambda: Torquers(max_torque=[1 + 0j, 1, 1]), "max_torque", "(1+0j) (complex) is no real number"),
    (lambda: Torquers(max_torque=np.array([1, "2", 1], dtype=object)), "max_torque", "'2' (str) is no real number"),
    (lambda: Magnetorquers(max_dipole=np.array([True, True, True])), "max_dipole", "an array of booleans"),
    (lambda: ReactionWheels.from_body_axes(max_torque=[0.1, np.True_, 0.1]), "max_torque",
     "np.True_ (bool) is no real number"),
    (lambda: ReactionWheels.from_body_axes(max_momentum=[0.1, None, 0.1]), "max_momentum",
     "None (NoneType) is no real number"),
    (lambda: ReactionWheels(np.eye(3, dtype=complex)), "axes", "an array of complex numbers"),
    (lambda: ReactionWheels([[1, 0, 0], [0, True, 0], [0, 0, 1]]), "axes", "True (bool) is no real number"),
    (lambda: ReactionWheels(np.eye(3), failed=[True]), "failed", "True (bool)"),
    (lambda: ReactionWheels(np.eye(3), failed=[1.7]), "failed", "1.7 (float)"),
])
def test_an_actuator_number_that_is_no_real_number_is_refused_naming_it(build, field, named):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way
        with pytest.raises(ModelError) as raised:
            build()
    assert raised.value.field == field
    assert named in str(raised.value), str(raised.value)


def test_wheel_axes_must_be_finite_and_huge_ones_are_directions():
    with pytest.raises(ModelError, match=r"axes: expected finite wheel axes, got \[\[nan"):
        ReactionWheels([[np.nan, 0, 0], [0, 1, 0], [0, 0, 1]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the norm of [1e300, 1e300, 0] overflowed
        wheels = ReactionWheels([[1e300, 0, 0], [1e300, 1, 0], [0, 0, 1]])
    assert np.allclose(wheels.axes[:, 0], [np.sqrt(0.5), np.sqrt(0.5), 0.0])


@pytest.mark.parametrize("limit", [0.1, 7, np.float32(0.5), [0.1, 0.2, 0.3], np.array([1, 2, 3]), np.inf])
def test_real_limits_of_any_numeric_type_are_accepted(limit):
    assert np.array_equal(Torquers(max_torque=limit).max_torque, np.broadcast_to(np.asarray(limit, dtype=float), 3))


@pytest.mark.parametrize("value, reason", [
    (True, "True (bool) is no real number"), ([1, 2 + 0j], "(2+0j) (complex)"), ([[1, 2], [3]], "[1, 2] (list) is no real number"),
    ([], "no numbers"), (np.array(["1"]), "an array of text"), ([10**400], "beyond the floats' range"),
])
def test_real_array_names_what_is_no_real_number(value, reason):
    with pytest.raises(ValueError, match=re.escape(reason)):
        real_array(value)


def test_the_schema_and_the_library_share_their_bounds():
    assert schema_model.MIN_INERTIA is MIN_INERTIA and schema_model.MAX_INERTIA is MAX_INERTIA
    assert schema_estimation.STAR_TRACKER_RATE_LIMIT_HZ is STAR_TRACKER_RATE_LIMIT_HZ


@pytest.mark.parametrize("rate", [1e308, STAR_TRACKER_RATE_LIMIT_HZ * 1.5])
def test_a_star_tracker_beyond_the_rate_limit_is_refused(rate):
    with pytest.raises(ValueError, match=r"rate must be at most 1e\+07 Hz .*got " + re.escape(f"{rate:g}")):
        StarTracker(noise=[1e-5] * 3, rate=rate)


def test_a_star_tracker_at_the_rate_limit_updates_at_every_count():
    # Oracle: at r Hz an update falls on every sample 1/r apart, over the longest run (1e8 s).
    tracker = StarTracker(noise=[1e-5] * 3, rate=STAR_TRACKER_RATE_LIMIT_HZ)
    times = 1e8 - 1e-7 * np.arange(5)[::-1] - 0.5e-7
    assert tracker.available(times).all()


@pytest.mark.parametrize("build, named", [
    (lambda: StarTracker(noise=[1e-5, True, 1e-5]), "noise must be 3 finite numbers, got [1e-05, True, 1e-05]: "
                                                   "True (bool) is no real number"),
    (lambda: StarTracker(noise=[1e-5] * 3, boresight=[0, 0, 1 + 0j]), "(1+0j) (complex) is no real number"),
    (lambda: Gyro(bias=np.array([0, "0", 0], dtype=object)), "'0' (str) is no real number"),
    (lambda: StarTracker(noise=[1e-5] * 3, rate=True), "got True (bool)"),
])
def test_sensor_numbers_that_are_no_real_numbers_are_refused(build, named):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError) as raised:
            build()
    assert named in str(raised.value), str(raised.value)


@pytest.mark.parametrize("inertia, words", [
    ([1e-250, 1e-250, 1e-250], r"least principal moment must be at least 1e-09 kg m\^2 .*got 1e-250"),
    ([MIN_INERTIA / 2, 1.0, 1.0], r"least principal moment must be at least 1e-09 .*got 5e-10"),
    ([1e300, 1e300, 1e300], r"expected entries within ±1e\+12 kg m\^2"),
    ([[2e12, 0, 0], [0, 2e12, 0], [0, 0, 2e12]], r"expected entries within ±1e\+12 kg m\^2"),
])
def test_an_inertia_beyond_the_schema_bounds_is_refused(inertia, words):
    with pytest.raises(ModelError, match=words):
        Spacecraft(inertia)


def test_the_inertia_bounds_themselves_are_accepted():
    assert Spacecraft([MIN_INERTIA, MIN_INERTIA, MIN_INERTIA]).inertia[0, 0] == MIN_INERTIA
    assert Spacecraft([MAX_INERTIA, MAX_INERTIA, MAX_INERTIA]).inertia[0, 0] == MAX_INERTIA


def _problem(inertia: float, max_torque: float) -> ManeuverProblem:
    spacecraft = Spacecraft([inertia] * 3, torquers=Torquers(max_torque=max_torque))
    return ManeuverProblem(spacecraft, [1, 0, 0, 0], [0, 0, 0], [0, 1, 0, 0], 100.0, omegaf=[0, 0, 0])


def test_eigenaxis_writes_a_huge_duration_in_powers_of_ten():
    # Oracle: rest-to-rest bang-bang about a principal axis, t = 2 sqrt(theta I / tau) = 2 sqrt(pi 1e312).
    least = 2 * np.sqrt(np.pi * MAX_INERTIA) * 1e150
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fastest = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(_problem(MAX_INERTIA, 1e-300))
        refused = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(_problem(MAX_INERTIA, 1e-300))
    assert fastest.duration == pytest.approx(least, rel=1e-9)
    assert f"minimum time {least:.4g} s" in fastest.message, fastest.message
    assert refused.status == "infeasible"
    assert f"a maneuver.duration of at least {least * (1 + 1e-4):.3e} s admits it" in refused.message, refused.message
    assert not re.search(r"\d{20}", fastest.message + refused.message)


def test_eigenaxis_writes_a_tiny_duration_in_powers_of_ten():
    least = 2 * np.sqrt(np.pi * MIN_INERTIA / 1e10)
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(_problem(MIN_INERTIA, 1e10))
    assert f"minimum time {least:.4g} s" in reference.message, reference.message


@pytest.mark.parametrize("profile", ["trapezoidal", "min_time"])
def test_an_eigenaxis_overflow_is_a_failed_reference_not_a_warning(profile):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # was "overflow encountered in divide" and an ok reference of NaN s
        reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(_problem(MIN_INERTIA, 1e300))
    assert not reference.ok
    assert reference.message.startswith("numerical failure: FloatingPointError: overflow encountered"), reference.message
    assert "principal moments [1e-09, 1e-09, 1e-09] kg m^2" in reference.message
    assert "spacecraft.torquers.max_torque" in reference.message
