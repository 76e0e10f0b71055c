"""The sensors' noise tabulated before a run (``draw_sensor_noise``, ``initial_sensor_state``)
against their definitions: the gyro's random walk and white noise by their sample statistics, the
star tracker's schedule by hand, its noise along the boresight by projection, and the MEKF's
initial error by its spread over seeds."""
import numpy as np

from ocp import quat
from ocp.estimation import (
    Gyro,
    Mekf,
    SensorSuite,
    StarTracker,
    draw_sensor_noise,
    initial_sensor_state,
)


def test_gyro_bias_increments_and_white_noise_have_their_farrenkopf_deviations():
    """Per sample of length Δt: bias increment σ_u √Δt, reading noise √(σ_v²/Δt + σ_u² Δt / 12)."""
    arw, rrw, dt, n = 1e-4, 1e-5, 0.25, 40000
    times = np.arange(n + 1) * dt
    rows = draw_sensor_noise(SensorSuite(gyro=Gyro(arw, rrw)), 7, times)
    walk, white = rows[:, 0:3].std(), rows[:, 3:6].std()
    # 120000 normal draws each: the sample deviation is within 1 % (about 5 of its standard errors)
    assert abs(walk / (rrw * np.sqrt(dt)) - 1) < 0.01
    assert abs(white / np.sqrt(arw**2 / dt + rrw**2 * dt / 12) - 1) < 0.01


def test_star_tracker_availability_is_that_of_the_sample_instant():
    """0.5 Hz on a 1 s grid: updates at t = 0, 2, 4, ...; an outage [3, 6) removes the one at 4."""
    tracker = StarTracker(noise=[1e-5, 1e-5, 1e-5], rate=0.5, outages=((3.0, 6.0),))
    times = np.arange(11.0)  # samples at 0 ... 9, the run ends at 10
    rows = draw_sensor_noise(SensorSuite(star_tracker=tracker), 0, times)
    np.testing.assert_array_equal(rows[:, 9], [1, 0, 1, 0, 0, 0, 1, 0, 1, 0])


def test_star_tracker_noise_about_the_boresight_is_its_third_deviation():
    """The noise is per sensor axis, z the boresight: projected on the boresight (body axes) the
    rotation vector has the third deviation, across it the first two."""
    noise = np.array([1e-5, 2e-5, 1e-4])
    boresight = np.array([0.0, 1.0, 1.0]) / np.sqrt(2)
    tracker = StarTracker(noise=noise, boresight=boresight)
    rows = draw_sensor_noise(SensorSuite(star_tracker=tracker), 3, np.arange(50001.0))
    along = rows[:, 6:9] @ boresight
    assert abs(along.std() / noise[2] - 1) < 0.02
    across = rows[:, 6:9] - np.outer(along, boresight)
    total = np.mean(np.sum(across**2, axis=1))
    assert abs(total / (noise[0] ** 2 + noise[1] ** 2) - 1) < 0.02


def test_the_mekf_starts_off_by_its_attitude_sigma():
    """The estimate starts a draw of N(0, σ_θ² I) away: E|δθ|² = 3 σ_θ² over seeds (σ_b elsewhere)."""
    sigma = 1e-2
    suite = SensorSuite(Gyro(1e-6, 1e-8), StarTracker(noise=[1e-5] * 3), None, Mekf(attitude_sigma=sigma, bias_sigma=1e-4))
    q0 = quat.normalize(np.array([0.4, -0.2, 0.7, 0.3]))
    angles = np.array([quat.error_angle(initial_sensor_state(suite, q0, seed)[3:7], q0) for seed in range(3000)])
    assert abs(np.mean(angles**2) / (3 * sigma**2) - 1) < 0.1  # chi-square with 9000 dof: about 1.5 %
