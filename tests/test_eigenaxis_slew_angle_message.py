"""The eigenaxis planner's 'T is shorter than the minimum time' states the slew it timed: with a
point-form target the final attitude is evaluated at T, so a shorter T is another slew, and a
minimum time without its angle read as the scenario's own."""
import numpy as np

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem


def test_the_minimum_time_message_states_the_slew_angle():
    spacecraft = Spacecraft([19.5, 19.0, 12.6], torquers=Torquers(max_torque=0.1))
    for degrees in (37.5, 120.0):  # about the y axis, written by hand
        target = quat.from_axis_angle([0, 1, 0], np.deg2rad(degrees))
        problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), target, 2.0)
        reference = PLANNERS["eigenaxis"]({"profile": "trapezoidal"}).plan(problem)
        assert reference.status == "infeasible"
        assert f"for its slew of {degrees:g} deg to the final attitude" in reference.message, reference.message
