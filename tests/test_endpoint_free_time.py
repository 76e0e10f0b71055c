"""Pre-planning proofs (endpoint_violations): a moving cone's target with a free final time, and the
rate requirement over the angle between the end points.

The fixture is a user's 6U case (a 4-wheel pyramid, a star tracker kept 20 deg from the Earth's
limb and 40 deg from the Sun, 500 km SSO): 150 deg about [0.4, 0, 0.917] ends clear of the limb at
the end of its ~15 s minimum-time slew, and the limb reaches the held target ~58 s later, before
maneuver.duration = 120 s. The pre-check used to call it infeasible at 120 s.
"""
from __future__ import annotations

import copy
import math
import time

import numpy as np
import pytest

import scenarios
from ocp import quat
from scenarios.requirements.scoring import endpoint_violations
from scenarios.slewtable.compute import TablePart, _fill, _proven_infeasible, end_cones
from scenarios.slewtable.spec import TableCase

PYRAMID = [[0.5773503, 0.5773503, 0.5773503], [-0.5773503, 0.5773503, 0.5773503],
           [-0.5773503, -0.5773503, 0.5773503], [0.5773503, -0.5773503, 0.5773503]]
AXIS = np.array([0.4, 0.0, 0.917]) / np.linalg.norm([0.4, 0.0, 0.917])
DURATION = 120.0


def sat6u(q_final: list[float], planner: dict, pointing: bool = True, rate: float | None = None) -> dict:
    data: dict = {
        "name": "sat6u", "epoch": "2027-06-01T00:00:00Z",
        "spacecraft": {"inertia": [[0.13, 0.003, -0.002], [0.003, 0.11, 0.001], [-0.002, 0.001, 0.045]],
                       "wheels": {"axes": PYRAMID, "max_torque": 0.002, "max_momentum": 0.02},
                       "sensors": {"star_tracker": {"boresight": [0, 0.7071068, -0.7071068]}}},
        "orbit": {"altitude_km": 500, "inclination_deg": 97.4, "raan_deg": 120.0},
        "maneuver": {"duration": DURATION, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": [float(v) for v in q_final], "omega": [0, 0, 0]}},
        "planners": [planner], "controller": {"name": "augmented_quaternion_feedback"},
        "simulation": {"sample_time": 0.2}, "requirements": {"actuators": {"margin": 0.1}}}
    if pointing:
        data["requirements"]["pointing"] = {
            "st_sun": {"sensor": "star_tracker", "keep_out": "sun", "angle_deg": 40},
            "st_limb": {"sensor": "star_tracker", "keep_out": "earth_limb", "angle_deg": 20}}
    if rate is not None:
        data["requirements"]["rate"] = {"max": rate}
    return data


TARGET = [math.cos(math.radians(75.0)), *(math.sin(math.radians(75.0)) * AXIS)]
EIGENAXIS = {"name": "eigenaxis", "options": {"profile": "min_time"}}
SMOOTH = {"name": "eigenaxis", "options": {"profile": "smooth"}}
COLLOCATION = {"name": "collocation", "label": "collocation", "options": {"objective": "min_time"}}


def limb(scenario: scenarios.Scenario):
    return next(c for c in scenario.problem.pointing if c.name == "st_limb")


def test_fixture_target_is_inside_the_moving_limb_cone_at_the_bound_only():
    """The fixture's premise, from the constraint's own margins: outside at the slew's end, inside at T."""
    scenario = scenarios.parse_scenario(sat6u(TARGET, EIGENAXIS))
    cone = limb(scenario)
    assert cone.moving
    margins = np.rad2deg(cone.margins(np.array([15.0, DURATION]), np.tile(TARGET, (2, 1))))
    assert margins[0] > 0.5 and margins[1] < -1.0


def test_free_final_time_does_not_refuse_a_target_the_moving_cone_reaches_after_the_slew():
    scenario = scenarios.parse_scenario(sat6u(TARGET, EIGENAXIS))
    fixed = endpoint_violations(scenario.problem)  # a fixed final time: the slew ends at T, inside
    assert len(fixed) == 1 and fixed[0].startswith("st_limb: the target attitude already breaks it at 120 s")
    assert endpoint_violations(scenario.problem, free_time=True) == []


def test_free_final_time_still_refuses_a_target_inside_the_cone_at_every_time():
    """The Sun moves ~0.005 deg in 120 s: a target with the tracker on the Sun is refused all the same."""
    scenario = scenarios.parse_scenario(sat6u(TARGET, EIGENAXIS))
    sun = next(c for c in scenario.problem.pointing if c.name == "st_sun")
    b, d = np.asarray(sun.boresight, float), sun.direction([DURATION])[0]
    axis = np.cross(b, d)
    onto = quat.from_axis_angle(axis / np.linalg.norm(axis), math.acos(float(np.clip(b @ d, -1, 1))))
    scenario = scenarios.parse_scenario(sat6u(list(onto), EIGENAXIS))
    found = endpoint_violations(scenario.problem, free_time=True)
    assert any(line.startswith("st_sun: the target attitude breaks it at every time a minimum-time slew may end")
               and "no reference can meet it" in line for line in found), found


def test_minimum_time_row_is_planned_and_its_hold_named():
    """`run` with a minimum-time planner plans the slew; the target held into the cone is the row's
    violation, naming when the cone reaches it (the first zero of the margin, found here on a 0.01 s
    grid of the constraint's own margins)."""
    scenario = scenarios.parse_scenario(sat6u(TARGET, EIGENAXIS))
    row = scenarios.run(scenario).rows[0]
    assert row.status == "violated" and row.reference is not None and row.reference.duration < 20.0
    grid = np.arange(row.reference.duration, DURATION, 0.01)
    enters = grid[np.argmax(limb(scenario).margins(grid, np.tile(TARGET, (grid.size, 1))) < 0)]
    assert f"the slew clears it (it ends at T = {row.reference.duration:.4g} s), but the cone reaches its end " \
           f"state, held after it, at {enters:.1f} s" in row.message
    assert "no reference can meet it" not in row.message


def test_fixed_time_row_is_still_refused_before_planning():
    scenario = scenarios.parse_scenario(sat6u(TARGET, SMOOTH))
    row = scenarios.run(scenario).rows[0]
    assert row.status == "infeasible" and row.plan_time_s == 0.0  # documented: a proof before planning, infeasible
    assert row.message.startswith("st_limb: the target attitude already breaks it at 120 s, maneuver.duration")


def test_table_entry_is_the_slew_not_the_hold():
    """A min_time table entry: not proven infeasible, its fit cone leaves the moving limb out, and a
    row broken only after its slew is an ok entry (its time fitted) whose message says so."""
    data = sat6u(TARGET, COLLOCATION)
    assert not _proven_infeasible(data)
    cones = end_cones(data)
    assert cones.shape == (2, 8) and np.all(cones[:, 7] == 1.0)  # both keep-outs, the limb's narrowed
    # the fit's end check (inside a keep-out: the rotated boresight within the cone) clears the target
    pointing = quat.rotation_matrix(np.asarray(TARGET)) @ cones[:, :3].T
    assert np.all(np.einsum("ij,ji->i", cones[:, 3:6], pointing) < cones[:, 6])
    fixed = end_cones(sat6u(TARGET, {**COLLOCATION, "options": {"objective": "min_energy"}}))  # checked at T
    assert np.any(np.einsum("ij,ji->i", fixed[:, 3:6], quat.rotation_matrix(np.asarray(TARGET)) @ fixed[:, :3].T)
                  > fixed[:, 6])
    assert _proven_infeasible(sat6u(TARGET, {**COLLOCATION, "options": {"objective": "min_energy"}}))

    def entry(first_violation_s: float) -> tuple[str, str]:
        part = TablePart.empty(np.array([AXIS]), [150.0])
        held = {"met": False, "min_margin_deg": -1.84, "time_in_violation_s": 61.6,
                "first_violation_s": first_violation_s, "min_margin_time_s": 120.0}
        row = {"status": "violated", "message": "st_limb (reference): ...", "plan_time_s": 3.0,
               "reference": {"duration_s": 14.52},
               "requirements": {"reference": {"st_limb": held, "st_sun": {"met": True}},
                                "closed_loop": {"st_limb": dict(held)}}}
        _fill(part, TableCase("table", 0, 0, AXIS, 150.0, data), {"rows": [row]}, "min_time")
        assert part.slew_time_s[0, 0] == 14.52
        return part.status[0][0], part.message[0][0]

    assert entry(58.4) == ("ok", "st_limb (reference): ...")
    assert entry(10.0)[0] == "violated"  # broken during the slew: the slew's own violation


def test_table_entry_broken_by_another_requirement_stays_violated():
    part = TablePart.empty(np.array([AXIS]), [150.0])
    row = {"status": "violated", "message": "rate ...", "reference": {"duration_s": 14.52},
           "requirements": {"reference": {"rate": {"met": False, "peak_rate": 1.0}}}}
    _fill(part, TableCase("table", 0, 0, AXIS, 150.0, sat6u(TARGET, COLLOCATION)), {"rows": [row]}, "min_time")
    assert part.status[0][0] == "violated"


def rotation(angle_rad: float) -> list[float]:
    return [math.cos(angle_rad / 2), 0.0, 0.0, math.sin(angle_rad / 2)]


def test_rate_bound_below_the_angle_over_the_duration_is_refused_at_once():
    """90 deg at 1e-5 rad/s takes at least pi/2 / 1e-5 = 157,080 s: every row infeasible, in seconds."""
    data = sat6u(rotation(math.pi / 2), COLLOCATION, pointing=False, rate=1e-5)
    data["planners"] = [COLLOCATION, EIGENAXIS]
    scenario = scenarios.parse_scenario(data)
    start = time.perf_counter()
    rows = scenarios.run(scenario).rows
    assert time.perf_counter() - start < 30.0
    least = (math.pi / 2) / 1e-5
    assert [row.status for row in rows] == ["infeasible", "infeasible"]
    for row in rows:
        assert row.plan_time_s == 0.0 and row.reference_metrics is None
        assert row.message == (
            "rate: the slew turns 90 deg (the principal angle from maneuver.initial.q to maneuver.final.q); at "
            f"‖ω‖ at most 1e-05 rad/s (requirements.rate.max) it takes at least θ/ω_max = {least:.4g} s, more "
            "than the 120 s bound (maneuver.duration); no reference within it can meet it")
    assert f"{least:.4g}" == "1.571e+05"


@pytest.mark.parametrize("ratio, refused", [(0.999, False), (1.001, True)])
def test_rate_proof_at_its_edge(ratio: float, refused: bool):
    """theta / omega_max just below the bound is not refused, just above it is; the shorter way of
    +-qf counts (a target written as -qf, 270 deg the long way round, is 90 deg)."""
    theta = math.pi / 2
    bound = theta / (ratio * DURATION)
    for target in (rotation(theta), [-v for v in rotation(theta)]):
        problem = scenarios.parse_scenario(sat6u(target, SMOOTH, pointing=False, rate=bound)).problem
        found = [line for line in endpoint_violations(problem) if line.startswith("rate:")]
        assert bool(found) is refused


def test_rate_proof_holds_whatever_the_boundary_rates():
    """Nonzero boundary rates do not weaken it (the bound holds at every time); a rate bound met with
    room is never refused."""
    data = sat6u(rotation(math.pi / 2), SMOOTH, pointing=False, rate=1e-3)
    data["maneuver"]["initial"]["omega"] = [0.0, 0.0, 5e-4]
    assert any(line.startswith("rate:") for line in endpoint_violations(scenarios.parse_scenario(data).problem))
    roomy = copy.deepcopy(data)
    roomy["requirements"]["rate"]["max"] = 0.05
    assert endpoint_violations(scenarios.parse_scenario(roomy).problem) == []


def test_validate_names_only_the_rows_the_end_points_doom():
    """``validate`` proves it per planner as the runner does: the fixed-time row is doomed by the
    limb at 120 s, the minimum-time row is not (its slew may end before)."""
    from scenarios.cli.commands import _before_planning, _doomed_notes

    data = sat6u(TARGET, {**EIGENAXIS, "label": "fastest"})
    data["planners"].append({**SMOOTH, "label": "smooth"})
    notes = [line for line, _ in _before_planning(scenarios.parse_scenario(data))]
    assert [note.split(": ")[0] for note in notes] == ["the row of smooth is infeasible before planning"], notes
    assert "st_limb: the target attitude already breaks it at 120 s" in notes[0]
    assert _doomed_notes(scenarios.parse_scenario(data)) == []  # the minimum-time row may be ok
    alone = _doomed_notes(scenarios.parse_scenario(sat6u(TARGET, {**SMOOTH, "label": "smooth"})))
    assert [note.split(": ")[0] for note in alone] == ["every planner's row is infeasible before planning"], alone
