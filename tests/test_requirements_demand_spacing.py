"""The actuator demand does not depend on how coarsely a reference is sampled (after T the scorer
samples at the closed loop's spacing), against oracles that do not use the demand's own method:

* a torque-free spin (constant rate about a principal axis): the wheels' momentum keeps its
  inertial direction, so in body axes it turns at ``−ω`` (hand-worked, closed form); three wheels
  (the conservation form) and two wheels with torquers (the integrated form), at spacings where the
  body turns 0.1 to 10 rad between samples (Heun's step on whole intervals diverged from 1 rad on);
* a bang rate acquisition (constant torque ``−c`` about the spin axis until the body stops at T,
  then rest): the wheels take ``c t`` and hold ``c T`` after T, the wheel torque is ``c`` up to T and
  0 after it (hand-worked); a coarse step after T used to carry the torque before T into it;
* the repository's spin scenario with 0.5 s and 5 s closed-loop samples: the same demand at the
  common times after T, equal to SciPy's integration of the wheels' equation
  ``ḣ = −(u + ω × h)`` along the reference (DOP853, tight tolerances, no conservation used);
* a demand that is not finite breaks the requirement with a message (it used to pass as null).
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from controllers import CONTROLLERS
from controllers.allocation import Demand, reference_demand
from ocp import AttitudeModel, ReactionWheels, Spacecraft, Torquers, quat
from planners import ManeuverProblem, Reference, ReferenceSample
from scenarios.requirements.scoring import _actuators, reference_times, score_reference
from scenarios.requirements.spec import ActuatorRequirement, Requirements

INERTIA = np.diag([19.5, 19.0, 12.6])
SPIN = 2.0  # rad/s about body x


def spin(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A constant spin about body x (a principal axis): q, ω and its (zero) torque."""
    q = quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), SPIN * t)
    omega = np.tile([SPIN, 0.0, 0.0], (t.size, 1))
    return q, omega, np.zeros((t.size, 3))


def spin_momentum(t: np.ndarray, across: float) -> np.ndarray:
    """Body-axis wheel momentum with ``across`` N m s along body y at 0: fixed in inertial space,
    it turns at −ω in the body, ``(0, a cos ωt, −a sin ωt)``."""
    return np.stack([0.0 * t, across * np.cos(SPIN * t), -across * np.sin(SPIN * t)], axis=1)


THREE = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=4.0))
TWO = Spacecraft(INERTIA, wheels=ReactionWheels(axes=np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]),
                                                max_torque=0.1, max_momentum=4.0),
                 torquers=Torquers(max_torque=1.0))


@pytest.mark.parametrize("spacing", [0.05, 0.5, 5.0])
@pytest.mark.parametrize("spacecraft", [THREE, TWO], ids=["three wheels", "two wheels"])
def test_a_torque_free_spin_keeps_the_wheels_momentum_inertial_at_any_spacing(spacing, spacecraft):
    t = np.arange(0.0, 40.0 + spacing / 2, spacing)
    q, omega, torque = spin(t)
    across = 0.3
    h0 = np.array([0.0, across, 0.0]) if spacecraft is THREE else np.array([across, 0.0])
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(spacecraft), t, q, omega,
                              torque, h0)
    expected = spin_momentum(t, across)  # body axes
    axes = spacecraft.wheel_axes
    stored = demand["wheels_momentum"].values @ axes.T
    # three wheels: exact (the conservation form); two: RK4 sub-steps of at most 0.05 rad,
    # θ⁴/120 = 5e-8 per radian over 80 rad
    tolerance = 1e-12 if spacecraft is THREE else 1e-5
    np.testing.assert_allclose(stored, expected, rtol=0.0, atol=tolerance * across)
    # the wheel torque that turns it, −(u + ω × A h): hand-worked for a spin about x
    g_body = demand["wheels_torque"].values @ axes.T
    by_hand = -SPIN * np.stack([0.0 * t, -expected[:, 2], expected[:, 1]], axis=1)
    np.testing.assert_allclose(g_body, by_hand, rtol=0.0, atol=tolerance * SPIN * across)
    if spacecraft is TWO:
        np.testing.assert_allclose(demand["torquers_torque"].values, 0.0, atol=1e-12)


class Bang(Reference):
    """Rate acquisition from a spin about x with the constant torque −c: ω_x = ω₀ − c t / I_x until T."""

    def __init__(self, omega0: float, c: float) -> None:
        super().__init__("bang", INERTIA[0, 0] * omega0 / c, INERTIA)
        self.omega0, self.c = omega0, c

    def _evaluate(self, t: np.ndarray) -> ReferenceSample:
        rate = self.omega0 - self.c * t / INERTIA[0, 0]
        angle = self.omega0 * t - 0.5 * self.c * t**2 / INERTIA[0, 0]
        zeros = np.zeros_like(t)
        return ReferenceSample(quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), angle),
                               np.stack([rate, zeros, zeros], axis=1),
                               np.stack([zeros - self.c / INERTIA[0, 0], zeros, zeros], axis=1),
                               np.stack([zeros - self.c, zeros, zeros], axis=1))


@pytest.mark.parametrize("spacecraft", [THREE, TWO], ids=["three wheels", "two wheels"])
def test_a_bang_stop_leaves_its_torque_before_T_and_its_momentum_after(spacecraft):
    """c = 10 N m stops 0.1 rad/s about x (I_x = 19.5) in T = 0.195 s: the wheels take c t, then
    hold c T = 1.95 N m s (0.4875 of 4), asked c = 10 N m (100 of 0.1) until T and nothing after,
    at 0.5 s and 5 s samples after T alike (the user's case read 4.45 N m s: 0.5 x 0.499 s x 10 N m
    too much, the torque at T carried into the first coarse step)."""
    if spacecraft is TWO:  # a wheel on the spin axis: the two wheels are along x and y
        spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(axes=np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]]),
                                                               max_torque=0.1, max_momentum=4.0),
                                torquers=Torquers(max_torque=1.0))
    reference = Bang(0.1, 10.0)
    law = CONTROLLERS["augmented_quaternion_feedback"]()
    for sample_time in (0.5, 5.0):
        t = reference_times(reference.duration, 120.0, sample_time)
        sample = reference.sample(t)
        problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.array([0.1, 0.0, 0.0]), None, reference.duration,
                                  omegaf=np.zeros(3))
        score = score_reference(Requirements(actuators=ActuatorRequirement(0.0)), problem, t, sample, law,
                                reference)["actuators"]
        assert score.values["wheels_momentum"] == pytest.approx(10.0 * 0.195 / 4.0, rel=1e-12)
        assert score.values["wheels_torque"] == pytest.approx(10.0 / 0.1, rel=1e-12)
        assert score.values["wheels_torque_time_s"] <= reference.duration
        demand = reference_demand(law, AttitudeModel(spacecraft), t, sample.q, sample.omega, sample.torque,
                                  torque_after=np.where((t >= reference.duration)[:, None], 0.0, sample.torque))
        h = demand["wheels_momentum"].values[:, 0]
        inside = t <= reference.duration
        np.testing.assert_allclose(h[inside], 10.0 * t[inside], rtol=0.0, atol=1e-12)
        np.testing.assert_allclose(h[~inside], 1.95, rtol=1e-12)
        g = demand["wheels_torque"].values[:, 0]
        np.testing.assert_allclose(g[inside], 10.0, rtol=1e-12)  # T itself: the torque there
        np.testing.assert_allclose(g[~inside], 0.0, atol=1e-12)


SPIN_SCENARIO = "scenarios/biggs_horri_spin_repoint_wheels.yaml"


def test_the_spin_scenario_asks_the_same_at_half_a_second_and_five_seconds():
    """The repository's spin re-pointing (0.2 rad/s), the paper's spin-extremal row, run to 400 s
    (T = 200 s) with 0.1 N m / 20 N m s wheels: its demand at the times after T common to 0.5 s and
    5 s samples is the same and equals SciPy's integration of ``ḣ = −(u + ω × h)`` along the
    reference. Before: 7.80 x and 0.390 x at 0.5 s, 81.4 x and 2.07 x at 5 s."""
    from scenarios.schema.loader import load
    scenario = load(SPIN_SCENARIO)
    problem = scenario.problem
    spec = next(spec for spec in scenario.planners if spec.name == "spin_extremal")
    reference = spec.planner.plan(problem)
    assert reference.ok and reference.duration == pytest.approx(200.0)
    spacecraft = Spacecraft(problem.spacecraft.inertia,
                            wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=20.0))
    law = scenario.controllers[0].controller
    h0 = np.zeros(3)

    def rhs(time, h):
        at = reference.sample(np.array([time]))
        return -(at.torque[0] + np.cross(at.omega[0], h))

    first = solve_ivp(rhs, (0.0, 200.0), h0, method="DOP853", rtol=1e-11, atol=1e-12)
    second = solve_ivp(rhs, (200.0, 400.0), first.y[:, -1], method="DOP853", rtol=1e-11, atol=1e-12,
                       t_eval=np.arange(200.0, 400.0 + 1.0, 5.0))
    oracle = second.y.T  # at 200, 205, ..., 400 s
    found = {}
    for sample_time in (0.5, 5.0):
        t = reference_times(reference.duration, 400.0, sample_time)
        sample = reference.sample(t)
        demand = reference_demand(law, AttitudeModel(spacecraft), t, sample.q, sample.omega, sample.torque, h0,
                                  torque_after=np.where((t >= 200.0)[:, None], 0.0, sample.torque))
        common = np.isin(np.round(t, 9), np.arange(200.0, 400.0 + 1.0, 5.0))
        assert np.count_nonzero(common) == 41
        h = demand["wheels_momentum"].values[common]
        np.testing.assert_allclose(h, oracle, rtol=0.0, atol=1e-8 * np.max(np.abs(oracle)))
        found[sample_time] = (h, demand["wheels_torque"].values[common],
                              np.max(demand["wheels_torque"].ratios()), np.max(demand["wheels_momentum"].ratios()))
    np.testing.assert_allclose(found[0.5][0], found[5.0][0], rtol=0.0, atol=1e-12 * np.max(np.abs(oracle)))
    np.testing.assert_allclose(found[0.5][1], found[5.0][1], rtol=0.0, atol=1e-12)
    # the peaks: 7.80 x and 0.390 x at both (the peak torque is inside [0, T], on the same 2001 points)
    for sample_time in (0.5, 5.0):
        assert found[sample_time][2] == pytest.approx(7.802, abs=5e-4)
        assert found[sample_time][3] == pytest.approx(0.390, abs=5e-4)


def test_a_demand_that_is_not_finite_breaks_the_requirement_with_a_message():
    t = np.array([0.0, 1.0, 2.0])
    torque = Demand("wheels_torque", np.array([[0.01, 0.0, 0.0], [np.nan, 0.0, 0.0], [np.inf, 0.0, 0.0]]),
                    np.full(3, 0.1))
    momentum = Demand("wheels_momentum", np.array([[0.01, 0.0, 0.0], [0.02, 0.0, 0.0], [0.03, 0.0, 0.0]]),
                      np.full(3, 4.0))
    score = _actuators(1.0, {"wheels_torque": torque, "wheels_momentum": momentum}, t)
    assert not score.met
    assert score.detail.startswith("wheels_torque is not finite (nan or inf) from 1.0 s: the demand cannot be scored "
                                   "(a reference rate that is not finite, or past the 5,000,000 integration sub-steps")
    assert score.values["wheels_torque"] is None and score.values["wheels_torque_time_s"] == 1.0
    assert score.values["wheels_momentum"] == pytest.approx(0.03 / 4.0)
    # and the unrealised torque: a nan there is no torque given
    unrealised = np.array([[0.0, 0.0, 0.0], [0.0, np.nan, 0.0], [0.0, 0.0, 0.0]])
    score = _actuators(1.0, {"wheels_momentum": momentum}, t, [], unrealised, np.ones((3, 3)))
    assert not score.met and score.detail.startswith("the unrealised torque is not finite (nan or inf) from 1 s")
    assert score.values["unrealised_torque"] is None


def test_a_rate_that_is_not_finite_is_a_violation_not_a_pass():
    """A reference whose rate is nan from some sample (an overflowed planner) gives nan demands:
    the score is broken, where the ratios' nan used to compare false and pass."""
    t = np.linspace(0.0, 10.0, 11)
    q, omega, torque = spin(t)
    omega[6:] = np.nan
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(THREE), t, q, omega,
                              torque)
    assert np.all(demand["wheels_momentum"].values[:6] == 0.0)  # nothing asked before: only the nan breaks it
    score = _actuators(1.0, demand, t)
    assert not score.met and "not finite" in score.detail


def test_a_rotation_past_the_substep_budget_is_no_number_on_two_wheels(monkeypatch):
    """Two wheels (the integrated form) spinning past :data:`MAX_SUBSTEPS` sub-steps: the samples
    after the budget are nan, and the requirement is broken with a message, not scored on an
    under-resolved integration."""
    from controllers import allocation
    monkeypatch.setattr(allocation, "MAX_SUBSTEPS", 4000)  # 200 rad at 0.05 rad a sub-step
    t = np.linspace(0.0, 200.0, 41)  # 2 rad/s: 400 rad, 8000 sub-steps
    q, omega, torque = spin(t)
    demand = reference_demand(CONTROLLERS["augmented_quaternion_feedback"](), AttitudeModel(TWO), t, q, omega,
                              torque, np.array([0.3, 0.0]))
    h = demand["wheels_momentum"].values
    resolved = t <= 100.0 + 1e-9
    np.testing.assert_allclose(h[resolved] @ TWO.wheel_axes.T, spin_momentum(t[resolved], 0.3), atol=1e-5 * 0.3)
    assert np.all(np.isnan(h[~resolved]))
    score = _actuators(1.0, demand, t)
    assert not score.met and "wheels_momentum is not finite (nan or inf) from 105.0 s" in score.detail


def test_an_external_torque_is_taken_by_the_wheels_not_conserved_away():
    """Held at rest against a constant disturbance τ_d, the reference asks the actuators for −τ_d:
    three body-axis wheels store h(t) = τ_d t (A ḣ = τ_d). The total momentum is not conserved, so
    the closed form (which would say 0) must not be used there."""
    from ocp import Environment

    disturbance = np.array([1e-3, -2e-3, 5e-4])
    spacecraft = Spacecraft([10.0, 8.0, 6.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05, max_momentum=2.0))
    model = AttitudeModel(spacecraft, Environment(disturbance_torque=disturbance))
    law = CONTROLLERS["augmented_quaternion_feedback"]()
    law.reset(spacecraft, 1.0)
    t = np.linspace(0.0, 100.0, 11)
    q = np.tile(quat.IDENTITY, (t.size, 1))
    demand = reference_demand(law, model, t, q, np.zeros((t.size, 3)), np.tile(-disturbance, (t.size, 1)),
                              np.zeros(3))
    np.testing.assert_allclose(demand["wheels_momentum"].values, np.outer(t, disturbance), rtol=1e-9, atol=1e-12)


def test_the_actuators_cancel_the_disturbance_a_planner_did_not_model():
    """The eigenaxis reference's torque is the rigid body's I ω̇ + ω × I ω (it models no environment):
    under a body-fixed disturbance τ_d about the slew axis z the wheels must also cancel τ_d, so
    h_z(t) = τ_d t − I_z ω_z(t) (a row was ok at 0.079 x its momentum limit while the closed loop
    saturated the wheels and ended 173 deg off; the oracle said 1.5 x)."""
    from ocp import Environment

    disturbance = 0.05
    spacecraft = Spacecraft([0.25, 0.28, 0.12], wheels=ReactionWheels.from_body_axes(max_torque=0.1, max_momentum=4.0))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([0, 0, 1], np.pi / 2),
                              120.0, omegaf=np.zeros(3),
                              environment=Environment(disturbance_torque=np.array([0.0, 0.0, disturbance])))
    from planners import PLANNERS

    reference = PLANNERS["eigenaxis"]().plan(problem)
    t = reference_times(reference.duration, 120.0, 0.5)
    sample = reference.sample(t)
    score = score_reference(Requirements(actuators=ActuatorRequirement(0.0)), problem, t, sample,
                            CONTROLLERS["augmented_quaternion_feedback"](), reference)
    expected = np.max(np.abs(disturbance * t - 0.12 * sample.omega[:, 2])) / 4.0
    assert score["actuators"].values["wheels_momentum"] == pytest.approx(expected, rel=1e-6)  # 1.5 x
    assert not score["actuators"].met
