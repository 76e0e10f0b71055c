"""Ctrl-C (a real SIGINT to a real sweep's process group) where it used to go wrong: lost while the
study's cases were checked, cut into a worker's start, and ignored by the C compiler a worker
started."""
import contextlib
import os
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

