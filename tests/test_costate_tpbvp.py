"""Indirect minimum-energy planner: co-states against automatic differentiation, and the optimum
against the direct collocation planner (the cross-method oracle)."""
import casadi as ca
import numpy as np
import pytest

from ocp import CircularOrbit, Environment, Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from planners.costate_tpbvp import MinimumEnergySystem

INERTIA = [[10.0, 0.5, 0.2], [0.5, 8.0, 0.3], [0.2, 0.3, 6.0]]


def problem(gravity_gradient=False):
    environment = Environment(CircularOrbit(500e3, 0.9), gravity_gradient=True) if gravity_gradient else Environment()
    spacecraft = Spacecraft(INERTIA, torquers=Torquers(10.0))  # bounds far away: the unconstrained optimum
    return ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.normalize([0.3, 0.5, -0.6, 0.4]), 120.0,
                           omegaf=np.zeros(3), environment=environment)


def test_costate_equations_are_minus_the_gradient_of_the_hamiltonian(rng):
    system = MinimumEnergySystem(problem(gravity_gradient=True))
    t, y = ca.SX.sym("t"), ca.SX.sym("y", 14)
    gradient = ca.Function("dH", [t, y], [ca.gradient(system.hamiltonian(t, y), y)])
    for _ in range(20):
        point = np.r_[quat.random_unit(rng), rng.normal(0, 0.1, 3), rng.normal(0, 1, 7)]
        time = rng.uniform(0, 5000)
        rhs = system.rhs(time, point).full().ravel()
        dh = gradient(time, point).full().ravel()
        np.testing.assert_allclose(rhs[7:], -dh[:7], rtol=1e-10, atol=1e-14)   # λ̇ = −∂H/∂x
        np.testing.assert_allclose(rhs[:7], dh[7:], rtol=1e-10, atol=1e-14)    # ẋ = ∂H/∂λ


@pytest.mark.parametrize("gravity_gradient", [False, True])
def test_indirect_and_direct_minimum_energy_agree(gravity_gradient):
    case = problem(gravity_gradient)
    indirect = PLANNERS["costate_tpbvp"]().plan(case)
    direct = PLANNERS["collocation"]({"intervals": 50}).plan(case)
    assert indirect.status == direct.status == "ok", (indirect.message, direct.message)
    assert indirect.stats["int_u2"] == pytest.approx(direct.stats["objective"], rel=1e-3)
    assert np.rad2deg(quat.error_angle(indirect.q(120.0), case.qf)) < 1e-6
    t = np.linspace(0, 120, 61)
    assert np.max(quat.error_angle(indirect.q(t), direct.q(t))) < np.deg2rad(0.01)
