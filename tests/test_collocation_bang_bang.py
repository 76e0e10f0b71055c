"""The exact bang-bang minimum time of ``collocation`` (``switch_refinement: auto``): the switch-time
shooting from the coarse (N = 8) optimum, certified, is the reference; the 50-interval solve is
skipped (planners.collocation.planner.CollocationPlanner._bang_bang).

Oracles, independent of the planner: the published minimum times (Bilimoria & Wie 1993, 180° about
x with unit inertia and |u_i| <= 1: 3.2431 s; Betts 2010, sect. 6.8, XTE: 28.6304077 s); Bilimoria
& Wie's on 400 intervals with ``switch_refinement: 4`` (3.2430833738 s, within 2e-7 s of converged:
tests/test_mesh_error.py); and scipy's DOP853 (rtol 1e-13) flying the bang-bang control with the
returned switch times: the final conditions are met and the reference's states are that flight.
"""
import json

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import planners.collocation.certificate as certificate
import planners.collocation.planner as planner_module
import scenarios
from ocp import quat
from planners import PLANNERS
from planners.collocation.reference import CollocationReference
from planners.conformance import check_reference
from scenarios.cli.commands import main

PUBLISHED = {"bilimoria_wie_180": (3.2431, 5e-5), "xte_150": (28.6304077, 5e-6)}
FINE_BW = 3.2430833738


def problem_of(name):
    return scenarios.load(f"scenarios/bench/problems/{name}.yaml").problem


def plan(name, **options):
    return PLANNERS["collocation"]({"objective": "min_time", **options}).plan(problem_of(name))


def flown(problem, times, controls, t_end, samples=None):
    """DOP853 on ``q̇ = ½ q ⊗ [0, ω]``, ``I ω̇ = u − ω × I ω`` (written out here, not the model's),
    the control ``controls[k]`` before ``times[k]`` (the last arc to ``t_end``): the final state,
    and the states at ``samples`` [s] when given."""
    inertia = np.asarray(problem.spacecraft.inertia, dtype=float)
    inverse = np.linalg.inv(inertia)

    def rhs(_, x, u):
        q, w = x[:4], x[4:7]
        q_dot = 0.5 * np.array([-q[1:] @ w, *(q[0] * w + np.cross(q[1:], w))])
        return np.concatenate([q_dot, inverse @ (u - np.cross(w, inertia @ w))])

    edges = np.concatenate([[0.0], times, [t_end]])
    x, found = np.array(problem.initial_state[:7], dtype=float), {}
    samples = np.asarray([] if samples is None else samples, dtype=float)
    for start, end, u in zip(edges[:-1], edges[1:], controls):
        inside = samples[(samples >= start) & (samples < end)]
        if end > start:
            solution = solve_ivp(rhs, (start, end), x, method="DOP853", rtol=1e-13, atol=1e-14,
                                 args=(np.asarray(u, dtype=float),), t_eval=inside if inside.size else None,
                                 dense_output=False)
            if inside.size:
                found.update({float(t): solution.y[:, i] for i, t in enumerate(solution.t)})
            x = solve_ivp(rhs, (start, end), x, method="DOP853", rtol=1e-13, atol=1e-14,
                          args=(np.asarray(u, dtype=float),)).y[:, -1]
    return x, np.array([found[float(t)] for t in samples]) if samples.size else None


@pytest.fixture(scope="module")
def exact():
    return {name: plan(name) for name in ("bilimoria_wie_180", "full_inertia_150", "xte_150")}


@pytest.mark.parametrize("name", ["bilimoria_wie_180", "xte_150"])
def test_the_default_minimum_time_is_the_published_one(exact, name):
    reference = exact[name]
    value, tolerance = PUBLISHED[name]
    assert reference.ok and abs(reference.duration - value) < tolerance, reference.duration
    shooting = reference.stats["shooting"]
    assert shooting["used"] and shooting["from_intervals"] == 8 and shooting["miss"] < 1e-10
    assert reference.stats["certificate"]["verdict"] == "certified"
    assert reference.stats["certificate"]["method"] == "switch-time shooting"
    assert "the bang-bang optimum, T = " in reference.message and "RK4" in reference.message and "N=8 optimum" in reference.message
    # from YAML the actuator requirement is on (margin 0): checked between the points, met
    assert reference.stats["dense_check"]["met"] and reference.stats["dense_check"]["rounds"] == 0


def test_bilimoria_and_wie_is_the_mesh_converged_value(exact):
    # the 50-interval solve gave 3.2431108 (2.8e-5 s above); the exact optimum is within the fine
    # mesh's 2e-7 s and the shooting's RK4 steps (2.6e-8 s)
    assert exact["bilimoria_wie_180"].duration == pytest.approx(FINE_BW, abs=3e-7)


@pytest.mark.parametrize("name", ["bilimoria_wie_180", "full_inertia_150", "xte_150"])
def test_the_switch_times_fly_to_the_target_and_the_reference_is_that_flight(exact, name):
    reference = exact[name]
    problem = problem_of(name)
    shooting = reference.stats["shooting"]
    times, controls, T = shooting["switch_times_s"], shooting["controls"], reference.duration
    assert T == shooting["shooting_T_s"]
    # the stats' stated T and switches against DOP853: the final conditions (the shooting's RK4 steps
    # leave 5e-7 rad on the full inertia case)
    samples = np.linspace(0.0, T, 37)[1:-1]
    end, states = flown(problem, times, controls, T, samples)
    assert quat.error_angle(end[:4], problem.qf) < 2e-6
    assert np.max(np.abs(end[4:7] - problem.omegaf)) < 2e-6
    # the reference between its points (its interpolation of the integrated states)
    assert np.max(np.abs(reference.omega(samples) - states[:, 4:7])) < 1e-6
    assert np.max(quat.error_angle(reference.q(samples), states[:, :4])) < 1e-6
    # the control is bang-bang on the bounds, switched where the stats say
    middles = 0.5 * (np.concatenate([[0.0], times]) + np.concatenate([times, [T]]))
    assert np.allclose(reference.control(middles), np.asarray(controls), rtol=0.0, atol=1e-12)
    assert isinstance(reference, CollocationReference) and reference.intervals == 50
    nodes = reference.transcription.nodes * T
    assert np.min(np.abs(nodes[:, None] - np.asarray(times)[None, :]), axis=0).max() < 1e-12


@pytest.mark.parametrize("name", ["bilimoria_wie_180", "xte_150"])
def test_the_exact_reference_passes_the_conformance_checks(exact, name):
    check_reference(problem_of(name), exact[name])


def uncertified(monkeypatch, verdict="first-order"):
    real = certificate.bang_bang_certificate

    def judged(*args, **kwargs):
        return {**real(*args, **kwargs), "verdict": verdict}

    monkeypatch.setattr(planner_module, "bang_bang_certificate", judged)


def test_without_a_certified_optimum_the_fifty_interval_solve_runs(monkeypatch):
    uncertified(monkeypatch)
    reference = plan("bilimoria_wie_180")
    plain = plan("bilimoria_wie_180", switch_refinement=0)
    assert reference.duration == plain.duration and reference.duration - FINE_BW > 1e-5
    assert np.array_equal(reference.states, plain.states)
    assert reference.stats["shooting"]["used"] is False
    assert "first-order" in reference.stats["shooting"]["why"]
    assert reference.stats["certificate"]["method"] != "switch-time shooting"
    assert "the bang-bang optimum, T = " not in reference.message
    # the message says why the full mesh was solved
    assert "the shooting from the N=8 optimum not used (its certificate: first-order)" in reference.message


def test_without_a_converged_shooting_the_fifty_interval_solve_runs(monkeypatch):
    monkeypatch.setattr(certificate, "SHOOTING_ITERATIONS", 1)  # the shooting cannot converge
    reference = plan("bilimoria_wie_180")
    assert reference.ok and reference.intervals == 50 and reference.duration - FINE_BW > 1e-5
    assert reference.stats["shooting"]["used"] is False and "does not converge" in reference.stats["shooting"]["why"]
    assert "not used (no exact optimum: the shooting does not converge" in reference.message


def test_switch_refinement_0_is_the_plain_fifty_interval_answer():
    reference = plan("bilimoria_wie_180", switch_refinement=0)
    assert "shooting" not in reference.stats and reference.transcription.mesh is None
    assert reference.duration - FINE_BW == pytest.approx(2.76e-5, abs=0.1e-5)


def test_a_suite_run_scores_the_exact_row_and_shows_its_certificate(tmp_path):
    out = tmp_path / "out"
    assert main(["run", "scenarios/bench/problems/bilimoria_wie_180.yaml", "--out", str(out)]) == 0
    rows = {row["label"]: row for row in json.loads((out / "results.json").read_text())["rows"]}
    row = rows["collocation"]
    assert row["status"] == "ok" and "the bang-bang optimum, T = " in row["message"]
    assert row["requirements"] and row["reference"]["final_error_deg"] < 1e-3
    assert "switch-time shooting" in json.dumps(row["certificate"]) or "certified" in json.dumps(row["certificate"])


def test_the_message_counts_the_coarse_seeds_as_they_were_tried(exact):
    # the full inertia's coarse multistart tries one seed (nothing to agree with), B&W's two
    for name in ("full_inertia_150", "bilimoria_wie_180"):
        seeds = exact[name].stats["seeds"]
        message = exact[name].message
        if seeds["tried"] == 1:
            assert ", from 1 seed):" in message and "of 1 seeds" not in message, message
        else:
            assert f", {seeds['agreed']} of {seeds['tried']} seeds agreed there):" in message, message
    assert exact["full_inertia_150"].stats["seeds"]["tried"] == 1
    assert exact["bilimoria_wie_180"].stats["seeds"]["tried"] == 2
