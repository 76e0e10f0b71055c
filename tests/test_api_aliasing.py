"""The library API keeps no caller's array and hands out no array it relies on: ``Spacecraft``, its
actuators, ``ManeuverProblem``, a cached transcription and ``ocp.quat``'s constants store read-only
private copies. A caller reusing a buffer changes nothing; an in-place edit of a stored array
raises. Also the numbers the API accepts (numpy integers, not bools) and a numerical overflow in a
planner (a failed reference, not an exception)."""
import numpy as np
import pytest

from ocp import ReactionWheels, Simulator, SolverCache, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem

MOMENTS = (19.5, 19.0, 12.6)
ANGLE = np.pi / 2
T = 120.0


def craft(inertia=MOMENTS, **wheels):
    return Spacecraft(inertia, wheels=ReactionWheels.from_body_axes(**({"max_torque": 0.1} | wheels)))


def slew(spacecraft=None, omega0=None, omegaf=None, duration=T, **kw):
    """A rest-to-rest slew of 90 deg about body y."""
    return ManeuverProblem(spacecraft or craft(), q0=quat.IDENTITY, omega0=np.zeros(3) if omega0 is None else omega0,
                           qf=quat.from_axis_angle([0, 1, 0], ANGLE), duration=duration,
                           omegaf=np.zeros(3) if omegaf is None else omegaf, **kw)


def energy(reference, n=4001):
    """∫‖τ‖² dt of a reference, by the trapezoid rule on n samples."""
    t = np.linspace(0.0, reference.duration, n)
    return float(np.trapezoid(np.sum(reference.sample(t).torque ** 2, axis=1), t))


# --- Spacecraft and its actuators --------------------------------------------------------------

def test_spacecraft_keeps_a_copy_of_a_reused_inertia_matrix():
    J = np.diag(MOMENTS)
    spacecraft = craft(J)
    J[:] = np.diag([1.0, 1.0, 5.0])  # the caller's next spacecraft: violates I1 + I2 >= I3
    np.testing.assert_array_equal(spacecraft.inertia, np.diag(MOMENTS))
    # the plan uses 19 kg m² about y: min-energy single-axis rest-to-rest ∫τ² = 12 I² θ² / T³
    reference = PLANNERS["collocation"]({}).plan(slew(spacecraft))
    assert reference.ok, reference.message
    assert energy(reference) == pytest.approx(12 * 19.0**2 * ANGLE**2 / T**3, rel=1e-3)


@pytest.mark.parametrize("given", [MOMENTS, np.array(MOMENTS), np.diag(MOMENTS)])
def test_spacecraft_inertia_is_read_only(given):
    spacecraft = craft(given)
    with pytest.raises(ValueError, match="read-only"):
        spacecraft.inertia[1, 1] = 40.0
    np.testing.assert_array_equal(spacecraft.inertia, np.diag(MOMENTS))


def test_wheels_keep_copies_of_their_limits_and_freeze_them():
    limits, axes = np.array([0.1, 0.1, 0.1]), np.eye(3)
    wheels = ReactionWheels(axes=axes, max_torque=limits, max_momentum=limits * 10)
    limits[:] = 5.0
    axes[:] = 0.0
    np.testing.assert_array_equal(wheels.max_torque, [0.1, 0.1, 0.1])
    np.testing.assert_array_equal(wheels.max_momentum, [1.0, 1.0, 1.0])
    np.testing.assert_array_equal(wheels.axes, np.eye(3))
    for array in (wheels.axes, wheels.max_torque, wheels.max_momentum):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


# --- ManeuverProblem ---------------------------------------------------------------------------

def test_problem_keeps_copies_of_reused_rate_buffers():
    omega0, omegaf, momentum = np.zeros(3), np.zeros(3), np.zeros(3)
    problem = slew(omega0=omega0, omegaf=omegaf, wheel_momentum0=momentum)
    omega0[:], omegaf[:], momentum[:] = [0, 0.01, 0], [0, 0.005, 0], 0.3  # the next problem's values
    np.testing.assert_array_equal(problem.omega0, np.zeros(3))
    np.testing.assert_array_equal(problem.omegaf, np.zeros(3))
    np.testing.assert_array_equal(problem.wheel_momentum0, np.zeros(3))
    reference = PLANNERS["eigenaxis"]({}).plan(problem)
    assert reference.ok, reference.message
    ends = reference.sample(np.array([0.0, reference.duration]))
    np.testing.assert_allclose(ends.omega, 0.0, atol=1e-15)  # rest to rest, as asked


@pytest.mark.parametrize("name", ["q0", "qf", "omega0", "omegaf", "wheel_momentum0"])
def test_problem_arrays_are_read_only(name):
    problem = slew()
    with pytest.raises(ValueError, match="read-only"):
        getattr(problem, name)[0] = 0.5


def test_shape_polynomial_reference_does_not_follow_the_problem():
    omega0, omegaf = np.zeros(3), np.zeros(3)
    problem = slew(omega0=omega0, omegaf=omegaf)
    reference = PLANNERS["shape_polynomial"]({"duration": "scenario"}).plan(problem)
    assert reference.ok, reference.message
    t = np.array([0.0, 30.0, 60.0, 90.0, 120.0])
    before = reference.sample(t)
    omega0[:], omegaf[:] = [0.05, 0, 0], [0, 0.05, 0]
    with pytest.raises(ValueError, match="read-only"):
        problem.qf[:] = quat.from_axis_angle([1, 0, 0], 2.0)
    after = reference.sample(t)
    for field in ("q", "omega", "omega_dot", "torque"):
        np.testing.assert_array_equal(getattr(after, field), getattr(before, field))
    np.testing.assert_allclose(after.q[-1], quat.from_axis_angle([0, 1, 0], ANGLE), atol=1e-12)


def test_eigenaxis_reference_start_is_read_only():
    reference = PLANNERS["eigenaxis"]({}).plan(slew())
    with pytest.raises(ValueError, match="read-only"):
        reference.q0[0] = 0.0


def test_identity_constant_is_read_only():
    with pytest.raises(ValueError, match="read-only"):
        quat.IDENTITY[0] = 0.0
    np.testing.assert_array_equal(quat.IDENTITY, [1.0, 0.0, 0.0, 0.0])


# --- a cached transcription --------------------------------------------------------------------

def test_collocation_transcription_is_read_only_and_later_plans_unchanged():
    planner = PLANNERS["collocation"]({}, cache=SolverCache())
    t = np.linspace(0.0, T, 241)
    first = planner.plan(slew())
    assert first.ok, first.message
    tables = [first.transcription.tau, first.transcription.derivative, first.transcription.quadrature,
              first.transcription.midpoint_weights]
    for table in tables:
        with pytest.raises(ValueError, match="read-only"):
            table[...] *= 1.01
    again = planner.plan(slew())
    np.testing.assert_array_equal(again.sample(t).torque, first.sample(t).torque)


# --- numbers -----------------------------------------------------------------------------------

@pytest.mark.parametrize("value", [np.int64(120), np.int32(120), np.float32(120.0), 120])
def test_duration_accepts_numpy_numbers(value):
    problem = slew(duration=value)
    assert type(problem.duration) is float and problem.duration == 120.0


@pytest.mark.parametrize("key", ["duration", "max_rate"])
@pytest.mark.parametrize("value", [True, np.bool_(True)])
def test_bool_is_no_number(key, value):
    kw = {"duration": value} if key == "duration" else {"max_rate": value}
    with pytest.raises(ValueError, match=key):
        slew(**kw)


def test_numpy_integer_rate_bound_and_sample_time():
    problem = slew(max_rate=np.int64(1))
    assert type(problem.max_rate) is float and problem.max_rate == 1.0
    simulator = Simulator(problem.model, sample_time=np.int64(1))
    assert simulator.sample_time == 1.0
    with pytest.raises(ValueError, match="sample_time"):
        Simulator(problem.model, sample_time=True)


@pytest.mark.parametrize("name", ["eigenaxis", "costate_tpbvp"])
def test_overflowing_duration_gives_a_failed_reference(name):
    reference = PLANNERS[name]({}).plan(slew(duration=1e300))
    assert not reference.ok
    assert "OverflowError" in reference.message
