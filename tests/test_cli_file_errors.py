"""Every command of the command line that reads a file, given one it cannot read (missing, a
directory, unreadable), exits with status 2 and one line that names the file exactly once and says
what is wrong; so do the commands that read a directory (``export RUN_DIR``, ``sweep --report``).

Before the fix ``slewbench validate`` named the file twice (``error in FILE: scenario file not
found: FILE``, ``error in DIR: cannot read DIR: it is a directory, not a file``).
"""
from __future__ import annotations

import errno
import os

import pytest

from scenarios.cli.commands import build_parser, main

FILE_COMMANDS = {
    "validate": lambda file, out: ["validate", file],
    "run": lambda file, out: ["run", file, "--out", out, "--no-plots"],
    "sweep": lambda file, out: ["sweep", file, "--out", out, "--no-plots"],
    "table": lambda file, out: ["table", file, "--out", out],
    "codegen": lambda file, out: ["codegen", file, "--out", out],
}
"""The commands whose positional argument is a YAML file, and their arguments."""
DIRECTORY_COMMANDS = {
    "export": lambda directory, out: ["export", directory, "--format", "aem", "--out", out],
    "sweep --report": lambda directory, out: ["sweep", "--report", directory],
}
"""The commands that read a directory slewbench wrote."""
NOT_READING = {"list", "schema", "bench"}
"""Commands that read no file or directory the user names (``bench`` reads its built-in problems)."""


def test_every_command_is_covered():
    """A new command must be added here (or to NOT_READING, if it reads no file it is given)."""
    subcommands = next(action for action in build_parser()._actions if action.dest == "command").choices
    assert set(subcommands) == set(FILE_COMMANDS) | {name.split()[0] for name in DIRECTORY_COMMANDS} | NOT_READING


def _missing(tmp_path, monkeypatch):
    return tmp_path / "missing.yaml", "not found"


def _directory(tmp_path, monkeypatch):
    folder = tmp_path / "a-folder.yaml"
    folder.mkdir()
    return folder, "it is a directory, not a file"


def _unreadable(tmp_path, monkeypatch):
    path = tmp_path / "locked.yaml"
    path.write_text("name: x\n")
    path.chmod(0)
    if os.access(path, os.R_OK):
        pytest.skip("running as root: a file without permissions is still readable")
    return path, "Permission denied"


def _refused(tmp_path, monkeypatch):
    """A file the system refuses to open (as for a user without permission; also when run as root)."""
    path = tmp_path / "refused.yaml"
    path.write_text("name: x\n")
    real_open = os.open

    def refusing_open(name, *args, **kwargs):
        if os.fspath(name) == str(path):
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        return real_open(name, *args, **kwargs)

    monkeypatch.setattr(os, "open", refusing_open)
    return path, "Permission denied"


def _exactly_one_line_naming(stderr: str, path: os.PathLike[str], expected: str) -> str:
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    line = lines[0]
    assert line.startswith("slewbench: "), line
    assert "Traceback" not in stderr
    assert line.count(str(path)) == 1, line
    assert expected in line, line
    return line


@pytest.mark.parametrize("case", [_missing, _directory, _unreadable, _refused],
                         ids=["missing", "directory", "unreadable", "refused"])
@pytest.mark.parametrize("command", sorted(FILE_COMMANDS))
def test_a_file_that_cannot_be_read_is_named_once(command, case, tmp_path, monkeypatch, capsys):
    path, expected = case(tmp_path, monkeypatch)
    out = tmp_path / "out"
    status = main(FILE_COMMANDS[command](str(path), str(out)))
    line = _exactly_one_line_naming(capsys.readouterr().err, path, expected)
    assert status == 2, line
    assert not out.exists()


@pytest.mark.parametrize("command", sorted(FILE_COMMANDS))
def test_a_missing_file_is_said_to_be_missing_in_the_command_s_terms(command, tmp_path, capsys):
    path = tmp_path / "missing.yaml"
    assert main(FILE_COMMANDS[command](str(path), str(tmp_path / "out"))) == 2
    line = capsys.readouterr().err.strip()
    if command == "validate":  # a scenario, a study or a table: the file is where, its kind not known yet
        assert line == f"slewbench: error in {path}: file not found"
    else:
        kind = {"sweep": "study file", "table": "table file"}.get(command, "scenario file")
        assert f"{kind} not found: {path}" in line


def test_validate_names_a_directory_once(tmp_path, capsys):
    assert main(["validate", str(tmp_path)]) == 2
    assert capsys.readouterr().err == f"slewbench: error in {tmp_path}: cannot read: it is a directory, not a file\n"


@pytest.mark.parametrize("case", ["missing", "a file"])
@pytest.mark.parametrize("command", sorted(DIRECTORY_COMMANDS))
def test_a_directory_argument_that_is_not_one_is_named_once(command, case, tmp_path, capsys):
    path = tmp_path / "run-dir"
    if case == "a file":
        path.write_text("name: x\n")
    status = main(DIRECTORY_COMMANDS[command](str(path), str(tmp_path / "out")))
    expected = "holds no slewbench sweep" if command == "sweep --report" else "is not a directory"
    line = _exactly_one_line_naming(capsys.readouterr().err, path, expected)
    assert status == 2, line
