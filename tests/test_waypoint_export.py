"""The Basilisk ``waypointReference`` export (``scenarios.output.basilisk``).

Oracles: a reference written in closed form whose inertial rate is worked by hand (a turn about the
inertial z axis composed with a turn about the body x axis: ``ω_N = [b cos at, b sin at, a]``,
``ω̇_N = [−ab sin at, ab cos at, 0]``), read back by a parser written from Basilisk's documented
file format (``waypointReference.rst``: header lines skipped, then ``t, attitude, ω_RN_N,
ω̇_RN_N`` split on the delimiter; MRPs turned back into Euler parameters by the textbook inverse
``β_0 = (1 − σ²)/(1 + σ²)``, ``β_v = 2σ/(1 + σ²)``); and, when Basilisk is installed, Basilisk's
own module reading the file.
"""
from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from scenarios.output.basilisk import ATTITUDE_TYPES, write_waypoint_reference

A_RATE, B_RATE = 0.07, -0.11  # rad/s: about inertial z, then about body x


class ConingReference:
    """``q(t) = [cos(at/2), 0, 0, sin(at/2)] ⊗ [cos(bt/2), sin(bt/2), 0, 0]``, worked by hand."""

    def sample(self, t: np.ndarray) -> SimpleNamespace:
        t = np.asarray(t, dtype=float)
        p0, p3 = np.cos(A_RATE * t / 2), np.sin(A_RATE * t / 2)
        r0, r1 = np.cos(B_RATE * t / 2), np.sin(B_RATE * t / 2)
        q = np.column_stack([p0 * r0, p0 * r1, p3 * r1, p3 * r0])
        a, b = A_RATE, B_RATE
        omega = np.column_stack([np.full_like(t, b), a * np.sin(b * t), a * np.cos(b * t)])  # body axes
        omega_dot = np.column_stack([np.zeros_like(t), a * b * np.cos(b * t), -a * b * np.sin(b * t)])
        return SimpleNamespace(q=q, omega=omega, omega_dot=omega_dot)


def expected_inertial(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a, b = A_RATE, B_RATE
    omega_n = np.column_stack([b * np.cos(a * t), b * np.sin(a * t), np.full_like(t, a)])
    omega_dot_n = np.column_stack([-a * b * np.sin(a * t), a * b * np.cos(a * t), np.zeros_like(t)])
    return omega_n, omega_dot_n


def parse_waypoints(path: Path, attitude_type: int, delimiter: str, header_lines: int) -> dict[str, np.ndarray]:
    """Basilisk's documented format, read independently of the writer."""
    lines = path.read_text().splitlines()[header_lines:]
    rows = [[float(field) for field in line.split(delimiter)] for line in lines if line.strip()]
    table = np.array(rows)
    width = 3 if attitude_type == 0 else 4
    assert table.shape[1] == 1 + width + 6
    attitude = table[:, 1:1 + width]
    if attitude_type == 0:
        s2 = np.sum(attitude**2, axis=1, keepdims=True)
        beta = np.hstack([(1 - s2) / (1 + s2), 2 * attitude / (1 + s2)])
    elif attitude_type == 1:
        beta = attitude
    else:
        beta = attitude[:, [3, 0, 1, 2]]
    return {"t": table[:, 0], "beta": beta, "attitude": attitude,
            "omega_n": table[:, 1 + width:4 + width], "omega_dot_n": table[:, 4 + width:7 + width]}


@pytest.mark.parametrize("attitude_type", sorted(ATTITUDE_TYPES))
@pytest.mark.parametrize("delimiter,header", [(",", True), (";", False)])
def test_round_trip_against_the_documented_format(tmp_path: Path, attitude_type: str, delimiter: str,
                                                   header: bool) -> None:
    times = np.linspace(0.0, 80.0, 161)  # turns of 320° and 504°: both MRP sets and the switch between
    written = write_waypoint_reference(ConingReference(), times, tmp_path / "wp.txt", attitude_type=attitude_type,
                                       delimiter=delimiter, header=header)
    settings = written.basilisk_settings()
    assert settings["attitudeType"] == {"mrp": 0, "quaternion": 1, "quaternion_scalar_last": 2}[attitude_type]
    assert settings["headerLines"] == (1 if header else 0) and settings["delimiter"] == delimiter
    assert settings["useReferenceFrame"] is False and written.rows == times.size
    read = parse_waypoints(written.path, settings["attitudeType"], delimiter, settings["headerLines"])
    np.testing.assert_allclose(read["t"], times, rtol=1e-15, atol=0.0)
    q = ConingReference().sample(times).q
    # the same attitude, either sign
    dot = np.abs(np.sum(read["beta"] * q, axis=1))
    np.testing.assert_allclose(dot, 1.0, atol=1e-14)
    if attitude_type == "mrp":  # the short set, as Basilisk stores it
        assert np.all(np.linalg.norm(read["attitude"], axis=1) <= 1.0 + 1e-15)
    omega_n, omega_dot_n = expected_inertial(times)
    np.testing.assert_allclose(read["omega_n"], omega_n, atol=1e-15)
    np.testing.assert_allclose(read["omega_dot_n"], omega_dot_n, atol=1e-15)


def test_mrps_are_the_short_set_of_a_hand_worked_turn(tmp_path: Path) -> None:
    """A turn by θ about z: σ = ẑ tan(θ/4), and past 180° its shadow ẑ tan((θ − 2π)/4)."""

    class Turn:
        def sample(self, t: np.ndarray) -> SimpleNamespace:
            theta = 0.05 * t
            zeros = np.zeros_like(t)
            q = np.column_stack([np.cos(theta / 2), zeros, zeros, np.sin(theta / 2)])
            return SimpleNamespace(q=q, omega=np.column_stack([zeros, zeros, np.full_like(t, 0.05)]),
                                   omega_dot=np.zeros((t.size, 3)))

    times = np.arange(0.0, 120.0, 1.0)  # up to 5.95 rad
    read = parse_waypoints(write_waypoint_reference(Turn(), times, tmp_path / "turn.txt").path, 0, ",", 1)
    theta = 0.05 * times
    expected = np.where(theta <= math.pi, np.tan(theta / 4), np.tan((theta - 2 * math.pi) / 4))
    np.testing.assert_allclose(read["attitude"][:, 2], expected, atol=1e-15)
    np.testing.assert_allclose(read["attitude"][:, :2], 0.0, atol=0.0)


def test_times_read_back_on_their_nanosecond(tmp_path: Path) -> None:
    """Basilisk reads ``(uint64_t)(stod(field) * 1e9)``: 1.001 s would truncate to 1 000 999 999 ns."""
    times = np.arange(1, 2001) * 0.001
    assert any(int(t * 1e9) != round(t * 1e9) for t in times)  # the trap is real on this grid
    read = parse_waypoints(write_waypoint_reference(ConingReference(), times, tmp_path / "ns.txt").path, 0, ",", 1)
    assert [int(t * 1e9) for t in read["t"]] == [round(t * 1e9) for t in times]


@pytest.mark.parametrize("times,words", [([0.0], "at least two"), ([0.0, 1.0, 1.0], "strictly increasing"),
                                         ([-1.0, 1.0], "non-negative"), ([0.0, np.nan], "finite")])
def test_bad_times_are_refused(tmp_path: Path, times: list[float], words: str) -> None:
    with pytest.raises(ValueError, match=words):
        write_waypoint_reference(ConingReference(), times, tmp_path / "bad.txt")


@pytest.mark.parametrize("kwargs,words", [({"attitude_type": "euler"}, "attitude_type"),
                                          ({"delimiter": "e"}, "delimiter"), ({"delimiter": ", "}, "delimiter")])
def test_bad_settings_are_refused(tmp_path: Path, kwargs: dict[str, str], words: str) -> None:
    with pytest.raises(ValueError, match=words):
        write_waypoint_reference(ConingReference(), [0.0, 1.0], tmp_path / "bad.txt", **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize("attitude_type", sorted(ATTITUDE_TYPES))
def test_basilisk_reads_the_file(tmp_path: Path, attitude_type: str) -> None:
    """Basilisk's own module, sampled at the waypoints, gives the hand-worked reference back."""
    pytest.importorskip("Basilisk", reason="Basilisk (PyPI bsk, the 'basilisk' extra) is not installed")
    from Basilisk.fswAlgorithms import waypointReference
    from Basilisk.utilities import SimulationBaseClass, macros

    step = 0.5
    times = np.arange(0.0, 60.0 + step / 2, step)
    written = write_waypoint_reference(ConingReference(), times, tmp_path / "wp.txt", attitude_type=attitude_type)
    sim = SimulationBaseClass.SimBaseClass()
    sim.CreateNewProcess("p").addTask(sim.CreateNewTask("task", macros.sec2nano(step)))
    module = waypointReference.WaypointReference()
    module.ModelTag = "waypoints"
    for name, value in written.basilisk_settings().items():
        setattr(module, name, value)
    sim.AddModelToTask("task", module)
    recorder = module.attRefOutMsg.recorder()
    sim.AddModelToTask("task", recorder)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(times[-1]))
    sim.ExecuteSimulation()
    np.testing.assert_allclose(recorder.times() * 1e-9, times, atol=1e-12)
    sigma = np.asarray(recorder.sigma_RN)
    s2 = np.sum(sigma**2, axis=1, keepdims=True)
    beta = np.hstack([(1 - s2) / (1 + s2), 2 * sigma / (1 + s2)])
    q = ConingReference().sample(times).q
    np.testing.assert_allclose(np.abs(np.sum(beta * q, axis=1)), 1.0, atol=1e-13)
    omega_n, omega_dot_n = expected_inertial(times)
    np.testing.assert_allclose(np.asarray(recorder.omega_RN_N), omega_n, atol=1e-15)
    np.testing.assert_allclose(np.asarray(recorder.domega_RN_N), omega_dot_n, atol=1e-15)


def test_export_of_a_run_directory_is_each_reference_at_the_controllers_samples(tmp_path: Path) -> None:
    """``slewbench run --export basilisk`` and ``slewbench export RUN_DIR --format basilisk``: one
    file per planner row, equal (read back by the documented format) to the reference itself
    sampled at the closed loop's times, its rates turned to inertial axes by SciPy; the
    settings file names what reads each file; bad options exit 2 and write nothing."""
    import json

    from scipy.spatial.transform import Rotation

    from scenarios import load, run
    from scenarios.cli.commands import main

    scenario = Path(__file__).resolve().parents[1] / "scenarios" / "eigenaxis_demo.yaml"
    out = tmp_path / "demo"
    assert main(["run", str(scenario), "--out", str(out), "--no-plots", "--export", "basilisk"]) == 0
    exported = tmp_path / "demo-basilisk"
    settings = json.loads((exported / "waypoints.json").read_text())
    results = run(load(scenario))
    assert sorted(settings) == sorted(f"{stem}.waypoints.csv" for stem in ("smooth", "bang-coast-bang", "min-time"))
    for row in results.rows:
        name = f"{row.label}.waypoints.csv"
        entry = settings[name]
        assert (entry["attitudeType"], entry["delimiter"], entry["useReferenceFrame"]) == (0, ",", False)
        read = parse_waypoints(exported / name, 0, ",", entry["headerLines"])
        t = row.simulation.t
        np.testing.assert_allclose(read["t"], t, rtol=0, atol=1e-15)
        sample = row.reference.sample(t)
        q = np.where(sample.q[:, :1] < 0, -sample.q, sample.q)  # the short set's sign
        np.testing.assert_allclose(read["beta"], q, rtol=0, atol=1e-12)
        rotation = Rotation.from_quat(sample.q[:, [1, 2, 3, 0]])  # body to inertial, SciPy scalar last
        np.testing.assert_allclose(read["omega_n"], rotation.apply(sample.omega), rtol=0, atol=1e-14)
        np.testing.assert_allclose(read["omega_dot_n"], rotation.apply(sample.omega_dot), rtol=0, atol=1e-14)
    again = tmp_path / "again"
    assert main(["export", str(out), "--format", "basilisk", "--out", str(again),
                 "--option", "attitude_type=quaternion", "--option", "delimiter=;"]) == 0
    read = parse_waypoints(again / "smooth.waypoints.csv", 1, ";", 1)
    first = parse_waypoints(exported / "smooth.waypoints.csv", 0, ",", 1)
    np.testing.assert_allclose(read["beta"] * np.sign(read["beta"][:, :1]), first["beta"], rtol=0, atol=1e-12)
    assert main(["export", str(out), "--format", "basilisk", "--out", str(tmp_path / "bad"),
                 "--option", "delimiter=."]) == 2
    assert not (tmp_path / "bad").exists()


def test_a_run_without_a_planner_row_is_refused_not_exported_as_an_empty_settings_file(tmp_path: Path,
                                                                                      capsys: pytest.CaptureFixture
                                                                                      ) -> None:
    """``planners: []`` (regulation rows, no reference): ``export --format basilisk`` wrote an empty
    ``waypoints.json`` ({}) and said 'wrote DIR/: waypoints.json', exit 0; ``run --export basilisk``
    ran and did the same. Now both exit 2 before writing, saying why."""
    import yaml

    from scenarios.cli.commands import main

    data = yaml.safe_load((Path(__file__).resolve().parents[1] / "scenarios" / "eigenaxis_demo.yaml").read_text())
    data["planners"] = []
    data["simulation"]["duration"] = 20.0
    scenario = tmp_path / "regulation.yaml"
    scenario.write_text(yaml.safe_dump(data))
    out = tmp_path / "run"
    assert main(["run", str(scenario), "--out", str(out), "--no-plots", "--export", "basilisk"]) == 2
    assert "`--export basilisk` writes each planner row's reference, and the scenario has no planner" \
        in capsys.readouterr().err
    assert not out.exists() and not (tmp_path / "run-basilisk").exists()
    assert main(["run", str(scenario), "--out", str(out), "--no-plots"]) == 0
    capsys.readouterr()
    assert main(["export", str(out), "--format", "basilisk", "--out", str(tmp_path / "b")]) == 2
    error = capsys.readouterr().err
    assert (f"--format basilisk: the run in {out} has no simulated planner row ('augmented_quaternion_feedback': "
            "regulation, no reference): a waypoint file holds a planner's reference; nothing to export") in error, error
    assert not (tmp_path / "b").exists()
