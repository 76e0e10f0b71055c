"""Solver statuses in the one solve path (:mod:`ocp.nlp.solve`): FATROP's integer return flags are named."""
import numpy as np
import pytest

from ocp import Spacecraft, Torquers, quat
from ocp.nlp.solve import FATROP_STATUS, status_name
from planners import PLANNERS, ManeuverProblem


def small_slew() -> ManeuverProblem:
    return ManeuverProblem(Spacecraft([12.0, 10.0, 8.0], torquers=Torquers(0.1)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([0.0, 0.6, 0.8], np.deg2rad(60.0)), 120.0, omegaf=np.zeros(3))


@pytest.mark.parametrize("max_iterations, converged", [(500, True), (2, False)])
def test_fatrop_starts_report_named_statuses(max_iterations, converged):
    reference = PLANNERS["collocation"]({"intervals": 10, "coarse_intervals": 0, "solver": "fatrop",
                                         "max_iterations": max_iterations}).plan(small_slew())
    expected = "Fatrop_Converged" if converged else "Fatrop_Stopped"
    assert reference.ok == converged
    assert set(reference.stats["solver_status"]) == {expected}
    assert expected in reference.message


def test_status_names():
    assert status_name({"return_status": "Solve_Succeeded"}) == "Solve_Succeeded"
    assert status_name({"return_status": 0}) == FATROP_STATUS[0]
    assert status_name({"return_status": np.int64(7)}) == "Fatrop_Flag_7"
    assert status_name({}) == "unknown"
