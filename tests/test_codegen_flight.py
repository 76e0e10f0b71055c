"""Flight C (issue 29, part 5): ``slewbench codegen`` exports every planned row's reference as a
table and ``slewbench_step`` (law, then the simulator's saturation stage) behind a plain C
interface. The generated code is built with its own Makefile (strict C99) and called through
ctypes; its outputs are compared with the Python controller, the Python actuator model
(``ActuatorModel.apply``, the numeric form) and the NumPy interpolation of the same table, to 1e-12.
The interpolation itself is checked against SciPy's cubic Hermite spline, and each table's stated
error against the continuous reference is recomputed independently."""
import ctypes
import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from ocp import Measurement, quat
from ocp.dynamics.actuators import ActuatorModel
from ocp.dynamics.layout import control_layout
from planners.reference import FailedReference
from scenarios.cli.commands import main
from scenarios.codegen.tables import ReferenceTable, TableReference, interpolate
from scenarios.schema.loader import load

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"
pytestmark = pytest.mark.skipif(shutil.which("make") is None or shutil.which("cc") is None,
                                reason="needs make and a C compiler")
ROW = 13


class Table(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("times", ctypes.POINTER(ctypes.c_double)),
                ("rows", ctypes.POINTER(ctypes.c_double))]


def _dim(n):
    return max(n, 1)


class Built:
    """A generated directory, built, with ctypes mirrors of its structs."""

    def __init__(self, name, out):
        assert main(["codegen", str(SCENARIOS / name), "--out", str(out)]) == 0
        subprocess.run(["make", "-C", str(out)], check=True, capture_output=True)
        self.out = out
        self.interface = json.loads((out / "interface.json").read_text())
        self.lib = ctypes.CDLL(str(out / self.interface["library"]))
        header = (out / "slewbench_step.h").read_text()

        def define(name):
            line = next(line for line in header.splitlines() if line.startswith(f"#define {name} "))
            return line.split()[2]

        self.n_w, self.nu, self.nz = (int(define(k)) for k in ("SLEWBENCH_N_WHEELS", "SLEWBENCH_NU", "SLEWBENCH_NZ"))
        self.sample_time = float(define("SLEWBENCH_SAMPLE_TIME"))

        class MeasurementC(ctypes.Structure):
            _fields_ = [("q", ctypes.c_double * 4), ("omega", ctypes.c_double * 3),
                        ("wheel_momentum", ctypes.c_double * _dim(self.n_w)), ("field", ctypes.c_double * 3)]

        def c_type(shape):
            kind = ctypes.c_double
            for size in reversed(shape):
                kind = kind * size
            return kind

        self.parameters = self.interface["parameters"]

        class Params(ctypes.Structure):
            _fields_ = [(p["name"], c_type(p["shape"])) for p in self.parameters] + [
                ("saturate", ctypes.c_int), ("reference", ctypes.POINTER(Table)), ("target", ctypes.c_double * ROW)]

        class CommandC(ctypes.Structure):
            _fields_ = [("u", ctypes.c_double * _dim(self.nu)), ("u_applied", ctypes.c_double * _dim(self.nu)),
                        ("saturated", ctypes.c_int)]

        class State(ctypes.Structure):
            _fields_ = [("z", ctypes.c_double * _dim(self.nz))]

        self.MeasurementC, self.Params, self.CommandC, self.State = MeasurementC, Params, CommandC, State
        self.lib.slewbench_step.argtypes = [ctypes.c_double, ctypes.POINTER(MeasurementC), ctypes.POINTER(Params),
                                            ctypes.POINTER(CommandC), ctypes.POINTER(State)]
        self.lib.slewbench_reference_row.argtypes = [ctypes.POINTER(Table), ctypes.c_double,
                                                     ctypes.POINTER(ctypes.c_double)]

    def params(self, saturate=1, **values):
        """The parameter struct: the defaults (the scenario's numbers), some replaced."""
        params = self.Params(saturate=saturate)
        for p in self.parameters:
            value = np.asarray(values.get(p["name"], p["default"]), dtype=float)
            field = getattr(params, p["name"])
            if value.ndim == 0:
                setattr(params, p["name"], float(value))
            elif value.ndim == 1:
                field[:] = list(value)
            else:
                for i, row in enumerate(value):
                    field[i][:] = list(row)
        return params

    def table(self, label):
        """The C table of a row, and the same numbers as a ReferenceTable."""
        c_table = Table.in_dll(self.lib, self.interface["tables"][label]["table"])
        times = np.ctypeslib.as_array(c_table.times, (c_table.n,)).copy()
        rows = np.ctypeslib.as_array(c_table.rows, (c_table.n * ROW,)).reshape(c_table.n, ROW).copy()
        return c_table, ReferenceTable(times, rows, self.interface["tables"][label]["duration_s"])

    def row(self, c_table, t):
        out = (ctypes.c_double * ROW)()
        assert self.lib.slewbench_reference_row(ctypes.byref(c_table), t, out) == 0
        return np.array(out[:])

    def init(self):
        state = self.State()
        assert self.lib.slewbench_init(ctypes.byref(state)) == 0
        return state

    def step(self, t, measurement, params, state):
        m = self.MeasurementC()
        m.q[:], m.omega[:] = list(measurement.q), list(measurement.omega)
        for i in range(self.n_w):
            m.wheel_momentum[i] = measurement.wheel_momentum[i]
        if measurement.field_body is not None:
            m.field[:] = list(measurement.field_body)
        command = self.CommandC()
        status = self.lib.slewbench_step(t, ctypes.byref(m), ctypes.byref(params), ctypes.byref(command),
                                         ctypes.byref(state))
        return status, np.array(command.u[:self.nu]), np.array(command.u_applied[:self.nu]), command.saturated


@pytest.fixture(scope="module")
def build(tmp_path_factory):
    """``Built`` of a shipped scenario, generated and compiled once for the module's tests (in the
    same worker): they only read it, each ``slewbench_step`` call packing the parameters and the
    state it is given. ``horri_palmer_two_wheels.yaml`` took 44 s a test on a loaded machine."""
    cache: dict[str, Built] = {}

    def get(name: str) -> Built:
        if name not in cache:
            cache[name] = Built(name, tmp_path_factory.mktemp(Path(name).stem) / "c")
        return cache[name]

    return get


@pytest.mark.parametrize("name", ["eigenaxis_demo.yaml", "collocation_min_energy.yaml", "nano_detumble.yaml",
                                  "horri_palmer_two_wheels.yaml"])
def test_step_equals_the_python_law_then_the_simulators_saturation(name, build, rng):
    """Random measurements (rates and wheel momenta large enough to saturate some samples) on every
    exported table (and regulation): the C command, applied command, flag and controller state equal
    the Python controller followed by ActuatorModel.apply, sample after sample."""
    built = build(name)
    scenario = load(SCENARIOS / name)
    problem, spec = scenario.problem, scenario.simulation
    spacecraft = problem.spacecraft
    actuators = ActuatorModel(spacecraft, *control_layout(spacecraft))
    controller = scenario.controllers[0].controller
    references = [(None, None)] + [(label, built.table(label)) for label in built.interface["tables"]]
    has_field = problem.model.field_body is not None
    limits = [a for a in spacecraft.actuators if a.name == "wheels"]
    h_scale = float(np.min(limits[0].max_momentum)) if limits and np.all(np.isfinite(limits[0].max_momentum)) else 0.5
    saturated_seen = 0
    for label, table in references:
        controller.reset(spacecraft, spec.sample_time, target=(problem.qf, problem.omegaf))
        reference = None if table is None else TableReference(table[1], spacecraft.inertia)
        params = built.params()
        params.target[:] = list(controller.reference_rows(None, np.array([0.0]))[0])
        if table is not None:
            params.reference = ctypes.pointer(table[0])
        state = built.init()
        np.testing.assert_array_equal(state.z[:built.nz], controller.state_vector())
        # past T (the coast) and past the table's end (the last row held, in C as in TableReference)
        end = spec.sample_time * 40 if table is None else table[1].end + 5 * spec.sample_time
        for t in np.sort(rng.uniform(0.0, end, 12)):
            measurement = Measurement(float(t), quat.random_unit(rng), rng.normal(0, 0.05, 3),
                                      rng.uniform(-1.2, 1.2, spacecraft.n_wheels) * h_scale,
                                      rng.normal(0, 3e-5, 3) if has_field else None)
            status, u, applied, saturated = built.step(float(t), measurement, params, state)
            assert status == 0
            command = controller(float(t), measurement, reference)
            expected = controller.command_vector(command)
            scale = max(1.0, float(np.abs(expected).max()))
            np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12 * scale, err_msg=f"{label} t={t}")
            expected_applied, expected_flag = actuators.apply(command, measurement.wheel_momentum, spec.sample_time)
            np.testing.assert_allclose(applied, expected_applied, rtol=0, atol=1e-12 * scale, err_msg=f"{label} t={t}")
            assert bool(saturated) == expected_flag
            saturated_seen += expected_flag
            np.testing.assert_allclose(state.z[:built.nz], controller.state_vector(), rtol=0, atol=1e-12)
    assert saturated_seen > 0  # the saturation stage was exercised


def test_step_can_skip_the_saturation_and_a_law_that_bakes_its_sample_time_refuses_another(tmp_path, build, rng):
    text = (SCENARIOS / "nano_detumble.yaml").read_text()
    lines = [line for line in text.splitlines() if "name: bdot" not in line]  # TDFC alone: its delay is in samples
    (tmp_path / "tdfc.yaml").write_text("\n".join(lines) + "\n")
    built = Built(tmp_path / "tdfc.yaml", tmp_path / "d")
    assert built.interface["laws"][built.interface["step"]["law"]]["reads_parameters"] == ["gain"]
    state = built.init()
    measurement = Measurement(0.0, quat.random_unit(rng), np.full(3, 0.05), np.zeros(0), np.full(3, 2e-5))
    assert built.step(0.0, measurement, built.params(sample_time=2 * built.sample_time), state)[0] == 2  # ESAMPLE
    assert built.step(0.0, measurement, built.params(), state)[0] == 0
    built = build("eigenaxis_demo.yaml")
    state = built.init()
    measurement = Measurement(0.0, quat.random_unit(rng), np.full(3, 0.05), np.full(3, 2.0), None)
    params = built.params(saturate=0)
    params.target[:] = [1.0] + [0.0] * 12
    status, u, applied, saturated = built.step(0.0, measurement, params, state)
    assert status == 0 and saturated == 0
    np.testing.assert_array_equal(applied, u)


@pytest.mark.parametrize("name", ["eigenaxis_demo.yaml", "collocation_min_energy.yaml",
                                  "nano_natural_vs_eigenaxis.yaml", "vepa_attitude_acquisition.yaml"])
def test_c_tables_equal_the_python_interpolation_and_state_their_error_honestly(name, build, rng):
    """Every planned row: the C interpolation equals the NumPy one on the same table (at random
    times, at the nodes, beyond the ends); the stated error (seven points per interval) is what the C
    table gives against the continuous reference, recomputed here; at random times the error stays
    below twice the stated figure (the points are h/8 apart; a smooth error peaks at the midpoint)."""
    built = build(name)
    scenario = load(SCENARIOS / name)
    planners = {p.label: p for p in scenario.planners}
    assert set(built.interface["tables"]) | set(built.interface.get("skipped", {})) <= set(planners)
    for label, description in built.interface["tables"].items():
        c_table, table = built.table(label)
        reference = planners[label].planner.plan(scenario.problem)
        duration = table.end  # the closed-loop window and one sample: the coast after T
        window = scenario.simulation.duration or max(scenario.problem.duration, reference.duration)
        assert table.times[0] == 0.0 and duration == window + scenario.simulation.sample_time
        assert table.manoeuvre_duration == reference.duration == description["duration_s"]
        times = np.concatenate([rng.uniform(0, duration, 200), table.times, [-1.0, duration + 5.0]])
        python = interpolate(table.times, table.rows, times)
        c_rows = np.array([built.row(c_table, t) for t in times])
        np.testing.assert_allclose(c_rows, python, rtol=0, atol=1e-12 * max(1.0, float(np.abs(table.rows).max())))
        # The stated error, recomputed from the C table at its midpoints.
        h = np.diff(table.times)
        fractions = np.arange(1, 8) / 8  # the seven points per interval the README states
        mid = (table.times[:-1][h > 0, None] + fractions[None, :] * h[h > 0, None]).ravel()
        c_mid = np.array([built.row(c_table, t) for t in mid])
        exact = reference.sample(mid)
        angle = 2 * np.arctan2(np.linalg.norm(quat.product(quat.conjugate(exact.q), c_mid[:, 0:4])[:, 1:], axis=1),
                               np.abs(quat.product(quat.conjugate(exact.q), c_mid[:, 0:4])[:, 0]))
        error = description["error"]
        assert angle.max() == pytest.approx(error["attitude_rad"], rel=1e-6, abs=1e-14)
        assert np.abs(c_mid[:, 4:7] - exact.omega).max() == pytest.approx(error["rate_rad_s"], rel=1e-6, abs=1e-15)
        assert np.abs(c_mid[:, 10:13] - exact.torque).max() == pytest.approx(error["torque_N_m"], rel=1e-6, abs=1e-15)
        # At random times (away from the breakpoints, where the table is exact on either side).
        random = rng.uniform(0, duration, 400)
        c_random = np.array([built.row(c_table, t) for t in random])
        exact = reference.sample(random)
        assert quat.error_angle(c_random[:, 0:4], exact.q).max() <= 2 * error["attitude_rad"] + 1e-13
        assert np.abs(c_random[:, 4:7] - exact.omega).max() <= 2 * error["rate_rad_s"] + 1e-14
        assert np.abs(c_random[:, 10:13] - exact.torque).max() <= 2 * error["torque_N_m"] + 1e-14
        if error["tolerances_met"]:
            assert error["attitude_rad"] <= 1e-6


def test_the_interpolation_is_scipys_cubic_hermite_renormalised(rng):
    """An independent oracle for the NumPy twin: SciPy's CubicHermiteSpline with the kinematic
    derivatives for q (then normalised) and omega_dot for omega, np.interp for omega_dot and torque;
    on a table with a doubled node (a breakpoint)."""
    times = np.array([0.0, 0.7, 1.5, 1.5, 2.2, 3.0])
    rows = rng.normal(size=(6, ROW))
    rows[:, 0:4] = quat.continuous(quat.normalize(rows[:, 0:4]))
    t = np.concatenate([rng.uniform(0, 3.0, 300), times])
    got = interpolate(times, rows, t)
    q_dot = np.array([0.5 * quat.product(q, np.r_[0.0, w]) for q, w in zip(rows[:, 0:4], rows[:, 4:7])])
    expected = np.zeros_like(got)
    for side, (lo, hi) in (("left", (0, 3)), ("right", (3, 6))):  # the breakpoint splits the table in two
        inside = (t < 1.5) if side == "left" else (t >= 1.5)
        q = CubicHermiteSpline(times[lo:hi], rows[lo:hi, 0:4], q_dot[lo:hi])(t[inside])
        expected[inside, 0:4] = q / np.linalg.norm(q, axis=1)[:, None]
        expected[inside, 4:7] = CubicHermiteSpline(times[lo:hi], rows[lo:hi, 4:7], rows[lo:hi, 7:10])(t[inside])
        for j in range(7, 13):
            expected[inside, j] = np.interp(t[inside], times[lo:hi], rows[lo:hi, j])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def test_single_precision_builds_and_agrees_to_float_rounding(tmp_path):
    out = tmp_path / "c"
    Built("eigenaxis_demo.yaml", out)
    subprocess.run(["make", "-C", str(out), "float"], check=True, capture_output=True)
    double = subprocess.run([str(out / "example")], check=True, capture_output=True, text=True).stdout
    single = subprocess.run([str(out / "example_float")], check=True, capture_output=True, text=True).stdout

    def commands(text):
        return np.array([[float(v) for v in line.split("u =")[1].split("applied")[0].split()]
                         for line in text.splitlines() if " u =" in line])

    assert commands(double).shape == (5, 3)
    np.testing.assert_allclose(commands(single), commands(double), rtol=1e-4, atol=1e-7)


def test_a_row_that_fails_to_plan_is_skipped_with_its_reason(tmp_path, monkeypatch):
    from planners.eigenaxis import EigenaxisPlanner

    monkeypatch.setattr(EigenaxisPlanner, "plan",
                        lambda self, problem: FailedReference("eigenaxis", "solver gave up (test)"))
    out = tmp_path / "c"
    assert main(["codegen", str(SCENARIOS / "eigenaxis_demo.yaml"), "--out", str(out)]) == 0
    interface = json.loads((out / "interface.json").read_text())
    assert interface["tables"] == {} and interface["step"]["default_reference"] is None
    assert all("solver gave up (test)" in reason for reason in interface["skipped"].values())
    assert len(interface["skipped"]) == 3
    readme = (out / "README.md").read_text()
    assert "solver gave up (test)" in readme
    subprocess.run(["make", "-C", str(out)], check=True, capture_output=True)  # regulation only, still builds
    assert "regulation" in subprocess.run([str(out / "example")], check=True, capture_output=True, text=True).stdout


@pytest.mark.parametrize("name, law_reads", [
    ("eigenaxis_demo.yaml", {"sample_time", "stiffness", "damping", "inertia", "wheel_axes"}),
    ("nano_eigenaxis_pd.yaml", {"sample_time", "stiffness", "damping", "inertia", "wheel_axes"}),  # a regulator
    ("nano_detumble.yaml", {"sample_time", "gain"}),  # B-dot: K_b / T_s from both
    ("horri_palmer_two_wheels.yaml", set()),  # the two-wheel laws compile their numbers in (README says so)
])
def test_parameters_are_inputs_the_law_and_saturation_read(name, law_reads, build, rng):
    """Other gains, inertia, wheel axes, actuator limits and sample time, set in slewbench_params at
    run time (no regeneration): the C step equals the Python controller built with those options
    and reset for a spacecraft built with those numbers, followed by that spacecraft's
    ActuatorModel.apply."""
    from dataclasses import replace

    from ocp import Spacecraft
    from ocp.dynamics.actuator_kinds import Magnetorquers, ReactionWheels

    built = build(name)
    scenario = load(SCENARIOS / name)
    problem = scenario.problem
    law = built.interface["laws"][built.interface["step"]["law"]]
    reads = set(law["reads_parameters"])
    assert reads == law_reads
    controller_spec = scenario.controllers[0]
    original = problem.spacecraft
    values = {}
    inertia, sample_time = original.inertia, built.sample_time
    if "inertia" in reads:
        root = rng.normal(0, 0.2, (3, 3))
        inertia = values["inertia"] = original.inertia * 1.3 + 0.05 * (root @ root.T)
    if "sample_time" in reads:
        sample_time = values["sample_time"] = 0.7 * built.sample_time
    actuators = {}
    for actuator in original.actuators:
        if actuator.name == "wheels":  # the saturation reads the limits; the law the axes
            axes = actuator.axes
            if "wheel_axes" in reads:
                rotation = quat.rotation_matrix(quat.from_rotation_vector(rng.normal(0, 0.3, 3)))
                axes = values["wheel_axes"] = rotation @ actuator.axes
            values["wheel_max_torque"] = 0.6 * np.minimum(actuator.max_torque, 1.0)
            values["wheel_max_momentum"] = 0.5 * np.minimum(actuator.max_momentum, 5.0)
            actuators["wheels"] = ReactionWheels(axes, values["wheel_max_torque"], values["wheel_max_momentum"],
                                                 actuator.spin_inertia, actuator.failed)
        elif actuator.name == "magnetorquers":
            values["dipole_limit"] = 0.3 * actuator.control_bounds()[1]
            actuators["magnetorquers"] = Magnetorquers(values["dipole_limit"], actuator.saturation)
        else:
            actuators[actuator.name] = actuator
    spacecraft = Spacecraft(inertia, **actuators)
    changed = {}
    if {"stiffness", "damping"} <= reads:  # the gains as matrices: kp, kd of the law's options
        values["stiffness"] = rng.normal(0, 0.05, (3, 3)) + 0.3 * np.eye(3)
        values["damping"] = rng.normal(0, 0.1, (3, 3)) + 2.0 * np.eye(3)
        changed = {"kp": values["stiffness"].tolist(), "kd": values["damping"].tolist()}
    if "gain" in reads:
        values["gain"] = changed["gain"] = 1.7 * controller_spec.controller.options.gain
    controller = type(controller_spec.controller)(replace(controller_spec.controller.options, **changed))
    # Regulation to another attitude, for a law that reads its target (the two-wheel laws compile it in).
    target = quat.random_unit(rng) if problem.qf is not None and law["reads_r"] else problem.qf
    controller.reset(spacecraft, sample_time, target=(target, problem.omegaf))
    model = ActuatorModel(spacecraft, *control_layout(spacecraft))
    params = built.params(**values)
    params.target[:] = list(controller.reference_rows(None, np.array([0.0]))[0])
    state = built.init()
    saturated = 0
    has_field = problem.model.field_body is not None
    for k in range(10):
        t = k * sample_time
        measurement = Measurement(t, quat.random_unit(rng), rng.normal(0, 0.05, 3),
                                  rng.uniform(-3, 3, spacecraft.n_wheels), rng.normal(0, 3e-5, 3) if has_field else None)
        status, u, applied, flag = built.step(t, measurement, params, state)
        assert status == 0
        command = controller(t, measurement, None)
        expected = controller.command_vector(command)
        scale = max(1.0, float(np.abs(expected).max()))
        np.testing.assert_allclose(u, expected, rtol=0, atol=1e-12 * scale)
        expected_applied, expected_flag = model.apply(command, measurement.wheel_momentum, sample_time)
        np.testing.assert_allclose(applied, expected_applied, rtol=0, atol=1e-12 * scale)
        assert bool(flag) == expected_flag
        np.testing.assert_allclose(state.z[:built.nz], controller.state_vector(), rtol=0, atol=1e-12 * scale)
        saturated += expected_flag
    assert saturated > 0


def test_the_c_templates_ship_as_package_data():
    """The templates are read with importlib.resources: the wheel must hold them (pyproject's
    package-data patterns of the scenarios package match every one)."""
    import fnmatch

    import tomllib

    root = Path(__file__).resolve().parents[1]
    patterns = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["scenarios"]
    templates = sorted((root / "scenarios" / "codegen" / "templates").iterdir())
    assert {t.name for t in templates} >= {"slewbench_step.h.in", "slewbench_step.c.in", "example.c.in", "Makefile.in"}
    for template in templates:
        relative = template.relative_to(root / "scenarios").as_posix()
        assert any(fnmatch.fnmatch(relative, pattern) for pattern in patterns), relative
