"""The actuator demand of a reference is the law's own per-sample allocation, evaluated as a batch.

:func:`controllers.allocation.reference_demand` evaluates the allocation of every sample at once
(the law's map on CasADi expressions, mapped over chunks of samples), and
:func:`controllers.allocation.model_rows` evaluates a model's functions (the environment's torque,
the actuators' body torque, the field) over all samples: the scores of the actuator requirement
rest on both. The oracle here is the per-sample path the simulator and the controllers use: the
law's :meth:`~controllers.allocation.Allocation.allocate` called on one
:class:`~ocp.Measurement` (Python floats), and each model function called on one sample; on random
states for every actuator mix, sample counts that are not whole chunks included.
"""
from __future__ import annotations

import copy

import numpy as np
import pytest

from controllers import CONTROLLERS
from controllers.allocation import _CHUNK, model_rows, reference_demand
from ocp import (
    AttitudeModel,
    CircularOrbit,
    Environment,
    Magnetorquers,
    Measurement,
    ReactionWheels,
    Spacecraft,
    Torquers,
)
from ocp.dynamics.environment import MAGNETIC_FIELDS
from ocp.dynamics.layout import control_layout

INERTIA = np.array([[0.25, 0.01, -0.02], [0.01, 0.28, 0.015], [-0.02, 0.015, 0.12]])
PYRAMID = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / np.sqrt(3)
ORBIT = CircularOrbit(altitude=550e3, inclination=np.deg2rad(97.6))
FIELD = MAGNETIC_FIELDS["tilted_dipole"].from_options(MAGNETIC_FIELDS["tilted_dipole"].Options(), ORBIT)
SEED = 20261202


def _wheels(axes: np.ndarray | None = None, **options) -> ReactionWheels:
    return ReactionWheels(np.eye(3) if axes is None else axes, max_torque=0.003, max_momentum=0.02, **options)


MIXES = {
    "wheels only": Spacecraft(INERTIA, wheels=_wheels()),
    "skewed pyramid, one failed": Spacecraft(INERTIA, wheels=_wheels(axes=PYRAMID, failed=[1])),
    "wheels + torquers": Spacecraft(INERTIA, wheels=_wheels(failed=[2]), torquers=Torquers(max_torque=0.002)),
    "wheels + magnetorquers": Spacecraft(INERTIA, wheels=_wheels(failed=[0]), magnetorquers=Magnetorquers(max_dipole=0.2)),
    "torquers only": Spacecraft(INERTIA, wheels=None, torquers=Torquers(max_torque=0.002)),
    "magnetorquers only": Spacecraft(INERTIA, wheels=None, magnetorquers=Magnetorquers(max_dipole=0.2)),
}
COMMAND = {"wheels": "wheel_torque", "torquers": "torque", "magnetorquers": "dipole"}
"""An actuator kind -> its field of ``ocp.Command`` (stated here, not read from the code)."""


def _model(spacecraft: Spacecraft) -> AttitudeModel:
    """Gravity gradient and a constant disturbance always; the field where magnetorquers need it."""
    field = FIELD if spacecraft.magnetorquers is not None else None
    return AttitudeModel(spacecraft, Environment(orbit=ORBIT, gravity_gradient=True, magnetic_field=field,
                                                 disturbance_torque=np.array([1e-6, -2e-6, 5e-7])))


def _states(n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    t = np.sort(rng.uniform(0.0, 300.0, n))
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    return t, q, rng.normal(0.0, 0.05, (n, 3)), rng.normal(0.0, 2e-3, (n, 3))


@pytest.mark.parametrize("n", [1, 7, _CHUNK, _CHUNK + 1, 2 * _CHUNK + 77])
def test_model_rows_is_each_function_at_each_sample(n):
    model = _model(MIXES["wheels + magnetorquers"])
    rng = np.random.default_rng(SEED + n)
    t, q, omega, _ = _states(n, rng)
    x = np.hstack([q, omega, rng.normal(0.0, 0.01, (n, model.nx - 7))])
    u = rng.normal(0.0, 1e-3, (n, model.nu))
    p = np.asarray(model.default_parameters, dtype=float).ravel()
    batched = {"environment_torque": model_rows(model, "environment_torque", x, t[:, None], p),
               "body_torque": model_rows(model, "body_torque", x, u, t[:, None]),
               "field_body": model_rows(model, "field_body", x, t[:, None])}
    for k in range(n):
        one = {"environment_torque": model.environment_torque(x[k], t[k], p),
               "body_torque": model.body_torque(x[k], u[k], t[k]),
               "field_body": model.field_body(x[k], t[k])}
        for name, value in one.items():
            np.testing.assert_array_equal(batched[name][k], np.asarray(value).ravel(), err_msg=f"{name}, sample {k}")
    assert all(rows.shape == (n, 3) for rows in batched.values())


def test_model_rows_refuses_inputs_of_different_lengths():
    model = _model(MIXES["wheels only"])
    with pytest.raises(ValueError, match="rows"):
        model_rows(model, "field_body" if model.field_body is not None else "environment_torque",
                   np.zeros((4, model.nx)), np.zeros((3, 1)), np.zeros(3))


@pytest.mark.parametrize("mix", MIXES)
@pytest.mark.parametrize("law_name", ["augmented_quaternion_feedback", "min_norm"])
def test_batched_commands_are_the_law_per_sample(mix, law_name):
    spacecraft = MIXES[mix]
    model = _model(spacecraft)
    law = CONTROLLERS[law_name]()
    n = _CHUNK + 40  # a whole chunk and a padded one
    t, q, omega, torque = _states(n, np.random.default_rng(SEED))
    h0 = np.full(spacecraft.n_wheels, 0.004)
    demand = reference_demand(law, model, t, q, omega, torque, h0 if spacecraft.n_wheels else None)
    # the per-sample oracle: the law's own map on one measurement, with the gyroscopic term asked for
    # (as reference_demand does for every law) at the wheel momenta the demand reports
    oracle = copy.copy(law)
    oracle.gyroscopic_compensation = True
    oracle.spacecraft = spacecraft  # the allocation's own reset (a two-wheel law's reset refuses 3 wheels)
    oracle._slices, oracle._nu = control_layout(spacecraft)
    oracle._reset_allocation(spacecraft)
    momenta = demand["wheels_momentum"].values if spacecraft.n_wheels else np.zeros((n, 0))
    assert np.all(np.isfinite(momenta))
    checked = 0
    for k in range(n):
        field = None if model.field_body is None else np.asarray(
            model.field_body(np.concatenate([q[k], omega[k], np.zeros(model.nx - 7)]), t[k])).ravel()
        command = oracle.allocate(torque[k], Measurement(float(t[k]), q[k], omega[k], momenta[k], field_body=field))
        for actuator in spacecraft.actuators:
            quantity = f"{actuator.name}_{COMMAND[actuator.name].split('_')[-1]}"
            expected = getattr(command, COMMAND[actuator.name])
            expected = np.zeros(demand[quantity].values.shape[1]) if expected is None else np.asarray(expected)
            scale = max(float(np.linalg.norm(expected)), 1e-300)
            error = float(np.linalg.norm(demand[quantity].values[k] - expected))
            assert error <= 1e-12 * scale, f"{mix}, {law_name}, sample {k}, {quantity}: {error:.3g} of {scale:.3g}"
            checked += bool(np.any(expected))
    if law.wheels_only and not spacecraft.n_wheels:  # a wheels-only law asks nothing of other actuators
        assert checked == 0
    else:
        assert checked >= n  # the law asked something of the actuators at every sample
