"""A table entry whose planner runs out of ``case_timeout_s`` is ``timed_out``, not ``crashed``.

A tester's two-wheel (underactuated) table ended with its entries ``crashed``: they had run out of
the per-entry time limit. Reproduced (2026-12-03) on a unit-inertia body with wheels on x and y
(0.1 N m, 1 N m s) and z's failed: about x the minimum-time solve takes 2 to 3 s, about z 10 to
18 s, about [0, 0.6, 0.8] by 90° ipopt runs 105 s to its iteration limit and the entry is
``failed`` ("did not converge from any start: Maximum_Iterations_Exceeded"); with a limit of 150 s
or less the same entry was ``crashed``, the same word as a planner that raised. Collocation takes
underactuated slews (it solved the others): nothing to refuse up front; the entry now says that it
ran out of time while the planner was solving, and that the spacecraft is underactuated.

Oracle: the limit and the spacecraft's working wheels as written in the test; the command's status
words and exit codes as documented (docs/guide/slew_table.rst).
"""
from __future__ import annotations

import csv
from pathlib import Path

import yaml

from scenarios.cli.commands import main
from scenarios.cli.status import EXIT_CRASHED
from scenarios.slewtable.compute import UNDERACTUATED_NOTE

TWO_WHEELS = {
    "name": "two-wheels",
    "spacecraft": {"inertia": [1.0, 1.0, 1.0],
                   "wheels": {"axes": [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "max_torque": 0.1, "max_momentum": 1.0,
                              "failed": [2]}},
    "maneuver": {"duration": 60.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.7071068, 0.7071068, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "collocation"}],
    "controller": {"name": "augmented_quaternion_feedback"},
}


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_an_entry_out_of_time_is_timed_out_and_says_so(tmp_path, capsys):
    (tmp_path / "two.yaml").write_text(yaml.safe_dump(TWO_WHEELS))
    (tmp_path / "table.yaml").write_text(yaml.safe_dump({"table": {
        "scenario": "two.yaml", "axes": [[0, 0, 1]], "angles_deg": [90, 180],
        "execution": {"workers": 1, "case_timeout_s": 0.5}}}))
    out = tmp_path / "out"
    assert main(["table", str(tmp_path / "table.yaml"), "--out", str(out), "--no-plots"]) == EXIT_CRASHED
    said = capsys.readouterr()
    rows = _rows(out / "slew_table.csv")
    assert [r["status"] for r in rows] == ["timed_out", "timed_out"]
    for row in rows:
        assert row["message"].startswith("timed out after 0.5 s (case_timeout_s)"), row["message"]
        assert "the planner was still solving (no error, not a crash)" in row["message"]
        assert "table.execution.case_timeout_s" in row["message"]
        assert row["message"].endswith(UNDERACTUATED_NOTE)  # two working wheels
    assert "table: 0 of 2 entries ok (2 timed_out)" in said.out, said.out
    assert "slewbench: 2 of 2 entries timed out: the planner was still solving when table.execution." \
           "case_timeout_s (0.5 s) ran out" in said.err, said.err
    assert "entries crashed" not in said.err and "Traceback" not in said.err


def test_the_schema_and_the_exit_status_call_an_entry_out_of_time_timed_out():
    """The schema's ``table.execution.case_timeout_s`` said "its status is then crashed"; EXIT_CRASHED's
    description named only crashed entries."""
    from scenarios.cli import status
    from scenarios.schema.table import TABLE_EXECUTION, TABLE_FLAGS
    meaning = TABLE_EXECUTION["case_timeout_s"].meaning
    assert "``timed_out``" in meaning and "crashed" not in meaning, meaning
    assert TABLE_FLAGS["execution.case_timeout_s"] == "--case-timeout"
    described = " ".join(_attribute_doc(status, "EXIT_CRASHED").split())
    assert "timed out (status ``timed_out``" in described and "--case-timeout" in described, described


def _attribute_doc(module, name: str) -> str:
    """The docstring written under a module's constant (``NAME = 1`` then a string)."""
    import ast
    import inspect
    tree = ast.parse(inspect.getsource(module))
    for node, after in zip(tree.body, tree.body[1:]):
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == name for t in node.targets) \
                and isinstance(after, ast.Expr) and isinstance(after.value, ast.Constant):
            return str(after.value.value)
    return ""


def test_a_tables_crash_report_does_not_count_running_out_of_time_as_a_crash():
    """A table's entries that run out of time are ``timed_out`` (reported apart): its crash report
    said "crashed (raised, ran out of case_timeout_s or killed their worker)"; a sweep's still does."""
    import numpy as np

    from scenarios.cli.status import crash_report
    from scenarios.cli.table import crashed_message
    from scenarios.slewtable.compute import SlewTable, TablePart
    part = TablePart.empty(np.eye(3)[:1], [90.0, 180.0])
    part.status[0] = ["crashed", "timed_out"]
    part.message[0] = ["worker died (signal 9); 2 attempt(s)", "timed out after 1 s (case_timeout_s): ..."]
    said = crashed_message(SlewTable(None, {"table": part}), "slewbench table box.yaml")  # type: ignore[arg-type]
    assert said.startswith("slewbench: 1 of 2 entries crashed (raised or killed their worker): "), said
    assert "case_timeout_s" not in said and "timed out" not in said
    sweep = crash_report(["boom"], 3, ("case", "cases"), "cases.csv", "x", "slewbench sweep s.yaml --resume")
    assert sweep.startswith("slewbench: 1 of 3 cases crashed (raised, ran out of case_timeout_s or killed their "
                            "worker): "), sweep
