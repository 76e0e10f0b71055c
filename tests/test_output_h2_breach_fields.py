"""The terminal's requirement line says which field breaks a requirement where its headline number
does not show it (``req.actuators 0.2513 ✗ rate_jump``): a tester read ``0.2954 ✗`` on a row
whose reference's rate jumps, the cause only in the message. The field named is the column of
``results.md`` and ``results.csv`` (``ref.req.actuators.rate_jump``) that shows it.

Oracles: scores built by hand against bounds stated here (a jump breaks at any size, an
unrealised torque over its allowed, a ratio over ``1 − margin``, the final rate error over its
bound), and a natural motion stopped by a step, whose rate jump is its whole spin rate."""
from __future__ import annotations

import copy
import csv
import io
from pathlib import Path

import pytest
import yaml

import scenarios
from scenarios.output.tables import _LIMIT_ROUNDING, _requirement_cell, breaking_fields
from scenarios.requirements.spec import (
    ActuatorRequirement,
    FinalRequirement,
    Requirements,
)
from tests.test_requirements_runs import with_direction

ROOT = Path(__file__).resolve().parents[1]

MARGIN = Requirements(actuators=ActuatorRequirement(margin=0.1), final=FinalRequirement(after_s=5.0, error_deg=0.1,
                                                                                         rate=1e-3))


def actuators(**fields):
    values = {"met": False, "wheels_torque": 0.2954, "wheels_torque_time_s": 3.0, "wheels_momentum": 0.1,
              "wheels_momentum_time_s": 9.0, "rate_jump": 0.0, "rate_jump_time_s": None, "unrealised_torque": 0.0,
              "unrealised_torque_time_s": None, "unrealised_torque_allowed": 1e-4}
    values.update(fields)
    return values


@pytest.mark.parametrize("values, fields, cell", [
    # the reported case: a jump behind a small torque ratio
    (actuators(rate_jump=0.0419, rate_jump_time_s=50.0), ["rate_jump"], "0.2954 ✗ rate_jump"),
    (actuators(unrealised_torque=2e-3, unrealised_torque_time_s=4.0), ["unrealised_torque"],
     "0.2954 ✗ unrealised_torque"),
    (actuators(unrealised_torque=None, unrealised_torque_time_s=4.0), ["unrealised_torque"],
     "0.2954 ✗ unrealised_torque not finite"),
    (actuators(wheels_momentum=None, wheels_momentum_time_s=2.0), ["wheels_momentum"],
     "0.2954 ✗ wheels_momentum not finite"),
    # a ratio over 1 − margin = 0.9 and a jump: both named
    (actuators(wheels_torque=0.95, rate_jump=0.01, rate_jump_time_s=1.0), ["wheels_torque", "rate_jump"],
     "0.95 ✗ wheels_torque, rate_jump"),
    # the headline alone breaks it: the number shown is the breach, nothing more to say
    (actuators(wheels_torque=0.95), ["wheels_torque"], "0.95 ✗"),
    # at 0.9 to rounding: met by that field, so only the jump breaks it
    (actuators(wheels_torque=0.9 * (1 + _LIMIT_ROUNDING / 2), rate_jump=0.01, rate_jump_time_s=1.0), ["rate_jump"],
     "0.9 ✗ rate_jump"),
    (actuators(met=True), [], "0.2954"),
])
def test_the_reference_actuator_cell_names_what_breaks_it(values, fields, cell):
    assert breaking_fields("actuators", "reference", values, MARGIN) == fields
    assert _requirement_cell("actuators", "reference", values, MARGIN) == cell


def test_without_the_bounds_only_what_the_fields_show_themselves_is_named():
    values = actuators(wheels_torque=0.95, rate_jump=0.01, rate_jump_time_s=1.0)
    assert breaking_fields("actuators", "reference", values) == ["rate_jump"]


def test_the_final_requirement_broken_by_its_rate_error_says_so():
    values = {"met": False, "worst_error_deg": 0.02, "worst_rate_error": 3e-3, "from_s": 65.0}
    assert breaking_fields("final", "closed_loop", values, MARGIN) == ["worst_rate_error"]
    assert _requirement_cell("final", "closed_loop", values, MARGIN) == "0.02 ✗ worst_rate_error"
    values["worst_error_deg"] = 0.5  # the error too: both named, the shown one first
    assert _requirement_cell("final", "closed_loop", values, MARGIN) == "0.5 ✗ worst_error_deg, worst_rate_error"


def test_a_closed_loop_at_its_limit_reads_as_before():
    values = {"met": False, "wheels_momentum": 1.0, "wheels_momentum_time_s": 6.5}
    assert breaking_fields("actuators", "closed_loop", values, MARGIN) == ["wheels_momentum"]
    assert _requirement_cell("actuators", "closed_loop", values, MARGIN) == "at limit ✗"


def test_a_closed_loop_names_every_quantity_at_its_limit():
    # the scoring's rule: a closed-loop state at AT_LIMIT of its limit or more is at it (a ratio
    # held there to rounding, 1 - 1e-12, too): both quantities break it, so both are named
    from scenarios.requirements.scoring import AT_LIMIT

    values = {"met": False, "wheels_momentum": 1.0, "wheels_momentum_time_s": 6.5,
              "wheels_speed": AT_LIMIT, "wheels_speed_time_s": 7.0}
    assert breaking_fields("actuators", "closed_loop", values, MARGIN) == ["wheels_momentum", "wheels_speed"]
    values["wheels_speed"] = 0.5  # below: the momentum alone
    assert breaking_fields("actuators", "closed_loop", values, MARGIN) == ["wheels_momentum"]


def test_a_pointing_requirement_breaks_by_its_margin_alone():
    values = {"met": False, "min_margin_deg": -0.19, "time_in_violation_s": 3.2}
    assert breaking_fields("st", "reference", values, MARGIN) == ["min_margin_deg"]
    assert _requirement_cell("st", "reference", values, MARGIN) == "-0.19 ✗"


def test_a_run_whose_reference_jumps_names_the_jump_as_its_tables_show_it():
    data = copy.deepcopy(with_direction([-1, 0, 0]))  # the keep-out never nearer than 120 deg
    data["planners"] = [{"name": "natural_motion", "options": {"stop": "step"}}]
    results = scenarios.run(scenarios.parse_scenario(data))
    (line,) = [line for line in results.to_terminal().splitlines() if line.startswith("req.actuators")]
    ref, cl = line.split("(peak demand / limit; ref | cl)")[1].rsplit("|", 1)
    assert ref.strip().endswith("✗ rate_jump") and "✗" not in cl, line
    # the field named is the column that shows the jump, in results.csv and results.md alike
    (record,) = csv.DictReader(io.StringIO(results.to_csv()))
    assert record["ref.req.actuators.met"] == "False" and float(record["ref.req.actuators.rate_jump"]) > 0.0
    assert float(record["ref.req.actuators.wheels_momentum"]) < 0.9
    assert "| ref.req.actuators.rate_jump | " in results.to_markdown()


def test_a_breach_its_number_shows_gets_no_field_and_no_field_note():
    # the eigenaxis slew through the sun keep-out: broken by its min margin, the number shown
    data = yaml.safe_load((ROOT / "scenarios" / "cubesat_12u_sun_keep_out.yaml").read_text())
    data["planners"] = [{"name": "eigenaxis"}]
    results = scenarios.run(scenarios.parse_scenario(data))
    terminal = results.to_terminal().splitlines()
    (line,) = [line for line in terminal if line.startswith("req.st_sun")]
    ref, cl = line.split("ref | cl)", 1)[1].rsplit("|", 1)
    assert ref.strip().endswith("✗") and cl.strip().endswith("✗"), line  # the mark alone, no field
    assert results.rows[0].requirements["reference"]["st_sun"]["min_margin_deg"] < 0
    assert "(✗: that scope breaks the requirement; the messages below say how)" in terminal
    assert not any(text.startswith("(✗ FIELD") for text in terminal)
