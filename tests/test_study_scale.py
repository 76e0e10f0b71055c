"""Trade studies at scale (issue 32): nothing hangs, no process outlives the sweep, nothing is
written before the study, the options and the scheduler are checked, a full disk leaves nothing
behind, every study number has a limit, messages stay short, worker deaths are charged to the case
that caused them, and library calls name a bad argument."""
import contextlib
import copy
import http.server
import io
import itertools
import os
import signal
import socket
import sqlite3
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from scenarios.cli.commands import main
from scenarios.errors import ScenarioError
from scenarios.study import engine as engine_module
from scenarios.study.engine import SweepResults, sweep
from scenarios.study.spec import load_study, parse_study
from scenarios.study.store import SweepStore, claim_sweep_directory
from tests.test_sweep import BASE, InlineExecutor

ROOT = Path(__file__).resolve().parents[1]


def study_data(**parts):
    return {"study": "scale", "scenario": copy.deepcopy(BASE), **parts}


def write_study(folder: Path, data: dict, name: str = "study.yaml") -> Path:
    (folder / "base.yaml").write_text(yaml.safe_dump(BASE))
    data = dict(data)
    if isinstance(data.get("scenario"), dict):
        data["scenario"] = "base.yaml"
    path = folder / name
    path.write_text(yaml.safe_dump(data))
    return path


@contextlib.contextmanager
def bounded(seconds: float):
    """Fail the test (instead of hanging the suite) when the block runs longer than ``seconds``."""
    def expire(signum, frame):
        raise TimeoutError(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def cli(*args, seconds: float = 60.0) -> tuple[int, str, str]:
    """``slewbench`` in this process: status, stdout, stderr."""
    out, err = io.StringIO(), io.StringIO()
    with bounded(seconds), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main([str(arg) for arg in args])
    return status, out.getvalue(), err.getvalue()


# --- 1. nothing waits for a writer --------------------------------------------------------------

def test_a_named_pipe_is_refused_at_once_as_scenario_study_base_and_marker(tmp_path):
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    status, _, error = cli("validate", fifo, seconds=10)
    assert status == 2 and "named pipe" in error
    status, _, error = cli("sweep", fifo, "--out", tmp_path / "a", seconds=10)
    assert status == 2 and "named pipe" in error and not (tmp_path / "a").exists()
    study = tmp_path / "study.yaml"
    study.write_text(yaml.safe_dump({"study": "s", "scenario": "fifo.yaml", "grid": {"maneuver.duration": [30.0]}}))
    status, _, error = cli("sweep", study, "--out", tmp_path / "b", seconds=10)
    assert status == 2 and "scenario: cannot read" in error and "named pipe" in error
    marked = tmp_path / "marked"  # an output directory whose marker is a named pipe is not slewbench's
    marked.mkdir()
    os.mkfifo(marked / ".slewbench-output.json")
    good = write_study(tmp_path, study_data(grid={"maneuver.duration": [30.0]}), "good.yaml")
    status, _, error = cli("sweep", good, "--out", marked, "--no-plots", seconds=20)
    assert status == 2 and "did not create" in error
    status, _, error = cli("sweep", "--report", marked, seconds=10)
    assert status == 2 and "holds no slewbench sweep" in error


# --- 2. the case count comes before the cases -------------------------------------------------------

def test_a_huge_grid_is_refused_from_its_axes_lengths_without_building_it(tmp_path):
    path = write_study(tmp_path, study_data(grid={"maneuver.duration": {"linspace": [60, 100, 10000]},
                                                  "simulation.sample_time": {"linspace": [0.1, 1.0, 10000]}}))
    code = ("import resource, sys; resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30)); "
            "from scenarios.cli.commands import main; sys.exit(main(sys.argv[1:]))")
    start = time.monotonic()
    done = subprocess.run([sys.executable, "-c", code, "sweep", str(path), "--out", str(tmp_path / "out")],
                          cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)), capture_output=True, text=True,
                          timeout=120, check=False)
    assert done.returncode == 2, done.stderr[-2000:]
    assert "10000 x 10000 = 100000000 cases; at most 100000" in done.stderr
    assert time.monotonic() - start < 60 and not (tmp_path / "out").exists()


def test_a_monte_carlo_over_the_limit_names_its_samples():
    with pytest.raises(ScenarioError, match=r"monte_carlo.samples: the study has 3 x 40000 = 120000 cases"):
        parse_study(study_data(grid={"maneuver.duration": [30.0, 31.0, 32.0]}, monte_carlo={
            "samples": 40000, "dispersions": {"simulation.sensor_noise.seed": "case_seed"}}))


# --- 3, 4, 7, 9. the scheduler is checked before anything is written ---------------------------

@pytest.mark.parametrize("address, words", [
    ("not an address", "expected an address such as tcp://127.0.0.1:8786"),
    ("tcp://[::1", "expected an address such as"),
    ("foo://127.0.0.1:8786", "unknown scheme 'foo'"),
    ("tcp://127.0.0.1:99999", "expected a port from 1 to 65535, got 99999"),
    ("tcp://" + "h" * 300 + ":8786", "expected an address such as"),
])
def test_a_malformed_scheduler_address_is_exit_2_naming_it(tmp_path, address, words):
    path = write_study(tmp_path, study_data())
    status, _, error = cli("sweep", path, "--out", tmp_path / "out", "--scheduler", address, seconds=30)
    assert status == 2 and f"--scheduler: {words}" in error and "Traceback" not in error, error
    assert not (tmp_path / "out").exists() and len(error) < 600
    data = study_data(execution={"scheduler": address})
    with pytest.raises(ScenarioError, match="execution.scheduler: "):
        parse_study(data)


@contextlib.contextmanager
def web_server():
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"tcp://127.0.0.1:{server.server_address[1]}"
    finally:
        server.shutdown()
        server.server_close()


def test_a_web_server_as_scheduler_is_refused_within_the_handshake_timeout(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(engine_module, "HANDSHAKE_TIMEOUT_S", 2.0)
    path = write_study(tmp_path, study_data())
    with web_server() as address:
        start = time.monotonic()
        status, _, error = cli("sweep", path, "--out", tmp_path / "out", "--scheduler", address, seconds=40)
    assert status == 2 and "--scheduler: " in error and "Dask scheduler" in error, error
    assert time.monotonic() - start < 30 and not (tmp_path / "out").exists()


def test_a_closed_port_is_refused(tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(engine_module, "HANDSHAKE_TIMEOUT_S", 2.0)
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    path = write_study(tmp_path, study_data())
    status, _, error = cli("sweep", path, "--out", tmp_path / "out", "--scheduler", f"127.0.0.1:{port}", seconds=40)
    assert status == 2 and "no Dask scheduler answered" in error and not (tmp_path / "out").exists(), error


def test_a_scheduler_without_workers_is_refused_after_a_stated_wait_with_nothing_written(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    monkeypatch.setattr(engine_module, "WORKER_WAIT_S", 1.0)
    path = write_study(tmp_path, study_data())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cluster = distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp", host="127.0.0.1",
                                             dashboard_address=None)
    with cluster:
        status, _, error = cli("sweep", path, "--out", tmp_path / "out", "--scheduler", cluster.scheduler_address,
                               seconds=60)
    assert status == 2 and "has no workers (waited 1 s)" in error, error
    assert not (tmp_path / "out").exists()


# --- 6. no process outlives a killed sweep ----------------------------------------------------------

def session_processes(session: int) -> list[tuple[int, str]]:
    """Live (not zombie) processes of a session other than its leader: (pid, command line)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == session:
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
            fields = stat[stat.rindex(")") + 2:].split()
            if int(fields[3]) == session and fields[0] != "Z":
                found.append((int(entry), Path(f"/proc/{entry}/cmdline").read_text().replace("\0", " ")[:100]))
        except (OSError, ValueError, IndexError):
            continue
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_sigkill_of_the_sweep_leaves_no_process_of_its_tree_after_2_s(tmp_path):
    path = write_study(tmp_path, study_data(grid={"maneuver.duration": [30.0 + i for i in range(200)]}))
    out = tmp_path / "out"
    process = subprocess.Popen([sys.executable, "-m", "scenarios.cli", "sweep", str(path), "--out", str(out),
                                "--workers", "2", "--no-plots"], cwd=ROOT, env=dict(os.environ, PYTHONPATH=str(ROOT)),
                               start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    left = []
    try:
        deadline = time.monotonic() + 120
        while len(session_processes(process.pid)) < 4:  # the fork server, the resource tracker, 2 workers
            assert process.poll() is None, process.stderr.read()
            assert time.monotonic() < deadline, "the sweep did not start its workers"
            time.sleep(0.05)
        os.kill(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
        killed = time.monotonic()
        while session_processes(process.pid) and time.monotonic() - killed < 2.0:
            time.sleep(0.05)
        left = session_processes(process.pid)
        assert not left, f"alive 2 s after SIGKILL of the sweep: {left}"
    finally:
        for pid, _ in left or session_processes(process.pid):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        if process.poll() is None:
            process.kill()


# --- 8, 10, 11. output locations ---------------------------------------------------------------------

def test_a_300_character_out_name_is_exit_2(tmp_path):
    path = write_study(tmp_path, study_data())
    status, _, error = cli("sweep", path, "--out", tmp_path / ("x" * 300), "--no-plots", seconds=60)
    assert status == 2 and "output error: --out" in error and "Traceback" not in error and len(error) < 800, error


def test_a_store_that_cannot_start_leaves_no_folder_behind(tmp_path, monkeypatch):
    path = write_study(tmp_path, study_data())

    def full(self, name, value):
        raise sqlite3.OperationalError("database or disk is full")

    monkeypatch.setattr(SweepStore, "set_meta", full)
    status, _, error = cli("sweep", path, "--out", tmp_path / "new" / "out", "--no-plots", seconds=60)
    assert status == 2 and "disk is full" in error and "nothing was left behind" in error, error
    assert not (tmp_path / "new").exists()
    empty = tmp_path / "empty"
    empty.mkdir()
    status, _, _ = cli("sweep", path, "--out", empty, "--no-plots", seconds=60)
    assert status == 2 and list(empty.iterdir()) == []


@pytest.fixture
def small_file_system(tmp_path):
    """A 64 KiB tmpfs (needs the right to mount; skipped otherwise)."""
    mount = tmp_path / "small"
    mount.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mount)], capture_output=True, check=False)
    if done.returncode != 0:
        pytest.skip("cannot mount a tmpfs here")
    try:
        yield mount
    finally:
        subprocess.run(["umount", "-l", str(mount)], check=False)


def test_a_full_small_file_system_leaves_no_partial_folder(tmp_path, small_file_system):
    (small_file_system / "filler").write_bytes(b"\0" * (56 * 1024))  # leave a few kilobytes
    path = write_study(tmp_path, study_data())
    status, _, error = cli("sweep", path, "--out", small_file_system / "out", "--no-plots", seconds=60)
    assert status == 2 and "output error" in error and "Traceback" not in error, error
    assert sorted(p.name for p in small_file_system.iterdir()) == ["filler"]


def test_a_disk_full_while_running_keeps_the_stored_cases_and_says_how_to_resume(tmp_path, monkeypatch):
    path = write_study(tmp_path, study_data(grid={"maneuver.duration": [30.0, 31.0, 32.0, 33.0]}))
    original, commits = SweepStore.put_encoded, []

    def filling(self, cases):
        cases = list(cases)
        if commits:
            raise sqlite3.OperationalError("database or disk is full")
        commits.append(len(cases))
        original(self, cases)

    monkeypatch.setattr(SweepStore, "put_encoded", filling)
    monkeypatch.setattr(engine_module, "_POLL_S", 0.05)
    out = tmp_path / "out"
    status, _, error = cli("sweep", path, "--out", out, "--no-plots", "--workers", "1", seconds=120)
    assert status == 2 and "could not be written" in error and "--resume" in error, error
    with SweepStore(out, create=False) as store:
        assert len(store) == commits[0] >= 1


def test_report_of_a_damaged_store_is_exit_2(tmp_path):
    path = write_study(tmp_path, study_data())
    out = tmp_path / "out"
    assert cli("sweep", path, "--out", out, "--no-plots", "--workers", "1", seconds=120)[0] == 0
    with contextlib.closing(sqlite3.connect(out / "sweep.sqlite")) as db:
        db.execute("UPDATE cases SET rows = '{not json'")
        db.commit()
    status, _, error = cli("sweep", "--report", out, "--no-plots", seconds=60)
    assert status == 2 and "damaged" in error and "Traceback" not in error, error
    with contextlib.closing(sqlite3.connect(out / "sweep.sqlite")) as db:
        db.execute("UPDATE meta SET value = '[1, 2' WHERE name = 'study'")
        db.commit()
    status, _, error = cli("sweep", "--report", out, "--no-plots", seconds=60)
    assert status == 2 and "damaged" in error, error


# --- 12. limits on every number of a study ---------------------------------------------------------

@pytest.mark.parametrize("change, words", [
    ({"execution": {"case_timeout_s": 1.0e300}}, r"execution\.case_timeout_s: expected a number <= 604800"),
    ({"execution": {"case_timeout_s": float("nan")}}, r"execution\.case_timeout_s: expected a number"),
    ({"execution": {"case_timeout_s": 2**64}}, r"execution\.case_timeout_s: expected a number <= 604800"),
    ({"grid": {"maneuver.duration": [30.0, 10**400]}}, r"case 1 .*maneuver\.duration.*: expected a number, got"),
    ({"grid": {"planners[label=fast].options.torque_fraction": [10**400]}},
     r"case 0 .*planners\[1\]\.options\.torque_fraction.*expected a number"),
    ({"grid": {"spacecraft.inertia": [[2.0, 10**400, 3.0]]}}, r"case 0 .*spacecraft\.inertia.*expected finite numbers"),
    ({"monte_carlo": {"samples": 2, "seed": 2**70, "dispersions": {}}}, r"monte_carlo\.seed: expected an integer"),
    ({"monte_carlo": {"samples": 2, "dispersions": {"maneuver.duration": "case_seed"}}},
     r"monte_carlo\.dispersions\.maneuver\.duration: case_seed sets an integer"),
    ({"monte_carlo": {"samples": 2, "dispersions": {"planners[0].options.torque_fraction": "case_seed"}}},
     r"case_seed sets an integer"),
    ({"grid": {"maneuver.duration": [30.0]}, "zip": {"maneuver.duration": [40.0]}},
     r"zip\.maneuver\.duration: this path is also in grid"),
    ({"grid": {"simulation.sensor_noise.seed": [1, 2]}, "zip": {"simulation.sensor_noise": [{"seed": 3}]}},
     r"zip\.simulation\.sensor_noise: it replaces simulation\.sensor_noise\.seed"),
    ({"grid": {"maneuver.duration": {"linspace": [1.0e308, -1.0e308, 3]}}}, r"not finite"),
    ({"grid": {"maneuver.final.q": {"axis_angle": {"axis": [1.0e308, 1.0e308, 0], "angle_deg": [10, 20]}}}}, None),
    ({"monte_carlo": {"samples": 2, "dispersions": {"maneuver.duration": {"normal": {"mean": 1.0e308,
                                                                                      "std": 1.0e308}}}}},
     r"not finite.*too large"),
    ({"monte_carlo": {"samples": 2, "dispersions": {"spacecraft.inertia": {"scale": {"uniform": [1e307, 1e308]}}}}},
     r"not finite"),
    ({"study": "s" * 300}, r"study: expected a non-empty name of at most 200 characters"),
    ({"grid": {f"simulation.k{i}": [1] for i in range(150)}}, r"a study varies at most 100 scenario paths"),
])
def test_every_study_number_has_a_limit_and_nothing_warns(change, words):
    data = {**study_data(), **change}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # NumPy's overflow warnings would come before the message
        if words is None:
            study = parse_study(data)
            assert all(np.isfinite(c.scenario["maneuver"]["final"]["q"]).all() for c in study.cases)
            return
        with pytest.raises(ScenarioError, match=words):
            parse_study(data)


def test_case_seed_sets_integer_keys_of_the_schema_and_of_options():
    study = parse_study(study_data(monte_carlo={"samples": 3, "dispersions": {
        "simulation.sensor_noise.seed": "case_seed"}}))
    assert [c.scenario["simulation"]["sensor_noise"]["seed"] for c in study.cases] == [c.seed for c in study.cases]


def test_a_huge_duration_is_refused_before_any_case_runs(tmp_path):
    """maneuver.duration 1e308 with a short simulation window used to pass the loader, and the planner's
    overflow was printed by the worker."""
    path = write_study(tmp_path, study_data(grid={"maneuver.duration": [30.0, 1.0e308]}))
    status, _, error = cli("sweep", path, "--out", tmp_path / "out", "--no-plots", seconds=60)
    assert status == 2 and "case 1 [maneuver.duration=1e+308]: maneuver.duration" in error, error
    assert "expected a number <= 1e+08" in error and not (tmp_path / "out").exists()


# --- 13. bounded messages ---------------------------------------------------------------------------

def test_messages_are_bounded_for_many_keys_and_huge_paths(tmp_path):
    many = {f"simulation.k{i}": [1] for i in range(2000)}
    status, _, error = cli("sweep", write_study(tmp_path, study_data(grid=many)), "--out", tmp_path / "o", seconds=60)
    assert status == 2 and len(error) < 1000, len(error)
    huge = {"maneuver." + "d" * 100_000: [1.0]}
    status, _, error = cli("sweep", write_study(tmp_path, study_data(grid=huge), "huge.yaml"), "--out",
                           tmp_path / "o", seconds=60)
    assert status == 2 and len(error) < 3000, len(error)
    near = {"simulation.sensor_noise.seed": [1.5], **{f"maneuver.k{i}": [1] for i in range(90)}}
    with pytest.raises(ScenarioError) as raised:
        parse_study(study_data(grid=near))
    assert len(str(raised.value)) < 2500 and "case 0 [" in str(raised.value)


# --- 14. retry accounting ----------------------------------------------------------------------------

def dying_study(tmp_path, durations, retries):
    base = copy.deepcopy(BASE)
    base["name"] = str(tmp_path)  # where the tasks count their attempts
    return parse_study({"study": "dying", "scenario": base, "grid": {"maneuver.duration": durations},
                        "execution": {"retries": retries, "case_timeout_s": 60.0}})


def test_a_worker_death_is_charged_to_the_case_it_ran_never_to_a_queued_one(tmp_path):
    from tests.study_scale_tasks import dying_task
    study = dying_study(tmp_path, [37.0, 30.0], retries=1)  # one worker: 30 s waits in the queue
    results = sweep(study, workers=1, task=dying_task)
    records = {c.scenario["maneuver"]["duration"]: results.records[c.key] for c in study.cases}
    assert records[37.0]["status"] == "ok" and records[37.0]["attempts"] == 2
    assert records[30.0]["status"] == "ok" and records[30.0]["attempts"] == 1


def test_a_case_that_kills_its_worker_twice_with_one_retry_is_crashed(tmp_path):
    from tests.study_scale_tasks import dying_task
    study = dying_study(tmp_path, [36.0, 30.0], retries=1)
    results = sweep(study, workers=1, task=dying_task)
    records = {c.scenario["maneuver"]["duration"]: results.records[c.key] for c in study.cases}
    assert records[36.0]["status"] == "crashed" and records[36.0]["attempts"] == 2
    assert "worker died" in records[36.0]["rows"][0]["message"] and "2 attempt(s)" in records[36.0]["rows"][0]["message"]
    assert records[30.0]["status"] == "ok" and records[30.0]["attempts"] == 1
    (tmp_path / "again").mkdir()
    again = sweep(dying_study(tmp_path / "again", [36.0], retries=2), workers=1, task=dying_task)
    (record,) = again.records.values()
    assert record["status"] == "ok" and record["attempts"] == 3  # died twice, ran the third time


# --- the library names a bad argument -------------------------------------------------------------

@pytest.mark.parametrize("call, error, words", [
    (lambda s: sweep(s, workers=0), ValueError, "workers must be an integer from 1 to 1024"),
    (lambda s: sweep(s, workers=2.5), ValueError, "workers must be an integer"),
    (lambda s: sweep(s, workers=True), ValueError, "workers must be an integer"),
    (lambda s: sweep(s, task=None), TypeError, "task must be a callable"),
    (lambda s: sweep(s, executor="pool"), TypeError, "executor must be a concurrent.futures.Executor"),
    (lambda s: sweep(s, store="out"), TypeError, "store must be a SweepStore"),
    (lambda s: sweep(s, progress="yes"), TypeError, "progress must be True or False"),
    (lambda s: sweep(3), TypeError, "study must be a Study"),
    (lambda s: load_study(3), TypeError, "path must be a str or os.PathLike"),
    (lambda s: parse_study([1, 2]), ScenarioError, "expected a mapping"),
    (lambda s: parse_study({"study": "x"}, source=3), TypeError, "source must be a path"),
    (lambda s: parse_study({"study": "x"}, version=3), TypeError, "version must be a str"),
    (lambda s: SweepResults(None, {}), TypeError, "study must be a scenarios.study.Study"),
    (lambda s: SweepResults(s, []), TypeError, "records must be a dict"),
    (lambda s: SweepResults(s, {}).write(3), TypeError, "directory must be a str or os.PathLike"),
    (lambda s: SweepStore(3), TypeError, "directory must be a str or os.PathLike"),
    (lambda s: SweepStore("/nonexistent/slewbench"), FileNotFoundError, "does not exist"),
    (lambda s: SweepStore(__file__), NotADirectoryError, "is not a directory"),
])
def test_library_calls_name_the_bad_argument(call, error, words):
    study = parse_study(study_data())
    with pytest.raises(error, match=words):
        call(study)


def test_store_and_run_arguments_are_checked(tmp_path):
    import scenarios
    with SweepStore(tmp_path) as store:
        with pytest.raises(TypeError, match="create must be True or False"):
            SweepStore(tmp_path, create="no")
        with pytest.raises(ValueError, match="status must be one of ok, crashed"):
            store.put("k", "fine", [], None, 1)
        with pytest.raises(ValueError, match="attempts must be an integer >= 1"):
            store.put("k", "ok", [], None, 0)
        with pytest.raises(TypeError, match="rows must be a list of dicts"):
            store.put_many([("a", "ok", [], 1.0, 1), ("b", "ok", "rows", 1.0, 1)])
        assert len(store) == 0  # all or nothing
    scenario = scenarios.parse_scenario(copy.deepcopy(BASE))
    for kwargs, words in (({"cache": "x"}, "cache must be an ocp.SolverCache"), ({"progress": 3}, "progress must be"),
                          ({"simulators": "x"}, "simulators must have")):
        with pytest.raises(TypeError, match=words):
            scenarios.run(scenario, **kwargs)
    with pytest.raises(TypeError, match="scenario must be a Scenario"):
        scenarios.run(copy.deepcopy(BASE))


# --- the parent keeps up -------------------------------------------------------------------------

def test_progress_is_reported_while_the_cases_are_checked():
    seen = []
    study = parse_study(study_data(monte_carlo={"samples": 5000, "dispersions": {
        "simulation.sensor_noise.seed": "case_seed",
        "simulation.initial_attitude_error_deg": {"normal": {"mean": [0, 0, 0], "std": [1, 1, 1]}}}}),
        progress=lambda checked, total: seen.append((checked, total)))
    assert seen[-1] == (5000, 5000) and len(seen) >= 3 and all(b[0] > a[0] for a, b in itertools.pairwise(seen))
    assert len(study.cases) == 5000


def test_the_store_commits_what_finishes_together_in_one_transaction(tmp_path):
    study = parse_study(study_data(grid={"maneuver.duration": [30.0 + i for i in range(12)]}))
    out = claim_sweep_directory(tmp_path / "out")
    from tests.study_scale_tasks import cheap_task
    with SweepStore(out) as store:
        calls = []
        original = store.put_encoded
        store.put_encoded = lambda cases: (calls.append(len(cases)), original(cases))  # type: ignore[method-assign]
        sweep(study, InlineExecutor(), store=store, task=cheap_task)
        assert sum(calls) == 12 and len(store) == 12


def many_cases(tmp_path, special, count=60, retries=1, timeout=60.0):
    durations = [100.0 + i for i in range(count)]
    for position, value in special.items():
        durations[position] = value
    return dying_study(tmp_path, durations, retries) if timeout == 60.0 else parse_study({
        "study": "dying", "scenario": {**copy.deepcopy(BASE), "name": str(tmp_path)},
        "grid": {"maneuver.duration": durations}, "execution": {"retries": retries, "case_timeout_s": timeout}})


@pytest.mark.parametrize("duration, status, attempts", [(37.0, "ok", 2), (36.0, "crashed", 2)])
def test_deaths_inside_chunks_are_charged_to_their_cases_and_nothing_is_lost(tmp_path, duration, status, attempts):
    """Cheap cases go several to a task; a case that kills its worker in the middle of a chunk is
    charged (once it dies, twice it dies, with one retry), the chunk's other cases run again, and
    every case ends stored once."""
    from tests.study_scale_tasks import dying_task
    study = many_cases(tmp_path, {30: duration})
    results = sweep(study, workers=2, task=dying_task)
    assert results.missing == 0 and len(results.records) == 60
    by_duration = {c.scenario["maneuver"]["duration"]: results.records[c.key] for c in study.cases}
    assert by_duration[duration]["status"] == status and by_duration[duration]["attempts"] == attempts
    others = [record for d, record in by_duration.items() if d != duration]
    assert all(record["status"] == "ok" and 1 <= record["attempts"] <= 3 for record in others)


def test_a_case_stuck_inside_a_chunk_is_crashed_and_the_others_run(tmp_path, monkeypatch):
    from tests.study_scale_tasks import hanging_task
    monkeypatch.setattr(engine_module, "_POLL_S", 0.1)
    study = many_cases(tmp_path, {25: 38.0}, count=40, timeout=1.0)
    start = time.monotonic()
    results = sweep(study, workers=2, task=hanging_task)
    assert time.monotonic() - start < 60
    by_duration = {c.scenario["maneuver"]["duration"]: results.records[c.key] for c in study.cases}
    assert by_duration[38.0]["status"] == "crashed"
    assert by_duration[38.0]["rows"][0]["message"] == "timed out after 1 s (case_timeout_s); worker stopped"
    assert all(r["status"] == "ok" for d, r in by_duration.items() if d != 38.0) and results.missing == 0


def test_a_dask_cluster_that_loses_every_worker_stops_the_sweep_like_an_interruption(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    from scenarios.errors import SweepInterrupted
    from scenarios.study.engine import connect_scheduler
    from tests.study_scale_tasks import slow_task
    monkeypatch.setattr(engine_module, "WORKER_WAIT_S", 1.0)
    study = many_cases(tmp_path, {}, count=30)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp",
                                           host="127.0.0.1", dashboard_address=None)
    with cluster:
        connected = connect_scheduler(cluster.scheduler_address, wait_s=10.0)
        out = claim_sweep_directory(tmp_path / "out")
        retired = threading.Event()

        def retire():
            with SweepStore(out, create=False) as store:
                deadline = time.monotonic() + 60
                while len(store) < 1 and time.monotonic() < deadline:
                    time.sleep(0.05)
            cluster.scale(0)
            retired.set()

        try:
            with SweepStore(out) as store, bounded(120):
                store.set_meta("format", "slewbench-sweep-2")
                helper = threading.Thread(target=retire, daemon=True)
                helper.start()
                with pytest.raises(SweepInterrupted, match="no workers for 1 s") as stopped:
                    sweep(study, store=store, task=slow_task, cluster=connected)
                assert retired.is_set() and 1 <= len(store) < 30
                assert stopped.value.missing == 30 - len(store)
        finally:
            connected.close()


def test_a_signal_between_the_store_and_the_sweep_says_how_to_resume(tmp_path, monkeypatch):
    """SIGTERM once the store exists but before the engine took over: exit 130 with the command to resume."""
    import scenarios.study.engine as engine  # the sweep command imports `sweep` from it when it runs

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(engine, "sweep", interrupted)
    path = write_study(tmp_path, study_data(grid={"maneuver.duration": [30.0, 31.0]}))
    status, _, error = cli("sweep", path, "--out", tmp_path / "out", "--no-plots", seconds=60)
    assert status == 130 and "2 of 2 cases are missing" in error and "--resume" in error, error
