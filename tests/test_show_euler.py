"""Euler angles of an attitude and the sign continuity of a quaternion series (issue 31, item 4).

Oracles: attitudes built by hand from three axis-angle quaternions (the definition of a sequence),
SciPy's ``Rotation.as_euler`` (an independent implementation) for every sequence, and series whose
signs were flipped on purpose.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from ocp import quat

AXES = np.eye(3)
TAIT_BRYAN = ("321", "123", "132", "213", "231", "312")
PROPER = ("313", "121", "131", "212", "232", "323")


def composed(sequence: str, angles) -> np.ndarray:
    """``q_a(θ1) ⊗ q_b(θ2) ⊗ q_c(θ3)`` for the body axes a, b, c of ``sequence``."""
    angles = np.asarray(angles, dtype=float)
    factors = [quat.from_axis_angle(AXES[int(axis) - 1], angles[..., i]) for i, axis in enumerate(sequence)]
    return quat.product(quat.product(factors[0], factors[1]), factors[2])


def test_yaw_pitch_roll_of_a_hand_built_attitude():
    yaw, pitch, roll = np.deg2rad([30.0, 20.0, 10.0])
    q = quat.product(quat.product(quat.from_axis_angle([0, 0, 1], yaw), quat.from_axis_angle([0, 1, 0], pitch)),
                     quat.from_axis_angle([1, 0, 0], roll))
    np.testing.assert_allclose(np.rad2deg(quat.to_euler(q)), [30.0, 20.0, 10.0], atol=1e-12)
    np.testing.assert_allclose(np.rad2deg(quat.to_euler(-q, "321")), [30.0, 20.0, 10.0], atol=1e-12)
    np.testing.assert_allclose(np.rad2deg(quat.to_euler(q, "zyx")), [30.0, 20.0, 10.0], atol=1e-12)
    # the rotation matrix of the angles: R = Rz(yaw) Ry(pitch) Rx(roll), elements by hand
    matrix = quat.rotation_matrix(q)
    assert matrix[2, 0] == pytest.approx(-np.sin(pitch))
    assert matrix[1, 0] == pytest.approx(np.sin(yaw) * np.cos(pitch))
    assert matrix[2, 1] == pytest.approx(np.cos(pitch) * np.sin(roll))


def test_a_single_axis_rotation_is_one_angle():
    q = quat.from_axis_angle([0, 0, 1], np.deg2rad(-135.0))
    np.testing.assert_allclose(np.rad2deg(quat.to_euler(q)), [-135.0, 0.0, 0.0], atol=1e-12)
    q = quat.from_axis_angle([1, 0, 0], np.deg2rad(170.0))
    np.testing.assert_allclose(np.rad2deg(quat.to_euler(q)), [0.0, 0.0, 170.0], atol=1e-12)


@pytest.mark.parametrize("sequence", TAIT_BRYAN + PROPER)
def test_every_sequence_agrees_with_scipy_and_rebuilds_the_attitude(sequence):
    q = quat.random_unit(np.random.default_rng(31), 500)
    angles = quat.to_euler(q, sequence)
    intrinsic = "".join("XYZ"[int(axis) - 1] for axis in sequence)  # upper case: intrinsic (body) axes
    expected = Rotation.from_quat(quat.to_scalar_last(q)).as_euler(intrinsic)
    np.testing.assert_allclose(np.angle(np.exp(1j * (angles - expected))), 0.0, atol=1e-12)
    np.testing.assert_allclose(quat.error_angle(composed(sequence, angles), q), 0.0, atol=1e-12)
    middle = angles[:, 1]
    if sequence in TAIT_BRYAN:
        assert np.all(np.abs(middle) <= np.pi / 2 + 1e-15)
    else:
        assert np.all((middle >= 0) & (middle <= np.pi))
    assert np.all((angles[:, [0, 2]] > -np.pi) & (angles[:, [0, 2]] <= np.pi))


@pytest.mark.parametrize(("sequence", "middle"), [("321", 90.0), ("321", -90.0), ("123", 90.0), ("313", 0.0),
                                                  ("313", 180.0), ("232", 180.0)])
def test_gimbal_lock_puts_the_rotation_in_the_first_angle(sequence, middle):
    q = composed(sequence, np.deg2rad([40.0, middle, -25.0]))
    angles = quat.to_euler(q, sequence)
    assert np.rad2deg(angles[1]) == pytest.approx(middle, abs=1e-6)
    assert angles[2] == 0.0
    assert quat.error_angle(composed(sequence, angles), q) < 1e-12


@pytest.mark.parametrize("sequence", ["32", "331", "3210", "456", "xxy", 321])
def test_a_bad_sequence_is_refused(sequence):
    with pytest.raises(ValueError, match="sequence"):
        quat.to_euler(quat.IDENTITY, sequence)


def test_continuous_undoes_sign_flips_and_keeps_the_attitudes():
    t = np.linspace(0.0, 10.0, 201)
    smooth = quat.from_axis_angle([1.0, 2.0, 2.0], 0.6 * t)  # one turn and a bit: q0 changes sign itself
    flips = np.ones(t.size)
    flips[[5, 6, 7, 40, 150, 200]] = -1.0  # a run of three, single samples, the last one
    given = smooth * flips[:, None]
    fixed = quat.continuous(given)
    np.testing.assert_allclose(fixed, smooth, atol=1e-15)
    assert np.all(np.sum(fixed[1:] * fixed[:-1], axis=1) > 0)  # no jump between consecutive samples
    np.testing.assert_allclose(quat.error_angle(fixed, given), 0.0, atol=1e-7)
    # the first sample keeps its sign, and the rest follow it
    np.testing.assert_allclose(quat.continuous(-given), -smooth, atol=1e-15)


def test_continuous_of_short_and_bad_series():
    np.testing.assert_array_equal(quat.continuous(np.array([[0.0, 1.0, 0.0, 0.0]])), [[0.0, 1.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="N, 4"):
        quat.continuous(np.zeros(4))
