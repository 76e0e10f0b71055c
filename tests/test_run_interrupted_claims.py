"""``slewbench run`` interrupted (or failing) before it wrote its results leaves no output directory
behind that it made, and withdraws only its own claim where the directory was there before:
the run's and its ``--export`` directories, each checked on disk."""
import json

import pytest

from scenarios.cli import commands
from scenarios.cli.commands import main
from scenarios.cli.status import interrupted_status
from scenarios.output.directory import MARKER
from tests.test_export_cli import scenario_file


def _interrupt(*args, **kwargs):
    raise KeyboardInterrupt  # what Ctrl-C raises in the planning


@pytest.mark.parametrize("exports", [[], ["aem"]], ids=["run", "run-export"])
def test_an_interrupted_run_leaves_no_new_directory(tmp_path, monkeypatch, exports):
    # before: each claimed directory stayed, holding only a manifest marked incomplete
    monkeypatch.setattr(commands, "run", _interrupt)
    out = tmp_path / "new" / "run"
    argv = ["run", str(scenario_file(tmp_path)), "--out", str(out), "--no-plots"]
    for name in exports:
        argv += ["--export", name]
    assert main(argv) == interrupted_status("run")
    assert not (tmp_path / "new").exists()


def test_an_interrupted_run_keeps_the_users_empty_folder_and_an_earlier_run(tmp_path, monkeypatch):
    scenario = scenario_file(tmp_path)
    earlier = tmp_path / "earlier"
    assert main(["run", str(scenario), "--out", str(earlier), "--no-plots"]) == 0
    before = {p.relative_to(earlier): p.read_bytes() for p in earlier.rglob("*") if p.is_file()}
    empty = tmp_path / "mine"
    empty.mkdir()
    monkeypatch.setattr(commands, "run", _interrupt)
    for out in (earlier, empty):
        assert main(["run", str(scenario), "--out", str(out), "--no-plots"]) == interrupted_status("run")
    assert empty.is_dir() and not any(empty.iterdir())  # the folder stays, without the claim's marker
    assert {p.relative_to(earlier): p.read_bytes() for p in earlier.rglob("*") if p.is_file()} == before
    assert json.loads((earlier / MARKER).read_text())["complete"]


def test_a_withdrawn_claim_keeps_the_marker_of_another_run_writing_there(tmp_path):
    # two runs into the same new folder: the first (which made it) is interrupted while the
    # second is writing; before, the first removed the marker and the second's commit failed
    # ("lost its .slewbench-output.json while running")
    from scenarios.output.directory import (
        claim_output_directory,
        claimed_output_directory,
        commit_outputs,
        new_staging,
    )

    out = tmp_path / "X"
    with pytest.raises(KeyboardInterrupt):
        with claimed_output_directory(out):
            other = claim_output_directory(out)  # the second run's claim: the marker is there
            staging = new_staging(other)
            (staging / "results.json").write_text("{}")
            raise KeyboardInterrupt
    assert commit_outputs(other, staging, kind="run") == ["results.json"]
    assert json.loads((out / MARKER).read_text())["complete"]


def test_an_interrupted_run_keeps_the_empty_folders_above_those_it_made(tmp_path, monkeypatch):
    # the withdrawal stops at the outermost folder the claim created: a user's empty folder above
    # it stays (a withdrawal that went on up would remove it)
    monkeypatch.setattr(commands, "run", _interrupt)
    mine = tmp_path / "mine"
    mine.mkdir()
    argv = ["run", str(scenario_file(tmp_path)), "--out", str(mine / "new" / "run"), "--no-plots"]
    assert main(argv) == interrupted_status("run")
    assert mine.is_dir() and not any(mine.iterdir())


def test_an_export_interrupted_after_the_run_committed_keeps_the_run(tmp_path, monkeypatch):
    # the run's claim is not withdrawn once its files are committed: its marker stays, complete
    monkeypatch.setattr(commands, "export_run", _interrupt)
    out = tmp_path / "new"
    argv = ["run", str(scenario_file(tmp_path)), "--out", str(out), "--no-plots", "--export", "aem"]
    assert main(argv) == interrupted_status("run")
    manifest = json.loads((out / MARKER).read_text())
    assert manifest["complete"] and "results.json" in manifest["files"] and (out / "results.json").is_file()
    assert not (tmp_path / "new-aem").exists()


def test_an_interrupted_run_through_a_missing_folder_and_dotdot_keeps_the_users_folder(tmp_path, monkeypatch):
    # --out new/../mine/run: 'new' is missing, so 'new/..' and 'new/../mine' do not exist as
    # written, but 'mine' does (the user's, empty); before, the withdrawal took it for a folder
    # the claim made and removed it
    monkeypatch.setattr(commands, "run", _interrupt)
    mine = tmp_path / "mine"
    mine.mkdir()
    argv = ["run", str(scenario_file(tmp_path)), "--out", str(tmp_path / "new" / ".." / "mine" / "run"), "--no-plots"]
    assert main(argv) == interrupted_status("run")
    assert mine.is_dir() and not any(mine.iterdir())


def test_an_interrupted_case_rerun_leaves_no_folder_in_the_sweep(tmp_path, monkeypatch, capsys):
    # sweep DIR --case N claims DIR/cases/N as a run does; before, an interrupted re-run left it
    # (and DIR/cases) holding only a manifest marked incomplete
    import yaml

    from scenarios.study import rerun
    from tests.test_verdict_rules import slew

    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "budget", "scenario": slew(80.0, "trapezoidal"),
                                     "grid": {"maneuver.duration": [80.0]}}, sort_keys=False))
    out = tmp_path / "out"
    assert main(["sweep", str(study), "--out", str(out), "--no-plots", "--workers", "1"]) == 0, capsys.readouterr()
    monkeypatch.setattr(rerun, "rerun_case", _interrupt)
    assert main(["sweep", str(out), "--case", "0", "--no-plots"]) == interrupted_status("sweep")
    assert not (out / "cases").exists()


def test_dot_dot_through_a_missing_folder_is_checked_as_the_folder_it_names(tmp_path, capsys):
    # before: 'zz/../mine' (zz missing) was taken for a new path: a non-empty 'mine' gave "cannot be
    # written: File exists" after 'zz' had been created, and 'zz' stayed
    scenario = scenario_file(tmp_path)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("the user's")
    assert main(["run", str(scenario), "--out", str(tmp_path / "zz" / ".." / "mine"), "--no-plots"]) == 2
    assert "did not create" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine", "scenario.yaml"]
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["run", str(scenario), "--out", str(tmp_path / "zz" / ".." / "empty"), "--no-plots"]) == 0
    assert (empty / "results.json").is_file() and not (tmp_path / "zz").exists()


def test_a_symbolic_link_as_out_is_named_as_a_link(tmp_path, capsys):
    target = tmp_path / "real"
    target.mkdir()
    (tmp_path / "link").symlink_to(target)
    assert main(["run", str(scenario_file(tmp_path)), "--out", str(tmp_path / "link"), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "is a symbolic link" in err and str(target) in err  # it said "exists and is not a directory"
    assert not any(target.iterdir())
