"""Runs scored against requirements: statuses, messages, ``--strict``, the columns of every table.

The slew turns 120 deg about the inertial z axis from the inertial attitude; the star tracker's
boresight lies in the body xy-plane at azimuth -60 deg, so along the eigenaxis path it sweeps the
azimuths -60 to +60 deg in the xy-plane and crosses the inertial x axis mid-way: a 30 deg keep-out
about inertial x is entered at azimuth -30 deg and its margin reaches -30 deg (the boresight on the
axis), whatever the profile in time. A keep-out about inertial -x is never nearer than 120 deg.
"""
from __future__ import annotations

import contextlib
import copy
import csv
import io
import json
import math
import re
from pathlib import Path

import pytest
import yaml

import scenarios
from scenarios.cli.commands import main

ROOT = Path(__file__).resolve().parents[1]
SUN_SCENARIO = ROOT / "scenarios" / "cubesat_12u_sun_keep_out.yaml"

BASE = {
    "name": "requirements-run",
    "spacecraft": {"inertia": [0.25, 0.28, 0.12], "wheels": {"max_torque": 0.003, "max_momentum": 0.02},
                   "sensors": {"star_tracker": {"boresight": [0.5, -0.8660254, 0.0]}}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0, 0, 0.8660254], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5},
    "requirements": {"pointing": {"st": {"sensor": "star_tracker", "keep_out": {"inertial": [1, 0, 0]},
                                         "angle_deg": 30}}},
}


def with_direction(direction: list) -> dict:
    data = copy.deepcopy(BASE)
    data["requirements"]["pointing"]["st"]["keep_out"] = {"inertial": direction}
    return data


def run_cli(tmp_path: Path, data: dict, *flags: str) -> tuple[int, str, str]:
    tmp_path.mkdir(parents=True, exist_ok=True)
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(["run", str(path), "--out", str(tmp_path / "out"), "--no-plots", *flags])
    return status, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def crossing():
    return scenarios.run(scenarios.parse_scenario(copy.deepcopy(BASE)))


def test_an_eigenaxis_row_through_a_keep_out_is_violated_and_says_why(crossing):
    row = crossing.rows[0]
    assert row.status == "violated"
    assert row.message.startswith("st (reference): min margin -30 deg at 30.0 s")
    assert "st (closed loop): min margin" in row.message
    assert row.message.endswith("eigenaxis does not honour the pointing requirement (scored only)")
    reference = row.requirements["reference"]["st"]
    assert reference["min_margin_deg"] == pytest.approx(-30.0, abs=1e-6)  # the boresight on the axis
    assert reference["min_margin_time_s"] == pytest.approx(30.0, abs=0.03)  # mid-way, by symmetry
    # symmetric profile: in from azimuth -30 deg to +30 deg, i.e. the middle third of the angle
    first, inside = reference["first_violation_s"], reference["time_in_violation_s"]
    assert first + inside / 2 == pytest.approx(30.0, abs=1e-3)
    assert row.requirements["closed_loop"]["st"]["min_margin_deg"] < 0
    assert crossing.status_counts() == {"violated": 1}


def test_a_keep_out_the_path_never_nears_leaves_the_row_ok(tmp_path):
    results = scenarios.run(scenarios.parse_scenario(with_direction([-1, 0, 0])))
    row = results.rows[0]
    assert row.status == "ok"
    assert row.requirements["reference"]["st"]["min_margin_deg"] == pytest.approx(90.0, abs=1e-6)  # 120 - 30
    assert "does not honour the pointing requirement" in row.message


def test_strict_exits_1_when_a_row_is_not_ok_and_writes_the_results_all_the_same(tmp_path):
    status, out, err = run_cli(tmp_path / "a", copy.deepcopy(BASE))
    assert status == 0 and "rows: 1 (1 violated)" in out, err
    status, out, err = run_cli(tmp_path / "b", copy.deepcopy(BASE), "--strict")
    assert status == 1 and "--strict: 1 of 1 rows not ok (eigenaxis)" in err
    assert (tmp_path / "b" / "out" / "results.json").is_file()
    status, out, err = run_cli(tmp_path / "c", with_direction([-1, 0, 0]), "--strict")
    assert status == 0 and "rows: 1 (1 ok)" in out, err


def test_the_requirement_columns_in_every_table(crossing, tmp_path):
    data = json.loads(crossing.to_json())
    assert data["frame"] == "inertial (no epoch)" and data["epoch"] is None
    scores = data["rows"][0]["requirements"]
    assert set(scores) == {"reference", "closed_loop"}
    assert list(scores["reference"]["st"]) == ["met", "min_margin_deg", "time_in_violation_s", "first_violation_s",
                                               "min_margin_time_s"]
    assert (scores["reference"]["st"]["met"], scores["closed_loop"]["st"]["met"]) == (False, False)  # bools
    lines = list(csv.DictReader(io.StringIO(crossing.to_csv())))
    header = crossing.to_csv().splitlines()[0].split(",")
    req = [c for c in header if ".req." in c]
    pointing = ("met", "min_margin_deg", "time_in_violation_s", "first_violation_s", "min_margin_time_s")
    # the actuator requirement every scenario carries (margin 0): the reference's demand, and the closed
    # loop's wheel momentum
    assert req == ([f"ref.req.st.{field}" for field in pointing]
                   + [f"ref.req.actuators.{field}" for field in ("met", "wheels_torque", "wheels_torque_time_s",
                                                                 "wheels_momentum", "wheels_momentum_time_s",
                                                                 "rate_jump", "rate_jump_time_s",
                                                                 "unrealised_torque", "unrealised_torque_time_s",
                                                                 "unrealised_torque_allowed")]
                   + [f"cl.req.st.{field}" for field in pointing]
                   + [f"cl.req.actuators.{field}" for field in ("met", "wheels_momentum", "wheels_momentum_time_s")])
    assert header.index(req[0]) > header.index("cl.initial_rate_error")  # after the metric columns
    assert float(lines[0]["ref.req.st.min_margin_deg"]) == scores["reference"]["st"]["min_margin_deg"]
    frame = crossing.to_dataframe()
    assert all(frame[c].dtype == ("boolean" if c.endswith(".met") else "float64") for c in req)
    markdown = crossing.to_markdown()
    assert "| ref.req.st.min_margin_deg | -30 |" in markdown and "rows: 1 (1 violated)" in markdown
    terminal = crossing.to_terminal()
    assert "req.st (min margin, deg; ref | cl)" in terminal and terminal.rstrip().endswith("rows: 1 (1 violated)")


def test_a_row_without_requirements_keeps_its_columns():
    data = copy.deepcopy(BASE)
    data["requirements"] = None  # stated null: nothing required, not even the actuators' limits
    results = scenarios.run(scenarios.parse_scenario(data))
    assert results.rows[0].status == "ok" and results.rows[0].requirements is None
    assert ".req." not in results.to_csv().splitlines()[0] and results.rows[0].message.startswith("quintic")


def test_without_a_requirements_section_the_actuator_limits_are_still_required():
    data = copy.deepcopy(BASE)
    del data["requirements"]
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    # eigenaxis quintic about body z (I = 0.12, wheel momentum limit 0.02 N m s): peak rate
    # 1.875 theta / T, so the peak momentum asked is 0.12 * 1.875 * (2 pi / 3) / 60 = 0.0078540
    assert row.status == "ok" and row.message.startswith("quintic")  # unstated: no "does not honour" note
    ratio = row.requirements["reference"]["actuators"]["wheels_momentum"]
    assert ratio == pytest.approx(0.12 * 1.875 * (2 * math.pi / 3) / 60.0 / 0.02, rel=1e-4)
    data["spacecraft"]["wheels"]["max_momentum"] = 0.005  # now the reference asks 1.57 x the limit
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    assert row.status == "violated" and "actuators (reference): wheels_momentum 1.57 x its limit" in row.message


def test_the_actuator_rate_and_final_requirements_on_a_run():
    data = copy.deepcopy(BASE)
    data["simulation"]["duration"] = 80.0
    data["requirements"] = {"actuators": {"margin": 0.5}, "rate": {"max": 0.07},
                            "final": {"after_s": 10.0, "error_deg": 0.5, "rate": 1e-3}}
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    reference, closed = row.requirements["reference"], row.requirements["closed_loop"]
    # eigenaxis quintic about body z (I = 0.12): peak rate 1.875 θ / T, θ = 120 deg, mid-slew
    peak = 1.875 * math.radians(120.0) / 60.0
    assert reference["rate"]["peak_rate"] == pytest.approx(peak, rel=1e-6)
    assert reference["rate"]["ratio"] == pytest.approx(peak / 0.07, rel=1e-6)
    assert reference["rate"]["peak_time_s"] == pytest.approx(30.0)
    # the wheel about z stores I_z ω: 0.12 x peak against 0.02 N m s (0.39, within 1 - margin = 0.5);
    # its torque peaks at I_z x 5.7735 θ / T² (the quintic's peak acceleration) against 0.003 N m
    assert reference["actuators"]["wheels_momentum"] == pytest.approx(0.12 * peak / 0.02, rel=1e-3)
    accel = 5.7735 * math.radians(120.0) / 60.0**2
    assert reference["actuators"]["wheels_torque"] == pytest.approx(0.12 * accel / 0.003, rel=1e-3)
    assert set(closed) == {"actuators", "rate", "final"} and closed["final"]["from_s"] == 70.0
    # the closed loop's z wheel stores about the reference's I_z ω (the loop follows it)
    assert closed["actuators"]["met"] is True
    assert closed["actuators"]["wheels_momentum"] == pytest.approx(0.12 * peak / 0.02, rel=1e-2)
    assert closed["rate"]["peak_rate"] == pytest.approx(peak, rel=1e-3)  # the loop follows the reference
    assert closed["final"]["worst_error_deg"] < 0.5 and closed["final"]["worst_rate_error"] < 1e-3
    assert row.status == "ok" and "rate" not in row.message.split(";", 1)[-1]  # the eigenaxis honours the rate
    # a rate bound below the quintic's peak: the eigenaxis row is infeasible and says why (it planned past it)
    data["requirements"]["rate"]["max"] = 0.05
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    # (planned 1 % below it, the planner's rate_margin: a closed loop tracking the bound overshoots it)
    assert row.status == "infeasible" and row.message.startswith(
        f"the quintic over T = 60 s peaks at {peak:.4g} rad/s, above the rate bound 0.0495 rad/s "
        "(requirements.rate.max less rate_margin 0.01)")


def test_the_sun_scenario_others_violated_with_their_margins():
    """The shipped 12U CubeSat case without its collocation row (which honours pointing once the
    collocation branch lands): every other planner sweeps the star tracker through the Sun."""
    scenario = scenarios.load(SUN_SCENARIO)
    scenario.planners = [spec for spec in scenario.planners if spec.name in ("eigenaxis", "natural_motion")]
    results = scenarios.run(scenario)
    for row in results.rows:
        assert row.status == "violated", (row.label, row.message)
        assert row.message.startswith("st_sun (reference): min margin")
        assert row.requirements["reference"]["st_sun"]["min_margin_deg"] < -29.0  # through the Sun's centre
        assert row.requirements["closed_loop"]["st_sun"]["min_margin_deg"] < -29.0
    assert json.loads(results.to_json())["frame"] == "GCRF (epoch 2027-03-20T12:00:00Z)"
    assert json.loads(results.to_json())["epoch"] == "2027-03-20T12:00:00Z"


def test_end_points_inside_a_keep_out_make_every_planner_row_infeasible_before_planning():
    """A proof before planning that no motion meets the requirement: ``infeasible`` (as the rate
    proof's), not ``failed`` (a numerical failure)."""
    text = SUN_SCENARIO.read_text().replace("boresight: [0.5, -0.8660254, 0.0]", "boresight: [1, 0, 0]")
    scenario = scenarios.parse_scenario(yaml.safe_load(text))
    results = scenarios.run(scenario)
    assert [row.status for row in results.rows] == ["infeasible"] * 4
    for row in results.rows:
        assert row.message.startswith("st_sun: the initial attitude already breaks it at 0 s")
        assert row.reference_metrics is None and row.simulation is None and row.plan_time_s == 0.0


def test_an_infeasible_row_ranks_between_failed_and_violated():
    """A user saw ``rows: 3 (1 ok, 2 infeasible)``: infeasible counted after ok, as an unknown status.
    The eigenaxis demo with two of its three wheels failed (all three are refused where the scenario
    is read: nothing would steer): the trapezoidal and minimum-time profiles find no torque about the
    slew's axis [1, 1, 1]/√3, off the one wheel's axis (infeasible); the smooth one asks it of no
    actuator (violated)."""
    data = yaml.safe_load((Path(__file__).resolve().parents[1] / "scenarios" / "eigenaxis_demo.yaml").read_text())
    data["spacecraft"]["wheels"]["failed"] = [0, 1]
    results = scenarios.run(scenarios.parse_scenario(data))
    statuses = [row.status for row in results.rows]
    assert sorted(statuses) == ["infeasible", "infeasible", "violated"], [row.message for row in results.rows]
    assert list(results.status_counts()) == ["infeasible", "violated"]
    assert results.to_terminal().count("rows: 3 (2 infeasible, 1 violated)") == 1


def test_a_closed_loop_window_shorter_than_the_reference_is_said():
    """A 30 s window on a 60 s slew: the closed loop stops mid-manoeuvre, and the row says so (it
    was "ok" with a 74 deg final error and nothing in the message)."""
    data = copy.deepcopy(BASE)
    del data["requirements"]
    data["simulation"]["duration"] = 30.0
    row = scenarios.run(scenarios.parse_scenario(data)).rows[0]
    assert row.message.endswith("the closed loop stops at 30 s (simulation.duration), before the reference ends at "
                                "T = 60 s: its closed-loop metrics cover 50 % of the manoeuvre")
    data["simulation"]["duration"] = 60.0  # the whole manoeuvre: nothing to say
    assert "closed loop stops" not in scenarios.run(scenarios.parse_scenario(data)).rows[0].message


def test_the_terminal_marks_a_requirement_broken_by_a_field_its_headline_does_not_show():
    """A tester read ``req.actuators 0.1202`` (well under its limit) on a row violated by an impulsive
    rate jump: the headline is the peak torque demand, which a jump does not raise. Here the natural
    motion spins about the principal z axis through the 120° of the slew (no torque at all) and its
    rate steps to the final rest at the arc's end: the cell must say broken."""
    data = with_direction([-1, 0, 0])  # the keep-out is never nearer than 120 deg: only the actuators break
    data["planners"] = [{"name": "natural_motion", "options": {"stop": "step"}}]
    results = scenarios.run(scenarios.parse_scenario(data))
    row = results.rows[0]
    actuators = row.requirements["reference"]["actuators"]
    arc_s = float(re.search(r"over ([0-9.]+) s, stop 'step'", row.message).group(1))
    assert row.status == "violated" and "jumps by" in row.message, row.message
    # the jump is the whole spin rate: 120 deg over the arc's time
    assert actuators["met"] is False and actuators["rate_jump"] == pytest.approx(2.0 * math.pi / 3.0 / arc_s, rel=1e-6)
    assert actuators["wheels_torque"] < 0.5 and row.requirements["reference"]["st"]["met"] is True
    terminal = results.to_terminal().splitlines()
    line = next(line for line in terminal if line.startswith("req.actuators"))
    ref, cl = line.rstrip().rsplit("|", 1)  # its number well under 1, yet broken: marked (the closed loop's met)
    assert ref.rstrip().endswith("✗ rate_jump") and "✗" not in cl, line  # the field that breaks it
    st = next(line for line in terminal if line.startswith("req.st "))
    assert "✗" not in st and "(✗: that scope breaks the requirement; the messages below say how)" in terminal
