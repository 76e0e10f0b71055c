"""One rule each for what a row's status says before and after planning.

1. Every proof before planning that no motion meets the requirements (a pointing requirement broken
   at an end point, an angle the rate requirement cannot turn within ``maneuver.duration``) makes
   the row ``infeasible``, never ``failed`` (a numerical failure).
2. ``maneuver.duration`` is the manoeuvre's time budget for every planner: the rate proof holds a
   minimum-time planner to it, and so does the runner: a slew planned longer than it is
   ``infeasible``, with or without a rate requirement.
3. ``validate`` says in one line when every row is doomed before planning for reasons that differ
   by planner, and a line that dooms only some rows is no ``--strict`` finding.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml

import scenarios
from ocp import quat
from scenarios.cli.commands import _before_planning, _doomed_notes, main
from scenarios.requirements.scoring import late_slew

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "scenarios" / "eigenaxis_demo.yaml"

INERTIA = 10.0  # kg m^2, a sphere: the eigenaxis slew's torque is I theta'' about any axis
TORQUE = 0.0144  # N m per wheel, along the body axes
ANGLE = math.pi / 2  # about body z
FASTEST = 2.0 * math.sqrt(ANGLE * INERTIA / TORQUE)  # the bang-bang triangle: 66.05 s, no rate bound


def slew(duration: float, profile: str = "min_time", rate: float | None = None) -> dict:
    """A 90 deg rest-to-rest slew about z of a 10 kg m^2 sphere on 0.0144 N m wheels."""
    data: dict = {
        "name": "budget", "spacecraft": {"inertia": [INERTIA] * 3, "wheels": {"max_torque": TORQUE, "max_momentum": 5.0}},
        "maneuver": {"duration": duration, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": [math.cos(ANGLE / 2), 0, 0, math.sin(ANGLE / 2)], "omega": [0, 0, 0]}},
        "planners": [{"name": "eigenaxis", "options": {"profile": profile}}],
        "controller": {"name": "augmented_quaternion_feedback"}, "simulation": {"sample_time": 1.0}}
    if rate is not None:
        data["requirements"] = {"rate": {"max": rate}}
    return data


def row(data: dict) -> scenarios.output.results.Row:
    return scenarios.run(scenarios.parse_scenario(data)).rows[0]


# 1. a proof before planning: infeasible, whichever requirement it proves

def test_a_pointing_end_point_and_the_rate_proof_give_the_same_status():
    """The demo starts at identity, its camera on inertial +z: a 20 deg keep-out about +z is broken at
    t = 0; a 1e-5 rad/s rate bound cannot turn its 90 deg within 120 s. Both are proofs before
    planning (nothing planned, no simulation): both rows are ``infeasible``."""
    pointing = yaml.safe_load(DEMO.read_text())
    pointing["spacecraft"]["sensors"] = {"camera": {"boresight": [0, 0, 1]}}
    pointing["requirements"] = {"pointing": {"cam": {"sensor": "camera", "keep_out": {"inertial": [0, 0, 1]},
                                                     "angle_deg": 20}}}
    rate = yaml.safe_load(DEMO.read_text())
    rate["requirements"] = {"rate": {"max": 1e-5}}
    for data, words in ((pointing, "cam: the initial attitude already breaks it at 0 s"),
                        (rate, "rate: the slew turns 90 deg")):
        rows = scenarios.run(scenarios.parse_scenario(data)).rows
        assert [r.status for r in rows] == ["infeasible"] * 3, [(r.status, r.message) for r in rows]
        assert all(r.message.startswith(words) and r.simulation is None and r.plan_time_s == 0.0 for r in rows)


# 2. maneuver.duration is every planner's time budget

def test_the_fastest_slew_of_the_fixture():
    """The premise, from the planner's own reference: the fastest eigenaxis slew takes 2 sqrt(theta I / tau)."""
    reference = scenarios.parse_scenario(slew(120.0)).planners[0].planner.plan(scenarios.parse_scenario(slew(120.0)).problem)
    assert reference.ok and math.isclose(reference.duration, FASTEST, rel_tol=1e-9)
    assert 66.0 < FASTEST < 66.1


def test_a_minimum_time_slew_longer_than_the_duration_is_infeasible_with_or_without_a_rate_requirement():
    """Within 60 s: at 0.025 rad/s the rate proof refuses it (theta/omega_max = 62.8 s), and without a
    rate requirement the 66.05 s minimum-time slew is held to the same budget, as a bang-coast-bang
    over 60 s is (the planner's own check)."""
    assert ANGLE / 0.025 > 60.0
    rated = row(slew(60.0, rate=0.025))
    assert rated.status == "infeasible" and rated.message.startswith("rate: "), rated.message
    free = row(slew(60.0))
    assert free.status == "infeasible", free.message
    assert free.simulation is None and free.reference is not None and not free.reference.ok
    assert free.message.startswith(f"its slew takes {FASTEST:.7g} s, longer than the 60 s bound (maneuver.duration"), \
        free.message
    assert "a maneuver.duration of at least 66.1 s admits this one" in free.message  # FASTEST rounded up
    trapezoid = row(slew(60.0, profile="trapezoidal"))
    assert trapezoid.status == "infeasible" and trapezoid.message.startswith(
        "maneuver.duration, the manoeuvre's time budget (T = 60 s), is shorter than the minimum bang-coast-bang "
        f"time {FASTEST:.6g} s"), trapezoid.message
    # what to change: the budget, rounded up (never below the time needed), or the bounds
    assert "a maneuver.duration of at least 66.06 s admits it, or larger actuator limits" in trapezoid.message


def test_a_minimum_time_slew_within_the_duration_is_planned_and_flown():
    within = row(slew(70.0))
    assert within.status == "ok", within.message
    assert within.reference is not None and math.isclose(within.reference.duration, FASTEST, rel_tol=1e-9)
    assert within.simulation is not None and math.isclose(float(within.simulation.t[-1]), 70.0)


def test_late_slew_at_its_edge():
    """Within the solver's bound relaxation (1e-8 of T) a slew is on time; 60.001 s of a 60 s budget is late."""
    problem = scenarios.parse_scenario(slew(60.0)).problem
    assert late_slew(problem, 60.0) == "" and late_slew(problem, 60.0 * (1 + 1e-8)) == ""
    assert late_slew(problem, 60.0001).startswith("its slew takes 60.0001 s, longer than the 60 s bound")
    assert late_slew(problem, 60.001).startswith("its slew takes 60.001 s, longer than the 60 s bound")


# 3. validate: every row doomed, for reasons that differ by planner

PYRAMID = [[0.5773503, 0.5773503, 0.5773503], [-0.5773503, 0.5773503, 0.5773503],
           [-0.5773503, -0.5773503, 0.5773503], [0.5773503, -0.5773503, 0.5773503]]


def sat6u(q_final: list[float]) -> dict:
    """A 6U with a star tracker kept 40 deg from the Sun and 20 deg from the Earth's limb (500 km SSO),
    planned at a fixed time (smooth) and at a free one (fastest), T = 120 s."""
    return {
        "name": "sat6u", "epoch": "2027-06-01T00:00:00Z",
        "spacecraft": {"inertia": [[0.13, 0.003, -0.002], [0.003, 0.11, 0.001], [-0.002, 0.001, 0.045]],
                       "wheels": {"axes": PYRAMID, "max_torque": 0.002, "max_momentum": 0.02},
                       "sensors": {"star_tracker": {"boresight": [0, 0.7071068, -0.7071068]}}},
        "orbit": {"altitude_km": 500, "inclination_deg": 97.4, "raan_deg": 120.0},
        "maneuver": {"duration": 120.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": [float(v) for v in q_final], "omega": [0, 0, 0]}},
        "planners": [{"name": "eigenaxis", "label": "fastest", "options": {"profile": "min_time"}},
                     {"name": "eigenaxis", "label": "smooth", "options": {"profile": "smooth"}}],
        "controller": {"name": "augmented_quaternion_feedback"}, "simulation": {"sample_time": 0.2},
        "requirements": {"actuators": {"margin": 0.1}, "pointing": {
            "st_sun": {"sensor": "star_tracker", "keep_out": "sun", "angle_deg": 40},
            "st_limb": {"sensor": "star_tracker", "keep_out": "earth_limb", "angle_deg": 20}}}}


def onto_the_sun() -> list[float]:
    """The target that turns the tracker onto the Sun at T (the Sun moves ~0.005 deg in 120 s)."""
    sun = next(c for c in scenarios.parse_scenario(sat6u([1, 0, 0, 0])).problem.pointing if c.name == "st_sun")
    b, d = np.asarray(sun.boresight, float), sun.direction([120.0])[0]
    axis = np.cross(b, d)
    return list(quat.from_axis_angle(axis / np.linalg.norm(axis), math.acos(float(np.clip(b @ d, -1, 1)))))


def test_validate_says_once_that_every_row_is_doomed_when_the_reasons_differ_by_planner(tmp_path, capsys):
    """Onto the Sun, each row is proven infeasible, by differently worded proofs (at T for the fixed
    time; at every time the slew may end for the free one): one line says that no row can be ok."""
    data = sat6u(onto_the_sun())
    scenario = scenarios.parse_scenario(data)
    said = _before_planning(scenario)
    per_planner = [line for line, every in said if not every]
    assert [line.split(": ")[0] for line in per_planner] == ["the row of fastest is infeasible before planning",
                                                             "the row of smooth is infeasible before planning"], said
    assert _doomed_notes(scenario) == [
        "every planner's row is infeasible before planning (fastest: st_sun; smooth: st_sun): no row can be ok"], said
    rows = scenarios.run(scenario).rows  # the runner agrees: nothing planned, every row infeasible
    assert [r.status for r in rows] == ["infeasible", "infeasible"] and all(r.simulation is None for r in rows)
    path = tmp_path / "sun.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path), "--strict"]) == 1
    captured = capsys.readouterr()
    assert ("  every planner's row is infeasible before planning (fastest: st_sun; smooth: st_sun): no row can be ok"
            in captured.out.splitlines())
    assert "no row can be ok (1 note(s) above say every row is infeasible, fails or breaks a requirement)" in captured.err


def test_a_line_that_dooms_some_rows_only_is_said_but_is_no_strict_finding(tmp_path, capsys):
    """A target the limb reaches only at T dooms the fixed-time row; the minimum-time one may end
    before it (and is planned): validate says so, and --strict passes (a row may be ok)."""
    axis = np.array([0.4, 0.0, 0.917]) / np.linalg.norm([0.4, 0.0, 0.917])
    data = sat6u([math.cos(math.radians(75.0)), *(math.sin(math.radians(75.0)) * axis)])
    scenario = scenarios.parse_scenario(data)
    said = _before_planning(scenario)
    assert [(line.split(": ")[0], every) for line, every in said] == [
        ("the row of smooth is infeasible before planning", False)], said
    assert _doomed_notes(scenario) == []
    path = tmp_path / "limb.yaml"
    path.write_text(yaml.safe_dump(copy.deepcopy(data)))
    assert main(["validate", str(path), "--strict"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert any(line.startswith("  the row of smooth is infeasible before planning: st_limb") for line in out), out


@pytest.mark.parametrize("needed, bound", [(100.00045, 100.0), (29.736, 29.7), (66.0555, 60.0), (123456.7, 120000.0)])
def test_a_late_slew_names_its_duration_apart_from_the_bound_and_suggests_one_that_admits_it(needed, bound):
    """A reviewer's sphere needed 100.00045 s within 100 s: the message said "takes 100 s ... at
    least 100 s admits this one", and 100 s is still infeasible. The duration shown must differ from
    the bound, and the suggestion must be at least the duration needed (and close to it)."""
    message = late_slew(SimpleNamespace(duration=bound), needed)
    shown = float(message.split("its slew takes ")[1].split(" s")[0])
    suggested = float(message.split("at least ")[1].split(" s")[0])
    assert shown != bound and abs(shown - needed) <= 1e-6 * needed
    assert needed <= suggested <= needed * (1 + 1e-3)
