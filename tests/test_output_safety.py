"""Output safety: slewbench writes only into directories it owns and never touches a user's files.

Each test starts from a layout that lost data before this was enforced (issue 11, section 1).
"""
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.errors import OutputError
from scenarios.output.directory import MARKER, STAGING_PREFIX
from scenarios.output.names import default_output_directory, row_stems

REPO = Path(__file__).resolve().parents[1]

TINY = """
name: tiny
spacecraft: {inertia: [2.0, 3.0, 4.0], wheels: {max_torque: 0.05}}
maneuver:
  duration: 20.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.9659258, 0.2588190, 0, 0], omega: [0, 0, 0]}
planners:
  - {name: eigenaxis, label: smooth}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
simulation: {sample_time: 0.5}
"""


def scenario(tmp_path: Path, text: str = TINY, file: str = "s.yaml", **changes) -> Path:
    data = yaml.safe_load(textwrap.dedent(text))
    data.update(changes)
    path = tmp_path / file
    path.write_text(yaml.safe_dump(data))
    return path


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize("where", ["cwd", "scenario_folder", "parent"])
def test_out_at_a_users_directory_is_refused_and_nothing_is_touched(where, tmp_path, monkeypatch, capsys):
    user = tmp_path / "work"
    user.mkdir()
    (user / "thesis.tex").write_text("three years of work")
    path = scenario(user)
    before = snapshot(tmp_path)
    monkeypatch.chdir(user)
    out = {"cwd": ".", "scenario_folder": str(user), "parent": str(tmp_path)}[where]
    assert main(["run", str(path), "--out", out, "--no-plots"]) == 2
    error = capsys.readouterr().err
    assert "did not create" in error and "nothing was touched" in error and "Traceback" not in error
    assert snapshot(tmp_path) == before


def test_out_at_an_existing_file_is_an_error(tmp_path, capsys):
    path = scenario(tmp_path)
    target = tmp_path / "results.txt"
    target.write_text("keep me")
    assert main(["run", str(path), "--out", str(target), "--no-plots"]) == 2
    assert "not a directory" in capsys.readouterr().err
    assert target.read_text() == "keep me"


def test_subprocess_run_keeps_a_user_file_in_a_slewbench_directory(tmp_path):
    """End to end through the console entry point: a rerun into slewbench's own directory
    replaces slewbench's files and leaves the user's file alone."""
    path = scenario(tmp_path)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "scenarios.cli", "run", str(path), "--out", str(out), "--no-plots"]
    first = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    (out / "notes.txt").write_text("my notes")
    second = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=300)
    assert second.returncode == 0, second.stderr
    assert (out / "notes.txt").read_text() == "my notes"
    manifest = json.loads((out / MARKER).read_text())
    assert manifest["complete"] is True and "notes.txt" not in manifest["files"]
    assert "results.json" in manifest["files"] and "timeseries/smooth.csv" in manifest["files"]


def test_a_user_file_named_like_a_result_is_never_overwritten(tmp_path, capsys):
    path = scenario(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    manifest = json.loads((out / MARKER).read_text())
    (out / "results.json").unlink()  # the user deletes ours and writes their own file of that name
    manifest["files"].remove("results.json")
    (out / MARKER).write_text(json.dumps(manifest))
    (out / "results.json").write_text("user data")
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 2
    assert "did not write" in capsys.readouterr().err
    assert (out / "results.json").read_text() == "user data"


def test_a_user_file_among_the_files_a_run_would_write_is_refused_before_planning(tmp_path, capsys):
    # a figure the earlier run (no plots) did not write, whose name the user then took
    path = scenario(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    capsys.readouterr()
    (out / "smooth.png").write_text("user figure")
    assert main(["run", str(path), "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert "[1/" not in captured.out and "rows:" not in captured.out  # nothing was planned, no table printed
    assert "smooth.png" in captured.err and "did not write" in captured.err
    assert (out / "smooth.png").read_text() == "user figure"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0  # a run that does not write it goes on
    assert (out / "smooth.png").read_text() == "user figure"
    # a figure this run does not draw (no pointing requirement: no sky or margins figure) is no clash
    (out / "smooth.png").unlink()
    (out / "sky.png").write_text("my photo")
    assert main(["run", str(path), "--out", str(out)]) == 0
    assert (out / "sky.png").read_text() == "my photo" and (out / "smooth.png").is_file()


def test_an_empty_directory_is_claimed_and_stale_results_are_removed(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    two = scenario(tmp_path, planners=[{"name": "eigenaxis", "label": "a"}, {"name": "eigenaxis", "label": "b"}])
    assert main(["run", str(two), "--out", str(out), "--no-plots"]) == 0
    assert (out / "timeseries" / "b.csv").exists()
    one = scenario(tmp_path, file="one.yaml", planners=[{"name": "eigenaxis", "label": "a"}])
    assert main(["run", str(one), "--out", str(out), "--no-plots"]) == 0
    assert not (out / "timeseries" / "b.csv").exists() and (out / "timeseries" / "a.csv").exists()


@pytest.mark.parametrize("name", ["..", "", " ", "/etc", "../escape", "a/../../b", "α", "results", "x" * 500])
def test_default_output_path_stays_one_level_under_results(name):
    path = default_output_directory(name)
    assert path.parent == Path("results")
    assert path.name not in ("", ".", "..") and "/" not in path.name and len(path.name) <= 80


@pytest.mark.parametrize("name", ["..", "../escape", "/tmp/abs"])
def test_scenario_name_cannot_write_outside_results(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "keep.txt").write_text("keep")
    path = scenario(tmp_path, name=name)
    assert main(["run", str(path), "--no-plots"]) == 0
    produced = [p for p in tmp_path.rglob(MARKER)]
    assert len(produced) == 1 and produced[0].parent.parent == tmp_path / "results"
    assert (tmp_path / "keep.txt").read_text() == "keep"


def test_empty_name_is_an_error(tmp_path, capsys):
    assert main(["validate", str(scenario(tmp_path, name=""))]) == 2
    assert "name: expected a non-empty name" in capsys.readouterr().err


@pytest.mark.parametrize("labels", [["a/b", "a_b"], ["α", "β"], ["comparison", "x"], ["A", "a"], ["Margins", "sky"],
                                    ["results", "timeseries"]])
def test_rows_get_distinct_file_names(labels):
    stems = row_stems(labels)
    lowered = [s.lower() for s in stems]
    assert len(set(lowered)) == len(labels)
    assert not {"comparison", "margins", "results", "sky", "timeseries"} & set(lowered)


def test_colliding_labels_each_get_their_own_time_series(tmp_path):
    path = scenario(tmp_path, planners=[{"name": "eigenaxis", "label": "a/b"}, {"name": "eigenaxis", "label": "a_b"},
                                        {"name": "eigenaxis", "label": "comparison"}])
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out)]) == 0
    # readable: the label that is the stem keeps it, the other gets -2; comparison.png is slewbench's
    assert sorted(p.name for p in (out / "timeseries").glob("*.csv")) == ["a_b-2.csv", "a_b.csv", "comparison-2.csv"]
    assert sorted(p.name for p in out.glob("*.png")) == ["a_b-2.png", "a_b.png", "comparison-2.png", "comparison.png"]


# the stems written out by hand from the rule (docs/outputs.rst, "Distinct rows, distinct files")
@pytest.mark.parametrize(("labels", "stems"), [
    (["a/b", "a_b"], ["a_b-2", "a_b"]),  # the label that is the stem keeps it
    (["a/b", "a b"], ["a_b", "a_b-2"]),  # else the first, in row order
    (["A", "a", "a"], ["A", "a-2", "a-3"]),  # compared ignoring case
    (["α", "β"], ["row", "row-2"]),  # nothing usable: row
    (["comparison", "Sky", "x"], ["comparison-2", "Sky-2", "x"]),  # slewbench's own file is the first
    (["a/b", "a_b", "a_b-2"], ["a_b-3", "a_b", "a_b-2"]),  # a label that is a suffix keeps its stem
    # case variants are one file name: the first label that is its stem exactly keeps it
    (["a/b", "A_B", "a_b", "a_b-2"], ["a_b-3", "A_B", "a_b-4", "a_b-2"]),
    (["a/b", "a_b", "A_B"], ["a_b-2", "a_b", "A_B-3"]),
    (["pd", "k=0.5", "lqr gain", "wheel.2"], ["pd", "k=0.5", "lqr_gain", "wheel.2"]),  # no collision: as sanitised
])
def test_colliding_labels_get_a_numeric_suffix_in_row_order(labels, stems):
    assert row_stems(labels) == stems


def test_each_rows_file_stem_is_recorded_and_names_its_time_series(tmp_path):
    import csv

    from scenarios.output.export import read_run
    labels = ["a/b", "A_B", "a_b", "a_b-2"]
    path = scenario(tmp_path, planners=[{"name": "eigenaxis", "label": label} for label in labels])
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    expected = {"a/b": "a_b-3", "A_B": "A_B", "a_b": "a_b-4", "a_b-2": "a_b-2"}  # by hand, the rule in the docs
    rows = json.loads((out / "results.json").read_text())["rows"]
    assert {row["label"]: row["file_stem"] for row in rows} == expected
    lines = list(csv.reader((out / "results.csv").read_text().splitlines()))
    assert lines[0][:7] == ["label", "planner", "controller", "status", "message", "plan_time_s", "plan_reused"]
    assert lines[0][-1] == "file_stem"  # appended: the columns before it keep their places
    assert {line[0]: line[-1] for line in lines[1:]} == expected
    for label, stem in expected.items():  # each file is its row's: the time series of that row's planner
        assert (out / "timeseries" / f"{stem}.csv").is_file()
    assert {row.label: row.stem for row in read_run(out).rows} == expected


def restamp(out):
    """The manifest's stamps of the files as they are now: the run as an older slewbench wrote it
    (an export refuses files changed since their run wrote them)."""
    from scenarios.output.directory import _stamp
    marker = out / MARKER
    manifest = json.loads(marker.read_text())
    manifest["stamps"] = {name: [_stamp(out / name)] for name in manifest["files"]}
    marker.write_text(json.dumps(manifest))


def test_export_reads_the_recorded_stem_and_works_it_out_for_an_older_run(tmp_path):
    from scenarios.output.export import read_run
    path = scenario(tmp_path, planners=[{"name": "eigenaxis", "label": "a/b"}, {"name": "eigenaxis", "label": "a_b"}])
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    results = out / "results.json"
    data = json.loads(results.read_text())
    (out / "timeseries" / "a_b.csv").rename(out / "timeseries" / "kept.csv")
    manifest = out / MARKER
    manifest.write_text(manifest.read_text().replace("timeseries/a_b.csv", "timeseries/kept.csv"))
    data["rows"][1]["file_stem"] = "kept"
    results.write_text(json.dumps(data))
    restamp(out)
    assert [(row.stem, row.timeseries.name if row.timeseries else None) for row in read_run(out).rows] == [
        ("a_b-2", "a_b-2.csv"), ("kept", "kept.csv")]  # the recorded stem, not the label's
    for row in data["rows"]:  # a run written before the field: worked out from the labels
        del row["file_stem"]
    (out / "timeseries" / "kept.csv").rename(out / "timeseries" / "a_b.csv")
    manifest.write_text(manifest.read_text().replace("timeseries/kept.csv", "timeseries/a_b.csv"))
    results.write_text(json.dumps(data))
    restamp(out)
    assert [row.stem for row in read_run(out).rows] == ["a_b-2", "a_b"]
    assert all(row.timeseries is not None for row in read_run(out).rows)


def test_a_suffix_keeps_a_long_stem_within_the_limit():
    from scenarios.output.names import MAX_STEM
    long = "x" * (MAX_STEM + 5)
    stems = row_stems([long, long + "y"])  # both cut to the same MAX_STEM characters
    assert stems == ["x" * MAX_STEM, "x" * (MAX_STEM - 2) + "-2"]


@pytest.mark.parametrize("make", ["parent_is_file", "too_long", "unwritable"])
def test_write_failures_are_found_before_planning(make, tmp_path, capsys):
    path = scenario(tmp_path)
    if make == "parent_is_file":
        (tmp_path / "file").write_text("x")
        out = tmp_path / "file" / "out"
    elif make == "too_long":
        out = tmp_path / ("n" * 300)
    else:
        if os.geteuid() == 0:  # root ignores permissions; /proc refuses new directories to anyone
            out = Path("/proc/slewbench-test-out")
        else:
            locked = tmp_path / "locked"
            locked.mkdir(mode=0o500)
            out = locked / "out"
    start = time.perf_counter()
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 2
    captured = capsys.readouterr()
    assert "[1/1]" not in captured.out  # nothing was planned
    assert "--out" in captured.err and "Traceback" not in captured.err
    assert time.perf_counter() - start < 5.0


def test_a_killed_run_leaves_nothing_that_looks_complete_and_the_next_run_cleans_up(tmp_path):
    """SIGKILL in the middle of writing (simulated by a leftover staging folder and an incomplete
    manifest), then a normal run: the staging folder is gone and the manifest is complete."""
    path = scenario(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    leftover = out / f"{STAGING_PREFIX}abc"
    leftover.mkdir()
    (leftover / "results.json").write_text("{partial")
    manifest = json.loads((out / MARKER).read_text())
    manifest["complete"] = False
    (out / MARKER).write_text(json.dumps(manifest))
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    assert not leftover.exists()
    assert json.loads((out / MARKER).read_text())["complete"] is True


def test_sigterm_during_a_run_leaves_nothing_behind(tmp_path):
    # 400,000 samples: long enough to be interrupted even by the compiled-speed closed loop (issue 13)
    slow = scenario(tmp_path, simulation={"sample_time": 0.01, "duration": 10000.0})  # 10⁶ samples: seconds even compiled
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "scenarios.cli", "run", str(slow), "--out", str(out)],
                               cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    while not (out / MARKER).exists() and time.time() < deadline and process.poll() is None:
        time.sleep(0.05)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode != 0 and "Traceback" not in err
    # the run wrote nothing, so it withdrew its claim: the directory it made is gone (staging too)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml"]


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_swallowed_during_the_run_still_stops_it_before_writing(tmp_path, monkeypatch, capsys, signum):
    """A KeyboardInterrupt raised by the SIGTERM or Ctrl-C handler can be lost on the way (inside
    a finaliser, recorded as a failed row, or turned into a failed solve by CasADi inside IPOPT);
    seen in CI: SIGTERM, then exit 0 with complete results; seen in review: Ctrl-C during a
    collocation solve, the same. The run must still stop, with nothing written but the marker,
    marked incomplete."""
    import scenarios.cli.commands as cli
    real_run = cli.run

    def run_swallowing_a_sigterm(*args, **kwargs):
        try:
            os.kill(os.getpid(), signum)
            time.sleep(1.0)  # the handler runs here
        except KeyboardInterrupt:
            pass  # swallowed on the way, as a C extension may
        return real_run(*args, **kwargs)

    monkeypatch.setattr(cli, "run", run_swallowing_a_sigterm)
    out = tmp_path / "out"
    assert main(["run", str(scenario(tmp_path)), "--out", str(out), "--no-plots"]) == 1
    assert "interrupted" in capsys.readouterr().err
    assert not out.exists()  # nothing written: the claim withdrawn, not a directory of results


def test_a_manifest_naming_files_outside_its_directory_is_not_trusted(tmp_path, capsys):
    """A shared or edited manifest listing ``../x`` or an absolute path must not make a run
    delete or replace those files: the directory is then not slewbench's."""
    path = scenario(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    precious, absolute = tmp_path / "precious.txt", tmp_path / "abs.txt"
    precious.write_text("keep")
    absolute.write_text("keep")
    manifest = json.loads((out / MARKER).read_text())
    manifest["files"] += ["../precious.txt", str(absolute)]
    (out / MARKER).write_text(json.dumps(manifest))
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 2
    assert precious.read_text() == "keep" and absolute.read_text() == "keep"
    assert "did not create" in capsys.readouterr().err


def test_a_symlinked_folder_inside_the_output_is_refused(tmp_path, capsys):
    path = scenario(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    elsewhere = tmp_path / "userdata"
    elsewhere.mkdir()
    (elsewhere / "smooth.csv").write_text("user")
    (elsewhere / "old.csv").write_text("user")
    manifest = json.loads((out / MARKER).read_text())
    manifest["files"].append("timeseries/old.csv")
    (out / MARKER).write_text(json.dumps(manifest))
    for name in list((out / "timeseries").iterdir()):
        name.unlink()
    (out / "timeseries").rmdir()
    (out / "timeseries").symlink_to(elsewhere)
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert (elsewhere / "smooth.csv").read_text() == "user" and (elsewhere / "old.csv").read_text() == "user"


def test_a_live_runs_staging_folder_survives_another_run(tmp_path):
    """Two runs into one directory: the second removes only staging folders of dead processes."""
    from scenarios.output.directory import claim_output_directory, new_staging
    out = claim_output_directory(tmp_path / "out")
    mine = new_staging(out)  # this process is alive
    dead = out / f"{STAGING_PREFIX}999999999-x"
    dead.mkdir()
    claim_output_directory(out)
    assert mine.is_dir() and not dead.exists()


def test_codegen_output_never_replaces_a_runs_results(tmp_path, capsys):
    path = scenario(tmp_path)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    before = snapshot(out)
    assert main(["codegen", str(path), "--out", str(out)]) == 2
    assert "directory of its own" in capsys.readouterr().err
    assert snapshot(out) == before


OUTPUT_OPTIONS = [
    ["run", "scenarios/eigenaxis_demo.yaml", "--out"],
    ["bench", "--problems", "bilimoria_wie_45", "--out"],
    ["sweep", "scenarios/study_spin_monte_carlo.yaml", "--out"],
    ["sweep", "--report"],
    ["table", "scenarios/eigenaxis_demo.yaml", "--out"],
    ["codegen", "scenarios/eigenaxis_demo.yaml", "--out"],
    ["export", "results/none", "--format", "aem", "--out"],
]
"""Every command's output-directory option, before its value."""


def _refused_output(argv: list[str], value: str, tmp_path: Path, monkeypatch, capsys) -> str:
    """Run ``argv`` + ``value`` in an empty ``tmp_path``: exit 2, nothing made there; its stderr."""
    root = Path(__file__).resolve().parents[1]
    monkeypatch.chdir(tmp_path)
    argv = [str(root / a) if a.startswith("scenarios/") else a for a in argv]
    with pytest.raises(SystemExit) as stop:
        main([*argv, value])
    assert stop.value.code == 2
    assert list(tmp_path.iterdir()) == []  # no results/, no directory named after the value
    return capsys.readouterr().err


@pytest.mark.parametrize("argv", OUTPUT_OPTIONS)
def test_an_empty_output_directory_is_refused_not_replaced_by_the_default(argv, tmp_path, monkeypatch, capsys):
    """``--out ""`` wrote into results/<name> without a word."""
    assert "an empty path: give the output directory" in _refused_output(argv, "", tmp_path, monkeypatch, capsys)


@pytest.mark.parametrize("argv", OUTPUT_OPTIONS)
def test_a_dash_output_directory_is_refused_not_made(argv, tmp_path, monkeypatch, capsys):
    """``--out -`` (a dash usually means standard output) made a directory named ``-``."""
    err = _refused_output(argv, "-", tmp_path, monkeypatch, capsys)
    assert f"{argv[-1]}: '-' is not standard output here: slewbench writes a directory of files" in err


def test_a_file_changed_since_slewbench_wrote_it_is_not_replaced(tmp_path, capsys):
    """A user saved their own figure over a run's output, with the same name; the rerun replaced it
    (the manifest knew names only). Its stamp (size, mtime) now says it is no longer slewbench's."""
    demo = str(Path(__file__).resolve().parents[1] / "scenarios" / "eigenaxis_demo.yaml")
    out = tmp_path / "run"
    assert main(["run", demo, "--out", str(out), "--no-plots"]) == 0
    manifest = json.loads((out / MARKER).read_text())
    assert set(manifest["stamps"]) == set(manifest["files"]) and "results.md" in manifest["stamps"]
    assert main(["run", demo, "--out", str(out), "--no-plots"]) == 0  # its own files: replaced
    (out / "results.md").write_text("my notes")
    capsys.readouterr()
    assert main(["run", demo, "--out", str(out), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "changed since slewbench wrote them (results.md)" in err and "nothing was touched" in err
    assert (out / "results.md").read_text() == "my notes"
    import shutil  # a copy of the directory (new modification times) is still slewbench's: stamps are contents
    copy = tmp_path / "copy"
    (out / "results.md").unlink()  # gone: nothing to replace, the run goes on
    shutil.copytree(out, copy, copy_function=shutil.copy)
    assert main(["run", demo, "--out", str(copy), "--no-plots"]) == 0
    assert main(["run", demo, "--out", str(out), "--no-plots"]) == 0
    assert (out / "results.md").read_text().startswith("#")


def test_an_interrupted_commit_keeps_every_file_stamped(tmp_path, monkeypatch):
    """A commit that stops between its moves left the manifest without stamps, and a user's later
    edit of a listed file was then replaced. While a commit moves, a file it replaces may hold the
    old content or the new: both stamps stand, any other content is the user's."""
    from scenarios.output.directory import (
        claim_output_directory,
        commit_outputs,
        new_staging,
    )

    out = claim_output_directory(tmp_path / "out")
    staging = new_staging(out)
    (staging / "a.txt").write_text("a1")
    (staging / "b.txt").write_text("b1")
    commit_outputs(out, staging, kind="run")
    staging = new_staging(out)
    (staging / "a.txt").write_text("a2")
    (staging / "b.txt").write_text("b2")
    real = os.replace
    moved = []

    def interrupted(source, target):  # the second move out of staging fails (the marker's writes pass)
        if STAGING_PREFIX in str(source):
            if moved:
                raise OSError(28, "No space left on device")
            moved.append(target)
        real(source, target)

    monkeypatch.setattr(os, "replace", interrupted)
    with pytest.raises(OSError):
        commit_outputs(out, staging, kind="run")
    monkeypatch.setattr(os, "replace", real)
    assert {(out / "a.txt").read_text(), (out / "b.txt").read_text()} == {"a2", "b1"}  # one moved, one not
    edited = out / ("b.txt" if (out / "a.txt").read_text() == "a2" else "a.txt")
    edited.write_text("the user's")
    staging = new_staging(out)
    (staging / "a.txt").write_text("a3")
    (staging / "b.txt").write_text("b3")
    with pytest.raises(OutputError, match=f"changed since slewbench wrote them \\({edited.name}\\)"):
        commit_outputs(out, staging, kind="run")
    assert edited.read_text() == "the user's"


@pytest.mark.parametrize("number", ["ENOSPC", "EDQUOT", "EROFS"])
def test_a_file_system_that_refuses_a_write_is_an_output_error_not_a_bug(number, tmp_path, monkeypatch, capsys):
    """A full disk while the outputs were staged: a traceback and 'internal error (this is a bug)',
    exit 1. Now exit 2 naming the cause, no traceback; the earlier complete output is kept."""
    import errno
    out = tmp_path / "out"
    assert main(["run", str(scenario(tmp_path)), "--out", str(out), "--no-plots"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    original = Path.write_text

    def full(self, *args, **kwargs):
        if self.name == "results.md":
            raise OSError(getattr(errno, number), os.strerror(getattr(errno, number)))
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Path, "write_text", full)
    capsys.readouterr()
    assert main(["run", str(scenario(tmp_path)), "--out", str(out), "--no-plots"]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"slewbench: output error: cannot write: {os.strerror(getattr(errno, number))}; the "
                            "files being written were discarded"), error
    assert "Traceback" not in error and "bug" not in error
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == before
    assert not [p for p in out.iterdir() if p.name.startswith(STAGING_PREFIX)]


@pytest.mark.parametrize("command", ["table", "sweep"])
def test_a_full_disk_at_the_store_is_an_output_error(command, tmp_path, monkeypatch, capsys):
    """SQLite's 'database or disk is full' opening the store: `table` printed a traceback and
    'internal error (this is a bug ...)'; `sweep` named it with a stray '[Errno 28]'."""
    import sqlite3

    def full(*args, **kwargs):
        error = sqlite3.OperationalError("database or disk is full")
        error.sqlite_errorcode = 13  # SQLITE_FULL
        raise error

    monkeypatch.setattr("scenarios.study.store.sqlite3.connect", full)
    path = scenario(tmp_path)
    if command == "sweep":
        study = tmp_path / "study.yaml"
        study.write_text(yaml.safe_dump({"study": "full", "scenario": path.name,
                                         "grid": {"controller.options.kp": [0.2, 0.3]}}))
        argv = ["sweep", str(study), "--workers", "1"]
    else:
        argv = ["table", str(path), "--axes", "2", "--grid", "fibonacci", "--angles", "30,90"]
    assert main([*argv, "--out", str(tmp_path / "out"), "--no-plots"]) == 2
    error = capsys.readouterr().err
    assert "cannot open the sweep store" in error and "database or disk is full" in error, error
    assert "Traceback" not in error and "bug" not in error and "[Errno" not in error, error
