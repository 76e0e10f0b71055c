"""``slewbench validate`` on a study or a slew-table file checks what ``sweep`` and ``table`` check
before running, and ``--strict`` exits 1 on a finding there as on a scenario's: a study case that
cannot have an ok row (named with its varied values), a table that ``table`` refuses for its size."""
from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from scenarios.cli.commands import main

BASE = {
    "name": "rate-gate",
    "spacecraft": {"inertia": [19.5, 19.0, 12.6], "wheels": {"max_torque": 0.1, "max_momentum": 4.0}},
    "maneuver": {"duration": 120.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.7071068, 0.4082483, 0.4082483, 0.4082483], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "options": {"profile": "smooth"}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.06, "kd": 0.48}},
    "simulation": {"sample_time": 0.5, "duration": 140.0},
    "requirements": {"rate": {"max": 0.1}},
}

BOX = {"name": "box", "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0}},
       "maneuver": {"duration": 10.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                    "final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
       "planners": [{"name": "collocation"}], "controller": {"name": "augmented_quaternion_feedback"}}


def write(folder: Path, name: str, data: dict) -> str:
    path = folder / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def study(folder: Path, errors: list) -> str:
    return write(folder, "study.yaml", {"study": "rate-gate", "scenario": BASE,
                                        "grid": {"simulation.initial_rate_error": errors}})


def test_a_study_case_that_cannot_pass_fails_validate_strict_naming_the_case(tmp_path, capsys):
    path = study(tmp_path, [[0.0, 0.0, 0.01], [0.0, 0.0, 0.2]])  # case 1 starts above the 0.1 rad/s bound
    assert main(["validate", path]) == 0
    out = capsys.readouterr().out
    assert "case 1 [simulation.initial_rate_error=" in out and "breaks the rate requirement" in out, out
    assert "case 0" not in out
    assert main(["validate", path, "--strict"]) == 1
    captured = capsys.readouterr()
    # case 1's two findings: the rate requirement it cannot meet, and 0.2 rad/s as an initial rate
    # error, at or above the 0.1 rad/s plausibility bar (deg/s written as rad/s?)
    assert "case 1 [" in captured.out and "--strict: 2 finding(s) above" in captured.err, captured
    assert "warning: simulation.initial_rate_error" in captured.out, captured


def test_a_study_whose_cases_may_pass_exits_0_under_strict(tmp_path, capsys):
    assert main(["validate", study(tmp_path, [[0.0, 0.0, 0.01], [0.0, 0.02, 0.0]]), "--strict"]) == 0
    assert "case " not in capsys.readouterr().out


def test_a_bad_study_case_exits_2_naming_the_case_and_path(tmp_path, capsys):
    path = study(tmp_path, [[0.0, 0.0, 0.01], [0.0, 0.0]])
    assert main(["validate", path, "--strict"]) == 2
    err = capsys.readouterr().err
    assert "error in study file" in err and "case 1" in err and "simulation.initial_rate_error" in err, err


def table(folder: Path, axes: int) -> str:
    write(folder, "box.yaml", BOX)
    return write(folder, "table.yaml", {"table": {"scenario": "box.yaml", "axes": axes, "grid": "fibonacci",
                                                  "angles_deg": list(range(5, 181, 5))}})


def test_a_table_that_table_refuses_for_its_size_fails_validate_strict(tmp_path, capsys):
    path = table(tmp_path, 100)  # 100 axes x 36 angles = 3600 entries, over table's default 2000
    assert main(["validate", path]) == 0
    assert "--max-entries" in capsys.readouterr().out
    assert main(["validate", path, "--strict"]) == 1
    captured = capsys.readouterr()
    assert "3600 entries, more than 2000" in captured.out and "--strict: 1 finding(s)" in captured.err, captured
    assert main(["table", path, "--out", str(tmp_path / "out")]) == 2  # what validate foretold
    assert "--max-entries" in capsys.readouterr().err


@pytest.mark.parametrize("strict", [[], ["--strict"]])
def test_a_table_within_the_limit_validates(tmp_path, capsys, strict):
    assert main(["validate", table(tmp_path, 10), *strict]) == 0
    assert "--max-entries" not in capsys.readouterr().out
