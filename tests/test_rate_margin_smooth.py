"""``rate_margin`` applies to the smooth profiles too (the eigenaxis quintic, the shape polynomials
with ``duration: rate_limit``), not only to a coast at the bound: a closed loop tracking a smooth
peak at the bound overshoots it as well.

The case: the user's 12U 90° slew (``test_honour_environment_and_rate``) under a 0.05 rad/s
requirement. Oracles by hand: the rest-to-rest quintic's peak rate ``15 Θ / (8 T)``; the closed
loop's peak rate is the simulation's, against the requirement.
"""
from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

import scenarios
from planners import PLANNERS
from tests.test_honour_environment_and_rate import ANGLE, SCENARIO, problem

REQUIRED = 0.05  # rad/s


def quintic_duration(peak: float) -> float:
    """T of the rest-to-rest quintic peaking at ``peak`` [rad/s]: 15 Θ / (8 peak)."""
    return 15 * ANGLE / (8 * peak)


@pytest.mark.parametrize("margin, status", [(None, "infeasible"), (0.001, "ok"), (0.0, "ok")])
def test_a_quintic_peaking_just_under_the_requirement_needs_a_smaller_margin(margin, status):
    slew = problem(False, rate_requirement=REQUIRED)
    slew = dataclasses.replace(slew, duration=quintic_duration(0.0497))
    options = {"profile": "smooth"} | ({} if margin is None else {"rate_margin": margin})
    reference = PLANNERS["eigenaxis"](options).plan(slew)
    assert reference.status == status, reference.message
    if status == "infeasible":  # the default margin plans 0.99 of the requirement, 0.0495 rad/s
        assert "rate_margin 0.01" in reference.message and "above the rate bound 0.0495" in reference.message
    else:
        t = np.linspace(0.0, reference.duration, 4001)
        assert np.max(np.linalg.norm(reference.omega(t), axis=1)) == pytest.approx(0.0497, rel=1e-6)


def closed_loop_rate(planner: dict, duration: float) -> tuple[float, float, str]:
    data = copy.deepcopy(SCENARIO)
    data["environment"]["gravity_gradient"] = False
    data["maneuver"]["duration"] = duration
    data["requirements"] = {"rate": {"max": REQUIRED}}
    data["planners"] = [dict(planner, label="smooth")]
    data["simulation"] = {"sample_time": 0.5, "duration": 120.0}
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    scores = row.requirements
    return scores["reference"]["rate"]["peak_rate"], scores["closed_loop"]["rate"]["peak_rate"], row.status


def test_a_tracked_quintic_at_the_requirement_overshoots_it_and_the_margin_keeps_it_within():
    # rate_margin 0: the quintic peaks at the requirement itself, and its closed loop above it
    reference, closed, status = closed_loop_rate({"name": "eigenaxis", "options": {"profile": "smooth",
                                                                                   "rate_margin": 0.0}},
                                                 quintic_duration(REQUIRED))
    assert reference == pytest.approx(REQUIRED, rel=1e-9)
    assert closed > REQUIRED and status == "violated"  # 1.000024 x (0.5 s samples)
    # the default margin: T for 0.99 of it, the closed loop within
    reference, closed, status = closed_loop_rate({"name": "eigenaxis", "options": {"profile": "smooth"}},
                                                 quintic_duration(0.99 * REQUIRED))
    assert reference == pytest.approx(0.99 * REQUIRED, rel=1e-9)
    assert closed <= REQUIRED and status == "ok"


def test_the_shape_polynomials_rate_limit_keeps_the_margin():
    # t_f = max_τ ‖ω_τ‖ / bound: 0.99 of the requirement lengthens it by 1/0.99 exactly
    slew = problem(False, rate_requirement=REQUIRED)
    planner = PLANNERS["shape_polynomial"]
    margin, none = planner({"terms": 2}).plan(slew), planner({"terms": 2, "rate_margin": 0.0}).plan(slew)
    assert margin.ok and none.ok, (margin.message, none.message)
    assert margin.duration == pytest.approx(none.duration / 0.99, rel=1e-9)
