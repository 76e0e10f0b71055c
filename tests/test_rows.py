"""Rows of runs and sweeps: one labelling, one plain form, one column naming, one rule for missing and
non-finite values, and output problems reported apart from scenario errors.

A run's ``results.csv`` and a sweep's ``cases.csv`` of the same scenario are compared cell by cell;
the non-finite rule is pinned on hand-built rows whose every expected cell is written out here.
"""
import contextlib
import copy
import csv
import io
import json
import math
import sqlite3
from concurrent.futures import Executor, Future

import pandas as pd
import pytest
import yaml

import scenarios
from ocp import METRIC_KEYS, SlewbenchError
from scenarios.cli.commands import main
from scenarios.errors import OutputError, ScenarioError
from scenarios.output.results import Row, RunResults
from scenarios.schema.labels import RowLabel, row_labels
from scenarios.study.engine import sweep
from scenarios.study.spec import parse_study
from scenarios.study.worker import crashed_rows, run_case

BASE = {
    "name": "rows",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "eigenaxis", "label": "fast", "options": {"profile": "min_time", "torque_fraction": 0.8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}
ROW_KEYS = {"label", "planner", "controller", "status", "message", "plan_time_s", "plan_reused", "reference",
            "closed_loop", "requirements", "certificate", "needed_duration_s"}
IDENTITY = ["label", "planner", "controller", "status", "message", "plan_time_s", "plan_reused"]
CERTIFICATE = ["certificate", "certificate_verdict", "certificate_kkt_scaled", "certificate_kkt_unscaled"]


def strict_json(text):
    """JSON that must not contain NaN or Infinity (which Python's parser would accept)."""
    def refuse(name):
        raise AssertionError(f"{name} in JSON")
    return json.loads(text, parse_constant=refuse)


def read_csv(text):
    return list(csv.DictReader(io.StringIO(text)))


# --- columns and the non-finite rule ------------------------------------------------------------

def expected_metric_columns():
    """Written out from the metrics page's table: ref then cl, int_abs_u split per axis, no plan_time_s."""
    columns = []
    for scope in ("ref", "cl"):
        for key in METRIC_KEYS:
            if key == "plan_time_s":
                continue
            columns += [f"{scope}.int_abs_u_{a}" for a in "xyz"] if key == "int_abs_u" else [f"{scope}.{key}"]
    return columns


def hand_built_results():
    scenario = scenarios.parse_scenario(copy.deepcopy(BASE))
    reference = dict.fromkeys(METRIC_KEYS)
    reference.update(int_u2=2.0, int_u=math.nan, peak_body_torque=math.inf, settling_time_s=-math.inf,
                     int_abs_u=[1.0, math.nan, 3.0], duration_s=30.0)
    closed = dict.fromkeys(METRIC_KEYS)
    closed.update(final_error_deg=0.25, int_u=0.5)
    rows = [Row("odd", "eigenaxis", "failed", "reference metrics are not physical", 0.125, reference, None,
                controller="augmented_quaternion_feedback"),
            Row("regulating", None, "ok", "regulation to the target", None, None, closed, controller="eigenaxis_pd")]
    return RunResults(scenario, rows)


def test_missing_and_non_finite_values_are_null_in_json_empty_in_csv_and_float_nan_in_the_dataframe():
    results = hand_built_results()
    assert [row["reference"] for row in strict_json(results.to_json())["rows"]][0] == {
        **dict.fromkeys(METRIC_KEYS), "int_u2": 2.0, "int_abs_u": [1.0, None, 3.0], "duration_s": 30.0}
    json_rows = strict_json(results.to_json())["rows"]
    assert set(json_rows[0]) == ROW_KEYS | {"file_stem"} and json_rows[0]["closed_loop"] is None
    assert json_rows[1]["planner"] is None and json_rows[1]["plan_time_s"] is None

    text = results.to_csv()
    header = text.splitlines()[0].split(",")
    # the duration an infeasible row needs after the identity columns; the rows' file stems appended
    assert header == IDENTITY + ["needed_duration_s"] + expected_metric_columns() + CERTIFICATE + ["file_stem"]
    odd, regulating = read_csv(text)
    assert odd["certificate"] == "" and odd["certificate_kkt_scaled"] == ""  # no reference: no certificate
    assert (odd["ref.int_u2"], odd["ref.int_abs_u_x"], odd["ref.int_abs_u_z"], odd["ref.duration_s"]) == \
        ("2.0", "1.0", "3.0", "30.0")
    for column in ("ref.int_u", "ref.peak_body_torque", "ref.settling_time_s", "ref.int_abs_u_y", "ref.rms_error_deg", "cl.int_u"):
        assert odd[column] == "", column
    assert odd["plan_time_s"] == "0.125" and regulating["plan_time_s"] == "" and regulating["planner"] == ""
    assert regulating["cl.final_error_deg"] == "0.25" and regulating["ref.int_u"] == ""

    frame = results.to_dataframe()
    assert list(frame.columns) == header
    numeric = ["plan_time_s", *expected_metric_columns(), *CERTIFICATE[2:]]
    assert all(frame[column].dtype == "float64" for column in numeric), frame.dtypes[frame.dtypes != "float64"]
    assert not frame[numeric].map(lambda value: value is None).to_numpy().any()
    for column in ("ref.int_u", "ref.peak_body_torque", "ref.settling_time_s", "ref.int_abs_u_y", "cl.int_u"):
        assert math.isnan(frame.loc[0, column]), column
    assert frame.loc[0, "ref.int_u2"] == 2.0 and frame.loc[1, "cl.int_u"] == 0.5 and math.isnan(frame.loc[1, "plan_time_s"])

    markdown = results.to_markdown()
    assert "| ref.int_u | - | - |" in markdown and "| ref.int_u2 | 2 | - |" in markdown
    assert "| ref.peak_body_torque | - | - |" in markdown and "nan" not in markdown and "inf" not in markdown


def test_a_runs_results_csv_and_a_sweeps_cases_csv_agree_cell_for_cell(tmp_path):
    """The same scenario run by ``slewbench run`` and as the one case of a study: the same metric
    columns, the same text in every cell but the wall-clock ``plan_time_s``, the same DataFrame."""
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(BASE))
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "one-case", "scenario": "scenario.yaml",
                                     "summary": ["cl.int_abs_u_y", "ref.int_u", "cl.rms_error_deg"]}))
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--no-plots"]) == 0
    assert main(["sweep", str(study), "--out", str(tmp_path / "sweep"), "--workers", "1", "--no-plots"]) == 0
    run_text = (tmp_path / "run" / "results.csv").read_text()
    cases_text = (tmp_path / "sweep" / "cases.csv").read_text()
    # the same columns in the same order, both ending with the rows' file stems
    assert cases_text.splitlines()[0] == "case,seed," + run_text.splitlines()[0]
    ran, cased = read_csv(run_text), read_csv(cases_text)
    assert len(ran) == len(cased) == 2
    for run_row, case_row in zip(ran, cased):
        for column in IDENTITY + expected_metric_columns():
            if column != "plan_time_s":
                assert run_row[column] == case_row[column], column
        assert run_row["ref.rms_error_deg"] == "" and run_row["cl.rms_error_deg"] != ""  # null: a closed-loop metric
    summary = read_csv((tmp_path / "sweep" / "summary.csv").read_text())
    for line in summary:  # one case: the mean is the case's value
        row = next(r for r in ran if r["label"] == line["label"])
        assert float(line["mean"]) == float(row[line["metric"]]) and line["std"] == "0.0"
    assert {line["metric"] for line in summary} == {"cl.int_abs_u_y", "ref.int_u", "cl.rms_error_deg"}

    direct = scenarios.run(scenarios.load(path)).to_dataframe()
    swept = sweep(scenarios.load_study(study), workers=1).to_dataframe()
    assert list(swept.columns[:2]) == ["case", "seed"]
    assert list(direct["file_stem"]) == ["smooth", "fast"]  # the rows' file stems, appended
    assert list(swept["file_stem"]) == ["smooth", "fast"]  # one case: the stems a --case re-run gives
    pd.testing.assert_frame_equal(direct.drop(columns=["plan_time_s", "file_stem"]),
                                  swept.drop(columns=["case", "seed", "plan_time_s", "file_stem"]))


def test_a_sweeps_dataframe_holds_nan_not_none_for_a_crashed_case():
    def crash(payload):
        return {"key": payload["key"], "status": "crashed", "rows": crashed_rows(payload["scenario"], "boom"),
                "elapsed_s": 0.0, "worker": "here:1", "cache_builds": 0}

    study = parse_study({"study": "crash", "scenario": copy.deepcopy(BASE)})
    frame = sweep(study, workers=1, task=crash, executor=_Inline()).to_dataframe()
    numeric = ["plan_time_s", *expected_metric_columns()]
    assert list(frame["status"]) == ["crashed", "crashed"] and list(frame["message"]) == ["boom", "boom"]
    assert all(frame[column].dtype == "float64" for column in numeric)
    assert frame[numeric].isna().all().all()


class _Inline(Executor):
    """Runs each task at submission, in this thread."""

    def submit(self, fn, /, *args, **kwargs):
        future = Future()
        future.set_result(fn(*args, **kwargs))
        return future


def test_summary_keys_are_the_metric_columns():
    for key in ("cl.int_abs_u", "ref.plan_time_s", "cl.int_u_x", "cl_int_u"):
        with pytest.raises(ScenarioError, match=r"summary\[0\]: expected ref\.<metric> or cl\.<metric>") as error:
            parse_study({"study": "s", "scenario": copy.deepcopy(BASE), "summary": [key]})
        assert repr(key) in str(error.value)
    assert parse_study({"study": "s", "scenario": copy.deepcopy(BASE), "summary": ["cl.int_abs_u_z"]}).summary == \
        ["cl.int_abs_u_z"]


# --- one plain form -----------------------------------------------------------------------------

def test_a_worker_returns_each_rows_to_dict_and_a_crashed_row_has_the_same_keys():
    data = copy.deepcopy(BASE)
    result = run_case({"key": "k", "scenario": data, "timeout_s": 60.0})
    direct = scenarios.run(scenarios.parse_scenario(copy.deepcopy(BASE)))
    assert [set(row) for row in result["rows"]] == [ROW_KEYS, ROW_KEYS]
    def without_clock(value):  # plan_time_s is wall time, in the row and in its metric dicts
        if isinstance(value, dict):
            return {k: without_clock(v) for k, v in value.items() if k != "plan_time_s"}
        return value

    for stored, row in zip(result["rows"], direct.rows):
        assert without_clock(stored) == without_clock(row.to_dict())
    assert [set(row) for row in crashed_rows(data, "x")] == [ROW_KEYS, ROW_KEYS]
    assert [row["reference"] for row in crashed_rows(data, "x")] == [None, None]


# --- one labelling ------------------------------------------------------------------------------

def test_row_labels_by_hand():
    assert row_labels([], ["bdot", "free"]) == [RowLabel("bdot", None, 0), RowLabel("free", None, 1)]
    assert row_labels(["a", "b"], ["pd"]) == [RowLabel("a", 0, 0), RowLabel("b", 1, 0)]
    assert row_labels(["a", "b"], ["c", "d"]) == [RowLabel("a / c", 0, 0), RowLabel("a / d", 0, 1),
                                                 RowLabel("b / c", 1, 0), RowLabel("b / d", 1, 1)]
    cases = [(["a", "a"], ["pd"], "planners[1].label", "duplicate label 'a'; give each row its own label"),
             (["a", "a"], ["c", "d"], "planners[1].label", "duplicate label 'a'; give each row its own label"),
             ([], ["c", "c"], "controllers[1].label", "duplicate label 'c'; give each controller its own label"),
             (["a"], ["c", "c"], "controllers[1].label", "duplicate label 'c'; give each controller its own label"),
             (["a / b", "a"], ["c", "b / c"], "controllers[1].label",
              "row label 'a / b / c' is made twice (planners[0] with controllers[0], planners[1] with "
              "controllers[1]); choose labels without ' / '")]
    for planners, controllers, path, message in cases:
        with pytest.raises(ScenarioError) as error:
            row_labels(planners, controllers)
        assert (error.value.path, error.value.message) == (path, message)


def colliding():
    data = copy.deepcopy(BASE)
    data["planners"] = [{"name": "eigenaxis", "label": "a / b"}, {"name": "eigenaxis", "label": "a"}]
    data["controllers"] = [data.pop("controller"), {"name": "eigenaxis_pd", "label": "b / c"}]
    data["controllers"][0]["label"] = "c"
    return data


def test_a_label_collision_is_the_same_error_in_the_loader_the_runner_and_the_sweep():
    with pytest.raises(ScenarioError) as loaded:
        scenarios.parse_scenario(colliding())
    with pytest.raises(ScenarioError) as crashed:  # a sweep's worker labels a crashed case's rows
        crashed_rows(colliding(), "x")
    valid = copy.deepcopy(colliding())
    valid["planners"][0]["label"] = "z"
    scenario = scenarios.parse_scenario(valid)
    scenario.planners[0].label = "a / b"  # a scenario changed after it was checked
    with pytest.raises(ScenarioError) as ran:
        scenarios.run(scenario)
    with pytest.raises(ScenarioError) as swept:
        parse_study({"study": "s", "scenario": colliding()})
    expected = ("controllers[1].label", "row label 'a / b / c' is made twice (planners[0] with controllers[0], "
                                        "planners[1] with controllers[1]); choose labels without ' / '")
    for error in (loaded, crashed, ran):
        assert (error.value.path, error.value.message) == expected
    assert (swept.value.path, swept.value.message) == (f"scenario: {expected[0]}", expected[1])


# --- output errors ------------------------------------------------------------------------------

def test_an_output_problem_is_an_output_error_not_a_scenario_error(tmp_path, capsys, monkeypatch):
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(BASE))
    target = tmp_path / "file.txt"
    target.write_text("keep")
    assert main(["run", str(path), "--out", str(target), "--no-plots"]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"slewbench: output error: --out {target}: exists and is not a directory"), error
    assert "error in scenario" not in error and target.read_text() == "keep"
    assert main(["codegen", str(path), "--out", str(target)]) == 2
    assert capsys.readouterr().err.startswith(f"slewbench: output error: --out {target}:")
    assert main(["sweep", "--report", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith(f"slewbench: output error: --report {tmp_path}: holds no slewbench sweep")

    default = tmp_path / "results" / BASE["name"]  # the default results/<name>, occupied by a file of the user's
    default.parent.mkdir()
    default.write_text("keep")
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(path), "--no-plots"]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"slewbench: output error: results/{BASE['name']}: exists and is not a directory"), error
    assert default.read_text() == "keep"  # and --out, which the user did not give, is not named

    results = hand_built_results()
    with pytest.raises(OutputError) as raised:
        results.write(target, plots=False)
    assert not isinstance(raised.value, ScenarioError) and isinstance(raised.value, SlewbenchError)
    assert raised.value.path == target and str(raised.value).startswith(f"{target}: exists and is not a directory")


# --- a store written by the previous version ------------------------------------------------------

def test_a_store_of_the_previous_format_is_redrawn_by_report_and_refused_by_resume(tmp_path, capsys):
    """Format 1 stored each row's metrics under ``ref`` and ``cl``; ``--report`` redraws it into the
    same cases.csv, a run into it is refused with a message naming ``--report``."""
    (tmp_path / "scenario.yaml").write_text(yaml.safe_dump(BASE))
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "old", "scenario": "scenario.yaml"}))
    out = tmp_path / "out"
    assert main(["sweep", str(study), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    before = (out / "cases.csv").read_text()
    with contextlib.closing(sqlite3.connect(out / "sweep.sqlite")) as db:  # as the previous version wrote it
        for key, rows in db.execute("SELECT key, rows FROM cases").fetchall():
            old = [{**{k: v for k, v in row.items() if k not in ("reference", "closed_loop")},
                    "ref": row["reference"], "cl": row["closed_loop"]} for row in json.loads(rows)]
            db.execute("UPDATE cases SET rows = ? WHERE key = ?", (json.dumps(old), key))
        db.execute("UPDATE meta SET value = ? WHERE name = 'format'", (json.dumps("slewbench-sweep-1"),))
        db.commit()
    (out / "cases.csv").unlink()
    capsys.readouterr()
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0
    assert (out / "cases.csv").read_text() == before
    stored = (out / "sweep.sqlite").read_bytes()
    for extra in ([], ["--resume"]):
        assert main(["sweep", str(study), "--out", str(out), "--no-plots", *extra]) == 2
        error = capsys.readouterr().err
        assert error.startswith(f"slewbench: output error: --out {out}: holds a sweep written by an earlier "
                                "slewbench (sweep.sqlite format 'slewbench-sweep-1')"), error
        assert f"slewbench sweep --report {out}" in error
    assert (out / "sweep.sqlite").read_bytes() == stored
