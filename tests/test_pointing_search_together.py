"""A row's pointing searches evaluated together: each search exactly as alone, bit for bit.

:func:`ocp.geometry.pointing.scores_between_samples` finds the heads and sub-grids of a row's
searches in one array and evaluates the moving constraints' margins in one pass (their direction
tables end to end, each point looked up in its own). The oracle is each constraint alone: its own
:meth:`~ocp.geometry.pointing.PointingConstraint.margins` on the same points, and its own
:meth:`~ocp.geometry.pointing.PointingConstraint.score_between_samples` (one search, evaluated by its
own margins). The constraints differ in everything the pass indexes per point: tables of 2, 5 and
13 rows on different times (one starting after the run starts, one ending before it ends: held
values), a growth, a keep-in, windows inside the run and past it, and a fixed direction among them.
"""
from __future__ import annotations

import math

import numpy as np

from ocp.geometry.pointing import (
    HermiteMotion,
    PointingConstraint,
    _margins_together,
    scores_between_samples,
    search_between_samples,
    searches_between_samples,
)


def tumble() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A 0.2 rad/s tumble about z with a slow nod about x, sampled every 0.1 s for 120 s (0.02 rad a step:
    groups of a few samples between heads)."""
    t = np.arange(0.0, 120.0, 0.1)
    half = 0.5 * 0.2 * t
    nod = 0.5 * 0.3 * np.sin(0.05 * t)
    q = np.stack([np.cos(half) * np.cos(nod), np.cos(half) * np.sin(nod), -np.sin(half) * np.sin(nod),
                  np.sin(half) * np.cos(nod)], axis=-1)
    omega = np.column_stack([0.3 * 0.025 * np.cos(0.05 * t), np.zeros_like(t), np.full(t.size, 0.2)])
    return t, q, omega


def swinging(count: int, start: float, end: float, tilt: float) -> tuple[np.ndarray, np.ndarray]:
    """A direction table of ``count`` rows from ``start`` to ``end`` [s], swinging about the y axis."""
    times = np.linspace(start, end, count)
    angle = tilt + 0.01 * times
    return times, np.column_stack([np.cos(angle), np.zeros(count), np.sin(angle)])


def constraints() -> list[PointingConstraint]:
    sun_t, sun = swinging(2, 0.0, 200.0, 0.2)
    moon_t, moon = swinging(13, 10.0, 90.0, -0.4)  # starts after the run, ends before it: held
    limb_t, limb = swinging(5, -5.0, 130.0, 1.2)
    return [
        PointingConstraint("sun", [1.0, 0.0, 0.0], True, math.radians(20.0), sun_t, sun),
        PointingConstraint("moon", [0.0, 1.0, 0.3], True, math.radians(15.0), moon_t, moon, window=(12.25, 87.3)),
        PointingConstraint("fixed", [0.0, 0.0, 1.0], True, math.radians(30.0), directions=[[0.0, 1.0, 0.0]]),
        PointingConstraint("limb", [1.0, 0.2, 0.0], True, math.radians(10.0), limb_t, limb,
                           growth=np.linspace(0.3, 0.35, 5)),
        PointingConstraint("kept_in", [0.0, 0.0, 1.0], False, math.radians(40.0), sun_t, sun[:, [2, 1, 0]]),
        PointingConstraint("after", [1.0, 0.0, 0.0], True, math.radians(5.0), limb_t, limb, window=(500.0, 600.0)),
    ]


def test_the_margins_together_are_each_constraints_own_bit_for_bit() -> None:
    t, q, omega = tumble()
    motion = HermiteMotion(t, q, omega)
    rng = np.random.default_rng(7)
    every = constraints()
    sizes = [17, 0, 40, 333, 1, 64]  # one constraint without a point
    points = [np.sort(rng.uniform(-3.0, 125.0, size)) for size in sizes]
    times = np.concatenate(points)
    attitudes = motion.attitudes(times)
    bounds = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)
    values = _margins_together(every)(bounds, times, attitudes)
    for index, constraint in enumerate(every):
        span = slice(bounds[index], bounds[index + 1])
        alone = constraint.margins(times[span], attitudes[span])
        assert values[span].tobytes() == alone.tobytes(), constraint.name
    # the window past the run: no value; the sun's whole-run window: a value from t = 0 on
    assert np.isnan(values[bounds[5]:]).all() and np.isfinite(values[:bounds[1]][points[0] >= 0.0]).all()


def test_a_rows_searches_together_are_each_constraints_search_alone() -> None:
    t, q, omega = tumble()
    motion = HermiteMotion(t, q, omega)
    every = constraints()
    searches = [(constraint.margins, 0.0, constraint.drift, constraint.window) for constraint in every]
    together = searches_between_samples(motion, searches, _margins_together(every))
    alone = [search_between_samples(motion, *search) for search in searches]
    for (times, values), (times_alone, values_alone) in zip(together, alone, strict=True):
        assert times.tobytes() == times_alone.tobytes()
        assert values.tobytes() == values_alone.tobytes()
    scores = scores_between_samples(every, t, q, omega, motion)
    assert scores == [constraint.score_between_samples(t, q, omega, motion) for constraint in every]
    # what the case covers: crossings between samples, met constraints, a window past the run
    assert not scores[0].met and scores[0].time_in_violation_s > 0.0
    assert any(score.met and score.min_margin_deg is not None for score in scores)
    assert scores[5].min_margin_deg is None
