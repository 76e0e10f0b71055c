"""The effort integrals compare across scopes: in closed loop ``int_u2``, ``int_u`` and
``int_abs_u`` integrate the control torque on the rigid body (the ``u`` of
``I ω̇ = −ω × I ω + u``, as a reference's feed-forward), while ``int_actuator_torque`` integrates
what the actuators applied. On wheels the two differ by the wheels' gyroscopic torque
``ω × A h_w``; with the total momentum zero, ``A h_w = −I ω`` and the actuators' torque is
``I ω̇``. Expected values are worked out here from the motion (Euler's equations, the quintic's
closed form), not taken from the code under test."""
from __future__ import annotations

import math

import numpy as np
import pytest

import scenarios
from ocp import (
    AttitudeModel,
    Command,
    ReactionWheels,
    Simulator,
    Spacecraft,
    Torquers,
    metrics_from_simulation,
)
from ocp.metrics import compute_metrics

NANO_INERTIA = np.diag([0.0109, 0.05, 0.05])  # kg m², the nano paper's UKube-1 (scenarios/nano_*.yaml)
SLEW_T = 60.0                                   # s, the quintic's duration
EFFORT_KEYS = ("int_u2", "int_u", "int_abs_u")


def tracked_slew(axis: np.ndarray, angle: float) -> scenarios.Row:
    """A rest-to-rest quintic eigenaxis slew on three body-axis wheels (no disturbance, the plant
    is the model), tracked by the augmented quaternion law with its feed-forward, 0.1 s hold."""
    q_f = np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis]
    data = {"name": "effort", "spacecraft": {"inertia": np.diag(NANO_INERTIA).tolist(), "wheels": {}},
            "maneuver": {"duration": SLEW_T, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                         "final": {"q": q_f.tolist(), "omega": [0, 0, 0]}},
            "planners": [{"name": "eigenaxis", "options": {"profile": "smooth"}}],
            "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 1.0, "kd": 1.6}},
            "simulation": {"sample_time": 0.1}}
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    assert row.status == "ok", row.message
    return row


def quintic_integrals(axis: np.ndarray, angle: float, points: int = 200001) -> tuple[float, float]:
    """∫‖u‖ dt and ∫‖I ω̇‖ dt of the quintic θ(t) = θ_f (10 s³ − 15 s⁴ + 6 s⁵), s = t/T,
    about the fixed ``axis`` e: ω = θ̇ e, u = I ω̇ + ω × I ω = θ̈ I e + θ̇² e × I e, by
    trapezoids on a fine grid; ∫‖I ω̇‖ dt = ‖I e‖ ∫|θ̈| dt = ‖I e‖ · 2 max θ̇
    = ‖I e‖ 15 θ_f / (4 T) in closed form."""
    s = np.linspace(0.0, 1.0, points)
    rate = angle / SLEW_T * (30 * s**2 - 60 * s**3 + 30 * s**4)
    acceleration = angle / SLEW_T**2 * (60 * s - 180 * s**2 + 120 * s**3)
    i_e = NANO_INERTIA @ axis
    u = np.outer(acceleration, i_e) + np.outer(rate**2, np.cross(axis, i_e))
    norms = np.linalg.norm(u, axis=1)
    int_u = float(np.sum(0.5 * (norms[1:] + norms[:-1])) * SLEW_T / (points - 1))
    return int_u, float(np.linalg.norm(i_e) * 15 * angle / (4 * SLEW_T))


def test_slew_about_a_principal_axis_has_no_gyroscopic_torque():
    """90° about body z, a principal axis: ω × I ω = 0 along the slew, so the body torque is the
    wheels' torque and every effort integral, reference or closed loop, is I_z ∫|θ̈| dt =
    15 I_z θ_f / (4 T) = 4.909e-3 N m s. The closed loop's differ from it by the hold and the
    feedback: measured 6e-6 relative at a 0.1 s hold, asserted to 1e-4."""
    z = np.array([0.0, 0.0, 1.0])
    row = tracked_slew(z, math.pi / 2)
    hand = 15 * 0.05 * (math.pi / 2) / (4 * SLEW_T)
    closed, reference = row.closed_loop_metrics, row.reference_metrics
    assert reference["int_u"] == pytest.approx(hand, rel=1e-5)
    assert closed["int_u"] == pytest.approx(hand, rel=1e-4)
    assert closed["int_actuator_torque"] == pytest.approx(closed["int_u"], rel=1e-9)
    assert closed["int_abs_u"][2] == pytest.approx(hand, rel=1e-4)
    assert closed["int_abs_u"][0] < 1e-9 * hand and closed["int_abs_u"][1] < 1e-9 * hand


def test_slew_about_a_general_axis_scores_the_rigid_body_torque():
    """120° about (1, 1, 1)/√3 (the nano paper's slew, non-principal for I = diag(0.0109, 0.05,
    0.05)): the body torque carries θ̇² e × I e, which the wheels' gyroscopic torque supplies at
    zero total momentum. The closed loop's ``int_u`` and ``int_u2`` follow the reference's (and
    the quintic's own, integrated here) to 1e-4 (measured 5e-6 at this 0.1 s hold, 1.7e-5 at
    0.2 s, 1.6e-6 at 0.05 s: second order in the hold), where the wheels' torque integral is 13 %
    lower: it is ∫‖I ω̇‖ dt = ‖I e‖ 15 θ_f / (4 T), the motion's, to the same 1e-4. Per axis,
    ``int_abs_u`` on y and z, where the gyroscopic torque sits, is first order in the hold: the
    law compensates ω × A h_w at the start of each hold, half a hold behind the held feed-forward
    (measured ±1.2e-3 at 0.1 s, ±2.3e-3 at 0.2 s, ±5.8e-4 at 0.05 s), asserted to 2e-3. The
    tracking error that separates closed loop and reference stays below 1e-4° (6.8e-5°)."""
    axis = np.ones(3) / math.sqrt(3.0)
    row = tracked_slew(axis, 2 * math.pi / 3)
    body, actuators = quintic_integrals(axis, 2 * math.pi / 3)
    closed, reference = row.closed_loop_metrics, row.reference_metrics
    assert closed["max_error_deg"] < 1e-4
    assert reference["int_u"] == pytest.approx(body, rel=1e-5)  # 2001 trapezoids: 6e-7
    assert closed["int_u"] == pytest.approx(body, rel=1e-4)
    assert closed["int_u"] == pytest.approx(reference["int_u"], rel=1e-4)
    assert closed["int_abs_u"] == pytest.approx(reference["int_abs_u"], rel=2e-3)
    assert closed["int_u2"] == pytest.approx(reference["int_u2"], rel=1e-4)
    assert closed["int_actuator_torque"] == pytest.approx(actuators, rel=1e-4)
    assert actuators < 0.9 * body  # the two are told apart, not within the tolerances above


class Idle:
    """Commands nothing: the wheels keep their momentum."""

    def reset(self, spacecraft, sample_time, target=None):
        pass

    def __call__(self, t, measurement, reference):
        return Command(wheel_torque=np.zeros(3))


@pytest.mark.parametrize("omega0, gyroscopic", [
    ([0.03, 0.02, 0.01], [0.0002, -0.0006, 0.0006]),  # ω × I ω, I = diag(2, 3, 4), worked by hand
    ([0.0, 0.0, 0.03], [0.0, 0.0, 0.0]),              # a principal axis: ω ∥ I ω
])
def test_zero_momentum_spin_by_hand(omega0, gyroscopic):
    """The wheels hold h_w = −I ω0 (total momentum zero) and apply nothing: the body turns at
    ω0 for 20 s. A rigid body turning so needs u = ω × I ω (the gyroscopic torque, which the
    wheels' ω × A h_w supplies), so int_u = T ‖ω × I ω‖, int_abs_u = T |(ω × I ω)_i|, int_u2 =
    T ‖ω × I ω‖²; the actuators did nothing, int_actuator_torque = 0."""
    inertia = np.diag([2.0, 3.0, 4.0])
    wheels = ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=1.0)
    model = AttitudeModel(Spacecraft(inertia, wheels=wheels))
    omega0, gyroscopic = np.array(omega0), np.array(gyroscopic)
    x0 = np.r_[1.0, 0.0, 0.0, 0.0, omega0, -inertia @ omega0]
    result = Simulator(model, 0.5).run(Idle(), x0, 20.0)
    metrics = metrics_from_simulation(result, None)
    assert np.allclose(result.omega, omega0, rtol=0, atol=1e-15)
    assert metrics["int_actuator_torque"] == 0.0 and metrics["peak_actuator_torque"] == 0.0
    assert metrics["int_u"] == pytest.approx(20.0 * np.linalg.norm(gyroscopic), rel=1e-12, abs=1e-18)
    assert metrics["int_abs_u"] == pytest.approx(20.0 * np.abs(gyroscopic), rel=1e-12, abs=1e-18)
    assert metrics["int_u2"] == pytest.approx(20.0 * gyroscopic @ gyroscopic, rel=1e-12, abs=1e-18)
    assert metrics["peak_body_torque"] == pytest.approx(np.max(np.abs(gyroscopic)), rel=1e-12, abs=1e-18)


class Turning:
    """A torquer command that turns with time, on every axis."""

    def reset(self, spacecraft, sample_time, target=None):
        pass

    def __call__(self, t, measurement, reference):
        return Command(torque=0.01 * np.array([math.sin(0.3 * t), math.cos(0.2 * t), -0.5]))


def test_torquers_alone_score_the_applied_torque_bit_for_bit():
    """Without wheels the body torque is the applied torque itself: every integral equals, bit for
    bit, the one of the applied torque (the closed loop's effort as it was scored before the
    wheels' gyroscopic torque was taken out), and ``int_actuator_torque`` is ``int_u``."""
    model = AttitudeModel(Spacecraft(np.diag([2.0, 3.0, 4.0]), torquers=Torquers(max_torque=0.05)))
    result = Simulator(model, 0.5).run(Turning(), np.r_[1.0, 0.0, 0.0, 0.0, 0.01, -0.02, 0.03], 30.0)
    metrics = metrics_from_simulation(result, None)
    applied = compute_metrics(result.t, result.q, result.omega, result.applied_torque, None)
    for key in EFFORT_KEYS + ("peak_body_torque",):
        assert metrics[key] == applied[key], key
    assert metrics["int_actuator_torque"] == metrics["int_u"] > 0.0


def test_with_a_bias_momentum_the_closed_loop_still_scores_the_rigid_body_torque():
    """The same 120° slew with the x wheel carrying a bias momentum of 0.02 N m s (total momentum not
    zero, and off the slew axis: a bias along the eigenaxis has no gyroscopic torque ω × A h_w, and
    with none a sign slip in it is invisible): the actuators' torque is now the rigid body's
    u = I ω̇ + ω × I ω (which the reference's quintic fixes whatever the wheels hold; hand value
    :func:`quintic_integrals`) plus ω × A h_w, whose integral is 5.6 times u's here. The closed loop's
    ``int_u`` must stay on u (measured 7.5e-4 relative at the 0.1 s hold, asserted 2e-3; ``+ ω × A h_w``
    for ``− ω × A h_w`` reads 10 times it), while ``int_actuator_torque`` carries the bias's share."""
    axis = np.ones(3) / math.sqrt(3.0)
    angle = 2 * math.pi / 3
    q_f = np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis]
    data = {"name": "effort-bias", "spacecraft": {"inertia": np.diag(NANO_INERTIA).tolist(), "wheels": {}},
            "maneuver": {"duration": SLEW_T, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0],
                                                         "wheel_momentum": [0.02, 0.0, 0.0]},
                         "final": {"q": q_f.tolist(), "omega": [0, 0, 0]}},
            "planners": [{"name": "eigenaxis", "options": {"profile": "smooth"}}],
            "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 1.0, "kd": 1.6}},
            "simulation": {"sample_time": 0.1}}
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    assert row.status == "ok", row.message
    hand, _ = quintic_integrals(axis, angle)
    closed = row.closed_loop_metrics
    assert row.reference_metrics["int_u"] == pytest.approx(hand, rel=1e-5)
    assert closed["int_u"] == pytest.approx(hand, rel=2e-3)
    assert closed["int_actuator_torque"] > 4 * hand  # the bias's gyroscopic torque, in the actuators' share
