"""The model's CasADi functions are built on first use, and shared by models of equal fingerprint
(ocp.dynamics.model): constructing a model builds nothing, equal models share one build, different
ones do not, and the shared functions give exactly what a build of their own gives."""
from __future__ import annotations

import threading

import casadi as ca
import numpy as np
import pytest

from ocp import (
    AttitudeModel,
    CircularOrbit,
    Environment,
    Magnetorquers,
    ReactionWheels,
    Spacecraft,
    TiltedDipole,
)
from ocp.dynamics import model as model_module

NAMES = ("rhs", "body_torque", "environment_torque", "field_body", "field_rate_inertial")


def make(moments=(1.0, 2.0, 2.5)) -> AttitudeModel:
    """A model with wheels and magnetorquers in a dipole field with gravity gradient (all five functions)."""
    spacecraft = Spacecraft(list(moments), wheels=ReactionWheels.from_body_axes(max_torque=0.1),
                            magnetorquers=Magnetorquers(max_dipole=0.2))
    environment = Environment(orbit=CircularOrbit(altitude=550e3), magnetic_field=TiltedDipole(),
                              gravity_gradient=True, disturbance_torque=np.array([1e-6, -2e-6, 3e-6]))
    return AttitudeModel(spacecraft, environment)


def test_constructing_a_model_builds_no_function():
    builds = model_module._BUILT.builds
    model = make((1.0, 2.0, 2.25))
    assert not set(NAMES) & set(vars(model))
    assert model_module._BUILT.builds == builds
    assert isinstance(model.rhs, ca.Function) and set(NAMES) <= set(vars(model))


def test_equal_models_share_the_functions_and_different_ones_do_not():
    first, second = make(), make()
    assert first is not second and first.fingerprint == second.fingerprint
    for name in NAMES:
        assert getattr(first, name) is getattr(second, name)
    nudged = make((1.0, 2.0, np.nextafter(2.5, 3.0)))  # one bit of one moment of inertia
    assert nudged.fingerprint != first.fingerprint
    for name in NAMES:
        assert getattr(nudged, name) is not getattr(first, name)


def test_shared_functions_equal_a_build_of_their_own(rng):
    make().rhs  # another model of equal fingerprint builds first: this one reuses its functions
    model = make()
    own = model._build()  # bypasses the cache
    x = np.concatenate([rng.normal(size=4), rng.normal(size=3), rng.normal(size=model.nx - 7)])
    u, t, p = rng.normal(size=model.nu), rng.uniform(0.0, 5000.0), rng.normal(size=3) * 1e-5
    arguments = {"rhs": (x, u, t, p), "body_torque": (x, u, t), "environment_torque": (x, t, p),
                 "field_body": (x, t), "field_rate_inertial": (t,)}
    for name in NAMES:
        shared, fresh = getattr(model, name), own[name]
        assert shared is not fresh
        np.testing.assert_array_equal(np.asarray(shared(*arguments[name])), np.asarray(fresh(*arguments[name])))


def test_a_model_without_field_has_no_field_functions():
    model = AttitudeModel(Spacecraft([1.0, 2.0, 3.0]))
    assert model.field_body is None and model.field_rate_inertial is None
    with pytest.raises(AttributeError, match="no_such_function"):
        model.no_such_function  # noqa: B018 - the attribute look-up is the test


def test_another_thread_builds_its_own_functions():
    main = make()
    main_rhs = main.rhs
    seen = {}
    worker = threading.Thread(target=lambda: seen.update(rhs=make().rhs))
    worker.start()
    worker.join()
    assert seen["rhs"] is not main_rhs  # a CasADi function is never handed to another thread


def test_the_cache_is_bounded():
    cache = model_module._BUILT
    for k in range(cache.size + 2):
        make((1.0, 2.0, 2.5 + 0.01 * (k + 1))).rhs
    assert len(cache._entries) == cache.size
