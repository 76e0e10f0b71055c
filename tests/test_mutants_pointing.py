"""The work limit of the search between samples (``ocp.geometry.pointing.MAX_SUB_GRID``) on a
motion of two speeds, against what the limit promises: a sub-grid cut coarser holds at most the
limit's points, and ``missable_s`` is at least every step of it (a crossing shorter than it may be
missed, so no longer step may be left).

The motion: a turn about z at 50 rad/s for 5 s, then at 0.01 rad/s for 5 s, sampled every 10 ms
(500 intervals each). The value searched is a constant ``C`` = 1e-4 against a threshold of 0: the
bound (the rate times the length, halved) lets every group of samples cross it (a slow group of 16
intervals: 16 × 1e-4 / 2 = 8e-4 > C), so every interval is opened and cut at FINE_STEP = 8.7e-4 rad:
573 steps (0.5 rad) a fast interval, the minimum 4 a slow one; 288 500 steps in all (hand count:
500 × 573 + 500 × 4, and the interval at the change of speed, cut by its faster end). A slow
interval kept whole cannot cross (1e-4 × 0.01 / 2 = 5e-5 < C): the zooms leave it alone, and the
search's ``missable_s`` is its sub-grid's (the fast brackets the zooms leave are shorter).
"""
from __future__ import annotations

import numpy as np
import pytest

from ocp.geometry import pointing
from ocp.geometry.pointing import HermiteMotion, search_between_samples

FAST, SLOW, DT, C = 50.0, 0.01, 0.01, 1e-4


def two_speeds() -> HermiteMotion:
    t = np.round(np.arange(0.0, 10.0 + 0.5 * DT, DT), 12)
    rate = np.where(t < 5.0, FAST, SLOW)
    angle = np.where(t < 5.0, FAST * t, FAST * 5.0 + SLOW * (t - 5.0))
    q = np.stack([np.cos(angle / 2), 0 * t, 0 * t, np.sin(angle / 2)], axis=-1)
    omega = np.stack([0 * t, 0 * t, rate], axis=-1)
    return HermiteMotion(t, q, omega)


def sub_grid(limit: int, monkeypatch) -> tuple[np.ndarray, float]:
    """The points of the first two evaluations (the heads, then the sub-grid's other points) and the
    search's ``missable_s`` under a work limit of ``limit``."""
    monkeypatch.setattr(pointing, "MAX_SUB_GRID", limit)
    calls: list[np.ndarray] = []

    def constant(times: np.ndarray, attitudes: np.ndarray) -> np.ndarray:
        calls.append(np.array(times, dtype=float))
        return np.full(len(times), C)

    found = search_between_samples(two_speeds(), constant, 0.0)
    return np.sort(np.concatenate(calls[:2])), found.missable_s


def test_the_motion_needs_more_than_the_limits_used_here(monkeypatch):
    """The control: with the module's limit the sub-grid is the full one (the hand count above,
    within the interval at the change of speed), every interval opened."""
    motion = two_speeds()
    assert int(motion.sample_steps[2].sum()) == pytest.approx(500 * 573 + 500 * 4, abs=600)
    grid, _ = sub_grid(pointing.MAX_SUB_GRID, monkeypatch)
    assert grid.size == int(motion.sample_steps[2].sum()) + 1


@pytest.mark.parametrize("limit", [5_300, 20_000])
def test_a_sub_grid_cut_coarser_holds_at_most_the_limit(limit, monkeypatch):
    """Past the limit every opened interval is cut in one ratio but into one step at least: the 500
    slow intervals keep one step each, and the fast ones share the rest, so the sub-grid's points
    (its steps and the last sample) stay within the limit plus one."""
    grid, missable = sub_grid(limit, monkeypatch)
    assert missable > 0.0
    assert grid.size <= limit + 1


@pytest.mark.parametrize("limit", [5_300, 20_000])
def test_missable_is_the_longest_step_of_the_coarser_sub_grid(limit, monkeypatch):
    """A slow interval cut into 4 × ratio < 1 steps keeps one: a whole sample interval, 10 ms, is one
    step of the sub-grid, the longest. A crossing that short may be missed, so ``missable_s`` is
    10 ms, and at least every gap between the sub-grid's points."""
    grid, missable = sub_grid(limit, monkeypatch)
    assert missable == pytest.approx(DT, rel=1e-9)
    assert missable >= np.max(np.diff(grid)) * (1.0 - 1e-9)


def test_a_zoom_past_its_limit_searches_its_deepest_brackets_and_says_how_long_the_others_are(monkeypatch):
    """A zoom past the work limit goes on by the brackets whose bound falls deepest below the
    threshold, and ``missable_s`` is the longest bracket it leaves.

    A body at rest sampled every 1 s over [0, 100] s, then every 0.5 s to 150 s; the value, allowed
    to change at D = 1 per s (``drift``; the attitude does not move), is 0.05, but −1 over
    [20, 30] s (a long violation: the least value, so the search for a lower one stays there) and a
    V of depth 0.01 at 60.3 s (below 0 for 10 ms either side). Every interval may cross 0 (its bound
    0.5 D h > 0.05) and is cut into 4 steps: 0.25 s, then 0.125 s. A step whose ends are at 0.05
    may hide a crossing (0.05 − D s / 2 < 0): 0.05 − 0.125 = −0.075 on the first part, −0.0125 on
    the second; the step (60.25, 60.5) holding the V, with ends 0.04 and 0.05, is the deepest:
    0.045 − 0.125 = −0.08. Under a limit of 63 × (64 + 20) points a zoom searches 20 such brackets:
    the V is found, and the brackets left include steps of 0.25 s."""
    monkeypatch.setattr(pointing, "MAX_SUB_GRID", 63 * (64 + 20))
    t = np.concatenate([np.arange(0.0, 100.0, 1.0), np.arange(100.0, 150.0 + 0.25, 0.5)])
    motion = HermiteMotion(t, np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1)), np.zeros((t.size, 3)))

    def value(times: np.ndarray, attitudes: np.ndarray) -> np.ndarray:
        to_violation = np.maximum(np.maximum(20.0 - times, times - 30.0), 0.0)
        return np.minimum.reduce([np.full(times.shape, 0.05), to_violation - 1.0, np.abs(times - 60.3) - 0.01])

    times, values = found = search_between_samples(motion, value, 0.0, drift=1.0)
    assert found.missable_s == pytest.approx(0.25, rel=1e-12)
    inside = (times > 60.25) & (times < 60.5)
    assert np.min(values[inside]) < 0.0  # the V, 10 ms either side of 60.3 s
    assert np.min(values) == -1.0
