"""``slewbench table``'s wording on bad input: an angle that is not finite names its item's path and
says so (it said ``got nan`` of the whole list); the file is named as what it is (a scenario, a
study file, a file that cannot be read), not always as a "table file"; a count of angles that
NumPy cannot allocate is refused (a traceback); and a table without a fit says "no fit" once, with
its reason (it said it twice, after a note on the fit's cells)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.cli.table import no_fit_line
from scenarios.slewtable.compute import TablePart, fit_entries

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = ROOT / "scenarios" / "collocation_min_time.yaml"


def error_of(capsys, *argv: str) -> str:
    assert main(["table", *argv]) == 2
    said = capsys.readouterr().err.strip().splitlines()
    assert len(said) == 1, said  # one line, no traceback
    return said[0]


def table_file(tmp_path: Path, table: dict) -> str:
    path = tmp_path / "table.yaml"
    path.write_text(yaml.safe_dump({"table": {"scenario": str(SCENARIO), **table}}))
    return str(path)


@pytest.mark.parametrize("angles, said", [
    ([float("nan"), 0, 1], "item 1: nan is not finite; expected an angle in degrees, in (0, 180]"),
    ([30, float("inf")], "item 2: inf is not finite"),
    ([30, 10**400], "item 2: 10000000000000000000... (401 digits) is beyond a float's range"),
    ([30, 0], "item 2: 0 is outside (0, 180]"),
    ([30, 90, 30], "item 3: 30 repeats item 1: expected distinct angles"),
])
def test_a_bad_angle_in_a_table_file_names_its_item_and_why(tmp_path, capsys, angles, said):
    file = table_file(tmp_path, {"angles_deg": angles})
    line = error_of(capsys, file, "--out", str(tmp_path / "out"))
    assert line.startswith(f"slewbench: error in table file: {file}: table.angles_deg: {said}"), line
    assert not (tmp_path / "out").exists()


def test_a_bad_angle_flag_names_the_item_and_a_huge_count_is_refused_not_allocated(tmp_path, capsys):
    line = error_of(capsys, str(SCENARIO), "--angles", "30,nan", "--out", str(tmp_path / "out"))
    assert line == "slewbench: error in option: --angles: item 2: nan is not finite; expected an angle in degrees, in (0, 180]"
    for count in ("100000000000", "1" + "0" * 400):  # 1e11 asked for 745 GiB: MemoryError, a traceback
        line = error_of(capsys, str(SCENARIO), "--angles", count, "--out", str(tmp_path / "out"))
        assert line.startswith("slewbench: error in option: --angles: expected a count of 2 to 10000 angles, got "), line


def test_the_file_is_named_as_what_it_is(tmp_path, capsys):
    bad = yaml.safe_load(SCENARIO.read_text())
    bad["spacecraft"]["inertia"] = [1, 2, True]
    scenario = tmp_path / "scenario.yaml"
    scenario.write_text(yaml.safe_dump(bad))
    line = error_of(capsys, str(scenario), "--out", str(tmp_path / "out"))
    assert line.startswith(f"slewbench: error in scenario: {scenario}: spacecraft.inertia: "), line  # not "table file"

    study = ROOT / "scenarios" / "study_spin_monte_carlo.yaml"
    line = error_of(capsys, str(study), "--out", str(tmp_path / "out"))
    assert line.startswith(f"slewbench: error in study file: {study} is a study file, not a scenario: "), line
    assert "slewbench table expects a scenario file or a table file" in line and "slewbench sweep" in line, line

    duplicate = tmp_path / "duplicate.yaml"  # unreadable as a mapping: named by the file, as validate does
    duplicate.write_text(SCENARIO.read_text() + "maneuver: 3\n")
    line = error_of(capsys, str(duplicate))
    assert line.startswith(f"slewbench: error in {duplicate}: maneuver: duplicate key (lines "), line

    line = error_of(capsys, table_file(tmp_path, {"scenario": str(duplicate)}))
    assert f"table.scenario: {duplicate}: maneuver: duplicate key" in line, line  # the file the lines are in


def test_a_table_without_a_fit_says_no_fit_once_with_its_reason():
    """Notes made by fit_entries itself: 4 axes x 2 angles, every entry infeasible; 3 axes."""
    axes = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [-1.0, -1.0, -1.0]]) / [[1], [1], [1], [3 ** 0.5]]
    shape = (4, 2)
    part = TablePart(axes, [30.0, 60.0], np.full(shape, np.nan), np.full(shape, np.nan), np.zeros(shape),
                     [["infeasible"] * 2 for _ in range(4)], [[""] * 2 for _ in range(4)])
    fit, note = fit_entries(part)
    assert fit is None
    assert no_fit_line(note) == "no fit: no entry is ok", note
    assert "8 entries not ok (8 infeasible)" in note and "the fit gives" not in note, note  # there is no fit
    three = TablePart(axes[:3], [30.0, 60.0], np.ones((3, 2)), np.ones((3, 2)), np.zeros((3, 2)),
                      [["ok"] * 2 for _ in range(3)], [[""] * 2 for _ in range(3)])
    fit, note = fit_entries(three)
    assert fit is None and no_fit_line(note).count("no fit") == 1, note
    assert no_fit_line(note).startswith("no fit over the sphere: 3 axes"), no_fit_line(note)


def test_a_huge_axis_is_its_direction(tmp_path):
    """[1e300, 1e300, 0]: its norm overflowed (NumPy's RuntimeWarning), the axis came out zero and the
    table refused 'maneuver.final.q: a quaternion must have unit norm', a quaternion no one wrote."""
    import warnings

    from scenarios.slewtable.spec import parse_table_spec
    file = table_file(tmp_path, {"axes": [[1e300, 1e300, 0], [0, 0, 2]], "angles_deg": [30, 90]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        spec = parse_table_spec(file)
    np.testing.assert_allclose(spec.axes, [[0.5 ** 0.5, 0.5 ** 0.5, 0.0], [0.0, 0.0, 1.0]], rtol=1e-15)
