"""Rows whose file stems got a suffix are said in the terminal (``run``, ``sweep``, ``sweep --case``),
and a study's ``cases.csv`` records each row's ``file_stem`` as a run's ``results.csv`` does: the stem
its files get when the case is re-run in full.

Oracle (docs/outputs.rst, "Distinct rows, distinct files"): of the labels ``a_b``, ``a/b`` and
``comparison``, ``a_b`` keeps its stem (its label exactly), ``a/b`` gets ``a_b-2`` and
``comparison`` (a reserved stem) ``comparison-2``.
"""
from __future__ import annotations

import csv
import json

import yaml

from scenarios.cli.commands import main

SCENARIO = {
    "name": "collide", "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 20.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "a_b"}, {"name": "eigenaxis", "label": "a/b"},
                 {"name": "eigenaxis", "label": "comparison"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 22.0}}
STEMS = ["a_b", "a_b-2", "comparison-2"]
NOTE = ("note: 2 rows' file stems got a suffix, the label's stem being another row's or one of slewbench's own "
        "(file_stem in {}): 'a/b' -> a_b-2, 'comparison' -> comparison-2")


def test_a_run_says_which_rows_files_got_a_suffix(tmp_path, capsys):
    path = tmp_path / "collide.yaml"
    path.write_text(yaml.safe_dump(SCENARIO, sort_keys=False))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    assert NOTE.format("results.json and results.csv") in capsys.readouterr().out.splitlines()
    rows = json.loads((tmp_path / "out" / "results.json").read_text())["rows"]
    assert [row["file_stem"] for row in rows] == STEMS


def test_no_note_without_a_suffix(tmp_path, capsys):
    data = {**SCENARIO, "planners": [{"name": "eigenaxis", "label": "a/b"}]}  # a_b: sanitised, not suffixed
    path = tmp_path / "alone.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    assert "got a suffix" not in capsys.readouterr().out


def test_a_studys_cases_csv_records_the_file_stem_a_rerun_writes(tmp_path, capsys):
    study = {"study": "collide", "scenario": SCENARIO, "grid": {"maneuver.duration": [20.0, 22.0]},
             "execution": {"workers": 1}}
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(study, sort_keys=False))
    out = tmp_path / "sweep"
    assert main(["sweep", str(path), "--out", str(out), "--no-plots"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines.count(NOTE.format("cases.csv")) == 1, lines  # said once, not per case
    with open(out / "cases.csv", newline="") as handle:
        table = list(csv.DictReader(handle))
    assert list(table[0])[-1] == "file_stem"
    assert [line["file_stem"] for line in table] == STEMS * 2
    assert main(["sweep", str(out), "--case", "1", "--no-plots"]) == 0
    assert NOTE.format("results.json and results.csv") in capsys.readouterr().out.splitlines()
    rows = json.loads((out / "cases" / "1" / "results.json").read_text())["rows"]
    assert [row["file_stem"] for row in rows] == [line["file_stem"] for line in table if line["case"] == "1"]
    assert all((out / "cases" / "1" / "timeseries" / f"{stem}.csv").is_file() for stem in STEMS)
