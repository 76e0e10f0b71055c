"""The model against conservation laws, independent formulas and linear theory."""
import casadi as ca
import numpy as np
import pytest

from ocp import (
    AttitudeModel,
    CircularOrbit,
    Command,
    Environment,
    ModelError,
    ReactionWheels,
    Simulator,
    Spacecraft,
    TiltedDipole,
    quat,
)
from ocp.dynamics.environment import EARTH_RATE
from ocp.dynamics.orbits import MU_EARTH, R_EARTH


class InternalWheelTorques:
    """Wheel motor torques that vary in time but are purely internal."""

    def reset(self, spacecraft, sample_time, target=None):
        pass

    def __call__(self, t, measurement, reference):
        return Command(wheel_torque=0.002 * np.array([np.sin(0.1 * t), np.cos(0.07 * t), -0.5]))


class NoActuation:
    def reset(self, spacecraft, sample_time, target=None):
        pass

    def __call__(self, t, measurement, reference):
        return Command()


def kinetic_energy(inertia, omega):
    return 0.5 * np.einsum("ij,jk,ik->i", omega, inertia, omega)


def test_torque_free_asymmetric_body_conserves_momentum_energy_and_norm(rng):
    inertia = np.array([[10.0, 0.3, -0.2], [0.3, 7.0, 0.4], [-0.2, 0.4, 5.0]])
    model = AttitudeModel(Spacecraft(inertia))
    x0 = np.r_[quat.random_unit(rng), 0.3, -0.2, 0.25]
    sim = Simulator(model, sample_time=10.0, max_step=0.01)  # conservation to 1e-9 wants h ≤ 0.01 s at 0.4 rad/s
    result = sim.run(NoActuation(), x0, duration=2000.0)
    momentum = model.inertial_momentum(result.x)
    assert np.max(np.linalg.norm(momentum - momentum[0], axis=1)) / np.linalg.norm(momentum[0]) < 1e-9
    energy = kinetic_energy(inertia, result.omega)
    assert np.max(np.abs(energy - energy[0])) / energy[0] < 1e-9
    # Re-normalisation happens after each sample; the integrator alone must keep the norm too.
    x = x0
    for k in range(200):
        x = sim._step(x, np.zeros(0), 10.0 * k, 10.0, np.zeros(3)).full().ravel()
    assert abs(np.linalg.norm(x[:4]) - 1) < 1e-9


def test_wheels_with_internal_torques_conserve_total_inertial_momentum(rng):
    spacecraft = Spacecraft([4.0, 3.0, 2.0], wheels=ReactionWheels.from_body_axes())
    model = AttitudeModel(spacecraft)
    x0 = np.r_[quat.random_unit(rng), 0.05, -0.1, 0.08, 0.1, -0.2, 0.05]
    result = Simulator(model, sample_time=1.0, max_step=0.01).run(InternalWheelTorques(), x0, duration=500.0)
    momentum = model.inertial_momentum(result.x)
    # The wheels exchange a momentum comparable to the total: the test is not vacuous.
    assert np.max(np.linalg.norm(result.wheel_momentum - result.wheel_momentum[0], axis=1)) > 0.5
    assert np.max(np.linalg.norm(momentum - momentum[0], axis=1)) / np.linalg.norm(momentum[0]) < 1e-9


def gravity_gradient_numpy(q, r_inertial, inertia):
    """Independent formula: 3μ/r³ (n̂_B × I n̂_B) with the nadir direction in body axes."""
    nadir_body = quat.rotate_inverse(q, -r_inertial / np.linalg.norm(r_inertial))
    return 3 * MU_EARTH / np.linalg.norm(r_inertial) ** 3 * np.cross(nadir_body, inertia @ nadir_body)


def test_gravity_gradient_matches_independent_formula(rng):
    orbit = CircularOrbit(altitude=700e3, inclination=1.2, raan=0.4)
    moments = rng.uniform(2.0, 4.0, 3)  # any three in [2, 4] satisfy the triangle inequalities
    rotation = quat.rotation_matrix(quat.random_unit(rng))
    inertia = rotation @ np.diag(moments) @ rotation.T
    model = AttitudeModel(Spacecraft(inertia), Environment(orbit=orbit, gravity_gradient=True))
    for _ in range(20):
        q = quat.random_unit(rng)
        t = rng.uniform(0, 6000)
        r = np.array(ca.DM(orbit.position(t))).ravel()
        torque = model.environment_torque(np.r_[q, 0, 0, 0], t, np.zeros(3)).full().ravel()
        np.testing.assert_allclose(torque, gravity_gradient_numpy(q, r, inertia), rtol=1e-10, atol=1e-16)


def test_gravity_gradient_vanishes_with_a_principal_axis_at_nadir(rng):
    orbit = CircularOrbit(altitude=600e3, inclination=0.5)
    inertia = np.diag([3.0, 4.0, 5.0])
    model = AttitudeModel(Spacecraft(inertia), Environment(orbit=orbit, gravity_gradient=True))
    t = 1234.0
    nadir = np.array(ca.DM(orbit.nadir(t))).ravel()
    for axis in np.eye(3):
        # Any attitude whose body principal axis `axis` points at nadir (random roll about it).
        q_align = quat.from_rotation_matrix(_frame_with_first_column(nadir, rng))
        q = quat.product(q_align, _rotation_taking_x_to(axis))
        assert np.allclose(quat.rotate(q, axis), nadir)
        torque = model.environment_torque(np.r_[q, 0, 0, 0], t, np.zeros(3)).full().ravel()
        tilted = quat.product(q, quat.from_rotation_vector([0.01, 0.02, 0.0]))
        off = model.environment_torque(np.r_[tilted, 0, 0, 0], t, np.zeros(3)).full().ravel()
        assert np.linalg.norm(torque) < 1e-12 * np.linalg.norm(off)


def _frame_with_first_column(direction, rng):
    other = rng.standard_normal(3)
    y = np.cross(direction, other)
    y /= np.linalg.norm(y)
    return np.column_stack([direction, y, np.cross(direction, y)])


def _rotation_taking_x_to(axis):
    """Quaternion whose rotation takes ``axis`` to body x (so R(q_align ⊗ this) axis = nadir)."""
    x = np.array([1.0, 0, 0])
    cross = np.cross(axis, x)
    if np.linalg.norm(cross) < 1e-12:
        return quat.IDENTITY
    return quat.from_axis_angle(cross / np.linalg.norm(cross), np.arccos(np.dot(axis, x)))


def test_orbit_function_is_circular_at_the_mean_motion():
    orbit = CircularOrbit(altitude=600e3, inclination=np.deg2rad(97.79), raan=0.5, arg_latitude=0.2)
    evaluate = orbit.function()
    for t in (0.0, 1000.0, 5000.0):
        out = evaluate(t=t)
        r, v, nadir = (out[k].full().ravel() for k in ("position", "velocity", "nadir"))
        assert np.linalg.norm(r) == pytest.approx(orbit.radius, rel=1e-12)
        assert np.linalg.norm(v) == pytest.approx(np.sqrt(MU_EARTH / orbit.radius), rel=1e-12)
        assert abs(r @ v) < 1e-6 * orbit.radius and np.allclose(nadir, -r / orbit.radius)
    # 600 km: mean motion 1.083e-3 rad/s and period 5801 s (nano-spacecraft paper, section III).
    assert orbit.mean_motion == pytest.approx(1.083e-3, rel=1e-3)
    assert 2 * np.pi / orbit.mean_motion == pytest.approx(5801.06, rel=1e-3)


def test_pitch_libration_frequency_matches_linear_theory():
    # x along-track, y orbit normal (LVLH: minus the orbit angular momentum), z nadir.
    inertia = np.array([2.0, 2.5, 1.0])
    orbit = CircularOrbit(altitude=600e3, inclination=0.9, raan=0.3)
    model = AttitudeModel(Spacecraft(inertia), Environment(orbit=orbit, gravity_gradient=True))
    n = orbit.mean_motion
    lvlh = ca.Function("lvlh", [s := ca.SX.sym("t")], [orbit.lvlh_matrix(s)])
    q_lvlh0 = quat.from_rotation_matrix(np.array(lvlh(0.0)))
    pitch0 = np.deg2rad(1.0)
    q0 = quat.product(q_lvlh0, quat.from_axis_angle([0, 1, 0], pitch0))
    x0 = np.r_[q0, 0.0, -n, 0.0]  # the LVLH frame turns at −n about its y axis
    period_guess = 2 * np.pi / (n * np.sqrt(3 * (inertia[0] - inertia[2]) / inertia[1]))
    result = Simulator(model, sample_time=5.0, max_step=1.0).run(NoActuation(), x0, 3.2 * period_guess)
    q_lvlh = quat.from_rotation_matrix(np.stack([np.array(lvlh(t)) for t in result.t]))
    relative = quat.product(quat.conjugate(q_lvlh), result.q)
    relative *= np.sign(relative[:, :1])  # q and −q are one attitude; keep q0 > 0 (small pitch)
    pitch = 2 * np.arctan2(relative[:, 2], relative[:, 0])
    assert np.max(np.abs(relative[:, [1, 3]])) < 1e-6  # motion stays in pitch
    crossings = [
        result.t[k] - pitch[k] * (result.t[k + 1] - result.t[k]) / (pitch[k + 1] - pitch[k])
        for k in range(len(pitch) - 1) if pitch[k] * pitch[k + 1] < 0
    ]
    measured = 2 * np.pi / (2 * np.mean(np.diff(crossings)))
    expected = n * np.sqrt(3 * (inertia[0] - inertia[2]) / inertia[1])
    assert len(crossings) >= 5
    assert measured == pytest.approx(expected, rel=0.01)


def dipole_field(dipole, position, t):
    return dipole.function()(position=position, t=t)["b"].full().ravel()


def test_dipole_magnitude_on_equator_and_poles_at_600_km(rng):
    dipole = TiltedDipole()
    r = R_EARTH + 600e3
    t = 3000.0
    axis = -np.array(ca.DM(dipole.dipole_direction(t))).ravel()  # towards the northern pole
    for _ in range(10):
        equatorial = np.cross(axis, rng.standard_normal(3))
        equatorial *= r / np.linalg.norm(equatorial)
        assert np.linalg.norm(dipole_field(dipole, equatorial, t)) == pytest.approx(dipole.strength / r**3, rel=1e-12)
    for pole in (axis, -axis):
        assert np.linalg.norm(dipole_field(dipole, r * pole, t)) == pytest.approx(2 * dipole.strength / r**3, rel=1e-12)


def test_dipole_matches_the_papers_geomagnetic_form(rng):
    """Eq. 6 of the nano-spacecraft paper in geomagnetic latitude/longitude, with zero tilt."""
    dipole = TiltedDipole(tilt=0.0, pole_longitude=0.0)
    r = R_EARTH + 600e3
    for _ in range(10):
        lat, lon = rng.uniform(-1.5, 1.5), rng.uniform(-np.pi, np.pi)
        position = r * np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
        b_geomagnetic_cartesian = -dipole.strength / r**3 * np.array([
            3 * np.sin(lat) * np.cos(lat) * np.cos(lon),
            3 * np.sin(lat) * np.cos(lat) * np.sin(lon),
            3 * np.sin(lat) ** 2 - 1,
        ])
        np.testing.assert_allclose(dipole_field(dipole, position, 0.0), b_geomagnetic_cartesian, rtol=1e-12, atol=1e-18)


def test_dipole_rotates_with_the_earth_at_the_sidereal_rate(rng):
    dipole = TiltedDipole()
    r = R_EARTH + 600e3
    position = r * quat.normalize(rng.standard_normal(3))
    dt = 4000.0
    turn = quat.from_axis_angle([0, 0, 1], EARTH_RATE * dt)
    later = dipole_field(dipole, quat.rotate(turn, position), dt)
    np.testing.assert_allclose(later, quat.rotate(turn, dipole_field(dipole, position, 0.0)), rtol=1e-10, atol=1e-18)
    # And it does change for an inertially fixed point (the test above would pass for a static field).
    assert np.linalg.norm(dipole_field(dipole, position, dt) - dipole_field(dipole, position, 0.0)) > 1e-7


@pytest.mark.parametrize(
    "inertia, message",
    [
        ([1.0, 1.0, 3.0], "triangle"),
        ([1.0, -1.0, 1.0], "positive definite"),
        ([[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], "symmetric"),
        ([1.0, 2.0], "3 principal moments"),
    ],
)
def test_invalid_inertia_is_rejected_with_a_clear_message(inertia, message):
    with pytest.raises(ModelError, match=message) as info:
        Spacecraft(inertia)
    assert info.value.field == "inertia"


def test_an_asymmetric_inertia_names_the_mismatched_product_and_its_values():
    """A product of inertia typed with opposite signs (a sign-convention slip) is named by its
    elements and their values, not only "must be symmetric"."""
    with pytest.raises(ModelError) as info:
        Spacecraft([[3.1, 0.06, 0.04], [-0.06, 2.7, -0.03], [0.04, -0.03, 2.2]])
    assert "[0][1] = 0.06 but [1][0] = -0.06" in info.value.message
    with pytest.raises(ModelError, match="non-zero, got"):
        Spacecraft(np.zeros((3, 3)))


def test_two_wheel_satellite_is_expressible():
    spacecraft = Spacecraft([1.0, 1.2, 1.4], wheels=ReactionWheels(np.eye(3)[:, :2], max_torque=0.01))
    assert spacecraft.n_wheels == 2
    np.testing.assert_allclose(spacecraft.body_torque_limit(), [0.01, 0.01, 0.0])
    failed = Spacecraft([1.0, 1.2, 1.4], wheels=ReactionWheels.from_body_axes(max_torque=0.01, failed=(2,)))
    np.testing.assert_allclose(failed.body_torque_limit(), [0.01, 0.01, 0.0])
