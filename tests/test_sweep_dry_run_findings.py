"""``sweep --dry-run`` says what ``validate`` finds in a study's cases, line for line: a case whose
every row is late (a slew longer than ``maneuver.duration``, by the planners' ``least_duration``).

Oracle (tests/test_validate_budget.py): the reviewer's eigenaxis demo with trapezoidal and min_time
rows at 0.8 of the torque and a 35 s budget: its 180 deg case takes 42.05 s, its 30 and 90 deg cases fit.
"""
from __future__ import annotations

from scenarios.cli.commands import main
from tests.test_validate_budget import DEMO, written


def short_budget(tmp_path) -> str:
    import copy
    base = copy.deepcopy(DEMO)
    base["planners"] = base["planners"][1:]  # trapezoidal and min_time
    base["maneuver"]["duration"] = 35.0
    del base["simulation"]["duration"]
    study = {"study": "short-budget", "scenario": base,
             "grid": {"maneuver.final.q": {"axis_angle": {"axis": [1, 1, 1], "angle_deg": [30, 90, 180]}}}}
    return written(tmp_path, study, "study.yaml")


def test_the_dry_run_names_the_late_case_as_validate_does(tmp_path, capsys):
    path = short_budget(tmp_path)
    assert main(["validate", path]) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("  case ")]
    assert len(said) == 1 and said[0].startswith("  case 2 [maneuver.final.q=180"), said
    assert main(["sweep", path, "--dry-run"]) == 0  # a dry run never fails on a finding
    out = capsys.readouterr().out.splitlines()
    assert said[0] in out, out  # the same line
    assert "its slew takes 42.05" in said[0]
    heading = out[out.index(said[0]) - 1]
    assert heading.startswith("1 finding(s), as `slewbench validate` says them"), heading
    assert not (tmp_path / "results").exists()


def test_no_finding_no_line(tmp_path, capsys):
    path = short_budget(tmp_path)
    text = (tmp_path / "study.yaml").read_text().replace("duration: 35.0", "duration: 43.0")
    (tmp_path / "study.yaml").write_text(text)
    assert main(["sweep", path, "--dry-run"]) == 0
    assert "finding" not in capsys.readouterr().out
