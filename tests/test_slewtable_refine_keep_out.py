"""``slewbench table`` refines a table with pointing requirements.

The refinement's working fits used to be made without the table's ``meta``: a fit with end cones
(a keep-out, :func:`scenarios.slewtable.compute.end_cones`) needs ``meta.from_identity_only``, so
every working fit was refused and the refinement stopped before its first round, "NOT reached at
its check points (no fit over the sphere to check against)", on every table with pointing
requirements (a 12U Sun keep-out table, 2026-12-03). Through the command, on a small keep-out
table whose entries about ``[1, 1, 0]`` at 180 deg are proven infeasible (the camera ends on the
keep-out's direction): a round is made, it splits triangles across the boundary of the entries
without a time, and ``fit.json`` (strict JSON) keeps it.

The round's line names the triangles split across that boundary only when there are some: a table
whose entries all have a time used to say "(0 of them across the boundary ...)" all the same.

Oracle of the infeasible entry: the half-turn about ``[1, 1, 0] / sqrt(2)`` takes the body x axis
to the y axis, the keep-out's direction (0 deg from it, inside 20 deg).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from ocp import quat
from scenarios.cli.commands import main
from scenarios.slewtable.compute import _Runner
from tests.test_slewtable import UNIT_BOX
from tests.test_slewtable_gaps import KEEP_OUT
from tests.test_slewtable_refine import _box_time

BOX = KEEP_OUT  # the keep-out box of the table report's end-to-end test
AXES = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1], [0.7071068, 0.7071068, 0]]


def _refine_the_keep_out_table(tmp_path: Path, capsys) -> None:
    """The command on the keep-out table, one round, and what its output and ``fit.json`` must say."""
    (tmp_path / "box.yaml").write_text(yaml.safe_dump(BOX))
    table = tmp_path / "table.yaml"
    table.write_text(yaml.safe_dump({"table": {
        "scenario": "box.yaml", "axes": AXES, "angles_deg": [60, 180], "planner_options": {"multistart": 0},
        "execution": {"workers": 2}, "refine": {"tolerance": 0.05, "max_rounds": 1}}}))
    out = tmp_path / "out"
    assert main(["table", str(table), "--out", str(out), "--no-plots"]) == 0
    said = capsys.readouterr().out
    assert "no fit over the sphere to check against" not in said, said
    rounds = [line for line in said.splitlines() if line.startswith("refinement round ")]
    assert len(rounds) == 1 and rounds[0].startswith("refinement round 1: "), said
    refinement = json.loads((out / "fit.json").read_text())["meta"]["refinement"]
    assert len(refinement["rounds"]) == 1 and refinement["axes"] > len(AXES)
    first = refinement["rounds"][0]
    assert first["checked"] > 0 and first["split"] > 0 and first["boundary"] > 0  # across the infeasible entry
    assert f"({first['boundary']} of them across the boundary of the entries without a time; " in rounds[0]
    assert "(the budget of 1 rounds)" in said


# Slow (about 45 s of IPOPT solves on a quiet machine, 155 s loaded): the same command with the
# engine's solves replaced runs by default in test_a_keep_out_table_is_refined_with_the_solves_replaced
# (the refinement's working fits with the table's meta and end cones, the round, the boundary and
# fit.json); the keep-out solves themselves, infeasible entry included, run by default in
# tests/test_slewtable_gaps.py::test_the_keep_out_table_records_the_impossible_entry_and_the_fit_gives_no_time.
@pytest.mark.slow
def test_a_keep_out_table_is_refined(tmp_path: Path, capsys) -> None:
    _refine_the_keep_out_table(tmp_path, capsys)


def _camera_inside_the_keep_out(axis, angle_deg: float) -> bool:
    """The oracle of test_slewtable_gaps: the body x camera ends within 20 deg of inertial +y."""
    boresight = quat.rotate(quat.from_axis_angle(np.asarray(axis, dtype=float) / np.linalg.norm(axis),
                                                 math.radians(angle_deg)), [1.0, 0.0, 0.0])
    return math.degrees(math.acos(float(np.clip(boresight[1], -1.0, 1.0)))) < 20.0


def test_a_keep_out_table_is_refined_with_the_solves_replaced(tmp_path: Path, capsys, monkeypatch) -> None:
    """The command's refinement of the keep-out table, each entry's solve replaced: infeasible where
    the camera ends in the keep-out (the run's verdict there, by the geometric oracle), else the
    analytic ``_box_time``. The working fits still carry the table's meta and end cones."""
    def run(self, cases):
        return [{"rows": [{"status": "infeasible", "message": "no reference can meet it", "reference": {}}]}
                if _camera_inside_the_keep_out(case.axis, case.angle_deg) else
                {"rows": [{"status": "ok", "message": "", "plan_time_s": 0.5,
                           "reference": {"duration_s": _box_time(np.asarray(case.axis), case.angle_deg)}}]}
                for case in cases]

    assert _camera_inside_the_keep_out(AXES[-1], 180.0)  # the table's entry without a time
    monkeypatch.setattr(_Runner, "__call__", run)
    _refine_the_keep_out_table(tmp_path, capsys)


def test_a_round_without_a_boundary_does_not_mention_it(tmp_path: Path, capsys, monkeypatch) -> None:
    def run(self, cases):  # every entry ok: the analytic slew time (the engine's solves are the test above's)
        return [{"rows": [{"status": "ok", "message": "", "plan_time_s": 0.5,
                           "reference": {"duration_s": _box_time(np.asarray(case.axis), case.angle_deg)}}]}
                for case in cases]

    monkeypatch.setattr(_Runner, "__call__", run)
    scenario = tmp_path / "box.yaml"
    scenario.write_text(yaml.safe_dump(UNIT_BOX))
    assert main(["table", str(scenario), "--out", str(tmp_path / "out"), "--axes", "14", "--angles", "45,180",
                 "--tolerance", "0.004", "--max-rounds", "1", "--no-plots"]) == 0
    rounds = [line for line in capsys.readouterr().out.splitlines() if line.startswith("refinement round ")]
    assert len(rounds) == 1 and " triangles split (+" in rounds[0], rounds
    assert "across the boundary" not in rounds[0]
