"""``slewbench table``: entries against closed forms and direct solves, the files, the fit, the CLI.

Oracles: the single-axis bang-bang T = 2 √(θ J / u) (one working wheel about a principal axis of a
spherical body: a double integrator); Bilimoria & Wie's published 3.2431 s; a direct collocation
call outside the engine; analytic slew-time functions for the fit (not the fit itself); quaternion
products from :mod:`ocp.quat` for the convention; ``scipy.io.netcdf_file`` reading the file back.
"""
from __future__ import annotations

import json
import math
import time
import timeit
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import yaml

from ocp import Spacecraft, Torquers, quat
from planners import PLANNERS, ManeuverProblem
from scenarios.cli.commands import main
from scenarios.slewtable.compute import SlewTable, TablePart, compute_table, fit_entries
from scenarios.slewtable.files import STATUS_CODES, write_table_files
from scenarios.slewtable.fit import SlewTimeFit, load_fit, zonotope_facets
from scenarios.slewtable.grid import fibonacci_axes, offset_axes, polytope_grid
from scenarios.slewtable.spec import parse_table_spec
from scenarios.study import engine

BILIMORIA_WIE = 3.2431  # s: unit inertia, |u_i| <= 1 N m, 180 deg about x (J. Guid. Control Dyn. 16(3), 1993)

SPHERE_ONE_WHEEL = {
    "name": "sphere-one-wheel",
    "spacecraft": {"inertia": [2.0, 2.0, 2.0], "wheels": {"max_torque": 0.1, "failed": [1, 2]}},
    "maneuver": {"duration": 40.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis"}],
    "controller": {"name": "augmented_quaternion_feedback"},
}

UNIT_BOX = {
    "name": "bilimoria-wie",
    "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0}},
    "maneuver": {"duration": 10.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "collocation"}],
    "controller": {"name": "augmented_quaternion_feedback"},
}


def _write(folder: Path, name: str, data: dict) -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data))
    return path


def _table(tmp_path: Path, scenario: dict, table: dict) -> SlewTable:
    scenario_file = _write(tmp_path, "scenario.yaml", scenario)
    spec_file = _write(tmp_path, "table.yaml", {"table": {"scenario": scenario_file.name, **table}})
    spec = parse_table_spec(spec_file)
    with ThreadPoolExecutor(1) as executor:
        return compute_table(spec, executor=executor)


# --- entries against oracles ---------------------------------------------------------------------

def test_one_working_wheel_gives_the_single_axis_bang_bang(tmp_path):
    # Spherical J = 2 kg m², the y and z wheels failed, u_max = 0.1 N m about x: the slew about x is a
    # double integrator, T = 2 √(θ J / u_max); 90 deg: 11.2100 s, 30 deg: 6.4721 s. The eigenaxis
    # start is that optimum: one start is enough (multistart 0 keeps the test fast).
    table = _table(tmp_path, SPHERE_ONE_WHEEL, {"axes": [[1, 0, 0]], "angles_deg": [30, 90],
                                                "planner_options": {"multistart": 0}})
    part = table.parts["table"]
    assert part.status == [["ok", "ok"]], part.message
    for k, angle in enumerate((30.0, 90.0)):
        expected = 2.0 * math.sqrt(math.radians(angle) * 2.0 / 0.1)
        assert part.slew_time_s[0, k] == pytest.approx(expected, rel=1e-6)
    assert table.fit is None and "4 or more" in table.fit_note  # one axis: no fit over the sphere


def test_bilimoria_wie_entry_matches_the_published_optimum_and_a_direct_solve(tmp_path):
    table = _table(tmp_path, UNIT_BOX, {"axes": [[1, 0, 0]], "angles_deg": [90, 180]})
    part = table.parts["table"]
    assert part.status[0][1] == "ok", part.message[0][1]
    assert part.slew_time_s[0, 1] == pytest.approx(BILIMORIA_WIE, abs=2e-4)
    problem = ManeuverProblem(Spacecraft([1.0, 1.0, 1.0], torquers=Torquers(1.0)), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle([1, 0, 0], math.radians(90)), 10.0, omegaf=np.zeros(3))
    direct = PLANNERS["collocation"]({"objective": "min_time"}).plan(problem)
    assert direct.ok
    assert part.slew_time_s[0, 0] == pytest.approx(direct.duration, rel=1e-6)
    assert part.objective_value[0, 0] == part.slew_time_s[0, 0]
    assert part.plan_time_s[0, 0] > 0


def test_min_energy_entry_meets_the_double_integrator_closed_form(tmp_path):
    # Rest to rest in T about the one working wheel's axis, bounds inactive: ∫u² dt = 12 J² θ² / T³.
    table = _table(tmp_path, SPHERE_ONE_WHEEL, {"axes": [[1, 0, 0]], "angles_deg": [15, 30], "objective": "min_energy",
                                                "duration": 20.0, "planner_options": {"multistart": 0}})
    part = table.parts["table"]
    assert part.status == [["ok", "ok"]], part.message
    for k, angle in enumerate((15.0, 30.0)):
        assert part.objective_value[0, k] == pytest.approx(12 * 2.0 ** 2 * math.radians(angle) ** 2 / 20.0 ** 3, rel=1e-4)
        assert part.slew_time_s[0, k] == pytest.approx(20.0)
    assert table.fit is None and "min_energy" in table.fit_note


def test_a_window_longer_than_100_s_is_tabulated(tmp_path):
    # The closed loop that completes each row takes two samples of half the window: with the default
    # 0.05 s RK4 sub-step a 500 s window was refused (more than 1000 sub-steps per sample). The entry
    # still meets the double integrator's 12 J² θ² / T³.
    table = _table(tmp_path, SPHERE_ONE_WHEEL, {"axes": [[1, 0, 0]], "angles_deg": [15, 30], "objective": "min_energy",
                                                "duration": 500.0, "planner_options": {"multistart": 0}})
    part = table.parts["table"]
    assert part.status == [["ok", "ok"]], part.message
    for k, angle in enumerate((15.0, 30.0)):
        assert part.objective_value[0, k] == pytest.approx(12 * 2.0 ** 2 * math.radians(angle) ** 2 / 500.0 ** 3,
                                                           rel=1e-4)


def test_a_failed_solve_is_an_entry_with_its_status(tmp_path):
    # The duration bound 8 s admits 30 deg (6.47 s) but not 90 deg (11.21 s): that entry is
    # infeasible (collocation's minimum time with the bound released is above 8 s; until 2026-12-04
    # it was failed), the table goes on and keeps the planner's message.
    scenario = dict(SPHERE_ONE_WHEEL, maneuver=dict(SPHERE_ONE_WHEEL["maneuver"], duration=8.0))
    table = _table(tmp_path, scenario, {"axes": [[1, 0, 0]], "angles_deg": [30, 90],
                                        "planner_options": {"max_iterations": 40, "multistart": 0}})
    part = table.parts["table"]
    assert part.status == [["ok", "infeasible"]], part.message
    assert part.ok.tolist() == [[True, False]]
    assert np.isnan(part.slew_time_s[0, 1]) and "did not converge" in part.message[0][1]


# --- the fit against analytic slew times ---------------------------------------------------------

INERTIA = np.diag([10.0, 8.0, 6.0])


def analytic_time(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """The eigenaxis bang-bang time under |τ_i| <= 1 (kinks where the bounding axis changes),
    times a smooth factor over the sphere and in angle."""
    axes = np.atleast_2d(axes)
    s = np.max(np.abs(axes @ INERTIA), axis=1)
    return 2.0 * np.sqrt(angles * s) * (1 + 0.1 * axes[:, 0] * axes[:, 1] + 0.05 * axes[:, 2] ** 2) * (1 + 0.02 * angles)


def analytic_fit(n_axes: int = 80) -> SlewTimeFit:
    angles = np.deg2rad([10, 30, 60, 90, 120, 150, 180])
    axes = fibonacci_axes(n_axes)
    times = np.array([analytic_time(np.tile(a, (len(angles), 1)), angles) for a in axes])
    return SlewTimeFit(angles, axes, times, inertia=INERTIA, generators=np.eye(3))


def test_fit_reproduces_the_grid_and_meets_the_held_out_error():
    fit = analytic_fit()
    axes = np.repeat(fit.axes, len(fit.angles), axis=0)
    angles = np.tile(fit.angles, len(fit.axes))
    np.testing.assert_allclose(fit.many_axis_angle(axes, angles), fit.times.ravel(), rtol=1e-12)
    held_axes = offset_axes(50)
    held_angles = np.deg2rad([20, 45, 75, 105, 135, 165])
    axes, angles = np.repeat(held_axes, len(held_angles), axis=0), np.tile(held_angles, len(held_axes))
    relative = np.abs(fit.many_axis_angle(axes, angles) / analytic_time(axes, angles) - 1.0)
    assert relative.max() <= 0.01
    scalar = [fit.axis_angle(*a, t) for a, t in zip(axes.tolist(), angles.tolist())]
    np.testing.assert_allclose(scalar, fit.many_axis_angle(axes, angles), rtol=1e-12)
    assert fit.axis_angle(1.0, 0.0, 0.0, 0.0) == 0.0


def test_fit_follows_the_body_frame_convention():
    # q body -> inertial: a rotation about body x from q0 is qf = q0 ⊗ q_x; about inertial x it is
    # qf = q_x ⊗ q0, whose body axis is R(q0)ᵀ x.
    fit = analytic_fit()
    q0 = quat.from_axis_angle([0.3, -0.5, 0.8], 1.3)
    theta = math.radians(110.0)
    q_x = quat.from_axis_angle([1, 0, 0], theta)
    body = fit(q0, quat.product(q0, q_x))
    assert body == pytest.approx(float(analytic_time(np.array([1.0, 0, 0]), np.array([theta]))[0]), rel=0.01)
    assert body == pytest.approx(fit.axis_angle(1.0, 0.0, 0.0, theta), rel=1e-12)
    inertial_axis = quat.rotate_inverse(q0, [1.0, 0.0, 0.0])
    inertial = fit(tuple(q0.tolist()), tuple(quat.product(q_x, q0).tolist()))
    assert inertial == pytest.approx(float(analytic_time(inertial_axis, np.array([theta]))[0]), rel=0.01)
    assert abs(inertial / body - 1.0) > 0.05  # the two readings differ on this body
    # the short way: -qf is the same attitude
    assert fit(q0, -quat.product(q0, q_x)) == pytest.approx(body, rel=1e-12)
    many = fit.slew_time_many(np.array([q0, q0]), np.array([quat.product(q0, q_x), quat.product(q_x, q0)]))
    np.testing.assert_allclose(many, [body, inertial], rtol=1e-12)


def test_fit_round_trips_through_fit_json(tmp_path):
    fit = analytic_fit(20)
    fit.save(tmp_path / "fit.json")
    loaded = load_fit(tmp_path)
    q0, qf = quat.from_axis_angle([1, 2, 3], 0.4), quat.from_axis_angle([-1, 0, 2], 2.0)
    assert loaded(q0, qf) == fit(q0, qf)
    with pytest.raises(ValueError, match="not a slewbench slew-time fit"):
        (tmp_path / "other.json").write_text(json.dumps({"format": "x"}))
        load_fit(tmp_path / "other.json")


@pytest.mark.parametrize("bad, error, words", [
    ([1.0, 1.0, 0.0, 0.0], ValueError, r"qf must be a unit quaternion .*norm 1\.414"),
    (np.zeros(4), ValueError, "qf must be a unit quaternion"),
    ([math.nan, 0.0, 0.0, 1.0], ValueError, "norm nan"),
    ("abcd", TypeError, "qf must be 4 numbers"),
    ([1.0, 0.0, 0.0], TypeError, "4 numbers"),
])
def test_fit_refuses_what_is_not_a_unit_quaternion(bad, error, words):
    """Not silently a slew time: a zero quaternion read as the identity gave 0 s, [1, 1, 0, 0] a time."""
    fit = analytic_fit(20)
    with pytest.raises(error, match=words):
        fit([1.0, 0.0, 0.0, 0.0], bad)
    with pytest.raises(error):
        fit.slew_time_many(np.array([[1.0, 0.0, 0.0, 0.0]]), np.array([bad], dtype=object if error is TypeError else float))
    # a quaternion within the scenario files' tolerance (1e-2) is accepted: the relative axis and
    # angle do not depend on its norm
    q = quat.from_axis_angle([1, 2, 3], 0.9)
    assert fit([1.0, 0.0, 0.0, 0.0], 1.005 * q) == pytest.approx(fit([1.0, 0.0, 0.0, 0.0], q), rel=1e-12)


@pytest.mark.slow
def test_fit_evaluates_within_ten_microseconds():
    fit = analytic_fit()
    q0, qf = tuple(quat.from_axis_angle([0.3, 0.2, 0.9], 0.7).tolist()), tuple(quat.from_axis_angle([1, 2, 3], 1.1).tolist())
    # CPU time, not wall time: the machine running the tests may be shared
    per_call = sorted(timeit.repeat(lambda: fit(q0, qf), timer=time.process_time, number=5000, repeat=9))[4] / 5000
    assert per_call <= 10e-6


def _ridged_time(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Like Bilimoria & Wie's box: the eigenaxis time where two axes limit at once (a ridge, with a
    kink, on the planes |J_i e_i| = |J_j e_j|), shorter between them."""
    axes = np.atleast_2d(axes)
    loads = np.sort(np.abs(axes @ INERTIA), axis=1)
    s = loads[:, 2]
    return 2.0 * np.sqrt(angles * s) * (1.0 - 0.1 * (s - loads[:, 1]) / s) * (1 + 0.02 * angles)


def test_polytope_grid_covers_the_sphere_once_without_crossing_a_kink():
    facets = zonotope_facets(np.eye(3)) @ INERTIA
    axes, triangles = polytope_grid(facets, 50)
    assert len(axes) == 50
    inverses = np.linalg.inv(np.stack([axes[t].T for t in triangles]))
    directions = np.random.default_rng(1).normal(size=(4000, 3))
    inside = np.all(np.einsum("tij,nj->nti", inverses, directions) >= -1e-12, axis=2)
    assert np.all(inside.sum(axis=1) == 1)
    for triangle in triangles:  # every vertex is limited by the facet limiting the triangle's centre
        loads = np.abs(axes[triangle] @ facets.T)
        centre = int(np.argmax(np.abs(axes[triangle].mean(axis=0) @ facets.T)))
        assert np.all(loads[:, centre] >= loads.max(axis=1) * (1 - 1e-9))


def test_fit_on_the_polytope_grid_follows_kinks_that_a_lattice_misses():
    angles = np.deg2rad([10, 30, 60, 90, 120, 150, 180])
    held_axes, held_angles = offset_axes(60), np.deg2rad([20, 45, 75, 105, 135, 165])
    axes, theta = np.repeat(held_axes, len(held_angles), axis=0), np.tile(held_angles, len(held_axes))
    errors = {}
    for name, (grid, triangles) in {"polytope": polytope_grid(zonotope_facets(np.eye(3)) @ INERTIA, 110),
                                    "fibonacci": (fibonacci_axes(110), None)}.items():
        times = np.array([_ridged_time(np.tile(a, (len(angles), 1)), angles) for a in grid])
        fit = SlewTimeFit(angles, grid, times, inertia=INERTIA, generators=np.eye(3), triangles=triangles)
        errors[name] = np.max(np.abs(fit.many_axis_angle(axes, theta) / _ridged_time(axes, theta) - 1.0))
    assert errors["polytope"] <= 0.01 < errors["fibonacci"]


def test_fit_entries_keeps_entries_that_are_not_ok_as_gaps():
    """Not filled along the axis, nor the axis left out (its neighbours' times then covered it):
    the fit has no time in the cells that use such an entry (tests/test_slewtable_gaps.py)."""
    fit = analytic_fit(12)
    part = TablePart.empty(fit.axes, list(np.rad2deg(fit.angles)))
    part.slew_time_s[:] = fit.times
    part.status = [["ok"] * len(fit.angles) for _ in fit.axes]
    part.status[0] = ["failed"] * len(fit.angles)
    part.status[1][2] = "failed"
    part.slew_time_s[1, 2] = np.nan
    refit, note = fit_entries(part, INERTIA, np.eye(3))
    assert refit is not None and len(refit.axes) == len(fit.axes)
    assert "8 entries not ok (0 infeasible): the fit gives NaN in the cells around them" in note
    assert np.isnan(refit.axis_angle(*fit.axes[0], fit.angles[3]))
    assert np.isnan(refit.axis_angle(*fit.axes[1], 0.5 * (fit.angles[1] + fit.angles[2])))
    far = -fit.axes[0]  # the cells there use neither axis 0 nor axis 1
    assert refit.axis_angle(*far, 2.0) == pytest.approx(fit.axis_angle(*far, 2.0), rel=1e-12)


# --- files -------------------------------------------------------------------------------------

def _synthetic_table(tmp_path: Path) -> SlewTable:
    spec = parse_table_spec(_write(tmp_path, "box.yaml", UNIT_BOX),
                            {"axes": 12, "grid": "fibonacci", "angles": "45,90,180", "held-out": 4})
    fit = analytic_fit(12)
    table = SlewTable(spec, {"table": TablePart.empty(spec.axes, spec.angles_deg),
                             "held_out": TablePart.empty(spec.held_out_axes, spec.held_out_angles_deg)})
    part = table.parts["table"]
    part.slew_time_s[:] = analytic_time(np.repeat(spec.axes, 3, 0), np.tile(np.deg2rad(spec.angles_deg), 12)).reshape(12, 3)
    part.objective_value[:] = part.slew_time_s
    part.status = [["ok"] * 3 for _ in range(12)]
    part.status[3][1] = "failed"
    part.status[5][2] = "infeasible"  # was written as "crashed"
    table.fit = fit
    return table


def test_netcdf_reads_back_with_dimensions_units_and_attributes(tmp_path):
    from scipy.io import netcdf_file
    table = _synthetic_table(tmp_path)
    written = write_table_files(table, tmp_path, plots=False)
    assert written == ["slew_table.csv", "slew_table.nc", "fit.json"]
    with netcdf_file(tmp_path / "slew_table.nc", "r", mmap=False) as nc:
        assert nc.dimensions["axis"] == 12 and nc.dimensions["angle"] == 3
        assert nc.dimensions["held_out_axis"] == 4 and nc.dimensions["held_out_angle"] == 5
        time_var = nc.variables["slew_time"]
        assert time_var.dimensions == ("axis", "angle")
        assert time_var.units == b"s" and time_var.long_name
        assert nc.variables["angle"].units == b"degree"
        np.testing.assert_array_equal(nc.variables["angle"][:], [45.0, 90.0, 180.0])
        np.testing.assert_allclose(nc.variables["slew_time"][:], table.parts["table"].slew_time_s)
        np.testing.assert_allclose(nc.variables["axis_x"][:], table.spec.axes[:, 0])
        assert nc.variables["status"][3, 1] == STATUS_CODES.index("failed")
        meanings = nc.variables["status"].flag_meanings.decode().split()
        assert meanings[nc.variables["status"][5, 2]] == "infeasible"
        assert meanings[:5] == ["ok", "violated", "failed", "crashed", "missing"]  # the earlier codes kept
        assert nc.variables["held_out_status"][0, 0] == STATUS_CODES.index("missing")
        assert nc.scenario == b"bilimoria-wie" and nc.objective == b"min_time"
        assert json.loads(nc.spacecraft)["inertia"] == [1.0, 1.0, 1.0]
        assert nc.slewbench_version and nc.date_created
    rows = (tmp_path / "slew_table.csv").read_text().splitlines()
    assert rows[0].startswith("grid,axis_x,axis_y,axis_z,angle_deg,slew_time_s,objective")
    assert len(rows) == 1 + 12 * 3 + 4 * 5  # held-out: the 3 table angles and their 2 midpoints


# --- the command line ----------------------------------------------------------------------------

@pytest.mark.parametrize(("flags", "where"), [
    (["--angles", "0,90"], "--angles"),
    (["--angles", "ten"], "--angles"),
    (["--angles", "30,,90"], "--angles: item 2 of '30,,90' is empty"),  # not dropped: a typo for 30,60,90?
    (["--angles", ",30,90"], "--angles: item 1 of ',30,90' is empty"),
    (["--angles", "-10,90"], "--angles: item 1: -10 is outside (0, 180]"),  # checked, not read as an option
    (["--check-angles", "-5,30", "--tolerance", "0.01"], "--check-angles"),  # a list: argparse read it as an option
    (["--check-angles", "30,,90", "--tolerance", "0.01", "--max-entries", "1"],  # 1: no table computed before
     "--check-angles: item 2 of '30,,90' is empty"),
    (["--axes", "many"], "--axes"),
    (["--axes", "[[1,0,0]]"], "--axes: expected a whole number of axes from 1 to 10000 (e.g. --axes 40; to give "
                              "the axes themselves, list them at table.axes in a table file), got '[[1,0,0]]'"),
    (["--axes", "-1"], "--axes: expected a number of axes from 1 to 10000, got -1"),  # as the YAML form says
    (["--duration", "5"], "--duration"),
    (["--objective", "min_energy"], "--duration"),
    (["--objective", "fastest"], "--objective"),
    (["--grid", "icosahedral"], "--grid"),
    (["--held-out", "-1"], "--held-out"),
    (["--scheduler", "tcp://127.0.0.1:1"], "--scheduler"),  # nobody listens: nothing is claimed
])
def test_bad_options_exit_2_naming_the_option(tmp_path, capsys, monkeypatch, flags, where):
    # a closed port: Dask's connect retries until the handshake timeout (10 s), which only the
    # connection attempt (as in tests/test_study_errors_name_the_file.py) needs, not its length
    monkeypatch.setattr(engine, "HANDSHAKE_TIMEOUT_S", 0.5)
    scenario = _write(tmp_path, "box.yaml", UNIT_BOX)
    assert main(["table", str(scenario), "--out", str(tmp_path / "out"), *flags]) == 2
    assert where in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("table", "where"), [
    ({"axes": "many"}, "table.axes"),
    ({"axes": [[0, 0, 0]]}, "table.axes[0]"),
    ({"angles_deg": [10, 200]}, "table.angles_deg"),
    ({"bogus": 1}, "table.bogus"),
    ({"planner_options": {"intervals": "lots"}}, "table.planner_options.intervals"),
    ({"execution": {"workers": 0}}, "table.execution.workers"),
])
def test_bad_table_file_exits_2_naming_the_yaml_path(tmp_path, capsys, table, where):
    _write(tmp_path, "box.yaml", UNIT_BOX)
    spec = _write(tmp_path, "table.yaml", {"table": {"scenario": "box.yaml", **table}})
    assert main(["table", str(spec), "--out", str(tmp_path / "out")]) == 2
    assert where in capsys.readouterr().err


def test_bad_scenario_exits_2_naming_its_path(tmp_path, capsys):
    bad = dict(UNIT_BOX, spacecraft={"inertia": [1.0, -1.0, 1.0], "torquers": {"max_torque": 1.0}})
    assert main(["table", str(_write(tmp_path, "bad.yaml", bad)), "--out", str(tmp_path / "out")]) == 2
    assert "spacecraft.inertia" in capsys.readouterr().err


def test_a_table_files_scenario_errors_name_that_scenario_file(tmp_path, capsys, monkeypatch):
    """From a table file, the scenario's YAML path alone did not say which file it is in, and a
    missing scenario was named as written (relative to the table file, not to where one stands)."""
    bad = dict(UNIT_BOX, spacecraft={"inertia": [1.0, -1.0, 1.0], "torquers": {"max_torque": 1.0}})
    _write(tmp_path, "bad.yaml", bad)
    table = _write(tmp_path, "table.yaml", {"table": {"scenario": "bad.yaml", "axes": 6, "angles_deg": [30, 90]}})
    monkeypatch.chdir(tmp_path.parent)
    assert main(["table", str(table), "--out", str(tmp_path / "out")]) == 2
    assert f"{tmp_path / 'bad.yaml'}: spacecraft.inertia" in capsys.readouterr().err
    _write(tmp_path, "table.yaml", {"table": {"scenario": "nothere.yaml", "axes": 6, "angles_deg": [30, 90]}})
    assert main(["table", str(table.relative_to(tmp_path.parent)), "--out", str(tmp_path / "out")]) == 2
    assert f"scenario file not found: {(tmp_path / 'nothere.yaml').resolve()}" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_never_writes_into_a_directory_slewbench_did_not_make(tmp_path, capsys):
    scenario = _write(tmp_path, "box.yaml", UNIT_BOX)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    assert main(["table", str(scenario), "--out", str(mine), "--axes", "4", "--angles", "90,180"]) == 2
    assert "did not create" in capsys.readouterr().err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]


def test_never_writes_into_another_kind_of_slewbench_output(tmp_path, capsys):
    from scenarios.output.directory import claim_output_directory, write_manifest
    scenario = _write(tmp_path, "box.yaml", UNIT_BOX)
    run_dir = claim_output_directory(tmp_path / "run", kind="run")
    (run_dir / "results.json").write_text("{}")
    write_manifest(run_dir, ["results.json"], complete=True, kind="run")
    assert main(["table", str(scenario), "--out", str(run_dir), "--axes", "4", "--angles", "90,180"]) == 2
    assert "holds slewbench run output" in capsys.readouterr().err
    assert sorted(p.name for p in run_dir.iterdir()) == [".slewbench-output.json", "results.json"]


def test_command_writes_the_table_and_resumes_from_its_store(tmp_path, capsys):
    scenario = _write(tmp_path, "box.yaml", UNIT_BOX)
    out = tmp_path / "out"
    args = ["table", str(scenario), "--out", str(out), "--axes", "6", "--grid", "fibonacci", "--angles", "90,180",
            "--held-out", "2", "--workers", "2"]
    assert main(args) == 0
    said = capsys.readouterr().out
    assert "12 of 12 entries ok" in said and "held-out error" in said
    # the output names the held-out set: 2 axes at both table angles and their midpoint
    assert "held-out points: 2 axes not in the table, at the table's angles (90, 180 deg) and their midpoints " \
           "(135 deg)" in said, said
    assert {"slew_table.csv", "slew_table.nc", "fit.json", "agility_envelope.png"} <= {p.name for p in out.iterdir()}
    fit = load_fit(out / "fit.json")
    assert fit.meta["held_out"]["points"] == 6
    assert fit.meta["held_out"]["held_out"]["table_angles_deg"] == [90.0, 180.0]
    assert main(args) == 0
    assert "(18 entries already stored)" in capsys.readouterr().out


def test_a_bad_table_file_is_named_as_one(tmp_path, capsys):
    table = tmp_path / "table.yaml"
    table.write_text("table: {scenario: nowhere.yaml, axes: 6, angles_deg: [30, 90]}\n")
    assert main(["table", str(table), "--out", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.startswith(f"slewbench: error in table file: {table}: table.scenario: ")
