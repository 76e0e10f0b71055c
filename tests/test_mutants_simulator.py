"""The simulator's sampling, hold and noise against hand-worked values and their definitions: the
last sample is shortened to end at the duration, wheels saturated by momentum never exceed it
(``h_w + g Δt`` within ``±h_max`` from the momentum at each sample), and the attitude noise is a
rotation by the drawn vector (mean square angle 3σ²); a time-varying environment torque is
integrated at the right times (against scipy on the model's own equations), by CVODES too; a
duration that is a whole number of samples up to rounding takes that many, the shortened last sample
is integrated and saturated over its own length, the initial quaternion is normalised, and a run of
exactly ``max_samples`` samples is allowed."""
import math
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from controllers import CONTROLLERS
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Command,
    Environment,
    ReactionWheels,
    Simulator,
    Spacecraft,
    Torquers,
    quat,
)
from ocp.errors import SimulationArgumentError
from ocp.simulation.simulator import SensorNoise, measure
from planners import ManeuverProblem

QF = quat.from_axis_angle([0.3, -0.5, 0.8], np.deg2rad(90.0))


def problem(max_momentum=None):
    wheels = ReactionWheels.from_body_axes(max_torque=0.02, max_momentum=max_momentum)
    return ManeuverProblem(Spacecraft([0.6, 0.5, 0.4], wheels=wheels), quat.IDENTITY, np.zeros(3), QF, 60.0,
                           omegaf=np.zeros(3))


def test_the_last_sample_is_shortened_to_end_at_the_duration():
    p = problem()
    for python_loop in (True, False):
        result = Simulator(p.model, 0.1, python_loop=python_loop).run(
            CONTROLLERS["eigenaxis_pd"](), p.initial_state, 1.05, target=(p.qf, p.omegaf))
        np.testing.assert_allclose(result.t, np.r_[np.arange(11) * 0.1, 1.05], rtol=0, atol=1e-15)


def test_wheels_saturated_by_momentum_stay_within_it_in_the_python_loop():
    h_max = 0.01
    p = problem(max_momentum=h_max)
    result = Simulator(p.model, 0.1, python_loop=True).run(
        CONTROLLERS["eigenaxis_pd"]({"kp": 0.5, "kd": 1.5}), p.initial_state, 20.0, target=(p.qf, p.omegaf))
    assert np.any(result.saturated)
    assert np.max(np.abs(result.wheel_momentum)) > 0.99 * h_max  # the limit is reached
    assert np.max(np.abs(result.wheel_momentum)) <= h_max * (1 + 1e-9)


def test_the_attitude_noise_turns_by_the_drawn_rotation_vector():
    sigma = 1e-3
    x = np.r_[quat.normalize(np.array([0.7, 0.1, -0.4, 0.3])), 0.01, 0.0, -0.02]
    rng = np.random.default_rng(4)
    noise = SensorNoise(attitude_std=sigma)
    angles = np.array([quat.error_angle(measure(x, 0.0, noise, rng).q, x[0:4]) for _ in range(4000)])
    assert abs(np.mean(angles**2) / (3 * sigma**2) - 1) < 0.1  # chi-square with 12000 dof: about 1.3 %


def gravity_gradient_drift() -> tuple[AttitudeModel, np.ndarray, float, Any]:
    """``(model, x0, duration, truth)``: a full-inertia body drifting under gravity gradient along a
    circular orbit, uncontrolled, and the model's own equations integrated by scipy's DOP853 from
    t = 0 (``truth.y`` every 10 s)."""
    spacecraft = Spacecraft([[0.9, 0.05, 0.0], [0.05, 0.4, 0.02], [0.0, 0.02, 0.6]], torquers=Torquers(1.0))
    model = AttitudeModel(spacecraft, Environment(CircularOrbit(500e3, 0.9), gravity_gradient=True))
    x0 = np.r_[quat.normalize(np.array([0.8, 0.3, -0.2, 0.4])), 2e-3, -1e-3, 5e-4]
    duration = 600.0
    u, p = np.zeros(model.nu), np.zeros(3)
    truth = solve_ivp(lambda t, x: model.rhs(x, u, t, p).full().ravel(), (0.0, duration), x0, method="DOP853",
                      rtol=1e-12, atol=1e-14, t_eval=np.arange(0.0, duration + 1.0, 10.0))
    return model, x0, duration, truth


def test_a_time_varying_torque_is_held_at_the_right_times_against_scipy():
    """Gravity gradient along a circular orbit, no control: the run (both paths, 20 RK4 sub-steps a
    sample) is the model's own equations integrated by scipy's DOP853 from t = 0."""
    model, x0, duration, truth = gravity_gradient_drift()
    for python_loop in (True, False):
        result = Simulator(model, 10.0, max_step=0.5, python_loop=python_loop).run(CONTROLLERS["none"](), x0, duration)
        assert np.max(quat.error_angle(result.q, truth.y[:4].T)) < 1e-9
        np.testing.assert_allclose(result.omega, truth.y[4:].T, atol=1e-11)


def test_no_rk4_sub_step_is_longer_than_max_step():
    """⌈T_s / max_step⌉ sub-steps, by hand."""
    model = problem().model
    for sample_time, max_step, substeps in ((0.1, 0.03, 4), (0.1, 0.05, 2), (0.1, 0.1, 1), (1.0, 0.3, 4), (0.1, 0.2, 1)):
        assert Simulator(model, sample_time, max_step=max_step).substeps == substeps


def test_cvodes_integrates_a_time_varying_torque_at_the_right_times_against_scipy():
    """As above with CVODES, which integrates each hold on a normalised time s in [0, 1]: the
    environment must be evaluated at t_k + s T_s, not t_k + s (10 s samples, so that the two part)."""
    model, x0, duration, truth = gravity_gradient_drift()
    result = Simulator(model, 10.0, integrator="cvodes", rtol=1e-12, atol=1e-14).run(CONTROLLERS["none"](), x0, duration)
    assert np.max(quat.error_angle(result.q, truth.y[:4].T)) < 1e-8  # 2.5e-10 rad; evaluated at t_k + s: 8e-4
    np.testing.assert_allclose(result.omega, truth.y[4:].T, atol=1e-10)


@pytest.mark.parametrize("duration, sample_time, samples", [(0.07, 0.01, 7), (0.56, 0.01, 56), (0.3, 0.1, 3), (1.0, 0.1, 10)])
def test_a_duration_of_whole_samples_up_to_rounding_takes_that_many(duration, sample_time, samples):
    """0.07 / 0.01 is 7.000000000000001 in floating point (0.56 / 0.01 is 56.00000000000001): ⌈ ⌉ of
    it would add an eighth sample of zero length (a repeated final time that the metrics then count
    as an interval); 0.3 / 0.1 is 2.9999999999999996."""
    p = problem()
    for python_loop in (True, False):
        result = Simulator(p.model, sample_time, python_loop=python_loop).run(
            CONTROLLERS["eigenaxis_pd"](), p.initial_state, duration, target=(p.qf, p.omegaf))
        assert result.t.size == samples + 1 and result.saturated.size == samples
        assert np.all(np.diff(result.t) > 0.5 * sample_time) and result.t[-1] == duration


def test_the_shortened_last_sample_is_integrated_over_its_own_length():
    """A torque-free spin about a principal axis, ω = 0.2 rad/s about z: q(t) = [cos(ω t / 2), 0, 0,
    sin(ω t / 2)] (closed form) at every sample, 10 whole samples of 1 s and a last one of 0.5 s."""
    model = AttitudeModel(Spacecraft([2.0, 3.0, 4.0], torquers=Torquers(1.0)))
    rate = 0.2
    for python_loop in (True, False):
        result = Simulator(model, 1.0, max_step=0.01, python_loop=python_loop).run(
            CONTROLLERS["none"](), np.r_[quat.IDENTITY, 0.0, 0.0, rate], 10.5)
        expected = np.stack([np.cos(0.5 * rate * result.t), 0 * result.t, 0 * result.t, np.sin(0.5 * rate * result.t)], axis=1)
        assert result.t[-1] == 10.5
        assert np.max(quat.error_angle(result.q, expected)) < 1e-12


class ConstantWheelTorque:
    """Asks wheel 1 for 0.1 N m at every sample (a Python law: the simulator's Python loop)."""

    def reset(self, spacecraft, sample_time, target=None):
        pass

    def __call__(self, t, measurement, reference):
        return Command(wheel_torque=np.array([0.1, 0.0, 0.0]))


def test_the_shortened_last_sample_is_saturated_over_its_own_length():
    """h_1 grows 0.1 N m s per second, h_max = 1.04 N m s: 1.0 at t = 10 s; over the last sample of
    0.5 s the wheel may still take (1.04 − 1.0) / 0.5 = 0.08 N m, and ends exactly at its limit,
    h_1(10.5) = min(0.1 × 10.5, 1.04) = 1.04 (a limit computed with the full 1 s sample would allow
    0.04 N m and stop at 1.02)."""
    wheels = ReactionWheels.from_body_axes(max_torque=1.0, max_momentum=1.04)
    model = AttitudeModel(Spacecraft([2.0, 3.0, 4.0], wheels=wheels))
    result = Simulator(model, 1.0).run(ConstantWheelTorque(), np.r_[quat.IDENTITY, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 10.5)
    np.testing.assert_allclose(result.wheel_momentum[:, 0], np.minimum(0.1 * result.t, 1.04), rtol=0, atol=1e-12)
    assert result.applied_u[-1, 0] == pytest.approx(0.08, abs=1e-12)
    assert result.saturated[-1] and not result.saturated[:-1].any()


def test_the_initial_quaternion_is_normalised():
    """x0 with its quaternion three times too long is the same run as with the unit quaternion
    (the docstring: 'the quaternion is normalised'): its first row is a unit quaternion too."""
    p = problem()
    x0 = np.array(p.initial_state, dtype=float)
    x0[0:4] = quat.normalize(np.array([0.7, 0.1, -0.4, 0.3]))
    long = x0.copy()
    long[0:4] *= 3.0
    for python_loop in (True, False):
        simulator = Simulator(p.model, 0.1, python_loop=python_loop)
        unit = simulator.run(CONTROLLERS["eigenaxis_pd"](), x0, 2.0, target=(p.qf, p.omegaf))
        scaled = simulator.run(CONTROLLERS["eigenaxis_pd"](), long, 2.0, target=(p.qf, p.omegaf))
        assert math.isclose(float(np.linalg.norm(scaled.q[0])), 1.0, abs_tol=1e-15)
        np.testing.assert_allclose(scaled.x, unit.x, rtol=0, atol=1e-14)


def test_a_run_of_exactly_max_samples_is_allowed():
    """``max_samples`` is the most samples a run may take: 5 of 5 run, 6 are refused."""
    p = problem()
    simulator = Simulator(p.model, 1.0, max_samples=5)
    assert simulator.run(CONTROLLERS["eigenaxis_pd"](), p.initial_state, 5.0, target=(p.qf, p.omegaf)).t.size == 6
    with pytest.raises(SimulationArgumentError, match="6 samples"):
        simulator.run(CONTROLLERS["eigenaxis_pd"](), p.initial_state, 5.5, target=(p.qf, p.omegaf))
