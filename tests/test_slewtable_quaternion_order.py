"""The order the slew-time fit reads quaternions in is stated, kept in ``fit.json`` and can be chosen.

A quaternion given scalar last, ``[x, y, z, w]``, was silently read scalar first (another rotation:
a unit quaternion either way, which no check can tell). The fit now has a ``quaternion_order``
(``scalar_first`` by default, ``scalar_last`` as a scenario's ``maneuver.quaternion_order``), kept in
``fit.json`` and chosen at ``load_fit``; a table of slews from the identity only, given the identity
written in the other order, says so.

Oracles: rotations built by :mod:`ocp.quat` (scalar first) and reordered by hand; the eigenaxis
bang-bang time of a unit-inertia body with ``|u_i| <= 1`` N m, which the fit of its exact table
reproduces.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ocp import quat
from scenarios.slewtable.fit import load_fit
from tests.test_slewtable_gaps import _fit, bang_bang


def _last(q: np.ndarray) -> np.ndarray:
    """``[w, x, y, z]`` -> ``[x, y, z, w]``."""
    return np.asarray(q, dtype=float)[..., [1, 2, 3, 0]]


def _rotations(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Start attitudes, body axes, angles [rad] and end attitudes ``q0 ⊗ q(axis, angle)``, scalar first."""
    rng = np.random.default_rng(seed)
    q0 = rng.normal(size=(n, 4))
    q0 /= np.linalg.norm(q0, axis=1, keepdims=True)
    axes = rng.normal(size=(n, 3))
    angles = rng.uniform(0.6, math.pi, n)
    qf = np.array([quat.product(a, quat.from_axis_angle(e, t)) for a, e, t in zip(q0, axes, angles)])
    return q0, axes, angles, qf


def test_a_scalar_last_fit_reads_scalar_last_quaternions(tmp_path):
    first = _fit({})
    first.save(tmp_path / "fit.json")
    assert json.loads((tmp_path / "fit.json").read_text())["quaternion_order"] == "scalar_first"
    last = load_fit(tmp_path, quaternion_order="scalar_last")
    assert first.quaternion_order == "scalar_first" and last.quaternion_order == "scalar_last"
    assert "scalar last" in repr(last)
    q0, axes, angles, qf = _rotations(200, 3)
    expected = np.array([bang_bang(e, t) for e, t in zip(axes, angles)])
    scalar = np.array([last(tuple(_last(a).tolist()), list(_last(b))) for a, b in zip(q0, qf)])
    np.testing.assert_allclose(scalar, expected, rtol=1e-9)
    np.testing.assert_allclose(last.slew_time_many(_last(q0), _last(qf)), expected, rtol=1e-9)
    np.testing.assert_allclose(first.slew_time_many(q0, qf), expected, rtol=1e-9)
    # the scalar-last quaternions read scalar first are other rotations: other times
    assert np.max(np.abs(first.slew_time_many(_last(q0), _last(qf)) / expected - 1.0)) > 0.05
    # the order round-trips through fit.json, and the loader's argument wins over the file
    last.save(tmp_path / "last.json")
    assert json.loads((tmp_path / "last.json").read_text())["quaternion_order"] == "scalar_last"
    assert load_fit(tmp_path / "last.json").quaternion_order == "scalar_last"
    assert load_fit(tmp_path / "last.json", quaternion_order="scalar_first").quaternion_order == "scalar_first"


def test_a_file_without_an_order_is_scalar_first_and_a_bad_order_is_refused(tmp_path):
    data = _fit({}).to_dict()
    del data["quaternion_order"]
    (tmp_path / "fit.json").write_text(json.dumps(data))
    assert load_fit(tmp_path).quaternion_order == "scalar_first"
    with pytest.raises(ValueError, match="quaternion_order must be one of scalar_first, scalar_last, got 'xyzw'"):
        load_fit(tmp_path, quaternion_order="xyzw")
    data["quaternion_order"] = "wxyz"
    (tmp_path / "bad.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="bad.json's quaternion_order must be one of"):
        load_fit(tmp_path / "bad.json")


def test_the_identity_in_the_other_order_is_named_by_a_table_from_the_identity_only(tmp_path):
    """``[0, 0, 0, 1]`` read scalar first is 180 deg about z: refused, and the refusal says why."""
    first = _fit({}, meta={"from_identity_only": True})
    qf = quat.from_axis_angle([0, 0, 1], math.radians(60.0))
    with pytest.raises(ValueError, match=r"read scalar first\); it is the identity written \[x, y, z, w\].*"
                                         r"quaternion_order='scalar_last'"):
        first([0.0, 0.0, 0.0, 1.0], list(_last(qf)))
    with pytest.raises(ValueError, match=r"q0\[0\] must be the identity .*written \[x, y, z, w\]"):
        first.slew_time_many(np.array([[0.0, 0.0, 0.0, 1.0]]), _last(qf)[None, :])
    first.save(tmp_path / "fit.json")
    last = load_fit(tmp_path, quaternion_order="scalar_last")
    expected = bang_bang([0, 0, 1], math.radians(60.0))
    assert last([0.0, 0.0, 0.0, 1.0], list(_last(qf))) == pytest.approx(expected, rel=1e-12)
    with pytest.raises(ValueError, match=r"read scalar last\); it is the identity written \[w, x, y, z\]"):
        last([1.0, 0.0, 0.0, 0.0], qf.tolist())
    # another start is refused without the hint
    with pytest.raises(ValueError, match=r"read scalar first\)$"):
        first(quat.from_axis_angle([1, 0, 0], 0.3).tolist(), qf.tolist())


def test_a_bad_quaternion_is_refused_in_the_fits_order(tmp_path):
    """A ``scalar_last`` fit's refusals of what is not 4 numbers said "(scalar first)"."""
    _fit({}).save(tmp_path / "fit.json")
    for order, words, other in (("scalar_last", "scalar last", "scalar first"),
                                ("scalar_first", "scalar first", "scalar last")):
        fit = load_fit(tmp_path, quaternion_order=order)
        unit = [0.0, 0.0, 0.0, 1.0]
        for call, q0, qf in ((fit, np.array([0, 0, 1.0]), unit),  # an array of 3
                             (fit, (np.float64(0.0), np.float64(0.0), np.float64(0.0), "1"), unit),  # text
                             (fit, object(), unit),  # not numbers
                             (fit.slew_time_many, np.zeros((2, 3)), np.array(unit)),
                             (fit.slew_time_many, "abcd", np.array(unit))):
            with pytest.raises(TypeError, match=f"q0 (and qf )?must be .*4 numbers.*\\({words}\\)") as raised:
                call(q0, qf)
            assert other not in str(raised.value)
