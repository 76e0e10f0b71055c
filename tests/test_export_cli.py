"""``slewbench export`` and ``slewbench run --export``: a finished run's rows as CCSDS AEMs, read
back independently (the run's own time series CSV, parsed here, and ``ccsds-ndm-py`` when
installed), and the command line's refusals (exit status 2, nothing written)."""
import csv
import json
import shutil
import textwrap

import numpy as np
import pytest

from scenarios.cli.commands import main
from scenarios.output.aem import read_aem

SCENARIO = """
name: export check
epoch: 2027-03-20T12:00:00Z
spacecraft:
  inertia: [2.0, 3.0, 4.0]
  wheels: {max_torque: 0.05}
maneuver:
  duration: 30.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.9238795, 0.3826834, 0, 0], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth}
  - {name: eigenaxis, label: fast, options: {profile: min_time}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
simulation: {sample_time: 0.5, duration: 35.0, initial_attitude_error_deg: [0.5, 0.2, 0]}
"""


def scenario_file(tmp_path, text=SCENARIO, name="scenario.yaml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def csv_columns(path, names):
    """Columns of a time series CSV, parsed here with the csv module."""
    with path.open(newline="") as handle:
        rows = list(csv.DictReader(handle))
    return np.array([[float(row[name]) for name in names] for row in rows])


@pytest.fixture(scope="module")
def run_directory(tmp_path_factory):
    root = tmp_path_factory.mktemp("export")
    out = root / "run"
    assert main(["run", str(scenario_file(root)), "--out", str(out), "--no-plots", "--export", "aem"]) == 0
    return out


def test_run_export_writes_each_rows_reference_and_closed_loop_with_the_csv_quaternions(run_directory):
    export = run_directory.with_name("run-aem")
    names = sorted(p.name for p in export.iterdir() if not p.name.startswith("."))
    assert names == ["fast.closed_loop.aem", "fast.reference.aem", "smooth.closed_loop.aem", "smooth.reference.aem"]
    manifest = json.loads((export / ".slewbench-output.json").read_text())
    assert manifest["kind"] == "export" and manifest["complete"] and sorted(manifest["files"]) == names
    for label in ("smooth", "fast"):
        series = run_directory / "timeseries" / f"{label}.csv"
        t = csv_columns(series, ["t"])[:, 0]
        for scope, prefix in (("closed_loop", ""), ("reference", "ref_")):
            q = csv_columns(series, [f"{prefix}q{i}" for i in range(4)])
            omega = csv_columns(series, [f"{prefix}omega_{axis}" for axis in "xyz"])
            segment, = read_aem((export / f"{label}.{scope}.aem").read_text()).segments
            assert segment.metadata["ATTITUDE_TYPE"] == "QUATERNION/ANGVEL"
            assert segment.metadata["TIME_SYSTEM"] == "UTC" and segment.metadata["REF_FRAME_A"] == "GCRF"
            assert np.max(np.abs(segment.quaternions() - q)) < 1e-12
            assert np.max(np.abs(np.radians(segment.values[:, 4:]) - omega)) < 1e-12
            # the time tags: the epoch 12:00:00 plus the CSV's t (no leap second in March 2027)
            seconds = [int(tag[11:13]) * 3600 + int(tag[14:16]) * 60 + float(tag[17:]) - 12 * 3600
                       for tag in segment.epochs]
            assert np.max(np.abs(np.array(seconds) - t)) < 1e-9
            assert segment.epochs[0] == "2027-03-20T12:00:00.000000000"


def test_the_independent_reader_agrees_on_every_exported_file(run_directory):
    ndm = pytest.importorskip("ccsds_ndm", reason="ccsds-ndm-py (the `test` extra) reads AEMs independently")
    export = run_directory.with_name("run-aem")
    for path in sorted(export.glob("*.aem")):
        message = ndm.from_file(str(path))
        message.validate()
        data = message.segments[0].data.attitude_states_numpy
        mine = read_aem(path.read_text()).segments[0]
        assert np.max(np.abs(np.column_stack([data[:, 3], data[:, :3]]) - mine.quaternions())) < 1e-12
        assert list(message.segments[0].data.attitude_states_epochs) == mine.epochs


def test_export_command_with_options_and_a_rerun_into_its_own_directory(run_directory, tmp_path, capsys):
    out = tmp_path / "tt"
    argv = ["export", str(run_directory), "--format", "aem", "--out", str(out), "--option", "time_system=TT",
            "--option", "attitude_type=QUATERNION", "--option", "object_id=2027-012A"]
    assert main(argv) == 0
    assert main(argv) == 0  # its own directory: replaced
    assert "smooth.reference.aem" in capsys.readouterr().out
    segment, = read_aem((out / "smooth.reference.aem").read_text()).segments
    assert segment.metadata["TIME_SYSTEM"] == "TT" and segment.metadata["OBJECT_ID"] == "2027-012A"
    assert segment.values.shape[1] == 4 and "ANGVEL_FRAME" not in segment.metadata
    assert segment.epochs[0] == "2027-03-20T12:01:09.184000000"  # TT = UTC + 37 s + 32.184 s


def test_export_in_gps_time(run_directory, tmp_path):
    out = tmp_path / "gps"
    assert main(["export", str(run_directory), "--format", "aem", "--out", str(out), "--option", "time_system=GPS"]) == 0
    segment, = read_aem((out / "smooth.reference.aem").read_text()).segments
    assert segment.metadata["TIME_SYSTEM"] == "GPS"
    assert segment.epochs[0] == "2027-03-20T12:00:18.000000000"  # GPS = TAI - 19 s = UTC + 37 s - 19 s


@pytest.mark.parametrize("argv, fragment", [
    (["--option", "time_system=GLONASS"], "time_system"),
    (["--option", "colour=red"], "NAME one of time_system"),
    (["--option", "attitude_type=EULER_ANGLE"], "attitude_type"),
    # the last one silently won
    (["--option", "object_id=2027-012A", "--option", "object_id=2027-013B"],
     "--option object_id: given twice ('2027-012A', then '2027-013B')"),
    # a 5014-character OBJECT_NAME line was written (KVN lines are at most 254 characters, 6.6.1)
    (["--option", "object_name=" + "x" * 241], "--option object_name: 241 characters"),
    (["--option", "originator=" + "x" * 300], "expected at most 241, so that the ORIGINATOR line keeps to the 254"),
    # written as OBJECT_NAME = A_B, ORIGINATOR = __ _ and ORIGINATOR = UNKNOWN: other names than the ones given
    (["--option", "object_name=a\nb"], "--option object_name: 'a\\nb' has characters a KVN line cannot carry ('\\n')"),
    (["--option", "originator=ÄÖ é"], "--option originator: 'ÄÖ é' has characters a KVN line cannot carry"),
    (["--option", "originator="], "--option originator: '' is empty"),
    (["--option", "object_id= "], "--option object_id: '' is empty"),
])
def test_bad_options_exit_2_and_write_nothing(run_directory, tmp_path, capsys, argv, fragment):
    out = tmp_path / "bad"
    assert main(["export", str(run_directory), "--format", "aem", "--out", str(out), *argv]) == 2
    assert fragment in capsys.readouterr().err
    assert not out.exists()


def test_a_run_without_epoch_is_refused_naming_epoch(tmp_path, capsys):
    text = SCENARIO.replace("epoch: 2027-03-20T12:00:00Z\n", "")
    path = scenario_file(tmp_path, text)
    out = tmp_path / "plain"
    assert main(["run", str(path), "--out", str(out), "--no-plots", "--export", "aem"]) == 2
    assert "epoch" in capsys.readouterr().err and not out.exists()  # refused before planning
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    capsys.readouterr()
    assert main(["export", str(out), "--format", "aem"]) == 2
    error = capsys.readouterr().err
    assert "epoch" in error and "GCRF" in error
    assert not out.with_name("plain-aem").exists()


def test_an_interrupted_run_is_refused_and_nothing_is_exported(run_directory, tmp_path, capsys):
    """A run whose manifest says it is incomplete (interrupted while committing) holds files of two
    runs or half a run: exporting it would present them as complete."""
    import shutil
    copy = tmp_path / "interrupted"
    shutil.copytree(run_directory, copy)
    marker = copy / ".slewbench-output.json"
    manifest = json.loads(marker.read_text())
    assert manifest["complete"] is True
    marker.write_text(json.dumps({**manifest, "complete": False}))
    assert main(["export", str(copy), "--format", "aem", "--out", str(tmp_path / "aem")]) == 2
    assert "incomplete" in capsys.readouterr().err
    assert not (tmp_path / "aem").exists()


def test_a_recorded_stem_that_is_not_a_file_stem_is_worked_out_again_from_the_label(run_directory, tmp_path):
    """A ``file_stem`` in results.json that slewbench would not make (a path, say: an edited or foreign
    file) is not trusted: the stems come from the labels, the rule that named the run's files, so
    both rows are still exported under their own names."""
    import shutil

    from scenarios.output.export import export_run
    from tests.test_output_safety import restamp
    copy = tmp_path / "edited"
    shutil.copytree(run_directory, copy)
    data = json.loads((copy / "results.json").read_text())
    assert [row["file_stem"] for row in data["rows"]] == ["smooth", "fast"]
    data["rows"][0]["file_stem"] = "../smooth"
    (copy / "results.json").write_text(json.dumps(data))
    restamp(copy)  # stamped as its writer left it (an edit since is refused before any stem is read)
    report = export_run(copy, "aem", tmp_path / "aem")
    assert sorted(report.files) == ["fast.closed_loop.aem", "fast.reference.aem", "smooth.closed_loop.aem",
                                    "smooth.reference.aem"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["aem", "edited"]  # nothing written beside


def test_results_json_records_the_epoch_in_utc_with_z(run_directory):
    """The epoch as the scenario wrote it (2027-03-20T12:00:00Z), ISO 8601 with the UTC designator Z
    (docs: results.json's epoch), so a reader does not take it for local time."""
    import datetime
    data = json.loads((run_directory / "results.json").read_text())
    assert data["epoch"] == "2027-03-20T12:00:00Z"
    parsed = datetime.datetime.fromisoformat(data["epoch"].replace("Z", "+00:00"))
    assert parsed == datetime.datetime(2027, 3, 20, 12, tzinfo=datetime.timezone.utc)


def test_a_missing_or_foreign_directory_exits_2(tmp_path, capsys):
    assert main(["export", str(tmp_path / "nowhere"), "--format", "aem"]) == 2
    assert "is not a directory" in capsys.readouterr().err
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("a user's file")
    assert main(["export", str(mine), "--format", "aem"]) == 2
    assert "no run" in capsys.readouterr().err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]


def test_an_export_never_writes_into_a_users_directory(run_directory, tmp_path, capsys):
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("a user's file")
    assert main(["export", str(run_directory), "--format", "aem", "--out", str(mine)]) == 2
    assert "did not create" in capsys.readouterr().err
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]


def test_a_regulation_row_exports_its_closed_loop_only_and_says_so(tmp_path, capsys):
    text = SCENARIO.replace("""planners:
  - {name: eigenaxis, label: smooth}
  - {name: eigenaxis, label: fast, options: {profile: min_time}}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}""",
                            """planners: []
controller: {name: eigenaxis_pd, options: {kp: 0.2, kd: 0.6}}""")
    out = tmp_path / "regulation"
    assert main(["run", str(scenario_file(tmp_path, text)), "--out", str(out), "--no-plots", "--export", "aem"]) == 0
    printed = capsys.readouterr().out
    assert "no reference (regulation mode)" in printed
    export = out.with_name("regulation-aem")
    assert sorted(p.name for p in export.glob("*.aem")) == ["eigenaxis_pd.closed_loop.aem"]
    segment, = read_aem((export / "eigenaxis_pd.closed_loop.aem").read_text()).segments
    q = csv_columns(out / "timeseries" / "eigenaxis_pd.csv", ["q0", "q1", "q2", "q3"])
    assert np.max(np.abs(segment.quaternions() - q)) < 1e-12


def test_an_exported_row_the_run_did_not_score_ok_is_named_with_its_reason(tmp_path, capsys):
    """A user handed an AEM of a row that broke its keep-out to ops with no word on the console
    (only a COMMENT line in the file said its status)."""
    strict = SCENARIO + "requirements: {final: {error_deg: 1.0e-9}}\n"  # no closed loop settles to 1e-9 deg
    out = tmp_path / "run"
    assert main(["run", str(scenario_file(tmp_path, strict)), "--out", str(out), "--no-plots"]) == 0
    capsys.readouterr()
    statuses = {row["label"]: row["status"] for row in json.loads((out / "results.json").read_text())["rows"]}
    assert statuses == {"smooth": "violated", "fast": "violated"}
    assert main(["export", str(out), "--format", "aem", "--out", str(tmp_path / "aem")]) == 0
    said = capsys.readouterr().out
    for label in statuses:
        assert f"row {label!r}: exported, but the run scored it violated: " in said and "final" in said, said



def test_the_reason_in_the_note_is_cut_between_words_and_says_so(tmp_path, capsys, monkeypatch):
    """A reason longer than the note's limit is cut between words and ends in `` ...``: cut inside a
    token, ``over 0.05 deg`` read ``over 0.0`` (a user's basilisk export; the limit is lowered here
    so that the run's own messages are cut)."""
    import scenarios.output.export as export

    monkeypatch.setattr(export, "NOTE_MESSAGE_CHARS", 60)
    strict = SCENARIO + "requirements: {final: {error_deg: 1.0e-9}}\n"
    out = tmp_path / "run"
    assert main(["run", str(scenario_file(tmp_path, strict)), "--out", str(out), "--no-plots"]) == 0
    messages = {row["label"]: row["message"] for row in json.loads((out / "results.json").read_text())["rows"]}
    capsys.readouterr()
    assert main(["export", str(out), "--format", "aem", "--out", str(tmp_path / "aem")]) == 0
    said = capsys.readouterr().out
    for label, message in messages.items():
        flat = " ".join(message.split())
        assert len(flat) > 60, flat
        reason = said.split(f"row {label!r}: exported, but the run scored it violated: ", 1)[1].splitlines()[0]
        assert reason.endswith(" ...") and len(reason) <= 60, reason
        kept = reason.removesuffix(" ...")
        assert flat.startswith(kept) and flat[len(kept)] == " ", (kept, flat)  # whole words only

def test_rows_scored_ok_get_no_such_note(run_directory, tmp_path, capsys):
    statuses = {row["status"] for row in json.loads((run_directory / "results.json").read_text())["rows"]}
    assert statuses == {"ok"}
    assert main(["export", str(run_directory), "--format", "aem", "--out", str(tmp_path / "aem")]) == 0
    assert "scored it" not in capsys.readouterr().out


def test_the_note_goes_to_the_row_whose_file_it_is_when_stems_share_a_prefix(tmp_path, monkeypatch):
    """Row file stems hold dots (``k=0``, ``k=0.5``): a file of ``k=0.5`` was taken for ``k=0``'s."""
    from dataclasses import dataclass

    from scenarios.output import export as export_module

    text = (SCENARIO.replace("label: smooth", "label: k=0").replace("label: fast", "label: k=0.5")
            + "requirements: {final: {error_deg: 1.0e-9}}\n")  # both rows violated
    out = tmp_path / "run"
    assert main(["run", str(scenario_file(tmp_path, text)), "--out", str(out), "--no-plots"]) == 0

    @dataclass(frozen=True)
    class NoOptions:
        pass

    def write_one(run, directory, options):  # a format that writes the k=0.5 row only
        (directory / "k=0.5.waypoints.csv").write_text("t\n0\n")
        return []

    fake = export_module.ExportFormat("fake", "one row's file", NoOptions, lambda run, options: None, write_one)
    monkeypatch.setitem(export_module.EXPORT_FORMATS, "fake", fake)
    report = export_module.export_run(out, "fake", tmp_path / "fake")
    assert report.files == ["k=0.5.waypoints.csv"]
    assert [note.split(":")[0] for note in report.notes] == ["row 'k=0.5'"], report.notes


def test_a_reason_whose_first_word_is_longer_than_the_room_is_cut_at_the_room():
    """A word longer than the note's room (a long path) leaves no whole word to keep: the reason is
    cut at the room's end, not dropped (``textwrap.shorten`` gave ``...`` alone); a reason that fits
    is kept whole, on one line. Lengths by hand: 300 characters at most, 296 of them the text."""
    from scenarios.output.export import NOTE_MESSAGE_CHARS, _cut

    assert NOTE_MESSAGE_CHARS == 300
    assert _cut("x" * 400 + " tail") == "x" * 296 + " ..."
    path = "reference failed: /" + "a" * 320
    assert _cut(path) == path[:296] + " ..."
    assert _cut("final (closed loop):\n error 0.439 deg") == "final (closed loop): error 0.439 deg"


def _damage_copy(run_directory, tmp_path, damage):
    run = tmp_path / "run"
    shutil.copytree(run_directory, run)
    damage(run)
    return run


def _cut_series(run):  # a time series cut short: it was exported as a complete 3-sample AEM
    path = run / "timeseries" / "smooth.csv"
    path.write_text("".join(path.read_text().splitlines(keepends=True)[:4]))


def _text_in_series(run):  # was an internal error (ValueError: could not convert string to float), exit 1
    path = run / "timeseries" / "smooth.csv"
    lines = path.read_text().splitlines(keepends=True)
    lines[5] = "abc" + lines[5][lines[5].index(","):]
    path.write_text("".join(lines))


def _edited_epoch(run):  # was exit 0 with every row "not exported" and an empty export directory
    path = run / "results.json"
    data = json.loads(path.read_text())
    data["epoch"] = "2027-13-40T00:00:00Z"
    path.write_text(json.dumps(data))


@pytest.mark.parametrize("damage, fragment", [
    # was exit 0: row 'smooth' skipped as "not simulated (ok)", the other rows exported
    (lambda run: (run / "timeseries" / "smooth.csv").unlink(), "removed since slewbench wrote them: timeseries/smooth.csv"),
    (lambda run: shutil.rmtree(run / "timeseries"), "removed since slewbench wrote them: timeseries/fast.csv, "
                                                    "timeseries/smooth.csv"),
    (_cut_series, "changed since slewbench wrote them: timeseries/smooth.csv"),
    (_text_in_series, "changed since slewbench wrote them: timeseries/smooth.csv"),
    (_edited_epoch, "changed since slewbench wrote them: results.json"),
])
def test_a_run_directory_edited_or_half_deleted_is_refused_and_nothing_written(run_directory, tmp_path, capsys,
                                                                               damage, fragment):
    run = _damage_copy(run_directory, tmp_path, damage)
    out = tmp_path / "export"
    assert main(["export", str(run), "--format", "aem", "--out", str(out)]) == 2
    assert fragment in capsys.readouterr().err
    assert not out.exists()


def test_a_run_with_its_results_md_removed_still_exports(run_directory, tmp_path):
    # results.md is not read by an export: its loss changes nothing the export hands off
    run = _damage_copy(run_directory, tmp_path, lambda run: (run / "results.md").unlink())
    assert main(["export", str(run), "--format", "aem", "--out", str(tmp_path / "export")]) == 0


def test_text_in_a_series_of_a_run_without_stamps_is_named_not_an_internal_error(run_directory, tmp_path, capsys):
    # a run written before the manifest kept stamps cannot tell an edit: the bad cell is named
    run = _damage_copy(run_directory, tmp_path, _text_in_series)
    marker = run / ".slewbench-output.json"
    manifest = json.loads(marker.read_text())
    manifest["stamps"] = {}
    marker.write_text(json.dumps(manifest))
    assert main(["export", str(run), "--format", "aem", "--out", str(tmp_path / "export")]) == 2
    assert "smooth.csv: cannot be read as the time series of row 'smooth': could not convert string to float: 'abc'" \
        in capsys.readouterr().err
