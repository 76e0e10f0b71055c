"""The star tracker's schedule at the edges of its outage windows, by hand: a window ``[t0, t1)``
holds no update, so the sample at ``t0`` has none and the sample at ``t1`` has one again."""
from __future__ import annotations

import numpy as np

from ocp.estimation.sensors import StarTracker


def test_an_outage_is_closed_at_its_start_and_open_at_its_end():
    """Updates every sample of 0..8 s; outages [2, 4) and [5.5, 6): 2 and 3 have none, 4 has one
    (the end is open), 5 has one and 6 has one (no sample inside the second window but its end)."""
    tracker = StarTracker(noise=[1e-5] * 3, outages=((2.0, 4.0), (5.5, 6.0)))
    available = tracker.available(np.arange(9.0))
    assert np.flatnonzero(~available).tolist() == [2, 3]


def test_an_update_due_by_the_rate_at_an_outages_end_is_given():
    """At 0.5 Hz on samples every second, updates fall at 0, 2, 4, 6, 8 s; an outage [2, 6) drops
    those at 2 and 4 and keeps the one at 6."""
    tracker = StarTracker(noise=[1e-5] * 3, rate=0.5, outages=((2.0, 6.0),))
    assert np.flatnonzero(tracker.available(np.arange(9.0))).tolist() == [0, 6, 8]
