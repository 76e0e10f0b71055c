"""Trade studies (issue 12): expansion and validation of a study, seeds, the store, resume, failures
of cases and workers, the outputs and the command line. Studies here are tiny (eigenaxis, a few
tens of seconds of simulated time) so that the default run stays fast."""
import contextlib
import copy
import json
import math
import sqlite3
import textwrap
from concurrent.futures import Executor, Future, ThreadPoolExecutor

import numpy as np
import pandas as pd
import pytest
import yaml

import scenarios
from scenarios import runner
from scenarios.cli.commands import main
from scenarios.output.directory import claim_output_directory
from scenarios.output.tables import flatten_row
from scenarios.study.engine import sweep
from scenarios.study.rerun import PROCESS_COLUMNS
from scenarios.study.spec import parse_study
from scenarios.study.store import SweepStore
from scenarios.study.worker import run_case

BASE = {
    "name": "tiny",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "eigenaxis", "label": "fast", "options": {"profile": "min_time", "torque_fraction": 0.8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}


def study_data(**parts):
    return {"study": "tiny-study", "scenario": copy.deepcopy(BASE), **parts}


class InlineExecutor(Executor):
    """Runs each task at submission, in this thread (so a test's monkeypatching applies)."""

    def __init__(self):
        self.submitted = 0

    def submit(self, fn, *args, **kwargs):
        self.submitted += 1
        future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except BaseException as error:  # noqa: BLE001 - handed to the caller like any executor
            future.set_exception(error)
        return future


def comparable(frame):
    """The table without the columns that describe the process, not the case (the wall-clock plan
    time; whether a worker reused a reference, which depends on which worker ran which case)."""
    return frame.drop(columns=list(PROCESS_COLUMNS)).reset_index(drop=True)


# --- expansion -------------------------------------------------------------------------------

def test_grid_is_a_cartesian_product_in_order_with_generators_and_label_paths():
    study = parse_study(study_data(grid={
        "maneuver.duration": [30.0, 40.0],
        "planners[label=fast].options.torque_fraction": {"linspace": [0.5, 1.0, 3]},
        "maneuver.final.q": {"axis_angle": {"axis": [0, 0, 2], "angle_deg": [30, 120]}}}))
    assert len(study.cases) == 2 * 3 * 2
    fractions = [c.scenario["planners"][1]["options"]["torque_fraction"] for c in study.cases]
    assert fractions[:6] == [0.5, 0.5, 0.75, 0.75, 1.0, 1.0]  # the last key varies fastest
    assert [c.scenario["maneuver"]["duration"] for c in study.cases] == [30.0] * 6 + [40.0] * 6
    assert all("options" not in c.scenario["planners"][0] for c in study.cases)  # the other row untouched
    for case in study.cases:
        q = np.array(case.scenario["maneuver"]["final"]["q"])
        angle = math.degrees(2 * math.acos(min(1.0, q[0])))
        assert angle == pytest.approx(case.varied["maneuver.final.q"], abs=1e-9)
        assert q[1:] / np.linalg.norm(q[1:]) == pytest.approx([0, 0, 1])


def test_zip_varies_together_and_unequal_lengths_are_rejected():
    study = parse_study(study_data(zip={"maneuver.duration": [30.0, 40.0], "simulation.duration": [35.0, 45.0]}))
    assert [(c.scenario["maneuver"]["duration"], c.scenario["simulation"]["duration"]) for c in study.cases] == \
        [(30.0, 35.0), (40.0, 45.0)]
    with pytest.raises(scenarios.ScenarioError, match=r"zip\.simulation\.duration: zip lists must have equal"):
        parse_study(study_data(zip={"maneuver.duration": [30.0, 40.0], "simulation.duration": [35.0]}))


@pytest.mark.parametrize("grid, expected", [
    ({"planners[5].options.profile": ["smooth"]}, r"grid\.planners\[5\]\.options\.profile: planners has 2 entries"),
    ({"planners[label=slow].options.profile": ["smooth"]}, r"no entries with label = 'slow'"),
    ({"maneuver.duration.x": [1.0]}, r"maneuver\.duration is not a mapping"),
    ({"maneuver..duration": [1.0]}, r"cannot read the scenario path"),
    ({"simulation.initial_atitude_error_deg": [[1, 0, 0]]}, r"case 0 .*simulation\.initial_atitude_error_deg.*unknown key"),
    ({"maneuver.duration": [30.0, 40.0, -1.0]}, r"case 2 \[maneuver\.duration=-1\.0\]: maneuver\.duration \(set by maneuver\.duration\): expected a positive number"),
    ({"planners[label=fast].options.torque_fraction": [0.5, 7.0]}, r"case 1 .*planners\[1\]\.options\.torque_fraction"),
])
def test_bad_paths_and_bad_cases_name_the_study_entry_and_the_case(grid, expected):
    with pytest.raises(scenarios.ScenarioError, match=expected):
        parse_study(study_data(grid=grid))


def test_a_misspelt_dispersion_is_an_error_not_a_silent_no_op():
    data = study_data(monte_carlo={"samples": 3, "dispersions": {
        "simulation.sensor_noise.sed": "case_seed"}})
    with pytest.raises(scenarios.ScenarioError, match=r"case 0 .*simulation\.sensor_noise\.sed.*unknown key"):
        parse_study(data)


def test_seeds_come_from_seed_sequence_spawn_and_dispersions_follow_them():
    data = study_data(grid={"maneuver.duration": [30.0, 40.0]}, monte_carlo={
        "samples": 200, "seed": 7, "dispersions": {
            "simulation.initial_attitude_error_deg": {"normal": {"mean": [1, 0, -1], "std": [0.5, 1, 2]}},
            "spacecraft.inertia": {"scale": {"uniform": [0.9, 1.1]}},
            "simulation.sensor_noise.seed": "case_seed"}})
    study = parse_study(data)
    children = np.random.SeedSequence(7).spawn(400)
    assert [c.seed for c in study.cases] == [int(s.generate_state(1)[0]) for s in children]
    assert all(c.scenario["simulation"]["sensor_noise"]["seed"] == c.seed for c in study.cases)
    errors = np.array([c.scenario["simulation"]["initial_attitude_error_deg"] for c in study.cases])
    # 400 draws: the sample mean is within 4 standard errors, the std within 15 %
    assert np.all(np.abs(errors.mean(axis=0) - [1, 0, -1]) < 4 * np.array([0.5, 1, 2]) / 20)
    assert errors.std(axis=0, ddof=1) == pytest.approx([0.5, 1, 2], rel=0.15)
    ratios = np.array([c.scenario["spacecraft"]["inertia"] for c in study.cases]) / [2.0, 3.0, 4.0]
    assert np.allclose(ratios, ratios[:, :1]) and 0.9 <= ratios.min() and ratios.max() <= 1.1
    again = parse_study(copy.deepcopy(data))
    assert [c.key for c in again.cases] == [c.key for c in study.cases]


def test_latin_hypercube_puts_one_sample_in_each_stratum_per_grid_point():
    study = parse_study(study_data(grid={"maneuver.duration": [30.0, 40.0]}, monte_carlo={
        "samples": 50, "method": "latin_hypercube", "seed": 3,
        "dispersions": {"simulation.sample_time": {"uniform": [0.5, 1.5]}}}))
    for point in (0, 1):
        values = np.array([c.scenario["simulation"]["sample_time"] for c in study.cases if c.point == point])
        assert sorted(np.floor((values - 0.5) * 50).astype(int)) == list(range(50))


# --- running ---------------------------------------------------------------------------------

SMALL_GRID = {"maneuver.final.q": {"axis_angle": {"axis": [1, 0, 0], "angle_deg": [20, 45]}}}


def test_a_sweep_row_equals_a_direct_run_and_a_case_does_not_depend_on_the_executor():
    data = study_data(grid=SMALL_GRID, monte_carlo={"samples": 2, "seed": 5, "dispersions": {
        "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}})
    inline = sweep(parse_study(data), InlineExecutor()).to_dataframe()
    with ThreadPoolExecutor(2) as pool:
        threaded = sweep(parse_study(data), pool, workers=2).to_dataframe()
    pd.testing.assert_frame_equal(comparable(inline), comparable(threaded))
    case = parse_study(data).cases[3]
    direct = scenarios.run(scenarios.parse_scenario(case.scenario))
    rows = inline[inline["case"] == 3]
    assert list(rows["label"]) == ["smooth", "fast"] and set(rows["status"]) == {"ok"}
    for (_, line), row in zip(rows.iterrows(), direct.rows):
        assert line["cl.final_error_deg"] == row.closed_loop_metrics["final_error_deg"]
        assert line["cl.int_abs_u_y"] == row.closed_loop_metrics["int_abs_u"][1]
        assert line["controller"] == "augmented_quaternion_feedback"


def test_a_worker_reuses_simulators_only_where_a_fresh_one_gives_the_same_rows():
    """Cases that share a worker's simulators (same model and settings; the gain, target and
    sensor noise vary, and the inertia in the last grid value) give exactly the rows of a run with
    a new simulator per case; the worker's cache keeps only its last few simulators."""
    from ocp.cache import RecentCache
    from scenarios.study.worker import worker_state

    data = study_data(grid={"controller.options.kp": [0.2, 0.3],
                            "maneuver.final.q": {"axis_angle": {"axis": [0, 1, 0], "angle_deg": [20, 40]}},
                            "spacecraft.inertia": [[2.0, 3.0, 4.0], [2.5, 3.0, 4.0]],
                            "simulation.sensor_noise": [{"attitude_deg": 0.01, "seed": 1},
                                                        {"attitude_deg": 0.01, "seed": 2}]})
    study = parse_study(data)
    simulators = worker_state()[1]
    hits = simulators.hits
    frame = sweep(study, InlineExecutor()).to_dataframe()
    assert simulators.hits - hits >= len(study.cases) - 4 and len(simulators) <= simulators.size
    metrics = [c for c in frame.columns if c.startswith(("cl.", "ref.")) and ".req." not in c]
    scored = [c for c in frame.columns if ".req." in c]
    assert scored  # the implicit actuator requirement is scored in every case
    for case in study.cases:
        direct = scenarios.run(scenarios.parse_scenario(copy.deepcopy(case.scenario)))
        rows = frame[frame["case"] == case.index]
        assert len(rows) == len(direct.rows) == 2 and set(rows["status"]) == {"ok"}
        for (_, line), row in zip(rows.iterrows(), direct.rows):
            for column in metrics:
                scope, key = column.split(".", 1)
                source = row.closed_loop_metrics if scope == "cl" else row.reference_metrics
                value = source.get(key[:-2], [None] * 3)["xyz".index(key[-1])] \
                    if key[-2:] in ("_x", "_y", "_z") and key[:-2] in source else source.get(key)
                assert line[column] == value or (value is None and pd.isna(line[column])) or (
                    isinstance(value, float) and math.isnan(value) and pd.isna(line[column])), (case.index, column)
            flat = flatten_row(row.to_dict())
            for column in scored:
                assert line[column] == flat.get(column) or (flat.get(column) is None and pd.isna(line[column])), \
                    (case.index, column)
    cache = RecentCache(size=2)
    for key in "abcbca":  # c evicts a; b and c are hits; a is built again and evicts b (least recent)
        cache.get(key, lambda: object())
    assert len(cache) == 2 and cache.builds == 4 and cache.hits == 2
    cache.get("c", lambda: object())
    assert cache.hits == 3


def test_resume_skips_stored_cases_runs_a_crashed_one_again_and_a_raising_case_is_a_crashed_row(tmp_path, monkeypatch):
    study = parse_study(study_data(grid={"maneuver.duration": [30.0, 40.0, 50.0]}))
    original = runner.run

    def flaky(scenario, **kwargs):
        if scenario.problem.duration == 40.0:
            raise RuntimeError("planner exploded")
        return original(scenario, **kwargs)

    monkeypatch.setattr(runner, "run", flaky)
    with SweepStore(tmp_path) as store:
        first = sweep(study, InlineExecutor(), store=store)
    crashed = [r for r in first.records.values() if r["status"] == "crashed"]
    assert len(crashed) == 1 and {row["label"] for row in crashed[0]["rows"]} == {"smooth", "fast"}
    assert "RuntimeError: planner exploded" in crashed[0]["rows"][0]["message"]
    executor = InlineExecutor()
    with SweepStore(tmp_path) as store:
        second = sweep(study, executor, store=store)
        assert len(store) == 3
    key = next(key for key, record in first.records.items() if record["status"] == "crashed")
    assert executor.submitted == 1  # the crashed case runs again (and crashes again here): no other
    assert second.records[key]["status"] == "crashed" and second.records[key]["attempts"] == 2
    assert {k: r for k, r in second.records.items() if k != key} == {k: r for k, r in first.records.items() if k != key}


def test_worker_keeps_one_solver_cache_so_a_collocation_nlp_is_built_once_per_worker():
    base = copy.deepcopy(BASE)
    base["planners"] = [{"name": "collocation", "label": "min energy", "options": {"intervals": 10}}]
    data = {"study": "colloc", "scenario": base,
            "grid": {"maneuver.final.q": {"axis_angle": {"axis": [0, 1, 0], "angle_deg": [10, 20, 30, 40]}}}}
    results = sweep(parse_study(data), workers=2)
    assert all(r["rows"][0]["status"] == "ok" for r in results.records.values())
    assert results.workers and set(results.workers.values()) == {1}, results.workers


def test_killed_workers_are_retried_alone_and_a_hung_case_times_out(tmp_path):
    from tests.sweep_tasks import misbehaving_task
    base = copy.deepcopy(BASE)
    base["name"] = str(tmp_path)  # where the die-once task leaves its marker
    data = {"study": "faults", "scenario": base, "grid": {"maneuver.duration": [30.0, 31.0, 32.0, 33.0, 34.0, 35.0]},
            # 4 s: the normal cases (about 0.2 s each) must finish within it on a loaded 2-core machine
            "execution": {"case_timeout_s": 4.0, "retries": 1}}
    results = sweep(parse_study(data), workers=2, task=misbehaving_task)
    status = {int(row["maneuver.duration"]): (row["status"], row["message"])
              for _, row in results.to_dataframe().iterrows() if row["label"] == "smooth"}
    assert status[30][0] == status[34][0] == "ok"
    assert status[31][0] == "crashed" and "worker died" in status[31][1] and "2 attempt(s)" in status[31][1]
    assert status[32][0] == "ok"  # died once, retried
    assert status[33][0] == "crashed" and "timed out after 4 s (case_timeout_s)" == status[33][1]
    assert status[35][0] == "crashed" and "timed out after 4 s (case_timeout_s); worker stopped" == status[35][1]


# --- command line and outputs -------------------------------------------------------------------

def write_study(tmp_path, data, name="study.yaml"):
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    data = dict(data, scenario="base.yaml")
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_cli_bad_case_exits_2_and_writes_nothing(tmp_path, capsys):
    path = write_study(tmp_path, study_data(grid={"maneuver.duration": [30.0, 0.0]}))
    assert main(["sweep", str(path), "--out", str(tmp_path / "out")]) == 2
    assert "study.yaml: case 1 [maneuver.duration=0.0]: maneuver.duration" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_cli_refuses_a_directory_it_did_not_write_and_a_stored_sweep_without_resume(tmp_path, capsys):
    path = write_study(tmp_path, study_data())
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("mine")
    assert main(["sweep", str(path), "--out", str(foreign)]) == 2
    assert sorted(p.name for p in foreign.iterdir()) == ["notes.txt"]
    (tmp_path / "file").write_text("x")
    assert main(["sweep", str(path), "--out", str(tmp_path / "file")]) == 2
    assert (tmp_path / "file").read_text() == "x"
    marked = claim_output_directory(tmp_path / "marked")  # slewbench's, with a user's database in it
    with contextlib.closing(sqlite3.connect(marked / "sweep.sqlite")) as db:
        db.execute("CREATE TABLE mine (x)")
        db.commit()
    before = (marked / "sweep.sqlite").read_bytes()
    assert main(["sweep", str(path), "--out", str(marked), "--resume"]) == 2
    assert (marked / "sweep.sqlite").read_bytes() == before
    assert "not a slewbench sweep store" in capsys.readouterr().err
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    (out / "notes.txt").write_text("mine")
    assert main(["sweep", str(path), "--out", str(out)]) == 2
    assert "pass --resume" in capsys.readouterr().err
    assert main(["sweep", "--report", str(out)]) == 0
    manifest = json.loads((out / ".slewbench-output.json").read_text())
    assert manifest["complete"] and {"cases.csv", "summary.csv", "summary.md", "study.yaml", "sweep.sqlite",
                                     "plots/pareto.png"} <= set(manifest["files"])
    assert (out / "notes.txt").read_text() == "mine" and "notes.txt" not in manifest["files"]


def test_cli_outputs_summary_statistics_and_report_redraw(tmp_path):
    data = study_data(grid={"maneuver.duration": [30.0, 40.0]}, monte_carlo={"samples": 3, "seed": 2, "dispersions": {
        "simulation.initial_attitude_error_deg": {"uniform": {"low": [-1, -1, -1], "high": [1, 1, 1]}}}},
        summary=["cl.int_u", "cl.final_error_deg", "cl.settling_time_s"])
    path = write_study(tmp_path, data)
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "2"]) == 0
    cases = pd.read_csv(out / "cases.csv")
    assert len(cases) == 2 * 3 * 2 and list(cases.columns[:4]) == ["case", "seed", "maneuver.duration",
                                                                   "simulation.initial_attitude_error_deg"]
    assert {"label", "planner", "controller", "status", "message", "plan_time_s", "ref.int_u",
            "cl.int_abs_u_x", "cl.int_abs_u_z"} <= set(cases.columns)
    summary = pd.read_csv(out / "summary.csv")
    for (duration, label), group in cases.groupby(["maneuver.duration", "label"]):
        line = summary[(summary["maneuver.duration"] == duration) & (summary["label"] == label)
                       & (summary["metric"] == "cl.int_u")].iloc[0]
        values = group["cl.int_u"].to_numpy()
        assert line["count"] == 3 and line["not_ok"] == 0
        assert line["mean"] == pytest.approx(values.mean()) and line["std"] == pytest.approx(values.std(ddof=1))
        assert line["p95"] == pytest.approx(np.percentile(values, 95)) and line["max"] == pytest.approx(values.max())
    for name in ("summary.md", "study.yaml", "plots/metrics_vs_maneuver.duration.png", "plots/boxplots.png",
                 "plots/cdf.png", "plots/pareto.png"):
        assert (out / name).stat().st_size > 100, name
    resolved = yaml.safe_load((out / "study.yaml").read_text())
    assert resolved["resolved"]["case_seeds"] == cases.drop_duplicates("case")["seed"].tolist()
    again = parse_study(resolved)  # the resolved study reproduces the same cases
    assert [c.seed for c in again.cases] == resolved["resolved"]["case_seeds"]
    before = (out / "cases.csv").read_text()
    (out / "cases.csv").unlink()
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0
    assert (out / "cases.csv").read_text() == before


def test_run_case_returns_plain_data_only():
    case = parse_study(study_data()).cases[0]
    result = run_case({"key": case.key, "scenario": case.scenario, "timeout_s": 60.0})
    assert yaml.safe_load(yaml.safe_dump(result)) == result  # nothing but plain values


def test_readme_study_and_example_studies_are_valid():
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    guide = (root / "docs" / "guide" / "studies.rst").read_text()  # the user guide's study, every key used
    block = guide.split("A study file\n", 1)[1].split(".. code-block:: yaml\n\n", 1)[1].split("\n\n", 1)[0]
    data = yaml.safe_load(textwrap.dedent(block))
    data["monte_carlo"]["samples"] = 2  # the schema as written, fewer samples
    study = parse_study(data, root / "scenarios" / "README-study.yaml")
    assert len(study.cases) == 2 * 3 * 3 * 2 * 2
    fractions = {c.scenario["planners"][1]["options"]["torque_fraction"] for c in study.cases}
    assert fractions == {0.5, 0.75, 1.0}
    from scenarios.study.report import _DUMPER, resolved_study
    for name, count in (("study_spin_weight_sample_time", 20), ("study_planners_vs_slew_angle", 7),
                        ("study_spin_monte_carlo", 1000)):
        example = scenarios.load_study(root / "scenarios" / f"{name}.yaml")
        assert len(example.cases) == count
        # study.yaml goes through libyaml's emitter when built: the same text as PyYAML's own, read back whole
        resolved = resolved_study(example)
        text = yaml.dump(resolved, Dumper=_DUMPER, sort_keys=False, width=120)
        assert text == yaml.safe_dump(resolved, sort_keys=False, width=120) and yaml.safe_load(text) == resolved


def test_pareto_front_is_the_set_of_non_dominated_points(rng):
    from scenarios.study.plots import pareto_front
    points = rng.random((200, 2))
    points[::17] = np.nan  # failed cases are left out
    finite = points[np.isfinite(points).all(axis=1)]
    dominated = [any((q <= p).all() and (q < p).any() for q in finite) for p in finite]
    expected = finite[~np.array(dominated)]
    front = pareto_front(points)
    assert sorted(map(tuple, front)) == sorted(map(tuple, expected))
    assert np.all(np.diff(front[:, 0]) > 0) and np.all(np.diff(front[:, 1]) < 0)


def test_crashed_rows_match_the_runner_rows_with_several_controllers():
    from scenarios.study.worker import crashed_rows
    data = copy.deepcopy(BASE)
    data["controllers"] = [data.pop("controller"), {"name": "eigenaxis_pd", "label": "pd"}]
    ran = scenarios.run(scenarios.parse_scenario(copy.deepcopy(data)))
    assert [(r["label"], r["planner"], r["controller"]) for r in crashed_rows(data, "x")] == \
        [(row.label, row.planner, row.controller) for row in ran.rows]
    data["planners"] = []
    ran = scenarios.run(scenarios.parse_scenario(copy.deepcopy(data)))
    assert [(r["label"], r["planner"], r["controller"]) for r in crashed_rows(data, "x")] == \
        [(row.label, row.planner, row.controller) for row in ran.rows]
