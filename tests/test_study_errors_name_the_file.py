"""An error in a study or a slew-table file names the file as well as the YAML path, where its own text
does not (a study's ``execution.scheduler`` that does not answer, a table's ``table`` that is not a
mapping); with no file given, the error is the command line's."""
from __future__ import annotations

import yaml

import scenarios.study.engine as engine
from scenarios.cli.commands import main

STUDY = {
    "study": "tiny", "scenario": {
        "name": "tiny", "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
        "maneuver": {"duration": 20.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                     "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
        "planners": [{"name": "eigenaxis"}], "controller": {"name": "augmented_quaternion_feedback"}},
    "grid": {"maneuver.duration": [20.0, 22.0]}, "execution": {"scheduler": "tcp://127.0.0.1:1"}}


def test_a_studys_scheduler_that_does_not_answer_names_the_study_file(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(engine, "HANDSHAKE_TIMEOUT_S", 0.5)
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(STUDY, sort_keys=False))
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"slewbench: error in study file: {path}: execution.scheduler: no Dask scheduler"), err
    assert main(["sweep", str(path), "--out", str(tmp_path / "out"), "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert capsys.readouterr().err.startswith("slewbench: error in option: --scheduler: ")  # the option's own


def test_an_error_that_names_the_file_names_it_once(tmp_path, capsys):
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({**STUDY, "gird": {}}, sort_keys=False))
    assert main(["sweep", str(path), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"slewbench: error in study file: {path}: gird: unknown key") and err.count(str(path)) == 1
    assert main(["sweep", str(tmp_path / "none.yaml"), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count(str(tmp_path / "none.yaml")) == 1 and "study file not found" in err, err


def test_a_table_file_error_names_the_file_under_table_and_validate(tmp_path, capsys):
    path = tmp_path / "t.yaml"
    path.write_text("table: t\n")
    for command in ("table", "validate"):
        assert main([command, str(path)]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"slewbench: error in table file: {path}: table: expected a mapping"), (command, err)


def test_no_study_file_given_is_the_command_lines_error(capsys):
    assert main(["sweep", "--dry-run"]) == 2
    assert capsys.readouterr().err == "slewbench: error in the command line: give a study file, or --report DIR\n"
