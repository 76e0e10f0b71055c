"""The requirement fields' one declaration (:mod:`scenarios.requirements.fields`): it covers every
field the scorer emits, its units are right by arguments independent of it, and the report's
units, ``results.md``'s units line and the figures' axes read it.

The run: every requirement kind (a pointing keep-out, the actuators on wheels, torquers and
magnetorquers, a rate bound, the final error) on a 120 deg slew about the inertial z axis in 60 s
(the geometry of ``tests/test_requirements_runs.py``: the star tracker's boresight, in the body
xy-plane at azimuth -60 deg, sweeps through a 30 deg keep-out about inertial x and reaches its axis,
a margin of -30 deg) by natural motion (a torque-free arc of 50 s after a 10 s stop time, at the
constant rate (2π/3)/50 rad/s about z, left by a step at 50 s: a rate jump of that size) and the
quintic eigenaxis slew (peak rate 1.875 θ / T).
"""
from __future__ import annotations

import copy
import math

import pytest

import scenarios
from scenarios.output.plot_data import column_quantity
from scenarios.output.report.page import column_unit
from scenarios.output.tables import (
    flatten_row,
    requirement_columns,
    requirement_units,
    to_markdown,
)
from scenarios.requirements.fields import (
    QUANTITY,
    REQUIREMENT_FIELDS,
    VERDICT,
    field_info,
    requirement_kind,
)
from scenarios.requirements.scoring import (
    FINAL_FIELDS,
    JUMP_FIELDS,
    POINTING_FIELDS,
    RATE_FIELDS,
    UNREALISED_FIELDS,
    score_fields,
)
from scenarios.requirements.spec import RESERVED_NAMES

DURATION = 70.0
"""The run's simulated time [s] (the manoeuvre's 60 s and 10 s of hold)."""
EVERY_KIND = {
    "name": "every-requirement-kind",
    "spacecraft": {"inertia": [0.25, 0.28, 0.12], "wheels": {"max_torque": 0.003, "max_momentum": 0.004},
                   "torquers": {"max_torque": 0.01}, "magnetorquers": {"max_dipole": 0.2},
                   "sensors": {"star_tracker": {"boresight": [0.5, -0.8660254, 0.0]}}},
    "orbit": {"altitude_km": 600, "inclination_deg": 97.79},
    "environment": {"magnetic_field": "tilted_dipole"},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0, 0, 0.8660254], "omega": [0, 0, 0]}},
    "planners": [{"name": "natural_motion"}, {"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5, "duration": DURATION},
    "requirements": {"pointing": {"st": {"sensor": "star_tracker", "keep_out": {"inertial": [1, 0, 0]},
                                         "angle_deg": 30}},
                     "actuators": {"margin": 0.1}, "rate": {"max": 0.07},
                     "final": {"after_s": 5.0, "error_deg": 0.5, "rate": 1e-3}},
}
QUANTITIES = {"wheels_torque", "wheels_momentum", "torquers_torque", "magnetorquers_dipole"}
"""The actuator quantities with a limit on that spacecraft (each kind's command, the wheels' momentum)."""


@pytest.fixture(scope="module")
def every_kind():
    scenario = scenarios.parse_scenario(copy.deepcopy(EVERY_KIND))
    return scenario, scenarios.run(scenario)


def _columns(results) -> list[str]:
    return requirement_columns([{"requirements": row.requirements} for row in results.rows])


def test_every_field_the_scorer_emits_is_declared(every_kind):
    scenario, results = every_kind
    columns = _columns(results)
    names = {column.split(".")[2] for column in columns}
    assert names == {"st", "actuators", "rate", "final"}  # every kind emitted
    fields = {column.split(".")[3] for column in columns if column.split(".")[2] == "actuators"}
    assert QUANTITIES | {f"{q}_time_s" for q in QUANTITIES} <= fields  # wheels, torquers, magnetorquers
    for column in columns:
        info = field_info(column)  # raises for a field without a declaration
        assert info.field == column.split(".")[3]
        assert info.requirement == requirement_kind(column.split(".")[2])
        assert column.split(".")[0] in info.scopes, column  # the declaration says which scopes give it
    # the scorer's own list of the columns a scenario can give (a study's summary keys): the same
    expected = score_fields(scenario.requirements, scenario.problem.spacecraft)
    assert set(columns) == {f"{prefix}.req.{name}.{field}" for scope, prefix in (("reference", "ref"), ("closed_loop", "cl"))
                            for name, fields in expected[scope].items() for field in fields}
    assert all(fields[0] == VERDICT for scope in expected.values() for fields in scope.values())  # the runner's order


def test_the_declaration_names_the_scorers_fields_and_the_reserved_names():
    by_kind: dict[str, list[str]] = {}
    for info in REQUIREMENT_FIELDS:
        by_kind.setdefault(info.requirement, []).append(info.field)
    assert tuple(by_kind["pointing"]) == (VERDICT, *POINTING_FIELDS)
    assert tuple(by_kind["rate"]) == (VERDICT, *RATE_FIELDS)
    assert tuple(by_kind["final"]) == (VERDICT, *FINAL_FIELDS)
    assert tuple(by_kind["actuators"]) == (VERDICT, QUANTITY, f"{QUANTITY}_time_s") + JUMP_FIELDS + UNREALISED_FIELDS
    assert set(by_kind) - {"pointing"} == set(RESERVED_NAMES)
    assert {requirement_kind(name) for name in RESERVED_NAMES} == set(RESERVED_NAMES)
    for info in REQUIREMENT_FIELDS:
        assert info.unit.strip() and info.words.strip() and info.meaning.strip(), info.field
        # a name's unit suffix says its unit: the units line of results.md states them by suffix
        if info.field.endswith("_deg"):
            assert info.unit == "deg", info.field
        if info.field.endswith("_s"):
            assert info.unit == "s", info.field


def test_units_by_independent_arguments(every_kind):
    _, results = every_kind
    natural, eigenaxis = results.rows
    # rate_jump [rad/s]: natural motion leaves its arc at 50 s by a step from (2π/3)/50 rad/s to rest
    assert field_info("ref.req.actuators.rate_jump").unit == "rad/s"
    arc_rate = (2.0 * math.pi / 3.0) / 50.0  # rad/s, by construction (not deg/s: 2.4; not rpm: 0.4)
    assert natural.requirements["reference"]["actuators"]["rate_jump"] == pytest.approx(arc_rate, rel=1e-6)
    assert natural.requirements["reference"]["actuators"]["rate_jump_time_s"] == pytest.approx(50.0)
    # peak_rate [rad/s]: the quintic's peak 1.875 θ / T at mid-slew
    assert field_info("ref.req.rate.peak_rate").unit == "rad/s"
    assert eigenaxis.requirements["reference"]["rate"]["peak_rate"] == pytest.approx(
        1.875 * math.radians(120.0) / 60.0, rel=1e-6)
    # min_margin_deg [deg]: the boresight on the keep-out's axis, 30 deg inside a 30 deg cone
    assert field_info("cl.req.st.min_margin_deg").unit == "deg"
    assert eigenaxis.requirements["reference"]["st"]["min_margin_deg"] == pytest.approx(-30.0, abs=1e-6)
    # wheels_momentum [–]: the wheel about z holds I_zz ω at the arc's rate, over its 0.004 N m s
    assert field_info("ref.req.actuators.wheels_momentum").unit == "–"
    assert natural.requirements["reference"]["actuators"]["wheels_momentum"] == pytest.approx(
        0.12 * arc_rate / 0.004, rel=1e-4)
    # every time [s] lies within the run, and every field declared in s is a time
    times = 0
    for row in results.rows:
        for column, value in flatten_row(row.to_dict()).items():
            if column.startswith(("ref.req.", "cl.req.")) and field_info(column).unit == "s" and value is not None:
                assert 0.0 <= value <= DURATION, (row.label, column, value)
                times += 1
    assert times > 20


ONE_WHEEL = {
    "name": "one-wheel",
    "spacecraft": {"inertia": [2.0, 2.0, 2.0], "wheels": {"axes": [[1, 0, 0]], "max_torque": 0.1, "max_momentum": 10.0}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.7071068, 0, 0.7071068, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.8}},
    "simulation": {"sample_time": 0.5, "duration": 80.0},
    "requirements": {"actuators": {"margin": 0.0}},
}


def test_unrealised_torque_is_in_newton_metres():
    """90 deg about y on a sphere (I = 2 kg m²) with one wheel on x: the quintic asks
    I θ̈ about y, 2 x 5.7735 θ / T² N m at its peak, which no actuator gives."""
    row = scenarios.run(scenarios.parse_scenario(copy.deepcopy(ONE_WHEEL))).rows[0]
    assert field_info("ref.req.actuators.unrealised_torque").unit == "N m"
    peak = 2.0 * 5.7735 * (math.pi / 2.0) / 60.0**2  # N m: the quintic's peak acceleration times I
    assert row.requirements["reference"]["actuators"]["unrealised_torque"] == pytest.approx(peak, rel=1e-3)
    assert 0.0 <= row.requirements["reference"]["actuators"]["unrealised_torque_time_s"] <= 60.0


def test_the_report_the_units_line_and_the_axes_read_the_declaration(every_kind):
    _, results = every_kind
    columns = _columns(results)
    for column in columns:
        assert column_unit(column) == field_info(column).unit, column
        assert column_quantity(column)[1] == field_info(column).unit, column
    assert column_unit("ref.req.actuators.rate_jump") == "rad/s"  # was '–'
    assert column_unit("ref.req.actuators.unrealised_torque") == "N m"  # was '–'
    assert column_unit("ref.req.actuators.wheels_torque") == "–"
    assert column_unit("cl.req.st.peak_rate") == ""  # no such field of a pointing requirement
    with pytest.raises(KeyError, match="pointing requirement 'st'"):
        column_quantity("cl.req.st.peak_rate")
    line = next(text for text in to_markdown(results).splitlines() if text.startswith("Units:"))
    assert "peak demand over the limit" not in line
    assert line.endswith(requirement_units(columns)[1:] + ".")
    assert "rad/s: rate_jump, peak_rate, worst_rate_error" in line and "N m: unrealised_torque" in line
    assert "wheels_torque (peak wheels torque / limit)" in line and "*_s s" in line


def test_field_info_reads_columns_names_and_bare_fields():
    assert field_info("actuators.rate_jump") == field_info("ref.req.actuators.rate_jump") == field_info("rate_jump")
    assert field_info("magnetorquers_dipole_time_s").words == "time of peak magnetorquers dipole"
    assert field_info("ref.req.actuators.wheels_momentum").field == "wheels_momentum"
    for wrong in ("ref.req.rate.min_margin_deg", "cl.req.final.rate_jump", "ref.int_u", "x.req.st.min_margin_deg",
                  "", "a.b.c"):
        with pytest.raises(KeyError):
            field_info(wrong)
    # pointing, actuators (two patterns), rate, final, each with its verdict
    assert len(REQUIREMENT_FIELDS) == (1 + 4) + (1 + 7) + (1 + 3) + (1 + 3)
