"""With an estimator in the loop, the knowledge error over time is in ``timeseries/<row>.csv``
(``known_q0..3``, ``knowledge_error_deg``) and drawn in the row figures (PNG and report.html), not
only as the two scalars of the results.

Oracles: the sensor state's documented layout (:mod:`ocp.estimation.loop`: ``q̂`` at indices 3-6 of
the state after sample k, what the controller was given at t_k), and the angle between two unit
quaternions written here, ``2 atan2(‖vec(q̂* ⊗ q)‖, |scalar(q̂* ⊗ q)|)``.
"""
from __future__ import annotations

import csv
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import scenarios
from scenarios.output.plot_data import row_series
from scenarios.output.plots import RowFigure
from scenarios.output.report.figures import row_figure
from scenarios.output.writer import write_timeseries

REPO = Path(__file__).resolve().parents[1]


def angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation angle between unit quaternions (scalar first), row by row, written out."""
    w1, v1 = a[:, 0], a[:, 1:]
    w2, v2 = b[:, 0], b[:, 1:]
    scalar = w1 * w2 + np.sum(v1 * v2, axis=1)  # scalar part of conj(a) ⊗ b
    vector = w1[:, None] * v2 - w2[:, None] * v1 - np.cross(v1, v2)
    return np.rad2deg(2.0 * np.arctan2(np.linalg.norm(vector, axis=1), np.abs(scalar)))


@pytest.fixture(scope="module")
def estimated():
    results = scenarios.run(scenarios.load(REPO / "scenarios" / "spin_repoint_estimator.yaml"))
    return results, results.rows[0]


def read(path: Path) -> dict[str, np.ndarray]:
    with path.open(newline="") as handle:
        lines = list(csv.reader(handle))
    return {name: np.array([float(line[i]) if line[i] else np.nan for line in lines[1:]])
            for i, name in enumerate(lines[0])}


def test_the_csv_has_the_knowledge_error_over_time(estimated, tmp_path):
    _, row = estimated
    sim = row.simulation
    path = tmp_path / "row.csv"
    write_timeseries(row, path)
    table = read(path)
    names = ["known_q0", "known_q1", "known_q2", "known_q3", "knowledge_error_deg"]
    assert all(name in table for name in names)
    known = np.stack([table[f"known_q{i}"] for i in range(4)], axis=1)
    true = np.stack([table[f"q{i}"] for i in range(4)], axis=1)
    # what the controller was given at t_0 ... t_(N-1), blank at the final time
    np.testing.assert_array_equal(known[:-1], sim.sensor_state[1:, 3:7])
    assert np.all(np.isnan(known[-1])) and np.isnan(table["knowledge_error_deg"][-1])
    error = table["knowledge_error_deg"][:-1]
    np.testing.assert_allclose(error, angle_deg(known[:-1], true[:-1]), rtol=1e-9, atol=1e-12)
    # the two scalars of the results are that column's largest and last values
    metrics = row.closed_loop_metrics
    assert error.max() == pytest.approx(metrics["max_knowledge_error_deg"], rel=1e-12)
    assert error[-1] == pytest.approx(metrics["final_knowledge_error_deg"], rel=1e-12)
    # a star tracker at 5 arcsec and a MEKF: the knowledge error stays well under a tenth of a degree
    assert 0.0 < error.max() < 0.1


def test_without_a_star_tracker_the_columns_are_absent(tmp_path):
    t = np.arange(3.0)
    sim = SimpleNamespace(t=t, x=np.hstack([np.tile([1.0, 0, 0, 0], (3, 1)), np.zeros((3, 3))]),
                          q=np.tile([1.0, 0, 0, 0], (3, 1)), wheel_momentum=np.zeros((3, 0)),
                          applied_torque=np.zeros((2, 3)), sensors=None, sensor_state=None)
    path = tmp_path / "row.csv"
    write_timeseries(SimpleNamespace(label="r", simulation=sim, reference=None), path)  # type: ignore[arg-type]
    header = path.read_text().splitlines()[0].split(",")
    assert not any(name.startswith(("known_", "knowledge")) for name in header)


def test_the_row_figures_draw_the_knowledge_error(estimated):
    results, row = estimated
    sim = row.simulation
    expected = angle_deg(sim.sensor_state[1:, 3:7], np.asarray(sim.q)[:-1])
    problem = results.scenario.problem
    series = row_series(row, problem.qf, problem.spacecraft)
    figure = RowFigure(*series.shape)
    figure.prepare(series)
    (line,) = [item for item in figure.panels["error"].get_lines() if item.get_label() == "knowledge"]
    t, values = (np.asarray(v, dtype=float) for v in line.get_data())
    index = np.searchsorted(sim.t, t)
    np.testing.assert_allclose(values, expected[index], rtol=1e-9)
    assert values.max() == pytest.approx(expected.max(), rel=1e-12)  # decimation keeps the peak
    html = row_figure(row, results.scenario)
    (trace,) = [trace for trace in html["data"] if trace["name"] == "knowledge error"]
    y = np.asarray(trace["y"], dtype=float)
    assert trace["yaxis"] == "y1" and y.max() == pytest.approx(expected.max(), rel=1e-12)
