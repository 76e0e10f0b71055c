"""No output directory inside another one (docs/outputs.rst, "What slewbench writes"): ``slewbench
export RUN --out RUN/sub`` put an export inside the run it was made from, where it reads as part of
the run and a re-run of the run leaves it stale; every command that claims a directory through the
shared check refuses a path inside a directory carrying slewbench's marker, naming both, with exit
status 2 and nothing touched. A sweep's case re-runs (``DIR/cases/N``) are the one place an output
holds others. Oracle: the file trees before and after, and where the markers are."""
from __future__ import annotations

from pathlib import Path

import pytest

from scenarios.cli.commands import main
from scenarios.errors import OutputError
from scenarios.output.directory import (
    MARKER,
    check_output_directory,
    claim_output_directory,
    enclosing_output,
    write_manifest,
)
from tests.test_output_safety_claims import scenario, snapshot


def marked(folder: Path, kind: str) -> Path:
    folder.mkdir(parents=True)
    write_manifest(folder, [], complete=True, kind=kind)
    return folder


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    root = tmp_path_factory.mktemp("nesting")
    out = root / "run"
    assert main(["run", str(scenario(root)), "--out", str(out), "--no-plots"]) == 0
    return out


def test_an_export_into_its_own_run_directory_is_refused(run, capsys):
    before = snapshot(run)
    assert main(["export", str(run), "--format", "aem", "--out", str(run / "sub")]) == 2
    err = capsys.readouterr().err
    assert f"{run / 'sub'}: is inside {run}, a slewbench run output directory" in err, err
    assert "choose a directory outside" in err and "nothing was touched" in err and "Traceback" not in err
    assert snapshot(run) == before and not (run / "sub").exists()
    # beside it (the default), it is written
    assert main(["export", str(run), "--format", "aem", "--out", str(run.with_name("run-beside"))]) == 0


def test_a_run_into_another_run_directory_is_refused_before_planning(run, capsys):
    before = snapshot(run)
    assert main(["run", str(scenario(run.parent, "t.yaml")), "--out", str(run / "timeseries" / "x"),
                 "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert f"is inside {run}, a slewbench run output directory" in err, err
    assert snapshot(run) == before


def test_an_earlier_nested_output_is_refused_too_and_left_as_it_was(tmp_path):
    outer = marked(tmp_path / "outer", "run")
    inner = marked(outer / "inner", "export")
    with pytest.raises(OutputError, match="is inside .*outer, a slewbench run output directory"):
        claim_output_directory(inner, kind="export")
    assert sorted(p.name for p in inner.iterdir()) == [MARKER]


def test_a_sweep_holds_its_case_reruns_and_nothing_else(tmp_path):
    sweep = marked(tmp_path / "sweep", "sweep")
    assert enclosing_output(sweep / "cases" / "3") is None  # sweep DIR --case 3
    assert check_output_directory(sweep / "cases" / "3") == sweep / "cases" / "3"
    assert enclosing_output(sweep / "cases") == (sweep, "sweep")
    assert enclosing_output(sweep / "other") == (sweep, "sweep")
    case = marked(sweep / "cases" / "3", "run")
    assert enclosing_output(case / "deeper") == (case, "run")
    assert enclosing_output(tmp_path / "free" / "x") is None
