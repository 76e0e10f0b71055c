"""NumPy and CasADi quaternion algebra agree, and obey the algebra's identities."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ocp import quat
from ocp.quat_casadi import FUNCTIONS

finite = st.floats(-1.0, 1.0, allow_nan=False)
vectors4 = st.lists(finite, min_size=4, max_size=4).filter(lambda v: np.linalg.norm(v) > 1e-3)
vectors3 = st.lists(st.floats(-3.0, 3.0, allow_nan=False), min_size=3, max_size=3)


def unit(v):
    return quat.normalize(np.array(v))


def casadi_value(name, *args):
    return np.array(FUNCTIONS[name](*args)).squeeze()


@settings(max_examples=60, deadline=None)
@given(vectors4, vectors4, vectors3, st.floats(0.0, 1.0))
def test_casadi_and_numpy_agree(p, q, v, s):
    p, q, v = unit(p), unit(q), np.array(v)
    axis = v / np.linalg.norm(v) if np.linalg.norm(v) > 1e-6 else np.array([1.0, 0, 0])
    cases = {
        "product": ((p, q), quat.product(p, q)),
        "conjugate": ((q,), quat.conjugate(q)),
        "rotation_matrix": ((q,), quat.rotation_matrix(q)),
        "error": ((q, p), quat.error(q, p)),
        "error_angle": ((q, p), quat.error_angle(q, p)),
        "from_axis_angle": ((axis, s * 7), quat.from_axis_angle(axis, s * 7)),
        "from_rotation_vector": ((v,), quat.from_rotation_vector(v)),
        "from_scalar_last": ((q,), quat.from_scalar_last(q)),
        "to_scalar_last": ((q,), quat.to_scalar_last(q)),
        "slerp": ((p, q, s), quat.slerp(p, q, s)),
        "kinematics": ((q, v), quat.kinematics(q, v)),
    }
    for name, (args, expected) in cases.items():
        np.testing.assert_allclose(casadi_value(name, *args), expected, atol=1e-12, err_msg=name)


@settings(max_examples=60, deadline=None)
@given(vectors4, vectors4, vectors3)
def test_algebraic_identities(p, q, v):
    p, q, v = unit(p), unit(q), np.array(v)
    # R(p ⊗ q) = R(p) R(q), and rotation by the sandwich product equals R(q) v.
    np.testing.assert_allclose(quat.rotation_matrix(quat.product(p, q)),
                               quat.rotation_matrix(p) @ quat.rotation_matrix(q), atol=1e-12)
    sandwich = quat.product(quat.product(q, np.r_[0.0, v]), quat.conjugate(q))[1:]
    np.testing.assert_allclose(sandwich, quat.rotation_matrix(q) @ v, atol=1e-12)
    # The rotation vector round trip, and the error angle equals the rotation-vector norm.
    rotvec = quat.to_rotation_vector(quat.from_rotation_vector(v))
    angle = np.linalg.norm(v) % (2 * np.pi)
    if angle < np.pi - 1e-6:
        np.testing.assert_allclose(rotvec, v / np.linalg.norm(v) * angle if angle else v, atol=1e-9)
    q_rot = quat.product(p, quat.from_rotation_vector(v))
    expected = min(angle, 2 * np.pi - angle)
    assert quat.error_angle(q_rot, p) == pytest.approx(expected, abs=1e-7)


def test_slerp_endpoints_and_constant_rate(rng):
    p, q = quat.random_unit(rng), quat.random_unit(rng)
    s = np.linspace(0, 1, 11)
    path = quat.slerp(p, q, s)
    assert quat.error_angle(path[0], p) < 1e-12
    assert quat.error_angle(path[-1], q) < 1e-7
    steps = quat.error_angle(path[1:], path[:-1])
    np.testing.assert_allclose(steps, steps[0], rtol=1e-9)


def test_scalar_last_conversion_of_a_paper_quaternion():
    # Nano-spacecraft paper target [0.5, 0.5, 0.5, 0.5] is symmetric; Vepa's qd is not.
    q_paper = np.array([0.2068, 0.2518, 0.1682, 0.9303])
    np.testing.assert_allclose(quat.from_scalar_last(q_paper), [0.9303, 0.2068, 0.2518, 0.1682])
    np.testing.assert_allclose(quat.to_scalar_last(quat.from_scalar_last(q_paper)), q_paper)


def test_kinematics_about_a_fixed_axis_matches_axis_angle():
    axis = np.array([1.0, 2.0, -2.0]) / 3.0
    rate = 0.3
    t = 2.5
    # q(t) = exp(t ω/2) solves q̇ = ½ q ⊗ [0, ω] for constant ω.
    q_t = quat.from_axis_angle(axis, rate * t)
    np.testing.assert_allclose(quat.kinematics(q_t, rate * axis),
                               0.5 * rate * np.r_[-np.sin(rate * t / 2), np.cos(rate * t / 2) * axis], atol=1e-15)


def test_rotation_vector_series_branch_matches_the_half_angle_closed_form():
    """Below θ² = 1e-8 the CasADi exponential map takes its series branch: its value must still be
    ``[cos(θ/2), sin(θ/2) e]`` to rounding, and its second derivatives at zero those of the closed
    form (∂²q0/∂v² = −I/4, ∂²q_v/∂v² = 0 at v = 0), as the NLP's Hessian reads them."""
    import casadi as ca

    from ocp.quat_casadi import from_rotation_vector
    axis = np.array([2.0, -1.0, 2.0]) / 3.0
    for angle in (3e-5, 1e-5, 1e-7):  # θ² from 9e-10 down: all in the series branch
        expected = np.r_[np.cos(angle / 2), np.sin(angle / 2) * axis]
        np.testing.assert_allclose(casadi_value("from_rotation_vector", angle * axis), expected, rtol=0, atol=1e-16)
    v = ca.SX.sym("v", 3)
    q = from_rotation_vector(v)
    hessian = ca.Function("h", [v], [ca.hessian(q[0], v)[0]])
    np.testing.assert_allclose(np.array(hessian(np.zeros(3))), -0.25 * np.eye(3), atol=1e-15)
    jacobian = ca.Function("j", [v], [ca.jacobian(q[1:4], v)])
    np.testing.assert_allclose(np.array(jacobian(np.zeros(3))), 0.5 * np.eye(3), atol=1e-15)
