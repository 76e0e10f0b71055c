"""Every command that reads a scenario names the file in its error, not only the YAML path: ``run``,
``validate``, ``codegen``, ``table`` (a scenario given as the table, or named by a table file),
``sweep`` (its study file, and the base scenario a study names), and the library's readers
(:func:`scenarios.load`, :func:`scenarios.load_study`, :func:`~scenarios.slewtable.spec.parse_table_spec`,
:func:`~scenarios.bench.suite.load_suite`) keep the file in the exception. A file that is not YAML, missing,
a directory or empty is one line on standard error that names the file (once), exit status 2, no traceback.

Oracles: the file names and YAML paths written by hand below; the exit status of a bad file is the
documented 2 (docs/guide/scenarios.rst, "Exit status").
"""
from __future__ import annotations

from pathlib import Path

import pytest
import yaml

import scenarios
from scenarios.bench.suite import load_suite
from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.slewtable.spec import parse_table_spec

BAD = "spacecraft:\n  inertia: [1, 2]\n"  # no name: the first key the loader misses
SYNTAX = "name: x\nspacecraft:\n  inertia: [1, 2\n  wheels: {\n"  # unclosed brackets
# the commands that read a scenario file; each also needs what its own parser requires
COMMANDS = {"run": ["--no-plots"], "validate": [], "codegen": [], "table": []}
OUT = {"run", "codegen", "table"}  # take --out (given, so that nothing is written under results/)


def _cli(command: str, file: Path, tmp_path: Path, capsys) -> tuple[int, str]:
    extra = [*COMMANDS.get(command, []), *(["--out", str(tmp_path / "out")] if command in OUT | {"sweep"} else [])]
    status = main([command, str(file), *extra])
    captured = capsys.readouterr()
    return status, captured.err


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_scenario_error_names_the_file_and_the_yaml_path(command, tmp_path, capsys):
    path = tmp_path / "bad.yaml"
    path.write_text(BAD)
    status, err = _cli(command, path, tmp_path, capsys)
    assert status == 2, err
    assert err == f"slewbench: error in scenario: {path}: name: required key is missing\n", err  # table too: a scenario
    assert not (tmp_path / "out").exists()


def _inputs(tmp_path: Path) -> dict[str, Path]:
    """A file of each bad kind (the name says which)."""
    syntax, empty, folder = tmp_path / "syntax.yaml", tmp_path / "empty.yaml", tmp_path / "folder.yaml"
    syntax.write_text(SYNTAX)
    empty.write_text("# nothing here\n\n")
    folder.mkdir()
    return {"syntax": syntax, "empty": empty, "directory": folder, "missing": tmp_path / "missing.yaml"}


WORDS = {"syntax": "not valid YAML (line", "empty": "the file is empty", "directory": "it is a directory",
         "missing": "file not found"}


@pytest.mark.parametrize("bad", sorted(WORDS))
@pytest.mark.parametrize("command", [*sorted(COMMANDS), "sweep"])
def test_a_file_that_cannot_be_read_is_one_line_naming_it(command, bad, tmp_path, capsys):
    path = _inputs(tmp_path)[bad]
    status, err = _cli(command, path, tmp_path, capsys)
    assert status == 2, err
    assert err.startswith("slewbench: error in ") and err.endswith("\n") and err.count("\n") == 1, err
    assert WORDS[bad] in err and str(path) in err and "Traceback" not in err, err
    if command != "validate" or bad in ("syntax", "empty"):  # validate names a file of unknown kind as its kind
        assert err.count(str(path)) == 1, err
    assert not (tmp_path / "out").exists()


def test_a_missing_file_is_called_by_the_kind_the_command_reads(tmp_path, capsys):
    missing = tmp_path / "missing.yaml"
    for command, kind in (("run", "scenario"), ("sweep", "study"), ("table", "table")):
        _, err = _cli(command, missing, tmp_path, capsys)
        assert f"{kind} file not found: {missing}" in err, (command, err)


def test_a_studys_base_scenario_file_is_named_with_the_study(tmp_path, capsys):
    base = tmp_path / "base.yaml"
    base.write_text(BAD)
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "s", "scenario": "base.yaml", "grid": {"maneuver.duration": [10.0]}}))
    for command in ("sweep", "validate"):
        status, err = _cli(command, study, tmp_path, capsys)
        assert status == 2 and err == (f"slewbench: error in study file: {study}: scenario: {base}: name: required "
                                       "key is missing\n"), (command, err)


def test_a_table_files_scenario_is_named_with_the_table_file(tmp_path, capsys):
    (tmp_path / "bad.yaml").write_text(BAD)
    table = tmp_path / "table.yaml"
    table.write_text(yaml.safe_dump({"table": {"scenario": "bad.yaml", "axes": 6, "angles_deg": [30, 60]}}))
    status, err = _cli("table", table, tmp_path, capsys)
    assert status == 2 and err == (f"slewbench: error in table file: {table}: {tmp_path / 'bad.yaml'}: name: required "
                                   "key is missing\n"), err


def test_an_option_error_is_the_options_not_the_files(tmp_path, capsys):
    demo = Path(scenarios.__file__).parent / "eigenaxis_demo.yaml"
    status = main(["table", str(demo), "--objective", "min_energy", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert status == 2 and err.startswith("slewbench: error in option: --duration: "), err
    assert str(demo) not in err, err


def test_the_library_keeps_the_file_in_the_exception(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(BAD)
    with pytest.raises(ScenarioError) as error:
        scenarios.load(bad)
    assert (error.value.file, error.value.path, error.value.message) == (bad, "name", "required key is missing")
    assert str(error.value) == f"{bad}: name: required key is missing"
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "s", "scenario": "bad.yaml", "grid": {"maneuver.duration": [10.0]}}))
    with pytest.raises(ScenarioError) as error:
        scenarios.load_study(str(study))
    assert (error.value.file, error.value.path) == (study, f"scenario: {bad}: name"), error.value
    assert str(error.value) == f"{study}: scenario: {bad}: name: required key is missing"
    with pytest.raises(ScenarioError) as error:
        parse_table_spec(bad)
    assert error.value.file == bad and str(error.value).startswith(f"{bad}: "), error.value
    with pytest.raises(ScenarioError) as error:
        scenarios.load(tmp_path / "missing.yaml")
    assert error.value.file == tmp_path / "missing.yaml" and error.value.path == "", error.value
    assert str(error.value) == f"scenario file not found: {tmp_path / 'missing.yaml'}"
    empty = tmp_path / "empty.yaml"
    empty.write_text("")
    with pytest.raises(ScenarioError) as error:
        scenarios.load(empty)
    assert error.value.path == "" and str(error.value).count(str(empty)) == 1, error.value


def test_a_bench_suite_error_names_the_index(tmp_path):
    index = tmp_path / "suite.yaml"
    index.write_text(yaml.safe_dump({"version": 0, "problems": {}}))
    with pytest.raises(ScenarioError) as error:
        load_suite(index)
    assert error.value.file == index and str(error.value).startswith(f"{index}: version: expected a positive"), error.value


def test_parsed_data_without_a_file_names_none():
    with pytest.raises(ScenarioError) as error:
        scenarios.parse_scenario(yaml.safe_load(BAD))
    assert error.value.file is None and str(error.value) == "name: required key is missing"
