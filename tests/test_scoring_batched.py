"""The scoring's shared work: what a row's scores compute once gives what each computed alone.

* :func:`controllers.allocation.reference_demand` given the environment's torque the scorer has
  already evaluated (``environment``) is the demand that evaluates it itself, number for number;
  the torque is read (a demand given none differs);
* :func:`controllers.allocation.model_rows` writes each chunk into its map's buffers (kept per map
  and thread): calls of different lengths and shared values one after another each give every
  sample's own call (the oracle: the model function on one sample), nothing of the call before;
* times inserted between the samples (the reference's breakpoints, the windows' edges) skip those
  on a sample, found by a binary search in the increasing samples;
* the free start's second demand (what each wheel would hold starting at the reference's rate) is
  asked only where a quantity is broken and its message needs it; the message then names the free
  start as before (``tests/test_requirements_free_start_wheels.py``: by hand).
"""
from __future__ import annotations

import numpy as np
import pytest

from controllers import CONTROLLERS
from controllers.allocation import _CHUNK, model_rows, reference_demand
from ocp import AttitudeModel, CircularOrbit, Environment, ReactionWheels, Spacecraft
from scenarios.requirements import scoring
from tests.test_batched_demand import _states as _motion
from tests.test_requirements_free_start_wheels import SPHERE as FREE_START_SPHERE

INERTIA = np.array([[0.25, 0.01, -0.02], [0.01, 0.28, 0.015], [-0.02, 0.015, 0.12]])
ORBIT = CircularOrbit(altitude=550e3, inclination=np.deg2rad(97.6))
SEED = 20261203


def _model() -> AttitudeModel:
    """Three wheels (the demand's closed form of the momenta) in a gravity gradient with a disturbance."""
    spacecraft = Spacecraft(INERTIA, wheels=ReactionWheels(np.eye(3), max_torque=0.003, max_momentum=0.02))
    return AttitudeModel(spacecraft, Environment(orbit=ORBIT, gravity_gradient=True,
                                                 disturbance_torque=np.array([1e-6, -2e-6, 5e-7])))



def test_the_demand_given_the_scorers_environment_torque_is_the_demand_alone():
    model = _model()
    n = 2 * _CHUNK + 33
    t, q, omega, torque = _motion(n, np.random.default_rng(SEED))
    x = np.hstack([q, omega, np.zeros((n, model.nx - 7))])
    environment = model_rows(model, "environment_torque", x, t[:, None],
                             np.asarray(model.default_parameters, dtype=float).ravel())
    assert np.all(np.abs(environment) > 0.0)
    law = CONTROLLERS["augmented_quaternion_feedback"]()
    h0 = np.array([0.004, -0.002, 0.001])
    jumps = np.zeros((n, 3))
    jumps[0] = [0.01, 0.0, -0.02]  # a free start's step, taken up by the wheels at once
    alone = reference_demand(law, model, t, q, omega, torque, h0, jumps=jumps)
    given = reference_demand(law, model, t, q, omega, torque, h0, jumps=jumps, environment=environment)
    assert list(given) == list(alone) == ["wheels_torque", "wheels_momentum"]
    for name in alone:
        np.testing.assert_array_equal(given[name].values, alone[name].values, err_msg=name)
    # the torque given is the one the momenta integrate: none given, other momenta
    without = reference_demand(law, model, t, q, omega, torque, h0, jumps=jumps, environment=np.zeros((n, 3)))
    assert not np.allclose(without["wheels_momentum"].values, alone["wheels_momentum"].values, rtol=0.0, atol=1e-9)


def test_model_rows_one_call_after_another_is_each_samples_own_call():
    model = _model()
    rng = np.random.default_rng(SEED + 1)
    default = np.asarray(model.default_parameters, dtype=float).ravel()
    # long, short, long again (the short one leaves its rows in the buffers), each with its own disturbance
    for n, scale in ((2 * _CHUNK + 77, 1.0), (5, -3.0), (_CHUNK + 1, 0.5)):
        t, q, omega, _ = _motion(n, rng)
        x = np.hstack([q, omega, np.zeros((n, model.nx - 7))])
        p = scale * default
        rows = model_rows(model, "environment_torque", x, t[:, None], p)
        assert rows.shape == (n, 3)
        for k in range(n):
            one = np.asarray(model.environment_torque(x[k], t[k], p)).ravel()
            np.testing.assert_array_equal(rows[k], one, err_msg=f"{n} samples, sample {k}")


# the free-start sphere of test_requirements_free_start_wheels at 0.05 rad/s, its actuators required
SPHERE = FREE_START_SPHERE.replace("SPIN", "0.05") + "requirements:\n  actuators: {margin: 0.0}\n"


@pytest.mark.parametrize("momentum, demands, named", [(1.0, 1, False), (0.2, 2, True)])
def test_the_free_starts_second_demand_only_where_a_broken_quantity_asks(tmp_path, monkeypatch, momentum, demands,
                                                                          named):
    from scenarios.runner import run
    from scenarios.schema.loader import load

    calls: list[np.ndarray] = []

    def counted(*args, **kwargs):
        calls.append(np.asarray(kwargs["jumps"]))
        return reference_demand(*args, **kwargs)

    monkeypatch.setattr(scoring, "reference_demand", counted)
    path = tmp_path / "free_start_wheels.yaml"
    path.write_text(SPHERE.replace("MOMENTUM", f"{momentum}"))
    row = run(load(path)).rows[0]
    assert len(calls) == demands
    assert np.any(calls[0][0])  # the row's demand holds the free start's step
    if named:  # the second demand starts at the reference's rate: no step at t = 0
        assert not np.any(calls[1][0])
        assert "(the free start's momentum, 0.5 N m s, takes it there: 0 x without it)" in row.message, row.message
    else:
        assert row.requirements is not None and row.requirements["reference"]["actuators"]["met"], row.message
        assert "takes it there" not in row.message, row.message


def test_times_inserted_between_the_samples_by_hand():
    # on a sample (1, 3), outside the span (-1, 4), repeated (1.5 twice): only 1.5 and 2.5 go in, once each
    t = np.array([0.0, 1.0, 2.0, 3.0])
    column = np.column_stack([t, 10 * t])
    times = np.array([1.0, 1.5, 1.5, -1.0, 3.0, 2.5, 4.0])
    values = np.column_stack([100 + np.arange(7.0), 200 + np.arange(7.0)])
    merged, (rows,) = scoring._inserted(t, [column], times, [values])
    np.testing.assert_array_equal(merged, [0.0, 1.0, 1.5, 2.0, 2.5, 3.0])
    np.testing.assert_array_equal(rows, [[0, 0], [1, 10], [101, 201], [2, 20], [105, 205], [3, 30]])
