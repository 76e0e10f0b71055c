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
    held = np.abs(row.simulation.wheel_momentum) >= LOW * (1 - 1e-9)  # the states at the limit, to rounding
    first = int(np.argmax(held.any(axis=1)))
    wheel = int(np.argmax(held[first]))  # the first there: earliest, then the lowest index
    assert h[first, wheel] == pytest.approx(LOW, rel=1e-6)  # the oracle agrees it is there
    t = row.simulation.t
    at = np.flatnonzero(held.any(axis=1))
    spans = [b - a for a, b, ka, kb in zip(t[:-1], t[1:], held.any(axis=1)[:-1], held.any(axis=1)[1:]) if ka and kb]
    assert at.size > 10 and spans  # held there a while, not touched once
    assert not score.met
    assert score.values["wheels_momentum"] >= AT_LIMIT
    assert score.values["wheels_momentum_time_s"] == t[first]
    assert score.detail.startswith(f"wheels_momentum at its limit, 1 x (wheel {wheel}: {LOW:g} N m s, the first "
                                   f"there) from {t[first]:.1f} s to {t[at[-1]]:.1f} s, "
                                   f"{sum(spans):.3g} s at the limit in all"), score.detail
    (message,) = violations({"closed_loop": scores})
    assert message.startswith("actuators (closed loop): wheels_momentum at its limit")
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
    assert "at or over its limit, up to 1.11 x" in score.detail and "truth model's" not in score.detail
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


def test_the_wheel_named_is_the_first_at_its_limit_and_the_time_there_is_said():
    # by hand: wheel 0 at its 0.3 N m s limit from 3 s to 5 s; wheel 2 touches it at 4 s, its
    # rounding a little higher: the first there (wheel 0, 3 s) is named, not the rounding's peak
    spacecraft = _scenario(LOW).problem.spacecraft
    t = np.arange(11.0)
    h = np.zeros((11, 3))
    h[:, 0] = h[:, 2] = 0.2
    h[3:6, 0] = 0.30000000000000004
    h[4, 2] = 0.3000000000000001
    score = closed_loop_wheels(spacecraft, t, np.zeros((11, 3)), h)
    assert not score.met and score.values["wheels_momentum_time_s"] == 3.0
    assert score.detail.startswith("wheels_momentum at its limit, 1 x (wheel 0: 0.3 N m s, the first there) "
                                   "from 3.0 s to 5.0 s, 2 s at the limit in all"), score.detail
    # one sample touching it reads as such, not as a wheel held there
    h[3:6, 0] = 0.2
    h[6, 1] = -0.3
    score = closed_loop_wheels(spacecraft, t, np.zeros((11, 3)), h)
    assert score.detail.startswith("wheels_momentum at its limit, 1 x (wheel 2: 0.3 N m s, the first there) "
                                   "on 2 separate samples from 4.0 s to 6.0 s"), score.detail
    h[4, 2] = 0.2
    score = closed_loop_wheels(spacecraft, t, np.zeros((11, 3)), h)
    assert score.detail.startswith("wheels_momentum at its limit, 1 x (wheel 1: 0.3 N m s, the first there) "
                                   "at 6.0 s, on that sample only"), score.detail
    # just below the limit: met, and it does not read as 1 where a value at the limit is marked
    h[4, 2] = h[6, 1] = 0.3 * 0.99998
    score = closed_loop_wheels(spacecraft, t, np.zeros((11, 3)), h)
    assert score.met and not score.detail


def test_a_met_and_a_broken_ratio_never_read_alike(low):
    from scenarios.output.results import RunResults
    from scenarios.output.tables import ratio_text
    assert ratio_text(0.99998) == "0.99998" and ratio_text(0.99998, broken=True) == "0.99998"
    assert ratio_text(1.0000000000000002) == "1"  # a reference at its allowed limit: met
    assert ratio_text(1.0000000000000007, broken=True) == "at limit"  # a closed loop held there: broken
    assert ratio_text(1.00001, broken=True) == "1.00001" and ratio_text(0.9211) == "0.9211"
    scenario, row = low  # the closed loop at its limit: the terminal and Markdown say so
    results = RunResults(scenario, [row])
    assert "| cl.req.actuators.wheels_momentum | at limit |" in results.to_markdown()
    (line,) = [line for line in results.to_terminal().splitlines() if line.startswith("req.actuators")]
    assert line.endswith("| at limit ✗"), line
