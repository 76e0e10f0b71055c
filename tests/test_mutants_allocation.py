"""Gaps the mutation check found in :func:`controllers.allocation.model_rows`.

A shared input (one row for every sample) may come first: the number of samples is that of the
inputs with more than one row, whichever position they hold. The oracle: each model function
called on one sample (the per-sample path of the simulator), and the wheels' body torque ``−A g``
written out by hand.
"""
import numpy as np

from controllers.allocation import model_rows
from ocp import AttitudeModel, ReactionWheels, Spacecraft

INERTIA = np.diag([0.25, 0.28, 0.12])


def test_a_shared_first_input_takes_the_sample_count_of_the_others():
    axes = np.array([[1, 1, 1], [-1, 1, 1], [-1, -1, 1], [1, -1, 1]], float).T / np.sqrt(3)
    model = AttitudeModel(Spacecraft(INERTIA, wheels=ReactionWheels(axes, max_torque=0.003, max_momentum=0.02)))
    rng = np.random.default_rng(7)
    n = 9
    x = np.concatenate([[1.0, 0.0, 0.0, 0.0], np.zeros(3), np.zeros(model.nx - 7)])  # at rest: no gyroscopic term
    u = rng.normal(0.0, 1e-3, (n, model.nu))
    t = np.linspace(0.0, 8.0, n)[:, None]
    rows = model_rows(model, "body_torque", x, u, t)  # the state shared, one command per sample
    assert rows.shape == (n, 3)
    for k in range(n):
        np.testing.assert_allclose(rows[k], np.asarray(model.body_torque(x, u[k], t[k, 0])).ravel(), rtol=0,
                                   atol=1e-15)
        np.testing.assert_allclose(rows[k], -axes @ u[k, :4], rtol=1e-12, atol=1e-18)  # the wheels' −A g
