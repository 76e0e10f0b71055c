"""A local sweep run from a directory holding a user's ``controllers.py`` (``planners.py``,
``ocp.py``, ``scenarios.py``): the workers import slewbench's packages, not the user's files, and
still load the user's plugin given by a relative path; and a sweep whose cases crashed does not
exit 0 as if it were complete.

Before: the process the local workers fork from is started as ``python -c``, whose ``sys.path``
starts with the current directory; it imported the user's ``controllers.py`` in place of the
package. A file that raised on import killed it (an ``EOFError`` traceback, "internal error", exit
1); a file that did not made every case ``crashed`` ("worker died (ModuleNotFoundError: No module
named 'controllers.allocation'; 'controllers' is not a package)"), and the sweep exited 0.

The command runs in a subprocess through a launcher written as pip writes the ``slewbench``
console script (its own folder first on ``sys.path``, not the working directory), with this
checkout on ``PYTHONPATH``.
"""
from __future__ import annotations

import csv
import json
import os
import shlex
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXIT_OK, EXIT_CRASHED = 0, 1  # the documented statuses (docs/guide/studies.rst)

BASE = """\
name: tiny
spacecraft:
  inertia: [2.0, 3.0, 4.0]
  wheels: {max_torque: 0.05}
maneuver:
  duration: 30.0
  initial: {q: [1, 0, 0, 0], omega: [0, 0, 0]}
  final: {q: [0.9238795, 0.3826834, 0, 0], omega: [0, 0, 0]}
planners:
  - {name: PLANNER, label: smooth}
controller: {name: augmented_quaternion_feedback, options: {kp: 0.2, kd: 0.6}}
simulation: {sample_time: 1.0, duration: 35.0}
"""

STUDY = """\
study: STUDY
scenario: scenarios/base.yaml
grid:
  maneuver.duration: [30.0, 32.0]
summary: [cl.int_u]
execution: {workers: 2, case_timeout_s: TIMEOUT}
"""

PROBE = """\
import json
import os
import sys

import controllers
from planners import PLANNERS


class ProbeEigenaxis(PLANNERS["eigenaxis"]):
    name = "probe_eigenaxis"


PLANNERS[ProbeEigenaxis.name] = ProbeEigenaxis
with open(f"probe-{os.getpid()}.json", "w") as handle:  # relative: the process's working directory
    json.dump({"cwd": os.getcwd(), "sys_path": sys.path, "controllers": controllers.__file__,
               "environment": {name: os.environ.get(name) for name in ("PYTHONSAFEPATH", "SLEWBENCH_SAFE_PATH",
                                                                      "PYTHONPATH", "SLEWBENCH_USER_PYTHONPATH")}},
              handle)
"""

LAUNCHER = """\
import sys
from scenarios.console import main
if __name__ == '__main__':
    sys.exit(main())
"""

CHECKOUT_LAUNCHER = """\
import sys
sys.path.insert(0, ROOT)  # a checkout put first by the script itself (a notebook's sys.path.insert)
from scenarios.console import main
if __name__ == '__main__':
    sys.exit(main())
"""


def user_directory(tmp_path: Path, planner: str, timeout: float, shadows: bool = True) -> Path:
    """A working directory with (``shadows``) the user's own modules named as slewbench's packages,
    each raising on import, a plugin file, and a study whose base scenario is referenced by a
    relative path."""
    user = tmp_path / "work"
    (user / "scenarios").mkdir(parents=True)  # a folder of the user's scenario files, not a package
    for name in ("controllers", "planners", "ocp", "scenarios") if shadows else ():
        (user / f"{name}.py").write_text(f"raise RuntimeError('the user\\'s own {name}.py was imported')\n")
    (user / "scenarios" / "base.yaml").write_text(BASE.replace("PLANNER", planner))
    (user / "study.yaml").write_text(STUDY.replace("STUDY", f"isolation-{planner}").replace("TIMEOUT", str(timeout)))
    (user / "probe_plugin.py").write_text(PROBE)
    return user


def slewbench(tmp_path: Path, user: Path, *args: str, checkout_first: bool = False) -> subprocess.Popen[str]:
    launcher = tmp_path / "bin" / "slewbench_console.py"
    launcher.parent.mkdir(exist_ok=True)
    launcher.write_text(CHECKOUT_LAUNCHER.replace("ROOT", repr(str(ROOT))) if checkout_first else LAUNCHER)
    env = {key: value for key, value in os.environ.items()
           if key not in ("PYTHONPATH", "PYTHONSAFEPATH", "SLEWBENCH_PLUGINS", "SLEWBENCH_SAFE_PATH")}
    env.update(MPLBACKEND="Agg", SLEWBENCH_PLUGINS="./probe_plugin.py")
    if not checkout_first:
        env["PYTHONPATH"] = str(ROOT)
    return subprocess.Popen([sys.executable, str(launcher), *args], cwd=user, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_a_local_sweep_imports_slewbench_not_the_users_files_of_the_same_name(tmp_path: Path) -> None:
    user = user_directory(tmp_path, "probe_eigenaxis", 600.0)
    process = slewbench(tmp_path, user, "sweep", "study.yaml", "--out", "out", "--no-plots")
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == EXIT_OK, stdout + stderr
    assert "Traceback" not in stderr and "was imported" not in stdout + stderr
    found = rows(user / "out" / "cases.csv")
    assert [(r["case"], r["planner"], r["status"]) for r in found] == [("0", "probe_eigenaxis", "ok"),
                                                                     ("1", "probe_eigenaxis", "ok")], found
    assert all(float(r["cl.int_u"]) > 0 for r in found)
    # the plugin ran in the sweep's process and in at least one worker, each seeing slewbench's package
    probes = {int(p.stem.split("-")[1]): json.loads(p.read_text()) for p in user.glob("probe-*.json")}
    assert process.pid in probes and len(probes) >= 2, sorted(probes)
    for pid, probe in probes.items():
        assert Path(probe["controllers"]).resolve() == ROOT / "controllers" / "__init__.py", (pid, probe)
        assert Path(probe["cwd"]).resolve() == user.resolve(), (pid, probe)  # relative paths as in the sweep
    for pid, probe in probes.items():
        if pid != process.pid:  # a worker: no current directory on its path, the environment put back
            assert "" not in probe["sys_path"] and str(user) not in probe["sys_path"], probe["sys_path"]
            assert probe["environment"] == {"PYTHONSAFEPATH": None, "SLEWBENCH_SAFE_PATH": None,
                                            "PYTHONPATH": str(ROOT), "SLEWBENCH_USER_PYTHONPATH": None}, probe


def test_the_workers_run_the_workbench_the_sweep_runs(tmp_path: Path) -> None:
    # The sweep's process finds this checkout first by its own sys.path (no PYTHONPATH), while
    # another copy may be installed: the server (safe-path mode) imported the installed one, and
    # the workers ran other code than the sweep (a reviewer, 2026-12-02: main's runner in a
    # worktree's sweep). Now the server is given the sweep's sys.path.
    user = user_directory(tmp_path, "probe_eigenaxis", 600.0)
    process = slewbench(tmp_path, user, "sweep", "study.yaml", "--out", "out", "--no-plots", checkout_first=True)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == EXIT_OK, stdout + stderr
    probes = {int(p.stem.split("-")[1]): json.loads(p.read_text()) for p in user.glob("probe-*.json")}
    workers = {pid: probe for pid, probe in probes.items() if pid != process.pid}
    assert workers, sorted(probes)
    for pid, probe in probes.items():
        assert Path(probe["controllers"]).resolve() == ROOT / "controllers" / "__init__.py", (pid, probe)
    for probe in workers.values():  # the user's environment put back: no PYTHONPATH
        assert probe["environment"]["PYTHONPATH"] is None and "" not in probe["sys_path"], probe


def test_a_sweep_whose_cases_crashed_says_so_and_exits_nonzero(tmp_path: Path) -> None:
    # every case runs out of its 1 ms (a crash: an outcome of the execution, not a result)
    user = user_directory(tmp_path, "eigenaxis", 0.001, shadows=False)
    process = slewbench(tmp_path, user, "sweep", "study.yaml", "--out", "out", "--no-plots")
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == EXIT_CRASHED, stdout + stderr
    assert "Traceback" not in stderr and "internal error" not in stderr, stderr
    assert "slewbench: 2 of 2 cases crashed" in stderr, stderr
    assert "2 cases: timed out after 0.001 s (case_timeout_s)" in stderr, stderr
    resume = shlex.join(["slewbench", "sweep", "study.yaml", "--out", str(user / "out"), "--resume", "--no-plots"])
    assert resume in stderr, stderr
    found = rows(user / "out" / "cases.csv")  # the tables are written all the same
    assert [r["status"] for r in found] == ["crashed", "crashed"], found
    report = slewbench(tmp_path, user, "sweep", "--report", "out", "--no-plots")  # a redraw says so too
    stdout, stderr = report.communicate(timeout=120)
    assert report.returncode == EXIT_OK, stdout + stderr
    assert "from 2 stored case(s) (2 crashed: no result; `--resume` runs them again); 0 missing" in stdout, stdout


def test_the_fork_server_module_takes_the_current_directory_off_its_path(monkeypatch) -> None:
    """Where Python has no safe-path mode (3.10), the server's first import takes ``''`` (what
    ``python -c`` puts first) off ``sys.path``, and the environment variables the sweep set for the
    server are taken out again; in any other process (no mark) nothing changes."""
    from scenarios.study import server

    monkeypatch.setattr(sys, "path", ["", "/somewhere", "", "/site-packages"])
    monkeypatch.setenv("SLEWBENCH_SAFE_PATH", "added")
    monkeypatch.setenv("PYTHONSAFEPATH", "1")
    server.isolate_import_path()
    assert sys.path == ["/somewhere", "/site-packages"]
    assert "SLEWBENCH_SAFE_PATH" not in os.environ and "PYTHONSAFEPATH" not in os.environ
    monkeypatch.setattr(sys, "path", ["", "/somewhere"])
    monkeypatch.setenv("SLEWBENCH_SAFE_PATH", "kept")  # the user had set PYTHONSAFEPATH: it stays
    monkeypatch.setenv("PYTHONSAFEPATH", "1")
    server.isolate_import_path()
    assert sys.path == ["/somewhere"] and os.environ["PYTHONSAFEPATH"] == "1"
    monkeypatch.setattr(sys, "path", ["", "/somewhere"])  # the user's PYTHONPATH put back, or none
    monkeypatch.setenv("SLEWBENCH_SAFE_PATH", "kept")
    monkeypatch.setenv("PYTHONPATH", "/the/sweeps/sys/path")
    monkeypatch.setenv("SLEWBENCH_USER_PYTHONPATH", "/users/own")
    server.isolate_import_path()
    assert os.environ["PYTHONPATH"] == "/users/own" and "SLEWBENCH_USER_PYTHONPATH" not in os.environ
    monkeypatch.setenv("SLEWBENCH_SAFE_PATH", "kept")
    monkeypatch.setenv("SLEWBENCH_USER_PYTHONPATH", server.UNSET)
    server.isolate_import_path()
    assert "PYTHONPATH" not in os.environ
    monkeypatch.setattr(sys, "path", ["", "/somewhere"])
    server.isolate_import_path()  # not the server (no mark): nothing changes
    assert sys.path == ["", "/somewhere"] and os.environ["PYTHONSAFEPATH"] == "1"
