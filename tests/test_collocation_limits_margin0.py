"""``collocation`` plans within the actuator limits it is scored against, with no margin to spare.

A user's minimum-time slew on a 12U's 4-wheel pyramid (no ``requirements:`` section: the actuator
margin is 0) was scored ``violated``: its reference asked 1.0000003 x the wheels' momentum limit.
The solver relaxes every variable bound ``b`` by 1e-8 max(1, |b|) (IPOPT's ``bound_relax_factor``),
1e-8 N m s over a 0.03 N m s limit, and the optimum rides it. The wheel momenta are now imposed
2e-8 N m s inside (``STATE_BACKOFF``); the controls were saturated at their bounds already.

Each case's optimum rides the limit checked (a bang-bang torque, a momentum-capped coast): the
scored peak is within 1e-5 of the limit (not vacuous) and at most the limit itself, with no
tolerance but floating-point rounding for a torque the allocation gives back; the row is ``ok``.
"""
import copy

import numpy as np
import pytest

from planners.collocation.requirements import (
    SOLVER_BOUND_RELAXATION,
    STATE_BACKOFF,
    imposed_state_bounds,
)
from scenarios import parse_scenario, run

PYRAMID = np.array([[0.612372, 0.612372, 0.5], [-0.612372, 0.612372, 0.5], [-0.612372, -0.612372, 0.5],
                    [0.612372, -0.612372, 0.5]])
BASE = {
    "name": "limits-margin0",
    "spacecraft": {"inertia": [[0.21, -0.004, 0.003], [-0.004, 0.24, 0.002], [0.003, 0.002, 0.11]],
                   "wheels": {"axes": PYRAMID.tolist(), "max_torque": 0.004, "max_momentum": 0.03}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": {"axis_angle": {"axis": [0, 1, 1], "angle_deg": 120}}, "omega": [0, 0, 0]}},
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.06, "kd": 0.48}},
    "simulation": {"sample_time": 0.5, "duration": 90.0},
}


ROUNDING = 1e-12
"""A torque scored as the allocation gives it back, ``A⁺ (A u)``: floating-point rounding, 2e-15 seen."""


def _row(changes, options, requirements=True):
    data = copy.deepcopy(BASE)
    for key, value in changes.items():
        data[key] = {**data[key], **value}
    data["planners"] = [{"name": "collocation", "options": options}]
    if requirements:
        data["requirements"] = {"actuators": {"margin": 0.0}}
    row = run(parse_scenario(data)).rows[0]
    assert row.reference.ok, row.reference.message
    return row


def _ratios(row):
    scored = row.requirements["reference"]["actuators"]
    return {name: scored[name] for name in ("wheels_torque", "wheels_momentum", "torquers_torque") if name in scored}


@pytest.mark.parametrize("intervals", [20, 40])
def test_user_pyramid_min_time_is_ok_at_margin_0(intervals):
    """The user's case: the optimum coasts on the momentum limit (15.033 s, against eigenaxis's 15.162 s)
    between torque bangs; both scored peaks within the limits."""
    row = _row({}, {"objective": "min_time", "intervals": intervals})
    ratios = _ratios(row)
    assert row.status == "ok", row.message
    assert 1.0 - 1e-5 < ratios["wheels_momentum"] <= 1.0, ratios
    # the torque is the saturated control's, read back through the allocation's matrices: their rounding
    assert 1.0 - 1e-5 < ratios["wheels_torque"] <= 1.0 + ROUNDING, ratios
    assert 15.03 < row.reference.duration < 15.04


def test_without_a_requirements_section_the_margin_is_0_and_met():
    row = _row({}, {"objective": "min_time", "intervals": 20}, requirements=False)
    assert row.requirements is not None and row.status == "ok", row.message
    assert 1.0 - 1e-5 < _ratios(row)["wheels_momentum"] <= 1.0


def test_reference_states_stay_within_the_limit_where_the_scorer_reads():
    """The reference's own wheel momenta, on a grid 50 times the mesh's, at most 0.03 N m s."""
    row = _row({}, {"objective": "min_time", "intervals": 20})
    reference = row.reference
    x, _ = reference._interpolated(np.linspace(0.0, reference.duration, 50 * 20 * 20 + 1))
    peak = float(np.max(np.abs(x[:, 7:])))
    assert 0.03 * (1 - 1e-5) < peak <= 0.03 - SOLVER_BOUND_RELAXATION * 0.5, peak


def test_min_energy_riding_the_momentum_limit_at_margin_0():
    """Three orthogonal wheels, 90 deg about the 4 kg m^2 axis in 130 s: the minimum-energy cubic
    would peak at 1.5 Θ / T = 0.0181 rad/s, above the 0.05 N m s / 4 kg m^2 = 0.0125 rad/s the
    wheel's momentum allows, so the momentum limit is active (the dense check tightens it where the
    interpolant passes it between the points)."""
    assert 1.5 * np.deg2rad(90) / 130.0 > 0.05 / 4.0
    changes = {"spacecraft": {"inertia": [4.0, 5.0, 6.0],
                              "wheels": {"axes": np.eye(3).tolist(), "max_torque": 0.1, "max_momentum": 0.05}},
               "maneuver": {"duration": 130.0,
                            "final": {"q": {"axis_angle": {"axis": [1, 0, 0], "angle_deg": 90}}, "omega": [0, 0, 0]}},
               "simulation": {"duration": 180.0}}
    row = _row(changes, {"objective": "min_energy", "intervals": 30})
    ratios = _ratios(row)
    assert row.status == "ok", row.message
    assert 0.99 < ratios["wheels_momentum"] <= 1.0, ratios
    assert ratios["wheels_torque"] <= 1.0 + ROUNDING, ratios


def test_torque_box_min_time_at_margin_0():
    """Body torquers (a torque box, 0.5 N m per axis), 180 deg of the symmetric 10 kg m^2 body: the
    bang-bang rides every axis's bound; the scored peak within it."""
    changes = {"spacecraft": {"inertia": [10.0, 10.0, 10.0], "wheels": "none", "torquers": {"max_torque": 0.5}},
               "maneuver": {"final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
               "simulation": {"sample_time": 0.05, "duration": 25.0},
               "controller": {"options": {"kp": 2.0, "kd": 3.0}}}
    row = _row(changes, {"objective": "min_time", "intervals": 20})
    ratios = _ratios(row)
    assert row.status == "ok", row.message
    assert 1.0 - 1e-5 < ratios["torquers_torque"] <= 1.0, ratios


def test_imposed_state_bounds():
    """Hand values: the actuator states (from entry 7) 2e-8 inside a bound below 1, 2e-8 of the bound
    above 1; never past the start's value; the attitude and rate entries and infinite bounds kept."""
    assert STATE_BACKOFF == 2 * SOLVER_BOUND_RELAXATION == 2e-8
    low = np.array([-1.5] * 4 + [-0.1] * 3 + [-0.03, -2.0, -np.inf, -0.03])
    high = -low
    start = np.array([1.0, 0, 0, 0, 0, 0, 0, 0.0, 0.0, 5.0, 0.03])
    new_low, new_high = imposed_state_bounds(low, high, start)
    assert np.array_equal(new_low[:7], low[:7]) and np.array_equal(new_high[:7], high[:7])
    assert new_high[7] == 0.03 - 2e-8 and new_low[7] == -0.03 + 2e-8
    assert new_high[8] == pytest.approx(2.0 * (1 - 2e-8), rel=1e-15) and new_low[8] == pytest.approx(-2.0 * (1 - 2e-8))
    assert np.isinf(new_high[9]) and np.isinf(new_low[9])
    assert new_high[10] == 0.03 and new_low[10] == -0.03 + 2e-8  # a start at its bound keeps it
    assert np.array_equal(low, -high)  # the inputs untouched
