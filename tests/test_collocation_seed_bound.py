"""Collocation's minimum time against a feasible slew of the same problem (the seed bound).

A user's slew table (2026-12-02): a 4-wheel pyramid (54.74 deg, wheel 0 failed, 0.01 N m and
0.05 N m s per wheel, a 5 % actuator margin), 90 deg about [0.9045, 0, 0.4264]: collocation's
minimum time 81.38 s, unflagged, where the eigenaxis bang-coast-bang within the same bounds takes
78.27 s. The planner must not return such an answer without saying so.
"""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem

MARGIN = 0.05
MAX_MOMENTUM = 0.05
INERTIA = np.diag([2.0, 2.5, 3.0])
AXES = np.array([[0.81650, 0.0, 0.57735], [0.0, 0.81650, 0.57735], [-0.81650, 0.0, 0.57735],
                 [0.0, -0.81650, 0.57735]]).T


def pyramid_problem():
    wheels = ReactionWheels(AXES, max_torque=0.01, max_momentum=MAX_MOMENTUM, failed=[0])
    axis = np.array([0.9045347990869904, 0.0, 0.4263998091470701])
    return ManeuverProblem(Spacecraft(INERTIA, wheels=wheels), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle(axis, np.deg2rad(90.0)), 150.0, omegaf=np.zeros(3),
                           actuator_margin=MARGIN)


def bilimoria_wie_problem():
    return ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([1, 0, 0], np.pi), 10.0, omegaf=np.zeros(3))


def feasible_eigenaxis(problem):
    """The eigenaxis bang-coast-bang within the margin (the planner keeps ``1 − actuator_margin``
    of every limit), checked here: the working wheels' torques ``g = −A_w⁺ I ω̇`` and momenta (the
    conserved zero total: ``h = −A_w⁺ I ω``) within (1 − margin) of their bounds."""
    keep = 1.0 - MARGIN
    slew = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(problem)
    assert slew.ok, slew.message
    t = np.linspace(0.0, slew.duration, 2001)
    sample = slew.sample(t)
    working = AXES.copy()
    working[:, 0] = 0.0
    inverse = np.linalg.pinv(working)
    momenta = -(sample.omega @ INERTIA.T) @ inverse.T
    torques = -(sample.omega_dot @ INERTIA.T) @ inverse.T  # I ω̇ + ω × H with H = 0: no gyroscopic term
    assert np.max(np.abs(momenta)) <= keep * MAX_MOMENTUM * (1 + 1e-9)
    assert np.max(np.abs(torques)) <= keep * 0.01 * (1 + 1e-9)
    return slew


def test_minimum_time_is_not_silently_slower_than_a_feasible_eigenaxis_slew():
    problem = pyramid_problem()
    bound = feasible_eigenaxis(problem)
    assert bound.duration == pytest.approx(78.27, abs=0.01)
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert reference.ok, reference.message
    if reference.duration > bound.duration * (1 + 1e-6):
        # then it must say so, in the message and the certificate, naming the faster slew
        assert "slower than a feasible slew of this problem" in reference.message
        assert "not the best known" in reference.stats["certificate"]["summary"]
        record = reference.stats["seed_bound"]
        assert record["resolved"] and record["met"] is False
        assert record["bound_s"] == pytest.approx(bound.duration, rel=1e-9)


def test_the_full_limit_eigenaxis_is_no_bound_under_a_margin():
    # The eigenaxis at the full limits (74.6 s) uses the whole momentum: not a slew of the problem
    # with a 5 % margin, so its duration bounds nothing; the derated one is feasible.
    from dataclasses import replace

    from planners.collocation.certificate import start_violations
    from planners.collocation.problem import variable_bounds
    problem = pyramid_problem()
    bounds = variable_bounds(problem, None, 1.0 - MARGIN)
    full = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(replace(problem, actuator_margin=None))
    assert full.duration == pytest.approx(74.61, abs=0.01)
    broken = start_violations(problem, full, bounds, None, (), 1001, 1e-6, 1e-6)
    assert broken["states"] == pytest.approx(1.0 / (1.0 - MARGIN) - 1.0, rel=1e-3)
    assert start_violations(problem, feasible_eigenaxis(problem), bounds, None, (), 1001, 1e-6, 1e-6) == {}


def test_no_extra_solve_when_the_optimum_beats_every_start():
    # Bilimoria & Wie: the optimum 3.2431 is below the eigenaxis minimum time 2 √π = 3.5449 and the
    # starts' durations: nothing is checked densely, nothing solved again.
    reference = PLANNERS["collocation"]({"objective": "min_time"}).plan(bilimoria_wie_problem())
    assert reference.duration == pytest.approx(3.2431, abs=2e-4)
    record = reference.stats["seed_bound"]
    assert record["resolved"] is False and "resolve" not in record
    assert {c["from"] for c in record["candidates"]} >= {"eigenaxis min_time"}
    eigenaxis = next(c for c in record["candidates"] if c["from"] == "eigenaxis min_time")
    assert eigenaxis["duration_s"] == pytest.approx(2.0 * np.sqrt(np.pi), rel=1e-9)
    assert all(c["checked"] == "not faster" for c in record["candidates"])
    assert "slower than a feasible" not in reference.message
