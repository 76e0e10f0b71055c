"""The work a slew table would take is checked by one public function,
:func:`scenarios.cli.table.check_table_work`, which ``slewbench table`` (with its options) and
``slewbench validate`` on a table file (with the default limit) both call: what ``validate``
foretells is what ``table`` does.

Oracles: the entry counts by hand (axes x angles, plus the held-out grid's) and the limit as the
module states it (:data:`scenarios.cli.table.MAX_ENTRIES`).
"""
from __future__ import annotations

import pytest

import scenarios.cli.table as table_command
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.slewtable.spec import parse_table_spec
from tests.test_validate_files import table


@pytest.fixture
def calls(monkeypatch):
    """Every call of the check, recorded (its arguments), the check then run as it is."""
    made = []
    check = table_command.check_table_work

    def recorded(spec, entries, max_entries=None, angles=None):
        made.append((spec.name, entries, max_entries, angles))
        return check(spec, entries, max_entries, angles)
    monkeypatch.setattr(table_command, "check_table_work", recorded)
    return made


def test_validate_and_table_both_check_the_work_through_the_one_function(tmp_path, capsys, calls):
    path = table(tmp_path, 100)  # 100 axes x 36 angles = 3600 entries
    assert main(["validate", path]) == 0
    assert len(calls) == 1 and calls[0][1:] == (3600, None, None), calls
    assert main(["table", path, "--max-entries", "3599", "--angles", "36", "--out", str(tmp_path / "out")]) == 2
    assert len(calls) == 2 and calls[1][1:] == (3600, 3599, "36"), calls
    err = capsys.readouterr().err
    assert "3600 entries, more than 3599" in err and "--angles 36 means 36 angles" in err, err
    assert not (tmp_path / "out").exists()


def test_the_check_takes_its_limit_and_angles_as_arguments(tmp_path):
    spec = parse_table_spec(table(tmp_path, 10))  # 10 axes x 36 angles = 360 entries
    entries = len(spec.axes) * len(spec.angles_deg)
    assert entries == 360
    assert table_command.check_table_work(spec, entries) is None  # within the default limit
    assert table_command.MAX_ENTRIES < 3600
    with pytest.raises(ScenarioError) as default:
        table_command.check_table_work(spec, 3600)
    assert default.value.path == "--max-entries" and f"more than {table_command.MAX_ENTRIES}" in str(default.value)
    assert table_command.check_table_work(spec, entries, max_entries=360) is None
    with pytest.raises(ScenarioError) as given:
        table_command.check_table_work(spec, entries, max_entries=359, angles="36")
    assert "360 entries, more than 359" in str(given.value) and "--angles 36 means 36 angles" in str(given.value)
    assert "give --max-entries 360" in str(given.value)
    with pytest.raises(ScenarioError, match="expected a positive number of entries, got 0"):
        table_command.check_table_work(spec, entries, max_entries=0)


# --- a bare --angles count that reads like degrees (report 51 M3) ---

def test_a_bare_count_that_reads_like_degrees_is_refused_within_the_entry_limit(tmp_path, capsys, monkeypatch):
    """``--axes 12 --angles 90`` is 12 x 90 = 1080 entries, under the 2000 limit: the user meant the
    angle 90 deg. Refused before anything is computed or written, naming the count, the work and
    both ways on; ``--max-entries`` confirms the work."""
    import scenarios.slewtable.compute as compute

    def computed(*args, **kwargs):
        raise AssertionError("the table was computed")
    monkeypatch.setattr(compute, "compute_table", computed)
    path = table(tmp_path, 12)
    out = tmp_path / "out"
    assert 12 * 90 < table_command.MAX_ENTRIES
    assert main(["table", path, "--angles", "90", "--out", str(out), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "--angles: 90 is a count: 90 angles" in err and "12 axes x 90 angles = 1080 entries" in err, err
    assert "not the angle 90 deg" in err and "--angles 60,90,120" in err and "--max-entries 1080" in err, err
    assert not out.exists()


def test_the_count_limit_is_bare_angles_and_max_entries_confirms_the_work(tmp_path, capsys):
    spec = parse_table_spec(table(tmp_path, 10))  # the check reads the count as given, beside the spec
    limit = table_command.BARE_ANGLES
    assert table_command.check_table_work(spec, 10 * limit, angles=str(limit)) is None
    assert f"--angles {limit} is a count: {limit} angles spread from 10 to 180 deg" in capsys.readouterr().out
    with pytest.raises(ScenarioError) as over:
        table_command.check_table_work(spec, 10 * (limit + 1), angles=str(limit + 1))
    assert over.value.path == "--angles" and f"--max-entries {10 * (limit + 1)}" in over.value.message
    assert table_command.check_table_work(spec, 900, max_entries=900, angles="90") is None  # confirmed
    assert "--angles 90 is a count" in capsys.readouterr().out
    assert table_command.check_table_work(spec, 900, angles="30,90") is None  # a list: degrees, no note
    assert capsys.readouterr().out == ""


def test_a_trailing_comma_makes_a_list_not_a_count():
    from scenarios.schema.table import angles_from_text
    assert len(angles_from_text("8")) == 8
    with pytest.raises(ScenarioError) as one:
        angles_from_text("90,")  # one angle in degrees: a table needs two
    assert one.value.path == "--angles" and "at least 2 angles in degrees" in one.value.message
    assert "got [90.0]" in one.value.message
    assert angles_from_text("90,180,") == [90.0, 180.0]


# --- a table file's bare count is checked as the flag's, at its YAML path (report 52) ---

def _counted(folder, angles, axes=12):
    """A table file of ``axes`` Fibonacci axes whose ``angles_deg`` is ``angles`` as written."""
    from tests.test_validate_files import BOX, write
    write(folder, "box.yaml", BOX)
    return write(folder, "table.yaml", {"table": {"scenario": "box.yaml", "axes": axes, "grid": "fibonacci",
                                                  "angles_deg": angles}})


def test_a_table_files_bare_count_that_reads_like_degrees_is_refused_at_its_yaml_path(tmp_path, capsys, monkeypatch):
    """``angles_deg: 90`` on 12 axes is 1080 entries, under the 2000 limit: the file meant 90 deg.
    ``table`` refuses it before computing, naming the YAML path, the count, the work and both ways
    on; ``validate`` foretells it (a finding); ``--max-entries`` confirms the work."""
    import scenarios.slewtable.compute as compute

    def computed(*args, **kwargs):
        raise AssertionError("the table was computed")
    monkeypatch.setattr(compute, "compute_table", computed)
    path = _counted(tmp_path, 90)
    out = tmp_path / "out"
    assert main(["table", path, "--out", str(out), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "table.angles_deg: 90 is a count: 90 angles spread from 10 to 180 deg" in err, err
    assert "12 axes x 90 angles = 1080 entries" in err and "not the angle 90 deg" in err, err
    assert "angles_deg: [60, 90, 120]" in err and "--max-entries 1080" in err and "Traceback" not in err, err
    assert not out.exists()
    assert main(["validate", path, "--strict"]) == 1
    assert "table.angles_deg: 90 is a count" in capsys.readouterr().out
    spec = parse_table_spec(path)
    assert (spec.angles_count, spec.angles_where) == (90, "table.angles_deg")
    assert table_command.check_table_work(spec, 1080, max_entries=1080) is None  # confirmed
    assert "table.angles_deg: 90 is a count: 90 angles" in capsys.readouterr().out


def test_a_table_files_small_count_is_said_to_be_one_and_a_flag_wins_over_it(tmp_path, capsys):
    spec = parse_table_spec(_counted(tmp_path, table_command.BARE_ANGLES, axes=4))
    assert len(spec.angles_deg) == table_command.BARE_ANGLES
    assert table_command.check_table_work(spec, 4 * table_command.BARE_ANGLES) is None
    assert f"table.angles_deg: {table_command.BARE_ANGLES} is a count" in capsys.readouterr().out
    flagged = parse_table_spec(_counted(tmp_path, 90, axes=4), {"angles": "30,90"})  # the flag's list wins
    assert flagged.angles_count is None and flagged.angles_deg == [30.0, 90.0]
    assert table_command.check_table_work(flagged, 8) is None and capsys.readouterr().out == ""
    counted = parse_table_spec(_counted(tmp_path, [30, 90], axes=4), {"angles": "40"})  # the flag's count
    with pytest.raises(ScenarioError) as flag:
        table_command.check_table_work(counted, 160)
    assert flag.value.path == "--angles" and "40 is a count" in flag.value.message
    listed = parse_table_spec(_counted(tmp_path, [30, 90], axes=4))  # a list: degrees, no note
    assert listed.angles_count is None and table_command.check_table_work(listed, 8) is None
    assert capsys.readouterr().out == ""


@pytest.mark.parametrize("written", [90.0, 2.0, 1e2])
def test_a_lone_number_that_is_not_whole_is_neither_a_count_nor_angles(tmp_path, capsys, written):
    """``angles_deg: 90.0`` is not a count (a whole number) and one angle is not a table: refused
    at its YAML path, naming the value and both forms."""
    assert main(["validate", _counted(tmp_path, written)]) == 2
    err = capsys.readouterr().err
    assert "table.angles_deg" in err and f"got the lone number {written!r}" in err, err
    assert "a list of at least 2 angles in degrees" in err and "a count of angles" in err and "Traceback" not in err


def test_the_schema_says_a_bare_number_is_a_count_not_degrees():
    from scenarios.schema.table import TABLE
    key = TABLE["angles_deg"]
    # the reference writes the unit after the type: it reads as the list's, the count's said to be a count
    assert f"{key.type} [{key.unit}]" == "a whole number (a count of angles), or a list of angles [deg]"
    assert "a whole number ``n``, a count, not an angle" in key.meaning
