"""Limits a user's scenario can reach: the work of the search between samples, and a minimum time
asked under a bound below it.

Oracle of the search: a body spinning at a constant rate w about the inertial z axis points its
body x axis at azimuth φ(t) = w t + φ0 in the xy-plane; its angle θ to a direction at elevation e
above the inertial x axis obeys cos θ = cos e cos φ (closed form), so a keep-out cone of half-angle
α > e is entered for ``2 arccos(cos α / cos e) / w`` at each pass of φ through a whole turn, and the
least margin is e − α.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from ocp.geometry import pointing
from ocp.geometry.directions import Geometry
from ocp.geometry.pointing import FINE_STEP, HermiteMotion, search_between_samples
from scenarios.requirements.spec import Direction, PointingRequirement, Sensor

W, PHI0 = 50.0, 0.3  # [rad/s], [rad]
E, ALPHA = math.radians(5.0), math.radians(10.0)


def spin(duration: float, dt: float, rate: float = W) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Samples of the spin about z (attitude scalar first, body rate)."""
    t = np.arange(0.0, duration + 0.5 * dt, dt)
    half = 0.5 * (rate * t + PHI0)
    q = np.stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)], axis=-1)
    return t, q, np.tile([0.0, 0.0, rate], (t.size, 1))


def inside_time(duration: float) -> tuple[float, float]:
    """Closed form: the time inside the cone over [0, duration] and when it is first entered."""
    half = math.acos(math.cos(ALPHA) / math.cos(E)) / W
    turns = np.arange(1, int((W * duration + PHI0) / (2.0 * math.pi)) + 1)
    centres = (2.0 * math.pi * turns - PHI0) / W
    return float(np.sum(np.minimum(centres + half, duration) - np.maximum(centres - half, 0.0))), centres[0] - half


def keep_out(duration: float) -> pointing.PointingConstraint:
    requirement = PointingRequirement("x_out", Sensor("x_axis", np.array([1.0, 0.0, 0.0])), True, ALPHA,
                                      Direction(None, np.array([math.cos(E), 0.0, math.sin(E)])))
    return requirement.constraint(Geometry(None, None), duration)


def counted_margins(monkeypatch) -> list[int]:
    """The number of points of each margin evaluation of the pointing searches, from now on."""
    evaluated: list[int] = []
    original = pointing.PointingConstraint.margins

    def counted(self, times, attitudes):
        evaluated.append(len(np.atleast_1d(times)))
        return original(self, times, attitudes)

    monkeypatch.setattr(pointing.PointingConstraint, "margins", counted)
    return evaluated


def test_a_search_past_its_work_limit_is_coarser_says_so_and_still_finds_long_violations(monkeypatch) -> None:
    """10 s of a 50 rad/s spin sampled every 10 ms: its sub-grid at FINE_STEP would hold 8.2e4
    points near the cone. Under a work limit of 2e4 it is cut coarser (4x): the search evaluates
    at most the limit a stage, says how long a step of its sub-grid is, and every 6 ms pass through
    the cone, far longer than that step, is still found. Its time inside: each crossing is
    interpolated linearly on a step dφ = w dt < 5e-3 rad (dt < 1e-4 s), off by at most
    θ''/(8 θ') dφ² in φ (θ ≈ √(e² + φ²) near the cone: θ'' / θ' = e² / (α² √(α² − e²)) ≈ 1.65),
    1.1e-7 s a crossing, 1.8e-5 s over the 159 crossings."""
    limit = 20_000
    monkeypatch.setattr(pointing, "MAX_SUB_GRID", limit)
    t, q, omega = spin(10.0, 0.01)
    constraint = keep_out(10.0)
    evaluated = counted_margins(monkeypatch)
    score = constraint.score_between_samples(t, q, omega)
    inside, first = inside_time(10.0)
    assert score.missable_s > 0.0
    assert FINE_STEP / W < score.missable_s < 0.01  # coarser than FINE_STEP, finer than the samples
    assert score.missable_s < 2.0 * math.acos(math.cos(ALPHA) / math.cos(E)) / W  # a pass is longer
    assert score.min_margin_deg == pytest.approx(math.degrees(E - ALPHA), abs=1e-6)
    assert score.missable_s < 1e-4
    assert score.time_in_violation_s == pytest.approx(inside, abs=1.8e-5)
    assert score.first_violation_s == pytest.approx(first, abs=1.1e-7)
    assert sum(evaluated) <= t.size + limit + pointing.REFINE_LEVELS * limit


def test_below_the_work_limit_the_search_is_in_full_and_says_so() -> None:
    """The same spin with the module's limit: its sub-grid fits, nothing may be missed."""
    t, q, omega = spin(10.0, 0.01)
    score = keep_out(10.0).score_between_samples(t, q, omega)
    inside, _ = inside_time(10.0)
    assert score.missable_s == 0.0
    assert score.time_in_violation_s == pytest.approx(inside, rel=1e-5)


def test_a_unit_mix_up_rate_is_searched_within_the_work_limit(monkeypatch) -> None:
    """A 1e6 rad/s spin sampled every 0.1 s for 40 s (a user's initial rate in the wrong unit):
    the final error's search at FINE_STEP would need 4.6e10 points (a 128 GiB array). It must end,
    within the work limit, and say that a crossing shorter than its step may be missed."""
    t, q, omega = spin(40.0, 0.1, rate=1e6)
    motion = HermiteMotion(t, q, omega)
    evaluated = []

    def less_error(times: np.ndarray, attitudes: np.ndarray) -> np.ndarray:
        evaluated.append(len(times))
        return -2.0 * np.arccos(np.minimum(np.abs(attitudes[:, 0]), 1.0))

    times, values = found = search_between_samples(motion, less_error, -math.radians(0.1), edges=(25.0,))
    assert found.missable_s > 0.0
    assert sum(evaluated) <= t.size + 1 + pointing.MAX_SUB_GRID * (1 + pointing.REFINE_LEVELS)
    assert np.all(np.diff(times) >= 0.0) and -np.nanmin(values) <= math.pi + 1e-12


@pytest.mark.parametrize("alpha_deg, met", [(10.0, False), (4.0, True)])
def test_a_limited_search_is_said_in_the_row_met_or_not(monkeypatch, alpha_deg, met) -> None:
    """The limited search of the first test reaches the user: its caveat is the score's detail (after
    what breaks it, or alone when the cone is met: α = 4° < e = 5° is never entered) and the row's
    message."""
    from scenarios.output.results import Row
    from scenarios.requirements.scoring import _pointing
    from scenarios.runner import _judge

    monkeypatch.setattr(pointing, "MAX_SUB_GRID", 20_000)
    t, q, omega = spin(10.0, 0.01)
    requirement = PointingRequirement("x_out", Sensor("x_axis", np.array([1.0, 0.0, 0.0])), True,
                                      math.radians(alpha_deg), Direction(None, np.array([math.cos(E), 0.0, math.sin(E)])))
    constraint = requirement.constraint(Geometry(None, None), 10.0)
    score = _pointing(constraint, constraint.score_between_samples(t, q, omega))
    assert score.met == met
    assert "work limit" in score.detail and "may be missed" in score.detail
    row = Row("spin", "eigenaxis", "ok", "", None, None, None)
    _judge(row, {"reference": {"x_out": score}}, "")
    assert row.status == ("ok" if met else "violated")
    assert "work limit" in row.message and (("met, but" in row.message) == met)


HAND = """
name: hand-colloc
spacecraft: {inertia: [10.0, 10.0, 10.0], wheels: {max_torque: 0.1, max_momentum: 2.0}}
maneuver:
  duration: 15.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.7071067811865476, 0, 0, 0.7071067811865476], omega: [0, 0, 0]}
planners: [{name: collocation, options: {objective: min_time}}]
controller: {name: augmented_quaternion_feedback, options: {kp: 0.5, kd: 3.0}}
"""


def test_a_min_time_bound_below_the_minimum_time_says_so_and_names_a_feasible_duration() -> None:
    """A 10 kg m² sphere on three orthogonal wheels of 0.1 N m turned 90 deg at rest: the body's
    angular momentum changes no faster than the wheels' torque, √3 · 0.1 N m, and its rate is at
    most that momentum over 10 kg m², so a rest-to-rest turn by θ takes at least
    2 √(θ J / (√3 u)) = 19.05 s. Under a 15 s bound the solve must fail (not ok), and its message
    must say that maneuver.duration bounds the free final time and may be below the minimum time,
    and name the eigenaxis bang-bang slew, 2 √(θ J / u) = 25.066 s, as a feasible duration."""
    import yaml

    from planners import PLANNERS
    from scenarios.schema.loader import parse_scenario

    problem = parse_scenario(yaml.safe_load(HAND)).problem
    theta, inertia, torque = math.pi / 2.0, 10.0, 0.1
    assert 2.0 * math.sqrt(theta * inertia / (math.sqrt(3.0) * torque)) > problem.duration  # provably below
    reference = PLANNERS["collocation"]({"objective": "min_time", "intervals": 10, "coarse_intervals": 0,
                                        "max_iterations": 150}).plan(problem)
    assert not reference.ok
    message = reference.message
    assert "the final time is free and maneuver.duration = 15 s bounds it" in message
    assert "may be below the minimum time" in message
    eigenaxis = 2.0 * math.sqrt(theta * inertia / torque)
    assert f"eigenaxis min_time is a feasible slew of this problem in {eigenaxis:.6g} s" in message
    assert message.index("maneuver.duration = 15 s") < message.index("try ")  # the bound first


def test_the_feasible_duration_named_is_that_of_the_problems_own_rate_bound() -> None:
    """The same manoeuvre with its body rate bounded by 0.1 rad/s, below the bang-bang slew's
    coast rate √(θ u / J) = 0.125 rad/s: the eigenaxis slew then coasts at the bound, in
    θ / ω + ω J / u = 15.708 + 10 = 25.708 s (accelerating and braking at u / J), and that, not the
    unbounded 25.066 s, is the feasible duration named."""
    import yaml

    from planners import PLANNERS
    from scenarios.schema.loader import parse_scenario

    data = yaml.safe_load(HAND)
    data["maneuver"]["max_rate"] = 0.1
    problem = parse_scenario(data).problem
    assert math.sqrt(math.pi / 2.0 * 0.1 / 10.0) > 0.1
    reference = PLANNERS["collocation"]({"objective": "min_time", "intervals": 10, "coarse_intervals": 0,
                                        "max_iterations": 150}).plan(problem)
    assert not reference.ok
    assert "maneuver.duration = 15 s bounds it" in reference.message
    assert f"a feasible slew of this problem in {math.pi / 2.0 / 0.1 + 0.1 * 10.0 / 0.1:.6g} s" in reference.message


def test_a_long_graze_of_a_cone_edge_zooms_within_the_work_limit(monkeypatch) -> None:
    """A reviewer's case: a boresight 30° from the spin axis (1 rad/s about inertial z) keeps 30° from a
    keep-out direction along z, a cone of 29.99°: the margin is 0.01° throughout (closed form). The
    sub-grid fits the limit, but every bracket of it may hide a crossing, and the zooms into them
    went on without a limit (43 million points, out of memory, for 10 min of such a spin). With a
    limit of 1e5 (the sub-grid of 50 rad of turn, 5.7e4 points, fits it; its zooms do not): each zoom stays within it, the search says how
    long a violation it may have missed, and the margin is still the closed form's."""
    limit = 100_000
    monkeypatch.setattr(pointing, "MAX_SUB_GRID", limit)
    beta = math.radians(30.0)
    t = np.arange(0.0, 50.0 + 0.05, 0.1)
    q = np.stack([np.cos(t / 2), 0 * t, 0 * t, np.sin(t / 2)], axis=-1)
    omega = np.tile([0.0, 0.0, 1.0], (t.size, 1))
    requirement = PointingRequirement("z_out", Sensor("b", np.array([math.sin(beta), 0.0, math.cos(beta)])), True,
                                      beta - math.radians(0.01), Direction(None, np.array([0.0, 0.0, 1.0])))
    constraint = requirement.constraint(Geometry(None, None), 50.0)
    evaluated = counted_margins(monkeypatch)
    score = constraint.score_between_samples(t, q, omega)
    assert score.met and score.min_margin_deg == pytest.approx(0.01, abs=1e-9)
    assert score.missable_s > 0.0
    assert max(evaluated) <= limit + t.size


HUGE_RATE = """
name: huge-rate
spacecraft: {inertia: [10.0, 10.0, 10.0], wheels: {max_torque: 0.1, max_momentum: 2.0}}
maneuver:
  duration: 20.0
  initial: {q: [1, 0, 0, 0], omega: [999.0, 0, 0]}
  final: {q: [0.7071068, 0, 0, 0.7071068], omega: [0, 0, 0]}
planners: [{name: eigenaxis, options: {profile: smooth}}]
controller: {name: augmented_quaternion_feedback, options: {kp: 0.5, kd: 3.0}}
simulation: {sample_time: 0.1, duration: 40.0}
requirements: {final: {after_s: 5, error_deg: 0.1, rate: 0.001}}
"""


def test_a_unit_mix_up_rate_runs_and_its_final_error_search_says_it_was_limited(tmp_path) -> None:
    """A user's 1e6 rad/s initial rate (a unit mix-up) crashed the run (128 GiB); the loader now refuses
    rates beyond 1e3 rad/s, and at 999 rad/s the same work limit is met. It runs; the final
    requirement is broken (the body cannot stop such a spin: its error and rate are far off) and
    the row says that the error's search between samples reached its work limit."""
    from scenarios.runner import run
    from scenarios.schema.loader import load

    path = tmp_path / "huge.yaml"
    path.write_text(HUGE_RATE)
    row = run(load(path)).rows[0]
    assert row.status == "violated" and not row.requirements["closed_loop"]["final"]["met"]
    assert "final (closed loop)" in row.message
    assert "the error's search between samples reached its work limit" in row.message, row.message


def test_a_feasible_slew_within_the_bound_is_said_so_not_that_the_bound_may_be_too_low() -> None:
    """A reviewer's case: the same sphere under a 30 s bound, with a start ended locally infeasible.
    The eigenaxis bang-bang slew, 2 √(θ J / u) = 25.066 s (by hand), is feasible within 30 s: the
    bound is provably not below the minimum time, and the note must say that instead."""
    from types import SimpleNamespace

    import yaml

    from planners import PLANNERS
    from planners.collocation.planner import INFEASIBLE
    from scenarios.schema.loader import parse_scenario

    data = yaml.safe_load(HAND)
    data["maneuver"]["duration"] = 30.0
    problem = parse_scenario(data).problem
    planner = PLANNERS["collocation"]({"objective": "min_time"})
    failed = SimpleNamespace(starts=[SimpleNamespace(status=sorted(INFEASIBLE)[0], f=float("nan"))])
    note = planner._time_bound_note(problem, planner._ocp(problem), failed)
    assert "may be below the minimum time" not in note
    assert "within the bound" in note and f"{2.0 * math.sqrt(math.pi / 2.0 * 10.0 / 0.1):.6g} s" in note, note
