"""The slew-table fit gives no time for a slew whose end attitude breaks a pointing requirement.

A user's failed-wheel table with a Sun keep-out (2026-12-03) gave finite times for all 805 of 20,000
random 180° slews that end with the star tracker inside the cone (one 1° from the Sun: 44.25 s),
while the table's own entry there was ``infeasible``: between the table's axes the fit blended
its neighbours' times. The fit now checks the end attitude against the cones itself.

Oracles: :meth:`ocp.geometry.pointing.PointingConstraint.margins` of the parsed scenario (the
code every run scores pointing with, a rotation matrix and ``arccos`` where the fit uses a
quaternion rotation and a cosine), at the time the table checks its entries' targets; the
eigenaxis bang-bang time of a unit-inertia body with ``|u_i| <= 1`` N m for the table's times.
"""
from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest

from ocp import quat
from scenarios.schema.loader import parse_scenario
from scenarios.slewtable.compute import (
    TablePart,
    end_cones,
    fit_entries,
    held_out_errors,
    quality_lines,
)
from scenarios.slewtable.fit import SlewTimeFit, load_fit
from scenarios.slewtable.grid import polytope_grid

ANGLES_DEG = [30.0, 90.0, 135.0, 180.0]

KEEP_OUT = {
    "name": "box-keep-out",
    "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0},
                   "sensors": {"camera": {"boresight": [1, 0, 0]}, "antenna": {"boresight": [0, 0.6, 0.8]}}},
    "maneuver": {"duration": 20.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.7071068, 0, 0, 0.7071068], "omega": [0, 0, 0]}},
    "planners": [{"name": "collocation"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "requirements": {"pointing": {
        "cam_y": {"sensor": "camera", "keep_out": {"inertial": [0, 1, 0]}, "angle_deg": 20},
        "antenna_in": {"sensor": "antenna", "keep_in": {"inertial": [0.2, 0.3, 0.9]}, "angle_deg": 70}}},
}

SUN = copy.deepcopy(KEEP_OUT)
SUN["epoch"] = "2027-03-20T12:00:00Z"
SUN["requirements"] = {"pointing": {"cam_sun": {"sensor": "camera", "keep_out": "sun", "angle_deg": 30}}}


def _table_fit(cones: np.ndarray | None) -> SlewTimeFit:
    """A fit of a table whose every entry is ok, the eigenaxis bang-bang times (as if nobody had
    told the table of the cones)."""
    axes, triangles = polytope_grid(np.eye(3), 2)
    part = TablePart.empty(axes, ANGLES_DEG)
    for i, axis in enumerate(axes):
        for k, angle in enumerate(ANGLES_DEG):
            part.status[i][k] = "ok"
            part.slew_time_s[i, k] = 2.0 * math.sqrt(math.radians(angle) * float(np.max(np.abs(axis))))
    fit, _ = fit_entries(part, np.eye(3), np.eye(3), {"from_identity_only": True}, triangles, None, cones)
    assert fit is not None
    return fit


def _broken(scenario: dict, axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Whether each slew's end attitude breaks a pointing requirement: the parsed scenario's
    constraints' margins at the scenario's duration (the time the table checks its targets at)."""
    problem = parse_scenario(scenario).problem
    q = np.array([quat.from_axis_angle(axis, angle) for axis, angle in zip(axes, angles)])
    time = np.full(len(q), float(problem.duration))
    broken = np.zeros(len(q), dtype=bool)
    for constraint in problem.pointing:
        broken |= constraint.margins(time, q) < 0.0
    return broken


@pytest.mark.parametrize("scenario", [KEEP_OUT, SUN], ids=["inertial keep-out and keep-in", "sun keep-out"])
def test_the_fit_is_inf_exactly_where_the_end_attitude_breaks_a_cone(scenario):
    rng = np.random.default_rng(7)
    axes = rng.normal(size=(3000, 3))
    angles = rng.uniform(0.01, math.pi, size=3000)
    angles[:500] = math.pi  # the user's case: a table angle of 180 deg
    truth = _broken(scenario, axes, angles)
    assert 100 < truth.sum() < 2900  # both sides are exercised
    fit = _table_fit(end_cones(scenario))
    many = fit.many_axis_angle(axes, angles)
    np.testing.assert_array_equal(np.isinf(many), truth)
    assert np.all(np.isfinite(many[~truth]))
    scalar = np.array([fit.axis_angle(*axis, angle) for axis, angle in zip(axes.tolist(), angles.tolist())])
    np.testing.assert_array_equal(np.isinf(scalar), truth)
    qf = np.array([quat.from_axis_angle(axis, angle) for axis, angle in zip(axes, angles)])
    calls = np.array([fit([1.0, 0.0, 0.0, 0.0], q.tolist()) for q in qf])
    np.testing.assert_array_equal(np.isinf(calls), truth)
    # without the cones (before the fix) every one of those slews had a time
    assert np.all(np.isfinite(_table_fit(None).many_axis_angle(axes[truth], angles[truth])))


def test_end_cones_hold_the_cone_at_the_duration_and_leave_out_a_closed_window():
    cones = end_cones(KEEP_OUT)
    assert cones.shape == (2, 8)
    np.testing.assert_allclose(cones[0], [1, 0, 0, 0, 1, 0, math.cos(math.radians(20)), 1.0], atol=1e-15)
    direction = np.array([0.2, 0.3, 0.9]) / np.linalg.norm([0.2, 0.3, 0.9])
    np.testing.assert_allclose(cones[1], [0, 0.6, 0.8, *direction, math.cos(math.radians(70)), 0.0], atol=1e-15)
    closed = copy.deepcopy(KEEP_OUT)
    closed["requirements"]["pointing"]["cam_y"]["window"] = [0.0, 5.0]  # over before the duration (20 s)
    assert len(end_cones(closed)) == 1
    assert len(end_cones({**KEEP_OUT, "requirements": {}})) == 0


def test_the_cones_survive_fit_json(tmp_path):
    fit = _table_fit(end_cones(KEEP_OUT))
    fit.save(tmp_path / "fit.json")
    again = load_fit(tmp_path)
    np.testing.assert_array_equal(again.end_cones, fit.end_cones)
    rng = np.random.default_rng(3)
    axes, angles = rng.normal(size=(400, 3)), rng.uniform(0.1, math.pi, size=400)
    np.testing.assert_array_equal(again.many_axis_angle(axes, angles), fit.many_axis_angle(axes, angles))


def test_held_out_errors_count_an_infeasible_entry_the_fit_gives_a_time():
    fit = _table_fit(None)
    part = TablePart.empty(np.array([[0.3, 0.5, 0.81]]), [90.0, 180.0])
    part.status = [["ok", "infeasible"]]
    part.slew_time_s[0] = [fit.axis_angle(0.3, 0.5, 0.81, math.radians(90.0)), math.nan]
    quality = held_out_errors(fit, part, [90.0, 180.0])
    assert quality["max_rel_error"] == pytest.approx(0.0, abs=1e-12)  # the ok point is exact ...
    assert quality["timed_infeasible"] == 1 and quality["target_met"] is False  # ... but a time for no slew
    assert quality["timed_infeasible_example"]["angle_deg"] == 180.0
    quality["eval_time_us"] = 1.0
    assert any("infeasible held-out entry" in line and "NOT met" in line for line in quality_lines(quality))
    part.status = [["ok", "ok"]]
    part.slew_time_s[0, 1] = fit.axis_angle(0.3, 0.5, 0.81, math.pi)
    quality = held_out_errors(fit, part, [90.0, 180.0])
    assert quality["timed_infeasible"] == 0 and quality["target_met"] is True


def test_the_error_by_angle_is_the_range_of_the_signed_errors():
    """A user read "90 deg (table) 0 to +11.4 %" where every error there was +3.3 % or more: the
    lower end was the largest under-estimate clamped at 0, not the least error."""
    fit = _table_fit(None)
    axes = np.array([[0.3, 0.5, 0.81], [0.7, -0.2, 0.4]])
    part = TablePart.empty(axes, [90.0])
    part.status = [["ok"], ["ok"]]
    for i, (axis, over) in enumerate(zip(axes.tolist(), (1.03, 1.11))):
        part.slew_time_s[i, 0] = fit.axis_angle(*axis, math.radians(90.0)) / over
    quality = held_out_errors(fit, part, [90.0])
    quality["eval_time_us"] = 1.0
    (item,) = quality["by_angle"]
    assert item["min_error"] == pytest.approx(0.03) and item["max_error"] == pytest.approx(0.11)
    assert "90 deg (table) +3 to +11 %" in quality_lines(quality)[2]


def test_an_earlier_fit_without_the_end_check_is_refused(tmp_path):
    """A reviewer loaded a keep-out fit.json written before the check: it gave 2.5066 s where the
    fit now gives inf."""
    data = _table_fit(end_cones(KEEP_OUT)).to_dict()
    del data["end_cones"]
    (tmp_path / "fit.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="end attitude"):
        load_fit(tmp_path)
    data["meta"]["from_identity_only"] = False  # a table of any start: no cones to check
    (tmp_path / "fit.json").write_text(json.dumps(data))
    assert load_fit(tmp_path).end_cones.shape == (0, 8)


def test_cones_need_slews_from_the_identity():
    """The end check takes the slew's rotation for the end attitude, true only from the identity."""
    fit = _table_fit(None)
    with pytest.raises(ValueError, match="from_identity_only"):
        SlewTimeFit(fit.angles, fit.axes, fit.times, {}, np.eye(3), np.eye(3), fit.triangles,
                    end_cones=end_cones(KEEP_OUT))
