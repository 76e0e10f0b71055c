"""Planner timings on the papers' cases. Targets: spin extremal (issue 4) at most 10 ms median,
all multi-starts included, on the spin paper's case."""
import numpy as np
import pytest

from ocp import ReactionWheels, Spacecraft
from planners import PLANNERS, ManeuverProblem


@pytest.mark.parametrize("weight", [0.0, 3.9e-3, 0.1])
def test_spin_extremal_paper_case(benchmark, weight):
    # Spin paper, section V: I = [19.5, 19, 12.6] kg m², v = 0.2 rad/s, [1,0,0,0] -> [0,0,1,0], T = 200 s.
    spacecraft = Spacecraft([19.5, 19.0, 12.6], wheels=ReactionWheels.from_body_axes(max_torque=0.1))
    problem = ManeuverProblem(spacecraft, [1, 0, 0, 0], [0.2, 0, 0], [0, 0, 1, 0], 200.0)
    planner = PLANNERS["spin_extremal"]({"weight": weight})
    planner.plan(problem)  # builds the IPOPT solver once
    reference = benchmark(planner.plan, problem)
    assert reference.status == "ok"
    assert len(reference.stats["ipopt_status"]) == planner.options.starts
