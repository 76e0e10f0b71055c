"""A ``warm_start`` the user named that cannot plan the problem is said in the row's message (the
seed record alone kept it before): collocation starts from the seed planners instead."""
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem


def _problem(inertia):
    return ManeuverProblem(Spacecraft(inertia, torquers=Torquers(1.0)), quat.IDENTITY, np.array([0.1, 0.0, 0.0]),
                           quat.from_axis_angle([1, 1, 1], np.deg2rad(150)), 60.0)


@pytest.mark.parametrize("inertia, unused", [([[10, 0.5, 0.2], [0.5, 8, 0.3], [0.2, 0.3, 6]], True),
                                             ([10, 8, 6], False)], ids=["full", "principal"])
def test_an_unusable_warm_start_is_named_in_the_message(inertia, unused):
    problem = _problem(inertia)
    why = PLANNERS["spin_extremal"](None).start_error(problem)  # the warm-start planner's own verdict
    assert (why is not None) == unused
    reference = PLANNERS["collocation"]({"objective": "min_energy", "warm_start": "spin_extremal"}).plan(problem)
    assert reference.ok
    note = "the warm start 'spin_extremal' was not used"
    assert (note in reference.message) == unused, reference.message
    if unused:
        assert why in reference.message
