"""A large study is announced with its case count and how to estimate its time, in ``--dry-run``
and when the sweep starts; it is never refused (docs/guide/studies.rst).

Oracle: the case count of the grid by hand (1001 Monte Carlo samples of one grid point), the worker time at 1 s a
case (1001 s = 0.278 h, 0.139 h on 2 workers), and a small study (10 cases) that gets no note.

The dry run checks every case (parse, plan, findings: 1 to 3 ms a case since 2026-12-05, 9 ms before), so the command line's 1001-case dry
run is marked slow; its default twin runs the same command on 11 cases over a limit of 10 (and 10 cases at it,
no note) and checks the note of the real limit on the 1001-case study in-process.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from scenarios.cli import main
from scenarios.study.spec import LARGE_STUDY, load_study, size_note

BASE = Path("scenarios/eigenaxis_demo.yaml").resolve()


def study_file(tmp_path: Path, cases: int) -> Path:
    path = tmp_path / f"s{cases}.yaml"
    path.write_text(f"study: s{cases}\nscenario: {BASE}\nmonte_carlo: {{samples: {cases}, seed: 1, dispersions: "
                    "{simulation.sensor_noise.seed: case_seed}}\n")
    return path


def test_a_dry_run_over_the_limit_prints_the_count_and_how_to_estimate_its_time(tmp_path, capsys, monkeypatch):
    import scenarios.study.spec as spec
    assert LARGE_STUDY == 1000
    # the real limit: 1001 cases, 1001 s = 0.278 h of worker time, 0.139 h on 2 workers
    assert size_note(load_study(study_file(tmp_path, 1001)), 2) == (
        "note: 1001 cases is a large study (over 1000): at 1 s a case that is 0.3 h of worker time, 0.1 h on 2 "
        f"workers. To estimate it, time one case (slewbench run {BASE} --no-plots prints its plan and simulation "
        "times) and multiply by 1001 / 2; once cases finish, the progress bar shows the time left.")
    # the command line's dry run, over a limit of 10 (and at it: no note)
    monkeypatch.setattr(spec, "LARGE_STUDY", 10)
    assert main(["sweep", str(study_file(tmp_path, 10)), "--dry-run", "--workers", "2"]) == 0
    assert "note:" not in capsys.readouterr().out
    assert main(["sweep", str(study_file(tmp_path, 11)), "--dry-run", "--workers", "2"]) == 0
    out = capsys.readouterr().out
    assert "s11: 11 cases, checked; nothing run, nothing written" in out
    assert "note: 11 cases is a large study (over 10): at 1 s a case that is 0.0 h of worker time, 0.0 h on 2 " \
           "workers" in out, out
    assert f"slewbench run {BASE} --no-plots" in out and "multiply by 11 / 2" in out


@pytest.mark.slow  # 1001 cases checked one by one: 9 s idle (the twin above runs the same command on 11)
def test_a_large_dry_run_prints_the_count_and_how_to_estimate_its_time(tmp_path, capsys):
    assert LARGE_STUDY == 1000
    assert main(["sweep", str(study_file(tmp_path, 1001)), "--dry-run", "--workers", "2"]) == 0
    out = capsys.readouterr().out
    assert "s1001: 1001 cases, checked; nothing run, nothing written" in out
    assert ("note: 1001 cases is a large study (over 1000): at 1 s a case that is 0.3 h of worker time, 0.1 h on 2 "
            "workers") in out, out
    assert f"slewbench run {BASE} --no-plots" in out and "multiply by 1001 / 2" in out


def test_a_small_study_gets_no_note(tmp_path, capsys):
    assert main(["sweep", str(study_file(tmp_path, 10)), "--dry-run"]) == 0
    assert "note:" not in capsys.readouterr().out
    assert size_note(load_study(study_file(tmp_path, 10)), 1) is None


def test_the_sweep_says_it_when_it_starts_and_runs_the_study(tmp_path, capsys, monkeypatch):
    import scenarios.study.spec as spec
    monkeypatch.setattr(spec, "LARGE_STUDY", 1)  # two cases stand for a large study: the note, then the run
    assert main(["sweep", str(study_file(tmp_path, 2)), "--out", str(tmp_path / "sweep"), "--workers", "1",
                 "--no-plots"]) == 0
    out = capsys.readouterr().out
    first = out.splitlines()
    assert first[0].startswith("s2: 2 cases") and first[1].startswith("note: 2 cases is a large study (over 1)")
    assert "2 cases run in" in out


def test_the_size_note_never_stops_a_sweep_on_a_scheduler_that_does_not_answer() -> None:
    """The note asks the cluster for its threads only to size itself: a scheduler that fails to
    answer gives no count (a fake cluster without ``workers`` once made a sweep an internal error)."""
    from scenarios.cli.sweep import _cluster_threads

    class Silent:
        def workers(self) -> int:
            raise OSError("scheduler gone")

    class Answering:
        def workers(self) -> int:
            return 3

    assert _cluster_threads(None) is None
    assert _cluster_threads(Silent()) is None  # type: ignore[arg-type]
    assert _cluster_threads(Answering()) == 3  # type: ignore[arg-type]
