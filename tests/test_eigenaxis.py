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
    # ω by central differences of q is O(h²) only where θ̇ is smooth: not within h = 1e-3 s of a
    # switch (the apex of a triangle profile, at T/2, is one of the samples)
    switches = np.asarray(reference.breakpoints, dtype=float).reshape(-1)
    away = np.min(np.abs(t[:, None] - switches[None, :]), axis=1, initial=np.inf) > 2e-3
    assert away.mean() > 0.9
    np.testing.assert_allclose(sample.omega[away], omega_fd[away], atol=1e-8)
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
        # wheels along the body axes, from rest at zero momentum: the total momentum stays zero and
        # the wheels' torque is −I ω̇ (the body's ω × I ω is their own −ω × A h_w)
        assert np.max(np.abs(sample.omega_dot @ spacecraft.inertia.T)) <= 0.05 * (1 + 1e-9)
        assert np.max(np.linalg.norm(sample.omega, axis=1)) <= 0.02 * (1 + 1e-9)


def test_too_short_a_duration_is_infeasible_not_an_exception():
    spacecraft = Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(max_torque=0.1))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 1, 0], np.pi), 30.0)
    reference = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(problem)
    assert reference.status == "infeasible"
    assert "minimum" in reference.message
    with pytest.raises(RuntimeError):
        reference.q(1.0)


def test_the_quintic_honours_the_rate_bound_or_is_infeasible():
    """From rest to rest the quintic's |θ̇| peaks at 15 Θ / (8 T) mid-slew (θ = Θ (10 s³ − 15 s⁴ + 6 s⁵),
    s = t / T): a bound just above it is met, one just below makes the row infeasible, naming the
    bound's source and the T that would do (the smooth profile ignored maneuver.max_rate)."""
    spacecraft = Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(max_torque=0.1))
    angle, T = 2.0, 100.0
    peak = 15 * angle / (8 * T)
    for bound, met in ((peak * 1.001, True), (peak * 0.999, False)):
        problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], angle), T,
                                  omegaf=np.zeros(3), max_rate=bound)
        reference = PLANNERS["eigenaxis"]({"profile": "smooth"}).plan(problem)
        if met:
            assert reference.status == "ok", reference.message
            rates = np.linalg.norm(reference.sample(np.linspace(0, T, 20001)).omega, axis=1)
            assert np.max(rates) == pytest.approx(peak, rel=1e-9) and np.argmax(rates) == 10000
        else:
            assert reference.status == "infeasible"
            assert f"peaks at {peak:.4g} rad/s" in reference.message and "(the problem's: maneuver.max_rate, else requirements.rate.max)" in reference.message
            assert f"T >= {15 * angle / (8 * bound):.8g} s keeps it within" in reference.message
    option = PLANNERS["eigenaxis"]({"profile": "smooth", "max_rate": peak / 2}).plan(problem)
    assert option.status == "infeasible" and "(option max_rate)" in option.message


def test_quintic_peak_rate_against_dense_sampling(rng):
    from planners.eigenaxis import QuinticProfile
    for _ in range(100):
        duration = rng.uniform(1.0, 200.0)
        profile = QuinticProfile(rng.uniform(0.1, 3.0), duration, rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05))
        dense = np.max(np.abs(profile.rate(np.linspace(0.0, duration, 200001))))
        assert profile.peak_rate() == pytest.approx(dense, rel=1e-9)


def test_a_duration_too_short_under_the_rate_bound_names_it():
    spacecraft = Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(max_torque=0.1))
    # torques alone: 2 sqrt(Θ J / u) = 35.0 s; at 0.01 rad/s the coast makes it Θ/w + w J/u = 160 s
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], 1.57), 120.0,
                              max_rate=0.01)
    reference = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(problem)
    assert reference.status == "infeasible"
    assert f"time {1.57 / 0.01 + 0.01 * 12.6 / 0.1:.6g} s under the torque bounds and the rate bound 0.01 rad/s " \
           "(the problem's: maneuver.max_rate, else requirements.rate.max)" in reference.message


def test_a_triangle_profile_has_one_switch_and_a_coast_two():
    """Minimum time without a rate bound is a triangle, one switch at T/2 = sqrt(Θ J / u); a rate bound
    adds a coast between two switches (the triangle's coast of 1e-16 s made a second breakpoint
    8.9e-16 s after the first, and a 4100-node flight table)."""
    spacecraft = Spacecraft([2.0, 2.0, 2.0], torquers=Torquers(max_torque=0.5))
    target = quat.from_axis_angle([1, 0, 0], np.pi)
    triangle = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(
        ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), target, 20.0, omegaf=np.zeros(3)))
    assert triangle.breakpoints == pytest.approx([np.sqrt(np.pi * 2.0 / 0.5)], rel=1e-12)
    coast = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(
        ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), target, 20.0, omegaf=np.zeros(3), max_rate=0.5))
    ramp = 0.5 / (0.5 / 2.0)  # w / α, α = u / J
    assert coast.breakpoints == pytest.approx([ramp, np.pi / 0.5], rel=1e-12)  # the coast ends at Θ / w
