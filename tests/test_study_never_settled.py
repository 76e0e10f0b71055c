"""A case that never settles (``settling_time_s`` null while the row has a final error: still outside
the band at the last sample) is the worst outcome, not a missing value: the summary counts it apart
(``count`` rows with a value, ``never``, ``no_value``), its order statistics take it as +inf, the
worst-case list ranks it first and the rank correlation ranks it last. Oracles: the statistics
worked out by hand below, Spearman's rho from ``scipy.stats.spearmanr``."""
import copy
import csv
import math

import numpy as np
import pytest
from scipy.stats import spearmanr

import scenarios
from ocp.metrics import METRIC_INFO
from scenarios.study.report import never_witness, percentile
from scenarios.study.robustness import robustness_lines
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




# per case: (settling time, final error, row status); case 2 and 5 end outside the band (a final
# error, no settling time): never settled; case 4's planner failed (no closed loop at all)
GIVEN = [(10.0, 0.01, "ok"), (20.0, 0.02, "ok"), (None, 1.0, "ok"), (40.0, 0.03, "ok"), (None, None, "failed"),
         (None, 2.0, "violated")]


def task_for(study):
    by_key = {case.key: GIVEN[case.index] for case in study.cases}

    def task(payload):
        settling, error, status = by_key[payload["key"]]
        closed = None if error is None else {"settling_time_s": settling, "final_error_deg": error}
        row = {"label": "smooth", "planner": "eigenaxis", "controller": "augmented_quaternion_feedback",
               "status": status, "message": "", "plan_time_s": 0.1, "reference": None, "closed_loop": closed}
        return {"key": payload["key"], "status": "ok", "rows": [row], "elapsed_s": 0.0, "cpu_s": 0.0,
                "worker_cpu_s": 0.0, "worker": "here:0", "cache_builds": 0}
    return task


def study_results(tmp_path):
    study = scenarios.parse_study({
        "study": "never", "scenario": copy.deepcopy(BASE), "summary": ["cl.settling_time_s", "cl.final_error_deg"],
        "monte_carlo": {"samples": 6, "seed": 5, "dispersions": {"controller.options.kd": {"uniform": [0.5, 0.7]}}},
        "robustness": {"thresholds": {"cl.settling_time_s": 30.0}}})
    results = scenarios.sweep(study, InlineExecutor(), workers=1, task=task_for(study))
    results.write(tmp_path / "out", plots=False)
    return study, tmp_path / "out"


def read(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_the_metric_table_declares_which_null_means_never():
    assert METRIC_INFO["settling_time_s"].null_worst_when == "final_error_deg"
    assert METRIC_INFO["int_u"].null_worst_when is None
    assert never_witness("cl.settling_time_s") == "cl.final_error_deg"
    assert never_witness("ref.settling_time_s") == "ref.final_error_deg"
    assert never_witness("cl.final_error_deg") is None and never_witness("cl.req.final.error_deg") is None


def test_summary_counts_never_settled_cases_and_takes_them_as_inf(tmp_path):
    """Settled [10, 20, 40], never settled 2, no value 1 (the failed planner). mean 70/3; sample
    std of [10, 20, 40]: deviations -40/3, -10/3, 50/3, squares (1600 + 100 + 2500)/9 = 1400/3,
    over n - 1 = 2: variance 700/3. Ordered with +inf: [10, 20, 40, inf, inf]:
    median (position 2) 40, p5 (position 0.2) 12, p95 (position 3.8, towards inf) inf, min 10,
    max inf."""
    _, out = study_results(tmp_path)
    line = next(r for r in read(out / "summary.csv") if r["metric"] == "cl.settling_time_s")
    assert (line["count"], line["never"], line["no_value"], line["not_ok"]) == ("3", "2", "1", "2")
    assert float(line["mean"]) == pytest.approx(70 / 3, rel=1e-12)
    assert float(line["std"]) == pytest.approx(math.sqrt(700 / 3), rel=1e-12)
    assert float(line["median"]) == 40.0 and float(line["p5"]) == pytest.approx(12.0, rel=1e-12)
    assert line["p95"] == "inf" and line["max"] == "inf" and float(line["min"]) == 10.0
    error = next(r for r in read(out / "summary.csv") if r["metric"] == "cl.final_error_deg")
    assert (error["count"], error["never"], error["no_value"]) == ("5", "", "1")  # "never" does not apply
    assert "| inf |" in (out / "summary.md").read_text()


def test_worst_cases_rank_the_never_settled_first(tmp_path):
    _, out = study_results(tmp_path)
    worst = [r for r in read(out / "worst_cases.csv") if r["metric"] == "cl.settling_time_s"]
    assert [(r["case"], r["value"]) for r in worst] == [("2", "inf"), ("5", "inf"), ("3", "40.0"), ("1", "20.0"),
                                                        ("0", "10.0")]


def test_sensitivity_ranks_never_settled_last_as_scipy_does(tmp_path):
    study, out = study_results(tmp_path)
    kd = np.array([case.scenario["controller"]["options"]["kd"] for case in study.cases])
    settling = np.array([math.inf if s is None and e is not None else (math.nan if s is None else s)
                         for s, e, _ in GIVEN])
    keep = ~np.isnan(settling)
    expected = spearmanr(kd[keep], settling[keep]).statistic
    line = next(r for r in read(out / "sensitivity.csv") if r["metric"] == "cl.settling_time_s")
    assert line["cases"] == "5"
    assert float(line["spearman_rho"]) == pytest.approx(expected, rel=1e-12)


def test_threshold_and_printed_worst_list(tmp_path):
    study, out = study_results(tmp_path)
    met = next(r for r in read(out / "robustness.csv") if r["criterion"] == "cl.settling_time_s <= 30")
    assert (met["met"], met["completed"]) == ("2", "6")
    from scenarios.study.report import robustness_tables
    results = scenarios.sweep(study, InlineExecutor(), workers=1, task=task_for(study))
    proportions, _, worst = robustness_tables(study, results.table()[1])
    assert "  smooth: worst cl.settling_time_s: case 2 (never), 5 (never), 3, 1, 0" in robustness_lines(proportions,
                                                                                                          worst)


def test_percentile_towards_inf():
    values = np.array([1.0, 2.0, math.inf])
    assert percentile(values, 0.0) == 1.0 and percentile(values, 25.0) == 1.5
    assert percentile(values, 50.0) == 2.0 and percentile(values, 75.0) == math.inf
    finite = np.array([3.0, 1.0, 7.0, 2.0])
    assert percentile(finite, 95.0) == np.percentile(finite, 95.0)


def test_an_impulsive_reference_counts_as_infinite_effort_not_as_no_value():
    """A reference whose rate jumps has ``int_u`` (its impulses) and no finite ``int_u2`` nor peak
    torque (written null in the files): the study takes those nulls as +inf, the worst effort; a
    failed planner's row (no ``int_u`` either) has no value."""
    from scenarios.study.report import metric_values

    rows = [{"ref.int_u": 8.06e-4, "ref.int_u2": None, "ref.peak_body_torque": None},   # impulses
            {"ref.int_u": 2.2e-3, "ref.int_u2": 5.85e-8, "ref.peak_body_torque": 1e-4},  # a smooth plan
            {"ref.int_u": None, "ref.int_u2": None, "ref.peak_body_torque": None}]      # failed
    for column, finite in (("ref.int_u2", 5.85e-8), ("ref.peak_body_torque", 1e-4)):
        values = metric_values(column, rows)
        assert values[0] == math.inf and values[1] == finite and math.isnan(values[2])
