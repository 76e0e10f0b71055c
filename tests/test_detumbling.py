"""Magnetic detumbling laws (nano-spacecraft paper, eq. 11-12): physics, not the paper's numbers.

Oracles: the power balance ω·(m × B) written out here; a numerical derivative of the model's
body-frame field along the motion; a rotation by SciPy for the delayed field of a spinning body;
an identity between the two laws; and kinetic energy along simulated trajectories.
"""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from controllers import TDFC, BDot
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Environment,
    Magnetorquers,
    Measurement,
    SensorNoise,
    Simulator,
    Spacecraft,
    TiltedDipole,
    quat,
)

UKUBE_INERTIA = np.diag([0.0109, 0.05, 0.05])  # kg m², nano-spacecraft paper, "Simulations"
ORBIT = CircularOrbit(altitude=600e3, inclination=np.deg2rad(97.79))


def ukube_model(max_dipole=0.1, saturation="per_axis"):
    spacecraft = Spacecraft(UKUBE_INERTIA, magnetorquers=Magnetorquers(max_dipole, saturation))
    return AttitudeModel(spacecraft, Environment(ORBIT, magnetic_field=TiltedDipole()))


def kinetic_energy(omega):
    return 0.5 * np.einsum("ni,ij,nj->n", omega, UKUBE_INERTIA, omega)


def random_state(rng, rate=0.5):
    return np.r_[quat.random_unit(rng), rng.normal(0.0, rate, 3)]


def test_exact_bdot_power_is_minus_gain_times_cross_product_squared(rng):
    """Exact derivative, no saturation, a field fixed in inertial space (ḃ_I = 0): the power of the
    magnetorquer torque through the model is ω·(m × B) = −K_b |ω × B|², at random states."""
    model = ukube_model(max_dipole=None)
    gain = 3.7e4
    law = BDot({"gain": gain, "derivative": "exact"})
    law.reset(model.spacecraft, 0.2)
    for _ in range(50):
        x, t = random_state(rng), float(rng.uniform(0, 1e5))
        field = model.field_body(x, t).full().ravel()
        measurement = Measurement(t, x[0:4], x[4:7], np.zeros(0), field, field_rate_inertial=np.zeros(3))
        dipole = law(t, measurement, None).dipole
        power = x[4:7] @ model.body_torque(x, dipole, t).full().ravel()
        expected = -gain * np.sum(np.cross(x[4:7], field) ** 2)
        assert expected < 0
        assert abs(power - expected) <= 1e-9 * abs(expected)


def test_exact_bdot_derivative_matches_the_field_rate_along_the_motion(rng):
    """With the orbit's ḃ_I the law's Ḃ = R(q)ᵀ ḃ_I − ω × B is the time derivative of the model's
    body-frame field along the motion (central differences over ±1 ms of rotation at constant ω),
    and the power is then −K_b (|ω × B|² + (R(q)ᵀ ḃ_I)·(B × ω))."""
    model = ukube_model(max_dipole=None)
    gain, h = 1.0e4, 1e-3
    law = BDot({"gain": gain, "derivative": "exact"})
    law.reset(model.spacecraft, 0.2)
    for _ in range(20):
        x, t = random_state(rng, rate=0.05), float(rng.uniform(0, 1e5))
        q, omega = x[0:4], x[4:7]
        field = model.field_body(x, t).full().ravel()
        inertial_rate = model.field_rate_inertial(t).full().ravel()
        measurement = Measurement(t, q, omega, np.zeros(0), field, field_rate_inertial=inertial_rate)
        dipole = law(t, measurement, None).dipole

        def field_at(dt, q=q, omega=omega, t=t):
            return model.field_body(np.r_[quat.product(q, quat.from_rotation_vector(omega * dt)), omega],
                                    t + dt).full().ravel()

        numerical = (field_at(h) - field_at(-h)) / (2 * h)
        np.testing.assert_allclose(-dipole / gain, numerical, rtol=0, atol=1e-6 * np.linalg.norm(numerical))
        rotated = quat.rotation_matrix(q).T @ inertial_rate
        power = omega @ model.body_torque(x, dipole, t).full().ravel()
        expected = -gain * (np.sum(np.cross(omega, field) ** 2) + rotated @ np.cross(field, omega))
        assert abs(power - expected) <= 1e-9 * gain * np.sum(np.cross(omega, field) ** 2)


@pytest.mark.parametrize("delay_samples", [1, 3, 10])
def test_tdfc_power_of_a_spinning_body_is_minus_gain_rate_sine(rng, delay_samples):
    """A body spinning at constant ω in a fixed field sees B(t) = exp(−[ω×] t) B0 (SciPy rotation).
    TDFC's power after the delay is −K_t |ω| sin(|ω| τ) |B_⊥|²: negative below |ω| τ = π, positive
    between π and 2π (the limit the paper does not state)."""
    gain = 2.0e4
    for _ in range(10):
        omega = rng.normal(0, 1, 3)
        omega *= rng.uniform(0.1, 3.0) / np.linalg.norm(omega)
        tau = float(rng.uniform(0.2, 6.0))
        sample_time = tau / delay_samples
        law = TDFC({"gain": gain, "delay": tau})
        law.reset(Spacecraft(UKUBE_INERTIA, magnetorquers=Magnetorquers(None)), sample_time)
        b0 = rng.normal(0, 3e-5, 3)
        for k in range(delay_samples + 1):
            t = k * sample_time
            field = Rotation.from_rotvec(-omega * t).apply(b0)
            dipole = law(t, Measurement(t, quat.IDENTITY, omega, np.zeros(0), field), None).dipole
            if k < delay_samples:
                np.testing.assert_array_equal(dipole, 0.0)  # m = 0 before τ
        rate = np.linalg.norm(omega)
        normal = field - (field @ omega) * omega / rate**2
        expected = -gain * rate * np.sin(rate * tau) * (normal @ normal)
        power = omega @ np.cross(dipole, field)
        assert abs(power - expected) <= 1e-9 * gain * rate * (normal @ normal)


def test_tdfc_delay_must_be_a_multiple_of_the_sample_time():
    law = TDFC({"delay": 2.0})
    assert law.sample_time_error(0.5) is None and law.sample_time_error(0.2) is None
    option, message = law.sample_time_error(0.3)
    assert option == "delay" and "whole multiple" in message
    with pytest.raises(ValueError, match="whole multiple"):
        law.reset(Spacecraft(UKUBE_INERTIA, magnetorquers=Magnetorquers(0.1)), 0.3)


def test_tdfc_buffer_is_cleared_on_reset(rng):
    """A second run from the same state gives the same commands: nothing survives ``reset``."""
    law = TDFC({"delay": 0.6})
    spacecraft = Spacecraft(UKUBE_INERTIA, magnetorquers=Magnetorquers(0.1))
    readings = rng.normal(0, 3e-5, (8, 3))
    runs = []
    for _ in range(2):
        law.reset(spacecraft, 0.2)
        runs.append([law(0.2 * k, Measurement(0.2 * k, quat.IDENTITY, np.zeros(3), np.zeros(0), b), None).dipole
                     for k, b in enumerate(readings)])
    np.testing.assert_array_equal(runs[0], runs[1])
    np.testing.assert_array_equal(runs[0][:3], 0.0)
    np.testing.assert_allclose(runs[0][3], -1e4 * (readings[3] - readings[0]), rtol=1e-15)


@pytest.mark.parametrize("python_loop", [True, False], ids=["python", "casadi"])
@pytest.mark.parametrize("saturation", ["per_axis", "scale"])
def test_backward_difference_bdot_is_tdfc_with_one_sample_delay(saturation, python_loop):
    """B-dot by backward difference at T_s ≡ TDFC with τ = T_s and K_t = K_b / T_s: the same
    trajectory, magnetometer noise included (same seed), saturated or not, in either simulator path."""
    model = ukube_model(saturation=saturation)
    simulator = Simulator(model, 0.2, max_step=0.1, python_loop=python_loop)
    x0 = np.r_[quat.IDENTITY, 0.52, 0.52, 0.52]
    noise = SensorNoise(field_std=1e-5, seed=7)
    gain = 2.0e4
    bdot = simulator.run(BDot({"gain": gain}), x0, 400.0, noise=noise)
    tdfc = simulator.run(TDFC({"gain": gain / 0.2, "delay": 0.2}), x0, 400.0, noise=noise)
    np.testing.assert_array_equal(bdot.commanded_u[0], 0.0)
    np.testing.assert_allclose(bdot.x, tdfc.x, rtol=0, atol=1e-13)
    np.testing.assert_allclose(bdot.commanded_u, tdfc.commanded_u, rtol=1e-12, atol=0)
    assert np.mean(bdot.saturated) > 0.1  # the comparison includes saturated samples
    quiet = simulator.run(BDot({"gain": gain}), x0, 400.0)
    assert np.max(np.abs(quiet.x - bdot.x)) > 1e-6  # the noise does change the trajectory


def test_magnetometer_noise_leaves_attitude_and_rate_noise_unchanged():
    """Adding magnetometer noise leaves a scenario's attitude and rate noise unchanged (own stream)."""
    model = ukube_model()
    simulator = Simulator(model, 0.2)
    x = np.r_[quat.IDENTITY, 0.1, -0.2, 0.3]
    draws = []
    for field_std in (0.0, 1e-5):
        noise = SensorNoise(attitude_std=1e-3, rate_std=1e-3, seed=4, field_std=field_std)
        rng, field_rng = np.random.default_rng(noise.seed), np.random.default_rng([noise.seed, 1])
        draws.append([simulator._measure(x, 0.2 * k, noise, rng, field_rng) for k in range(5)])
    for plain, noisy in zip(*draws):
        np.testing.assert_array_equal(plain.q, noisy.q)
        np.testing.assert_array_equal(plain.omega, noisy.omega)
    errors = np.array([noisy.field_body - plain.field_body for plain, noisy in zip(*draws)])
    assert 1e-7 < np.std(errors) < 1e-4


def test_scaled_saturation_keeps_the_dipole_direction():
    from ocp import ActuatorModel, Command
    model = ukube_model(saturation="scale")
    actuators = ActuatorModel(model.spacecraft, model.control_slices, model.nu)
    applied, saturated = actuators.apply(Command(dipole=np.array([0.4, -0.1, 0.05])), np.zeros(0), 0.2)
    np.testing.assert_allclose(applied, [0.1, -0.025, 0.0125], rtol=1e-15)
    assert saturated
    per_axis = ukube_model()
    clipped, _ = ActuatorModel(per_axis.spacecraft, per_axis.control_slices, per_axis.nu).apply(
        Command(dipole=np.array([0.4, -0.1, 0.05])), np.zeros(0), 0.2)
    np.testing.assert_allclose(clipped, [0.1, -0.1, 0.05])


@pytest.mark.parametrize("law", [BDot({"gain": 2.0e4}), TDFC({"gain": 1.0e4, "delay": 2.0})], ids=["bdot", "tdfc"])
def test_kinetic_energy_never_rises_over_a_1000_s_window_while_tumbling(law, rng):
    """No noise: E(t + 1000 s) < E(t) for every window start t (every sample) with |ω(t)| > 0.02
    rad/s, from the paper's tip-off rate and from a random 0.7 rad/s. (Sample to sample the energy is not
    monotone: TDFC's delayed difference points the wrong way at times while the axisymmetric body
    nutates, and the orbital motion of the field adds a small term to B-dot's.)"""
    simulator = Simulator(ukube_model(), 0.5, max_step=0.1)
    window = round(1000.0 / 0.5)
    direction = rng.normal(0, 1, 3)
    for omega0 in (np.full(3, 0.52), 0.7 * direction / np.linalg.norm(direction)):
        result = simulator.run(law, np.r_[quat.random_unit(rng), omega0], 2000.0)
        energy = kinetic_energy(result.omega)
        starts = np.nonzero(np.linalg.norm(result.omega[:-window], axis=1) > 0.02)[0]
        assert starts.size > window // 2
        assert np.all(energy[starts + window] < energy[starts])
        assert energy[-1] < 0.95 * energy[0]


def test_tdfc_pumps_energy_in_beyond_half_a_turn_per_delay():
    """From |ω0| = 2 rad/s with τ = 2 s (|ω| τ = 4 > π) TDFC adds kinetic energy over 3000 s while
    B-dot (backward difference at 0.5 s, |ω| T_s = 1) removes it."""
    simulator = Simulator(ukube_model(), 0.5, max_step=0.1)
    x0 = np.r_[quat.IDENTITY, 2.0 * np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0)]
    tdfc = simulator.run(TDFC({"gain": 1.0e4, "delay": 2.0}), x0, 3000.0)
    bdot = simulator.run(BDot({"gain": 2.0e4}), x0, 3000.0)
    tdfc_energy, bdot_energy = kinetic_energy(tdfc.omega), kinetic_energy(bdot.omega)
    assert tdfc_energy[-1] > 1.05 * tdfc_energy[0]
    assert bdot_energy[-1] < 0.9 * bdot_energy[0]


@pytest.mark.parametrize("saturation", ["per_axis", "scale"])
@pytest.mark.parametrize("law", [BDot({"gain": 2.0e4}), BDot({"gain": 2.0e4, "derivative": "filtered",
                                                               "filter_time_constant": 0.7}),
                                 TDFC({"gain": 1.0e4, "delay": 1.0})], ids=["bdot", "bdot_filtered", "tdfc"])
def test_closed_loop_function_agrees_with_the_python_loop(law, saturation):
    """The symbolic laws run as one CasADi function give the Python loop's trajectory, with
    magnetometer noise (drawn in advance from the same stream) and either saturation."""
    model = ukube_model(saturation=saturation)
    x0 = np.r_[quat.from_rotation_vector([0.3, -0.2, 0.1]), 0.52, 0.52, 0.52]
    noise = SensorNoise(rate_std=1e-4, seed=11, field_std=1e-5)
    python = Simulator(model, 0.2, max_step=0.1, python_loop=True).run(law, x0, 200.0, noise=noise)
    casadi = Simulator(model, 0.2, max_step=0.1).run(law, x0, 200.0, noise=noise)
    assert python.path == "python" and casadi.path != "python"
    assert np.mean(python.saturated) > 0.1
    np.testing.assert_allclose(casadi.x, python.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(casadi.applied_u, python.applied_u, rtol=0, atol=1e-10)


def test_tdfc_mean_power_over_a_hold_and_its_sampled_stability_limit():
    """Held over a sample ``T``, TDFC's dipole ``m_k = −K (B_k − B_(k−τ))`` gives the mean power
    ``−(K |B_⊥|² / T) [cos ωτ − cos ω(τ+T) + cos ωT − 1]`` (quadrature here), which changes sign at
    ``|ω| = π/3`` for τ = 2 s and T = 1 s, not at the continuous law's ``π/τ = 1.57`` rad/s: a
    closed loop spinning at 1.0 rad/s loses energy, at 1.1 rad/s gains it."""
    from scipy.integrate import quad

    gain, tau, hold = 1.0e3, 2.0, 1.0
    axis, b0 = np.array([1.0, 0.0, 0.0]), np.array([1e-5, 3e-5, -2e-5])
    normal = b0 - (b0 @ axis) * axis
    def mean_power(omega: np.ndarray) -> float:
        def field(t: float) -> np.ndarray:
            return Rotation.from_rotvec(-omega * t).apply(b0)

        dipole = -gain * (field(0.0) - field(-tau))
        return quad(lambda s: omega @ np.cross(dipole, field(s)), 0.0, hold, epsabs=1e-13 * gain * (normal @ normal),
                    epsrel=1e-12)[0] / hold

    for rate in (0.5, 1.0, np.pi / 3, 1.1, 1.4):
        mean = mean_power(rate * axis)
        closed = -gain * (normal @ normal) / hold * (np.cos(rate * tau) - np.cos(rate * (tau + hold))
                                                       + np.cos(rate * hold) - 1.0)
        assert mean == pytest.approx(closed, rel=1e-9, abs=1e-12 * gain * (normal @ normal))
    simulator = Simulator(ukube_model(), hold, max_step=0.02)
    ratios = {}
    for rate in (1.0, 1.1):
        result = simulator.run(TDFC({"gain": gain, "delay": tau}), np.r_[quat.IDENTITY, rate, 0.0, 0.0], 1000.0)
        energy = kinetic_energy(result.omega)
        ratios[rate] = energy[-1] / energy[0]
    assert ratios[1.0] < 1.0 < ratios[1.1], ratios


@pytest.mark.parametrize("name", ["bdot", "tdfc"])
def test_a_magnetic_law_refuses_a_model_without_magnetorquers_or_without_a_field(name):
    """The magnetometer-only laws need both (their documented requirement): each missing piece is
    named by its YAML key; with both the law runs."""
    from controllers import CONTROLLERS
    law = CONTROLLERS[name]()
    with_torquers = Spacecraft(UKUBE_INERTIA, magnetorquers=Magnetorquers(0.1))
    field = Environment(ORBIT, magnetic_field=TiltedDipole())
    assert law.environment_error(with_torquers, field) is None
    assert "environment.magnetic_field" in law.environment_error(with_torquers, Environment(ORBIT))
    assert "spacecraft.magnetorquers" in law.environment_error(Spacecraft(UKUBE_INERTIA), field)
