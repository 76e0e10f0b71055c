"""A sweep that stops kills the fork server it started (its workers die with it), never one the
caller's program started for pools of its own: slewbench stops only what it started."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SCRIPT = textwrap.dedent("""
    import multiprocessing, os
    from multiprocessing import forkserver
    from scenarios.study import engine

    if __name__ == "__main__":
        if {users}:
            multiprocessing.get_context("forkserver")
            forkserver.ensure_running()  # the caller's own server, for pools of its own
        before = forkserver._forkserver._forkserver_pid
        engine.start_forkserver()
        server = forkserver._forkserver._forkserver_pid
        engine._stop_forkserver()
        import time
        alive, deadline = True, time.monotonic() + 5.0
        while alive and time.monotonic() < deadline:  # a killed server is reaped here (our child)
            alive = os.waitpid(server, os.WNOHANG)[0] != server
            time.sleep(0.05)
        print(before == server, alive)
""")


def _run(users: bool) -> str:
    done = subprocess.run([sys.executable, "-c", SCRIPT.format(users=users)], cwd=ROOT, capture_output=True,
                          text=True, timeout=120, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


def test_the_callers_fork_server_is_left_alone():
    same, alive = _run(users=True)
    assert same == "True"  # slewbench's pools use the server that was running
    assert alive == "True"


def test_the_fork_server_slewbench_started_is_stopped():
    same, alive = _run(users=False)
    assert same == "False"
    assert alive == "False"
