"""Co-state feedback (Vepa eq. 40-42): the constrained gain fit against known answers, and the
closed loop on the paper's spin-up against its reference."""
from pathlib import Path

import numpy as np
import pytest

from controllers.tracking.costate_feedback import fit_costate_gain, project_psd
from scenarios.errors import ScenarioError
from scenarios.runner import run
from scenarios.schema.loader import load, parse_scenario
from scenarios.schema.read import read_yaml

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def objective(P, X, L, rho):
    return 0.5 * np.sum((X @ P - L) ** 2) + 0.5 * rho * np.sum(P**2)


def test_gain_fit_recovers_a_non_negative_definite_matrix(rng):
    root = rng.normal(size=(7, 7))
    truth = root @ root.T
    states = rng.normal(size=(30, 7))
    fitted = fit_costate_gain(states, states @ truth, ridge=0.0)
    np.testing.assert_allclose(fitted, truth, rtol=1e-9, atol=1e-9)


def test_gain_fit_is_the_constrained_optimum_when_the_data_are_indefinite(rng):
    truth = np.diag([3.0, 2.0, 1.0, 0.5, -1.0, -2.0, 0.2])
    states = rng.normal(size=(30, 7))
    costates = states @ truth
    fitted = fit_costate_gain(states, costates, ridge=1e-4, iterations=5000, tolerance=1e-13)
    assert np.allclose(fitted, fitted.T) and np.linalg.eigvalsh(fitted)[0] >= -1e-12
    rho = 1e-4 * np.linalg.eigvalsh(states.T @ states)[-1]
    best = objective(fitted, states, costates, rho)
    # Every feasible neighbour is worse: the projection of small random steps (convex problem, so
    # local optimality among feasible points is global).
    for _ in range(200):
        step = rng.normal(size=(7, 7)) * 1e-3
        neighbour = project_psd(fitted + step + step.T)
        assert objective(neighbour, states, costates, rho) >= best - 1e-9
    assert best <= objective(project_psd(truth), states, costates, rho)


def test_costate_feedback_tracks_the_spin_up_within_five_percent():
    # Vepa section 9: the tracked rates stay within 5 % of the reference. Noise free, 0.02 s hold.
    scenario = load(SCENARIOS / "vepa_spin_up.yaml")
    scenario.simulation.sample_time = 0.02
    row = run(scenario).rows[0]
    assert row.status == "ok", row.message
    sim, reference = row.simulation, row.reference
    inside = sim.t <= reference.duration
    deviation = np.linalg.norm(sim.omega[inside] - reference.omega(sim.t[inside]), axis=1)
    target = scenario.problem.omegaf
    assert np.max(deviation) <= 0.05 * np.linalg.norm(target)
    np.testing.assert_allclose(sim.omega[inside][-1], target, rtol=0.05)


def test_costate_feedback_needs_a_torque_costate_reference():
    data = read_yaml(SCENARIOS / "vepa_spin_up.yaml")
    data["planners"] = [{"name": "eigenaxis"}]
    data["maneuver"]["final"]["q"] = [1, 0, 0, 0]
    with pytest.raises(ScenarioError, match="controller.name.*costate_tpbvp"):
        parse_scenario(data)


def test_a_free_final_attitude_is_rejected_for_planners_that_need_one():
    data = read_yaml(SCENARIOS / "vepa_spin_up.yaml")
    data["planners"].append({"name": "eigenaxis"})
    with pytest.raises(ScenarioError, match=r"planners\[1\].*needs a target attitude"):
        parse_scenario(data)


def test_costate_feedback_removes_an_initial_rate_error():
    # With P = 0 (the reference co-state fed forward alone) an initial error of 0.035 rad/s grows to
    # 0.046 rad/s by t_f; the fitted P must shrink it instead.
    scenario = load(SCENARIOS / "vepa_spin_up.yaml")
    scenario.simulation.sample_time = 0.02
    scenario.simulation.initial_rate_error = np.array([0.02, -0.02, 0.02])
    row = run(scenario).rows[0]
    sim, reference = row.simulation, row.reference
    deviation = np.linalg.norm(sim.omega - reference.omega(sim.t), axis=1)
    assert deviation[-1] < 0.5 * deviation[0]
