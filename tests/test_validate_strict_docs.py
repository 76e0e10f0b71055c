"""The requirements page's account of ``slewbench validate --strict`` on a study and a slew-table
file is the command's own output: each example there is run here and each of its lines checked
against what the command prints (a line ending in ``...`` is the start of the printed line), and
the limits the page states in words are the code's.

Oracles: the page (docs/guide/requirements.rst) against the command's output and constants.
"""
from __future__ import annotations

import contextlib
import io
import re
from pathlib import Path

import pytest

from scenarios.cli.commands import STRICT_LINES_SHOWN, main
from scenarios.cli.table import BARE_ANGLES, MAX_ENTRIES
from tests.test_validate_files import study, table

PAGE = Path(__file__).resolve().parents[1] / "docs" / "guide" / "requirements.rst"


def example(command: str) -> list[str]:
    """The lines of the page's text block that starts with ``command``, after it (dedented)."""
    lines = PAGE.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip() == command)
    indent = len(lines[start]) - len(lines[start].lstrip())
    block = []
    for line in lines[start + 1:]:
        if not line.strip():
            break
        block.append(line[indent:])
    return block


@pytest.mark.parametrize(("kind", "write"), [("study", lambda folder: study(folder, [[0.0, 0.0, 0.01], [0.0, 0.0, 0.2]])),
                                             ("table", lambda folder: table(folder, 100))])
def test_the_pages_validate_strict_examples_are_what_the_command_prints(tmp_path, monkeypatch, kind, write):
    write(tmp_path)
    monkeypatch.chdir(tmp_path)  # the file named as on the page
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(["validate", f"{kind}.yaml", "--strict"])
    assert status == 1
    printed = out.getvalue().splitlines() + err.getvalue().splitlines()
    shown = example(f"slewbench validate {kind}.yaml --strict")
    assert len(shown) == len(printed), (shown, printed)
    for line, actual in zip(shown, printed):
        if line.endswith("..."):
            assert actual.startswith(line.removesuffix("...").rstrip()), (line, actual)
        else:
            assert actual == line, (line, actual)


def test_the_limits_the_page_states_are_the_codes():
    text = re.sub(r"\s+", " ", PAGE.read_text())
    words = {10: "ten"}
    assert f"the first {words[STRICT_LINES_SHOWN]};" in text
    assert f"without ``--max-entries`` ({MAX_ENTRIES})" in text
    assert f"reads like an angle in degrees (above {BARE_ANGLES})" in text
