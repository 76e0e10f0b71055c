"""Trade studies across processes: a real Dask cluster on localhost, and a sweep stopped by
SIGTERM and by SIGKILL, then resumed, against an uninterrupted run."""
import contextlib
import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.study.engine import sweep
from scenarios.study.spec import load_study
from tests.test_sweep import BASE, InlineExecutor, comparable

ROOT = Path(__file__).resolve().parents[1]


def scheduler_address(scheduler_file: Path, scheduler: subprocess.Popen, timeout_s: float = 60.0) -> str:
    """The address a Dask scheduler started on port 0 bound (the system chose a free port as it
    bound, so no other process can take it in between), read back from its ``--scheduler-file``."""
    start = time.monotonic()
    while True:
        with contextlib.suppress(FileNotFoundError, ValueError):  # not written yet, or being written
            address = json.loads(scheduler_file.read_text())["address"]
            if address:
                return address
        assert scheduler.poll() is None, f"the scheduler exited ({scheduler.returncode}) before binding"
        assert time.monotonic() - start < timeout_s, "the scheduler wrote no address"
        time.sleep(0.05)


@contextlib.contextmanager
def processes(*commands):
    """Start each command in its own session; always stop them (TERM, then KILL after 10 s)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    started = []
    try:
        for command in commands:
            started.append(subprocess.Popen(command, cwd=ROOT, env=env, start_new_session=True,
                                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        yield started
    finally:
        for process in started:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGTERM)
        for process in started:
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait(timeout=10)


def write_study(tmp_path, grid, name="study.yaml"):
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    path = tmp_path / name
    path.write_text(yaml.safe_dump({"study": "processes", "scenario": "base.yaml", "grid": grid}))
    return path


def test_dask_cluster_on_localhost_gives_the_local_results(tmp_path):
    pytest.importorskip("distributed")
    from distributed import Client
    scheduler_file = tmp_path / "scheduler.json"  # where the scheduler says the address it bound
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
            "--no-dashboard", "--scheduler-file", str(scheduler_file)]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file", str(scheduler_file),
              "--nthreads", "1", "--no-nanny", "--no-dashboard", "--memory-limit", "0", "--host", "127.0.0.1"]
    path = write_study(tmp_path, {"maneuver.final.q": {"axis_angle": {"axis": [0, 1, 0], "angle_deg": [15, 30, 60]}}})
    with processes(dask, worker, worker) as (scheduler, *_):
        address = scheduler_address(scheduler_file, scheduler)
        assert address.startswith("tcp://127.0.0.1:"), address  # a TCP cluster on localhost, as before
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=90)
        assert main(["sweep", str(path), "--out", str(tmp_path / "dask"), "--scheduler", address, "--no-plots"]) == 0
    on_cluster = pd.read_csv(tmp_path / "dask" / "cases.csv")
    local = sweep(load_study(path), InlineExecutor())
    local.write(tmp_path / "local", plots=False)
    pd.testing.assert_frame_equal(comparable(on_cluster), comparable(pd.read_csv(tmp_path / "local" / "cases.csv")))
    assert len(on_cluster) == 6 and set(on_cluster["status"]) == {"ok"}


def stored(out: Path) -> int:
    if not (out / "sweep.sqlite").is_file():
        return 0
    try:  # read-only: connecting must not create the store the sweep is about to create
        with contextlib.closing(sqlite3.connect(f"file:{out / 'sweep.sqlite'}?mode=ro", uri=True, timeout=5)) as db:
            return db.execute("SELECT COUNT(*) FROM cases").fetchone()[0]
    except sqlite3.OperationalError:  # the schema is not created yet
        return 0


def run_until(command, out: Path, count: int, stop: int, kill_group: bool, deadline_s: float = 240.0):
    """Start the sweep, wait until ``count`` cases are stored, send ``stop``; returns the process."""
    process = subprocess.Popen(command, cwd=ROOT, start_new_session=True, text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    start = time.monotonic()
    try:
        while stored(out) < count:
            assert process.poll() is None, process.communicate()
            assert time.monotonic() - start < deadline_s, "the sweep did not progress"
            time.sleep(0.02)
        (os.killpg if kill_group else os.kill)(process.pid, stop)
        _, process.stderr_text = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout=10)
    return process


@pytest.mark.slow  # three sweeps in fresh processes: about 35 s on the shared 2-core machine
def test_sigterm_then_sigkill_then_resume_equals_an_uninterrupted_run(tmp_path):
    durations = [30.0 + 2 * i for i in range(10)]
    path = write_study(tmp_path, {"maneuver.duration": durations})
    out = tmp_path / "out"
    command = [sys.executable, "-m", "scenarios.cli", "sweep", str(path), "--out", str(out), "--workers", "2",
               "--no-plots"]
    terminated = run_until(command, out, 1, signal.SIGTERM, kill_group=False)
    assert terminated.returncode == 130
    first = stored(out)
    assert 1 <= first < 10
    assert f"{10 - first} of 10 cases are missing" in terminated.stderr_text
    assert f"--out {out} --resume" in terminated.stderr_text
    killed = run_until(command + ["--resume"], out, first + 2, signal.SIGKILL, kill_group=True)
    assert killed.returncode == -signal.SIGKILL
    assert stored(out) < 10, "the sweep finished before it was killed; the test proves nothing"
    assert main(["sweep", str(path), "--out", str(out), "--resume", "--no-plots"]) == 0
    resumed = pd.read_csv(out / "cases.csv")
    uninterrupted = sweep(load_study(path), InlineExecutor())
    uninterrupted.write(tmp_path / "reference", plots=False)
    reference = pd.read_csv(tmp_path / "reference" / "cases.csv")
    assert len(resumed) == 20 and not resumed.duplicated(["case", "label"]).any()
    pd.testing.assert_frame_equal(comparable(resumed), comparable(reference))


def _session(sid: int) -> list[int]:
    """Processes (not zombies) of the session ``sid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:  # ended meanwhile
            continue
        fields = stat[stat.rindex(")") + 2:].split()  # state, ppid, pgrp, session, ...
        if int(fields[3]) == sid and fields[0] != "Z":
            found.append(int(entry.name))
    return found


def _forkserver_importing(sweep_pid: int) -> bool:
    """Whether a child of the sweep is the fork server of its workers and has set up its SIGINT
    disposition (caught: Python's KeyboardInterrupt; or ignored): it imports the model now."""
    for entry in Path(f"/proc/{sweep_pid}/task").iterdir():
        for child in (entry / "children").read_text().split():
            with contextlib.suppress(OSError, ValueError):
                if b"forkserver" in Path(f"/proc/{child}/cmdline").read_bytes():
                    status = dict(line.split(":\t", 1) for line in Path(f"/proc/{child}/status").read_text().splitlines()
                                  if ":\t" in line)
                    sigint = 1 << (signal.SIGINT - 1)
                    return bool((int(status["SigCgt"], 16) | int(status["SigIgn"], 16)) & sigint)
    return False


def test_ctrl_c_while_the_workers_import_ends_the_sweep_without_a_traceback_or_a_process_left(tmp_path):
    """Ctrl-C in a terminal reaches the whole foreground process group, the fork server of the
    local workers too, which then imports the model (seen: its KeyboardInterrupt traceback mixed
    into the sweep's "interrupted" message). The interrupt is sent as soon as the server's Python
    runs; 3000 Monte Carlo cases keep the sweep checking them meanwhile (several seconds), as the
    user's 40 cases of a heavier study did."""
    (tmp_path / "base.yaml").write_text(yaml.safe_dump(BASE))
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump({"study": "interrupted", "scenario": "base.yaml", "monte_carlo": {
        "samples": 3000, "seed": 1, "dispersions": {
            "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}}}))
    command = [sys.executable, "-c", "import sys, scenarios.console; sys.exit(scenarios.console.main())",
               "sweep", str(path), "--out", str(tmp_path / "out"), "--workers", "2", "--no-plots"]
    process = subprocess.Popen(command, cwd=ROOT, start_new_session=True, text=True, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    try:
        start = time.monotonic()
        while not _forkserver_importing(process.pid):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() - start < 20, "no fork server was started"
            time.sleep(0.005)
        os.killpg(process.pid, signal.SIGINT)  # what Ctrl-C does
        stdout, stderr = process.communicate(timeout=20)
        deadline = time.monotonic() + 5
        while _session(process.pid) and time.monotonic() < deadline:
            time.sleep(0.05)
        left = _session(process.pid)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout=10)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)  # whatever the sweep left behind
    assert "Traceback" not in stderr, stderr
    assert process.returncode == 130, (stdout, stderr)
    assert "interrupted while its cases were checked" in stderr, "not interrupted where the test means to"
    assert not left, f"processes left behind: {left}"
