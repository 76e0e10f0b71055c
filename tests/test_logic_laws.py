"""Control laws against formulas written out here, on non-default options where the defaults hide
a bug (issue 33): the B-dot low-pass filter's time constant, the two-wheel feed-forward sign on
each axis, and the gain of each mode of the gain-scheduled law with K1 ≠ K2. Each law's symbolic
form (the closed-loop function and code generation) is checked against the same oracle."""
import math

import numpy as np
import pytest

from controllers import CONTROLLERS, BDot
from ocp import Magnetorquers, Measurement, ReactionWheels, Spacecraft, quat

UOSAT12 = np.array([40.45, 42.09, 42.36])


def symbolic(law, t, measurement, z, sample_time):
    """The law's CasADi function at one sample: (u, z_next)."""
    function = law.symbolic_law().function
    n_w = measurement.wheel_momentum.size
    field = np.zeros(3) if measurement.field_body is None else measurement.field_body
    y = np.r_[measurement.q, measurement.omega, measurement.wheel_momentum, field]
    r = law.reference_rows(None, np.array([t, t + sample_time])).ravel()
    u, z_next = (v.full().ravel() for v in function(t, y, z, r))
    assert u.size >= n_w
    return u, z_next


@pytest.mark.parametrize("time_constant", [0.7, 5.0])
def test_filtered_bdot_is_the_first_order_filter_of_the_backward_difference(time_constant, rng):
    """y_k = α y_{k−1} + (1 − α)(B_k − B_{k−1})/T_s with α = exp(−T_s/T_f), m = −K_b y_k, m = 0 at
    the first sample; in the Python law and in its symbolic form (state carried sample to sample)."""
    sample_time, gain = 0.2, 3.0e3
    law = BDot({"gain": gain, "derivative": "filtered", "filter_time_constant": time_constant})
    spacecraft = Spacecraft(np.diag([0.0109, 0.05, 0.05]), magnetorquers=Magnetorquers(1e9))
    law.reset(spacecraft, sample_time, target=(quat.IDENTITY, np.zeros(3)))
    readings = rng.normal(0.0, 3e-5, (12, 3))
    alpha = math.exp(-sample_time / time_constant)
    filtered, expected = np.zeros(3), [np.zeros(3)]
    for k in range(1, len(readings)):
        filtered = alpha * filtered + (1 - alpha) * (readings[k] - readings[k - 1]) / sample_time
        expected.append(-gain * filtered)
    z = law.symbolic_law().state0
    for k, b in enumerate(readings):
        t = k * sample_time
        measurement = Measurement(t, quat.IDENTITY, np.zeros(3), np.zeros(0), b)
        u, z = symbolic(law, t, measurement, z, sample_time)
        dipole = law(t, measurement, None).dipole
        np.testing.assert_allclose(dipole, expected[k], rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(u, expected[k], rtol=1e-10, atol=1e-300)


def eq7_rates(q, k, g):
    """ωd of eq. 7 (unsaturated), written out: ωd1 = −k q1 + g q2 q3 / D, ωd2 = −k q2 − g q1 q3 / D."""
    _, q1, q2, q3 = q
    d = q1 * q1 + q2 * q2
    return np.array([-k * q1 + g * q2 * q3 / d, -k * q2 - g * q1 * q3 / d])


def snlc_torque(q, omega, k, g, gain, inertia, h=1e-6):
    """u_i = −K (ω_i − ωd_i) + I_i ω̇d_i with ω̇d by central differences along q̇ = ½ q ⊗ [0, ω]."""
    rate = quat.kinematics(q, omega)
    derivative = (eq7_rates(q + h * rate, k, g) - eq7_rates(q - h * rate, k, g)) / (2 * h)
    return -gain * (omega[:2] - eq7_rates(q, k, g)) + inertia[:2] * derivative


def two_wheel_spacecraft():
    return Spacecraft(UOSAT12, wheels=ReactionWheels.from_body_axes(max_torque=1e3, failed=(2,)))


def random_state(rng):
    q = quat.normalize(np.r_[0.8, rng.normal(0, 0.3, 3)])
    omega = np.r_[rng.normal(0, 0.01, 2), 0.0]
    return q, omega


def check_symbolic_equals_python(law, spacecraft, measurement):
    u, _ = symbolic(law, measurement.t, measurement, law.symbolic_law().state0, 1.0)
    np.testing.assert_allclose(u, law.command_vector(law(measurement.t, measurement, None)), rtol=1e-9, atol=1e-15)


def test_rate_tracking_feed_forward_has_the_sign_of_the_desired_rate_derivative_on_each_axis(rng):
    """The failed wheel on z: the control frame is the body frame. Away from rest the feed-forward
    I_i ω̇d_i is of the size of the feedback, so a sign error on either axis is seen."""
    options = {"k": 0.03, "g": 0.1, "K": 3.0, "a1": None, "a2": None}
    law = CONTROLLERS["singular_rate_tracking"](options)
    spacecraft = two_wheel_spacecraft()
    law.reset(spacecraft, 1.0, target=(quat.IDENTITY, np.zeros(3)))
    for _ in range(10):
        q, omega = random_state(rng)
        measurement = Measurement(0.0, q, omega, np.zeros(3), None)
        expected = snlc_torque(q, omega, 0.03, 0.1, 3.0, UOSAT12)
        np.testing.assert_allclose(law.torque(measurement), expected, rtol=1e-6, atol=1e-12)
        check_symbolic_equals_python(law, spacecraft, measurement)


@pytest.mark.parametrize("mode", ["high", "low"])
def test_gain_scheduled_modes_use_their_own_gains(mode, rng):
    """K1 ≠ K2 (and k, g of each mode): with ε huge the high-gain mode is the benchmark everywhere,
    with ε tiny the low-gain mode; the benchmark is eq. 31-32 with that mode's k, g and K."""
    gains = {"k1": 0.02, "g1": 0.08, "K1": 3.0, "k2": 0.05, "g2": 0.3, "K2": 17.0, "a1": None, "a2": None,
             "epsilon": 1e6 if mode == "high" else 1e-12}
    law = CONTROLLERS["gain_scheduled_min_norm"](gains)
    spacecraft = two_wheel_spacecraft()
    law.reset(spacecraft, 1.0, target=(quat.IDENTITY, np.zeros(3)))
    k, g, K = (gains["k2"], gains["g2"], gains["K2"]) if mode == "high" else (gains["k1"], gains["g1"], gains["K1"])
    for _ in range(10):
        q, omega = random_state(rng)
        measurement = Measurement(0.0, q, omega, np.zeros(3), None)
        _, benchmark, _ = law.torques(measurement)
        np.testing.assert_allclose(benchmark, snlc_torque(q, omega, k, g, K, UOSAT12), rtol=1e-6, atol=1e-12)
        check_symbolic_equals_python(law, spacecraft, measurement)
