"""Sweeps carry the requirement columns and statuses per case; the report gives per planner the
fraction of completed cases that meet every requirement with a Wilson 95 % interval.

The Wilson bounds are checked against values worked out by hand from the closed forms (0 and n
successes: ``z²/(n + z²)`` and ``n/(n + z²)``), the 8/10 case written out step by step below, and
the published example of Newcombe (1998, Statistics in Medicine 17, 857-872, table II: 81 of 263,
0.2553 to 0.3662).
"""
from __future__ import annotations

import copy
import csv
import io
import math

import pytest

from scenarios.study.engine import sweep
from scenarios.study.report import WILSON_Z, requirement_table, wilson_interval
from scenarios.study.spec import parse_study

Z2 = 1.959963984540054 ** 2  # 3.841458820694124


def test_wilson_interval_by_hand():
    assert WILSON_Z == pytest.approx(1.959963984540054, rel=1e-15)
    # 8 of 10: p = 0.8; z²/n = 0.38414588; 1 + z²/n = 1.38414588; centre = (0.8 + 0.19207294) / 1.38414588
    # = 0.71674016; half = (1.95996398 / 1.38414588) sqrt(0.016 + 0.00960365) = 1.41600969 x 0.16001140
    # = 0.22657769
    low, high = wilson_interval(8, 10)
    assert low == pytest.approx(0.71674016 - 0.22657769, abs=2e-8)
    assert high == pytest.approx(0.71674016 + 0.22657769, abs=2e-8)
    assert wilson_interval(0, 10) == pytest.approx((0.0, Z2 / (10 + Z2)), abs=1e-15)   # (0, 0.27753)
    assert wilson_interval(10, 10) == pytest.approx((10 / (10 + Z2), 1.0), abs=1e-15)  # (0.72247, 1)
    low, high = wilson_interval(81, 263)
    assert (round(low, 4), round(high, 4)) == (0.2553, 0.3662)
    assert wilson_interval(0, 0) is None


BASE = {
    "name": "requirements-sweep",
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


def test_a_sweep_stores_the_requirement_columns_and_reports_the_fraction_met(tmp_path):
    """The keep-out's axis varied: the eigenaxis path crosses inertial x (violated), and never nears
    -x or z (ok): 2 of 3 cases meet every requirement."""
    study = parse_study({"study": "req", "scenario": copy.deepcopy(BASE),
                         "grid": {"requirements.pointing.st.keep_out.inertial": [[1, 0, 0], [-1, 0, 0], [0, 0, 1]]},
                         "summary": ["cl.final_error_deg", "ref.req.st.min_margin_deg"]})
    results = sweep(study, workers=1)
    columns, rows = results.table()
    assert [row["status"] for row in rows] == ["violated", "ok", "ok"]
    assert "ref.req.st.min_margin_deg" in columns and "cl.req.st.time_in_violation_s" in columns
    assert rows[0]["ref.req.st.min_margin_deg"] == pytest.approx(-30.0, abs=1e-6)
    assert rows[1]["ref.req.st.min_margin_deg"] == pytest.approx(90.0, abs=1e-6)
    frame = results.to_dataframe()
    assert frame["cl.req.st.min_margin_deg"].dtype == "float64"
    req_columns, table = requirement_table(study, rows)
    assert req_columns == ["label", "criterion", "completed", "excluded", "scored", "not_scored",
                           "no_verdict", "met", "fraction_met", "wilson_low", "wilson_high"]
    line = table[0]
    assert line["criterion"] == "every requirement"
    # 2 of 3: centre (2/3 + z²/6) / (1 + z²/3), half z/(1 + z²/3) sqrt(2/27 + z²/36)
    centre = (2 / 3 + Z2 / 6) / (1 + Z2 / 3)
    half = math.sqrt(Z2) / (1 + Z2 / 3) * math.sqrt(2 / 27 + Z2 / 36)
    assert (line["completed"], line["met"], line["fraction_met"]) == (3, 2, pytest.approx(2 / 3))
    assert (line["wilson_low"], line["wilson_high"]) == (pytest.approx(centre - half), pytest.approx(centre + half))
    assert round(line["wilson_low"], 4) == 0.2077 and round(line["wilson_high"], 4) == 0.9385
    results.write(tmp_path / "out", plots=False)
    summary = list(csv.DictReader(io.StringIO((tmp_path / "out" / "summary.csv").read_text())))
    margins = next(line for line in summary if line["metric"] == "ref.req.st.min_margin_deg")
    assert float(margins["min"]) == pytest.approx(-30.0, abs=1e-6) and margins["not_ok"] == "1"
    written = list(csv.DictReader(io.StringIO((tmp_path / "out" / "requirements.csv").read_text())))
    assert written[0]["met"] == "2" and written[0]["completed"] == "3"
    assert "## Cases meeting the requirements" in (tmp_path / "out" / "summary.md").read_text()
    cases = (tmp_path / "out" / "cases.csv").read_text().splitlines()[0].split(",")
    assert cases[-2:] == ["cl.req.actuators.wheels_momentum_time_s", "file_stem"]  # the closed loop's wheels, after
    # its pointing, then the rows' file stem (as results.csv)


def test_crashed_rows_do_not_count_as_completed():
    study = parse_study({"study": "req", "scenario": copy.deepcopy(BASE)})
    rows = [{"label": "eigenaxis", "status": status} for status in ("ok", "crashed", "violated", "failed", "ok")]
    (line,) = requirement_table(study, rows)[1]  # rows without verdicts: the one criterion
    assert (line["completed"], line["met"]) == (4, 2)
    assert (line["wilson_low"], line["wilson_high"]) == pytest.approx(wilson_interval(2, 4))
    (none,) = requirement_table(study, [{"label": "eigenaxis", "status": "crashed"}])[1]
    assert none["completed"] == 0 and none["fraction_met"] is None and none["wilson_low"] is None
