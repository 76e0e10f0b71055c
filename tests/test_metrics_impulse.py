"""A reference whose body rate jumps asks an impulse: its torque metrics must not read as a finite,
small (or zero) torque. The expected values are closed forms worked out here: a jump Δω of a rigid
body needs the angular impulse I Δω, so ∫‖u‖ dt is at least ‖I Δω‖ (exactly that for the Dirac
torque I Δω δ(t − t_j)), ∫‖u‖² dt and the peak torque have no finite value."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from ocp import metric_violations
from ocp.metrics import IMPULSE_INFINITE, compute_metrics, metrics_from_reference
from planners import Reference, ReferenceSample

INERTIA = np.diag([0.0109, 0.05, 0.05])  # kg m^2
SPIN = np.array([0.0, 0.0, 0.03])        # rad/s about the principal z axis: torque-free, ω×Iω = 0
STOP = 4.0                               # s, the rate steps to 0 there
T = 6.0
ROOT = Path(__file__).resolve().parents[1]


class StepStop(Reference):
    """A spin about a principal axis (no torque) that stops dead at STOP: one jump Δω = −SPIN."""

    def __init__(self) -> None:
        super().__init__("hand", T, INERTIA)

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        omega = np.where((t < STOP)[:, None], SPIN, 0.0)
        angle = SPIN[2] * np.minimum(t, STOP)
        q = np.stack([np.cos(angle / 2), 0 * angle, 0 * angle, np.sin(angle / 2)], axis=-1)
        zeros = np.zeros((t.size, 3))
        return ReferenceSample(q, omega, zeros, zeros)


def test_a_rate_jump_is_an_impulse_not_zero_torque():
    jump = -SPIN
    metrics = metrics_from_reference(StepStop(), None, None, inertia=INERTIA, rate_jumps=[jump])
    # by hand: I Δω = [0, 0, −0.05 × 0.03] = [0, 0, −1.5e-3] N m s
    assert metrics["int_u"] == pytest.approx(1.5e-3, rel=1e-12)
    assert metrics["int_abs_u"] == pytest.approx([0.0, 0.0, 1.5e-3], rel=1e-12)
    assert metrics["int_u2"] == math.inf and metrics["peak_body_torque"] == math.inf
    assert metric_violations(metrics) == []  # an impulse's infinity is physical, not a solver's NaN
    # without the jumps the same sampled torque claims a free motion: the defect this guards
    blind = metrics_from_reference(StepStop(), None, None, inertia=INERTIA)
    assert blind["int_u2"] == 0.0 and blind["int_u"] == 0.0


def test_impulses_add_to_a_sampled_torque():
    t = np.array([0.0, 1.0, 3.0])
    held = np.array([[0.1, 0.0, 0.0], [0.0, -0.2, 0.0]])  # zero-order hold: ∫‖u‖ = 0.1 + 0.4
    kicks = np.array([[0.3, 0.0, -0.4], [0.0, 0.0, 0.0]])  # ‖·‖ = 0.5; a zero impulse is none
    q = np.tile([1.0, 0.0, 0.0, 0.0], (3, 1))
    metrics = compute_metrics(t, q, np.zeros((3, 3)), held, None, impulses=kicks)
    assert metrics["int_u"] == pytest.approx(0.1 + 0.4 + 0.5, rel=1e-12)
    assert metrics["int_abs_u"] == pytest.approx([0.1 + 0.3, 0.4, 0.4], rel=1e-12)
    assert all(metrics[key] == math.inf for key in IMPULSE_INFINITE)
    still = compute_metrics(t, q, np.zeros((3, 3)), held, None, impulses=np.zeros((2, 3)))
    assert still["int_u2"] == pytest.approx(0.01 + 2 * 0.04, rel=1e-12) and still["peak_body_torque"] == 0.2


def test_infinity_without_an_impulse_is_still_a_violation():
    assert metric_violations({"int_u2": math.inf, "peak_body_torque": 1.0, "int_u": 2.0})  # peak finite
    assert metric_violations({"int_u2": math.inf, "peak_body_torque": math.inf, "int_u": math.inf})
    assert metric_violations({"int_u2": math.nan, "peak_body_torque": math.inf, "int_u": 1.0})


def test_rate_jumps_need_the_inertia():
    with pytest.raises(ValueError, match="inertia"):
        metrics_from_reference(StepStop(), None, None, rate_jumps=[-SPIN])


def test_natural_motion_stop_is_its_angular_momentum():
    """The bench's natural-motion problem, rest to rest: the reference steps from rest to its ω0 at
    0 s (a start it declares free, which the metrics count all the same), coasts torque-free and
    steps to rest at 100 s; ‖I ω‖ is conserved along a torque-free motion, so each step's impulse is
    ‖I ω0‖ (ω0 read from the reference, the norm computed here) and the motion needs twice it; the
    row is violated (its rate jumps), not failed on non-physical metrics."""
    from scenarios import load
    from scenarios.runner import run

    scenario = load(ROOT / "scenarios/bench/problems/natural_motion_min_energy.yaml")
    specs = [spec for spec in scenario.planners if spec.name == "natural_motion"]
    results = run(dataclasses.replace(scenario, planners=specs))
    (row,) = results.rows
    omega0 = row.reference.omega(np.array([0.0]))[0]
    momentum = float(np.linalg.norm(np.diag(INERTIA) * omega0))
    assert momentum == pytest.approx(8.065e-4, rel=1e-3)  # [0.0109, 0.05, 0.05] × [0.01482, 0.00323, 0.01547]
    metrics = row.reference_metrics
    assert metrics["int_u"] >= 2 * momentum * (1 - 1e-9)  # no finite claim below the two impulses
    assert metrics["int_u"] == pytest.approx(2 * momentum, rel=1e-6)  # a natural arc asks no other torque
    assert metrics["int_u2"] == math.inf and metrics["peak_body_torque"] == math.inf
    assert row.status == "violated" and "jumps" in row.message
