"""The robustness outputs of a Monte Carlo study take the rows the summary takes: ``ok`` and
``violated``. A ``failed``, ``infeasible`` or ``crashed`` row is left out of ``robustness.csv``'s
thresholds (it is completed and meets none), ``sensitivity.csv``'s rank correlations and
``worst_cases.csv``'s ranking whatever values it carries, each file says how many rows were left
out (``excluded``), and ``report.html``'s robustness sections show the same tables.

Before: a failed or infeasible row's values met a threshold (``cl.settling_time_s <= 12``: 3 of 5
instead of 1), ranked first among the worst cases (the failed row's 100 N m s), and entered the
rank correlations (5 cases instead of 3). Oracles: counts and rankings by hand from the given
values, SciPy's ``spearmanr`` on the counted rows' values read back from ``cases.csv``.
"""
from __future__ import annotations

import copy
import csv
import json
from pathlib import Path
from typing import Any

import pytest
from scipy.stats import spearmanr

import scenarios
from scenarios.study.html import study_report
from scenarios.study.report import (
    case_table,
    requirement_table,
    robustness_tables,
    summary_table,
)
from tests.test_study_summary_failed import BASE, InlineExecutor, task_for

# per case: (row status, cl.int_u, cl.settling_time_s, cl.final_error_deg). Case 3 (failed) and case 5
# (infeasible) carry values that would meet the settling threshold and rank first; case 4 crashed.
GIVEN: list[tuple[str, float | None, float | None, float | None]] = [
    ("ok", 1.0, 10.0, 0.01), ("violated", 2.0, None, 2.0), ("ok", 4.0, 20.0, 0.02),
    ("failed", 100.0, 5.0, 5.0), ("crashed", None, None, None), ("infeasible", 0.5, 5.0, 0.01)]
KD = "controller.options.kd"


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory) -> tuple[scenarios.Study, Any, Path]:
    study = scenarios.parse_study({
        "study": "failed-robustness", "scenario": copy.deepcopy(BASE),
        "monte_carlo": {"samples": 6, "seed": 3, "dispersions": {KD: {"uniform": [0.5, 0.7]}}},
        "summary": ["cl.int_u", "cl.settling_time_s"],
        "robustness": {"thresholds": {"cl.settling_time_s": 12.0, "cl.int_u": {"at_least": 1.5}}, "worst": 2}})
    assert [case.index for case in study.cases] == list(range(len(GIVEN)))
    results = scenarios.sweep(study, InlineExecutor(), workers=1, task=task_for(study, GIVEN))
    out = tmp_path_factory.mktemp("robust-failed") / "out"
    results.write(out, plots=False)
    return study, results, out


def read(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_a_failed_or_infeasible_row_meets_no_threshold(swept: Any) -> None:
    """5 completed cases (the crashed one is not). cl.settling_time_s <= 12: case 0 (10 s) only;
    case 1 never settled, case 2 took 20 s, and the failed and infeasible rows' 5 s do not count
    (before: 3). cl.int_u >= 1.5: cases 1 and 2 (2, 4), not the failed row's 100 (before: 3).
    Every requirement: the 2 ok rows. excluded: failed, crashed, infeasible: 3."""
    _, _, out = swept
    lines = {line["criterion"]: line for line in read(out / "robustness.csv")}
    found = {criterion: (line["completed"], line["met"], line.get("excluded")) for criterion, line in lines.items()}
    assert found == {"every requirement": ("5", "2", "3"), "cl.settling_time_s <= 12": ("5", "1", "3"),
                     "cl.int_u >= 1.5": ("5", "2", "3")}, found
    assert float(lines["cl.settling_time_s <= 12"]["fraction_met"]) == pytest.approx(0.2, rel=1e-12)


def test_the_worst_cases_rank_only_the_rows_that_count(swept: Any) -> None:
    """cl.int_u (an at_least threshold: smallest first) over [1, 2, 4]: case 0, then case 1 (not
    the infeasible row's 0.5); cl.settling_time_s (largest first): case 1 never settled (inf), then
    case 2 (20 s)."""
    _, _, out = swept
    worst = [(line["metric"], line["rank"], line["case"], line["value"], line["status"], line.get("excluded"))
             for line in read(out / "worst_cases.csv")]
    assert worst == [("cl.int_u", "1", "0", "1.0", "ok", "3"), ("cl.int_u", "2", "1", "2.0", "violated", "3"),
                     ("cl.settling_time_s", "1", "1", "inf", "violated", "3"),
                     ("cl.settling_time_s", "2", "2", "20.0", "ok", "3")], worst


def test_the_rank_correlations_take_the_rows_that_count(swept: Any) -> None:
    """Spearman's rho of cl.int_u with the dispersed kd over cases 0, 1, 2 (scipy, from cases.csv)."""
    _, _, out = swept
    cases = {int(line["case"]): line for line in read(out / "cases.csv")}
    kd = [float(cases[k][KD]) for k in (0, 1, 2)]
    expected = spearmanr(kd, [1.0, 2.0, 4.0]).statistic
    (line,) = [line for line in read(out / "sensitivity.csv") if line["metric"] == "cl.int_u"]
    assert (line["parameter"], line["cases"], line.get("excluded")) == (KD, "3", "3"), line
    assert float(line["spearman_rho"]) == pytest.approx(expected, abs=1e-12)


def test_the_summary_markdown_and_the_report_say_the_same(swept: Any) -> None:
    study, results, out = swept
    text = (out / "summary.md").read_text()
    assert "a failed or infeasible row meets no threshold whatever its values" in text
    assert "| 3 (failed) |" not in text and "| 3 | 100.0 |" not in text  # case 3 is not a worst case
    columns, rows = case_table(study, results.records)
    html = study_report(study, (columns, rows), summary_table(study, rows), requirement_table(study, rows), 0,
                        robustness_tables(study, rows))
    tables = {}
    for key in ("robustness", "worst"):
        start = html.index(f'"{key}":{{"columns"') + len(key) + 3
        tables[key] = json.JSONDecoder().raw_decode(html, start)[0]
    worst = tables["worst"]
    names = [column["key"] for column in worst["columns"]]
    assert [row[names.index("case")] for row in worst["rows"]] == [0, 1, 1, 2]
    robustness = tables["robustness"]
    names = [column["key"] for column in robustness["columns"]]
    met = {row[names.index("criterion")]: row[names.index("met")] for row in robustness["rows"]}
    assert met == {"every requirement": 2, "cl.settling_time_s <= 12": 1, "cl.int_u >= 1.5": 2}
    assert "only rows ok or violated count" in html
