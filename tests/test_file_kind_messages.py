"""A file given to the wrong command, or an empty file: the message says what the file is and what
to do (the mirror of ``run`` refusing a study file, tested in ``test_show_cli``)."""
from __future__ import annotations

from pathlib import Path

import pytest

from scenarios.cli.commands import main

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "scenarios" / "eigenaxis_demo.yaml"


def test_sweep_refuses_a_scenario_file_and_names_the_command(tmp_path, capsys):
    """It said 'study: required key is missing'."""
    assert main(["sweep", str(DEMO), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "is a scenario file, not a study" in err and f"slewbench run {DEMO}" in err, err
    assert "required key is missing" not in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("text", ["", "\n\n", "# a scenario, one day\n# name: x\n"])
@pytest.mark.parametrize("command", ["validate", "run", "sweep"])
def test_an_empty_or_comment_only_file_is_called_empty(tmp_path, capsys, text, command):
    """It said '(top level): expected a mapping, got None'."""
    path = tmp_path / "slew.yaml"
    path.write_text(text)
    extra = [] if command == "validate" else ["--out", str(tmp_path / "out")]
    assert main([command, str(path), *extra]) == 2
    err = capsys.readouterr().err
    assert f"{path}: the file is empty" in err, err
    assert "None" not in err and err.count(str(path)) == 1, err
