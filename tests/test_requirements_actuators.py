"""A reference's actuator demand through a law's allocation, against independent computations.

* Three orthogonal wheels: the allocation's wheel torque is ``g = -(u + ω × h)`` component-wise
  (hand-worked), and the wheel momenta, integrated by the demand, must equal what the conservation
  of the total angular momentum gives without any allocation: ``h(t) = R(q)ᵀ R(q₀)(I ω₀ + h₀) − I ω(t)``
  along a motion whose attitude is integrated from its rate (SciPy, tight tolerances) and whose
  torque is the inverse dynamics.
* Two wheels and torquers: what the wheels cannot give goes to the torquers (hand-worked); a
  ``wheels_only`` law drops it.
* Magnetorquers: ``m = B × τ / |B|²`` with the field along the reference, leaving the torque along it.
* The actuator score: demand over limit against ``1 − margin``.
* The torque the commands leave out (``unrealised_torque``): about an axis no wheel spans, the whole
  component (hand-worked); zero for torque the wheels give through their gyroscopic term (a torque
  built from chosen motor torques and momenta); along the field for magnetorquers alone; and a
  reference that needs it is never ``ok`` (a run on one wheel), while the optimal two-wheel
  manoeuvre, which needs none, stays ``ok``.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from controllers import CONTROLLERS
from controllers.allocation import Demand, reference_demand, unrealised_torque
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Environment,
    Magnetorquers,
    ReactionWheels,
    Spacecraft,
    Torquers,
    quat,
)
from ocp.dynamics.environment import MAGNETIC_FIELDS
from scenarios.requirements.scoring import _actuators

INERTIA = np.diag([0.25, 0.28, 0.12])


def rate(t: np.ndarray) -> np.ndarray:
    return np.stack([0.02 * np.sin(0.3 * t), 0.015 * np.cos(0.2 * t) - 0.015, 0.01 * t / (1 + 0.1 * t)], axis=-1)


def rate_dot(t: np.ndarray) -> np.ndarray:
    return np.stack([0.006 * np.cos(0.3 * t), -0.003 * np.sin(0.2 * t), 0.01 / (1 + 0.1 * t) ** 2], axis=-1)


def motion(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Attitude integrated from the rate (q̇ = ½ q ⊗ [0, ω]), the rate, the inverse-dynamics torque."""
    def rhs(time, q):
        return 0.5 * quat.product(q, np.concatenate([[0.0], rate(np.array([time]))[0]]))
    solution = solve_ivp(rhs, (t[0], t[-1]), quat.IDENTITY, t_eval=t, rtol=1e-12, atol=1e-13, method="DOP853")
    omega = rate(t)
    torque = rate_dot(t) @ INERTIA.T + np.cross(omega, omega @ INERTIA.T)
    return solution.y.T, omega, torque


def test_three_orthogonal_wheels_torque_by_hand_and_momentum_by_conservation():
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.003, max_momentum=0.02))
    model = AttitudeModel(spacecraft)
    t = np.linspace(0.0, 40.0, 4001)
    q, omega, torque = motion(t)
    h0 = np.array([0.004, -0.002, 0.001])
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, omega, torque, h0)
    assert list(demand) == ["wheels_torque", "wheels_momentum"]
    # momentum: conserved total angular momentum, no allocation involved
    total = quat.rotate(quat.IDENTITY, INERTIA @ omega[0] + h0)
    expected_h = quat.rotate(quat.conjugate(q), np.tile(total, (t.size, 1))) - omega @ INERTIA.T
    h = demand["wheels_momentum"].values
    assert np.max(np.abs(h - expected_h)) < 1e-6 * np.max(np.abs(expected_h))
    # torque: g = -(u + ω × h), component by component, at the demand's own momenta
    g = demand["wheels_torque"].values
    for k in (0, 1234, 4000):
        u, w, hk = torque[k], omega[k], h[k]
        hand = [-(u[0] + w[1] * hk[2] - w[2] * hk[1]),
                -(u[1] + w[2] * hk[0] - w[0] * hk[2]),
                -(u[2] + w[0] * hk[1] - w[1] * hk[0])]
        assert g[k] == pytest.approx(hand, rel=1e-12, abs=1e-15)
    np.testing.assert_array_equal(demand["wheels_torque"].limit, [0.003] * 3)
    np.testing.assert_array_equal(demand["wheels_momentum"].limit, [0.02] * 3)


@pytest.mark.parametrize("options", [{"gyroscopic_rate": "reference"}, {"gyroscopic_rate": "body"}])
def test_the_demand_is_physics_whatever_the_laws_formula(options):
    """``mrp_feedback`` with the reference rate computes ``ω × A h_w`` inside its law and declares
    no gyroscopic compensation; following the reference still asks the wheels for that term. Its
    demand equals the hand-worked ``g = -(u + ω × h)`` with the momenta the conservation of total
    angular momentum gives (the oracles of the test above), for both of its forms."""
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.003, max_momentum=0.02))
    t = np.linspace(0.0, 40.0, 4001)
    q, omega, torque = motion(t)
    h0 = np.array([0.004, -0.002, 0.001])
    law = CONTROLLERS["mrp_feedback"](CONTROLLERS["mrp_feedback"].Options(**options))
    law.reset(spacecraft, 0.1)
    assert law.gyroscopic_compensation == (options["gyroscopic_rate"] == "body")
    demand = reference_demand(law, AttitudeModel(spacecraft), t, q, omega, torque, h0)
    total = quat.rotate(quat.IDENTITY, INERTIA @ omega[0] + h0)
    expected_h = quat.rotate(quat.conjugate(q), np.tile(total, (t.size, 1))) - omega @ INERTIA.T
    h = demand["wheels_momentum"].values
    assert np.max(np.abs(h - expected_h)) < 1e-6 * np.max(np.abs(expected_h))
    expected_g = -(torque + np.cross(omega, h))
    np.testing.assert_allclose(demand["wheels_torque"].values, expected_g, rtol=1e-12, atol=1e-15)
    assert law.gyroscopic_compensation == (options["gyroscopic_rate"] == "body")  # the law is not changed


def test_what_two_wheels_cannot_give_goes_to_the_torquers_unless_the_law_is_wheels_only():
    """Wheels on body x and y with zero momentum and ω = 0: g = [-u_x, -u_y], torquers [0, 0, u_z]."""
    axes = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes=axes, max_torque=0.01), torquers=Torquers(max_torque=0.02))
    model = AttitudeModel(spacecraft)
    t = np.array([0.0, 1.0])
    u = np.array([[0.001, -0.002, 0.003], [0.004, 0.005, -0.006]])
    q, omega = np.tile(quat.IDENTITY, (2, 1)), np.zeros((2, 3))
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, omega, u)
    np.testing.assert_allclose(demand["wheels_torque"].values, [[-0.001, 0.002], [-0.004, -0.005]], rtol=1e-12)
    np.testing.assert_allclose(demand["torquers_torque"].values, [[0.0, 0.0, 0.003], [0.0, 0.0, -0.006]], atol=1e-15)
    np.testing.assert_allclose(demand["wheels_momentum"].values, [[0.0, 0.0], [-0.0025, -0.0015]], rtol=1e-12)
    wheels_only = CONTROLLERS["min_norm"]
    assert wheels_only.wheels_only
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes=axes, max_torque=0.01), torquers=Torquers(max_torque=0.02))
    demand = reference_demand(wheels_only(), AttitudeModel(spacecraft), t, q, omega, u)
    np.testing.assert_array_equal(demand["torquers_torque"].values, np.zeros((2, 3)))


def test_magnetorquers_take_the_torque_across_the_field_along_the_reference():
    orbit = CircularOrbit(altitude=600e3, inclination=np.deg2rad(97.8))
    field = MAGNETIC_FIELDS["tilted_dipole"].from_options(MAGNETIC_FIELDS["tilted_dipole"].Options(), orbit)
    spacecraft = Spacecraft(INERTIA, wheels=None, magnetorquers=Magnetorquers(max_dipole=0.2))
    model = AttitudeModel(spacecraft, Environment(orbit=orbit, magnetic_field=field))
    t = np.array([0.0, 30.0, 60.0])
    q = np.stack([quat.from_axis_angle(np.array([0.0, 1.0, 0.0]), a) for a in (0.0, 0.4, 0.9)])
    u = np.array([[1e-5, 0.0, -2e-5], [0.0, 3e-5, 0.0], [-1e-5, 1e-5, 1e-5]])
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, np.zeros((3, 3)), u)
    missing = unrealised_torque(model, t, q, np.zeros((3, 3)), u, demand)
    for k in range(3):
        b_inertial = np.asarray(field.field_inertial(orbit.position(t[k]), t[k])).ravel()
        b = quat.rotate(quat.conjugate(q[k]), b_inertial)
        np.testing.assert_allclose(demand["magnetorquers_dipole"].values[k], np.cross(b, u[k]) / b.dot(b), rtol=1e-9)
        # what they leave: the torque along the field (m × B has none)
        np.testing.assert_allclose(missing[k], b * u[k].dot(b) / b.dot(b), rtol=1e-9, atol=1e-20)


def test_ratios_and_the_actuator_score():
    demand = Demand("wheels_torque", np.array([[0.001, -0.0027, 0.0], [0.0005, 0.001, 0.0]]),
                    np.array([0.003, 0.003, np.inf]))
    ratios = demand.ratios()
    np.testing.assert_allclose(ratios, [[1 / 3, 0.9, 0.0], [1 / 6, 1 / 3, 0.0]])
    failed = Demand("wheels_torque", np.array([[0.0, 0.001]]), np.array([0.0, 0.0]))
    np.testing.assert_array_equal(failed.ratios(), [[0.0, np.inf]])
    t = np.array([0.0, 2.0])
    met = _actuators(0.9, {"wheels_torque": demand}, t)
    assert met.met and met.values == {"wheels_torque": pytest.approx(0.9), "wheels_torque_time_s": 0.0}
    broken = _actuators(0.8, {"wheels_torque": demand}, t)
    assert not broken.met and broken.detail == "wheels_torque 0.9 x its limit at 0.0 s (allowed 0.8 x)"
    unlimited = Demand("wheels_momentum", np.ones((2, 3)), np.full(3, np.inf))
    assert _actuators(0.5, {"wheels_momentum": unlimited}, t).values == {}


def test_torque_about_an_axis_no_wheel_spans_is_unrealised_by_hand():
    """One wheel on body x, at rest, no momentum: of u = [a, b, c] the wheel gives a; [0, b, c] is left."""
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes=np.array([[1.0], [0.0], [0.0]]), max_torque=0.01))
    model = AttitudeModel(spacecraft)
    t = np.array([0.0, 1.0, 2.0])
    u = np.array([[0.001, -0.002, 0.003], [0.0, 0.004, 0.0], [-0.005, 0.0, 0.0]])
    q, omega = np.tile(quat.IDENTITY, (3, 1)), np.zeros((3, 3))
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, omega, u)
    missing = unrealised_torque(model, t, q, omega, u, demand)
    np.testing.assert_allclose(missing, [[0.0, -0.002, 0.003], [0.0, 0.004, 0.0], [0.0, 0.0, 0.0]], atol=1e-15)
    score = _actuators(1.0, demand, t, [], missing, u)
    assert not score.met and "given by no working actuator" in score.detail
    assert score.values["unrealised_torque"] == pytest.approx(0.004, rel=1e-12)  # > |[0, -0.002, 0.003]|
    assert score.values["unrealised_torque_time_s"] == 1.0


def test_torque_two_wheels_give_through_their_momentum_is_realised():
    """Two wheels (x, y) spinning while the body turns: u = −A g − ω × A h has a z part, which the
    gyroscopic term gives; built from chosen g and the momenta they integrate to, nothing is left."""
    axes = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes=axes, max_torque=0.01, max_momentum=1.0))
    model = AttitudeModel(spacecraft)
    t = np.linspace(0.0, 10.0, 1001)
    q, omega, _ = motion(t)
    g = np.stack([0.002 * np.cos(0.5 * t), -0.001 + 0.0 * t], axis=1)
    h0 = np.array([0.05, -0.03])
    h = h0 + np.stack([0.004 * np.sin(0.5 * t), -0.001 * t], axis=1)  # ∫ g dt, closed form
    u = -g @ axes.T - np.cross(omega, h @ axes.T)
    assert np.max(np.abs(u[:, 2])) > 1e-4  # the z part is not small
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, omega, u, h0)
    missing = np.linalg.norm(unrealised_torque(model, t, q, omega, u, demand), axis=1)
    # the integrated momenta (two wheels: Runge-Kutta on inputs linear between samples) against the
    # closed form: O(dt²) (dt = 0.01 s); the missing torque follows them
    assert np.max(missing) < 1e-3 * np.max(np.abs(u[:, 2]))
    assert _actuators(1.0, demand, t, [], unrealised_torque(model, t, q, omega, u, demand), u).met


ONE_WHEEL = """
name: one-wheel
spacecraft:
  inertia: [2.0, 2.0, 2.0]
  wheels: {axes: [[1, 0, 0]], max_torque: 0.1, max_momentum: 10.0}
maneuver:
  duration: 60.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [AXIS_Q], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth, options: {profile: smooth}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.8}}
simulation: {sample_time: 0.5, duration: 80.0}
"""


@pytest.mark.parametrize("target, ok", [("0.7071068, 0, 0.7071068, 0", False), ("0.7071068, 0.7071068, 0, 0", True)])
def test_a_reference_needing_torque_no_actuator_gives_is_never_ok(tmp_path, target, ok):
    """90° about y on a spacecraft with one wheel on x (no torque about y: violated) and 90° about x
    (the wheel's own axis: ok)."""
    from scenarios.runner import run
    from scenarios.schema.loader import load

    path = tmp_path / "one_wheel.yaml"
    path.write_text(ONE_WHEEL.replace("AXIS_Q", target))
    row = run(load(path)).rows[0]
    assert (row.status == "ok") == ok, row.message
    if not ok:
        assert "given by no working actuator" in row.message
        # an eigenaxis slew of a sphere about y: all of its torque is about y
        assert row.requirements["reference"]["actuators"]["unrealised_torque"] == pytest.approx(
            np.max(np.abs(row.reference.torque(np.linspace(0.0, 60.0, 2001))[:, 1])), rel=1e-2)


def test_a_reference_asking_no_torque_is_scored_without_dividing_by_it():
    """A torque-free reference (u = 0): rounding of the allocation is no demand, a real unrealised
    torque is one, and the message has no share of a zero peak (it divided by it)."""
    t = np.array([0.0, 1.0])
    zero = np.zeros((2, 3))
    assert _actuators(0.9, {}, t, [], np.array([[1e-18, 0.0, 0.0], [0.0, 0.0, 0.0]]), zero).met
    score = _actuators(0.9, {}, t, [], np.array([[0.0, 0.0, 0.0], [0.0, 2e-6, 0.0]]), zero)
    assert not score.met and score.detail.startswith("2e-06 N m of the torque asked at 1 s is given by no")


SPINNING = """
name: spinning
spacecraft:
  inertia: [10.0, 10.0, 10.0]
  wheels: {max_torque: 0.1, max_momentum: 1.0}
maneuver:
  duration: 200.0
  initial: {q: [1, 0, 0, 0], omega: [SPIN, 0, 0]}
  final: {q: [0.7071068, 0, 0, 0.7071068], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth, options: {profile: smooth}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.5, kd: 3.0}}
simulation: {sample_time: 0.5, duration: 260.0}
"""


@pytest.mark.parametrize("spin, ok", [(0.2, False), (0.05, True)])
def test_a_free_start_from_a_spin_counts_the_spins_momentum_in_the_wheels(tmp_path, spin, ok):
    """A user's case: an eigenaxis slew (a declared free start: it starts at rest) of a sphere
    spinning at ``spin`` about x. No external torque acts, so the total angular momentum stays
    I ω₀ = 10 spin N m s along inertial x; along a reference at rest at both ends the body-axis
    wheels hold all of it, on x at the start and on -y at the end (90° about z): a peak of
    10 spin per wheel, beside the slew's own I ω_ref about z (0.147 N m s, 1.875 × 90° / 200 s for
    the quintic). At 0.2 rad/s that is 2 N m s against 1: no wheel can bring the body to rest
    (it was scored 0.147, the slew's alone, and ok)."""
    from scenarios.runner import run
    from scenarios.schema.loader import load

    path = tmp_path / "spinning.yaml"
    path.write_text(SPINNING.replace("SPIN", str(spin)))
    row = run(load(path)).rows[0]
    assert row.requirements["reference"]["actuators"]["wheels_momentum"] == pytest.approx(10 * spin / 1.0, rel=1e-6)
    assert (row.status == "ok") == ok, row.message
    if not ok:
        assert "wheels_momentum 2 x its limit" in row.message


PYRAMID = np.array([[c * np.cos(a), c * np.sin(a), s] for a in np.deg2rad([45.0, 135.0, 225.0, 315.0])
                    for c, s in [(np.cos(np.deg2rad(30.0)), np.sin(np.deg2rad(30.0)))]]).T


@pytest.mark.parametrize("other", ["magnetorquers", "torquers"])
def test_pyramid_beside_stateless_actuators_keeps_the_momentum_balance(other):
    """A four-wheel pyramid beside magnetorquers (in a field) or torquers: the wheels span three
    axes, so the allocation asks the other actuator nothing and the total angular momentum changes
    by no torque. The wheels' stored momentum must be the balance's closed form at every sample,
    ``A h_w = R(q)ᵀ R(q₀)(I ω₀ + A h₀) − I ω``, however coarse the samples: here 2 s samples of a
    nutating motion, where integrating the states between them (linear inputs) missed it, and the
    wheel torque asked read up to 0.1 % of a wheel's limit too much (a collocation min-time slew
    on a 50 kg satellite's pyramid with magnetorquers, planned at 0.9 of the limit, scored 0.901
    and violated)."""
    orbit = CircularOrbit(altitude=600e3, inclination=np.deg2rad(97.8))
    actuator = (Magnetorquers(max_dipole=1.0) if other == "magnetorquers" else Torquers(max_torque=0.01))
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(PYRAMID, max_torque=0.003, max_momentum=0.02),
                            **{other: actuator})
    field = MAGNETIC_FIELDS["tilted_dipole"].from_options(MAGNETIC_FIELDS["tilted_dipole"].Options(), orbit)
    model = AttitudeModel(spacecraft, Environment(orbit=orbit, magnetic_field=field))
    t = np.linspace(0.0, 40.0, 21)
    q, omega, torque = motion(t)
    h0 = np.array([0.004, -0.002, 0.001, 0.003])
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, omega, torque, h0)
    h = demand["wheels_momentum"].values
    total = INERTIA @ omega[0] + PYRAMID @ h0  # inertial = body at the identity start
    expected = quat.rotate(quat.conjugate(q), np.tile(total, (t.size, 1))) - omega @ INERTIA.T
    np.testing.assert_allclose(h @ PYRAMID.T, expected, rtol=0, atol=1e-12)
    # the redundant wheels' null-space momentum is untouched: h − h0 lies in the row space of A
    null = np.linalg.svd(PYRAMID)[2][3]
    np.testing.assert_allclose((h - h0) @ null, 0.0, atol=1e-14)
    # the other actuator is asked nothing (the wheels give every torque)
    other_block = next(name for name in demand if name.startswith(other))
    np.testing.assert_allclose(demand[other_block].values, 0.0, atol=1e-15)
