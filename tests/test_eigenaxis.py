"""Eigenaxis planner: boundary conditions, inverse dynamics, bang-coast-bang time."""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from tests.conftest import finite_difference_torque

PROFILES = ("smooth", "trapezoidal", "min_time")


def non_principal_spacecraft(rng, max_torque=0.1):
    moments = rng.uniform(8.0, 20.0, 3)
    rotation = quat.rotation_matrix(quat.random_unit(rng))
    return Spacecraft(rotation @ np.diag(moments) @ rotation.T, wheels=ReactionWheels.from_body_axes(max_torque=max_torque))


@pytest.mark.parametrize("profile", PROFILES)
def test_reaches_target_at_rest(profile, rng):
    spacecraft = non_principal_spacecraft(rng)
    problem = ManeuverProblem(spacecraft, quat.random_unit(rng), np.zeros(3), quat.random_unit(rng), 300.0,
                              omegaf=np.zeros(3))
    reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)
    assert reference.status == "ok", reference.message
    end = reference.sample(reference.duration)
    assert quat.error_angle(end.q, problem.qf) < 1e-10
    assert np.linalg.norm(end.omega) < 1e-12
    assert quat.error_angle(reference.q(0.0), problem.q0) < 1e-12
    # After T the reference holds the final attitude at rest.
    later = reference.sample(reference.duration + 50.0)
    assert quat.error_angle(later.q, problem.qf) < 1e-10 and np.allclose(later.torque, 0)


@pytest.mark.parametrize("profile", PROFILES)
def test_feedforward_torque_is_the_inverse_dynamics_of_the_attitude(profile, rng):
    spacecraft = non_principal_spacecraft(rng)
    problem = ManeuverProblem(spacecraft, quat.random_unit(rng), np.zeros(3), quat.random_unit(rng), 200.0)
    reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)
    # Interior times away from the bang-coast-bang switches, where the torque jumps.
    t = np.linspace(0.03, 0.97, 37) * reference.duration
    omega_fd, torque_fd = finite_difference_torque(reference, spacecraft.inertia, t)
    sample = reference.sample(t)
    np.testing.assert_allclose(sample.omega, omega_fd, atol=1e-8)
    scale = np.max(np.abs(sample.torque))
    smooth = np.all(np.abs(sample.torque - torque_fd) < 1e-5 * scale, axis=1)
    assert smooth.mean() > 0.9  # only samples within h of a switch may differ
    gyroscopic = np.cross(sample.omega, sample.omega @ spacecraft.inertia.T)
    assert np.max(np.abs(gyroscopic)) > 1e-6 * scale  # the term that makes non-principal axes non-trivial


def test_minimum_time_about_a_principal_axis_is_the_bang_bang_time():
    inertia = np.array([19.5, 19.0, 12.6])
    u_max = 0.1
    spacecraft = Spacecraft(inertia, torquers=Torquers(max_torque=u_max))
    for axis_index, angle in ((0, 0.7), (1, np.pi), (2, 2.0)):
        axis = np.eye(3)[axis_index]
        problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle(axis, angle), 100.0)
        reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(problem)
        assert reference.duration == pytest.approx(2 * np.sqrt(angle * inertia[axis_index] / u_max), rel=1e-9)
        assert np.max(np.abs(reference.torque(np.linspace(0, reference.duration, 1001)))) == pytest.approx(u_max)


def test_bang_coast_bang_respects_torque_and_rate_bounds_off_axis(rng):
    spacecraft = non_principal_spacecraft(rng, max_torque=0.05)
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.random_unit(rng), 400.0, max_rate=0.02)
    for profile in ("trapezoidal", "min_time"):
        reference = PLANNERS["eigenaxis"]({"profile": profile}).plan(problem)
        sample = reference.sample(np.linspace(0, reference.duration, 20001))
        assert np.max(np.abs(sample.torque)) <= 0.05 * (1 + 1e-9)
        assert np.max(np.linalg.norm(sample.omega, axis=1)) <= 0.02 * (1 + 1e-9)


def test_too_short_a_duration_is_infeasible_not_an_exception():
    spacecraft = Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(max_torque=0.1))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 1, 0], np.pi), 30.0)
    reference = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(problem)
    assert reference.status == "infeasible"
    assert "minimum" in reference.message
    with pytest.raises(RuntimeError):
        reference.q(1.0)
