"""``Environment.disturbance_torque`` at the library: real numbers only, finite, within the schema's
bound (one constant), each refusal a ModelError naming the field."""
import numpy as np
import pytest

from ocp.dynamics.environment import MAX_DISTURBANCE, Environment
from ocp.errors import ModelError


@pytest.mark.parametrize("value", [[True, 0, 0], [1 + 0j, 0, 0], np.array(["1", 0, 0], dtype=object), [None, 0, 0],
                                   [np.nan, 0, 0], [0, np.inf, 0], [0, 0, 10 * MAX_DISTURBANCE], [0, 0, -1e300]])
def test_a_disturbance_that_is_no_real_finite_torque_is_refused(value):
    # before: True read as 1 N m, complex a raw TypeError, nan/inf/1e300 accepted
    with pytest.raises(ModelError, match="disturbance_torque"):
        Environment(disturbance_torque=value)


def test_the_bound_itself_and_ordinary_torques_are_accepted():
    for value in ([MAX_DISTURBANCE, -MAX_DISTURBANCE, 0.0], [1e-6, 2, 3], np.array([1, 2, 3])):
        np.testing.assert_array_equal(Environment(disturbance_torque=value).disturbance_torque, np.asarray(value, float))
