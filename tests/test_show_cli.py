"""The command line that explains itself (issue 31, item 5): ``--version``, ``list --options``,
``validate`` of study files, the compact terminal table and the files a run removes.

Oracles: the package metadata (or pyproject.toml for a checkout), the Options dataclasses'
``Annotated[..., Range(...)]`` declarations read with ``typing``, case counts worked by hand from the
shipped study files, rows whose missing metrics are chosen by hand, and the directory's listing.
"""
from __future__ import annotations

import dataclasses
import importlib.metadata
import math
import re
import sys
import typing
from pathlib import Path

import pytest
import yaml

import scenarios
from ocp.options import Range
from planners import PLANNERS
from scenarios.cli.commands import main
from scenarios.output import provenance
from scenarios.output.results import Row, RunResults
from scenarios.schema.columns import SCOPES, SCORED_METRICS, VECTOR_METRICS

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "scenarios" / "eigenaxis_demo.yaml"
STUDY_CASES = {"study_planners_vs_slew_angle.yaml": 7,  # seven angle_deg values of one axis_angle grid entry
               "study_spin_monte_carlo.yaml": 1000,  # one point, monte_carlo.samples: 1000
               "study_spin_weight_sample_time.yaml": 20,  # 5 weights x 4 sample times
               "study_truth_inertia_monte_carlo.yaml": 40}  # one point, monte_carlo.samples: 40
"""Cases of each shipped study, counted by hand from its file."""


def source_version() -> str:
    try:
        return importlib.metadata.version("slewbench")
    except importlib.metadata.PackageNotFoundError:
        text = (ROOT / "pyproject.toml").read_text()
        return re.search(r'^version\s*=\s*"([^"]+)"', text, re.MULTILINE).group(1)


# --- --version ------------------------------------------------------------------------------------------

def test_version_is_the_package_metadata(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--version"])
    assert stop.value.code == 0
    assert capsys.readouterr().out.strip() == f"slewbench {source_version()}"


def test_version_prefers_the_installed_metadata_and_falls_back_to_the_source(monkeypatch, capsys):
    monkeypatch.setattr(provenance, "version", lambda name: {"slewbench": "9.8.7"}[name])
    with pytest.raises(SystemExit):
        main(["--version"])
    assert capsys.readouterr().out.strip() == "slewbench 9.8.7"

    def missing(name):
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(provenance, "version", missing)
    text = (ROOT / "pyproject.toml").read_text()
    assert provenance.package_version() == re.search(r'^version\s*=\s*"([^"]+)"', text, re.MULTILINE).group(1)


# --- list --options -------------------------------------------------------------------------------------

def declared(options: type, name: str) -> tuple[Range, typing.Any]:
    """The Range and default an Options dataclass declares for a field."""
    hints = typing.get_type_hints(options, include_extras=True)
    (bounds,) = [item for item in typing.get_args(hints[name])[1:] if isinstance(item, Range)]
    (field,) = [field for field in dataclasses.fields(options) if field.name == name]
    return bounds, field.default


def test_list_options_of_collocation_gives_each_option_with_its_range(capsys):
    assert main(["list", "--options", "collocation"]) == 0
    out = capsys.readouterr().out
    lines = {line.split()[0]: line for line in out.splitlines()[2:] if line.startswith("  ")}
    options = PLANNERS["collocation"].Options
    assert set(lines) == {field.name for field in dataclasses.fields(options)}
    bounds, default = declared(options, "intervals")
    line = lines["intervals"].split()
    assert line[1] == "integer" and line[2] == "-" and line[3] == str(default)
    assert f">= {bounds.ge:g} and <= {bounds.le:g}" in lines["intervals"]
    bounds, default = declared(options, "cone_margin_deg")
    assert lines["cone_margin_deg"].split()[2] == "deg" and f"< {bounds.lt:g}" in lines["cone_margin_deg"]
    assert out.splitlines()[0].startswith("collocation (planner): ")
    assert "slewbench schema planners.collocation" in out


def test_list_options_of_a_controller_and_of_an_unknown_name(capsys):
    assert main(["list", "--options", "eigenaxis_pd"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("eigenaxis_pd (controller): ") and "\n  kp " in out
    assert main(["list", "--options", "colocation"]) == 2
    error = capsys.readouterr().err
    assert "'colocation' is neither a registered planner nor controller" in error and "collocation" in error


def test_list_names_the_options_flag(capsys):
    assert main(["list"]) == 0
    assert "list --options NAME" in capsys.readouterr().out


# --- validate ------------------------------------------------------------------------------------------

def test_every_shipped_study_is_counted_by_hand():
    assert {path.name for path in (ROOT / "scenarios").glob("study_*.yaml")} == set(STUDY_CASES)


@pytest.mark.parametrize("name", sorted(STUDY_CASES))
def test_validate_a_shipped_study_prints_its_case_count(name, capsys, monkeypatch):
    monkeypatch.chdir(ROOT)
    assert main(["validate", f"scenarios/{name}"]) == 0
    out = capsys.readouterr().out
    study = yaml.safe_load((ROOT / "scenarios" / name).read_text())["study"]
    assert out.startswith(f"scenarios/{name}: valid study {study!r}: {STUDY_CASES[name]} cases (")
    assert f"slewbench sweep scenarios/{name}" in out


def test_validate_a_broken_study_exits_2_naming_the_path(tmp_path, capsys):
    data = yaml.safe_load((ROOT / "scenarios" / "study_spin_weight_sample_time.yaml").read_text())
    data["grid"]["simulation.sample_time"] = [0.5, "fast"]
    path = tmp_path / "broken.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and str(path) in captured.err and "simulation.sample_time" in captured.err
    assert "'fast'" in captured.err


def test_validate_a_scenario_names_its_rows(capsys):
    assert main(["validate", str(DEMO)]) == 0
    out = capsys.readouterr().out
    assert "valid scenario 'eigenaxis-demo'" in out and "3 row(s) (smooth, bang-coast-bang, min-time)" in out


def test_run_refuses_a_study_or_table_file_and_names_the_command(tmp_path, capsys, monkeypatch):
    """Read as a scenario, a study said ``name: required key is missing``."""
    monkeypatch.chdir(ROOT)
    out = tmp_path / "out"
    assert main(["run", "scenarios/study_spin_weight_sample_time.yaml", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "is a study file, not a scenario" in err and "slewbench sweep scenarios/study_spin_weight_sample_time.yaml" in err
    table = tmp_path / "table.yaml"
    table.write_text(yaml.safe_dump({"table": {"scenario": str(DEMO), "axes": 6, "angles_deg": [30, 90]}}))
    assert main(["run", str(table), "--out", str(out)]) == 2
    assert f"slewbench table {table}" in capsys.readouterr().err
    assert not out.exists()
    assert main(["validate", str(table)]) == 0
    assert "valid slew table 'eigenaxis-demo': " in capsys.readouterr().out


@pytest.mark.parametrize("argv, expected", [
    (["table", "t.yaml", "--angles", "-10,90"], ["table", "t.yaml", "--angles=-10,90"]),
    (["sweep", "s.yaml", "--case", "-1"], ["sweep", "s.yaml", "--case=-1"]),
    (["run", "--no-plots", "-1"], ["run", "--no-plots", "-1"]),  # a flag takes no value: -1 is the file
    (["run", "--strict", "-2.5,3"], ["run", "--strict", "-2.5,3"]),
    (["table", "t.yaml", "--angles", "-10", "--", "--out", "-3"], ["table", "t.yaml", "--angles=-10", "--", "--out", "-3"]),
    (["export", "d", "--option", "x=-5"], ["export", "d", "--option", "x=-5"]),  # not a number list
])
def test_only_an_option_that_takes_a_value_gets_a_negative_value_attached(argv, expected):
    from scenarios.cli.commands import build_parser
    from scenarios.cli.status import attached_values
    assert attached_values(argv, build_parser()) == expected


def test_a_study_without_its_study_key_is_named_as_such_not_as_a_scenario_missing_name(tmp_path, capsys):
    # read as a scenario it said only "name: required key is missing", without the file
    lost = tmp_path / "lost.yaml"
    lost.write_text(yaml.safe_dump({"scenario": str(DEMO), "grid": {"simulation.sample_time": [0.5, 1.0]}}))
    for argv in (["run", str(lost), "--out", str(tmp_path / "out")], ["validate", str(lost)]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert f"{lost} reads as a study file without its `study: NAME` key" in err and "slewbench sweep" in err, err
        assert "name: required key is missing" not in err
    assert main(["sweep", str(lost), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.startswith(f"slewbench: error in study file: {lost}: study: required key")
    assert not (tmp_path / "out").exists()


# --- the compact table ------------------------------------------------------------------------------

def none_metrics() -> dict:
    return {key: ([None] * 3 if key in VECTOR_METRICS else None) for key in SCORED_METRICS}


def test_the_compact_table_hides_exactly_the_lines_without_a_value():
    scenario = scenarios.load(DEMO)
    first_ref, first_cl, second_ref, second_cl = none_metrics(), none_metrics(), none_metrics(), none_metrics()
    first_ref["int_u"] = 1.0
    second_ref["int_u"] = math.nan  # missing too
    second_ref["energy_ratio"] = 2.0
    first_cl["final_error_deg"] = 0.5
    second_cl["int_abs_u"] = [0.1, None, None]  # one component: the line applies
    second_cl["final_rate"] = math.inf  # non-finite: missing
    rows = [Row("one", "eigenaxis", "ok", "", 0.1, first_ref, first_cl, controller="pd"),
            Row("two", "eigenaxis", "violated", "why", None, second_ref, second_cl, controller="pd",
                requirements={"reference": {"cone": {"min_margin_deg": None}},
                              "closed_loop": {"cone": {"min_margin_deg": None}}})]
    results = RunResults(scenario, rows)
    full, compact = results.to_terminal(all_metrics=True), results.to_terminal()
    everything = ["status", "plan_time_s", "needed_duration_s", "certificate"] + [f"{prefix}.{key}" for _, prefix in SCOPES for key in SCORED_METRICS]
    shown = {"status", "plan_time_s", "ref.int_u", "ref.energy_ratio", "cl.final_error_deg", "cl.int_abs_u"}

    def names(text):
        return [line.split()[0] for line in text.splitlines()[2:] if line and not line.startswith(("(", " "))]

    assert names(full)[:len(everything)] == everything and "req.cone" in names(full)
    assert set(names(compact)) - {"one:", "two:", "rows:"} == shown
    hidden = len(everything) + 1 - len(shown)  # every metric line and the requirement's, less those shown
    assert f"({hidden} metrics with no value in any row not shown; --all-metrics shows them)" in compact
    assert "not shown" not in full


def test_run_prints_the_compact_table_unless_all_metrics(tmp_path, capsys):
    assert main(["run", str(DEMO), "--out", str(tmp_path / "a"), "--no-plots"]) == 0
    compact = capsys.readouterr().out
    assert main(["run", str(DEMO), "--out", str(tmp_path / "b"), "--no-plots", "--all-metrics"]) == 0
    full = capsys.readouterr().out
    assert "ref.int_dipole" in full and "ref.int_dipole" not in compact  # no magnetorquers: never a value
    assert "cl.final_error_deg" in compact and "--all-metrics shows them" in compact


# --- removed files ------------------------------------------------------------------------------------

def test_a_run_names_the_files_it_removed(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(DEMO), "--out", str(out)]) == 0
    pictures = sorted(path.name for path in [*out.glob("*.png"), out / "report.html"])
    assert len(pictures) == 5  # one PNG per row, the comparison and the interactive report
    capsys.readouterr()
    assert main(["run", str(DEMO), "--out", str(out), "--no-plots"]) == 0
    said = [line for line in capsys.readouterr().out.splitlines() if line.startswith("removed")]
    assert said == [f"removed {len(pictures)} file(s) of the earlier run in {out}/ that this run did not write: "
                    + ", ".join(pictures)]
    assert not list(out.glob("*.png")) and not (out / "report.html").exists()
    assert main(["run", str(DEMO), "--out", str(out), "--no-plots"]) == 0
    assert "removed" not in capsys.readouterr().out  # nothing removed, nothing said


def test_console_script_version(tmp_path):
    import subprocess
    completed = subprocess.run([sys.executable, "-m", "scenarios.console", "--version"], capture_output=True,
                               text=True, timeout=120, cwd=ROOT)
    assert completed.returncode == 0 and completed.stdout.strip() == f"slewbench {source_version()}"


def test_validate_a_scenario_says_what_every_row_is_scored_against(tmp_path, capsys):
    """The requirements in words (the margin 0.25 is 75 % of each limit; the window, the final bounds),
    the truth model's keys and the sensors: a user sees what a run will hold each row to."""
    data = yaml.safe_load(DEMO.read_text())
    data["spacecraft"]["sensors"] = {"camera": {"boresight": [0, 0, 1]}}
    data["requirements"] = {
        "pointing": {"cam_sun": {"sensor": "camera", "keep_out": {"inertial": [0, 1, 0]}, "angle_deg": 20, "window": [5, 40]},
                     "cam_in": {"sensor": "camera", "keep_in": {"inertial": [0, 0, 1]}, "angle_deg": 170}},
        "actuators": {"margin": 0.25}, "rate": {"max": 0.3},
        "final": {"after_s": 4, "error_deg": 0.5, "rate": 0.002}}
    data["truth"] = {"spacecraft": {"inertia": [1.1, 1.2, 1.3]}}
    data["simulation"].pop("sensor_noise", None)  # the declared sensors give the noise
    data["simulation"]["sensors"] = {"gyro": {"arw_deg_per_sqrt_h": 0.01},
                                     "star_tracker": {"noise_arcsec": [5, 5, 40], "outages_s": [[10, 12.5]],
                                                      "exclusion_deg": {"sun": 30, "moon": 12.5}}}
    data["epoch"] = "2027-03-20T12:00:00Z"  # the Sun's and the Moon's directions
    data["simulation"]["estimator"] = {"type": "mekf", "initial_attitude_sigma_deg": 0.1,
                                       "initial_bias_sigma_deg_per_h": 5.0}
    path = tmp_path / "scored.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))  # the requirements in the order written
    assert main(["validate", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()[1:]
    assert lines == [
        "  requirement cam_sun: camera keep-out 20 deg about inertial [0, 1, 0] from 5 s to 40 s",
        "  requirement cam_in: camera keep-in 170 deg about inertial [0, 0, 1]",
        "  requirement actuators: the reference's demand at most 75 % of each actuator limit",
        "  requirement rate: ‖ω‖ at most 0.3 rad/s (reference and closed loop)",
        ("  requirement final: error to the target at most 0.5 deg, ‖ω − ω_f‖ at most 0.002 rad/s in the closed "
         "loop from T + 4 s to the end of the run"),
        "  truth (the closed loop's plant differs from the design in): truth.spacecraft.inertia",
        ("  sensors: gyro, star tracker (outages 10-12.5 s; blinded within 30 deg of the sun, 12.5 deg of the "
         "moon); estimator: MEKF")]


def test_validate_without_requirements_says_the_actuator_limits_alone_are_scored(tmp_path, capsys):
    assert main(["validate", str(DEMO)]) == 0
    assert capsys.readouterr().out.splitlines()[1:] == [
        ("  requirement actuators: the reference's demand at most 100 % of each actuator limit (every scenario's, "
         "unstated)"), ("  sensor noise (simulation.sensor_noise, 1 sigma per axis): attitude 0.005 deg, rate 1e-05 rad/s, "
                     "seed 1")]
    data = yaml.safe_load(DEMO.read_text())
    del data["simulation"]["sensor_noise"]
    data["requirements"] = None  # not even the actuators' limits
    path = tmp_path / "unscored.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 0
    assert capsys.readouterr().out.splitlines()[1:] == ["  requirements: none (requirements: null)"]
    data["requirements"] = {"actuators": None, "rate": {"max": 0.02}}  # the actuators off, the rate scored
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 0
    assert capsys.readouterr().out.splitlines()[1:] == [
        "  requirement rate: ‖ω‖ at most 0.02 rad/s (reference and closed loop)",
        "  requirement actuators: off (requirements.actuators: null)"]


def test_validate_says_when_the_end_points_already_break_a_requirement(tmp_path, capsys):
    """``run`` makes every row infeasible before planning when the initial or target attitude breaks a
    pointing requirement; validate says so at once (the demo starts at identity: body z on inertial z)."""
    data = yaml.safe_load(DEMO.read_text())
    data["spacecraft"]["sensors"] = {"camera": {"boresight": [0, 0, 1]}}
    data["requirements"] = {"pointing": {"cam": {"sensor": "camera", "keep_out": {"inertial": [0, 0, 1]},
                                                 "angle_deg": 20}}}
    path = tmp_path / "broken_ends.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 0
    broken = [line for line in capsys.readouterr().out.splitlines()
              if "every planner's row is infeasible before planning" in line]
    assert len(broken) == 1 and "cam" in broken[0] and "initial attitude already breaks it" in broken[0]


def test_validate_says_when_a_boundary_rate_breaks_the_rate_requirement(tmp_path, capsys):
    data = yaml.safe_load(DEMO.read_text())
    data["maneuver"]["initial"]["omega"] = [0.03, 0.04, 0.0]  # 0.05 rad/s
    data["requirements"] = {"rate": {"max": 0.01}}
    path = tmp_path / "spinning.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 0
    assert ("  every row breaks the rate requirement: maneuver.initial.omega has ‖ω‖ = 0.05 rad/s, above 0.01 rad/s"
            in capsys.readouterr().out.splitlines())
