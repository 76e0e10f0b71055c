"""The eigenaxis planner's reserve of wheel momentum for the environment's torque
(planners/eigenaxis.py, ``WheelBudget.momentum_reserve``): ``‖(A⁺)_i‖ (‖d‖ + g) T`` per working
wheel, ``T`` the slew's own duration for ``min_time``.

Oracles, none from the planner's code:

* the minimum time by hand: wheels on the body axes, a rest-to-rest slew about the principal axis
  x (no gyroscopic torque), so the profile is bang-coast-bang at ``α = (L − r) / J_x`` (``r`` the
  torque kept for the environment on x) and coast rate ``w = (H − (‖d‖ + g) T) / J_x`` (wheel x's
  momentum ``J_x θ̇``), ``T = Θ / w + w / α``; the least ``T`` solving this (``scipy.optimize.brentq``)
  is the planner's, once with a constant disturbance, once with the gravity gradient alone;
* the momentum a torque of norm ``D`` held for ``T`` puts into wheel ``i`` through the min-norm
  allocation (``numpy.linalg.lstsq`` of ``A g = τ``), maximised over directions sampled on the
  sphere: the reserve covers every direction and is no larger than the worst one.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from ocp import CircularOrbit, Environment, ReactionWheels, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem
from planners.eigenaxis import WheelBudget

INERTIA = np.diag([2.0, 2.5, 3.0])
L, H = 0.01, 0.05  # the wheels' torque [N m] and momentum [N m s] bounds
ANGLE = math.pi / 2


def _problem(environment: Environment, wheels: ReactionWheels | None = None) -> ManeuverProblem:
    wheels = ReactionWheels.from_body_axes(max_torque=L, max_momentum=H) if wheels is None else wheels
    return ManeuverProblem(Spacecraft(INERTIA, wheels=wheels), quat.IDENTITY, np.zeros(3),
                           quat.from_axis_angle(np.array([1.0, 0.0, 0.0]), ANGLE), 300.0, omegaf=np.zeros(3),
                           environment=environment)


def _least_time(torque_kept: float, momentum_rate: float) -> float:
    """The least T with T = Θ / w(T) + w(T) / α, w(T) = (H − momentum_rate T) / J_x."""
    j = INERTIA[0, 0]
    alpha = (L - torque_kept) / j

    def excess(t: float) -> float:
        w = (H - momentum_rate * t) / j
        assert ANGLE >= w * w / alpha  # the coast is reached: bang-coast-bang
        return ANGLE / w + w / alpha - t

    low = ANGLE / (H / j) + (H / j) / alpha  # no reserve: a lower bound, excess > 0 there
    high = low
    while excess(high) > 0.0:
        high *= 1.05
    return brentq(excess, low, high, xtol=1e-12, rtol=1e-14)


def test_min_time_reserves_the_disturbances_momentum_over_its_own_duration():
    disturbance = np.array([0.0, 1e-4, 0.0])  # across the slew's axis: no torque kept on x
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(_problem(Environment(disturbance_torque=disturbance)))
    expected = _least_time(0.0, float(np.linalg.norm(disturbance)))
    assert reference.ok and abs(reference.duration - expected) <= 1e-5 * expected, (reference.duration, expected)
    # the reserve matters here: without it the slew takes 10 % less
    assert _least_time(0.0, 0.0) < 0.9 * expected


def test_min_time_reserves_the_gravity_gradients_momentum():
    problem = _problem(Environment(orbit=CircularOrbit(altitude=500e3), gravity_gradient=True))
    _, g = problem.environment_torque_bound(problem.duration)
    n2 = 3.986004418e14 / (6378137.0 + 500e3) ** 3
    assert g >= 1.5 * n2 * (3.0 - 2.0) and g <= 1.01 * 1.5 * n2  # 3 n² (I_max − I_min) / 2, by hand
    reference = PLANNERS["eigenaxis"]({"profile": "min_time"}).plan(problem)
    expected = _least_time(g, g)
    assert reference.ok and abs(reference.duration - expected) <= 1e-5 * expected, (reference.duration, expected)
    assert _least_time(g, 0.0) < (1 - 1e-3) * expected  # without the momentum reserve: measurably shorter


def _fibonacci_sphere(n: int) -> np.ndarray:
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = math.pi * (1.0 + math.sqrt(5.0)) * k
    r = np.sqrt(1.0 - z * z)
    return np.column_stack([r * np.cos(phi), r * np.sin(phi), z])


def test_each_wheels_reserve_is_its_worst_direction_of_the_disturbance():
    beta = math.radians(30.0)  # a pyramid whose allocation rows mix unequal entries
    s, c = math.sin(beta), math.cos(beta)
    axes = np.array([[s, 0, c], [0, s, c], [-s, 0, c], [0, -s, c]]).T
    disturbance = np.array([2e-5, -1e-5, 3e-5])
    horizon = 120.0
    problem = _problem(Environment(disturbance_torque=disturbance), ReactionWheels(axes, max_torque=L, max_momentum=H))
    budget = WheelBudget(problem, np.array([1.0, 0.0, 0.0]), ANGLE, 1.0, horizon=horizon)
    directions = _fibonacci_sphere(100_000)
    shares = np.linalg.lstsq(axes, directions.T, rcond=None)[0]  # (4, n): each direction's min-norm allocation
    worst = np.max(np.abs(shares), axis=1) * np.linalg.norm(disturbance) * horizon
    reserve = budget.momentum_reserve
    assert reserve.shape == (4,)
    assert np.all(worst <= reserve * (1 + 1e-12)), (worst, reserve)  # covers every direction
    assert np.all(worst >= reserve * (1 - 1e-3)), (worst, reserve)  # and no more than the worst one
