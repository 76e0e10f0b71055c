"""The study summary takes the rows the plots take: ``ok`` and ``violated`` (the motion completed);
a ``failed``, ``infeasible`` or ``crashed`` row is left out of the statistics whatever values it
carries, and ``summary.csv`` says how many were left out (``excluded``).

Before: ``summary.csv`` counted a failed row's values (a planner or simulation that failed, metrics
that are not physical) in its count, mean, percentiles and extremes, while the plots and the
histograms left it out or drew it, each by its own rule. Oracle: the statistics worked out by hand
below from the given values.
"""
from __future__ import annotations

import copy
import csv
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import scenarios
from scenarios.study.html import histogram_figure
from tests.test_sweep import InlineExecutor

BASE = {
    "name": "tiny",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}

# per case: (row status, cl.int_u, cl.settling_time_s, cl.final_error_deg). Cases 3 and 5 carry values
# though they did not complete (a failed simulation's metrics that are not physical, an infeasible
# plan's); case 3 also ends outside the band (no settling time): "never settled" if it counted.
# Case 4 crashed (no metrics at all).
GIVEN: list[tuple[str, float | None, float | None, float | None]] = [
    ("ok", 1.0, 10.0, 0.01), ("violated", 2.0, None, 2.0), ("ok", 4.0, 20.0, 0.02),
    ("failed", 100.0, None, 5.0), ("crashed", None, None, None), ("infeasible", 50.0, 5.0, 0.01)]




def task_for(study: scenarios.Study, given: list[tuple[str, float | None, float | None, float | None]] = GIVEN) -> Any:
    """A sweep task returning, for case i, one row with ``given[i]``'s status and closed-loop metrics."""
    by_key = {case.key: given[case.index] for case in study.cases}

    def task(payload: dict[str, Any]) -> dict[str, Any]:
        status, int_u, settling, error = by_key[payload["key"]]
        closed = None if int_u is None else {"int_u": int_u, "settling_time_s": settling, "final_error_deg": error}
        row = {"label": "smooth", "planner": "eigenaxis", "controller": "augmented_quaternion_feedback",
               "status": status, "message": "timed out" if status == "crashed" else "",
               "plan_time_s": None if status == "crashed" else 0.1, "reference": None, "closed_loop": closed}
        return {"key": payload["key"], "status": "crashed" if status == "crashed" else "ok", "rows": [row],
                "elapsed_s": 0.0, "cpu_s": 0.0, "worker_cpu_s": 0.0, "worker": "here:0", "cache_builds": 0}
    return task


@pytest.fixture(scope="module")
def swept(tmp_path_factory: pytest.TempPathFactory) -> tuple[scenarios.Study, Any, Path]:
    study = scenarios.parse_study({
        "study": "failed-rows", "scenario": copy.deepcopy(BASE),
        "grid": {"maneuver.duration": [30.0, 31.0, 32.0, 33.0, 34.0, 35.0]},
        "summary": ["cl.int_u", "cl.settling_time_s"]})
    results = scenarios.sweep(study, InlineExecutor(), workers=1, task=task_for(study))
    out = tmp_path_factory.mktemp("failed") / "out"
    results.write(out, plots=False)
    return study, results, out


def summary_lines(out: Path) -> dict[str, dict[str, str]]:
    with open(out / "summary.csv", newline="") as handle:
        return {line["metric"]: line for line in csv.DictReader(handle)}


def test_the_summary_leaves_out_rows_that_did_not_complete_and_counts_them(swept: Any) -> None:
    """cl.int_u over the rows ok or violated, [1, 2, 4]: mean 7/3; deviations -4/3, -1/3, 5/3,
    squares 42/9, over n - 1 = 2: variance 7/3; median 2; p5 at position 0.1: 1.1; p95 at 1.9: 3.8;
    min 1, max 4. Left out: the failed (100), the crashed and the infeasible (50) rows: no_value 3,
    excluded 3; not_ok (rows not ok) 4."""
    _, _, out = swept
    line = summary_lines(out)["cl.int_u"]
    assert float(line["mean"]) == pytest.approx(7 / 3, rel=1e-12), line
    assert float(line["std"]) == pytest.approx(math.sqrt(7 / 3), rel=1e-12)
    assert float(line["median"]) == 2.0 and float(line["min"]) == 1.0 and float(line["max"]) == 4.0
    assert float(line["p5"]) == pytest.approx(1.1, rel=1e-12) and float(line["p95"]) == pytest.approx(3.8, rel=1e-12)
    assert (line["count"], line["never"], line["no_value"], line.get("excluded"), line["not_ok"]) == \
        ("3", "", "3", "3", "4"), line


def test_a_failed_row_that_never_settled_is_left_out_not_counted_as_never(swept: Any) -> None:
    """cl.settling_time_s over the rows ok or violated: settled [10, 20], the violated row never
    settled (+inf). mean 15, std sqrt(50); ordered [10, 20, inf]: median 20, p5 at position 0.1:
    11, p95 at 1.9 (towards inf): inf. The failed row (final error 5 deg, no settling time) is not
    a second "never"; the infeasible row's 5 s is not the minimum."""
    _, _, out = swept
    line = summary_lines(out)["cl.settling_time_s"]
    assert float(line["mean"]) == pytest.approx(15.0, rel=1e-12), line
    assert float(line["std"]) == pytest.approx(math.sqrt(50.0), rel=1e-12)
    assert float(line["median"]) == 20.0 and float(line["p5"]) == pytest.approx(11.0, rel=1e-12)
    assert line["p95"] == "inf" and line["max"] == "inf" and float(line["min"]) == 10.0
    assert (line["count"], line["never"], line["no_value"], line.get("excluded")) == ("2", "1", "3", "3"), line


def test_the_summary_markdown_states_the_excluded_rows(swept: Any) -> None:
    _, _, out = swept
    text = (out / "summary.md").read_text()
    header = next(line for line in text.splitlines() if line.startswith("| label"))
    assert "| excluded |" in header
    assert "a failed, infeasible or crashed row is left out" in text


def test_the_report_histogram_bins_the_rows_the_summary_counts(swept: Any) -> None:
    """The histogram of report.html counts the summary's ``count`` rows, [1, 2, 4]: not 100 or 50."""
    _, results, _ = swept
    _, rows = results.table()
    figure = histogram_figure("cl.int_u", rows, ["smooth"])
    (curve,) = figure["data"]
    assert curve["name"] == "smooth (3 cases)"
    assert float(np.sum(curve["y"])) == 3.0
    assert min(curve["x"]) == 1.0 and max(curve["x"]) == 4.0
