"""The bench's plan times on two clocks (docs/guide/bench.rst): ``plan_cpu_s``, the process's CPU
time around the plan, and ``plan_time_s``, its wall time, in every output, the summary giving the
median of each.

Oracle: a plan made to sleep (wall time passes, no CPU) and one made to spin (CPU time passes),
measured against ``time.sleep`` and ``time.process_time`` themselves.
"""
from __future__ import annotations

import csv
import json
import time

from planners.eigenaxis import EigenaxisPlanner
from scenarios.bench.leaderboard import run_bench
from scenarios.bench.suite import load_suite


def board_with(monkeypatch, extra):
    original = EigenaxisPlanner._plan

    def slowed(self, problem):
        extra()
        return original(self, problem)

    monkeypatch.setattr(EigenaxisPlanner, "_plan", slowed)
    return run_bench(load_suite(), problems=["bilimoria_wie_45"], planners=["eigenaxis"])


def test_a_sleeping_plan_takes_wall_time_and_no_cpu_time(monkeypatch):
    row = board_with(monkeypatch, lambda: time.sleep(0.4)).rows[0]
    assert row.plan_time_s >= 0.4
    assert row.plan_cpu_s is not None and row.plan_cpu_s < 0.2  # the eigenaxis plan itself: milliseconds


def test_a_spinning_plan_takes_cpu_time(monkeypatch):
    def spin():
        began = time.process_time()
        while time.process_time() - began < 0.3:
            pass

    row = board_with(monkeypatch, spin).rows[0]
    assert row.plan_cpu_s >= 0.3 and row.plan_time_s >= row.plan_cpu_s * 0.99


def test_both_clocks_are_in_every_output(monkeypatch, tmp_path):
    board = board_with(monkeypatch, lambda: time.sleep(0.2))
    board.write(tmp_path / "board", plots=False)
    line = next(csv.DictReader((tmp_path / "board" / "leaderboard.csv").open()))
    assert float(line["plan_time_s"]) >= 0.2 and float(line["plan_cpu_s"]) < 0.1
    row = json.loads((tmp_path / "board" / "leaderboard.json").read_text())["rows"][0]
    assert row["plan_time_s"] >= 0.2 and row["plan_cpu_s"] < 0.1
    text = (tmp_path / "board" / "leaderboard.md").read_text()
    assert "| median plan CPU [s] | median plan wall [s] |" in text
    assert "| plan CPU [s] | plan wall [s] |" in text
    assert "time.process_time" in text  # the header says which clock
    summary = next(line for line in text.splitlines() if line.startswith("| eigenaxis | planner |"))
    cpu, wall = (float(cell) for cell in summary.split("|")[7:9])
    assert cpu < 0.1 and wall >= 0.2
