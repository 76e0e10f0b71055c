"""The sensors and the MEKF of ocp.estimation against oracles: the filter's own covariance (NEES
over Monte Carlo runs, chi-square bounds), scipy's discrete Riccati solution, a hand-worked
update, the gyro's Allan variance, and the NumPy step against its CasADi twin."""
import math

import casadi as ca
import numpy as np
import pytest
from scipy.linalg import solve_discrete_are
from scipy.stats import chi2

from ocp import quat
from ocp.estimation import (
    SENSOR_STATE_SIZE,
    Gyro,
    Mekf,
    SensorSuite,
    StarTracker,
    draw_sensor_noise,
    initial_sensor_state,
    sensor_step,
    sensor_step_symbolic,
)
from ocp.estimation.mekf import unpack, update

D2R = math.pi / 180.0
ARCSEC = D2R / 3600.0
SUITE = SensorSuite(gyro=Gyro(arw=0.15 * D2R / 60, rrw=3 * D2R / 3600 / 60, bias=np.zeros(3)),
                    star_tracker=StarTracker(noise=np.array([10, 10, 60]) * ARCSEC, rate=0.05,
                                             outages=((100.0, 160.0),), boresight=[0, 1, 1]),
                    estimator=Mekf(attitude_sigma=0.5 * D2R, bias_sigma=20 * D2R / 3600))
OMEGA = np.array([0.01, -0.02, 0.015])
Q0 = quat.normalize([0.3, 0.1, -0.5, 0.8])


def truth(t):
    """Constant body rate: the attitude in closed form."""
    return quat.product(Q0, quat.from_rotation_vector(OMEGA * t))


def nees_run(run, n, dt=1.0):
    """NEES of [δθ, δb] at every sample of one run, the true bias drawn from the filter's prior."""
    rng = np.random.default_rng([99, run])
    gyro = Gyro(SUITE.gyro.arw, SUITE.gyro.rrw, rng.normal(0.0, SUITE.estimator.bias_sigma, 3))
    suite = SensorSuite(gyro, SUITE.star_tracker, None, SUITE.estimator)
    times = np.arange(n + 1) * dt
    noise, s = draw_sensor_noise(suite, run, times), initial_sensor_state(suite, Q0, run)
    values = np.empty(n)
    for k in range(n):
        q_true = truth(times[k])
        q_hat, _, _, s = sensor_step(suite, s, q_true, OMEGA, None, noise[k], dt)
        error = np.concatenate([quat.to_rotation_vector(quat.product(quat.conjugate(q_hat), q_true)),
                                s[0:3] - s[7:10]])
        values[k] = error @ np.linalg.solve(unpack(s[10:31]), error)
    return values


@pytest.mark.slow
def test_nees_over_50_runs_lies_within_its_95_percent_bounds():
    runs, n = 50, 200
    mean = np.mean([nees_run(run, n) for run in range(runs)], axis=0)
    low, high = chi2.ppf([0.025, 0.975], 6 * runs) / runs
    inside = np.mean((mean > low) & (mean < high))
    print(f"NEES over {runs} runs: mean {mean.mean():.3f} (6 expected), bounds [{low:.3f}, {high:.3f}], "
          f"{100 * inside:.1f} % of {n} samples inside")
    assert low < mean.mean() < high
    assert inside >= 0.9


def test_an_overconfident_filter_fails_the_nees_bounds():
    """The NEES check detects a wrong covariance: a filter told the gyro is 100 times quieter."""
    global SUITE
    saved = SUITE
    SUITE = SensorSuite(Gyro(saved.gyro.arw / 100, saved.gyro.rrw / 100), saved.star_tracker, None, saved.estimator)
    try:
        quiet = SUITE
        runs, n = 10, 60
        means = []
        for run in range(runs):  # the truth keeps the real gyro noise: draw it with the real model
            rng = np.random.default_rng([99, run])
            real = SensorSuite(Gyro(saved.gyro.arw, saved.gyro.rrw, rng.normal(0, saved.estimator.bias_sigma, 3)),
                               saved.star_tracker, None, saved.estimator)
            times = np.arange(n + 1.0)
            noise, s = draw_sensor_noise(real, run, times), initial_sensor_state(quiet, Q0, run)
            s[0:3] = real.gyro.bias
            values = []
            for k in range(n):
                q_hat, _, _, s = sensor_step(quiet, s, truth(times[k]), OMEGA, None, noise[k], 1.0)
                e = np.concatenate([quat.to_rotation_vector(quat.product(quat.conjugate(q_hat), truth(times[k]))),
                                    s[0:3] - s[7:10]])
                values.append(e @ np.linalg.solve(unpack(s[10:31]), e))
            means.append(values)
        assert np.mean(means) > chi2.ppf(0.975, 6 * runs) / runs
    finally:
        SUITE = saved


def test_steady_state_covariance_is_the_discrete_riccati_solution():
    """At rest the axes decouple; each is the two-state system [angle, bias] with Φ = [[1, -Δt],
    [0, 1]], Farrenkopf's Q and H = [1, 0]: scipy's discrete algebraic Riccati solution is the
    a-priori covariance, and the update gives the a-posteriori one."""
    sv, su, sn, dt = 1e-4, 1e-6, 2e-5, 1.0
    suite = SensorSuite(Gyro(sv, su), StarTracker(noise=[sn, sn, sn]), None, Mekf(1e-3, 1e-4))
    s = initial_sensor_state(suite, np.array([1.0, 0, 0, 0]), 0)
    quiet = np.zeros(10)
    quiet[9] = 1.0  # no noise draws: the covariance does not depend on them
    for _ in range(3000):
        _, _, _, s = sensor_step(suite, s, np.array([1.0, 0, 0, 0]), np.zeros(3), None, quiet, dt)
    phi = np.array([[1.0, -dt], [0.0, 1.0]])
    Q = np.array([[sv**2 * dt + su**2 * dt**3 / 3, -su**2 * dt**2 / 2], [-su**2 * dt**2 / 2, su**2 * dt]])
    H = np.array([[1.0, 0.0]])
    prior = solve_discrete_are(phi.T, H.T, Q, np.array([[sn**2]]))
    gain = prior @ H.T / (H @ prior @ H.T + sn**2)
    posterior = (np.eye(2) - gain @ H) @ prior
    P = unpack(s[10:31])
    for axis in range(3):
        block = P[np.ix_([axis, axis + 3], [axis, axis + 3])]
        np.testing.assert_allclose(block, posterior, rtol=1e-6)
    assert abs(P[0, 1]) < 1e-6 * P[0, 0]


def test_a_perfect_star_tracker_at_rest_brings_the_estimate_to_the_truth():
    """Zero noise, a static attitude, an initial error of 0.5 deg: the filter converges to the truth."""
    suite = SensorSuite(Gyro(1e-6, 1e-9), StarTracker(noise=[1e-9, 1e-9, 1e-9]), None, Mekf(0.5 * D2R, 1e-5))
    q_true = quat.normalize([0.9, -0.2, 0.3, 0.1])
    s = initial_sensor_state(suite, q_true, 0)
    s[3:7] = quat.product(q_true, quat.from_rotation_vector([0.5 * D2R, 0, 0]))
    row = np.zeros(10)
    row[9] = 1.0
    q_hat, _, _, s = sensor_step(suite, s, q_true, np.zeros(3), None, row, 1.0)
    assert quat.error_angle(q_hat, q_true) < 1e-6  # the first update takes the reading (to its θ³ linearisation)
    for _ in range(2000):
        q_hat, rate, _, s = sensor_step(suite, s, q_true, np.zeros(3), None, row, 1.0)
    assert quat.error_angle(q_hat, q_true) < 1e-10
    assert np.linalg.norm(rate) < 1e-10  # the bias estimate's transient has died out


def test_one_update_by_hand():
    """P = diag(p I, c I), R = r I, a measured error v along x: δθ = p/(p+r) v, b̂ unchanged,
    P_θθ = p r/(p+r) (P − K H P)."""
    p, c, r = 4e-6, 1e-10, 1e-6
    P = np.diag([p] * 3 + [c] * 3)
    v = np.array([1e-3, 0.0, 0.0])
    q_hat = np.array([1.0, 0, 0, 0])
    measured = quat.from_rotation_vector(v)
    q_new, bias, P_new = update(q_hat, np.zeros(3), P, measured, r * np.eye(3))
    # residual 2 sin(|v|/2) along x; the reset q̂ ⊗ [1, δθ/2] normalised
    z = 2 * math.sin(0.5e-3)
    expected = quat.normalize([1.0, 0.5 * p / (p + r) * z, 0, 0])
    np.testing.assert_allclose(q_new, expected, atol=1e-15)
    np.testing.assert_array_equal(bias, np.zeros(3))
    np.testing.assert_allclose(np.diag(P_new)[0:3], p * r / (p + r), rtol=1e-12)
    np.testing.assert_allclose(np.diag(P_new)[3:6], c, rtol=1e-12)


def test_gyro_allan_variance_shows_its_arw_and_rrw():
    """At rest the reading is the bias plus noise; its overlapping Allan variance is
    σ_v²/τ + σ_u² τ / 3: fitted on τ from 1 s to 1000 s over 60 axes, both within 10 %."""
    sv, su, dt, n = 1e-4, 1e-6, 1.0, 20000
    suite = SensorSuite(gyro=Gyro(sv, su))
    times = np.arange(n + 1) * dt
    readings = []
    for seed in range(20):
        noise = draw_sensor_noise(suite, seed, times)
        s = initial_sensor_state(suite, np.array([1.0, 0, 0, 0]), seed)
        series = np.empty((n, 3))
        for k in range(n):
            _, series[k], _, s = sensor_step(suite, s, np.array([1.0, 0, 0, 0]), np.zeros(3), None, noise[k], dt)
        readings.append(series)
    rates = np.concatenate(readings, axis=1)  # (n, 60)
    theta = np.vstack([np.zeros((1, rates.shape[1])), np.cumsum(rates, axis=0) * dt])
    taus = np.unique(np.logspace(0, 3, 16).astype(int))
    allan = []
    for m in taus:
        d = theta[2 * m:] - 2 * theta[m:-m] + theta[:-2 * m]
        allan.append(np.mean(d**2) / (2 * (m * dt) ** 2))
    tau = taus * dt
    A = np.column_stack([1 / tau, tau / 3])
    (arw2, rrw2), *_ = np.linalg.lstsq(A / np.array(allan)[:, None], np.ones(len(tau)), rcond=None)
    assert math.sqrt(arw2) == pytest.approx(sv, rel=0.1)
    assert math.sqrt(rrw2) == pytest.approx(su, rel=0.1)


@pytest.mark.parametrize("estimator", [True, False])
def test_the_casadi_step_is_the_numpy_step(estimator):
    suite = SensorSuite(SUITE.gyro, SUITE.star_tracker, None, SUITE.estimator if estimator else None)
    s_sym, q_sym, w_sym = ca.SX.sym("s", SENSOR_STATE_SIZE), ca.SX.sym("q", 4), ca.SX.sym("w", 3)
    n_sym, dt_sym = ca.SX.sym("n", suite.noise_size), ca.SX.sym("dt")
    outputs = sensor_step_symbolic(suite, s_sym, q_sym, w_sym, None, n_sym, dt_sym)
    function = ca.Function("step", [s_sym, q_sym, w_sym, n_sym, dt_sym], [outputs[0], outputs[1], outputs[3]])
    times = np.arange(301.0)
    noise = draw_sensor_noise(suite, 7, times)
    s_num = s_cas = initial_sensor_state(suite, Q0, 7)
    for k in range(300):
        q, w, _, s_num = sensor_step(suite, s_num, truth(times[k]), OMEGA, None, noise[k], 1.0)
        qc, wc, s_cas = (np.ravel(o.full()) for o in function(s_cas, truth(times[k]), OMEGA, noise[k], 1.0))
        np.testing.assert_allclose(qc, q, atol=1e-13)
        np.testing.assert_allclose(wc, w, atol=1e-13)
        np.testing.assert_allclose(s_cas, s_num, atol=1e-13, rtol=1e-10)


def test_star_tracker_schedule_rate_and_outages():
    tracker = StarTracker(noise=[1e-5] * 3, rate=0.25, outages=((4.0, 9.0),))
    available = tracker.available(np.arange(16.0))
    assert np.flatnonzero(available).tolist() == [0, 12]  # every 4 s; 4 and 8 fall in the outage
    assert StarTracker(noise=[1e-5] * 3).available(np.arange(3.0)).all()


def test_star_tracker_noise_is_per_sensor_axis():
    """A boresight along body x: the large boresight noise lands on body x."""
    tracker = StarTracker(noise=np.array([1.0, 1.0, 10.0]), boresight=[1, 0, 0])
    np.testing.assert_allclose(np.diag(tracker.covariance), [100.0, 1.0, 1.0], atol=1e-12)
    draws = draw_sensor_noise(SensorSuite(star_tracker=tracker), 1, np.arange(20001.0))[:, 6:9]
    np.testing.assert_allclose(draws.std(axis=0), [10.0, 1.0, 1.0], rtol=0.03)


@pytest.mark.parametrize("outages, words", [
    ((10, 20), "got a single window (10, 20); write outages=((10, 20),)"),
    ([10.0, 20.0], "got a single window (10.0, 20.0)"),
    (((1.0, 2.0, 3.0),), "an outage must be a window (t0, t1) of two numbers of s, got (1.0, 2.0, 3.0)"),
    (((1.0, "2"),), "an outage must be a window (t0, t1) of two numbers of s, got (1.0, '2')"),
    ((5.0,), "an outage must be a window (t0, t1) of two numbers of s, got 5.0"),
    (7.0, "outages must be a tuple of (t0, t1) windows in s, got 7.0"),
])
def test_star_tracker_refuses_outages_that_are_not_windows_in_words(outages, words):
    """A single window (or anything but a tuple of pairs of numbers) is a ValueError that says what
    was expected, as a single Exclusion is, not a raw unpacking TypeError."""
    with pytest.raises(ValueError) as raised:
        StarTracker(noise=[1e-5] * 3, outages=outages)
    assert words in str(raised.value)


def test_star_tracker_takes_windows_as_lists_and_arrays():
    assert StarTracker(noise=[1e-5] * 3, outages=[[1, 2], [3, 4.5]]).outages == ((1.0, 2.0), (3.0, 4.5))
    assert StarTracker(noise=[1e-5] * 3, outages=np.array([[1.0, 2.0]])).outages == ((1.0, 2.0),)
