"""Robustness outputs of a Monte Carlo study (issue 28, part 5): the probabilities of meeting every
requirement and the study's thresholds with Wilson intervals (robustness.csv), the rank correlations
of the summary metrics with the dispersed parameters (sensitivity.csv), the worst cases
(worst_cases.csv), and ``slewbench sweep DIR --case N``. The oracles are SciPy (``binomtest``'s
Wilson interval, ``spearmanr``), pandas on the stored ``cases.csv``, and counts by hand."""
import copy
import json
import math
import re

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.stats import binomtest, permutation_test, rankdata, spearmanr

from scenarios.cli.commands import main
from scenarios.output.directory import MARKER
from scenarios.study.report import wilson_interval
from scenarios.study.robustness import proportion_table, spearman, worst_table
from scenarios.study.spec import parse_study
from tests.test_sweep import BASE as SWEEP_BASE  # the tiny two-row eigenaxis scenario

BASE = {**copy.deepcopy(SWEEP_BASE),
        "simulation": {"sample_time": 1.0, "duration": 35.0, "sensor_noise": {"attitude_deg": 0.01}}}
SUMMARY = ["cl.final_error_deg", "cl.int_u", "cl.max_error_deg"]
THRESHOLD = 0.0045  # about the median final error of these cases [deg]: some meet it, some do not
STUDY = {"study": "robust-mc", "scenario": "base.yaml",
         "monte_carlo": {"samples": 10, "seed": 11, "dispersions": {
             "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1.0, 0.5, 0.0]}},
             "spacecraft.inertia": {"scale": {"uniform": [0.9, 1.1]}},
             "controller.options.kd": {"uniform": [0.5, 0.7]},
             "simulation.sensor_noise.seed": "case_seed"}},
         "summary": SUMMARY,
         "robustness": {"thresholds": {"cl.final_error_deg": THRESHOLD, "cl.int_u": {"at_least": 0.2}}, "worst": 3}}


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A small Monte Carlo study run by the command line, without plots."""
    folder = tmp_path_factory.mktemp("robust")
    (folder / "base.yaml").write_text(yaml.safe_dump(BASE))
    (folder / "study.yaml").write_text(yaml.safe_dump(STUDY))
    out = folder / "out"
    assert main(["sweep", str(folder / "study.yaml"), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    return folder, out


# --- Wilson ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("met, n", [(0, 1), (1, 1), (8, 10), (0, 10), (10, 10), (81, 263), (1, 1000), (999, 1000)])
def test_wilson_interval_equals_scipys(met, n):
    expected = binomtest(met, n).proportion_ci(confidence_level=0.95, method="wilson")
    assert wilson_interval(met, n) == pytest.approx((expected.low, expected.high), abs=1e-12)


def test_wilson_interval_is_exactly_0_or_1_at_the_ends():
    assert wilson_interval(0, 100)[0] == 0.0 and wilson_interval(100, 100)[1] == 1.0


def test_wilson_interval_by_hand():
    """8 of 10, z = 1.959964: centre (0.8 + z²/20) / (1 + z²/10) = 0.71674, half-width
    z √(0.016 + z²/400) / (1 + z²/10) = 0.22658."""
    low, high = wilson_interval(8, 10)
    assert low == pytest.approx(0.71674 - 0.22658, abs=1e-5) and high == pytest.approx(0.71674 + 0.22658, abs=1e-5)


# --- proportions ----------------------------------------------------------------------------------

def _rows(values, statuses):
    return [{"case": k, "seed": k, "label": "a", "status": s, "cl.final_error_deg": v, "cl.int_u": v}
            for k, (v, s) in enumerate(zip(values, statuses))]


def test_threshold_fractions_count_by_hand():
    """Five rows: 0.05, 0.1 (at the bound: meets it), 0.2, a failed row without a value, a crashed
    row (not completed): of 4 completed, 2 are <= 0.1, 1 is >= 0.15, 2 meet every requirement."""
    study = parse_study({"study": "s", "scenario": copy.deepcopy(BASE),
                         "robustness": {"thresholds": {"cl.final_error_deg": 0.1, "cl.int_u": {"at_least": 0.15}}}})
    rows = _rows([0.05, 0.1, 0.2, None, None], ["ok", "ok", "violated", "failed", "crashed"])
    columns, table = proportion_table(study, rows)
    assert columns == ["label", "criterion", "completed", "excluded", "met", "fraction_met", "wilson_low", "wilson_high"]
    assert {line["excluded"] for line in table} == {2}  # the failed and the crashed rows
    found = {line["criterion"]: (line["completed"], line["met"], line["fraction_met"]) for line in table}
    assert found == {"every requirement": (4, 2, 0.5), "cl.final_error_deg <= 0.1": (4, 2, 0.5),
                     "cl.int_u >= 0.15": (4, 1, 0.25)}
    line = next(line for line in table if line["criterion"] == "cl.int_u >= 0.15")
    assert (line["wilson_low"], line["wilson_high"]) == pytest.approx(wilson_interval(1, 4))


def test_robustness_csv_counts_the_stored_cases(swept):
    _, out = swept
    cases = pd.read_csv(out / "cases.csv")
    robustness = pd.read_csv(out / "robustness.csv")
    assert set(robustness["criterion"]) == {"every requirement", f"cl.final_error_deg <= {THRESHOLD:g}",
                                            "cl.int_u >= 0.2"}
    for label, group in cases.groupby("label"):
        mine = robustness[robustness["label"] == label].set_index("criterion")
        below = int((group["cl.final_error_deg"] <= THRESHOLD).sum())
        above = int((group["cl.int_u"] >= 0.2).sum())
        ok = int((group["status"] == "ok").sum())
        for criterion, met in (("every requirement", ok), (f"cl.final_error_deg <= {THRESHOLD:g}", below),
                               ("cl.int_u >= 0.2", above)):
            assert mine.loc[criterion, "completed"] == len(group) == 10
            assert mine.loc[criterion, "met"] == met, (label, criterion)
            ci = binomtest(met, len(group)).proportion_ci(method="wilson")
            assert mine.loc[criterion, "wilson_low"] == pytest.approx(ci.low, abs=1e-12)
            assert mine.loc[criterion, "wilson_high"] == pytest.approx(ci.high, abs=1e-12)
    # the threshold splits the cases: neither all nor none meet it (else the test would be blind)
    below = robustness[robustness["criterion"].str.startswith("cl.final_error_deg")]["met"]
    assert 0 < below.sum() < 20


# --- rank correlations ----------------------------------------------------------------------------

def test_spearman_equals_scipys_with_ties_and_missing_values(rng):
    x = rng.integers(0, 5, 40).astype(float)  # many ties
    y = x + rng.normal(0, 2, 40)
    y[[3, 17]] = np.nan
    keep = np.isfinite(y)
    assert spearman(x, y) == pytest.approx(spearmanr(x[keep], y[keep]).statistic, abs=1e-12)
    assert spearman(np.arange(5.0), -np.arange(5.0) ** 3) == pytest.approx(-1.0)
    assert spearman(np.ones(5), np.arange(5.0)) is None and spearman(np.arange(2.0), np.arange(2.0)) is None


def _component(value, k):
    parsed = json.loads(value) if isinstance(value, str) else value
    return float(np.ravel(parsed)[k]) if isinstance(parsed, list) else float(parsed)


def _rank_correlation(a, b, axis=-1):
    """Pearson's correlation of rank vectors along ``axis`` (Spearman's rho of the ranked data)."""
    a = a - a.mean(axis=axis, keepdims=True)
    b = b - b.mean(axis=axis, keepdims=True)
    return np.sum(a * b, axis=axis) / np.sqrt(np.sum(a * a, axis=axis) * np.sum(b * b, axis=axis))


def test_sensitivity_csv_equals_scipy_on_the_stored_cases(swept):
    _, out = swept
    cases = pd.read_csv(out / "cases.csv")
    sensitivity = pd.read_csv(out / "sensitivity.csv")
    # one parameter per drawn quantity: a vector per component (the one not dispersed, std 0, and the case
    # seed left out), the whole-inertia scale ONE factor although it multiplies 3 moments
    assert set(sensitivity["parameter"]) == {"simulation.initial_attitude_error_deg[0]",
                                             "simulation.initial_attitude_error_deg[1]", "spacecraft.inertia",
                                             "controller.options.kd"}
    assert dict(zip(sensitivity["parameter"], sensitivity["draw"])) == {
        "simulation.initial_attitude_error_deg[0]": "value", "simulation.initial_attitude_error_deg[1]": "value",
        "spacecraft.inertia": "scale", "controller.options.kd": "value"}
    assert len(sensitivity) == 2 * len(SUMMARY) * 4
    for _, line in sensitivity.iterrows():
        group = cases[cases["label"] == line["label"]]
        path, _, index = line["parameter"].partition("[")
        # the scale's ranks are those of any (positive) moment it multiplies, read back from cases.csv
        x = np.array([_component(v, int(index[:-1]) if index else 0) for v in group[path]])
        y = group[line["metric"]].to_numpy(dtype=float)
        expected = spearmanr(x, y)
        assert line["cases"] == 10
        assert line["spearman_rho"] == pytest.approx(expected.statistic, abs=1e-12), (line["label"], line["metric"], path)
        # 10 cases: a permutation test's p-value (the t approximation's is 1.2-4x too small here);
        # scipy's own permutation test on the ranks, within both tests' sampling error
        ranks = (rankdata(x), rankdata(y))
        reference = permutation_test(ranks, _rank_correlation, permutation_type="pairings", vectorized=True,
                                     n_resamples=99999, random_state=1).pvalue
        spread = 4.0 * math.sqrt(reference * (1.0 - reference) * (1.0 / 20000 + 1.0 / 99999)) + 1e-4
        assert line["p_value"] == pytest.approx(reference, abs=spread), (line["label"], line["metric"])
        assert line["rho_low"] <= line["spearman_rho"] <= line["rho_high"]
    # Holm within each label: the adjusted p-values, by scipy's multiple-test-free arithmetic by hand
    for _, group in sensitivity.groupby("label"):
        p = group["p_value"].to_numpy()
        order = np.argsort(p, kind="stable")
        adjusted = np.maximum.accumulate(np.minimum(1.0, (len(p) - np.arange(len(p))) * p[order]))
        np.testing.assert_allclose(group["p_holm"].to_numpy()[order], adjusted, rtol=1e-12)
        assert (group["significant"] == (group["p_holm"] <= 0.05)).all()
    # the smooth row's reference is one quintic profile whatever the inertia, so its torque (I times the
    # angular acceleration) and the closed loop's effort rank with the inertia scale: the table is not noise
    rho = sensitivity.set_index(["label", "metric", "parameter"])
    assert rho.loc[("smooth", "cl.int_u", "spacecraft.inertia"), "spearman_rho"] > 0.9
    assert bool(rho.loc[("smooth", "cl.int_u", "spacecraft.inertia"), "significant"])


# --- worst cases ----------------------------------------------------------------------------------

def test_worst_cases_csv_lists_the_largest_values_by_case(swept):
    _, out = swept
    cases = pd.read_csv(out / "cases.csv")
    worst = pd.read_csv(out / "worst_cases.csv")
    for (label, metric), listed in worst.groupby(["label", "metric"], sort=False):
        group = cases[cases["label"] == label]
        least = metric == "cl.int_u"  # an at_least threshold: the smallest are the worst
        expected = group.nsmallest(3, metric) if least else group.nlargest(3, metric)
        assert list(listed["rank"]) == [1, 2, 3]
        assert list(listed["case"]) == list(expected["case"]), (label, metric)
        assert list(listed["value"]) == pytest.approx(list(expected[metric]))
        assert list(listed["seed"]) == list(expected["seed"])
    summary = (out / "summary.md").read_text()
    assert "## Robustness" in summary and "## Sensitivity" in summary and "## Worst cases" in summary


def test_worst_cases_skip_rows_without_a_value():
    study = parse_study({"study": "s", "scenario": copy.deepcopy(BASE), "robustness": {"worst": 2}})
    study.summary = ["cl.final_error_deg"]
    rows = _rows([0.3, None, 0.5, 0.1], ["ok", "failed", "ok", "ok"])
    _, table = worst_table(study, rows)
    assert [(line["case"], line["value"]) for line in table] == [(2, 0.5), (0, 0.3)]
    assert worst_table(study, _rows([0.2, 0.2, None], ["ok", "ok", "failed"]))[1] == []  # all alike: none is worst


def test_a_grid_study_writes_no_robustness_tables(tmp_path):
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "grid.yaml").write_text(yaml.safe_dump({"study": "g", "scenario": "base.yaml",
                                                        "grid": {"maneuver.duration": [30.0, 40.0]}}))
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "grid.yaml"), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    assert (out / "requirements.csv").exists() and not (out / "robustness.csv").exists()


# --- the study file's robustness keys -------------------------------------------------------------

@pytest.mark.parametrize("robustness, where, words", [
    ({"thresholds": {"cl.bogus": 1.0}}, "robustness.thresholds.cl.bogus", "expected ref.<metric> or cl.<metric>"),
    ({"thresholds": {"cl.int_u": {"between": 1.0}}}, "robustness.thresholds.cl.int_u", "{at_least: number}"),
    ({"thresholds": {"cl.int_u": "small"}}, "robustness.thresholds.cl.int_u", "number"),
    ({"thresholds": {"cl.req.nothing.ok": 1.0}}, "robustness.thresholds.cl.req.nothing.ok", "no case has a requirement"),
    ({"worst": 0}, "robustness.worst", "0"),
    ({"worst": 101}, "robustness.worst", "101"),
    ({"unknown": 1}, "robustness.unknown", "unknown key"),
])
def test_bad_robustness_keys_exit_2_naming_the_path(tmp_path, capsys, robustness, where, words):
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump({"study": "b", "scenario": "base.yaml",
                                                       "robustness": robustness}))
    assert main(["sweep", str(tmp_path / "bad.yaml"), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert where in error and words in error, error
    assert not (tmp_path / "out").exists()


# --- sweep DIR --case N ---------------------------------------------------------------------------

def test_sweep_case_reruns_a_stored_case_in_full_with_the_stored_rows(swept, capsys):
    folder, out = swept
    capsys.readouterr()
    assert main(["sweep", str(out), "--case", "7", "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "the re-run's rows equal the stored case's" in printed
    rerun = pd.read_csv(out / "cases" / "7" / "results.csv")
    stored = pd.read_csv(out / "cases.csv")
    stored = stored[stored["case"] == 7].reset_index(drop=True)
    assert list(rerun["label"]) == list(stored["label"]) == ["smooth", "fast"]
    metrics = [c for c in rerun.columns if c.startswith(("ref.", "cl."))]
    assert metrics and set(metrics) <= set(stored.columns)
    pd.testing.assert_frame_equal(rerun[metrics], stored[metrics], check_exact=True)
    assert (out / "cases" / "7" / "timeseries").is_dir()
    manifest = json.loads((out / "cases" / "7" / MARKER).read_text())
    assert manifest["kind"] == "run" and manifest["complete"] and "results.json" in manifest["files"]
    # the sweep's own report is redrawn beside the re-run case, which it leaves alone
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0
    assert (out / "cases" / "7" / "results.csv").exists()


def test_sweep_case_never_writes_where_slewbench_did_not(swept, capsys):
    folder, out = swept
    foreign = folder / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    assert main(["sweep", str(out), "--case", "0", "--out", str(foreign), "--no-plots"]) == 2
    assert sorted(p.name for p in foreign.iterdir()) == ["notes.txt"]
    assert "slewbench did not create" in capsys.readouterr().err
    assert main(["sweep", str(out), "--case", "10"]) == 2
    assert "--case: expected a case of the study, 0 to 9, got 10" in capsys.readouterr().err
    assert main(["sweep", str(out), "--case", "1", "--resume"]) == 2
    assert main(["sweep", str(folder), "--case", "1"]) == 2
    assert "holds no slewbench sweep" in capsys.readouterr().err
    assert not (folder / "cases").exists()


def test_sweep_case_reports_a_row_that_differs(swept, capsys, monkeypatch):
    """The comparison is not blind: a stored row changed behind the re-run's back is reported."""
    from scenarios.study import rerun

    _, out = swept
    original = rerun.stored_results

    def tampered(directory):
        results, version = original(directory)
        key = results.study.cases[2].key
        results.records[key]["rows"][1]["closed_loop"]["final_error_deg"] += 1e-9
        return results, version

    monkeypatch.setattr("scenarios.study.rerun.stored_results", tampered)  # imported by the handler
    capsys.readouterr()
    assert main(["sweep", str(out), "--case", "2", "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "differs from the stored case in 1 column(s)" in printed and "fast: cl.final_error_deg stored" in printed
    stored, now = re.search(r"cl\.final_error_deg stored (\S+), now (\S+)", printed).groups()
    assert float(stored) - float(now) == pytest.approx(1e-9, rel=1e-3)


def test_the_sensitivity_heat_map_draws_the_table(swept):
    import matplotlib.pyplot as plt

    from scenarios.study.plots import figures
    from scenarios.study.rerun import stored_results

    _, out = swept
    results, _ = stored_results(out)
    _, rows = results.table()
    sensitivity = pd.read_csv(out / "sensitivity.csv")
    drawn = {}
    for name, figure in figures(results.study, rows):
        if name == "sensitivity.png":
            drawn = {axis.get_title(): axis.images[0].get_array() for axis in figure.axes if axis.images}
        plt.close(figure)
    assert set(drawn) == {"smooth", "fast"}
    parameters = list(dict.fromkeys(sensitivity["parameter"]))
    for label, image in drawn.items():
        expected = sensitivity[sensitivity["label"] == label].pivot(index="metric", columns="parameter",
                                                                    values="spearman_rho").loc[SUMMARY, parameters]
        np.testing.assert_allclose(np.ma.filled(image.astype(float), np.nan), expected.to_numpy(), rtol=0, atol=1e-15)


def test_the_sweep_prints_each_criterion_and_the_worst_cases(swept):
    from scenarios.study.report import robustness_tables
    from scenarios.study.rerun import stored_results
    from scenarios.study.robustness import robustness_lines

    _, out = swept
    results, _ = stored_results(out)
    proportions, _, worst = robustness_tables(results.study, results.table()[1])
    lines = robustness_lines(proportions, worst)
    robustness = pd.read_csv(out / "robustness.csv")
    line = robustness[(robustness["label"] == "fast") & (robustness["criterion"] == "every requirement")].iloc[0]
    assert (f"  fast: every requirement {line['met']}/10 = {line['fraction_met']:.3g} "
            f"[{line['wilson_low']:.3f}, {line['wilson_high']:.3f}]") in lines
    worst_cases = pd.read_csv(out / "worst_cases.csv")
    mine = worst_cases[(worst_cases["label"] == "smooth") & (worst_cases["metric"] == "cl.int_u")]["case"]
    assert f"  smooth: worst cl.int_u: case {', '.join(map(str, mine))}" in lines


def test_the_sensitivity_map_shows_whole_paths_broken_after_dots():
    """A tester found the parameter names cut (``…raft.inertia.principal_moments_scale[0]``); two
    drawn quantities that differ early in their path could not be told apart. The oracle: the
    lines joined are the path, and each break follows a dot."""
    from scenarios.study.plots import PATH_LINE_CHARS, _path_lines

    for path in ("truth.spacecraft.inertia.principal_moments_scale[0]", "truth.wheels.friction.coulomb",
                 "maneuver.duration", "a_key_longer_than_the_line_with_no_dot_at_all_anywhere"):
        lines = _path_lines(path).split("\n")
        assert "".join(lines) == path
        assert all(line.endswith(".") for line in lines[:-1])
        assert all(len(line) <= PATH_LINE_CHARS or "." not in line[:-1] for line in lines), lines
