"""A slew-table entry's cost outside its solve: the token closed loop (controller ``none``) that only
completes the row built one CasADi closed-loop function per entry (its law's key holds the entry's
target), about 5 s of an entry whose solve took under 1 s. The entries must be what they were.

Oracles: the same entry run with the earlier token loop (RK4, the closed loop as one CasADi
function): every field the table keeps (status, message, slew time, objective, best known) equal
(times to 1e-12), on a free box and on a keep-out body whose requirements are scored; and the
number of closed-loop functions built over entries with different targets, counted.
"""
from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from ocp.simulation import closed_loop
from scenarios.runner import run
from scenarios.schema.loader import parse_scenario
from scenarios.slewtable.compute import TablePart, _fill
from scenarios.slewtable.spec import case_scenario, parse_table_spec, table_cases
from tests.test_slewtable import UNIT_BOX
from tests.test_slewtable_gaps import KEEP_OUT


def _spec(tmp_path: Path, scenario: dict, axes: list, angles: list):
    (tmp_path / "sc.yaml").write_text(yaml.safe_dump(scenario))
    (tmp_path / "t.yaml").write_text(yaml.safe_dump({"table": {"scenario": "sc.yaml", "axes": axes, "angles_deg": angles,
                                                               "planner_options": {"intervals": 20}}}))
    return parse_table_spec(tmp_path / "t.yaml")


def _entry(case, scenario: dict) -> TablePart:
    """The entry as the table keeps it, from a fresh run of ``scenario`` (no cache shared)."""
    part = TablePart.empty(np.zeros((1, 3)), [case.angle_deg])
    rows = [row.to_dict() for row in run(parse_scenario(scenario)).rows]
    _fill(part, type(case)("table", 0, 0, case.axis, case.angle_deg, scenario), {"rows": rows}, "min_time")
    return part


@pytest.mark.parametrize(("scenario", "axis", "angle"), [
    (UNIT_BOX, [1.0, 0.0, 0.0], 180.0),
    (KEEP_OUT, [0.0, 0.0, -1.0], 90.0),   # keep-out scored, met
    (KEEP_OUT, [0.0, 0.0, 1.0], 90.0),    # ends with the camera on +y: infeasible
])
def test_an_entry_is_the_same_with_the_earlier_token_closed_loop(tmp_path, scenario, axis, angle):
    spec = _spec(tmp_path, scenario, [axis], [30.0, angle])
    case = table_cases(spec)[1]
    assert case.angle_deg == angle
    earlier = copy.deepcopy(case.scenario)
    earlier["simulation"].pop("integrator")  # the RK4 default: one CasADi closed-loop function per target
    now, before = _entry(case, case.scenario), _entry(case, earlier)
    assert now.status == before.status and now.message == before.message and now.best_known == before.best_known
    for name in ("slew_time_s", "objective_value"):
        a, b = getattr(now, name), getattr(before, name)
        assert np.array_equal(np.isnan(a), np.isnan(b))
        np.testing.assert_allclose(a[~np.isnan(a)], b[~np.isnan(b)], rtol=1e-12, atol=0)
    if scenario is UNIT_BOX:
        # 20 intervals: within 0.02 % of the published optimum (Bilimoria & Wie 1993: 3.2431 s)
        assert now.status[0][0] == "ok" and now.slew_time_s[0, 0] == pytest.approx(3.2431, rel=2e-4)


def test_entries_of_different_targets_build_no_closed_loop_function(tmp_path, monkeypatch):
    builds = []
    original = closed_loop.ClosedLoop.__init__

    def counted(self, *args, **kwargs):
        builds.append(1)
        original(self, *args, **kwargs)

    monkeypatch.setattr(closed_loop.ClosedLoop, "__init__", counted)
    spec = _spec(tmp_path, UNIT_BOX, [[1, 0, 0], [0, 1, 0]], [60.0, 75.0])
    for angle in (60.0, 75.0):
        for axis in spec.axes:
            rows = run(parse_scenario(case_scenario(spec, axis, angle))).rows
            assert rows[0].status == "ok" and rows[0].simulation is not None  # the row's token loop ran
    assert builds == []
    assert math.isfinite(rows[0].reference.duration)
