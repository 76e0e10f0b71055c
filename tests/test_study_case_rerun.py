"""A stored sweep's infeasible row keeps its ``needed_duration_s`` (the least ``maneuver.duration`` its
slew needs) through ``slewbench sweep DIR --case N``: in the stored case (``cases.csv``), in the re-run's
``results.json``, ``results.csv`` and ``results.md``, and the re-run's rows compare equal to the stored ones.

Oracle: a 90 deg rest-to-rest slew of a 10 kg m^2 sphere on 0.0144 N m wheels takes at least the
bang-bang triangle's 2 sqrt(theta I / tau) = 66.05545 s (tests/test_verdict_rules.py's ``FASTEST``),
more than the first case's 60 s budget; the second case's 80 s admits it (an ``ok`` row, no value).
"""
from __future__ import annotations

import csv
import json
import math

import pytest
import yaml

from scenarios.cli.commands import main
from tests.test_verdict_rules import FASTEST, slew


@pytest.mark.parametrize("profile", ["min_time", "trapezoidal"])  # the reference refused; the slew refused itself
def test_a_case_rerun_keeps_the_needed_duration_of_an_infeasible_row(profile, tmp_path, capsys):
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "budget", "scenario": slew(60.0, profile),
                                     "grid": {"maneuver.duration": [60.0, 80.0]}}, sort_keys=False))
    out = tmp_path / "out"
    assert main(["sweep", str(study), "--out", str(out), "--no-plots", "--workers", "1"]) == 0, capsys.readouterr()
    stored = list(csv.DictReader((out / "cases.csv").open()))
    assert [(row["case"], row["status"]) for row in stored] == [("0", "infeasible"), ("1", "ok")]
    assert math.isclose(float(stored[0]["needed_duration_s"]), FASTEST, rel_tol=1e-9) and stored[1]["needed_duration_s"] == ""
    capsys.readouterr()

    assert main(["sweep", str(out), "--case", "0", "--no-plots"]) == 0
    said = capsys.readouterr().out
    assert "the re-run's rows equal the stored case's" in said, said
    case = out / "cases" / "0"
    (row,) = json.loads((case / "results.json").read_text())["rows"]
    assert row["status"] == "infeasible" and math.isclose(row["needed_duration_s"], FASTEST, rel_tol=1e-9), row
    (line,) = csv.DictReader((case / "results.csv").open())
    assert math.isclose(float(line["needed_duration_s"]), FASTEST, rel_tol=1e-9), line
    assert f"| needed_duration_s | {FASTEST:.4g} |" in (case / "results.md").read_text()
