"""An ``infeasible`` row whose slew does not fit ``maneuver.duration`` records the least budget known to
be needed (``needed_duration_s`` in ``results.json``, ``results.csv``, the DataFrame and the terminal
table), and a row whose reference was refused does not show that reference's certificate as the
row's optimum.

Oracles by hand: the bang-bang triangle of a 90 deg slew of a 10 kg m^2 sphere on 0.0144 N m wheels
takes 2 sqrt(theta I / tau) = 66.05545 s (``FASTEST``, tests/test_verdict_rules.py); a 90 deg slew at
most 0.01 rad/s takes at least (pi/2)/0.01 = 157.0796 s; the vepa spin-up's minimum-time form ends at
t_f = 4.973 s (its scenario file says so), longer than a 4.5 s budget.
"""
from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import pytest
import yaml

import scenarios
from scenarios.output.tables import REFUSED_CERTIFICATE
from tests.test_verdict_rules import FASTEST, slew

ROOT = Path(__file__).resolve().parents[1]


def rows_of(data: dict) -> list[dict]:
    """``results.json``'s rows and ``results.csv``'s lines of a run of ``data``."""
    results = scenarios.run(scenarios.parse_scenario(data))
    lines = list(csv.DictReader(io.StringIO(results.to_csv())))
    rows = json.loads(results.to_json())["rows"]
    for row, line in zip(rows, lines):
        row["csv"] = line["needed_duration_s"]
    return rows


@pytest.mark.parametrize("profile", ["min_time", "trapezoidal"])
def test_a_slew_longer_than_the_budget_records_the_duration_it_needs(profile):
    """min_time plans its 66.06 s slew and the run refuses it (the reference's own duration);
    trapezoidal refuses the slew itself (the planner's least_duration, the closed form)."""
    (row,) = rows_of(slew(60.0, profile))
    assert row["status"] == "infeasible"
    assert math.isclose(row["needed_duration_s"], FASTEST, rel_tol=1e-9), row
    assert math.isclose(float(row["csv"]), FASTEST, rel_tol=1e-9), row


def test_the_rate_proof_before_planning_records_theta_over_the_rate_bound():
    (row,) = rows_of(slew(60.0, "smooth", rate=0.01))
    assert row["status"] == "infeasible" and row["message"].startswith("rate: "), row
    assert math.isclose(row["needed_duration_s"], (math.pi / 2) / 0.01, rel_tol=1e-9), row


def test_no_needed_duration_where_the_budget_is_not_the_reason():
    (ok,) = rows_of(slew(70.0))  # within the budget
    assert ok["status"] == "ok" and ok["needed_duration_s"] is None and ok["csv"] == ""
    demo = yaml.safe_load((ROOT / "scenarios" / "eigenaxis_demo.yaml").read_text())
    demo["spacecraft"]["sensors"] = {"camera": {"boresight": [0, 0, 1]}}  # on the keep-out cone at t = 0
    demo["requirements"] = {"pointing": {"cam": {"sensor": "camera", "keep_out": {"inertial": [0, 0, 1]},
                                                 "angle_deg": 20}}}
    for row in rows_of(demo):  # no budget admits a start inside a keep-out cone
        assert row["status"] == "infeasible" and row["needed_duration_s"] is None, row


def test_the_terminal_table_shows_the_needed_duration_and_the_dataframe_holds_a_float():
    results = scenarios.run(scenarios.parse_scenario(slew(60.0)))
    line = next(text for text in results.to_terminal().splitlines() if text.startswith("needed_duration_s"))
    assert line.split()[-1] == f"{FASTEST:.4g}", line
    pytest.importorskip("pandas")
    frame = results.to_dataframe()
    assert frame["needed_duration_s"].dtype == float and math.isclose(frame["needed_duration_s"][0], FASTEST)


def test_a_refused_reference_certificate_is_not_shown_as_the_rows_optimum():
    data = yaml.safe_load((ROOT / "scenarios" / "vepa_spin_up.yaml").read_text())
    data["maneuver"]["duration"] = 4.5  # its minimum-time form ends at 4.973 s
    results = scenarios.run(scenarios.parse_scenario(data))
    (row,) = results.rows
    assert row.status == "infeasible" and math.isclose(row.needed_duration_s, 4.9727, rel_tol=1e-4), row
    summary = row.to_dict()["certificate"]["summary"]  # kept in results.json: the planner's record
    text = results.to_terminal()
    cell = next(line for line in text.splitlines() if line.startswith("certificate"))
    assert cell.split(None, 1)[1].strip() == REFUSED_CERTIFICATE, cell
    said = next(line for line in text.splitlines() if line.startswith(f"{row.label} certificate: "))
    assert said.startswith(f"{row.label} certificate: not applicable, its reference was refused (infeasible"), said
    assert said.endswith(f"the planner's own optimum had {summary}"), said
    assert f"| certificate | {REFUSED_CERTIFICATE} |" in results.to_markdown()
