"""``validate`` predicts a slew longer than ``maneuver.duration`` (every planner's time budget) for
planners that say their duration cheaply (``Planner.least_duration``: eigenaxis ``min_time`` and
``trapezoidal``, closed forms), for a scenario and for each case of a study; a table file
``table`` would refuse is not called valid nor given a command that fails; the help says
``infeasible`` where rows are.

Oracles by hand: the bang-bang triangle of a 90 deg slew of a 10 kg m^2 sphere on 0.0144 N m wheels
takes 2 sqrt(theta I / tau) = 66.05545 s (tests/test_verdict_rules.py); the reviewer's eigenaxis_demo
min_time at torque_fraction 0.8 takes 29.73596 s (run: infeasible at 29.7 s, ok at 29.736 s).
"""
from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest
import yaml

import scenarios
from planners import PLANNERS
from planners.base import Planner
from scenarios.cli.commands import _doomed_notes, build_parser, main
from tests.test_verdict_rules import FASTEST, slew

ROOT = Path(__file__).resolve().parents[1]
DEMO = yaml.safe_load((ROOT / "scenarios" / "eigenaxis_demo.yaml").read_text())


def written(tmp_path: Path, data: dict, name: str = "case.yaml") -> str:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def test_the_capability_defaults_to_unknown_and_eigenaxis_says_its_bang_profiles_duration():
    problem = scenarios.parse_scenario(slew(60.0)).problem
    assert Planner.least_duration(PLANNERS["eigenaxis"]({"profile": "smooth"}), problem) is None  # the default
    assert PLANNERS["eigenaxis"]({"profile": "smooth"}).least_duration(problem) is None  # planned over T
    for profile in ("min_time", "trapezoidal"):
        least = PLANNERS["eigenaxis"]({"profile": profile}).least_duration(problem)
        assert least is not None and math.isclose(least, FASTEST, rel_tol=1e-9), (profile, least)


@pytest.mark.parametrize("profile", ["min_time", "trapezoidal"])
def test_validate_strict_says_a_bang_slew_longer_than_the_budget_is_infeasible(tmp_path, capsys, profile):
    scenario = scenarios.parse_scenario(slew(60.0, profile))
    assert _doomed_notes(scenario) == [
        f"every planner's row is infeasible before planning: its slew takes {FASTEST:.7g} s, longer than the 60 s "
        "bound (maneuver.duration, the manoeuvre's time budget for every planner): the planner found no slew within "
        "it under its bounds; a maneuver.duration of at least 66.1 s admits this one"]
    assert scenarios.run(scenario).rows[0].status == "infeasible"  # the run agrees
    path = written(tmp_path, slew(60.0, profile))
    assert main(["validate", path, "--strict"]) == 1
    assert "no row can be ok" in capsys.readouterr().err
    assert _doomed_notes(scenarios.parse_scenario(slew(66.1, profile))) == []  # the advice admits it
    assert main(["validate", written(tmp_path, slew(66.1, profile)), "--strict"]) == 0


def test_the_reviewers_eigenaxis_min_time_at_29_7_s_fails_validate_strict(tmp_path, capsys):
    data = copy.deepcopy(DEMO)
    data["planners"] = [data["planners"][2]]  # min-time, torque_fraction 0.8
    data["maneuver"]["duration"] = 29.7
    assert main(["validate", written(tmp_path, data), "--strict"]) == 1
    assert "its slew takes 29.73596 s, longer than the 29.7 s bound" in capsys.readouterr().out
    data["maneuver"]["duration"] = 29.736
    assert main(["validate", written(tmp_path, data), "--strict"]) == 0


def test_a_row_of_several_late_is_said_but_no_strict_finding(tmp_path, capsys):
    data = copy.deepcopy(DEMO)
    data["maneuver"]["duration"] = 29.7  # smooth plans over T (its quintic may be ok); the bang rows are late
    data["simulation"]["duration"] = 40.0
    assert main(["validate", written(tmp_path, data), "--strict"]) == 0
    out = capsys.readouterr().out
    assert "  the rows of bang-coast-bang, min-time are infeasible before planning: its slew takes 29.73596 s" in out


def test_a_study_names_each_case_whose_rows_are_all_late(tmp_path, capsys):
    base = copy.deepcopy(DEMO)
    base["planners"] = base["planners"][1:]  # trapezoidal and min_time
    base["maneuver"]["duration"] = 35.0
    del base["simulation"]["duration"]
    study = {"study": "short-budget", "scenario": base,
             "grid": {"maneuver.final.q": {"axis_angle": {"axis": [1, 1, 1], "angle_deg": [30, 90, 180]}}}}
    assert main(["validate", written(tmp_path, study, "study.yaml"), "--strict"]) == 1
    captured = capsys.readouterr()
    cases = [line for line in captured.out.splitlines() if line.startswith("  case ")]
    assert len(cases) == 1 and cases[0].startswith("  case 2 [maneuver.final.q=180"), captured.out
    assert "every planner's row is infeasible before planning: its slew takes 42.05" in cases[0]
    assert "--strict: 1 finding(s) above" in captured.err


def test_a_table_that_table_refuses_is_not_called_valid_nor_given_a_refused_command(tmp_path, capsys):
    from tests.test_validate_files import table
    path = table(tmp_path, 100)  # 3600 entries, over table's default 2000
    assert main(["validate", path]) == 0
    summary = capsys.readouterr().out.splitlines()[0]
    assert "valid" not in summary and f"run it with `slewbench table {path}`" not in summary, summary
    assert summary.endswith(f"confirm the work with `slewbench table {path} --max-entries 3600`"), summary
    assert main(["validate", table(tmp_path, 10)]) == 0  # within the limit: valid, and the command that runs it
    summary = capsys.readouterr().out.splitlines()[0]
    assert ": valid slew table " in summary and summary.endswith(f"run it with `slewbench table {path}`"), summary


def test_the_strict_help_names_infeasible_rows():
    commands = next(action for action in build_parser()._actions if action.dest == "command")
    helps = {name: next(a.help for a in parser._actions if a.dest == "strict")
             for name, parser in commands.choices.items() if name in ("run", "validate")}
    assert "infeasible" in helps["run"] and "violated" in helps["run"] and "failed" in helps["run"], helps
    assert "infeasible" in helps["validate"] and "must fail" not in helps["validate"], helps


def test_the_conformance_check_refuses_a_least_duration_above_what_the_planner_plans():
    """``least_duration`` is an extension point: a planner's least duration above its own plan
    would make validate doom a row the run makes ok. The check runs over every registered planner
    (tests/test_planner_conformance.py); here it refuses one that overstates and passes eigenaxis."""
    from planners.conformance import CHECKS
    from planners.errors import ConformanceError

    problem = scenarios.parse_scenario(slew(70.0)).problem  # both bang profiles plannable (66.06 s)
    for profile in ("min_time", "trapezoidal"):
        planner = PLANNERS["eigenaxis"]({"profile": profile})
        assert planner.plan(problem).ok
        CHECKS["least_duration"](problem, planner.plan(problem), planner)

    class Overstating(PLANNERS["eigenaxis"]):  # type: ignore[misc, valid-type]
        def least_duration(self, problem):
            return 1.01 * self.plan(problem).duration

    planner = Overstating({"profile": "min_time"})
    with pytest.raises(ConformanceError, match="least_duration says .* above the .* it plans"):
        CHECKS["least_duration"](problem, planner.plan(problem), planner)
