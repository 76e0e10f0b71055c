"""The search between samples against oracles it does not use: the interpolated motion sampled by
brute force at 1e5+ points (``hermite_attitudes``, the margin and the error angle computed from the
attitudes with ``quat.rotate`` and ``quat.error_angle``, not through the search), and closed forms
of a cone crossed by a constant-rate turn.

A search whose screening bound were unsound (a rate bound below the interpolant's rate) would miss
the grazes below: each lies between two points of the sub-grid, less deep than half the turn over a
sub-grid step (checked by hand: the rate bound halved misses them).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from ocp import quat
from ocp.geometry.pointing import HermiteMotion, PointingConstraint, hermite_attitudes
from scenarios.requirements.scoring import worst_error_between_samples

DENSE = 200_001


def dense_margin(constraint: PointingConstraint, t: np.ndarray, q: np.ndarray, omega: np.ndarray,
                 times: np.ndarray) -> np.ndarray:
    """The margin of the interpolated motion at ``times`` by brute force (``quat.rotate``, ``arccos``)."""
    attitudes = hermite_attitudes(t, q, omega, times)
    pointing = quat.rotate(attitudes, constraint.boresight)
    direction = constraint.direction(times)
    angle = np.arccos(np.clip(np.sum(pointing * direction, axis=1) / np.linalg.norm(pointing, axis=1), -1.0, 1.0))
    excess = angle - constraint.limit(times)
    margin = excess if constraint.keep_out else -excess
    return np.where((times >= constraint.window[0]) & (times <= constraint.window[1]), margin, np.nan)


def least(constraint: PointingConstraint, t: np.ndarray, q: np.ndarray, omega: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """The least margin by brute force: DENSE points over the span, then DENSE more over the two
    steps about the least of them; also the first sampling and its margins."""
    times = np.linspace(t[0], t[-1], DENSE)
    margin = dense_margin(constraint, t, q, omega, times)
    best = int(np.nanargmin(margin))
    around = np.linspace(times[max(best - 1, 0)], times[min(best + 1, DENSE - 1)], DENSE)
    return float(min(np.nanmin(margin), np.nanmin(dense_margin(constraint, t, q, omega, around)))), times, margin


def off_the_path(t: np.ndarray, q: np.ndarray, omega: np.ndarray, boresight: np.ndarray, when: float,
                 offset: float) -> np.ndarray:
    """The direction ``offset`` [rad] off the boresight's path at ``when``, across the path."""
    on_path, ahead = quat.rotate(hermite_attitudes(t, q, omega, [when, when + 1e-4]), boresight)
    side = np.cross(on_path, ahead - on_path)
    side /= np.linalg.norm(side)
    return np.asarray(math.cos(offset) * on_path + math.sin(offset) * side)


def wobbling(seed: int, count: int, step: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A smooth motion (a turn about a slowly precessing axis at a varying rate) integrated finely
    and sampled every ``step`` s: attitudes and body rates that agree."""
    rng = np.random.default_rng(seed)
    fine = 50
    h = step / fine
    base = rng.normal(size=3)
    tilt = rng.normal(size=3)
    rate0, rate1 = rng.uniform(0.02, 0.08), rng.uniform(-0.02, 0.02)
    q = quat.random_unit(rng)
    samples_q, samples_w = [], []
    for i in range((count - 1) * fine + 1):
        time = i * h

        def omega_at(s: float) -> np.ndarray:
            axis = base + tilt * math.sin(0.1 * s)
            return (rate0 + rate1 * math.sin(0.05 * s)) * axis / np.linalg.norm(axis)

        if i % fine == 0:
            samples_q.append(q.copy())
            samples_w.append(omega_at(time))
        # RK4 on q̇ = ½ q ⊗ [0, ω]
        k1 = quat.kinematics(q, omega_at(time))
        k2 = quat.kinematics(q + 0.5 * h * k1, omega_at(time + 0.5 * h))
        k3 = quat.kinematics(q + 0.5 * h * k2, omega_at(time + 0.5 * h))
        k4 = quat.kinematics(q + h * k3, omega_at(time + h))
        q = quat.normalize(q + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4))
    return np.arange(count) * step, np.array(samples_q), np.array(samples_w)


@pytest.mark.parametrize("seed", range(6))
def test_the_rate_bound_holds_over_every_interval_against_a_dense_sampling(seed: int) -> None:
    t, q, omega = wobbling(seed, 25, 2.0)
    motion = HermiteMotion(t, q, omega)
    times = np.linspace(t[0], t[-1], DENSE)
    attitudes = hermite_attitudes(t, q, omega, times)
    rate = 2.0 * np.linalg.norm(np.diff(attitudes, axis=0), axis=1) / np.diff(times)  # chord rate <= true rate
    largest = np.zeros(len(t) - 1)
    np.maximum.at(largest, np.clip(np.searchsorted(t, times[:-1], side="right") - 1, 0, len(t) - 2), rate)
    assert np.all(largest <= motion.rate_bound)
    assert np.all(motion.rate_bound <= 1.25 * largest)  # not vacuous: tight (measured: at most 1.17 x)


def test_the_drift_bounds_a_moving_directions_rate() -> None:
    """A direction table turning 170 deg between two rows: the normalised linear interpolation turns
    fastest mid-row, 2 tan(85 deg) / 10 s, far above the mean 170 deg / 10 s."""
    angle = math.radians(170.0)
    constraint = PointingConstraint("c", [1.0, 0.0, 0.0], True, 0.1, times=[0.0, 10.0],
                                    directions=[[1.0, 0.0, 0.0], [math.cos(angle), math.sin(angle), 0.0]])
    times = np.linspace(0.0, 10.0, DENSE)
    direction = constraint.direction(times)
    turn = np.arccos(np.clip(np.sum(direction[1:] * direction[:-1], axis=1), -1.0, 1.0)) / np.diff(times)
    assert np.max(turn) > 2.0 * angle / 10.0
    assert np.max(turn) <= constraint.drift <= 1.001 * np.max(turn)


@pytest.mark.parametrize("seed", range(8))
def test_a_narrow_cone_grazed_between_samples_against_a_dense_sampling(seed: int) -> None:
    """A cone about a direction a hair off the boresight's path at a time between two samples (and
    between two points of the sub-grid), its half-angle a little more than that offset: the motion
    grazes it for a moment only. The score must find it as the brute force does."""
    rng = np.random.default_rng(100 + seed)
    t, q, omega = wobbling(seed, 21, 1.0)
    boresight = np.array([1.0, 0.0, 0.0])
    offset, depth = math.radians(0.004), math.radians(rng.uniform(0.0005, 0.003))
    direction = off_the_path(t, q, omega, boresight, float(rng.uniform(3.0, 17.0)), offset)
    constraint = PointingConstraint("graze", boresight, True, offset + depth, directions=[direction])
    score = constraint.score_between_samples(t, q, omega)
    dense_min, times, margin = least(constraint, t, q, omega)
    assert dense_min < 0.0  # the oracle sees the graze
    assert np.all(constraint.margins(t, q) > math.radians(0.05))  # the samples do not
    assert not score.met
    # the search finds the graze at least as deep as the brute force (whose points straddle it)
    assert score.min_margin_deg == pytest.approx(math.degrees(dense_min), abs=1e-8)
    inside = np.count_nonzero(margin < 0.0) * (times[1] - times[0])
    assert score.time_in_violation_s == pytest.approx(inside, abs=2 * (times[1] - times[0]) + 1e-4)


@pytest.mark.parametrize("seed", range(4))
def test_a_clear_pass_keeps_the_brute_forces_least_margin(seed: int) -> None:
    """The same pass with the cone a little narrower than the offset: met, and the least margin the
    brute force's (the search does not report a violation the interpolated motion does not have)."""
    rng = np.random.default_rng(200 + seed)
    t, q, omega = wobbling(seed, 21, 1.0)
    boresight = np.array([0.0, 1.0, 0.0])
    offset = math.radians(0.01)
    direction = off_the_path(t, q, omega, boresight, float(rng.uniform(3.0, 17.0)), offset)
    constraint = PointingConstraint("pass", boresight, True, 0.5 * offset, directions=[direction])
    score = constraint.score_between_samples(t, q, omega)
    dense_min = least(constraint, t, q, omega)[0]
    assert dense_min > 0.0
    assert score.met
    assert score.min_margin_deg == pytest.approx(math.degrees(dense_min), abs=1e-8)


RATE = 0.05  # rad/s about the inertial z axis


def turning(t: np.ndarray, through: float) -> tuple[np.ndarray, np.ndarray]:
    """Body x at azimuth RATE (t − through) in the inertial xy-plane: attitude and body rate."""
    half = 0.5 * RATE * (t - through)
    q = np.stack([np.cos(half), np.zeros_like(t), np.zeros_like(t), np.sin(half)], axis=-1)
    return q, np.tile([0.0, 0.0, RATE], (t.size, 1))


def test_a_crossing_at_a_window_edge_between_samples_by_closed_form() -> None:
    """Body x passes azimuth 0 at 4.3 s; a 1 deg keep-out about the x axis whose window opens at
    4.4 s, between the samples 4 and 5 s: inside the cone at the window's opening (azimuth 0.29 deg),
    out of it from 4.3 + 1 deg / RATE = 4.649 s (closed form). Both samples 4 and 5 s lie outside
    the cone; the violation is the window's edge to the exit."""
    t = np.arange(0.0, 10.5, 1.0)
    q, omega = turning(t, 4.3)
    cone = math.radians(1.0)
    constraint = PointingConstraint("edge", [1.0, 0.0, 0.0], True, cone, directions=[[1.0, 0.0, 0.0]],
                                    window=(4.4, 8.0))
    assert np.all(np.nan_to_num(constraint.margins(t, q), nan=1.0) > 0.0)
    score = constraint.score_between_samples(t, q, omega)
    exit_time = 4.3 + cone / RATE
    assert not score.met
    assert score.first_violation_s == pytest.approx(4.4, abs=1e-12)
    assert score.time_in_violation_s == pytest.approx(exit_time - 4.4, abs=1e-4)
    assert score.min_margin_time_s == pytest.approx(4.4, abs=1e-12)
    assert score.min_margin_deg == pytest.approx(math.degrees(RATE * 0.1 - cone), abs=1e-6)


def test_a_crossing_just_inside_a_window_edge_by_closed_form() -> None:
    """The window closes at 4.301 s, 0.001 s after body x passes a 0.01 deg cone's centre at 4.3 s
    (it enters at 4.3 − 0.0035 s, would leave at 4.3035 s): a violation of 0.0045 s that ends at the
    window's edge, with the least margin at the centre."""
    t = np.arange(0.0, 10.5, 1.0)
    q, omega = turning(t, 4.3)
    cone = math.radians(0.01)
    constraint = PointingConstraint("edge", [1.0, 0.0, 0.0], True, cone, directions=[[1.0, 0.0, 0.0]],
                                    window=(0.0, 4.301))
    score = constraint.score_between_samples(t, q, omega)
    enter = 4.3 - cone / RATE
    assert not score.met
    assert score.first_violation_s == pytest.approx(enter, abs=1e-4)
    assert score.time_in_violation_s == pytest.approx(4.301 - enter, abs=1e-5)
    assert score.min_margin_time_s == pytest.approx(4.3, abs=1e-5)
    assert score.min_margin_deg == pytest.approx(-math.degrees(cone), abs=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_the_final_error_between_samples_against_a_dense_sampling(seed: int) -> None:
    """The largest error angle to the attitude at 8 s, from 6.5 s on, of a wobbling motion: the
    brute force's, whether asked for a bound just below it (broken between the samples) or none."""
    t, q, omega = wobbling(seed, 21, 1.0)
    target = q[8]
    times = np.linspace(6.5, t[-1], DENSE)
    dense = quat.error_angle(hermite_attitudes(t, q, omega, times), target)
    largest = float(np.max(dense))
    for limit in (None, largest - 1e-6):
        worst, when = worst_error_between_samples(t, q, omega, target, 6.5, limit)
        assert worst >= largest - 1e-12
        assert worst == pytest.approx(largest, abs=1e-8)
        assert when == pytest.approx(float(times[np.argmax(dense)]), abs=1e-3)


def test_a_final_error_peaking_between_samples_by_closed_form() -> None:
    """A turn about z at RATE through the target at 4.3 s: from 5.0 s the error is RATE (t − 4.3),
    largest at the last sample; from 2.0 s to the end it is largest at the end too; the error at
    the start 4.0 s between samples... the largest of |RATE (t − 4.3)| over [4.1, 4.6]: at 4.6."""
    t = np.arange(0.0, 4.61, 0.2)
    q, omega = turning(t, 4.3)
    worst, when = worst_error_between_samples(t, q, omega, quat.IDENTITY, 4.1, math.radians(0.5))
    assert worst == pytest.approx(RATE * 0.3, abs=1e-9)
    assert when == pytest.approx(4.6, abs=1e-9)
    q, omega = turning(t, 4.5)  # error RATE |t − 4.5| from 4.1: 0.02 rad at 4.1, 0.005 at 4.6
    worst, when = worst_error_between_samples(t, q, omega, quat.IDENTITY, 4.1)
    assert worst == pytest.approx(RATE * 0.4, abs=1e-9)
    assert when == pytest.approx(4.1, abs=1e-9)


def test_a_window_between_two_samples_is_scored_by_closed_form() -> None:
    """A 0.01 rad keep-out about the x axis whose window, [4.25, 4.28] s, lies between the samples
    4 and 5 s: the boresight at azimuth RATE (t − 4.3) is inside the cone throughout it, deepest
    at 4.28 s (margin 0.001 − 0.01 rad). No sample lies in the window (fcaf45b scored no point)."""
    t = np.arange(0.0, 10.5, 1.0)
    q, omega = turning(t, 4.3)
    constraint = PointingConstraint("short", [1.0, 0.0, 0.0], True, 0.01, directions=[[1.0, 0.0, 0.0]],
                                    window=(4.25, 4.28))
    assert np.all(np.isnan(constraint.margins(t, q)))
    score = constraint.score_between_samples(t, q, omega)
    assert not score.met
    assert score.min_margin_deg == pytest.approx(math.degrees(RATE * 0.02 - 0.01), abs=1e-9)
    assert score.min_margin_time_s == pytest.approx(4.28, abs=1e-12)
    assert score.first_violation_s == pytest.approx(4.25, abs=1e-12)
    assert score.time_in_violation_s == pytest.approx(0.03, abs=1e-9)
