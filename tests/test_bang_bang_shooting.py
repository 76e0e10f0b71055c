"""The switch-time shooting's Jacobian by forward sensitivities along the RK4 steps
(``planners.collocation.certificate._shooting`` with as many arcs as final conditions or fewer) is
CasADi's own Jacobian of the same flight bit for bit, so that ``time_error``'s Newton iterates, and
with them the shot optimum ``T`` a plan returns, do not move by one rounding.

Oracles, independent of the code under test: ``casadi.jacobian`` (forward mode) of
``_flight``'s final miss, the function the shooting used before its sensitivities were written out,
evaluated by CasADi's own call; and central differences of that flight (to 1e-6).
"""
import casadi as ca
import numpy as np
import pytest

import planners.collocation.certificate as certificate
from ocp import Spacecraft, Torquers, quat
from ocp.fast_call import buffered
from planners import ManeuverProblem

INERTIAS = {"unit": [1.0, 1.0, 1.0], "full": [[10, 0.5, 0.2], [0.5, 8, 0.3], [0.2, 0.3, 6]]}


def model_of(inertia):
    return ManeuverProblem(Spacecraft(INERTIAS[inertia], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle([1, 1, 1], 2.5), 10.0, omegaf=np.zeros(3)).model


def points(arcs, count, seed):
    """Switch times and T, the arcs' controls (±1, each arc another corner), a disturbance."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        z = np.cumsum(rng.uniform(0.2, 1.5, arcs))
        U = rng.choice([-1.0, 1.0], size=(3, arcs))
        yield z, U, rng.normal(scale=0.05, size=3)


@pytest.mark.parametrize("inertia", sorted(INERTIAS))
@pytest.mark.parametrize("fixed_rate, arcs", [(True, 6), (True, 4), (False, 3), (False, 1)])
def test_the_sensitivities_are_casadis_jacobian_bit_for_bit(inertia, fixed_rate, arcs):
    model = model_of(inertia)
    steps = 5
    shooting = certificate._shooting(model, arcs, fixed_rate, steps)
    inputs, r = certificate._flight(model, arcs, fixed_rate, steps)
    reference = ca.Function("reference", inputs, [r, ca.jacobian(r, inputs[1])])
    x0 = np.r_[quat.from_axis_angle([0, 1, 0], 0.3), 0.01, -0.02, 0.03]
    xf = np.r_[quat.from_axis_angle([1, 1, 1], 2.5), 0.0, 0.0, 0.0]
    for z, U, d in points(arcs, 5, seed=arcs):
        miss, jacobian = (np.asarray(m) for m in reference(x0, z, U, d, xf))
        ours = buffered(shooting).all_outputs(x0, z, U.ravel(order="F"), d, xf)
        assert np.array_equal(ours[0], miss.ravel())
        assert np.array_equal(ours[1].reshape(jacobian.shape, order="F"), jacobian)


def test_the_sensitivities_are_the_flights_derivative():
    model = model_of("full")
    arcs, steps = 6, 12
    shooting = certificate._shooting(model, arcs, True, steps)
    flight = ca.Function("miss", *certificate._listed(certificate._flight(model, arcs, True, steps)))
    x0, xf = np.r_[1.0, 0, 0, 0, 0, 0, 0], np.r_[quat.from_axis_angle([1, 1, 1], 2.5), 0.0, 0.0, 0.0]
    for z, U, d in points(arcs, 2, seed=11):
        _, jacobian = (np.asarray(m) for m in shooting(x0, z, U, d, xf))
        for k in range(arcs):
            e = np.zeros(arcs)
            e[k] = 1e-6
            central = (np.asarray(flight(x0, z + e, U, d, xf)) - np.asarray(flight(x0, z - e, U, d, xf))).ravel() / 2e-6
            assert np.allclose(jacobian[:, k], central, rtol=1e-6, atol=1e-8)
