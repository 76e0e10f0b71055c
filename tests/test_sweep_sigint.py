"""Ctrl-C (a real SIGINT to a real sweep's process group) where it used to go wrong: lost while the
study's cases were checked, cut into a worker's start, and ignored by the C compiler a worker
started."""
import contextlib
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import yaml

from tests.test_sweep import BASE
from tests.test_sweep_processes import _session

ROOT = Path(__file__).resolve().parents[1]


def write_study(tmp_path, scenario=None, durations=(30.0, 32.0)):
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "sigint", "scenario": scenario or BASE,
                                    "grid": {"maneuver.duration": list(durations)}}))
    return path


def start(tmp_path, script, env=None):
    """Run ``script`` (Python, as ``-c``: the workers do not import it) in a process of its own
    session, in ``tmp_path``, the worktree first on its path."""
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(script)], cwd=tmp_path, start_new_session=True,
                            text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=dict(os.environ, PYTHONPATH=str(ROOT), **(env or {})))


def wait_for(path: Path, process, timeout_s: float = 60.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not path.exists():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, f"{path.name} did not appear"
        time.sleep(0.01)


@contextlib.contextmanager
def session_of(process):
    """Yield; then kill whatever is left of the process's session (and the process)."""
    try:
        yield
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        for pid in _session(process.pid):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.communicate(timeout=10)


def _command_line(pid: int) -> bytes:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes()
    except OSError:  # ended meanwhile
        return b""


def left_behind(process, wait_s: float = 5.0) -> list[int]:
    """Processes of the (ended) process's session still alive after at most ``wait_s``."""
    deadline = time.monotonic() + wait_s
    while _session(process.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    return _session(process.pid)


@pytest.mark.parametrize("how", ["swallowed", "turned into an error"])
def test_ctrl_c_lost_while_the_cases_are_checked_still_stops_the_sweep(tmp_path, how):
    """CasADi converts arguments by calling back into Python: a KeyboardInterrupt raised there is
    swallowed (another overload matches, the sweep ran on to its end, exit 0) or turned into its
    NotImplementedError ("internal error" and a traceback, exit 1). Seen on a 4-case sweep at about
    1 Ctrl-C in 20 sent while it started. Here the checking swallows the interrupt the same way."""
    study = write_study(tmp_path)
    ending = "pass" if how == "swallowed" else "raise NotImplementedError('Wrong number or type of arguments')"
    process = start(tmp_path, f"""
        import pathlib, sys, time
        import scenarios.study.spec as spec
        from scenarios.cli.commands import main
        real = spec.load_study

        def checking(*args, **kwargs):  # the interrupt comes while C code has the control
            pathlib.Path("checking").touch()
            try:
                time.sleep(30)
            except KeyboardInterrupt:
                {ending}
            return real(*args, **kwargs)

        spec.load_study = checking
        sys.exit(main(["sweep", "{study}", "--out", "out", "--workers", "1", "--no-plots"]))
        """)
    with session_of(process):
        wait_for(tmp_path / "checking", process)
        os.killpg(process.pid, signal.SIGINT)  # what Ctrl-C does
        stdout, stderr = process.communicate(timeout=60)
    assert "Traceback" not in stderr, stderr
    assert process.returncode == 130, (stdout, stderr)
    assert stderr.strip() == "slewbench: sweep interrupted while its cases were checked; nothing was run or written"
    assert not (tmp_path / "out").exists()


def test_a_long_check_shows_a_line_off_a_terminal_and_ctrl_c_there_says_nothing_was_written(tmp_path):
    """A study that disperses the inertia is checked case by case, by the whole loader (a user's 180
    cases: 17 s without a line on a redirected stderr, then "results not written or marked
    incomplete", with nothing written). Here 4000 cases keep the check going for seconds; stderr is
    a pipe, not a terminal; Ctrl-C comes once the check's first line is there. ``--dry-run``: a
    check that never shows its line ends without running anything."""
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "checked", "scenario": BASE, "monte_carlo": {
        "samples": 4000, "seed": 1, "dispersions": {"spacecraft.inertia": {"scale": {"uniform": [0.9, 1.1]}}}}}))
    process = start(tmp_path, f"""
        import sys
        from scenarios.cli.commands import main
        sys.exit(main(["sweep", "{study}", "--out", "out", "--workers", "1", "--no-plots", "--dry-run"]))
        """)
    with session_of(process):
        line = process.stderr.readline()  # blocks until the line (or the end: no line was shown)
        os.killpg(process.pid, signal.SIGINT)  # what Ctrl-C does
        stdout, stderr = process.communicate(timeout=60)
    assert re.fullmatch(r"study: checking 4000 cases, \d+ checked, \d+\.\d s elapsed\n", line), (line, stderr)
    checked, elapsed = int(line.split(", ")[1].split()[0]), float(line.split(", ")[2].split()[0])
    assert 0 < checked < 4000 and 1.0 <= elapsed < 30.0, line  # the first line after 1 s of checking
    assert process.returncode == 130, (stdout, stderr)
    assert stderr.strip() == "slewbench: sweep interrupted while its cases were checked; nothing was run or written"
    assert stdout == "" and not (tmp_path / "out").exists()


def test_ctrl_c_while_a_worker_starts_stops_it_silently(tmp_path):
    """A Ctrl-C while the pool waits for a worker that the fork server has not forked yet (it still
    imports) cut the worker's start short: the pool did not know that worker, the server forked it
    later, and it failed on the stopped pool's queues with a traceback (or stayed, waiting). Here a
    module preloaded last keeps the server importing for 2.5 s; the sweep is called from Python, whose
    process goes on after the interrupt (4.5 s: the 2.3 s margin of the earlier 4 s import and 6 s
    wait, after the import would have ended; the interrupt lands 0.3 s into the import)."""
    (tmp_path / "slow_preload.py").write_text("import pathlib, time\npathlib.Path('importing').touch()\n"
                                              "time.sleep(2.5)\npathlib.Path('imported').touch()\n")
    study = write_study(tmp_path)
    process = start(tmp_path, f"""
        import gc, os, pathlib, sys, time
        sys.path.insert(0, "{tmp_path}")
        import scenarios.study.engine as engine
        from scenarios.errors import SweepInterrupted
        engine.PRELOAD = (*engine.PRELOAD, "slow_preload")
        try:
            engine.sweep("{study}", workers=1)
        except (SweepInterrupted, KeyboardInterrupt) as stop:
            print("interrupted", type(stop).__name__, flush=True)
        interrupted = time.monotonic()
        gc.collect()  # the stopped pool's queues and semaphores go
        time.sleep(4.5)  # the server would have forked the worker by now
        print("imported" if pathlib.Path("imported").exists() else "not imported", flush=True)
        """)
    with session_of(process):
        wait_for(tmp_path / "importing", process)
        time.sleep(0.3)  # the sweep waits for its first worker
        os.killpg(process.pid, signal.SIGINT)
        time.sleep(1.0)
        running = [pid for pid in _session(process.pid) if b"forkserver" in _command_line(pid)]  # server, workers
        stdout, stderr = process.communicate(timeout=60)
        left = left_behind(process)
    assert "interrupted" in stdout, (stdout, stderr)
    assert "Traceback" not in stderr, stderr
    assert not running, f"still running 1 s after Ctrl-C: {running}"
    assert stdout.split()[-1] == "imported" and stdout.split()[-2] == "not", \
        "the fork server went on importing after Ctrl-C"
    assert not left, f"processes left behind: {left}"


@pytest.mark.parametrize("stop", ["Ctrl-C", "SIGTERM to the sweep"])
def test_ctrl_c_stops_the_compiler_a_worker_started(tmp_path, stop):
    """The workers ignore Ctrl-C (the sweep stops them); a C compiler one of them started inherited
    the ignoring (SIG_IGN survives exec) and compiled on, alone, after the sweep had stopped; so it
    did when only the sweep was stopped (SIGTERM), which kills its workers, not their children. The
    compiler here is a stand-in that runs for a minute unless a signal stops it."""
    compiler = tmp_path / "slowcc"
    compiler.write_text(f"#!/bin/sh\necho $$ > {tmp_path}/compiling\nexec sleep 60\n")
    compiler.chmod(0o755)
    scenario = {**BASE, "simulation": {**BASE["simulation"], "compile": True}}
    study = write_study(tmp_path, scenario, durations=(30.0,))
    process = start(tmp_path, f"""
        import sys
        from scenarios.cli.commands import main
        sys.exit(main(["sweep", "{study}", "--out", "out", "--workers", "1", "--no-plots"]))
        """, env={"CC": str(compiler), "XDG_CACHE_HOME": str(tmp_path / "cache")})
    with session_of(process):
        wait_for(tmp_path / "compiling", process)
        time.sleep(0.2)  # the stand-in has become `sleep`
        pid = int((tmp_path / "compiling").read_text())
        if stop == "Ctrl-C":
            os.killpg(process.pid, signal.SIGINT)
        else:
            os.kill(process.pid, signal.SIGTERM)
        stdout, stderr = process.communicate(timeout=60)
        left = left_behind(process)
    assert process.returncode == 130, (stdout, stderr)
    assert "Traceback" not in stderr, stderr
    assert "runs interpreted" not in stderr, "a compiler stopped by Ctrl-C was reported as a failed build"
    assert pid not in left, "the compiler ran on after Ctrl-C"
    assert not left, f"processes left behind: {left}"


def test_a_compiler_stopped_by_ctrl_c_stops_its_caller(tmp_path, monkeypatch):
    """A compiler that Ctrl-C ended is not a failed build (reported, and the closed loop run
    interpreted): the caller stops as it would have (a sweep's worker, which ignores Ctrl-C itself)."""
    import casadi as ca

    from ocp.simulation.compiled import compile_function

    compiler = tmp_path / "interruptedcc"
    compiler.write_text("#!/bin/sh\nkill -INT $$\nsleep 60\n")  # what Ctrl-C does to a compiler
    compiler.chmod(0o755)
    monkeypatch.setenv("CC", str(compiler))
    x = ca.SX.sym("x")
    with pytest.raises(KeyboardInterrupt):
        compile_function(ca.Function("twice", [x], [2 * x]), tmp_path / "cache")
