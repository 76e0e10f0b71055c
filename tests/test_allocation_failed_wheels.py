"""A failed wheel is asked exactly nothing by the allocation (not the pseudo-inverse's round-off).

A 4-wheel pyramid (54.74°) with wheel 1 failed: ``numpy.linalg.pinv`` of the working axes (the failed
column zeroed) leaves entries of about 1e-17 in the failed wheel's row, and the requirement scoring
turns any torque asked of a zero limit into "inf x its limit": before, every row of such a scenario
was violated and its slew table had no entry ok.
"""
from __future__ import annotations

import numpy as np

import scenarios
from controllers import CONTROLLERS
from ocp import Measurement, ReactionWheels, Spacecraft, quat

S, C = np.sqrt(2.0 / 3.0), np.sqrt(1.0 / 3.0)  # 54.74° from the z axis: unit axes
PYRAMID = [[S, 0.0, C], [0.0, S, C], [-S, 0.0, C], [0.0, -S, C]]


def test_the_failed_wheel_is_asked_exactly_zero_and_the_others_give_the_torque(rng):
    wheels = ReactionWheels(np.array(PYRAMID).T, max_torque=0.01, failed=(1,))
    spacecraft = Spacecraft([2.0, 2.5, 3.0], wheels=wheels)
    law = CONTROLLERS["augmented_quaternion_feedback"]({})
    law.reset(spacecraft, 0.1, target=(quat.IDENTITY, np.zeros(3)))
    working = np.array(PYRAMID)[[0, 2, 3]].T  # 3 independent axes: the split is unique
    for _ in range(20):
        torque = rng.normal(0.0, 0.005, 3)
        command = law.allocate(torque, Measurement(0.0, quat.IDENTITY, np.zeros(3), np.zeros(4), None))
        g = np.asarray(command.wheel_torque)
        assert g[1] == 0.0  # exactly: a zero limit forgives nothing
        np.testing.assert_allclose(-g[[0, 2, 3]], np.linalg.solve(working, torque), rtol=1e-12, atol=1e-18)


def test_a_pyramid_with_a_failed_wheel_plans_a_row_that_is_ok():
    data = {
        "name": "pyramid-failed-wheel",
        "spacecraft": {"inertia": [2.0, 2.5, 3.0],
                       "wheels": {"axes": PYRAMID, "max_torque": 0.01, "failed": [1]}},
        "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": {"axis_angle": {"axis": [0.3, -0.5, 0.8], "angle_deg": 110}},
                               "omega": [0, 0, 0]}},
        "planners": [{"name": "eigenaxis", "options": {"profile": "min_time"}}],
        "controller": {"name": "augmented_quaternion_feedback"},
        "simulation": {"sample_time": 0.1, "duration": 80.0},
        "requirements": {"actuators": {"margin": 0.0}},
    }
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    ratio = row.requirements["reference"]["actuators"]
    assert row.status == "ok", (row.message, ratio)
