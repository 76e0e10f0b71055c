"""Each requirement's verdict per scope (the score's field ``met``): stored with the scores as a bool,
flattened into every table, read by the report's sign-off record (never from the message) and
counted per requirement and scope by a study.

The geometry (as ``tests/test_requirements_runs.py``): the slew turns 120 deg about the inertial z
axis in 60 s; the star tracker's boresight lies in the body xy-plane at azimuth -60 deg, so along the
eigenaxis path it sweeps the inertial xy-plane from azimuth -60 to +60 deg. A keep-out cone of
9.8 deg about the direction at elevation 10 deg above inertial x is then never nearer than 10 deg
to the reference's boresight: the reference meets it by 0.2 deg, a closed form. The closed loop
starts with an attitude error of 10 deg about the body axis [0.866, 0.5, 0] (perpendicular to the
boresight in the xy-plane): turned one way it tilts the boresight up towards the cone, and what the
controller has not removed by mid-slew brings it inside the cone (broken, checked here on the
simulated attitudes with SciPy's rotations); turned the other way it tilts it away (met).
"""
from __future__ import annotations

import copy
import csv
import io
import json
import math

import numpy as np
import pandas
import pytest
from scipy.spatial.transform import Rotation

import scenarios
from scenarios.output.report.record import requirement_lines
from scenarios.output.tables import to_csv, to_dataframe, to_json, to_markdown
from scenarios.requirements.fields import (
    VERDICT,
    VERDICT_UNIT,
    field_info,
    is_requirement_column,
    is_verdict_column,
)
from scenarios.schema import columns as schema_columns
from scenarios.study.engine import sweep
from scenarios.study.report import requirement_lines as study_lines
from scenarios.study.report import requirement_table
from scenarios.study.spec import parse_study

ELEVATION_DEG = 10.0
CONE_DEG = 9.8
BORESIGHT = np.array([0.5, -0.8660254, 0.0])
KEEP_OUT = [math.cos(math.radians(ELEVATION_DEG)), 0.0, math.sin(math.radians(ELEVATION_DEG))]
TOWARDS = [-8.660254, -5.0, 0.0]
"""An initial attitude error [deg] (rotation vector, body axes) that tilts the boresight up, towards the cone."""
AWAY = [8.660254, 5.0, 0.0]
"""The same error turned the other way: the boresight tilted down, away from the cone."""

BASE = {
    "name": "verdicts",
    "spacecraft": {"inertia": [0.25, 0.28, 0.12], "wheels": {"max_torque": 0.003, "max_momentum": 0.02},
                   "sensors": {"star_tracker": {"boresight": BORESIGHT.tolist()}}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.5, 0, 0, 0.8660254], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
    "simulation": {"sample_time": 0.5, "initial_attitude_error_deg": TOWARDS},
    "requirements": {"pointing": {"st": {"sensor": "star_tracker", "keep_out": {"inertial": KEEP_OUT},
                                         "angle_deg": CONE_DEG}}},
}


def scenario(error: list[float]) -> dict:
    data = copy.deepcopy(BASE)
    data["simulation"]["initial_attitude_error_deg"] = error
    return data


def closest_approach_deg(row) -> float:
    """The smallest angle [deg] between the boresight and the keep-out direction at the closed loop's
    samples (SciPy's rotations of the simulated attitudes, scalar-first quaternions body to inertial)."""
    q = np.asarray(row.simulation.q)
    boresights = Rotation.from_quat(q[:, [1, 2, 3, 0]]).apply(BORESIGHT / np.linalg.norm(BORESIGHT))
    cosines = np.clip(boresights @ np.asarray(KEEP_OUT), -1.0, 1.0)
    return float(np.degrees(np.arccos(cosines.max())))


@pytest.fixture(scope="module")
def towards():
    return scenarios.run(scenarios.parse_scenario(scenario(TOWARDS)))


@pytest.fixture(scope="module")
def away():
    return scenarios.run(scenarios.parse_scenario(scenario(AWAY)))


def test_the_verdict_is_stored_per_requirement_and_scope(towards, away):
    (broken,), (kept,) = towards.rows, away.rows
    # the reference: the boresight stays in the xy-plane, 10 deg from the direction at its nearest
    for row in (broken, kept):
        assert row.requirements["reference"]["st"]["min_margin_deg"] == pytest.approx(ELEVATION_DEG - CONE_DEG,
                                                                                      abs=1e-6)
        assert row.requirements["reference"]["st"][VERDICT] is True
        assert row.requirements["reference"]["actuators"][VERDICT] is True  # 0.13 of the torque, 0.39 of the momentum
    # the closed loop: inside the cone at some sample when tilted towards it (so broken between the
    # samples too); never nearer than the reference's 10 deg when tilted away
    assert closest_approach_deg(broken) < CONE_DEG
    assert closest_approach_deg(kept) > CONE_DEG
    assert broken.requirements["closed_loop"]["st"][VERDICT] is False
    assert kept.requirements["closed_loop"]["st"][VERDICT] is True
    # the closed loop's wheels keep within their momentum limit (0.39 of it): met there too
    assert broken.requirements["closed_loop"]["actuators"][VERDICT] is True
    # the row's status follows the verdicts: violated iff one is false (neither row otherwise failed)
    for row in (broken, kept):
        verdicts = [fields[VERDICT] for scored in row.requirements.values() for fields in scored.values()]
        assert all(isinstance(v, bool) for v in verdicts)
        assert row.status == ("violated" if not all(verdicts) else "ok")
    assert (broken.status, kept.status) == ("violated", "ok")
    # the verdict comes first in the score, then the scoring's numbers
    assert next(iter(broken.requirements["closed_loop"]["st"])) == VERDICT


def test_the_verdict_is_a_bool_in_every_table(towards):
    data = json.loads(to_json(towards))
    scores = data["rows"][0]["requirements"]
    assert scores["closed_loop"]["st"]["met"] is False and scores["reference"]["st"]["met"] is True
    assert scores["reference"]["actuators"]["met"] is True
    # CSV: True/False cells, which pandas reads back as bools
    lines = list(csv.DictReader(io.StringIO(to_csv(towards))))
    assert (lines[0]["ref.req.st.met"], lines[0]["cl.req.st.met"]) == ("True", "False")
    read = pandas.read_csv(io.StringIO(to_csv(towards)))
    assert read["cl.req.st.met"].dtype == bool and not read["cl.req.st.met"][0]
    # the DataFrame: the verdicts nullable booleans, the numbers floats (never a verdict as 0.0/1.0)
    frame = to_dataframe(towards)
    assert str(frame["cl.req.st.met"].dtype) == "boolean" and str(frame["ref.req.st.met"].dtype) == "boolean"
    assert not frame["cl.req.st.met"][0] and frame["ref.req.st.met"][0]
    assert frame["cl.req.st.min_margin_deg"].dtype == "float64"
    markdown = to_markdown(towards)
    assert "| cl.req.st.met | False |" in markdown and "true/false: met" in markdown
    # the field's declaration
    info = field_info("cl.req.st.met")
    assert (info.field, info.unit, info.scopes) == (VERDICT, VERDICT_UNIT, ("ref", "cl"))
    assert field_info("ref.req.actuators.met").scopes == ("ref", "cl") and field_info("cl.req.final.met").scopes == ("cl",)
    assert is_verdict_column("cl.req.st.met") and not is_verdict_column("cl.req.st.min_margin_deg")


def _verdicts(results) -> dict[tuple[str, str], set[str]]:
    """(scope in words, requirement) -> the verdicts of the record's lines."""
    found: dict[tuple[str, str], set[str]] = {}
    for line in requirement_lines(results):
        found.setdefault((line[1], line[2]), set()).add(line[-1])
    return found


def test_the_record_reads_the_verdict_not_the_message(towards, away):
    expected = {("reference", "st"): {"met"}, ("reference", "actuators"): {"met"}, ("closed loop", "st"): {"broken"},
                ("closed loop", "actuators"): {"met"}}
    assert _verdicts(towards) == expected
    assert _verdicts(away) == {**expected, ("closed loop", "st"): {"met"}}
    # a message reworded (or empty) leaves the verdicts as the scoring gave them
    broken, kept = towards.rows[0], away.rows[0]
    original = (broken.message, kept.message)
    try:
        broken.message = "the closed loop entered the star tracker's keep-out"
        kept.message = "st (closed loop): looks as if it names a broken requirement; st (reference): too"
        assert _verdicts(towards) == expected
        assert _verdicts(away) == {**expected, ("closed loop", "st"): {"met"}}
    finally:
        broken.message, kept.message = original
    # a score without its verdict is refused, not read as met
    saved = broken.requirements["closed_loop"]["st"].pop(VERDICT)
    try:
        with pytest.raises(TypeError, match="no verdict"):
            requirement_lines(towards)
    finally:
        broken.requirements["closed_loop"]["st"] = {VERDICT: saved, **broken.requirements["closed_loop"]["st"]}


def test_a_study_counts_the_cases_meeting_each_requirement_in_each_scope(tmp_path):
    """Four cases: the closed loop tilted towards the cone by 10 and 20 deg (broken), away by 10 deg
    and not at all (met); the reference meets every requirement in all four."""
    errors = [TOWARDS, AWAY, [0.0, 0.0, 0.0], [2 * value for value in TOWARDS]]
    study = parse_study({"study": "verdicts", "scenario": scenario([0.0, 0.0, 0.0]),
                         "grid": {"simulation.initial_attitude_error_deg": errors},
                         "summary": ["cl.req.st.min_margin_deg"]})
    results = sweep(study, workers=1)
    columns, rows = results.table()
    assert {"ref.req.st.met", "cl.req.st.met", "ref.req.actuators.met"} <= set(columns)
    # the independent count: the simulated attitudes' closest approach to the cone, case by case
    # (each case re-run here; a case inside the cone at a sample breaks the requirement)
    inside = [closest_approach_deg(scenarios.run(scenarios.parse_scenario(scenario(error))).rows[0]) < CONE_DEG
              for error in errors]
    assert inside == [True, False, False, True]
    assert [row["cl.req.st.met"] for row in rows] == [not flag for flag in inside]
    req_columns, table = requirement_table(study, rows)
    assert req_columns == ["label", "criterion", "completed", "excluded", "scored", "not_scored",
                           "no_verdict", "met", "fraction_met", "wilson_low", "wilson_high"]
    lines = {line["criterion"]: line for line in table}
    assert list(lines) == ["every requirement", "st (reference)", "st (closed loop)", "actuators (reference)",
                           "actuators (closed loop)"]
    assert (lines["every requirement"]["met"], lines["every requirement"]["completed"]) == (2, 4)
    assert (lines["st (reference)"]["met"], lines["st (reference)"]["scored"]) == (4, 4)
    assert (lines["st (closed loop)"]["met"], lines["st (closed loop)"]["scored"]) == (sum(not f for f in inside), 4)
    assert lines["st (closed loop)"]["fraction_met"] == pytest.approx(0.5, rel=1e-15)
    assert (lines["actuators (reference)"]["met"], lines["actuators (reference)"]["scored"]) == (4, 4)
    printed = study_lines((req_columns, table))
    assert "  eigenaxis: st (closed loop) met in 2 of 4 cases" in printed
    assert "  eigenaxis: every requirement met in 2 of 4 cases" in printed
    results.write(tmp_path / "out", plots=False)
    written = list(csv.DictReader(io.StringIO((tmp_path / "out" / "requirements.csv").read_text())))
    closed = next(line for line in written if line["criterion"] == "st (closed loop)")
    assert (closed["completed"], closed["scored"], closed["met"]) == ("4", "4", "2")
    cases = list(csv.DictReader(io.StringIO((tmp_path / "out" / "cases.csv").read_text())))
    assert [line["cl.req.st.met"] for line in cases] == ["False", "True", "True", "False"]
    summary = (tmp_path / "out" / "summary.md").read_text()
    assert "| eigenaxis | st (closed loop) | 4 | 0 | 4 | 0 | 0 | 2 | 0.5 |" in summary


def test_unscored_rows_are_counted_apart_and_a_verdict_is_no_summary_metric():
    study = parse_study({"study": "verdicts", "scenario": scenario([0.0, 0.0, 0.0])})
    rows = [{"label": "eigenaxis", "status": "ok", "ref.req.st.met": True, "cl.req.st.met": True},
            {"label": "eigenaxis", "status": "violated", "ref.req.st.met": True, "cl.req.st.met": False},
            {"label": "eigenaxis", "status": "failed", "ref.req.st.met": True, "cl.req.st.met": None},
            {"label": "eigenaxis", "status": "crashed"},
            {"label": "eigenaxis", "status": "ok", "ref.req.st.met": True}]  # no closed loop scored
    columns, table = requirement_table(study, rows)
    lines = {line["criterion"]: line for line in table}
    # the failed row's verdicts do not count (tests/test_study_verdicts.py); it and the crashed one are left out
    assert (lines["st (closed loop)"]["completed"], lines["st (closed loop)"]["scored"],
            lines["st (closed loop)"]["met"], lines["st (closed loop)"]["not_scored"]) == (4, 2, 1, 1)
    assert (lines["st (reference)"]["scored"], lines["st (reference)"]["met"]) == (3, 3)
    assert ("  eigenaxis: st (closed loop) met in 1 of 2 cases, 1 not scored, 2 left out (failed, infeasible or "
            "crashed)") in study_lines((columns, table))
    crashed = requirement_table(study, [{"label": "eigenaxis", "status": "crashed"}])
    assert study_lines(crashed) == ["  eigenaxis: every requirement: no completed case"]
    with pytest.raises(scenarios.ScenarioError, match=r"summary\[0\].*verdict"):
        parse_study({"study": "verdicts", "scenario": scenario([0.0, 0.0, 0.0]), "summary": ["cl.req.st.met"]})


def test_the_sweep_prints_the_counts(tmp_path, capsys):
    import yaml

    from scenarios.cli.commands import main

    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "verdicts-cli", "scenario": scenario([0.0, 0.0, 0.0]),
                                    "grid": {"simulation.initial_attitude_error_deg": [TOWARDS, AWAY]}}))
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--no-plots", "--workers", "1"]) == 0
    printed = capsys.readouterr().out.splitlines()
    start = printed.index("requirements (cases meeting each, of those scored; requirements.csv):")
    assert printed[start + 1:start + 5] == ["  eigenaxis: every requirement met in 1 of 2 cases",
                                            "  eigenaxis: st (reference) met in 2 of 2 cases",
                                            "  eigenaxis: st (closed loop) met in 1 of 2 cases",
                                            "  eigenaxis: actuators (reference) met in 2 of 2 cases"]


REQUIREMENT_COLUMNS = ["ref.req.st.min_margin_deg", "cl.req.st.met", "ref.req.actuators.wheels_torque_time_s",
                       "ref.req.rate.met", "cl.req.final.worst_error_deg"]
"""Requirement columns, written out by hand: ``<ref|cl>.req.<name>.<field>``."""
OTHER_COLUMNS = ["status", "plan_time_s", "ref.final_error_deg", "cl.int_abs_u_x", "ref.req.st", "xx.req.st.met",
                 "cl.reqs.st.met", "cl.req..met", "cl.req.st.", "cl.req.st.met.x", "req.st.met", "cl.met.st.req"]
"""Columns that are no requirement's: metrics, identity columns, and near misses of the pattern."""


def test_one_helper_tells_a_requirement_column_and_its_verdict():
    assert all(is_requirement_column(column) for column in REQUIREMENT_COLUMNS)
    assert not any(is_requirement_column(column) for column in OTHER_COLUMNS)
    assert [c for c in REQUIREMENT_COLUMNS + OTHER_COLUMNS if is_verdict_column(c)] == ["cl.req.st.met",
                                                                                        "ref.req.rate.met"]
    # the columns' naming the schema builds them by (prefixes, mark) is the one the helpers read
    for _, prefix in schema_columns.SCOPES:
        column = f"{prefix}.{schema_columns.REQUIREMENT_MARK}.st.{VERDICT}"
        assert is_requirement_column(column) and is_verdict_column(column)
    assert not is_requirement_column(f"{schema_columns.SCOPES[0][1]}.{schema_columns.REQUIREMENT_MARK}x.st.met")
    # one way to ask: the schema's names keep no helper of their own
    assert not hasattr(schema_columns, "is_requirement_column")
