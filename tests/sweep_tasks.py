"""Worker tasks for the sweep tests: importable by worker processes (the tests' monkeypatching does
not reach them). The case's ``maneuver.duration`` says what to do: 31 s kills its worker every
time, 32 s kills it on the first attempt only (a marker file in the folder named by the scenario's
``name``: worker processes do not see the test's environment), 33 s hangs
inside the runner, 35 s hangs where the worker's alarm cannot reach; anything else runs normally."""
import os
import signal
import time
from pathlib import Path

from scenarios import runner
from scenarios.study.worker import run_case


def misbehaving_task(payload):
    duration = payload["scenario"]["maneuver"]["duration"]
    if duration == 31.0:
        os._exit(3)
    if duration == 32.0:
        marker = Path(payload["scenario"]["name"]) / "died-once"
        if not marker.exists():
            marker.write_text("")
            os._exit(3)
    if duration == 33.0:
        original = runner.run
        runner.run = lambda *args, **kwargs: time.sleep(600)
        try:
            return run_case(payload)
        finally:
            runner.run = original
    if duration == 35.0:  # stuck where the worker's alarm cannot interrupt it (as in C code)
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM})
        time.sleep(600)
    return run_case(payload)
