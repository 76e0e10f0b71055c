"""The collocation reference's and the switching check's mapped functions: a model keeps only its
most recently used maps, however many sample counts a study meets, and a mapped evaluation equals
the function evaluated point by point.

Oracle: the model's own ``rhs``, ``body_torque`` and ``environment_torque``, and ``∂f/∂u`` from
CasADi's ``jacobian`` of ``rhs``, each called at one point at a time.
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocp import Environment, ReactionWheels, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem
from planners.collocation.certificate import _control_jacobian
from planners.collocation.reference import MAPS_KEPT, _mapped


@pytest.fixture(scope="module")
def reference():
    spacecraft = Spacecraft([3.0, 3.5, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05, max_momentum=1.0))
    problem = ManeuverProblem(spacecraft, quat.IDENTITY, np.zeros(3), quat.from_axis_angle([1, 1, 0], 0.6), 40.0,
                              omegaf=np.zeros(3), environment=Environment(disturbance_torque=[1e-5, -2e-5, 3e-5]))
    planned = PLANNERS["collocation"]({"intervals": 6}).plan(problem)
    assert planned.ok, planned.message
    return planned


def test_many_sample_counts_keep_a_bounded_number_of_maps(reference):
    cache = reference.model.solver_cache
    reference.sample(np.linspace(0.0, reference.duration, 7))
    entries = len(cache)
    for n in range(8, 8 + 6 * MAPS_KEPT):  # three maps a count: far more counts than are kept
        reference.sample(np.linspace(0.0, reference.duration, n))
    assert len(cache) == entries
    maps = cache.get(("collocation", "maps"), dict)
    assert len(maps) == MAPS_KEPT


def test_the_mapped_sample_equals_the_functions_point_by_point(reference):
    model, d = reference.model, reference.disturbance
    t = np.linspace(0.0, reference.duration, 23)
    sample = reference.sample(t)
    x, u = reference._state_control(t)
    for k in range(t.size):
        x_dot = model.rhs(x[k], u[k], t[k], d).full().ravel()
        torque = (model.body_torque(x[k], u[k], t[k]).full().ravel()
                  - np.cross(x[k, 4:7], model.spacecraft.wheel_axes @ x[k, 7:])
                  + model.environment_torque(x[k], t[k], d).full().ravel())
        np.testing.assert_array_equal(sample.omega_dot[k], x_dot[4:7])
        np.testing.assert_allclose(sample.torque[k], torque, rtol=1e-14, atol=1e-20)


def test_the_switching_jacobian_map_is_bounded_and_equals_the_jacobian_point_by_point(reference):
    model = reference.model
    rng = np.random.default_rng(4)
    xs, us, ts = ca.SX.sym("x", model.nx), ca.SX.sym("u", model.nu), ca.SX.sym("t")
    ds = ca.SX.sym("d", 3)
    jacobian = ca.Function("oracle", [xs, us, ts, ds], [ca.jacobian(model.rhs(xs, us, ts, ds), us)])
    for n in range(3, 3 + 2 * MAPS_KEPT):
        x, u, t, d = rng.normal(size=(n, model.nx)), rng.normal(size=(n, model.nu)), rng.random(n), rng.normal(size=3)
        mapped = np.asarray(_mapped(model, "switching f_u", n, lambda: _control_jacobian(model))(
            x.T, u.T, t[None, :], np.tile(d, (n, 1)).T)).reshape(model.nx, n, model.nu).transpose(1, 0, 2)
        for k in range(n):
            np.testing.assert_array_equal(mapped[k], jacobian(x[k], u[k], t[k], d).full())
    assert len(model.solver_cache.get(("collocation", "maps"), dict)) == MAPS_KEPT
