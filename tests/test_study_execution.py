"""How a sweep executes its cases: the time limit (however a case spends its time), the crashed
cases a resumed sweep runs again, the stored cases of another version (left out) and a changed
study (refused), and a sweep started from an unguarded script (which must fail once, never hang)."""
import ast
import contextlib
import copy
import csv
import os
import signal
import subprocess
import sys
import textwrap
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
import yaml

from planners.eigenaxis import EigenaxisPlanner
from scenarios import runner
from scenarios.cli.commands import main
from scenarios.errors import CaseTimeout
from scenarios.study.engine import sweep
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import SweepStore, resume_counts
from scenarios.study.types import case_key
from scenarios.study.worker import crashed_rows, run_case
from tests.test_sweep import InlineExecutor

ROOT = Path(__file__).resolve().parents[1]

BASE = {
    "name": "tiny",
    "spacecraft": {"inertia": [2.0, 3.0, 4.0], "wheels": {"max_torque": 0.05}},
    "maneuver": {"duration": 30.0, "initial": {"q": [1, 0, 0, 0], "omega": [0, 0, 0]},
                 "final": {"q": [0.9238795, 0.3826834, 0, 0], "omega": [0, 0, 0]}},
    "planners": [{"name": "eigenaxis", "label": "smooth"},
                 {"name": "eigenaxis", "label": "fast", "options": {"profile": "min_time", "torque_fraction": 0.8}}],
    "controller": {"name": "augmented_quaternion_feedback", "options": {"kp": 0.2, "kd": 0.6}},
    "simulation": {"sample_time": 1.0, "duration": 35.0},
}
TIMED_OUT = "timed out after {:g} s (case_timeout_s)"


def payload(timeout_s, duration=30.0):
    scenario = copy.deepcopy(BASE)
    scenario["maneuver"]["duration"] = duration
    return {"key": "k", "index": 0, "scenario": scenario, "timeout_s": timeout_s}


# --- the time limit ------------------------------------------------------------------------------

def test_the_timeout_is_not_an_error_that_a_generic_handler_catches():
    assert issubclass(CaseTimeout, BaseException) and not issubclass(CaseTimeout, Exception)
    with pytest.raises(CaseTimeout):
        try:
            raise CaseTimeout
        except Exception:  # noqa: BLE001 - what the runner's planner handler does
            pytest.fail("except Exception caught the timeout")


def test_a_planner_out_of_time_is_a_timed_out_case_not_a_failed_row(monkeypatch):
    """The runner turns a planner's exception into a failed row (``except Exception``): the alarm
    must get through it, end the case at its limit and make it a crashed, timed-out case."""
    def slow_plan(self, problem):
        time.sleep(5.0)
        raise AssertionError("the case went on past its time limit")

    monkeypatch.setattr(EigenaxisPlanner, "plan", slow_plan)
    handler = signal.getsignal(signal.SIGALRM)
    result = run_case(payload(0.3))
    assert result["status"] == "crashed", result
    assert [row["message"] for row in result["rows"]] == [TIMED_OUT.format(0.3)] * 2
    assert 0.3 <= result["elapsed_s"] < 2.0, result["elapsed_s"]  # stopped by the alarm, not after 5 s
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0) and signal.getsignal(signal.SIGALRM) == handler


def test_an_alarm_a_c_call_wraps_still_ends_the_case_without_a_traceback(monkeypatch, capsys):
    """CasADi's buffered call returns the alarm's exception wrapped: ``SystemError: <built-in
    function _function_buffer_eval> returned a result with an exception set``, its cause the
    ``CaseTimeout``. The runner's planner handler caught that ``SystemError``, printed its traceback
    (a user saw eight) and went on to the next row until the measured time ended the case."""
    def wrapped_plan(self, problem):
        try:
            time.sleep(5.0)
        except CaseTimeout as stop:  # what CasADi hands back for the alarm raised inside its call
            raise SystemError("<built-in function _function_buffer_eval> returned a result with an "
                              "exception set") from stop
        raise AssertionError("the case went on past its time limit")

    monkeypatch.setattr(EigenaxisPlanner, "plan", wrapped_plan)
    result = run_case(payload(0.3))
    assert result["status"] == "crashed", result
    assert [row["message"] for row in result["rows"]] == [TIMED_OUT.format(0.3)] * 2
    assert 0.3 <= result["elapsed_s"] < 2.0, result["elapsed_s"]  # the first row's alarm ended the case
    assert "Traceback" not in capsys.readouterr().err


class _Raising:
    """A planner whose plan raises what ``make`` returns."""

    def __init__(self, make):
        self.make = make

    def plan(self, problem):
        raise self.make()


def _from(error, cause):
    error.__cause__ = cause
    return error


def _in_handler(error, handled):
    """``error`` raised while ``handled`` was being handled (its context), optionally ``from None``."""
    def make():
        try:
            raise handled
        except BaseException:  # noqa: BLE001 - the planner handles it, then fails otherwise
            return error
    return make


@pytest.mark.parametrize("make", [
    lambda: _from(SystemError("returned a result with an exception set"), CaseTimeout()),
    lambda: _from(SystemError("returned a result with an exception set"), KeyboardInterrupt()),
], ids=["time limit", "ctrl-c"])
def test_a_signal_a_c_call_wraps_is_raised_as_itself(make):
    with pytest.raises((CaseTimeout, KeyboardInterrupt)):
        runner._plan(_Raising(make), "wrapped", None)


@pytest.mark.parametrize("make", [
    _in_handler(ValueError("cleanup failed"), GeneratorExit()),
    _in_handler(ValueError("after a handled Ctrl-C"), KeyboardInterrupt()),
    lambda: _from(ValueError("a library exited"), SystemExit(3)),
    lambda: _from(ValueError("wrapped"), GeneratorExit()),
], ids=["context GeneratorExit", "context KeyboardInterrupt", "cause SystemExit", "cause GeneratorExit"])
def test_a_planner_error_that_merely_carries_another_exception_is_a_failed_row(make, capsys):
    """A reviewer crashed ``run`` and ``sweep`` with a planner whose generator cleanup raised a
    ValueError: its context held a GeneratorExit, which the runner re-raised."""
    reference = runner._plan(_Raising(make), "carrying", None)
    assert not reference.ok and "planner raised ValueError" in reference.message
    capsys.readouterr()


def test_a_case_that_swallows_the_alarm_and_finishes_late_is_timed_out(monkeypatch):
    """C code can swallow the alarm's exception (CasADi turns an exception in its callbacks into its
    own error): a case that then finishes past its limit is still out of time."""
    original = runner.run

    def swallowing(scenario, **kwargs):
        with contextlib.suppress(BaseException):  # as a C extension may: the alarm is lost
            time.sleep(0.6)
        return original(scenario, **kwargs)

    monkeypatch.setattr(runner, "run", swallowing)
    result = run_case(payload(0.2))
    assert result["status"] == "crashed" and result["elapsed_s"] > 0.2, result
    assert [row["message"] for row in result["rows"]] == [TIMED_OUT.format(0.2)] * 2


def test_without_an_alarm_a_case_over_its_limit_is_timed_out(monkeypatch):
    """A Dask worker runs cases in a thread, where there is no SIGALRM: the measured time decides."""
    original = runner.run

    def late(scenario, **kwargs):
        time.sleep(0.4)
        return original(scenario, **kwargs)

    monkeypatch.setattr(runner, "run", late)
    with ThreadPoolExecutor(1) as pool:
        slow = pool.submit(run_case, payload(0.2)).result()
        quick = pool.submit(run_case, payload(30.0)).result()
    assert slow["status"] == "crashed" and slow["elapsed_s"] > 0.2, slow
    assert [row["message"] for row in slow["rows"]] == [TIMED_OUT.format(0.2)] * 2
    assert quick["status"] == "ok" and all(row["status"] == "ok" for row in quick["rows"]), quick


def test_ctrl_c_in_a_case_is_not_turned_into_a_row(monkeypatch):
    def interrupted(scenario, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(runner, "run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run_case(payload(30.0))
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)


def test_on_a_local_pool_no_case_over_its_limit_is_stored_ok(tmp_path):
    """The tester's study: 2 x 6 cases of about 0.05-0.2 s each under a 0.05 s limit. Every case is
    ok within its limit or crashed as timed out; none is a row the planner "failed" with the timeout."""
    base = yaml.safe_load((ROOT / "scenarios" / "eigenaxis_truth.yaml").read_text())
    data = {"study": "timeout-0.05", "scenario": base, "grid": {"maneuver.duration": [100.0, 120.0]},
            "monte_carlo": {"samples": 6, "seed": 3,
                            "dispersions": {"truth.spacecraft.inertia": {"scale": {"uniform": [0.9, 1.1]}}}},
            "execution": {"case_timeout_s": 0.05, "retries": 0}}
    results = sweep(parse_study(data), workers=2)
    assert len(results.records) == 12
    for key, record in results.records.items():
        messages = {row["message"] for row in record["rows"]}
        if record["status"] == "ok":
            assert record["elapsed_s"] <= 0.05, (key, record["elapsed_s"])
            assert all(row["status"] == "ok" for row in record["rows"]), record
        else:
            assert record["status"] == "crashed" and messages == {TIMED_OUT.format(0.05)}, (key, messages)
    assert any(record["status"] == "crashed" for record in results.records.values())


# --- resuming ------------------------------------------------------------------------------------

def test_resume_runs_the_crashed_cases_again_and_keeps_the_failed_rows(tmp_path, monkeypatch):
    study = parse_study({"study": "resume", "scenario": copy.deepcopy(BASE),
                         "grid": {"maneuver.duration": [30.0, 40.0, 50.0]}})
    original, plan = runner.run, EigenaxisPlanner.plan

    def flaky(scenario, **kwargs):  # the case of 40 s crashes (an execution fault)
        if scenario.problem.duration == 40.0:
            raise RuntimeError("worker ran out of memory")
        return original(scenario, **kwargs)

    def failing(self, problem):  # the planners of 50 s fail (a result: a failed row, kept)
        if problem.duration == 50.0:
            raise ValueError("no solution")
        return plan(self, problem)

    monkeypatch.setattr(runner, "run", flaky)
    monkeypatch.setattr(EigenaxisPlanner, "plan", failing)
    with SweepStore(tmp_path) as store:
        first = sweep(study, InlineExecutor(), store=store)
    by_duration = {case.scenario["maneuver"]["duration"]: case.key for case in study.cases}
    assert first.records[by_duration[40.0]]["status"] == "crashed"
    assert first.records[by_duration[50.0]]["status"] == "ok"
    assert {row["status"] for row in first.records[by_duration[50.0]]["rows"]} == {"failed"}

    monkeypatch.setattr(runner, "run", original)  # the fault is gone; the planners still fail at 50 s
    executor = InlineExecutor()
    with SweepStore(tmp_path) as store:
        assert resume_counts(store, by_duration.values()) == (2, 1, 0)
        second = sweep(study, executor, store=store)
        assert len(store) == 3 and store.statuses()[by_duration[40.0]] == "ok"
        assert store.records() == second.records
    assert executor.submitted == 1  # the crashed case alone
    rerun = second.records[by_duration[40.0]]
    assert rerun["status"] == "ok" and {row["status"] for row in rerun["rows"]} == {"ok"}
    assert rerun["attempts"] == 2  # every start counted, across the resume
    for duration in (30.0, 50.0):
        assert second.records[by_duration[duration]] == first.records[by_duration[duration]]


def write_study(directory, grid, timeout=600):
    (directory / "base.yaml").write_text(yaml.safe_dump(BASE))
    path = directory / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "cli-resume", "scenario": "base.yaml", "grid": grid,
                                    "execution": {"case_timeout_s": timeout}}))
    return path


def test_cli_resume_says_what_it_runs_again_and_what_is_not_the_studys(tmp_path, capsys):
    path = write_study(tmp_path, {"maneuver.duration": [30.0, 40.0, 50.0]})
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    capsys.readouterr()
    cases = {case.scenario["maneuver"]["duration"]: case for case in load_study(path).cases}
    keys = {duration: case.key for duration, case in cases.items()}
    with SweepStore(out) as store:  # as a timed-out case is stored
        store.put(keys[40.0], "crashed", crashed_rows(cases[40.0].scenario, TIMED_OUT.format(600)), 600.0, 1)
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0
    said = capsys.readouterr().out
    assert "cli-resume: 3 cases, 2 already stored, 1 crashed case run again, local process pool" in said, said
    assert "1 case run in" in said and "(2 already stored, 3 in all); of the 3 cases stored, 0 crashed and 0 others have a row not ok" in said, said
    assert "not this study's" not in said
    with SweepStore(out) as store:
        assert set(store.statuses().values()) == {"ok"} and store.records()[keys[40.0]]["attempts"] == 2

    # cases stored by another slewbench version (their keys differ): kept in the store, left out, counted in a note
    with SweepStore(out) as store:
        store.put(case_key(cases[50.0].scenario, "0.0.1"), "ok", [], 1.0, 1)
        store.put(keys[50.0], "crashed", crashed_rows(cases[50.0].scenario, TIMED_OUT.format(600)), 600.0, 1)
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 0
    said = capsys.readouterr().out
    assert "cli-resume: 3 cases, 2 already stored, 1 crashed case run again, local process pool\n" in said, said
    assert ("note: 1 stored case is not this study's as this slewbench keys them (stored by another version?): kept "
            "in the store, left out of the outputs") in said, said
    assert "(2 already stored, 3 in all); of the 3 cases stored, 0 crashed and 0 others have a row not ok" in said, said
    with (out / "cases.csv").open() as stream:
        durations = sorted({float(row["maneuver.duration"]) for row in csv.DictReader(stream)})
    assert durations == [30.0, 40.0, 50.0]
    # the redrawn report counts this study's cases (the other version's is not one)
    assert main(["sweep", "--report", str(out), "--no-plots"]) == 0
    assert "from 3 stored case(s); 0 missing" in capsys.readouterr().out

    # a changed study is refused: the store holds the sweep of the study as it was
    path = write_study(tmp_path, {"maneuver.duration": [30.0, 40.0, 60.0, 70.0]})
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--no-plots", "--resume"]) == 2
    error = capsys.readouterr().err
    assert ("with another definition (3 cases then, 4 now), changed since: grid.maneuver.duration: "
            "[30.0, 40.0, 50.0] -> [30.0, 40.0, 60.0, 70.0]") in error, error


# --- a sweep started by an unguarded script ------------------------------------------------------

SCRIPT = """\
import scenarios

results = scenarios.sweep({study!r}, workers=2)
print("cases", len(results.records))
"""


def run_script(tmp_path, body, name):
    script = tmp_path / name
    script.write_text(body)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    start = time.monotonic()
    done = subprocess.run([sys.executable, str(script)], check=False, capture_output=True, text=True, timeout=120,
                          env=env, cwd=tmp_path)
    return done, time.monotonic() - start


def test_an_unguarded_script_fails_once_with_the_fix_named_and_a_guarded_one_runs(tmp_path):
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "script", "scenario": "base.yaml",
                                     "grid": {"maneuver.duration": [30.0, 40.0]}}))
    done, seconds = run_script(tmp_path, SCRIPT.format(study=str(study)), "unguarded.py")
    assert done.returncode != 0 and "cases" not in done.stdout, (done.stdout, done.stderr[-3000:])
    assert 'if __name__ == "__main__":' in done.stderr and "WorkersCannotStart" in done.stderr, done.stderr[-3000:]
    assert "bootstrapping phase" not in done.stderr, done.stderr[-3000:]  # multiprocessing's, once per worker
    assert done.stderr.count("Traceback") == 1, done.stderr[-3000:]
    assert seconds < 120, seconds

    guarded = "if __name__ == \"__main__\":\n" + textwrap.indent(SCRIPT.format(study=str(study)), "    ")
    done, _ = run_script(tmp_path, guarded, "guarded.py")
    assert done.returncode == 0 and "cases 2" in done.stdout, done.stderr[-3000:]


def test_the_guide_shows_the_guard_around_a_sweep_from_python():
    guide = (ROOT / "docs" / "guide" / "studies.rst").read_text()
    section = guide[guide.index("From Python\n"):]
    lines = []
    for line in section[section.index(".. code-block:: python"):].splitlines()[2:]:
        if line and not line.startswith("   "):
            break
        lines.append(line)
    block = textwrap.dedent("\n".join(lines))
    tree = ast.parse(block)
    guards = [node for node in tree.body if isinstance(node, ast.If) and ast.unparse(node.test) == "__name__ == '__main__'"]
    assert len(guards) == 1, block
    calls = [node for node in ast.walk(tree) if isinstance(node, ast.Call) and ast.unparse(node.func) == "scenarios.sweep"]
    inside = [node for node in ast.walk(guards[0]) if node in calls]
    assert calls and inside == calls, block  # every sweep under the guard
