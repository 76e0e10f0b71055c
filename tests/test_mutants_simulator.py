"""The simulator's sampling, hold and noise against hand-worked values and their definitions: the
last sample is shortened to end at the duration, wheels saturated by momentum never exceed it
(``h_w + g Δt`` within ``±h_max`` from the momentum at each sample), and the attitude noise is a
rotation by the drawn vector (mean square angle 3σ²); a time-varying environment torque is
integrated at the right times (against scipy on the model's own equations)."""
import numpy as np
from scipy.integrate import solve_ivp

from controllers import CONTROLLERS
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Environment,
    ReactionWheels,
    Simulator,
    Spacecraft,
    Torquers,
    quat,
)
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


def test_a_time_varying_torque_is_held_at_the_right_times_against_scipy():
    """Gravity gradient along a circular orbit, no control: the run (both paths, 20 RK4 sub-steps a
    sample) is the model's own equations integrated by scipy's DOP853 from t = 0."""
    spacecraft = Spacecraft([[0.9, 0.05, 0.0], [0.05, 0.4, 0.02], [0.0, 0.02, 0.6]], torquers=Torquers(1.0))
    model = AttitudeModel(spacecraft, Environment(CircularOrbit(500e3, 0.9), gravity_gradient=True))
    x0 = np.r_[quat.normalize(np.array([0.8, 0.3, -0.2, 0.4])), 2e-3, -1e-3, 5e-4]
    duration = 600.0
    u, p = np.zeros(model.nu), np.zeros(3)
    truth = solve_ivp(lambda t, x: model.rhs(x, u, t, p).full().ravel(), (0.0, duration), x0, method="DOP853",
                      rtol=1e-12, atol=1e-14, t_eval=np.arange(0.0, duration + 1.0, 10.0))
    for python_loop in (True, False):
        result = Simulator(model, 10.0, max_step=0.5, python_loop=python_loop).run(CONTROLLERS["none"](), x0, duration)
        assert np.max(quat.error_angle(result.q, truth.y[:4].T)) < 1e-9
        np.testing.assert_allclose(result.omega, truth.y[4:].T, atol=1e-11)


def test_no_rk4_sub_step_is_longer_than_max_step():
    """⌈T_s / max_step⌉ sub-steps, by hand."""
    model = problem().model
    for sample_time, max_step, substeps in ((0.1, 0.03, 4), (0.1, 0.05, 2), (0.1, 0.1, 1), (1.0, 0.3, 4), (0.1, 0.2, 1)):
        assert Simulator(model, sample_time, max_step=max_step).substeps == substeps
