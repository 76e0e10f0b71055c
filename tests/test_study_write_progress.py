"""Writing a study's tables and figures shows its progress as the sweep shows its cases (issue 31's
``_Progress``): a bar counting the files in a terminal; off a terminal, a line at most every
``PROGRESS_LINE_S`` and none for a quick write."""
from __future__ import annotations

import re

import pytest
import yaml

import scenarios.study.engine as engine
from scenarios.cli.commands import main
from scenarios.study.rerun import stored_results
from tests.test_study_plots_progress import STUDY, sweep_output

WRITING = re.compile(r"tiny-bar: writing: (\d+) files \[")


def test_a_terminal_shows_the_files_written_and_the_last_count_is_every_file(tmp_path):
    output = sweep_output(tmp_path, 100)  # --no-plots: the tables only
    counts = [int(match.group(1)) for match in WRITING.finditer(output)]
    written = re.search(r"wrote \S+ \(([^)]*)\)", output)
    assert counts and written, output
    assert counts[-1] == len(written.group(1).split(", ")) == 5, (counts, written.group(1))


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sweep")
    study = yaml.safe_load(STUDY)
    study["grid"]["maneuver.duration"] = [20.0, 22.0]
    path = folder / "study.yaml"
    path.write_text(yaml.safe_dump(study, sort_keys=False))
    assert main(["sweep", str(path), "--out", str(folder / "out"), "--no-plots"]) == 0
    return folder / "out"


def test_off_a_terminal_a_long_write_says_lines_and_a_last_one(stored, capsys, monkeypatch):
    capsys.readouterr()
    monkeypatch.setattr(engine, "PROGRESS_LINE_S", 0.0)  # every step is "long"
    results, _ = stored_results(stored)
    files = results.write(stored, plots=True, progress=True)
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("tiny-bar: writing: ")]
    assert lines, "no progress line"
    assert re.fullmatch(rf"tiny-bar: writing: {len(files)} files done, \d+s elapsed", lines[-1]), (lines, files)
    counts = [int(line.split()[2]) for line in lines]
    assert counts == sorted(counts) and any(name.startswith("plots/") for name in files), lines  # tables, figures, report.html


def test_off_a_terminal_a_quick_write_says_nothing_and_a_library_call_shows_nothing(stored, capsys):
    capsys.readouterr()
    results, _ = stored_results(stored)
    results.write(stored, plots=False, progress=True)
    assert "writing" not in capsys.readouterr().err
    results.write(stored, plots=False)
    assert capsys.readouterr().err == ""
