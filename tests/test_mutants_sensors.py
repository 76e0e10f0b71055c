"""The sensors' models at their edges, by hand: a star tracker's outage window ``[t0, t1)`` (the
sample at ``t0`` has no update, the sample at ``t1`` has one again), its sensor frame (the shortest
rotation taking z to the boresight), an exclusion cone past a half turn; the gyro's draws against
the continuous model they discretise."""
from __future__ import annotations

import math

import numpy as np
import pytest

from ocp.estimation.sensors import Exclusion, Gyro, StarTracker


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


@pytest.mark.parametrize("arw, rrw, dt", [(0.0, 1e-3, 12.0), (2e-4, 0.0, 0.5), (2e-4, 3e-5, 0.1)])
def test_the_gyros_draws_give_the_continuous_models_angle_variance_over_a_sample(arw, rrw, dt):
    """Farrenkopf's model integrated over one sample from a known bias: the angle error is
    ``∫ (σ_u W(t) + σ_v ν(t)) dt``, of variance ``σ_u² Δt³ / 3 + σ_v² Δt`` (W a Wiener process,
    ν white noise). The discrete reading errs by ``(β_{k+1} − β_k) / 2 + white`` a sample, so its
    angle error ``Δt × that`` has variance ``Δt² (walk² / 4 + white²)``: the two must agree."""
    walk, white = Gyro(arw=arw, rrw=rrw).scales(dt)
    assert walk == pytest.approx(rrw * math.sqrt(dt), rel=1e-15)  # the bias's increment: σ_u √Δt
    assert dt ** 2 * (walk ** 2 / 4.0 + white ** 2) == pytest.approx(rrw ** 2 * dt ** 3 / 3.0 + arw ** 2 * dt,
                                                                      rel=1e-12)


@pytest.mark.parametrize("boresight", [[0, 1, 1], [1, 1, 1], [1, 0, 0], [0.2, -0.3, -0.9], [0, 0, 1], [0, 0, -1]])
def test_the_sensor_frame_is_the_shortest_rotation_taking_z_to_the_boresight(boresight):
    """A rotation (orthonormal, determinant 1) that takes z to the boresight and leaves the axis
    z × b of the shortest turn where it is (its angle arccos(z·b)); a boresight along −z is a half
    turn about x, as documented."""
    tracker = StarTracker(noise=[1e-5] * 3, boresight=boresight)
    rotation = tracker.sensor_to_body
    b = np.asarray(boresight, dtype=float) / np.linalg.norm(boresight)
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-14)
    np.testing.assert_allclose(rotation @ [0.0, 0.0, 1.0], b, atol=1e-14)
    axis = np.cross([0.0, 0.0, 1.0], b)
    np.testing.assert_allclose(rotation @ axis, axis, atol=1e-14)
    assert np.trace(rotation) == pytest.approx(1.0 + 2.0 * b[2], abs=1e-14)  # 1 + 2 cos(angle)


def test_an_exclusion_grown_past_a_half_turn_covers_the_whole_sky():
    """A half-angle of π − 0.01 rad grown by 0.1 rad (a body's apparent radius) is a cone of more
    than a half turn: every direction but the exact opposite is inside it, so its cosine is
    cos π = −1, not cos(π + 0.09) = −0.996 (which would leave a 7.7° hole about the opposite)."""
    exclusion = Exclusion("moon", math.pi - 0.01, lambda times: (np.tile([1.0, 0.0, 0.0], (len(times), 1)),
                                                                  np.full(len(times), 0.1)))
    directions, cosines = exclusion.table(np.array([0.0, 5.0]))
    np.testing.assert_array_equal(cosines, [-1.0, -1.0])
    np.testing.assert_array_equal(directions, [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
