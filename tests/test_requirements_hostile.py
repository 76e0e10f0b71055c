"""A hostile new user's input and the defects a review of the requirements found.

Bad input through the command line (exit 2, the message naming the YAML path, the value and what
was expected, never a traceback) for the cases the schema tests do not already hold; and one test
per defect found in review, each failing before its fix.
"""
from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.requirements.scoring import endpoint_violations
from scenarios.schema.loader import parse_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "cubesat_12u_sun_keep_out.yaml"


def base() -> dict:
    """The 12U CubeSat Sun keep-out scenario as data (the epoch as text, as a user writes it)."""
    data = yaml.safe_load(SCENARIO.read_text())
    data["epoch"] = "2027-03-20T12:00:00Z"
    return data


def limb_scenario() -> dict:
    """The 12U case with a 10 deg keep-out about the Earth's limb. The orbit (RAAN 90 deg, argument
    of latitude 0) starts on the inertial y axis, so nadir is -y; the star tracker's boresight
    [0.5, -0.866, 0] at the initial attitude (identity) lies 30 deg from it."""
    data = base()
    data["requirements"]["pointing"] = {"st_earth": {"sensor": "star_tracker", "keep_out": "earth_limb",
                                                     "angle_deg": 10}}
    return data


def test_an_end_point_inside_a_grown_cone_names_the_cone_it_breaks():
    """The Earth's disc from 500 km subtends asin(R / (R + h)) = 68.02 deg: a 10 deg keep-out about
    the limb is a 78.02 deg cone about nadir. A boresight 30 deg from nadir breaks it by 48.02 deg,
    and the message must name the 78 deg cone, not a '10 deg keep-out cone' that 30 deg would meet."""
    scenario = parse_scenario(limb_scenario())
    radius = 6378.137e3
    disc = np.rad2deg(np.arcsin(radius / (radius + 500e3)))
    assert disc == pytest.approx(68.0187, abs=1e-4)
    messages = endpoint_violations(scenario.problem)
    assert len(messages) == 1, messages
    message = messages[0]
    assert "initial attitude" in message and "st_earth" in message
    assert f"{30.0 - 10.0 - disc:.3g} deg" in message, message       # the margin, -48.0 deg
    assert f"{10.0 + disc:.4g} deg keep-out cone" in message, message  # 78.02 deg, the cone broken
    assert "10 deg about earth_limb" in message, message               # what the user wrote
    assert "the 10 deg keep-out cone" not in message, message


def run_cli(tmp_path: Path, data: dict | str, command: str = "validate", name: str = "case.yaml") -> tuple[int, str]:
    """``slewbench <command> FILE`` on ``data`` written to a file; (exit status, stderr)."""
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data, sort_keys=False))
    extra = {"validate": [], "run": ["--out", str(tmp_path / "out"), "--no-plots"],
             "sweep": ["--out", str(tmp_path / "out"), "--no-plots", "--workers", "1"]}[command]
    stderr = io.StringIO()
    with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
        status = main([command, str(path), *extra])
    return status, stderr.getvalue()


def study(summary: list[str] | None = None, **grid) -> dict:
    """A study of the 12U case (eigenaxis only) over ``grid`` (paths with '__' for '.')."""
    scenario = base()
    scenario["planners"] = [{"name": "eigenaxis"}]
    data = {"study": "hostile", "scenario": scenario,
            "grid": {path.replace("__", "."): values for path, values in grid.items()}
            or {"requirements.pointing.st_sun.angle_deg": [20, 30]}}
    if summary is not None:
        data["summary"] = summary
    return data


@pytest.mark.parametrize(("column", "words"), [
    ("ref.req.st_moon.min_margin_deg", ["'st_moon'", "ref.req.st_sun.min_margin_deg"]),
    ("ref.req.st_sun.min_margin", ["'min_margin'", "min_margin_deg"]),
    ("cl.req.actuators.wheels_torque", ["closed loop", "ref.req.actuators.wheels_torque"]),
    ("ref.req.actuators.wheel_torque", ["'wheel_torque'", "wheels_torque"]),
    ("ref.req.rate.peak_rate", ["'rate'"]),
])
def test_a_summary_naming_a_requirement_column_the_study_lacks_is_refused(tmp_path, column, words):
    """A typo in a summary's requirement column ran the whole study and summarised nothing (empty
    statistics, no word said): it is refused before anything runs, naming the entry and the columns
    there are."""
    status, error = run_cli(tmp_path, study(summary=["cl.final_error_deg", column]), command="sweep")
    assert status == 2, error
    assert "summary[1]" in error and column in error, error
    for word in words:
        assert word in error, (word, error)
    assert "Traceback" not in error and not (tmp_path / "out").exists()


def test_a_summary_of_requirement_columns_the_cases_have_is_accepted():
    from scenarios.study.spec import parse_study

    columns = ["ref.req.st_sun.min_margin_deg", "cl.req.st_sun.time_in_violation_s",
               "ref.req.actuators.wheels_momentum", "ref.req.actuators.wheels_torque_time_s"]
    parsed = parse_study(study(summary=columns))
    assert parsed.summary == columns
    # a requirement only some cases have (added by the grid) is a column of the study
    data = study(summary=["cl.req.rate.peak_rate"], requirements__rate=[None, {"max": 0.1}])
    assert parse_study(data).summary == ["cl.req.rate.peak_rate"]


def test_the_fields_a_study_checks_its_summary_against_are_those_a_run_gives():
    """score_fields (what a summary may name) against the scores of a run with every kind of
    requirement: the same names and fields, scope by scope."""
    import scenarios
    from scenarios.requirements.scoring import score_fields

    data = base()
    data["planners"] = [{"name": "eigenaxis"}]
    data["requirements"]["rate"] = {"max": 0.1}
    data["requirements"]["final"] = {"after_s": 5.0, "error_deg": 1.0, "rate": 0.01}
    scenario = parse_scenario(data)
    row = scenarios.run(scenario).rows[0]
    fields = score_fields(scenario.requirements, scenario.problem.spacecraft)
    assert row.requirements is not None
    for scope in ("reference", "closed_loop"):
        given = {name: tuple(values) for name, values in row.requirements[scope].items()}
        assert given == fields[scope], scope
