"""The closed loop's wheels are held to the actuator limits the reference's demand is: a closed loop
whose wheel reaches its momentum limit (the simulator then cuts the motor torque the law asks) or,
under a truth model, its speed limit breaks the actuator requirement in the closed loop.

The scenario: the eigenaxis demo's 90 deg slew on three wheels along the body axes, tracked from an
initial rate error of 0.01 rad/s per axis, which the wheels take up on top of the slew's momentum:
the closed loop needs more momentum than the reference asks.

Oracle: without an environment torque the total angular momentum is conserved in the inertial frame,
``R(q) (I ω + A h) = H₀``, with ``A`` the identity (wheels along the body axes), so the wheel momenta
are ``h = R(q)ᵀ H₀ − I ω``, computed here from the closed loop's attitude and body rate alone, not
from its wheel states nor from the scoring; the wheel speed relative to the body is
``Ω = h / J_s − ω`` per axis.
"""
import copy

import numpy as np
import pytest

import scenarios
from ocp import quat
from scenarios.requirements.scoring import (
    AT_LIMIT,
    closed_loop_wheels,
    plant_limits,
    score_closed_loop,
    score_fields,
    violations,
)

INERTIA = np.diag([19.5, 19.0, 12.6])
SPIN_INERTIA = 0.01  # kg m^2
RATE_ERROR = [0.01, -0.01, 0.01]  # rad/s, the closed loop's initial rate error
DATA = {
    "name": "closed-loop-wheel-momentum",
    "spacecraft": {"inertia": np.diag(INERTIA).tolist(),
                   "wheels": {"max_torque": 0.1, "max_momentum": 4.0, "spin_inertia": SPIN_INERTIA}},
    "maneuver": {"duration": 120.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.7071068, 0.4082483, 0.4082483, 0.4082483], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "options": {"profile": "smooth"}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.06, "kd": 0.48}},
    "simulation": {"sample_time": 0.5, "duration": 140.0, "initial_rate_error": RATE_ERROR},
}
LOW = 0.3  # N m s: the reference asks 0.92 of it, the closed loop more (0.43 N m s with 4 N m s wheels)


def _scenario(max_momentum, truth=None):
    data = copy.deepcopy(DATA)
    data["spacecraft"]["wheels"]["max_momentum"] = max_momentum
    if max_momentum is None:
        del data["spacecraft"]["wheels"]["max_momentum"]
    if truth is not None:
        data["truth"] = {"wheels": truth}
    return scenarios.parse_scenario(data)


def _flown(max_momentum, truth=None):
    scenario = _scenario(max_momentum, truth)
    (row,) = scenarios.run(scenario).rows
    return scenario, row


def _scores(scenario, row):
    sim = row.simulation
    return score_closed_loop(scenario.requirements, scenario.problem, sim.t, sim.q, sim.omega,
                             row.reference.duration, row.reference, sim.wheel_momentum, scenario.truth)


def _conserved_momenta(sim):
    """The wheel momenta from the conservation of the total angular momentum (module docstring)."""
    h0 = quat.rotate(sim.q[0], INERTIA @ sim.omega[0] + sim.wheel_momentum[0])
    return quat.rotate_inverse(sim.q, np.tile(h0, (sim.t.size, 1))) - sim.omega @ INERTIA


@pytest.fixture(scope="module")
def generous():
    return _flown(4.0)


@pytest.fixture(scope="module")
def low():
    return _flown(LOW)


def test_the_oracle_is_the_closed_loops_own_wheel_momentum(generous):
    _, row = generous
    sim = row.simulation
    h = _conserved_momenta(sim)
    assert np.max(np.abs(h - sim.wheel_momentum)) < 1e-6 * np.max(np.abs(h))


def test_generous_wheels_meet_it(generous):
    scenario, row = generous
    score = _scores(scenario, row)["actuators"]
    peak = np.abs(_conserved_momenta(row.simulation))
    assert score.met and not score.detail
    assert score.values["wheels_momentum"] == pytest.approx(np.max(peak) / 4.0, rel=1e-6)
    worst = np.unravel_index(np.argmax(peak), peak.shape)[0]
    assert score.values["wheels_momentum_time_s"] == row.simulation.t[worst]
    assert not violations({"closed_loop": {"actuators": score}})
    # the run's row: scored so, and ok
    assert row.requirements["closed_loop"]["actuators"] == {"met": True, **score.values}
    assert row.status == "ok", row.message


def test_a_closed_loop_at_its_momentum_limit_breaks_it_where_the_reference_meets_it(low):
    scenario, row = low
    scores = _scores(scenario, row)
    score = scores["actuators"]
    h = np.abs(_conserved_momenta(row.simulation))
    # the oracle: the closed loop's wheel reaches the limit (the simulator holds it there)
    assert np.max(h) == pytest.approx(LOW, rel=1e-6)
    wheel = int(np.unravel_index(np.argmax(h), h.shape)[1])
    assert not score.met
    assert score.values["wheels_momentum"] >= AT_LIMIT
    assert f"wheel {wheel} momentum" in score.detail and f"{LOW:g} N m s limit" in score.detail
    assert f"at {score.values['wheels_momentum_time_s']:.1f} s" in score.detail
    (message,) = violations({"closed_loop": scores})
    assert message.startswith("actuators (closed loop): wheel")
    # the run's row: violated, by the closed loop's wheel alone
    assert row.status == "violated" and row.message.startswith(message), row.message
    assert row.requirements["closed_loop"]["actuators"] == {"met": False, **score.values}
    # the reference's demand is within the same limit: the closed loop alone breaks it
    assert row.requirements["reference"]["actuators"]["met"]
    assert row.requirements["reference"]["actuators"]["wheels_momentum"] < 1.0


def test_a_truth_speed_limit_reached_breaks_it():
    speed_rpm = 300.0
    scenario, row = _flown(4.0, {"max_speed_rpm": speed_rpm})
    score = _scores(scenario, row)["actuators"]
    sim = row.simulation
    speed = np.abs(_conserved_momenta(sim) / SPIN_INERTIA - sim.omega) * 60.0 / (2.0 * np.pi)
    assert np.max(speed) >= speed_rpm * (1 - 1e-6)  # the oracle: the wheel reached its speed limit
    assert score.values["wheels_speed"] == pytest.approx(np.max(speed) / speed_rpm, rel=1e-6)
    assert not score.met and "speed" in score.detail and "truth.wheels.max_speed_rpm" in score.detail


def test_a_truth_momentum_limit_above_the_design_s_holds_the_closed_loop_to_the_design(generous):
    scenario, row = generous
    sim = row.simulation
    peak = float(np.max(np.abs(_conserved_momenta(sim))))
    design = _scenario(0.9 * peak, {"max_momentum": 2 * peak})  # the truth's wheels hold it, the design's not
    score = closed_loop_wheels(design.problem.spacecraft, sim.t, sim.omega, sim.wheel_momentum, design.truth)
    assert score is not None and not score.met
    assert score.values["wheels_momentum"] == pytest.approx(1 / 0.9, rel=1e-6)
    assert "over its" in score.detail and "truth model's" not in score.detail
    lowered = _scenario(2 * peak, {"max_momentum": 0.9 * peak})
    assert plant_limits(lowered.truth)["wheels_momentum"] == pytest.approx(0.9 * peak)
    score = closed_loop_wheels(lowered.problem.spacecraft, sim.t, sim.omega, sim.wheel_momentum, lowered.truth)
    assert score is not None and not score.met and "truth model's" in score.detail


def test_unlimited_wheels_or_no_actuator_requirement_score_nothing(generous):
    _, row = generous
    sim = row.simulation
    data = copy.deepcopy(DATA)
    del data["spacecraft"]["wheels"]["max_momentum"]
    unlimited = scenarios.parse_scenario(data)
    assert closed_loop_wheels(unlimited.problem.spacecraft, sim.t, sim.omega, sim.wheel_momentum) is None
    assert "actuators" not in score_fields(unlimited.requirements, unlimited.problem.spacecraft)["closed_loop"]
    data = copy.deepcopy(DATA)
    data["requirements"] = {"actuators": None}
    off = scenarios.parse_scenario(data)
    assert "actuators" not in score_closed_loop(off.requirements, off.problem, sim.t, sim.q, sim.omega,
                                                row.reference.duration, row.reference, sim.wheel_momentum)


@pytest.mark.parametrize("max_momentum, truth", [(4.0, None), (4.0, {"max_speed_rpm": 300.0}),
                                                 (None, {"max_speed_rpm": 300.0})])
def test_the_declared_fields_are_those_scored(generous, max_momentum, truth):
    # without a design momentum limit, a truth speed limit gives the speed only (the momentum
    # J_s Ω_max the reference is held to is not the closed loop's: its speed is scored itself)
    _, row = generous
    scenario = _scenario(max_momentum, truth)
    sim = row.simulation
    declared = score_fields(scenario.requirements, scenario.problem.spacecraft, scenario.truth)["closed_loop"]
    score = closed_loop_wheels(scenario.problem.spacecraft, sim.t, sim.omega, sim.wheel_momentum, scenario.truth)
    assert score is not None
    assert declared["actuators"] == ("met", *score.values)
    assert ("wheels_momentum" in score.values) == (max_momentum is not None)
