"""An export that cannot be completed leaves no export directory behind, and removes only what it
made itself: a damaged run (stamped or written before stamps) is refused before anything is
created, and a failure while writing withdraws the claim."""
import json
import shutil

import pytest

from scenarios.cli.commands import main
from scenarios.output import export as export_module
from scenarios.output.directory import MARKER
from tests.test_export_cli import _text_in_series, scenario_file


@pytest.fixture(scope="module")
def run_directory(tmp_path_factory):
    root = tmp_path_factory.mktemp("h2export")
    out = root / "run"
    assert main(["run", str(scenario_file(root)), "--out", str(out), "--no-plots"]) == 0
    return out


def _copy(run_directory, tmp_path, damage, stamped):
    run = tmp_path / "run"
    shutil.copytree(run_directory, run)
    damage(run)
    if not stamped:  # as written before the manifest kept stamps
        marker = run / MARKER
        manifest = json.loads(marker.read_text())
        manifest["stamps"] = {}
        marker.write_text(json.dumps(manifest))
    return run


def _times_repeated(run):
    path = run / "timeseries" / "smooth.csv"
    lines = path.read_text().splitlines(keepends=True)
    lines[3] = lines[2]  # the same sample twice: times that do not increase
    path.write_text("".join(lines))


@pytest.mark.parametrize("stamped", [True, False], ids=["stamped", "pre-stamp"])
@pytest.mark.parametrize("damage, fragment", [
    (_text_in_series, "could not convert string to float: 'abc'"),
    (_times_repeated, "not finite and strictly increasing"),
])
@pytest.mark.parametrize("format_name", ["aem", "basilisk"])
def test_a_damaged_run_is_refused_before_any_export_directory_is_made(run_directory, tmp_path, capsys, stamped,
                                                                      damage, fragment, format_name):
    # before: a pre-stamp run left <run>-aem/ marked incomplete (exit 2), and its repeated times were
    # a ValueError traceback (basilisk) or an export with the row left out
    run = _copy(run_directory, tmp_path, damage, stamped)
    assert main(["export", str(run), "--format", format_name]) == 2
    err = capsys.readouterr().err
    assert "timeseries/smooth.csv" in err
    if not stamped:
        assert fragment in err
    assert not run.with_name(f"run-{format_name}").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


def test_a_nested_new_out_is_not_left_behind(run_directory, tmp_path):
    run = _copy(run_directory, tmp_path, _text_in_series, stamped=False)
    assert main(["export", str(run), "--format", "aem", "--out", str(tmp_path / "a" / "b" / "export")]) == 2
    assert not (tmp_path / "a").exists()


def _failing_writer(monkeypatch, error):
    """The aem writer, failing after it has written one file into its staging folder."""
    format_ = export_module.EXPORT_FORMATS["aem"]

    def write(run, directory, options):
        (directory / "partial.aem").write_text("half")
        raise error

    monkeypatch.setitem(export_module.EXPORT_FORMATS, "aem", export_module.ExportFormat(
        format_.name, format_.description, format_.options, format_.check, write))


@pytest.mark.parametrize("error", [OSError(28, "No space left on device"), KeyboardInterrupt()])
def test_a_failure_while_writing_removes_what_this_export_made_and_only_that(run_directory, tmp_path, monkeypatch,
                                                                             error):
    export_run = export_module.export_run
    earlier = tmp_path / "earlier"
    export_run(run_directory, "aem", earlier)
    before = {p.name: p.read_bytes() for p in earlier.iterdir()}
    _failing_writer(monkeypatch, error)
    new = tmp_path / "new" / "deeper"
    empty = tmp_path / "empty"
    empty.mkdir()
    above = tmp_path / "yours"
    (above / "keep").mkdir(parents=True)
    for out in (new, empty, earlier, above / "export"):
        with pytest.raises(type(error)):
            export_run(run_directory, "aem", out)
    assert not (tmp_path / "new").exists()  # made by the export, with its parent
    assert empty.is_dir() and list(empty.iterdir()) == []  # the user's folder stays, the marker goes
    assert {p.name: p.read_bytes() for p in earlier.iterdir()} == before  # the earlier export, untouched
    assert json.loads((earlier / MARKER).read_text())["complete"]
    assert sorted(p.name for p in above.iterdir()) == ["keep"]  # the user's folder above stays


def test_a_run_write_that_fails_leaves_no_new_directory_and_an_earlier_run_as_it_was(tmp_path, monkeypatch):
    # before: RunResults.write interrupted (or out of space) left its new directory marked incomplete
    import scenarios
    from scenarios.output import writer
    results = scenarios.run(scenarios.load(scenario_file(tmp_path)))
    earlier = tmp_path / "earlier"
    results.write(earlier, plots=False)
    before = {p.relative_to(earlier): p.read_bytes() for p in earlier.rglob("*") if p.is_file()}

    def fail(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(writer, "write_timeseries", fail)
    for out in (tmp_path / "new" / "run", earlier):
        with pytest.raises(KeyboardInterrupt):
            results.write(out, plots=False)
    assert not (tmp_path / "new").exists()
    assert {p.relative_to(earlier): p.read_bytes() for p in earlier.rglob("*") if p.is_file()} == before
    assert json.loads((earlier / MARKER).read_text())["complete"]
