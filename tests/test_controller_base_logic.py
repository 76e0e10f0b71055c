"""The controller base's shared helpers and its closed-loop key (``controllers.base``).

Oracles: hand-worked gains (a scalar gain is that number times the inertia, docs: "a scalar (times
the inertia)"); the energy a gain matrix takes out, ``xᵀ K x = xᵀ ½(K + Kᵀ) x`` (the skew part does
no work), worked by hand for two matrices; and a closed loop built afresh for a sample time
against the one a shared model's cache gives for it.
"""
from __future__ import annotations

import numpy as np
import pytest

from controllers import CONTROLLERS
from controllers.base import check_gain, gain_matrix
from ocp import AttitudeModel, ReactionWheels, Spacecraft, quat
from ocp.errors import InvalidOption


def test_a_scalar_gain_is_that_number_times_the_inertia():
    inertia = np.diag([2.0, 3.0, 4.0])
    np.testing.assert_array_equal(gain_matrix(0.5, inertia), np.diag([1.0, 1.5, 2.0]))
    matrix = [[1.0, 0.1, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 3.0]]
    np.testing.assert_array_equal(gain_matrix(matrix, inertia), np.array(matrix))


def test_a_zero_gain_is_allowed_and_a_negative_one_is_not():
    check_gain("kd", 0.0)  # non-negative: no damping is a choice, not an error
    check_gain("kd", 0)
    with pytest.raises(InvalidOption, match="non-negative"):
        check_gain("kd", -0.1)


def test_the_gain_check_reads_the_matrix_through_its_symmetric_part():
    # symmetric part the identity, skew part large: x^T K x = |x|^2 >= 0 for every x, so it takes energy out
    check_gain("kp", [[1.0, 10.0, 0.0], [-10.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    # lower triangle the identity, but x = (1, 1, 0) gives x^T K x = 1 + 1 - 10 = -8: it pumps energy in
    x = np.array([1.0, 1.0, 0.0])
    pumping = [[1.0, -10.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    assert x @ np.array(pumping) @ x == -8.0
    with pytest.raises(InvalidOption, match="positive semi-definite"):
        check_gain("kp", pumping)


def _model() -> AttitudeModel:
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels.from_body_axes(max_torque=0.05, max_momentum=0.3))
    return AttitudeModel(spacecraft)


def test_a_closed_loop_for_another_sample_time_is_not_the_cached_one():
    """The key of the compiled law holds the sample time (docs: class, options, spacecraft, sample
    time, target): a law compiled at 1 s reused at 0.5 s would integrate its state with the wrong step."""
    options = {"kp": 0.2, "kd": 0.8}
    law = CONTROLLERS["augmented_quaternion_feedback"]
    spacecraft = _model().spacecraft
    target = (quat.normalize(np.array([0.6, 0.2, -0.5, 0.3])), None)
    keys = set()
    for step in (1.0, 0.5, 1.0):
        controller = law(options)
        controller.reset(spacecraft, step, target=target)
        keys.add(controller.symbolic_key())
    assert len(keys) == 2
