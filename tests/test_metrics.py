"""Every metric key on hand-built motions, with the expected value worked out here from its
definition (the metrics page of the documentation): zero-order-hold integrals are sums of held
value x interval, norms are Euclidean, RMS is the root of the mean square, settling is the first
sample time after which the error stays inside the band."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ocp import (
    METRIC_KEYS,
    AttitudeModel,
    ReactionWheels,
    SimulationResult,
    Spacecraft,
    metrics_from_simulation,
    quat,
)
from ocp.metrics import compute_metrics, metrics_from_reference
from planners import Reference, ReferenceSample

Z = np.array([0.0, 0.0, 1.0])
T_GRID = np.array([0.0, 1.0, 2.5, 3.0, 5.0])           # non-uniform sample times, s
HELD = np.array([[0.03, -0.04, 0.0],                     # N m held over each interval
                 [0.0, 0.01, -0.02],
                 [-0.05, 0.0, 0.012],
                 [0.002, 0.003, 0.006]])
ERROR_TO_TARGET_DEG = np.array([10.0, 0.4, 0.6, 0.3, 0.2])
TRACKING_DEG = np.array([1.0, 2.0, 3.0, 0.0, 2.0])
TARGET_ANGLE = 1.0  # rad about z
OMEGA = np.array([[0.02, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.003, -0.004, 0.012]])
WHEELS = np.array([[0.0, 0.1, 0.0], [0.2, -0.35, 0.1], [0.0, 0.0, 0.0], [0.1, 0.1, 0.1], [0.0, 0.3, 0.0]])
SATURATED = np.array([True, False, False, True])


def hand_built_result() -> SimulationResult:
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.1))
    q = np.stack([quat.from_axis_angle(Z, TARGET_ANGLE - np.deg2rad(e)) for e in ERROR_TO_TARGET_DEG])
    x = np.hstack([q, OMEGA, WHEELS])
    u = np.zeros((4, 3))
    return SimulationResult(AttitudeModel(spacecraft), 1.0, T_GRID, x, u, u, HELD, SATURATED)


class TrackedReference(Reference):
    """A reference whose attitude is the simulated one turned by TRACKING_DEG about x at the samples."""

    def __init__(self, q_samples: np.ndarray) -> None:
        super().__init__("hand", T_GRID[-1], np.eye(3))
        self.q_samples = q_samples

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        k = np.searchsorted(T_GRID, t)
        q = np.stack([quat.product(self.q_samples[i], quat.from_axis_angle(np.array([1.0, 0, 0]), np.deg2rad(TRACKING_DEG[i])))
                      for i in k])
        zeros = np.zeros((t.size, 3))
        return ReferenceSample(q, zeros, zeros, zeros)


@pytest.fixture(scope="module")
def metrics():
    result = hand_built_result()
    reference = TrackedReference(result.q)
    return metrics_from_simulation(result, quat.from_axis_angle(Z, TARGET_ANGLE), np.array([0.0, 0.0, 0.01]),
                                   reference=reference, plan_time_s=0.25, duration_s=4.5,
                                   fine_settling_tolerance_deg=0.25, detumble_tolerance=0.0125)


def test_every_key_is_tested_here():
    tested = {"int_u2", "int_u", "int_abs_u", "int_actuator_torque", "peak_body_torque", "peak_actuator_torque",
              "peak_wheel_torque",
              "final_error_deg", "final_rate_error", "rms_error_deg",
              "max_error_deg", "settling_time_s", "saturation_fraction", "peak_wheel_momentum", "plan_time_s",
              "duration_s", "initial_rate_error", "detumble_time_s", "int_dipole", "final_rate", "energy_ratio",
              "fine_settling_time_s", "final_knowledge_error_deg", "max_knowledge_error_deg",
              "star_tracker_blinded_s", "star_tracker_blinded_updates"}
    assert set(METRIC_KEYS) == tested


def test_knowledge_error_by_hand():
    """The attitude given at t_0..t_(N-1) off the truth by 0.1, 0.3, 0.2 deg about three axes:
    final 0.2 deg (at the last sample given), max 0.3 deg; null when none is given."""
    t = np.array([0.0, 1.0, 2.0, 3.0])
    q = np.array([quat.from_axis_angle(Z, a) for a in (0.0, 0.1, 0.2, 0.3)])
    offsets = [(np.array([1.0, 0, 0]), 0.1), (np.array([0, 1.0, 0]), 0.3), (np.array([0, 0.6, 0.8]), 0.2)]
    known = np.array([quat.product(q[k], quat.from_axis_angle(axis, np.deg2rad(angle)))
                      for k, (axis, angle) in enumerate(offsets)])
    metrics = compute_metrics(t, q, np.zeros((4, 3)), np.zeros((3, 3)), None, known_q=known)
    assert metrics["final_knowledge_error_deg"] == pytest.approx(0.2, rel=1e-9)
    assert metrics["max_knowledge_error_deg"] == pytest.approx(0.3, rel=1e-9)
    none = compute_metrics(t, q, np.zeros((4, 3)), np.zeros((3, 3)), None)
    assert none["final_knowledge_error_deg"] is None and none["max_knowledge_error_deg"] is None


def test_star_tracker_blinding_by_hand():
    """Samples 1 s, 1.5 s, 0.5 s, 2 s long; the boresight inside an exclusion at t_1 and t_2
    (1.5 + 0.5 = 2 s), an update due at t_0 and t_2 only: one update dropped; null without."""
    t = np.array([0.0, 1.0, 2.5, 3.0, 5.0])
    q = np.tile(quat.IDENTITY, (5, 1))
    blinded, due = [False, True, True, False], [True, False, True, True]
    metrics = compute_metrics(t, q, np.zeros((5, 3)), np.zeros((4, 3)), None, blinded=blinded, due=due)
    assert metrics["star_tracker_blinded_s"] == 2.0 and metrics["star_tracker_blinded_updates"] == 1
    every = compute_metrics(t, q, np.zeros((5, 3)), np.zeros((4, 3)), None, blinded=blinded)
    assert every["star_tracker_blinded_updates"] == 2
    none = compute_metrics(t, q, np.zeros((5, 3)), np.zeros((4, 3)), None)
    assert none["star_tracker_blinded_s"] is None and none["star_tracker_blinded_updates"] is None


def test_star_tracker_blinded_time_adds_each_blinded_samples_own_length():
    """Samples 1 s, 1.5 s, 0.5 s, 2 s long, blinded at t_0, t_2 and t_3: 1 + 0.5 + 2 = 3.5 s (not
    three samples of the first's length, 3 s)."""
    t = np.array([0.0, 1.0, 2.5, 3.0, 5.0])
    metrics = compute_metrics(t, np.tile(quat.IDENTITY, (5, 1)), np.zeros((5, 3)), np.zeros((4, 3)), None,
                              blinded=[True, False, True, True])
    assert metrics["star_tracker_blinded_s"] == 3.5 and metrics["star_tracker_blinded_updates"] == 3


def test_zero_order_hold_integrals(metrics):
    """The integrals of the body torque: HELD less ω × A h_w at the start of each sample; only the
    first sample turns, ω = [0.02, 0, 0] with h_w = [0, 0.1, 0] on body-axis wheels: ω × A h_w =
    [0, 0, 0.002]. ``int_actuator_torque`` integrates HELD itself."""
    dt = [1.0, 1.5, 0.5, 2.0]
    body = [(0.03, -0.04, -0.002)] + [tuple(row) for row in HELD[1:]]
    int_u2 = sum(d * (a * a + b * b + c * c) for d, (a, b, c) in zip(dt, body))
    int_u = sum(d * math.sqrt(a * a + b * b + c * c) for d, (a, b, c) in zip(dt, body))
    int_abs = [sum(d * abs(row[i]) for d, row in zip(dt, body)) for i in range(3)]
    assert metrics["int_u2"] == pytest.approx(int_u2, rel=1e-12)
    assert metrics["int_u"] == pytest.approx(int_u, rel=1e-12)
    assert metrics["int_abs_u"] == pytest.approx(int_abs, rel=1e-12)
    applied = sum(d * math.sqrt(a * a + b * b + c * c) for d, (a, b, c) in zip(dt, HELD))
    assert metrics["int_actuator_torque"] == pytest.approx(applied, rel=1e-12)
    assert metrics["peak_actuator_torque"] == pytest.approx(0.05, rel=1e-12)  # |−0.05|, a negative component


def test_errors_to_the_target(metrics):
    assert metrics["final_error_deg"] == pytest.approx(0.2, rel=1e-9)
    assert metrics["final_rate_error"] == pytest.approx(math.sqrt(0.003**2 + 0.004**2 + 0.002**2), rel=1e-12)
    # Outside the 0.5 deg band at samples 0 and 2 (0.6 deg); inside from t[3] = 3 s on.
    assert metrics["settling_time_s"] == 3.0


def test_settling_edge_cases():
    t = np.arange(4.0)
    target = quat.IDENTITY
    q = np.stack([quat.from_axis_angle(Z, np.deg2rad(e)) for e in (0.1, 0.2, 0.3, 0.9)])
    w, u = np.zeros((4, 3)), np.zeros((3, 3))
    assert compute_metrics(t, q, w, u, target)["settling_time_s"] is None      # leaves the band at the end
    assert compute_metrics(t[:3], q[:3], w[:3], u[:2], target)["settling_time_s"] == 0.0  # always inside
    assert compute_metrics(t, q, w, u, None)["settling_time_s"] is None        # free final attitude


def test_tracking_errors(metrics):
    assert metrics["rms_error_deg"] == pytest.approx(math.sqrt(sum(e * e for e in TRACKING_DEG) / 5), rel=1e-9)
    assert metrics["max_error_deg"] == pytest.approx(3.0, rel=1e-9)


def test_max_tracking_error_counts_the_last_sample():
    """Tracking errors 0.5, 1.0, 2.5 deg about y, the largest at the last sample: max 2.5 deg,
    RMS √((0.25 + 1 + 6.25) / 3) deg."""
    t = np.array([0.0, 1.0, 2.0])
    q = np.stack([quat.from_axis_angle(Z, a) for a in (0.0, 0.1, 0.2)])
    reference = np.stack([quat.product(q[k], quat.from_axis_angle(np.array([0, 1.0, 0]), np.deg2rad(e)))
                          for k, e in enumerate((0.5, 1.0, 2.5))])
    metrics = compute_metrics(t, q, np.zeros((3, 3)), np.zeros((2, 3)), None, reference_q=reference)
    assert metrics["max_error_deg"] == pytest.approx(2.5, rel=1e-9)
    assert metrics["rms_error_deg"] == pytest.approx(math.sqrt(7.5 / 3), rel=1e-9)


def test_body_and_wheel_torques_by_hand():
    """Two wheels on x and y holding momentum: the body torque, of the peak and the integrals, is
    the applied actuator torque less ω × A h_w at the start of each sample, the wheel torque the
    applied motor torque."""
    axes = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels(axes=axes, max_torque=0.1))
    t = np.array([0.0, 1.0, 3.0])
    q = np.tile(quat.IDENTITY, (3, 1))
    omega = np.array([[0.0, 0.0, 0.5], [0.1, 0.0, 0.0], [0.0, 0.0, 0.0]])
    h = np.array([[0.2, -0.1], [0.0, 0.3], [0.0, 0.0]])
    g = np.array([[0.01, -0.02], [0.004, 0.003]])
    actuator = np.array([[-0.01, 0.02, 0.0], [-0.004, -0.003, 0.0]])  # −A g
    result = SimulationResult(AttitudeModel(spacecraft), 1.0, t, np.hstack([q, omega, h]), g, g, actuator,
                              np.zeros(2, dtype=bool))
    metrics = metrics_from_simulation(result, None)
    # sample 0: ω × A h = [0, 0, 0.5] × [0.2, −0.1, 0] = [0.05, 0.1, 0]; u = [−0.06, −0.08, 0]
    # sample 1: [0.1, 0, 0] × [0, 0.3, 0] = [0, 0, 0.03]; u = [−0.004, −0.003, −0.03]
    assert metrics["peak_body_torque"] == pytest.approx(0.08, rel=1e-12)
    assert metrics["int_u"] == pytest.approx(1.0 * 0.1 + 2.0 * math.sqrt(0.004**2 + 0.003**2 + 0.03**2), rel=1e-12)
    assert metrics["int_abs_u"] == pytest.approx([0.06 + 2 * 0.004, 0.08 + 2 * 0.003, 2 * 0.03], rel=1e-12)
    assert metrics["int_u2"] == pytest.approx(0.01 + 2.0 * (0.004**2 + 0.003**2 + 0.03**2), rel=1e-12)
    assert metrics["int_actuator_torque"] == pytest.approx(math.sqrt(0.01**2 + 0.02**2) + 2.0 * 0.005, rel=1e-12)
    assert metrics["peak_actuator_torque"] == pytest.approx(0.02, rel=1e-12)
    assert metrics["peak_wheel_torque"] == pytest.approx(0.02, rel=1e-12)


def test_actuator_metrics_and_passed_values(metrics):
    assert metrics["saturation_fraction"] == 0.5
    assert metrics["peak_wheel_momentum"] == pytest.approx(0.35)  # |−0.35|
    assert metrics["plan_time_s"] == 0.25 and metrics["duration_s"] == 4.5
    assert metrics["initial_rate_error"] is None  # closed loop: the reference metric


class RampRate(Reference):
    """ω(t) = [0.1 + 0.5 t, 0, 0] on [0, 2] s (the torque does not matter here)."""

    def __init__(self) -> None:
        super().__init__("hand", 2.0, np.eye(3))

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        omega = np.stack([0.1 + 0.5 * t, np.zeros_like(t), np.zeros_like(t)], axis=-1)
        zeros = np.zeros((t.size, 3))
        return ReferenceSample(np.tile(quat.IDENTITY, (t.size, 1)), omega, zeros, zeros)


def test_initial_rate_error_is_taken_at_t0():
    """ω(0) = [0.1, 0, 0] against ω0 = [0.1, 0.03, −0.04]: ‖[0, −0.03, 0.04]‖ = 0.05, whatever the
    rate does after t = 0 (on 11 samples, ω(0.2 s) = [0.2, 0, 0] would give 0.112)."""
    metrics = metrics_from_reference(RampRate(), None, None, points=11, initial_omega=np.array([0.1, 0.03, -0.04]))
    assert metrics["initial_rate_error"] == pytest.approx(0.05, rel=1e-12)


class RampTorque(Reference):
    """u(t) = [a t, b, 0] on [0, T]; the attitude does not matter for the torque integrals."""

    A, B, T = 0.02, -0.05, 10.0

    def __init__(self) -> None:
        super().__init__("hand", self.T, np.eye(3))

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        q = np.tile(quat.IDENTITY, (t.size, 1))
        omega = np.tile([0.1, 0.0, 0.0], (t.size, 1))
        torque = np.stack([self.A * t, np.full_like(t, self.B), np.zeros_like(t)], axis=-1)
        return ReferenceSample(q, omega, np.zeros((t.size, 3)), torque)


def test_reference_integrals_against_closed_forms():
    a, b, T = RampTorque.A, RampTorque.B, RampTorque.T
    metrics = metrics_from_reference(RampTorque(), None, np.zeros(3), initial_omega=np.array([0.1, 0.03, -0.04]))
    assert metrics["int_u2"] == pytest.approx(a**2 * T**3 / 3 + b**2 * T, rel=1e-6)
    # ∫ sqrt(a² t² + b²) dt = [t s / 2 + b² asinh(a t / |b|) / (2 a)], s = sqrt(a² t² + b²)
    s = math.sqrt(a * a * T * T + b * b)
    assert metrics["int_u"] == pytest.approx(T * s / 2 + b * b * math.asinh(a * T / abs(b)) / (2 * a), rel=1e-6)
    assert metrics["int_abs_u"] == pytest.approx([a * T**2 / 2, abs(b) * T, 0.0], rel=1e-9)
    assert metrics["peak_body_torque"] == pytest.approx(max(a * T, abs(b)))
    assert metrics["peak_actuator_torque"] is None and metrics["peak_wheel_torque"] is None  # closed loop only
    assert metrics["int_actuator_torque"] is None
    assert metrics["final_rate_error"] == pytest.approx(0.1)
    assert metrics["initial_rate_error"] == pytest.approx(0.05)  # ‖[0, −0.03, 0.04]‖
    assert metrics["duration_s"] == T and metrics["final_error_deg"] is None


def test_regulation_metrics(metrics):
    # max_i |ω_i| per sample: 0.02, 0, 0, 0, 0.012: below 0.0125 rad/s from t[1] = 1 s on.
    assert metrics["detumble_time_s"] == 1.0
    assert metrics["final_rate"] == pytest.approx(math.sqrt(0.003**2 + 0.004**2 + 0.012**2), rel=1e-12)
    start = 0.5 * 2.0 * 0.02**2                                            # ½ ωᵀ I ω, I = diag(2, 3, 4)
    end = 0.5 * (2.0 * 0.003**2 + 3.0 * 0.004**2 + 4.0 * 0.012**2)
    assert metrics["energy_ratio"] == pytest.approx(end / start, rel=1e-12)
    # Fine band 0.25 deg: the 0.3 deg at t[3] is outside, the 0.2 deg at t[4] = 5 s inside.
    assert metrics["fine_settling_time_s"] == 5.0
    assert metrics["int_dipole"] is None  # no magnetorquers


def test_dipole_integral_is_a_hold_integral_of_the_euclidean_norm():
    dipole = np.array([[0.1, -0.2, 0.0], [0.0, 0.0, 0.3], [-0.05, 0.05, 0.05], [0.0, 0.0, 0.0]])
    dt = [1.0, 1.5, 0.5, 2.0]
    expected = sum(d * math.sqrt(a * a + b * b + c * c) for d, (a, b, c) in zip(dt, dipole))
    metrics = compute_metrics(T_GRID, np.tile(quat.IDENTITY, (5, 1)), OMEGA, HELD, None, dipole=dipole)
    assert metrics["int_dipole"] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("residue, expected", [
    (1e-17, None), (0.0, None),
    (1e-8, None),            # E_0 / max E = (1e-8 / 0.05)² = 4e-14, below 1e-12: rest
    (5e-7, (0.02 / 5e-7) ** 2),  # 1e-10, above it: a (slow) spin, its ratio kept
    (1e-3, (0.02 / 1e-3) ** 2)])
def test_energy_ratio_is_null_for_a_start_at_rest_up_to_rounding(residue, expected):
    """A rest-to-rest reference starts at 1e-17 rad/s (rounding): E_T/E_0 would divide two rounding
    errors (the README's eigenaxis row showed 4.956). A real 1e-3 rad/s start keeps its ratio."""
    t = np.linspace(0.0, 4.0, 5)
    omega = np.array([[residue, 0, 0], [0.02, 0, 0], [0.05, 0, 0], [0.02, 0, 0], [0.02, 0, 0]])
    q = np.tile([1.0, 0, 0, 0], (5, 1))
    metrics = compute_metrics(t, q, omega, np.zeros((4, 3)), None, inertia=np.diag([2.0, 3.0, 4.0]))
    if expected is None:
        assert metrics["energy_ratio"] is None
    else:
        assert metrics["energy_ratio"] == pytest.approx(expected, rel=1e-12)  # ω_T²/ω_0² (same axis)


def test_energy_ratio_is_null_for_a_rest_to_rest_motion():
    """Rounding residue 1e-17 rad/s at both ends of a slew that peaks at 0.05 rad/s: the start is at
    rest against the motion's largest energy, so the ratio is null (E_T / E_0 would divide two
    rounding errors, here 1.0), whatever the energy at the end."""
    t = np.linspace(0.0, 4.0, 5)
    omega = np.array([[1e-17, 0, 0], [0.02, 0, 0], [0.05, 0, 0], [0.02, 0, 0], [1e-17, 0, 0]])
    metrics = compute_metrics(t, np.tile(quat.IDENTITY, (5, 1)), omega, np.zeros((4, 3)), None,
                              inertia=np.diag([2.0, 3.0, 4.0]))
    assert metrics["energy_ratio"] is None
