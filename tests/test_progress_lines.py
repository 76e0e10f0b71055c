"""A sweep's progress where standard error is not a terminal (CI, ``nohup``; user B's finding 6): a
plain line at most every ``PROGRESS_LINE_S`` and one at the end; on a terminal the bar alone."""
from __future__ import annotations

import re
import subprocess
import sys

from scenarios.study import engine
from scenarios.study.engine import _Progress
from tests.test_study_plots_progress import BAR, ROOT, STUDY, sweep_output

LINE = re.compile(r"^tiny-bar: (\d+)/4 cases done(, \d+ not ok)?( \(\d+ crashed\))?, (\d+)s elapsed$", re.M)


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_a_line_at_most_every_interval_and_at_the_end(capsys):
    clock = Clock()
    progress = _Progress("study-x", 40, clock=clock)
    assert progress.bar is None  # capsys: stderr is not a terminal
    clock.now += 10.0
    progress.update(3, 0, 0)
    progress.poll()
    assert capsys.readouterr().err == ""  # 10 s: not yet
    clock.now += 20.0
    progress.poll()  # 30 s without a case finishing: still a line
    assert capsys.readouterr().err == "study-x: 3/40 cases done, 30s elapsed\n"
    clock.now += 29.0
    progress.update(9, 2, 1)
    assert capsys.readouterr().err == ""  # 29 s after the last line
    clock.now += 101.0
    progress.update(0, 3, 1)
    assert capsys.readouterr().err == "study-x: 12/40 cases done, 3 not ok (1 crashed), 2m40s elapsed\n"
    clock.now += 3600.0
    progress.close()
    assert capsys.readouterr().err == "study-x: 12/40 cases done, 3 not ok (1 crashed), 1h02m40s elapsed\n"


def test_nothing_to_run_says_nothing(capsys):
    _Progress("study-x", 0, clock=Clock()).close()
    assert capsys.readouterr().err == ""


def test_the_interval_is_the_module_constant(capsys, monkeypatch):
    clock = Clock()
    progress = _Progress("study-x", 2, clock=clock)
    monkeypatch.setattr(engine, "PROGRESS_LINE_S", 5.0)
    clock.now += 5.0
    progress.update(1, 0, 0)
    assert capsys.readouterr().err == "study-x: 1/2 cases done, 5s elapsed\n"


def test_a_sweep_off_a_terminal_prints_its_progress_lines(tmp_path):
    study = tmp_path / "study.yaml"
    study.write_text(STUDY)
    done = subprocess.run([sys.executable, "-m", "scenarios.cli", "sweep", str(study), "--out", str(tmp_path / "out"),
                           "--no-plots"], cwd=ROOT, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    lines = LINE.findall(done.stderr)
    assert lines and lines[-1][0] == "4"  # the last line: every case done
    assert not BAR.search(done.stderr)


def test_a_sweep_with_a_short_interval_reports_as_it_goes(tmp_path, monkeypatch, capsys):
    from scenarios.cli.commands import main

    monkeypatch.setattr(engine, "PROGRESS_LINE_S", 0.0)
    study = tmp_path / "study.yaml"
    study.write_text(STUDY)
    assert main(["sweep", str(study), "--out", str(tmp_path / "out"), "--no-plots", "--workers", "1"]) == 0
    counts = [int(found[0]) for found in LINE.findall(capsys.readouterr().err)]
    assert counts[-1] == 4 and len(counts) > 2 and counts == sorted(counts)


def test_no_line_on_a_terminal(tmp_path):
    output = sweep_output(tmp_path, 100)
    assert BAR.search(output) and "cases done" not in output
