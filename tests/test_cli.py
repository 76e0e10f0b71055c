"""Scenario files, the runner and the ``slewbench`` command line, end to end."""
import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.integrate import solve_ivp

import scenarios
from ocp import METRIC_KEYS, quat
from scenarios.cli.commands import main

SMALL = """
name: small
spacecraft:
  inertia: [2.0, 3.0, 4.0]
  wheels: {max_torque: 0.05}
maneuver:
  duration: 40.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.9238795, 0.3826834, 0, 0], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth}
  - {name: eigenaxis, label: fast, options: {profile: min_time}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
simulation: {sample_time: 0.5, duration: 45.0, initial_attitude_error_deg: [0.5, 0, 0]}
"""


def write(tmp_path, text, name="scenario.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def edited(change):
    """SMALL with ``change(data)`` applied."""
    data = yaml.safe_load(SMALL)
    change(data)
    return yaml.safe_dump(data)


def test_run_end_to_end_through_the_console_entry_point(tmp_path):
    out = tmp_path / "out"
    completed = subprocess.run([sys.executable, "-m", "scenarios.console", "run", str(write(tmp_path, SMALL)),
                                "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert completed.returncode == 0, completed.stderr
    assert "[1/2] smooth: ok" in completed.stdout and "[2/2] fast: ok" in completed.stdout
    results = json.loads((out / "results.json").read_text())
    assert results["scenario"] == "small" and [r["label"] for r in results["rows"]] == ["smooth", "fast"]
    for row in results["rows"]:
        assert set(row) == {"label", "planner", "controller", "status", "message", "plan_time_s", "plan_reused",
                            "needed_duration_s", "reference", "closed_loop", "requirements", "certificate", "file_stem"}
        assert (out / "timeseries" / f"{row['file_stem']}.csv").is_file()  # its files' stem
        assert row["plan_reused"] is False  # a run plans every row
        assert row["controller"] == "augmented_quaternion_feedback"
        assert set(row["reference"]) == set(METRIC_KEYS) == set(row["closed_loop"])
        assert row["closed_loop"]["final_error_deg"] < 0.05
    for name in ("results.csv", "results.md", "timeseries/smooth.csv", "timeseries/fast.csv",
                 "smooth.png", "fast.png", "comparison.png"):
        assert (out / name).stat().st_size > 100, name
    assert (out / "smooth.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    series = np.genfromtxt(out / "timeseries" / "smooth.csv", delimiter=",", names=True)
    assert series["t"][-1] == 45.0 and np.allclose(series["q0"] ** 2 + series["q1"] ** 2 + series["q2"] ** 2
                                                  + series["q3"] ** 2, 1)


BAD_INPUTS = {
    "unknown key": (lambda d: d["spacecraft"].update(colour="red"), "spacecraft.colour", "unknown key"),
    "wrong type": (lambda d: d["maneuver"].update(duration="long"), "maneuver.duration", "expected a number"),
    "planner option type": (lambda d: d["planners"][1]["options"].update(torque_fraction="all"),
                            "planners[1].options.torque_fraction", "expected a number"),
    "unknown planner option": (lambda d: d["planners"][1]["options"].update(weight=0.1),
                               "planners[1].options.weight", "unknown option"),
    "not positive definite": (lambda d: d["spacecraft"].update(inertia=[[1, 2, 0], [2, 1, 0], [0, 0, 1]]),
                              "spacecraft.inertia", "positive definite"),
    "triangle inequality": (lambda d: d["spacecraft"].update(inertia=[1, 1, 5]), "spacecraft.inertia", "triangle"),
    "zero quaternion": (lambda d: d["maneuver"]["final"].update(q=[0, 0, 0, 0]), "maneuver.final.q", "cannot be zero"),
    "far from unit": (lambda d: d["maneuver"]["initial"].update(q=[1, 1, 0, 0]), "maneuver.initial.q", "unit norm"),
    "unknown planner": (lambda d: d["planners"][0].update(name="magic"), "planners[0].name", "unknown planner"),
    "unknown controller": (lambda d: d["controller"].update(name="magic"), "controller.name", "unknown controller"),
    "controller gain type": (lambda d: d["controller"]["options"].update(kp=[1, 2]), "controller.options.kp",
                             "expected a number or a matrix"),
    "missing key": (lambda d: d.pop("maneuver"), "maneuver", "required"),
    "bad warm start option": (lambda d: d["planners"].append({"name": "collocation", "label": "c",
                                                              "options": {"warm_start_options": {"profile": "fast"}}}),
                              "planners[2].options", "warm_start_options.profile"),
    "shooting with an L1 cost": (lambda d: d["planners"].append({"name": "collocation", "label": "c", "options": {
        "transcription": "multiple_shooting", "objective": "min_l1"}}),
                                 "planners[2].options", "use transcription: collocation"),
    "unknown warm start": (lambda d: d["planners"].append({"name": "collocation", "label": "c",
                                                           "options": {"warm_start": "magic"}}),
                           "planners[2].options", "not another registered planner"),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUTS))
def test_bad_scenario_exits_2_naming_the_path(case, tmp_path, capsys):
    change, path, expected = BAD_INPUTS[case]
    out = tmp_path / "out"
    code = main(["run", str(write(tmp_path, edited(change))), "--out", str(out)])
    stderr = capsys.readouterr().err
    assert code == 2
    assert path in stderr and expected in stderr, stderr
    assert "Traceback" not in stderr
    assert not out.exists()


@pytest.mark.parametrize("text, expected", [
    (None, "not found"),
    ("name: [unclosed\n  - x: {", "not valid YAML"),
])
def test_missing_file_and_non_yaml_exit_2(text, expected, tmp_path, capsys):
    path = tmp_path / "missing.yaml" if text is None else write(tmp_path, text)
    assert main(["validate", str(path)]) == 2
    stderr = capsys.readouterr().err
    assert expected in stderr and "Traceback" not in stderr


def test_exponent_numbers_are_accepted(tmp_path):
    text = SMALL.replace("duration: 40.0", "duration: 4e1").replace("max_torque: 0.05", "max_torque: 5e-2")
    scenario = scenarios.load(write(tmp_path, text))
    assert scenario.problem.duration == 40.0
    assert scenario.problem.torque_limit[0] == 0.05


def test_library_api_returns_tables(tmp_path):
    results = scenarios.run(scenarios.load(write(tmp_path, SMALL)))
    assert [row.status for row in results.rows] == ["ok", "ok"]
    csv_lines = results.to_csv().splitlines()
    assert len(csv_lines) == 3 and csv_lines[0].startswith("label,planner,controller,status")
    assert "| cl.final_error_deg |" in results.to_markdown()


def test_regulation_mode_uses_the_controller_as_the_row(tmp_path):
    text = edited(lambda d: (d.update(planners=[]), d.update(controller={"name": "eigenaxis_pd",
                                                                          "options": {"kp": 0.2, "kd": 0.6}})))
    results = scenarios.run(scenarios.load(write(tmp_path, text)))
    (row,) = results.rows
    assert row.label == "eigenaxis_pd" and row.planner is None and row.status == "ok"
    assert row.closed_loop_metrics["final_error_deg"] < 0.1 and row.reference_metrics is None


def rotation_x(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rotation_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_free_motion_with_gravity_gradient_matches_an_independent_integration(tmp_path):
    """One orbit of free motion, against SciPy's DOP853 on equations written out here."""
    mu, radius = 3.986004418e14, 6378.137e3 + 500e3
    inclination, raan, u0 = np.deg2rad(51.6), np.deg2rad(30.0), np.deg2rad(10.0)
    inertia = np.array([[12.0, 0.4, -0.3], [0.4, 9.0, 0.2], [-0.3, 0.2, 5.0]])
    q0 = quat.normalize(np.array([0.8, 0.1, -0.3, 0.5]))
    omega0 = np.array([0.002, -0.004, 0.003])
    n = np.sqrt(mu / radius**3)
    period = 2 * np.pi / n
    text = f"""
    name: free-gg
    spacecraft: {{inertia: {inertia.tolist()}, wheels: none}}
    orbit: {{altitude_km: 500, inclination_deg: 51.6, raan_deg: 30, arg_latitude_deg: 10}}
    environment: {{gravity_gradient: true}}
    maneuver:
      duration: {period}
      initial: {{q: {q0.tolist()}, omega: {omega0.tolist()}}}
      final: {{q: [1, 0, 0, 0]}}
    planners: []
    controller: {{name: none}}
    simulation: {{sample_time: 20.0}}
    """
    (row,) = scenarios.run(scenarios.load(write(tmp_path, text))).rows
    simulation = row.simulation

    def position(t):
        u = u0 + n * t
        return rotation_z(raan) @ rotation_x(inclination) @ (radius * np.array([np.cos(u), np.sin(u), 0.0]))

    def rhs(t, y):
        q, omega = y[:4], y[4:]
        w1, w2, w3 = omega
        big_omega = np.array([[0, -w1, -w2, -w3], [w1, 0, w3, -w2], [w2, -w3, 0, w1], [w3, w2, -w1, 0]])
        r_body = quat.rotation_matrix(q).T @ position(t)
        torque = 3 * mu / np.linalg.norm(r_body) ** 5 * np.cross(r_body, inertia @ r_body)
        return np.r_[0.5 * big_omega @ q, np.linalg.solve(inertia, torque - np.cross(omega, inertia @ omega))]

    truth = solve_ivp(rhs, (0, period), np.r_[q0, omega0], method="DOP853", rtol=1e-12, atol=1e-14,
                      t_eval=simulation.t)
    errors = quat.error_angle(simulation.q, truth.y[:4].T)
    gg_effect = quat.error_angle(truth.y[:4, -1], quat.product(q0, quat.from_rotation_vector(omega0 * period)))
    assert gg_effect > np.deg2rad(10)  # the gravity gradient matters over the orbit
    assert np.max(np.rad2deg(errors)) < 1e-6
    np.testing.assert_allclose(simulation.omega, truth.y[4:].T, atol=1e-10)


def test_several_controllers_give_one_row_per_planner_and_controller(tmp_path):
    laws = [{"name": "augmented_quaternion_feedback", "label": "soft", "options": {"kp": 0.2, "kd": 0.6}},
            {"name": "augmented_quaternion_feedback", "label": "stiff", "options": {"kp": 0.8, "kd": 1.2}}]
    text = edited(lambda d: (d.pop("controller"), d.update(controllers=laws)))
    results = scenarios.run(scenarios.load(write(tmp_path, text)))
    assert [row.label for row in results.rows] == ["smooth / soft", "smooth / stiff", "fast / soft", "fast / stiff"]
    assert {row.controller for row in results.rows} == {"augmented_quaternion_feedback"}
    # the gains differ, so the closed loops must differ while each planner's reference is shared
    soft, stiff = results.rows[0], results.rows[1]
    assert soft.reference_metrics == stiff.reference_metrics
    assert soft.closed_loop_metrics["int_u2"] != stiff.closed_loop_metrics["int_u2"]
    assert results.to_csv().splitlines()[1].startswith("smooth / soft,eigenaxis,augmented_quaternion_feedback,ok")
    assert [row["controller"] for row in json.loads(results.to_json())["rows"]] == ["augmented_quaternion_feedback"] * 4


def test_regulation_with_several_controllers_gives_one_row_each(tmp_path):
    laws = [{"name": "eigenaxis_pd", "options": {"kp": 0.2, "kd": 0.6}}, {"name": "none", "label": "free"}]
    text = edited(lambda d: (d.update(planners=[]), d.pop("controller"), d.update(controllers=laws)))
    results = scenarios.run(scenarios.load(write(tmp_path, text)))
    assert [(row.label, row.controller) for row in results.rows] == [("eigenaxis_pd", "eigenaxis_pd"), ("free", "none")]
    assert results.rows[0].closed_loop_metrics["final_error_deg"] < 0.1
    assert results.rows[1].closed_loop_metrics["final_error_deg"] > 40  # no actuation: still 45 deg away


@pytest.mark.parametrize("change, path, fragment", [
    (lambda d: d.update(controllers=[{"name": "none"}]), "controllers", "not both"),
    (lambda d: (d.pop("controller"), d.update(controllers=[])), "controllers", "at least one"),
    (lambda d: (d.pop("controller"), d.update(controllers=[{"name": "none"}, {"name": "none"}])),
     "controllers[1].label", "duplicate label"),
    (lambda d: (d.pop("controller"), d.update(controllers=[{"name": "none"}, {"name": "magic"}])),
     "controllers[1].name", "unknown controller"),
    (lambda d: (d.update(planners=[]), d["maneuver"]["final"].update(q=None)), "maneuver.final.q",
     "needs a target attitude"),
])
def test_controller_list_errors_name_the_entry(tmp_path, change, path, fragment):
    with pytest.raises(scenarios.ScenarioError) as error:
        scenarios.load(write(tmp_path, edited(change)))
    assert error.value.path == path and fragment in str(error.value)


@pytest.mark.parametrize("command", [["schema"], ["list"]])
def test_a_reader_that_stops_early_is_not_an_internal_error(command):
    """``slewbench schema | head -1``: the pipe closes under the writer; the command ends quietly."""
    import os

    read_end, write_end = os.pipe()
    process = subprocess.Popen([sys.executable, "-m", "scenarios.cli", *command], stdout=write_end,
                               stderr=subprocess.PIPE, cwd=Path(__file__).resolve().parents[1])
    os.close(write_end)
    os.close(read_end)  # the reader is gone before the command writes anything
    assert process.stderr is not None
    error = process.stderr.read().decode()
    assert process.wait(timeout=60) == 0, error
    assert "Traceback" not in error and "internal error" not in error
