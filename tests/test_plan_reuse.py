"""A study worker reuses a reference when the planning inputs are identical (the planner, its
options, the design problem), and plans again when any of them changes.

A Monte Carlo that disperses only the truth plant (``truth.*``) plans once per worker; its rows are
those of cases each planned afresh, bit for bit (the wall-clock ``plan_time_s`` aside, and
``plan_reused``, which says which rows reused a reference). A planner that declares
``deterministic = False`` is planned every time.
"""
from __future__ import annotations

import copy
import dataclasses
import json
import math
import shutil
import sqlite3

import numpy as np
import pandas as pd
import pytest
import yaml

import scenarios
from ocp import SolverCache
from planners import PLANNERS, FailedReference
from planners.collocation.planner import CollocationPlanner
from planners.eigenaxis import EigenaxisPlanner
from scenarios.cli.commands import main
from scenarios.runner import planning_key
from scenarios.study.engine import sweep
from scenarios.study.rerun import (
    PROCESS_COLUMNS,
    rerun_case,
    row_differences,
    stored_results,
)
from scenarios.study.spec import parse_study
from tests.test_sweep import InlineExecutor

BASE = {
    "name": "plan-reuse",
    "spacecraft": {"inertia": [3.0, 3.5, 4.0], "wheels": {"max_torque": 0.05, "spin_inertia": 2.0e-5}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "collocation", "label": "min energy", "options": {"intervals": 8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
    "truth": {"spacecraft": {"inertia": [3.1, 3.4, 4.1]}, "wheels": {"friction": {"coulomb": 1e-5}}},
}




@pytest.fixture
def calls(monkeypatch):
    """Counts the plans of each planner class (the class's plan replaced by a counting one; a
    collocation's seed planned by eigenaxis counts too)."""
    counts = {"eigenaxis": 0, "collocation": 0}
    for name, kind in (("eigenaxis", EigenaxisPlanner), ("collocation", CollocationPlanner)):
        def counting(self, problem, original=kind.plan, name=name):
            counts[name] += 1
            return original(self, problem)

        monkeypatch.setattr(kind, "plan", counting)
    return counts


def _bits(value):
    """A row as nested plain values with every float as its exact bits (NaN equal to NaN), but the
    columns that describe how the row was computed (its plan time, whether it was reused)."""
    if isinstance(value, dict):
        return {key: _bits(item) for key, item in value.items() if key not in PROCESS_COLUMNS}
    if isinstance(value, (list, tuple)):
        return [_bits(item) for item in value]
    if isinstance(value, (float, np.floating)):
        return "nan" if math.isnan(value) else float(value).hex()
    return value


def _study(dispersions, samples=3):
    return parse_study({"study": "plan-reuse", "scenario": copy.deepcopy(BASE),
                        "monte_carlo": {"samples": samples, "seed": 3, "dispersions": dispersions}})


def _fresh_rows(cases):
    """Each case run alone, its references planned afresh (no reuse), as rows."""
    return [[row.to_dict() for row in scenarios.run(scenarios.parse_scenario(copy.deepcopy(case.scenario)),
                                                    cache=SolverCache()).rows]
            for case in cases]


def test_a_plant_only_monte_carlo_plans_once_and_gives_the_rows_of_fresh_plans(calls):
    study = _study({"truth.spacecraft.inertia": {"principal": {"moments_scale": {"uniform": [[0.9] * 3, [1.1] * 3]}}},
                    "truth.wheels.friction.coulomb": {"uniform": [0.0, 4e-5]}})
    fresh = _fresh_rows(study.cases[:1])
    one = dict(calls)  # the plans of one case
    assert one["eigenaxis"] >= 1 and one["collocation"] == 1
    results = sweep(study, InlineExecutor())
    assert calls == {name: 2 * count for name, count in one.items()}  # one worker: planned in the first case only
    stored = [results.records[case.key]["rows"] for case in study.cases]
    assert all(row["status"] == "ok" for rows in stored for row in rows)
    # the closed loops differ (the plants do), the references do not
    assert len({rows[0]["closed_loop"]["final_error_deg"] for rows in stored}) == len(study.cases)
    # a reused row carries the time of the plan that made its reference
    assert len({rows[1]["plan_time_s"] for rows in stored}) == 1
    fresh += _fresh_rows(study.cases[1:])
    assert calls == {name: (1 + len(study.cases)) * count for name, count in one.items()}
    assert [_bits(rows) for rows in stored] == [_bits(rows) for rows in fresh]


def test_a_design_dispersion_plans_every_case(calls):
    study = _study({"spacecraft.inertia": {"principal": {"moments_scale": {"uniform": [[0.9] * 3, [1.1] * 3]}}}})
    sweep(study, InlineExecutor())
    assert calls["collocation"] == len(study.cases) and calls["eigenaxis"] >= len(study.cases)


def test_a_changed_planner_option_or_boundary_condition_plans_again(calls):
    references = SolverCache()

    def run(change=None):
        data = copy.deepcopy(BASE)
        data["planners"] = data["planners"][:1]
        if change:
            change(data)
        scenarios.run(scenarios.parse_scenario(data), cache=SolverCache(), references=references)

    run()
    run()
    assert calls["eigenaxis"] == 1
    run(lambda data: data["planners"][0].update(options={"torque_fraction": 0.8}))
    assert calls["eigenaxis"] == 2
    run(lambda data: data["maneuver"].update(duration=30.0 + 1e-12))  # compared exactly
    assert calls["eigenaxis"] == 3
    run(lambda data: data["maneuver"]["final"].update(omega=[0, 0, 1e-6]))
    assert calls["eigenaxis"] == 4
    run(lambda data: data.update(truth={"spacecraft": {"inertia": [3.2, 3.5, 4.0]}}))  # the plant only
    run(lambda data: data["simulation"].update(duration=40.0))  # the closed loop only
    assert calls["eigenaxis"] == 4


def test_a_failed_plan_is_never_reused(monkeypatch):
    planned = []

    def out_of_time(self, problem):
        planned.append(problem)
        return FailedReference(self.name, "time limit reached after 3 calls")

    monkeypatch.setattr(EigenaxisPlanner, "plan", out_of_time)
    references = SolverCache()
    data = copy.deepcopy(BASE)
    data["planners"] = data["planners"][:1]
    for _ in range(3):
        row = scenarios.run(scenarios.parse_scenario(data), references=references).rows[0]
        assert row.status == "failed" and "time limit" in row.message
    assert len(planned) == 3 and len(references) == 0


def test_a_reused_reference_is_a_copy_that_a_run_cannot_change(calls):
    references = SolverCache()
    data = copy.deepcopy(BASE)
    data["planners"] = data["planners"][:1]
    first = scenarios.run(scenarios.parse_scenario(data), references=references).rows[0].reference
    first.stats["certificate"] = {"verdict": "changed by the first run"}
    second = scenarios.run(scenarios.parse_scenario(data), references=references).rows[0].reference
    assert calls["eigenaxis"] == 1 and second is not first and "certificate" not in second.stats


# --- plan_reused: the row says its reference was reused --------------------------------------------

TRUTH_ONLY = {"truth.spacecraft.inertia": {"principal": {"moments_scale": {"uniform": [[0.9] * 3, [1.1] * 3]}}}}


def test_the_rows_of_a_truth_only_sweep_say_which_reused_their_reference(calls):
    study = _study(TRUTH_ONLY)
    results = sweep(study, InlineExecutor())
    assert calls["collocation"] == 1  # one worker: planned in the first case, reused in the two others
    stored = [results.records[case.key]["rows"] for case in study.cases]
    assert [[row["plan_reused"] for row in rows] for rows in stored] == [[False, False], [True, True], [True, True]]
    # cases.csv and its DataFrame carry the column: a bool, True where reused
    columns, table = results.table()
    assert "plan_reused" in columns
    assert [line["plan_reused"] for line in table] == [False, False, True, True, True, True]
    frame = results.to_dataframe()
    assert str(frame["plan_reused"].dtype) == "boolean" and list(frame["plan_reused"]) == [False] * 2 + [True] * 4


def test_a_run_without_reference_reuse_plans_and_says_so(calls):
    data = copy.deepcopy(BASE)
    references = SolverCache()
    first = scenarios.run(scenarios.parse_scenario(data), references=references)
    again = scenarios.run(scenarios.parse_scenario(data), references=references)
    alone = scenarios.run(scenarios.parse_scenario(data))
    assert [row.plan_reused for row in first.rows] == [False, False]
    assert [row.plan_reused for row in again.rows] == [True, True]
    assert [row.to_dict()["plan_reused"] for row in alone.rows] == [False, False]
    assert "plan_reused,needed_duration_s,ref." in again.to_csv().splitlines()[0] and ",True," in again.to_csv().splitlines()[1]


@pytest.fixture(scope="module")
def swept_truth_only(tmp_path_factory):
    """A three-case truth-only Monte Carlo swept by the command line with one worker process."""
    folder = tmp_path_factory.mktemp("reused")
    study = {"study": "plan-reused", "scenario": copy.deepcopy(BASE),
             "monte_carlo": {"samples": 3, "seed": 3, "dispersions": TRUTH_ONLY}}
    (folder / "study.yaml").write_text(yaml.safe_dump(study))
    out = folder / "out"
    assert main(["sweep", str(folder / "study.yaml"), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    return folder, out


def test_case_on_a_reused_case_reports_the_stored_rows_equal(swept_truth_only, capsys):
    _, out = swept_truth_only
    results, _ = stored_results(out)
    reused = [case.index for case in results.study.cases
              if all(row["plan_reused"] for row in results.records[case.key]["rows"])]
    assert len(reused) == 2  # one worker: the first case it ran planned, the two others reused
    capsys.readouterr()
    assert main(["sweep", str(out), "--case", str(reused[0]), "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert "the re-run's rows equal the stored case's (2 row(s)" in printed, printed
    rerun = json.loads((out / "cases" / str(reused[0]) / "results.json").read_text())
    assert [row["plan_reused"] for row in rerun["rows"]] == [False, False]  # planned afresh, the same rows


def test_a_store_written_before_the_column_loads_resumes_and_reports(swept_truth_only, capsys):
    folder, original = swept_truth_only
    out = folder / "older"
    shutil.copytree(original, out)
    with sqlite3.connect(out / "sweep.sqlite") as db:  # rows as an earlier slewbench stored them
        cases = db.execute("SELECT key, rows FROM cases ORDER BY key").fetchall()
        for key, rows in cases:
            older = [{name: value for name, value in row.items() if name != "plan_reused"} for row in json.loads(rows)]
            db.execute("UPDATE cases SET rows = ? WHERE key = ?", (json.dumps(older), key))
        db.execute("DELETE FROM cases WHERE key = ?", (cases[0][0],))  # a case not run yet
    results, _ = stored_results(out)
    assert len(results.records) == 2
    frame = results.to_dataframe()
    assert str(frame["plan_reused"].dtype) == "boolean" and frame["plan_reused"].isna().all()
    index = next(case.index for case in results.study.cases if case.key in results.records)
    rows = results.records[results.study.cases[index].key]["rows"]
    assert row_differences(rows, rerun_case(results, index)) == []
    assert main(["sweep", str(folder / "study.yaml"), "--out", str(out), "--resume", "--workers", "1",
                 "--no-plots"]) == 0
    table = pd.read_csv(out / "cases.csv", keep_default_na=False)
    assert len(table) == 6
    resumed = table["case"] == next(case.index for case in results.study.cases if case.key == cases[0][0])
    assert set(table.loc[~resumed, "plan_reused"]) == {""}  # stored before: missing, an empty cell
    assert set(table.loc[resumed, "plan_reused"]) == {"False"}  # the resumed worker's first case: planned


# --- a planner that does not declare deterministic is never reused --------------------------------

class Jittery(EigenaxisPlanner):
    """An eigenaxis slew whose duration is off by a random part in 1e9: two plans differ."""

    name = "jittery"
    deterministic = False
    plans = 0

    def _plan(self, problem):
        type(self).plans += 1
        stretch = 1.0 + 1e-9 * (0.5 + np.random.default_rng().random())  # never 1
        return super()._plan(dataclasses.replace(problem, duration=problem.duration * stretch))


class JitteryDeclared(Jittery):
    """The same planner declaring (wrongly) that it is deterministic."""

    name = "jittery_declared"
    deterministic = True


@pytest.mark.parametrize("kind, plans, reused", [(Jittery, 3, [False] * 3),
                                                 (JitteryDeclared, 1, [False, True, True])])
def test_a_planner_declaring_itself_not_deterministic_is_planned_every_time(monkeypatch, kind, plans, reused):
    monkeypatch.setitem(PLANNERS, kind.name, kind)
    monkeypatch.setattr(kind, "plans", 0)
    data = copy.deepcopy(BASE)
    data["planners"] = [{"name": kind.name}]
    references = SolverCache()
    rows = [scenarios.run(scenarios.parse_scenario(data), references=references).rows[0] for _ in range(3)]
    assert [row.status for row in rows] == ["ok"] * 3
    assert kind.plans == plans and [row.plan_reused for row in rows] == reused
    durations = {row.reference.duration for row in rows}
    assert len(durations) == (3 if kind is Jittery else 1)  # the declaration decides; the plans differ
    scenario = scenarios.parse_scenario(data)
    assert (planning_key(scenario.planners[0].planner, scenario.problem) is None) == (kind is Jittery)
