"""What an optimal-control problem asks for (:class:`ocp.transcription.OptimalControlProblem`), by hand:
the running cost ``energy_weight ‖τ‖² + l1_weight Σ slack`` with torquers (τ = u), and the rate-norm
path constraint ``‖ω‖² / max_rate² − 1``."""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocp import AttitudeModel, Spacecraft, Torquers
from ocp.transcription import OptimalControlProblem


@pytest.mark.parametrize("energy_weight, l1_weight", [(1.0, 0.0), (0.5, 0.3), (0.0, 2.5)])
def test_the_stage_cost_weighs_the_energy_and_the_l1_slacks(energy_weight, l1_weight):
    model = AttitudeModel(Spacecraft(np.diag([10.0, 8.0, 6.0]), torquers=Torquers(1.0)))
    problem = OptimalControlProblem(model, energy_weight=energy_weight, l1_weight=l1_weight)
    u, slack = np.array([0.2, -0.3, 0.6]), np.array([0.25, 0.35, 0.65])
    x = np.r_[1.0, 0.0, 0.0, 0.0, 0.01, 0.02, -0.03, np.zeros(model.nx - 7)]
    cost = float(ca.evalf(problem.stage_cost(ca.DM(x), ca.DM(u), 0.0, ca.DM(slack) if l1_weight else None)))
    assert cost == pytest.approx(energy_weight * (0.04 + 0.09 + 0.36) + l1_weight * 1.25, rel=1e-14)


def test_the_rate_norm_constraint_is_zero_on_the_bound_and_scales_with_its_square():
    model = AttitudeModel(Spacecraft(np.diag([10.0, 8.0, 6.0]), torquers=Torquers(1.0)))
    problem = OptimalControlProblem(model, max_rate=0.02)
    for omega, expected in (([0.012, 0.0, 0.016], 0.0), ([0.0, 0.01, 0.0], -0.75), ([0.0, 0.0, 0.04], 3.0)):
        x = ca.DM(np.r_[1.0, 0.0, 0.0, 0.0, omega, np.zeros(model.nx - 7)])
        (g,) = problem.path_constraints(x, 0.0)
        assert float(ca.evalf(g)) == pytest.approx(expected, abs=1e-12)
