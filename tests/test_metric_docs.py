"""The metric table (``ocp.metrics.METRIC_INFO``, rendered as the documentation's metrics page)
documents every key ``compute_metrics`` returns and nothing else, and says "null" exactly for the
keys that can be null."""
from __future__ import annotations

import numpy as np

from ocp import METRIC_KEYS, quat
from ocp.metrics import METRIC_INFO, MetricInfo, compute_metrics

NEVER_NULL = {"int_u2", "int_u", "int_abs_u", "peak_body_torque", "final_rate"}
"""Keys that compute_metrics fills whatever the optional inputs (read off its return statement)."""


def minimal_metrics() -> dict:
    """compute_metrics with every optional input left out, on a motion that never settles its rate."""
    t = np.linspace(0.0, 2.0, 5)
    q = np.tile(quat.IDENTITY, (5, 1))
    omega = np.full((5, 3), 1.0)  # above the detumble tolerance at every sample: detumble_time_s is null
    return compute_metrics(t, q, omega, np.zeros((4, 3)), target_q=None)


def test_every_metric_key_is_documented_and_nothing_else() -> None:
    assert list(METRIC_INFO) == list(METRIC_KEYS)
    assert set(minimal_metrics()) == set(METRIC_KEYS)  # the keys compute_metrics actually returns


def test_every_entry_has_a_unit_and_a_definition() -> None:
    for key, info in METRIC_INFO.items():
        assert isinstance(info, MetricInfo), key
        assert info.unit.strip() and info.meaning.strip(), key


def test_nullable_keys_say_when_they_are_null() -> None:
    null_here = {key for key, value in minimal_metrics().items() if value is None}
    assert null_here == set(METRIC_KEYS) - NEVER_NULL
    for key, info in METRIC_INFO.items():
        assert ("null" in info.meaning) == (key not in NEVER_NULL), key
