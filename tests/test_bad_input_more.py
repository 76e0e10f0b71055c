"""Bad input found by trying mistakes on the command line and in the YAML: each was a traceback
("internal error") or an unclear message before its fix; each is one line with exit status 2 now,
naming the file once, the place and what is wrong."""
from __future__ import annotations

import copy

import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.errors import ScenarioError, in_file
from scenarios.schema.loader import load
from tests.test_sweep import BASE


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize("content, where", [
    (b"\x00\x01\x02", "line 1, column 1): character #x0000"),
    (b"name: x\n\x01\n", "line 2, column 1): character #x0001"),
    (b"name: x\nplanners: [\x07]\n", "line 2, column 12): character #x0007"),
])
@pytest.mark.parametrize("command", ["validate", "run", "sweep", "table"])
def test_a_binary_file_is_not_yaml_text_not_a_crash(command, content, where, tmp_path, capsys):
    """A NUL or another control character: PyYAML refuses the text when its reader is made, before
    the parse the loader guarded (a ``ReaderError``, an internal error)."""
    path = tmp_path / "binary.yaml"
    path.write_bytes(content)
    assert main([command, str(path), "--out", str(tmp_path / "out")] if command != "validate" else
                 [command, str(path)]) == 2
    line = _one_error_line(capsys)
    assert line.count(str(path)) == 1, line
    assert f"not YAML text ({where} is not allowed in YAML" in line, line


def test_a_binary_file_is_a_scenario_error_from_the_library(tmp_path):
    path = tmp_path / "binary.yaml"
    path.write_bytes(b"\x00")
    with pytest.raises(ScenarioError, match="not YAML text"):
        load(path)


@pytest.mark.parametrize("key, shown", [(None, "None"), (1, "1"), (2.5, "2.5")])
@pytest.mark.parametrize("parent", ["", "maneuver", "spacecraft"])
def test_a_key_that_is_not_a_name_is_said_to_be_one(key, shown, parent, tmp_path, capsys):
    """``~: 1`` at the top level made a ScenarioError whose path was None (``in_file`` then failed
    on it: an internal error); ``1: 2`` was reported at the path ``[1]``, as a list's item."""
    data = copy.deepcopy(BASE)
    (data[parent] if parent else data)[key] = 1
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == 2
    line = _one_error_line(capsys)
    prefix = f"{parent}: " if parent else ""
    assert f"{path}: {prefix}a key must be a name, got {shown} (a YAML null or number); expected one of [" in line, line


def test_a_study_key_that_is_not_a_name_is_said_to_be_one(tmp_path, capsys):
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "s", "scenario": copy.deepcopy(BASE), None: 1}))
    assert main(["validate", str(path)]) == 2
    assert "study.yaml: a key must be a name, got None" in _one_error_line(capsys)


def test_in_file_takes_an_error_without_a_path():
    error = in_file(ScenarioError(None, "what went wrong"), "a.yaml")  # type: ignore[arg-type]
    assert str(error) == "a.yaml: what went wrong"


@pytest.mark.parametrize("text, why", [
    (".nan", "got nan (NaN and infinities are not accepted)"),
    (".inf", "got inf (NaN and infinities are not accepted)"),
    ("-.inf", "got -inf (NaN and infinities are not accepted)"),
    ("9" * 400, "(too large: beyond the range of a float, about 1.8e308)"),
])
def test_a_number_that_is_not_finite_says_why_it_is_refused(text, why, tmp_path, capsys):
    """``expected a number, got nan``: NaN is a number to a reader; the message says what is refused."""
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(BASE).replace("duration: 30.0", f"duration: {text}"))
    assert main(["validate", str(path)]) == 2
    line = _one_error_line(capsys)
    assert "maneuver.duration: expected a number, got " in line and why in line, line


def test_table_option_infinity_says_why_it_is_refused(tmp_path, capsys):
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(BASE))
    assert main(["table", str(path), "--duration", "inf", "--out", str(tmp_path / "out")]) == 2
    assert "--duration: expected a number, got inf (NaN and infinities are not accepted)" in _one_error_line(capsys)


def test_sweep_case_given_the_study_file_asks_for_the_sweep_directory(tmp_path, capsys):
    """``--case N`` re-runs a stored case from the sweep's directory; given the study file it said
    ``output error: study.yaml: holds no slewbench sweep``."""
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "s", "scenario": copy.deepcopy(BASE)}))
    assert main(["sweep", str(path), "--case", "0"]) == 2
    line = _one_error_line(capsys)
    assert "--case: re-runs a case of a stored sweep: give the sweep's output directory" in line, line
    assert line.count(str(path)) == 1


def test_validate_of_a_huge_torque_bound_prints_no_numpy_warning(tmp_path, capsys):
    """A 1e300 N m wheel torque: the plausibility check's norm overflowed and numpy's
    ``RuntimeWarning: overflow encountered in dot`` was printed amid validate's output; the
    plausibility warning (a unit slip?) is what the user is shown."""
    import warnings
    data = copy.deepcopy(BASE)
    data["spacecraft"]["wheels"]["max_torque"] = 1e300
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert main(["validate", str(path)]) == 0
    captured = capsys.readouterr()
    assert "RuntimeWarning" not in captured.err + captured.out
    assert "spacecraft.wheels.max_torque: 1e+300 N m" in captured.out


@pytest.mark.parametrize("encoding, byte, line", [("latin-1", "0xe9", 1), ("utf-16", "0xff", 1)])
@pytest.mark.parametrize("command", ["validate", "run"])
def test_a_file_not_in_utf8_says_so_and_what_to_do(encoding, byte, line, command, tmp_path, capsys):
    """Was ``cannot read FILE: 'utf-8' codec can't decode byte 0xe9 in position 7: invalid
    continuation byte``."""
    path = tmp_path / "scenario.yaml"
    rest = yaml.safe_dump({key: value for key, value in BASE.items() if key != "name"})
    path.write_bytes(f"name: tést\n{rest}".encode(encoding))  # the first non-ASCII byte on line 1
    assert main([command, str(path), "--out", str(tmp_path / "out")] if command == "run" else [command, str(path)]) == 2
    message = _one_error_line(capsys)
    assert message.count(str(path)) == 1, message
    assert f"not UTF-8 text (byte {byte} on line {line}); save it as UTF-8" in message, message
    assert "codec" not in message
