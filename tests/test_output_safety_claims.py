"""Output safety across a command's directories and between scenarios: a refused command touches none
of the directories it would write (``run --export``: the run's and the export's), and a run
directory holding another scenario's run is not replaced by a run of a different scenario."""
import json
import textwrap
from pathlib import Path

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.errors import OutputError
from scenarios.output.directory import (
    MARKER,
    check_output_directory,
    claim_output_directory,
)

TINY = """
name: tiny
epoch: 2027-03-20T12:00:00Z
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


def scenario(tmp_path: Path, file: str = "s.yaml", **changes) -> Path:
    data = yaml.safe_load(textwrap.dedent(TINY))
    data.update(changes)
    path = tmp_path / file
    path.write_text(yaml.safe_dump(data))
    return path


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_a_foreign_export_directory_leaves_the_run_directory_unmade(tmp_path, capsys):
    """User A's F5: the export directory is refused before the run's is claimed, so exit 2 touches nothing."""
    path = scenario(tmp_path)
    foreign = tmp_path / "sl4-aem"
    foreign.mkdir()
    (foreign / "x").write_text("keep")
    assert main(["run", str(path), "--out", str(tmp_path / "sl4"), "--no-plots", "--export", "aem"]) == 2
    error = capsys.readouterr().err
    assert "sl4-aem" in error and "nothing was touched" in error and "`--export aem` writes" in error
    assert "output error: --out" not in error  # the export directory is not the one given as --out
    assert not (tmp_path / "sl4").exists()
    assert snapshot(foreign) == {"x": b"keep"} and sorted(p.name for p in tmp_path.iterdir()) == ["s.yaml", "sl4-aem"]


def test_a_foreign_export_directory_leaves_an_earlier_run_directory_as_it_was(tmp_path, capsys):
    path = scenario(tmp_path)
    out = tmp_path / "sl4"
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    before = snapshot(out)
    (tmp_path / "sl4-aem").mkdir()
    (tmp_path / "sl4-aem" / "x").write_text("keep")
    (out / ".slewbench-staging-x-abandoned").mkdir()  # a claim would remove an abandoned staging folder
    capsys.readouterr()
    assert main(["run", str(path), "--out", str(out), "--no-plots", "--export", "aem"]) == 2
    assert snapshot(out) == before and (out / ".slewbench-staging-x-abandoned").is_dir()


def test_check_output_directory_writes_nothing(tmp_path):
    new = tmp_path / "a" / "b"
    assert check_output_directory(new) == new.absolute()
    assert not (tmp_path / "a").exists()
    empty = tmp_path / "empty"
    empty.mkdir()
    check_output_directory(empty)
    assert list(empty.iterdir()) == []
    claim_output_directory(empty, kind="export")
    manifest = json.loads((empty / MARKER).read_text())
    (empty / "f").write_text("x")
    (empty / MARKER).write_text(json.dumps({**manifest, "files": ["f"]}))
    before = snapshot(empty)
    with pytest.raises(OutputError, match="holds slewbench export output"):
        check_output_directory(empty, kind="run")
    assert snapshot(empty) == before


def test_a_name_too_long_for_the_file_system_is_found_before_anything_is_made(tmp_path):
    with pytest.raises(OutputError, match="too long"):
        check_output_directory(tmp_path / "fine" / ("n" * 300))
    assert not (tmp_path / "fine").exists()


def test_a_run_of_another_scenario_is_not_replaced(tmp_path, capsys):
    """User A's F6: the directory names its scenario in results.json; another scenario is refused."""
    first = scenario(tmp_path, "a.yaml", name="user-a-12u")
    other = scenario(tmp_path, "b.yaml", name="fast")
    out = tmp_path / "run1"
    assert main(["run", str(first), "--out", str(out), "--no-plots"]) == 0
    before = snapshot(out)
    capsys.readouterr()
    assert main(["run", str(other), "--out", str(out), "--no-plots"]) == 2
    captured = capsys.readouterr()
    assert "'user-a-12u'" in captured.err and "'fast'" in captured.err and "--out on the command line" in captured.err
    assert "[1/1]" not in captured.out  # refused before planning
    assert snapshot(out) == before


def test_a_run_of_the_same_scenario_replaces_its_earlier_run(tmp_path, capsys):
    path = scenario(tmp_path, name="same")
    out = tmp_path / "run1"
    assert main(["run", str(path), "--out", str(out)]) == 0
    path.write_text(path.read_text().replace("duration: 20.0", "duration: 25.0"))
    capsys.readouterr()
    assert main(["run", str(path), "--out", str(out), "--no-plots"]) == 0
    assert "removed" in capsys.readouterr().out  # the plots of the earlier run (documented)
    written = json.loads((out / "results.json").read_text())
    assert written["provenance"]["scenario"]["maneuver"]["duration"] == 25.0


def test_a_run_directory_that_names_no_scenario_is_reused(tmp_path):
    out = tmp_path / "run1"
    assert main(["run", str(scenario(tmp_path, name="first")), "--out", str(out), "--no-plots"]) == 0
    (out / "results.json").unlink()  # what is left names no scenario
    assert main(["run", str(scenario(tmp_path, "b.yaml", name="second")), "--out", str(out), "--no-plots"]) == 0
    assert json.loads((out / "results.json").read_text())["scenario"] == "second"


def test_the_library_refuses_to_write_a_run_over_another_scenarios(tmp_path):
    import scenarios

    out = tmp_path / "out"
    results = scenarios.run(scenarios.load(scenario(tmp_path, name="first")))
    results.write(out, plots=False)
    results.write(out, plots=False)  # the same scenario again: replaced
    before = snapshot(out)
    other = scenarios.run(scenarios.load(scenario(tmp_path, "b.yaml", name="second")))
    with pytest.raises(OutputError, match="'first', not 'second'"):
        other.write(out, plots=False)
    assert snapshot(out) == before


def test_a_stored_case_is_not_rerun_over_another_scenarios_run(tmp_path, capsys):
    from tests.test_study_plots_progress import STUDY

    study = tmp_path / "study.yaml"
    study.write_text(STUDY)  # its cases' scenario is named "tiny"
    swept = tmp_path / "swept"
    assert main(["sweep", str(study), "--out", str(swept), "--no-plots", "--workers", "1"]) == 0
    other = tmp_path / "other"
    assert main(["run", str(scenario(tmp_path, name="other")), "--out", str(other), "--no-plots"]) == 0
    before = snapshot(other)
    capsys.readouterr()
    assert main(["sweep", str(swept), "--case", "1", "--out", str(other), "--no-plots"]) == 2
    captured = capsys.readouterr()
    assert "'other', not 'tiny'" in captured.err
    assert "case 1" not in captured.out  # refused before the case re-ran
    assert snapshot(other) == before
    assert main(["sweep", str(swept), "--case", "1", "--out", str(tmp_path / "case1"), "--no-plots"]) == 0
    assert main(["sweep", str(swept), "--case", "2", "--out", str(tmp_path / "case1"), "--no-plots"]) == 0
