"""The actuator requirement holds for the wheels flown: with a truth model, the lesser of the design's
and the truth's limits.

A fresh-eyes engineer signing off a pyramid slew (2026-12-02) found a row "ok" whose reference asked
107 % of the truth wheels' momentum (``truth.wheels.max_momentum``) under a 20 % margin, the closed
loop saturating 11 % of the time: the requirement read the design's limits only.

Oracle: the demand does not depend on the limits (the same reference, the same allocation), so with
one limit for every wheel each ratio scales exactly by design limit / truth limit; the design-only
scenario's ratio is the reference.
"""
import numpy as np
import pytest

import scenarios

DESIGN_MOMENTUM, DESIGN_TORQUE = 4.0, 0.1


SPIN_INERTIA = 0.01  # kg m^2, each wheel's


def _data(truth_wheels=None, final_q=(0.7071068, 0.4082483, 0.4082483, 0.4082483), momentum=DESIGN_MOMENTUM):
    data = {
        "name": "truth-limits",
        "spacecraft": {"inertia": [19.5, 19.0, 12.6],
                       "wheels": {"max_torque": DESIGN_TORQUE, "spin_inertia": SPIN_INERTIA}},
        "maneuver": {"duration": 120.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": list(final_q), "omega": [0, 0, 0]}},
        "planners": [{"name": "eigenaxis", "options": {"profile": "smooth"}}],
        "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.06, "kd": 0.48}},
        "simulation": {"sample_time": 0.5, "duration": 140.0},
        "requirements": {"actuators": {"margin": 0.2}},
    }
    if momentum is not None:
        data["spacecraft"]["wheels"]["max_momentum"] = momentum
    if truth_wheels is not None:
        data["truth"] = {"wheels": truth_wheels}
    return data


def _run(truth_wheels=None, **options):
    (row,) = scenarios.run(scenarios.parse_scenario(_data(truth_wheels, **options))).rows
    return row


@pytest.fixture(scope="module")
def design():
    row = _run()
    assert row.status == "ok", row.message
    return row.requirements["reference"]["actuators"]


def test_a_truth_wheel_below_the_demand_breaks_the_requirement(design):
    ratio = design["wheels_momentum"]
    truth = 0.9 * ratio * DESIGN_MOMENTUM  # the reference asks 1.11x the truth's momentum limit
    row = _run({"max_momentum": truth})
    scored = row.requirements["reference"]["actuators"]
    assert scored["wheels_momentum"] == pytest.approx(ratio * DESIGN_MOMENTUM / truth, rel=1e-9)
    assert scored["wheels_torque"] == pytest.approx(design["wheels_torque"], rel=1e-12)  # design torque kept
    assert row.status == "violated"
    assert "wheels_momentum" in row.message and "truth model's" in row.message


def test_a_truth_torque_limit_scales_the_torque_ratio(design):
    truth = 0.5 * DESIGN_TORQUE
    row = _run({"max_torque": truth})
    scored = row.requirements["reference"]["actuators"]
    assert scored["wheels_torque"] == pytest.approx(design["wheels_torque"] * 2.0, rel=1e-9)
    assert scored["wheels_momentum"] == pytest.approx(design["wheels_momentum"], rel=1e-12)


def test_truth_limits_above_the_design_change_nothing(design):
    row = _run({"max_torque": 2 * DESIGN_TORQUE, "max_momentum": 2 * DESIGN_MOMENTUM})
    assert row.requirements["reference"]["actuators"] == design
    assert row.status == "ok", row.message


def test_a_truth_speed_limit_bounds_the_momentum(design):
    # |h| <= J_s * Omega_max (the wheel's speed relative to the body, the body rate's share left out):
    # a reviewer's run with 60 rpm was "ok" while the truth wheels saturated 75 % of the time
    rpm = 60.0
    stored = SPIN_INERTIA * rpm * 2 * np.pi / 60
    row = _run({"max_speed_rpm": rpm})
    scored = row.requirements["reference"]["actuators"]
    assert scored["wheels_momentum"] == pytest.approx(design["wheels_momentum"] * DESIGN_MOMENTUM / stored, rel=1e-9)
    assert row.status == "violated" and "truth model's" in row.message
    # a tester read only "does not honour the pointing requirement" and wondered why a planner that
    # honours the actuators broke them: it honours the design's limits
    assert "the planners plan to the design's, above it" in row.message, row.message


def test_the_message_blames_the_truth_only_for_the_wheel_that_broke_its_limit():
    # a slew about x: the x wheel breaks its design limit; the y wheel's truth limit is lower but
    # it is asked almost nothing
    final = (0.7071068, 0.7071068, 0.0, 0.0)
    row = _run({"max_momentum": [0.5, 0.3, 0.5]}, final_q=final, momentum=0.5)
    assert row.status == "violated"
    assert "wheels_momentum" in row.message and "truth model's" not in row.message, row.message
    lowered = _run({"max_momentum": [0.3, 0.5, 0.5]}, final_q=final, momentum=0.5)  # now the x wheel's
    assert "truth model's" in lowered.message, lowered.message


def test_a_limit_only_the_truth_has_is_a_study_column():
    from scenarios.requirements.scoring import score_fields

    scenario = scenarios.parse_scenario(_data({"max_momentum": 0.5}, momentum=None))
    fields = score_fields(scenario.requirements, scenario.problem.spacecraft, scenario.truth)
    assert "wheels_momentum" in fields["reference"]["actuators"]
    assert "wheels_momentum" not in score_fields(scenario.requirements, scenario.problem.spacecraft)["reference"][
        "actuators"]


def test_a_truth_dipole_scale_error_lowers_the_magnetorquers_limit():
    # the truth delivers (1 + e) times the saturated command (ocp.dynamics.truth.Truth): a -40 % error
    # on x leaves the plant 0.6 of the design's dipole there; a +20 % error on z lets it deliver more,
    # which the scoring's minimum with the design's limit then ignores. A reviewer found the scale
    # error left out of the limits (2026-12-02).
    from ocp import AttitudeModel, CircularOrbit, Environment, Magnetorquers, Spacecraft
    from ocp.dynamics.environment import MAGNETIC_FIELDS
    from ocp.dynamics.truth import Truth, TruthPlant
    from scenarios.requirements.scoring import plant_limits

    max_dipole = 0.2
    orbit, dipole = CircularOrbit(altitude=550e3, inclination=np.deg2rad(97.6)), MAGNETIC_FIELDS["tilted_dipole"]
    design = AttitudeModel(Spacecraft([0.1, 0.12, 0.08], magnetorquers=Magnetorquers(max_dipole=max_dipole)),
                           Environment(orbit=orbit, magnetic_field=dipole.from_options(dipole.Options(), orbit)))
    limits = plant_limits(TruthPlant(design, Truth(dipole_scale_error=[-0.4, 0.0, 0.2])))
    assert limits["magnetorquers_dipole"] == pytest.approx([0.12, 0.2, 0.24], rel=1e-12)
    assert plant_limits(TruthPlant(design, Truth(residual_dipole=[0.01, 0, 0])))["magnetorquers_dipole"] == \
        pytest.approx([max_dipole] * 3, rel=1e-12)
