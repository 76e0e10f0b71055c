"""Gaps the mutation check found in how a planner gives a start to another method
(:meth:`planners.base.Planner.plan_start`, :meth:`~planners.base.Planner.start_error`).

Oracle: the rest-to-rest quintic about the eigenaxis peaks at ``15 Θ / (8 T)`` mid-slew (its
closed form): above the problem's rate bound it is infeasible as a row, yet it is the start.
"""
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

SPACECRAFT = Spacecraft(np.diag([10.0, 8.0, 6.0]), torquers=Torquers(0.1))
ANGLE, T = 2.0, 100.0  # 15 Θ / (8 T) = 0.0375 rad/s


def _problem(max_rate=None, qf=True):
    return ManeuverProblem(SPACECRAFT, quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([1.0, 1.0, 0.0], ANGLE) if qf else None, T, omegaf=np.zeros(3),
                           max_rate=max_rate)


def test_a_start_is_planned_without_the_rate_bound_that_stops_the_row():
    bounded = _problem(max_rate=0.03)
    planner = PLANNERS["eigenaxis"]({"profile": "smooth"})
    assert planner.plan(bounded).status == "infeasible"
    start = planner.plan_start(bounded)
    assert start.ok, start.message
    peak = np.max(np.linalg.norm(start.sample(np.linspace(0.0, T, 2001)).omega, axis=1))
    assert peak == pytest.approx(15 * ANGLE / (8 * T), rel=1e-9)  # the quintic, above the bound 0.03
    within = planner.plan_start(_problem(max_rate=0.04))  # within the bound: the row's own plan
    assert within.ok and np.max(np.linalg.norm(within.sample(np.linspace(0.0, T, 2001)).omega, axis=1)) <= 0.04


def test_a_start_is_refused_for_what_the_row_is_refused_by_default():
    planner = PLANNERS["eigenaxis"]({"profile": "smooth"})
    free = _problem(qf=False)
    assert planner.start_error(free) == planner.problem_error(free)
    assert "maneuver.final.q" in planner.start_error(free)
    assert planner.start_error(_problem()) is None
