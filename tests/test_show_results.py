"""Results that show themselves (issue 31, item 4): compact reprs and notebook tables of rows, runs,
references, simulations and studies; a simulation as a DataFrame; provenance in results.json; tidy
public namespaces.

Oracles: the rows' own labels, statuses and numbers (read from the objects, not from the text under
test), an HTML parser for the notebook tables, hand-built simulation arrays with sign flips and a
known wheel inertia, attitudes built from three axis-angle quaternions, and the package metadata.
"""
from __future__ import annotations

import datetime
import importlib
import json
import pkgutil
import platform
from html.parser import HTMLParser

import numpy as np
import pytest

import scenarios
from ocp import (
    AttitudeModel,
    Magnetorquers,
    ReactionWheels,
    SimulationResult,
    Spacecraft,
    Torquers,
    quat,
)
from planners import FailedReference
from scenarios.output.provenance import package_version
from scenarios.output.results import Row, RunResults
from scenarios.study.engine import SweepResults
from scenarios.study.spec import parse_study

DEMO = "scenarios/eigenaxis_demo.yaml"


class Tables(HTMLParser):
    """The cells of every table of an HTML text: ``tables[i][row][cell]``, and the captions."""

    def __init__(self, text: str):
        super().__init__()
        self.tables: list[list[list[str]]] = []
        self.captions: list[str] = []
        self._cell: list[str] | None = None
        self._caption: list[str] | None = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []
        elif tag == "caption":
            self._caption = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell))
            self._cell = None
        elif tag == "caption" and self._caption is not None:
            self.captions.append("".join(self._caption))
            self._caption = None

    def handle_data(self, data):
        for part in (self._cell, self._caption):
            if part is not None:
                part.append(data)


@pytest.fixture(scope="module")
def demo() -> RunResults:
    return scenarios.run(scenarios.load(DEMO))


# --- reprs and notebook tables ----------------------------------------------------------------------

def test_run_repr_is_short_and_names_every_row_and_status(demo):
    text = repr(demo)
    assert len(text) < 200 * (1 + len(demo.rows)) and len(text.splitlines()) == len(demo.rows) + 1
    assert text.startswith(f"<RunResults {demo.scenario.name!r}")
    for row, line in zip(demo.rows, text.splitlines()[1:]):
        assert f"{row.label!r}: {row.status}" in line and row.planner in line and row.controller in line
        final = row.closed_loop_metrics["final_error_deg"]
        assert f"final_error_deg={final:.4g}" in line
    assert "Scenario(" not in text and "array(" not in text  # not the dataclass dump


def test_run_notebook_table_has_one_line_per_row(demo):
    tables = Tables(demo._repr_html_())
    (table,) = tables.tables
    header, lines = table[0], table[1:]
    assert header[:5] == ["label", "planner", "controller", "status", "plan_time_s"] and header[-1] == "message"
    assert [line[0] for line in lines] == [row.label for row in demo.rows]
    assert [line[3] for line in lines] == [row.status for row in demo.rows]
    column = header.index("final_error_deg")
    for line, row in zip(lines, demo.rows):
        assert float(line[column]) == pytest.approx(row.closed_loop_metrics["final_error_deg"], rel=1e-3)
    assert demo.scenario.name in tables.captions[0]


def test_row_repr_shows_a_failure_and_escapes_html():
    row = Row("a <b> & c", "collocation", "failed", "Ipopt: " + "Restoration_Failed " * 40, 1.5, None, None,
              controller="eigenaxis_pd")
    text = repr(row)
    assert text.startswith("<Row 'a <b> & c': failed (collocation / eigenaxis_pd)") and "Ipopt: Restoration" in text
    assert len(text) < 250  # the message is cut
    table = Tables(row._repr_html_()).tables[0]
    assert table[1][:4] == ["a <b> & c", "collocation", "eigenaxis_pd", "failed"]  # escaped, read back whole
    assert "<b>" not in row._repr_html_()
    regulation = Row("pd", None, "ok", "", None, None, {"final_error_deg": None, "final_rate": 1e-4,
                                                         "detumble_time_s": 12.0, "int_u": 0.5, "int_dipole": None},
                     controller="bdot")
    assert repr(regulation) == "<Row 'pd': ok (regulation / bdot); final_rate=0.0001, detumble_time_s=12, int_u=0.5>"


def test_reference_repr_and_table(demo):
    reference = demo.rows[0].reference
    text = repr(reference)
    assert text.startswith(f"<{type(reference).__name__} of eigenaxis: status ok, duration "
                           f"{reference.duration:.4g} s") and " at 0x" not in text
    assert reference.message in text
    failed = FailedReference("collocation", "Ipopt: Maximum_Iterations_Exceeded\n" + "x" * 500, status="infeasible")
    text = repr(failed)
    assert text.startswith("<FailedReference of collocation: status infeasible") and "Maximum_Iterations" in text
    assert len(text) < 200 and "\n" not in text
    (table,) = Tables(failed._repr_html_()).tables
    assert table[0] == ["planner", "status", "duration", "planned in", "message"]
    assert table[1][:2] == ["collocation", "infeasible"]


def test_simulation_repr_and_table(demo):
    simulation = demo.rows[0].simulation
    text = repr(simulation)
    assert text.startswith(f"<SimulationResult: samples {simulation.t.size}, window 0 to {simulation.t[-1]:.4g} s")
    assert f"final |ω| {np.linalg.norm(simulation.omega[-1]):.4g} rad/s" in text and "\n" not in text
    assert len(text) < 300
    rows = dict(line for line in Tables(simulation._repr_html_()).tables[0])
    assert rows["samples"] == str(simulation.t.size) and rows["actuators"] == "wheels"


def test_sweep_and_study_reprs_count_rows_by_status():
    study = parse_study({"study": "tiny", "scenario": DEMO, "grid": {"maneuver.duration": [100.0, 120.0, 140.0]}})
    first, second, third = study.cases
    records = {
        first.key: {"status": "ok", "rows": [{"label": "smooth", "status": "ok"},
                                             {"label": "min-time", "status": "violated"}]},
        second.key: {"status": "ok", "rows": [{"label": "smooth", "status": "ok"},
                                              {"label": "min-time", "status": "failed"}]},
    }
    results = SweepResults(study, records)
    text = repr(results)
    assert text.splitlines() == ["<SweepResults 'tiny': 3 cases (1 missing)", "  smooth: 2 ok",
                                 "  min-time: 1 violated, 1 failed>"]
    (table,) = Tables(results._repr_html_()).tables
    assert table == [["label", "rows", "ok", "violated", "failed"], ["smooth", "2", "2", "0", "0"],
                     ["min-time", "2", "0", "1", "1"]]
    records[third.key] = {"status": "crashed", "rows": [{"label": "smooth", "status": "crashed"}]}
    assert repr(results).splitlines()[0] == "<SweepResults 'tiny': 3 cases (0 missing, 1 crashed)"
    assert repr(study) == "<Study 'tiny': 3 cases, 1 sample(s) per grid point; varies maneuver.duration>"


# --- a simulation as a table --------------------------------------------------------------------------

def hand_built_simulation(rng: np.random.Generator) -> tuple[SimulationResult, dict]:
    """A simulation of a spacecraft with two wheels (spin inertia known), magnetorquers and torquers,
    whose arrays are made up: attitudes from known Euler angles, the quaternion's sign flipped at
    some samples."""
    spacecraft = Spacecraft([2.0, 3.0, 4.0], wheels=ReactionWheels(np.eye(3)[:, :2], max_torque=0.01,
                                                                   spin_inertia=[0.002, 0.004]),
                            magnetorquers=Magnetorquers(max_dipole=0.2), torquers=Torquers(max_torque=0.05))
    model = AttitudeModel(spacecraft)
    n = 12
    t = np.linspace(0.0, 11.0, n)
    yaw, pitch, roll = np.deg2rad(np.linspace(-170, 170, n)), np.deg2rad(np.linspace(-80, 80, n)), \
        np.deg2rad(np.linspace(10, 60, n))
    q = quat.product(quat.product(quat.from_axis_angle([0, 0, 1], yaw), quat.from_axis_angle([0, 1, 0], pitch)),
                     quat.from_axis_angle([1, 0, 0], roll))
    signs = np.ones(n)
    signs[[3, 4, 9]] = -1.0
    x = np.hstack([q * signs[:, None], rng.normal(size=(n, 3)), rng.normal(size=(n, 2))])
    commanded, applied = rng.normal(size=(n - 1, model.nu)), rng.normal(size=(n - 1, model.nu))
    torque = rng.normal(size=(n - 1, 3))
    saturated = rng.random(n - 1) < 0.5
    simulation = SimulationResult(model, 1.0, t, x, commanded, applied, torque, saturated)
    return simulation, {"q": q, "signs": signs, "euler_deg": np.rad2deg(np.stack([yaw, pitch, roll], axis=1))}


def test_simulation_dataframe_columns_are_the_arrays():
    simulation, truth = hand_built_simulation(np.random.default_rng(7))
    frame = simulation.to_dataframe()
    slices = simulation.model.control_slices
    assert list(frame.columns) == [
        "t_s", "q0", "q1", "q2", "q3", "yaw_deg", "pitch_deg", "roll_deg",
        "omega_x_rad_s", "omega_y_rad_s", "omega_z_rad_s",
        "actuator_torque_x_N_m", "actuator_torque_y_N_m", "actuator_torque_z_N_m",
        "wheel0_torque_cmd_N_m", "wheel0_torque_N_m", "wheel1_torque_cmd_N_m", "wheel1_torque_N_m",
        "dipole_x_cmd_A_m2", "dipole_x_A_m2", "dipole_y_cmd_A_m2", "dipole_y_A_m2", "dipole_z_cmd_A_m2", "dipole_z_A_m2",
        "torquer_x_cmd_N_m", "torquer_x_N_m", "torquer_y_cmd_N_m", "torquer_y_N_m", "torquer_z_cmd_N_m", "torquer_z_N_m",
        "wheel0_momentum_N_m_s", "wheel0_speed_rpm", "wheel1_momentum_N_m_s", "wheel1_speed_rpm", "saturated"]
    assert len(frame) == simulation.t.size
    np.testing.assert_array_equal(frame["t_s"], simulation.t)
    np.testing.assert_array_equal(frame[["omega_x_rad_s", "omega_y_rad_s", "omega_z_rad_s"]], simulation.omega)
    np.testing.assert_array_equal(frame[["actuator_torque_x_N_m", "actuator_torque_y_N_m", "actuator_torque_z_N_m"]]
                                  .to_numpy()[:-1], simulation.applied_torque)
    for name, block, index in [("wheel0_torque", "wheels", 0), ("wheel1_torque", "wheels", 1),
                               ("dipole_y", "dipole", 1), ("torquer_z", "torquers", 2)]:
        unit = "A_m2" if block == "dipole" else "N_m"
        column = slices[block].start + index
        np.testing.assert_array_equal(frame[f"{name}_cmd_{unit}"].to_numpy()[:-1], simulation.commanded_u[:, column])
        np.testing.assert_array_equal(frame[f"{name}_{unit}"].to_numpy()[:-1], simulation.applied_u[:, column])
    last = frame.iloc[-1]
    assert np.isnan(last["wheel0_torque_N_m"]) and np.isnan(last["actuator_torque_x_N_m"])
    assert frame["saturated"].iloc[:-1].tolist() == simulation.saturated.tolist() and frame["saturated"].isna().iloc[-1]
    np.testing.assert_array_equal(frame["wheel1_momentum_N_m_s"], simulation.wheel_momentum[:, 1])
    rpm = simulation.wheel_momentum[:, 1] / 0.004 * 60.0 / (2.0 * np.pi)  # h / J_s in rev/min
    np.testing.assert_allclose(frame["wheel1_speed_rpm"], rpm, rtol=1e-15)


def test_simulation_dataframe_euler_angles_and_sign_continuity():
    simulation, truth = hand_built_simulation(np.random.default_rng(8))
    frame = simulation.to_dataframe()
    np.testing.assert_allclose(frame[["yaw_deg", "pitch_deg", "roll_deg"]], truth["euler_deg"], atol=1e-10)
    q = frame[["q0", "q1", "q2", "q3"]].to_numpy()
    assert np.all(np.sum(q[1:] * q[:-1], axis=1) > 0)  # no jump, though the input flips at 3, 4, 9
    np.testing.assert_allclose(q, truth["q"], atol=1e-15)  # the first sample's sign, kept throughout
    assert np.any(np.sum(simulation.q[1:] * simulation.q[:-1], axis=1) < 0)  # the input did jump
    other = simulation.to_dataframe(sequence="313")
    assert ["euler_313_1_deg", "euler_313_2_deg", "euler_313_3_deg"] == list(other.columns[5:8])
    np.testing.assert_allclose(other[["euler_313_1_deg", "euler_313_2_deg", "euler_313_3_deg"]],
                               np.rad2deg(quat.to_euler(truth["q"], "313")))


def test_simulation_dataframe_of_a_real_run(demo):
    simulation = demo.rows[1].simulation
    frame = simulation.to_dataframe()
    np.testing.assert_array_equal(frame[[f"wheel{i}_momentum_N_m_s" for i in range(3)]], simulation.wheel_momentum)
    assert "wheel0_speed_rpm" not in frame  # the demo's wheels give no spin inertia
    angles = np.deg2rad(frame[["yaw_deg", "pitch_deg", "roll_deg"]].to_numpy())
    rebuilt = quat.product(quat.product(quat.from_axis_angle([0, 0, 1], angles[:, 0]),
                                        quat.from_axis_angle([0, 1, 0], angles[:, 1])),
                           quat.from_axis_angle([1, 0, 0], angles[:, 2]))
    np.testing.assert_allclose(quat.error_angle(rebuilt, simulation.q), 0.0, atol=1e-7)


# --- provenance ---------------------------------------------------------------------------------------

def test_results_json_records_its_provenance(demo, tmp_path):
    before = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    results = scenarios.run(scenarios.load(DEMO))
    after = datetime.datetime.now(datetime.timezone.utc)
    provenance = json.loads(results.to_json())["provenance"]
    assert provenance["slewbench"] == package_version()
    assert provenance["python"].startswith(platform.python_version()) and provenance["platform"] == platform.platform()
    import casadi
    assert provenance["libraries"]["casadi"] == casadi.__version__ and provenance["libraries"]["numpy"] == np.__version__
    date = datetime.datetime.fromisoformat(provenance["date_utc"].replace("Z", "+00:00"))
    assert before <= date <= after
    assert provenance["scenario_file"] == DEMO and provenance["seeds"] == {"simulation.sensor_noise.seed": 1}
    import yaml
    with open(DEMO) as handle:
        assert provenance["scenario"] == yaml.safe_load(handle)  # the YAML as read
    results.write(tmp_path / "out", plots=False)
    written = json.loads((tmp_path / "out" / "results.json").read_text())
    assert written["provenance"]["scenario"]["name"] == "eigenaxis-demo"


def test_the_recorded_scenario_is_a_copy():
    import yaml
    with open(DEMO) as handle:
        data = yaml.safe_load(handle)
    scenario = scenarios.parse_scenario(data)
    data["maneuver"]["duration"] = 1.0  # a script varying the mapping after parsing it
    assert scenario.data["maneuver"]["duration"] == 120.0 and scenario.source is None


# --- namespaces -------------------------------------------------------------------------------------

def faces() -> list[str]:
    found = []
    for package in ("ocp", "planners", "controllers", "scenarios"):
        module = importlib.import_module(package)
        found.append(package)
        found += [info.name for info in pkgutil.walk_packages(module.__path__, prefix=f"{package}.")
                  if info.ispkg and not info.name.rsplit(".", 1)[-1].startswith("_")]
    return found


@pytest.mark.parametrize("face", faces())
def test_dir_of_every_face_lists_only_its_public_names(face):
    module = importlib.import_module(face)
    for name in module.__all__:
        getattr(module, name)  # imports every lazy name, which must not leak into dir() either
    listed = set(dir(module))
    public = {name for name in listed if not (name.startswith("__") and name.endswith("__"))}
    assert public == set(module.__all__), sorted(public ^ set(module.__all__))
    assert {"__name__", "__doc__", "__all__"} <= listed
    assert not {"Any", "TYPE_CHECKING", "annotations", "importlib"} & listed


def test_submodules_stay_reachable_though_not_listed():
    import ocp
    assert "quat" not in dir(ocp) and ocp.quat.product is quat.product
    assert scenarios.output.tables.text_cell(1.0) == "1"
