"""Worker tasks for the trade-study scale tests, importable by worker processes. The case's
``maneuver.duration`` says what to do; the scenario's ``name`` is a folder where a task counts its
attempts (worker processes do not see the test's environment):

* 36 s: kills its worker on its first two attempts, then runs;
* 37 s: kills its worker on its first attempt, then runs;
* anything else: a cheap result without running the case (the sweep machinery alone).
"""
import os
import socket
import time
from pathlib import Path

from scenarios.study.worker import crashed_rows, run_case


def _attempt(payload) -> int:
    """This case's attempt number, from 1 (a file per attempt in the scenario's ``name`` folder)."""
    folder = Path(payload["scenario"]["name"])
    count = len(list(folder.glob(f"{payload['key']}-*"))) + 1
    (folder / f"{payload['key']}-{count}").write_text("")
    return count


def dying_task(payload):
    duration = payload["scenario"]["maneuver"]["duration"]
    if duration == 36.0 and _attempt(payload) <= 2:
        time.sleep(0.2)  # the other case is queued behind this one meanwhile
        os._exit(3)
    if duration == 37.0 and _attempt(payload) <= 1:
        time.sleep(0.2)
        os._exit(3)
    return cheap_task(payload)


def cheap_task(payload):
    """A result of the right shape, without running anything (rows marked ok)."""
    rows = [dict(row, status="ok", message="") for row in crashed_rows(payload["scenario"], "")]
    return {"key": payload["key"], "status": "ok", "rows": rows, "elapsed_s": 0.001, "cpu_s": 0.001,
            "worker_cpu_s": time.process_time(), "worker": f"{socket.gethostname()}:{os.getpid()}",
            "cache_builds": 0}


def real_task(payload):
    return run_case(payload)


def hanging_task(payload):
    """38 s: stuck where the worker's alarm cannot reach it (as in C code); anything else cheap."""
    if payload["scenario"]["maneuver"]["duration"] == 38.0:
        import signal
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(600)
    return cheap_task(payload)


def slow_task(payload):
    """A cheap result after 0.2 s (a Dask worker can be retired meanwhile)."""
    time.sleep(0.2)
    return cheap_task(payload)
