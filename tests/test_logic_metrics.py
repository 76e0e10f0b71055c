"""Metric boundaries against hand-worked samples (issue 33): the detumbling threshold (a rate equal
to the bound is not detumbled; ``docs/metrics.rst``: the last sample with max |ω_i| ≥ bound) and the
physical-range check of fractions (at most 1, 1 itself allowed)."""
import numpy as np
import pytest

from ocp import compute_metrics, metric_violations, quat

T = np.arange(6.0)


def detumble(rates, tolerance=0.01):
    omega = np.zeros((T.size, 3))
    omega[:, 1] = rates  # on one axis, with its sign
    q = np.tile(quat.IDENTITY, (T.size, 1))
    return compute_metrics(T, q, omega, np.zeros((T.size - 1, 3)), None, detumble_tolerance=tolerance)["detumble_time_s"]


@pytest.mark.parametrize("rates, expected", [
    ([0.05, 0.02, 0.01, 0.009, 0.0, 0.0], 3.0),    # 0.01 at t = 2 is at the bound: not yet detumbled
    ([0.05, 0.02, 0.0099, 0.009, 0.0, 0.0], 2.0),  # just below the bound from t = 2
    ([-0.05, 0.0, 0.0, -0.01, 0.0, 0.0], 4.0),     # a negative rate counts by its size
    ([0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0),         # below throughout
    ([0.0, 0.0, 0.0, 0.0, 0.0, 0.01], None),       # at the bound at the last sample
])
def test_detumble_time_boundary(rates, expected):
    assert detumble(rates) == expected


def test_detumble_tolerance_option_is_used():
    assert detumble([0.05, 0.02, 0.01, 0.009, 0.0, 0.0], tolerance=0.03) == 1.0


@pytest.mark.parametrize("value, bad", [(1.0, False), (0.0, False), (0.5, False), (1.0 + 1e-12, True),
                                        (1.5, True), (-0.1, True), (float("nan"), True)])
def test_fraction_metrics_must_lie_in_zero_one(value, bad):
    assert bool(metric_violations({"saturation_fraction": value})) is bad


def test_only_fractions_are_bounded_by_one():
    assert metric_violations({"settling_time_s": 12.0, "int_u": 3.5, "peak_u": 1.5}) == []
    assert metric_violations({"saturation_fraction": 2.0, "int_u": 3.5}) == ["saturation_fraction = 2.0"]
    assert metric_violations({"duration_s": 0.0}) == ["duration_s = 0.0"]
    assert metric_violations({"int_abs_u": [0.1, -0.2, 0.3]}) == ["int_abs_u = [0.1, -0.2, 0.3]"]


@pytest.mark.parametrize("errors, expected", [
    ([5.0, 2.0, 1.0, 0.5, 1.0, 0.2], 2.0),   # 1.0 deg is at the band: settled (docs: "at or below")
    ([5.0, 2.0, 1.0, 0.5, 1.01, 0.2], 5.0),  # just outside at t = 4
    ([0.5, 0.2, 0.1, 0.0, 0.0, 1.0], 0.0),   # inside throughout
    ([0.5, 0.2, 0.1, 0.0, 0.0, 1.5], None),  # outside at the last sample
])
def test_settling_time_boundary(errors, expected):
    from ocp.metrics import settling_time
    assert settling_time(T, np.array(errors), 1.0) == expected
