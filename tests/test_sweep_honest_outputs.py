"""What a sweep's directory and summary claim: a study whose cases collapse to one simulation says so
and counts it once, an empty ``dispersions`` is refused at its path, a resumed sweep marks the
directory incomplete until its new tables are written, ``--resume`` into another study's directory
is refused with nothing touched, Ctrl-C while the cases are checked exits 130, and a study without
``requirements.final`` says that its rows are ok whatever their final error."""
from __future__ import annotations

import copy
import csv
import hashlib
import json

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.output.directory import MARKER
from scenarios.runner import final_accuracy_note
from scenarios.study.report import wilson_interval
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import SweepStore
from scenarios.study.worker import crashed_rows
from tests.test_sweep import BASE


def write(tmp_path, data, name="study.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump({"scenario": copy.deepcopy(BASE), **data}))
    return path


def snapshot(directory):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(directory.iterdir()) if p.is_file()}


def test_empty_dispersions_are_refused_at_their_path():
    with pytest.raises(ScenarioError) as caught:
        parse_study({"study": "empty", "scenario": copy.deepcopy(BASE),
                     "monte_carlo": {"samples": 5, "seed": 1, "dispersions": {}}})
    assert caught.value.path == "monte_carlo.dispersions" and "at least one dispersion" in caught.value.message


def test_cases_that_collapse_to_one_simulation_count_once(tmp_path, capsys):
    """uniform [a, a]: 6 cases, one store key. The proportion is 1 of 1 distinct case, its Wilson
    interval that of n = 1 (not [0.61, 1] as for 6 independent samples), and the summary says so."""
    path = write(tmp_path, {"study": "dup", "monte_carlo": {
        "samples": 6, "seed": 1, "dispersions": {"controller.options.kd": {"uniform": [0.6, 0.6]}}}})
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    said = capsys.readouterr().out
    assert "note: the 6 cases are 1 distinct case" in said, said
    low, high = wilson_interval(1, 1)
    assert f"smooth: every requirement 1/1 = 1 [{low:.3f}, {high:.3f}]" in said, said
    with open(out / "requirements.csv", newline="") as handle:
        lines = list(csv.DictReader(handle))
    assert [(line["completed"], line["met"]) for line in lines if line["criterion"] == "every requirement"] == [
        ("1", "1"), ("1", "1")]
    assert "note: the 6 cases are 1 distinct case" in (out / "summary.md").read_text()
    with open(out / "cases.csv", newline="") as handle:
        assert len(list(csv.DictReader(handle))) == 12  # the table still lists every case


def test_a_resumed_sweep_marks_the_directory_incomplete_until_its_tables_are_written(tmp_path, monkeypatch, capsys):
    from scenarios.study import engine
    out = tmp_path / "out"
    grown = write(tmp_path, {"study": "grow", "grid": {"controller.options.kp": [0.2, 0.3, 0.4]}})
    assert main(["sweep", str(grown), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    assert json.loads((out / MARKER).read_text())["complete"] is True
    case = load_study(grown).cases[2]
    with SweepStore(out) as store:  # as a crashed case is stored: its tables are written, and resume runs it again
        store.put(case.key, "crashed", crashed_rows(case.scenario, "timed out after 600 s (case_timeout_s)"), 600.0, 1)
    seen = {}
    real_sweep = engine.sweep

    def interrupted(*args, **kwargs):
        seen["complete"] = json.loads((out / MARKER).read_text())["complete"]
        raise KeyboardInterrupt

    monkeypatch.setattr(engine, "sweep", interrupted)
    assert main(["sweep", str(grown), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 130
    assert seen == {"complete": False}  # before any case ran
    assert json.loads((out / MARKER).read_text())["complete"] is False  # the tables of the crash stay, marked stale
    monkeypatch.setattr(engine, "sweep", real_sweep)
    assert main(["sweep", str(grown), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0
    assert json.loads((out / MARKER).read_text())["complete"] is True
    with open(out / "cases.csv", newline="") as handle:
        assert len(list(csv.DictReader(handle))) == 6


def test_resume_into_another_studys_directory_is_refused_and_touches_nothing(tmp_path, capsys):
    out = tmp_path / "out"
    first = write(tmp_path, {"study": "first", "grid": {"controller.options.kp": [0.2]}}, "first.yaml")
    assert main(["sweep", str(first), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    before = snapshot(out)
    other = write(tmp_path, {"study": "second", "grid": {"controller.options.kp": [0.3]}}, "second.yaml")
    capsys.readouterr()
    assert main(["sweep", str(other), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 2
    err = capsys.readouterr().err
    assert "holds the sweep of study 'first', not 'second'" in err and "nothing was touched" in err, err
    assert snapshot(out) == before
    # the same study resumes
    assert main(["sweep", str(first), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0


def test_ctrl_c_while_the_cases_are_checked_exits_130(tmp_path, monkeypatch, capsys):
    import scenarios.cli.sweep as command

    def checking(name):
        def show(checked, total):
            raise KeyboardInterrupt
        return show

    monkeypatch.setattr(command, "_checking", checking)
    path = write(tmp_path, {"study": "checked", "grid": {"controller.options.kp": [0.2, 0.3]}})
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 130
    assert "interrupted while its cases were checked" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("where, phase", [("engine.start_forkserver", "while it started"),
                                          ("command._output", "before its first case")])
def test_ctrl_c_before_the_first_case_says_where_and_that_nothing_was_written(tmp_path, monkeypatch, capsys, where,
                                                                              phase):
    # Before: Ctrl-C between the check and the first case (the plots' import, the output directory's
    # check) reached main's "results not written or marked incomplete in the output manifest".
    import scenarios.cli.sweep as command
    from scenarios.study import engine

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    owner, name = where.split(".")
    monkeypatch.setattr({"engine": engine, "command": command}[owner], name, interrupted)
    path = write(tmp_path, {"study": "phases", "grid": {"controller.options.kp": [0.2, 0.3]}})
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 130
    assert capsys.readouterr().err == f"slewbench: sweep interrupted {phase}; nothing was run or written\n"
    assert not (tmp_path / "out").exists()


def test_the_check_says_how_far_it_is_off_a_terminal_after_1_s_then_every_30_s(capsys):
    import scenarios.cli.sweep as command

    now = [100.0]
    show = command._checking("big", clock=lambda: now[0])
    for elapsed, checked in ((0.4, 10), (0.99, 30), (1.0, 31), (20.0, 500), (30.99, 800), (31.0, 801), (45.0, 900),
                             (61.0, 1500), (62.5, 2000)):
        now[0] = 100.0 + elapsed
        show(checked, 2000)
    assert capsys.readouterr().err.splitlines() == [
        "big: checking 2000 cases, 31 checked, 1.0 s elapsed",
        "big: checking 2000 cases, 801 checked, 31.0 s elapsed",
        "big: checking 2000 cases, 1500 checked, 61.0 s elapsed",
        "big: 2000 cases checked in 62.5 s"]
    show = command._checking("small", clock=lambda: now[0])  # checked within 1 s: nothing said
    now[0] += 0.9
    show(5, 10)
    show(10, 10)
    assert capsys.readouterr().err == ""


def test_ctrl_c_while_connecting_to_a_scheduler_exits_130(tmp_path, monkeypatch, capsys):
    # Before: the KeyboardInterrupt reached main's catch-all for a run and exited 1.
    from scenarios.study import engine

    def connecting(address, where):
        raise KeyboardInterrupt

    monkeypatch.setattr(engine, "connect_scheduler", connecting)
    path = write(tmp_path, {"study": "connecting", "grid": {"controller.options.kp": [0.2]}})
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--scheduler", "tcp://10.0.0.7:8786"]) == 130
    assert "interrupted while it connected to the Dask scheduler tcp://10.0.0.7:8786" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_finished_sweep_leaves_no_sqlite_side_files(tmp_path):
    # Before: sweep.sqlite-wal and sweep.sqlite-shm stayed beside the store after every sweep (the
    # report's read-only reader re-made them on a WAL database).
    path = write(tmp_path, {"study": "tidy", "grid": {"controller.options.kp": [0.2]}})
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    names = {p.name for p in out.iterdir()}
    assert "sweep.sqlite" in names and not names & {"sweep.sqlite-wal", "sweep.sqlite-shm"}, names
    assert main(["sweep", "--report", str(out)]) == 0
    assert not {p.name for p in out.iterdir()} & {"sweep.sqlite-wal", "sweep.sqlite-shm"}


def test_the_final_accuracy_note_counts_the_rows_outside_their_band():
    assert final_accuracy_note([(0.05, 0.1), (None, 0.1)], 2) is None
    note = final_accuracy_note([(0.05, 0.1), (45.0, 0.1), (89.7, 0.1), (None, 0.1)], 4)
    assert note == ("note: no requirements.final: rows are ok whatever their final error; 2 of 4 rows end more "
                    "than 0.1 deg (simulation.settling_tolerance_deg) off the target (up to 89.7 deg)")


def test_a_sweep_without_a_final_requirement_says_its_rows_end_off_target(tmp_path, capsys):
    """A simulation that stops 10 s into a 30 s slew of 45 deg ends far off the target; without
    requirements.final its rows are ok, and the summary says so. With the requirement, no note."""
    base = copy.deepcopy(BASE)
    base["simulation"]["duration"] = 10.0
    path = tmp_path / "short.yaml"
    path.write_text(yaml.safe_dump({"study": "short", "scenario": base, "grid": {"controller.options.kp": [0.2]}}))
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--no-plots"]) == 0
    said = capsys.readouterr().out
    assert "note: no requirements.final: rows are ok whatever their final error; 2 of 2 rows end more than " \
           "0.5 deg (simulation.settling_tolerance_deg) off the target" in said, said
    assert "0 crashed and 0 others have a row not ok" in said


def test_the_shipped_truth_scenario_requires_the_slew_to_be_performed():
    """eigenaxis_truth.yaml states requirements.final: a plant whose wheels give 1e-4 N m (a 90 deg
    slew of a 19 kg m^2 body needs about 0.05 N m) ends far off the target and its rows are
    violated, not ok; the nominal plant's rows stay ok."""
    from pathlib import Path

    from scenarios.runner import run
    from scenarios.schema.loader import load, parse_scenario

    scenario = load(Path(__file__).resolve().parents[1] / "scenarios" / "eigenaxis_truth.yaml")
    assert scenario.requirements.final is not None
    assert {row.status for row in run(scenario).rows} == {"ok"}
    data = copy.deepcopy(scenario.data)
    data["truth"]["wheels"] = {"max_torque": 1.0e-4}
    rows = run(parse_scenario(data)).rows
    assert all(row.closed_loop_metrics["final_error_deg"] > 10.0 for row in rows)
    assert {row.status for row in rows} == {"violated"} and all("final" in row.message for row in rows)
