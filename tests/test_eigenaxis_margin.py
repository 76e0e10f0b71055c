"""The eigenaxis bang profiles keep the scenario's actuator margin (``requirements.actuators.margin``).

A scenario with a margin ``m`` asks every reference for at most ``1 − m`` of each torque and
momentum limit. The bang profiles (``trapezoidal``, ``min_time``) plan within it; the quintic's
torque is fixed by T and does not. Oracles: the closed-form minimum time of a rest-to-rest
bang-coast-bang about a principal axis, ``T = Θ / w + w / α`` with ``α = (1 − m) u_max / J`` and the
coast rate ``w`` the smaller of ``sqrt(Θ α)`` (a triangle) and ``(1 − m) h_max / J`` (the wheel's
momentum ``J θ̇`` at its share of the limit); and the scenario's own scoring of the row.
"""
import numpy as np
import pytest
import yaml

from ocp import ReactionWheels, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from planners.eigenaxis import EigenaxisPlanner
from scenarios.runner import run
from scenarios.schema.loader import parse_scenario


def _torquers(margin):
    return ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([1, 0, 0], np.pi), 10.0, omegaf=np.zeros(3), actuator_margin=margin)


@pytest.mark.parametrize("margin", [None, 0.1, 0.3])
def test_min_time_on_torquers_scales_with_the_kept_share(margin):
    keep = 1.0 - (margin or 0.0)
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(_torquers(margin))
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(2 * np.sqrt(np.pi / keep), rel=1e-12)  # a triangle: 2 sqrt(Θ / α)
    peak = np.max(np.abs(reference.sample(np.linspace(0.0, reference.duration, 2001)).torque))
    assert peak == pytest.approx(keep, rel=1e-12)


@pytest.mark.parametrize("margin", [0.0, 0.2])
def test_min_time_on_wheels_keeps_the_share_of_torque_and_momentum(margin):
    J, u_max, h_max, angle = 4.0, 0.1, 0.05, np.deg2rad(90.0)
    wheels = ReactionWheels(np.eye(3), max_torque=u_max, max_momentum=h_max)
    problem = ManeuverProblem(Spacecraft([J, 5.0, 6.0], wheels=wheels), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 0, 0], angle), 200.0, omegaf=np.zeros(3), actuator_margin=margin)
    keep = 1.0 - margin
    alpha, w = keep * u_max / J, keep * h_max / J
    assert w < np.sqrt(angle * alpha)  # not vacuous: the momentum caps the coast
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(problem)
    assert reference.ok, reference.message
    assert reference.duration == pytest.approx(angle / w + w / alpha, rel=1e-9)
    sample = reference.sample(np.linspace(0.0, reference.duration, 4001))
    assert np.max(np.abs(sample.torque[:, 0])) == pytest.approx(keep * u_max, rel=1e-9)
    assert np.max(np.abs(J * sample.omega[:, 0])) == pytest.approx(keep * h_max, rel=1e-9)  # wheel: −J θ̇


def test_honoured_by_the_bang_profiles_only():
    honoured = {p: EigenaxisPlanner.honoured(EigenaxisPlanner({"profile": p}).options)
                for p in ("smooth", "trapezoidal", "min_time")}
    assert honoured == {"smooth": {"rate"}, "trapezoidal": {"rate", "actuators"}, "min_time": {"rate", "actuators"}}


SCENARIO = """
name: eigenaxis-margin
spacecraft:
  inertia: [4.0, 5.0, 6.0]
  wheels: {max_torque: 0.1, max_momentum: 0.05}
maneuver:
  duration: 200.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: {axis_angle: {axis: [1, 0, 0], angle_deg: 90}}, omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: min_time, options: {profile: min_time}}
controller: {name: augmented_quaternion_feedback}
simulation: {sample_time: 0.1, duration: 120.0}
requirements:
  actuators: {margin: 0.2}
"""


def test_the_scenario_scores_the_min_time_row_within_its_margin():
    # before: the profile used the full limits and the row was violated (its reference asked 1.25 x
    # the 80 % share of the momentum limit) in every scenario with a margin
    scenario = parse_scenario(yaml.safe_load(SCENARIO))
    results = run(scenario)
    row = results.rows[0]
    assert row.reference.ok, row.reference.message
    assert row.reference.duration == pytest.approx(np.pi / 2 / (0.8 * 0.05 / 4.0) + (0.8 * 0.05 / 4.0) / (0.8 * 0.1 / 4.0),
                                                   rel=1e-9)
    assert row.status == "ok", row.message
