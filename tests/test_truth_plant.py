"""The truth plant (issue 28): its physics against closed forms and conservation, its noise stream,
and the three closed-loop paths (Python loop, CasADi interpreted and compiled) agreeing with it; a
truth that changes nothing changes no bit."""
import copy
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from controllers import CONTROLLERS
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Command,
    Environment,
    Magnetorquers,
    ReactionWheels,
    SensorNoise,
    Simulator,
    Spacecraft,
    TiltedDipole,
)
from ocp.dynamics.truth import PeriodicTorque, Truth, TruthPlant
from ocp.errors import ModelError
from scenarios.runner import run
from scenarios.schema.loader import load, parse_scenario

SPIN_INERTIA = 0.01  # kg m^2


class Constant:
    """A duck-typed controller asking constant wheel torques (Python loop)."""

    def __init__(self, torque):
        self.torque = np.asarray(torque, dtype=float)

    def reset(self, spacecraft, sample_time, target=None):
        self.spacecraft = spacecraft

    def __call__(self, t, measurement, reference):
        return Command(wheel_torque=self.torque.copy())


def wheel_model(axes=None, inertia=(19.5, 19.0, 12.6), environment=None, **wheels):
    axes = np.eye(3) if axes is None else axes
    spacecraft = Spacecraft(inertia, wheels=ReactionWheels(axes, spin_inertia=SPIN_INERTIA, **wheels))
    return AttitudeModel(spacecraft, environment)


def simulate(plant, controller, x0, duration, sample_time=0.5, **options):
    simulator = Simulator(plant.design, sample_time, plant=plant, **options)
    return simulator.run(controller, x0, duration, noise=SensorNoise(seed=4))


def test_friction_is_internal_total_momentum_is_conserved():
    """Coulomb and viscous bearing friction on misaligned wheels of a body with products of inertia:
    no external torque, so R(q)(I ω + A h_w) (truth I and A) stays constant while friction
    trades momentum between wheels and body."""
    design = wheel_model()
    truth = Truth(inertia=[[20.0, 0.4, -0.3], [0.4, 18.0, 0.2], [-0.3, 0.2, 13.0]],
                  wheel_misalignment=np.radians([[0.0, 2.0, 1.0], [1.5, 0.0, -1.0], [-2.0, 1.0, 0.0]]),
                  wheel_coulomb=[2e-4, 1e-4, 3e-4], wheel_viscous=[1e-4, 2e-4, 5e-5])
    plant = TruthPlant(design, truth)
    x0 = np.r_[1.0, 0, 0, 0, 0.01, -0.02, 0.015, 0.5, -0.3, 0.4]
    result = simulate(plant, CONTROLLERS["none"](), x0, 60.0, max_step=0.01)
    momentum = plant.model.inertial_momentum(result.x)
    np.testing.assert_allclose(momentum, np.broadcast_to(momentum[0], momentum.shape), rtol=0, atol=1e-11)
    assert np.max(np.abs(result.x[-1, 7:] - x0[7:])) > 0.05  # friction moved momentum from the wheels
    # the design model's momentum (design inertia and axes) is not what is conserved
    design_momentum = design.inertial_momentum(result.x)
    assert np.max(np.abs(design_momentum - design_momentum[0])) > 1e-3


def test_viscous_spin_down_closed_form():
    """One wheel on the principal z axis, body at rest: Ω = h/J − ω_z decays as
    exp(−b (1/J + 1/I_z) t) (I_z ω̇ = bΩ, ḣ = −bΩ)."""
    design = wheel_model(axes=[[0.0], [0.0], [1.0]])
    b, i_z = 2e-4, 12.6
    plant = TruthPlant(design, Truth(wheel_viscous=b))
    h0 = 0.8
    result = simulate(plant, CONTROLLERS["none"](), np.r_[1.0, 0, 0, 0, 0, 0, 0, h0], 40.0)
    speed = result.x[:, 7] / SPIN_INERTIA - result.x[:, 6]
    expected = h0 / SPIN_INERTIA * np.exp(-b * (1 / SPIN_INERTIA + 1 / i_z) * result.t)
    np.testing.assert_allclose(speed, expected, rtol=1e-9)
    np.testing.assert_allclose(result.x[:, 4:6], 0.0, atol=1e-15)


def test_coulomb_spin_down_is_linear_until_the_wheel_stops():
    """Coulomb friction c: Ω falls by c (1/J + 1/I_z) per second."""
    design = wheel_model(axes=[[0.0], [0.0], [1.0]])
    c, i_z = 1e-3, 12.6
    plant = TruthPlant(design, Truth(wheel_coulomb=c))
    h0 = 0.2
    result = simulate(plant, CONTROLLERS["none"](), np.r_[1.0, 0, 0, 0, 0, 0, 0, h0], 15.0)
    speed = result.x[:, 7] / SPIN_INERTIA - result.x[:, 6]
    np.testing.assert_allclose(speed, h0 / SPIN_INERTIA - c * (1 / SPIN_INERTIA + 1 / i_z) * result.t, rtol=1e-11)


def test_speed_limit_cuts_the_motor_torque_in_the_driving_direction_only():
    """A constant motor torque spins a wheel up to its limit (100 rpm) and no further; at the
    limit the torque on the body is zero; a torque braking the wheel is not cut."""
    design = wheel_model(axes=[[0.0], [0.0], [1.0]])
    limit = 100 * 2 * math.pi / 60
    plant = TruthPlant(design, Truth(wheel_max_speed=limit))
    result = simulate(plant, Constant([0.01]), np.r_[1.0, 0, 0, 0, 0, 0, 0, 0], 20.0)
    speed = result.x[:, 7] / SPIN_INERTIA - result.x[:, 6]
    step_gain = 0.01 * (1 / SPIN_INERTIA + 1 / 12.6) * 0.05  # one RK4 sub-step of spin-up
    assert limit <= speed[-1] <= limit + step_gain
    assert np.max(speed) <= limit + step_gain
    assert np.all(result.applied_torque[-10:] == 0.0)  # at the limit: no torque on the body
    assert result.applied_u[-1, 0] == 0.01  # the motor is asked, the wheel is at its speed
    braking = simulate(plant, Constant([-0.01]), np.r_[1.0, 0, 0, 0, 0, 0, 0, 1.1 * limit * SPIN_INERTIA], 2.0)
    np.testing.assert_allclose(braking.applied_torque[:, 2], 0.01, rtol=1e-12)


def test_misaligned_axis_torque_is_the_rotated_axis_times_the_torque():
    """Each wheel's body torque is −R(v_i) a_i g_i, R from SciPy's rotation vectors."""
    design = wheel_model()
    misalignment = np.radians([[0.0, 3.0, 1.0], [2.0, 0.0, -4.0], [-1.0, 5.0, 0.0]])
    plant = TruthPlant(design, Truth(wheel_misalignment=misalignment))
    x = np.r_[1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0]
    for i in range(3):
        g = np.zeros(3)
        g[i] = 0.07
        torque = plant.body_torque(x, g, 0.0).full().ravel()
        expected = -Rotation.from_rotvec(misalignment[i]).apply(np.eye(3)[i]) * 0.07
        np.testing.assert_allclose(torque, expected, rtol=0, atol=1e-15)
        assert np.linalg.norm(torque - (-np.eye(3)[i] * 0.07)) > 1e-4  # not the design axis


def test_misalignment_over_ten_degrees_is_refused():
    with pytest.raises(ModelError, match="wheels.misalignment_deg"):
        Truth(wheel_misalignment=np.radians([[0.0, 10.5, 0.0]]))


def orbit_environment():
    orbit = CircularOrbit(altitude=500e3, inclination=math.radians(51.6))
    return Environment(orbit=orbit, magnetic_field=TiltedDipole(), disturbance_torque=np.array([1e-6, 0, 0]))


def test_residual_dipole_periodic_and_constant_disturbances_add_their_torques():
    """I (ω̇_truth − ω̇_design) = m_res × B_B + Σ A sin(k n t + φ) + (p_truth − p_design), with the
    field from the model, n = sqrt(μ/r³) by hand and the sines by NumPy."""
    environment = orbit_environment()
    design = wheel_model(environment=environment)
    residual = np.array([0.05, -0.02, 0.1])
    periodic = (PeriodicTorque(1, [1e-5, 0, 2e-5], [0.3, 0, -1.0]), PeriodicTorque(2, [0, 3e-5, 0], [0, 0.7, 0]))
    plant = TruthPlant(design, Truth(residual_dipole=residual, periodic_disturbance=periodic,
                                     constant_disturbance=[0, 2e-6, 0]))
    np.testing.assert_array_equal(plant.default_parameters, [0, 2e-6, 0])
    n = math.sqrt(3.986004418e14 / (6378137.0 + 500e3) ** 3)
    x = np.r_[0.9, 0.1, -0.3, 0.2, 0.01, 0.0, -0.01, 0.1, 0.2, -0.1]
    x[0:4] /= np.linalg.norm(x[0:4])
    u = np.array([0.01, -0.02, 0.005])
    for t in (0.0, 1234.5):
        difference = (plant.rhs(x, u, t, plant.default_parameters) - design.rhs(x, u, t, design.default_parameters))
        torque = np.diag([19.5, 19.0, 12.6]) @ difference.full().ravel()[4:7]
        field = design.field_body(x, t).full().ravel()
        expected = np.cross(residual, field) + np.array([0, 2e-6, 0]) - np.array([1e-6, 0, 0])
        expected += np.array([1e-5, 0, 2e-5]) * np.sin(n * t + np.array([0.3, 0, -1.0]))
        expected += np.array([0, 3e-5, 0]) * np.sin(2 * n * t + np.array([0, 0.7, 0]))
        np.testing.assert_allclose(torque, expected, rtol=1e-10, atol=1e-18)
        np.testing.assert_allclose(difference.full().ravel()[7:], 0.0, atol=0)


def test_effects_needing_what_the_design_lacks_are_refused():
    bare = wheel_model()
    with pytest.raises(ModelError, match="residual_dipole"):
        TruthPlant(bare, Truth(residual_dipole=[0.1, 0, 0]))
    with pytest.raises(ModelError, match="orbit_periodic"):
        TruthPlant(bare, Truth(periodic_disturbance=(PeriodicTorque(1, [1e-5, 0, 0]),)))
    with pytest.raises(ModelError, match="scale_error"):
        TruthPlant(bare, Truth(dipole_scale_error=0.1))
    no_spin = AttitudeModel(Spacecraft([1.0, 1.0, 1.0], wheels=ReactionWheels(np.eye(3))))
    with pytest.raises(ModelError, match="viscous"):
        TruthPlant(no_spin, Truth(wheel_viscous=1e-4))
    with pytest.raises(ModelError, match="wheels.max_torque"):
        TruthPlant(bare, Truth(wheel_max_torque=[0.1, 0.1]))
    with pytest.raises(ModelError, match="spacecraft.inertia"):
        Truth(inertia=[[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]])  # eigenvalue -1
    with pytest.raises(ModelError, match="torque_noise"):
        Truth(wheel_torque_noise=-1e-3)


def test_truth_limits_saturate_the_loop_and_noise_comes_from_its_own_stream():
    """The truth's torque limit (0.02 N m) clips what the design (0.1 N m) allows; the delivered
    torque is the clipped one plus normals from default_rng([seed, 2]) times the deviations."""
    design = wheel_model(max_torque=0.1)
    std = np.array([1e-3, 2e-3, 5e-4])
    plant = TruthPlant(design, Truth(wheel_max_torque=0.02, wheel_torque_noise=std))
    simulator = Simulator(design, 0.5, plant=plant)
    result = simulator.run(Constant([0.05, -0.01, 0.0]), np.r_[1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0], 5.0,
                           noise=SensorNoise(seed=7))
    normals = np.random.default_rng([7, 2]).standard_normal((10, 3))
    np.testing.assert_allclose(result.applied_u, np.array([0.02, -0.01, 0.0]) + normals * std, rtol=0, atol=1e-17)
    assert result.saturated.all()
    np.testing.assert_array_equal(result.commanded_u, np.tile([0.05, -0.01, 0.0], (10, 1)))


def symbolic_case():
    """Two misaligned wheels with every wheel effect, magnetorquers with a scale error, a residual
    dipole, constant and periodic disturbances, a field and gravity gradient; the augmented
    quaternion feedback (symbolic) regulating a 20° error under sensor noise."""
    environment = Environment(orbit=CircularOrbit(altitude=500e3, inclination=math.radians(97.0)),
                              gravity_gradient=True, magnetic_field=TiltedDipole())
    spacecraft = Spacecraft([2.0, 1.8, 1.2], wheels=ReactionWheels(np.eye(3)[:, :2], max_torque=0.005,
                                                                   max_momentum=0.05, spin_inertia=2e-4),
                            magnetorquers=Magnetorquers(max_dipole=0.5))
    design = AttitudeModel(spacecraft, environment)
    truth = Truth(inertia=[[2.1, 0.05, -0.02], [0.05, 1.75, 0.01], [-0.02, 0.01, 1.25]],
                  wheel_misalignment=np.radians([[0.0, 1.0, 2.0], [-1.5, 0.0, 0.5]]), wheel_max_torque=0.004,
                  wheel_coulomb=2e-5, wheel_viscous=[1e-6, 2e-6], wheel_max_speed=200.0,
                  wheel_torque_noise=[1e-4, 5e-5], dipole_scale_error=[0.05, -0.1, 0.02],
                  residual_dipole=[0.01, -0.005, 0.02], constant_disturbance=[1e-6, -2e-6, 0.0],
                  periodic_disturbance=(PeriodicTorque(1, [2e-6, 0, 1e-6], [0.1, 0, 0.4]),
                                        PeriodicTorque(2, [0, 1e-6, 0])))
    controller = CONTROLLERS["augmented_quaternion_feedback"]
    return TruthPlant(design, truth), controller(controller.Options(kp=0.02, kd=0.1))


@pytest.mark.parametrize("compiled", [False, True])
def test_python_loop_and_casadi_closed_loop_integrate_the_same_truth(compiled):
    plant, controller = symbolic_case()
    x0 = np.r_[1.0, 0, 0, 0, 0.01, -0.005, 0.002, 0.002, -0.001]
    target = (np.array([math.cos(math.radians(10)), math.sin(math.radians(10)), 0, 0]), np.zeros(3))
    noise = SensorNoise(attitude_std=1e-4, rate_std=1e-5, field_std=1e-8, seed=11)
    results = []
    for python_loop in (True, False):
        simulator = Simulator(plant.design, 1.0, plant=plant, python_loop=python_loop, compile=compiled)
        results.append(simulator.run(controller, x0, 120.0, target=target, noise=noise))
    python, symbolic = results
    assert python.path == "python"
    assert symbolic.path in (("compiled", "interpreted") if compiled else ("interpreted",))  # no compiler: interpreted
    for name in ("x", "commanded_u", "applied_u", "applied_torque"):
        np.testing.assert_allclose(getattr(symbolic, name), getattr(python, name), rtol=0, atol=1e-12, err_msg=name)
    np.testing.assert_array_equal(symbolic.saturated, python.saturated)
    assert python.saturated.any() and python.model is plant.model
    dipole = python.applied_u[:, 2:5]
    assert np.abs(dipole).max() > 1e-3  # the scale error acts on a dipole that is used
    untouched = Simulator(plant.design, 1.0, python_loop=True).run(controller, x0, 120.0, target=target, noise=noise)
    assert np.abs(untouched.x - python.x).max() > 1e-4  # the truth changed the run


def test_a_truth_that_changes_nothing_changes_no_bit():
    """Truth() (every value the design's) gives bit for bit the run without a plant, on every path."""
    plant, controller = symbolic_case()
    design = plant.design
    empty = TruthPlant(design, Truth())
    x0 = np.r_[1.0, 0, 0, 0, 0.01, -0.005, 0.002, 0.002, -0.001]
    target = (np.array([math.cos(math.radians(10)), math.sin(math.radians(10)), 0, 0]), np.zeros(3))
    noise = SensorNoise(attitude_std=1e-4, rate_std=1e-5, seed=3)
    for python_loop in (True, False):
        runs = [Simulator(design, 1.0, plant=p, python_loop=python_loop).run(controller, x0, 60.0, target=target,
                                                                              noise=noise) for p in (None, empty)]
        for name in ("x", "commanded_u", "applied_u", "applied_torque", "saturated"):
            assert np.array_equal(getattr(runs[0], name), getattr(runs[1], name)), name


def test_a_shipped_scenario_whose_truth_is_its_design_runs_bit_for_bit_as_without_truth():
    """eigenaxis_truth.yaml's truth inertia is its design's: the runner's rows are the same bits
    with the truth section and without it."""
    path = Path(__file__).resolve().parents[1] / "scenarios" / "eigenaxis_truth.yaml"
    with_truth = load(path)
    data = copy.deepcopy(with_truth.data)
    del data["truth"]
    without = parse_scenario(data)
    assert with_truth.truth is not None and without.truth is None
    rows = [run(scenario).rows for scenario in (with_truth, without)]
    for a, b in zip(*rows):
        for name in ("x", "commanded_u", "applied_u", "applied_torque", "saturated"):
            assert np.array_equal(getattr(a.simulation, name), getattr(b.simulation, name)), (a.label, name)


def test_the_controller_is_reset_with_the_design_spacecraft():
    design = wheel_model()
    plant = TruthPlant(design, Truth(inertia=[25.0, 20.0, 15.0], wheel_max_torque=0.01))
    controller = Constant([0.0, 0.0, 0.0])
    simulate(plant, controller, np.r_[1.0, 0, 0, 0, 0, 0, 0, 0, 0, 0], 1.0)
    assert controller.spacecraft is design.spacecraft
    assert plant.model.spacecraft.wheels.max_torque.tolist() == [0.01] * 3
    np.testing.assert_array_equal(design.spacecraft.inertia, np.diag([19.5, 19.0, 12.6]))
    with pytest.raises(TypeError, match="built on this simulator's model"):
        Simulator(wheel_model(), 0.5, plant=plant)


@pytest.mark.parametrize("compiled", [False, True])
def test_truth_and_sensors_with_the_estimator_agree_on_every_path(compiled, tmp_path, monkeypatch):
    """The truth plant (every effect, motor noise on stream [seed, 2]) and the gyro, star tracker
    and MEKF (streams [seed, 3..5]) in one loop: the Python loop and the CasADi loop give the same
    run, and each of the two changes it (neither silently drops the other)."""
    from ocp.estimation import Gyro, Mekf, SensorSuite, StarTracker

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    plant, controller = symbolic_case()
    x0 = np.r_[1.0, 0, 0, 0, 0.01, -0.005, 0.002, 0.002, -0.001]
    target = (np.array([math.cos(math.radians(10)), math.sin(math.radians(10)), 0, 0]), np.zeros(3))
    sensors = SensorSuite(Gyro(arw=1e-5, rrw=1e-7, bias=[1e-5, -2e-5, 5e-6]), StarTracker(noise=[2e-5, 2e-5, 1e-4]),
                          estimator=Mekf(attitude_sigma=1e-3, bias_sigma=5e-5))
    noise = SensorNoise(seed=11)

    def simulate(python_loop, with_plant=True, with_sensors=True):
        simulator = Simulator(plant.design, 1.0, plant=plant if with_plant else None, python_loop=python_loop,
                              compile=compiled and not python_loop)
        return simulator.run(controller, x0, 120.0, target=target, noise=noise,
                             sensors=sensors if with_sensors else None)

    python, symbolic = simulate(True), simulate(False)
    assert python.path == "python" and symbolic.path != "python"
    for name in ("x", "commanded_u", "applied_u", "applied_torque", "sensor_state"):
        np.testing.assert_allclose(getattr(symbolic, name), getattr(python, name), rtol=0, atol=1e-10, err_msg=name)
    np.testing.assert_array_equal(symbolic.saturated, python.saturated)
    assert np.abs(simulate(True, with_plant=False).x - python.x).max() > 1e-4  # the truth acts
    assert np.abs(simulate(True, with_sensors=False).x - python.x).max() > 1e-6  # the sensors act
