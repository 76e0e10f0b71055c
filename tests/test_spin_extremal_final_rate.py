"""The spin extremals leave the final rate free: a problem that fixes one is refused (fresh-eyes
report of 2026-12-02: a rest-to-rest slew of a 4-wheel pyramid was an "ok" row whose reference
ended turning at 0.013 rad/s and whose closed loop ended 74.9 deg off the target)."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp

import scenarios
from ocp import quat
from planners import PLANNERS
from scenarios.errors import ScenarioError

PYRAMID = {
    "name": "pyr54-spin",
    "spacecraft": {"inertia": [2.0, 2.5, 3.0],
                   "wheels": {"axes": [[0.8165, 0.0, 0.57735], [0.0, 0.8165, 0.57735],
                                       [-0.8165, 0.0, 0.57735], [0.0, -0.8165, 0.57735]],
                              "max_torque": 0.01, "max_momentum": 0.05, "failed": [0]}},
    "maneuver": {"duration": 150.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": {"axis_angle": {"axis": [1, 2, 3], "angle_deg": 100}}, "omega": [0, 0, 0]}},
    "planners": [{"name": "spin_extremal"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5, "duration": 250.0},
}


def _load(tmp_path: Path, final_omega) -> scenarios.Scenario:
    data = yaml.safe_load(yaml.safe_dump(PYRAMID))
    data["maneuver"]["final"]["omega"] = final_omega
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    return scenarios.load(path)


def test_a_fixed_final_rate_is_refused_naming_the_yaml_key(tmp_path):
    with pytest.raises(ScenarioError) as caught:
        _load(tmp_path, [0.0, 0.0, 0.0])
    text = str(caught.value)
    assert "planners[0]" in text and "maneuver.final.omega" in text, text


def test_the_refusal_is_right_the_extremal_ends_turning_and_coasts_off_the_target(tmp_path):
    # The same slew with the final rate free, as the method poses it: accepted. Its reference reaches
    # the target attitude, but finite differences of its attitude alone (not its rate) show the body
    # still turning at T, and a torque-free coast of that state (Euler + kinematics, solve_ivp) leaves
    # the target: a fixed final rate at rest is not a boundary the family can meet.
    problem = _load(tmp_path, None).problem
    reference = PLANNERS["spin_extremal"]({}).plan(problem)
    assert reference.ok, reference.message
    T, h = reference.duration, 1e-3
    q = reference.q(np.array([T - 2 * h, T - h, T]))
    assert quat.error_angle(q[2], problem.qf) < 1e-6
    rate = 2.0 * quat.product(quat.conjugate(q[1]), (q[2] - q[0]) / (2 * h))[1:]  # body rate at T - h
    assert np.linalg.norm(rate) > 5e-3  # rad/s: turning at T (the user's run: 0.0131)
    inertia = problem.spacecraft.inertia

    def coast(_, x):
        q, w = x[:4], x[4:]
        return np.r_[quat.kinematics(q, w), np.linalg.solve(inertia, -np.cross(w, inertia @ w))]

    end = solve_ivp(coast, (0.0, 100.0), np.r_[q[1], rate], rtol=1e-10, atol=1e-12).y[:4, -1]
    assert np.degrees(quat.error_angle(end / np.linalg.norm(end), problem.qf)) > 30.0


def test_as_a_start_the_extremal_frees_the_final_rate(tmp_path):
    # collocation's warm_start: spin_extremal on a rest-to-rest problem still gets the extremal,
    # the same one as on the free problem (the optimisation never reads omegaf).
    fixed = replace(_load(tmp_path, None).problem, omegaf=np.zeros(3))
    planner = PLANNERS["spin_extremal"]({})
    assert not planner.plan(fixed).ok
    start = planner.plan_start(fixed)
    free = planner.plan(_load(tmp_path, None).problem)
    assert start.ok, start.message
    t = np.linspace(0.0, fixed.duration, 7)
    np.testing.assert_allclose(start.q(t), free.q(t), atol=1e-12)


def test_the_start_on_a_fixed_final_rate_builds_its_nlp_once(tmp_path, monkeypatch):
    # The freed problem is a new ManeuverProblem with a model (and a solver cache) of its own: each
    # start built the extremal's IPOPT again (25 ms of a 90 ms Bilimoria & Wie plan) until the start
    # built into the given problem's cache.
    from planners import spin_extremal

    built = []
    original = spin_extremal.build_solver
    monkeypatch.setattr(spin_extremal, "build_solver", lambda: built.append(1) or original())
    fixed = replace(_load(tmp_path, None).problem, omegaf=np.zeros(3))
    planner = PLANNERS["spin_extremal"]({})
    assert all(planner.plan_start(fixed).ok for _ in range(3))
    assert len(built) == 1
