"""``sweep --dry-run`` and ``validate`` on a study: each case is parsed by the scenario loader at
most once, a planner's ``least_duration`` (it plans the slew) runs once for the cases that differ
only in ``INDEPENDENT_KEYS``, and the findings are those of each case parsed and judged on its own.

Oracles: counts by hand (one base scenario, N cases, P planners that say their duration); and a
second method for the findings, ``_strict_findings(parse_scenario(case))`` case by case, on a study
whose findings differ by grid point (a 180 deg slew too long for its 35 s budget) and by the
independent keys (a rate noise of 0.2 rad/s, an initial rate error that breaks the rate requirement).
A bad value of an independent key in one case still stops the dry run (exit 2, naming the case).
"""
from __future__ import annotations

import copy
import re
import warnings

import pytest

import scenarios.cli.commands as commands
import scenarios.study.spec as spec
from planners import PLANNERS
from scenarios.cli.commands import StudyFindings, _strict_findings, main, study_findings
from scenarios.schema.loader import parse_scenario
from scenarios.study.spec import load_study
from tests.test_validate_budget import DEMO, written

NOISE = [1.0e-5, 0.2]  # rad/s; 0.2 is at or above the plausibility bar of 0.1 rad/s
RATE_ERRORS = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]]  # rad/s; 0.5 breaks requirements.rate.max 0.3 from rest


def base() -> dict:
    data = copy.deepcopy(DEMO)
    data["planners"] = data["planners"][1:]  # trapezoidal and min_time: both say their duration
    data["maneuver"]["duration"] = 35.0
    del data["simulation"]["duration"]
    data["requirements"] = {"rate": {"max": 0.3}}
    return data


def mixed(tmp_path) -> str:
    """3 slew angles x 2 rate noises x 2 initial rate errors = 12 cases, findings in each part."""
    return written(tmp_path, {"study": "mixed", "scenario": base(),
                              "grid": {"maneuver.final.q": {"axis_angle": {"axis": [1, 1, 1], "angle_deg": [30, 90, 180]}},
                                       "simulation.sensor_noise.rate": NOISE,
                                       "simulation.initial_rate_error": RATE_ERRORS}}, "mixed.yaml")


@pytest.fixture
def parses(monkeypatch):
    """How many times the scenario loader parsed a scenario (the study's check and the findings)."""
    count = {"n": 0}

    def counted(*args, **kwargs):
        count["n"] += 1
        return parse_scenario(*args, **kwargs)

    monkeypatch.setattr(spec, "parse_scenario", counted)
    monkeypatch.setattr(commands, "parse_scenario", counted)
    return count


@pytest.fixture
def plans(monkeypatch):
    """How many times the eigenaxis planner said its least duration."""
    count = {"n": 0}
    planner = PLANNERS["eigenaxis"]
    original = planner.least_duration

    def counted(self, problem):
        count["n"] += 1
        return original(self, problem)

    monkeypatch.setattr(planner, "least_duration", counted)
    return count


def test_the_findings_are_each_case_judged_on_its_own(tmp_path):
    study = load_study(mixed(tmp_path))
    assert len(study.cases) == 12
    expected = []
    for case in study.cases:  # the second method: each case parsed and judged by itself
        values = ", ".join(f"{path}={value}" for path, value in case.varied.items())
        with warnings.catch_warnings():  # the loader's PlausibilityWarning, called from here
            warnings.simplefilter("ignore")
            scenario = parse_scenario(case.scenario, inapplicable_rows=True)
        expected += [f"case {case.index} [{values}]: {line}" for line in _strict_findings(scenario)]
    found = StudyFindings()
    assert study_findings(load_study(mixed(tmp_path), parsed=found), found) == expected
    assert study_findings(study) == expected  # without the check's parses
    # every part is there: the late 180 deg grid point (4 cases), the noise (6), the rate error (6:
    # the rate requirement's finding and the plausibility warning of a 0.5 rad/s error, each)
    said = [line.split("]: ", 1)[1] for line in expected]
    assert sum("infeasible before planning" in line for line in said) == 4
    assert sum(line.startswith("warning: simulation.sensor_noise.rate") for line in said) == 6
    assert sum(line.startswith("every row's closed loop breaks the rate requirement: simulation.initial_rate_error")
               for line in said) == 6
    assert sum(line.startswith("warning: simulation.initial_rate_error") for line in said) == 6


def test_a_dry_run_parses_each_case_once(tmp_path, parses, plans, capsys):
    # a grid over the slew angle: the check parses each of the 3 cases (and the base); before, the
    # findings parsed each again (7 parses)
    path = written(tmp_path, {"study": "angles", "scenario": base(),
                              "grid": {"maneuver.final.q": {"axis_angle": {"axis": [1, 1, 1],
                                                                           "angle_deg": [30, 90, 180]}}}})
    assert main(["sweep", path, "--dry-run"]) == 0
    assert parses["n"] == 1 + 3
    assert plans["n"] == 3 * 2  # 2 planners that say their duration, per case
    assert "1 finding(s), as `slewbench validate` says them" in capsys.readouterr().out


def test_the_planning_is_shared_by_cases_that_differ_in_independent_keys(tmp_path, parses, plans, capsys):
    # 40 Monte Carlo samples of the noise's seed: one class of cases for the check (one parse), the
    # findings parse the other 39; before, every case planned its 2 slews (80 plans)
    path = written(tmp_path, {"study": "seeds", "scenario": base(), "monte_carlo": {
        "samples": 40, "seed": 1, "dispersions": {"simulation.sensor_noise.seed": "case_seed"}}})
    assert main(["validate", path]) == 0
    assert parses["n"] == 1 + 40
    assert plans["n"] == 2
    assert "valid study 'seeds': 40 cases" in capsys.readouterr().out


def test_a_bad_independent_value_in_one_case_still_stops_the_dry_run(tmp_path, capsys):
    path = written(tmp_path, {"study": "bad", "scenario": base(),
                              "grid": {"simulation.sensor_noise.rate": [1.0e-5, -1.0e-5, 2.0e-5]}})
    assert main(["sweep", path, "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert "case 1 [" in err and "simulation.sensor_noise.rate" in err, err
    assert not (tmp_path / "results").exists()


def test_a_long_dry_run_says_how_far_its_findings_are_off_a_terminal(tmp_path, monkeypatch, capsys):
    """After ``N cases checked``, the findings of a 100,000-case dry run took 100 s without a word:
    now they are said as the check is (here from the first call on: the line's delays set to 0)."""
    import scenarios.cli.sweep as command
    import scenarios.study.engine as engine

    monkeypatch.setattr(command, "CHECKING_LINE_S", 0.0)
    monkeypatch.setattr(engine, "PROGRESS_LINE_S", 0.0)
    monkeypatch.setattr(commands, "FINDINGS_PROGRESS_EVERY", 4, raising=False)
    path = written(tmp_path, {"study": "seeds", "scenario": base(), "monte_carlo": {
        "samples": 10, "seed": 1, "dispersions": {"simulation.sensor_noise.seed": "case_seed"}}}, "seeds.yaml")
    assert main(["sweep", path, "--dry-run"]) == 0
    lines = [line for line in capsys.readouterr().err.splitlines() if "judg" in line]
    assert [re.sub(r"(, [0-9.]+ s elapsed| in [0-9.]+ s)$", "", line) for line in lines] == [
        "seeds: judging 10 cases, 4 judged", "seeds: judging 10 cases, 8 judged", "seeds: 10 cases judged"], lines
