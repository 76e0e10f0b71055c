"""A run whose table holds characters a legacy console encoding lacks (✗, ω) still writes its files.

A reviewer ran ``PYTHONIOENCODING=cp1252 slewbench run`` on a scenario with a broken requirement:
the terminal table's ✗ raised ``UnicodeEncodeError`` before any file was written (an "internal
error", exit 1). The oracle: cp1252 has no ✗ (U+2717); the run's exit status and files.
"""
from __future__ import annotations

import copy
import io
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from tests.test_requirements_runs import with_direction

ROOT = Path(__file__).resolve().parents[1]


def test_cp1252_has_no_ballot_x():
    with pytest.raises(UnicodeEncodeError):
        "✗".encode("cp1252")


def test_a_run_on_a_cp1252_console_writes_its_files_and_escapes_what_it_cannot_show(tmp_path):
    data = copy.deepcopy(with_direction([-1, 0, 0]))
    data["planners"] = [{"name": "natural_motion", "options": {"stop": "step"}}]  # violated: a rate jump (✗)
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, "-m", "scenarios.cli", "run", str(path), "--out", str(out), "--no-plots"],
                          cwd=ROOT, capture_output=True, env={**_environment(), "PYTHONIOENCODING": "cp1252"},
                          timeout=600)
    text = done.stdout.decode("cp1252")
    assert done.returncode == 0, done.stderr.decode("cp1252", errors="replace")
    assert "\\u2717" in text and "internal error" not in done.stderr.decode("cp1252", errors="replace")
    assert (out / "results.md").exists() and (out / "results.json").exists()


def _environment() -> dict[str, str]:
    import os
    return {key: value for key, value in os.environ.items() if key != "PYTHONIOENCODING"}


def test_a_utf8_stream_is_left_as_it_is(monkeypatch):
    from scenarios.cli.commands import _tolerant_streams
    stream = io.TextIOWrapper(io.BytesIO(), encoding="utf-8")
    monkeypatch.setattr(sys, "stdout", stream)
    _tolerant_streams()
    assert stream.errors == "strict"
