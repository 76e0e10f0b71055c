"""Pointing constraints (:mod:`ocp.geometry.pointing`): margins, scores, windows, growth, and the
CasADi constraint.

Oracles, worked by hand: a rotation about z at rate w sweeps the body x boresight through
``[cos wt, sin wt, 0]``; its angle to the y axis is ``|π/2 − wt|``, so a cone of half-angle α about y
is entered at ``wt = π/2 − α`` and left at ``π/2 + α``. The margin is piecewise linear in t with its
kink on a sample, so the linear interpolation of the score is exact there. The CasADi expression is
checked against ``cos θ − cos(limit)`` written out in NumPy (its own rotation matrix, its own table
look-up).
"""
from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from ocp.geometry import PointingConstraint, PointingScore, violation_intervals
from ocp.geometry.pointing import FINE_STEP, HermiteMotion

W = 0.1          # rad/s, the sweep rate
ALPHA = 0.3      # rad, the cone's half-angle
T_STAR = 0.5 * np.pi / W   # the boresight crosses y
T = np.linspace(0.0, 2.0 * T_STAR, 1001)   # T_STAR is T[500]
Y = np.array([[0.0, 1.0, 0.0]])


def sweep(t: np.ndarray, rate: float = W) -> np.ndarray:
    """Quaternions (scalar first) of a rotation about z by ``rate t``."""
    half = 0.5 * rate * np.asarray(t)
    return np.stack([np.cos(half), np.zeros_like(half), np.zeros_like(half), np.sin(half)], axis=-1)


def cone(keep_out: bool = True, angle: float = ALPHA, **kwargs) -> PointingConstraint:
    return PointingConstraint("tracker", np.array([2.0, 0.0, 0.0]), keep_out, angle, directions=kwargs.pop("directions", Y),
                              **kwargs)


# --- scores worked by hand ------------------------------------------------------------------------

def test_a_keep_out_swept_through_scores_its_time_first_violation_and_depth():
    constraint = cone()
    score = constraint.score(T, sweep(T))
    assert score.time_in_violation_s == pytest.approx(2 * ALPHA / W, abs=1e-9)          # 6 s
    assert score.first_violation_s == pytest.approx(T_STAR - ALPHA / W, abs=1e-9)        # 12.708 s
    assert score.min_margin_deg == pytest.approx(-np.degrees(ALPHA), abs=1e-9)           # -17.19 deg
    assert score.min_margin_time_s == pytest.approx(T_STAR, abs=1e-12)
    assert not score.met
    margins = constraint.margins(T, sweep(T))
    np.testing.assert_allclose(margins, np.abs(0.5 * np.pi - W * T) - ALPHA, atol=1e-12)


def test_a_keep_in_is_broken_outside_the_cone_from_the_start():
    constraint = cone(keep_out=False)
    score = constraint.score(T, sweep(T))
    assert score.time_in_violation_s == pytest.approx(T[-1] - 2 * ALPHA / W, abs=1e-9)
    assert score.first_violation_s == 0.0
    assert score.min_margin_deg == pytest.approx(np.degrees(ALPHA - 0.5 * np.pi), abs=1e-9)
    assert score.min_margin_time_s == 0.0                       # the first of two equal minima
    # the sweep held inside the cone: met
    inside = cone(keep_out=False).score(T[450:551], sweep(T[450:551]))
    assert inside.met and inside.time_in_violation_s == 0.0 and inside.first_violation_s is None
    assert inside.min_margin_deg == pytest.approx(np.degrees(ALPHA - 50 * W * (T[1] - T[0])), abs=1e-9)


def test_a_window_counts_only_what_lies_inside_it():
    end = T[450]   # 14.137 s, inside the violation (12.708 to 18.708 s)
    score = cone(window=(0.0, end)).score(T, sweep(T))
    assert score.time_in_violation_s == pytest.approx(end - (T_STAR - ALPHA / W), abs=1e-9)
    assert score.first_violation_s == pytest.approx(T_STAR - ALPHA / W, abs=1e-9)
    assert score.min_margin_deg == pytest.approx(np.degrees(abs(0.5 * np.pi - W * end) - ALPHA), abs=1e-9)
    assert score.min_margin_time_s == pytest.approx(end)
    after = cone(window=(20.0, 30.0)).score(T, sweep(T))
    first_inside = T[T >= 20.0][0]
    assert after.met and after.time_in_violation_s == 0.0 and after.first_violation_s is None
    assert after.min_margin_deg == pytest.approx(np.degrees(W * first_inside - 0.5 * np.pi - ALPHA), abs=1e-9)
    beyond = cone(window=(40.0, 50.0)).score(T, sweep(T))
    assert beyond == PointingScore(None, 0.0, None, None) and beyond.met
    margins = cone(window=(20.0, 30.0)).margins(T, sweep(T))
    assert np.isnan(margins[T < 20.0]).all() and np.isnan(margins[T > 30.0]).all()
    assert np.isfinite(margins[(T >= 20.0) & (T <= 30.0)]).all()


def test_growth_widens_the_cone():
    growth = 0.1
    constraint = cone(times=[0.0, 100.0], directions=np.vstack([Y, Y]), growth=[growth, growth])
    score = constraint.score(T, sweep(T))
    assert score.time_in_violation_s == pytest.approx(2 * (ALPHA + growth) / W, abs=1e-9)
    assert score.first_violation_s == pytest.approx(T_STAR - (ALPHA + growth) / W, abs=1e-9)
    assert score.min_margin_deg == pytest.approx(-np.degrees(ALPHA + growth), abs=1e-9)
    # growth varying linearly: limit(t) interpolates it
    ramp = cone(times=[0.0, 10.0], directions=np.vstack([Y, Y]), growth=[0.0, 0.2])
    np.testing.assert_allclose(ramp.limit([-1.0, 0.0, 2.5, 10.0, 12.0]), ALPHA + np.array([0.0, 0.0, 0.05, 0.2, 0.2]))


def test_a_moving_direction_is_followed():
    # the direction turns about z at w2 from y: relative angle |π/2 − (w − w2) t|
    w2 = 0.04
    t_star = 0.5 * np.pi / (W - w2)
    t = np.linspace(0.0, 2 * t_star, 1001)
    table_t = np.linspace(0.0, 2 * t_star, 2001)
    directions = np.stack([-np.sin(w2 * table_t), np.cos(w2 * table_t), np.zeros_like(table_t)], axis=-1)
    constraint = cone(times=table_t, directions=directions)
    assert constraint.moving
    score = constraint.score(t, sweep(t))
    assert score.time_in_violation_s == pytest.approx(2 * ALPHA / (W - w2), abs=1e-6)   # 10 s
    assert score.first_violation_s == pytest.approx(t_star - ALPHA / (W - w2), abs=1e-6)
    assert score.min_margin_deg == pytest.approx(-np.degrees(ALPHA), abs=1e-6)


def test_violation_intervals_by_hand():
    t = np.arange(6.0)
    assert violation_intervals(t, np.array([1.0, -1.0, 1.0, 1.0, -3.0, -1.0])) == [(0.5, 1.5), (3.25, 5.0)]
    assert violation_intervals(t, np.array([-1.0, 1.0, np.nan, -1.0, np.nan, 2.0])) == [(0.0, 0.5), (3.0, 3.0)]
    assert violation_intervals(t, np.full(6, np.nan)) == [] == violation_intervals(t, np.ones(6))


# --- construction ----------------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, words", [
    ({"boresight": [0.0, 0.0, 0.0]}, "boresight"), ({"boresight": [1.0, 0.0]}, "boresight"),
    ({"angle": 0.0}, "half-angle"), ({"angle": np.pi}, "half-angle"), ({"angle": np.nan}, "half-angle"),
    ({"times": [0.0, 1.0], "directions": Y}, "1 directions"),
    ({"times": [1.0, 0.0], "directions": np.vstack([Y, Y])}, "increase"),
    ({"directions": [[0.0, 0.0, 0.0]]}, "non-zero"),
    ({"growth": [0.0, 1.0]}, "growth"), ({"window": (5.0, 5.0)}, "window"),
])
def test_a_malformed_constraint_is_refused(kwargs, words):
    arguments = {"name": "c", "boresight": [1.0, 0.0, 0.0], "keep_out": True, "angle": 0.5, "directions": Y} | kwargs
    with pytest.raises(ValueError, match=words):
        PointingConstraint(**arguments)


def test_tightening_identity_and_windows():
    keep_out, keep_in = cone(), cone(keep_out=False)
    assert keep_out.tightened(0.01).angle == pytest.approx(ALPHA + 0.01)
    assert keep_in.tightened(0.01).angle == pytest.approx(ALPHA - 0.01)
    assert cone() == cone() and hash(cone()) == hash(cone()) and cone() != keep_in and cone() != cone(angle=0.2)
    windowed = cone(window=(10.0, 20.0))
    assert windowed.applies_between(0.0, 10.0) and windowed.applies_between(15.0, 16.0)
    assert not windowed.applies_between(20.5, 30.0) and not windowed.applies_between(0.0, 9.0)
    assert windowed.in_window([9.9, 10.0, 20.0, 20.1]).tolist() == [False, True, True, False]


# --- the CasADi constraint against NumPy written out ------------------------------------------------

def rotation_by_hand(q: np.ndarray) -> np.ndarray:
    """R(q) for a unit quaternion, scalar first, body to inertial."""
    a, b, c, d = q
    return np.array([[a*a + b*b - c*c - d*d, 2*(b*c - a*d), 2*(b*d + a*c)],
                     [2*(b*c + a*d), a*a - b*b + c*c - d*d, 2*(c*d - a*b)],
                     [2*(b*d - a*c), 2*(c*d + a*b), a*a - b*b - c*c + d*d]])


def g_by_hand(constraint: PointingConstraint, times: np.ndarray, table: np.ndarray, growth: np.ndarray,
              q: np.ndarray, t: float) -> float:
    """cos θ − cos(angle + growth(t)) (keep-out), its negative (keep-in); the table read by hand,
    held beyond its ends."""
    t = min(max(t, times[0]), times[-1])
    k = min(int(np.searchsorted(times, t, side="right")) - 1, len(times) - 2)
    s = (t - times[k]) / (times[k + 1] - times[k])
    direction = (1 - s) * table[k] + s * table[k + 1]
    direction = direction / np.linalg.norm(direction)
    boresight = rotation_by_hand(q) @ (constraint.boresight)
    limit = constraint.angle + (1 - s) * growth[k] + s * growth[k + 1]
    value = boresight @ direction - np.cos(limit)
    return value if constraint.keep_out else -value


@pytest.mark.parametrize("keep_out", [True, False])
def test_the_casadi_expression_is_cos_theta_minus_cos_limit_on_a_moving_table(keep_out):
    rng = np.random.default_rng(11)
    times = np.sort(rng.uniform(0.0, 100.0, 9))
    times[0] = 0.0
    table = rng.normal(size=(9, 3))
    growth = 0.1 + 0.05 * np.sin(times)
    constraint = PointingConstraint("c", rng.normal(size=3), keep_out, 0.7, times=times, directions=table,
                                    growth=growth)
    q_sym, t_sym = ca.MX.sym("q", 4), ca.MX.sym("t")
    g = ca.Function("g", [q_sym, t_sym], [constraint.expression(q_sym, t_sym)])
    for t in np.concatenate([rng.uniform(0.0, 100.0, 40), times, [-5.0, 130.0]]):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        expected = g_by_hand(constraint, times, table / np.linalg.norm(table, axis=1, keepdims=True), growth, q, t)
        assert float(g(q, t)) == pytest.approx(expected, abs=1e-12), f"t = {t}"
        # g <= 0 exactly where the margin is non-negative
        if 0.0 <= t <= 100.0:
            margin = constraint.margins([t], q[None, :])[0]
            assert (float(g(q, t)) <= 0.0) == (margin >= 0.0) or abs(margin) < 1e-12


def test_the_casadi_expression_of_a_fixed_direction():
    constraint = cone(growth=[0.05])
    q_sym = ca.MX.sym("q", 4)
    g = ca.Function("g", [q_sym], [constraint.expression(q_sym, 0.0)])
    for q in sweep(T[::50]):
        expected = (rotation_by_hand(q) @ [1.0, 0.0, 0.0]) @ Y[0] - np.cos(ALPHA + 0.05)
        assert float(g(q)) == pytest.approx(expected, abs=1e-14)


@pytest.mark.parametrize("times", [[0.0, 1.0, 1.001, 3.0], [0.0, 1.0, 1.0, 2.5]], ids=["increasing", "repeated"])
def test_a_motions_sample_steps_by_hand(times):
    """The steps between a motion's samples as the search cuts them, per step: its length, the rate
    bound of the sample interval holding it (at a repeated time the later interval, as
    ``HermiteMotion.interval`` says) and ``max(4, ceil(turn rate x length / FINE_STEP))``, written out
    step by step here."""
    t = np.asarray(times)
    rates = np.array([[0.0, 0.0, 0.1], [0.0, 0.02, 0.1], [0.01, 0.0, 0.2], [0.0, 0.0, 0.05]])
    motion = HermiteMotion(t, sweep(t), rates)
    h, bound, fine = motion.sample_steps
    for k in range(len(t) - 1):
        holding = max(i for i in range(len(t) - 1) if t[i] <= t[k])  # the later interval at a repeat
        assert h[k] == t[k + 1] - t[k]
        assert bound[k] == motion.rate_bound[holding]
        assert fine[k] == max(4, int(np.ceil(motion.turn_rate[holding] * (t[k + 1] - t[k]) / FINE_STEP)))
