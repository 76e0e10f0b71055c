"""``slewbench table``'s exit status when entries crash, and its entries that are not the best known.

1. A table whose entries crashed (here: every entry runs out of a 1 ms ``case_timeout_s``) writes
   its files, then exits 1 as ``slewbench sweep`` does (``EXIT_CRASHED``: the entries have no
   result), ending with how many crashed, why, and the command that computes them again; run
   again, it says the crashed entries are run again rather than "already stored". Before: exit 0,
   no word of the crash, and "(2 entries already stored)" on the second run though both ran again.
   Entries that ran out of time are ``timed_out`` and called timed out wherever the table speaks
   (the progress line said "(2 crashed)", the second run "2 crashed ones run again"), and the advice
   gives them more time with ``--case-timeout`` (it named a table file's key to one who gave a
   scenario alone).
2. A ``min_time`` entry that ``collocation`` found slower than a feasible slew of the same problem
   (its certificate's ``seed_bound`` note, "not the best known") stays ``ok`` and is fitted, but is
   marked: ``best_known`` false in ``slew_table.csv`` and ``slew_table.nc``, counted in the
   summary line and in the fit's note. Before: "2 of 2 entries ok", nothing marked. Oracle: the
   eigenaxis bang-coast-bang within the same bounds, its wheel momenta checked here, is a feasible
   slew; an entry slower than it must be marked.
"""
from __future__ import annotations

import csv
import re
import shlex
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
import yaml
from scipy.io import netcdf_file

from ocp import ReactionWheels, Spacecraft, quat
from planners import PLANNERS, ManeuverProblem
from scenarios.cli.commands import main
from scenarios.cli.table import entry_counts
from scenarios.slewtable.compute import SlewTable, TablePart, compute_table, fit_entries
from scenarios.slewtable.files import write_table_files
from scenarios.slewtable.spec import parse_table_spec

EXIT_CRASHED = 1  # the documented status (docs/guide/slew_table.rst)

BOX = {"name": "bilimoria-wie",
       "spacecraft": {"inertia": [1.0, 1.0, 1.0], "wheels": None, "torquers": {"max_torque": 1.0}},
       "maneuver": {"duration": 10.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                    "final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
       "planners": [{"name": "collocation"}], "controller": {"name": "augmented_quaternion_feedback"}}

# the user's table of commit 72c12cf: a 4-wheel pyramid, wheel 0 failed, a 5 % actuator margin
MARGIN, MAX_TORQUE, MAX_MOMENTUM = 0.05, 0.01, 0.05
INERTIA = [2.0, 2.5, 3.0]
WHEEL_AXES = [[0.81650, 0.0, 0.57735], [0.0, 0.81650, 0.57735], [-0.81650, 0.0, 0.57735], [0.0, -0.81650, 0.57735]]
AXIS = [0.9045347990869904, 0.0, 0.4263998091470701]
PYRAMID = {"name": "pyramid",
           "spacecraft": {"inertia": INERTIA, "wheels": {"axes": WHEEL_AXES, "max_torque": MAX_TORQUE,
                                                         "max_momentum": MAX_MOMENTUM, "failed": [0]}},
           "maneuver": {"duration": 150.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                        "final": {"q": [0, 1, 0, 0], "omega": [0, 0, 0]}},
           "planners": [{"name": "collocation"}], "controller": {"name": "augmented_quaternion_feedback"},
           "requirements": {"actuators": {"margin": MARGIN}}}


def write(folder: Path, name: str, data: dict) -> Path:
    path = folder / name
    path.write_text(yaml.safe_dump(data))
    return path


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


# --- 1. crashed entries ----------------------------------------------------------------------------

def test_a_table_whose_entries_crashed_writes_its_files_and_exits_1(tmp_path: Path, capsys) -> None:
    write(tmp_path, "box.yaml", BOX)
    path = write(tmp_path, "table.yaml", {"table": {"scenario": "box.yaml", "axes": [[1, 0, 0]], "angles_deg": [90, 180],
                                                    "planner_options": {"multistart": 0},
                                                    "execution": {"workers": 2, "case_timeout_s": 0.001}}})
    out = tmp_path / "out"
    assert main(["table", str(path), "--out", str(out), "--no-plots", "--angles", "90,180"]) == EXIT_CRASHED
    captured = capsys.readouterr()
    assert "table: 0 of 2 entries ok (2 timed_out)" in captured.out, captured.out
    lines = captured.err.strip().splitlines()
    # off a terminal the engine's progress line comes first (at most every 30 s, and at the end)
    progress = [line for line in lines if line.startswith("table bilimoria-wie: ")]
    # the table calls them timed out everywhere: its progress line too (a sweep's says crashed, as its rows)
    assert progress and progress[-1].startswith("table bilimoria-wie: 2/2 entries done, 2 not ok (2 timed out), "), \
        captured.err
    last = lines[lines.index(progress[-1]) + 1:]
    # each entry timed out (by the worker's own alarm, or under load by the driver's clock, which
    # stops the worker): status timed_out, not crashed, and the message says what to do
    assert last[0].startswith("slewbench: 2 of 2 entries timed out: the planner was still solving when "
                              "table.execution.case_timeout_s (0.001 s) ran out"), captured.err
    # the command gives them more time with a flag (twice the limit, to a whole second)
    assert "Give them more time (--case-timeout, which wins over table.execution.case_timeout_s)" in last[0]
    command = shlex.join(["slewbench", "table", str(path), "--angles", "90,180", "--case-timeout", "1", "--out",
                          str(out), "--no-plots"])
    assert last[-1] == f"  {command}" and len(last) == 2, captured.err
    assert "crashed" not in captured.err.replace("not a crash", ""), captured.err
    assert "Traceback" not in captured.err
    table_rows = rows(out / "slew_table.csv")
    assert [r["status"] for r in table_rows] == ["timed_out", "timed_out"]  # written all the same
    assert all(re.match(r"timed out after 0\.001 s \(case_timeout_s\)(?:; worker stopped)?: the planner was still "
                        r"solving", r["message"]) for r in table_rows), table_rows
    # run again: the timed-out entries are not "already stored", they run again (and time out again)
    assert main(["table", str(path), "--out", str(out), "--no-plots"]) == EXIT_CRASHED
    assert "(0 entries already stored, 2 timed-out ones run again)" in capsys.readouterr().out


def test_a_scenario_given_alone_is_told_how_to_give_its_entries_more_time(tmp_path: Path, capsys) -> None:
    """The advice named a key of a table file, and the command the same scenario file: one who ran
    ``slewbench table scenario.yaml`` has no table file. The flag holds for both."""
    scenario = write(tmp_path, "box.yaml", BOX)
    out = tmp_path / "out"
    assert main(["table", str(scenario), "--axes", "1", "--grid", "fibonacci", "--angles", "90,180",
                 "--case-timeout", "0.001", "--workers", "2", "--out", str(out), "--no-plots"]) == EXIT_CRASHED
    err = capsys.readouterr().err
    assert "when table.execution.case_timeout_s (0.001 s) ran out" in err, err  # the flag set the limit
    command = shlex.join(["slewbench", "table", str(scenario), "--axes", "1", "--grid", "fibonacci", "--angles",
                          "90,180", "--workers", "2", "--case-timeout", "1", "--out", str(out), "--no-plots"])
    assert err.rstrip().endswith(f"\n  {command}"), err
    assert "in the table file" not in err


# --- 2. entries that are not the best known --------------------------------------------------------

def feasible_eigenaxis_s(angle_deg: float) -> float:
    """The eigenaxis bang-coast-bang within the margin about AXIS, its working wheels' momenta
    (``h = −A_w⁺ I ω``, the total stays zero) checked within (1 − margin) of their bound here."""
    wheels = ReactionWheels(np.array(WHEEL_AXES).T, max_torque=MAX_TORQUE, max_momentum=MAX_MOMENTUM, failed=[0])
    problem = ManeuverProblem(Spacecraft(np.diag(INERTIA), wheels=wheels), quat.IDENTITY, np.zeros(3),
                              quat.from_axis_angle(np.array(AXIS), np.deg2rad(angle_deg)), 150.0,
                              omegaf=np.zeros(3), actuator_margin=MARGIN)
    keep = 1.0 - MARGIN
    first = PLANNERS["eigenaxis"]({"profile": "min_time", "torque_fraction": keep}).plan(problem)
    slew = PLANNERS["eigenaxis"]({"profile": "min_time", "torque_fraction": keep,
                                  "max_rate": keep * first.profile.rate_max}).plan(problem)
    assert slew.ok, slew.message
    omega = slew.sample(np.linspace(0.0, slew.duration, 2001)).omega
    working = np.array(WHEEL_AXES).T.copy()
    working[:, 0] = 0.0
    momenta = -(omega @ np.diag(INERTIA).T) @ np.linalg.pinv(working).T
    assert np.max(np.abs(momenta)) <= keep * MAX_MOMENTUM * (1 + 1e-9)
    return float(slew.duration)


def test_an_entry_slower_than_a_feasible_slew_is_marked_not_the_best_known(tmp_path: Path) -> None:
    write(tmp_path, "pyramid.yaml", PYRAMID)
    path = write(tmp_path, "table.yaml", {"table": {"scenario": "pyramid.yaml", "axes": [AXIS], "angles_deg": [60, 90],
                                                    "planner_options": {"intervals": 20}}})
    with ThreadPoolExecutor(1) as executor:
        table = compute_table(parse_table_spec(path), executor=executor)
    part = table.parts["table"]
    bounds = [feasible_eigenaxis_s(angle) for angle in part.angles_deg]
    slower = [bool(part.slew_time_s[0, k] > bound * (1 + 1e-6)) for k, bound in enumerate(bounds)]
    assert any(slower), (part.slew_time_s, bounds)  # else the test sees nothing
    for k, is_slower in enumerate(slower):
        if is_slower:  # slower than a feasible slew: it must be marked, and say so
            assert part.best_known[0][k] is False, (k, part.message[0][k])
            assert "not the best known" in part.message[0][k]
    write_table_files(table, tmp_path, plots=False)
    found = rows(tmp_path / "slew_table.csv")
    assert [r["best_known"] for r in found] == ["false" if flag is False else "true" for flag in part.best_known[0]]
    with netcdf_file(tmp_path / "slew_table.nc", "r", mmap=False) as nc:
        assert nc.variables["best_known"][0].tolist() == [0 if flag is False else 1 for flag in part.best_known[0]]


def synthetic_table(tmp_path: Path) -> SlewTable:
    """6 body axes x 2 angles of the unit box's table, every entry ok with the eigenaxis time
    ``2 √θ`` (no solve): entry (0, 1) not the best known, entry (2, 0) failed."""
    write(tmp_path, "box.yaml", BOX)
    axes = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    spec = parse_table_spec(write(tmp_path, "table.yaml", {"table": {"scenario": "box.yaml", "axes": axes,
                                                                     "angles_deg": [90, 180], "held_out": 0}}))
    part = TablePart.empty(spec.axes, spec.angles_deg)
    part.slew_time_s[:] = 2.0 * np.sqrt(np.deg2rad(spec.angles_deg))
    part.objective_value[:] = part.slew_time_s
    part.status = [["ok", "ok"] for _ in axes]
    part.best_known = [[True, True] for _ in axes]
    part.best_known[0][1] = False
    part.status[2][0], part.best_known[2][0] = "failed", None
    part.slew_time_s[2, 0] = np.nan
    table = SlewTable(spec, {"table": part, "held_out": TablePart.empty(np.zeros((0, 3)), [])})
    table.fit, table.fit_note = fit_entries(part)
    return table


def test_the_summary_line_counts_them_and_the_fit_keeps_them(tmp_path: Path) -> None:
    table = synthetic_table(tmp_path)
    assert entry_counts(table).startswith("11 of 12 entries ok (1 failed), 1 of them not the best known "
                                          "(slower than a feasible slew the planner knows: best_known false"), \
        entry_counts(table)
    assert table.fit is not None
    assert "1 fitted entry slower than a feasible slew the planner knows" in table.fit_note, table.fit_note
    # fitted: the fit gives the entry's own time at its axis and angle (not NaN)
    assert table.fit.many_axis_angle(np.array([[1.0, 0.0, 0.0]]), np.array([np.pi]))[0] == \
        pytest.approx(2.0 * np.sqrt(np.pi), rel=1e-9)
    write_table_files(table, tmp_path, plots=False)
    flags = {(r["axis_x"], r["axis_y"], r["axis_z"], r["angle_deg"]): r["best_known"]
             for r in rows(tmp_path / "slew_table.csv")}
    assert flags[("1.0", "0.0", "0.0", "180.0")] == "false"
    assert flags[("0.0", "1.0", "0.0", "90.0")] == ""  # failed: the question does not apply
    assert list(flags.values()).count("true") == 10
