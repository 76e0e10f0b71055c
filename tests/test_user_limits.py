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
    evaluated = []
    original = pointing.PointingConstraint.margins

    def counted(self, times, attitudes):
        evaluated.append(len(np.atleast_1d(times)))
        return original(self, times, attitudes)

    monkeypatch.setattr(pointing.PointingConstraint, "margins", counted)
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
