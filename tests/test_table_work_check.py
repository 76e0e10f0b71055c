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
