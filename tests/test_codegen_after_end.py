"""Flight C after the reference's end, the default reference and the export's words.

* A reference that ends while still rotating (the spin re-pointing ends at 0.2 rad/s): after T the
  Python closed loop tracks the reference's torque-free coast (the Reference contract), so the C
  table must hold that coast through the closed-loop window (and the one sample the step reads
  ahead); the C command then equals the Python law's on the planned reference past T, and the C
  table's coast is checked against SciPy's integration of Euler's equations from the reference's
  final state. Past the table's end the C holds the last row, and so does ``TableReference``.
* A row whose reference breaks the scenario's requirements (as ``slewbench run`` scores it) is named
  with what it breaks, and is not the default table when a row that meets them exists.
* The header's comments read plain numbers; a table that misses a tolerance names the quantity.
"""
import ctypes
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from ocp import Measurement, quat
from scenarios.codegen.export import generate
from scenarios.codegen.tables import TableReference, TableTolerance, tabulate
from scenarios.schema.loader import load
from tests.test_codegen_flight import Built

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
needs_cc = pytest.mark.skipif(shutil.which("make") is None or shutil.which("cc") is None,
                              reason="needs make and a C compiler")


def _variant(tmp_path: Path, name: str, old: str, new: str) -> Path:
    text = (SCENARIOS / name).read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new, 1))
    return path


@needs_cc
def test_c_commands_the_python_law_past_t_on_a_reference_that_ends_spinning(tmp_path):
    # the spin re-pointing (T = 200 s, final rate 0.2 rad/s free), its closed loop run to 240 s
    path = _variant(tmp_path, "spin_repoint_estimator.yaml", "  sample_time: 1.0\n",
                    "  sample_time: 1.0\n  duration: 240.0\n")
    built = Built(path, tmp_path / "c")
    scenario = load(path)
    problem, spec = scenario.problem, scenario.simulation
    spacecraft = problem.spacecraft
    controller = scenario.controllers[0].controller
    label = scenario.planners[0].label
    reference = scenario.planners[0].planner.plan(problem)
    assert reference.ok and reference.duration == 200.0
    q_end, omega_end = reference.final_state()
    assert np.linalg.norm(omega_end) > 0.19  # it ends rotating
    c_table, table = built.table(label)
    params = built.params(saturate=0)
    params.reference = ctypes.pointer(c_table)
    table_reference = TableReference(table, spacecraft.inertia)
    rng = np.random.default_rng(7)
    # before T - T_s, the last samples of the manoeuvre (reading t + T_s past T), the coast, past the table
    times = [150.0, 199.0, 199.5, 200.0, 205.0, 230.0, 239.0, 240.0]
    for t in times + [245.0, 300.0]:
        for q, omega in ((quat.IDENTITY, np.zeros(3)), (quat.random_unit(rng), rng.normal(0, 0.05, 3))):
            measurement = Measurement(t, q, omega, np.zeros(0), None)
            status, u, _, _ = built.step(t, measurement, params, built.init())
            assert status == 0
            if t <= 240.0:  # within the run: the law on the planned reference (its coast after T)
                controller.reset(spacecraft, spec.sample_time, target=(problem.qf, problem.omegaf))
                planned = controller.command_vector(controller(t, measurement, reference))
                # before the fix: 1e-2 N m at 199.5 s, 0.36 N m at 205 s
                np.testing.assert_allclose(u, planned, rtol=0, atol=1e-6, err_msg=f"t={t}")
            controller.reset(spacecraft, spec.sample_time, target=(problem.qf, problem.omegaf))
            on_table = controller.command_vector(controller(t, measurement, table_reference))
            np.testing.assert_allclose(u, on_table, rtol=0, atol=1e-12, err_msg=f"t={t}")
    assert table.end == 241.0  # the window, and the sample the step reads ahead
    assert table_reference.duration == 200.0
    # the C table's coast against Euler's equations integrated here from the reference's final state
    inertia = spacecraft.inertia
    inverse = np.linalg.inv(inertia)

    def euler(_t, y):
        q, w = y[:4], y[4:]
        return np.concatenate([0.5 * quat.product(q, np.r_[0.0, w]), -inverse @ np.cross(w, inertia @ w)])

    coast = np.array([200.5, 205.0, 222.2, 241.0])
    solution = solve_ivp(euler, (200.0, 241.0), np.r_[q_end, omega_end], method="DOP853", rtol=1e-12, atol=1e-14,
                         t_eval=coast)
    rows = np.array([built.row(c_table, t) for t in coast])
    assert quat.error_angle(rows[:, 0:4], solution.y[:4].T).max() < 1e-6
    np.testing.assert_allclose(rows[:, 4:7], solution.y[4:].T, rtol=0, atol=1e-8)
    expected_omega_dot = -(inverse @ np.cross(rows[:, 4:7], rows[:, 4:7] @ inertia.T).T).T
    np.testing.assert_allclose(rows[:, 7:10], expected_omega_dot, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(rows[:, 10:13], 0.0)
    # at T exactly the table gives the reference's own end (its torque), as the reference does
    np.testing.assert_allclose(built.row(c_table, 200.0)[10:13], reference.sample(200.0).torque, rtol=0, atol=1e-9)
    assert np.abs(reference.sample(200.0).torque).max() > 1e-3
    # past the table's end: the last row, held, in C and in TableReference
    np.testing.assert_array_equal(built.row(c_table, 300.0), table.rows[-1])
    held = table_reference.sample(300.0)
    np.testing.assert_array_equal(np.concatenate([held.q, held.omega, held.omega_dot, held.torque]), table.rows[-1])
    header = (tmp_path / "c" / "slewbench_tables.h").read_text()
    assert "over [0, 241] s: the manoeuvre to T = 200 s, then its torque-free coast" in header
    assert "after 241 s it holds its last row" in header


def test_a_row_that_breaks_the_requirements_is_named_and_not_the_default(tmp_path):
    from scenarios.runner import run

    # eigenaxis_demo in 30 s: the smooth profile asks 4.25 (5/30)^2 = 0.118 N m of 0.1 N m wheels; the
    # bang profiles (29.74 s at their fastest) fit within the 30 s budget
    path = _variant(tmp_path, "eigenaxis_demo.yaml", "  duration: 120.0\n", "  duration: 30.0\n")
    scenario = load(path)
    report = generate(scenario, tmp_path / "c")
    assert set(report.violations) == {"smooth"}
    assert any("wheels_torque" in sentence and "x its limit" in sentence for sentence in report.violations["smooth"])
    # the same verdicts as `slewbench run` on the same scenario
    results = run(load(path))
    violated = {row.label for row in results.rows if row.status == "violated"}
    assert violated == set(report.violations)
    ok = [label for label in report.tables if label not in report.violations]
    assert ok and report.default == ok[0] != "smooth"
    assert "meets the scenario's requirements" in report.default_reason and "'smooth'" in report.default_reason
    header = (tmp_path / "c" / "slewbench_step.h").read_text()
    default = re.search(r"#define SLEWBENCH_PARAMS_DEFAULT .*", header)
    assert default is not None
    table_name = json.loads((tmp_path / "c" / "interface.json").read_text())["tables"][report.default]["table"]
    assert f"&{table_name}" in default.group(0)
    lines = report.summary()
    assert any(line.startswith("  warning: row 'smooth' breaks the scenario's requirements:") and "wheels_torque" in line
               for line in lines)
    assert any(f"track row {report.default!r}" in line for line in lines)
    readme = (tmp_path / "c" / "README.md").read_text()
    assert "wheels_torque" in readme and f"track row {report.default!r}" in readme
    # the header's comments: plain numbers
    tables_h = (tmp_path / "c" / "slewbench_tables.h").read_text()
    assert "np.float64" not in tables_h and "over [0, 140.5] s" in tables_h


def test_the_default_is_the_first_row_when_all_meet_and_warns_when_none_does(tmp_path):
    report = generate(load(SCENARIOS / "eigenaxis_demo.yaml"), tmp_path / "a")
    assert report.violations == {} and report.default == next(iter(report.tables))
    path = _variant(tmp_path, "eigenaxis_demo.yaml", "  duration: 120.0\n", "  duration: 5.0\n")
    text = path.read_text()
    keep = [line for line in text.splitlines() if "bang-coast-bang" not in line and "min-time" not in line]
    path.write_text("\n".join(keep) + "\n")
    report = generate(load(path), tmp_path / "b")
    assert list(report.tables) == ["smooth"] and report.default == "smooth"
    assert "WARNING: every exported row breaks" in report.default_reason


def test_a_table_that_misses_a_tolerance_names_the_quantity(tmp_path):
    scenario = load(SCENARIOS / "eigenaxis_demo.yaml")
    reference = scenario.planners[0].planner.plan(scenario.problem)
    # attitude and rate loose, the linear quantities impossibly tight within 32 intervals
    tolerance = TableTolerance(attitude_rad=1.0, rate=1.0, linear=1e-12, max_intervals=32)
    _, error = tabulate(reference, tolerance)
    assert not error.met and error.failed == ("omega_dot", "torque")
    text = error.summary()
    assert "omega_dot" in text and "tolerances NOT met: omega_dot over" in text and "torque over" in text
    assert "attitude over" not in text and "rate over" not in text
    # the line shows the omega_dot error itself
    assert f"omega_dot {error.acceleration:.2g} rad/s^2" in text
    _, error = tabulate(reference)
    assert error.met and "NOT met" not in error.summary()


def test_a_spinning_coast_after_t_is_tabulated_within_the_tolerances():
    scenario = load(SCENARIOS / "spin_repoint_estimator.yaml")
    reference = scenario.planners[0].planner.plan(scenario.problem)
    table, error = tabulate(reference, end=260.0)
    assert error.met and table.end == 260.0 and table.manoeuvre_duration == 200.0
    t = np.linspace(200.0, 260.0, 301)
    got = table.evaluate(t)
    exact = reference.sample(t)
    assert quat.error_angle(got[:, 0:4], exact.q).max() < 2e-6
    assert np.all(got[t > 200.0, 10:13] == 0.0)
    # the manoeuvre part is what it was without the coast
    alone, _ = tabulate(reference)
    np.testing.assert_array_equal(table.times[:alone.times.size], alone.times)
    np.testing.assert_array_equal(table.rows[:alone.times.size], alone.rows)
