"""A study case that one listed planner cannot take (``spin_extremal`` given a fixed final rate)
gives that planner a failed row naming its reason, and the other planners' rows are computed; a
planner that no case suits is refused as ``run`` refuses it (exit 2), and ``run`` still refuses a
scenario whose listed planner cannot take it."""
from __future__ import annotations

import csv
from pathlib import Path

import yaml

from scenarios.cli.commands import main
from scenarios.study.spec import load_study

REASON = "cannot meet a fixed final rate"  # spin_extremal's problem_error
BASE = {
    "name": "spin-final-rate",
    "spacecraft": {"inertia": [19.5, 19.0, 12.6], "wheels": "none", "torquers": {"max_torque": 0.1}},
    "maneuver": {"duration": 200.0, "initial": {"q": [1, 0, 0, 0], "omega": [0.2, 0, 0]},
                 "final": {"q": [0, 0, 1, 0], "omega": None}},
    "planners": [{"name": "spin_extremal", "label": "k=0", "options": {"weight": 0.0}},
                 {"name": "eigenaxis", "label": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.025, "kd": 0.16}},
    "simulation": {"sample_time": 1.0},
}


def study(folder: Path, final_rates: list) -> str:
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "spin-final-rate", "scenario": BASE,
                                    "grid": {"maneuver.final.omega": final_rates}}, sort_keys=False))
    return str(path)


def test_the_cases_a_planner_cannot_take_are_its_failed_rows_and_the_rest_run(tmp_path, capsys):
    path = study(tmp_path, [None, [0, 0, 0]])
    assert len(load_study(path).cases) == 2  # checked without refusing the study
    assert main(["validate", path, "--strict"]) == 0
    out = tmp_path / "out"
    assert main(["sweep", path, "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    with open(out / "cases.csv", newline="") as handle:
        rows = {(row["case"], row["label"]): row for row in csv.DictReader(handle)}
    assert len(rows) == 4
    refused = rows[("1", "k=0")]
    assert refused["status"] == "failed", refused
    assert refused["message"].startswith("not applicable: spin_extremal cannot take this case") and \
        REASON in refused["message"], refused["message"]
    assert rows[("0", "k=0")]["status"] == "ok", rows[("0", "k=0")]["message"]  # a free final rate: planned
    assert {rows[(case, "eigenaxis")]["status"] for case in ("0", "1")} == {"ok"}


def test_a_planner_no_case_suits_refuses_the_study_naming_it(tmp_path, capsys):
    path = study(tmp_path, [[0, 0, 0], [0, 0, 0.01]])
    assert main(["validate", path]) == 2
    err = capsys.readouterr().err
    assert "scenario: planners[0]" in err and "cannot take any of the study's 2 case(s)" in err and REASON in err, err
    assert main(["sweep", path, "--out", str(tmp_path / "out")]) == 2
    assert not (tmp_path / "out").exists()


def test_run_still_refuses_a_scenario_its_planner_cannot_take(tmp_path, capsys):
    scenario = dict(BASE, maneuver=dict(BASE["maneuver"], final={"q": [0, 0, 1, 0], "omega": [0, 0, 0]}))
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(scenario, sort_keys=False))
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "planners[0]" in err and REASON in err, err


def test_validate_strict_fails_a_case_that_no_listed_planner_can_take(tmp_path, capsys):
    """A reviewer: with ``spin_extremal`` alone, case 1 fails all its rows, yet ``validate --strict``
    passed the study."""
    alone = dict(BASE, planners=[BASE["planners"][0]])
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "spin-final-rate", "scenario": alone,
                                    "grid": {"maneuver.final.omega": [None, [0, 0, 0]]}}, sort_keys=False))
    assert main(["validate", str(path)]) == 0
    capsys.readouterr()
    assert main(["validate", str(path), "--strict"]) == 1
    said = capsys.readouterr()
    text = said.out + said.err
    assert "case 1" in text and "none can take it" in text and REASON in text, text
    assert "case 0" not in text.split("none can take it")[0].splitlines()[-1], text
