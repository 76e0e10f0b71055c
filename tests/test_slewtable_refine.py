"""Adaptive refinement of a slew table (:mod:`scenarios.slewtable.refine`) against analytic slew times.

Oracles: analytic slew-time functions with a ridge off the grid's edges, a local bump, and none
(exactly representable by the fit); errors measured on a dense held-out lattice the refinement never
saw; the triangulation checked by sampling directions and counting edges. The table command's
refinement is run with its solves replaced by the analytic function (the engine's solves are the
slow tests' business) and its files read back.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.slewtable.compute import _Runner
from scenarios.slewtable.fit import SlewTimeFit, load_fit, zonotope_facets
from scenarios.slewtable.grid import offset_axes, polytope_grid
from scenarios.slewtable.refine import RefineOptions, TriangleMesh, refine
from tests.test_slewtable import UNIT_BOX

INERTIA = np.diag([10.0, 8.0, 6.0])
ANGLES = np.deg2rad([30.0, 90.0, 180.0])
RIDGE = np.array([0.3, 0.5, 0.81]) / np.linalg.norm([0.3, 0.5, 0.81])


def _shape(axes: np.ndarray) -> np.ndarray:
    return np.max(np.abs(np.atleast_2d(axes) @ INERTIA), axis=1)


def ridge_time(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """The eigenaxis bang-bang time under |τ_i| <= 1, shortened by up to 10 % with a V-shaped kink
    along the small circle 40° from RIDGE (crossing the grid's triangles, not on their edges)."""
    axes = np.atleast_2d(axes)
    v = np.abs(axes @ RIDGE - math.cos(math.radians(40.0)))
    return 2.0 * np.sqrt(angles * _shape(axes)) * (1.0 - 0.1 * v) * (1.0 + 0.02 * angles)


def bump_time(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Exactly the fit's model (g constant over the sphere) except in a cone of 0.3 rad about RIDGE."""
    axes = np.atleast_2d(axes)
    distance = np.arccos(np.clip(axes @ RIDGE, -1.0, 1.0))
    return 2.0 * np.sqrt(angles * _shape(axes)) * (1.0 - 0.05 * np.maximum(0.0, 1.0 - distance / 0.3)) * (1 + 0.02 * angles)


def smooth_time(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """The fit's model exactly: no refinement is needed."""
    return 2.0 * np.sqrt(angles * _shape(axes)) * (1.0 + 0.02 * angles)


def _at(positions) -> np.ndarray:
    """The angles [rad] of angle positions (k: ANGLES[k], k + 0.5: the midpoint of ANGLES[k] and ANGLES[k + 1])."""
    return np.interp(np.asarray(positions, dtype=float), np.arange(len(ANGLES)), ANGLES)


def _solver(function, calls: list[int] | None = None):
    def solve(axes: np.ndarray, positions: list[float]) -> np.ndarray:
        if calls is not None:
            calls.append(len(axes) * len(positions))
        return function(np.repeat(axes, len(positions), axis=0), np.tile(_at(positions), len(axes))).reshape(
            len(axes), len(positions))
    return solve


def _predict(axes: np.ndarray, times: np.ndarray, triangles: np.ndarray):
    fit = SlewTimeFit(ANGLES, axes, times, inertia=INERTIA, generators=np.eye(3), triangles=triangles)
    return lambda e, p: fit.many_axis_angle(np.repeat(e, len(p), axis=0), np.tile(_at(p), len(e))).reshape(len(e), len(p))


def _grid(n: int) -> tuple[np.ndarray, np.ndarray]:
    return polytope_grid(zonotope_facets(np.eye(3)) @ INERTIA, n)


def _held_out_error(function, axes: np.ndarray, times: np.ndarray, triangles: np.ndarray) -> float:
    fit = SlewTimeFit(ANGLES, axes, times, inertia=INERTIA, generators=np.eye(3), triangles=triangles)
    held = offset_axes(2000)
    e, theta = np.repeat(held, 2, axis=0), np.tile(np.deg2rad([60.0, 135.0]), len(held))
    return float(np.max(np.abs(fit.many_axis_angle(e, theta) / function(e, theta) - 1.0)))


def _initial(function, n: int = 50):
    axes, triangles = _grid(n)
    return axes, triangles, _solver(function)(axes, [0, 1, 2])


def test_refinement_reaches_the_tolerance_where_a_finer_uniform_grid_does_not():
    axes, triangles, times = _initial(ridge_time)
    result = refine(axes, triangles, times, _solver(ridge_time), _predict, RefineOptions(0.005))
    assert result.reached and result.rounds[-1]["missed"] == 0
    refined = _held_out_error(ridge_time, result.axes, result.times, result.triangles)
    uniform_axes, uniform_triangles = _grid(770)
    uniform = _held_out_error(ridge_time, uniform_axes, _solver(ridge_time)(uniform_axes, [0, 1, 2]), uniform_triangles)
    assert len(uniform_axes) == 770
    assert _held_out_error(ridge_time, axes, times, triangles) > 0.02  # the initial grid misses by far
    assert refined <= 0.005 < uniform  # on points the refinement never saw
    assert len(result.axes) < len(uniform_axes) / 2
    np.testing.assert_allclose(result.axes[:len(axes)], axes)  # the initial axes kept, first, in order
    np.testing.assert_allclose(result.times, _solver(ridge_time)(result.axes, [0, 1, 2]), rtol=1e-12)


def test_only_triangles_near_the_bump_are_split():
    axes, triangles, times = _initial(bump_time)
    result = refine(axes, triangles, times, _solver(bump_time), _predict, RefineOptions(0.002))
    assert result.reached
    new = result.axes[len(axes):]
    assert len(new) > 10
    # a split triangle meets the bump: its new points are within the bump's radius plus the
    # largest edge of the initial triangles of its centre
    edges = [math.acos(min(1.0, float(axes[a] @ axes[b]))) for t in triangles for a, b in ((t[0], t[1]), (t[1], t[2]))]
    distance = np.arccos(np.clip(new @ RIDGE, -1.0, 1.0))
    assert np.all(distance <= 0.3 + max(edges))
    # the checks are at edge midpoints: they do not bound the error inside a triangle (here 0.27 %
    # on the held-out lattice against a tolerance of 0.2 %), but the bump is followed
    initial = _held_out_error(bump_time, axes, times, triangles)
    assert initial > 0.02
    assert _held_out_error(bump_time, result.axes, result.times, result.triangles) < initial / 5


def test_a_table_the_fit_represents_is_checked_once_and_not_split():
    axes, triangles, times = _initial(smooth_time)
    calls: list[int] = []
    result = refine(axes, triangles, times, _solver(smooth_time, calls), _predict, RefineOptions(1e-6))
    assert result.reached and len(result.rounds) == 1
    edges = len(triangles) * 3 // 2
    assert calls == [edges * 5]  # every edge midpoint, at every angle and every angle midpoint, once
    assert result.rounds[0]["max_miss"] < 1e-9 and result.rounds[0]["split"] == 0
    assert len(result.axes) == len(axes) and len(result.checks) == edges
    np.testing.assert_array_equal(result.triangles, triangles)


def test_check_angles_cost_less_and_unsplit_checks_stay_out_of_the_fit():
    axes, triangles, times = _initial(bump_time)
    calls: list[int] = []
    result = refine(axes, triangles, times, _solver(bump_time, calls), _predict,
                    RefineOptions(0.002, check_angles=[2], max_rounds=1))
    edges = len(triangles) * 3 // 2
    assert calls[0] == edges * 2  # checked at 180 deg and at 135 deg, the midpoint of the interval beside it
    assert not result.reached and "rounds" in result.stopped
    assert result.checks and all(np.isnan(c["times"][0]) and np.isfinite(c["times"][2]) for c in result.checks)
    assert all(np.isnan(c["midpoint_times"][0]) and np.isfinite(c["midpoint_times"][1]) for c in result.checks)
    assert np.all(np.isfinite(result.times))  # split points completed at every angle
    fit_axes = {tuple(a) for a in np.round(result.axes, 12).tolist()}
    assert not {tuple(np.round(c["axis"], 12).tolist()) for c in result.checks} & fit_axes


def test_the_axes_budget_stops_the_refinement():
    axes, triangles, times = _initial(ridge_time)
    result = refine(axes, triangles, times, _solver(ridge_time), _predict, RefineOptions(0.001, max_axes=120))
    assert not result.reached and "120 axes" in result.stopped
    assert len(axes) < len(result.axes) <= 120 + 3 * 12  # grading may add a few beyond the worst triangles
    # the worst triangles go first: every check point left out misses less than the worst one split
    before = _predict(axes, times, triangles)
    left_out = np.array([c["axis"] for c in result.checks])
    miss = np.max(np.abs(before(left_out, [0, 1, 2]) / _solver(ridge_time)(left_out, [0, 1, 2]) - 1.0), axis=1)
    assert result.rounds[0]["max_miss"] > 0.02 and len(result.checks) > 50
    assert np.max(miss) < result.rounds[0]["max_miss"] / 2


@pytest.mark.parametrize("function", [ridge_time, bump_time])
def test_the_refined_triangulation_covers_the_sphere_once_and_is_conforming(function):
    axes, triangles, times = _initial(function)
    result = refine(axes, triangles, times, _solver(function), _predict, RefineOptions(0.005))
    e, t = result.axes, result.triangles
    assert len(e) > len(axes)
    inverses = np.linalg.inv(np.stack([e[tri].T for tri in t]))
    directions = np.random.default_rng(2).normal(size=(20000, 3))
    inside = np.all(np.einsum("tij,nj->nti", inverses, directions) >= -1e-12, axis=2)
    assert np.all(inside.sum(axis=1) >= 1)
    strictly = np.all(np.einsum("tij,nj->nti", inverses, directions) > 1e-12, axis=2)
    assert np.all(strictly.sum(axis=1) <= 1)  # no overlap
    # conforming: every directed edge appears once and its reverse once (no vertex inside an edge)
    directed = [(int(a), int(b)) for tri in t for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0]))]
    assert len(set(directed)) == len(directed)
    assert all((b, a) in set(directed) for a, b in directed)
    assert len(e) - len(directed) // 2 + len(t) == 2  # Euler: a sphere


def test_mesh_grading_splits_a_neighbour_two_levels_coarser():
    axes, triangles = _grid(14)
    mesh = TriangleMesh(axes, triangles)
    first = next(iter(mesh.leaves))
    children = mesh.split(first)
    mesh.split(children[0])
    mesh.grade()
    for leaf in mesh.leaves:  # every leaf has at most one cut edge, none cut twice
        cut = [(p, q) for p, q in ((leaf[0], leaf[1]), (leaf[1], leaf[2]), (leaf[2], leaf[0]))
               if (min(p, q), max(p, q)) in mesh.cut]
        assert len(cut) <= 1


def test_refine_refuses_bad_options():
    axes, triangles, times = _initial(smooth_time, 14)
    for options, match in ((RefineOptions(0.0), "tolerance"), (RefineOptions(-0.1), "tolerance"),
                           (RefineOptions(0.01, check_angles=[5]), "check angles"),
                           (RefineOptions(0.01, max_rounds=0), "max_rounds")):
        with pytest.raises(ValueError, match=match):
            refine(axes, triangles, times, _solver(smooth_time), _predict, options)


# --- the table command with refinement -----------------------------------------------------------

def _box_time(axis: np.ndarray, angle_deg: float) -> float:
    """A slew time with a ridge off the unit box's grid edges (the command's solves replaced)."""
    e = axis / np.linalg.norm(axis)
    theta = math.radians(angle_deg)
    return float(2.0 * math.sqrt(theta * np.max(np.abs(e))) * (1.0 - 0.1 * abs(e @ RIDGE - math.cos(math.radians(40.0)))))


@pytest.fixture
def analytic_engine(monkeypatch):
    """Replace the engine's solves by _box_time (one failed entry, about body z at the first angle)."""
    solved: list[int] = []

    def run(self, cases):
        solved.append(len(cases))
        records = []
        for case in cases:
            if np.allclose(case.axis, [0, 0, 1]) and case.angle_index == 0:
                records.append({"rows": [{"status": "failed", "message": "did not converge", "reference": {}}]})
            else:
                records.append({"rows": [{"status": "ok", "message": "", "plan_time_s": 0.5,
                                          "reference": {"duration_s": _box_time(case.axis, case.angle_deg)}}]})
        return records

    monkeypatch.setattr(_Runner, "__call__", run)
    return solved


def test_command_refines_and_writes_the_refined_table(tmp_path, capsys, analytic_engine):
    from scipy.io import netcdf_file
    scenario = tmp_path / "box.yaml"
    scenario.write_text(yaml.safe_dump(UNIT_BOX))
    out = tmp_path / "out"
    assert main(["table", str(scenario), "--out", str(out), "--axes", "14", "--angles", "45,90,180", "--held-out", "30",
                 "--tolerance", "0.004", "--check-angles", "180", "--no-plots"]) == 0
    said = capsys.readouterr().out
    assert "refinement round 1:" in said and "refinement: reached at its check points" in said
    assert "but the held-out error" not in said  # the held-out grid agrees with the checks (below)
    fit = load_fit(out)
    refinement = fit.meta["refinement"]
    assert refinement["reached"] and refinement["tolerance"] == 0.004 and refinement["check_angles_deg"] == [180.0]
    assert refinement["initial_axes"] == 14 and refinement["axes"] == len(fit.axes) > 14
    held = fit.meta["held_out"]
    assert held["points"] == 30 * 5 and held["max_rel_error"] <= 0.004  # 3 table angles and 2 midpoints
    rows = list(csv_rows(out / "slew_table.csv"))
    table_rows = [r for r in rows if r["grid"] == "table"]
    check_rows = [r for r in rows if r["grid"] == "check"]
    assert len(table_rows) == 3 * len(fit.axes)
    assert check_rows and len(check_rows) == 5 * refinement["check_points"]  # the table's angles and midpoints
    assert refinement["check_midpoint_angles_deg"] == [135.0]  # the midpoint beside the check angle
    assert all(r["status"] == "missing" for r in check_rows if float(r["angle_deg"]) not in (135.0, 180.0))
    assert all(r["status"] == "ok" for r in check_rows if float(r["angle_deg"]) in (135.0, 180.0))
    assert sum(r["status"] == "failed" for r in table_rows) == 1
    with netcdf_file(out / "slew_table.nc", "r", mmap=False) as nc:
        assert nc.dimensions["axis"] == len(fit.axes)
        assert nc.dimensions["check_axis"] == refinement["check_points"]
        np.testing.assert_allclose(nc.variables["axis_x"][:], fit.axes[:, 0])
    data = json.loads((out / "fit.json").read_text())
    assert len(data["triangles"]) == len(fit.triangles)
    # run again: the rounds repeat from the stored entries (here: the same answers) to the same table
    assert main(["table", str(scenario), "--out", str(out), "--axes", "14", "--angles", "45,90,180", "--held-out", "30",
                 "--tolerance", "0.004", "--check-angles", "180", "--no-plots"]) == 0
    np.testing.assert_array_equal(load_fit(out).axes, fit.axes)


def csv_rows(path: Path):
    import csv
    with open(path, newline="") as stream:
        yield from csv.DictReader(stream)


@pytest.mark.parametrize(("flags", "where", "text"), [
    (["--tolerance", "0"], "--tolerance", "0"),
    (["--tolerance", "-0.01"], "--tolerance", "-0.01"),
    (["--tolerance", "1.5"], "--tolerance", "1.5"),
    (["--tolerance", "nan"], "--tolerance", "nan"),
    (["--tolerance", "0.01", "--check-angles", "45"], "--check-angles", "45"),
    (["--tolerance", "0.01", "--check-angles", "ninety"], "--check-angles", "ninety"),
    (["--tolerance", "0.01", "--max-axes", "3"], "--max-axes", "3"),
    (["--tolerance", "0.01", "--max-rounds", "0"], "--max-rounds", "0"),
    (["--max-axes", "500"], "--max-axes", "tolerance"),
    (["--tolerance", "0.01", "--objective", "min_energy", "--duration", "5"], "--tolerance", "min_time"),
])
def test_bad_refinement_options_exit_2_naming_the_option_and_value(tmp_path, capsys, flags, where, text):
    scenario = tmp_path / "box.yaml"
    scenario.write_text(yaml.safe_dump(UNIT_BOX))
    assert main(["table", str(scenario), "--out", str(tmp_path / "out"), "--angles", "90,180", *flags]) == 2
    err = capsys.readouterr().err
    assert where in err and text in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("refine_section", "where"), [
    ({"tolerance": 0}, "table.refine.tolerance"),
    ({"tolerance": "tight"}, "table.refine.tolerance"),
    ({"tolerance": 0.01, "bogus": 1}, "table.refine.bogus"),
    ({"tolerance": 0.01, "check_angles_deg": [100]}, "table.refine.check_angles_deg"),
    ({"max_rounds": 3}, "table.refine.max_rounds"),
    ("0.01", "table.refine"),
])
def test_bad_refine_section_exits_2_naming_the_yaml_path(tmp_path, capsys, refine_section, where):
    (tmp_path / "box.yaml").write_text(yaml.safe_dump(UNIT_BOX))
    spec = tmp_path / "table.yaml"
    spec.write_text(yaml.safe_dump({"table": {"scenario": "box.yaml", "angles_deg": [90, 180], "refine": refine_section}}))
    assert main(["table", str(spec), "--out", str(tmp_path / "out")]) == 2
    assert where in capsys.readouterr().err


def test_a_budget_of_exactly_the_axes_a_round_needs_lets_it_finish():
    """max_axes is the refined table's axes *at most*: a round that ends on C axes without a budget (and
    grades nothing) is admitted whole by a budget of C, and one of C - 1 stops the refinement (grading may
    still complete the round's last cut)."""
    axes, triangles, times = _initial(bump_time, 14)
    free = refine(axes, triangles, times, _solver(bump_time), _predict, RefineOptions(0.005, max_rounds=1, max_axes=10**4))
    count = len(free.axes)
    assert free.rounds[0]["graded"] == 0 and count > len(axes)
    exact = refine(axes, triangles, times, _solver(bump_time), _predict, RefineOptions(0.005, max_rounds=1, max_axes=count))
    assert len(exact.axes) == count and "axes" not in exact.stopped
    np.testing.assert_array_equal(exact.axes, free.axes)
    short = refine(axes, triangles, times, _solver(bump_time), _predict,
                   RefineOptions(0.005, max_rounds=1, max_axes=count - 1))
    assert short.rounds[0]["split"] < free.rounds[0]["split"] and f"{count - 1} axes" in short.stopped


@pytest.mark.parametrize("check, refused", [([90.0], False), ([180.02], False), ([90.06], True), ([45.0], True)])
def test_check_angles_must_be_table_angles_within_005_deg(tmp_path, check, refused):
    """Read without computing anything: a check angle is one of the table's angles (to 0.05 deg, the
    documented rounding allowance) or the spec is refused naming table.refine.check_angles_deg and it."""
    from scenarios.errors import ScenarioError
    from scenarios.slewtable.spec import parse_table_spec
    (tmp_path / "box.yaml").write_text(yaml.safe_dump(UNIT_BOX))
    table = {"table": {"scenario": "box.yaml", "axes": 14, "angles_deg": [90.0, 180.0],
                       "refine": {"tolerance": 0.01, "check_angles_deg": check}}}
    (tmp_path / "table.yaml").write_text(yaml.safe_dump(table))
    if refused:
        with pytest.raises(ScenarioError) as error:
            parse_table_spec(tmp_path / "table.yaml")
        assert error.value.path == "table.refine.check_angles_deg" and f"{check[0]:g}" in error.value.message
    else:
        spec = parse_table_spec(tmp_path / "table.yaml")
        assert spec.refine is not None and spec.refine.check_angles == [0 if check[0] < 135 else 1]
