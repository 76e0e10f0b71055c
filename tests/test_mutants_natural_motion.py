"""Natural motion's stop against the kinematics integrated here: the attitude of the smooth stop is
the integral of its own rate, q̇ = ½ q ⊗ [0, ω], from the end of the arc (scipy's DOP853)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ocp import quat
from planners.natural_motion import NaturalMotionReference


@pytest.mark.parametrize("moments", [np.array([0.0109, 0.05, 0.05]), np.array([0.02, 0.05, 0.04])],
                         ids=["axisymmetric", "asymmetric"])
def test_the_smooth_stop_turns_by_the_integral_of_its_rate(moments):
    q0 = quat.normalize(np.array([0.3, -0.5, 0.1, 0.8]))
    omega0 = np.array([0.02, -0.015, 0.01])
    arc, duration = 90.0, 100.0
    reference = NaturalMotionReference(q0, omega0, moments, arc, duration, "smooth", "", {})
    t = np.linspace(arc, duration, 21)

    def rhs(time, q):
        w = reference.omega(time)
        return 0.5 * np.r_[-q[1:] @ w, q[0] * w + np.cross(q[1:], w)]

    truth = solve_ivp(rhs, (arc, duration), reference.q(arc), method="DOP853", rtol=1e-12, atol=1e-13, t_eval=t)
    assert np.max(quat.error_angle(reference.q(t), truth.y.T)) < 1e-9
    assert np.allclose(reference.omega(duration), 0.0)
