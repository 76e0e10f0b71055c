"""A closed loop's pointing requirement scored between its samples, not only on them.

Oracle: a body turning at a constant rate w about the inertial z axis points its body x axis at
azimuth φ(t) = w (t − t*) in the xy-plane; its angle θ to a fixed direction at elevation e above
the inertial x axis obeys cos θ = cos e cos φ (closed form). Past a keep-out cone of half-angle
α > e the margin θ − α is smallest, e − α, at t*; it is negative while
|φ| < arccos(cos α / cos e). Sampled every second at 0.05 rad/s with t* half-way between two
samples, every sample is 1.4 deg off the direction, clear of a 0.7 deg cone that the motion enters
for 0.4 s between them.

The 12U CubeSat case (``scenarios/cubesat_12u_sun_keep_out.yaml``) with a 0.7 deg Sun keep-out,
which the eigenaxis reference crosses for about 0.34 s around 29.8 s, tracked by a closed loop
sampled every second: the loop follows the reference to about 0.001 deg, so its margin and its
time inside must be the reference's (scored on 2001 points over its 60 s), although each of its
samples lies outside the cone.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import scenarios
from ocp import Spacecraft, quat
from ocp.geometry.directions import Geometry
from planners import ManeuverProblem
from scenarios.requirements.scoring import score_closed_loop
from scenarios.requirements.spec import (
    Direction,
    PointingRequirement,
    Requirements,
    Sensor,
)

ROOT = Path(__file__).resolve().parents[1]
SUN_SCENARIO = ROOT / "scenarios" / "cubesat_12u_sun_keep_out.yaml"

RATE = 0.05  # rad/s about z
PASS = 4.5  # s: body x at azimuth 0, half-way between the samples 4 and 5 s
CONE = math.radians(0.7)


def turning(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Attitude and body rate of the constant-rate turn at ``t``."""
    half = 0.5 * RATE * (t - PASS)
    q = np.stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)], axis=-1)
    return q, np.tile([0.0, 0.0, RATE], (t.size, 1))


@pytest.mark.parametrize("elevation_deg", [0.3, 0.0])
def test_a_cone_entered_between_samples_by_closed_form(elevation_deg: float) -> None:
    e = math.radians(elevation_deg)
    direction = [math.cos(e), 0.0, math.sin(e)]
    requirement = PointingRequirement("x_out", Sensor("x_axis", [1.0, 0.0, 0.0]), True, CONE, Direction(None, direction))
    requirements = Requirements((requirement,))
    problem = ManeuverProblem(Spacecraft(np.diag([2.0, 3.0, 4.0])), quat.IDENTITY, np.zeros(3), None, 10.0,
                              pointing=(requirement.constraint(Geometry(None, None), 10.0),))
    t = np.arange(0.0, 10.5, 1.0)
    q, omega = turning(t)
    sampled = np.arccos(math.cos(e) * np.cos(RATE * (t - PASS))) - CONE  # the closed form on the samples
    assert np.min(sampled) > math.radians(0.7)  # every sample is well clear of the cone

    score = score_closed_loop(requirements, problem, t, q, omega, 10.0)["x_out"]

    half_width = math.acos(math.cos(CONE) / math.cos(e)) / RATE  # s either side of PASS inside the cone
    assert not score.met
    assert score.values["min_margin_deg"] == pytest.approx(math.degrees(e - CONE), abs=1e-6)
    assert score.values["min_margin_time_s"] == pytest.approx(PASS, abs=1e-3)
    assert score.values["time_in_violation_s"] == pytest.approx(2.0 * half_width, abs=2e-4)
    assert score.values["first_violation_s"] == pytest.approx(PASS - half_width, abs=2e-4)


def test_a_cone_missed_between_samples_keeps_its_true_margin() -> None:
    """A 0.2 deg cone about a direction 0.3 deg above the path: met, with margin 0.1 deg at PASS
    (the samples alone say 1.25 deg)."""
    e = math.radians(0.3)
    cone = math.radians(0.2)
    requirement = PointingRequirement("x_out", Sensor("x_axis", [1.0, 0.0, 0.0]), True, cone,
                                      Direction(None, [math.cos(e), 0.0, math.sin(e)]))
    requirements = Requirements((requirement,))
    problem = ManeuverProblem(Spacecraft(np.diag([2.0, 3.0, 4.0])), quat.IDENTITY, np.zeros(3), None, 10.0,
                              pointing=(requirement.constraint(Geometry(None, None), 10.0),))
    t = np.arange(0.0, 10.5, 1.0)
    score = score_closed_loop(requirements, problem, t, *turning(t), 10.0)["x_out"]
    assert score.met
    assert score.values["min_margin_deg"] == pytest.approx(0.1, abs=1e-6)
    assert score.values["min_margin_time_s"] == pytest.approx(PASS, abs=1e-3)
    assert score.values["time_in_violation_s"] == 0.0 and score.values["first_violation_s"] is None


@pytest.fixture(scope="module")
def sun_pass_sampled_every_second():
    data = yaml.safe_load(SUN_SCENARIO.read_text())
    data = copy.deepcopy(data)
    data["planners"] = [{"name": "eigenaxis"}]
    data["simulation"]["sample_time"] = 1.0
    data["requirements"] = {"pointing": {"st_sun": {"sensor": "star_tracker", "keep_out": "sun", "angle_deg": 0.7}}}
    scenario = scenarios.parse_scenario(data)
    return scenario, scenarios.run(scenario).rows[0]


def test_a_closed_loop_sampled_every_second_is_scored_as_the_reference_it_tracks(sun_pass_sampled_every_second):
    scenario, row = sun_pass_sampled_every_second
    constraint = scenario.problem.pointing[0]
    on_samples = constraint.margins(row.simulation.t, row.simulation.q)
    assert np.nanmin(on_samples) > 0.0  # every sample of the loop is outside the cone
    reference = row.requirements["reference"]["st_sun"]
    closed_loop = row.requirements["closed_loop"]["st_sun"]
    assert reference["min_margin_deg"] < -0.4
    assert closed_loop["min_margin_deg"] < 0.0
    assert closed_loop["min_margin_deg"] == pytest.approx(reference["min_margin_deg"], abs=0.01)
    assert closed_loop["min_margin_time_s"] == pytest.approx(reference["min_margin_time_s"], abs=0.05)
    assert closed_loop["time_in_violation_s"] == pytest.approx(reference["time_in_violation_s"], abs=0.01)
    assert closed_loop["first_violation_s"] == pytest.approx(reference["first_violation_s"], abs=0.01)
    assert row.status == "violated" and "st_sun (closed loop): min margin -0.41" in row.message


def test_the_interpolated_attitude_off_an_eigenaxis_with_the_samples_signs_flipped() -> None:
    """A constant body rate about a body axis that is no inertial axis, from an attitude that is not
    the identity: q(t) = q0 ⊗ [cos(|ω| t / 2), sin(|ω| t / 2) ω̂] (closed form, body rates). The
    samples' signs alternate (q and -q are one attitude). A slope from inertial rates
    (½ [0, ω] ⊗ q) is 0.1 deg and more off here, at mid-interval."""
    from ocp.geometry.pointing import hermite_attitudes

    axis = np.array([1.0, 2.0, 3.0]) / math.sqrt(14.0)
    rate = 0.05
    q0 = quat.from_axis_angle(np.array([0.3, -1.0, 0.5]) / np.linalg.norm([0.3, -1.0, 0.5]), 1.1)

    def exact(times: np.ndarray) -> np.ndarray:
        half = 0.5 * rate * times
        turn = np.column_stack([np.cos(half), np.sin(half)[:, None] * axis])
        return np.stack([quat.product(q0, r) for r in turn])

    t = np.arange(0.0, 20.5, 1.0)
    q = exact(t) * np.where(np.arange(t.size) % 2, -1.0, 1.0)[:, None]
    omega = np.tile(rate * axis, (t.size, 1))
    middle = t[:-1] + 0.5
    error = np.degrees(quat.error_angle(hermite_attitudes(t, q, omega, middle), exact(middle)))
    assert np.max(error) < 1e-5


def test_a_violation_narrower_than_the_sub_grid_step_is_found_by_the_search() -> None:
    """A 0.01 deg cone about a direction 0.005 deg off the path, passed exactly half-way between two
    points of the sub-grid (58 steps per 1 s sample interval at 0.05 rad/s): on the sub-grid the
    boresight stays 0.025 deg off (clear of the cone); the true margin is -0.005 deg (closed form)."""
    steps = math.ceil(RATE * 1.0 / math.radians(0.05))
    passing = 4.0 + (steps // 2 + 0.5) / steps
    e, cone = math.radians(0.005), math.radians(0.01)
    requirement = PointingRequirement("x_out", Sensor("x_axis", [1.0, 0.0, 0.0]), True, cone,
                                      Direction(None, [math.cos(e), 0.0, math.sin(e)]))
    problem = ManeuverProblem(Spacecraft(np.diag([2.0, 3.0, 4.0])), quat.IDENTITY, np.zeros(3), None, 10.0,
                              pointing=(requirement.constraint(Geometry(None, None), 10.0),))
    t = np.arange(0.0, 10.5, 1.0)
    half = 0.5 * RATE * (t - passing)
    q = np.stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)], axis=-1)
    omega = np.tile([0.0, 0.0, RATE], (t.size, 1))
    score = score_closed_loop(Requirements((requirement,)), problem, t, q, omega, 10.0)["x_out"]
    assert not score.met
    assert score.values["min_margin_deg"] == pytest.approx(math.degrees(e - cone), abs=1e-7)
    assert score.values["min_margin_time_s"] == pytest.approx(passing, abs=1e-4)


def test_a_long_fast_run_far_from_the_cone_costs_a_bounded_search(monkeypatch) -> None:
    """15 000 one-second samples of a 0.2 rad/s tumble about z, the keep-out direction on the z
    axis (the x boresight stays 90 deg from it, margin 80 deg): no interval can hide a violation, and
    the bound cannot exclude a lower margin anywhere (it is constant), so each interval gets the
    coarse steps and only the deepest few steps are searched (the fine sub-grid of every interval
    and its search evaluated 3.6e8 margins: 4 s and 0.9 GB at 15 000 samples)."""
    from ocp.geometry.pointing import (
        COARSE_STEPS,
        MIN_SEARCHES,
        REFINE_LEVELS,
        REFINE_POINTS,
        PointingConstraint,
    )

    requirement = PointingRequirement("x_out", Sensor("x_axis", [1.0, 0.0, 0.0]), True, math.radians(10.0),
                                      Direction(None, [0.0, 0.0, 1.0]))
    constraint = requirement.constraint(Geometry(None, None), 15000.0)
    t = np.arange(0.0, 15000.0)
    half = 0.1 * t
    q = np.stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)], axis=-1)
    omega = np.tile([0.0, 0.0, 0.2], (t.size, 1))
    evaluated = []
    original = PointingConstraint.margins

    def counted(self, times, attitudes):
        evaluated.append(len(np.atleast_1d(times)))
        return original(self, times, attitudes)

    monkeypatch.setattr(PointingConstraint, "margins", counted)
    score = constraint.score_between_samples(t, q, omega)
    assert score.met and score.min_margin_deg == pytest.approx(80.0, abs=1e-6)
    assert sum(evaluated) <= (COARSE_STEPS + 1) * t.size + MIN_SEARCHES * REFINE_POINTS * REFINE_LEVELS


def test_a_rows_pointing_searches_together_are_each_the_search_alone() -> None:
    """``scores_between_samples`` runs a row's searches through the zooms together (one array of
    brackets tagged by search); every search must still evaluate exactly the points, and find exactly
    the values, it finds alone: a cone crossed between the samples (the zooms' branch and bound), a
    keep-in, a window inside the run (its edges: other knots), a window past the run (no point: no
    zoom), and two tumbles far from their cones whose lower-value candidates each exceed
    MIN_SEARCHES (the cap is per search: one shared by the searches would drop some of each)."""
    from ocp.geometry.pointing import (
        MIN_SEARCHES,
        HermiteMotion,
        PointingConstraint,
        scores_between_samples,
        search_between_samples,
        searches_between_samples,
    )

    t = np.arange(0.0, 400.0, 0.5)
    half = 0.5 * 0.2 * t  # a 0.2 rad/s tumble about z, a slow nod about x on top
    nod = 0.5 * 0.01 * np.sin(0.05 * t)
    q = np.stack([np.cos(half) * np.cos(nod), np.cos(half) * np.sin(nod), -np.sin(half) * np.sin(nod),
                  np.sin(half) * np.cos(nod)], axis=-1)
    omega = np.column_stack([0.01 * 0.025 * np.cos(0.05 * t) * np.ones_like(t), np.zeros_like(t), np.full(t.size, 0.2)])
    constraints = [
        PointingConstraint("crossed", [1.0, 0.0, 0.0], True, math.radians(2.0), directions=[[1.0, 0.0, 0.0]]),
        PointingConstraint("kept_in", [0.0, 0.0, 1.0], False, math.radians(0.5), directions=[[0.0, 0.0, 1.0]]),
        PointingConstraint("windowed", [0.0, 1.0, 0.0], True, math.radians(5.0), directions=[[0.0, 1.0, 0.0]],
                           window=(33.3, 77.7)),
        PointingConstraint("after", [1.0, 0.0, 0.0], True, math.radians(5.0), window=(500.0, 600.0)),
        PointingConstraint("tumble_a", [1.0, 0.0, 0.0], True, math.radians(10.0), directions=[[0.0, 0.0, 1.0]]),
        PointingConstraint("tumble_b", [0.0, 1.0, 0.0], True, math.radians(20.0), directions=[[0.0, 0.0, -1.0]]),
    ]
    motion = HermiteMotion(t, q, omega)
    searches = [(constraint.margins, 0.0, constraint.drift, constraint.window) for constraint in constraints]
    together = searches_between_samples(motion, searches)
    alone = [search_between_samples(motion, *search) for search in searches]
    for (times, values), (times_alone, values_alone) in zip(together, alone, strict=True):
        np.testing.assert_array_equal(times, times_alone)
        np.testing.assert_array_equal(values, values_alone)
    scores = scores_between_samples(constraints, t, q, omega, motion)
    assert scores == [constraint.score_between_samples(t, q, omega, motion) for constraint in constraints]
    assert not scores[0].met and scores[1].met is False and scores[3].min_margin_deg is None
    # the tumbles: more lower-value candidates than MIN_SEARCHES each (what the per-search cap is for)
    for constraint in constraints[4:]:
        values = constraint.margins(t, motion.unit)
        assert np.sum(values[:-1] - 0.5 * motion.rate_bound * np.diff(t) < np.min(values)) > MIN_SEARCHES
