"""The actuator demand of a reference (``controllers.allocation.reference_demand``) and the
per-sample allocation, against oracles that are not the module's own method:

* the total angular momentum's balance in closed form: a body spinning at a constant rate ``Ω``
  about body z under a constant body-axis disturbance ``τ_d``: the inertial momentum grows by
  ``∫ R(t) τ_d dt`` with ``R(t)`` the rotation about z by ``Ωt`` (integral by hand), and the
  wheels hold ``h = R(t)ᵀ (R₀ (I ω₀ + h₀) + ∫ R τ_d) − I ω`` (three body-axis wheels); a start
  attitude tilted about x so that ``R₀`` is not ``R₀ᵀ`` on the spin;
* a jump of the rate taken up by the wheels, ``Δh = −A⁺ I Δω`` (body axes: ``−I Δω``), worked by
  hand;
* two wheels (x, y) and a rate about z alone: ``ḣ = −(ω × A h)`` on the x, y rows turns ``h`` by
  ``−θ(t)``, ``θ = ∫ ω_z dt`` (the integral of the linearly interpolated rate by hand), so the
  states of the integrated form are known in closed form, with a rate ramp that starts at rest
  and a kick on the way;
* the documented allocation: wheels spanning three axes leave nothing to the torquers beside them
  (``None``: nothing asked), whatever the rounding of ``A A⁺``.

Mutations caught (a scratch run of the mutation runner on controllers/allocation.py, these tests
beside tests/test_allocation_*.py, test_batched_demand, test_requirements_actuators,
test_requirements_demand_spacing, test_unrealised_bound, test_symbolic_laws, test_mutants_allocation,
which let them through): the rate jump's wheel kick with the wrong sign, the environment's impulse
by the rectangle rule or in body axes, the start momentum rotated the wrong way, sub-steps counted
from the interval's start rate only, the kick left out of its own sample's state or out of the
first Runge-Kutta stage, and torquers asked a rounding residual beside spanning wheels.
"""
from __future__ import annotations

import numpy as np

from controllers import CONTROLLERS
from controllers.allocation import reference_demand
from ocp import AttitudeModel, Measurement, ReactionWheels, Spacecraft, Torquers
from ocp.dynamics.environment import Environment

INERTIA = np.diag([19.5, 19.0, 12.6])


def _axis_quaternion(axis: np.ndarray, angle: float | np.ndarray) -> np.ndarray:
    angle = np.atleast_1d(np.asarray(angle, dtype=float))
    return np.column_stack([np.cos(angle / 2), np.sin(angle / 2)[:, None] * axis])


def _product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product of rows, scalar first (written out here)."""
    p0, pv, q0, qv = p[..., :1], p[..., 1:], q[..., :1], q[..., 1:]
    return np.concatenate([p0 * q0 - np.sum(pv * qv, axis=-1, keepdims=True),
                           p0 * qv + q0 * pv + np.cross(pv, qv)], axis=-1)


def _rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _rx(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def test_three_wheels_hold_the_momentum_balance_under_a_disturbance_on_a_spinning_tilted_body():
    spin, tilt, disturbance = 0.1, 0.6, np.array([2e-3, 0.0, 5e-4])
    t = np.arange(0.0, 30.0 + 1e-9, 0.1)
    q0 = _axis_quaternion(np.array([1.0, 0.0, 0.0]), tilt)[0]
    q = _product(np.tile(q0, (t.size, 1)), _axis_quaternion(np.array([0.0, 0.0, 1.0]), spin * t))
    omega = np.tile([0.0, 0.0, spin], (t.size, 1))
    h0 = np.array([0.2, -0.1, 0.3])
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=5.0))
    model = AttitudeModel(spacecraft, Environment(disturbance_torque=disturbance))
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), model, t, q, omega,
                              np.tile(-disturbance, (t.size, 1)), h0)
    start = _rx(tilt)
    # ∫₀ᵗ Rx Rz(Ωs) τ_d ds: the z part grows as t, the x, y parts turn
    s, c = np.sin(spin * t), np.cos(spin * t)
    tx, ty, tz = disturbance
    swept = np.stack([(tx * s - ty * (1 - c)) / spin, (tx * (1 - c) + ty * s) / spin, tz * t], axis=1)
    total = start @ (INERTIA @ omega[0] + h0) + swept @ start.T  # inertial
    expected = np.array([(start @ _rz(spin * tk)).T @ total[k] for k, tk in enumerate(t)]) - omega @ INERTIA.T
    assert np.abs(expected - h0).max() > 0.05  # the disturbance's impulse is no rounding
    # trapezoidal rule on 0.1 s samples: error ~ T |τ| (Ω dt)² / 12 ~ 5e-7 N m s
    np.testing.assert_allclose(demand["wheels_momentum"].values, expected, rtol=0, atol=2e-6)


def test_three_wheels_take_up_a_rate_jump_at_the_start():
    """The spacecraft spins at ω_s; the reference starts at rest: the jump is Δω = −ω_s and the body
    wheels store I ω_s at once (the total momentum is conserved)."""
    t = np.linspace(0.0, 5.0, 11)
    q = np.tile(_axis_quaternion(np.array([0.0, 1.0, 0.0]), 0.4)[0], (t.size, 1))
    spinning = np.array([0.01, -0.02, 0.03])
    jumps = np.zeros((t.size, 3))
    jumps[0] = -spinning
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=5.0))
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(spacecraft), t, q,
                              np.zeros((t.size, 3)), np.zeros((t.size, 3)), np.zeros(3), jumps=jumps)
    np.testing.assert_allclose(demand["wheels_momentum"].values, np.tile(INERTIA @ spinning, (t.size, 1)),
                               rtol=0, atol=1e-15)


TWO = Spacecraft(INERTIA, wheels=ReactionWheels(axes=np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]),
                                                max_torque=0.1, max_momentum=5.0))


def _turned(h: np.ndarray, angle: float) -> np.ndarray:
    """h (x, y) turned by −angle: the body turns by +angle about z, the momentum stays put."""
    return _rz(-angle)[:2, :2] @ h


def test_two_wheels_integrate_a_rate_that_starts_at_rest_at_full_resolution():
    """ω_z linear from 0 to 2 rad/s over the first second (1 rad turned), then constant: the states
    turn by θ(t) = t² (t ≤ 1), 1 + 2 (t − 1) after."""
    t = np.array([0.0, 1.0, 2.0, 2.5])
    omega = np.zeros((t.size, 3))
    omega[1:, 2] = 2.0
    q = np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1))  # not read by the wheels' equation
    h0 = np.array([0.3, 0.1])
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(TWO), t, q, omega,
                              np.zeros((t.size, 3)), h0)
    angles = [0.0, 1.0, 3.0, 4.0]
    expected = np.array([_turned(h0, angle) for angle in angles])
    np.testing.assert_allclose(demand["wheels_momentum"].values, expected, rtol=0, atol=1e-7)


def test_two_wheels_take_a_kick_at_its_sample_and_turn_it_after():
    """Spin 0.5 rad/s about z; at t = 2 the rate jumps by Δω = (0.01, 0.02, 0): the wheels (x, y)
    take −I Δω at once, then the whole momentum turns with the spin."""
    t = np.arange(0.0, 6.0 + 1e-9, 1.0)
    spin = 0.5
    omega = np.tile([0.0, 0.0, spin], (t.size, 1))
    jump = np.array([0.01, 0.02, 0.0])
    jumps = np.zeros((t.size, 3))
    jumps[2] = jump
    omega[2:, :2] += jump[:2]  # (the x, y rate changes nothing on the x, y rows of ω × A h)
    q = np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1))
    h0 = np.array([0.3, 0.1])
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(TWO), t, q, omega,
                              np.zeros((t.size, 3)), h0, jumps=jumps)
    kick = -(INERTIA @ jump)[:2]
    expected = np.array([_turned(h0, spin * tk) if tk < 2 else _turned(_turned(h0, 2 * spin) + kick, spin * (tk - 2))
                         for tk in t])
    # Runge-Kutta steps of 0.05 rad: phase error ~ 0.05⁵/120 a step, 2e-7 of |h| over the 3 rad turned
    np.testing.assert_allclose(demand["wheels_momentum"].values, expected, rtol=0, atol=3e-7)


def test_spanning_wheels_leave_the_torquers_nothing_despite_rounding():
    """A 4-wheel pyramid spans three axes: A A⁺ = I up to rounding, so the torquers beside the wheels
    are asked nothing (``None``), and the wheels give the whole torque ``−A g = u + ω × A h``."""
    beta = np.deg2rad(54.7356)
    axes = np.array([[np.sin(beta) * np.cos(a), np.sin(beta) * np.sin(a), np.cos(beta)]
                     for a in np.deg2rad([10.0, 100.0, 190.0, 280.0])]).T
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes=axes, max_torque=0.1, max_momentum=5.0),
                            torquers=Torquers(max_torque=1.0))
    law = CONTROLLERS["augmented_quaternion_feedback"]()
    law.reset(spacecraft, 0.5, target=(np.array([1.0, 0.0, 0.0, 0.0]), None))
    rng = np.random.default_rng(3)
    for _ in range(20):
        u, omega, h = rng.normal(0, 0.01, 3), rng.normal(0, 0.05, 3), rng.normal(0, 0.5, 4)
        command = law.allocate(u, Measurement(0.0, np.array([1.0, 0.0, 0.0, 0.0]), omega, h))
        assert command.torque is None
        np.testing.assert_allclose(-axes @ command.wheel_torque, u + np.cross(omega, axes @ h), rtol=0, atol=1e-15)
