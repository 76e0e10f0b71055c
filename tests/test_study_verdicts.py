"""A study's per-requirement counts (``requirements.csv``) take a verdict only from a row that counts
(``ok`` or ``violated``), as the summary and the robustness tables take a row's values; a store
written before verdicts were stored says so instead of printing nothing; ``report.html`` shows a
bool as the CSV files write it.

Before: a ``failed`` row's stored verdict ``True`` counted as met (``st (reference)`` met in 5 of
6 below instead of 4 of 4) and an ``infeasible`` row's ``False`` as broken; rows with requirement scores
but no ``.met`` gave no per-requirement line at all; the HTML cells of a verdict read ``true`` /
``false`` where ``cases.csv`` reads ``True`` / ``False``. Oracles: counts by hand from the given rows.
"""
from __future__ import annotations

import copy
import csv
import io
import json
from typing import Any

import pytest

from scenarios.output.tables import csv_text
from scenarios.study.html import study_report
from scenarios.study.report import (
    _markdown,
    requirement_lines,
    requirement_table,
    summary_table,
    wilson_interval,
)
from scenarios.study.robustness import proportion_table
from scenarios.study.spec import parse_study
from tests.test_requirements_study import BASE


def study() -> Any:
    return parse_study({"study": "verdicts", "scenario": copy.deepcopy(BASE)})


def row(status: str, **columns: Any) -> dict[str, Any]:
    return {"label": "eigenaxis", "status": status, **columns}


# ref.req.st.met / cl.req.st.met per row; the failed row's True and the infeasible row's False are
# verdicts on motions that do not count
ROWS = [row("ok", ref_req_st_met=True, cl_req_st_met=True),
        row("violated", ref_req_st_met=True, cl_req_st_met=False),
        row("violated", ref_req_st_met=True, cl_req_st_met=False),
        row("failed", ref_req_st_met=True, cl_req_st_met=True),
        row("infeasible", ref_req_st_met=False, cl_req_st_met=False),
        row("crashed"),
        row("ok", ref_req_st_met=True)]  # no closed loop scored: not scored there


def dotted(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``ref_req_st_met`` -> ``ref.req.st.met``."""
    out = []
    for line in rows:
        fixed = {}
        for key, value in line.items():
            fixed[key.replace("_req_", ".req.").replace("_met", ".met").replace("_min_margin_deg", ".min_margin_deg")
                  .replace("_time_in_violation_s", ".time_in_violation_s")] = value
        out.append(fixed)
    return out


def by_criterion(table: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    return {line["criterion"]: line for line in table}


def test_a_verdict_counts_only_from_a_row_that_counts() -> None:
    rows = dotted(ROWS)
    columns, table = requirement_table(study(), rows)
    lines = by_criterion(table)
    assert list(lines) == ["every requirement", "st (reference)", "st (closed loop)"]
    every, ref, cl = lines["every requirement"], lines["st (reference)"], lines["st (closed loop)"]
    # every requirement: 2 ok of the 6 completed (the crashed one is not completed)
    assert (every["completed"], every["scored"], every["met"]) == (6, 6, 2)
    # reference: the 4 rows ok or violated, all met; the failed (True) and infeasible (False) left out
    assert (ref["scored"], ref["met"], ref["fraction_met"]) == (4, 4, 1.0)
    assert (ref["completed"], ref["excluded"], ref["not_scored"], ref["no_verdict"]) == (6, 3, 0, 0)
    # closed loop: ok True, violated False, violated False; the last ok row has no closed-loop score
    assert (cl["scored"], cl["met"]) == (3, 1)
    assert (cl["excluded"], cl["not_scored"], cl["no_verdict"]) == (3, 1, 0)
    assert cl["fraction_met"] == pytest.approx(1 / 3, rel=1e-15)
    assert (cl["wilson_low"], cl["wilson_high"]) == pytest.approx(wilson_interval(1, 3), rel=1e-15)
    # the same rows left out as robustness.csv's
    (robust,) = proportion_table(study(), rows)[1]
    assert all(line["excluded"] == robust["excluded"] == 3 for line in table)
    printed = requirement_lines((columns, table))
    assert printed == ["  eigenaxis: every requirement met in 2 of 6 cases",
                       "  eigenaxis: st (reference) met in 4 of 4 cases, 3 left out (failed, infeasible or crashed)",
                       ("  eigenaxis: st (closed loop) met in 1 of 3 cases, 1 not scored, 3 left out (failed, "
                        "infeasible or crashed)")]
    written = list(csv.DictReader(io.StringIO(csv_text(columns, table))))
    assert [(line["criterion"], line["excluded"], line["scored"], line["met"]) for line in written] == [
        ("every requirement", "3", "6", "2"), ("st (reference)", "3", "4", "4"), ("st (closed loop)", "3", "3", "1")]


def test_only_failed_rows_carry_verdicts_then_no_case_is_scored() -> None:
    rows = dotted([row("failed", ref_req_st_met=True), row("infeasible", ref_req_st_met=True)])
    columns, table = requirement_table(study(), rows)
    ref = by_criterion(table)["st (reference)"]
    assert (ref["completed"], ref["scored"], ref["met"], ref["fraction_met"]) == (2, 0, 0, None)
    assert ref["excluded"] == 2
    assert requirement_lines((columns, table))[1] == (
        "  eigenaxis: st (reference): no case scored (2 completed, 2 left out: failed, infeasible or crashed)")


# a store written before verdicts were stored: the scores, no .met
OLD = [row("ok", ref_req_st_min_margin_deg=12.0, cl_req_st_min_margin_deg=11.0, cl_req_st_time_in_violation_s=0.0),
       row("violated", ref_req_st_min_margin_deg=12.0, cl_req_st_min_margin_deg=-1.0,
           cl_req_st_time_in_violation_s=3.0),
       row("failed"),
       row("ok", ref_req_st_min_margin_deg=12.0, cl_req_st_min_margin_deg=10.0, cl_req_st_time_in_violation_s=0.0)]


def test_a_store_scored_before_verdicts_says_so() -> None:
    rows = dotted(OLD)
    assert not any(key.endswith(".met") for line in rows for key in line)
    columns, table = requirement_table(study(), rows)
    lines = by_criterion(table)
    assert list(lines) == ["every requirement", "st (reference)", "st (closed loop)"]
    for name in ("st (reference)", "st (closed loop)"):
        assert (lines[name]["scored"], lines[name]["fraction_met"]) == (0, None)
        assert (lines[name]["no_verdict"], lines[name]["not_scored"]) == (3, 0)
    printed = requirement_lines((columns, table))
    assert printed[0] == "  eigenaxis: every requirement met in 2 of 4 cases"
    for line, name in zip(printed[1:], ("st (reference)", "st (closed loop)")):
        assert line.startswith(f"  eigenaxis: {name}: not counted: 3 cases scored before per-requirement "
                               "verdicts were stored; re-run the cases to count them")
    from scenarios.study.report import verdict_note

    note = verdict_note((columns, table))
    assert note is not None and "scored before per-requirement verdicts were stored" in note
    assert "st (reference), st (closed loop) are not counted" in note
    markdown = _markdown(study(), *summary_table(study(), rows), 0, (columns, table))
    assert note in markdown
    page = study_report(study(), (["label", "status"], rows), summary_table(study(), rows), (columns, table), 0)
    assert json.dumps(note)[1:-1] in page or note in page


def test_a_partly_resumed_store_counts_the_verdicts_it_has() -> None:
    """One row stored before verdicts, two after: the two are counted, the one is said."""
    rows = dotted([OLD[0], row("ok", ref_req_st_met=True, ref_req_st_min_margin_deg=9.0),
                   row("violated", ref_req_st_met=False, ref_req_st_min_margin_deg=-2.0)])
    columns, table = requirement_table(study(), rows)
    ref = by_criterion(table)["st (reference)"]
    assert (ref["scored"], ref["met"]) == (2, 1)
    assert (ref["no_verdict"], ref["not_scored"]) == (1, 0)
    assert requirement_lines((columns, table))[1] == (
        "  eigenaxis: st (reference) met in 1 of 2 cases, 1 scored before per-requirement verdicts were stored; "
        "re-run the cases to count them (the study into a new directory: a resumed sweep keeps the stored cases)")
    cl = by_criterion(table)["st (closed loop)"]
    assert (cl["scored"], cl["no_verdict"], cl["not_scored"]) == (0, 1, 2)
    from scenarios.study.report import verdict_note

    fresh = requirement_table(study(), dotted(ROWS))
    assert verdict_note(fresh) is None


def html_table(page: str, key: str) -> dict[str, Any]:
    start = page.index(f'"{key}":{{"columns"') + len(key) + 3
    return json.JSONDecoder().raw_decode(page, start)[0]


def test_the_html_report_shows_a_bool_as_the_csv_files() -> None:
    rows = [{"case": k, **line} for k, line in enumerate(dotted(ROWS))]
    names = ["case", "label", "status", "ref.req.st.met", "cl.req.st.met"]
    page = study_report(study(), (names, rows), summary_table(study(), rows), requirement_table(study(), rows), 0)
    cases = html_table(page, "cases")
    keys = [column["key"] for column in cases["columns"]]
    shown = [line[keys.index("cl.req.st.met")] for line in cases["rows"]]
    written = list(csv.DictReader(io.StringIO(csv_text(names, rows))))
    assert [line["cl.req.st.met"] for line in written] == ["True", "False", "False", "True", "False", "", ""]
    assert shown == ["True", "False", "False", "True", "False", None, None]
