"""``requirements.csv``'s counts of a requirement's verdicts when a row holds the requirement's
columns empty (``cases.csv`` is the union of the cases' columns: a case whose closed loop was not
scored has its ``cl.req.*`` cells empty). Oracle: counts by hand from the given rows."""
from __future__ import annotations

from scenarios.study.report import requirement_table, verdict_note
from tests.test_study_verdicts import by_criterion, dotted, row, study

EMPTY = dict.fromkeys(("cl_req_st_min_margin_deg", "cl_req_st_time_in_violation_s", "cl_req_st_first_violation_s",
                       "cl_req_st_met"))


def test_a_row_with_its_score_cells_empty_is_not_scored_rather_than_without_a_verdict():
    """Three rows that count: two with the closed loop scored (met, broken), one with its closed-loop
    cells empty (None, or NaN as a float column reads back). Closed loop: 2 scored, 1 met, 1 not
    scored, none without a verdict, and no note about old stores."""
    rows = dotted([row("ok", ref_req_st_met=True, ref_req_st_min_margin_deg=9.0,
                       cl_req_st_met=True, cl_req_st_min_margin_deg=8.0, cl_req_st_time_in_violation_s=0.0,
                       cl_req_st_first_violation_s=None),
                   row("violated", ref_req_st_met=True, ref_req_st_min_margin_deg=7.0,
                       cl_req_st_met=False, cl_req_st_min_margin_deg=-1.0, cl_req_st_time_in_violation_s=2.0,
                       cl_req_st_first_violation_s=31.0),
                   row("ok", ref_req_st_met=True, ref_req_st_min_margin_deg=9.5,
                       **{**EMPTY, "cl_req_st_min_margin_deg": float("nan")})])
    table = requirement_table(study(), rows)
    cl = by_criterion(table[1])["st (closed loop)"]
    assert (cl["scored"], cl["met"], cl["not_scored"], cl["no_verdict"]) == (2, 1, 1, 0)
    ref = by_criterion(table[1])["st (reference)"]
    assert (ref["scored"], ref["met"], ref["not_scored"], ref["no_verdict"]) == (3, 3, 0, 0)
    assert verdict_note(table) is None
