"""``slewbench validate --strict``: exit 1 when validate's notes say every row must fail (a CI gate
on validate passed scenarios certain to fail), 0 otherwise; without ``--strict`` validate exits 0."""
from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from scenarios.cli.commands import main

ROOT = Path(__file__).resolve().parents[1]
KEEP_OUT = yaml.safe_load((ROOT / "scenarios" / "cubesat_12u_sun_keep_out.yaml").read_text())


def written(tmp_path: Path, data: dict) -> str:
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


def rate_typed_in_degrees() -> dict:
    data = copy.deepcopy(KEEP_OUT)
    data["maneuver"]["initial"]["omega"] = [0.0, 0.0, 3.0]  # 3 deg/s typed as rad/s
    data.setdefault("requirements", {})["rate"] = {"max": 0.03}
    return data


def test_a_scenario_no_row_can_pass_exits_1_under_strict_only(tmp_path, capsys):
    path = written(tmp_path, rate_typed_in_degrees())
    assert main(["validate", path]) == 0
    out = capsys.readouterr().out
    assert "every row breaks the rate requirement" in out
    assert main(["validate", path, "--strict"]) == 1
    captured = capsys.readouterr()
    assert "every row breaks the rate requirement" in captured.out  # the check is printed all the same
    assert "--strict: no row can be ok" in captured.err


def test_a_scenario_that_may_pass_exits_0_under_strict(tmp_path, capsys):
    assert main(["validate", written(tmp_path, KEEP_OUT), "--strict"]) == 0
    assert "every" not in capsys.readouterr().out


@pytest.mark.parametrize("strict", [[], ["--strict"]])
def test_a_study_validates_as_before(strict, capsys):
    assert main(["validate", str(ROOT / "scenarios" / "study_planners_vs_slew_angle.yaml"), *strict]) == 0
