"""``slewbench sweep`` shows a progress bar with the time left in a terminal (issue 31): run under a
pseudo-terminal, whether the terminal reports its size or, as some do (``script`` without a
terminal of its own, a freshly opened pty), reports 0 x 0; and shows none when its output is not a
terminal."""
from __future__ import annotations

import fcntl
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios
import textwrap
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
STUDY = textwrap.dedent("""\
    study: tiny-bar
    scenario:
      name: tiny
      spacecraft: {inertia: [2.0, 3.0, 4.0], wheels: {max_torque: 0.05}}
      maneuver:
        duration: 20.0
        initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
        final: {q: [0.9238795, 0.3826834, 0, 0], omega: [0, 0, 0]}
      planners: [{name: eigenaxis, label: smooth}]
      controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
      simulation: {sample_time: 1.0, duration: 22.0}
    grid:
      maneuver.duration: [20.0, 22.0, 24.0, 26.0]
    execution: {workers: 1}
    """)
BAR = re.compile(r"tiny-bar: +(\d+)%\|[^|]*\| *(\d+)/4 \[\d\d:\d\d<\d\d:\d\d")
"""A tqdm line: percentage, bar, count, elapsed < remaining (the ETA)."""


def sweep_output(tmp_path: Path, columns: int | None) -> str:
    """What a terminal of ``columns`` columns (None: one reporting 0 x 0) shows of a small sweep."""
    study = tmp_path / "study.yaml"
    study.write_text(STUDY)
    master, slave = pty.openpty()
    if columns is not None:
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    process = subprocess.Popen([sys.executable, "-m", "scenarios.cli", "sweep", str(study), "--out",
                                str(tmp_path / "out"), "--no-plots"], cwd=ROOT, stdin=slave, stdout=slave,
                               stderr=slave, close_fds=True)
    os.close(slave)
    output, deadline = b"", time.monotonic() + 120.0
    try:
        while time.monotonic() < deadline:
            ready, _, _ = select.select([master], [], [], 0.2)
            if ready:
                try:
                    chunk = os.read(master, 65536)
                except OSError:  # the child closed the terminal
                    break
                if not chunk:
                    break
                output += chunk
            elif process.poll() is not None:
                break
    finally:
        os.close(master)
        if process.poll() is None:
            process.kill()
        process.wait()
    assert process.returncode == 0, output.decode(errors="replace")
    return output.decode(errors="replace")


@pytest.mark.parametrize("columns", [100, None])
def test_the_sweep_shows_a_bar_with_the_time_left_in_a_terminal(tmp_path, columns):
    output = sweep_output(tmp_path, columns)
    frames = [m for m in BAR.finditer(output)]
    assert frames, output
    assert frames[-1].group(1) == "100" and frames[-1].group(2) == "4"
    width = max(len(line) for line in output.split("\r") if BAR.search(line))
    assert width <= (columns or 80)  # fits the terminal (80 columns when it reports none)


def test_no_bar_when_the_output_is_not_a_terminal(tmp_path):
    study = tmp_path / "study.yaml"
    study.write_text(STUDY)
    done = subprocess.run([sys.executable, "-m", "scenarios.cli", "sweep", str(study), "--out", str(tmp_path / "out"),
                           "--no-plots"], cwd=ROOT, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr
    assert not BAR.search(done.stderr) and "%|" not in done.stderr
