"""Zero-order hold, actuator saturation and sensor noise in the simulator."""
import numpy as np
import pytest

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
    Torquers,
    quat,
)
from planners import PLANNERS, ManeuverProblem
from tests.conftest import WheelPD


class GreedyController:
    """Asks every actuator for ten times its limit, with signs that change over time."""

    def reset(self, spacecraft, sample_time, target=None):
        self.seen = []

    def __call__(self, t, measurement, reference):
        self.seen.append(measurement)
        sign = np.sign(np.sin(0.05 * t) + 0.3)
        return Command(wheel_torque=sign * np.array([1.0, -1.0, 0.5]), dipole=sign * np.array([2.0, -3.0, 1.0]),
                       torque=-sign * np.array([0.5, 0.2, -0.3]))


def saturating_model():
    spacecraft = Spacecraft(
        [2.0, 3.0, 4.0],
        wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=[0.5, 0.8, 1.0], failed=()),
        magnetorquers=Magnetorquers(max_dipole=0.2),
        torquers=Torquers(max_torque=0.05),
    )
    environment = Environment(orbit=CircularOrbit(600e3, np.deg2rad(97.8)), magnetic_field=TiltedDipole())
    return AttitudeModel(spacecraft, environment)


def test_applied_control_is_held_and_never_exceeds_a_limit():
    model = saturating_model()
    dt = 0.5
    result = Simulator(model, dt).run(GreedyController(), np.r_[1, 0, 0, 0, 0, 0, 0, 0, 0, 0], 60.0)
    slices = model.control_slices
    g = result.applied_u[:, slices["wheels"]]
    h = result.wheel_momentum
    # Zero-order hold: h_w is integrated exactly with the held torque, h_{k+1} = h_k + g_k dt.
    np.testing.assert_allclose(np.diff(h, axis=0), g * dt, atol=1e-12)
    assert np.all(np.abs(g) <= 0.1 + 1e-15)
    assert np.all(np.abs(h) <= np.array([0.5, 0.8, 1.0]) + 1e-12)
    assert np.all(np.abs(result.applied_u[:, slices["dipole"]]) <= 0.2 + 1e-15)
    assert np.all(np.abs(result.applied_u[:, slices["torquers"]]) <= 0.05 + 1e-15)
    # Momentum saturation was reached (the clipping did something) and flagged on every sample.
    assert np.any(np.isclose(np.abs(h), [0.5, 0.8, 1.0], rtol=1e-12).any(axis=1))
    assert result.saturated.all()
    # The body torque reported is the actuators' torque: −A g + m × B + τ_t at the sample.
    k = 7
    field = model.field_body(result.x[k], result.t[k]).full().ravel()
    expected = -g[k] + np.cross(result.applied_u[k, slices["dipole"]], field) + result.applied_u[k, slices["torquers"]]
    np.testing.assert_allclose(result.applied_torque[k], expected, rtol=1e-12)


def test_failed_wheel_produces_no_torque():
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.1, failed=(1,)))
    result = Simulator(AttitudeModel(spacecraft), 1.0).run(GreedyController(), np.r_[1, 0, 0, 0, 0, 0, 0, 0, 0, 0], 10.0)
    assert np.all(result.applied_u[:, 1] == 0.0)
    assert np.all(result.wheel_momentum[:, 1] == 0.0)
    assert np.any(result.applied_u[:, 0] != 0.0)


def test_sensor_noise_is_seeded_and_has_the_requested_spread():
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.01))
    model = AttitudeModel(spacecraft)
    x0 = np.r_[quat.IDENTITY, 0.01, 0.0, 0.0, 0, 0, 0]

    def measured(seed):
        controller = GreedyController()
        Simulator(model, 1.0).run(controller, x0, 400.0, noise=SensorNoise(np.deg2rad(0.1), 1e-4, seed))
        return controller

    first, again, other = measured(3), measured(3), measured(4)
    assert all(np.array_equal(a.q, b.q) for a, b in zip(first.seen, again.seen))
    assert not np.array_equal(first.seen[5].q, other.seen[5].q)
    # The rate noise around the true rate (the truth is the same run without noise).
    truth = GreedyController()
    Simulator(model, 1.0).run(truth, x0, 400.0)
    rate_errors = np.array([m.omega - t.omega for m, t in zip(first.seen, truth.seen)])
    assert np.std(rate_errors) == pytest.approx(1e-4, rel=0.1)
    angle_errors = np.array([quat.to_rotation_vector(quat.error(m.q, t.q)) for m, t in zip(first.seen, truth.seen)])
    assert np.std(angle_errors) == pytest.approx(np.deg2rad(0.1), rel=0.1)


def test_magnetometer_noise_is_independent_of_the_attitude_noise():
    """The magnetometer draws from its own stream: over 400 samples its errors are uncorrelated with
    the attitude noise's rotation vectors (each sample correlation within 0.25, five standard
    deviations of 1/√400), and have the requested spread. Drawn from one seed, the two would repeat
    the same normals (correlation 1)."""
    model = saturating_model()
    x0 = np.r_[quat.IDENTITY, 0.01, 0.0, 0.0, 0, 0, 0]

    def seen(noise):
        controller = GreedyController()
        Simulator(model, 1.0).run(controller, x0, 400.0, noise=noise)
        return controller.seen

    noisy, truth = seen(SensorNoise(attitude_std=1e-3, seed=3, field_std=1e-7)), seen(None)
    field_errors = np.array([m.field_body - t.field_body for m, t in zip(noisy, truth)])
    angle_errors = np.array([quat.to_rotation_vector(quat.error(m.q, t.q)) for m, t in zip(noisy, truth)])
    assert np.std(field_errors) == pytest.approx(1e-7, rel=0.1)
    correlation = np.corrcoef(field_errors.T, angle_errors.T)[0:3, 3:6]
    assert np.max(np.abs(correlation)) < 0.25


def test_pd_regulation_converges_and_integrators_agree():
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.5))
    model = AttitudeModel(spacecraft)
    target = quat.normalize(np.array([0.6, 0.2, -0.5, 0.3]))
    x0 = np.r_[quat.IDENTITY, 0.02, -0.01, 0.0, 0, 0, 0]
    rk4 = Simulator(model, 0.5).run(WheelPD(target, kp=0.2, kd=0.8), x0, 60.0)
    cvodes = Simulator(model, 0.5, integrator="cvodes").run(WheelPD(target, kp=0.2, kd=0.8), x0, 60.0)
    np.testing.assert_allclose(rk4.x, cvodes.x, atol=1e-8)
    assert np.rad2deg(quat.error_angle(rk4.q[-1], target)) < 0.1


def test_divergence_is_reported_not_returned_as_nan():
    from ocp import SimulationError

    spacecraft = Spacecraft([2.0, 3.0, 4.0], torquers=Torquers(max_torque=1e6))

    class Runaway(GreedyController):
        def __call__(self, t, measurement, reference):
            return Command(torque=1e5 * np.array([1.0, -1.0, 1.0]))

    with pytest.raises(SimulationError, match="non-finite"):
        Simulator(AttitudeModel(spacecraft), 1.0).run(Runaway(), np.r_[1, 0, 0, 0, 0, 0, 0], 100.0)


# --- review findings of the float rewrite (2026-11-23) -------------------------------------------

def _actuators(spacecraft):
    from ocp.dynamics.actuators import ActuatorModel
    model = AttitudeModel(spacecraft)
    return ActuatorModel(spacecraft, model.control_slices, model.nu)


def test_a_wheel_command_of_the_wrong_length_is_refused_not_truncated():
    axes = np.array([[1, 0, 0, 0.577], [0, 1, 0, 0.577], [0, 0, 1, 0.577]])
    actuators = _actuators(Spacecraft([2, 3, 4], wheels=ReactionWheels(axes, max_torque=0.1)))
    with pytest.raises(ValueError, match="4 values"):  # three torques for four wheels
        actuators.apply(Command(wheel_torque=np.array([0.01, 0.02, 0.03])), np.zeros(4), 1.0)
    with pytest.raises(ValueError, match="4 values"):
        actuators.apply(Command(wheel_torque=np.zeros(4)), np.zeros(3), 1.0)


def test_a_torquer_torque_of_the_wrong_length_is_refused():
    actuators = _actuators(Spacecraft([2, 3, 4], torquers=Torquers(0.1)))
    with pytest.raises(ValueError, match="3 values"):
        actuators.apply(Command(torque=np.array([0.5, 0.01])), np.zeros(0), 1.0)


class _WritesIntoItsSample:
    """A user law that scales the reference sample it is handed in place (a misuse)."""

    tracks_reference = True

    def reset(self, spacecraft, sample_time, target=None):
        pass

    def __call__(self, t, measurement, reference):
        torque = reference.sample(t).torque
        torque *= 2.0
        return Command(wheel_torque=-torque)


def test_the_kept_reference_table_is_read_only_so_runs_stay_independent():
    # The simulator keeps the grid-sampled reference for the next run on the same grid; a law
    # writing into a sample would change every later run: it must fail instead.
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(3, max_torque=0.1))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], 1.0), 30.0)
    reference = PLANNERS["eigenaxis"]().plan(problem)
    simulator = Simulator(AttitudeModel(spacecraft), 1.0)
    with pytest.raises(ValueError, match="read-only"):
        simulator.run(_WritesIntoItsSample(), problem.initial_state, 30.0, reference=reference)
