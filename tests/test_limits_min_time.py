"""Minimum time and bang profiles need bounded actuators: without a bound the optimum takes no time.

With the default ``wheels: {}`` (no ``max_torque``) collocation's ``min_time`` returned ok with
T = 0.12 s and 5.9e5 N m, and eigenaxis's bang profiles ended in a non-finite simulation.
"""
import numpy as np
import pytest
import yaml

from ocp import Magnetorquers, ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from scenarios.errors import ScenarioError
from scenarios.schema.loader import parse_scenario

INERTIA = np.diag([19.5, 19.0, 12.6])
TARGET = np.array([0.7071068, 0.4082483, 0.4082483, 0.4082483])


def problem(spacecraft, **extra):
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), TARGET, 120.0, omegaf=np.zeros(3), **extra)


UNBOUNDED = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes())
BOUNDED = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1))


@pytest.mark.parametrize("profile", ["trapezoidal", "min_time"])
def test_eigenaxis_bang_profiles_refuse_unbounded_wheels(profile):
    planner = PLANNERS["eigenaxis"]({"profile": profile})
    error = planner.problem_error(problem(UNBOUNDED))
    assert error is not None and f"profile {profile}" in error and "spacecraft.wheels.max_torque" in error
    assert planner.plan(problem(UNBOUNDED)).status == "failed"
    # a rate bound caps the coast, not the acceleration: still refused
    assert planner.problem_error(problem(UNBOUNDED, max_rate=0.05)) is not None
    assert planner.problem_error(problem(BOUNDED)) is None


def test_eigenaxis_unbounded_torquers_count_only_where_the_allocation_gives_them_the_torque():
    """Beside three body-axis wheels the allocation never asks the torquers: their missing bound is
    no reason, and the min time about a principal axis is the wheels' closed form 2 sqrt(Θ I / g).
    Beside two wheels (x, y) a slew about z puts all its torque on the unbounded torquers: refused,
    naming them; about x the wheel bounds it (the same closed form); about a generic axis the
    wheels' rows bound it too."""
    planner = PLANNERS["eigenaxis"]({"profile": "min_time"})
    about = {axis: quat.from_axis_angle(np.eye(3)[i], np.deg2rad(60.0)) for i, axis in enumerate("xyz")}
    three = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1), torquers=Torquers())
    for axis, i in (("x", 0), ("z", 2)):
        slew = ManeuverProblem(three, quat.IDENTITY, np.zeros(3), about[axis], 120.0, omegaf=np.zeros(3))
        assert planner.problem_error(slew) is None
        assert planner.plan(slew).duration == pytest.approx(2 * np.sqrt(np.deg2rad(60.0) * INERTIA[i, i] / 0.1),
                                                            rel=1e-9)
    two = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(2, max_torque=0.1), torquers=Torquers())
    error = planner.problem_error(ManeuverProblem(two, quat.IDENTITY, np.zeros(3), about["z"], 120.0,
                                                  omegaf=np.zeros(3)))
    assert error is not None and "spacecraft.torquers.max_torque" in error and "wheels" not in error
    slew = ManeuverProblem(two, quat.IDENTITY, np.zeros(3), about["x"], 120.0, omegaf=np.zeros(3))
    assert planner.problem_error(slew) is None
    assert planner.plan(slew).duration == pytest.approx(2 * np.sqrt(np.deg2rad(60.0) * INERTIA[0, 0] / 0.1), rel=1e-9)
    generic = planner.plan(problem(two))
    assert generic.status == "ok" and 0 < generic.duration < np.inf
    # the quintic's T is the scenario's: it needs no torque bound
    assert PLANNERS["eigenaxis"]({"profile": "smooth"}).problem_error(problem(UNBOUNDED)) is None


@pytest.mark.parametrize("options", [{"objective": "min_time"}, {"objective": "min_l1"},
                                     {"objective": "weighted", "energy_weight": 0.0, "l1_weight": 1.0, "time_weight": 1.0},
                                     {"objective": "weighted", "energy_weight": 0.0, "time_weight": 1.0},
                                     {"objective": "weighted", "energy_weight": 0.0, "l1_weight": 1.0}])
def test_collocation_without_an_energy_term_refuses_unbounded_controls(options):
    """Time or L1 alone: impulses (min_l1 at fixed T on unbounded wheels: peak torque 0.112, 0.223,
    0.444 N m on 10, 20, 40 intervals, doubling with the mesh)."""
    planner = PLANNERS["collocation"](options)
    error = planner.problem_error(problem(UNBOUNDED))
    assert error is not None and "spacecraft.wheels.max_torque" in error and "without an energy term" in error
    reference = planner.plan(problem(UNBOUNDED))
    assert reference.status == "failed" and reference.message == error
    assert planner.problem_error(problem(BOUNDED)) is None


def test_collocation_names_unbounded_magnetorquers():
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels.from_body_axes(max_torque=0.1), magnetorquers=Magnetorquers())
    error = PLANNERS["collocation"]({"objective": "min_time"}).problem_error(problem(spacecraft))
    assert error is not None and "spacecraft.magnetorquers.max_dipole" in error and "wheels" not in error


@pytest.mark.parametrize("options", [{"objective": "min_energy"}, {"objective": "weighted", "time_weight": 1.0}])
def test_collocation_with_an_energy_term_takes_unbounded_controls(options):
    # ∫‖u‖² prices the torque: energy + time has a finite optimum (T = 12.75 s on 10 and on 20
    # intervals for this slew, peak 1.0 N m), so it is not refused
    assert PLANNERS["collocation"](options).problem_error(problem(UNBOUNDED)) is None


def test_the_loader_reports_the_refusal_at_the_planner_entry():
    data = yaml.safe_load("""
name: mintime_unbounded
spacecraft: {inertia: [19.5, 19.0, 12.6], wheels: {}}
maneuver:
  duration: 120.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.7071068, 0.4082483, 0.4082483, 0.4082483], omega: [0, 0, 0]}
planners:
- {name: eigenaxis}
- {name: collocation, options: {objective: min_time, intervals: 10}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.06, kd: 0.48}}
simulation: {sample_time: 0.5}
""")
    with pytest.raises(ScenarioError, match=r"planners\[1\].*spacecraft\.wheels\.max_torque"):
        parse_scenario(data)
