"""More local workers than cores is allowed, but said: ``sweep`` (its dry run too) and ``table``
print one line, not an error, naming the cores this process may run on (its CPU affinity) and that
each case then runs slower, its plan and simulation times inflated. A cluster's workers are not
this machine's: no note. Oracle: the affinity set by the test (``os.sched_getaffinity``)."""
from __future__ import annotations

import os

import pytest
import yaml

from scenarios.cli import main
from scenarios.cli.status import workers_note
from tests.test_sweep import BASE
from tests.test_table_status import BOX, write

NOTE = ("note: {option} {workers} is more than the {cores} cores this process may run on: the {units} share them, "
        "so each runs slower and its plan and simulation times in the tables are inflated")


@pytest.fixture
def two_cores(monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1}, raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 2)


def study(tmp_path, **execution) -> str:
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "tiny", "scenario": BASE, "grid": {"maneuver.duration": [30.0, 40.0]},
                                    **({"execution": execution} if execution else {})}))
    return str(path)


def test_the_note_names_the_cores_and_what_it_costs():
    assert workers_note(3, 2, "--workers", "cases") == NOTE.format(option="--workers", workers=3, cores=2,
                                                                   units="cases")
    assert workers_note(2, 2, "--workers", "cases") is None and workers_note(None, 2, "--workers", "cases") is None
    assert workers_note(2, 1, "--workers", "entries").startswith("note: --workers 2 is more than the 1 core this ")


def test_a_dry_run_with_more_workers_than_cores_says_so(tmp_path, two_cores, capsys):
    assert main(["sweep", study(tmp_path), "--dry-run", "--workers", "3"]) == 0
    out = capsys.readouterr().out
    assert NOTE.format(option="--workers", workers=3, cores=2, units="cases") in out.splitlines(), out
    assert main(["sweep", study(tmp_path), "--dry-run", "--workers", "2"]) == 0
    assert "more than the" not in capsys.readouterr().out
    assert main(["sweep", study(tmp_path, workers=5), "--dry-run"]) == 0  # the study's own number
    assert NOTE.format(option="execution.workers", workers=5, cores=2, units="cases") in capsys.readouterr().out
    # a scheduler's workers are not this machine's cores
    assert main(["sweep", study(tmp_path, workers=5, scheduler="tcp://127.0.0.1:1"), "--dry-run"]) == 0
    assert "more than the" not in capsys.readouterr().out


def test_a_sweep_with_more_workers_than_cores_says_so_and_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0}, raising=False)
    out = tmp_path / "out"
    assert main(["sweep", study(tmp_path), "--out", str(out), "--workers", "2", "--no-plots"]) == 0
    printed = capsys.readouterr().out
    assert NOTE.format(option="--workers", workers=2, cores=1, units="cases").replace("1 cores", "1 core") \
        in printed.splitlines(), printed
    assert "2 cases run in" in printed


def test_a_table_with_more_workers_than_cores_says_so(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0}, raising=False)
    write(tmp_path, "box.yaml", BOX)
    path = write(tmp_path, "table.yaml", {"table": {"scenario": "box.yaml", "axes": [[1, 0, 0]], "angles_deg": [90, 180],
                                                    "planner_options": {"multistart": 0},
                                                    "execution": {"case_timeout_s": 0.001}}})
    assert main(["table", str(path), "--out", str(tmp_path / "out"), "--no-plots", "--workers", "2"]) in (0, 1)
    printed = capsys.readouterr().out
    assert NOTE.format(option="--workers", workers=2, cores=1, units="entries").replace("1 cores", "1 core") \
        in printed.splitlines(), printed
