"""Docstrings of the public API say what the numbers do (checked against the numbers)."""
from __future__ import annotations

import inspect

import numpy as np

from ocp import quat


def _sandwich(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``q ⊗ [0, v] ⊗ q*`` written out (Hamilton, scalar first), independent of ocp.quat."""
    w, x, y, z = q
    a = np.array([-x * v[0] - y * v[1] - z * v[2], w * v[0] + y * v[2] - z * v[1],
                  w * v[1] + z * v[0] - x * v[2], w * v[2] + x * v[1] - y * v[0]])
    c = np.array([w, -x, -y, -z])
    return np.array([a[0] * c[1] + a[1] * c[0] + a[2] * c[3] - a[3] * c[2],
                     a[0] * c[2] - a[1] * c[3] + a[2] * c[0] + a[3] * c[1],
                     a[0] * c[3] + a[1] * c[2] - a[2] * c[1] + a[3] * c[0]])


def test_from_euler_returns_a_body_to_reference_quaternion_and_says_so():
    returns = inspect.getdoc(quat.from_euler).split("Returns\n-------")[1].split("Raises\n------")[0]
    assert "reference frame to body" not in returns  # it said both directions at once
    assert "rotating body vectors into the reference frame" in returns and "v_ref = R(q) v_B" in returns
    yaw = np.deg2rad(30.0)
    q = quat.from_euler([yaw, 0.0, 0.0])
    assert q[0] >= 0.0 and np.isclose(np.linalg.norm(q), 1.0, atol=1e-15)
    # Yawed by 30 deg, the body x axis lies at 30 deg from the reference x axis, in the reference's x-y plane.
    np.testing.assert_allclose(_sandwich(q, np.array([1.0, 0.0, 0.0])), [np.cos(yaw), np.sin(yaw), 0.0], atol=1e-15)
